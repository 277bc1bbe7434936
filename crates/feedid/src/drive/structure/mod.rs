//! A drive structure described in a parameter file: the loops, the drive,
//! the mechanics and the friction of an axis other than the paper's — a
//! P position loop around a P velocity loop driving a force source through a
//! drive gain (the EMPS benchmark axis), a PID position loop commanding force,
//! a PI velocity loop with feed-forward — with its linear closed loop
//! ([`DriveStructure::closed_loop`], `linear.rs`) and a nonlinear simulation
//! ([`DriveStructure::simulate`], `simulate.rs`).
//!
//! ```text
//! u   = C_v(s)·(C_p(s)·(x_s − x) + kvff·ẋ_s − ẋ) + kaff·(M/g)·ẍ_s    (with a velocity loop)
//! u   = C_p(s)·(x_s − x) + kaff·(M/g)·ẍ_s                          (without)
//! F   = g·sat(u),  sat to ±limit
//! M·ẍ = F − Fv·ẋ − F_c(ẋ) − F_0
//! C(s) = kp·(1 + ki/s + kd·s)       (P: ki = kd = 0; PI: kd = 0; PD: ki = 0)
//! F_c(v) = (Fc± + (Fs± − Fc±)·exp(−(v/vs)²))·tanh(v/vε)   (Coulomb + Stribeck, ± by the sign of v)
//! ```
//!
//! `g` is the drive gain (force per unit of controller output: the EMPS
//! amplifier's `gtau`, N/V), `F_0` a constant force (gravity, a cable, the
//! EMPS offset). The mechanics are rigid (one moving mass `M` that includes
//! the motor's inertia seen at the load), or two masses — the motor's `M_m`
//! (its inertia and the screw's seen at the load), on which the force acts,
//! and the load's `M_l`, on which the friction acts — joined by the
//! transmission's stiffness `k` and damping `c`
//! (`M_m·ẍ_m = F − k(x_m − x_l) − c(ẋ_m − ẋ_l)`,
//! `M_l·ẍ_l = k(x_m − x_l) + c(ẋ_m − ẋ_l) − Fv·ẋ_l − F_c(ẋ_l) − F_0`),
//! the position measured on the load or on the motor. The controller is continuous, or
//! sampled at the recording's interval (`[controller] sample_time`) with the
//! velocity estimated from the measured position (`velocity_estimate`:
//! `central`, `(x[k] − x[k−2])/(2·Ts)` as the EMPS controller does, or
//! `backward`), integrals by the rectangle rule, the output held.
//!
//! In the file (TOML; `[mechanics]`, `[drive]` and `[position]` required, every
//! other table optional,
//! unknown keys an error):
//!
//! ```toml
//! source = "where the values come from"
//! [controller]
//! sample_time = 0.001          # s; absent: continuous
//! velocity_estimate = "central"
//! [position]
//! kind = "P"                   # P, PI, PD, PID
//! kp = 160.18                  # 1/s (with a velocity loop), else output per m
//! [velocity]
//! kind = "P"                   # P, PI, or "none" (the position loop drives the force)
//! kp = 243.45                  # output per (m/s), e.g. V/(m/s)
//! [drive]
//! gain = 35.1507               # N per unit of output
//! limit = 10.0                 # ± output (optional)
//! # [current]                  # a modelled current loop (absent: a force source;
//! # kp = 4.4                   #   then gain is N/A and the output the current command)
//! # ki = 3430.0                # 1/s
//! # inductance = 3.5e-4        # H
//! # resistance = 1.2           # Ω
//! # back_emf = 37.7            # V/(m/s) of the motor side
//! [mechanics]
//! mass = 95.1089               # kg (two-mass: the load's, with motor_mass,
//!                              #   stiffness [N/m], damping, measured = "load"/"motor")
//! [friction]
//! viscous = 203.5034           # N·s/m
//! coulomb = 20.3935            # N (coulomb_negative for an asymmetric law)
//! offset = -3.1648             # N
//! [feed_forward]
//! velocity = 0.0               # kvff
//! acceleration = 0.0           # kaff
//! ```
//!
//! A current loop may be modelled (`[current]`: PI on the winding, `L·di/dt
//! = V − R·i − ke·v_m`, `F = g·i`), the velocity loop may feed back the
//! motor's side of a two-mass axis while the position loop closes on the
//! load (`[controller] velocity_feedback = "motor"`), and the motor side
//! may have its own viscous friction (`motor_viscous`): the paper's cascade
//! (P / PI / PI with the motor's electrical dynamics and the screw's
//! stiffness) is then a structure too ([`DriveStructure::paper`],
//! `examples/paper.toml`), whose closed loop is the rig parameter file's
//! ([`crate::drive::RigParams`]) 7th-order one.

