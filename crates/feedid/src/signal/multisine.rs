//! Multisine with Schroeder phases: flat amplitude spectrum, low crest factor.
//!
//! Harmonics of the base frequency `f_res` inside the band `[f_lo, f_hi]`,
//! `f_k = k·f_res` for `k = ⌈f_lo/f_res⌉ … ⌊f_hi/f_res⌋` (`M` lines, index `m = 1 … M`):
//!
//! ```text
//! s(t)   = Σ_m cos(2π f_k t + φ_m),      φ_m = −π·m·(m − 1)/M     (Schroeder 1970)
//! x_s(t) = A·w(t)·s(t − t_r)/max|s|,     w = raised-cosine onset over T_w
//! ```
//!
//! `max|s|` is taken over one period `1/f_res` sampled at the given rate, so
//! the steady part peaks at exactly `A`. Defaults: `A` = 0.03 mm (linear default rig: 8.3 A peak current), band
//! 1 … 200 Hz, `f_res` = 1 Hz (period 1 s), onset `T_w` = 0.05 s, rest 0.010 s.
//! Reference: M.R. Schroeder, "Synthesis of low-peak-factor signals and
//! binary sequences with low autocorrelation", IEEE Trans. Inf. Theory 16 (1970) 85–89.

use serde::{Deserialize, Serialize};

use super::common::{check_non_negative, check_positive, check_rate, sample_count, taper};

/// Most evaluations of a line when searching the peak over one period.
const MAX_PEAK_EVALUATIONS: f64 = 1e9;
use crate::error::{Error, Result};

/// Schroeder-phase multisine of position.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Multisine {
    /// Peak amplitude A \[m\]; default 3e-5.
    pub amplitude: f64,
    /// Lower band edge f_lo \[Hz\]; default 1.
    pub f_low: f64,
    /// Upper band edge f_hi \[Hz\]; default 200.
    pub f_high: f64,
    /// Frequency resolution f_res = 1/period \[Hz\]; default 1.
    pub resolution: f64,
    /// Raised-cosine onset length T_w \[s\]; default 0.05.
    pub taper: f64,
    /// Rest before the signal starts t_r \[s\]; default 0.010.
    pub rest: f64,
}

impl Default for Multisine {
    fn default() -> Self {
        Self {
            amplitude: 3e-5,
            f_low: 1.0,
            f_high: 200.0,
            resolution: 1.0,
            taper: 0.05,
            rest: 0.010,
        }
    }
}

impl Multisine {
    /// Check the parameters.
    pub fn validate(&self) -> Result<()> {
        check_non_negative("multisine.amplitude", self.amplitude)?;
        check_positive("multisine.f_low", self.f_low)?;
        check_positive("multisine.f_high", self.f_high)?;
        check_positive("multisine.resolution", self.resolution)?;
        check_non_negative("multisine.taper", self.taper)?;
        check_non_negative("multisine.rest", self.rest)?;
        let (k0, k1) = self.harmonics();
        if k1 < k0 {
            return Err(Error::InvalidParameter {
                name: "multisine.f_high",
                value: self.f_high,
                reason: "band holds no harmonic of multisine.resolution",
            });
        }
        if k1 - k0 > 1_000_000 {
            return Err(Error::InvalidParameter {
                name: "multisine.resolution",
                value: self.resolution,
                reason: "gives more than 1e6 lines",
            });
        }
        Ok(())
    }

    /// First and last harmonic numbers `k` of the band (empty if `last < first`).
    pub fn harmonics(&self) -> (u64, u64) {
        let k0 = (self.f_low / self.resolution).ceil().max(1.0);
        let k1 = (self.f_high / self.resolution).floor().max(0.0);
        (k0 as u64, k1 as u64)
    }

    /// Unscaled sum `s(τ)` (see the module doc).
    fn raw(&self, tau: f64) -> f64 {
        let (k0, k1) = self.harmonics();
        let m_total = (k1 - k0 + 1) as f64;
        let two_pi = 2.0 * std::f64::consts::PI;
        let mut s = 0.0;
        for (m, k) in (k0..=k1).enumerate() {
            let m = (m + 1) as f64;
            let phi = -std::f64::consts::PI * m * (m - 1.0) / m_total;
            // reduce the argument per line to keep precision for long signals
            let cycles = (k as f64 * self.resolution * tau).fract();
            s += (two_pi * cycles + phi).cos();
        }
        s
    }

