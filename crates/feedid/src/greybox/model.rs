//! The physical model a grey-box fit simulates: the linear 7-state cascade
//! (exact discretisation) or the nonlinear virtual rig, with the position
//! loop closed at the sample instants or continuously.
//!
//! # Sampled position loop (the default)
//!
//! A digital position controller reads the encoder and the command at each
//! sample `t_k` and holds its velocity command `v_c[k] = Kv·(x_s[k] − x_a[k])`
//! until `t_k+1`; velocity and current loops are continuous (the virtual rig's
//! default, [`crate::drive::PositionLoop::Sampled`]). With the plant
//! `ẋ = A₀·x + B₁·v_c` (the cascade of [`closed_loop_state_space`] with the
//! position loop opened: `A₀` its state matrix at `Kv = 0`, `B₁` its input
//! vector at `Kv = 1`) and its exact zero-order-hold image `(A_d, B_d)`, the
//! sampled loop is exactly the discrete system
//!
//! ```text
//! x[k+1] = (A_d − Kv·B_d·C)·x[k] + Kv·B_d·x_s[k],    x_a[k] = C·x[k]
//! ```
//!
//! in the physical state coordinates `[z_v, z_i, i, θ, ω, x_a, v_a]`.
//!
//! # Continuous position loop
//!
//! The 7-state closed loop driven by the zero-order-held command, discretised
//! exactly ([`crate::drive::simulate_nominal`]'s model).
//!
//! # Nonlinear
//!
//! The [`VirtualRig`] with its friction, position-dependent stiffness and
//! current/voltage limits as given, and quantisation and noise switched off
//! (they are properties of the measurement, and quantisation would make the
//! simulated response a staircase function of the parameters).
//!
//! Every model starts at rest at the first command value `u₀`: the simulated
//! position is `u₀ + (response to u − u₀)` (unit DC gain). Besides the table
//! position, the armature current (state `i`) can be simulated as a second
//! output.

use std::str::FromStr;

use nalgebra::DVector;
use serde::{Deserialize, Serialize};

use crate::drive::{closed_loop_state_space, PositionLoop, RigEffects, RigParams, VirtualRig};
use crate::error::{Error, Result};
use crate::lti::DiscreteStateSpace;

/// How the P position loop is modelled.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LoopModel {
    /// Position controller at the sample rate, output held (default; the virtual rig's default).
    #[default]
    Sampled,
    /// Continuous position loop, command held between samples.
    Continuous,
}

impl LoopModel {
    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            LoopModel::Sampled => "sampled",
            LoopModel::Continuous => "continuous",
        }
    }
}

impl FromStr for LoopModel {
    type Err = Error;

    fn from_str(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "sampled" => Ok(LoopModel::Sampled),
            "continuous" => Ok(LoopModel::Continuous),
            _ => Err(Error::InvalidChoice {
                what: "position loop",
                value: s.to_string(),
                expected: "sampled, continuous",
            }),
        }
    }
}

/// Which dynamics a grey-box fit simulates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Dynamics {
    /// The linear 7-state cascade (default).
    #[default]
    Linear,
    /// The nonlinear virtual rig (friction, variable stiffness, limits), without quantisation and noise.
    Nonlinear,
}

/// A physical model: parameters, nonlinear effects, dynamics and position-loop model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhysicalModel {
    /// Rig parameters.
    pub params: RigParams,
    /// Nonlinear effects (used by [`Dynamics::Nonlinear`] only).
    pub effects: RigEffects,
    /// Linear or nonlinear.
    pub dynamics: Dynamics,
    /// Sampled or continuous position loop.
    pub position_loop: LoopModel,
}

impl PhysicalModel {
    /// The linear model of `params` with the given position loop.
    pub fn linear(params: RigParams, position_loop: LoopModel) -> Self {
        Self {
            params,
            effects: RigEffects::default(),
            dynamics: Dynamics::Linear,
            position_loop,
        }
    }

    /// The linear model sampled every `dt` \[s\] (physical state coordinates).
    pub fn discrete(&self, dt: f64) -> Result<DiscreteStateSpace> {
        linear_discrete(&self.params, self.position_loop, dt)
    }

