//! Residual analysis: whiteness of the prediction residuals and their
//! independence of the input, with 99 % confidence bands (MATLAB `resid`).
//!
//! With the means removed from `e` and `u` (`N` samples):
//!
//! ```text
//! r_ee(τ) = Σ_k e[k]·e[k+τ] / Σ_k e[k]²,                       τ = 0 … M
//! r_ue(τ) = Σ_k u[k]·e[k+τ] / sqrt(Σ u[k]² · Σ e[k]²),           τ = −M … M
//! ```
//!
//! (`τ > 0`: residual after input — a correlation there means the model
//! missed part of the input's effect). For white residuals independent of the
//! input, each normalised correlation is approximately `N(0, 1/N)`, so 99 %
//! of them lie inside `±2.58/√N`. The flags count a set of `L` lags as
//! *inside* when at most `1 + ⌊0.02·L⌋` of them leave the 99 % band (chance
//! exceedances) and none leaves the 99.9 % band `±3.29/√N` (a strong single
//! peak is a real correlation).
//!
//! The `r_ee` verdict tests the lags `τ ≥ h` only ([`ResidualAnalysis::ee_first_lag`]):
//! the errors of a prediction `h` samples ahead ([`ResidualAnalysis::for_horizon`])
//! share the innovations since their common origin, so even a perfect
//! model's errors are correlated up to lag `h − 1` (an MA(h−1) process,
//! Ljung §16.6; Box & Jenkins §5.1). `h = 1` (one-step errors) tests every
//! lag `τ ≥ 1`. The largest lag is raised to at least `2h` so that some lags
//! are tested.
//!
//! Reference: L. Ljung, *System Identification*, 2nd ed., §16.6.
//!
//! ```
//! use feedid::ident::ResidualAnalysis;
//! let e: Vec<f64> = (0..2000).map(|k| ((k * 7919 % 1009) as f64 / 1009.0) - 0.5).collect();
//! let u: Vec<f64> = (0..2000).map(|k| (k as f64 * 0.01).sin()).collect();
//! let r = ResidualAnalysis::new(&u, &e, 20).unwrap();
//! assert_eq!(r.r_ee.len(), 21);
//! assert_eq!(r.r_ue.len(), 41);
//! assert!((r.r_ee[0] - 1.0).abs() < 1e-12);
//! ```

use serde::Serialize;

use crate::error::{Error, Result};
use crate::ident::engine::SlidingResult;

/// z-value of the two-sided 99 % band.
pub const Z_99: f64 = 2.58;

/// z-value of the two-sided 99.9 % band (no lag may exceed it).
const Z_999: f64 = 3.29;

/// Residual auto- and input–residual cross-correlation with 99 % bands.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ResidualAnalysis {
    /// Number of samples `N`.
    pub samples: usize,
    /// Largest lag `M`.
    pub max_lag: usize,
    /// `r_ee(τ)`, τ = 0 … M (`r_ee(0) = 1`).
    pub r_ee: Vec<f64>,
    /// `r_ue(τ)`, τ = −M … M (element `i` is τ = i − M).
    pub r_ue: Vec<f64>,
    /// Half-width of the 99 % band, `2.58/√N`.
    pub bound: f64,
    /// First lag of the `r_ee` verdict: the prediction horizon `h` (1 for one-step errors).
    pub ee_first_lag: usize,
    /// Lags τ ≥ `ee_first_lag` with `|r_ee(τ)| > bound`.
    pub ee_outside: usize,
    /// Lags with `|r_ue(τ)| > bound`.
    pub ue_outside: usize,
    /// Whether the residuals look white at the lags `ee_first_lag … max_lag`
    /// (see the module doc for the rule).
    pub ee_inside: bool,
    /// Whether the residuals look independent of the input (same rule over `2M+1` lags).
    pub ue_inside: bool,
}

impl ResidualAnalysis {
    /// Analyse residuals `e` against the input `u` (same length) up to lag `max_lag`.
    ///
    /// Errors: length mismatch, `N ≤ max_lag`, non-finite values. A zero
    /// residual (perfect fit) gives zero correlations (inside the bands);
    /// a constant input gives `r_ue = 0`.
    pub fn new(u: &[f64], e: &[f64], max_lag: usize) -> Result<Self> {
        Self::for_horizon(u, e, max_lag, 1)
    }

