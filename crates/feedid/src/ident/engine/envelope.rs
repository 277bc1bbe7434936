//! The runaway guard's envelope: how far the axis can be from its last
//! measured position `j` samples later, judged by the motion the recording
//! has shown.
//!
//! From the measured (outlier-cleaned) position the engine keeps, for every
//! step ahead `j = 1 … H`,
//!
//! ```text
//! D_j = max_k |y[k] − y[k−j]|                              (reach: speed)
//! S_j = max_k |y[k] − y[k−j] − j·v[k−j]|                   (swerve: acceleration)
//! v[i] = (y[i] − y[i−H]) / H
//! ```
//!
//! over the samples seen so far: the largest distance the axis has travelled
//! in `j` samples, and the largest departure in `j` samples from going on at
//! its recent velocity (the mean over the last `H` samples, so that the
//! noise of one sample is not multiplied by `j`). A prediction `ŷ_j` made
//! from the last position `y₀` (recent velocity `v = (y₀ − y₋H)/H`) is
//! expected within
//!
//! ```text
//! |ŷ_j − y₀| ≤ κ·D_j    and    |ŷ_j − y₀ − j·v| ≤ κ·S_j
//! ```
//!
//! (`κ` = [`GuardConfig::runaway`](crate::ident::GuardConfig::runaway)).
//! Where the command asks for more than it has before, the bounds grow with
//! it: the same two figures of the command over a whole horizon (`j = H`) —
//! over the commands the axis has had a horizon to answer (`D̂ᶜ`, `Ŝᶜ`) and
//! over the pairs that end in the current horizon (`Dᶜ`, `Sᶜ`) — widen every
//! `D_j` by `Dᶜ / D̂ᶜ` and every `S_j` by `Sᶜ / Ŝᶜ` where these exceed 1 (a
//! larger or faster move of a program, a sweep rising in frequency; a
//! command that has never moved gives no such scale: the axis has shown
//! nothing to scale), but never beyond the command's own figure plus the
//! following error now, `Dᶜ + |u₀ − y₀|` and `Sᶜ + |u₀ − y₀|`: a command
//! that has barely moved before (the first samples of a jerk-limited
//! start) would otherwise make the ratio, and the bound, as large as it
//! likes. Where the method predicts without the horizon's command, `Dᶜ` and
//! `Sᶜ` are taken over the pairs that end in the window's last `H` samples
//! (what has been asked and not yet answered): the command extrapolated
//! over the horizon is a guess, and a step extrapolated at its own slope
//! would ask for ten steps. [`Envelope::horizon_only`] keeps those figures.
//! A model that winds up within its horizon — an error growing by a
//! constant factor per step, as a nearly unstable window model does at a
//! reversal — leaves this envelope within a few steps; so does a model
//! fitted on a window at rest that predicts a jump onto a stepped command
//! the axis has never shown it can follow. The samples of a prediction
//! outside it are *cut back* to its edge and their interval is widened to
//! span the hold and the cut value; a sample beyond `κ` times the edge's
//! distance marks the prediction as run away, and from it on the horizon
//! holds the last position (see
//! [`Envelope::cut`]): a model that has left the envelope that far says
//! nothing about where the axis goes, and the edge, on the side it ran to,
//! would still be wrong by `(1 + κ)·D_j` where the axis goes the other way.
//! The envelope says how far, not where: the guard intersects it with the
//! command hull ([`CommandHull`](super::CommandHull)), which does.
//!
//! Why these bounds: a position servo's speed and acceleration are limited
//! (by its drive, its gains and its mass), and the recording shows them.
//! Both bounds are ratios of lengths of the recording itself, so they carry
//! no unit; the measurement noise enters both (the one-sample velocity is
//! as noisy as the data), so at high rates the envelope widens with the
//! noise rather than cutting honest predictions. The price is the first
//! motion of a recording: before the axis has moved, `D_j` and `S_j` are
//! the noise's, and a prediction that the axis will start is cut back
//! towards the hold (its interval widened to the prediction). Every later
//! start is judged by the motion seen before it.
//!
//! All state is allocated in [`Envelope::new`]; [`Envelope::track`] costs
//! `O(H)` per sample.

