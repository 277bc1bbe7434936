//! Disturbed members: copies of regular members with what real axes meet
//! and a clean simulation lacks — force pulses and impacts on the table (as
//! from interrupted cutting), strong Coulomb friction at reversals, and a
//! coarse encoder read at a low rate.
//!
//! The standard zoo holds 30, after the members with dropped rows, ten of
//! each kind in turn (`d mod 3`, `d` the place among the disturbed members):
//!
//! | kind | source (a regular member) | what changes |
//! |---|---|---|
//! | force pulses | any rig member | a train of table forces of alternating sign ([`ForcePulses`]), 10 … 50 % of the drive's peak force, 1 … 50 ms long (≥ 2 loop samples: impacts at the short end, cuts at the long end), 3 … 8 of them over the recording, the first after 5 … 30 % of it |
//! | friction | a rig member whose command reverses (sweep, square wave, point-to-point, contour) | Coulomb friction 10 … 25 % of the peak force (the regular members: 0 … 10 %), breakaway 1.1 … 1.6× that; the axis re-planned with it (the motor sized for it) |
//! | coarse encoder | a servo member, then a rig member, in turn | recorded at 100 Hz … 1 kHz (the source's rate quantile on that range, bounded below by the loop's `Kv/3`), encoder of 30 … 1000 counts over the command's amplitude, no noise (the count is the noise) |
//!
//! The `j`-th member of a kind copies the candidate at the share
//! `frac(0.05 + 0.3·kind + j·φ)` of its list (φ = 0.618…, the golden-ratio
//! sequence: spread evenly, and not in step with the design's cycles). Every
//! other parameter, the command's shape and the measurement noise sequence
//! are the source's, so the source shows what the disturbance costs.

use serde::Serialize;

use crate::drive::ForcePulses;

/// What a disturbed member adds to the regular member it copies (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Disturbance {
    /// Force pulses on the table of a rig member.
    Pulses {
        /// The train.
        pulses: ForcePulses,
        /// Its height as a share of the drive's peak force.
        share: f64,
    },
    /// Coulomb friction raised to `share` of the drive's peak force.
    Friction {
        /// Coulomb share of the peak force (0.1 … 0.25).
        share: f64,
    },
    /// A coarse encoder at a low recording rate.
    Encoder {
        /// Encoder counts over the command's amplitude (30 … 1000).
        counts: f64,
    },
}

impl Disturbance {
    /// Short name: `pulses`, `friction`, `encoder`.
    pub fn name(&self) -> &'static str {
        match self {
            Disturbance::Pulses { .. } => "pulses",
            Disturbance::Friction { .. } => "friction",
            Disturbance::Encoder { .. } => "encoder",
        }
    }
}

/// A disturbed member's disturbance and the member it copies.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Disturbed {
    /// The regular member it copies.
    pub source: usize,
    /// What it adds.
    pub disturbance: Disturbance,
}

/// Kind of the `d`-th disturbed member: 0 pulses, 1 friction, 2 encoder.
pub(crate) fn kind_of(d: usize) -> usize {
    d % 3
}

/// Highest recording rate of a coarse-encoder member \[Hz\].
pub(crate) const ENCODER_MAX_RATE: f64 = 1000.0;
/// Range of the Coulomb share of a friction member.
pub(crate) const FRICTION_SHARE: (f64, f64) = (0.1, 0.25);
/// Range of the pulse height as a share of the peak force.
pub(crate) const PULSE_SHARE: (f64, f64) = (0.1, 0.5);
/// Range of the pulse width \[s\].
pub(crate) const PULSE_WIDTH: (f64, f64) = (1e-3, 5e-2);
/// Range of the encoder counts over the amplitude.
pub(crate) const ENCODER_COUNTS: (f64, f64) = (30.0, 1000.0);
