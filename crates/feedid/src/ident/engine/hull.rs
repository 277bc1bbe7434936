//! The runaway guard's command hull: where a position servo can be `j`
//! samples after the last measured one, judged by where its command goes.
//!
//! A servo moves towards its command, and a moving axis goes on for a while
//! as it moves: `j` samples after the last sample `y₀` of a window, the
//! axis is, to within its overshoot and the noise, between where it was,
//! where it would be going on at its recent velocity, and where the command
//! has been since,
//!
//! ```text
//! hull_j = [min(y₀, y₀ + j·v, u₀ … u_j),  max(y₀, y₀ + j·v, u₀ … u_j)]
//! v = (y₀ − y₋H) / H
//! d_j = dist(y_j, hull_j)                       (the departure measured)
//! O_j = max over the windows so far of max(min(d_{j−1}, d_j), min(d_j, d_{j+1}))
//! ```
//!
//! (`v` as the envelope's, the mean velocity over the last `H` samples; the
//! hull is that of `y₀` and the command alone before `H` samples of a
//! segment). `O_j` is the farthest the axis has gone outside the hull `j`
//! samples after the last sample of a window — its overshoot past the
//! command at a stop or a reversal beyond its momentum, the excursion of a
//! force pulse, the noise of the measurement — where it stayed outside for
//! two samples in a row: a single wild sample that the outlier test had no
//! history yet to catch is no overshoot (one such glitch of 3 mm on a zoo
//! recording had let every later prediction at rest wander 3 mm). A
//! prediction `ŷ_j` from `y₀` is expected within
//!
//! ```text
//! hull_j ± O_j
//! ```
//!
//! with no margin beyond the largest overshoot seen: the hull already holds
//! where the command and the motion go, and where the noise makes the
//! overshoot (a coarse encoder at rest), a margin of 1.5 as the envelope's
//! let a prediction wander one and a half counts on the far side of an
//! axis that moves one (on the drive zoo, 188 of 210 members had the
//! paper's method's largest error within 1.5× the hold's with the margin,
//! 191 without; `oe` 205 and 206; the others the same).
//!
//! The departures are measured from the windows' last samples — where the
//! predictions start — against the same hull the prediction was bounded
//! by, as each measured sample scores the pending predictions: `O(1)` per
//! sample and window. (Measuring them from every sample, as the envelope
//! does, cost `O(H)` per sample: three times the envelope's own tracking.)
//! Where the method predicts without the horizon's command, the hull is
//! taken over the command it is given instead — the last command going on
//! at the velocity of its last two samples — and so is `O_j`, which then
//! also holds how far the axis departed from that guess where the command
//! accelerated.
//!
//! Why: the envelope of the motion shown ([`Envelope`](super::Envelope))
//! bounds how *far* a prediction may go but not *where*: after a 10 mm
//! move it allows a prediction to travel 10 mm with the command at rest,
//! or the wrong way at a step, and such a prediction is wrong by more than
//! any hold. The hull gives the direction. Its momentum term keeps it from
//! cutting an axis that runs ahead of its recorded command (feed-forward,
//! a command recorded late): without it such an axis was cut back to its
//! command at every motion until its first overshoot had been seen.
//! Counting the momentum only the way the command goes was tried: at a
//! reversal the mean velocity still points the old way, but an axis
//! settling with its command at rest has no command direction at all, and
//! `auto` lost up to 171× on such members. Both bounds are lengths of the
//! recording itself (no unit). A recording whose command is in another
//! frame or unit than its position (an offset, a scale) has the axis far
//! outside the hull from its first motion on; `O_j` then learns that and
//! the hull stops cutting: it never needs the two signals to agree, it
//! only profits where they do.

/// Per step ahead, the largest overshoot past the command hull seen.
#[derive(Debug, Clone)]
pub struct CommandHull {
    /// The hull over the command extrapolated from each window's end, not
    /// the command measured after it.
    extrapolated: bool,
    /// `O_j`, index `j − 1`.
    overshoot: Vec<f64>,
    /// Whether `O_j` has been measured, index `j − 1`.
    seen: Vec<bool>,
}

impl CommandHull {
    /// A hull for horizons of `horizon` samples over the command measured
    /// after each window (`extrapolated` false) or extrapolated from it.
    pub fn new(horizon: usize, extrapolated: bool) -> Self {
        let horizon = horizon.max(1);
        Self {
            extrapolated,
            overshoot: vec![0.0; horizon],
            seen: vec![false; horizon],
        }
    }

    /// Whether the hull is over the extrapolated command.
    pub fn extrapolated(&self) -> bool {
        self.extrapolated
    }

