//! Ridge least squares on an upper-Hessenberg (or triangular) matrix in
//! `n³/3 + O(n²)` multiply-adds, for problems that arrive already reduced to
//! (nearly) triangular form — the per-window problem of the sliding ARX
//! factor.
//!
//! Solves `min_x ‖H·x − b‖₂² + Σ_j λ_j·x_j²` (a ridge `λ_j ≥ 0` per
//! unknown) for an `m×n` upper-Hessenberg `H` (`H_ij = 0` for `i > j + 1`),
//! `m ∈ {n, n+1}`, row-major. The stacked problem
//! `[H; diag(√λ_j)]·x ≈ [b; 0]` is reduced by one Householder reflection
//! per column that respects its structure: at column `k` only `H_kk`, the
//! subdiagonal `H_(k+1)k` and the first `k + 1` ridge rows (filled in by the
//! earlier reflections) are non-zero, so step `k` costs `2(k+3)(n−k)`
//! multiply-adds on whole rows (Eldén's reduction of a regularised
//! triangular problem, done with reflections; the right-hand side rides
//! along as an extra column). Back substitution on the final triangle gives
//! `x`. No normal equations are formed.
//!
//! [`HessenbergInfo`] reports the residual `‖H·x − b‖` of the data rows
//! (without the ridge term). Without ridge a zero pivot is
//! [`Error::Singular`]; the routine does not reveal rank — use
//! [`lstsq_in_place`](super::lstsq_in_place) for rank-deficient problems.
//! [`hessenberg_condition`] estimates the 1-norm condition number of `H`'s
//! columns separately (LINPACK's `dtrco` on its triangular factor), for
//! callers that want it only now and then.
//!
//! Allocation-free with a [`HessenbergWorkspace`]; the row operations run
//! over aligned groups of 4 elements and on AVX2 when the CPU has it (same
//! operations in the same order, no FMA contraction: bit-identical).
//!
//! References: L. Eldén, "Algorithms for the regularization of ill-conditioned
//! least squares problems", BIT 17 (1977) 134–145; Golub & Van Loan,
//! *Matrix Computations*, 4th ed., §5.1–5.2, §6.1.4; A.K. Cline, C.B. Moler,
//! G.W. Stewart, J.H. Wilkinson, "An estimate for the condition number of a
//! matrix", SIAM J. Numer. Anal. 16 (1979) 368–375.

use crate::error::{Error, Result};
use crate::solve::rows::{avx2, axpy, reflection, scaled, sub_scaled};

/// Result information of [`lstsq_hessenberg`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HessenbergInfo {
    /// `‖H·x − b‖₂` of the returned solution (data rows only).
    pub residual_norm: f64,
}

/// Reusable scratch memory for [`lstsq_hessenberg`] and
/// [`hessenberg_condition`], for up to `n` unknowns.
#[derive(Debug, Clone)]
pub struct HessenbergWorkspace {
    n_max: usize,
    /// `[H | b]`, `(n+1) × ns` row-major, `ns` = `n + 1` rounded up to 4.
    a: Vec<f64>,
    /// The ridge rows `n × ns`, with their right-hand side in column `n`.
    l: Vec<f64>,
    /// Scratch of the condition estimate.
    z: Vec<f64>,
    /// The reflected combination of the active rows.
    w: Vec<f64>,
    avx: bool,
}

impl HessenbergWorkspace {
    /// Workspace for problems with at most `n` unknowns.
    pub fn new(n: usize) -> Self {
        let ns = stride_of(n);
        Self {
            n_max: n,
            a: vec![0.0; (n + 1) * ns],
            l: vec![0.0; n * ns],
            z: vec![0.0; n],
            w: vec![0.0; ns],
            avx: avx2(),
        }
    }
}

/// Row stride of the working rows: `n + 1` (the right-hand side) rounded up to 4.
fn stride_of(n: usize) -> usize {
    (n + 1).div_ceil(4) * 4
}

