//! Chirp: position sine sweep with raised-cosine onset and fade-out.
//!
//! Over the sweep interval `[t_r, t_end]` of length `T` (`t_end` = end of the buffer):
//!
//! ```text
//! x_s(t) = A·w(t)·sin φ(t),   τ = t − t_r
//! linear:       f(τ) = f0 + (f1 − f0)·τ/T,     φ = 2π·(f0·τ + (f1 − f0)·τ²/(2T))
//! logarithmic:  f(τ) = f0·(f1/f0)^(τ/T),       φ = 2π·f0·T/ln(f1/f0)·((f1/f0)^(τ/T) − 1)
//! w(t) = taper(τ/T_w)·taper((T − τ)/T_w),      taper(s) = (1 − cos πs)/2 on [0, 1]
//! ```
//!
//! so position, speed and acceleration start and end at zero. Defaults:
//! amplitude `A` = 0.03 mm, `f0` = 1 Hz, `f1` = 200 Hz, logarithmic sweep,
//! taper `T_w` = 0.05 s, rest `t_r` = 0.010 s. The amplitude keeps the default
//! rig inside its 10 A current limit (linear model: 7.4 A peak at the top of
//! the sweep); 0.1 mm would ask for 25 A and saturate the drive.

use serde::{Deserialize, Serialize};

use super::common::{check_non_negative, check_positive, check_rate, sample_count, taper};
use crate::error::{Error, Result};

/// Frequency law of a [`Chirp`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Sweep {
    /// Frequency rises linearly with time.
    Linear,
    /// Frequency rises exponentially (equal time per octave); the default.
    #[default]
    Logarithmic,
}

/// Sine sweep of position.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Chirp {
    /// Amplitude A \[m\]; default 3e-5.
    pub amplitude: f64,
    /// Start frequency f0 \[Hz\]; default 1.
    pub f_start: f64,
    /// End frequency f1 \[Hz\]; default 200.
    pub f_end: f64,
    /// Frequency law; default logarithmic.
    pub sweep: Sweep,
    /// Raised-cosine onset and fade-out length T_w \[s\]; default 0.05.
    pub taper: f64,
    /// Rest before the sweep t_r \[s\]; default 0.010.
    pub rest: f64,
}

impl Default for Chirp {
    fn default() -> Self {
        Self {
            amplitude: 3e-5,
            f_start: 1.0,
            f_end: 200.0,
            sweep: Sweep::Logarithmic,
            taper: 0.05,
            rest: 0.010,
        }
    }
}

impl Chirp {
    /// Check the parameters.
    pub fn validate(&self) -> Result<()> {
        check_non_negative("chirp.amplitude", self.amplitude)?;
        check_positive("chirp.f_start", self.f_start)?;
        check_positive("chirp.f_end", self.f_end)?;
        check_non_negative("chirp.taper", self.taper)?;
        check_non_negative("chirp.rest", self.rest)
    }

    /// Instantaneous frequency at time `tau` \[s\] after the start of a sweep of length `sweep` \[s\] → \[Hz\].
    pub fn frequency_at(&self, tau: f64, sweep: f64) -> f64 {
        let s = (tau / sweep).clamp(0.0, 1.0);
        match self.sweep {
            Sweep::Linear => self.f_start + (self.f_end - self.f_start) * s,
            Sweep::Logarithmic => self.f_start * (self.f_end / self.f_start).powf(s),
        }
    }

    /// Command at time `t` \[s\] for a sweep ending at `end` \[s\] → \[m\].
    pub fn value_at(&self, t: f64, end: f64) -> f64 {
        let sweep = end - self.rest;
        let tau = t - self.rest;
        if sweep <= 0.0 || tau <= 0.0 || tau >= sweep {
            return 0.0;
        }
        let two_pi = 2.0 * std::f64::consts::PI;
        let (f0, f1) = (self.f_start, self.f_end);
        let ratio = f1 / f0;
        let phase = if matches!(self.sweep, Sweep::Linear) || (ratio - 1.0).abs() < 1e-12 {
            two_pi * (f0 * tau + (f1 - f0) * tau * tau / (2.0 * sweep))
        } else {
            let lr = ratio.ln();
            two_pi * f0 * sweep / lr * ((lr * tau / sweep).exp() - 1.0)
        };
        let w = if self.taper > 0.0 {
            taper(tau / self.taper) * taper((sweep - tau) / self.taper)
        } else {
            1.0
        };
        self.amplitude * w * phase.sin()
    }

    /// Write the sweep sampled at `rate_hz` into `out`; it ends at the last sample.
    pub fn fill(&self, rate_hz: f64, out: &mut [f64]) -> Result<()> {
        check_rate(rate_hz)?;
        self.validate()?;
        let end = out.len().saturating_sub(1) as f64 / rate_hz;
        if end <= self.rest + 2.0 * self.taper {
            return Err(Error::InvalidParameter {
                name: "duration",
                value: end,
                reason: "too short for the chirp rest and tapers",
            });
        }
        for (k, x) in out.iter_mut().enumerate() {
            *x = self.value_at(k as f64 / rate_hz, end);
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

/// The default chirp (0.03 mm, 1 → 200 Hz logarithmic) filling `duration` s at `rate_hz`.
///
/// ```
/// let x = feedid::signal::chirp(5000.0, 2.0).unwrap();
/// assert_eq!(x.len(), 10_000);
/// assert!(x.iter().all(|v| v.abs() <= 3e-5));
/// ```
pub fn chirp(rate_hz: f64, duration: f64) -> Result<Vec<f64>> {
    Chirp::default().generate(rate_hz, duration)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chirp_starts_smoothly_and_stays_within_amplitude() {
        let rate = 5000.0;
        let x = chirp(rate, 2.0).unwrap();
        assert!(x[..=50].iter().all(|&v| v == 0.0));
        // smooth onset: the first samples after the rest are tiny (taper ~ τ²)
        assert!(x[51].abs() < 1e-9, "{}", x[51]);
        assert!(x.iter().all(|v| v.abs() <= 3e-5 + 1e-18));
        assert!(x.iter().any(|v| v.abs() > 0.9 * 3e-5));
        assert!(x.last().unwrap().abs() < 1e-12);
    }

    #[test]
    fn zero_crossings_follow_the_sweep_frequency() {
        // linear sweep, no taper: count zero crossings = 2·∫f dτ = (f0+f1)·T
        let c = Chirp {
            sweep: Sweep::Linear,
            f_start: 10.0,
            f_end: 50.0,
            taper: 0.0,
            rest: 0.0,
            ..Chirp::default()
        };
        let x = c.generate(50_000.0, 1.0).unwrap();
        let crossings = x.windows(2).filter(|w| w[0] * w[1] < 0.0).count() as f64;
        assert!((crossings - 60.0).abs() <= 1.0, "{crossings}");
        // logarithmic: ∫f = f0·T·(r − 1)/ln r
        let c = Chirp {
            sweep: Sweep::Logarithmic,
            ..c
        };
        let x = c.generate(50_000.0, 1.0).unwrap();
        let crossings = x.windows(2).filter(|w| w[0] * w[1] < 0.0).count() as f64;
        let expected = 2.0 * 10.0 * 4.0 / 5f64.ln();
        assert!(
            (crossings - expected).abs() <= 1.5,
            "{crossings} vs {expected}"
        );
        assert!((c.frequency_at(0.5, 1.0) - 10.0 * 5f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn too_short_a_chirp_is_rejected() {
        assert!(chirp(5000.0, 0.05).is_err());
    }
}
