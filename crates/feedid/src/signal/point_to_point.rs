//! Random point-to-point moves with dwells: jerk-limited moves between random
//! targets, each followed by a dwell, as in a machining or handling program.
//!
//! From the rest position 0 (after a rest `t_r`), move `i` goes from the
//! previous target `p_{i−1}` to a target `p_i` drawn uniformly from
//! `[−A, A]` (redrawn while `|p_i − p_{i−1}| < m·A`, `m` the minimum move
//! share), with the 7-segment [`Scurve`] profile of limits `v_max`, `a_max`,
//! `j`; it then dwells `T_d,i` drawn uniformly from `[T_d,min, T_d,max]`:
//!
//! ```text
//! t_0 = t_r,   t_{i+1} = t_i + T_move(p_i − p_{i−1}) + T_d,i
//! x_s(t) = p_{i−1} + S_i(t − t_i)       t_i ≤ t < t_{i+1}   (S_i the S-curve of move i)
//! ```
//!
//! so the command rests exactly at every target during its dwell. Draws come
//! from a ChaCha8 generator seeded with the `seed` argument: the same seed
//! gives the same program. Defaults: `A` = 10 mm, `v_max` = 50 mm/s,
//! `a_max` = 1 m/s², `j` = 100 m/s³, dwells 50 … 300 ms, `m` = 0.1, rest
//! 0.010 s.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::common::{check_non_negative, check_positive, check_rate, sample_count};
use super::scurve::{Kinematics, Scurve};
use crate::error::{Error, Result};

/// Most moves of one program (a guard against degenerate settings): 1e6.
const MAX_MOVES: usize = 1_000_000;

/// Random jerk-limited point-to-point moves with dwells.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PointToPoint {
    /// Targets lie in `[−A, A]`, A \[m\] > 0; default 0.010.
    pub amplitude: f64,
    /// Speed limit v_max \[m/s\]; default 0.050.
    pub max_velocity: f64,
    /// Acceleration limit a_max \[m/s²\]; default 1.0.
    pub max_acceleration: f64,
    /// Jerk j \[m/s³\]; default 100.
    pub jerk: f64,
    /// Shortest dwell after a move \[s\]; default 0.05.
    pub dwell_min: f64,
    /// Longest dwell after a move \[s\]; default 0.3.
    pub dwell_max: f64,
    /// Shortest move as a share of A, 0 … 1; default 0.1.
    pub min_move: f64,
    /// Rest before the first move \[s\]; default 0.010.
    pub rest: f64,
}

impl Default for PointToPoint {
    fn default() -> Self {
        Self {
            amplitude: 0.010,
            max_velocity: 0.050,
            max_acceleration: 1.0,
            jerk: 100.0,
            dwell_min: 0.05,
            dwell_max: 0.3,
            min_move: 0.1,
            rest: 0.010,
        }
    }
}

/// One planned move of a [`PointToPoint`] program.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlannedMove {
    /// Time the move starts \[s\].
    pub start: f64,
    /// Position before the move \[m\].
    pub from: f64,
    /// Target \[m\].
    pub to: f64,
    /// Time the move ends (the dwell starts) \[s\].
    pub end_of_motion: f64,
    /// Time the dwell ends (the next move starts) \[s\].
    pub end_of_dwell: f64,
}

impl PlannedMove {
    fn profile(&self, p: &PointToPoint) -> Scurve {
        Scurve {
            distance: self.to - self.from,
            max_velocity: p.max_velocity,
            max_acceleration: p.max_acceleration,
            jerk: p.jerk,
            rest: 0.0,
        }
    }
}

