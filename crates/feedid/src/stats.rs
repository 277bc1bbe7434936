//! Error statistics and information criteria, with the conventions of the
//! field (MATLAB System Identification Toolbox).
//!
//! ```text
//! rms    = sqrt(Σ e²/N)
//! fit%   = 100·(1 − ‖y − ŷ‖ / ‖y − mean(y)‖)             (NRMSE fit, MATLAB `compare`)
//! V      = Σ e²/N
//! FPE    = V·(1 + np/N)/(1 − np/N)
//! AIC    = N·ln V + 2·np + N·(ln 2π + 1)
//! AICc   = AIC + 2·np·(np + 1)/(N − np − 1)
//! BIC    = N·ln V + N·(ln 2π + 1) + np·ln N
//! ```
//!
//! ```
//! use feedid::stats::ErrorStats;
//! let y = [1.0, 2.0, 3.0];
//! let s = ErrorStats::from_pairs(y.iter().copied().zip(y.iter().copied()));
//! assert_eq!(s.rms, 0.0);
//! assert_eq!(s.fit_percent, 100.0);
//! ```

use serde::Serialize;

/// Error statistics of a prediction ŷ against a measurement y.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ErrorStats {
    /// Number of compared samples.
    pub samples: usize,
    /// Root-mean-square error \[unit of y\].
    pub rms: f64,
    /// Largest absolute error \[unit of y\].
    pub max_abs: f64,
    /// NRMSE fit \[%\]; 100 is perfect; `None`-like 0 samples give 0.
    pub fit_percent: f64,
}

impl ErrorStats {
    /// Statistics over `(measured, predicted)` pairs (two passes are avoided by
    /// accumulating around the first measured value for numerical care).
    pub fn from_pairs<I: IntoIterator<Item = (f64, f64)>>(pairs: I) -> Self {
        let mut acc = ErrorAccumulator::default();
        for (y, yhat) in pairs {
            acc.push(y, yhat);
        }
        acc.finish()
    }
}

/// Streaming accumulator for [`ErrorStats`] (allocation-free).
#[derive(Debug, Clone, Copy, Default)]
pub struct ErrorAccumulator {
    n: usize,
    sse: f64,
    max_abs: f64,
    shift: f64,
    sum: f64,
    sum_sq: f64,
}

impl ErrorAccumulator {
    /// Add one pair of measured `y` and predicted `yhat`.
    pub fn push(&mut self, y: f64, yhat: f64) {
        if self.n == 0 {
            self.shift = y;
        }
        let e = y - yhat;
        self.n += 1;
        self.sse += e * e;
        self.max_abs = self.max_abs.max(e.abs());
        let d = y - self.shift;
        self.sum += d;
        self.sum_sq += d * d;
    }

    /// Number of pairs so far.
    pub fn count(&self) -> usize {
        self.n
    }

    /// The statistics of the pairs so far.
    pub fn finish(&self) -> ErrorStats {
        if self.n == 0 {
            return ErrorStats {
                samples: 0,
                rms: 0.0,
                max_abs: 0.0,
                fit_percent: 0.0,
            };
        }
        let n = self.n as f64;
        let var_sum = (self.sum_sq - self.sum * self.sum / n).max(0.0);
        let fit = if var_sum > 0.0 {
            100.0 * (1.0 - (self.sse / var_sum).sqrt())
        } else if self.sse == 0.0 {
            100.0
        } else {
            f64::NEG_INFINITY
        };
        ErrorStats {
            samples: self.n,
            rms: (self.sse / n).sqrt(),
            max_abs: self.max_abs,
            fit_percent: if fit.is_finite() { fit } else { -1e9 },
        }
    }
}

