//! Diagonal similarity balancing (Parlett–Reinsch; scaling step of LAPACK `dgebal`).
//!
//! For a square matrix M the routine finds D = diag(d), every dᵢ a power of 2,
//! such that the rows and columns of D⁻¹·M·D have comparable 2-norms. It sweeps
//! over the indices, scales index i by the power of 2 that best equalises the
//! norms of row i and column i, and repeats until a full sweep changes nothing
//! by more than 5 % (the LAPACK ≥ 3.5 rule, norms include the diagonal). Powers
//! of 2 make the similarity exact in floating point, so eigenvalues and
//! transfer functions are unchanged while the spread of the entries (and with
//! it the rounding error of QR iterations, matrix exponentials and linear
//! solves) shrinks. Applied to `[[A, B], [C, 0]]` with the last index fixed it
//! is MATLAB's `ssbal`.
//!
//! Reference: B.N. Parlett, C. Reinsch, "Balancing a matrix for calculation of
//! eigenvalues and eigenvectors", Numer. Math. 13 (1969); LAPACK `dgebal`.

use nalgebra::DMatrix;

/// Radix of the scaling factors.
const RADIX: f64 = 2.0;
/// A sweep that reduces `‖row‖ + ‖col‖` by less than this factor changes nothing.
const FACTOR: f64 = 0.95;
/// Upper bound on the number of sweeps (LAPACK has none; convergence is fast).
const MAX_SWEEPS: usize = 1000;

/// Scaling vector d (powers of 2) balancing `m`; indices `≥ n_free` keep dᵢ = 1.
///
/// The balanced matrix is `D⁻¹·M·D`, i.e. entry (i, j) times `d[j] / d[i]`.
/// A non-square or non-finite matrix gives all ones.
pub(crate) fn balance_scaling(m: &DMatrix<f64>, n_free: usize) -> Vec<f64> {
    let n = m.nrows();
    let mut d = vec![1.0; n];
    if m.ncols() != n || m.iter().any(|v| !v.is_finite()) {
        return d;
    }
    let n_free = n_free.min(n);
    let mut a = m.clone();
    let sfmin1 = f64::MIN_POSITIVE / f64::EPSILON;
    let sfmax1 = 1.0 / sfmin1;
    let sfmin2 = sfmin1 * RADIX;
    let sfmax2 = 1.0 / sfmin2;
    for _ in 0..MAX_SWEEPS {
        let mut changed = false;
        for (i, di) in d.iter_mut().enumerate().take(n_free) {
            let mut c = a.column(i).norm();
            let mut r = a.row(i).norm();
            let mut ca = a.column(i).amax();
            let mut ra = a.row(i).amax();
            if c == 0.0 || r == 0.0 {
                continue;
            }
            let s = c + r;
            let mut f = 1.0_f64;
            let mut g = r / RADIX;
            while c < g && f.max(c).max(ca) < sfmax2 && r.min(g).min(ra) > sfmin2 {
                f *= RADIX;
                c *= RADIX;
                ca *= RADIX;
                r /= RADIX;
                g /= RADIX;
                ra /= RADIX;
            }
            g = c / RADIX;
            while g >= r && r.max(ra) < sfmax2 && f.min(c).min(g).min(ca) > sfmin2 {
                f /= RADIX;
                c /= RADIX;
                g /= RADIX;
                ca /= RADIX;
                r *= RADIX;
                ra *= RADIX;
            }
            if c + r >= FACTOR * s {
                continue;
            }
            if f < 1.0 && *di < 1.0 && f * *di <= sfmin1 {
                continue;
            }
            if f > 1.0 && *di > 1.0 && *di >= sfmax1 / f {
                continue;
            }
            *di *= f;
            a.row_mut(i).scale_mut(1.0 / f);
            a.column_mut(i).scale_mut(f);
            changed = true;
        }
        if !changed {
            break;
        }
    }
    d
}

/// `D⁻¹·M·D` for the scaling vector `d` (exact: the dᵢ are powers of 2).
pub(crate) fn apply_similarity(m: &DMatrix<f64>, d: &[f64]) -> DMatrix<f64> {
    DMatrix::from_fn(m.nrows(), m.ncols(), |i, j| {
        m[(i, j)] * d.get(j).copied().unwrap_or(1.0) / d.get(i).copied().unwrap_or(1.0)
    })
}

/// `D·M·D⁻¹`, the inverse of [`apply_similarity`].
pub(crate) fn undo_similarity(m: &DMatrix<f64>, d: &[f64]) -> DMatrix<f64> {
    DMatrix::from_fn(m.nrows(), m.ncols(), |i, j| {
        m[(i, j)] * d.get(i).copied().unwrap_or(1.0) / d.get(j).copied().unwrap_or(1.0)
    })
}

/// `D⁻¹·M·D` with the scaling computed by [`balance_scaling`] on all indices.
pub(crate) fn balanced(m: &DMatrix<f64>) -> DMatrix<f64> {
    let d = balance_scaling(m, m.nrows());
    apply_similarity(m, &d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn balancing_equalises_row_and_column_norms_of_graded_matrix() {
        // Companion-like matrix with entries spanning 1e-8 .. 1e16.
        let m = DMatrix::from_row_slice(3, 3, &[-1e3, -1e10, -1e16, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
        let d = balance_scaling(&m, 3);
        for v in &d {
            assert_eq!(v.log2().fract(), 0.0, "scaling {v} is not a power of 2");
        }
        let b = apply_similarity(&m, &d);
        for i in 0..3 {
            let ratio = b.row(i).norm() / b.column(i).norm();
            assert!((0.2..5.0).contains(&ratio), "row/col ratio {ratio} at {i}");
        }
        let back = undo_similarity(&b, &d);
        assert_eq!(back, m);
    }

    #[test]
    fn balancing_keeps_fixed_indices_at_one() {
        let m = DMatrix::from_row_slice(2, 2, &[1.0, 1e8, 1e-8, 1.0]);
        let d = balance_scaling(&m, 1);
        assert_eq!(d[1], 1.0);
        // Balanced off-diagonals are both of order sqrt(1e8 · 1e-8) = 1.
        let b = apply_similarity(&m, &d);
        assert!(
            b[(0, 1)] > 0.5 && b[(0, 1)] < 2.0 && b[(1, 0)] > 0.5 && b[(1, 0)] < 2.0,
            "{b}"
        );
    }
}
