//! Identification methods and the sliding-window prediction engine.
//!
//! Every method implements [`Estimator`]; the [`engine`] slides a window of
//! `W` samples over a recording, fits, predicts the next `H` samples, and
//! shifts by a hop. The [`stream`] module does the same one sample at a time.

mod arx;
mod auto;
pub mod batch;
mod companion;
pub mod engine;
mod estimator;
mod global;
mod identify;
mod method;
mod model;
mod oe;
mod order;
mod paper;
mod residuals;
mod rls;
mod srivc;
pub mod stream;
mod sweep;

pub use arx::{fit_arx, ArxConfig, ArxDiagnostics, ArxEstimator, ArxFit, ArxOrders, MAX_ARX_ORDER};
pub use auto::{AutoConfig, AutoEstimator, AUTO_CANDIDATES};
pub use engine::{EngineConfig, SlidingResult, WindowRecord};
pub use estimator::{Estimator, Signals, WindowFit};
pub use global::{fit_global_model, global_model_for, GlobalModelKind, ModelFile, ModelProvenance};
pub use identify::{identify, Identification, IdentifySummary, RESIDUAL_LAGS};
pub use method::{MethodKind, MethodSpec, METHOD_NAMES};
pub use model::LinearModel;
pub use oe::{fit_oe, OeConfig, OeEstimator, OeFit};
pub use order::{
    frols, order_table, select_order, Criterion, FrolsConfig, FrolsResult, FrolsTerm, OrderRow,
    OrderSearch, OrderSelection, OrderTable, TermKind,
};
pub use paper::{
    coefficients_from_polynomials, polynomials_from_coefficients, PaperConfig, PaperDiagnostics,
    PaperMethod, PredictionMode, SimplexSettings, Solver, TimeOrigin, SHIFT_AMPLIFICATION_WARNING,
};
pub use residuals::{ResidualAnalysis, Z_99};
pub use rls::{RlsConfig, RlsEstimator};
pub use stream::{Prediction, StreamOptions, StreamStats, Streamer};
pub use sweep::{sweep, SweepConfig, SweepResult, SweepRow, PAPER_WINDOW};