fn check_sizes(m: usize, n: usize, h: usize, ws: &HessenbergWorkspace) -> Result<()> {
    if n == 0 || !(m == n || m == n + 1) {
        return Err(Error::LengthMismatch {
            what: "Hessenberg least squares rows (n or n+1)",
            expected: n + 1,
            actual: m,
        });
    }
    if h != m * n {
        return Err(Error::LengthMismatch {
            what: "Hessenberg matrix",
            expected: m * n,
            actual: h,
        });
    }
    if ws.n_max < n {
        return Err(Error::LengthMismatch {
            what: "Hessenberg workspace capacity",
            expected: n,
            actual: ws.n_max,
        });
    }
    Ok(())
}

/// Solve `min ‖H·x − b‖² + Σ λ_j·x_j²` for an `m×n` upper-Hessenberg `H`
/// (row-major, `h[i·n + j]`; entries below the first subdiagonal are
/// ignored), `m = n` or `m = n + 1`; `ridge` holds the `λ_j` (length `n`).
///
/// Errors: [`Error::LengthMismatch`] for inconsistent sizes,
/// [`Error::InvalidParameter`] for a negative or non-finite `λ_j`,
/// [`Error::Singular`] for a zero pivot or a non-finite solution.
///
/// ```
/// use feedid::solve::{lstsq_hessenberg, HessenbergWorkspace};
/// // the 3×2 Hessenberg matrix [1 0; 1 1; 0 1] (row-major) and b = H·[1, 2]
/// let h = [1.0, 0.0, 1.0, 1.0, 0.0, 1.0];
/// let b = [1.0, 3.0, 2.0];
/// let mut x = [0.0; 2];
/// let mut ws = HessenbergWorkspace::new(2);
/// let info = lstsq_hessenberg(3, 2, &h, &b, &[0.0; 2], &mut x, &mut ws).unwrap();
/// assert!((x[0] - 1.0).abs() < 1e-14 && (x[1] - 2.0).abs() < 1e-14);
/// assert!(info.residual_norm < 1e-14);
/// ```
pub fn lstsq_hessenberg(
    m: usize,
    n: usize,
    h: &[f64],
    b: &[f64],
    ridge: &[f64],
    x: &mut [f64],
    ws: &mut HessenbergWorkspace,
) -> Result<HessenbergInfo> {
    check_sizes(m, n, h.len(), ws)?;
    if b.len() != m {
        return Err(Error::LengthMismatch {
            what: "Hessenberg right-hand side",
            expected: m,
            actual: b.len(),
        });
    }
    let ns = stride_of(n);
    load(m, n, ns, h, Some(b), &mut ws.a[..m * ns]);
    solve_loaded(
        m,
        n,
        ridge,
        x,
        ws,
        |i, j| if j < n { h[i * n + j] } else { b[i] },
    )
}

/// [`lstsq_hessenberg`] on a view of a larger row-major matrix: `H_ij =
/// rows[i·stride + off + j]` and `b_i = rows[i·stride + off + n]` (the
/// right-hand side is the column after `H`'s), `i < m`, `j < n`; entries
/// below the first subdiagonal must be zero.
#[allow(clippy::too_many_arguments)]
pub(crate) fn lstsq_hessenberg_view(
    m: usize,
    n: usize,
    rows: &[f64],
    stride: usize,
    off: usize,
    ridge: &[f64],
    x: &mut [f64],
    ws: &mut HessenbergWorkspace,
) -> Result<HessenbergInfo> {
    check_sizes(m, n, m * n, ws)?;
    if (m - 1) * stride + off + n >= rows.len() {
        return Err(Error::LengthMismatch {
            what: "Hessenberg matrix view",
            expected: (m - 1) * stride + off + n + 1,
            actual: rows.len(),
        });
    }
    let ns = stride_of(n);
    let a = &mut ws.a[..m * ns];
    for i in 0..m {
        let src = &rows[i * stride + off..i * stride + off + n + 1];
        let dst = &mut a[i * ns..(i + 1) * ns];
        dst[..n + 1].copy_from_slice(src);
        dst[n + 1..].fill(0.0);
    }
    solve_loaded(m, n, ridge, x, ws, |i, j| rows[i * stride + off + j])
}

