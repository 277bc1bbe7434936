//! Eigenvalues of a real square matrix: balancing, Householder reduction to
//! upper Hessenberg form, then the implicit double-shift (Francis) QR iteration
//! with exceptional shifts (EISPACK `hqr`).
//!
//! Eigenvalues are returned with complex-conjugate pairs adjacent and exactly
//! conjugate, which lets [`super::poly::poly_from_roots`] rebuild the
//! characteristic polynomial from real quadratic factors.
//!
//! References: R.S. Martin, G. Peters, J.H. Wilkinson, "The QR algorithm for
//! real Hessenberg matrices", Numer. Math. 14 (1970) (EISPACK `hqr`);
//! W.H. Press et al., Numerical Recipes, §11.6.

use nalgebra::{Complex, DMatrix, Hessenberg};

use super::balance::balanced;
use crate::error::{Error, Result};

/// Iterations allowed per eigenvalue before giving up.
const MAX_ITS: usize = 60;

/// Eigenvalues of a real square matrix (balanced first).
pub(crate) fn eigenvalues(a: &DMatrix<f64>) -> Result<Vec<Complex<f64>>> {
    let n = a.nrows();
    if a.ncols() != n {
        return Err(Error::LengthMismatch {
            what: "square matrix columns",
            expected: n,
            actual: a.ncols(),
        });
    }
    if a.iter().any(|v| !v.is_finite()) {
        return Err(Error::InvalidModel {
            reason: "non-finite matrix entry in eigenvalue problem",
        });
    }
    match n {
        0 => Ok(Vec::new()),
        1 => Ok(vec![Complex::new(a[(0, 0)], 0.0)]),
        _ => {
            let h = Hessenberg::new(balanced(a)).unpack_h();
            hessenberg_eigenvalues(&h)
        }
    }
}

/// Eigenvalues of an upper Hessenberg matrix (entries below the subdiagonal are ignored).
pub(crate) fn hessenberg_eigenvalues(h: &DMatrix<f64>) -> Result<Vec<Complex<f64>>> {
    let n = h.nrows();
    if h.ncols() != n {
        return Err(Error::LengthMismatch {
            what: "square matrix columns",
            expected: n,
            actual: h.ncols(),
        });
    }
    if n == 0 {
        return Ok(Vec::new());
    }
    // 1-based working copy (index 0 unused) so the classic algorithm reads as published.
    let w = n + 1;
    let mut a = vec![0.0; w * w];
    for i in 1..=n {
        for j in i.saturating_sub(1).max(1)..=n {
            a[i * w + j] = h[(i - 1, j - 1)];
        }
    }
    let mut wr = vec![0.0; w];
    let mut wi = vec![0.0; w];
    hqr(&mut a, n, &mut wr, &mut wi)?;
    Ok((1..=n).map(|i| Complex::new(wr[i], wi[i])).collect())
}

/// Copy the sign of `b` onto `|a|`.
fn sign(a: f64, b: f64) -> f64 {
    if b >= 0.0 {
        a.abs()
    } else {
        -a.abs()
    }
}

