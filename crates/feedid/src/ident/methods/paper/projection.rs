//! The window's least-squares projection, computed once and reused while
//! the sample grid repeats.
//!
//! In the scaled variable `s = (τ − τ_c)/h ∈ [−1, 1]` of a window, the
//! input basis `L_0(s) … L_7(s)` depends only on the sample grid `s_i`, not
//! on where the window lies: with the window time origin, and with the
//! motion origin alike, a uniformly sampled recording gives the same `s_i`
//! for every window of the same length. So the thin QR `V = Q·R` of the
//! Legendre columns `V_ik = L_k(s_i)` is computed once (classical
//! Gram–Schmidt with reorthogonalisation, "twice is enough") and every
//! window only projects its data, `c = Qᵀb` (`8·W` multiply-adds).
//!
//! * **Input fit** (all polynomials of degree ≤ 7): the Legendre
//!   coefficients are `R⁻¹·c`.
//! * **Output fit** (`span{τ⁵, τ⁶, τ⁷}`): the basis `φ_k(s) =
//!   (τ(s)/T)⁵·L_k(s)`, `k = 0, 1, 2`, is a polynomial of degree `5 + k ≤ 7`
//!   in `s` — an exact polynomial transform `φ_k = Σ_j C_jk·L_j` of the local
//!   basis, with `C` from `(α + β·s)⁵·L_k(s)`, `α = τ_c/T`, `β = h/T`. Its
//!   least-squares problem is the 8×3 problem `min ‖R·C·a − c‖`
//!   (same columns norms, same pivoted QR, so the same rank and condition
//!   estimate as the `W×3` problem).
//! * The residual norms are `‖b − Q·c‖` (the part of the data outside the
//!   8 polynomials, computed directly) combined with the small problem's.
//!
//! The grid matches the cached one when every `|s_i − s_ref,i|` is within
//! the rounding of `s_i` itself (`8ε·(|t_first| + |t_last| + |origin|)/h +
//! 64ε`): the difference to a fit on the window's own grid is then rounding.
//! Jittered sampling, another window length or the first window rebuild the
//! cache (`O(W·8²)`, about what a direct fit costs).

// Index loops mirror the matrix formulas.
#![allow(clippy::needless_range_loop)]

use super::basis::{LEGENDRE_A, LEGENDRE_B};
use super::polynomials::{NP, NQ};
use crate::error::{Error, Result};
use crate::solve::{lstsq_in_place, LstsqInfo, LstsqOptions, QrWorkspace};

/// Binomial coefficients `C(5, j)`.
const BINOM5: [f64; 6] = [1.0, 5.0, 10.0, 10.0, 5.0, 1.0];

/// QR of the Legendre basis on a sample grid.
#[derive(Debug, Clone)]
pub(super) struct Projection {
    /// Window length of the cached grid (0: none).
    w: usize,
    /// The grid `s_i` it was built for.
    s: Vec<f64>,
    /// `Q` (`W×8`, orthonormal columns), row-major: row `i` = `Q[i·8 .. i·8 + 8]`.
    q: Vec<f64>,
    /// `V = Q·R`, `R` upper triangular (row-major).
    r: [[f64; NQ]; NQ],
    /// Column norms of `V` (the normalised input basis of the direct fit).
    pub(super) vnorm: [f64; NQ],
    /// Rank and condition estimate of the normalised input basis.
    in_rank: usize,
    in_cond: f64,
    /// Scratch of the build (`W×8` and `W`).
    work: Vec<f64>,
    rhs: Vec<f64>,
    /// Grids built so far (a window whose grid matched the cache adds none).
    pub(super) builds: usize,
}

/// Monomial coefficients of `L_k(s)` (`table[k][j]` multiplies `s^j`) and of
/// `s^j` in the Legendre basis (`inverse[j][k]` multiplies `L_k`).
#[derive(Debug, Clone)]
pub(super) struct LegendreTables {
    pub(super) table: [[f64; NQ]; NQ],
    pub(super) inverse: [[f64; NQ]; NQ],
}

impl LegendreTables {
    pub(super) fn new(table: [[f64; NQ]; NQ]) -> Self {
        // s^j = (L_j − Σ_{i<j} table[j][i]·s^i) / table[j][j], recursively
        let mut inverse = [[0.0; NQ]; NQ];
        for j in 0..NQ {
            let lead = table[j][j];
            let mut row = [0.0; NQ];
            row[j] = 1.0 / lead;
            for i in 0..j {
                let c = table[j][i] / lead;
                if c != 0.0 {
                    for k in 0..NQ {
                        row[k] -= c * inverse[i][k];
                    }
                }
            }
            inverse[j] = row;
        }
        Self { table, inverse }
    }
}