    /// Simulate the table position \[m\] for `command` \[m\] sampled every `dt` \[s\].
    pub fn simulate(&self, command: &[f64], dt: f64) -> Result<Vec<f64>> {
        let mut out = vec![0.0; command.len()];
        self.simulate_into(command, dt, &mut out)?;
        Ok(out)
    }

    /// As [`PhysicalModel::simulate`], into `out` (same length as `command`).
    pub fn simulate_into(&self, command: &[f64], dt: f64, out: &mut [f64]) -> Result<()> {
        self.simulate_channels(command, dt, out, None)
    }

    /// Simulate the table position \[m\] into `position` and, if given, the
    /// armature current \[A\] into `current` (both the length of `command`).
    pub fn simulate_channels(
        &self,
        command: &[f64],
        dt: f64,
        position: &mut [f64],
        mut current: Option<&mut [f64]>,
    ) -> Result<()> {
        for len in std::iter::once(position.len()).chain(current.as_deref().map(<[f64]>::len)) {
            if len != command.len() {
                return Err(Error::LengthMismatch {
                    what: "simulation output",
                    expected: command.len(),
                    actual: len,
                });
            }
        }
        let Some(&u0) = command.first() else {
            return Ok(());
        };
        match self.dynamics {
            Dynamics::Linear => {
                let sys = self.discrete(dt)?;
                let n = sys.order();
                let (mut x, mut scratch) = (vec![0.0; n], vec![0.0; n]);
                for (k, &u) in command.iter().enumerate() {
                    position[k] = u0 + sys.output(&x, 0.0);
                    if let Some(c) = current.as_deref_mut() {
                        c[k] = x.get(CURRENT_STATE).copied().unwrap_or(0.0);
                    }
                    sys.advance(&mut x, u - u0, &mut scratch)?;
                }
            }
            Dynamics::Nonlinear => {
                let fx = RigEffects {
                    quantisation: false,
                    noise: false,
                    position_loop: match self.position_loop {
                        LoopModel::Sampled => PositionLoop::Sampled,
                        LoopModel::Continuous => PositionLoop::Continuous,
                    },
                    ..self.effects
                };
                let shifted: Vec<f64> = command.iter().map(|u| u - u0).collect();
                let rig = VirtualRig::new(self.params).with_effects(fx);
                let sim = rig.simulate(&shifted, 1.0 / dt)?;
                for (y, x) in position.iter_mut().zip(&sim.true_position) {
                    *y = u0 + x;
                }
                if let Some(c) = current.as_deref_mut() {
                    c.copy_from_slice(&sim.motor_current);
                }
            }
        }
        let channels = std::iter::once(("grey-box simulated position", &*position)).chain(
            current
                .as_deref()
                .map(|c| ("grey-box simulated current", c)),
        );
        for (name, v) in channels {
            if let Some(i) = v.iter().position(|v| !v.is_finite()) {
                return Err(Error::NonFinite {
                    channel: name.to_string(),
                    index: i,
                    value: v[i],
                });
            }
        }
        Ok(())
    }
}

/// Index of the armature current in the physical state `[z_v, z_i, i, θ, ω, x_a, v_a]`.
const CURRENT_STATE: usize = 2;

