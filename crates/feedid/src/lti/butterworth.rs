//! Butterworth low-pass filters as cascades of biquads (bilinear transform
//! with the cutoff prewarped) and zero-phase filtering (forward, then
//! backward: the magnitude squared, no delay), as inverse-dynamics
//! identification filters positions before differentiating them.
//!
//! The analogue prototype of even order `N` has the sections
//! `ω_c² / (s² + 2·sin θ_k·ω_c·s + ω_c²)`, `θ_k = π(2k + 1)/(2N)`; with
//! `Ω = tan(π·f_c/f_s)` each becomes
//!
//! ```text
//! H_k(z) = Ω²·(1 + 2z⁻¹ + z⁻²) / ((1 + a_kΩ + Ω²) + 2(Ω² − 1)z⁻¹ + (1 − a_kΩ + Ω²)z⁻²),  a_k = 2·sin θ_k
//! ```
//!
//! (an odd order adds the first-order section `Ω(1 + z⁻¹)/((1 + Ω) + (Ω − 1)z⁻¹)`).
//! [`filtfilt`] pads both ends with the signal's odd reflection (60
//! samples per section, at most the signal's length − 1: a straight line
//! continues straight) and starts each pass from rest at the first padded
//! value, so that a constant and a ramp pass unchanged and the ends carry
//! little start-up transient.

use crate::error::{Error, Result};

/// One second-order section `(b₀ + b₁z⁻¹ + b₂z⁻²)/(1 + a₁z⁻¹ + a₂z⁻²)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Biquad {
    /// Numerator `[b₀, b₁, b₂]`.
    pub b: [f64; 3],
    /// Denominator `[a₁, a₂]` (`a₀ = 1`).
    pub a: [f64; 2],
}

/// A Butterworth low-pass of `order` (1 … 12) with cutoff `cutoff_hz`
/// (−3 dB) at the sampling rate `rate_hz`, as biquads.
///
/// ```
/// use feedid::lti::{butterworth_lowpass, filtfilt};
/// let f = butterworth_lowpass(4, 100.0, 1000.0).unwrap();
/// assert_eq!(f.len(), 2);
/// let y = filtfilt(&f, &vec![2.5; 300]);
/// assert!(y.iter().all(|v| (v - 2.5).abs() < 1e-12));
/// ```
pub fn butterworth_lowpass(order: usize, cutoff_hz: f64, rate_hz: f64) -> Result<Vec<Biquad>> {
    if !(1..=12).contains(&order) {
        return Err(Error::InvalidParameter {
            name: "filter order",
            value: order as f64,
            reason: "must be 1 … 12",
        });
    }
    if !(rate_hz.is_finite()
        && rate_hz > 0.0
        && cutoff_hz.is_finite()
        && cutoff_hz > 0.0
        && cutoff_hz < 0.5 * rate_hz)
    {
        return Err(Error::InvalidParameter {
            name: "filter cutoff",
            value: cutoff_hz,
            reason: "must be > 0 and below half the sampling rate",
        });
    }
    let w = (std::f64::consts::PI * cutoff_hz / rate_hz).tan();
    let w2 = w * w;
    let mut sections = Vec::with_capacity(order.div_ceil(2));
    for k in 0..order / 2 {
        let theta = std::f64::consts::PI * (2 * k + 1) as f64 / (2 * order) as f64;
        let a = 2.0 * theta.sin();
        let a0 = 1.0 + a * w + w2;
        sections.push(Biquad {
            b: [w2 / a0, 2.0 * w2 / a0, w2 / a0],
            a: [2.0 * (w2 - 1.0) / a0, (1.0 - a * w + w2) / a0],
        });
    }
    if order % 2 == 1 {
        let a0 = 1.0 + w;
        sections.push(Biquad {
            b: [w / a0, w / a0, 0.0],
            a: [(w - 1.0) / a0, 0.0],
        });
    }
    Ok(sections)
}

/// Run the sections over `x` in place, from rest at `x[0]` (direct form II transposed).
fn pass(sections: &[Biquad], x: &mut [f64]) {
    let Some(&first) = x.first() else {
        return;
    };
    for s in sections {
        // the state of a section at rest with input and output `first`
        // (unit DC gain): z₁ = first·(1 − b₀), z₂ = first·(b₂ − a₂)
        let (mut z1, mut z2) = (first * (1.0 - s.b[0]), first * (s.b[2] - s.a[1]));
        for v in x.iter_mut() {
            let u = *v;
            let y = s.b[0] * u + z1;
            z1 = s.b[1] * u - s.a[0] * y + z2;
            z2 = s.b[2] * u - s.a[1] * y;
            *v = y;
        }
    }
}

