//! The identification methods, one module each: the paper's windowed
//! polynomial least squares, windowed ARX, recursive least squares,
//! continuous-time output error, `auto`, and the neural NARX predictor
//! `nn`; the ARX regressor they share.

mod arx;
mod auto;
mod nn;
mod oe;
mod paper;
pub(crate) mod regressor;
mod rls;

pub(crate) use arx::fit_arx_rows;
pub use arx::{fit_arx, fit_arx_segments, ArxConfig, ArxDiagnostics, ArxEstimator, ArxFit};
pub use auto::{AutoConfig, AutoEstimator, Candidate};
pub use nn::{NnConfig, NnEstimator, NnTraining};
pub use oe::{fit_oe, fit_oe_measured, OeConfig, OeEstimator, OeFit, OeJacobian};
pub use paper::{
    coefficients_from_polynomials, polynomials_from_coefficients, PaperConfig, PaperDiagnostics,
    PaperMethod, PredictionMode, SimplexSettings, SimplexStart, Solver, TimeOrigin,
    SHIFT_AMPLIFICATION_WARNING,
};
pub(crate) use regressor::regressor;
pub use regressor::{ArxOrders, MAX_ARX_ORDER};
pub(crate) use rls::{fold_scale, has_avx2, rls_update};
pub use rls::{RlsConfig, RlsEstimator};
