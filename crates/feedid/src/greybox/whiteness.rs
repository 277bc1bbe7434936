//! Is anything left in the residuals of a fit? The standard errors of
//! [`super::identifiability`] assume the model explains the data up to white
//! noise; residuals with structure mean it does not (an effect left out of
//! the model, e.g. friction), and then the estimates can be biased far beyond
//! their standard errors.
//!
//! The measure is the *predictable share* of a residual `e` (mean removed):
//! the fraction of its variance that a linear predictor of order `p` on its
//! own past explains,
//!
//! ```text
//! share = 1 − σ²_p/σ²_e = 1 − Π_{k=1…p} (1 − κ_k²)
//! ```
//!
//! with `κ_k` the reflection coefficients of the Levinson–Durbin recursion on
//! the biased autocorrelations `r(0) … r(p)`. White noise gives a share of
//! about `p/N`; an AR(1) residual with `r(1) = ρ` gives `ρ²`. It does not
//! depend on the scale of the residual, so one limit
//! ([`STRUCTURE_LIMIT`]) serves every unit and noise level.
//!
//! Reference: L. Ljung, *System Identification*, 2nd ed., §16.6 (residual
//! analysis); J. Durbin, "The fitting of time-series models", Rev. Int.
//! Stat. Inst. 28 (1960).

use serde::Serialize;

/// Order `p` of the predictor.
pub const PREDICTOR_ORDER: usize = 10;

/// Predictable share above which the residuals count as structured (25 %:
/// a residual whose lag-1 correlation is 0.5).
pub const STRUCTURE_LIMIT: f64 = 0.25;

/// The structure left in the residuals of one output.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ResidualStructure {
    /// The output (`position` or `current`).
    pub output: &'static str,
    /// Share of the residual variance predictable from its own past (0 … 1).
    pub predictable_share: f64,
    /// Lag-1 autocorrelation of the residual.
    pub lag1_correlation: f64,
    /// Whether the share exceeds [`STRUCTURE_LIMIT`].
    pub structured: bool,
}

/// Predictable share and lag-1 correlation of `e` (see the module doc);
/// `None` for fewer than `4·p` samples or a residual without variance.
pub fn predictable_share(e: &[f64], p: usize) -> Option<(f64, f64)> {
    let n = e.len();
    if n < 4 * p.max(1) {
        return None;
    }
    let mean = e.iter().sum::<f64>() / n as f64;
    let r: Vec<f64> = (0..=p)
        .map(|k| {
            e[..n - k]
                .iter()
                .zip(&e[k..])
                .map(|(a, b)| (a - mean) * (b - mean))
                .sum::<f64>()
                / n as f64
        })
        .collect();
    if !(r[0] > 0.0 && r[0].is_finite()) {
        return None;
    }
    // Levinson–Durbin
    let mut a = vec![0.0; p + 1];
    let mut prev = vec![0.0; p + 1];
    let mut err = r[0];
    let mut kept = 1.0;
    for k in 1..=p {
        let acc: f64 = (1..k).map(|j| a[j] * r[k - j]).sum();
        let kappa = ((r[k] - acc) / err).clamp(-1.0, 1.0);
        prev[..k].copy_from_slice(&a[..k]);
        a[k] = kappa;
        for j in 1..k {
            a[j] = prev[j] - kappa * prev[k - j];
        }
        kept *= 1.0 - kappa * kappa;
        err *= 1.0 - kappa * kappa;
        if err <= 0.0 {
            break;
        }
    }
    let share = (1.0 - kept).clamp(0.0, 1.0);
    Some((share, r[1] / r[0]))
}

/// The structure of the residual of `output`, or `None` when it cannot be measured.
pub fn residual_structure(output: &'static str, e: &[f64]) -> Option<ResidualStructure> {
    let (share, rho1) = predictable_share(e, PREDICTOR_ORDER)?;
    Some(ResidualStructure {
        output,
        predictable_share: share,
        lag1_correlation: rho1,
        structured: share > STRUCTURE_LIMIT,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, Normal};

    fn white(seed: u64, n: usize) -> Vec<f64> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let d = Normal::new(0.0, 1.0).unwrap();
        (0..n).map(|_| d.sample(&mut rng)).collect()
    }

    #[test]
    fn white_noise_has_a_share_near_p_over_n_at_any_scale() {
        for seed in 0..5 {
            let w = white(seed, 5000);
            let (s, _) = predictable_share(&w, 10).unwrap();
            assert!(s < 0.01, "{s}");
            let scaled: Vec<f64> = w.iter().map(|v| 1e-9 * v + 3.0).collect();
            let (s2, _) = predictable_share(&scaled, 10).unwrap();
            assert!((s - s2).abs() < 1e-9, "{s} vs {s2}");
        }
    }

    #[test]
    fn an_ar1_residual_has_the_share_rho_squared() {
        for rho in [0.3, 0.6, 0.9] {
            let w = white(1, 20000);
            let mut e = vec![0.0; w.len()];
            for k in 1..w.len() {
                e[k] = rho * e[k - 1] + w[k];
            }
            let (s, r1) = predictable_share(&e, 10).unwrap();
            assert!((s - rho * rho).abs() < 0.02, "{rho}: {s}");
            assert!((r1 - rho).abs() < 0.02, "{rho}: {r1}");
            assert_eq!(
                residual_structure("position", &e).unwrap().structured,
                rho * rho > STRUCTURE_LIMIT
            );
        }
    }

    #[test]
    fn a_slow_sine_left_in_the_residual_is_structure() {
        let w = white(2, 4000);
        let e: Vec<f64> = w
            .iter()
            .enumerate()
            .map(|(k, v)| 0.3 * v + (k as f64 * 0.01).sin())
            .collect();
        assert!(residual_structure("position", &e).unwrap().structured);
    }

    #[test]
    fn too_short_or_constant_residuals_are_not_measured() {
        assert!(predictable_share(&[1.0; 10], 10).is_none());
        assert!(predictable_share(&[2.0; 100], 10).is_none());
    }
}