/// Eliminate and back-substitute the rows loaded into `ws.a`; `hb(i, j)`
/// reads the original `H_ij` (`j < n`) or `b_i` (`j = n`) for the data residual.
fn solve_loaded(
    m: usize,
    n: usize,
    ridge: &[f64],
    x: &mut [f64],
    ws: &mut HessenbergWorkspace,
    hb: impl Fn(usize, usize) -> f64,
) -> Result<HessenbergInfo> {
    for (what, expected, actual) in [
        ("Hessenberg solution", n, x.len()),
        ("Hessenberg ridge", n, ridge.len()),
    ] {
        if expected != actual {
            return Err(Error::LengthMismatch {
                what,
                expected,
                actual,
            });
        }
    }
    if let Some(&v) = ridge.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
        return Err(Error::InvalidParameter {
            name: "ridge",
            value: v,
            reason: "must be finite and >= 0",
        });
    }
    let ns = stride_of(n);
    let a = &mut ws.a[..m * ns];
    let l = &mut ws.l[..n * ns];
    let with_ridge = ridge.iter().any(|&v| v > 0.0);
    if with_ridge {
        l.fill(0.0);
        for (k, &v) in ridge.iter().enumerate() {
            l[k * ns + k] = v.sqrt();
        }
    }
    let l = if with_ridge { Some(l) } else { None };
    eliminate(m, n, ns, a, l, &mut ws.w, ws.avx);

    // back substitution on the triangle, right-hand side in column n
    for k in (0..n).rev() {
        let d = a[k * ns + k];
        if d == 0.0 {
            return Err(Error::Singular {
                context: "Hessenberg least squares (zero pivot)",
            });
        }
        let mut s = a[k * ns + n];
        for j in (k + 1)..n {
            s -= a[k * ns + j] * x[j];
        }
        x[k] = s / d;
    }
    if x.iter().any(|v| !v.is_finite()) {
        return Err(Error::Singular {
            context: "Hessenberg least squares (solution overflowed)",
        });
    }
    // data residual from the untouched H and b
    let mut res2 = 0.0;
    for i in 0..m {
        let mut s = -hb(i, n);
        for (j, xj) in x.iter().enumerate().skip(i.saturating_sub(1)) {
            s += hb(i, j) * xj;
        }
        res2 += s * s;
    }
    Ok(HessenbergInfo {
        residual_norm: res2.sqrt(),
    })
}

/// Estimate of the 1-norm condition number of the columns of the `m×n`
/// upper-Hessenberg `H` (row-major, as for [`lstsq_hessenberg`]): LINPACK's
/// `dtrco` estimate of `‖T‖₁·‖T⁻¹‖₁` for its triangular factor `T`
/// (`∞` for a zero pivot; `1` at least). An estimate from below, in
/// practice within a small factor of the true value.
pub fn hessenberg_condition(
    m: usize,
    n: usize,
    h: &[f64],
    ws: &mut HessenbergWorkspace,
) -> Result<f64> {
    check_sizes(m, n, h.len(), ws)?;
    let ns = stride_of(n);
    let a = &mut ws.a[..m * ns];
    load(m, n, ns, h, None, a);
    eliminate(m, n, ns, a, None, &mut ws.w, ws.avx);
    Ok(triangular_condition(n, ns, a, &mut ws.z[..n]))
}

/// Copy `H` (and `b` into column `n`) into the padded rows of `a`.
fn load(m: usize, n: usize, ns: usize, h: &[f64], b: Option<&[f64]>, a: &mut [f64]) {
    a.fill(0.0);
    for i in 0..m {
        let from = i.saturating_sub(1);
        a[i * ns + from..i * ns + n].copy_from_slice(&h[i * n + from..(i + 1) * n]);
        if let Some(b) = b {
            a[i * ns + n] = b[i];
        }
    }
}

