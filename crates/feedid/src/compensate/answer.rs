//! The axis's answer to the last learning step beside the model's
//! prediction of it ([`super::learn`]): with the commands `u_{j−1}`, `u_j`
//! of two runs, the measured change of the error `Δe = e_j − e_{j−1}` and
//! the predicted one `Δê = −G·(u_j − u_{j−1})`.
//!
//! - **Ratio** `ρ = <Δe, Δê>/‖Δê‖²`: how strongly the axis answered
//!   relative to the model (a model with twice the axis's gain: ½).
//! - **Robustness filter** (ILC's Q-filter): the smallest σ of the
//!   compensation's levels at which both, smoothed with a zero-phase
//!   Gaussian `L_σ`, agree in shape, `‖L·Δe − ρ·L·Δê‖ ≤ ½·‖L·Δe‖`.
//! - **Local weight**: the same comparison in a Gaussian window `W` around
//!   each sample, `w = 1 − √(W·(a − ρb)² / W·½(a² + ρ²b²))` with `a = L·Δe`,
//!   `b = L·Δê`, clamped to \[0, 1\]: 1 where the axis moved as predicted,
//!   0 where it did not move as asked.
//!
//! Bristow, Tharayil & Alleyne, "A survey of iterative learning control",
//! IEEE Control Systems Magazine 26(3), 2006 (Q-filter and robustness).

use super::command::levels;
use super::smoothing::gaussian_smooth;

/// A response ratio at or below this is no answer to scale a step by (the
/// step did not act as the model predicts; the damping decides).
pub(super) const MIN_RESPONSE: f64 = 0.1;

/// Largest misfit of the axis's answer to the model's prediction within the
/// band a step learns (robustness filter, module doc): `‖a − ρ·b‖ ≤ ½·‖a‖`,
/// three quarters of the change's energy predicted in shape.
const MAX_MISFIT: f64 = 0.5;

/// The axis's answer to the last step beside the model's prediction of it:
/// with `Δu = u_j − u_{j−1}`, the measured change of the error
/// `Δe = e_j − e_{j−1}` and the predicted one `Δê = −G·Δu`.
pub(super) struct Answer {
    /// `Δe`.
    pub(super) measured: Vec<f64>,
    /// `Δê`.
    pub(super) predicted: Vec<f64>,
}

impl Answer {
    /// The answer to the step between two runs from their errors `e`,
    /// `e_last` and the model's positions `y`, `y_last` for their commands;
    /// `None` when `rms(Δê)` is below 3× the noise (the step was lost in it).
    pub(super) fn new(
        (e, y): (&[f64], &[f64]),
        (e_last, y_last): (&[f64], &[f64]),
        noise: f64,
    ) -> Option<Self> {
        let n = e.len();
        let measured: Vec<f64> = (0..n).map(|k| e[k] - e_last[k]).collect();
        let predicted: Vec<f64> = (0..n).map(|k| -(y[k] - y_last[k])).collect();
        let pp = predicted.iter().map(|v| v * v).sum::<f64>();
        (pp > 0.0 && (pp / n as f64).sqrt() > 3.0 * noise).then_some(Self {
            measured,
            predicted,
        })
    }

    /// How strongly the axis answered relative to the model: the
    /// least-squares factor `<Δe, Δê>/‖Δê‖²`.
    pub(super) fn ratio(&self) -> f64 {
        let (mut dot, mut pp) = (0.0, 0.0);
        for (m, p) in self.measured.iter().zip(&self.predicted) {
            dot += m * p;
            pp += p * p;
        }
        dot / pp
    }

    /// The robustness filter (module doc): the smallest σ \[samples\] of
    /// the compensation's levels up to `max_sigma` at which `Δe` and `Δê`
    /// (both smoothed with σ) agree in shape — `‖L·Δe − ρ·L·Δê‖ ≤
    /// MAX_MISFIT·‖L·Δe‖` with their least-squares ratio `ρ`
    /// (> [`MIN_RESPONSE`]); `None` when none does.
    pub(super) fn robustness_sigma(&self, max_sigma: f64) -> Option<f64> {
        let n = self.measured.len();
        let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
        for sigma in levels(max_sigma) {
            gaussian_smooth(&self.measured, sigma, &mut a);
            gaussian_smooth(&self.predicted, sigma, &mut b);
            let (mut ab, mut bb, mut aa) = (0.0, 0.0, 0.0);
            for k in 0..n {
                ab += a[k] * b[k];
                bb += b[k] * b[k];
                aa += a[k] * a[k];
            }
            if !(bb > 0.0 && aa > 0.0) {
                continue;
            }
            let rho = ab / bb;
            // ‖a − ρb‖² = ‖a‖² − ρ·<a, b> at the least-squares ρ
            let misfit = ((aa - rho * ab).max(0.0) / aa).sqrt();
            if rho > MIN_RESPONSE && misfit <= MAX_MISFIT {
                return Some(sigma);
            }
        }
        None
    }

