//! The physical parameters a grey-box fit can estimate, by the names a user
//! types (`Kv`, `Kp`, `Ki`, `C2`, `M`, …), and how each maps onto the rig
//! description ([`RigParams`], and [`RigEffects`] for the friction levels).
//!
//! Most names are one field of [`RigParams`]. Two are derived quantities of
//! the paper's eq. (1), (2), estimated by scaling every contribution by the
//! same factor, so the relations stay exact:
//!
//! * `K` (equivalent axial stiffness at `geometry.nut_position`): Young's
//!   modulus, bearing and nut stiffness scaled by `K/K₀`, which scales
//!   `1/K = 1/K_bs + 1/(2·K_bearing) + 1/K_nut` — and `K(l)` at every nut
//!   position — by the same factor;
//! * `J` (total inertia): density, motor and bearing inertia scaled by `J/J₀`.
//!
//! `Kvff` and `Kaff` are the velocity and acceleration feed-forward gains
//! (`control.kvff`, `control.kaff`, 0 … 2, 1 = full feed-forward). Estimated
//! on a log scale like every parameter, they need a non-zero start: from a
//! rig without feed-forward the fit starts at [`FEED_FORWARD_START`].
//!
//! `Fc` and `Tc` are the Coulomb levels of the table and motor friction of the
//! virtual rig (breakaway level scaled with them); they only act in the
//! nonlinear model.
//!
//! ```
//! use feedid::greybox::PhysicalParameter;
//! let set = PhysicalParameter::parse_list("Kv, kp,Ki,C2,M").unwrap();
//! assert_eq!(set.len(), 5);
//! assert_eq!(set[1], PhysicalParameter::Kp);
//! assert!(PhysicalParameter::parse_list("Kv,Kw").unwrap_err().to_string().contains("Kw"));
//! ```

use std::fmt;
use std::str::FromStr;

use serde::Serialize;

use crate::drive::{RigEffects, RigParams};
use crate::error::{Error, Result};

/// A physical parameter of the feed drive that grey-box estimation can free.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum PhysicalParameter {
    /// Position-loop gain Kv \[1/s\] (`control.kv`).
    Kv,
    /// Velocity-loop proportional gain Kp \[A/(m/s)\] (`control.kp`).
    Kp,
    /// Velocity-loop reset rate Ki \[1/s\] (`control.ki`).
    Ki,
    /// Velocity feed-forward gain kvff \[-\] (`control.kvff`; 1 = full).
    Kvff,
    /// Acceleration feed-forward gain kaff \[-\] (`control.kaff`; 1 = full).
    Kaff,
    /// Current-loop proportional gain Kpi \[V/A\] (`control.kpi`).
    Kpi,
    /// Current-loop reset rate Kii \[1/s\] (`control.kii`).
    Kii,
    /// Torque constant Kt \[N·m/A\] (`motor.kt`).
    Kt,
    /// Back-EMF constant Ke \[V·s/rad\] (`motor.ke`).
    Ke,
    /// Armature resistance R \[Ω\] (`motor.resistance`).
    R,
    /// Armature inductance L \[H\] (`motor.inductance`).
    L,
    /// Rotary damping C1 \[N·m·s/rad\] (`damping.c1`).
    C1,
    /// Table damping C2 \[N·s/m\] (`damping.c2`).
    C2,
    /// Table mass M \[kg\] (`table.mass`).
    M,
    /// Total inertia J \[kg·m²\] (eq. 2; every contribution scaled).
    J,
    /// Equivalent axial stiffness K \[N/m\] at the nut position (eq. 1; every compliance scaled).
    K,
    /// Table Coulomb friction Fc \[N\] (virtual rig; breakaway scaled with it).
    Fc,
    /// Motor Coulomb friction Tc \[N·m\] (virtual rig; breakaway scaled with it).
    Tc,
}

/// The accepted names, comma separated (for error messages).
pub const PARAMETER_NAMES: &str =
    "Kv, Kp, Ki, Kvff, Kaff, Kpi, Kii, Kt, Ke, R, L, C1, C2, M, J, K, Fc, Tc";

/// The accepted names of the linear model (without the friction levels).
pub const LINEAR_PARAMETER_NAMES: &str =
    "Kv, Kp, Ki, Kvff, Kaff, Kpi, Kii, Kt, Ke, R, L, C1, C2, M, J, K";

/// Starting value of a feed-forward gain (`Kvff`, `Kaff`) whose value in the
/// starting rig is 0 (a log-scale estimate cannot start at 0): 0.5.
pub const FEED_FORWARD_START: f64 = 0.5;

