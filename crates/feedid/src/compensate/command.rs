//! Model-based compensation of the command: the command that makes the
//! predicted table position follow a desired trajectory.
//!
//! With the model `G` sampled at the trajectory's interval (an identified
//! discrete model at its own sample time, a continuous one or the physical
//! rig model by exact zero-order hold), the desired positions `y_d` relative
//! to their first value, and a zero-phase smoothing `F`
//! ([`super::gaussian_smooth`], σ ≥ 0):
//!
//! ```text
//! u = y_d[0]/G(1) + G⁻¹·F·(y_d − y_d[0])       (stable inverse, super::StableInverse)
//! ŷ = y_d[0] + G·(u − y_d[0]/G(1))             (the prediction)
//! ```
//!
//! A position servo closed on the table encoder has unit DC gain; an
//! identified model is off by a little (say 1e-3), which on a 30 mm move
//! would leave 30 µm of final error, so by default the model's gain is
//! rescaled to make `G(1) = 1` ([`CompensateConfig::unit_dc_gain`]).
//!
//! `F` trades exactness for a command a drive can follow: the inverse of a
//! feed drive has a large high-frequency gain, so a trajectory with a
//! velocity step (the paper's ramp) or jerk steps asks for very large,
//! short command accelerations at its corners. The command's velocity and
//! acceleration (finite differences) are checked against
//! [`CompensateConfig::max_velocity`] and [`CompensateConfig::max_acceleration`];
//! with [`Smoothing::Auto`] the smallest σ of the sequence 0, ½, 1, 1½, 2,
//! 3, 4, 6, … samples (up to [`CompensateConfig::max_smoothing`]) that meets
//! both limits is used, otherwise the given σ must meet them; failing that,
//! [`Error::LimitExceeded`] names the quantity, value, time and limit. The
//! smoothing kernel reaches ±4σ, and the trajectory must stay at rest at its
//! first sample (the axis rests there before the command starts) and reach
//! its final value: σ is capped at a quarter of the rest before the motion
//! and after it (10 ms of rest at 5 kHz allow σ ≤ 2.45 ms). With
//! an exact model, no smoothing and no zero on the unit circle the
//! prediction equals the desired trajectory up to rounding.
//!
//! ```
//! use feedid::compensate::{compensate_model, CompensateConfig, Smoothing};
//! use feedid::ident::LinearModel;
//! // first-order lag with one sample of delay
//! let m = LinearModel::discrete(vec![0.0, 0.2], vec![1.0, -0.8], 1e-3).unwrap();
//! let desired: Vec<f64> = (0..200).map(|k| 1e-3 * (k as f64 / 100.0).min(1.0)).collect();
//! let cfg = CompensateConfig {
//!     smoothing: Smoothing::Fixed(0.0),
//!     max_acceleration: f64::INFINITY,
//!     ..CompensateConfig::default()
//! };
//! let c = compensate_model(&m, &desired, 1e-3, &cfg).unwrap();
//! assert!(c.predicted_error.max_abs < 1e-15);
//! ```

use serde::Serialize;

use super::inverse::{StableInverse, ZeroInfo};
use super::smoothing::gaussian_smooth;
use crate::drive::RigParams;
use crate::error::{Error, Result};
use crate::greybox::{linear_discrete, LoopModel};
use crate::ident::LinearModel;
use crate::lti::DiscreteStateSpace;
use crate::stats::ErrorStats;

/// Smoothing of the desired trajectory before inversion.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Smoothing {
    /// The smallest σ that keeps the command within its limits (default).
    Auto,
    /// A fixed σ \[s\] (0: none).
    Fixed(f64),
}

