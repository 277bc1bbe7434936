//! Model-based compensation of the command (the paper's future work): the
//! command that makes the predicted table position follow a desired
//! trajectory, from an identified model or the physical rig model, and its
//! check on the nonlinear virtual rig.
//!
//! * [`StableInverse`]: exact stable (non-causal) inversion of a sampled
//!   model as a cascade of first- and second-order sections; zeros outside
//!   the unit circle (the sampling zeros of a feed drive) are inverted
//!   anti-causally, zeros on it by Tomizuka's zero-phase approximation.
//! * [`compensate`], [`compensate_model`], [`compensate_params`]: the
//!   command (plain trajectory plus the correction the axis needs), smoothed
//!   only where the command's velocity and acceleration limits need it,
//!   segments moving at either end, and the model's prediction; where no
//!   smoothing meets the limits, the correction held back locally or the
//!   command slewed at the limits until it has caught up (`slew`), whichever
//!   the model expects to track better.
//! * [`Benefit`], [`ModelQuality`], [`Fallback`]: "never worse" — the plain
//!   command is sent when the model expects little benefit or fits poorly.
//! * [`learn`]: iterative learning control from measured runs of a repeated
//!   program, the model as learning filter, convergence checked run by run.
//! * [`verify_on_rig`]: tracking error on the virtual rig before and after.
//! * [`OnlineCompensator`]: online compensation, each command corrected
//!   from a model identified while the axis runs, before the drive needs
//!   it; [`CommandStream`]: the same fed line by line with a command lead
//!   (`feedid stream --compensate`); [`co_simulate`]: the axis stepped with
//!   the compensator in the loop.

mod answer;
mod benefit;
mod command;
mod cosim;
mod history;
mod inverse;
mod learn;
mod online;
mod online_stream;
mod slew;
mod smoothing;
mod step;
mod verify;

pub use benefit::{Benefit, Fallback, ModelErrorSource, ModelQuality, MAX_BENEFIT};
pub use command::{
    compensate, compensate_model, compensate_params, CompensateConfig, Compensation, Smoothing,
    StartMode, MAX_SMOOTHING_SAMPLES,
};
pub use cosim::{co_simulate, CoSimulation, PassError, SteppedAxis};
pub use history::{
    BestRun, LearnStatus, LearningHistory, LearningRun, HISTORY_FORMAT, HISTORY_VERSION,
};
pub use inverse::{StableInverse, ZeroHandling, ZeroInfo};
pub use learn::{learn, LearnConfig, Learning, NoiseFilter};
pub use online::{
    following_error_of, OnlineCompensator, OnlineConfig, OnlineState, OnlineStats, MAX_PREVIEW,
};
pub use online_stream::{CommandRow, CommandStream};
pub use smoothing::{gaussian_smooth, gaussian_smooth_profile, smooth_step, taper_profile};
pub use step::CommandPeaks;
pub use verify::{verify_on_rig, TrackingError, Verification};
