//! Rig parameters of a ball-screw feed drive and the paper's equations (1), (2).
//!
//! Equivalent axial stiffness (paper eq. 1) and total inertia (paper eq. 2):
//!
//! ```text
//! 1/K = 1/K_bs + 1/(2·K_bearing) + 1/K_nut,     K_bs = E·A/l,  A = π·d_root²/4
//! J   = J_bs + J_m + J_bearings,                J_bs = π·ρ·d⁴·L_screw/32
//! ```
//!
//! `l` is the distance from the fixed bearing to the nut, so `K` depends on the
//! nut position (a fixed–free screw). All quantities are SI. The default set is
//! the default rig of docs/METHODS.md §2.5: it gives `K = 3.0e7 N/m` and
//! `J = 1.6e-5 kg·m²` at the default nut position of 0.16 m.
//!
//! Parameter files are TOML with the sections below; every key is optional
//! (missing keys keep their default), unknown keys are an error.
//!
//! ```
//! let p = feedid::drive::RigParams::from_toml_str("[control]\nkv = 800.0\n", None).unwrap();
//! assert_eq!(p.control.kv, 800.0);
//! assert!((p.stiffness_k() - 3.0e7).abs() < 1.0);
//! ```

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// Screw and table geometry.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Geometry {
    /// Screw lead (pitch) \[m\]; default 0.010.
    pub lead: f64,
    /// Screw outer diameter \[m\]; default 0.010 (used for the screw inertia).
    pub screw_diameter: f64,
    /// Screw root diameter \[m\]; default 0.0082 (used for the screw stiffness).
    pub root_diameter: f64,
    /// Screw length \[m\]; default 0.32.
    pub screw_length: f64,
    /// Distance from the fixed bearing to the nut at table position 0 \[m\]; default 0.16.
    pub nut_position: f64,
}

/// Material of the screw.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Material {
    /// Young's modulus \[Pa\]; default 2.1e11.
    pub youngs_modulus: f64,
    /// Density \[kg/m³\]; default 7850.
    pub density: f64,
}

/// Axial stiffnesses of the bearings and the nut.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Stiffness {
    /// Axial stiffness of one thrust bearing \[N/m\]; default 5.6141306e7 (two act in series-parallel, eq. 1).
    pub bearing: f64,
    /// Axial stiffness of the nut \[N/m\]; default 1.0e8.
    pub nut: f64,
}

/// Rotating inertias other than the screw.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Inertia {
    /// Motor rotor inertia \[kg·m²\]; default 1.2e-5.
    pub motor: f64,
    /// Coupling and bearings inertia \[kg·m²\]; default 1.5338e-6.
    pub bearings: f64,
}

/// Table (translating mass and its guide damping).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Table {
    /// Moving mass M \[kg\]; default 3.0.
    pub mass: f64,
}

/// Viscous dampings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Damping {
    /// Rotary damping at the motor C1 \[N·m·s/rad\]; default 5e-5.
    pub c1: f64,
    /// Linear damping at the table C2 \[N·s/m\]; default 100.
    pub c2: f64,
}

/// DC motor constants.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Motor {
    /// Torque constant Kt \[N·m/A\]; default 0.06.
    pub kt: f64,
    /// Back-EMF constant Ke \[V·s/rad\]; default 0.06.
    pub ke: f64,
    /// Armature resistance R \[Ω\]; default 1.2.
    pub resistance: f64,
    /// Armature inductance L \[H\]; default 3.5e-4.
    pub inductance: f64,
}

