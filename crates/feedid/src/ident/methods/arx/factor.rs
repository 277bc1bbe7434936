//! The sliding QR factor of an ARX window: an upper-triangular `R` with
//! `RᵀR = XᵀX` for the scaled rows `X = [1, ψ, y]` of the window, in the
//! window's frame, obtained with orthogonal transformations only — no
//! downdating.
//!
//! **Two stacks.** A window `[s, e)` that moved by the hop `h` is split at
//! the last *rebuild* point `f` (the end of the window that was last factored
//! from scratch): the rows `[s, f)` and the rows `[f, e)`. At a rebuild the
//! factors of every suffix `[s + j·h, f)`, `j = 0, 1, …` (the *front
//! aggregates*) are computed from scratch, from the last block backwards,
//! each from the next by a block Householder update with `h` rows; the
//! *back* factor of `[f, e)` starts empty and takes the `h` new rows of
//! each window. The window's factor is then the front aggregate of its start
//! merged with the back factor: one Householder reduction of two stacked
//! triangles (`p³/3` multiply-adds). When the window start reaches `f`, the
//! next rebuild follows (every `⌈W/h⌉` windows: for W = 200, h = 10, every
//! 20th window; its cost, `W` rows in blocks of `h`, is then spread over 20
//! windows). Per window: `h` rows added, a merge, and `1/⌈W/h⌉` of a
//! rebuild. Each window's factor comes from the exact rows by orthogonal
//! steps alone, so there is no drift and no refactoring for accuracy; the
//! sliding downdate of earlier versions (LINPACK `dchdd`) failed on every
//! third window of smooth data, whose lagged commands are collinear to
//! machine precision.
//!
//! **Frame change.** The rows are `[1, ψ(r₀), ỹ(r₀)]` with
//! `ψ(r) = ψ(r₀) − (r − r₀)·w`, `w = [−1 … −1, 1 … 1]` (past outputs, past
//! commands) and `ỹ(r) = ỹ(r₀) − (r − r₀)`: every column moves by a multiple
//! of the ones column. With the ones column first, `R·M` for that column
//! operation changes only row 0 of `R` (the only row with a non-zero in
//! column 0), so moving any of the factors to another frame is `O(p)`. The
//! front aggregates stay in the frame of their rebuild, the back factor is
//! moved to each window's reference before it takes the new rows, and the
//! merged window factor is in the window's reference.
//!
//! **Scaling.** Columns are scaled by their 2-norms over the window of the
//! last rebuild (fixed until the next one).
//!
//! The kernels run over aligned groups of 4 elements (zeros left of the
//! diagonal stay zero) and on AVX2 when the CPU has it (same operations in
//! the same order, no FMA contraction: bit-identical to the portable path).
//!
//! Reference: Golub & Van Loan, *Matrix Computations*, 4th ed., §5.1–5.2
//! (Householder reflections), §6.5 (updating QR); the two-stack sliding
//! aggregate is the classic queue of two stacks with the QR "merge" as the
//! associative operation.

// Negated comparisons are deliberate (they reject NaN); index loops mirror the
// matrix formulas.
#![allow(
    clippy::neg_cmp_op_on_partial_ord,
    clippy::needless_range_loop,
    clippy::too_many_arguments
)]

use std::ops::Range;

use crate::ident::methods::regressor::{regressor, ArxOrders, MAX_ARX_ORDER};
use crate::solve::rows::{avx2, axpy, reflection, scaled, sub_scaled};

/// Rows per block Householder update (larger hops are added in several blocks).
const BLOCK: usize = 16;

/// Largest number of stored `p × ps` elements of the front aggregates
/// (2 MiB); with more windows per rebuild the rebuilds come more often.
const MAX_AGGREGATE_ELEMENTS: usize = 1 << 18;