    /// The local trust in the model (module doc): with `a = L·Δe` and `b =
    /// L·Δê` smoothed at the robustness filter's `sigma` and their
    /// least-squares ratio `ρ`, `w_k = 1 − √(W·(a − ρb)² / W·½(a² +
    /// ρ²b²))_k` clamped to \[0, 1\], `W` a Gaussian window of `window`
    /// samples (0 where the axis did not move as asked, 1 where it moved as
    /// predicted); 1 where neither changed by more than a thousandth of the
    /// largest local energy (nothing to tell).
    pub(super) fn local_weight(&self, sigma: f64, window: f64) -> Vec<f64> {
        let n = self.measured.len();
        let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
        gaussian_smooth(&self.measured, sigma, &mut a);
        gaussian_smooth(&self.predicted, sigma, &mut b);
        let (mut ab, mut bb) = (0.0, 0.0);
        for k in 0..n {
            ab += a[k] * b[k];
            bb += b[k] * b[k];
        }
        let rho = if bb > 0.0 { ab / bb } else { 0.0 };
        let misfit: Vec<f64> = (0..n).map(|k| (a[k] - rho * b[k]).powi(2)).collect();
        let energy: Vec<f64> = (0..n)
            .map(|k| 0.5 * (a[k] * a[k] + (rho * b[k]).powi(2)))
            .collect();
        gaussian_smooth(&misfit, window, &mut a);
        gaussian_smooth(&energy, window, &mut b);
        let top = b.iter().fold(0.0_f64, |m, v| m.max(*v));
        (0..n)
            .map(|k| {
                if b[k] <= 1e-3 * top {
                    1.0
                } else {
                    (1.0 - (a[k] / b[k]).sqrt()).clamp(0.0, 1.0)
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compensate::learn::tests::{axis, program, DT};
    use crate::ident::LinearModel;

    #[test]
    fn the_robustness_filter_passes_only_the_band_the_model_predicts() {
        // a step of the command with slow and fast parts; the model is the
        // axis, or the axis without its three samples of extra delay
        let model = axis();
        let LinearModel::Discrete { b, a, .. } = axis() else {
            unreachable!()
        };
        let mut late = vec![0.0; 3];
        late.extend(b);
        let delayed = LinearModel::discrete(late, a, DT).unwrap();
        let desired = program();
        let n = desired.len();
        let u_last = desired.clone();
        let u: Vec<f64> = (0..n)
            .map(|k| {
                let t = k as f64;
                desired[k]
                    + 2e-5 * ((t - 50.0) / 200.0).clamp(0.0, 1.0)
                    + 4e-5 * (0.3 * t).sin() * f64::from(k > 50)
            })
            .collect();
        let sigma = |plant: &LinearModel| {
            let e = |cmd: &[f64]| -> Vec<f64> {
                let y = plant.simulate(cmd).unwrap();
                desired.iter().zip(&y).map(|(d, y)| d - y).collect()
            };
            Answer::new(
                (&e(&u), &model.simulate(&u).unwrap()),
                (&e(&u_last), &model.simulate(&u_last).unwrap()),
                1e-12,
            )
            .unwrap()
            .robustness_sigma(40.0)
            .unwrap_or(40.0)
        };
        // the model is the axis: every band is learned
        assert_eq!(sigma(&axis()), 0.0);
        // three samples late: the fast part (0.3 rad/sample) is answered
        // 0.9 rad out of phase; only a smoothing that removes it leaves the
        // shape
        let s = sigma(&delayed);
        assert!((1.0..40.0).contains(&s), "{s}");
    }

    #[test]
    fn where_the_axis_did_not_answer_the_last_step_nothing_is_learned_again() {
        // the answer agrees with the prediction except on samples 300..400,
        // where the axis did not move at all
        let n = 800;
        let predicted: Vec<f64> = (0..n).map(|k| (k as f64 * 0.05).sin()).collect();
        let mut measured = predicted.clone();
        measured[300..400].fill(0.0);
        let answer = Answer {
            measured,
            predicted,
        };
        let w = answer.local_weight(0.0, 5.0);
        for (k, v) in w.iter().enumerate().take(380).skip(320) {
            assert!(*v < 0.2, "{k}: {v}");
        }
        for k in (0..250).chain(450..n) {
            assert!(w[k] > 0.8, "{k}: {}", w[k]);
        }
        // a step that changed nothing somewhere leaves the weight at 1 there
        let predicted: Vec<f64> = (0..n)
            .map(|k| {
                if k < 400 {
                    (k as f64 * 0.05).sin()
                } else {
                    0.0
                }
            })
            .collect();
        let answer = Answer {
            measured: predicted.clone(),
            predicted,
        };
        let w = answer.local_weight(0.0, 5.0);
        assert!(w.iter().all(|v| (v - 1.0).abs() < 1e-9));
    }
}
