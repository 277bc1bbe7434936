//! The identification methods, one module each: the paper's windowed
//! polynomial least squares, windowed ARX, recursive least squares,
//! continuous-time output error, and `auto`.

mod arx;
mod auto;
mod oe;
mod paper;
mod rls;

pub use arx::{fit_arx, ArxConfig, ArxDiagnostics, ArxEstimator, ArxFit, ArxOrders, MAX_ARX_ORDER};
pub(crate) use arx::{fit_arx_rows, regressor};
pub use auto::{AutoConfig, AutoEstimator, AUTO_CANDIDATES};
pub use oe::{fit_oe, OeConfig, OeEstimator, OeFit};
pub use paper::{
    coefficients_from_polynomials, polynomials_from_coefficients, PaperConfig, PaperDiagnostics,
    PaperMethod, PredictionMode, SimplexSettings, Solver, TimeOrigin, SHIFT_AMPLIFICATION_WARNING,
};
pub use rls::{RlsConfig, RlsEstimator};
