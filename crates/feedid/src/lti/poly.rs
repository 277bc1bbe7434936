//! Real polynomials in descending powers: roots, construction from roots and
//! evaluation.
//!
//! * Roots are the eigenvalues of the companion matrix of the monic polynomial
//!   after diagonal balancing ([`super::balance`]), computed with the
//!   double-shift Hessenberg QR iteration ([`super::eig`]). This is the method
//!   of MATLAB's `roots` and is backward stable for balanced companion
//!   matrices (Edelman & Murakami, Math. Comp. 64, 1995); balancing matters
//!   here because feed-drive coefficients span 1e-8 … 1e16. Trailing zero
//!   coefficients give exact roots at 0.
//! * Construction from roots multiplies real linear factors `(s − p)` and, for
//!   conjugate pairs, real quadratics `s² − 2·Re p·s + |p|²`, so no complex
//!   rounding leaks into the real coefficients.
//! * Evaluation is Horner's rule.

use nalgebra::{Complex, DMatrix};

use super::balance::balanced;
use super::eig::hessenberg_eigenvalues;
use crate::error::{Error, Result};

/// Roots of a real polynomial given in descending powers.
///
/// Leading zeros are stripped; a constant (or empty, or all-zero) polynomial has
/// no roots. Roots are sorted by modulus, then by imaginary part.
///
/// ```
/// use feedid::lti::poly_roots;
/// let r = poly_roots(&[1.0, 3.0, 2.0]).unwrap(); // (s + 1)(s + 2)
/// assert!((r[0].re + 1.0).abs() < 1e-12 && (r[1].re + 2.0).abs() < 1e-12);
/// ```
pub fn poly_roots(coeffs: &[f64]) -> Result<Vec<Complex<f64>>> {
    if coeffs.iter().any(|c| !c.is_finite()) {
        return Err(Error::InvalidModel {
            reason: "non-finite polynomial coefficient",
        });
    }
    let first = coeffs
        .iter()
        .position(|&c| c != 0.0)
        .unwrap_or(coeffs.len());
    let c = &coeffs[first..];
    if c.len() <= 1 {
        return Ok(Vec::new());
    }
    let trailing = c.iter().rev().take_while(|&&v| v == 0.0).count();
    let c = &c[..c.len() - trailing];
    let mut roots = vec![Complex::new(0.0, 0.0); trailing];
    let n = c.len() - 1;
    if n > 0 {
        let lead = c[0];
        let mut comp = DMatrix::<f64>::zeros(n, n);
        for j in 0..n {
            let v = -c[j + 1] / lead;
            if !v.is_finite() {
                return Err(Error::InvalidModel {
                    reason: "polynomial coefficients overflow when made monic",
                });
            }
            comp[(0, j)] = v;
        }
        for i in 1..n {
            comp[(i, i - 1)] = 1.0;
        }
        // Diagonal balancing keeps the upper Hessenberg structure.
        roots.extend(hessenberg_eigenvalues(&balanced(&comp))?);
    }
    sort_roots(&mut roots);
    Ok(roots)
}

/// Sort by modulus, then imaginary part (deterministic order for callers and tests).
pub(crate) fn sort_roots(roots: &mut [Complex<f64>]) {
    roots.sort_by(|a, b| {
        a.norm()
            .partial_cmp(&b.norm())
            .unwrap_or(std::cmp::Ordering::Equal)
            .then(a.im.partial_cmp(&b.im).unwrap_or(std::cmp::Ordering::Equal))
    });
}

/// Monic real polynomial (descending powers) with the given roots.
///
/// Complex roots are matched with their conjugates (exact or within 1e-10
/// relative) and multiplied as real quadratics; unmatched complex roots are
/// multiplied in complex arithmetic and only the real part is kept.
pub fn poly_from_roots(roots: &[Complex<f64>]) -> Vec<f64> {
    let n = roots.len();
    let mut used = vec![false; n];
    let mut real = vec![1.0];
    let mut cplx = vec![Complex::new(1.0, 0.0)];
    for i in 0..n {
        if used[i] {
            continue;
        }
        used[i] = true;
        let r = roots[i];
        if r.im == 0.0 {
            real = poly_mul(&real, &[1.0, -r.re]);
            continue;
        }
        // Best conjugate partner among the unused roots.
        let target = r.conj();
        let mut best: Option<(usize, f64)> = None;
        for (j, rj) in roots.iter().enumerate().skip(i + 1) {
            if used[j] {
                continue;
            }
            let dist = (rj - target).norm();
            if best.is_none_or(|(_, d)| dist < d) {
                best = Some((j, dist));
            }
        }
        match best {
            Some((j, dist)) if dist <= 1e-10 * r.norm() => {
                used[j] = true;
                let re = 0.5 * (r.re + roots[j].re);
                let im = 0.5 * (r.im.abs() + roots[j].im.abs());
                real = poly_mul(&real, &[1.0, -2.0 * re, re * re + im * im]);
            }
            _ => {
                let mut next = vec![Complex::new(0.0, 0.0); cplx.len() + 1];
                for (k, c) in cplx.iter().enumerate() {
                    next[k] += c;
                    next[k + 1] -= c * r;
                }
                cplx = next;
            }
        }
    }
    let cre: Vec<f64> = cplx.iter().map(|c| c.re).collect();
    poly_mul(&real, &cre)
}

/// Product of two polynomials (descending powers).
pub(crate) fn poly_mul(a: &[f64], b: &[f64]) -> Vec<f64> {
    if a.is_empty() || b.is_empty() {
        return Vec::new();
    }
    let mut out = vec![0.0; a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            out[i + j] += x * y;
        }
    }
    out
}