/// Cascade controller gains: P position loop, series-PI velocity and current loops.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Control {
    /// Position-loop gain Kv \[1/s\]; default 700.
    pub kv: f64,
    /// Velocity-loop proportional gain Kp \[A/(m/s)\] (velocity in table units); default 465.8.
    pub kp: f64,
    /// Velocity-loop reset rate Ki = 1/Tn \[1/s\]; default 471.2.
    pub ki: f64,
    /// Current-loop proportional gain Kpi \[V/A\]; default 4.398.
    pub kpi: f64,
    /// Current-loop reset rate Kii = 1/Tn \[1/s\]; default 3428.6.
    pub kii: f64,
    /// Velocity feed-forward gain kvff \[-\] (normally 0 … 1): the command
    /// velocity `kvff·ẋ_s` is added to the velocity reference,
    /// `v_c = Kv·(x_s − x_a) + kvff·ẋ_s`; the steady ramp following error
    /// becomes `(1 − kvff)·v/Kv`. Default 0 (the paper's cascade).
    pub kvff: f64,
    /// Acceleration (torque) feed-forward gain kaff \[-\] (normally 0 … 1): the
    /// current `kaff·(J + M·r²)·ẍ_s/(r·Kt)` \[A\] — the share kaff of the
    /// current that accelerates the rigid axis (motor, screw and table
    /// inertia) along the command — is added to the current reference.
    /// Default 0 (the paper's cascade).
    pub kaff: f64,
}

/// All parameters of a feed drive and its cascade controller (SI units).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RigParams {
    /// Screw and table geometry.
    pub geometry: Geometry,
    /// Screw material.
    pub material: Material,
    /// Bearing and nut stiffness.
    pub stiffness: Stiffness,
    /// Rotating inertias.
    pub inertia: Inertia,
    /// Moving table.
    pub table: Table,
    /// Viscous dampings.
    pub damping: Damping,
    /// Motor constants.
    pub motor: Motor,
    /// Controller gains.
    pub control: Control,
}

impl Default for Geometry {
    fn default() -> Self {
        Self {
            lead: 0.010,
            screw_diameter: 0.010,
            root_diameter: 0.0082,
            screw_length: 0.32,
            nut_position: 0.16,
        }
    }
}

impl Default for Material {
    fn default() -> Self {
        Self {
            youngs_modulus: 2.1e11,
            density: 7850.0,
        }
    }
}

impl Default for Stiffness {
    fn default() -> Self {
        Self {
            bearing: 5.614_130_605_652_452e7,
            nut: 1.0e8,
        }
    }
}

impl Default for Inertia {
    fn default() -> Self {
        Self {
            motor: 1.2e-5,
            bearings: 1.533_849_766_932_011_5e-6,
        }
    }
}

impl Default for Table {
    fn default() -> Self {
        Self { mass: 3.0 }
    }
}

impl Default for Damping {
    fn default() -> Self {
        Self {
            c1: 5e-5,
            c2: 100.0,
        }
    }
}

impl Default for Motor {
    fn default() -> Self {
        Self {
            kt: 0.06,
            ke: 0.06,
            resistance: 1.2,
            inductance: 3.5e-4,
        }
    }
}

impl Default for Control {
    fn default() -> Self {
        Self {
            kv: 700.0,
            kp: 465.8,
            ki: 471.2,
            kpi: 4.398,
            kii: 3428.6,
            kvff: 0.0,
            kaff: 0.0,
        }
    }
}

/// Screw stiffness of a fixed–free screw `K_bs = E·A/l` with `A = π·d_root²/4` \[N/m\].
pub fn screw_stiffness(youngs_modulus: f64, root_diameter: f64, length: f64) -> f64 {
    youngs_modulus * std::f64::consts::PI * root_diameter * root_diameter / 4.0 / length
}

/// Paper eq. (1): equivalent axial stiffness `1/K = 1/K_bs + 1/(2·K_bearing) + 1/K_nut` \[N/m\].
pub fn equivalent_stiffness(k_screw: f64, k_bearing: f64, k_nut: f64) -> f64 {
    1.0 / (1.0 / k_screw + 1.0 / (2.0 * k_bearing) + 1.0 / k_nut)
}

