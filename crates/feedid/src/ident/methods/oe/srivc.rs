//! Simplified refined instrumental variable method for continuous-time
//! models (SRIVC, Young & Jakeman 1980): the initial estimate of the
//! output-error fit ([`super::oe`]).
//!
//! For the model `A(σ)·y = B(σ)·u` (scaled, monic `A`, see
//! [`super::companion`]) and a current estimate `Â`, every signal is
//! prefiltered by `1/Â`:
//!
//! ```text
//!     y_f⁽ⁱ⁾ = σⁱ/Â·y,   u_f⁽ʲ⁾ = σʲ/Â·u,   x̂ = B̂/Â·u,   x̂_f⁽ⁱ⁾ = σⁱ/Â·x̂
//!     y_f⁽ⁿ⁾ = φᵀθ,   φ = [−y_f⁽ⁿ⁻¹⁾ … −y_f⁽⁰⁾, u_f⁽ᵐ⁾ … u_f⁽⁰⁾]
//! ```
//!
//! and `θ` solves the instrumental-variable equations `Σ ζ·φᵀ·θ = Σ ζ·y_f⁽ⁿ⁾`
//! with the noise-free instrument `ζ = [−x̂_f⁽ⁿ⁻¹⁾ … −x̂_f⁽⁰⁾, u_f⁽ᵐ⁾ … u_f⁽⁰⁾]`
//! (columns scaled to unit norm, solved by Householder QR). `Â ← A(θ)` and
//! repeat until `θ` stops changing. The first pass uses `Â = (σ + 1)ⁿ` and
//! least squares (`ζ = φ`, the state-variable-filter estimate). An unstable
//! `Â` is reflected into the left half plane before it is used as a filter.
//!
//! Discretisation: `u` is piecewise constant, so `u_f` is exact (zero-order
//! hold); `y` and `x̂` are sampled continuous signals, filtered with a
//! first-order hold (error O(Δt²)). The estimate is therefore consistent up to
//! that discretisation error, which the output-error refinement removes.
//! Signals are taken relative to their first sample (the data should start at
//! rest; otherwise the initial transient biases the estimate slightly).
//!
//! References: P.C. Young, A.J. Jakeman, "Refined instrumental variable
//! methods of recursive time-series analysis, Part III", Int. J. Control 31
//! (1980); H. Garnier, M. Gilson, P.C. Young, E. Huselstein, "An optimal IV
//! technique for identifying continuous-time transfer function model of
//! multiple input systems", Control Eng. Practice 15 (2007).

use nalgebra::{DMatrix, DVector};

use super::companion::{is_hurwitz, reflect_unstable, Companion};
use crate::error::{Error, Result};
use crate::solve::lstsq;

/// Outcome of an SRIVC run.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct SrivcEstimate {
    /// `[α_{n−1} … α₀, β_m … β₀]` in the scaled variable.
    pub theta: Vec<f64>,
    /// IV iterations performed (after the first least-squares pass).
    pub iterations: usize,
}

