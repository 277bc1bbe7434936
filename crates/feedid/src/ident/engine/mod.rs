//! The estimator trait and what drives it: the sliding-window engine over a
//! whole recording, the streaming engine fed one sample at a time, and
//! batches of recordings on all cores.

pub mod batch;
mod estimator;
mod guard;
mod signals;
mod sliding;
pub mod stream;
#[cfg(test)]
mod test_estimators;

pub(crate) use estimator::rate_changed;
pub use estimator::{Estimator, FitStatus, PredictStatus, WindowFit, WindowOutcome};
pub use guard::{Guard, GuardConfig, MIN_HISTORY};
pub use signals::{Samples, Signals};
pub(crate) use sliding::fit_and_predict;
pub use sliding::{
    run, run_with, run_with_progress, EngineConfig, Progress, SlidingResult, WindowIter,
    WindowRecord,
};
pub use stream::{Prediction, StreamOptions, StreamStats, Streamer};
