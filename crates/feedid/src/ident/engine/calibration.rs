//! The calibration of the engine's prediction intervals (the guard's
//! module doc, *Prediction intervals*, has the equations and references):
//! the scale of a regime's errors at a step ahead, the median of its last
//! errors, and the regime's factor on it, adapted by adaptive conformal
//! inference on whether each interval as given held.

/// Errors at a step ahead (per regime) whose median is its scale.
pub(super) const SCALE_MEMORY: usize = 20;

/// Errors needed in a regime at a step ahead before its interval there is
/// calibrated.
pub(super) const CALIBRATED: usize = 5;

/// The range of a regime's factor on the per-step scales (its bounds keep
/// a factor that a run of exact predictions drives down, or of a regime
/// the scales never describe up, within reach of its errors).
pub(super) const FACTOR_RANGE: (f64, f64) = (1e-4, 1e6);

/// A per-regime factor on the per-step scales: multiplied by
/// `up = e^{η·P}` after a measured sample outside the interval it gave and
/// by `down = e^{−η(1−P)}` after one inside, so that in the long run a
/// share `1 − P` of its intervals miss (see the guard's module doc), within
/// [`FACTOR_RANGE`].
#[derive(Debug, Clone, Copy)]
pub(super) struct Tracker {
    /// The factor.
    pub(super) q: f64,
    /// Updates taken.
    n: usize,
}

impl Tracker {
    /// A new factor: the ratio of the 95 % quantile to the median of
    /// Gaussian errors (about 2.9) rounded.
    pub(super) const START: Self = Self { q: 3.0, n: 0 };

    /// Take whether the interval the factor gave missed, with the step
    /// factors of the tracker's age (`rates[n]`, the last one from then on).
    pub(super) fn step(&mut self, miss: bool, rates: &[(f64, f64)]) {
        let (up, down) = rates[self.n.min(rates.len() - 1)];
        self.q = (self.q * if miss { up } else { down }).clamp(FACTOR_RANGE.0, FACTOR_RANGE.1);
        self.n += 1;
    }
}

/// The last [`SCALE_MEMORY`] absolute errors at one step ahead and their
/// median: the scale of that step's errors. The errors are kept twice, in
/// arrival order (to drop the oldest) and sorted (the median in O(1)), so
/// that a new error costs two binary searches and a shift of at most
/// [`SCALE_MEMORY`] values.
#[derive(Debug, Clone, Copy)]
pub(super) struct StepErrors {
    ring: [f64; SCALE_MEMORY],
    sorted: [f64; SCALE_MEMORY],
    next: usize,
    /// Errors taken since the reset.
    pub(super) n: usize,
}

impl StepErrors {
    pub(super) const NEW: Self = Self {
        ring: [0.0; SCALE_MEMORY],
        sorted: [0.0; SCALE_MEMORY],
        next: 0,
        n: 0,
    };

    /// Take the error `e` (finite, ≥ 0).
    pub(super) fn push(&mut self, e: f64) {
        let len = self.n.min(SCALE_MEMORY);
        let sorted = &mut self.sorted;
        if len == SCALE_MEMORY {
            // the memory is full: the oldest's place in the sorted values
            // moves to where the new error belongs
            let old = self.ring[self.next];
            let mut i = sorted.partition_point(|&v| v < old).min(len - 1);
            if e > old {
                while i + 1 < len && sorted[i + 1] < e {
                    sorted[i] = sorted[i + 1];
                    i += 1;
                }
            } else {
                while i > 0 && sorted[i - 1] > e {
                    sorted[i] = sorted[i - 1];
                    i -= 1;
                }
            }
            sorted[i] = e;
        } else {
            let i = sorted[..len].partition_point(|&v| v < e);
            sorted.copy_within(i..len, i + 1);
            sorted[i] = e;
        }
        self.ring[self.next] = e;
        self.next = if self.next + 1 == SCALE_MEMORY {
            0
        } else {
            self.next + 1
        };
        self.n += 1;
    }

    /// The median of the errors in memory; while it is 0 (more than half
    /// the errors exactly 0, a held position read by a coarse encoder),
    /// their mean \[m\].
    pub(super) fn scale(&self) -> f64 {
        let len = self.n.min(SCALE_MEMORY);
        if len == 0 {
            return 0.0;
        }
        let median = self.sorted[len / 2];
        if median > 0.0 {
            median
        } else {
            self.sorted[..len].iter().sum::<f64>() / len as f64
        }
    }
}

