//! Square wave of position: alternating moves between 0 and `A`.
//!
//! With period `P`, edge time `t_e` (linear edges; 0 = ideal steps) and rest
//! `t_r`, at phase `φ = (t − t_r) mod P`:
//!
//! ```text
//! x_s(t) = 0                                   t < t_r
//!        = A·min(φ/t_e, 1)                     0 ≤ φ < P/2      (rising edge, then high)
//!        = A·(1 − min((φ − P/2)/t_e, 1))       P/2 ≤ φ < P      (falling edge, then low)
//! ```
//!
//! (`t_e = 0` gives the ideal steps `A` on `[0, P/2)` and `0` on `[P/2, P)`).
//! The wave starts at 0, steps up at `t_r` and has mean `A/2` over whole
//! periods. Defaults: `A` = 1 mm, `P` = 0.2 s, `t_e` = 0, rest 0.010 s. The
//! square wave is a common test of slow actuators and of step response
//! repeatability; like the paper's step it asks for large currents on a stiff
//! axis.

use serde::{Deserialize, Serialize};

use super::common::{check_finite, check_non_negative, check_positive, check_rate, sample_count};
use crate::error::{Error, Result};

/// Square wave of position between 0 and `amplitude`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Square {
    /// Level of the high half A \[m\] (may be negative); default 0.001.
    pub amplitude: f64,
    /// Period P \[s\]; default 0.2.
    pub period: f64,
    /// Duration of each (linear) edge t_e \[s\], at most P/2; default 0 (ideal steps).
    pub edge_time: f64,
    /// Rest before the first edge \[s\]; default 0.010.
    pub rest: f64,
}

impl Default for Square {
    fn default() -> Self {
        Self {
            amplitude: 0.001,
            period: 0.2,
            edge_time: 0.0,
            rest: 0.010,
        }
    }
}

impl Square {
    /// Check the parameters.
    pub fn validate(&self) -> Result<()> {
        check_finite("square.amplitude", self.amplitude)?;
        check_positive("square.period", self.period)?;
        check_non_negative("square.edge_time", self.edge_time)?;
        check_non_negative("square.rest", self.rest)?;
        if self.edge_time > 0.5 * self.period {
            return Err(Error::InvalidParameter {
                name: "square.edge_time",
                value: self.edge_time,
                reason: "must not exceed half the period",
            });
        }
        Ok(())
    }

    /// Command position at time `t` \[s\] → \[m\].
    ///
    /// An instant within 1e-9 half periods of an edge counts as after it, so
    /// samples that fall on an edge by their nominal time do not depend on
    /// the rounding of `k/rate − t_r`.
    pub fn value_at(&self, t: f64) -> f64 {
        let half = 0.5 * self.period;
        let halves = (t - self.rest) / half + 1e-9;
        if halves < 0.0 {
            return 0.0;
        }
        let n = halves.floor();
        let since_edge = ((halves - n - 1e-9).max(0.0)) * half;
        let edge = if self.edge_time > 0.0 {
            (since_edge / self.edge_time).min(1.0)
        } else {
            1.0
        };
        if n.rem_euclid(2.0) == 0.0 {
            self.amplitude * edge
        } else if edge < 1.0 {
            self.amplitude * (1.0 - edge)
        } else {
            0.0
        }
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

/// The default square wave (1 mm, 0.2 s period, ideal edges) sampled at `rate_hz`.
///
/// ```
/// let x = feedid::signal::square(1000.0, 1.0).unwrap();
/// assert_eq!(x[9], 0.0);                       // rest
/// assert_eq!(x[10], 0.001);                    // up at 10 ms
/// assert_eq!(x[110], 0.0);                     // down half a period later
/// ```
pub fn square(rate_hz: f64, duration: f64) -> Result<Vec<f64>> {
    Square::default().generate(rate_hz, duration)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ideal_square_wave_has_the_closed_form_levels_edges_and_mean() {
        // rate 1 kHz, period 0.1 s = 100 samples, rest 10 samples, amplitude 2 mm
        let s = Square {
            amplitude: 0.002,
            period: 0.1,
            edge_time: 0.0,
            rest: 0.01,
        };
        let x = s.generate(1000.0, 1.01).unwrap();
        for (k, &v) in x.iter().enumerate() {
            let want = if k < 10 || ((k - 10) % 100) >= 50 {
                0.0
            } else {
                0.002
            };
            assert_eq!(v, want, "k = {k}");
        }
        // ten whole periods after the rest: mean A/2, ten rising edges
        let body = &x[10..1010];
        let mean = body.iter().sum::<f64>() / body.len() as f64;
        assert!((mean - 0.001).abs() < 1e-15, "{mean}");
        let rising = x.windows(2).filter(|w| w[1] > w[0]).count();
        assert_eq!(rising, 10);
    }

    #[test]
    fn linear_edges_rise_at_amplitude_over_edge_time() {
        let s = Square {
            amplitude: -0.004,
            period: 0.2,
            edge_time: 0.004,
            rest: 0.0,
        };
        let rate = 10_000.0;
        let x = s.generate(rate, 0.4).unwrap();
        // rising edge: slope A/t_e = −1 m/s during the first 4 ms
        for k in 0..40 {
            assert!((x[k + 1] - x[k] - (-1.0 / rate)).abs() < 1e-15, "k = {k}");
        }
        assert!((s.value_at(0.05) + 0.004).abs() < 1e-18);
        // falling edge from t = 0.1 s back to 0 by 0.104 s
        assert!((s.value_at(0.102) + 0.002).abs() < 1e-15);
        assert!(s.value_at(0.15).abs() < 1e-18);
        assert!(x.iter().all(|v| (-0.004..=0.0).contains(v)));
    }

    #[test]
    fn invalid_square_waves_are_rejected() {
        for s in [
            Square {
                period: 0.0,
                ..Square::default()
            },
            Square {
                edge_time: 0.15,
                ..Square::default()
            },
            Square {
                amplitude: f64::NAN,
                ..Square::default()
            },
        ] {
            assert!(s.generate(1000.0, 1.0).is_err(), "{s:?}");
        }
    }
}