/// The structured Householder reduction (see the module doc) of the rows of
/// `a` (`m × ns`) and the ridge rows `l` (`n × ns`, if any), with the row
/// length as a constant for the common strides, on AVX2 when the CPU has it.
fn eliminate(
    m: usize,
    n: usize,
    ns: usize,
    a: &mut [f64],
    l: Option<&mut [f64]>,
    w: &mut [f64],
    avx: bool,
) {
    #[cfg(target_arch = "x86_64")]
    if avx {
        // SAFETY: `avx` is set only when the CPU reports AVX2 (workspace construction).
        unsafe {
            match ns {
                8 => eliminate_avx2::<8>(m, n, ns, a, l, w),
                12 => eliminate_avx2::<12>(m, n, ns, a, l, w),
                16 => eliminate_avx2::<16>(m, n, ns, a, l, w),
                20 => eliminate_avx2::<20>(m, n, ns, a, l, w),
                24 => eliminate_avx2::<24>(m, n, ns, a, l, w),
                _ => eliminate_avx2::<0>(m, n, ns, a, l, w),
            }
        }
        return;
    }
    let _ = avx;
    match ns {
        8 => eliminate_kernel::<8>(m, n, ns, a, l, w),
        12 => eliminate_kernel::<12>(m, n, ns, a, l, w),
        16 => eliminate_kernel::<16>(m, n, ns, a, l, w),
        20 => eliminate_kernel::<20>(m, n, ns, a, l, w),
        24 => eliminate_kernel::<24>(m, n, ns, a, l, w),
        _ => eliminate_kernel::<0>(m, n, ns, a, l, w),
    }
}

/// [`eliminate_kernel`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn eliminate_avx2<const W: usize>(
    m: usize,
    n: usize,
    ns: usize,
    a: &mut [f64],
    l: Option<&mut [f64]>,
    w: &mut [f64],
) {
    eliminate_kernel::<W>(m, n, ns, a, l, w)
}

/// Step `k`: the reflection of `(a_kk; a_(k+1)k, l_0k … l_kk)` applied to
/// those rows. Every active row is zero left of column `k`, so the rows are
/// processed whole (`W = ns`) or from the column's aligned group of 4 on (`W = 0`).
#[inline(always)]
fn eliminate_kernel<const W: usize>(
    m: usize,
    n: usize,
    ns: usize,
    a: &mut [f64],
    l: Option<&mut [f64]>,
    w_dyn: &mut [f64],
) {
    // with a constant row length the reflected row is local (aliases nothing)
    if W > 0 {
        eliminate_body::<W>(m, n, ns, a, l, &mut [0.0; W]);
    } else {
        eliminate_body::<W>(m, n, ns, a, l, w_dyn);
    }
}

#[inline(always)]
fn eliminate_body<const W: usize>(
    m: usize,
    n: usize,
    ns: usize,
    a: &mut [f64],
    mut l: Option<&mut [f64]>,
    w_all: &mut [f64],
) {
    for k in 0..n {
        let start = if W > 0 { 0 } else { k & !3 };
        let sub = if k + 1 < m { a[(k + 1) * ns + k] } else { 0.0 };
        let mut sigma = sub * sub;
        if let Some(l) = l.as_deref() {
            for i in 0..=k {
                let v = l[i * ns + k];
                sigma += v * v;
            }
        }
        if sigma == 0.0 {
            continue;
        }
        // the rescaled norm (rare) needs the column's size only
        let (norm, v0, tau) = reflection(a[k * ns + k], sigma, &[sigma.sqrt()]);
        let w = &mut w_all[start..ns];
        let (head, tail) = a.split_at_mut((k + 1) * ns);
        let ak = &mut head[k * ns + start..(k + 1) * ns];
        scaled::<W>(w, v0, ak);
        let next = if k + 1 < m {
            Some(&mut tail[start..ns])
        } else {
            None
        };
        if let Some(row) = next.as_deref() {
            axpy::<W>(w, sub, row);
        }
        if let Some(l) = l.as_deref() {
            for i in 0..=k {
                let c = l[i * ns + k];
                axpy::<W>(w, c, &l[i * ns + start..(i + 1) * ns]);
            }
        }
        sub_scaled::<W>(ak, tau * v0, w);
        ak[k - start] = norm;
        if let Some(row) = next {
            sub_scaled::<W>(row, tau * sub, w);
            row[k - start] = 0.0;
        }
        if let Some(l) = l.as_deref_mut() {
            for i in 0..=k {
                let c = l[i * ns + k];
                let row = &mut l[i * ns + start..(i + 1) * ns];
                sub_scaled::<W>(row, tau * c, w);
                row[k - start] = 0.0;
            }
        }
    }
}