impl PointToPoint {
    /// Check the parameters.
    pub fn validate(&self) -> Result<()> {
        check_positive("point_to_point.amplitude", self.amplitude)?;
        check_positive("point_to_point.max_velocity", self.max_velocity)?;
        check_positive("point_to_point.max_acceleration", self.max_acceleration)?;
        check_positive("point_to_point.jerk", self.jerk)?;
        check_non_negative("point_to_point.dwell_min", self.dwell_min)?;
        check_non_negative("point_to_point.dwell_max", self.dwell_max)?;
        check_non_negative("point_to_point.rest", self.rest)?;
        if self.dwell_max < self.dwell_min {
            return Err(Error::InvalidParameter {
                name: "point_to_point.dwell_max",
                value: self.dwell_max,
                reason: "must not be below dwell_min",
            });
        }
        if !(0.0..=1.0).contains(&self.min_move) {
            return Err(Error::InvalidParameter {
                name: "point_to_point.min_move",
                value: self.min_move,
                reason: "must be between 0 and 1",
            });
        }
        Ok(())
    }

    /// The moves of the program drawn with `seed` that start before `end` \[s\].
    pub fn plan(&self, seed: u64, end: f64) -> Result<Vec<PlannedMove>> {
        self.validate()?;
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let a = self.amplitude;
        let mut moves = Vec::new();
        let (mut t, mut from) = (self.rest, 0.0);
        while t < end {
            if moves.len() >= MAX_MOVES {
                return Err(Error::InvalidParameter {
                    name: "duration",
                    value: end,
                    reason: "needs more than 1e6 point-to-point moves",
                });
            }
            let mut to = from;
            for _ in 0..32 {
                to = -a + 2.0 * a * rng.random::<f64>();
                if (to - from).abs() >= self.min_move * a {
                    break;
                }
            }
            if (to - from).abs() < self.min_move * a {
                to = if from > 0.0 { -a } else { a };
            }
            let dwell = self.dwell_min + (self.dwell_max - self.dwell_min) * rng.random::<f64>();
            let mut m = PlannedMove {
                start: t,
                from,
                to,
                end_of_motion: t,
                end_of_dwell: t,
            };
            m.end_of_motion = t + m.profile(self).plan().duration();
            m.end_of_dwell = m.end_of_motion + dwell;
            moves.push(m);
            t = m.end_of_dwell;
            from = to;
        }
        Ok(moves)
    }

    /// Position, speed and acceleration of the planned program `moves` at time `t` \[s\].
    pub fn state_at(&self, moves: &[PlannedMove], t: f64) -> Kinematics {
        let i = moves.partition_point(|m| m.start <= t);
        if i == 0 {
            return Kinematics::default();
        }
        let m = &moves[i - 1];
        if t >= m.end_of_motion {
            return Kinematics {
                position: m.to,
                ..Kinematics::default()
            };
        }
        let s = m.profile(self).state_at(t - m.start);
        Kinematics {
            position: m.from + s.position,
            ..s
        }
    }

    /// Write the program drawn with `seed`, sampled at `rate_hz`, into `out`.
    pub fn fill(&self, rate_hz: f64, seed: u64, out: &mut [f64]) -> Result<()> {
        check_rate(rate_hz)?;
        let end = out.len() as f64 / rate_hz;
        let moves = self.plan(seed, end)?;
        for (k, x) in out.iter_mut().enumerate() {
            *x = self.state_at(&moves, k as f64 / rate_hz).position;
        }
        Ok(())
    }

    /// Allocate and return `round(duration·rate_hz)` samples of the program drawn with `seed`.
    pub fn generate(&self, rate_hz: f64, duration: f64, seed: u64) -> Result<Vec<f64>> {
        let mut out = vec![0.0; sample_count(rate_hz, duration)?];
        self.fill(rate_hz, seed, &mut out)?;
        Ok(out)
    }
}

