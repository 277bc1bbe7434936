//! A linear model identified from data: a discrete-time transfer function
//! with its sample time, or a continuous-time one. It is what `--model-out`
//! writes (JSON) and what compensation and free-run simulation read.
//!
//! Discrete form (powers of q⁻¹, ARX convention):
//!
//! ```text
//! A(q)·y[k] = B(q)·u[k],   A = 1 + a1·q⁻¹ + … + a_na·q⁻ⁿᵃ,   B = b0 + b1·q⁻¹ + … + b_m·q⁻ᵐ
//! ```
//!
//! (the input delay is carried by leading zeros of `b`). Continuous form:
//! `N(s)/D(s)` in descending powers of s, simulated by exact zero-order hold.
//!
//! Free-run simulation starts at rest at the first command value: the output
//! is `u[0] + G·(u − u[0])` scaled by nothing else, which is exact for a model
//! with unit DC gain (a position servo) and the natural choice otherwise.
//!
//! ```
//! use feedid::ident::LinearModel;
//! // y[k] = 0.5·y[k−1] + 0.5·u[k−1]: unit DC gain, one-sample delay
//! let m = LinearModel::discrete(vec![0.0, 0.5], vec![1.0, -0.5], 1e-3).unwrap();
//! let y = m.simulate(&[0.0, 1.0, 1.0, 1.0]).unwrap();
//! assert_eq!(y, vec![0.0, 0.0, 0.5, 0.75]);
//! ```

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::lti::{DiscreteStateSpace, TransferFunction};

/// An identified linear model (see the module doc).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum LinearModel {
    /// Discrete-time `B(q)/A(q)` with sample time `dt`.
    Discrete {
        /// `[b0, b1, …]`, coefficients of q⁰, q⁻¹, ….
        b: Vec<f64>,
        /// `[1, a1, …]`, coefficients of q⁰, q⁻¹, … (a\[0\] = 1).
        a: Vec<f64>,
        /// Sample time \[s\].
        dt: f64,
    },
    /// Continuous-time `N(s)/D(s)`.
    Continuous {
        /// Numerator, descending powers of s.
        num: Vec<f64>,
        /// Denominator, descending powers of s.
        den: Vec<f64>,
    },
}

impl LinearModel {
    /// A discrete model; `a[0]` must be non-zero (the polynomials are normalised so a\[0\] = 1).
    pub fn discrete(b: Vec<f64>, a: Vec<f64>, dt: f64) -> Result<Self> {
        if !dt.is_finite() || dt <= 0.0 {
            return Err(Error::InvalidParameter {
                name: "dt",
                value: dt,
                reason: "must be finite and > 0",
            });
        }
        let a0 = a.first().copied().unwrap_or(0.0);
        if a0 == 0.0 || b.is_empty() {
            return Err(Error::InvalidModel {
                reason: "discrete model needs a[0] != 0 and at least one b coefficient",
            });
        }
        if a.iter().chain(&b).any(|v| !v.is_finite()) {
            return Err(Error::InvalidModel {
                reason: "non-finite model coefficient",
            });
        }
        Ok(LinearModel::Discrete {
            b: b.iter().map(|v| v / a0).collect(),
            a: a.iter().map(|v| v / a0).collect(),
            dt,
        })
    }

    /// A continuous model (checked by [`TransferFunction::new`]).
    pub fn continuous(tf: &TransferFunction) -> Self {
        LinearModel::Continuous {
            num: tf.num().to_vec(),
            den: tf.den().to_vec(),
        }
    }

    /// Whether every pole is stable (|z| < 1, or Re s < 0).
    pub fn is_stable(&self) -> Result<bool> {
        match self {
            LinearModel::Discrete { .. } => self.discrete_state_space(None)?.is_stable(),
            LinearModel::Continuous { num, den } => {
                TransferFunction::new(num.clone(), den.clone())?.is_stable()
            }
        }
    }

    /// Steady-state gain.
    pub fn dc_gain(&self) -> Result<f64> {
        match self {
            LinearModel::Discrete { b, a, .. } => {
                let sa: f64 = a.iter().sum();
                let sb: f64 = b.iter().sum();
                Ok(sb / sa)
            }
            LinearModel::Continuous { num, den } => {
                Ok(TransferFunction::new(num.clone(), den.clone())?.dc_gain())
            }
        }
    }

    /// Sample time of a discrete model.
    pub fn dt(&self) -> Option<f64> {
        match self {
            LinearModel::Discrete { dt, .. } => Some(*dt),
            LinearModel::Continuous { .. } => None,
        }
    }

    /// A state-space realisation sampled at `dt` (required for continuous
    /// models; a discrete model uses its own sample time and rejects a different one).
    pub fn discrete_state_space(&self, dt: Option<f64>) -> Result<DiscreteStateSpace> {
        match self {
            LinearModel::Discrete { b, a, dt: own } => {
                if let Some(d) = dt {
                    if (d - own).abs() > 1e-9 * own {
                        return Err(Error::InvalidParameter {
                            name: "dt",
                            value: d,
                            reason: "differs from the discrete model's sample time",
                        });
                    }
                }
                discrete_realisation(b, a, *own)
            }
            LinearModel::Continuous { num, den } => {
                let dt = dt.ok_or(Error::InvalidModel {
                    reason: "a continuous model needs a sample time to be simulated",
                })?;
                TransferFunction::new(num.clone(), den.clone())?
                    .to_state_space()?
                    .discretize_zoh(dt)
            }
        }
    }