/// Upper-triangular factor of the scaled rows `[1, ψ, y]` of a window.
#[derive(Debug, Clone)]
pub(super) struct SlidingFactor {
    /// Columns `p = n + 2`.
    pub(super) p: usize,
    /// Row stride `ps ≥ p`, a multiple of 4.
    pub(super) ps: usize,
    /// Number of `a` coefficients (the columns `1 ..= na` have `w = −1`).
    na: usize,
    /// The window's factor: row-major `p × ps` upper triangle, in the frame `r0`.
    pub(super) r: Vec<f64>,
    /// Column scale factors (fixed between rebuilds) and their inverses.
    pub(super) scale: Vec<f64>,
    inv_scale: Vec<f64>,
    /// Frame of the window's factor.
    pub(super) r0: f64,
    /// Rows of the window's factor (absolute sample indices).
    pub(super) rows: Range<usize>,
    /// Windows since the last rebuild.
    pub(super) age: usize,
    /// Whether `r` (and the stacks) hold the rows `rows`.
    pub(super) valid: bool,
    /// Front aggregates (`count × p × ps`): aggregate `j` holds the rows
    /// `[first + j·hop, split)` in the frame `r_front`.
    front: Vec<f64>,
    count: usize,
    first: usize,
    hop: usize,
    split: usize,
    r_front: f64,
    /// Back factor: the rows `[split, back_end)` in the frame `r_back`.
    back: Vec<f64>,
    back_end: usize,
    r_back: f64,
    /// Scratch: a block of rows, a copy of the back factor, one regressor.
    block: Vec<f64>,
    other: Vec<f64>,
    psi: Vec<f64>,
    /// Scratch of the reflections: the reflected row, one column.
    w: Vec<f64>,
    col: Vec<f64>,
    /// Largest number of front aggregates ([`MAX_AGGREGATE_ELEMENTS`] / `p·ps`).
    pub(super) max_aggregates: usize,
    /// Run the kernels compiled for AVX2.
    avx: bool,
}

impl SlidingFactor {
    pub(super) fn new(orders: &ArxOrders) -> Self {
        let n = orders.n_params();
        let p = n + 2;
        let ps = p.div_ceil(4) * 4;
        Self {
            p,
            ps,
            na: orders.na,
            r: vec![0.0; p * ps],
            scale: vec![1.0; p],
            inv_scale: vec![1.0; p],
            r0: 0.0,
            rows: 0..0,
            age: 0,
            valid: false,
            front: Vec::new(),
            count: 0,
            first: 0,
            hop: 0,
            split: 0,
            r_front: 0.0,
            back: vec![0.0; p * ps],
            back_end: 0,
            r_back: 0.0,
            block: vec![0.0; BLOCK * ps],
            other: vec![0.0; p * ps],
            psi: vec![0.0; n],
            w: vec![0.0; ps],
            col: vec![0.0; p.max(BLOCK)],
            max_aggregates: (MAX_AGGREGATE_ELEMENTS / (p * ps)).max(1),
            avx: avx2(),
        }
    }

    /// Element `(i, j)` of the window's `R` (scaled).
    #[inline]
    pub(super) fn at(&self, i: usize, j: usize) -> f64 {
        self.r[i * self.ps + j]
    }

    /// Column `j` of `R·S` (unscaled), element `i`.
    #[inline]
    pub(super) fn rs(&self, i: usize, j: usize) -> f64 {
        self.at(i, j) * self.scale[j]
    }

    /// Centred norm of unscaled data column `j ≥ 1` (frame-independent: the
    /// rows `1 …` of the factor).
    pub(super) fn centred_norm(&self, j: usize) -> f64 {
        (1..=j.min(self.p - 1))
            .map(|i| self.rs(i, j).powi(2))
            .sum::<f64>()
            .sqrt()
    }

    /// Squared norms of the columns of the window's `R` (scaled) into `c2`
    /// (length `ps`), accumulated row by row.
    pub(super) fn column_norms2(&self, c2: &mut [f64]) {
        let ps = self.ps;
        c2[..ps].fill(0.0);
        for row in self.r.chunks_exact(ps) {
            for (c, &v) in c2[..ps].iter_mut().zip(row) {
                *c += v * v;
            }
        }
    }

    /// Forget everything (the next window is factored from scratch).
    pub(super) fn invalidate(&mut self) {
        self.valid = false;
        self.rows = 0..0;
        self.count = 0;
    }

