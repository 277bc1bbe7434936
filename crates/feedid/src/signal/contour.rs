//! One axis of a circular contour: `x = R·sin φ` or `x = R·(1 − cos φ)` with
//! the path angle `φ = s/R` driven by a jerk-limited feed.
//!
//! The path length `s(t)` follows the 7-segment [`Scurve`] profile over
//! `S = 2π·R·n` (n turns) with the feed `F` as speed limit and the path
//! acceleration and jerk limits `a_t`, `j`, so the feed ramps up from rest,
//! cruises at `F` and stops at the start point:
//!
//! ```text
//! φ(t) = s(t)/R
//! sine axis:     x_s(t) = R·sin φ(t)             (starts at 0 moving at the feed)
//! cosine axis:   x_s(t) = R·(1 − cos φ(t))       (starts at 0 at rest, reverses at φ = π)
//! ```
//!
//! The two axes together trace the circle `x_sin² + (R − x_cos)² = R²`; each
//! axis reverses twice per turn (the quadrant points where friction shows as
//! "quadrant glitches"). While cruising the centripetal acceleration is
//! `F²/R`. Defaults: `R` = 10 mm, `F` = 50 mm/s, `a_t` = 1 m/s²,
//! `j` = 100 m/s³, one turn, sine axis, rest 0.010 s.

use serde::{Deserialize, Serialize};

use super::common::{check_non_negative, check_positive, check_rate, sample_count};
use super::scurve::{Kinematics, Scurve};
use crate::error::Result;

/// Which axis of the circle a [`Contour`] is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum ContourAxis {
    /// `x = R·sin φ`; the default.
    #[default]
    Sine,
    /// `x = R·(1 − cos φ)`.
    Cosine,
}

/// One axis of a circle traced at a jerk-limited feed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Contour {
    /// Radius R \[m\]; default 0.010.
    pub radius: f64,
    /// Feed (path speed) F \[m/s\]; default 0.050.
    pub feed: f64,
    /// Path acceleration limit a_t while the feed ramps \[m/s²\]; default 1.0.
    pub max_acceleration: f64,
    /// Path jerk j \[m/s³\]; default 100.
    pub jerk: f64,
    /// Number of turns n > 0; default 1.
    pub turns: f64,
    /// Which axis; default [`ContourAxis::Sine`].
    pub axis: ContourAxis,
    /// Rest before the feed starts \[s\]; default 0.010.
    pub rest: f64,
}

impl Default for Contour {
    fn default() -> Self {
        Self {
            radius: 0.010,
            feed: 0.050,
            max_acceleration: 1.0,
            jerk: 100.0,
            turns: 1.0,
            axis: ContourAxis::Sine,
            rest: 0.010,
        }
    }
}

impl Contour {
    /// Check the parameters.
    pub fn validate(&self) -> Result<()> {
        check_positive("contour.radius", self.radius)?;
        check_positive("contour.feed", self.feed)?;
        check_positive("contour.max_acceleration", self.max_acceleration)?;
        check_positive("contour.jerk", self.jerk)?;
        check_positive("contour.turns", self.turns)?;
        check_non_negative("contour.rest", self.rest)
    }

    /// The path-length profile s(t) \[m\].
    pub fn path(&self) -> Scurve {
        Scurve {
            distance: 2.0 * std::f64::consts::PI * self.radius * self.turns,
            max_velocity: self.feed,
            max_acceleration: self.max_acceleration,
            jerk: self.jerk,
            rest: self.rest,
        }
    }

    /// Time the contour ends (back at the start point, at rest) \[s\].
    pub fn end_of_motion(&self) -> f64 {
        self.path().end_of_motion()
    }

    /// Position, speed and acceleration of the axis at time `t` \[s\].
    pub fn state_at(&self, t: f64) -> Kinematics {
        self.state_on(&self.path(), t)
    }

    fn state_on(&self, path: &Scurve, t: f64) -> Kinematics {
        let s = path.state_at(t);
        let r = self.radius;
        let phi = s.position / r;
        let (sin, cos) = phi.sin_cos();
        // x = R·f(φ): ẋ = f'(φ)·ṡ, ẍ = f'(φ)·s̈ + f''(φ)·ṡ²/R
        let (f, df, ddf) = match self.axis {
            ContourAxis::Sine => (sin, cos, -sin),
            ContourAxis::Cosine => (1.0 - cos, sin, cos),
        };
        Kinematics {
            position: r * f,
            velocity: df * s.velocity,
            acceleration: df * s.acceleration + ddf * s.velocity * s.velocity / r,
        }
    }

