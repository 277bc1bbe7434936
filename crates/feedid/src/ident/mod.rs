//! Identification methods and the sliding-window prediction engine.
//!
//! Every method implements [`Estimator`]; the [`engine`] slides a window of
//! `W` samples over a recording, fits, predicts the next `H` samples, and
//! shifts by a hop. The [`stream`] module does the same one sample at a time.
//!
//! Folders follow the data flow: [`engine`] (the estimator trait, the
//! signals view, the sliding engine, the streamer), `model` (the linear model
//! type), `methods` (one module per method), `global` (global models of a
//! whole recording), `select` (model orders, window sweeps), `analysis`
//! (residuals). Inside `ident` a module imports its siblings directly (the
//! `pub use` lists here are for users); the order of the sub-layers is in
//! ARCHITECTURE.md and checked by `tests/layers.rs`.

mod analysis;
pub mod engine;
mod global;
mod method;
mod methods;
mod model;
mod option;
mod select;

pub use analysis::{
    prediction_errors, prediction_residuals, ResidualAnalysis, RESIDUAL_LAGS, RESIDUAL_SAMPLES,
    Z_99,
};
pub use engine::{
    stream, EngineConfig, Estimator, FitStatus, GuardConfig, PredictStatus, Prediction, Regime,
    RegimeCoverage, Samples, Signals, SlidingResult, Span, SpanParseError, StreamOptions,
    StreamStats, Streamer, WindowFit, WindowOutcome, WindowRecord,
};
pub use global::{
    fit_global_model, simulation_error, GlobalModelKind, ModelFile, ModelProvenance,
    GLOBAL_FIT_SAMPLES,
};
pub use method::{Method, MethodInfo, METHOD_NAMES, ORDER_METHODS};
pub use methods::{
    coefficients_from_polynomials, fit_arx, fit_arx_segments, fit_oe, fit_oe_measured,
    polynomials_from_coefficients, ArxConfig, ArxDiagnostics, ArxEstimator, ArxFit, ArxOrders,
    AutoConfig, AutoEstimator, Candidate, NnConfig, NnEstimator, NnTraining, OeConfig, OeEstimator,
    OeFit, OeJacobian, PaperConfig, PaperDiagnostics, PaperMethod, PredictionMode, RlsConfig,
    RlsEstimator, SimplexSettings, SimplexStart, Solver, TimeOrigin, MAX_ARX_ORDER,
    SHIFT_AMPLIFICATION_WARNING,
};
pub(crate) use methods::{fold_scale, has_avx2, rls_update};
pub use model::{LinearModel, NEGLIGIBLE_PAIR};
pub use option::{
    MethodOption, OptionInfo, OptionKind, OptionRange, OptionSpec, OptionUse, OptionValue,
};
pub use select::{
    frols, order_table, select_order, sweep, Criterion, FrolsConfig, FrolsResult, FrolsTerm,
    OrderRow, OrderSearch, OrderSelection, OrderTable, SweepConfig, SweepResult, SweepRow,
    TermKind, PAPER_WINDOW,
};