/// Root-mean-square of a slice (0 for an empty slice).
pub fn rms(v: &[f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

/// Information criteria of a fit with loss `V = Σe²/N`, `n` samples and `np` parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct InformationCriteria {
    /// Akaike's final prediction error.
    pub fpe: f64,
    /// Akaike information criterion.
    pub aic: f64,
    /// Small-sample corrected AIC (infinite when `N ≤ np + 1`).
    pub aicc: f64,
    /// Bayesian information criterion.
    pub bic: f64,
}

impl InformationCriteria {
    /// Criteria from the loss `v = Σe²/N`, sample count `n` and parameter count `np`.
    pub fn new(v: f64, n: usize, np: usize) -> Self {
        let nf = n as f64;
        let p = np as f64;
        let v = v.max(f64::MIN_POSITIVE);
        let c = nf * ((2.0 * std::f64::consts::PI).ln() + 1.0);
        let fpe = if np < n {
            v * (1.0 + p / nf) / (1.0 - p / nf)
        } else {
            f64::INFINITY
        };
        let aic = nf * v.ln() + 2.0 * p + c;
        let aicc = if n > np + 1 {
            aic + 2.0 * p * (p + 1.0) / (nf - p - 1.0)
        } else {
            f64::INFINITY
        };
        let bic = nf * v.ln() + c + p * nf.ln();
        Self {
            fpe,
            aic,
            aicc,
            bic,
        }
    }
}

/// A value with three significant digits for text and figure labels
/// (`1234.5` → `1235`, `0.01234` → `0.0123`; no exponent below 1e6;
/// `–` for a non-finite value).
pub fn sig3(v: f64) -> String {
    let a = v.abs();
    if !v.is_finite() {
        "–".to_string()
    } else if a >= 1e6 {
        format!("{v:.2e}")
    } else if a >= 100.0 {
        format!("{v:.0}")
    } else if a >= 10.0 {
        format!("{v:.1}")
    } else if a >= 1.0 {
        format!("{v:.2}")
    } else if a >= 0.01 || a == 0.0 {
        format!("{v:.3}")
    } else {
        format!("{v:.2e}")
    }
}

/// Noise level of a signal: the median absolute deviation of its second
/// differences, scaled to a standard deviation (`√6·σ` for white noise).
pub fn noise_level(e: &[f64]) -> f64 {
    if e.len() < 3 {
        return 0.0;
    }
    let mut d: Vec<f64> = e.windows(3).map(|w| w[2] - 2.0 * w[1] + w[0]).collect();
    let m = median(&mut d);
    let mut dev: Vec<f64> = d.iter().map(|v| (v - m).abs()).collect();
    1.4826 * median(&mut dev) / 6.0_f64.sqrt()
}

/// Noise level of a run's error or residual `e` (against its measured
/// position `measured`): [`noise_level`], or, when
/// the measured position is quantised (a quarter or more of its second
/// differences exactly zero, where the median absolute deviation sees
/// nothing), the larger of it and the rms of the second differences of `e`
/// without their largest 2 % (corners, wild samples), scaled as for white
/// noise (`√6`, and 0.874 for the trimmed tail).
pub fn noise_level_of_run(e: &[f64], measured: &[f64]) -> f64 {
    let mad = noise_level(e);
    if e.len() < 3 || measured.len() != e.len() {
        return mad;
    }
    let zero = measured
        .windows(3)
        .filter(|w| w[2] - 2.0 * w[1] + w[0] == 0.0)
        .count();
    if 4 * zero < measured.len() - 2 {
        return mad;
    }
    let mut sq: Vec<f64> = e
        .windows(3)
        .map(|w| (w[2] - 2.0 * w[1] + w[0]).powi(2))
        .collect();
    sq.sort_by(f64::total_cmp);
    let keep = sq.len() - sq.len() / 50;
    let ms = sq[..keep].iter().sum::<f64>() / keep.max(1) as f64;
    mad.max((ms / (6.0 * 0.874)).sqrt())
}

/// The resolution of a quantised measurement \[its units\]: the smallest
/// non-zero step between consecutive samples of `measured`, when at least
/// 99 % of the non-zero steps are whole multiples of it (to a thousandth)
/// and there are at least 10 of them; `None` for a signal that is not
/// quantised (the steps of a continuous signal are no multiples of the
/// smallest).
pub fn resolution(measured: &[f64]) -> Option<f64> {
    let scale = measured.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let steps: Vec<f64> = measured
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .filter(|d| *d > 1e-12 * scale)
        .collect();
    if steps.len() < 10 {
        return None;
    }
    let q = steps.iter().fold(f64::INFINITY, |m, v| m.min(*v));
    let whole = steps
        .iter()
        .filter(|d| {
            let m = *d / q;
            (m - m.round()).abs() < 1e-3
        })
        .count();
    (100 * whole >= 99 * steps.len()).then_some(q)
}

/// The median of `v` (reordered in place; 0 when empty).
pub fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let mid = v.len() / 2;
    let (_, m, _) = v.select_nth_unstable_by(mid, f64::total_cmp);
    *m
}

