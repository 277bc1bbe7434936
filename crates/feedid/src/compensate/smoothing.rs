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
//!
//! [`gaussian_smooth_profile`] lets σ vary along the trajectory (σ\[k\] for
//! output sample k, in steps of ⅛ sample): smoothing only where a limit
//! needs it. Each output is still a symmetric, normalised average, so a
//! straight line stays exact whatever the profile; [`taper_profile`] makes a
//! profile change slowly (at most one sample of σ per [`TAPER`] samples) so
//! that a curved trajectory stays smooth where σ changes.

use std::collections::HashMap;

/// Samples over which a tapered profile changes σ by one sample.
pub const TAPER: f64 = 8.0;

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

/// Normalised half-kernel `w_0 … w_h` for σ \[samples\].
fn kernel(sigma: f64) -> Vec<f64> {
    let h = (4.0 * sigma).ceil() as usize;
    let w: Vec<f64> = (0..=h)
        .map(|j| (-(j as f64).powi(2) / (2.0 * sigma * sigma)).exp())
        .collect();
    let norm = w[0] + 2.0 * w[1..].iter().sum::<f64>();
    w.into_iter().map(|v| v / norm).collect()
}

/// Smooth `y` into `out` with σ\[k\] = `sigma[k]` \[samples\] at output
/// sample `k` (rounded to ⅛ sample, the grid of [`taper_profile`]; below
/// ⅛: a copy of `y[k]`); `y` is held at
/// its end values beyond its ends. `sigma` and `out` have the length of `y`.
pub fn gaussian_smooth_profile(y: &[f64], sigma: &[f64], out: &mut [f64]) {
    let n = y.len().min(out.len()).min(sigma.len());
    let mut cache: HashMap<u32, Vec<f64>> = HashMap::new();
    let at = |k: isize| y[k.clamp(0, n as isize - 1) as usize];
    for k in 0..n {
        let s = sigma[k];
        if !(s.is_finite() && s >= 0.125) {
            out[k] = y[k];
            continue;
        }
        let key = (8.0 * s).round() as u32;
        let w = cache
            .entry(key)
            .or_insert_with(|| kernel(f64::from(key) / 8.0));
        let ki = k as isize;
        let mut acc = w[0] * y[k];
        for (j, wj) in w.iter().enumerate().skip(1) {
            let j = j as isize;
            acc += wj * (at(ki - j) + at(ki + j));
        }
        out[k] = acc;
    }
}

/// Taper a profile in place: σ\[k\] ← max over j of σ\[j\] − |k − j|/[`TAPER`].
pub fn taper_profile(sigma: &mut [f64]) {
    let n = sigma.len();
    for k in 1..n {
        sigma[k] = sigma[k].max(sigma[k - 1] - 1.0 / TAPER);
    }
    for k in (0..n.saturating_sub(1)).rev() {
        sigma[k] = sigma[k].max(sigma[k + 1] - 1.0 / TAPER);
    }
}

/// A step from 0 (x ≤ 0) to 1 (x ≥ 1) with every derivative continuous:
/// `φ(x)/(φ(x) + φ(1 − x))`, `φ(x) = exp(−1/x)`.
pub fn smooth_step(x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let a = (-1.0 / x).exp();
    let b = (-1.0 / (1.0 - x)).exp();
    a / (a + b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_constant_profile_equals_the_fixed_smoothing() {
        let y: Vec<f64> = (0..300)
            .map(|k| ((k as f64 - 100.0).max(0.0) * 0.01).sin())
            .collect();
        let mut a = vec![0.0; 300];
        let mut b = vec![0.0; 300];
        gaussian_smooth(&y, 3.25, &mut a);
        gaussian_smooth_profile(&y, &[3.25; 300], &mut b);
        for k in 0..300 {
            assert!((a[k] - b[k]).abs() < 1e-14, "{k}");
        }
    }

    #[test]
    fn a_varying_profile_keeps_straight_lines_and_smooths_only_where_asked() {
        // two corners; smoothing only around the second
        let y: Vec<f64> = (0..400)
            .map(|k| (k as f64 - 100.0).clamp(0.0, 200.0))
            .collect();
        let mut sigma = vec![0.0; 400];
        for s in &mut sigma[280..320] {
            *s = 4.0;
        }
        taper_profile(&mut sigma);
        assert!((sigma[250] - (4.0 - 30.0 / TAPER)).abs() < 1e-12);
        let mut out = vec![0.0; 400];
        gaussian_smooth_profile(&y, &sigma, &mut out);
        // the first corner is untouched, the line between is exact
        for k in 0..260 {
            assert!((out[k] - y[k]).abs() < 1e-12, "{k}");
        }
        // the second corner is rounded by Δv·σ/√(2π)
        let want = 4.0 / (2.0 * std::f64::consts::PI).sqrt();
        assert!((y[300] - out[300] - want).abs() < 1e-2 * want);
    }

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
