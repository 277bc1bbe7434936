//! Identification methods and the sliding-window prediction engine.
//!
//! Every method implements [`Estimator`]; the [`engine`] slides a window of
//! `W` samples over a recording, fits, predicts the next `H` samples, and
//! shifts by a hop. The [`stream`] module does the same one sample at a time.

pub mod batch;
pub mod engine;
mod estimator;
mod method;
mod model;
mod paper;
pub mod stream;

pub use engine::{EngineConfig, SlidingResult, WindowRecord};
pub use estimator::{Estimator, Signals, WindowFit};
pub use method::{build_estimator, MethodOptions, METHOD_NAMES};
pub use model::LinearModel;
pub use paper::{
    coefficients_from_polynomials, polynomials_from_coefficients, PaperConfig, PaperDiagnostics,
    PaperMethod, PredictionMode, SimplexSettings, Solver, TimeOrigin,
};
pub use stream::{Prediction, StreamOptions, StreamStats, Streamer};
