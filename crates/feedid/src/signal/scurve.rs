//! Jerk-limited point-to-point move (7-segment "S-curve" profile).
//!
//! Jerk is piecewise constant over seven segments
//!
//! ```text
//! segment   1    2    3    4    5    6    7
//! jerk     +j    0   −j    0   −j    0   +j
//! length   T_j  T_a  T_j  T_v  T_j  T_a  T_j
//! ```
//!
//! With limits `v_max`, `a_max`, `j` and distance `D` (all magnitudes):
//!
//! * acceleration phase to a peak speed `v_p`: if `v_p ≥ a_max²/j` the
//!   acceleration saturates, `T_j = a_max/j`, `T_a = v_p/a_max − T_j`;
//!   otherwise `T_j = √(v_p/j)`, `T_a = 0` (peak acceleration `√(v_p·j)`);
//! * one acceleration phase covers `v_p·(2T_j + T_a)/2`; if `D ≥ v_max·(2T_j + T_a)`
//!   then `v_p = v_max` and the cruise lasts `T_v = D/v_max − (2T_j + T_a)`;
//! * otherwise `T_v = 0` and `v_p < v_max` solves `v_p·(2T_j + T_a) = D`:
//!   `v_p = (D·√j/2)^{2/3}` if that is `≤ a_max²/j`, else the positive root of
//!   `v_p²/a_max + v_p·a_max/j = D`.
//!
//! Position, speed and acceleration are integrated exactly (cubic per segment);
//! after the last segment the position is set to `D` exactly.
//! Defaults: `D` = 0.020 m, `v_max` = 0.100 m/s, `a_max` = 2 m/s², `j` = 200 m/s³,
//! rest 0.010 s. Reference: L. Biagiotti, C. Melchiorri, *Trajectory Planning
//! for Automatic Machines and Robots*, Springer 2008, §3.4.

use serde::{Deserialize, Serialize};

use super::common::{check_finite, check_non_negative, check_positive, check_rate, sample_count};
use crate::error::Result;

/// Jerk-limited point-to-point move after a rest.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Scurve {
    /// Move distance D \[m\]; default 0.020 (may be negative).
    pub distance: f64,
    /// Speed limit v_max \[m/s\]; default 0.100.
    pub max_velocity: f64,
    /// Acceleration limit a_max \[m/s²\]; default 2.0.
    pub max_acceleration: f64,
    /// Jerk j \[m/s³\]; default 200.
    pub jerk: f64,
    /// Rest before motion \[s\]; default 0.010.
    pub rest: f64,
}

impl Default for Scurve {
    fn default() -> Self {
        Self {
            distance: 0.020,
            max_velocity: 0.100,
            max_acceleration: 2.0,
            jerk: 200.0,
            rest: 0.010,
        }
    }
}

/// Position, speed and acceleration of a trajectory at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Kinematics {
    /// Position \[m\].
    pub position: f64,
    /// Speed \[m/s\].
    pub velocity: f64,
    /// Acceleration \[m/s²\].
    pub acceleration: f64,
}

/// Planned segment times of a [`Scurve`] (all ≥ 0) \[s\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScurvePlan {
    /// Length of each jerk segment T_j \[s\].
    pub t_jerk: f64,
    /// Length of each constant-acceleration segment T_a \[s\].
    pub t_accel: f64,
    /// Length of the cruise segment T_v \[s\].
    pub t_cruise: f64,
    /// Peak speed reached v_p \[m/s\] (magnitude).
    pub peak_velocity: f64,
}

impl ScurvePlan {
    /// Total motion time `4·T_j + 2·T_a + T_v` \[s\].
    pub fn duration(&self) -> f64 {
        4.0 * self.t_jerk + 2.0 * self.t_accel + self.t_cruise
    }
}

impl Scurve {
    /// Check the parameters.
    pub fn validate(&self) -> Result<()> {
        check_finite("scurve.distance", self.distance)?;
        check_positive("scurve.max_velocity", self.max_velocity)?;
        check_positive("scurve.max_acceleration", self.max_acceleration)?;
        check_positive("scurve.jerk", self.jerk)?;
        check_non_negative("scurve.rest", self.rest)
    }

    /// Segment times for the move (see the module doc).
    pub fn plan(&self) -> ScurvePlan {
        let d = self.distance.abs();
        let (vmax, amax, j) = (self.max_velocity, self.max_acceleration, self.jerk);
        let times = |vp: f64| -> (f64, f64) {
            if vp >= amax * amax / j {
                let tj = amax / j;
                (tj, (vp / amax - tj).max(0.0))
            } else {
                ((vp / j).sqrt(), 0.0)
            }
        };
        let (tj, ta) = times(vmax);
        let accel_time = 2.0 * tj + ta;
        if d >= vmax * accel_time {
            return ScurvePlan {
                t_jerk: tj,
                t_accel: ta,
                t_cruise: d / vmax - accel_time,
                peak_velocity: vmax,
            };
        }
        let mut vp = (d * j.sqrt() / 2.0).powf(2.0 / 3.0);
        if vp > amax * amax / j {
            let b = amax / j;
            vp = amax * 0.5 * (-b + (b * b + 4.0 * d / amax).sqrt());
        }
        let (tj, ta) = times(vp);
        ScurvePlan {
            t_jerk: tj,
            t_accel: ta,
            t_cruise: 0.0,
            peak_velocity: vp,
        }
    }

    /// Time at which the move ends \[s\].
    pub fn end_of_motion(&self) -> f64 {
        self.rest + self.plan().duration()
    }