    /// Forget the overshoot seen (a new recording).
    pub fn reset(&mut self) {
        self.overshoot.fill(0.0);
        self.seen.fill(false);
    }

    /// The largest overshoot seen at `j` (1-based) steps ahead, if any.
    pub fn seen(&self, j: usize) -> Option<f64> {
        let i = j.checked_sub(1)?;
        (*self.seen.get(i)?).then(|| self.overshoot[i])
    }

    /// The hull of the next `lower.len()` samples after the last position
    /// `last`, moving at `velocity` (per sample; `None`: not known), whose
    /// command is `command[0]` then and `command[j]` `j` samples later:
    /// `hull_j` into `lower[j − 1]`, `upper[j − 1]`; NaN (no hull) from a
    /// step whose command is not given or not finite on.
    pub fn hull(
        last: f64,
        velocity: Option<f64>,
        command: &[f64],
        lower: &mut [f64],
        upper: &mut [f64],
    ) {
        let n = lower.len().min(upper.len());
        let u0 = command.first().copied().unwrap_or(f64::NAN);
        // (without a velocity the axis stays: `last + j·0`)
        let v = velocity.filter(|v| v.is_finite()).unwrap_or(0.0);
        let mut from = 0;
        if last.is_finite() && u0.is_finite() {
            // (numbers only here: selects, not `f64::min`)
            let (mut lo, mut hi) = if u0 < last { (u0, last) } else { (last, u0) };
            let steps = n.min(command.len().saturating_sub(1));
            while from < steps {
                let u = command[from + 1];
                if !u.is_finite() {
                    break;
                }
                lo = if u < lo { u } else { lo };
                hi = if u > hi { u } else { hi };
                let c = last + (from + 1) as f64 * v;
                lower[from] = if c < lo { c } else { lo };
                upper[from] = if c > hi { c } else { hi };
                from += 1;
            }
        }
        lower[from..n].fill(f64::NAN);
        upper[from..n].fill(f64::NAN);
    }

    /// A hull (from [`CommandHull::hull`]) widened by the overshoot seen at
    /// each step, `± O_j`, into `lower`, `upper`; NaN (no bound) at a step
    /// whose overshoot has not been seen.
    pub fn widen(
        &self,
        hull_lower: &[f64],
        hull_upper: &[f64],
        lower: &mut [f64],
        upper: &mut [f64],
    ) {
        let steps = lower
            .iter_mut()
            .zip(upper.iter_mut())
            .zip(hull_lower.iter().zip(hull_upper))
            .zip(self.overshoot.iter().zip(&self.seen));
        for (((l, h), (&a, &b)), (&o, &seen)) in steps {
            (*l, *h) = if seen {
                (a - o, b + o)
            } else {
                (f64::NAN, f64::NAN)
            };
        }
    }

    /// How far `y` lies outside the hull `[lower, upper]` (≤ 0 inside; NaN
    /// where `y` or both bounds are NaN, as [`CommandHull::hull`] leaves
    /// a step without a hull).
    #[inline]
    pub fn departure(lower: f64, upper: f64, y: f64) -> f64 {
        // (a select: both differences are NaN together, or neither)
        let (above, below) = (y - upper, lower - y);
        if above > below {
            above
        } else {
            below
        }
    }