    /// Bring the window's factor to `rows` in the frame `reference`; returns
    /// whether the two stacks were used (false: rebuilt from scratch).
    ///
    /// `y`, `u`: the samples with `y[k − base]` = sample `k`, reaching back
    /// `lag` samples before `rows.start`. `refactor_every` bounds the
    /// windows between rebuilds; `sliding = false` rebuilds every window.
    pub(super) fn update(
        &mut self,
        orders: &ArxOrders,
        y: &[f64],
        u: &[f64],
        base: usize,
        rows: Range<usize>,
        reference: f64,
        sliding: bool,
        refactor_every: usize,
    ) -> bool {
        let old = self.rows.clone();
        let slides = self.valid
            && sliding
            && rows.len() == old.len()
            && rows.start > old.start
            && rows.start < old.end;
        if slides {
            let hop = rows.start - old.start;
            let j = (rows.start - self.first) / hop.max(1);
            let stacked = hop == self.hop
                && (rows.start - self.first).is_multiple_of(hop)
                && j < self.count
                && rows.end > self.back_end
                && self.age + 1 < refactor_every;
            if stacked {
                self.slide(orders, y, u, base, j, rows, reference);
                return true;
            }
            self.rebuild(orders, y, u, base, rows, reference, hop);
        } else {
            self.rebuild(orders, y, u, base, rows, reference, 0);
        }
        false
    }

    /// The stacks' step: new rows into the back factor, the window's factor
    /// = front aggregate `j` merged with the back factor.
    fn slide(
        &mut self,
        orders: &ArxOrders,
        y: &[f64],
        u: &[f64],
        base: usize,
        j: usize,
        rows: Range<usize>,
        reference: f64,
    ) {
        let (p, ps, na) = (self.p, self.ps, self.na);
        // back factor: to the window's frame, then the new rows
        reframe(
            &mut self.back,
            na,
            p,
            &self.scale,
            &self.inv_scale,
            reference - self.r_back,
        );
        self.r_back = reference;
        let new = self.back_end..rows.end;
        self.add_rows(orders, y, u, base, new, reference, Target::Back);
        self.back_end = rows.end;
        // window factor: front aggregate j (to the window's frame) ⊕ back
        let size = p * ps;
        self.r
            .copy_from_slice(&self.front[j * size..(j + 1) * size]);
        reframe(
            &mut self.r,
            na,
            p,
            &self.scale,
            &self.inv_scale,
            reference - self.r_front,
        );
        self.other.copy_from_slice(&self.back);
        let scratch = (&mut self.w[..], &mut self.col[..]);
        merge(p, ps, &mut self.r, &mut self.other, scratch, self.avx);
        self.r0 = reference;
        self.rows = rows;
        self.age += 1;
        self.valid = self.is_finite();
    }

    /// Factor the window from scratch, with the front aggregates for the
    /// next windows if the hop is known (`hop > 0`).
    fn rebuild(
        &mut self,
        orders: &ArxOrders,
        y: &[f64],
        u: &[f64],
        base: usize,
        rows: Range<usize>,
        reference: f64,
        hop: usize,
    ) {
        let (p, ps) = (self.p, self.ps);
        let n = p - 2;
        // column norms of the window in its frame: the scaling until the next rebuild
        let mut ss = [0.0f64; 2 * MAX_ARX_ORDER + 2];
        let ss = &mut ss[..p];
        for k in rows.clone() {
            let t = regressor(orders, y, u, k - base, reference, &mut self.psi);
            for j in 0..n {
                ss[j + 1] += self.psi[j] * self.psi[j];
            }
            ss[n + 1] += t * t;
        }
        ss[0] = rows.len() as f64;
        for ((s, is), v) in self
            .scale
            .iter_mut()
            .zip(self.inv_scale.iter_mut())
            .zip(ss.iter())
        {
            let d = v.sqrt();
            *s = if d > 0.0 && d.is_finite() { d } else { 1.0 };
            *is = 1.0 / *s;
        }
        // suffix aggregates [first + j·hop, end), from the last one backwards
        let size = p * ps;
        let count = if hop == 0 {
            1
        } else {
            rows.len().div_ceil(hop).min(self.max_aggregates)
        };
        if self.front.len() < count * size {
            self.front.resize(count * size, 0.0);
        }
        self.r.fill(0.0);
        let mut next = rows.end;
        for j in (0..count).rev() {
            let start = rows.start + j * hop;
            self.add_rows(orders, y, u, base, start..next, reference, Target::Window);
            self.front[j * size..(j + 1) * size].copy_from_slice(&self.r);
            next = start;
        }
        self.count = count;
        self.first = rows.start;
        self.hop = hop;
        self.split = rows.end;
        self.r_front = reference;
        self.back.fill(0.0);
        self.back_end = rows.end;
        self.r_back = reference;
        self.r0 = reference;
        self.rows = rows;
        self.age = 0;
        self.valid = self.is_finite();
    }