/// Per step ahead, the largest reach and swerve seen, and the last samples.
#[derive(Debug, Clone)]
pub struct Envelope {
    horizon: usize,
    /// `D_j`, index `H − j` (the order of the ring's samples `j` back, so
    /// that tracking reads the ring forwards).
    reach: Vec<f64>,
    /// `S_j`, index `H − j`.
    swerve: Vec<f64>,
    /// `j` as a float, index `H − j`.
    steps: Vec<f64>,
    /// Whether a pair of samples `j` apart was seen, index `j − 1` (once
    /// the ring is full, every `j` has been).
    paired: Vec<bool>,
    /// The last `m = 2H + 1` samples, a ring (`head` = next write) stored
    /// twice (`recent[i]` = `recent[i + m]`), so that reading back needs no
    /// modulo.
    recent: Vec<f64>,
    head: usize,
    len: usize,
    /// Track the whole horizon (`j = H`) only.
    whole_only: bool,
    /// `1 / H`.
    inv_h: f64,
}

impl Envelope {
    /// An envelope for horizons of `horizon` samples.
    pub fn new(horizon: usize) -> Self {
        let horizon = horizon.max(1);
        Self {
            horizon,
            reach: vec![0.0; horizon],
            swerve: vec![0.0; horizon],
            steps: (0..horizon).map(|i| (horizon - i) as f64).collect(),
            paired: vec![false; horizon],
            recent: vec![0.0; 2 * (2 * horizon + 1)],
            head: 0,
            len: 0,
            whole_only: false,
            inv_h: 1.0 / horizon as f64,
        }
    }

    /// An envelope that tracks the whole horizon (`j = H`) only: the
    /// command's scale (see the module doc); `O(1)` per sample.
    pub fn horizon_only(horizon: usize) -> Self {
        Self {
            whole_only: true,
            ..Self::new(horizon)
        }
    }

    /// Forget the motion seen (a new recording).
    pub fn reset(&mut self) {
        self.reach.fill(0.0);
        self.swerve.fill(0.0);
        self.paired.fill(false);
        self.restart();
    }

    /// Forget the last samples but keep the motion seen (a gap: nothing
    /// pairs samples across it; the axis is the same).
    pub fn restart(&mut self) {
        self.head = 0;
        self.len = 0;
    }

    /// The sample `back` (< `2H + 1`) samples before the newest one (0: the newest).
    #[inline]
    fn ago(&self, back: usize) -> f64 {
        let m = self.recent.len() / 2;
        self.recent[self.head + m - 1 - back]
    }

