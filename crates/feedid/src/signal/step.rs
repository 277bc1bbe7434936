//! Step command (paper: 1 mm reached in 0.2 ms).
//!
//! A step with a finite rise: a linear rise of height `h` over `t_rise` after a rest `t_r`:
//!
//! ```text
//! x_s(t) = 0                           t < t_r
//!        = h·(t − t_r)/t_rise          t_r ≤ t < t_r + t_rise
//!        = h                           t ≥ t_r + t_rise
//! ```
//!
//! Defaults: `h` = 0.001 m, `t_rise` = 0.0002 s (one sample at 5 kHz),
//! `t_r` = 0.010 s. `t_rise = 0` gives an ideal step at `t_r`. For the linear
//! default rig the 10–90 % rise time is about 1.0 ms and it settles in about 7 ms.

use serde::{Deserialize, Serialize};

use super::common::{check_finite, check_non_negative, check_rate, sample_count};
use super::ramp::linear_rise;
use crate::error::Result;

/// Step of finite rise time after a rest.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Step {
    /// Step height h \[m\]; default 0.001 (may be negative).
    pub height: f64,
    /// Rise time t_rise \[s\]; default 0.0002 (0 = ideal step).
    pub rise_time: f64,
    /// Rest before motion t_r \[s\]; default 0.010.
    pub rest: f64,
}

impl Default for Step {
    fn default() -> Self {
        Self {
            height: 0.001,
            rise_time: 0.0002,
            rest: 0.010,
        }
    }
}

impl Step {
    /// Check the parameters.
    pub fn validate(&self) -> Result<()> {
        check_finite("step.height", self.height)?;
        check_non_negative("step.rise_time", self.rise_time)?;
        check_non_negative("step.rest", self.rest)
    }

    /// Command position at time `t` \[s\] → \[m\].
    pub fn value_at(&self, t: f64) -> f64 {
        linear_rise(t, self.rest, self.rise_time, self.height)
    }

    /// Write the command sampled at `rate_hz` (times `k/rate_hz`) into `out`.
    pub fn fill(&self, rate_hz: f64, out: &mut [f64]) -> Result<()> {
        check_rate(rate_hz)?;
        self.validate()?;
        for (k, x) in out.iter_mut().enumerate() {
            *x = self.value_at(k as f64 / rate_hz);
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

/// The paper's step (1 mm in 0.2 ms after a 10 ms rest), sampled at `rate_hz` for `duration` s.
///
/// ```
/// let x = feedid::signal::step(5000.0, 0.05).unwrap();
/// assert_eq!(x[50], 0.0);       // t = 10 ms: start of motion
/// assert_eq!(x[51], 0.001);     // t = 10.2 ms: 1 mm reached
/// ```
pub fn step(rate_hz: f64, duration: f64) -> Result<Vec<f64>> {
    Step::default().generate(rate_hz, duration)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_step_reaches_one_mm_in_two_tenths_of_a_millisecond() {
        let s = Step::default();
        assert_eq!(s.value_at(0.0099), 0.0);
        assert!((s.value_at(0.0101) - 0.0005).abs() < 1e-12);
        assert_eq!(s.value_at(0.0102), 0.001);
        let x = step(20_000.0, 0.02).unwrap();
        // at 20 kHz the rise spans 4 intervals: 0, .25, .5, .75, 1 mm
        for (j, k) in (200..=204).enumerate() {
            assert!((x[k] - 0.00025 * j as f64).abs() < 1e-15, "k={k}");
        }
    }

    #[test]
    fn zero_rise_time_is_an_ideal_step() {
        let s = Step {
            rise_time: 0.0,
            ..Step::default()
        };
        assert_eq!(s.value_at(0.0099999), 0.0);
        assert_eq!(s.value_at(0.01), 0.001);
    }

    #[test]
    fn negative_rise_time_is_rejected() {
        let s = Step {
            rise_time: -1e-4,
            ..Step::default()
        };
        assert!(s.generate(5000.0, 0.05).is_err());
    }
}