impl PhysicalParameter {
    /// Every parameter in documentation order.
    pub const ALL: [PhysicalParameter; 18] = [
        PhysicalParameter::Kv,
        PhysicalParameter::Kp,
        PhysicalParameter::Ki,
        PhysicalParameter::Kvff,
        PhysicalParameter::Kaff,
        PhysicalParameter::Kpi,
        PhysicalParameter::Kii,
        PhysicalParameter::Kt,
        PhysicalParameter::Ke,
        PhysicalParameter::R,
        PhysicalParameter::L,
        PhysicalParameter::C1,
        PhysicalParameter::C2,
        PhysicalParameter::M,
        PhysicalParameter::J,
        PhysicalParameter::K,
        PhysicalParameter::Fc,
        PhysicalParameter::Tc,
    ];

    /// The name as a user types it (`"Kv"`).
    pub fn name(self) -> &'static str {
        match self {
            PhysicalParameter::Kv => "Kv",
            PhysicalParameter::Kp => "Kp",
            PhysicalParameter::Ki => "Ki",
            PhysicalParameter::Kvff => "Kvff",
            PhysicalParameter::Kaff => "Kaff",
            PhysicalParameter::Kpi => "Kpi",
            PhysicalParameter::Kii => "Kii",
            PhysicalParameter::Kt => "Kt",
            PhysicalParameter::Ke => "Ke",
            PhysicalParameter::R => "R",
            PhysicalParameter::L => "L",
            PhysicalParameter::C1 => "C1",
            PhysicalParameter::C2 => "C2",
            PhysicalParameter::M => "M",
            PhysicalParameter::J => "J",
            PhysicalParameter::K => "K",
            PhysicalParameter::Fc => "Fc",
            PhysicalParameter::Tc => "Tc",
        }
    }

    /// SI unit of the value.
    pub fn unit(self) -> &'static str {
        match self {
            PhysicalParameter::Kv | PhysicalParameter::Ki | PhysicalParameter::Kii => "1/s",
            PhysicalParameter::Kp => "A/(m/s)",
            PhysicalParameter::Kpi => "V/A",
            PhysicalParameter::Kvff | PhysicalParameter::Kaff => "-",
            PhysicalParameter::Kt => "N·m/A",
            PhysicalParameter::Ke => "V·s/rad",
            PhysicalParameter::R => "Ω",
            PhysicalParameter::L => "H",
            PhysicalParameter::C1 => "N·m·s/rad",
            PhysicalParameter::C2 => "N·s/m",
            PhysicalParameter::M => "kg",
            PhysicalParameter::J => "kg·m²",
            PhysicalParameter::K => "N/m",
            PhysicalParameter::Fc => "N",
            PhysicalParameter::Tc => "N·m",
        }
    }

    /// True for the friction levels, which only the nonlinear model contains.
    pub fn needs_friction(self) -> bool {
        matches!(self, PhysicalParameter::Fc | PhysicalParameter::Tc)
    }

    /// True for the feed-forward gains, whose natural value 0 (no
    /// feed-forward) cannot start a log-scale fit.
    pub fn is_feed_forward(self) -> bool {
        matches!(self, PhysicalParameter::Kvff | PhysicalParameter::Kaff)
    }

    /// Current value in `params` / `effects` (SI).
    pub fn get(self, params: &RigParams, effects: &RigEffects) -> f64 {
        match self {
            PhysicalParameter::Kv => params.control.kv,
            PhysicalParameter::Kp => params.control.kp,
            PhysicalParameter::Ki => params.control.ki,
            PhysicalParameter::Kvff => params.control.kvff,
            PhysicalParameter::Kaff => params.control.kaff,
            PhysicalParameter::Kpi => params.control.kpi,
            PhysicalParameter::Kii => params.control.kii,
            PhysicalParameter::Kt => params.motor.kt,
            PhysicalParameter::Ke => params.motor.ke,
            PhysicalParameter::R => params.motor.resistance,
            PhysicalParameter::L => params.motor.inductance,
            PhysicalParameter::C1 => params.damping.c1,
            PhysicalParameter::C2 => params.damping.c2,
            PhysicalParameter::M => params.table.mass,
            PhysicalParameter::J => params.inertia_j(),
            PhysicalParameter::K => params.stiffness_k(),
            PhysicalParameter::Fc => effects.table_friction.coulomb,
            PhysicalParameter::Tc => effects.motor_friction.coulomb,
        }
    }

    /// Set the value (SI). `K`, `J`, `Fc` and `Tc` scale their contributions
    /// (see the module doc), so their current value must be non-zero.
    pub fn set(self, params: &mut RigParams, effects: &mut RigEffects, value: f64) {
        let scale = |current: f64| {
            if current != 0.0 {
                value / current
            } else {
                1.0
            }
        };
        match self {
            PhysicalParameter::Kv => params.control.kv = value,
            PhysicalParameter::Kp => params.control.kp = value,
            PhysicalParameter::Ki => params.control.ki = value,
            PhysicalParameter::Kvff => params.control.kvff = value,
            PhysicalParameter::Kaff => params.control.kaff = value,
            PhysicalParameter::Kpi => params.control.kpi = value,
            PhysicalParameter::Kii => params.control.kii = value,
            PhysicalParameter::Kt => params.motor.kt = value,
            PhysicalParameter::Ke => params.motor.ke = value,
            PhysicalParameter::R => params.motor.resistance = value,
            PhysicalParameter::L => params.motor.inductance = value,
            PhysicalParameter::C1 => params.damping.c1 = value,
            PhysicalParameter::C2 => params.damping.c2 = value,
            PhysicalParameter::M => params.table.mass = value,
            PhysicalParameter::J => {
                let s = scale(params.inertia_j());
                params.material.density *= s;
                params.inertia.motor *= s;
                params.inertia.bearings *= s;
            }
            PhysicalParameter::K => {
                let s = scale(params.stiffness_k());
                params.material.youngs_modulus *= s;
                params.stiffness.bearing *= s;
                params.stiffness.nut *= s;
            }
            PhysicalParameter::Fc => {
                let s = scale(effects.table_friction.coulomb);
                effects.table_friction.coulomb *= s;
                effects.table_friction.breakaway *= s;
            }
            PhysicalParameter::Tc => {
                let s = scale(effects.motor_friction.coulomb);
                effects.motor_friction.coulomb *= s;
                effects.motor_friction.breakaway *= s;
            }
        }
    }

    /// Parse a comma-separated list (`"Kv,Kp,Ki"`); names are case-insensitive,
    /// blanks are ignored; an unknown, repeated or empty entry is an error.
    pub fn parse_list(text: &str) -> Result<Vec<PhysicalParameter>> {
        let mut out: Vec<PhysicalParameter> = Vec::new();
        for item in text.split(',') {
            let p: PhysicalParameter = item.parse()?;
            if out.contains(&p) {
                return Err(Error::InvalidChoice {
                    what: "parameter (listed twice)",
                    value: p.name().to_string(),
                    expected: PARAMETER_NAMES,
                });
            }
            out.push(p);
        }
        Ok(out)
    }
}

