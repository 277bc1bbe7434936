//! Identification methods and the sliding-window prediction engine.
//!
//! Every method implements [`Estimator`]; the [`engine`] slides a window of
//! `W` samples over a recording, fits, predicts the next `H` samples, and
//! shifts by a hop.

pub mod engine;
mod estimator;

pub use engine::{EngineConfig, SlidingResult, WindowRecord};
pub use estimator::{Estimator, Signals, WindowFit};