/// Screw inertia of a solid cylinder `J_bs = π·ρ·d⁴·L/32` \[kg·m²\].
pub fn screw_inertia(density: f64, diameter: f64, length: f64) -> f64 {
    std::f64::consts::PI * density * diameter.powi(4) * length / 32.0
}

/// Paper eq. (2): total inertia `J = J_bs + J_m + J_bearings` \[kg·m²\].
pub fn total_inertia(j_screw: f64, j_motor: f64, j_bearings: f64) -> f64 {
    j_screw + j_motor + j_bearings
}

impl RigParams {
    /// Transmission ratio `r = lead/2π` \[m/rad\] (`K1` in the paper).
    pub fn r(&self) -> f64 {
        self.geometry.lead / (2.0 * std::f64::consts::PI)
    }

    /// Screw stiffness at the default nut position \[N/m\].
    pub fn screw_stiffness(&self) -> f64 {
        self.screw_stiffness_at(self.geometry.nut_position)
    }

    /// Screw stiffness with the nut at distance `l` \[m\] from the fixed bearing \[N/m\].
    pub fn screw_stiffness_at(&self, l: f64) -> f64 {
        screw_stiffness(self.material.youngs_modulus, self.geometry.root_diameter, l)
    }

    /// Equivalent axial stiffness K at the default nut position \[N/m\] (eq. 1).
    pub fn stiffness_k(&self) -> f64 {
        self.stiffness_at(self.geometry.nut_position)
    }

    /// Equivalent axial stiffness K with the nut at distance `l` \[m\] (eq. 1) \[N/m\].
    pub fn stiffness_at(&self, l: f64) -> f64 {
        equivalent_stiffness(
            self.screw_stiffness_at(l),
            self.stiffness.bearing,
            self.stiffness.nut,
        )
    }

    /// Screw inertia from geometry and density \[kg·m²\].
    pub fn screw_inertia(&self) -> f64 {
        screw_inertia(
            self.material.density,
            self.geometry.screw_diameter,
            self.geometry.screw_length,
        )
    }

    /// Inertia of the rigid axis reflected to the table, `J/r² + M` \[kg\]:
    /// the mass that acceleration feed-forward accelerates.
    pub fn rigid_mass(&self) -> f64 {
        let r = self.r();
        self.inertia_j() / (r * r) + self.table.mass
    }

    /// Current per command acceleration of the acceleration feed-forward,
    /// `kaff·(J + M·r²)/(r·Kt)` \[A/(m/s²)\] (0 without it).
    pub fn acceleration_feed_forward_gain(&self) -> f64 {
        let r = self.r();
        self.control.kaff * (self.inertia_j() + self.table.mass * r * r) / (r * self.motor.kt)
    }

    /// Total inertia J (eq. 2) \[kg·m²\].
    pub fn inertia_j(&self) -> f64 {
        total_inertia(
            self.screw_inertia(),
            self.inertia.motor,
            self.inertia.bearings,
        )
    }

