//! What a zoo member is: every parameter drawn for it, a short label, the
//! plant it runs on and the checks of its linear closed loop.

use std::fmt;

use serde::Serialize;

use super::disturbance::{Disturbance, Disturbed};
use crate::drive::{RigEffects, RigParams};
use crate::signal::{Chirp, Contour, PointToPoint, Ramp, Scurve, Square, Step};

/// Class of a virtual-rig axis (ranges in the module doc of [`crate::zoo`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum AxisClass {
    /// Heavy conventional axis: 50–500 kg, Kv 10–40 1/s.
    Heavy,
    /// Conventional CNC axis: 10–150 kg, Kv 17–170 1/s.
    Conventional,
    /// Stiff light axis (the paper's rig is one): 0.5–30 kg, Kv 100–1000 1/s.
    Stiff,
}

/// The plant a member runs on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PlantKind {
    /// The nonlinear virtual rig (ball screw under the P / PI / PI cascade).
    Rig(AxisClass),
    /// First-order servo: ideal velocity loop, `X/X_s = (kvff·s + Kv)/(s + Kv)`.
    FirstOrder,
    /// Second-order servo: velocity loop a first-order lag of bandwidth ω_v,
    /// `X/X_s = ω_v·(kvff·s + Kv)/(s² + ω_v·s + ω_v·Kv)`.
    SecondOrder,
}

impl PlantKind {
    /// Short name (`rig-heavy`, `first-order`, …).
    pub fn name(self) -> &'static str {
        match self {
            PlantKind::Rig(AxisClass::Heavy) => "rig-heavy",
            PlantKind::Rig(AxisClass::Conventional) => "rig-conventional",
            PlantKind::Rig(AxisClass::Stiff) => "rig-stiff",
            PlantKind::FirstOrder => "first-order",
            PlantKind::SecondOrder => "second-order",
        }
    }
}

impl fmt::Display for PlantKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The command of a member with its generator's parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum CommandSpec {
    /// Constant-speed move ([`Ramp`]).
    Ramp(Ramp),
    /// Step of finite rise ([`Step`]).
    Step(Step),
    /// One jerk-limited move ([`Scurve`]).
    Scurve(Scurve),
    /// Sine sweep ([`Chirp`]).
    Sweep(Chirp),
    /// Square wave ([`Square`]).
    Square(Square),
    /// Random point-to-point moves with dwells ([`PointToPoint`], targets from `seed`).
    PointToPoint {
        /// The program's parameters.
        program: PointToPoint,
        /// Seed of the targets and dwells.
        seed: u64,
    },
    /// One axis of a circle ([`Contour`]).
    Contour(Contour),
}

impl CommandSpec {
    /// Short name (`ramp`, `step`, `scurve`, `sweep`, `square`, `p2p`, `contour`).
    pub fn name(&self) -> &'static str {
        match self {
            CommandSpec::Ramp(_) => "ramp",
            CommandSpec::Step(_) => "step",
            CommandSpec::Scurve(_) => "scurve",
            CommandSpec::Sweep(_) => "sweep",
            CommandSpec::Square(_) => "square",
            CommandSpec::PointToPoint { .. } => "p2p",
            CommandSpec::Contour(_) => "contour",
        }
    }
}

/// Physical parameters and effects of a rig member.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RigSetup {
    /// Rig parameters (feed-forward gains in `control`).
    pub params: RigParams,
    /// Effects (friction, backlash, limits, encoder, noise, dead time in loop samples).
    pub effects: RigEffects,
    /// RK4 step bound \[s\], from the fastest closed-loop pole.
    pub max_step: f64,
}

/// Parameters of a simple servo member.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ServoSetup {
    /// Position-loop gain Kv \[1/s\].
    pub kv: f64,
    /// Velocity-loop bandwidth ω_v \[rad/s\] (second order only).
    pub velocity_bandwidth: Option<f64>,
    /// Velocity feed-forward gain \[-\].
    pub kvff: f64,
}

/// An isolated wild sample added to the measured position.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Glitch {
    /// Row of the recording.
    pub index: usize,
    /// Value added to the measured position there \[m\].
    pub offset: f64,
}

/// Checks of the member's linear closed loop (the rig without friction,
/// backlash, limits and quantisation; a servo as it is).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Stability {
    /// Largest real part of the continuous closed-loop poles \[1/s\] (< 0: stable),
    /// over the nut positions the command visits.
    pub max_real_part: f64,
    /// Smallest damping ratio of the continuous closed-loop poles.
    pub min_damping: f64,
    /// Spectral radius of the closed loop as simulated (sampled position loop
    /// at the loop rate; the ZOH image of a servo) (< 1: stable).
    pub spectral_radius: f64,
    /// Magnitude of the fastest continuous pole \[rad/s\].
    pub fastest_pole: f64,
}