/// The default point-to-point program (targets in ±10 mm) drawn with `seed`, sampled at `rate_hz`.
///
/// ```
/// let x = feedid::signal::point_to_point(1000.0, 2.0, 7).unwrap();
/// assert_eq!(x.len(), 2000);
/// assert!(x.iter().all(|v| v.abs() <= 0.010));
/// assert_eq!(x, feedid::signal::point_to_point(1000.0, 2.0, 7).unwrap());
/// ```
pub fn point_to_point(rate_hz: f64, duration: f64, seed: u64) -> Result<Vec<f64>> {
    PointToPoint::default().generate(rate_hz, duration, seed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_command_dwells_exactly_at_every_target_and_respects_the_limits() {
        let p = PointToPoint {
            amplitude: 0.02,
            ..PointToPoint::default()
        };
        let rate = 20_000.0;
        let duration = 3.0;
        let x = p.generate(rate, duration, 11).unwrap();
        let moves = p.plan(11, duration).unwrap();
        assert!(moves.len() >= 5, "{}", moves.len());
        let dt = 1.0 / rate;
        for (i, m) in moves.iter().enumerate() {
            // chained: each move starts where the previous ended, after its dwell
            if i > 0 {
                assert_eq!(m.from, moves[i - 1].to);
                assert_eq!(m.start, moves[i - 1].end_of_dwell);
            }
            assert!(m.to.abs() <= p.amplitude);
            assert!((m.to - m.from).abs() >= p.min_move * p.amplitude);
            let dwell = m.end_of_dwell - m.end_of_motion;
            assert!(
                dwell >= p.dwell_min && dwell <= p.dwell_max,
                "dwell {dwell}"
            );
            // during the dwell the command is the target, exactly
            let k0 = (m.end_of_motion * rate).ceil() as usize;
            let k1 = ((m.end_of_dwell * rate).floor() as usize).min(x.len());
            for (k, &v) in x.iter().enumerate().take(k1).skip(k0) {
                if (k as f64) * dt < m.end_of_dwell {
                    assert_eq!(v, m.to, "move {i} k {k}");
                }
            }
        }
        // finite differences stay inside the limits
        for k in 0..x.len() - 2 {
            let v = (x[k + 1] - x[k]) / dt;
            let a = (x[k + 2] - 2.0 * x[k + 1] + x[k]) / (dt * dt);
            assert!(v.abs() <= p.max_velocity * (1.0 + 1e-6), "v {v} at {k}");
            assert!(a.abs() <= p.max_acceleration * 1.01, "a {a} at {k}");
        }
    }

    #[test]
    fn the_sampled_command_equals_the_s_curves_of_the_plan() {
        // an independent composition: each move's Scurve with its own rest
        let p = PointToPoint::default();
        let rate = 1000.0;
        let x = p.generate(rate, 2.0, 3).unwrap();
        let moves = p.plan(3, 2.0).unwrap();
        for (k, &v) in x.iter().enumerate() {
            let t = k as f64 / rate;
            let mut want = 0.0;
            for m in &moves {
                let s = Scurve {
                    distance: m.to - m.from,
                    max_velocity: p.max_velocity,
                    max_acceleration: p.max_acceleration,
                    jerk: p.jerk,
                    rest: m.start,
                };
                if t >= m.start {
                    want = m.from + s.value_at(t);
                }
            }
            assert!((v - want).abs() < 1e-15, "k {k}: {v} vs {want}");
        }
    }

    #[test]
    fn same_seed_same_program_other_seed_other_targets() {
        let a = point_to_point(1000.0, 3.0, 5).unwrap();
        let b = point_to_point(1000.0, 3.0, 5).unwrap();
        let c = point_to_point(1000.0, 3.0, 6).unwrap();
        assert_eq!(a, b);
        assert_ne!(a, c);
        assert!(a[..10].iter().all(|&v| v == 0.0), "rests 10 ms first");
    }

    #[test]
    fn invalid_programs_are_rejected() {
        for p in [
            PointToPoint {
                amplitude: 0.0,
                ..PointToPoint::default()
            },
            PointToPoint {
                dwell_min: 0.5,
                dwell_max: 0.1,
                ..PointToPoint::default()
            },
            PointToPoint {
                min_move: 1.5,
                ..PointToPoint::default()
            },
        ] {
            assert!(p.generate(1000.0, 1.0, 0).is_err(), "{p:?}");
        }
    }
}