    /// Take the next measured (cleaned) sample into the envelope.
    #[inline(always)]
    pub fn track(&mut self, y: f64) {
        if !y.is_finite() {
            return;
        }
        let m = self.recent.len() / 2;
        self.recent[self.head] = y;
        self.recent[self.head + m] = y;
        self.head = if self.head + 1 == m { 0 } else { self.head + 1 };
        self.len = (self.len + 1).min(m);
        let h = self.horizon;
        // the newest sample sits at `newest`; j samples before it at `newest − j`
        let newest = self.head + m - 1;
        let (recent, reach, swerve, paired) = (
            &self.recent,
            &mut self.reach,
            &mut self.swerve,
            &mut self.paired,
        );
        let inv_h = self.inv_h;
        if self.len == m && !self.whole_only {
            // every pair is there (the ring is full): no flags, no
            // branches on the ring's length, the ring read forwards
            // (`i = H − j`: the sample `j` back is `bases[i]`, and `H`
            // before it `olds[i]`)
            let bases = &recent[newest - h..newest];
            let olds = &recent[newest - 2 * h..newest - h];
            let steps = &self.steps[..h];
            let (reach, swerve) = (&mut reach[..h], &mut swerve[..h]);
            for i in 0..h {
                // (finite samples only: a select, not `f64::max`'s NaN
                // handling, and the loop vectorises)
                let (base, old) = (bases[i], olds[i]);
                let d = (y - base).abs();
                reach[i] = if d > reach[i] { d } else { reach[i] };
                let v = (base - old) * inv_h;
                let s = (y - base - steps[i] * v).abs();
                swerve[i] = if s > swerve[i] { s } else { swerve[i] };
            }
            return;
        }
        if self.len == m {
            // the whole horizon only, every pair there
            let (base, old) = (recent[newest - h], recent[newest - 2 * h]);
            let d = (y - base).abs();
            if d > reach[0] {
                reach[0] = d;
            }
            let s = (y - base - h as f64 * ((base - old) * inv_h)).abs();
            if s > swerve[0] {
                swerve[0] = s;
            }
            return;
        }
        let first = if self.whole_only { h } else { 1 };
        for j in first..=h.min(self.len.saturating_sub(1)) {
            let base = recent[newest - j];
            let d = (y - base).abs();
            if d > reach[h - j] {
                reach[h - j] = d;
            }
            paired[j - 1] = true;
            if self.len > j + h {
                let v = (base - recent[newest - j - h]) * inv_h;
                let s = (y - base - j as f64 * v).abs();
                if s > swerve[h - j] {
                    swerve[h - j] = s;
                }
            }
        }
    }

    /// The largest reach and swerve seen at `j` (1-based) steps ahead (0
    /// before any was seen).
    pub fn seen(&self, j: usize) -> (f64, f64) {
        match j.checked_sub(1) {
            Some(i) if i < self.horizon => {
                let i = self.horizon - 1 - i;
                (self.reach[i], self.swerve[i])
            }
            _ => (0.0, 0.0),
        }
    }

    /// The reach and swerve over a whole horizon (`j = H`) of the pairs of
    /// `samples` that end in its last `last` samples (NaN pairs skipped):
    /// the same figures as tracking, over a slice.
    pub fn whole_horizon_of(&self, samples: &[f64], last: usize) -> (f64, f64) {
        let h = self.horizon;
        let inv_h = 1.0 / h as f64;
        let (mut reach, mut swerve) = (0.0f64, 0.0f64);
        for k in samples.len().saturating_sub(last).max(h)..samples.len() {
            let (y, base) = (samples[k], samples[k - h]);
            let d = (y - base).abs();
            if d > reach {
                reach = d;
            }
            if k >= 2 * h {
                let v = (base - samples[k - 2 * h]) * inv_h;
                let s = (y - base - h as f64 * v).abs();
                if s > swerve {
                    swerve = s;
                }
            }
        }
        (reach, swerve)
    }

    /// The envelope of the sample `j` (1-based) steps after the last one
    /// tracked, started from `last` with the recent velocity (over the last
    /// `H` tracked samples): within `widths(j, D_j, S_j).0` of `last` and
    /// `widths(j, D_j, S_j).1` of going on at that velocity (the caller
    /// turns the figures seen into the allowed ones, `κ·D_j` and `κ·S_j` or
    /// wider); `None` before any pair of samples `j` apart was seen.
    pub fn bounds(
        &self,
        j: usize,
        last: f64,
        widths: impl Fn(usize, f64, f64) -> (f64, f64),
    ) -> Option<(f64, f64)> {
        self.bounds_at(j, last, self.velocity(), widths)
    }

    /// The recent velocity (over the last `H` tracked samples, per
    /// sample), if tracked.
    pub fn velocity(&self) -> Option<f64> {
        (self.len > self.horizon)
            .then(|| (self.ago(0) - self.ago(self.horizon)) / self.horizon as f64)
    }