    /// Take a prediction's measured samples (`measured[j − 1]` `j` samples
    /// after the window's end; NaN: not known) and the hull it was bounded
    /// by: where the axis was outside the hull at two steps in a row, the
    /// smaller departure joins the overshoot at both steps. A NaN departure
    /// (no hull, no sample) counts nothing.
    pub fn score(&mut self, lower: &[f64], upper: &[f64], measured: &[f64]) {
        let n = lower
            .len()
            .min(upper.len())
            .min(measured.len())
            .min(self.overshoot.len());
        let mut before = f64::NAN;
        for i in 0..n {
            let now = Self::departure(lower[i], upper[i], measured[i]);
            if i > 0 && !before.is_nan() && !now.is_nan() {
                let d = if before < now { before } else { now };
                let d = if d > 0.0 { d } else { 0.0 };
                for k in [i - 1, i] {
                    self.seen[k] = true;
                    if d > self.overshoot[k] {
                        self.overshoot[k] = d;
                    }
                }
            }
            before = now;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_hull_runs_from_the_axis_to_its_command_and_its_momentum() {
        // at 0.2 moving at +0.01 per sample, the command at 0.2 stepping
        // to −1 after two samples: the hull runs from −1 to the coast
        let (mut lo, mut hi) = ([0.0; 4], [0.0; 4]);
        CommandHull::hull(
            0.2,
            Some(0.01),
            &[0.2, 0.2, -1.0, -1.0, -1.0],
            &mut lo,
            &mut hi,
        );
        assert_eq!(lo, [0.2, -1.0, -1.0, -1.0]);
        for (j, h) in hi.iter().enumerate() {
            assert!((h - (0.2 + 0.01 * (j + 1) as f64)).abs() < 1e-15);
        }
        // the velocity not known: the axis and the command alone; a command
        // not given from the third step on: no hull there
        CommandHull::hull(0.0, None, &[0.0, 1.0, f64::NAN, 2.0], &mut lo, &mut hi);
        assert_eq!((lo[0], hi[0]), (0.0, 1.0));
        assert!(lo[1..].iter().chain(&hi[1..]).all(|v| v.is_nan()));
    }

    /// Score departures `d` (with a hull of [−1, 1], the samples `1 + d`
    /// for `d ≥ −1`; NaN: no sample).
    fn score_departures(hull: &mut CommandHull, d: &[f64]) {
        let n = d.len();
        let measured: Vec<f64> = d.iter().map(|d| 1.0 + d).collect();
        hull.score(&vec![-1.0; n], &vec![1.0; n], &measured);
    }

    #[test]
    fn the_overshoot_is_the_largest_departure_held_two_samples() {
        // brute force over seeded random departures (some inside, some
        // NaN), against the definition: O_j = max over windows of
        // max(min(d_{j−1}, d_j), min(d_j, d_{j+1})) where both are numbers
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let h = 6;
        let mut hull = CommandHull::new(h, false);
        let mut windows: Vec<Vec<f64>> = Vec::new();
        for _ in 0..200 {
            let d: Vec<f64> = (0..h)
                .map(|_| {
                    if rng.random::<f64>() < 0.1 {
                        f64::NAN
                    } else {
                        rng.random::<f64>() * 1.5 - 1.0
                    }
                })
                .collect();
            score_departures(&mut hull, &d);
            windows.push(d);
            for j in 1..=h {
                let mut want: Option<f64> = None;
                for d in &windows {
                    for (a, b) in [(j.wrapping_sub(2), j - 1), (j - 1, j)] {
                        if let (Some(&x), Some(&y)) = (d.get(a), d.get(b)) {
                            if !x.is_nan() && !y.is_nan() {
                                let m = x.min(y).max(0.0);
                                want = Some(want.map_or(m, |w| w.max(m)));
                            }
                        }
                    }
                }
                let got = hull.seen(j);
                assert_eq!(got.is_some(), want.is_some(), "j {j}");
                if let (Some(g), Some(w)) = (got, want) {
                    assert!((g - w).abs() < 1e-12, "j {j}: {g} {w}");
                }
            }
        }
    }

    #[test]
    fn a_glitch_is_no_overshoot_and_an_excursion_is() {
        let mut hull = CommandHull::new(4, false);
        // one wild sample 0.5 outside at step 2
        score_departures(&mut hull, &[0.0, 0.5, 0.0, 0.0]);
        assert!((1..=4).all(|j| hull.seen(j) == Some(0.0)));
        // an excursion 0.125 outside at steps 2 and 3
        score_departures(&mut hull, &[0.0, 0.125, 0.25, -0.5]);
        assert_eq!(hull.seen(1), Some(0.0));
        assert_eq!(hull.seen(2), Some(0.125));
        assert_eq!(hull.seen(3), Some(0.125));
        assert_eq!(hull.seen(4), Some(0.0));
        let (mut lo, mut hi) = ([0.0; 4], [0.0; 4]);
        hull.widen(&[0.0; 4], &[1.0; 4], &mut lo, &mut hi);
        assert_eq!(lo, [0.0, -0.125, -0.125, 0.0]);
        assert_eq!(hi, [1.0, 1.125, 1.125, 1.0]);
        // a hull that has seen nothing bounds nothing
        CommandHull::new(4, true).widen(&[0.0; 4], &[1.0; 4], &mut lo, &mut hi);
        assert!(lo.iter().chain(&hi).all(|v| v.is_nan()));
        assert!(CommandHull::departure(0.0, 1.0, f64::NAN).is_nan());
        assert!(CommandHull::departure(f64::NAN, f64::NAN, 0.5).is_nan());
        assert_eq!(CommandHull::departure(0.0, 1.0, 1.25), 0.25);
        assert_eq!(CommandHull::departure(0.0, 1.0, 0.5), -0.5);
    }
}