    /// Free-run simulation on a command sampled at the model's `dt`
    /// (discrete) — see [`LinearModel::simulate_at`] for continuous models.
    pub fn simulate(&self, command: &[f64]) -> Result<Vec<f64>> {
        self.simulate_at(command, self.dt().unwrap_or(0.0))
    }

    /// Free-run simulation on a command sampled every `dt` \[s\], starting at
    /// rest at `command[0]`.
    pub fn simulate_at(&self, command: &[f64], dt: f64) -> Result<Vec<f64>> {
        let Some(&u0) = command.first() else {
            return Ok(Vec::new());
        };
        let sys = self.discrete_state_space(Some(dt).filter(|d| *d > 0.0))?;
        let du: Vec<f64> = command.iter().map(|&u| u - u0).collect();
        let mut y = sys.simulate(&du, None)?;
        let g = self.dc_gain()?;
        let offset = if g.is_finite() { g * u0 } else { u0 };
        for v in &mut y {
            *v += offset;
        }
        Ok(y)
    }

    /// Serialise as pretty JSON (for `--model-out`).
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_default()
    }

    /// Parse from JSON and check the coefficients.
    pub fn from_json(text: &str) -> Result<Self> {
        let m: LinearModel = serde_json::from_str(text).map_err(|e| Error::ParamsFile {
            path: None,
            message: format!("model JSON: {e}"),
        })?;
        match &m {
            LinearModel::Discrete { b, a, dt } => LinearModel::discrete(b.clone(), a.clone(), *dt),
            LinearModel::Continuous { num, den } => {
                TransferFunction::new(num.clone(), den.clone())?;
                Ok(m)
            }
        }
    }
}

/// Observer-canonical realisation of `B(q)/A(q)` (a\[0\] = 1) — direct form,
/// adequate for the low orders identified from data.
fn discrete_realisation(b: &[f64], a: &[f64], dt: f64) -> Result<DiscreteStateSpace> {
    use nalgebra::{DMatrix, DVector, RowDVector};
    let n = (a.len().max(b.len())).saturating_sub(1);
    let coef = |v: &[f64], k: usize| v.get(k).copied().unwrap_or(0.0);
    let d = coef(b, 0);
    if n == 0 {
        return DiscreteStateSpace::from_parts(
            DMatrix::zeros(0, 0),
            DVector::zeros(0),
            RowDVector::zeros(0),
            d,
            dt,
        );
    }
    // x1[k+1] = −a1·x1[k] + x2[k] + (b1 − a1·b0)·u[k], …; y = x1 + b0·u
    let mut am = DMatrix::zeros(n, n);
    let mut bm = DVector::zeros(n);
    for i in 0..n {
        am[(i, 0)] = -coef(a, i + 1);
        if i + 1 < n {
            am[(i, i + 1)] = 1.0;
        }
        bm[i] = coef(b, i + 1) - coef(a, i + 1) * d;
    }
    let mut c = RowDVector::zeros(n);
    c[0] = 1.0;
    DiscreteStateSpace::from_parts(am, bm, c, d, dt)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn discrete_simulation_matches_difference_equation() {
        // y[k] = 1.5 y[k-1] − 0.7 y[k-2] + 0.1 u[k-1] + 0.1 u[k-2]
        let a = vec![1.0, -1.5, 0.7];
        let b = vec![0.0, 0.1, 0.1];
        let m = LinearModel::discrete(b.clone(), a.clone(), 1e-3).unwrap();
        let u: Vec<f64> = (0..50).map(|k| ((k as f64) * 0.3).sin()).collect();
        let y = m.simulate(&u).unwrap();
        let mut r = vec![0.0; 50];
        let du: Vec<f64> = u.iter().map(|v| v - u[0]).collect();
        for k in 0..50 {
            let mut v = 0.0;
            for i in 1..3 {
                if k >= i {
                    v += -a[i] * r[k - i] + b[i] * du[k - i];
                }
            }
            r[k] = v;
        }
        let g = 0.2 / 0.2;
        for k in 0..50 {
            assert!((y[k] - (r[k] + g * u[0])).abs() < 1e-12, "{k}");
        }
    }

    #[test]
    fn continuous_first_order_step_matches_closed_form() {
        let tf = TransferFunction::new(vec![1.0], vec![0.01, 1.0]).unwrap();
        let m = LinearModel::continuous(&tf);
        let y = m.simulate_at(&[0.0, 1.0, 1.0, 1.0, 1.0], 1e-3).unwrap();
        for (k, v) in y.iter().enumerate().skip(1) {
            let want = 1.0 - (-((k - 1) as f64) * 0.1).exp();
            assert!((v - want).abs() < 1e-12, "{k}: {v} vs {want}");
        }
    }

    #[test]
    fn json_round_trip() {
        let m = LinearModel::discrete(vec![0.0, 0.5], vec![1.0, -0.5], 2e-4).unwrap();
        let back = LinearModel::from_json(&m.to_json()).unwrap();
        assert_eq!(m, back);
    }

    #[test]
    fn unstable_discrete_model_is_detected() {
        let m = LinearModel::discrete(vec![0.0, 1.0], vec![1.0, -1.1], 1e-3).unwrap();
        assert!(!m.is_stable().unwrap());
    }
}