/// Everything drawn for one member (serialised in the manifest).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MemberSpec {
    /// Index in the zoo.
    pub index: usize,
    /// Short human label.
    pub label: String,
    /// Plant.
    pub plant: PlantKind,
    /// Recording rate \[Hz\].
    pub rate_hz: f64,
    /// Position-loop (simulation) rate \[Hz\]; the recording keeps every
    /// `loop_rate_hz / rate_hz`-th sample.
    pub loop_rate_hz: f64,
    /// Rows of the recording (after dropped rows).
    pub samples: usize,
    /// Length \[s\].
    pub duration_s: f64,
    /// Position-loop gain Kv \[1/s\].
    pub kv: f64,
    /// Velocity-loop bandwidth \[Hz\] (rig: the tuning target; second-order servo).
    pub velocity_bandwidth_hz: Option<f64>,
    /// Velocity feed-forward gain \[-\].
    pub kvff: f64,
    /// Acceleration feed-forward gain \[-\] (rig only).
    pub kaff: f64,
    /// Moving mass \[kg\] (rig only).
    pub mass_kg: Option<f64>,
    /// Axial (two-mass) mode \[Hz\] at the rest position (rig only).
    pub axial_mode_hz: Option<f64>,
    /// The axial mode was placed low (20–300 Hz) by a soft transmission.
    pub resonance_placed: bool,
    /// Coulomb friction as a share of the drive's peak force (0 … 0.1).
    pub friction_share: f64,
    /// Backlash (total play) \[m\]; 0 = none.
    pub backlash_m: f64,
    /// Dead time between command and position \[recorded samples\].
    pub dead_time_samples: usize,
    /// Encoder resolution \[m\].
    pub resolution_m: f64,
    /// Standard deviation of the measurement noise \[m\].
    pub noise_std_m: f64,
    /// Largest |command| \[m\].
    pub amplitude_m: f64,
    /// The command.
    pub command: CommandSpec,
    /// Wild samples in the measured position.
    pub glitches: Vec<Glitch>,
    /// Rows of the uniform recording that were dropped (the time column jumps there).
    pub dropped_rows: Vec<usize>,
    /// For a member with dropped rows: the member it was made from.
    pub gap_source: Option<usize>,
    /// For a disturbed member: its disturbance and the member it copies.
    pub disturbed: Option<Disturbed>,
    /// Seed of the measurement noise.
    pub noise_seed: u64,
    /// Checks of the linear closed loop.
    pub stability: Stability,
    /// Rig parameters and effects (rig members).
    pub rig: Option<RigSetup>,
    /// Servo parameters (servo members).
    pub servo: Option<ServoSetup>,
}

impl MemberSpec {
    /// True when rows were dropped (the reader refuses the recording).
    pub fn has_gaps(&self) -> bool {
        !self.dropped_rows.is_empty()
    }

    /// The feed-forward as a word: `none`, `vff`, `vff+aff`.
    pub fn feed_forward(&self) -> &'static str {
        match (self.kvff > 0.0, self.kaff > 0.0) {
            (false, false) => "none",
            (true, false) => "vff",
            (false, true) => "aff",
            (true, true) => "vff+aff",
        }
    }

    /// Build the label from the fields.
    pub(crate) fn make_label(&self) -> String {
        let mut s = format!(
            "{} Kv {} {} {} {} @ {}",
            self.plant,
            short(self.kv),
            self.feed_forward(),
            self.command.name(),
            length(self.amplitude_m),
            rate(self.rate_hz)
        );
        if let Some(m) = self.mass_kg {
            s += &format!(", {} kg", short(m));
        }
        if self.resonance_placed {
            if let Some(f) = self.axial_mode_hz {
                s += &format!(", mode {} Hz", short(f));
            }
        }
        if self.backlash_m > 0.0 {
            s += &format!(", backlash {}", length(self.backlash_m));
        }
        if self.dead_time_samples > 0 {
            s += &format!(", dead time {}", self.dead_time_samples);
        }
        s += &format!(", q {}", length(self.resolution_m));
        if !self.glitches.is_empty() {
            s += &format!(", {} glitch(es)", self.glitches.len());
        }
        if let Some(src) = self.gap_source {
            s += &format!(", {} dropped row(s) of #{src}", self.dropped_rows.len());
        }
        if let Some(d) = &self.disturbed {
            let pct = |v: f64| format!("{:.0} %", 100.0 * v);
            s += &match d.disturbance {
                Disturbance::Pulses { pulses, share } => format!(
                    ", force pulses {} × {} ms of #{}",
                    pct(share),
                    short(1e3 * pulses.width),
                    d.source
                ),
                Disturbance::Friction { share } => {
                    format!(", friction {} of #{}", pct(share), d.source)
                }
                Disturbance::Encoder { counts } => {
                    format!(", encoder {:.0} counts of #{}", counts, d.source)
                }
            };
        }
        s
    }
}

/// Three significant digits, no exponent for everyday magnitudes.
fn short(v: f64) -> String {
    if v >= 100.0 {
        format!("{v:.0}")
    } else if v >= 10.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    }
}

/// A length with a readable unit.
fn length(m: f64) -> String {
    let a = m.abs();
    if a >= 0.1 {
        format!("{} m", short(m))
    } else if a >= 1e-4 {
        format!("{} mm", short(m * 1e3))
    } else if a >= 1e-7 {
        format!("{} µm", short(m * 1e6))
    } else {
        format!("{} nm", short(m * 1e9))
    }
}

/// A rate with a readable unit.
fn rate(hz: f64) -> String {
    if hz >= 1000.0 {
        format!("{} kHz", short(hz / 1000.0))
    } else {
        format!("{} Hz", short(hz))
    }
}
