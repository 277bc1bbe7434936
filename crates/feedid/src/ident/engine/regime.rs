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
    /// Index in the recording of the first sample whose differences are
    /// not in the scales yet (the recording's own samples; an extrapolated
    /// command is taken in at every call).
    scanned: usize,
    /// Index in the recording of the first sample of the last slice (a
    /// slice that starts earlier is a new recording: the scales restart).
    last_first: usize,
}

impl RegimeClassifier {
    /// Forget the scales (a new recording).
    pub fn reset(&mut self) {
        self.speed = 0.0;
        self.acceleration = 0.0;
        self.scanned = 0;
        self.last_first = 0;
    }

    /// Take the differences of `command[from..]` into the running scales.
    fn take_in(&mut self, command: &[f64], from: usize) {
        for i in from.max(1)..command.len() {
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
    }

    /// Classify the last `out.len()` samples of `command` (the samples
    /// before them are their look-back of `look_back` samples, as far as
    /// the slice reaches), after taking the slice's speeds and
    /// accelerations into the running scales.
    ///
    /// `first` is the index in the recording of `command[0]` and `own` the
    /// number of leading samples of `command` that are the recording's own
    /// (the rest an extrapolation of it): the recording's samples are taken
    /// into the scales once, when first seen finite, so sliding windows
    /// cost what they add, not their length.
    pub fn classify(
        &mut self,
        command: &[f64],
        first: usize,
        own: usize,
        look_back: usize,
        out: &mut [Regime],
    ) {
        let n = command.len();
        let own = own.min(n);
        let h = out.len().min(n);
        if first < self.last_first {
            self.speed = 0.0;
            self.acceleration = 0.0;
            self.scanned = 0;
        }
        self.last_first = first;
        // the recording's samples not taken in yet, up to the first one
        // not known (a stream waiting for it: taken in once it is)
        let from = self.scanned.saturating_sub(first).min(own);
        self.take_in(&command[..own], from);
        let known = command[from..own]
            .iter()
            .position(|x| !x.is_finite())
            .map_or(own, |p| from + p);
        self.scanned = self.scanned.max(first + known);
        if own < n {
            self.take_in(command, own);
        }
        // one pass over the outputs and their look-back: the direction of
        // each sample, and where each direction was last seen (index + 1;
        // 0: not in this pass)
        let lo = (n - h).saturating_sub(look_back).max(1);
        let v_limit = MOVING_SHARE * self.speed;
        let a_limit = MOVING_SHARE * self.acceleration;
        let mut last_seen = [0usize; 3];
        for i in lo.min(n - h)..n {
            let dir: i8 = if i == 0 {
                0
            } else {
                let d = command[i] - command[i - 1];
                if d.is_finite() && d.abs() > v_limit {
                    if d > 0.0 {
                        1
                    } else {
                        -1
                    }
                } else {
                    0
                }
            };
            let slot = (dir + 1) as usize;
            if i < n - h {
                last_seen[slot] = i + 1;
                continue;
            }
            // the look-back `max(i − L, 1) … i − 1` holds a direction seen
            // at an index ≥ its start
            let start = i.saturating_sub(look_back).max(1).min(i);
            let within = |s: usize| last_seen[s] > start;
            let rested = within(1);
            let other = dir != 0 && within((1 - dir) as usize);
            let moved = within(0) || within(2);
            last_seen[slot] = i + 1;
            let r = &mut out[i + h - n];
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
        c.classify(u, 0, u.len(), look_back, &mut out);
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

    /// The definition, slowly: the scales are the largest differences of
    /// every slice ever given, each slice scanned whole.
    struct FullScan {
        speed: f64,
        acceleration: f64,
    }

    impl FullScan {
        fn classify(&mut self, command: &[f64], look_back: usize, h: usize) -> Vec<Regime> {
            let n = command.len();
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
            let direction = |i: usize| -> i8 {
                let d = if i == 0 {
                    0.0
                } else {
                    command[i] - command[i - 1]
                };
                if d.is_finite() && d.abs() > MOVING_SHARE * self.speed {
                    if d > 0.0 {
                        1
                    } else {
                        -1
                    }
                } else {
                    0
                }
            };
            (n - h..n)
                .map(|i| {
                    let dir = direction(i);
                    let back: Vec<i8> = (i.saturating_sub(look_back).max(1).min(i)..i)
                        .map(direction)
                        .collect();
                    let rested = back.contains(&0);
                    let other = back.iter().any(|&b| b != 0 && b == -dir);
                    let moved = back.iter().any(|&b| b != 0);
                    let accelerating = i >= 2 && {
                        let a = (command[i] - command[i - 1]) - (command[i - 1] - command[i - 2]);
                        a.is_finite()
                            && a.abs() > MOVING_SHARE * self.acceleration
                            && self.acceleration > 0.0
                    };
                    if dir != 0 && other {
                        Regime::Reversal
                    } else if dir != 0 && rested {
                        Regime::Start
                    } else if accelerating || (dir == 0 && moved) {
                        Regime::Accelerating
                    } else if dir != 0 {
                        Regime::ConstantVelocity
                    } else {
                        Regime::Rest
                    }
                })
                .collect()
        }
    }

    #[test]
    fn sliding_slices_are_classified_as_if_each_were_scanned_whole() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        for case in 0..40 {
            // a seeded walk of rests, moves and reversals, with growing steps
            // so the scales change along the way
            let n = 600;
            let mut u = vec![0.0];
            let mut v = 0.0;
            for k in 1..n {
                if rng.random_bool(0.03) {
                    v = [0.0, 1.0, -1.0, 3.0][rng.random_range(0..4)] * (1.0 + k as f64 / 200.0);
                }
                u.push(u[k - 1] + v + rng.random_range(-0.01..0.01));
            }
            let w = rng.random_range(3..60);
            let h = rng.random_range(1..12);
            let hop = rng.random_range(1..w + h + 5);
            let look_back = rng.random_range(1..16);
            let extrapolate = case % 2 == 1;
            let waiting = case % 3 == 2;
            let mut fast = RegimeClassifier::default();
            let mut slow = FullScan {
                speed: 0.0,
                acceleration: 0.0,
            };
            let mut s = 0;
            while s + w + h <= n {
                let mut slice = u[s..s + w + h].to_vec();
                let own = if extrapolate {
                    // the horizon as a method without it sees it
                    let (a, b) = (slice[w - 2.min(w)], slice[w - 1]);
                    for j in 0..h {
                        slice[w + j] = b + (j + 1) as f64 * (b - a);
                    }
                    w
                } else {
                    if waiting {
                        // a stream still waiting for the horizon's last samples
                        let unknown = rng.random_range(0..=h);
                        for x in &mut slice[w + h - unknown..] {
                            *x = f64::NAN;
                        }
                    }
                    w + h
                };
                let mut out = vec![Regime::Rest; h];
                fast.classify(&slice, s, own, look_back, &mut out);
                let expected = slow.classify(&slice, look_back, h);
                assert_eq!(
                    out, expected,
                    "case {case}, slice at {s} (w {w}, h {h}, hop {hop})"
                );
                s += hop;
            }
        }
    }

    #[test]
    fn a_new_recording_restarts_the_scales() {
        let big: Vec<f64> = (0..100).map(|k| 10.0 * k as f64).collect();
        let small: Vec<f64> = (0..100)
            .map(|k| if k < 50 { 0.0 } else { 0.1 * (k - 50) as f64 })
            .collect();
        let mut c = RegimeClassifier::default();
        let mut out = vec![Regime::Rest; 10];
        c.classify(&big[..60], 40, 60, 10, &mut out);
        // the small recording from its start: its own moves are moves
        c.classify(&small, 0, 100, 10, &mut out);
        assert_eq!(out, vec![Regime::ConstantVelocity; 10]);
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
