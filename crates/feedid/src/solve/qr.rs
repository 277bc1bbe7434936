//! Dense linear least squares by Householder QR with column scaling and
//! column pivoting.
//!
//! Solves `min_x ‖A·x − b‖₂² + λ‖x‖₂²` for a dense `m×n` matrix `A`
//! (column-major), a right-hand side `b` and a ridge parameter `λ ≥ 0`
//! (Tikhonov regularisation, default 0).
//!
//! Method:
//! 1. **Column scaling.** Every column is divided by its 2-norm `d_j`
//!    (zero columns keep `d_j = 1`), so the problem is solved for `z = D·x`
//!    with `D = diag(d_j)`; this removes the artificial ill-conditioning of
//!    badly scaled regressors (e.g. powers of a time in seconds).
//! 2. **Householder QR with column pivoting** (Businger–Golub): at step `k`
//!    the remaining column of largest norm is moved to position `k`, so the
//!    diagonal of `R` is non-increasing in magnitude, `|R₀₀| ≥ |R₁₁| ≥ …`.
//!    `Qᵀ` is applied to `b` on the fly; no normal equations are formed.
//! 3. **Rank.** The numerical rank `r` is the number of pivots with
//!    `|R_kk| > tol·|R₀₀|` (`tol` defaults to `max(m, n)·ε`).
//!    Without ridge, the columns behind the tiny pivots are *dropped*: the
//!    result is the basic solution with those coefficients set to 0 (it
//!    attains the minimum residual, but is not the minimum-norm solution of a
//!    rank-deficient problem). A matrix of rank 0 is [`Error::Singular`].
//! 4. **Ridge.** With `λ > 0` the augmented problem `[A; √λ·I]·x ≈ [b; 0]`
//!    is solved exactly: after the QR of the scaled `A` it reduces to the
//!    small `(min(m,n)+n)×n` problem `[R; √λ·D⁻¹·P]·z ≈ [Qᵀb; 0]`, solved by
//!    a second Householder QR. All columns are kept (the ridge makes the
//!    problem full rank); `rank` still reports the numerical rank of `A`.
//! 5. **Unscaling.** `x = D⁻¹·Pᵀ·z`.
//!
//! [`LstsqInfo`] reports the rank, a condition estimate `|R₀₀|/|R_{n−1,n−1}|`
//! of the column-scaled matrix (a cheap lower-bound-like estimate of its
//! 2-norm condition number, `∞` for an exactly singular matrix or `m < n`),
//! and the residual norm `‖A·x − b‖₂` (data residual, without the ridge term).
//!
//! The core [`lstsq_in_place`] works on caller buffers and a reusable
//! [`QrWorkspace`] and allocates nothing; [`lstsq`] / [`lstsq_with`] are
//! allocating convenience wrappers on nalgebra types.
//!
//! References: G.H. Golub, C.F. Van Loan, *Matrix Computations*, 4th ed.,
//! §5.2 (Householder QR), §5.4.1 (column pivoting), §6.1 (Tikhonov);
//! Å. Björck, *Numerical Methods for Least Squares Problems*, §2.7.

use nalgebra::{DMatrix, DVector};

use crate::error::{Error, Result};

/// Options of the least-squares solver.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LstsqOptions {
    /// Ridge (Tikhonov) parameter `λ ≥ 0` on `‖x‖²` in the original (unscaled)
    /// coordinates. Default 0 (plain least squares).
    pub ridge: f64,
    /// Relative pivot tolerance for the numerical rank: pivots with
    /// `|R_kk| ≤ tol·|R₀₀|` count as zero. `None` (default) uses `max(m, n)·ε`.
    pub rank_tolerance: Option<f64>,
}

impl Default for LstsqOptions {
    fn default() -> Self {
        Self {
            ridge: 0.0,
            rank_tolerance: None,
        }
    }
}

/// Rank and conditioning information of a least-squares solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LstsqInfo {
    /// Numerical rank of the column-scaled matrix.
    pub rank: usize,
    /// Condition estimate `|R₀₀|/|R_{n−1,n−1}|` of the column-scaled matrix
    /// (`∞` if a pivot is exactly zero or `m < n`).
    pub cond_estimate: f64,
    /// Residual norm `‖A·x − b‖₂` of the returned solution.
    pub residual_norm: f64,
}

/// Solution and information returned by the convenience wrappers.
#[derive(Debug, Clone, PartialEq)]
pub struct LstsqSolution {
    /// The solution vector `x` (length `n`).
    pub x: DVector<f64>,
    /// Rank, condition estimate and residual norm.
    pub info: LstsqInfo,
}

/// Reusable scratch memory for [`lstsq_in_place`], sized for up to `n` unknowns.
#[derive(Debug, Clone)]
pub struct QrWorkspace {
    n_max: usize,
    scale: Vec<f64>,
    perm: Vec<usize>,
    z: Vec<f64>,
    small: Vec<f64>,
    small_rhs: Vec<f64>,
    /// Squared partial column norms (current estimate, last exact value).
    vn1: Vec<f64>,
    vn2: Vec<f64>,
    /// Run the AVX2 build of the solver.
    avx: bool,
}

