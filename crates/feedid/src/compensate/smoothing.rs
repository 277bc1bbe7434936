//! Zero-phase Gaussian smoothing of a desired trajectory.
//!
//! ```text
//! ỹ[k] = Σ_{j=−h..h} w_j·y[k + j],   w_j ∝ exp(−j²/(2σ²)),  Σ w_j = 1,  h = ⌈4σ⌉
//! ```
//!
//! with `y` held at its first value before the start and at its last value
//! after the end. The kernel is symmetric, so the smoothing has no delay and
//! reproduces straight lines exactly: a ramp keeps its speed and position
//! away from its corners, and only the corners (where the speed jumps) are
//! rounded, over about ±2σ, with an error of at most `Δv·σ/√(2π)` at the
//! corner. The rounded trajectory has finite derivatives of every order,
//! which the inverse of a model with a large high-frequency gain needs.

/// Smooth `y` with a Gaussian of standard deviation `sigma` \[samples\] into
/// `out` (same length); `sigma ≤ 0` copies.
pub fn gaussian_smooth(y: &[f64], sigma: f64, out: &mut [f64]) {
    let n = y.len().min(out.len());
    if n == 0 {
        return;
    }
    if !(sigma.is_finite() && sigma > 0.0) {
        out[..n].copy_from_slice(&y[..n]);
        return;
    }
    let h = (4.0 * sigma).ceil() as usize;
    let w: Vec<f64> = (0..=h)
        .map(|j| (-(j as f64).powi(2) / (2.0 * sigma * sigma)).exp())
        .collect();
    let norm = w[0] + 2.0 * w[1..].iter().sum::<f64>();
    let at = |k: isize| y[k.clamp(0, n as isize - 1) as usize];
    for (k, o) in out.iter_mut().enumerate().take(n) {
        let k = k as isize;
        let mut acc = w[0] * at(k);
        for (j, wj) in w.iter().enumerate().skip(1) {
            let j = j as isize;
            acc += wj * (at(k - j) + at(k + j));
        }
        *o = acc / norm;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ramp_is_kept_away_from_its_corners_and_rounded_at_them() {
        let n = 400;
        let v = 1e-3;
        let y: Vec<f64> = (0..n)
            .map(|k| v * (k as f64 - 100.0).clamp(0.0, 200.0))
            .collect();
        let mut s = vec![0.0; n];
        let sigma = 5.0;
        gaussian_smooth(&y, sigma, &mut s);
        for k in 130..270 {
            assert!((s[k] - y[k]).abs() < 1e-15, "{k}");
        }
        // corner error Δv·σ/√(2π)
        let want = v * sigma / (2.0 * std::f64::consts::PI).sqrt();
        assert!(
            (s[100] - y[100] - want).abs() < 1e-2 * want,
            "{} vs {want}",
            s[100] - y[100]
        );
    }

    #[test]
    fn zero_sigma_copies() {
        let y = [1.0, 2.0, 4.0];
        let mut s = [0.0; 3];
        gaussian_smooth(&y, 0.0, &mut s);
        assert_eq!(s, y);
    }
}