/// Value of a real polynomial (descending powers) at complex `s` by Horner's rule.
///
/// An empty coefficient list is the zero polynomial.
pub fn poly_eval(coeffs: &[f64], s: Complex<f64>) -> Complex<f64> {
    coeffs
        .iter()
        .fold(Complex::new(0.0, 0.0), |acc, &c| acc * s + c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    const RIG_DEN: [f64; 8] = [
        1.68e-8, 2.69316e-4, 1.57906, 6.30146e3, 1.77277e7, 2.71640e10, 2.55023e13, 6.63693e15,
    ];

    fn rel_close(a: &[f64], b: &[f64], tol: f64) -> bool {
        a.len() == b.len()
            && a.iter()
                .zip(b)
                .all(|(x, y)| (x - y).abs() <= tol * x.abs().max(y.abs()).max(f64::MIN_POSITIVE))
    }

    #[test]
    fn roots_of_quadratic_with_complex_pair() {
        // s² + 2s + 5 = (s + 1 − 2i)(s + 1 + 2i)
        let r = poly_roots(&[1.0, 2.0, 5.0]).unwrap();
        assert_eq!(r.len(), 2);
        assert!((r[0] - Complex::new(-1.0, -2.0)).norm() < 1e-14);
        assert!((r[1] - Complex::new(-1.0, 2.0)).norm() < 1e-14);
    }

    #[test]
    fn roots_strip_leading_zeros_and_keep_zero_roots_exact() {
        let r = poly_roots(&[0.0, 0.0, 2.0, -6.0, 0.0, 0.0]).unwrap(); // 2 s² (s − 3)
        assert_eq!(r.len(), 3);
        assert_eq!(r[0], Complex::new(0.0, 0.0));
        assert_eq!(r[1], Complex::new(0.0, 0.0));
        assert!((r[2] - Complex::new(3.0, 0.0)).norm() < 1e-14);
        assert!(poly_roots(&[4.0]).unwrap().is_empty());
        assert!(poly_roots(&[0.0, 0.0]).unwrap().is_empty());
        assert!(poly_roots(&[]).unwrap().is_empty());
        assert!(poly_roots(&[1.0, f64::NAN]).is_err());
    }

    #[test]
    fn roots_and_from_roots_round_trip_with_complex_pairs() {
        let roots = vec![
            Complex::new(-3.0, 0.0),
            Complex::new(-0.5, 4.0),
            Complex::new(-0.5, -4.0),
            Complex::new(2.0, 1.0),
            Complex::new(2.0, -1.0),
            Complex::new(-100.0, 0.0),
        ];
        let p = poly_from_roots(&roots);
        assert_eq!(p[0], 1.0);
        let back = poly_roots(&p).unwrap();
        let mut want = roots.clone();
        sort_roots(&mut want);
        for (a, b) in back.iter().zip(&want) {
            assert!((a - b).norm() < 1e-10 * b.norm(), "{a} vs {b}");
        }
        let p2 = poly_from_roots(&back);
        assert!(rel_close(&p, &p2, 1e-12), "{p:?} vs {p2:?}");
    }

    #[test]
    fn from_roots_uses_real_quadratics_for_pairs() {
        // (s² + 2s + 5)(s − 1) = s³ + s² + 3s − 5
        let p = poly_from_roots(&[
            Complex::new(-1.0, 2.0),
            Complex::new(1.0, 0.0),
            Complex::new(-1.0, -2.0),
        ]);
        assert_eq!(p, vec![1.0, 1.0, 3.0, -5.0]);
        // An unpaired complex root keeps only the real part of the product.
        let q = poly_from_roots(&[Complex::new(0.0, 1.0)]);
        assert_eq!(q, vec![1.0, 0.0]);
        assert_eq!(poly_from_roots(&[]), vec![1.0]);
    }

    #[test]
    fn notes_polynomial_round_trips_through_roots() {
        let r = poly_roots(&RIG_DEN).unwrap();
        assert_eq!(r.len(), 7);
        let p: Vec<f64> = poly_from_roots(&r).iter().map(|c| c * RIG_DEN[0]).collect();
        assert!(rel_close(&p, &RIG_DEN, 1e-11), "{p:?}");
    }

    #[test]
    fn random_stable_polynomials_round_trip() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for _ in 0..50 {
            let mut roots = Vec::new();
            let n_real = rng.random_range(0..4);
            let n_pair = rng.random_range(1..4);
            for _ in 0..n_real {
                roots.push(Complex::new(-10f64.powf(rng.random_range(-1.0..4.0)), 0.0));
            }
            for _ in 0..n_pair {
                let wn = 10f64.powf(rng.random_range(-1.0..4.0));
                let z: f64 = rng.random_range(0.02..0.99);
                let re = -z * wn;
                let im = wn * (1.0 - z * z).sqrt();
                roots.push(Complex::new(re, im));
                roots.push(Complex::new(re, -im));
            }
            let p = poly_from_roots(&roots);
            let back = poly_roots(&p).unwrap();
            let p2 = poly_from_roots(&back);
            assert!(rel_close(&p, &p2, 1e-10), "{p:?} vs {p2:?}");
        }
    }

    #[test]
    fn horner_matches_direct_sum() {
        let c = [2.0, -3.0, 0.5, 7.0];
        let s = Complex::new(0.3, -1.7);
        let direct = s * s * s * 2.0 - s * s * 3.0 + s * 0.5 + 7.0;
        assert!((poly_eval(&c, s) - direct).norm() < 1e-13);
        assert_eq!(poly_eval(&[], s), Complex::new(0.0, 0.0));
    }
}
