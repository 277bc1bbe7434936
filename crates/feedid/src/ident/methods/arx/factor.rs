//! The sliding QR factor of an ARX window: the scaled rows `[1, ψ, y]` of
//! the window kept as an upper-triangular factor, updated by Givens
//! rotations for new rows and the LINPACK `dchdd` downdate for old ones.

// Negated comparisons are deliberate (they reject NaN); index loops mirror the
// matrix formulas.
#![allow(
    clippy::neg_cmp_op_on_partial_ord,
    clippy::needless_range_loop,
    clippy::too_many_arguments
)]

use std::ops::Range;

use crate::ident::methods::regressor::{regressor, ArxOrders, MAX_ARX_ORDER};

/// Smallest `α² = 1 − ‖a‖²` of a sliding downdate; below it the factor is
/// recomputed from scratch.
pub(super) const MIN_DOWNDATE_ALPHA2: f64 = 1e-4;

/// Upper-triangular factor of the scaled rows `[1, ψ, y]` of a window.
#[derive(Debug, Clone)]
pub(super) struct SlidingFactor {
    /// Columns `p = n + 2`.
    pub(super) p: usize,
    /// Row-major `p×p` upper triangle.
    pub(super) r: Vec<f64>,
    /// Column scale factors (fixed between refactorisations).
    pub(super) scale: Vec<f64>,
    /// Frame of the stored rows.
    pub(super) r0: f64,
    /// Rows currently in the factor (absolute sample indices).
    pub(super) rows: Range<usize>,
    /// Windows since the last refactorisation.
    pub(super) age: usize,
    pub(super) valid: bool,
    /// Scratch: one row, downdate vectors.
    pub(super) x: Vec<f64>,
    pub(super) a: Vec<f64>,
    pub(super) c: Vec<f64>,
    pub(super) psi: Vec<f64>,
}

impl SlidingFactor {
    pub(super) fn new(n: usize) -> Self {
        let p = n + 2;
        Self {
            p,
            r: vec![0.0; p * p],
            scale: vec![1.0; p],
            r0: 0.0,
            rows: 0..0,
            age: 0,
            valid: false,
            x: vec![0.0; p],
            a: vec![0.0; p],
            c: vec![0.0; p],
            psi: vec![0.0; n],
        }
    }

    /// Fill `self.x` with the scaled row of sample `k` in frame `r0`.
    pub(super) fn load_row(&mut self, orders: &ArxOrders, y: &[f64], u: &[f64], k: usize) {
        let n = self.p - 2;
        let t = regressor(orders, y, u, k, self.r0, &mut self.psi);
        self.x[0] = 1.0 / self.scale[0];
        for j in 0..n {
            self.x[j + 1] = self.psi[j] / self.scale[j + 1];
        }
        self.x[n + 1] = t / self.scale[n + 1];
    }

    /// Givens update `RᵀR ← RᵀR + xxᵀ`.
    pub(super) fn add_loaded(&mut self) {
        let p = self.p;
        for i in 0..p {
            let xi = self.x[i];
            if xi == 0.0 {
                continue;
            }
            let rii = self.r[i * p + i];
            let h = rii.hypot(xi);
            let (c, s) = (rii / h, xi / h);
            self.r[i * p + i] = h;
            self.x[i] = 0.0;
            for j in (i + 1)..p {
                let rij = self.r[i * p + j];
                let xj = self.x[j];
                self.r[i * p + j] = c * rij + s * xj;
                self.x[j] = -s * rij + c * xj;
            }
        }
    }

    /// LINPACK `dchdd` downdate `RᵀR ← RᵀR − xxᵀ`; false if it would lose definiteness.
    pub(super) fn remove_loaded(&mut self) -> bool {
        let p = self.p;
        // solve Rᵀ a = x
        for j in 0..p {
            let mut s = self.x[j];
            for i in 0..j {
                s -= self.r[i * p + j] * self.a[i];
            }
            let d = self.r[j * p + j];
            if d == 0.0 {
                return false;
            }
            self.a[j] = s / d;
        }
        let norm2: f64 = self.a.iter().map(|v| v * v).sum();
        // The downdate loses about log10(1/α²) digits (α² = 1 − ‖a‖², small
        // when the removed row carried most of the window's energy in some
        // direction): refactor instead when that would exceed 4 digits.
        if !(norm2 < 1.0 - MIN_DOWNDATE_ALPHA2) {
            return false;
        }
        let mut alpha = (1.0 - norm2).sqrt();
        for i in (0..p).rev() {
            let scale = alpha + self.a[i].abs();
            let aa = alpha / scale;
            let bb = self.a[i] / scale;
            let nrm = aa.hypot(bb);
            self.c[i] = aa / nrm;
            self.a[i] = bb / nrm; // now the sine
            alpha = scale * nrm;
        }
        for j in 0..p {
            let mut xx = 0.0;
            for i in (0..=j).rev() {
                let rij = self.r[i * p + j];
                let t = self.c[i] * xx + self.a[i] * rij;
                self.r[i * p + j] = self.c[i] * rij - self.a[i] * xx;
                xx = t;
            }
        }
        self.r.iter().all(|v| v.is_finite())
    }

    /// Factor the rows `rows` (absolute; `y[k − base]` is sample `k`) from
    /// scratch in the frame `r0`.
    pub(super) fn refactor(
        &mut self,
        orders: &ArxOrders,
        y: &[f64],
        u: &[f64],
        base: usize,
        rows: Range<usize>,
        r0: f64,
    ) {
        let p = self.p;
        let n = p - 2;
        self.r0 = r0;
        // column norms for the scaling
        let mut ss = [0.0f64; 2 * MAX_ARX_ORDER + 2];
        let ss = &mut ss[..p];
        for k in rows.clone() {
            let t = regressor(orders, y, u, k - base, r0, &mut self.psi);
            for j in 0..n {
                ss[j + 1] += self.psi[j] * self.psi[j];
            }
            ss[n + 1] += t * t;
        }
        ss[0] = rows.len() as f64;
        for (s, v) in self.scale.iter_mut().zip(ss.iter()) {
            let d = v.sqrt();
            *s = if d > 0.0 && d.is_finite() { d } else { 1.0 };
        }
        self.r.fill(0.0);
        for k in rows.clone() {
            self.load_row(orders, y, u, k - base);
            self.add_loaded();
        }
        self.rows = rows;
        self.age = 0;
        self.valid = true;
    }

    /// Slide to `rows`; false if a downdate failed (the factor is then invalid).
    pub(super) fn slide(
        &mut self,
        orders: &ArxOrders,
        y: &[f64],
        u: &[f64],
        base: usize,
        rows: Range<usize>,
    ) -> bool {
        let old = self.rows.clone();
        for k in old.end..rows.end {
            self.load_row(orders, y, u, k - base);
            self.add_loaded();
        }
        for k in old.start..rows.start {
            self.load_row(orders, y, u, k - base);
            if !self.remove_loaded() {
                self.valid = false;
                return false;
            }
        }
        self.rows = rows;
        self.age += 1;
        true
    }

    /// Column `j` of `R·S` (unscaled), element `i`.
    #[inline]
    pub(super) fn rs(&self, i: usize, j: usize) -> f64 {
        self.r[i * self.p + j] * self.scale[j]
    }

    /// Centred norm of unscaled data column `j` (frame-independent; column 0 is the ones column).
    pub(super) fn centred_norm(&self, j: usize) -> f64 {
        (1..=j.min(self.p - 1))
            .map(|i| self.rs(i, j).powi(2))
            .sum::<f64>()
            .sqrt()
    }
}