    /// Command position at time `t` \[s\] → \[m\].
    pub fn value_at(&self, t: f64) -> f64 {
        self.state_at(t).position
    }

    /// Write the command sampled at `rate_hz` (times `k/rate_hz`) into `out`.
    pub fn fill(&self, rate_hz: f64, out: &mut [f64]) -> Result<()> {
        check_rate(rate_hz)?;
        self.validate()?;
        let path = self.path();
        for (k, x) in out.iter_mut().enumerate() {
            *x = self.state_on(&path, k as f64 / rate_hz).position;
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

/// The default contour axis (sine axis of a 10 mm circle at 50 mm/s) sampled at `rate_hz`.
///
/// ```
/// let x = feedid::signal::contour(1000.0, 1.5).unwrap();
/// assert!(x.iter().all(|v| v.abs() <= 0.010 + 1e-15));
/// assert!(x.last().unwrap().abs() < 1e-12); // one turn: back at the start
/// ```
pub fn contour(rate_hz: f64, duration: f64) -> Result<Vec<f64>> {
    Contour::default().generate(rate_hz, duration)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sine_and_cosine_axes_trace_the_circle() {
        let sin = Contour {
            radius: 0.05,
            feed: 0.2,
            turns: 2.0,
            ..Contour::default()
        };
        let cos = Contour {
            axis: ContourAxis::Cosine,
            ..sin
        };
        let rate = 2000.0;
        let duration = sin.end_of_motion() + 0.1;
        let xs = sin.generate(rate, duration).unwrap();
        let xc = cos.generate(rate, duration).unwrap();
        for (a, b) in xs.iter().zip(&xc) {
            let r2 = a * a + (0.05 - b) * (0.05 - b);
            assert!((r2 - 0.0025).abs() < 1e-15, "{r2}");
        }
        assert_eq!(xs[0], 0.0);
        assert_eq!(xc[0], 0.0);
        // two turns: the sine axis crosses zero 4 times (plus the start and end)
        let reversals = xc
            .windows(3)
            .filter(|w| (w[1] - w[0]) * (w[2] - w[1]) < 0.0)
            .count();
        assert_eq!(reversals, 3, "cosine axis reverses at φ = π, 2π, 3π");
        assert!(xs.last().unwrap().abs() < 1e-12 && xc.last().unwrap().abs() < 1e-12);
    }

    #[test]
    fn while_cruising_the_axis_is_a_sine_of_angular_rate_feed_over_radius() {
        let c = Contour {
            radius: 0.02,
            feed: 0.1,
            max_acceleration: 2.0,
            jerk: 200.0,
            turns: 3.0,
            ..Contour::default()
        };
        let plan = c.path().plan();
        // cruise from rest + accel phase; its path length at the start:
        let t0 = c.rest + 2.0 * plan.t_jerk + plan.t_accel;
        let s0 = c.path().state_at(t0).position;
        assert!((c.path().state_at(t0).velocity - 0.1).abs() < 1e-12);
        for k in 0..100 {
            let t = t0 + k as f64 * 0.01;
            let want = 0.02 * ((s0 + 0.1 * (t - t0)) / 0.02).sin();
            assert!((c.value_at(t) - want).abs() < 1e-12, "t {t}");
            // centripetal acceleration F²/R at the reversal of the sine axis
            let st = c.state_at(t);
            let w = 0.1 / 0.02;
            assert!((st.velocity - 0.1 * ((s0 + 0.1 * (t - t0)) / 0.02).cos()).abs() < 1e-10);
            assert!((st.acceleration + w * w * st.position).abs() < 1e-9);
        }
    }

    #[test]
    fn analytic_speed_matches_finite_differences() {
        let c = Contour {
            axis: ContourAxis::Cosine,
            ..Contour::default()
        };
        let h = 1e-7;
        for k in 1..50 {
            let t = c.rest + k as f64 * 0.03;
            let fd = (c.value_at(t + h) - c.value_at(t - h)) / (2.0 * h);
            assert!((fd - c.state_at(t).velocity).abs() < 1e-6, "t {t}");
        }
    }

    #[test]
    fn invalid_contours_are_rejected() {
        for c in [
            Contour {
                radius: 0.0,
                ..Contour::default()
            },
            Contour {
                turns: -1.0,
                ..Contour::default()
            },
        ] {
            assert!(c.generate(1000.0, 1.0).is_err(), "{c:?}");
        }
    }
}