/// The linear cascade sampled every `dt` \[s\] with a sampled or continuous
/// position loop, in the physical state coordinates (see the module doc).
///
/// ```
/// use feedid::drive::RigParams;
/// use feedid::greybox::{linear_discrete, LoopModel};
/// let sys = linear_discrete(&RigParams::default(), LoopModel::Sampled, 2e-4).unwrap();
/// assert_eq!(sys.order(), 7);
/// assert!((sys.dc_gain().unwrap() - 1.0).abs() < 1e-9);
/// ```
pub fn linear_discrete(
    params: &RigParams,
    position_loop: LoopModel,
    dt: f64,
) -> Result<DiscreteStateSpace> {
    match position_loop {
        LoopModel::Continuous => closed_loop_state_space(params)?.discretize_zoh(dt),
        LoopModel::Sampled => {
            let kv = params.control.kv;
            let mut open = *params;
            open.control.kv = 0.0;
            let plant = closed_loop_state_space(&open)?;
            open.control.kv = 1.0;
            let b1 = closed_loop_state_space(&open)?.b;
            let plant = crate::lti::StateSpace::new(plant.a, b1, plant.c, 0.0)?;
            let d = plant.discretize_zoh(dt)?;
            let bd: DVector<f64> = d.b.clone();
            let a = &d.a - (&bd * &d.c) * kv;
            DiscreteStateSpace::from_parts(a, bd * kv, d.c, 0.0, dt)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::simulate_nominal;
    use crate::signal::Scenario;

    fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn continuous_loop_equals_simulate_nominal() {
        let p = RigParams::default();
        let u = Scenario::Scurve.command(5000.0, 0.2, 0).unwrap();
        let a = PhysicalModel::linear(p, LoopModel::Continuous)
            .simulate(&u, 2e-4)
            .unwrap();
        let b = simulate_nominal(&p, &u, 2e-4).unwrap();
        assert!(max_abs_diff(&a, &b) < 1e-15, "{}", max_abs_diff(&a, &b));
    }

    #[test]
    fn sampled_loop_equals_the_linear_virtual_rig_with_a_sampled_loop() {
        // independent reference: RK4 integration of the state equations with
        // the P controller evaluated at the samples (drive::VirtualRig)
        let p = RigParams::default();
        for sc in [Scenario::Ramp, Scenario::Prbs] {
            let u = sc.command(5000.0, 0.15, 3).unwrap();
            let fx = RigEffects {
                position_loop: PositionLoop::Sampled,
                ..RigEffects::linear()
            };
            let rig = VirtualRig::new(p)
                .with_effects(fx)
                .simulate(&u, 5000.0)
                .unwrap();
            let y = PhysicalModel::linear(p, LoopModel::Sampled)
                .simulate(&u, 2e-4)
                .unwrap();
            let d = max_abs_diff(&y, &rig.true_position);
            assert!(d < 1e-9, "{sc}: {d}");
            let mut yy = vec![0.0; u.len()];
            let mut i = vec![0.0; u.len()];
            PhysicalModel::linear(p, LoopModel::Sampled)
                .simulate_channels(&u, 2e-4, &mut yy, Some(&mut i))
                .unwrap();
            assert_eq!(yy, y);
            let di = max_abs_diff(&i, &rig.motor_current);
            assert!(di < 1e-5, "{sc}: current {di}");
        }
    }

    #[test]
    fn sampled_ramp_following_error_is_v_over_kv() {
        let p = RigParams::default();
        let u = Scenario::Ramp.command(5000.0, 0.3, 0).unwrap();
        let y = PhysicalModel::linear(p, LoopModel::Sampled)
            .simulate(&u, 2e-4)
            .unwrap();
        let k = 1200;
        assert!(
            (u[k] - y[k] - 0.05 / 700.0).abs() < 1e-10,
            "{}",
            u[k] - y[k]
        );
    }

    #[test]
    fn nonlinear_dynamics_without_effects_equals_the_linear_model() {
        let p = RigParams::default();
        let u = Scenario::Chirp.command(5000.0, 0.2, 0).unwrap();
        let m = PhysicalModel {
            params: p,
            effects: RigEffects {
                friction: false,
                variable_stiffness: false,
                limits: false,
                ..RigEffects::default()
            },
            dynamics: Dynamics::Nonlinear,
            position_loop: LoopModel::Sampled,
        };
        let a = m.simulate(&u, 2e-4).unwrap();
        let b = PhysicalModel::linear(p, LoopModel::Sampled)
            .simulate(&u, 2e-4)
            .unwrap();
        assert!(max_abs_diff(&a, &b) < 1e-11, "{}", max_abs_diff(&a, &b));
    }

    #[test]
    fn loop_model_names_parse() {
        assert_eq!("Sampled".parse::<LoopModel>().unwrap(), LoopModel::Sampled);
        assert_eq!(
            "continuous".parse::<LoopModel>().unwrap(),
            LoopModel::Continuous
        );
        assert!("held"
            .parse::<LoopModel>()
            .unwrap_err()
            .to_string()
            .contains("held"));
    }
}