impl FromStr for PhysicalParameter {
    type Err = Error;

    fn from_str(s: &str) -> Result<Self> {
        let t = s.trim();
        PhysicalParameter::ALL
            .into_iter()
            .find(|p| p.name().eq_ignore_ascii_case(t))
            .ok_or_else(|| Error::InvalidChoice {
                what: "parameter",
                value: t.to_string(),
                expected: PARAMETER_NAMES,
            })
    }
}

impl fmt::Display for PhysicalParameter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_name_round_trips_and_is_case_insensitive() {
        for p in PhysicalParameter::ALL {
            assert_eq!(p.name().parse::<PhysicalParameter>().unwrap(), p);
            assert_eq!(
                p.name()
                    .to_ascii_lowercase()
                    .parse::<PhysicalParameter>()
                    .unwrap(),
                p
            );
            assert!(PARAMETER_NAMES.contains(p.name()));
        }
    }

    #[test]
    fn unknown_and_repeated_names_are_errors_naming_them() {
        let e = PhysicalParameter::parse_list("Kv,Kx")
            .unwrap_err()
            .to_string();
        assert!(e.contains("Kx") && e.contains("Kv, Kp"), "{e}");
        let e = PhysicalParameter::parse_list("Kv,kv")
            .unwrap_err()
            .to_string();
        assert!(e.contains("twice") && e.contains("Kv"), "{e}");
        assert!(PhysicalParameter::parse_list("Kv,").is_err());
    }

    #[test]
    fn set_then_get_returns_the_value_for_every_parameter() {
        for p in PhysicalParameter::ALL {
            let mut params = RigParams::default();
            let mut fx = RigEffects::default();
            let v = if p.is_feed_forward() {
                0.73
            } else {
                1.37 * p.get(&params, &fx)
            };
            p.set(&mut params, &mut fx, v);
            let back = p.get(&params, &fx);
            assert!((back / v - 1.0).abs() < 1e-14, "{p}: {back} vs {v}");
        }
    }

    #[test]
    fn scaling_k_scales_the_stiffness_at_every_nut_position() {
        let mut params = RigParams::default();
        let mut fx = RigEffects::default();
        let before = params.stiffness_at(0.28);
        let k2 = 2.0 * params.stiffness_k();
        PhysicalParameter::K.set(&mut params, &mut fx, k2);
        assert!((params.stiffness_at(0.28) / before - 2.0).abs() < 1e-14);
    }
}