    /// Check every value; returns the first invalid one by name.
    pub fn validate(&self) -> Result<()> {
        let positive: [(&'static str, f64); 19] = [
            ("geometry.lead", self.geometry.lead),
            ("geometry.screw_diameter", self.geometry.screw_diameter),
            ("geometry.root_diameter", self.geometry.root_diameter),
            ("geometry.screw_length", self.geometry.screw_length),
            ("geometry.nut_position", self.geometry.nut_position),
            ("material.youngs_modulus", self.material.youngs_modulus),
            ("material.density", self.material.density),
            ("stiffness.bearing", self.stiffness.bearing),
            ("stiffness.nut", self.stiffness.nut),
            ("inertia.motor", self.inertia.motor),
            ("table.mass", self.table.mass),
            ("motor.kt", self.motor.kt),
            ("motor.resistance", self.motor.resistance),
            ("motor.inductance", self.motor.inductance),
            ("control.kv", self.control.kv),
            ("control.kp", self.control.kp),
            ("control.ki", self.control.ki),
            ("control.kpi", self.control.kpi),
            ("control.kii", self.control.kii),
        ];
        for (name, value) in positive {
            if !value.is_finite() || value <= 0.0 {
                return Err(Error::InvalidParameter {
                    name,
                    value,
                    reason: "must be finite and > 0",
                });
            }
        }
        let non_negative: [(&'static str, f64); 4] = [
            ("inertia.bearings", self.inertia.bearings),
            ("damping.c1", self.damping.c1),
            ("damping.c2", self.damping.c2),
            ("motor.ke", self.motor.ke),
        ];
        for (name, value) in [
            ("control.kvff", self.control.kvff),
            ("control.kaff", self.control.kaff),
        ] {
            if !value.is_finite() || !(0.0..=MAX_FEED_FORWARD).contains(&value) {
                return Err(Error::InvalidParameter {
                    name,
                    value,
                    reason: "must be between 0 and 2 (1 = full feed-forward)",
                });
            }
        }
        for (name, value) in non_negative {
            if !value.is_finite() || value < 0.0 {
                return Err(Error::InvalidParameter {
                    name,
                    value,
                    reason: "must be finite and >= 0",
                });
            }
        }
        if self.geometry.root_diameter > self.geometry.screw_diameter {
            return Err(Error::InvalidParameter {
                name: "geometry.root_diameter",
                value: self.geometry.root_diameter,
                reason: "must not exceed geometry.screw_diameter",
            });
        }
        if self.geometry.nut_position > self.geometry.screw_length {
            return Err(Error::InvalidParameter {
                name: "geometry.nut_position",
                value: self.geometry.nut_position,
                reason: "must not exceed geometry.screw_length",
            });
        }
        // Values fine one by one can still overflow or underflow together
        // (J grows as the fourth power of the screw diameter).
        let derived: [(&'static str, f64); 4] = [
            ("r = lead/2π", self.r()),
            ("stiffness K", self.stiffness_k()),
            (
                "stiffness K at the screw end",
                self.stiffness_at(self.geometry.screw_length),
            ),
            ("inertia J", self.inertia_j()),
        ];
        for (name, value) in derived {
            if !value.is_finite() || value <= 0.0 {
                return Err(Error::InvalidParameter {
                    name,
                    value,
                    reason: "derived from the values given; must be finite and > 0",
                });
            }
        }
        Ok(())
    }

    /// Parse a TOML parameter set (missing keys keep defaults) and validate it.
    ///
    /// `path` is only used in error messages.
    pub fn from_toml_str(text: &str, path: Option<&Path>) -> Result<Self> {
        let params: RigParams = toml::from_str(text).map_err(|e| Error::ParamsFile {
            path: path.map(Path::to_path_buf),
            message: one_line(&e.to_string()),
        })?;
        params.validate().map_err(|e| match (e, path) {
            (
                Error::InvalidParameter {
                    name,
                    value,
                    reason,
                },
                Some(p),
            ) => Error::ParamsFile {
                path: Some(p.to_path_buf()),
                message: format!(
                    "invalid value for `{name}`: {} ({reason})",
                    crate::error::short_number(value)
                ),
            },
            (e, _) => e,
        })?;
        Ok(params)
    }

    /// Read and validate a TOML parameter file.
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_toml_str(&text, Some(path))
    }

    /// Serialise as TOML (all keys, SI units).
    pub fn to_toml_string(&self) -> String {
        // Serialising plain f64 structs into TOML cannot fail.
        let body = toml::to_string_pretty(self).unwrap_or_default();
        format!("{UNITS_HEADER}{body}")
    }

    /// Write as a TOML file.
    pub fn save(&self, path: &Path) -> Result<()> {
        std::fs::write(path, self.to_toml_string()).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })
    }
}