impl QrWorkspace {
    /// Workspace for problems with at most `n` unknowns (any number of rows).
    pub fn new(n: usize) -> Self {
        Self {
            n_max: n,
            scale: vec![0.0; n],
            perm: vec![0; n],
            z: vec![0.0; n],
            small: vec![0.0; 2 * n * n],
            small_rhs: vec![0.0; 2 * n],
            vn1: vec![0.0; n],
            vn2: vec![0.0; n],
            avx: crate::solve::rows::avx2(),
        }
    }

    /// Largest number of unknowns this workspace supports.
    pub fn capacity(&self) -> usize {
        self.n_max
    }

    /// Column permutation of the last [`lstsq_in_place`] with `n` unknowns
    /// (column `k` of its `R` is column `perm[k]` of `A`).
    pub(crate) fn permutation(&self, n: usize) -> &[usize] {
        &self.perm[..n]
    }

    /// Column scales `d_j` of the last [`lstsq_in_place`] with `n` unknowns
    /// (`R` is the factor of `A·diag(1/d_j)`, permuted).
    pub(crate) fn scales(&self, n: usize) -> &[f64] {
        &self.scale[..n]
    }
}

/// Solve `min ‖A·x − b‖² + λ‖x‖²` in place (allocation-free core).
///
/// * `a`: `m×n` matrix, column-major (`a[i + j·m]`), overwritten by the factorisation.
/// * `b`: right-hand side (length `m`), overwritten by `Qᵀb`.
/// * `x`: receives the solution (length `n`).
/// * `ws`: scratch with [`QrWorkspace::capacity`] `≥ n`.
///
/// Errors: [`Error::LengthMismatch`] for inconsistent sizes or a too small
/// workspace, [`Error::TooFewSamples`] for `m = 0` or `n = 0`,
/// [`Error::NonFinite`] for NaN/∞ in `a` or `b`, [`Error::InvalidParameter`]
/// for a negative or non-finite ridge or tolerance, [`Error::Singular`] if
/// the matrix has numerical rank 0 (or the ridge system is singular).
///
/// ```
/// use feedid::solve::{lstsq_in_place, LstsqOptions, QrWorkspace};
/// // Fit y = 1 + 2 t through three points (column-major A = [1 1 1; 0 1 2]).
/// let mut a = [1.0, 1.0, 1.0, 0.0, 1.0, 2.0];
/// let mut b = [1.0, 3.0, 5.0];
/// let mut x = [0.0; 2];
/// let mut ws = QrWorkspace::new(2);
/// let info = lstsq_in_place(3, 2, &mut a, &mut b, &mut x, &mut ws, &LstsqOptions::default()).unwrap();
/// assert_eq!(info.rank, 2);
/// assert!((x[0] - 1.0).abs() < 1e-14 && (x[1] - 2.0).abs() < 1e-14);
/// ```
pub fn lstsq_in_place(
    m: usize,
    n: usize,
    a: &mut [f64],
    b: &mut [f64],
    x: &mut [f64],
    ws: &mut QrWorkspace,
    options: &LstsqOptions,
) -> Result<LstsqInfo> {
    #[cfg(target_arch = "x86_64")]
    if ws.avx {
        // SAFETY: `avx` is set only when the CPU reports AVX2 (workspace construction).
        return unsafe { lstsq_avx2(m, n, a, b, x, ws, options) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = ws.avx;
    lstsq_impl(m, n, a, b, x, ws, options)
}

/// [`lstsq_impl`] compiled for AVX2 (4-wide vectors; the same operations in
/// the same order, no FMA contraction: bit-identical results).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn lstsq_avx2(
    m: usize,
    n: usize,
    a: &mut [f64],
    b: &mut [f64],
    x: &mut [f64],
    ws: &mut QrWorkspace,
    options: &LstsqOptions,
) -> Result<LstsqInfo> {
    lstsq_impl(m, n, a, b, x, ws, options)
}

#[inline(always)]
fn lstsq_impl(
    m: usize,
    n: usize,
    a: &mut [f64],
    b: &mut [f64],
    x: &mut [f64],
    ws: &mut QrWorkspace,
    options: &LstsqOptions,
) -> Result<LstsqInfo> {
    if m == 0 || n == 0 {
        return Err(Error::TooFewSamples {
            what: "least squares (rows and columns)",
            needed: 1,
            actual: 0,
        });
    }
    check_len("least-squares matrix", m * n, a.len())?;
    check_len("least-squares right-hand side", m, b.len())?;
    check_len("least-squares solution", n, x.len())?;
    if ws.n_max < n {
        return Err(Error::LengthMismatch {
            what: "QR workspace capacity",
            expected: n,
            actual: ws.n_max,
        });
    }
    let ridge = options.ridge;
    if !(ridge.is_finite() && ridge >= 0.0) {
        return Err(Error::InvalidParameter {
            name: "ridge",
            value: ridge,
            reason: "must be finite and >= 0",
        });
    }
    let tol = match options.rank_tolerance {
        Some(t) if !(t.is_finite() && t >= 0.0) => {
            return Err(Error::InvalidParameter {
                name: "rank_tolerance",
                value: t,
                reason: "must be finite and >= 0",
            })
        }
        Some(t) => t,
        None => m.max(n) as f64 * f64::EPSILON,
    };
    if !all_finite(a) {
        let (i, &v) = a
            .iter()
            .enumerate()
            .find(|(_, v)| !v.is_finite())
            .unwrap_or((0, &f64::NAN));
        return Err(Error::NonFinite {
            channel: "least-squares matrix".to_string(),
            index: i,
            value: v,
        });
    }
    if !all_finite(b) {
        let (i, &v) = b
            .iter()
            .enumerate()
            .find(|(_, v)| !v.is_finite())
            .unwrap_or((0, &f64::NAN));
        return Err(Error::NonFinite {
            channel: "least-squares right-hand side".to_string(),
            index: i,
            value: v,
        });
    }

    let scale = &mut ws.scale[..n];
    let perm = &mut ws.perm[..n];
    // 1. column scaling
    let vn1 = &mut ws.vn1[..n];
    let vn2 = &mut ws.vn2[..n];
    for j in 0..n {
        let col = &mut a[j * m..(j + 1) * m];
        let d = norm2(col);
        let d = if d > 0.0 && d.is_finite() { d } else { 1.0 };
        let inv = 1.0 / d;
        for v in col.iter_mut() {
            *v *= inv;
        }
        scale[j] = d;
        perm[j] = j;
        vn1[j] = sum_sq(col);
        vn2[j] = vn1[j];
    }

    // 2. Householder QR with column pivoting. The squared norms of the
    // remaining columns are downdated after each step, `‖a_j‖² −= r_kj²`, and
    // recomputed when cancellation has lost half the digits (LAPACK xGEQP3).
    let kmax = m.min(n);
    let tol3z = f64::EPSILON.sqrt();
    for k in 0..kmax {
        // pivot: remaining column (rows k..m) of largest norm
        let mut best = k;
        let mut best_norm = -1.0;
        for (j, &nj) in vn1.iter().enumerate().skip(k) {
            if nj > best_norm {
                best_norm = nj;
                best = j;
            }
        }
        if best != k {
            let (left, right) = a.split_at_mut(best * m);
            left[k * m..(k + 1) * m].swap_with_slice(&mut right[..m]);
            perm.swap(k, best);
            vn1.swap(k, best);
            vn2.swap(k, best);
        }
        let alpha_norm = norm2(&a[k * m + k..(k + 1) * m]);
        if alpha_norm == 0.0 {
            // the rest of the matrix is exactly zero
            continue;
        }
        let x0 = a[k + k * m];
        let alpha = if x0 >= 0.0 { -alpha_norm } else { alpha_norm };
        // v = x − alpha·e1 stored in a[k..m, k]; H = I − v vᵀ / (vᵀv / 1)·2
        a[k + k * m] = x0 - alpha;
        let vtv = {
            let v = &a[k * m + k..(k + 1) * m];
            v.iter().map(|t| t * t).sum::<f64>()
        };
        if vtv > 0.0 {
            let beta = 2.0 / vtv;
            for j in (k + 1)..n {
                let (vcol, ccol) = split_cols(a, m, k, j);
                let v = &vcol[k..];
                let c = &mut ccol[k..];
                let s = beta * dot(v, c);
                for (ci, vi) in c.iter_mut().zip(v) {
                    *ci -= s * vi;
                }
            }
            let v = &a[k * m + k..(k + 1) * m];
            let c = &mut b[k..];
            let s = beta * dot(v, c);
            for (ci, vi) in c.iter_mut().zip(v) {
                *ci -= s * vi;
            }
        }
        a[k + k * m] = alpha;
        for i in (k + 1)..m {
            a[i + k * m] = 0.0;
        }
        // downdate the remaining column norms by the new row of R
        for j in (k + 1)..n {
            let r = a[k + j * m];
            let rest = vn1[j] - r * r;
            if rest <= tol3z * vn2[j] {
                vn1[j] = sum_sq(&a[j * m + k + 1..(j + 1) * m]);
                vn2[j] = vn1[j];
            } else {
                vn1[j] = rest;
            }
        }
    }

    // 3. rank and condition estimate
    let r00 = a[0].abs();
    let mut rank = 0;
    for k in 0..kmax {
        if a[k + k * m].abs() > tol * r00 && r00 > 0.0 {
            rank += 1;
        } else {
            break;
        }
    }
    let cond_estimate = if m < n {
        f64::INFINITY
    } else {
        let rlast = a[(n - 1) + (n - 1) * m].abs();
        if rlast > 0.0 {
            r00 / rlast
        } else {
            f64::INFINITY
        }
    };
    if rank == 0 {
        return Err(Error::Singular {
            context: "least squares (matrix of rank 0)",
        });
    }

    // 4. solve for z (scaled, permuted coordinates)
    let z = &mut ws.z[..n];
    if ridge == 0.0 {
        for v in z.iter_mut() {
            *v = 0.0;
        }
        for k in (0..rank).rev() {
            let mut s = b[k];
            for j in (k + 1)..rank {
                s -= a[k + j * m] * z[j];
            }
            z[k] = s / a[k + k * m];
        }
    } else {
        let rows = kmax + n;
        let small = &mut ws.small[..rows * n];
        let rhs = &mut ws.small_rhs[..rows];
        for v in small.iter_mut() {
            *v = 0.0;
        }
        for j in 0..n {
            for i in 0..=j.min(kmax - 1) {
                small[i + j * rows] = a[i + j * m];
            }
            small[kmax + j + j * rows] = ridge.sqrt() / scale[perm[j]];
        }
        rhs[..kmax].copy_from_slice(&b[..kmax]);
        for v in rhs[kmax..].iter_mut() {
            *v = 0.0;
        }
        householder_solve(rows, n, small, rhs, z)?;
    }

    // residual ‖A x − b‖ = sqrt(‖R z − c₁‖² + ‖c₂‖²) with c = Qᵀb
    let mut res2 = 0.0;
    for i in 0..kmax {
        let mut s = -b[i];
        for j in i..n {
            s += a[i + j * m] * z[j];
        }
        res2 += s * s;
    }
    for bi in b.iter().skip(kmax) {
        res2 += bi * bi;
    }

    // 5. unpermute and unscale
    for k in 0..n {
        let j = perm[k];
        x[j] = z[k] / scale[j];
    }
    if x.iter().any(|v| !v.is_finite()) {
        return Err(Error::Singular {
            context: "least squares (solution overflowed)",
        });
    }
    Ok(LstsqInfo {
        rank,
        cond_estimate,
        residual_norm: res2.sqrt(),
    })
}

/// Least squares `min ‖A·x − b‖` with default options (allocating wrapper).
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// let a = DMatrix::from_row_slice(3, 2, &[1.0, 0.0, 1.0, 1.0, 1.0, 2.0]);
/// let b = DVector::from_vec(vec![1.0, 3.0, 5.0]);
/// let sol = feedid::solve::lstsq(&a, &b).unwrap();
/// assert!((sol.x[1] - 2.0).abs() < 1e-14);
/// ```
pub fn lstsq(a: &DMatrix<f64>, b: &DVector<f64>) -> Result<LstsqSolution> {
    lstsq_with(a, b, &LstsqOptions::default())
}

/// Least squares with options (ridge, rank tolerance); allocating wrapper.
pub fn lstsq_with(
    a: &DMatrix<f64>,
    b: &DVector<f64>,
    options: &LstsqOptions,
) -> Result<LstsqSolution> {
    let (m, n) = a.shape();
    check_len("least-squares right-hand side", m, b.len())?;
    let mut abuf: Vec<f64> = a.as_slice().to_vec();
    let mut bbuf: Vec<f64> = b.as_slice().to_vec();
    let mut x = vec![0.0; n];
    let mut ws = QrWorkspace::new(n);
    let info = lstsq_in_place(m, n, &mut abuf, &mut bbuf, &mut x, &mut ws, options)?;
    Ok(LstsqSolution {
        x: DVector::from_vec(x),
        info,
    })
}

/// Unpivoted Householder solve of a small full-rank problem (used for the ridge system).
fn householder_solve(
    m: usize,
    n: usize,
    a: &mut [f64],
    b: &mut [f64],
    z: &mut [f64],
) -> Result<()> {
    for k in 0..n {
        let xn = norm2(&a[k * m + k..(k + 1) * m]);
        if xn == 0.0 {
            return Err(Error::Singular {
                context: "ridge least squares",
            });
        }
        let x0 = a[k + k * m];
        let alpha = if x0 >= 0.0 { -xn } else { xn };
        a[k + k * m] = x0 - alpha;
        let vtv: f64 = a[k * m + k..(k + 1) * m].iter().map(|t| t * t).sum();
        if vtv > 0.0 {
            let beta = 2.0 / vtv;
            for j in (k + 1)..n {
                let (vcol, ccol) = split_cols(a, m, k, j);
                let v = &vcol[k..];
                let c = &mut ccol[k..];
                let s = beta * dot(v, c);
                for (ci, vi) in c.iter_mut().zip(v) {
                    *ci -= s * vi;
                }
            }
            let v = &a[k * m + k..(k + 1) * m];
            let c = &mut b[k..];
            let s = beta * dot(v, c);
            for (ci, vi) in c.iter_mut().zip(v) {
                *ci -= s * vi;
            }
        }
        a[k + k * m] = alpha;
    }
    for k in (0..n).rev() {
        let mut s = b[k];
        for j in (k + 1)..n {
            s -= a[k + j * m] * z[j];
        }
        z[k] = s / a[k + k * m];
    }
    Ok(())
}

/// [`lstsq_in_place`] without ridge for a small problem of fixed size
/// `M×N` (`M ≥ N`) on stack arrays: the same algorithm — unit-norm
/// columns, Householder QR with column pivoting (norms downdated, recomputed
/// after cancellation), numerical rank against `tol·|R₀₀|` (`None`:
/// `max(M, N)·ε`), condition estimate `|R₀₀|/|R_{N−1,N−1}|`, the basic
/// solution, the residual `‖A·x − b‖` — without the size checks and the
/// workspace (a few hundred instructions for 8×3 instead of thousands).
/// The same operations in the same order: bit-identical results.
///
/// `a` holds the `N` columns. Errors as [`lstsq_in_place`]: non-finite
/// input, rank 0, an overflowing solution.
#[allow(clippy::needless_range_loop)] // index loops mirror lstsq_in_place
pub(crate) fn lstsq_fixed<const M: usize, const N: usize>(
    a: &[[f64; M]; N],
    b: &[f64; M],
    tol: Option<f64>,
) -> Result<([f64; N], LstsqInfo)> {
    if let Some(v) = a.iter().flatten().chain(b).find(|v| !v.is_finite()) {
        return Err(Error::NonFinite {
            channel: "least-squares problem".to_string(),
            index: 0,
            value: *v,
        });
    }
    let tol = tol.unwrap_or(M.max(N) as f64 * f64::EPSILON);
    let mut a = *a;
    let mut b = *b;
    let mut scale = [1.0; N];
    let mut perm = [0usize; N];
    let mut vn1 = [0.0; N];
    let mut vn2 = [0.0; N];
    for j in 0..N {
        let d = norm2(&a[j]);
        let d = if d > 0.0 && d.is_finite() { d } else { 1.0 };
        let inv = 1.0 / d;
        a[j].iter_mut().for_each(|v| *v *= inv);
        scale[j] = d;
        perm[j] = j;
        vn1[j] = sum_sq(&a[j]);
        vn2[j] = vn1[j];
    }
    let tol3z = f64::EPSILON.sqrt();
    for k in 0..N.min(M) {
        let mut best = k;
        let mut best_norm = -1.0;
        for (j, &nj) in vn1.iter().enumerate().skip(k) {
            if nj > best_norm {
                best_norm = nj;
                best = j;
            }
        }
        if best != k {
            a.swap(k, best);
            perm.swap(k, best);
            vn1.swap(k, best);
            vn2.swap(k, best);
        }
        let alpha_norm = norm2(&a[k][k..]);
        if alpha_norm == 0.0 {
            continue;
        }
        let x0 = a[k][k];
        let alpha = if x0 >= 0.0 { -alpha_norm } else { alpha_norm };
        a[k][k] = x0 - alpha;
        let vtv = a[k][k..].iter().map(|t| t * t).sum::<f64>();
        if vtv > 0.0 {
            let beta = 2.0 / vtv;
            let (head, tail) = a.split_at_mut(k + 1);
            let v = &head[k][k..];
            for col in tail.iter_mut() {
                let c = &mut col[k..];
                let s = beta * dot(v, c);
                c.iter_mut().zip(v).for_each(|(ci, vi)| *ci -= s * vi);
            }
            let c = &mut b[k..];
            let s = beta * dot(v, c);
            c.iter_mut().zip(v).for_each(|(ci, vi)| *ci -= s * vi);
        }
        a[k][k] = alpha;
        a[k][k + 1..].iter_mut().for_each(|v| *v = 0.0);
        for j in (k + 1)..N {
            let r = a[j][k];
            let rest = vn1[j] - r * r;
            if rest <= tol3z * vn2[j] {
                vn1[j] = sum_sq(&a[j][k + 1..]);
                vn2[j] = vn1[j];
            } else {
                vn1[j] = rest;
            }
        }
    }
    let kmax = M.min(N);
    let r00 = a[0][0].abs();
    let mut rank = 0;
    for k in 0..kmax {
        if a[k][k].abs() > tol * r00 && r00 > 0.0 {
            rank += 1;
        } else {
            break;
        }
    }
    let cond_estimate = if M < N {
        f64::INFINITY
    } else {
        let rlast = a[N - 1][N - 1].abs();
        if rlast > 0.0 {
            r00 / rlast
        } else {
            f64::INFINITY
        }
    };
    if rank == 0 {
        return Err(Error::Singular {
            context: "least squares (matrix of rank 0)",
        });
    }
    let mut z = [0.0; N];
    for k in (0..rank).rev() {
        let mut s = b[k];
        for j in (k + 1)..rank {
            s -= a[j][k] * z[j];
        }
        z[k] = s / a[k][k];
    }
    let mut res2 = 0.0;
    for i in 0..kmax {
        let mut s = -b[i];
        for j in i..N {
            s += a[j][i] * z[j];
        }
        res2 += s * s;
    }
    for bi in b.iter().skip(kmax) {
        res2 += bi * bi;
    }
    let mut x = [0.0; N];
    for k in 0..N {
        let j = perm[k];
        x[j] = z[k] / scale[j];
    }
    if x.iter().any(|v| !v.is_finite()) {
        return Err(Error::Singular {
            context: "least squares (solution overflowed)",
        });
    }
    Ok((
        x,
        LstsqInfo {
            rank,
            cond_estimate,
            residual_norm: res2.sqrt(),
        },
    ))
}

/// Columns `k < j` of a column-major `m`-row matrix, `k` shared and `j` mutable.
fn split_cols(a: &mut [f64], m: usize, k: usize, j: usize) -> (&[f64], &mut [f64]) {
    let (left, right) = a.split_at_mut(j * m);
    (&left[k * m..(k + 1) * m], &mut right[..m])
}

/// Whether every element is finite: four partial sums of `v·0` (NaN exactly
/// when some `v` is NaN or infinite), vectorisable.
#[inline(always)]
fn all_finite(v: &[f64]) -> bool {
    let mut acc = [0.0f64; 4];
    let chunks = v.chunks_exact(4);
    let rest: f64 = chunks.remainder().iter().map(|x| x * 0.0).sum();
    for c in chunks {
        for (a, x) in acc.iter_mut().zip(c) {
            *a += x * 0.0;
        }
    }
    (acc[0] + acc[1] + acc[2] + acc[3] + rest) == 0.0
}

/// Dot product with four partial sums (independent dependency chains).
#[inline(always)]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    let mut acc = [0.0; 4];
    for (x, y) in ca.zip(cb) {
        acc[0] += x[0] * y[0];
        acc[1] += x[1] * y[1];
        acc[2] += x[2] * y[2];
        acc[3] += x[3] * y[3];
    }
    let mut s = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    for (x, y) in ra.iter().zip(rb) {
        s += x * y;
    }
    s
}