mod fit;
mod idim;
mod linear;
mod paper;
mod simulate;
mod tune;

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

pub use fit::{
    check_restarts, StructureEstimate, StructureFit, StructureParam, StructureValidation,
    StructureVerdict, EQUALLY_GOOD, MAX_RESTARTS, PINNED,
};
pub use idim::{inverse_dynamics, IdimConfig, IdimFit};
pub use linear::StructureSummary;
pub use simulate::StructureRun;
pub use tune::{RunFigures, TuneTarget, Tuned};

/// Kind of a loop's controller: `C(s) = kp·(1 + ki/s + kd·s)` with the terms
/// its name has.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum LoopKind {
    /// Proportional.
    #[default]
    P,
    /// Proportional–integral.
    PI,
    /// Proportional–derivative.
    PD,
    /// Proportional–integral–derivative.
    PID,
    /// No loop (the velocity loop only).
    #[serde(rename = "none")]
    None,
}

/// A loop's controller.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoopGains {
    /// Kind; default P.
    #[serde(default)]
    pub kind: LoopKind,
    /// Proportional gain (units of the loop's output per unit of its error).
    #[serde(default)]
    pub kp: f64,
    /// Integral rate \[1/s\] (PI, PID); default 0.
    #[serde(default)]
    pub ki: f64,
    /// Derivative time \[s\] (PD, PID); default 0.
    #[serde(default)]
    pub kd: f64,
}

impl LoopGains {
    /// `ki` and `kd` as the kind uses them (0 where it has no such term).
    pub fn terms(&self) -> (f64, f64, f64) {
        match self.kind {
            LoopKind::P => (self.kp, 0.0, 0.0),
            LoopKind::PI => (self.kp, self.ki, 0.0),
            LoopKind::PD => (self.kp, 0.0, self.kd),
            LoopKind::PID => (self.kp, self.ki, self.kd),
            LoopKind::None => (1.0, 0.0, 0.0),
        }
    }
}

/// How a sampled controller estimates the velocity from the measured position.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum VelocityEstimate {
    /// `(x[k] − x[k−2])/(2·Ts)` (the EMPS controller's, on the mean of two samples).
    #[default]
    Central,
    /// `(x[k] − x[k−1])/Ts`.
    Backward,
}

/// The controller's timing.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct Controller {
    /// Sample interval \[s\] of a sampled controller; `None`: continuous.
    pub sample_time: Option<f64>,
    /// Velocity estimate of a sampled controller; default central.
    #[serde(default)]
    pub velocity_estimate: VelocityEstimate,
    /// Side whose velocity the velocity loop feeds back (two-mass: a motor
    /// encoder under a position loop closed on the table, as the paper's
    /// cascade); `None`: the measured side.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub velocity_feedback: Option<Measured>,
}