    /// Analyse `h`-step-ahead prediction errors: as [`ResidualAnalysis::new`]
    /// with the largest lag raised to `max(max_lag, 2h)` and the `r_ee`
    /// verdict over the lags `τ ≥ h` (see the module doc).
    pub fn for_horizon(u: &[f64], e: &[f64], max_lag: usize, horizon: usize) -> Result<Self> {
        let first = horizon.max(1);
        let max_lag = max_lag.max(2 * first).max(1);
        let n = e.len();
        if u.len() != n {
            return Err(Error::LengthMismatch {
                what: "input",
                expected: n,
                actual: u.len(),
            });
        }
        if n <= max_lag || n < 2 {
            return Err(Error::TooFewSamples {
                what: "residual analysis (samples > max lag)",
                needed: max_lag.max(1) + 1,
                actual: n,
            });
        }
        for (ch, v) in [("residuals", e), ("input", u)] {
            if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                return Err(Error::NonFinite {
                    channel: ch.to_string(),
                    index: i,
                    value: v[i],
                });
            }
        }
        let me = e.iter().sum::<f64>() / n as f64;
        let mu = u.iter().sum::<f64>() / n as f64;
        let ec: Vec<f64> = e.iter().map(|v| v - me).collect();
        let uc: Vec<f64> = u.iter().map(|v| v - mu).collect();
        let see: f64 = ec.iter().map(|v| v * v).sum();
        let suu: f64 = uc.iter().map(|v| v * v).sum();
        let corr = |a: &[f64], b: &[f64], tau: isize| -> f64 {
            // Σ_k a[k]·b[k+τ]
            let t = tau.unsigned_abs();
            if tau >= 0 {
                a[..n - t].iter().zip(&b[t..]).map(|(x, y)| x * y).sum()
            } else {
                a[t..].iter().zip(&b[..n - t]).map(|(x, y)| x * y).sum()
            }
        };
        let m = max_lag as isize;
        let r_ee: Vec<f64> = (0..=m)
            .map(|t| {
                if see > 0.0 {
                    corr(&ec, &ec, t) / see
                } else {
                    0.0
                }
            })
            .collect();
        let den = (see * suu).sqrt();
        let r_ue: Vec<f64> = (-m..=m)
            .map(|t| {
                if den > 0.0 {
                    corr(&uc, &ec, t) / den
                } else {
                    0.0
                }
            })
            .collect();
        let bound = Z_99 / (n as f64).sqrt();
        let ee_outside = r_ee.iter().skip(first).filter(|v| v.abs() > bound).count();
        let ue_outside = r_ue.iter().filter(|v| v.abs() > bound).count();
        let strong = Z_999 / (n as f64).sqrt();
        let inside = |r: &[f64], outside: usize| {
            outside <= 1 + r.len() / 50 && r.iter().all(|v| v.abs() <= strong)
        };
        Ok(Self {
            samples: n,
            max_lag,
            ee_inside: inside(&r_ee[first..], ee_outside),
            ee_first_lag: first,
            ue_inside: inside(&r_ue, ue_outside),
            r_ee,
            r_ue,
            bound,
            ee_outside,
            ue_outside,
        })
    }

    /// `r_ue` at lag `tau` (`|tau| ≤ max_lag`).
    pub fn r_ue_at(&self, tau: isize) -> Option<f64> {
        let i = tau + self.max_lag as isize;
        usize::try_from(i)
            .ok()
            .and_then(|i| self.r_ue.get(i).copied())
    }
}

/// Largest lag of the residual analysis of a run's summary (`feedid identify`).
pub const RESIDUAL_LAGS: usize = 25;

/// Most recent predicted samples the residual analysis of a run uses.
pub const RESIDUAL_SAMPLES: usize = 200_000;

/// Residual analysis of the prediction errors `y − ŷ` of a sliding run over
/// its predicted samples (at most the last [`RESIDUAL_SAMPLES`]) against the
/// command, lags 0 … max(`max_lag`, 2·`horizon`); `None` when at most
/// `2·max_lag + 1` samples were predicted. The k-step errors of one horizon
/// share the state they were predicted from, so `r_ee` is positive for lags
/// below the horizon whatever the model: the verdict tests the lags from the
/// horizon on ([`ResidualAnalysis::for_horizon`]).
pub fn prediction_residuals(
    s: &SlidingResult,
    command: &[f64],
    position: &[f64],
    max_lag: usize,
    horizon: usize,
) -> Option<ResidualAnalysis> {
    let (u, e) = prediction_errors(s, command, position, RESIDUAL_SAMPLES);
    if e.len() <= 2 * max_lag + 1 {
        return None;
    }
    ResidualAnalysis::for_horizon(&u, &e, max_lag, horizon).ok()
}