const UNITS_HEADER: &str = "\
# feedid rig parameters (SI units)
# geometry: lead, screw_diameter, root_diameter, screw_length, nut_position [m]
# material: youngs_modulus [Pa], density [kg/m^3]
# stiffness: bearing, nut [N/m]        inertia: motor, bearings [kg m^2]
# table: mass [kg]                     damping: c1 [N m s/rad], c2 [N s/m]
# motor: kt [N m/A], ke [V s/rad], resistance [Ohm], inductance [H]
# control: kv [1/s], kp [A/(m/s)], ki [1/s], kpi [V/A], kii [1/s] (series PI, reset rates)
#          kvff, kaff [-]: velocity and acceleration feed-forward (0 = off, 1 = full)
";

/// Largest accepted feed-forward gain (`control.kvff`, `control.kaff`): 2.
pub const MAX_FEED_FORWARD: f64 = 2.0;

/// Collapse a multi-line parser message into one line.
fn one_line(s: &str) -> String {
    s.split('\n')
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.chars().all(|c| c == '|' || c == ' ' || c == '^'))
        .collect::<Vec<_>>()
        .join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_that_overflow_together_are_rejected() {
        // found by the params_toml fuzz target: every value finite and > 0,
        // the screw inertia ρ·π·d⁴·L/32 infinite
        let e = RigParams::from_toml_str(
            "[geometry]\nscrew_diameter = 2.2e104\n",
            Some("rig.toml".as_ref()),
        )
        .unwrap_err();
        assert!(
            e.to_string().contains("inertia J") && e.to_string().contains("inf"),
            "{e}"
        );
        // and underflow: a stiffness of 0
        let e = RigParams::from_toml_str(
            "[material]\nyoungs_modulus = 1e-320\n[stiffness]\nbearing = 1e-320\nnut = 1e-320\n",
            None,
        )
        .unwrap_err();
        assert!(e.to_string().contains("stiffness K"), "{e}");
    }

    #[test]
    fn default_rig_has_notes_stiffness_and_inertia() {
        let p = RigParams::default();
        assert!((p.stiffness_k() / 3.0e7 - 1.0).abs() < 1e-9);
        assert!((p.inertia_j() / 1.6e-5 - 1.0).abs() < 1e-9);
        p.validate().unwrap();
    }

    #[test]
    fn stiffness_falls_as_nut_moves_away_from_bearing() {
        let p = RigParams::default();
        assert!(p.stiffness_at(0.05) > p.stiffness_at(0.16));
        assert!(p.stiffness_at(0.16) > p.stiffness_at(0.30));
    }

    #[test]
    fn equivalent_stiffness_is_series_combination() {
        // three springs of 1: 1/(1 + 1/2 + 1) = 0.4
        assert!((equivalent_stiffness(1.0, 1.0, 1.0) - 0.4).abs() < 1e-15);
    }

    #[test]
    fn toml_round_trip_preserves_every_value() {
        let mut p = RigParams::default();
        p.control.kv = 812.5;
        p.table.mass = 4.25;
        let text = p.to_toml_string();
        let q = RigParams::from_toml_str(&text, None).unwrap();
        assert_eq!(p, q);
    }

    #[test]
    fn unknown_key_is_rejected_by_name() {
        let e = RigParams::from_toml_str("[control]\nkvv = 1.0\n", None).unwrap_err();
        assert!(e.to_string().contains("kvv"), "{e}");
    }

    #[test]
    fn negative_mass_is_rejected_by_name() {
        let e = RigParams::from_toml_str("[table]\nmass = -3.0\n", None).unwrap_err();
        assert!(e.to_string().contains("table.mass"), "{e}");
    }

    #[test]
    fn zero_lead_is_rejected() {
        let e = RigParams::from_toml_str("[geometry]\nlead = 0.0\n", None).unwrap_err();
        assert!(e.to_string().contains("geometry.lead"), "{e}");
    }

    #[test]
    fn wrong_type_is_rejected() {
        let e = RigParams::from_toml_str("[table]\nmass = \"heavy\"\n", None).unwrap_err();
        assert!(e.to_string().contains("mass"), "{e}");
    }
}