/// A current loop between the controller and the motor (absent: the drive
/// is an ideal force source): the controller's output is the current
/// command \[A\], a PI controller `kp·(1 + ki/s)` drives the winding's
/// voltage, `L·di/dt = V − R·i − ke·v_m` (`v_m` the motor side's velocity at
/// the load), and the force is `drive.gain·i` (`drive.gain` then in N/A at
/// the load: the motor constant over the screw's `h/2π`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CurrentLoop {
    /// Proportional gain \[V/A\].
    pub kp: f64,
    /// Integral rate \[1/s\]; default 0 (P).
    #[serde(default)]
    pub ki: f64,
    /// Winding inductance L \[H\].
    pub inductance: f64,
    /// Winding resistance R \[Ω\].
    pub resistance: f64,
    /// Back-EMF per velocity of the motor side at the load \[V/(m/s)\]
    /// (the motor's `Ke` over `h/2π`); default 0.
    #[serde(default)]
    pub back_emf: f64,
}

/// The drive: a force source commanded by the controller's output.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Drive {
    /// Force per unit of controller output \[N/unit\] (EMPS: `gtau`, N/V).
    pub gain: f64,
    /// Saturation of the controller output, ±; `None`: none.
    pub limit: Option<f64>,
}

/// Which side of a two-mass transmission the position is measured on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Measured {
    /// The load (a linear encoder on the table); default.
    #[default]
    Load,
    /// The motor (a rotary encoder mapped to the load side).
    Motor,
}

/// The mechanics: rigid, or two masses joined by a spring (the screw's
/// axial stiffness) when `stiffness` is given.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mechanics {
    /// Moving mass \[kg\]: rigid, everything that moves (the motor's
    /// inertia seen at the load included, unless `motor_mass` is given);
    /// two-mass, the load.
    pub mass: f64,
    /// The motor's and screw's inertia seen at the load \[kg\] (two-mass:
    /// required; rigid: added to `mass`).
    #[serde(default)]
    pub motor_mass: Option<f64>,
    /// Stiffness of the transmission \[N/m\]; present: two-mass mechanics.
    #[serde(default)]
    pub stiffness: Option<f64>,
    /// Damping of the transmission \[N·s/m\]; default 0.
    #[serde(default)]
    pub damping: f64,
    /// Side the position is measured on (two-mass); default load.
    #[serde(default)]
    pub measured: Measured,
    /// Viscous friction on the motor side \[N·s/m at the load\] (the
    /// motor's bearings, `C1/(h/2π)²`); default 0 (rigid: added to the
    /// friction law's).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub motor_viscous: f64,
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

impl Mechanics {
    /// Everything that moves \[kg\] (`mass` plus `motor_mass`).
    pub fn total_mass(&self) -> f64 {
        self.mass + self.motor_mass.unwrap_or(0.0)
    }

    /// True for two-mass mechanics (a stiffness given).
    pub fn two_mass(&self) -> bool {
        self.stiffness.is_some()
    }
}

/// The friction law (module doc); every term defaults to 0.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct FrictionLaw {
    /// Viscous coefficient Fv \[N·s/m\].
    pub viscous: f64,
    /// Coulomb level Fc \[N\] (moving forward, and backward unless `coulomb_negative`).
    pub coulomb: f64,
    /// Coulomb level moving backward \[N\], if it differs.
    pub coulomb_negative: Option<f64>,
    /// Static (breakaway) level Fs ≥ Fc \[N\]; `None`: Fc (no Stribeck dip).
    pub r#static: Option<f64>,
    /// Stribeck velocity vs \[m/s\]; default 1 mm/s when `static` is given.
    pub stribeck_velocity: Option<f64>,
    /// Constant force F_0 \[N\] (gravity, a cable, an offset).
    pub offset: f64,
    /// Smoothing velocity vε of the sign \[m/s\]; default 0.1 mm/s.
    pub smoothing_velocity: Option<f64>,
}

impl FrictionLaw {
    /// The friction force at velocity `v` \[N\] (viscous, Coulomb + Stribeck, offset).
    pub fn force(&self, v: f64) -> f64 {
        let fc = if v < 0.0 {
            self.coulomb_negative.unwrap_or(self.coulomb)
        } else {
            self.coulomb
        };
        let fs = self.r#static.map_or(fc, |s| s.max(fc));
        let vs = self.stribeck_velocity.unwrap_or(1e-3);
        let ve = self.smoothing_velocity.unwrap_or(1e-4);
        let dip = (v / vs) * (v / vs);
        self.viscous * v + (fc + (fs - fc) * (-dip).exp()) * (v / ve).tanh() + self.offset
    }
}