/// Sum of squares (no protection against over/underflow).
#[inline(always)]
fn sum_sq(v: &[f64]) -> f64 {
    dot(v, v)
}

/// 2-norm without overflow/underflow for extreme magnitudes (one pass when
/// the sum of squares is safely representable).
#[inline(always)]
fn norm2(v: &[f64]) -> f64 {
    let s = sum_sq(v);
    if s.is_finite() && s >= 1e-200 {
        return s.sqrt();
    }
    let amax = v.iter().fold(0.0f64, |acc, x| acc.max(x.abs()));
    if amax == 0.0 || !amax.is_finite() {
        return amax;
    }
    if (1e-150..=1e150).contains(&amax) {
        return v.iter().map(|x| x * x).sum::<f64>().sqrt();
    }
    let s: f64 = v.iter().map(|x| (x / amax) * (x / amax)).sum();
    amax * s.sqrt()
}

fn check_len(what: &'static str, expected: usize, actual: usize) -> Result<()> {
    if expected != actual {
        return Err(Error::LengthMismatch {
            what,
            expected,
            actual,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn random_problem(rng: &mut ChaCha8Rng, m: usize, n: usize) -> (DMatrix<f64>, DVector<f64>) {
        let a = DMatrix::from_fn(m, n, |_, _| rng.random_range(-1.0..1.0));
        let b = DVector::from_fn(m, |_, _| rng.random_range(-1.0..1.0));
        (a, b)
    }

    #[test]
    fn avx2_build_gives_the_portable_results_bit_for_bit() {
        // the kernels are chosen at run time: both builds must agree exactly
        // (on a CPU without AVX2 both are the portable one)
        let mut fast = QrWorkspace::new(24);
        let mut slow = crate::solve::rows::portable(|| QrWorkspace::new(24));
        assert!(!slow.avx);
        #[cfg(target_arch = "x86_64")]
        assert_eq!(fast.avx, std::arch::is_x86_feature_detected!("avx2"));
        let mut rng = ChaCha8Rng::seed_from_u64(41);
        for case in 0..300 {
            let n = rng.random_range(1..=24);
            let m = n + rng.random_range(0..60);
            let (a, b) = random_problem(&mut rng, m, n);
            let mut a: Vec<f64> = a.as_slice().to_vec();
            if n > 2 && case % 3 == 0 {
                // a nearly dependent column and decades of scale
                for i in 0..m {
                    a[i + 2 * m] = a[i + m] + 1e-9 * a[i + 2 * m];
                    a[i] *= 1e6;
                }
            }
            let options = LstsqOptions {
                ridge: [0.0, 1e-8, 1e-2][case % 3],
                rank_tolerance: [None, Some(1e-6)][case % 2],
            };
            let run = |ws: &mut QrWorkspace| {
                let (mut a, mut b, mut x) = (a.clone(), b.as_slice().to_vec(), vec![0.0; n]);
                let info = lstsq_in_place(m, n, &mut a, &mut b, &mut x, ws, &options)
                    .map(|i| format!("{i:?}"));
                let bits = |v: &[f64]| v.iter().map(|e| e.to_bits()).collect::<Vec<_>>();
                (
                    info.map_err(|e| e.to_string()),
                    bits(&x),
                    bits(&a),
                    bits(&b),
                )
            };
            assert_eq!(run(&mut fast), run(&mut slow), "case {case} (m {m}, n {n})");
        }
    }

    fn svd_solve(a: &DMatrix<f64>, b: &DVector<f64>) -> DVector<f64> {
        a.clone().svd(true, true).solve(b, 1e-13).unwrap()
    }

    #[test]
    fn random_overdetermined_problems_match_svd_reference() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for trial in 0..50 {
            let n = 1 + trial % 8;
            let m = n + rng.random_range(0..20);
            let (mut a, b) = random_problem(&mut rng, m, n);
            // random column scales over 12 decades
            for j in 0..n {
                let s = 10f64.powf(rng.random_range(-6.0..6.0));
                a.column_mut(j).scale_mut(s);
            }
            let sol = lstsq(&a, &b).unwrap();
            // slow reference: SVD of the column-equilibrated matrix, unscaled
            let norms: Vec<f64> = (0..n).map(|j| a.column(j).norm()).collect();
            let a_eq = DMatrix::from_fn(m, n, |i, j| a[(i, j)] / norms[j]);
            let z = svd_solve(&a_eq, &b);
            let reference = DVector::from_fn(n, |j, _| z[j] / norms[j]);
            for j in 0..n {
                assert!(
                    (sol.x[j] - reference[j]).abs() <= 1e-10 * reference[j].abs(),
                    "trial {trial} j {j}: {} vs {}",
                    sol.x[j],
                    reference[j]
                );
            }
            let res_ref = (&a * &reference - &b).norm();
            assert!((sol.info.residual_norm - res_ref).abs() <= 1e-10 * (1.0 + res_ref));
            assert_eq!(sol.info.rank, n);
        }
    }

    #[test]
    fn consistent_systems_are_recovered_exactly() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        for _ in 0..20 {
            let (a, _) = random_problem(&mut rng, 15, 6);
            let x_true = DVector::from_fn(6, |_, _| rng.random_range(-10.0..10.0));
            let b = &a * &x_true;
            let sol = lstsq(&a, &b).unwrap();
            assert!((&sol.x - &x_true).amax() < 1e-12 * x_true.amax());
            assert!(sol.info.residual_norm < 1e-12 * b.norm());
        }
    }

    #[test]
    fn square_system_matches_lu_solution() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let (a, b) = random_problem(&mut rng, 5, 5);
        let sol = lstsq(&a, &b).unwrap();
        let lu = a.clone().lu().solve(&b).unwrap();
        assert!((&sol.x - &lu).amax() < 1e-11 * lu.amax());
    }

    #[test]
    fn tiny_time_polynomial_basis_is_recovered_thanks_to_column_scaling() {
        // t in seconds over 4 ms: columns t^5, t^6, t^7 are ~1e-12 … 1e-17.
        let m = 20;
        let t: Vec<f64> = (0..m).map(|k| 2e-4 * k as f64).collect();
        let coef = [3.4e7, 2.2e10, 1.3e12];
        let a = DMatrix::from_fn(m, 3, |i, j| t[i].powi(5 + j as i32));
        let b = DVector::from_fn(m, |i, _| {
            (0..3).map(|j| coef[j] * t[i].powi(5 + j as i32)).sum()
        });
        let sol = lstsq(&a, &b).unwrap();
        for (j, c) in coef.iter().enumerate() {
            assert!((sol.x[j] - c).abs() < 1e-9 * c, "{j}: {}", sol.x[j]);
        }
        assert_eq!(sol.info.rank, 3);
    }

    #[test]
    fn ill_conditioned_vandermonde_agrees_with_svd_in_residual_and_fit() {
        // degree-9 monomials on [0, 1]: condition ~1e7 after scaling
        let m = 40;
        let n = 10;
        let t: Vec<f64> = (0..m).map(|k| k as f64 / (m - 1) as f64).collect();
        let a = DMatrix::from_fn(m, n, |i, j| t[i].powi(j as i32));
        let b = DVector::from_fn(m, |i, _| (3.0 * t[i]).sin() + 0.1 * (17.0 * t[i]).cos());
        let sol = lstsq(&a, &b).unwrap();
        let reference = svd_solve(&a, &b);
        assert_eq!(sol.info.rank, n);
        assert!(
            sol.info.cond_estimate > 1e4,
            "cond {}",
            sol.info.cond_estimate
        );
        let fit_qr = &a * &sol.x;
        let fit_ref = &a * &reference;
        assert!((&fit_qr - &fit_ref).amax() < 1e-9);
        let res_ref = (&a * &reference - &b).norm();
        assert!((sol.info.residual_norm - res_ref).abs() < 1e-9);
        // exact polynomial data: coefficients recovered to the conditioning level
        let c_true = DVector::from_fn(n, |j, _| 1.0 / (1.0 + j as f64));
        let b2 = &a * &c_true;
        let sol2 = lstsq(&a, &b2).unwrap();
        assert!(
            (&sol2.x - &c_true).amax() < 1e-6,
            "{}",
            (&sol2.x - &c_true).amax()
        );
    }

    #[test]
    fn duplicate_column_gives_rank_deficiency_and_minimum_residual() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let (mut a, b) = random_problem(&mut rng, 12, 4);
        let c1 = a.column(1).clone_owned();
        a.set_column(3, &(c1 * 2.0));
        let sol = lstsq(&a, &b).unwrap();
        assert_eq!(sol.info.rank, 3);
        assert!(sol.info.cond_estimate > 1e12);
        // a dropped coefficient is exactly 0
        assert_eq!(sol.x.iter().filter(|v| **v == 0.0).count(), 1);
        let reference = svd_solve(&a, &b);
        let res_ref = (&a * &reference - &b).norm();
        let res = (&a * &sol.x - &b).norm();
        assert!((res - res_ref).abs() < 1e-12);
        assert!((sol.info.residual_norm - res).abs() < 1e-12);
    }

    #[test]
    fn zero_matrix_is_singular() {
        let a = DMatrix::zeros(4, 2);
        let b = DVector::from_element(4, 1.0);
        assert!(matches!(lstsq(&a, &b), Err(Error::Singular { .. })));
    }

    #[test]
    fn zero_column_is_dropped() {
        let a = DMatrix::from_row_slice(3, 2, &[1.0, 0.0, 2.0, 0.0, 3.0, 0.0]);
        let b = DVector::from_vec(vec![2.0, 4.0, 6.0]);
        let sol = lstsq(&a, &b).unwrap();
        assert_eq!(sol.info.rank, 1);
        assert!((sol.x[0] - 2.0).abs() < 1e-14);
        assert_eq!(sol.x[1], 0.0);
    }

    #[test]
    fn ridge_matches_regularised_normal_equations() {
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        for &lambda in &[1e-3, 0.1, 10.0] {
            let (a, b) = random_problem(&mut rng, 10, 4);
            let opts = LstsqOptions {
                ridge: lambda,
                ..LstsqOptions::default()
            };
            let sol = lstsq_with(&a, &b, &opts).unwrap();
            let g = a.transpose() * &a + DMatrix::identity(4, 4) * lambda;
            let reference = g.cholesky().unwrap().solve(&(a.transpose() * &b));
            assert!((&sol.x - &reference).amax() < 1e-12, "lambda {lambda}");
            let res = (&a * &reference - &b).norm();
            assert!((sol.info.residual_norm - res).abs() < 1e-12);
        }
    }

    #[test]
    fn ridge_regularises_rank_deficient_problem() {
        let a = DMatrix::from_row_slice(3, 2, &[1.0, 1.0, 2.0, 2.0, 3.0, 3.0]);
        let b = DVector::from_vec(vec![1.0, 2.0, 3.0]);
        let lambda = 0.5;
        let sol = lstsq_with(
            &a,
            &b,
            &LstsqOptions {
                ridge: lambda,
                ..Default::default()
            },
        )
        .unwrap();
        // symmetric solution x1 = x2 = 14 / (28 + λ)
        let expected = 14.0 / (28.0 + lambda);
        assert!((sol.x[0] - expected).abs() < 1e-14 && (sol.x[1] - expected).abs() < 1e-14);
        assert_eq!(sol.info.rank, 1);
    }

    #[test]
    fn underdetermined_problem_fits_exactly() {
        let a = DMatrix::from_row_slice(2, 3, &[1.0, 2.0, 3.0, 0.0, 1.0, 1.0]);
        let b = DVector::from_vec(vec![6.0, 2.0]);
        let sol = lstsq(&a, &b).unwrap();
        assert_eq!(sol.info.rank, 2);
        assert!(sol.info.cond_estimate.is_infinite());
        assert!((&a * &sol.x - &b).amax() < 1e-13);
    }

    #[test]
    fn bad_inputs_are_errors() {
        let mut ws = QrWorkspace::new(2);
        let mut a = [1.0, f64::NAN, 0.0, 1.0];
        let mut b = [1.0, 2.0];
        let mut x = [0.0; 2];
        let o = LstsqOptions::default();
        assert!(matches!(
            lstsq_in_place(2, 2, &mut a, &mut b, &mut x, &mut ws, &o),
            Err(Error::NonFinite { .. })
        ));
        let mut a = [1.0, 0.0, 0.0, 1.0];
        assert!(matches!(
            lstsq_in_place(2, 2, &mut a, &mut b, &mut x[..1], &mut ws, &o),
            Err(Error::LengthMismatch { .. })
        ));
        let mut small = QrWorkspace::new(1);
        assert!(matches!(
            lstsq_in_place(2, 2, &mut a, &mut b, &mut x, &mut small, &o),
            Err(Error::LengthMismatch { .. })
        ));
        let neg = LstsqOptions { ridge: -1.0, ..o };
        assert!(matches!(
            lstsq_in_place(2, 2, &mut a, &mut b, &mut x, &mut ws, &neg),
            Err(Error::InvalidParameter { .. })
        ));
    }

    #[test]
    fn fixed_size_solver_matches_lstsq_in_place() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(31);
        let mut ws = QrWorkspace::new(3);
        for case in 0..500 {
            let mut a = [[0.0; 8]; 3];
            for col in a.iter_mut() {
                for v in col.iter_mut() {
                    *v = rng.random_range(-1.0..1.0);
                }
            }
            // dependent or badly scaled columns now and then
            match case % 5 {
                1 => a[2] = a[0].map(|v| 2.0 * v),
                2 => a[1] = a[1].map(|v| 1e-9 * v),
                3 => a[2] = [0.0; 8],
                _ => {}
            }
            let b: [f64; 8] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
            let mut flat: Vec<f64> = a.iter().flatten().copied().collect();
            let mut bb = b.to_vec();
            let mut want = [0.0; 3];
            let opts = LstsqOptions::default();
            let r = lstsq_in_place(8, 3, &mut flat, &mut bb, &mut want, &mut ws, &opts);
            let got = lstsq_fixed::<8, 3>(&a, &b, None);
            match (r, got) {
                (Ok(ri), Ok((x, gi))) => {
                    assert_eq!(ri.rank, gi.rank, "case {case}");
                    // the same operations in the same order: the same numbers
                    assert_eq!(ri, gi, "case {case}");
                    assert_eq!(x, want, "case {case}");
                }
                (Err(_), Err(_)) => {}
                (r, g) => panic!("case {case}: {r:?} vs {g:?}"),
            }
        }
    }
}