    /// Add the scaled rows `rows` in the frame `frame` to the window's or the
    /// back factor, in blocks of [`BLOCK`] rows.
    fn add_rows(
        &mut self,
        orders: &ArxOrders,
        y: &[f64],
        u: &[f64],
        base: usize,
        rows: Range<usize>,
        frame: f64,
        target: Target,
    ) {
        let (p, ps) = (self.p, self.ps);
        let n = p - 2;
        let mut k = rows.start;
        while k < rows.end {
            let h = (rows.end - k).min(BLOCK);
            for row in 0..h {
                let t = regressor(orders, y, u, k + row - base, frame, &mut self.psi);
                let x = &mut self.block[row * ps..(row + 1) * ps];
                x[0] = self.inv_scale[0];
                for ((xj, &v), &s) in x[1..=n].iter_mut().zip(&self.psi).zip(&self.inv_scale[1..]) {
                    *xj = v * s;
                }
                x[n + 1] = t * self.inv_scale[n + 1];
                x[p..].fill(0.0);
            }
            let r = match target {
                Target::Window => &mut self.r,
                Target::Back => &mut self.back,
            };
            let scratch = (&mut self.w[..], &mut self.col[..]);
            block_update(p, ps, r, &mut self.block[..h * ps], h, scratch, self.avx);
            k += h;
        }
    }

    /// Whether every element of the window's `R` is finite (four
    /// accumulators of `v·0`, NaN exactly when some `v` is not finite).
    fn is_finite(&self) -> bool {
        let mut acc = [0.0f64; 4];
        for c in self.r.chunks_exact(4) {
            for (a, v) in acc.iter_mut().zip(c) {
                *a += v * 0.0;
            }
        }
        (acc[0] + acc[1] + acc[2] + acc[3]) == 0.0
    }
}

/// Which factor [`SlidingFactor::add_rows`] updates.
#[derive(Debug, Clone, Copy)]
enum Target {
    Window,
    Back,
}

/// Move a factor by `d` to another frame: column `j` (unscaled) ← column
/// `j` − `d·w_j`·column 0, which changes only row 0 (see the module doc).
fn reframe(r: &mut [f64], na: usize, p: usize, scale: &[f64], inv_scale: &[f64], d: f64) {
    if d == 0.0 {
        return;
    }
    let base = d * r[0] * scale[0];
    for j in 1..p {
        let w = if j <= na { -1.0 } else { 1.0 };
        r[j] -= w * base * inv_scale[j];
    }
}

/// Add the `h` rows of `x` (row-major, stride `ps`, destroyed) to the
/// triangle `r` by one Householder reflection per column.
fn block_update(
    p: usize,
    ps: usize,
    r: &mut [f64],
    x: &mut [f64],
    h: usize,
    scratch: Scratch<'_>,
    avx: bool,
) {
    reflect(p, ps, r, x, h, false, scratch, avx);
}

/// Scratch of [`reflect_kernel`]: the reflected row (length `ps`), one column (length ≥ rows).
type Scratch<'a> = (&'a mut [f64], &'a mut [f64]);

/// Merge the triangle `o` (destroyed) into the triangle `r`: the factor of
/// the stacked `[r; o]`.
fn merge(p: usize, ps: usize, r: &mut [f64], o: &mut [f64], scratch: Scratch<'_>, avx: bool) {
    reflect(p, ps, r, o, p, true, scratch, avx);
}