/// Feed-forward gains.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct FeedForward {
    /// Velocity feed-forward kvff \[-\] (needs a velocity loop).
    pub velocity: f64,
    /// Acceleration feed-forward kaff \[-\]: `kaff·M/g·ẍ_s` added to the output.
    pub acceleration: f64,
}

/// A drive structure (module doc).
///
/// ```
/// use feedid::drive::DriveStructure;
/// let s = DriveStructure::from_toml_str(
///     "[position]\nkp = 160.18\n[velocity]\nkp = 243.45\n\
///      [drive]\ngain = 35.1507\n[mechanics]\nmass = 95.1089\n\
///      [friction]\nviscous = 203.5034\n",
///     None,
/// )
/// .unwrap();
/// let summary = s.closed_loop().unwrap();
/// assert!(summary.stable);
/// // the following error of a ramp: v·(1/kp + Fv/(g·kv·kp))
/// let e = summary.following_error_per_velocity.unwrap();
/// let expected = 1.0 / 160.18 + 203.5034 / (35.1507 * 243.45 * 160.18);
/// assert!((e - expected).abs() < 1e-12 * expected);
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DriveStructure {
    /// Where the values come from (a reference, a data sheet).
    #[serde(default)]
    pub source: Option<String>,
    /// The controller's timing; default continuous.
    #[serde(default)]
    pub controller: Controller,
    /// The position loop.
    pub position: LoopGains,
    /// The velocity loop (`kind = "none"`: absent); default absent.
    #[serde(default = "no_loop")]
    pub velocity: LoopGains,
    /// The drive.
    pub drive: Drive,
    /// The current loop, when modelled; default: an ideal force source.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub current: Option<CurrentLoop>,
    /// The mechanics.
    pub mechanics: Mechanics,
    /// The friction law; default none.
    #[serde(default)]
    pub friction: FrictionLaw,
    /// Feed-forward; default none.
    #[serde(default)]
    pub feed_forward: FeedForward,
}

fn no_loop() -> LoopGains {
    LoopGains {
        kind: LoopKind::None,
        kp: 0.0,
        ki: 0.0,
        kd: 0.0,
    }
}

impl DriveStructure {
    /// True when a TOML text describes a drive structure (it has a
    /// `[drive]` or `[mechanics]` table) rather than the paper's rig.
    pub fn describes(text: &str) -> bool {
        toml::from_str::<toml::Table>(text)
            .map(|t| t.contains_key("drive") || t.contains_key("mechanics"))
            .unwrap_or(false)
    }

    /// Parse and validate a structure file's text (`path` names it in errors).
    pub fn from_toml_str(text: &str, path: Option<&Path>) -> Result<Self> {
        let file_error = |message: String| Error::ParamsFile {
            path: path.map(Path::to_path_buf),
            message,
        };
        let s: DriveStructure = toml::from_str(text)
            .map_err(|e| file_error(e.to_string().lines().collect::<Vec<_>>().join(" ")))?;
        s.validate().map_err(|e| match e {
            Error::InvalidParameter {
                name,
                value,
                reason,
            } => file_error(format!(
                "invalid value for `{name}`: {} ({reason})",
                crate::error::short_number(value)
            )),
            e => e,
        })?;
        Ok(s)
    }

