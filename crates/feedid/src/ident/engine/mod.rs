//! The estimator trait and what drives it: the sliding-window engine over a
//! whole recording, and the streaming engine fed one sample at a time.

mod calibration;
mod envelope;
mod estimator;
mod guard;
mod hull;
mod regime;
mod signals;
mod sliding;
mod span;
pub mod stream;
#[cfg(test)]
mod test_estimators;

pub use envelope::Envelope;
pub(crate) use estimator::rate_changed;
pub use estimator::{Estimator, FitStatus, PredictStatus, WindowFit, WindowOutcome};
pub use guard::{CommandBasis, Guard, GuardConfig, MIN_HISTORY};
pub use hull::CommandHull;
pub use regime::{Regime, RegimeClassifier, MOVING_SHARE};
pub use signals::{Samples, Signals};
#[cfg(test)]
pub(crate) use sliding::run_as_made;
pub(crate) use sliding::{fit_and_predict, range};
pub use sliding::{
    run, run_with, run_with_progress, EngineConfig, Progress, RegimeCoverage, SlidingResult,
    WindowIter, WindowRecord,
};
pub use span::{Span, SpanParseError};
pub use stream::{Prediction, StreamOptions, StreamStats, Streamer};
