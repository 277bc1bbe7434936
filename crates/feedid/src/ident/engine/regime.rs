//! The command regime of each predicted sample: at rest, start of motion,
//! constant velocity, accelerating, reversal — the situations in which a
//! predictor's errors differ most, told apart from the command alone (known
//! over the horizon when a prediction is made), relative to the recording's
//! own commanded speeds and accelerations.
//!
//! With `Δu[k] = u[k] − u[k−1]` and `Δ²u[k] = Δu[k] − Δu[k−1]`, `v̂` and `â`
//! the largest `|Δu|` and `|Δ²u|` of the command seen so far, the command
//! *moves* at `k` when `|Δu[k]| > ε·v̂` and *accelerates* when
//! `|Δ²u[k]| > ε·â` (`ε` = [`MOVING_SHARE`]). Looking back `L` samples (the
//! horizon; the axis follows its command with a lag of that order):
//!
//! | regime | when (first match) |
//! |---|---|
//! | reversal | moving at `k` and at some sample of `k−L … k−1` with the other sign |
//! | start of motion | moving at `k`, at rest at some sample of `k−L … k−1` |
//! | accelerating | accelerating at `k`, or at rest at `k` after moving within `k−L … k−1` (a stop) |
//! | constant velocity | moving at `k` |
//! | at rest | otherwise |
//!
//! A sample whose command is not finite (a stream waiting for it) is at
//! rest unless its neighbours say otherwise; the classification never
//! fails. The thresholds are shares of the recording's own extremes: units
//! and offsets do not change the regimes.

/// Share of the largest commanded speed (and acceleration) above which the
/// command counts as moving (accelerating): about 1.8 %, deliberately not a
/// round share — generated profiles change in round fractions of their
/// extremes (an S-curve's jerk phase of 150 samples passes 2 % exactly on
/// a sample), and a threshold on that grid would leave a sample's regime to
/// the last bits of the arithmetic, and so to the unit of the recording.
pub const MOVING_SHARE: f64 = 0.0183;

/// The command regime of a predicted sample (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Regime {
    /// The command at rest and at rest over the look-back.
    Rest,
    /// The command moving after resting within the look-back.
    Start,
    /// The command moving at a constant velocity.
    ConstantVelocity,
    /// The command accelerating, decelerating or just stopped.
    Accelerating,
    /// The command's velocity changed sign within the look-back.
    Reversal,
}

impl Regime {
    /// Every regime, in the order of [`Regime::index`].
    pub const ALL: [Regime; 5] = [
        Regime::Rest,
        Regime::Start,
        Regime::ConstantVelocity,
        Regime::Accelerating,
        Regime::Reversal,
    ];

    /// Position in [`Regime::ALL`].
    pub fn index(self) -> usize {
        self as usize
    }

    /// Short name (`rest`, `start`, `constant_velocity`, `accelerating`, `reversal`).
    pub fn name(self) -> &'static str {
        match self {
            Regime::Rest => "rest",
            Regime::Start => "start",
            Regime::ConstantVelocity => "constant_velocity",
            Regime::Accelerating => "accelerating",
            Regime::Reversal => "reversal",
        }
    }

    /// Words for a table (`at rest`, `start of motion`, …).
    pub fn label(self) -> &'static str {
        match self {
            Regime::Rest => "at rest",
            Regime::Start => "start of motion",
            Regime::ConstantVelocity => "constant velocity",
            Regime::Accelerating => "accelerating",
            Regime::Reversal => "reversal",
        }
    }
}

/// The running scales of the command and the classification of slices of
/// it (see the module doc).
#[derive(Debug, Clone, Default)]
pub struct RegimeClassifier {
    /// Largest `|Δu|` seen so far.
    speed: f64,
    /// Largest `|Δ²u|` seen so far.
    acceleration: f64,
    /// Per sample of the slice being classified: −1, 0, +1 (direction of
    /// motion, 0 at rest) — scratch, grown once.
    direction: Vec<i8>,
}

impl RegimeClassifier {
    /// Forget the scales (a new recording).
    pub fn reset(&mut self) {
        self.speed = 0.0;
        self.acceleration = 0.0;
    }

