//! Ramp command (paper: 30 mm at 50 mm/s).
//!
//! ```text
//! x_s(t) = 0                      t < t_r
//!        = v·(t − t_r)            t_r ≤ t < t_r + D/v
//!        = D                      t ≥ t_r + D/v
//! ```
//!
//! `D` distance \[m\] (default 0.030, may be negative), `v` speed \[m/s\]
//! (default 0.050), `t_r` rest before motion \[s\] (default 0.010). The steady
//! following error of a P position loop on this ramp is `v/Kv`.

use serde::{Deserialize, Serialize};

use super::common::{check_finite, check_non_negative, check_positive, check_rate, sample_count};
use crate::error::Result;

/// Linear move from 0 to `distance` at constant speed after a rest.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Ramp {
    /// Move distance D \[m\]; default 0.030 (may be negative).
    pub distance: f64,
    /// Speed v \[m/s\]; default 0.050.
    pub velocity: f64,
    /// Rest before motion t_r \[s\]; default 0.010.
    pub rest: f64,
}

impl Default for Ramp {
    fn default() -> Self {
        Self {
            distance: 0.030,
            velocity: 0.050,
            rest: 0.010,
        }
    }
}

impl Ramp {
    /// Check the parameters.
    pub fn validate(&self) -> Result<()> {
        check_finite("ramp.distance", self.distance)?;
        check_positive("ramp.velocity", self.velocity)?;
        check_non_negative("ramp.rest", self.rest)
    }

    /// Time at which the ramp reaches `distance` \[s\].
    pub fn end_of_motion(&self) -> f64 {
        self.rest + self.distance.abs() / self.velocity
    }

    /// Command position at time `t` \[s\] → \[m\].
    pub fn value_at(&self, t: f64) -> f64 {
        linear_rise(
            t,
            self.rest,
            self.distance.abs() / self.velocity,
            self.distance,
        )
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

/// The paper's ramp (30 mm at 50 mm/s after a 10 ms rest), sampled at `rate_hz` for `duration` s.
///
/// ```
/// let x = feedid::signal::ramp(5000.0, 0.8).unwrap();
/// assert_eq!(x.len(), 4000);
/// assert_eq!(x[0], 0.0);
/// assert!((x[3999] - 0.030).abs() < 1e-15);
/// ```
pub fn ramp(rate_hz: f64, duration: f64) -> Result<Vec<f64>> {
    Ramp::default().generate(rate_hz, duration)
}

/// 0 before `start`, linear rise to `height` over `rise` s, then `height`.
pub(crate) fn linear_rise(t: f64, start: f64, rise: f64, height: f64) -> f64 {
    if t < start {
        0.0
    } else if rise <= 0.0 || t >= start + rise {
        height
    } else {
        height * ((t - start) / rise)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_ramp_rises_at_fifty_mm_per_second_then_holds_thirty_mm() {
        let x = ramp(5000.0, 1.0).unwrap();
        let dt = 1.0 / 5000.0;
        // rest: first 10 ms (50 samples) at 0
        assert!(x[..=50].iter().all(|&v| v == 0.0));
        // constant slope during the move (0.01 s … 0.61 s)
        for k in 51..3050 {
            let slope = (x[k + 1] - x[k]) / dt;
            assert!((slope - 0.05).abs() < 1e-9, "k={k} slope={slope}");
        }
        assert!(x[3050..].iter().all(|&v| (v - 0.030).abs() < 1e-15));
    }

    #[test]
    fn negative_distance_moves_backwards() {
        let r = Ramp {
            distance: -0.01,
            ..Ramp::default()
        };
        assert!((r.value_at(0.11) + 0.005).abs() < 1e-15);
        assert_eq!(r.value_at(1.0), -0.01);
    }

    #[test]
    fn zero_velocity_is_rejected() {
        let r = Ramp {
            velocity: 0.0,
            ..Ramp::default()
        };
        assert!(r.generate(5000.0, 1.0).is_err());
        assert!(ramp(0.0, 1.0).is_err());
        assert!(ramp(5000.0, f64::NAN).is_err());
    }
}
