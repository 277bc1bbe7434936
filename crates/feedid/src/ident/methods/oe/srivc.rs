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
//! Every pass's instrument `x̂` is the simulated output of the previous
//! pass's model, so its simulation error comes free: when the passes do not
//! converge, the best-fitting iterates are returned as starts
//! ([`SrivcEstimate::alternatives`]) instead of whichever came last.
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
    /// When the iterations did not converge (they cycle): other iterates
    /// worth starting the output-error refinement from, best-fitting first
    /// (at most [`ALTERNATIVES`]); empty after convergence.
    pub alternatives: Vec<Vec<f64>>,
}

/// How many other iterates of a cycling SRIVC run are kept as starts.
pub(crate) const ALTERNATIVES: usize = 2;

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
    // every iterate's simulation error (from pass 1 on: the model of the pass before)
    let mut iterates: Vec<(f64, Vec<f64>)> = Vec::new();
    let mut converged = false;
    for pass in 0..=max_iterations {
        if !is_hurwitz(&alpha) {
            reflect_unstable(&mut alpha)?;
        }
        comp.discretize(&alpha, h)?;
        xu.fill(0.0);
        xy.fill(0.0);
        xx.fill(0.0);
        let beta: Vec<f64> = theta[n..].to_vec();
        // x̂ is the simulated output of the previous pass's model (Â, B̂)
        let mut sse = 0.0;
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
            sse += (yk - xhat_k) * (yk - xhat_k);
            comp.step_zoh(&mut xu, uk);
            let xhat_next: f64 = (0..=m).map(|j| beta[m - j] * xu[j]).sum();
            let y_next = if k + 1 < len { y[k + 1] - y0 } else { yk };
            comp.step_foh(&mut xy, yk, y_next);
            comp.step_foh(&mut xx, xhat_k, xhat_next);
        }
        // column scaling by the regressor norms
        if pass > 0 && sse.is_finite() {
            let mut model = theta.clone();
            model[..n].copy_from_slice(&alpha);
            iterates.push((sse, model));
        }
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
                converged = true;
                break;
            }
        }
    }
    if !is_hurwitz(&alpha) {
        reflect_unstable(&mut alpha)?;
        theta[..n].copy_from_slice(&alpha);
    }
    let mut alternatives = Vec::new();
    if !converged {
        // the iterations cycle (or wander): which iterate is the last one
        // the last bits of the data decide, so the best-fitting iterates
        // of all passes start the refinement instead
        let sse = simulation_sse(&mut comp, &theta, h, n, m, u, y)?;
        iterates.push((sse, theta.clone()));
        iterates.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut kept: Vec<Vec<f64>> = Vec::new();
        for (_, model) in iterates {
            let distinct = kept.iter().all(|k| {
                k.iter()
                    .zip(&model)
                    .any(|(a, b)| (a - b).abs() > 1e-6 * a.abs().max(b.abs()).max(1e-12))
            });
            if distinct {
                kept.push(model);
                if kept.len() > ALTERNATIVES {
                    break;
                }
            }
        }
        let mut kept = kept.into_iter();
        if let Some(first) = kept.next() {
            theta = first;
        }
        alternatives = kept.collect();
    }
    Ok(SrivcEstimate {
        theta,
        iterations,
        alternatives,
    })
}

/// Sum of squared simulation errors of the model `θ = [α, β]` (relative to
/// the first samples, zero initial state), ∞ if it cannot be discretised.
fn simulation_sse(
    comp: &mut Companion,
    theta: &[f64],
    h: f64,
    n: usize,
    m: usize,
    u: &[f64],
    y: &[f64],
) -> Result<f64> {
    if comp.discretize(&theta[..n], h).is_err() {
        return Ok(f64::INFINITY);
    }
    let (u0, y0) = (u[0], y[0]);
    let mut x = vec![0.0; n];
    let mut sse = 0.0;
    for (&uk, &yk) in u.iter().zip(y) {
        let xhat: f64 = (0..=m).map(|j| theta[n + m - j] * x[j]).sum();
        sse += (yk - y0 - xhat) * (yk - y0 - xhat);
        comp.step_zoh(&mut x, uk - u0);
    }
    Ok(if sse.is_finite() { sse } else { f64::INFINITY })
}

fn binomial(n: usize, k: usize) -> f64 {
    let mut c = 1.0;
    for i in 0..k {
        c = c * (n - i) as f64 / (i + 1) as f64;
    }
    c
}

#[cfg(test)]
pub(crate) mod tests {
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

    /// The first 200 samples of member 132 of the drive zoo (a stiff rig
    /// axis with feed-forward at 3.6 kHz: SRIVC's iterations cycle there).
    pub(crate) fn cycling_window() -> (Vec<f64>, Vec<f64>, f64) {
        let rec = crate::zoo::Zoo::standard()
            .member(132)
            .unwrap()
            .recording()
            .unwrap();
        let w = 200;
        (
            rec.command()[..w].to_vec(),
            rec.position()[..w].to_vec(),
            rec.dt(),
        )
    }

    #[test]
    fn a_cycling_run_starts_from_its_best_fitting_iterates() {
        let (u, y, _) = cycling_window();
        let h = 0.1 * std::f64::consts::PI;
        let est = srivc(&u, &y, h, 3, 1, 30).unwrap();
        assert_eq!(
            est.iterations, 30,
            "the iterations should not converge here"
        );
        assert!(!est.alternatives.is_empty() && est.alternatives.len() <= ALTERNATIVES);
        let mut comp = Companion::new(3);
        let sse =
            |th: &[f64], comp: &mut Companion| simulation_sse(comp, th, h, 3, 1, &u, &y).unwrap();
        let first = sse(&est.theta, &mut comp);
        assert!(first.is_finite());
        for alt in &est.alternatives {
            assert!(first <= sse(alt, &mut comp), "the first start fits best");
            assert_ne!(alt, &est.theta);
        }
        // a converging run has no alternatives
        let tf = TransferFunction::new(vec![1.5], vec![1.0, 0.6, 1.5]).unwrap();
        let u: Vec<f64> = (0..600)
            .map(|k| if (k / 40) % 2 == 1 { 1.0 } else { 0.0 })
            .collect();
        let y = tf
            .to_state_space()
            .unwrap()
            .discretize_zoh(0.05)
            .unwrap()
            .simulate(&u, None)
            .unwrap();
        let est = srivc(&u, &y, 0.05, 2, 0, 30).unwrap();
        assert!(est.iterations < 30 && est.alternatives.is_empty());
    }
}