/// Zero-phase filtering of `x` by `sections` (module doc).
pub fn filtfilt(sections: &[Biquad], x: &[f64]) -> Vec<f64> {
    let n = x.len();
    if n < 2 {
        return x.to_vec();
    }
    let pad = (60 * sections.len().max(1)).min(n - 1);
    let mut y = Vec::with_capacity(n + 2 * pad);
    y.extend((1..=pad).rev().map(|i| 2.0 * x[0] - x[i]));
    y.extend_from_slice(x);
    y.extend((1..=pad).map(|i| 2.0 * x[n - 1] - x[n - 1 - i]));
    pass(sections, &mut y);
    y.reverse();
    pass(sections, &mut y);
    y.reverse();
    y[pad..pad + n].to_vec()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// |H(e^{jω})| of the cascade.
    fn magnitude(sections: &[Biquad], f: f64, rate: f64) -> f64 {
        let w = 2.0 * std::f64::consts::PI * f / rate;
        let z1 = nalgebra::Complex::new(w.cos(), -w.sin());
        let z2 = z1 * z1;
        sections
            .iter()
            .map(|s| {
                let num = s.b[0] + z1 * s.b[1] + z2 * s.b[2];
                let den = nalgebra::Complex::new(1.0, 0.0) + z1 * s.a[0] + z2 * s.a[1];
                (num / den).norm()
            })
            .product()
    }

    #[test]
    fn the_response_is_maximally_flat_with_minus_3_db_at_the_cutoff() {
        for order in [1, 2, 3, 4, 6] {
            let f = butterworth_lowpass(order, 100.0, 1000.0).unwrap();
            assert!((magnitude(&f, 0.0, 1000.0) - 1.0).abs() < 1e-12);
            let at_cutoff = magnitude(&f, 100.0, 1000.0);
            assert!(
                (at_cutoff - 0.5f64.sqrt()).abs() < 1e-9,
                "{order}: {at_cutoff}"
            );
            // the analogue prototype's |H| = 1/√(1 + (Ω_d/Ω_c)^{2N}) at the prewarped frequency
            let omega = |f: f64| (std::f64::consts::PI * f / 1000.0).tan();
            let r = omega(200.0) / omega(100.0);
            let expected = 1.0 / (1.0 + r.powi(2 * order as i32)).sqrt();
            assert!(
                (magnitude(&f, 200.0, 1000.0) - expected).abs() < 1e-9,
                "{order}"
            );
        }
    }

    #[test]
    fn filtfilt_has_no_delay_and_squares_the_magnitude() {
        let f = butterworth_lowpass(4, 100.0, 1000.0).unwrap();
        let sine = |hz: f64| -> Vec<f64> {
            (0..4000)
                .map(|k| (2.0 * std::f64::consts::PI * hz * k as f64 / 1000.0).sin())
                .collect()
        };
        // well inside the pass band: the same sine, no phase shift
        let x = sine(5.0);
        let y = filtfilt(&f, &x);
        let worst = x[500..3500]
            .iter()
            .zip(&y[500..3500])
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-6, "{worst}");
        // at the cutoff: amplitude 1/2 (−3 dB twice), still in phase
        let x = sine(100.0);
        let y = filtfilt(&f, &x);
        for k in 1000..3000 {
            assert!((y[k] - 0.5 * x[k]).abs() < 1e-6, "{k}: {} {}", y[k], x[k]);
        }
        // a ramp passes unchanged, ends included (odd reflection)
        let ramp: Vec<f64> = (0..500).map(|k| 0.1 * k as f64).collect();
        let y = filtfilt(&f, &ramp);
        let worst = ramp
            .iter()
            .zip(&y)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-9, "{worst}");
    }

    #[test]
    fn invalid_designs_are_refused() {
        assert!(butterworth_lowpass(0, 10.0, 100.0).is_err());
        assert!(butterworth_lowpass(4, 50.0, 100.0).is_err());
        assert!(butterworth_lowpass(4, f64::NAN, 100.0).is_err());
    }
}