/// Settings of the compensation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CompensateConfig {
    /// Smoothing of the desired trajectory; default [`Smoothing::Auto`].
    pub smoothing: Smoothing,
    /// Command velocity limit \[m/s\]; default 1.0 (∞ disables).
    pub max_velocity: f64,
    /// Command acceleration limit \[m/s²\]; default 30 (∞ disables).
    pub max_acceleration: f64,
    /// Largest σ tried by [`Smoothing::Auto`] \[s\]; default 0.02.
    pub max_smoothing: f64,
    /// Zeros closer than this to the unit circle get the zero-phase
    /// approximation instead of an exact inverse; default 1e-4.
    pub unit_circle_margin: f64,
    /// Rescale the model to unit DC gain (a position loop); default true.
    pub unit_dc_gain: bool,
}

impl Default for CompensateConfig {
    fn default() -> Self {
        Self {
            smoothing: Smoothing::Auto,
            max_velocity: 1.0,
            max_acceleration: 30.0,
            max_smoothing: 0.02,
            unit_circle_margin: 1e-4,
            unit_dc_gain: true,
        }
    }
}

impl CompensateConfig {
    /// Check the settings.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("max velocity", self.max_velocity),
            ("max acceleration", self.max_acceleration),
        ] {
            if v.is_nan() || v <= 0.0 {
                return Err(Error::InvalidParameter {
                    name,
                    value: v,
                    reason: "must be > 0 (inf disables the limit)",
                });
            }
        }
        if !(self.max_smoothing.is_finite() && self.max_smoothing >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "max smoothing",
                value: self.max_smoothing,
                reason: "must be finite and >= 0 (s)",
            });
        }
        if let Smoothing::Fixed(s) = self.smoothing {
            if !(s.is_finite() && s >= 0.0) {
                return Err(Error::InvalidParameter {
                    name: "smoothing",
                    value: s,
                    reason: "must be finite and >= 0 (s)",
                });
            }
        }
        Ok(())
    }
}

/// A compensated command and what the model predicts for it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Compensation {
    /// The command \[m\], one per desired sample.
    #[serde(skip)]
    pub command: Vec<f64>,
    /// The model's position for that command \[m\].
    #[serde(skip)]
    pub predicted: Vec<f64>,
    /// Predicted minus desired: rms, max (and fit) \[m\].
    pub predicted_error: ErrorStats,
    /// σ of the smoothing used \[s\].
    pub smoothing_s: f64,
    /// Peak command velocity \[m/s\].
    pub peak_velocity: f64,
    /// Peak command acceleration \[m/s²\].
    pub peak_acceleration: f64,
    /// DC gain of the model before any rescaling.
    pub model_dc_gain: f64,
    /// Delay of the sampled model \[samples\].
    pub delay_samples: usize,
    /// Zeros of the sampled model and how each was inverted.
    pub zeros: Vec<ZeroInfo>,
    /// True when every zero was inverted exactly.
    pub exact_inverse: bool,
    /// Command offset at the first sample from its rest value \[m\]
    /// (pre-actuation that would have been needed before the start).
    pub pre_actuation_m: f64,
}

/// Peak |velocity| and |acceleration| of `u` and their sample indices.
fn peaks(u: &[f64], dt: f64) -> ((f64, usize), (f64, usize)) {
    let mut v = (0.0_f64, 0usize);
    let mut a = (0.0_f64, 0usize);
    for k in 1..u.len() {
        let vk = ((u[k] - u[k - 1]) / dt).abs();
        if vk > v.0 {
            v = (vk, k);
        }
        if k + 1 < u.len() {
            let ak = ((u[k + 1] - 2.0 * u[k] + u[k - 1]) / (dt * dt)).abs();
            if ak > a.0 {
                a = (ak, k);
            }
        }
    }
    (v, a)
}

/// Compensate with a sampled model `sys` whose sample time equals the
/// trajectory's (`sys.dt`); `desired` \[m\] one value per sample.
pub fn compensate(
    sys: &DiscreteStateSpace,
    desired: &[f64],
    cfg: &CompensateConfig,
) -> Result<Compensation> {
    let inverse = StableInverse::from_state_space(sys, cfg.unit_circle_margin)?;
    compensate_with(sys, inverse, desired, cfg)
}