    /// Write the multisine sampled at `rate_hz` into `out`.
    pub fn fill(&self, rate_hz: f64, out: &mut [f64]) -> Result<()> {
        check_rate(rate_hz)?;
        self.validate()?;
        // the peak is searched over one period: bound its cost (samples × lines)
        let (k0, k1) = self.harmonics();
        let period = (rate_hz / self.resolution).ceil().max(1.0);
        if period * (k1 - k0 + 1) as f64 > MAX_PEAK_EVALUATIONS {
            return Err(Error::InvalidParameter {
                name: "rate",
                value: rate_hz,
                reason: "too high for this multisine: one period (rate / resolution samples) \
                         times the lines exceeds 1e9 evaluations",
            });
        }
        let period_samples = period as usize;
        let mut peak = 0.0f64;
        for k in 0..period_samples {
            peak = peak.max(self.raw(k as f64 / rate_hz).abs());
        }
        let scale = if peak > 0.0 {
            self.amplitude / peak
        } else {
            0.0
        };
        for (k, x) in out.iter_mut().enumerate() {
            let tau = k as f64 / rate_hz - self.rest;
            *x = if tau < 0.0 {
                0.0
            } else {
                let w = if self.taper > 0.0 {
                    taper(tau / self.taper)
                } else {
                    1.0
                };
                scale * w * self.raw(tau)
            };
        }
        Ok(())
    }

    /// Allocate and return `round(duration·rate_hz)` samples.
    pub fn generate(&self, rate_hz: f64, duration: f64) -> Result<Vec<f64>> {
        let mut out = vec![0.0; sample_count(rate_hz, duration)?];
        self.fill(rate_hz, &mut out)?;
        Ok(out)
    }
}

/// The default multisine (0.03 mm peak, 1 … 200 Hz, 1 Hz lines) at `rate_hz`.
///
/// ```
/// let x = feedid::signal::multisine(5000.0, 1.1).unwrap();
/// assert!(x.iter().all(|v| v.abs() <= 3e-5 + 1e-18));
/// ```
pub fn multisine(rate_hz: f64, duration: f64) -> Result<Vec<f64>> {
    Multisine::default().generate(rate_hz, duration)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spectrum_is_flat_over_the_band_and_empty_outside() {
        // one full period without rest/taper: DFT lines k = 5 … 20 equal, others ~0
        let m = Multisine {
            f_low: 5.0,
            f_high: 20.0,
            resolution: 1.0,
            taper: 0.0,
            rest: 0.0,
            ..Multisine::default()
        };
        let n = 1000;
        let x = m.generate(1000.0, 1.0).unwrap();
        assert_eq!(x.len(), n);
        let mag = |k: usize| {
            let (mut re, mut im) = (0.0, 0.0);
            for (j, v) in x.iter().enumerate() {
                let a = 2.0 * std::f64::consts::PI * (k * j) as f64 / n as f64;
                re += v * a.cos();
                im -= v * a.sin();
            }
            (re * re + im * im).sqrt()
        };
        let ref_mag = mag(5);
        for k in 5..=20 {
            assert!((mag(k) / ref_mag - 1.0).abs() < 1e-9, "k={k}");
        }
        for k in [0, 1, 4, 21, 100] {
            assert!(mag(k) < 1e-9 * ref_mag, "k={k}");
        }
        let peak = x.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        assert!((peak - 3e-5).abs() < 1e-18);
    }

    #[test]
    fn schroeder_phases_give_low_crest_factor() {
        let m = Multisine {
            taper: 0.0,
            rest: 0.0,
            ..Multisine::default()
        };
        let x = m.generate(5000.0, 1.0).unwrap();
        let rms = (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt();
        let crest = 3e-5 / rms;
        // zero-phase multisine of 200 lines has crest 20; Schroeder about 1.7
        assert!(crest < 2.0, "crest factor {crest}");
    }

    #[test]
    fn empty_band_is_rejected() {
        let m = Multisine {
            f_low: 10.2,
            f_high: 10.8,
            ..Multisine::default()
        };
        assert!(m.generate(5000.0, 1.0).is_err());
    }
}
