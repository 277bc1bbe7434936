//! Identification methods and the sliding-window prediction engine.
//!
//! Every method implements [`Estimator`]; the [`engine`] slides a window of
//! `W` samples over a recording, fits, predicts the next `H` samples, and
//! shifts by a hop. The [`stream`] module does the same one sample at a time.
//!
//! Folders follow the data flow: [`engine`] (the estimator trait, the
//! signals view, the sliding engine, the streamer, batches), `methods` (one
//! module per method), `select` (model orders, window sweeps), `model`
//! (global models of a whole recording), `analysis` (residuals).

mod analysis;
pub mod engine;
mod method;
mod methods;
mod model;
mod select;

pub use analysis::{
    prediction_errors, prediction_residuals, ResidualAnalysis, RESIDUAL_LAGS, RESIDUAL_SAMPLES,
    Z_99,
};
pub use engine::{
    batch, stream, EngineConfig, Estimator, FitStatus, GuardConfig, PredictStatus, Prediction,
    Regime, RegimeCoverage, Samples, Signals, SlidingResult, Span, SpanParseError, StreamOptions,
    StreamStats, Streamer, WindowFit, WindowOutcome, WindowRecord,
};
pub use method::{
    Method, MethodInfo, MethodOption, OptionInfo, OptionKind, OptionRange, OptionSpec, OptionUse,
    OptionValue, METHOD_NAMES,
};
pub use methods::{
    coefficients_from_polynomials, fit_arx, fit_arx_segments, fit_oe, fit_oe_measured,
    polynomials_from_coefficients, ArxConfig, ArxDiagnostics, ArxEstimator, ArxFit, ArxOrders,
    AutoConfig, AutoEstimator, Candidate, OeConfig, OeEstimator, OeFit, OeJacobian, PaperConfig,
    PaperDiagnostics, PaperMethod, PredictionMode, RlsConfig, RlsEstimator, SimplexSettings,
    SimplexStart, Solver, TimeOrigin, MAX_ARX_ORDER, SHIFT_AMPLIFICATION_WARNING,
};
pub(crate) use methods::{fold_scale, has_avx2, rls_update};
pub use model::{
    fit_global_model, simulation_error, GlobalModelKind, LinearModel, ModelFile, ModelProvenance,
    GLOBAL_FIT_SAMPLES,
};
pub use select::{
    frols, order_table, select_order, sweep, Criterion, FrolsConfig, FrolsResult, FrolsTerm,
    OrderRow, OrderSearch, OrderSelection, OrderTable, SweepConfig, SweepResult, SweepRow,
    TermKind, PAPER_WINDOW,
};