    /// Check every value (finite, positive where it must be) and the
    /// combinations the simulation supports.
    pub fn validate(&self) -> Result<()> {
        let bad = |name: &'static str, value: f64, reason: &'static str| {
            Err(Error::InvalidParameter {
                name,
                value,
                reason,
            })
        };
        let p = &self.position;
        if p.kind == LoopKind::None {
            return bad(
                "position.kind",
                f64::NAN,
                "the position loop must be P, PI, PD or PID",
            );
        }
        for (name, v) in [
            ("position.kp", p.kp),
            ("drive.gain", self.drive.gain),
            ("mechanics.mass", self.mechanics.mass),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return bad(name, v, "must be finite and > 0");
            }
        }
        let v = &self.velocity;
        let non_negative = [
            ("position.ki", p.ki),
            ("position.kd", p.kd),
            ("velocity.ki", v.ki),
            ("velocity.kd", v.kd),
            ("friction.viscous", self.friction.viscous),
            ("friction.coulomb", self.friction.coulomb),
            (
                "friction.coulomb_negative",
                self.friction.coulomb_negative.unwrap_or(0.0),
            ),
            ("friction.static", self.friction.r#static.unwrap_or(0.0)),
            ("feed_forward.velocity", self.feed_forward.velocity),
            ("feed_forward.acceleration", self.feed_forward.acceleration),
        ];
        for (name, x) in non_negative {
            if !(x.is_finite() && x >= 0.0) {
                return bad(name, x, "must be finite and >= 0");
            }
        }
        if v.kind != LoopKind::None && !(v.kp.is_finite() && v.kp > 0.0) {
            return bad("velocity.kp", v.kp, "must be finite and > 0");
        }
        if matches!(v.kind, LoopKind::PD | LoopKind::PID) {
            return bad(
                "velocity.kind",
                f64::NAN,
                "a velocity loop is P or PI (a derivative term there acts on the acceleration)",
            );
        }
        if v.kind == LoopKind::None && self.feed_forward.velocity != 0.0 {
            return bad(
                "feed_forward.velocity",
                self.feed_forward.velocity,
                "velocity feed-forward needs a velocity loop",
            );
        }
        let mech = &self.mechanics;
        for (name, x) in [
            ("mechanics.motor_mass", mech.motor_mass),
            ("mechanics.stiffness", mech.stiffness),
        ] {
            if let Some(x) = x {
                if !(x.is_finite() && x > 0.0) {
                    return bad(name, x, "must be finite and > 0");
                }
            }
        }
        if !(mech.damping.is_finite() && mech.damping >= 0.0) {
            return bad("mechanics.damping", mech.damping, "must be finite and >= 0");
        }
        if !(mech.motor_viscous.is_finite() && mech.motor_viscous >= 0.0) {
            return bad(
                "mechanics.motor_viscous",
                mech.motor_viscous,
                "must be finite and >= 0",
            );
        }
        if let Some(c) = &self.current {
            for (name, x) in [("current.kp", c.kp), ("current.inductance", c.inductance)] {
                if !(x.is_finite() && x > 0.0) {
                    return bad(name, x, "must be finite and > 0");
                }
            }
            for (name, x) in [
                ("current.ki", c.ki),
                ("current.resistance", c.resistance),
                ("current.back_emf", c.back_emf),
            ] {
                if !(x.is_finite() && x >= 0.0) {
                    return bad(name, x, "must be finite and >= 0");
                }
            }
        }
        if mech.two_mass() && mech.motor_mass.is_none() {
            return bad(
                "mechanics.motor_mass",
                f64::NAN,
                "two-mass mechanics (a stiffness given) need the motor's mass at the load",
            );
        }
        if !self.friction.offset.is_finite() {
            return bad("friction.offset", self.friction.offset, "must be finite");
        }
        for (name, x) in [
            (
                "friction.stribeck_velocity",
                self.friction.stribeck_velocity,
            ),
            (
                "friction.smoothing_velocity",
                self.friction.smoothing_velocity,
            ),
            ("drive.limit", self.drive.limit),
            ("controller.sample_time", self.controller.sample_time),
        ] {
            if let Some(x) = x {
                if !(x.is_finite() && x > 0.0) {
                    return bad(name, x, "must be finite and > 0");
                }
            }
        }
        Ok(())
    }

    /// The structure as TOML text (the file format read by [`DriveStructure::from_toml_str`]).
    pub fn to_toml_string(&self) -> String {
        toml::to_string_pretty(self).unwrap_or_default()
    }
}