/// [`reflect_kernel`] with the row length as a constant for the common
/// strides, on AVX2 when the CPU has it.
fn reflect(
    p: usize,
    ps: usize,
    r: &mut [f64],
    x: &mut [f64],
    h: usize,
    tri: bool,
    (w, col): Scratch<'_>,
    avx: bool,
) {
    #[cfg(target_arch = "x86_64")]
    if avx {
        // SAFETY: `avx` is set only when the CPU reports AVX2.
        unsafe {
            match ps {
                8 => reflect_avx2::<8>(p, ps, r, x, h, tri, w, col),
                12 => reflect_avx2::<12>(p, ps, r, x, h, tri, w, col),
                16 => reflect_avx2::<16>(p, ps, r, x, h, tri, w, col),
                20 => reflect_avx2::<20>(p, ps, r, x, h, tri, w, col),
                24 => reflect_avx2::<24>(p, ps, r, x, h, tri, w, col),
                _ => reflect_avx2::<0>(p, ps, r, x, h, tri, w, col),
            }
        }
        return;
    }
    let _ = avx;
    match ps {
        8 => reflect_kernel::<8>(p, ps, r, x, h, tri, w, col),
        12 => reflect_kernel::<12>(p, ps, r, x, h, tri, w, col),
        16 => reflect_kernel::<16>(p, ps, r, x, h, tri, w, col),
        20 => reflect_kernel::<20>(p, ps, r, x, h, tri, w, col),
        24 => reflect_kernel::<24>(p, ps, r, x, h, tri, w, col),
        _ => reflect_kernel::<0>(p, ps, r, x, h, tri, w, col),
    }
}

/// Column by column, the Householder reflection that maps `(r_ii, x_·i)`
/// to `(‖·‖, 0)` (keeping `r_ii > 0`), applied to the rows of `r` and `x`.
/// `x` has `h` rows (stride `ps`); with `triangular` its row `k` is zero
/// left of column `k`, so column `i` involves only its rows `0 ..= i`.
/// Every active row is zero left of column `i` and stays zero, so the rows
/// are processed whole (`W = ps`, a constant) or from the column's aligned
/// group of 4 on (`W = 0`).
#[inline(always)]
fn reflect_kernel<const W: usize>(
    p: usize,
    ps: usize,
    r: &mut [f64],
    x: &mut [f64],
    h: usize,
    triangular: bool,
    wdyn: &mut [f64],
    coldyn: &mut [f64],
) {
    // with a constant row length the scratch is local (the compiler sees it
    // alias nothing); `h ≤ W` for the stacks' blocks and merges
    if W > 0 && h <= W {
        reflect_body::<W>(p, ps, r, x, h, triangular, &mut [0.0; W], &mut [0.0; W]);
    } else {
        reflect_body::<W>(p, ps, r, x, h, triangular, wdyn, coldyn);
    }
}

#[inline(always)]
fn reflect_body<const W: usize>(
    p: usize,
    ps: usize,
    r: &mut [f64],
    x: &mut [f64],
    h: usize,
    triangular: bool,
    wbuf: &mut [f64],
    col: &mut [f64],
) {
    for i in 0..p {
        let rows = if triangular { (i + 1).min(h) } else { h };
        let mut sigma = 0.0;
        for k in 0..rows {
            let v = x[k * ps + i];
            col[k] = v;
            sigma += v * v;
        }
        if sigma == 0.0 {
            continue;
        }
        let (norm, v0, tau) = reflection(r[i * ps + i], sigma, &col[..rows]);
        let start = if W > 0 { 0 } else { i & !3 };
        let w = &mut wbuf[start..ps];
        let ri = &mut r[i * ps + start..(i + 1) * ps];
        scaled::<W>(w, v0, ri);
        for k in 0..rows {
            axpy::<W>(w, col[k], &x[k * ps + start..(k + 1) * ps]);
        }
        sub_scaled::<W>(ri, tau * v0, w);
        ri[i - start] = norm;
        for k in 0..rows {
            let xk = &mut x[k * ps + start..(k + 1) * ps];
            sub_scaled::<W>(xk, tau * col[k], w);
            xk[i - start] = 0.0;
        }
    }
}

/// [`reflect_kernel`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn reflect_avx2<const W: usize>(
    p: usize,
    ps: usize,
    r: &mut [f64],
    x: &mut [f64],
    h: usize,
    triangular: bool,
    w: &mut [f64],
    col: &mut [f64],
) {
    reflect_kernel::<W>(p, ps, r, x, h, triangular, w, col)
}