impl Projection {
    pub(super) fn new() -> Self {
        Self {
            w: 0,
            s: Vec::new(),
            q: Vec::new(),
            r: [[0.0; NQ]; NQ],
            vnorm: [1.0; NQ],
            in_rank: 0,
            in_cond: f64::INFINITY,
            work: Vec::new(),
            rhs: Vec::new(),
            builds: 0,
        }
    }

    /// Whether the cached grid is `s` to within `tol` in every sample.
    pub(super) fn matches(&self, s: &[f64], tol: f64) -> bool {
        self.w == s.len() && self.s.iter().zip(s).all(|(a, b)| (a - b).abs() <= tol)
    }

    /// Build the QR of the Legendre columns on the grid `s` (grows the
    /// buffers for a longer window; allocation-free otherwise).
    pub(super) fn build(&mut self, s: &[f64], qr: &mut QrWorkspace) -> Result<()> {
        let w = s.len();
        if w < NQ {
            return Err(Error::TooFewSamples {
                what: "paper window (8 input coefficients)",
                needed: NQ,
                actual: w,
            });
        }
        if self.s.len() < w {
            self.s.resize(w, 0.0);
            self.q.resize(w * NQ, 0.0);
            self.work.resize(w * NQ, 0.0);
            self.rhs.resize(w, 0.0);
        }
        self.w = 0;
        self.s[..w].copy_from_slice(s);
        // V columns (column-major in `q` during the build) by the Legendre recurrence
        let q = &mut self.work[..w * NQ];
        for (i, &si) in s.iter().enumerate() {
            let mut lm1 = 1.0;
            let mut l = si;
            q[i] = 1.0;
            q[i + w] = si;
            for k in 1..NQ - 1 {
                let next = LEGENDRE_A[k] * si * l - LEGENDRE_B[k] * lm1;
                lm1 = l;
                l = next;
                q[i + (k + 1) * w] = l;
            }
        }
        // rank and condition estimate of the normalised V, as the direct fit reports them
        let work = &mut self.q[..w * NQ];
        work.copy_from_slice(q);
        for k in 0..NQ {
            let col = &mut work[k * w..(k + 1) * w];
            let n = col.iter().map(|v| v * v).sum::<f64>().sqrt();
            self.vnorm[k] = n;
            if n > 0.0 {
                col.iter_mut().for_each(|v| *v /= n);
            }
        }
        let rhs = &mut self.rhs[..w];
        rhs.fill(0.0);
        let mut x = [0.0; NQ];
        let info = lstsq_in_place(w, NQ, work, rhs, &mut x, qr, &LstsqOptions::default())?;
        self.in_rank = info.rank;
        self.in_cond = info.cond_estimate;
        // classical Gram–Schmidt, each column twice: V = Q·R
        self.r = [[0.0; NQ]; NQ];
        for k in 0..NQ {
            for _ in 0..2 {
                for i in 0..k {
                    let (head, tail) = q.split_at_mut(k * w);
                    let qi = &head[i * w..(i + 1) * w];
                    let vk = &mut tail[..w];
                    let d: f64 = qi.iter().zip(vk.iter()).map(|(a, b)| a * b).sum();
                    self.r[i][k] += d;
                    vk.iter_mut().zip(qi).for_each(|(v, a)| *v -= d * a);
                }
            }
            let vk = &mut q[k * w..(k + 1) * w];
            let n = vk.iter().map(|v| v * v).sum::<f64>().sqrt();
            if !(n > 0.0 && n.is_finite()) {
                return Err(Error::Singular {
                    context: "paper window basis (repeated sample times)",
                });
            }
            self.r[k][k] = n;
            vk.iter_mut().for_each(|v| *v /= n);
        }
        // Q row-major for the projections
        for i in 0..w {
            for k in 0..NQ {
                self.q[i * NQ + k] = q[i + k * w];
            }
        }
        self.w = w;
        self.builds += 1;
        Ok(())
    }