/// LINPACK's `dtrco` estimate of `‖T‖₁·‖T⁻¹‖₁` for the row-major upper
/// triangle `t` (row stride `ts`; `∞` if a diagonal entry is zero): solve `Tᵀy = e` with
/// `e_k = ±1` chosen for growth as the substitution goes, then `T·z = y`;
/// `‖T⁻¹‖₁ ≈ ‖z‖₁/‖y‖₁`.
fn triangular_condition(n: usize, ts: usize, t: &[f64], z: &mut [f64]) -> f64 {
    if (0..n).any(|k| t[k * ts + k] == 0.0) {
        return f64::INFINITY;
    }
    // ‖T‖₁: largest column sum
    let mut tnorm = 0.0f64;
    for j in 0..n {
        let s: f64 = (0..=j).map(|i| t[i * ts + j].abs()).sum();
        tnorm = tnorm.max(s);
    }
    // Tᵀ y = e, y in z (forward substitution by rows of T)
    z.fill(0.0);
    let mut ek = 1.0f64;
    for k in 0..n {
        if z[k] != 0.0 {
            ek = ek.abs().copysign(-z[k]);
        }
        let tkk = t[k * ts + k];
        if (ek - z[k]).abs() > tkk.abs() {
            let s = tkk.abs() / (ek - z[k]).abs();
            for v in z.iter_mut() {
                *v *= s;
            }
            ek *= s;
        }
        let mut wk = (ek - z[k]) / tkk;
        let wkm = (-ek - z[k]) / tkk;
        let mut s = (ek - z[k]).abs();
        let mut sm = (-ek - z[k]).abs();
        let row = &t[k * ts + k + 1..k * ts + n];
        let tail = &mut z[k + 1..n];
        for (zj, &tkj) in tail.iter_mut().zip(row) {
            sm += (*zj + wkm * tkj).abs();
            *zj += wk * tkj;
            s += zj.abs();
        }
        if s < sm {
            let w = wkm - wk;
            wk = wkm;
            for (zj, &tkj) in tail.iter_mut().zip(row) {
                *zj += w * tkj;
            }
        }
        z[k] = wk;
    }
    let ynorm: f64 = z.iter().map(|v| v.abs()).sum();
    // T z = y (back substitution)
    for k in (0..n).rev() {
        let mut s = z[k];
        for j in (k + 1)..n {
            s -= t[k * ts + j] * z[j];
        }
        z[k] = s / t[k * ts + k];
    }
    let znorm: f64 = z.iter().map(|v| v.abs()).sum();
    let est = tnorm * znorm / ynorm;
    if est.is_finite() {
        est.max(1.0)
    } else {
        f64::INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solve::{lstsq_in_place, LstsqOptions, QrWorkspace};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Random Hessenberg (or triangular) problem, row-major, with column scales over decades.
    fn problem(rng: &mut ChaCha8Rng, m: usize, n: usize) -> (Vec<f64>, Vec<f64>) {
        let mut h = vec![0.0; m * n];
        for i in 0..m {
            for j in 0..n {
                if i <= j + 1 {
                    h[i * n + j] = rng.random_range(-1.0..1.0);
                }
            }
        }
        // make a few columns nearly dependent
        if n > 3 {
            for i in 0..m {
                h[i * n + 2] = h[i * n + 1] + 1e-6 * h[i * n + 2];
            }
        }
        let b = (0..m).map(|_| rng.random_range(-1.0..1.0)).collect();
        (h, b)
    }

    #[test]
    fn hessenberg_solution_matches_householder_lstsq_with_and_without_ridge() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let mut ws = HessenbergWorkspace::new(20);
        let mut qr = QrWorkspace::new(20);
        for case in 0..400 {
            let n = rng.random_range(1..18);
            let m = if case % 3 == 0 { n } else { n + 1 };
            let level = [0.0, 1e-8, 1e-3, 1.0][case % 4];
            // the same ridge on every unknown, or one per unknown (some zero)
            let ridge: Vec<f64> = (0..n)
                .map(|_| {
                    if case % 8 < 4 {
                        level
                    } else {
                        level * rng.random_range(0.0..2.0f64).floor()
                    }
                })
                .collect();
            let (h, b) = problem(&mut rng, m, n);
            // reference: the stacked problem [H; diag(√λ)] by the pivoted Householder solver
            let rows = m + n;
            let mut a = vec![0.0; rows * n];
            for i in 0..m {
                for j in 0..n {
                    a[i + j * rows] = h[i * n + j];
                }
            }
            for j in 0..n {
                a[m + j + j * rows] = ridge[j].sqrt();
            }
            let mut bb = b.clone();
            bb.resize(rows, 0.0);
            let mut want = vec![0.0; n];
            let opts = LstsqOptions {
                ridge: 0.0,
                rank_tolerance: Some(0.0),
            };
            let Ok(ref_info) = lstsq_in_place(rows, n, &mut a, &mut bb, &mut want, &mut qr, &opts)
            else {
                continue;
            };
            let mut x = vec![0.0; n];
            let Ok(info) = lstsq_hessenberg(m, n, &h, &b, &ridge, &mut x, &mut ws) else {
                // only a zero pivot of an unregularised column may fail
                assert!(ridge.contains(&0.0), "case {case}");
                continue;
            };
            // agreement to the conditioning of the (stacked) problem
            let cond = ref_info.cond_estimate;
            let scale = want.iter().fold(1.0f64, |a, v| a.max(v.abs()));
            for j in 0..n {
                assert!(
                    (x[j] - want[j]).abs() <= 1e-13 * cond * cond.max(1.0) * scale + 1e-13 * scale,
                    "case {case} (m {m}, n {n}, ridge {ridge:?}) x[{j}] {} vs {} (cond {cond:e})",
                    x[j],
                    want[j]
                );
            }
            // the residual is the data residual of the returned x, to its
            // rounding level ε·‖H‖·‖x‖
            let rtol = 1e-13 * (1.0 + info.residual_norm + n as f64 * scale);
            let mut r2 = 0.0;
            for i in 0..m {
                let s: f64 = (0..n).map(|j| h[i * n + j] * x[j]).sum::<f64>() - b[i];
                r2 += s * s;
            }
            assert!(
                (r2.sqrt() - info.residual_norm).abs() <= rtol,
                "case {case}: residual {} vs {}",
                info.residual_norm,
                r2.sqrt()
            );
            let cond = hessenberg_condition(m, n, &h, &mut ws).unwrap();
            assert!(cond >= 1.0);
        }
    }

    #[test]
    fn avx2_build_gives_the_portable_results_bit_for_bit() {
        // the kernels are chosen at run time: both builds must agree exactly
        // (on a CPU without AVX2 both are the portable one), for every row
        // stride (the fixed-length kernels 8…24 and the general one)
        let mut fast = HessenbergWorkspace::new(30);
        let mut slow = crate::solve::rows::portable(|| HessenbergWorkspace::new(30));
        assert!(!slow.avx);
        #[cfg(target_arch = "x86_64")]
        assert_eq!(fast.avx, std::arch::is_x86_feature_detected!("avx2"));
        let mut rng = ChaCha8Rng::seed_from_u64(43);
        for case in 0..400 {
            let n = rng.random_range(1..=30);
            let m = if case % 3 == 0 { n } else { n + 1 };
            let (h, b) = problem(&mut rng, m, n);
            let ridge: Vec<f64> = (0..n).map(|j| [1e-8, 0.0, 1.0][(case + j) % 3]).collect();
            let run = |ws: &mut HessenbergWorkspace| {
                let mut x = vec![0.0; n];
                let info =
                    lstsq_hessenberg(m, n, &h, &b, &ridge, &mut x, ws).map(|i| format!("{i:?}"));
                let cond = hessenberg_condition(m, n, &h, ws).map(f64::to_bits);
                let x: Vec<u64> = x.iter().map(|v| v.to_bits()).collect();
                (
                    info.map_err(|e| e.to_string()),
                    cond.map_err(|e| e.to_string()),
                    x,
                )
            };
            assert_eq!(run(&mut fast), run(&mut slow), "case {case} (m {m}, n {n})");
        }
    }

    #[test]
    fn condition_estimate_is_within_a_small_factor_of_the_true_one_norm_condition() {
        let mut rng = ChaCha8Rng::seed_from_u64(12);
        let mut z = [0.0; 12];
        let mut worst: f64 = 1.0;
        for case in 0..300 {
            let n = rng.random_range(1..12);
            // triangle with graded or nearly dependent columns
            let mut t = vec![0.0; n * n];
            for i in 0..n {
                for j in i..n {
                    t[i * n + j] = rng.random_range(-1.0..1.0);
                }
                t[i * n + i] *= 10f64.powi(-rng.random_range(0..(1 + case % 8)));
            }
            let est = triangular_condition(n, n, &t, &mut z[..n]);
            let m = nalgebra::DMatrix::from_row_slice(n, n, &t);
            let inv = m.clone().try_inverse().unwrap();
            let norm1 = |a: &nalgebra::DMatrix<f64>| {
                (0..n)
                    .map(|j| a.column(j).iter().map(|v| v.abs()).sum::<f64>())
                    .fold(0.0, f64::max)
            };
            let truth = norm1(&m) * norm1(&inv);
            // an estimate never exceeds the truth (‖z‖/‖y‖ ≤ ‖T⁻¹‖₁) up to rounding
            assert!(est <= truth * (1.0 + 1e-8), "case {case}: {est} > {truth}");
            worst = worst.max(truth / est);
        }
        assert!(worst < 10.0, "worst underestimate factor {worst}");
    }

    #[test]
    fn zero_pivot_without_ridge_is_singular_and_ridge_makes_it_solvable() {
        let mut ws = HessenbergWorkspace::new(2);
        // triangular 2×2 with a zero in the last pivot (two equal columns)
        let h = [1.0, 1.0, 0.0, 0.0];
        let mut x = [0.0; 2];
        assert!(lstsq_hessenberg(2, 2, &h, &[1.0, 1.0], &[0.0; 2], &mut x, &mut ws).is_err());
        lstsq_hessenberg(2, 2, &h, &[2.0, 0.0], &[1e-6; 2], &mut x, &mut ws).unwrap();
        // the ridge splits the weight evenly between the two equal columns
        assert!((x[0] - x[1]).abs() < 1e-6 && (x[0] + x[1] - 2.0).abs() < 1e-5);
        assert_eq!(
            hessenberg_condition(2, 2, &h, &mut ws).unwrap(),
            f64::INFINITY
        );
    }

    #[test]
    fn bad_sizes_and_ridge_are_rejected() {
        let mut ws = HessenbergWorkspace::new(2);
        let mut x = [0.0; 2];
        let eye = [1.0, 0.0, 0.0, 1.0];
        assert!(lstsq_hessenberg(4, 2, &[0.0; 8], &[0.0; 4], &[0.0; 2], &mut x, &mut ws).is_err());
        assert!(lstsq_hessenberg(2, 2, &eye, &[0.0; 2], &[-1.0, 0.0], &mut x, &mut ws).is_err());
        assert!(lstsq_hessenberg(2, 2, &eye, &[0.0; 3], &[0.0; 2], &mut x, &mut ws).is_err());
        let mut small = HessenbergWorkspace::new(1);
        assert!(lstsq_hessenberg(2, 2, &eye, &[0.0; 2], &[0.0; 2], &mut x, &mut small).is_err());
    }
}