/// The share of a following error `following` (`y − u`) that a model with
/// free-run residual `residual` (`y − ŷ`, same samples) explains, both
/// without a measurement noise of `noise` per sample, which no model
/// explains: `100·(1 − √(max(0, ‖r‖² − nσ²) / (‖f − f̄‖² − nσ²)))` \[%\];
/// `None` when the following error is no larger than the noise.
pub fn error_fit_percent(residual: &[f64], following: &[f64], noise: f64) -> Option<f64> {
    let n = following.len().min(residual.len());
    if n == 0 {
        return None;
    }
    let floor = noise * noise * n as f64;
    let mean = following[..n].iter().sum::<f64>() / n as f64;
    let sse = (residual[..n].iter().map(|r| r * r).sum::<f64>() - floor).max(0.0);
    let ssf = following[..n]
        .iter()
        .map(|f| (f - mean).powi(2))
        .sum::<f64>()
        - floor;
    if ssf > 0.0 && sse.is_finite() {
        Some(100.0 * (1.0 - (sse / ssf).sqrt()))
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_resolution_of_a_quantised_signal_is_its_step_and_a_continuous_one_has_none() {
        let q = 0.39e-6;
        let x: Vec<f64> = (0..2000)
            .map(|k| 1e-3 * (k as f64 * 0.003).sin() + 2e-7 * ((k * 7919) % 13) as f64)
            .collect();
        let quantised: Vec<f64> = x.iter().map(|v| q * (v / q).round()).collect();
        let r = resolution(&quantised).unwrap();
        assert!((r - q).abs() < 1e-9 * q, "{r}");
        assert_eq!(resolution(&x), None);
        // at rest: no steps, nothing to tell
        assert_eq!(resolution(&[1e-3; 100]), None);
    }

    #[test]
    fn fit_percent_matches_definition() {
        let y = [1.0, 2.0, 4.0, 3.0];
        let yhat = [1.1, 1.9, 3.5, 3.2];
        let s = ErrorStats::from_pairs(y.iter().copied().zip(yhat.iter().copied()));
        let mean = 2.5;
        let num: f64 = y.iter().zip(&yhat).map(|(a, b)| (a - b) * (a - b)).sum();
        let den: f64 = y.iter().map(|a| (a - mean) * (a - mean)).sum();
        assert!((s.fit_percent - 100.0 * (1.0 - (num / den).sqrt())).abs() < 1e-12);
        assert!((s.rms - (num / 4.0).sqrt()).abs() < 1e-15);
        assert!((s.max_abs - 0.5).abs() < 1e-15);
    }

    #[test]
    fn fit_is_accurate_for_large_offsets() {
        // a 25 m offset must not destroy the variance by cancellation
        let y: Vec<f64> = (0..100).map(|k| 25.0 + 1e-6 * (k as f64).sin()).collect();
        let s = ErrorStats::from_pairs(y.iter().map(|&v| (v, v)));
        assert_eq!(s.fit_percent, 100.0);
    }

    #[test]
    fn criteria_match_formulas() {
        let ic = InformationCriteria::new(0.5, 100, 4);
        let c = 100.0 * ((2.0 * std::f64::consts::PI).ln() + 1.0);
        assert!((ic.fpe - 0.5 * 1.04 / 0.96).abs() < 1e-12);
        assert!((ic.aic - (100.0 * 0.5f64.ln() + 8.0 + c)).abs() < 1e-9);
        assert!((ic.aicc - ic.aic - 40.0 / 95.0).abs() < 1e-9);
        assert!((ic.bic - (100.0 * 0.5f64.ln() + c + 4.0 * 100f64.ln())).abs() < 1e-9);
    }
}