    /// [`Envelope::bounds`] with the recent velocity given.
    fn bounds_at(
        &self,
        j: usize,
        last: f64,
        velocity: Option<f64>,
        widths: impl Fn(usize, f64, f64) -> (f64, f64),
    ) -> Option<(f64, f64)> {
        if j == 0 || j > self.horizon || !self.paired[j - 1] || !last.is_finite() {
            return None;
        }
        let (seen_reach, seen_swerve) = self.seen(j);
        let (reach, swerve) = widths(j, seen_reach, seen_swerve);
        let (mut lo, mut hi) = (last - reach, last + reach);
        if let (Some(v), true) = (velocity, seen_swerve > 0.0) {
            let c = last + j as f64 * v;
            let (a, b) = (lo.max(c - swerve), hi.min(c + swerve));
            if a <= b {
                lo = a;
                hi = b;
            }
        }
        Some((lo, hi))
    }

    /// Cut `values` (the prediction of the next samples from `last`) back
    /// into the envelope, its reach and swerve at step `j` allowed as
    /// `widths(j, D_j, S_j)` (see [`Envelope::bounds`]). A sample outside is
    /// set to the envelope's edge; a sample farther from `last` than `far`
    /// times the envelope's edge marks the prediction as run away, and it
    /// and every
    /// later sample of the horizon become the hold (`last`, within the
    /// envelope). The interval of a changed sample becomes
    /// `[min(last, ŷ) − q, max(last, ŷ) + q]` with `ŷ` its new value and `q`
    /// its half-width before (from `lower`/`upper`). `hull`, where given,
    /// bounds step `j` (index `j − 1`) further, by where the command goes
    /// ([`CommandHull::widen`](super::hull::CommandHull::widen); NaN: no
    /// bound): the bounds are the intersection of the two, or the hull's
    /// alone where they do not meet; the hull cuts but never marks a
    /// runaway.
    /// Returns the number of samples changed.
    #[allow(clippy::too_many_arguments)]
    pub fn cut(
        &self,
        values: &mut [f64],
        last: f64,
        widths: impl Fn(usize, f64, f64) -> (f64, f64),
        far: f64,
        hull: Option<(&[f64], &[f64])>,
        lower: &mut [f64],
        upper: &mut [f64],
    ) -> usize {
        let mut cut = 0;
        let mut run_away = false;
        let velocity = self.velocity();
        let h = self.horizon;
        let n = values.len().min(lower.len()).min(upper.len()).min(h);
        let (hull_lo, hull_hi) = hull.unwrap_or((&[], &[]));
        let known = last.is_finite();
        for i in 0..n {
            let v = &mut values[i];
            // the envelope's bounds (NaN: none; see `bounds_at`)
            let (mut ea, mut eb) = (f64::NAN, f64::NAN);
            if known && self.paired[i] {
                let (seen_reach, seen_swerve) = (self.reach[h - 1 - i], self.swerve[h - 1 - i]);
                let (reach, swerve) = widths(i + 1, seen_reach, seen_swerve);
                (ea, eb) = (last - reach, last + reach);
                if let (Some(vel), true) = (velocity, seen_swerve > 0.0) {
                    let c = last + (i + 1) as f64 * vel;
                    let (a, b) = (larger(ea, c - swerve), smaller(eb, c + swerve));
                    if a <= b {
                        (ea, eb) = (a, b);
                    }
                }
            }
            // with the hull's: their intersection, or the hull's alone
            // where they do not meet (bounds that are not ordered, NaN
            // included, cut nothing)
            let (mut a, mut b) = (ea, eb);
            if let (Some(&c), Some(&d)) = (hull_lo.get(i), hull_hi.get(i)) {
                if c <= d {
                    let (x, y) = (larger(ea, c), smaller(eb, d));
                    (a, b) = if ea <= eb && x <= y { (x, y) } else { (c, d) };
                }
            }
            let ordered = a <= b;
            if !ordered || (!run_away && *v >= a && *v <= b) {
                continue;
            }
            let (lo, hi) = (&mut lower[i], &mut upper[i]);
            let edge = within(*v, a, b);
            // a runaway is judged on the envelope alone, against its edge's
            // distance: the hull only cuts (where it is tight, a noise-free
            // axis at rest before a step, a model's least excess over it
            // would otherwise void the rest of the horizon); a NaN
            // prediction is as far as it gets
            let distance = (*v - last).abs();
            let near = if ea <= eb {
                let allowed = far * (within(*v, ea, eb) - last).abs();
                distance <= allowed
            } else {
                !distance.is_nan()
            };
            if !near {
                run_away = true;
            }
            let q = 0.5 * (*hi - *lo).abs();
            *v = if run_away { within(last, a, b) } else { edge };
            *lo = last.min(*v) - q;
            *hi = last.max(*v) + q;
            cut += 1;
        }
        cut
    }
}