/// SRIVC estimate of an `n`-pole, `m`-zero model from `u`, `y` sampled every
/// scaled step `h = ω_r·Δt`, with at most `max_iterations` IV passes.
pub(crate) fn srivc(
    u: &[f64],
    y: &[f64],
    h: f64,
    n: usize,
    m: usize,
    max_iterations: usize,
) -> Result<SrivcEstimate> {
    let len = u.len();
    let p = n + m + 1;
    if y.len() != len {
        return Err(Error::LengthMismatch {
            what: "SRIVC output",
            expected: len,
            actual: y.len(),
        });
    }
    if len < 2 * p + 2 {
        return Err(Error::TooFewSamples {
            what: "SRIVC",
            needed: 2 * p + 2,
            actual: len,
        });
    }
    let (u0, y0) = (u[0], y[0]);
    // (σ + 1)ⁿ
    let mut alpha = vec![0.0; n];
    for (k, a) in alpha.iter_mut().enumerate() {
        *a = binomial(n, k + 1);
    }
    let mut theta = vec![0.0; p];
    let mut comp = Companion::new(n);
    let mut phi = DMatrix::<f64>::zeros(len, p);
    let mut zeta = DMatrix::<f64>::zeros(len, p);
    let mut target = DVector::<f64>::zeros(len);
    let mut xu = vec![0.0; n];
    let mut xy = vec![0.0; n];
    let mut xx = vec![0.0; n];
    let mut iterations = 0;
    for pass in 0..=max_iterations {
        if !is_hurwitz(&alpha) {
            reflect_unstable(&mut alpha)?;
        }
        comp.discretize(&alpha, h)?;
        xu.fill(0.0);
        xy.fill(0.0);
        xx.fill(0.0);
        let beta: Vec<f64> = theta[n..].to_vec();
        for k in 0..len {
            // filtered values at sample k (states at k)
            for i in 0..n {
                // column of −y_f⁽ⁱ⁾ is at index n−1−i
                phi[(k, n - 1 - i)] = -xy[i];
                zeta[(k, n - 1 - i)] = -xx[i];
            }
            for j in 0..=m {
                phi[(k, n + m - j)] = xu[j];
                zeta[(k, n + m - j)] = xu[j];
            }
            let yk = y[k] - y0;
            let yf_n = yk - (0..n).map(|i| alpha[n - 1 - i] * xy[i]).sum::<f64>();
            target[k] = yf_n;
            // advance
            let uk = u[k] - u0;
            let xhat_k: f64 = (0..=m).map(|j| beta[m - j] * xu[j]).sum();
            comp.step_zoh(&mut xu, uk);
            let xhat_next: f64 = (0..=m).map(|j| beta[m - j] * xu[j]).sum();
            let y_next = if k + 1 < len { y[k + 1] - y0 } else { yk };
            comp.step_foh(&mut xy, yk, y_next);
            comp.step_foh(&mut xx, xhat_k, xhat_next);
        }
        // column scaling by the regressor norms
        let mut scale = vec![1.0; p];
        for (j, s) in scale.iter_mut().enumerate() {
            let nrm = phi.column(j).norm();
            if nrm > 0.0 && nrm.is_finite() {
                *s = nrm;
            }
        }
        for (j, &s) in scale.iter().enumerate() {
            phi.column_mut(j).scale_mut(1.0 / s);
            zeta.column_mut(j).scale_mut(1.0 / s);
        }
        let z = if pass == 0 {
            lstsq(&phi, &target)?.x
        } else {
            let lhs = zeta.transpose() * &phi;
            let rhs = zeta.transpose() * &target;
            lstsq(&lhs, &rhs)?.x
        };
        let new: Vec<f64> = z.iter().zip(&scale).map(|(v, s)| v / s).collect();
        if new.iter().any(|v| !v.is_finite()) {
            return Err(Error::InvalidModel {
                reason: "SRIVC produced non-finite coefficients",
            });
        }
        let change = new
            .iter()
            .zip(&theta)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f64, f64::max);
        let size = new.iter().map(|v| v.abs()).fold(0.0f64, f64::max);
        theta.copy_from_slice(&new);
        alpha.copy_from_slice(&theta[..n]);
        if pass > 0 {
            iterations = pass;
            if change <= 1e-12 * size {
                break;
            }
        }
    }
    if !is_hurwitz(&alpha) {
        reflect_unstable(&mut alpha)?;
        theta[..n].copy_from_slice(&alpha);
    }
    Ok(SrivcEstimate { theta, iterations })
}

fn binomial(n: usize, k: usize) -> f64 {
    let mut c = 1.0;
    for i in 0..k {
        c = c * (n - i) as f64 / (i + 1) as f64;
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lti::TransferFunction;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn srivc_recovers_a_second_order_system_from_noise_free_data() {
        // G(σ) = 1.5/(σ² + 0.6σ + 1.5), sampled with h = 0.05
        let tf = TransferFunction::new(vec![1.5], vec![1.0, 0.6, 1.5]).unwrap();
        let h = 0.05;
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut u = vec![0.0; 4000];
        let mut level = 0.0;
        for (k, v) in u.iter_mut().enumerate() {
            if k % 20 == 0 && k > 10 {
                level = if rng.random::<bool>() { 1.0 } else { -1.0 };
            }
            *v = level;
        }
        let y = tf
            .to_state_space()
            .unwrap()
            .discretize_zoh(h)
            .unwrap()
            .simulate(&u, None)
            .unwrap();
        let est = srivc(&u, &y, h, 2, 0, 20).unwrap();
        let truth = [0.6, 1.5, 1.5];
        for (a, b) in est.theta.iter().zip(&truth) {
            // first-order-hold discretisation error of the filtered output
            assert!((a - b).abs() < 2e-3, "{:?}", est.theta);
        }
    }
}
