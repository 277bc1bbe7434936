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
//! With feed-forward (`control.kvff`, `control.kaff`) the set-point
//! generator adds, held over the interval like the P output (as the virtual
//! rig does), the velocity of the coming interval to the velocity reference
//! and the current for the change of velocity to the current reference:
//!
//! ```text
//! v_c[k]  = Kv·(x_s[k] − x_a[k]) + kvff·(x_s[k+1] − x_s[k])/Δt
//! i_ff[k] = c_a·(x_s[k+1] − 2·x_s[k] + x_s[k−1])/Δt²,   c_a = kaff·(J + M·r²)/(r·Kt)
//! x[k+1]  = Φ·x[k] + Γ_v·v_c[k] + Γ_i·i_ff[k]
//! ```
//!
//! (`Φ, Γ_v, Γ_i` the exact ZOH image of `A₀` and the reference inputs of
//! [`crate::drive::reference_inputs`]; `x_s[−1] = x_s[0]`). Collecting terms,
//! `x[k+1] = A_cl·x[k] + B₁·x_s[k+1] + B₀·x_s[k] + B₂·x_s[k−1]` with
//! `A_cl = Φ − Kv·Γ_v·C`, `B₁ = (kvff/Δt)·Γ_v + (c_a/Δt²)·Γ_i`,
//! `B₂ = (c_a/Δt²)·Γ_i`, `B₀ = Kv·Γ_v − (kvff/Δt)·Γ_v − 2·B₂`. The look-ahead
//! goes into the state `η[k] = x[k] − B₁·x_s[k]` and the previous command
//! into an eighth state `q[k] = x_s[k−1]`:
//!
//! ```text
//! η[k+1] = A_cl·η[k] + B₂·q[k] + (A_cl·B₁ + B₀)·x_s[k],   q[k+1] = x_s[k]
//! x_a[k] = C·η[k] + (C·B₁)·x_s[k]
//! ```
//!
//! so the model has 8 states and a direct feed-through `C·B₁` with
//! feed-forward (the position at `t_k` already depends on `x_s[k]` through the
//! velocity held since `t_k−1`), and is the 7-state system above without.
//!
//! # Continuous position loop
//!
//! The 7-state closed loop driven by the zero-order-held command, discretised
//! exactly ([`crate::drive::simulate_nominal`]'s model). With feed-forward its
//! states are the shifted `z` of [`crate::drive::closed_loop_state_space`]
//! (the output is the same): the ZOH image of the transfer function with
//! feed-forward, as the virtual rig's continuous loop.
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

use nalgebra::{DMatrix, DVector, RowDVector};
use serde::{Deserialize, Serialize};

use crate::drive::{
    closed_loop_state_space, reference_inputs, PositionLoop, RigEffects, RigParams, VirtualRig,
};
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
                let (sys, map) = discrete_with_current(&self.params, self.position_loop, dt)?;
                let n = sys.order();
                let (mut x, mut scratch) = (vec![0.0; n], vec![0.0; n]);
                let mut previous = 0.0;
                for (k, &u) in command.iter().enumerate() {
                    let du = u - u0;
                    position[k] = u0 + sys.output(&x, du);
                    if let Some(c) = current.as_deref_mut() {
                        c[k] = x.get(CURRENT_STATE).copied().unwrap_or(0.0)
                            + map.now * du
                            + map.previous * previous;
                    }
                    sys.advance(&mut x, du, &mut scratch)?;
                    previous = du;
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
    Ok(discrete_with_current(params, position_loop, dt)?.0)
}

/// The armature current from the state of [`linear_discrete`]:
/// `i[k] = x[2] + now·x_s[k] + previous·x_s[k−1]` (the states are shifted by
/// command terms with feed-forward; both 0 without).
#[derive(Debug, Clone, Copy, PartialEq)]
struct CurrentMap {
    now: f64,
    previous: f64,
}