    /// `c = Qᵀ·b` and `d = Qᵀ·e` for two data vectors; returns `‖b − Q·c‖`
    /// and `‖e − Q·d‖` (the data outside the 8 polynomials). By rows of `Q`:
    /// 8-wide operations throughout.
    pub(super) fn project2(
        &self,
        b: &[f64],
        e: &[f64],
        c: &mut [f64; NQ],
        d: &mut [f64; NQ],
    ) -> (f64, f64) {
        let w = self.w;
        let q = &self.q[..w * NQ];
        let (b, e) = (&b[..w], &e[..w]);
        *c = [0.0; NQ];
        *d = [0.0; NQ];
        for ((row, &bi), &ei) in q.chunks_exact(NQ).zip(b).zip(e) {
            for k in 0..NQ {
                c[k] += row[k] * bi;
                d[k] += row[k] * ei;
            }
        }
        let (mut rb, mut re) = (0.0, 0.0);
        for ((row, &bi), &ei) in q.chunks_exact(NQ).zip(b).zip(e) {
            let (mut pb, mut pe) = (0.0, 0.0);
            for k in 0..NQ {
                pb += row[k] * c[k];
                pe += row[k] * d[k];
            }
            rb += (bi - pb) * (bi - pb);
            re += (ei - pe) * (ei - pe);
        }
        (rb.sqrt(), re.sqrt())
    }

    /// Legendre coefficients `R⁻¹·c` of the input fit.
    pub(super) fn input_coefficients(&self, c: &[f64; NQ], a: &mut [f64; NQ]) {
        for k in (0..NQ).rev() {
            let mut v = c[k];
            for j in (k + 1)..NQ {
                v -= self.r[k][j] * a[j];
            }
            a[k] = v / self.r[k][k];
        }
    }

    /// `R` times the Legendre coefficients `x`.
    pub(super) fn times_r(&self, x: &[f64; NQ], out: &mut [f64; NQ]) {
        for i in 0..NQ {
            out[i] = (i..NQ).map(|j| self.r[i][j] * x[j]).sum();
        }
    }

    /// The normalised input basis in the projected coordinates: `R·diag(1/‖V_k‖)`
    /// (column-major 8×8, upper triangular).
    pub(super) fn input_matrix(&self, m: &mut [f64; NQ * NQ]) {
        for k in 0..NQ {
            for i in 0..NQ {
                m[i + k * NQ] = if i <= k {
                    self.r[i][k] / self.vnorm[k]
                } else {
                    0.0
                };
            }
        }
    }

    /// Rank, condition estimate and (given) residual of the input fit.
    pub(super) fn input_info(&self, residual_norm: f64) -> LstsqInfo {
        LstsqInfo {
            rank: self.in_rank,
            cond_estimate: self.in_cond,
            residual_norm,
        }
    }

    /// The output basis `φ_k = (α + β·s)⁵·L_k(s)`, `k = 0, 1, 2`, in the
    /// projected coordinates `R·C` (column-major 8×3), its column norms
    /// (those of the `W×3` basis) in `norms`.
    pub(super) fn output_matrix(
        &self,
        tables: &LegendreTables,
        alpha: f64,
        beta: f64,
        m: &mut [f64; NQ * NP],
        norms: &mut [f64; NP],
    ) {
        // (α + β·s)⁵ in powers of s
        let mut e = [0.0; 6];
        let (mut ap, mut bp) = ([1.0; 6], [1.0; 6]);
        for j in 1..6 {
            ap[j] = ap[j - 1] * alpha;
            bp[j] = bp[j - 1] * beta;
        }
        for (j, ej) in e.iter_mut().enumerate() {
            *ej = BINOM5[j] * ap[5 - j] * bp[j];
        }
        for k in 0..NP {
            // times L_k in powers of s, then in the Legendre basis
            let mut mono = [0.0; NQ];
            for (j, &ej) in e.iter().enumerate() {
                for i in 0..=k {
                    mono[j + i] += ej * tables.table[k][i];
                }
            }
            let mut leg = [0.0; NQ];
            for (j, &mj) in mono.iter().enumerate() {
                if mj != 0.0 {
                    for (l, inv) in leg.iter_mut().zip(&tables.inverse[j]) {
                        *l += mj * inv;
                    }
                }
            }
            let mut col = [0.0; NQ];
            self.times_r(&leg, &mut col);
            norms[k] = col.iter().map(|v| v * v).sum::<f64>().sqrt();
            m[k * NQ..(k + 1) * NQ].copy_from_slice(&col);
        }
    }
}