    /// Classify the last `out.len()` samples of `command` (the samples
    /// before them are their look-back of `look_back` samples, as far as
    /// the slice reaches), after taking the slice's speeds and
    /// accelerations into the running scales.
    pub fn classify(&mut self, command: &[f64], look_back: usize, out: &mut [Regime]) {
        let n = command.len();
        let h = out.len().min(n);
        for i in 1..n {
            let d = command[i] - command[i - 1];
            if d.abs() > self.speed {
                self.speed = d.abs();
            }
            if i >= 2 {
                let a = d - (command[i - 1] - command[i - 2]);
                if a.abs() > self.acceleration {
                    self.acceleration = a.abs();
                }
            }
        }
        if self.direction.len() < n {
            self.direction.resize(n, 0);
        }
        let v_limit = MOVING_SHARE * self.speed;
        let a_limit = MOVING_SHARE * self.acceleration;
        for i in 0..n {
            let d = if i == 0 {
                0.0
            } else {
                command[i] - command[i - 1]
            };
            self.direction[i] = if d.is_finite() && d.abs() > v_limit {
                if d > 0.0 {
                    1
                } else {
                    -1
                }
            } else {
                0
            };
        }
        for (m, r) in out.iter_mut().enumerate().take(h) {
            let i = n - h + m;
            let dir = self.direction[i];
            let back = i.saturating_sub(look_back).max(1).min(i)..i;
            let mut rested = false;
            let mut other = false;
            let mut moved = false;
            for &b in &self.direction[back.clone()] {
                rested |= b == 0;
                other |= b != 0 && b == -dir;
                moved |= b != 0;
            }
            let accelerating = i >= 2 && {
                let a = (command[i] - command[i - 1]) - (command[i - 1] - command[i - 2]);
                a.is_finite() && a.abs() > a_limit && self.acceleration > 0.0
            };
            *r = if dir != 0 && other {
                Regime::Reversal
            } else if dir != 0 && rested {
                Regime::Start
            } else if accelerating || (dir == 0 && moved) {
                Regime::Accelerating
            } else if dir != 0 {
                Regime::ConstantVelocity
            } else {
                Regime::Rest
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn classify(u: &[f64], look_back: usize) -> Vec<Regime> {
        let mut c = RegimeClassifier::default();
        let mut out = vec![Regime::Rest; u.len()];
        c.classify(u, look_back, &mut out);
        out
    }

    #[test]
    fn a_trapezoid_and_back_passes_through_every_regime_in_order() {
        // rest, accelerate, cruise, decelerate, rest, then back
        let mut v = Vec::new();
        v.extend(std::iter::repeat_n(0.0, 20));
        v.extend((1..=20).map(|i| i as f64 * 0.05));
        v.extend(std::iter::repeat_n(1.0, 30));
        v.extend((0..10).rev().map(|i| i as f64 * 0.1));
        v.extend(std::iter::repeat_n(0.0, 15));
        v.extend(std::iter::repeat_n(-1.0, 30));
        v.extend(std::iter::repeat_n(0.0, 20));
        let mut u = vec![0.0];
        for dv in &v {
            u.push(u.last().unwrap() + dv);
        }
        let r = classify(&u, 10);
        assert_eq!(r[10], Regime::Rest);
        assert_eq!(r[21], Regime::Start);
        assert_eq!(r[35], Regime::Accelerating);
        assert_eq!(r[50], Regime::ConstantVelocity);
        assert_eq!(r[75], Regime::Accelerating);
        // the reverse motion starts 15 samples after the stop (a start);
        // 5 samples after it, the look-back would hold both directions
        assert_eq!(r[97], Regime::Start);
        assert_eq!(r[120], Regime::ConstantVelocity);
        assert_eq!(r[144], Regime::Rest);
        // a direct reversal (no rest between)
        let u: Vec<f64> = (0..200)
            .map(|k| (k as f64 * std::f64::consts::TAU / 100.0).sin())
            .collect();
        let r = classify(&u, 5);
        assert!(r[24..30].contains(&Regime::Reversal), "{:?}", &r[20..32]);
        assert_eq!(r[50], Regime::Accelerating);
    }

    #[test]
    fn units_and_offsets_do_not_change_the_regimes() {
        let u: Vec<f64> = (0..300)
            .map(|k| {
                let t = k as f64 / 100.0;
                (t * 3.0).sin() * (t - 1.0).max(0.0)
            })
            .collect();
        let a = classify(&u, 10);
        let scaled: Vec<f64> = u.iter().map(|x| 1e3 * x + 5.0).collect();
        assert_eq!(a, classify(&scaled, 10));
    }

    #[test]
    fn an_unknown_command_never_fails_the_classification() {
        let mut u: Vec<f64> = (0..50).map(|k| k as f64).collect();
        u[40..].fill(f64::NAN);
        let r = classify(&u, 10);
        assert_eq!(r.len(), 50);
    }
}