/// [`linear_discrete`] and the map from its state to the armature current.
fn discrete_with_current(
    params: &RigParams,
    position_loop: LoopModel,
    dt: f64,
) -> Result<(DiscreteStateSpace, CurrentMap)> {
    let g = &params.control;
    let (kv, kvff) = (g.kv, g.kvff);
    let feed_forward = g.kvff != 0.0 || g.kaff != 0.0;
    let none = CurrentMap {
        now: 0.0,
        previous: 0.0,
    };
    let (bv, bi) = reference_inputs(params);
    let ca = params.acceleration_feed_forward_gain();
    match position_loop {
        LoopModel::Continuous => {
            let ct = closed_loop_state_space(params)?;
            // physical state just before t_k: z + (A·b₂ + b₁)·x_s[k−1]
            let map = if feed_forward {
                let b2 = &bi * ca;
                let jump = &ct.a * &b2 + &bv * kvff;
                CurrentMap {
                    now: 0.0,
                    previous: jump[CURRENT_STATE],
                }
            } else {
                none
            };
            Ok((ct.discretize_zoh(dt)?, map))
        }
        LoopModel::Sampled => {
            let mut open = *params;
            open.control.kv = 0.0;
            open.control.kvff = 0.0;
            open.control.kaff = 0.0;
            let plant = closed_loop_state_space(&open)?;
            let c = plant.c.clone();
            let dv = crate::lti::StateSpace::new(plant.a.clone(), bv, c.clone(), 0.0)?
                .discretize_zoh(dt)?;
            let gv: DVector<f64> = dv.b.clone();
            let a_cl = &dv.a - (&gv * &dv.c) * kv;
            if !feed_forward {
                return Ok((
                    DiscreteStateSpace::from_parts(a_cl, gv * kv, dv.c, 0.0, dt)?,
                    none,
                ));
            }
            let gi = crate::lti::StateSpace::new(plant.a, bi, c.clone(), 0.0)?
                .discretize_zoh(dt)?
                .b;
            let b2 = &gi * (ca / (dt * dt));
            let b1 = &gv * (kvff / dt) + &b2;
            let b0 = &gv * (kv - kvff / dt) - &b2 * 2.0;
            let b_now = &a_cl * &b1 + b0;
            let d = c.dot(&b1.transpose());
            let mut a = DMatrix::<f64>::zeros(8, 8);
            a.view_mut((0, 0), (7, 7)).copy_from(&a_cl);
            a.view_mut((0, 7), (7, 1)).copy_from(&b2);
            let mut b = DVector::<f64>::zeros(8);
            b.rows_mut(0, 7).copy_from(&b_now);
            b[7] = 1.0;
            let mut c8 = RowDVector::<f64>::zeros(8);
            c8.columns_mut(0, 7).copy_from(&c);
            let map = CurrentMap {
                now: b1[CURRENT_STATE],
                previous: 0.0,
            };
            Ok((DiscreteStateSpace::from_parts(a, b, c8, d, dt)?, map))
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

    fn ff(kvff: f64, kaff: f64) -> RigParams {
        let mut p = RigParams::default();
        p.control.kvff = kvff;
        p.control.kaff = kaff;
        p
    }

    const FF_CASES: [(f64, f64); 3] = [(0.9, 0.0), (0.0, 0.8), (1.0, 1.0)];

    #[test]
    fn feed_forward_sampled_loop_equals_the_virtual_rig_with_a_sampled_loop() {
        // the rig's sampled loop with feed-forward is checked against an
        // independent exact discretisation in drive::rig's extension tests
        for (kvff, kaff) in FF_CASES {
            let p = ff(kvff, kaff);
            for sc in [Scenario::Ramp, Scenario::Scurve, Scenario::Prbs] {
                let u = sc.command(5000.0, 0.15, 3).unwrap();
                let fx = RigEffects {
                    position_loop: PositionLoop::Sampled,
                    ..RigEffects::linear()
                };
                let rig = VirtualRig::new(p)
                    .with_effects(fx)
                    .simulate(&u, 5000.0)
                    .unwrap();
                let mut y = vec![0.0; u.len()];
                let mut i = vec![0.0; u.len()];
                PhysicalModel::linear(p, LoopModel::Sampled)
                    .simulate_channels(&u, 2e-4, &mut y, Some(&mut i))
                    .unwrap();
                let d = max_abs_diff(&y, &rig.true_position);
                assert!(d < 1e-9, "{kvff} {kaff} {sc}: {d}");
                let di = max_abs_diff(&i, &rig.motor_current);
                let scale = rig
                    .motor_current
                    .iter()
                    .fold(0.0_f64, |m, v| m.max(v.abs()));
                assert!(
                    di < 1e-6 * scale.max(1.0),
                    "{kvff} {kaff} {sc}: current {di}"
                );
            }
        }
    }

    #[test]
    fn feed_forward_continuous_loop_equals_the_virtual_rig_with_a_continuous_loop() {
        for (kvff, kaff) in FF_CASES {
            let p = ff(kvff, kaff);
            let u = Scenario::Scurve.command(5000.0, 0.15, 0).unwrap();
            let fx = RigEffects {
                position_loop: PositionLoop::Continuous,
                ..RigEffects::linear()
            };
            let rig = VirtualRig::new(p)
                .with_effects(fx)
                .simulate(&u, 5000.0)
                .unwrap();
            let mut y = vec![0.0; u.len()];
            let mut i = vec![0.0; u.len()];
            PhysicalModel::linear(p, LoopModel::Continuous)
                .simulate_channels(&u, 2e-4, &mut y, Some(&mut i))
                .unwrap();
            let d = max_abs_diff(&y, &rig.true_position);
            assert!(d < 1e-9, "{kvff} {kaff}: {d}");
            let di = max_abs_diff(&i, &rig.motor_current);
            let scale = rig
                .motor_current
                .iter()
                .fold(0.0_f64, |m, v| m.max(v.abs()));
            // the rig integrates the current's jumps with RK4: 5e-6 of the peak
            assert!(di < 1e-5 * scale, "{kvff} {kaff}: current {di} of {scale}");
        }
    }

    /// Response of the continuous transfer function with feed-forward
    /// (`closed_loop_coefficients`, a companion realisation independent of the
    /// rig and of `linear_discrete`) to the smooth S-curve, from a fine ZOH
    /// discretisation at 1 µs.
    fn continuous_tf_scurve(p: &RigParams, rate: f64, duration: f64) -> Vec<f64> {
        use crate::drive::{closed_loop_coefficients, D1Variant};
        use crate::signal::Scurve;
        let fine = 1e6;
        let u = Scurve::default().generate(fine, duration).unwrap();
        let ss = closed_loop_coefficients(p, D1Variant::Corrected)
            .transfer_function()
            .unwrap()
            .to_state_space()
            .unwrap();
        // first-order hold: the command interpolated linearly between samples
        let n = ss.order();
        let mut aug = DMatrix::<f64>::zeros(n + 2, n + 2);
        aug.view_mut((0, 0), (n, n)).copy_from(&ss.a);
        aug.view_mut((0, n), (n, 1)).copy_from(&ss.b);
        aug[(n, n + 1)] = 1.0;
        let e = (aug / fine).exp();
        let phi = e.view((0, 0), (n, n)).into_owned();
        let g0 = e.view((0, n), (n, 1)).into_owned();
        let g1 = e.view((0, n + 1), (n, 1)).into_owned();
        let every = (fine / rate).round() as usize;
        let mut x = DVector::<f64>::zeros(n);
        let mut y = Vec::new();
        for k in 0..u.len() {
            if k % every == 0 {
                y.push((&ss.c * &x)[0]);
            }
            let slope = u.get(k + 1).map_or(0.0, |v| (v - u[k]) * fine);
            x = &phi * &x + &g0 * u[k] + &g1 * slope;
        }
        y
    }

    #[test]
    fn feed_forward_sampled_loop_converges_to_the_continuous_transfer_function() {
        use crate::signal::Scurve;
        let duration = 0.12;
        for (kvff, kaff) in FF_CASES {
            let p = ff(kvff, kaff);
            let mut errors = Vec::new();
            for rate in [20_000.0, 40_000.0] {
                let u = Scurve::default().generate(rate, duration).unwrap();
                let reference = continuous_tf_scurve(&p, rate, duration);
                let y = PhysicalModel::linear(p, LoopModel::Sampled)
                    .simulate(&u, 1.0 / rate)
                    .unwrap();
                let n = y.len().min(reference.len());
                errors.push(max_abs_diff(&y[..n], &reference[..n]));
                // the feed-forward's own effect is far larger than the gap
                let plain = PhysicalModel::linear(RigParams::default(), LoopModel::Sampled)
                    .simulate(&u, 1.0 / rate)
                    .unwrap();
                let effect = max_abs_diff(&plain[..n], &reference[..n]);
                let lag = max_abs_diff(&u[..n], &reference[..n]);
                let gap = errors[errors.len() - 1];
                assert!(
                    gap < 0.3 * effect && gap < 0.1 * lag,
                    "{kvff} {kaff} at {rate} Hz: gap {errors:?} vs effect {effect}, lag {lag}"
                );
            }
            // first order in Δt (held references)
            let ratio = errors[0] / errors[1];
            assert!(
                (1.6..2.4).contains(&ratio),
                "{kvff} {kaff}: {errors:?} ratio {ratio}"
            );
        }
    }

    #[test]
    fn feed_forward_sampled_ramp_following_error_is_one_minus_kvff_times_v_over_kv() {
        let u = Scenario::Ramp.command(5000.0, 0.3, 0).unwrap();
        for (kvff, kaff) in FF_CASES {
            let p = ff(kvff, kaff);
            let y = PhysicalModel::linear(p, LoopModel::Sampled)
                .simulate(&u, 2e-4)
                .unwrap();
            let k = 1200;
            let expected = (1.0 - kvff) * 0.05 / 700.0;
            assert!(
                (u[k] - y[k] - expected).abs() < 1e-10,
                "{kvff} {kaff}: {} vs {expected}",
                u[k] - y[k]
            );
        }
    }

    #[test]
    fn discrete_order_is_seven_without_feed_forward_and_eight_with() {
        for (kvff, kaff, order, feed_through) in [
            (0.0, 0.0, 7, false),
            (0.9, 0.0, 8, true),
            (0.0, 0.5, 8, true),
        ] {
            let sys = linear_discrete(&ff(kvff, kaff), LoopModel::Sampled, 2e-4).unwrap();
            assert_eq!(sys.order(), order);
            assert_eq!(sys.d != 0.0, feed_through);
            assert!((sys.dc_gain().unwrap() - 1.0).abs() < 1e-9);
            assert!(sys.is_stable().unwrap());
        }
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