/// The step factors of a tracker by its age: `η_n = max(η, 1/√(n+1))`,
/// so that a first width below the errors' scale grows to it in about half
/// the errors that `η` alone takes; from `n = 1/η²` on (at most 1000), `η`.
pub(super) fn adaptation_rates(eta: f64, p: f64) -> Vec<(f64, f64)> {
    let factors = |rate: f64| ((rate * p).exp(), (-rate * (1.0 - p)).exp());
    let warm = (1.0 / (eta * eta)).ceil().clamp(1.0, 1000.0) as usize;
    (0..warm)
        .map(|n| factors(eta.max(1.0 / ((n + 1) as f64).sqrt())))
        .chain(std::iter::once(factors(eta)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Errors `scale(i)·u` (`u` uniform in [0, 1)) at one step ahead,
    /// each interval given as the step's scale times the factor before the
    /// error is known; returns the share of errors outside their interval
    /// after the first `skip` and the last width.
    fn misses(p: f64, n: usize, skip: usize, scale: impl Fn(usize) -> f64) -> (f64, f64) {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        let rates = adaptation_rates(0.2, p);
        let (mut step, mut factor) = (StepErrors::NEW, Tracker::START);
        let (mut out, mut total, mut width) = (0, 0, 0.0);
        for i in 0..n {
            let e = scale(i) * rng.random::<f64>();
            if step.n >= CALIBRATED {
                width = step.scale() * factor.q;
                let miss = e > width;
                factor.step(miss, &rates);
                if i >= skip {
                    out += usize::from(miss);
                    total += 1;
                }
            }
            step.push(e);
        }
        (out as f64 / total as f64, width)
    }

    #[test]
    fn a_share_one_minus_p_of_stationary_errors_leaves_the_interval() {
        // uniform errors: the 0.9-quantile is 0.9 and the median 0.5, so
        // the factor settles near 1.8 and a tenth of the errors miss
        let (share, width) = misses(0.9, 200_000, 1000, |_| 1.0);
        assert!((share - 0.1).abs() < 0.005, "{share}");
        assert!(width > 0.6 && width < 1.2, "{width}");
        let (share, _) = misses(0.95, 200_000, 1000, |_| 1.0);
        assert!((share - 0.05).abs() < 0.005, "{share}");
    }

    #[test]
    fn the_share_of_misses_holds_when_the_errors_fall_a_thousandfold() {
        // the errors of a model that has converged fall 1000× after the
        // first 300: the scale follows within its memory, so the share
        // of misses over what follows stays near 1 − P and the width
        // reaches the new errors' scale
        let (share, width) = misses(0.95, 3000, 0, |i| if i < 300 { 1.0 } else { 1e-3 });
        assert!((share - 0.05).abs() < 0.015, "{share}");
        assert!(width < 3e-3, "{width}");
        // the same errors in other units: the same misses, widths in those
        // units
        let (share_um, width_um) =
            misses(0.95, 3000, 0, |i| 1e6 * if i < 300 { 1.0 } else { 1e-3 });
        assert_eq!(share, share_um);
        assert!(
            (width_um - 1e6 * width).abs() <= 1e-9 * width_um,
            "{width_um} {width}"
        );
    }

    #[test]
    fn a_step_scale_is_the_median_of_its_recent_errors() {
        let mut s = StepErrors::NEW;
        for e in [5.0, 1.0, 3.0] {
            s.push(e);
        }
        assert_eq!(s.scale(), 3.0);
        // more than half of the memory at a new level: the scale is there
        for _ in 0..SCALE_MEMORY / 2 + 1 {
            s.push(1e-6);
        }
        assert_eq!(s.scale(), 1e-6);
        for _ in 0..SCALE_MEMORY / 2 + 1 {
            s.push(7.0);
        }
        assert_eq!(s.scale(), 7.0);
        // errors mostly exactly 0 (a held position on a coarse encoder):
        // their mean, not 0
        let mut z = StepErrors::NEW;
        for e in [0.0, 0.0, 0.0, 4.0] {
            z.push(e);
        }
        assert_eq!(z.scale(), 1.0);
    }

    #[test]
    fn the_kept_median_equals_the_median_of_the_last_errors_sorted_afresh() {
        // seeded errors with many ties (a coarse grid) and exact zeros,
        // mixed with errors off the grid
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let mut s = StepErrors::NEW;
        let mut all = Vec::new();
        for _ in 0..4000 {
            let e = if rng.random_bool(0.7) {
                (rng.random::<f64>() * 6.0).floor() * 0.5
            } else {
                rng.random::<f64>() * 3.0
            };
            s.push(e);
            all.push(e);
            let mut last: Vec<f64> = all[all.len().saturating_sub(SCALE_MEMORY)..].to_vec();
            last.sort_by(f64::total_cmp);
            assert_eq!(&s.sorted[..last.len()], &last[..]);
            let median = last[last.len() / 2];
            let expected = if median > 0.0 {
                median
            } else {
                last.iter().sum::<f64>() / last.len() as f64
            };
            assert_eq!(s.scale(), expected);
        }
    }

    #[test]
    fn a_factor_stays_within_its_range() {
        let rates = adaptation_rates(0.2, 0.95);
        let mut f = Tracker::START;
        for _ in 0..100_000 {
            f.step(false, &rates);
        }
        assert_eq!(f.q, FACTOR_RANGE.0);
        for _ in 0..100_000 {
            f.step(true, &rates);
        }
        assert_eq!(f.q, FACTOR_RANGE.1);
    }
}