/// EISPACK/Numerical-Recipes `hqr` on a 1-based row-major (n+1)² buffer.
#[allow(clippy::many_single_char_names)]
fn hqr(a: &mut [f64], n: usize, wr: &mut [f64], wi: &mut [f64]) -> Result<()> {
    let w = n + 1;
    let ix = |i: usize, j: usize| i * w + j;
    let mut anorm = 0.0;
    for i in 1..=n {
        for j in i.saturating_sub(1).max(1)..=n {
            anorm += a[ix(i, j)].abs();
        }
    }
    let mut nn = n;
    let mut t = 0.0;
    let mut total_its = 0usize;
    while nn >= 1 {
        let mut its = 0usize;
        loop {
            // Look for a single small subdiagonal element.
            let mut l = nn;
            while l >= 2 {
                let mut s = a[ix(l - 1, l - 1)].abs() + a[ix(l, l)].abs();
                if s == 0.0 {
                    s = anorm;
                }
                if a[ix(l, l - 1)].abs() <= f64::EPSILON * s {
                    a[ix(l, l - 1)] = 0.0;
                    break;
                }
                l -= 1;
            }
            let mut x = a[ix(nn, nn)];
            if l == nn {
                // One root found.
                wr[nn] = x + t;
                wi[nn] = 0.0;
                nn -= 1;
                break;
            }
            let mut y = a[ix(nn - 1, nn - 1)];
            let mut ww = a[ix(nn, nn - 1)] * a[ix(nn - 1, nn)];
            if l == nn - 1 {
                // Two roots found.
                let p = 0.5 * (y - x);
                let q = p * p + ww;
                let mut z = q.abs().sqrt();
                x += t;
                if q >= 0.0 {
                    z = p + sign(z, p);
                    wr[nn - 1] = x + z;
                    wr[nn] = x + z;
                    if z != 0.0 {
                        wr[nn] = x - ww / z;
                    }
                    wi[nn - 1] = 0.0;
                    wi[nn] = 0.0;
                } else {
                    wr[nn - 1] = x + p;
                    wr[nn] = x + p;
                    wi[nn - 1] = z;
                    wi[nn] = -z;
                }
                nn -= 2;
                break;
            }
            // No roots found yet: continue iterating.
            if its >= MAX_ITS {
                return Err(Error::NotConverged {
                    algorithm: "Hessenberg QR eigenvalue iteration",
                    iterations: total_its,
                });
            }
            if its > 0 && its.is_multiple_of(10) {
                // Exceptional shift.
                t += x;
                for i in 1..=nn {
                    a[ix(i, i)] -= x;
                }
                let s = a[ix(nn, nn - 1)].abs() + a[ix(nn - 1, nn - 2)].abs();
                x = 0.75 * s;
                y = x;
                ww = -0.4375 * s * s;
            }
            its += 1;
            total_its += 1;
            // Form shift and look for two consecutive small subdiagonal elements.
            let (mut p, mut q, mut r): (f64, f64, f64);
            let mut m = nn - 2;
            loop {
                let z = a[ix(m, m)];
                r = x - z;
                let s = y - z;
                p = (r * s - ww) / a[ix(m + 1, m)] + a[ix(m, m + 1)];
                q = a[ix(m + 1, m + 1)] - z - r - s;
                r = a[ix(m + 2, m + 1)];
                let s = p.abs() + q.abs() + r.abs();
                p /= s;
                q /= s;
                r /= s;
                if m == l {
                    break;
                }
                let u = a[ix(m, m - 1)].abs() * (q.abs() + r.abs());
                let v = p.abs() * (a[ix(m - 1, m - 1)].abs() + z.abs() + a[ix(m + 1, m + 1)].abs());
                if u <= f64::EPSILON * v {
                    break;
                }
                m -= 1;
            }
            for i in (m + 2)..=nn {
                a[ix(i, i - 2)] = 0.0;
                if i != m + 2 {
                    a[ix(i, i - 3)] = 0.0;
                }
            }
            // Double QR step on rows l..nn and columns m..nn.
            for k in m..nn {
                if k != m {
                    p = a[ix(k, k - 1)];
                    q = a[ix(k + 1, k - 1)];
                    r = 0.0;
                    if k != nn - 1 {
                        r = a[ix(k + 2, k - 1)];
                    }
                    x = p.abs() + q.abs() + r.abs();
                    if x != 0.0 {
                        p /= x;
                        q /= x;
                        r /= x;
                    }
                }
                let s = sign((p * p + q * q + r * r).sqrt(), p);
                if s != 0.0 {
                    if k == m {
                        if l != m {
                            a[ix(k, k - 1)] = -a[ix(k, k - 1)];
                        }
                    } else {
                        a[ix(k, k - 1)] = -s * x;
                    }
                    p += s;
                    x = p / s;
                    y = q / s;
                    let z = r / s;
                    q /= p;
                    r /= p;
                    for j in k..=nn {
                        let mut pp = a[ix(k, j)] + q * a[ix(k + 1, j)];
                        if k != nn - 1 {
                            pp += r * a[ix(k + 2, j)];
                            a[ix(k + 2, j)] -= pp * z;
                        }
                        a[ix(k + 1, j)] -= pp * y;
                        a[ix(k, j)] -= pp * x;
                    }
                    let mmin = nn.min(k + 3);
                    for i in l..=mmin {
                        let mut pp = x * a[ix(i, k)] + y * a[ix(i, k + 1)];
                        if k != nn - 1 {
                            pp += z * a[ix(i, k + 2)];
                            a[ix(i, k + 2)] -= pp * r;
                        }
                        a[ix(i, k + 1)] -= pp * q;
                        a[ix(i, k)] -= pp;
                    }
                }
            }
            if a.iter().any(|v| !v.is_finite()) {
                return Err(Error::NotConverged {
                    algorithm: "Hessenberg QR eigenvalue iteration (overflow)",
                    iterations: total_its,
                });
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sorted(mut v: Vec<Complex<f64>>) -> Vec<Complex<f64>> {
        v.sort_by(|a, b| {
            a.re.partial_cmp(&b.re)
                .unwrap_or(std::cmp::Ordering::Equal)
                .then(a.im.partial_cmp(&b.im).unwrap_or(std::cmp::Ordering::Equal))
        });
        v
    }

    #[test]
    fn eigenvalues_of_cyclic_permutation_are_roots_of_unity() {
        // Plain Francis shifts stall on this matrix; the exceptional shifts must break the cycle.
        for n in [2usize, 3, 5, 8, 12] {
            let mut m = DMatrix::zeros(n, n);
            for i in 0..n {
                m[((i + 1) % n, i)] = 1.0;
            }
            let ev = eigenvalues(&m).unwrap();
            assert_eq!(ev.len(), n);
            for l in &ev {
                assert!((l.norm() - 1.0).abs() < 1e-12, "n={n}: |λ|={}", l.norm());
                let z = l.powu(n as u32);
                assert!(
                    (z - Complex::new(1.0, 0.0)).norm() < 1e-11,
                    "n={n}: λ^n={z}"
                );
            }
        }
    }

    #[test]
    fn eigenvalues_of_triangular_matrix_are_its_diagonal() {
        let m = DMatrix::from_row_slice(3, 3, &[1.0, 5.0, -3.0, 0.0, -2.0, 7.0, 0.0, 0.0, 4.0]);
        let ev = sorted(eigenvalues(&m).unwrap());
        let want = [-2.0, 1.0, 4.0];
        for (l, w) in ev.iter().zip(want) {
            assert!((l.re - w).abs() < 1e-14 && l.im == 0.0, "{l} vs {w}");
        }
    }

    #[test]
    fn eigenvalues_of_rotation_block_are_conjugate_pair() {
        let m = DMatrix::from_row_slice(3, 3, &[-1.0, 2.0, 0.0, -2.0, -1.0, 0.0, 0.5, 0.3, -7.0]);
        let ev = sorted(eigenvalues(&m).unwrap());
        assert!((ev[0] - Complex::new(-7.0, 0.0)).norm() < 1e-13);
        assert!((ev[1] - Complex::new(-1.0, -2.0)).norm() < 1e-13);
        assert!((ev[2] - Complex::new(-1.0, 2.0)).norm() < 1e-13);
    }
}