/// The larger of two numbers by a select, cheaper than `f64::max`: a NaN
/// `a` gives `b` as `f64::max` does, a NaN `b` gives NaN (callers pass a
/// number as `b`).
#[inline(always)]
fn larger(a: f64, b: f64) -> f64 {
    if a > b {
        a
    } else {
        b
    }
}

/// The smaller of two numbers by a select (as [`larger`]: `b` a number).
#[inline(always)]
fn smaller(a: f64, b: f64) -> f64 {
    if a < b {
        a
    } else {
        b
    }
}

/// `v` within `[a, b]` (`a ≤ b`), by selects: a NaN `v` stays NaN.
#[inline(always)]
fn within(v: f64, a: f64, b: f64) -> f64 {
    if v < a {
        a
    } else if v > b {
        b
    } else {
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tracking_equals_the_figures_counted_over_every_pair_afresh() {
        // seeded random walks with rests and restarts, every horizon 1 … 6,
        // against the definitions counted over all pairs of the samples
        // since the last restart
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        for h in 1..=6 {
            for whole_only in [false, true] {
                let mut e = if whole_only {
                    Envelope::horizon_only(h)
                } else {
                    Envelope::new(h)
                };
                let (mut reach, mut swerve, mut pairs) = (vec![0.0; h], vec![0.0; h], vec![0; h]);
                let mut seg: Vec<f64> = Vec::new();
                let mut x = 0.0;
                for i in 0..600 {
                    if i % 250 == 249 {
                        e.restart();
                        seg.clear();
                    }
                    x += if rng.random::<f64>() < 0.3 {
                        0.0
                    } else {
                        rng.random::<f64>() - 0.4
                    };
                    e.track(x);
                    seg.push(x);
                    let k = seg.len() - 1;
                    let first = if whole_only { h } else { 1 };
                    for j in first..=h.min(k) {
                        reach[j - 1] = f64::max(reach[j - 1], (x - seg[k - j]).abs());
                        pairs[j - 1] += 1;
                        // a swerve needs j + H samples before the newest
                        // (within the ring's 2H + 1)
                        if k >= j + h {
                            let v = (seg[k - j] - seg[k - j - h]) / h as f64;
                            swerve[j - 1] =
                                f64::max(swerve[j - 1], (x - seg[k - j] - j as f64 * v).abs());
                        }
                    }
                    for j in 1..=h {
                        let (r, s) = e.seen(j);
                        assert!(
                            (r - reach[j - 1]).abs() <= 1e-12,
                            "h {h} j {j} reach {r} {}",
                            reach[j - 1]
                        );
                        assert!(
                            (s - swerve[j - 1]).abs() <= 1e-12,
                            "h {h} j {j} swerve {s} {}",
                            swerve[j - 1]
                        );
                    }
                    assert_eq!(e.paired, pairs.iter().map(|&c| c > 0).collect::<Vec<_>>());
                }
            }
        }
    }

    #[test]
    fn reach_and_swerve_are_the_largest_displacement_and_departure_seen() {
        // a parabola y = k²/2 (acceleration 1 per sample²): D_j over samples
        // 0..=20 is the largest |y[k] − y[k−j]|, S_j = j²/2 exactly
        let mut e = Envelope::new(5);
        for k in 0..=20 {
            e.track(0.5 * (k * k) as f64);
        }
        for j in 1..=5 {
            let d = 0.5 * (400 - (20 - j) * (20 - j)) as f64;
            let (reach, swerve) = e.seen(j);
            assert!((reach - d).abs() < 1e-12, "{j}");
            // the mean velocity over the 5 samples before k−j lags 2.5
            // samples: y[k] − y[k−j] − j·v = j²/2 + 2.5·j
            let s = 0.5 * (j * j) as f64 + 2.5 * j as f64;
            assert!((swerve - s).abs() < 1e-12, "{j}: {swerve}");
        }
    }

    #[test]
    fn the_whole_horizon_figures_of_a_slice_are_those_of_tracking_it() {
        let y: Vec<f64> = (0..60)
            .map(|k| ((k as f64) * 0.15).sin() * (k as f64))
            .collect();
        let mut e = Envelope::horizon_only(7);
        for v in &y {
            e.track(*v);
        }
        assert_eq!(e.seen(7), e.whole_horizon_of(&y, y.len()));
        assert_eq!(e.seen(3), (0.0, 0.0));
        // the pairs ending in the last 5 samples only: brute force
        let reach = (55..60)
            .map(|k| (y[k] - y[k - 7]).abs())
            .fold(0.0, f64::max);
        assert_eq!(e.whole_horizon_of(&y, 5).0, reach);
    }

    #[test]
    fn a_geometric_runaway_is_cut_back_and_its_interval_spans_the_hold() {
        // a constant velocity of 1 per sample: a prediction whose error
        // doubles every step leaves the envelope (κ = 1.5) and is cut
        let mut e = Envelope::new(10);
        for k in 0..100 {
            e.track(k as f64);
        }
        let last = 99.0;
        let mut pred: Vec<f64> = (1..=10)
            .map(|j| last + j as f64 + 0.01 * 2f64.powi(j))
            .collect();
        let mut lo: Vec<f64> = pred.iter().map(|v| v - 0.1).collect();
        let mut hi: Vec<f64> = pred.iter().map(|v| v + 0.1).collect();
        let cut = e.cut(
            &mut pred,
            last,
            |_, d, s| (1.5 * d, 1.5 * s),
            f64::INFINITY,
            None,
            &mut lo,
            &mut hi,
        );
        // reach 1.5·j always holds; the swerve is 0 on an exact ramp, so the
        // acceleration bound is not used and only the reach cuts: steps
        // whose excess 0.01·2^j exceeds 0.5·j
        let expected = (1..=10)
            .filter(|&j| 0.01 * 2f64.powi(j) > 0.5 * j as f64)
            .count();
        assert_eq!(cut, expected);
        for (j, v) in pred.iter().enumerate() {
            assert!(*v <= last + 1.5 * (j + 1) as f64 + 1e-12);
        }
        assert!(lo[9] <= last && hi[9] >= pred[9]);
    }

    #[test]
    fn a_prediction_far_beyond_the_envelope_holds_for_the_rest_of_its_horizon() {
        // the ramp of the test above, the error doubling every step (cut
        // from step 6, farther than 1.5 times the edge from step 8): the
        // samples just outside are cut to the edge; from the first one
        // farther than 1.5 times the edge's distance, the horizon holds
        let mut e = Envelope::new(10);
        for k in 0..100 {
            e.track(k as f64);
        }
        let last = 99.0;
        let original: Vec<f64> = (1..=10)
            .map(|j| last + j as f64 + 0.05 * 2f64.powi(j))
            .collect();
        let mut pred = original.clone();
        let mut lo: Vec<f64> = pred.iter().map(|v| v - 0.1).collect();
        let mut hi: Vec<f64> = pred.iter().map(|v| v + 0.1).collect();
        let cut = e.cut(
            &mut pred,
            last,
            |_, d, s| (1.5 * d, 1.5 * s),
            1.5,
            None,
            &mut lo,
            &mut hi,
        );
        let edge = |j: usize| last + 1.5 * j as f64;
        let far = (1..=10)
            .find(|&j| original[j - 1] - last > 1.5 * (edge(j) - last))
            .unwrap();
        let first_cut = (1..=10).find(|&j| original[j - 1] > edge(j)).unwrap();
        assert!(first_cut < far, "{first_cut} {far}");
        for j in 1..=10 {
            let v = pred[j - 1];
            if j < first_cut {
                assert_eq!(v, original[j - 1]);
            } else if j < far {
                assert!((v - edge(j)).abs() < 1e-12, "{j}: {v}");
            } else {
                assert_eq!(v, last, "{j}");
                // its interval is about the hold
                assert!(lo[j - 1] <= last && hi[j - 1] >= last);
            }
        }
        assert_eq!(cut, 11 - first_cut);
    }

    #[test]
    fn a_non_finite_prediction_holds_for_the_rest_of_its_horizon() {
        let mut e = Envelope::new(4);
        for k in 0..50 {
            e.track(k as f64);
        }
        let mut pred = vec![50.0, f64::NAN, 52.0, 53.0];
        let (mut lo, mut hi) = (vec![49.0; 4], vec![54.0; 4]);
        let cut = e.cut(
            &mut pred,
            49.0,
            |_, d, s| (1.5 * d, 1.5 * s),
            1.5,
            None,
            &mut lo,
            &mut hi,
        );
        assert_eq!(cut, 3);
        assert_eq!(pred, vec![50.0, 49.0, 49.0, 49.0]);
        assert!(lo.iter().chain(&hi).all(|v| v.is_finite()));
    }

    #[test]
    fn before_any_motion_a_jump_is_cut_to_the_noise() {
        let mut e = Envelope::new(4);
        for k in 0..50 {
            e.track(1e-9 * ((k * 7 % 3) as f64 - 1.0));
        }
        let mut pred = vec![-1e-3; 4];
        let (mut lo, mut hi) = (vec![-2e-3; 4], vec![0.0; 4]);
        assert_eq!(
            e.cut(
                &mut pred,
                0.0,
                |_, d, s| (1.5 * d, 1.5 * s),
                f64::INFINITY,
                None,
                &mut lo,
                &mut hi
            ),
            4
        );
        assert!(pred.iter().all(|v| v.abs() <= 1e-8), "{pred:?}");
        // its interval still reaches what the model said, widened to the hold
        assert!(lo.iter().all(|&l| l <= -1e-3 + 1e-9), "{lo:?}");
    }

    #[test]
    fn units_do_not_change_what_is_cut() {
        let y: Vec<f64> = (0..80).map(|k| ((k as f64) * 0.2).sin()).collect();
        let run = |scale: f64| {
            let mut e = Envelope::new(6);
            for v in &y {
                e.track(v * scale);
            }
            let mut p: Vec<f64> = (1..=6).map(|j| scale * 0.3 * j as f64).collect();
            let (mut lo, mut hi) = (p.clone(), p.clone());
            let n = e.cut(
                &mut p,
                y[79] * scale,
                |_, d, s| (1.5 * d, 1.5 * s),
                f64::INFINITY,
                None,
                &mut lo,
                &mut hi,
            );
            (n, p.iter().map(|v| v / scale).collect::<Vec<_>>())
        };
        let (a, pa) = run(1.0);
        let (b, pb) = run(1e-6);
        assert_eq!(a, b);
        for (x, z) in pa.iter().zip(&pb) {
            assert!((x - z).abs() < 1e-9 * x.abs().max(1.0));
        }
    }
}
