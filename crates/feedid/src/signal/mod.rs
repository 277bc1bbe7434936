//! Command trajectories: ramp, step, jerk-limited move, chirp, PRBS, multisine,
//! square wave, random point-to-point moves with dwells, contour axis.
//!
//! Every family has a parameter struct with the documented defaults
//! (`Default`), a `fill` method writing the command sampled at `rate_hz`
//! (sample `k` at `t = k/rate_hz`) into a caller buffer, and an allocating
//! `generate`; a free function gives the default command of each family.
//! [`Scenario`] names the defaults for the CLI. All commands are table
//! positions in metres, start at 0 and rest 10 ms before moving; the default
//! rate is 5 kHz as in the paper.
//!
//! | family | formula | file |
//! |---|---|---|
//! | ramp | `x = v·(t − t_r)` up to `D` | `ramp.rs` |
//! | step | linear rise of `h` over `t_rise` | `step.rs` |
//! | S-curve | 7-segment jerk-limited profile | `scurve.rs` |
//! | chirp | `A·w(t)·sin φ(t)`, linear or logarithmic sweep | `chirp.rs` |
//! | PRBS | maximum-length LFSR, held `clock` samples, optional raised-cosine edges | `prbs.rs` |
//! | multisine | Schroeder-phase sum of cosines over a band | `multisine.rs` |
//! | square wave | `0` / `A` alternating every half period, optional linear edges | `square.rs` |
//! | point-to-point | jerk-limited moves between seeded random targets, dwells between | `point_to_point.rs` |
//! | contour | one axis of a circle, `R·sin(s/R)` or `R·(1 − cos(s/R))`, jerk-limited feed | `contour.rs` |

mod chirp;
mod common;
mod contour;
mod multisine;
mod point_to_point;
mod prbs;
mod ramp;
mod scenario;
mod scurve;
mod square;
mod step;

pub use chirp::{chirp, Chirp, Sweep};
pub(crate) use common::{check_command, check_rate};
pub use common::{sample_count, DEFAULT_RATE_HZ, DEFAULT_REST, MAX_SAMPLES};
pub use contour::{contour, Contour, ContourAxis};
pub use multisine::{multisine, Multisine};
pub use point_to_point::{point_to_point, PlannedMove, PointToPoint};
pub use prbs::{prbs, Lfsr, Prbs};
pub use ramp::{ramp, Ramp};
pub use scenario::Scenario;
pub use scurve::{scurve, Kinematics, Scurve, ScurvePlan};
pub use square::{square, Square};
pub use step::{step, Step};