    /// Position, speed and acceleration at time `t` \[s\].
    pub fn state_at(&self, t: f64) -> Kinematics {
        self.state_with_plan(&self.plan(), t)
    }

    fn state_with_plan(&self, plan: &ScurvePlan, t: f64) -> Kinematics {
        let sign = if self.distance < 0.0 { -1.0 } else { 1.0 };
        let tau = t - self.rest;
        if tau <= 0.0 {
            return Kinematics::default();
        }
        if tau >= plan.duration() {
            return Kinematics {
                position: self.distance,
                ..Kinematics::default()
            };
        }
        let j = self.jerk;
        let lengths = [
            plan.t_jerk,
            plan.t_accel,
            plan.t_jerk,
            plan.t_cruise,
            plan.t_jerk,
            plan.t_accel,
            plan.t_jerk,
        ];
        let jerks = [j, 0.0, -j, 0.0, -j, 0.0, j];
        let (mut p, mut v, mut a) = (0.0, 0.0, 0.0);
        let mut rem = tau;
        for (&len, &jk) in lengths.iter().zip(jerks.iter()) {
            let h = rem.min(len);
            p += v * h + a * h * h / 2.0 + jk * h * h * h / 6.0;
            v += a * h + jk * h * h / 2.0;
            a += jk * h;
            rem -= h;
            if rem <= 0.0 {
                break;
            }
        }
        Kinematics {
            position: sign * p,
            velocity: sign * v,
            acceleration: sign * a,
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
        let plan = self.plan();
        for (k, x) in out.iter_mut().enumerate() {
            *x = self.state_with_plan(&plan, k as f64 / rate_hz).position;
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

/// The default jerk-limited move (20 mm, 100 mm/s, 2 m/s², 200 m/s³) sampled at `rate_hz`.
///
/// ```
/// let x = feedid::signal::scurve(5000.0, 0.4).unwrap();
/// assert_eq!(*x.last().unwrap(), 0.020);
/// ```
pub fn scurve(rate_hz: f64, duration: f64) -> Result<Vec<f64>> {
    Scurve::default().generate(rate_hz, duration)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Check limits by finite differences of a finely sampled profile and the
    /// end point, for a profile that reaches every limit and ones that do not.
    fn check_limits(s: &Scurve) {
        let plan = s.plan();
        let end = s.end_of_motion();
        let rate = 200_000.0;
        let x = s.generate(rate, end + 0.01).unwrap();
        let dt = 1.0 / rate;
        let (mut vpk, mut apk, mut jpk) = (0.0f64, 0.0f64, 0.0f64);
        for k in 0..x.len() - 3 {
            let v = (x[k + 1] - x[k]) / dt;
            let a = (x[k + 2] - 2.0 * x[k + 1] + x[k]) / (dt * dt);
            let j = (x[k + 3] - 3.0 * x[k + 2] + 3.0 * x[k + 1] - x[k]) / (dt * dt * dt);
            vpk = vpk.max(v.abs());
            apk = apk.max(a.abs());
            jpk = jpk.max(j.abs());
        }
        assert!(
            vpk <= s.max_velocity * (1.0 + 1e-6),
            "v {vpk} plan {plan:?}"
        );
        assert!(apk <= s.max_acceleration * (1.0 + 1e-3), "a {apk}");
        // third differences straddling a jerk switch average the jerk; never exceed it
        assert!(jpk <= s.jerk * (1.0 + 1e-2), "j {jpk}");
        // analytic state: continuous speed / acceleration, exact end point
        let st = s.state_at(end - 1e-12);
        assert!((st.position - s.distance).abs() < 1e-12, "{st:?}");
        assert!(
            st.velocity.abs() < 1e-8 && st.acceleration.abs() < 1e-6,
            "{st:?}"
        );
        assert_eq!(s.value_at(end), s.distance);
        assert_eq!(*x.last().unwrap(), s.distance);
        for k in 0..200 {
            let t = s.rest + end * k as f64 / 200.0;
            let st = s.state_at(t);
            assert!(st.velocity.abs() <= s.max_velocity * (1.0 + 1e-12));
            assert!(st.acceleration.abs() <= s.max_acceleration * (1.0 + 1e-12));
        }
    }

    #[test]
    fn default_move_respects_vmax_amax_jerk_and_ends_exactly() {
        let s = Scurve::default();
        let p = s.plan();
        // T_j = a/j = 10 ms, T_a = v/a − T_j = 40 ms, T_v = D/v − (2T_j+T_a) = 140 ms
        assert!((p.t_jerk - 0.01).abs() < 1e-15);
        assert!((p.t_accel - 0.04).abs() < 1e-15);
        assert!((p.t_cruise - 0.14).abs() < 1e-12);
        check_limits(&s);
        // peak speed and acceleration are reached
        assert!((s.state_at(s.rest + 0.1).velocity - 0.1).abs() < 1e-12);
        assert!((s.state_at(s.rest + 0.03).acceleration - 2.0).abs() < 1e-12);
    }

    #[test]
    fn short_move_without_cruise_respects_limits() {
        // amax reached, vmax not
        check_limits(&Scurve {
            distance: 0.004,
            ..Scurve::default()
        });
        // neither reached
        check_limits(&Scurve {
            distance: 0.0002,
            ..Scurve::default()
        });
        // amax never reachable (v < a²/j), negative direction
        check_limits(&Scurve {
            distance: -0.01,
            max_velocity: 0.01,
            ..Scurve::default()
        });
    }

    #[test]
    fn invalid_limits_are_rejected() {
        let s = Scurve {
            jerk: 0.0,
            ..Scurve::default()
        };
        assert!(s.generate(5000.0, 0.4).is_err());
    }
}