/// Compensate with an identified model (discrete: its sample time must equal
/// `dt`; continuous: sampled at `dt` by zero-order hold).
pub fn compensate_model(
    model: &LinearModel,
    desired: &[f64],
    dt: f64,
    cfg: &CompensateConfig,
) -> Result<Compensation> {
    let sys = model.discrete_state_space(Some(dt))?;
    let inverse = match model {
        LinearModel::Discrete { b, a, .. } => {
            StableInverse::from_polynomials(b, a, cfg.unit_circle_margin)?
        }
        LinearModel::Continuous { .. } => {
            StableInverse::from_state_space(&sys, cfg.unit_circle_margin)?
        }
    };
    compensate_with(&sys, inverse, desired, cfg)
}

/// Compensate with the physical model of `params` (linear cascade, sampled
/// or continuous position loop) sampled at `dt`.
pub fn compensate_params(
    params: &RigParams,
    position_loop: LoopModel,
    desired: &[f64],
    dt: f64,
    cfg: &CompensateConfig,
) -> Result<Compensation> {
    params.validate()?;
    let sys = linear_discrete(params, position_loop, dt)?;
    compensate(&sys, desired, cfg)
}

fn compensate_with(
    sys: &DiscreteStateSpace,
    mut inverse: StableInverse,
    desired: &[f64],
    cfg: &CompensateConfig,
) -> Result<Compensation> {
    cfg.validate()?;
    let n = desired.len();
    if n < 2 {
        return Err(Error::TooFewSamples {
            what: "a desired trajectory",
            needed: 2,
            actual: n,
        });
    }
    if let Some(i) = desired.iter().position(|v| !v.is_finite()) {
        return Err(Error::NonFinite {
            channel: "desired".to_string(),
            index: i,
            value: desired[i],
        });
    }
    let dt = sys.dt;
    let model_dc_gain = inverse.dc_gain();
    if !(model_dc_gain.is_finite() && model_dc_gain.abs() > 1e-12) {
        return Err(Error::InvalidModel {
            reason: "the model's DC gain is zero or infinite; a position model must have a finite non-zero DC gain",
        });
    }
    let out_scale = if cfg.unit_dc_gain {
        inverse.scale_gain(1.0 / model_dc_gain);
        1.0 / model_dc_gain
    } else {
        1.0
    };
    let g = model_dc_gain * out_scale;
    let y0 = desired[0];
    let e: Vec<f64> = desired.iter().map(|v| v - y0).collect();
    // the smoothing must leave the rest at both ends untouched (kernel ±4σ)
    let scale = e.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let moving = |v: &f64| (v - e[n - 1]).abs() > 1e-12 * scale;
    let first_move = e.iter().position(|v| v.abs() > 1e-12 * scale).unwrap_or(n);
    let last_move = e.iter().rposition(moving).unwrap_or(0);
    let rest = first_move.min(n - 1 - last_move.min(n - 1));
    let sigma_cap = (rest as f64 - 1.0).max(0.0) / 4.0;
    let candidates: Vec<f64> = match cfg.smoothing {
        Smoothing::Fixed(s) => {
            if s / dt > sigma_cap && s > 0.0 {
                return Err(Error::InvalidParameter {
                    name: "smoothing",
                    value: s,
                    reason: "needs at least 4·σ of rest before the motion starts and after it ends",
                });
            }
            vec![s / dt]
        }
        Smoothing::Auto => {
            let max = (cfg.max_smoothing / dt).min(sigma_cap);
            let mut c = vec![0.0, 0.5, 1.0, 1.5];
            let mut s = 2.0;
            while s <= max {
                c.push(s);
                c.push(1.5 * s);
                s *= 2.0;
            }
            c.retain(|&x| x <= max.max(0.0));
            if c.is_empty() {
                c.push(0.0);
            }
            c
        }
    };
    let mut smoothed = vec![0.0; n];
    let mut dev = vec![0.0; n];
    let mut work = Vec::new();
    let mut last_violation = None;
    let mut chosen = None;
    for &sigma in &candidates {
        gaussian_smooth(&e, sigma, &mut smoothed);
        inverse.apply_into(&smoothed, &mut dev, &mut work)?;
        let ((v, kv), (a, ka)) = peaks(&dev, dt);
        if v > cfg.max_velocity {
            last_violation = Some(Error::LimitExceeded {
                quantity: "velocity",
                value: v,
                limit: cfg.max_velocity,
                unit: "m/s",
                time: kv as f64 * dt,
                hint: LIMIT_HINT,
            });
        } else if a > cfg.max_acceleration {
            last_violation = Some(Error::LimitExceeded {
                quantity: "acceleration",
                value: a,
                limit: cfg.max_acceleration,
                unit: "m/s²",
                time: ka as f64 * dt,
                hint: LIMIT_HINT,
            });
        } else {
            chosen = Some((sigma, v, a));
            break;
        }
    }
    let Some((sigma, peak_velocity, peak_acceleration)) = chosen else {
        return Err(last_violation.unwrap_or(Error::InvalidModel {
            reason: "no smoothing candidate",
        }));
    };
    // the prediction: the (rescaled) model driven by the deviation command
    let mut x = vec![0.0; sys.order()];
    let mut yd = vec![0.0; n];
    let mut scratch = vec![0.0; sys.order()];
    sys.simulate_into(&dev, &mut x, &mut yd, &mut scratch)?;
    let predicted: Vec<f64> = yd.iter().map(|v| y0 + out_scale * v).collect();
    let u_rest = y0 / g;
    let command: Vec<f64> = dev.iter().map(|v| u_rest + v).collect();
    let predicted_error =
        ErrorStats::from_pairs(desired.iter().copied().zip(predicted.iter().copied()));
    Ok(Compensation {
        pre_actuation_m: dev[0].abs(),
        command,
        predicted,
        predicted_error,
        smoothing_s: sigma * dt,
        peak_velocity,
        peak_acceleration,
        model_dc_gain,
        delay_samples: inverse.delay(),
        zeros: inverse.zeros().to_vec(),
        exact_inverse: inverse.is_exact(),
    })
}