/// The command `u[k]` and the prediction error `y[k] − ŷ[k]` at the
/// predicted samples `k` of a sliding run, in time order: the last
/// `max_samples` of them at most.
pub fn prediction_errors(
    s: &SlidingResult,
    command: &[f64],
    position: &[f64],
    max_samples: usize,
) -> (Vec<f64>, Vec<f64>) {
    let (mut u, mut e) = (Vec::new(), Vec::new());
    for k in (0..s.predicted.len()).rev() {
        if e.len() >= max_samples {
            break;
        }
        if s.has_prediction[k] {
            u.push(command.get(k).copied().unwrap_or(0.0));
            e.push(position.get(k).copied().unwrap_or(0.0) - s.predicted[k]);
        }
    }
    u.reverse();
    e.reverse();
    (u, e)
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
    fn white_noise_stays_inside_the_99_percent_band() {
        let mut outside = 0;
        let mut total = 0;
        let mut inside_flags = 0;
        for seed in 0..40 {
            let e = white(seed, 4000);
            let u = white(1000 + seed, 4000);
            let r = ResidualAnalysis::new(&u, &e, 25).unwrap();
            outside += r.ee_outside + r.ue_outside;
            total += 25 + 51;
            inside_flags += usize::from(r.ee_inside && r.ue_inside);
        }
        let frac = outside as f64 / total as f64;
        assert!(frac < 0.02, "fraction outside {frac}");
        assert!(inside_flags >= 30, "{inside_flags} of 40");
    }

    #[test]
    fn coloured_noise_and_input_dependence_are_detected() {
        let w = white(1, 4000);
        let mut e = vec![0.0; 4000];
        for k in 1..4000 {
            e[k] = 0.8 * e[k - 1] + w[k];
        }
        let u = white(2, 4000);
        let r = ResidualAnalysis::new(&u, &e, 20).unwrap();
        assert!(!r.ee_inside);
        assert!((r.r_ee[1] - 0.8).abs() < 0.05, "{}", r.r_ee[1]);
        assert!(r.ue_inside);
        // residual containing the input delayed by 3 samples
        let e2: Vec<f64> = (0..4000)
            .map(|k| w[k] + if k >= 3 { 0.5 * u[k - 3] } else { 0.0 })
            .collect();
        let r2 = ResidualAnalysis::new(&u, &e2, 20).unwrap();
        assert!(!r2.ue_inside);
        let peak = r2.r_ue_at(3).unwrap();
        assert!((peak - 0.5 / 1.25f64.sqrt()).abs() < 0.05, "{peak}");
        assert!(r2.r_ue_at(-3).unwrap().abs() < r2.bound);
    }

    #[test]
    fn k_step_errors_of_a_perfect_model_pass_beyond_the_horizon_only() {
        // h-step-ahead errors of a perfect predictor of a random walk: the sum
        // of the innovations since the window's origin (an MA(h−1) process)
        let h = 10;
        let w = white(5, 6000);
        let mut e = Vec::new();
        for origin in (0..w.len() - h).step_by(h) {
            let mut acc = 0.0;
            for k in 1..=h {
                acc += w[origin + k];
                e.push(acc);
            }
        }
        let u = white(6, e.len());
        let one_step = ResidualAnalysis::new(&u, &e, 25).unwrap();
        assert!(!one_step.ee_inside, "correlated at lags below h");
        let r = ResidualAnalysis::for_horizon(&u, &e, 25, h).unwrap();
        assert_eq!(r.ee_first_lag, h);
        assert!(
            r.ee_inside,
            "outside {} of lags ≥ {h}: {:?}",
            r.ee_outside,
            &r.r_ee[h..]
        );
        // a residual correlated beyond the horizon still fails
        let mut c = vec![0.0; e.len()];
        for k in 1..e.len() {
            c[k] = 0.97 * c[k - 1] + w[k % w.len()];
        }
        assert!(
            !ResidualAnalysis::for_horizon(&u, &c, 25, h)
                .unwrap()
                .ee_inside
        );
        // a long horizon raises the largest lag
        let r = ResidualAnalysis::for_horizon(&u, &e, 25, 20).unwrap();
        assert_eq!(r.max_lag, 40);
        assert_eq!(r.r_ee.len(), 41);
    }

    #[test]
    fn bad_inputs_are_errors() {
        assert!(ResidualAnalysis::new(&[1.0, 2.0], &[1.0], 0).is_err());
        assert!(ResidualAnalysis::new(&[1.0; 5], &[1.0; 5], 5).is_err());
        assert!(ResidualAnalysis::new(&[1.0, f64::NAN, 0.0], &[1.0; 3], 1).is_err());
    }
}
