//! Min/max decimation of long series for plotting.
//!
//! A recording of an hour at 5 kHz has 18 million samples; a figure needs a
//! few thousand points per curve. Plain subsampling drops spikes (a 1-sample
//! 5 mm blow-up disappears), so the samples are split into `B` buckets of
//! consecutive indices and each bucket keeps its smallest and its largest
//! finite value, in their original order:
//!
//! ```text
//! bucket j = [j·b, (j+1)·b),   b = ⌈n / B⌉,   B = ⌊max_points / 2⌋
//! ```
//!
//! Every extremum of every bucket (hence the global extrema) is kept, so the
//! drawn envelope is the true one at the figure's resolution. Non-finite
//! values (gaps, e.g. samples without a prediction) are kept as one NaN
//! between the runs they separate, so gaps stay gaps. Without gaps the result
//! has at most `max_points` points.
//!
//! Reference: the "min/max" reduction of time-series plotting tools (e.g.
//! S. Steinarsson, *Downsampling Time Series for Visual Representation*, 2013, §3).
//!
//! ```
//! use feedid_report::plot::decimate_minmax;
//! let x: Vec<f64> = (0..10_000).map(|k| k as f64).collect();
//! let mut y = vec![0.0; 10_000];
//! y[4321] = 5.0; // a one-sample spike
//! let (xd, yd) = decimate_minmax(&x, &y, 200);
//! assert!(xd.len() <= 200);
//! assert!(yd.contains(&5.0));
//! ```

/// Min/max decimation of `(x, y)` to about `max_points` points (see the module doc).
///
/// Series no longer than `max_points` (or `max_points < 4`) are returned
/// unchanged; `x` and `y` are cut to the shorter length.
pub fn decimate_minmax(x: &[f64], y: &[f64], max_points: usize) -> (Vec<f64>, Vec<f64>) {
    let n = x.len().min(y.len());
    if n <= max_points || max_points < 4 {
        return (x[..n].to_vec(), y[..n].to_vec());
    }
    let buckets = max_points / 2;
    let b = n.div_ceil(buckets);
    let mut xo = Vec::with_capacity(max_points + 8);
    let mut yo = Vec::with_capacity(max_points + 8);
    // A run of finite samples inside one bucket: emit its min and max in index order.
    let emit = |lo: usize, hi: usize, xo: &mut Vec<f64>, yo: &mut Vec<f64>| {
        let (mut imin, mut imax) = (lo, lo);
        for k in lo..hi {
            if y[k] < y[imin] {
                imin = k;
            }
            if y[k] > y[imax] {
                imax = k;
            }
        }
        let (a, c) = if imin <= imax {
            (imin, imax)
        } else {
            (imax, imin)
        };
        xo.push(x[a]);
        yo.push(y[a]);
        if c != a {
            xo.push(x[c]);
            yo.push(y[c]);
        }
    };
    let finite = |k: usize| x[k].is_finite() && y[k].is_finite();
    let mut start = 0;
    while start < n {
        let end = (start + b).min(n);
        let mut k = start;
        while k < end {
            if !finite(k) {
                // one NaN per gap (not before the first point, not twice in a row)
                if yo.last().is_some_and(|v: &f64| v.is_finite()) {
                    xo.push(x[k]);
                    yo.push(f64::NAN);
                }
                k += 1;
                continue;
            }
            let run = k;
            while k < end && finite(k) {
                k += 1;
            }
            emit(run, k, &mut xo, &mut yo);
        }
        start = end;
    }
    (xo, yo)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn decimation_keeps_every_bucket_extremum_and_the_order() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let n: usize = 100_003;
        let x: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let y: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
        let max_points = 2000;
        let (xd, yd) = decimate_minmax(&x, &y, max_points);
        assert!(xd.len() <= max_points, "{}", xd.len());
        assert!(
            xd.windows(2).all(|w| w[0] < w[1]),
            "abscissae stay increasing"
        );
        let b = n.div_ceil(max_points / 2);
        for chunk in (0..n).step_by(b) {
            let hi = (chunk + b).min(n);
            let bmax = y[chunk..hi].iter().cloned().fold(f64::MIN, f64::max);
            let bmin = y[chunk..hi].iter().cloned().fold(f64::MAX, f64::min);
            assert!(yd.contains(&bmax) && yd.contains(&bmin), "bucket {chunk}");
        }
        // every output point is an input point
        for (xv, yv) in xd.iter().zip(&yd) {
            let k = (xv / 1e-3).round() as usize;
            assert_eq!(y[k], *yv);
        }
    }

    #[test]
    fn one_sample_spikes_survive() {
        let n = 50_000;
        let x: Vec<f64> = (0..n).map(|k| k as f64).collect();
        let mut y = vec![0.0; n];
        y[17] = 3.0;
        y[31_415] = -7.0;
        let (_, yd) = decimate_minmax(&x, &y, 500);
        assert!(yd.contains(&3.0) && yd.contains(&-7.0));
    }

    #[test]
    fn gaps_are_kept_as_single_nans() {
        let n = 10_000;
        let x: Vec<f64> = (0..n).map(|k| k as f64).collect();
        let y: Vec<f64> = (0..n)
            .map(|k| {
                if (3000..5000).contains(&k) {
                    f64::NAN
                } else {
                    k as f64
                }
            })
            .collect();
        let (xd, yd) = decimate_minmax(&x, &y, 400);
        let nans = yd.iter().filter(|v| v.is_nan()).count();
        assert_eq!(nans, 1);
        let i = yd.iter().position(|v| v.is_nan()).unwrap();
        assert!(yd[i - 1] <= 2999.0 && yd[i + 1] >= 5000.0);
        assert!(xd.len() <= 402);
        // the first and last finite values (extrema of a monotone series) survive
        assert_eq!(yd[0], 0.0);
        assert_eq!(*yd.last().unwrap(), (n - 1) as f64);
    }

    #[test]
    fn short_series_are_unchanged() {
        let x = [0.0, 1.0, 2.0];
        let y = [1.0, f64::NAN, 3.0];
        let (xd, yd) = decimate_minmax(&x, &y, 10);
        assert_eq!(xd, x.to_vec());
        assert!(yd[1].is_nan() && yd[0] == 1.0 && yd[2] == 3.0);
    }
}