const LIMIT_HINT: &str = "allow more smoothing (--smooth, --max-smoothing; the trajectory needs 4·σ of rest at both ends) or raise the limit";

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{closed_loop_coefficients, simulate_nominal, D1Variant};
    use crate::signal::{Ramp, Scenario};

    const DT: f64 = 2e-4;

    fn exact() -> CompensateConfig {
        CompensateConfig {
            smoothing: Smoothing::Fixed(0.0),
            max_velocity: f64::INFINITY,
            max_acceleration: f64::INFINITY,
            ..CompensateConfig::default()
        }
    }

    #[test]
    fn exact_continuous_model_gives_rounding_level_tracking() {
        let p = RigParams::default();
        let tf = closed_loop_coefficients(&p, D1Variant::Corrected)
            .transfer_function()
            .unwrap();
        let model = LinearModel::continuous(&tf);
        let desired = Scenario::Scurve.command(5000.0, 0.4, 0).unwrap();
        let c = compensate_model(&model, &desired, DT, &exact()).unwrap();
        assert!(c.exact_inverse);
        assert!(
            c.predicted_error.max_abs < 1e-12,
            "{}",
            c.predicted_error.max_abs
        );
        // the model as an independent user would simulate it
        let y = model.simulate_at(&c.command, DT).unwrap();
        let err = y
            .iter()
            .zip(&desired)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-12, "{err}");
        // and the physical 7-state model (another realisation of the same G)
        let y = simulate_nominal(&p, &c.command, DT).unwrap();
        let err = y
            .iter()
            .zip(&desired)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-11, "{err}");
        // sampling zeros of relative degree 5 lie outside the unit circle
        assert!(c
            .zeros
            .iter()
            .any(|z| z.handling == super::super::ZeroHandling::AntiCausal));
    }

    #[test]
    fn exact_sampled_loop_model_gives_rounding_level_tracking_of_the_ramp() {
        let p = RigParams::default();
        let desired = Scenario::Ramp.command(5000.0, 0.8, 0).unwrap();
        let c = compensate_params(&p, LoopModel::Sampled, &desired, DT, &exact()).unwrap();
        assert!(
            c.predicted_error.max_abs < 1e-12,
            "{}",
            c.predicted_error.max_abs
        );
        let y = crate::greybox::PhysicalModel::linear(p, LoopModel::Sampled)
            .simulate(&c.command, DT)
            .unwrap();
        let err = y
            .iter()
            .zip(&desired)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-12, "{err}");
        // uncompensated: the 71.4 µm following error
        let y = crate::greybox::PhysicalModel::linear(p, LoopModel::Sampled)
            .simulate(&desired, DT)
            .unwrap();
        assert!((desired[2000] - y[2000] - 71.43e-6).abs() < 0.01e-6);
    }

    #[test]
    fn limits_choose_the_smoothing_and_bound_the_command() {
        let p = RigParams::default();
        let desired = Ramp::default().generate(5000.0, 0.8).unwrap();
        let cfg = CompensateConfig::default();
        let c = compensate_params(&p, LoopModel::Sampled, &desired, DT, &cfg).unwrap();
        assert!(c.smoothing_s > 0.0);
        assert!(c.peak_acceleration <= cfg.max_acceleration);
        assert!(c.peak_velocity <= cfg.max_velocity);
        let ((_, _), (a, _)) = peaks(&c.command, DT);
        assert!(a <= cfg.max_acceleration * (1.0 + 1e-9));
        // the remaining error is the rounding of the two corners
        let corner = 0.05 * c.smoothing_s / (2.0 * std::f64::consts::PI).sqrt();
        assert!(
            c.predicted_error.max_abs < 1.1 * corner,
            "{} vs {corner}",
            c.predicted_error.max_abs
        );
        // a fixed smoothing that is too small is an error naming the limit
        let tight = CompensateConfig {
            smoothing: Smoothing::Fixed(0.0),
            ..cfg
        };
        let e = compensate_params(&p, LoopModel::Sampled, &desired, DT, &tight)
            .unwrap_err()
            .to_string();
        assert!(e.contains("velocity") && e.contains("limit 1 m/s"), "{e}");
    }

    #[test]
    fn unit_dc_gain_rescales_an_identified_model() {
        // a lag with DC gain 1.01 (a slightly wrong identified model)
        let m = LinearModel::discrete(vec![0.0, 0.202], vec![1.0, -0.8], 1e-3).unwrap();
        let desired: Vec<f64> = (0..300)
            .map(|k| 0.03 * (k as f64 / 100.0 - 0.5).clamp(0.0, 1.0))
            .collect();
        let cfg = CompensateConfig {
            max_acceleration: f64::INFINITY,
            ..CompensateConfig::default()
        };
        let c = compensate_model(&m, &desired, 1e-3, &cfg).unwrap();
        assert!((c.model_dc_gain - 1.01).abs() < 1e-12);
        // the command ends at the desired end (unit gain assumed)
        assert!((c.command[299] - 0.03).abs() < 1e-12);
        let keep = CompensateConfig {
            unit_dc_gain: false,
            ..cfg
        };
        let c = compensate_model(&m, &desired, 1e-3, &keep).unwrap();
        assert!((c.command[299] - 0.03 / 1.01).abs() < 1e-12);
    }

    #[test]
    fn sample_time_mismatch_is_an_error() {
        let m = LinearModel::discrete(vec![0.0, 0.2], vec![1.0, -0.8], 1e-3).unwrap();
        let e = compensate_model(&m, &[0.0, 1.0, 1.0], 2e-4, &exact()).unwrap_err();
        assert!(e.to_string().contains("sample time"), "{e}");
    }
}
