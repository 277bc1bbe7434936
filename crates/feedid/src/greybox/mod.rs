//! Grey-box estimation: physical parameters of the feed drive (gains,
//! masses, stiffness, damping, friction levels) from command/position data,
//! the others fixed at their nominal values — the paper's future work.
//!
//! * [`fit_greybox`]: Levenberg–Marquardt on the simulation error of the
//!   physical model ([`PhysicalModel`]: the linear cascade with a sampled or
//!   continuous position loop, or the nonlinear virtual rig with friction),
//!   over log-parameters; standard errors, correlations and an
//!   identifiability verdict per parameter ([`identifiability`]); a set the
//!   data cannot separate is refused by name.
//! * [`fit_coefficients`]: the same parameters from identified closed-loop
//!   coefficients N2 … N0, D7 … D0, where that map is invertible.
//! * [`track_greybox`]: a fit per sliding window, e.g. the stiffness along
//!   the move against the nut position.
//! * [`GreyboxFit::validate_on`]: the fitted model simulated on another
//!   recording of the axis.
//!
//! Parameter names are those a user types: [`PhysicalParameter`]
//! (`Kv, Kp, Ki, Kvff, Kaff, Kpi, Kii, Kt, Ke, R, L, C1, C2, M, J, K, Fc, Tc`).

mod coefficients;
mod fit;
pub mod identifiability;
mod model;
mod names;
pub mod omitted;
mod track;
mod validate;
pub mod whiteness;

pub use coefficients::fit_coefficients;
pub use fit::{
    fit_greybox, fit_greybox_with_progress, GreyboxConfig, GreyboxFit, Measurements,
    ParameterEstimate,
};
pub use identifiability::{Identifiability, IdentifiabilityThresholds, NullDirection, Verdict};
pub use model::{linear_discrete, Dynamics, LoopModel, PhysicalModel};
pub use names::{PhysicalParameter, FEED_FORWARD_START, LINEAR_PARAMETER_NAMES, PARAMETER_NAMES};
pub use omitted::{MissingFeedForward, FEED_FORWARD_LIMIT};
pub use track::{track_greybox, track_greybox_with_progress, TrackConfig, TrackWindow};
