//! Windowed ARX identification with an exact sliding least-squares update,
//! and a batch (global) ARX fit.
//!
//! # Model
//!
//! ```text
//! A(q)·ỹ[k] = B(q)·ũ[k] + e[k]
//! A = 1 + a1·q⁻¹ + … + a_na·q⁻ⁿᵃ,   B = q⁻ⁿᵏ·(b_nk + b_(nk+1)·q⁻¹ + … + b_(nk+nb−1)·q⁻⁽ⁿᵇ⁻¹⁾)
//! ```
//!
//! in **deviation coordinates** `ỹ = y − r`, `ũ = u − r` from a reference
//! position `r`: positions are far from zero (EMPS up to 0.25 m), the
//! dynamics live in micrometres. For a window `[s, e)` the reference is the
//! last measured position of the window, `r = y[e−1]`, for fitting and for
//! predicting, so the prediction starts from the last measurement. (The
//! model has no offset term; with a unit DC gain, as for a position servo,
//! the result is independent of `r`; [`ArxConfig::offset`] adds an offset
//! term `c` for other systems.) The batch fit [`fit_arx`] uses
//! `r = y[0]`, the same convention as [`LinearModel::simulate`] (start at
//! rest at the first sample).
//!
//! Regression row `k` (one per sample of the window):
//! `ψ_k = [−ỹ[k−1] … −ỹ[k−na], ũ[k−nk] … ũ[k−nk−nb+1]]`, target `ỹ[k]`,
//! coefficients `θ = [a1 … a_na, b_nk … b_(nk+nb−1)]` (coefficient names
//! `"a1"…`, `"b<lag>"`). `nk = 0` is allowed: the command is the set-point,
//! known ahead of the prediction horizon.
//!
//! # Least squares
//!
//! `θ = argmin ‖Ψθ − ỹ‖² + ρ·Σ d_j²·θ_j²` with `d_j` the 2-norm of column `j`
//! of `Ψ` (a *relative* ridge `ρ`, [`ArxConfig::ridge`]). No normal
//! equations: the rows `[1, ψ_k, y_k]` (in a frame `r₀`, columns scaled by
//! fixed factors) are kept as an upper-triangular QR factor `R` of the
//! window; the deviation problem of the window is `R·S·M` with the exact
//! affine change of frame `M` (`ψ ↦ ψ − (r − r₀)·w`), a `(n+2)×(n+1)` matrix,
//! solved by [`lstsq_in_place`] (Householder QR on unit-norm columns with
//! the ridge).
//!
//! **Exact sliding update.** When the window is the previous one shifted by
//! `h < W` samples, the `h` new rows are added to `R` by Givens rotations
//! and the `h` oldest rows removed by the LINPACK `dchdd` downdate (an
//! orthogonal-hyperbolic scheme: solve `Rᵀa = x`, `α = √(1 − ‖a‖²)`, then
//! Givens rotations built from `a` and `α`), `O(n²)` per row. The factor is
//! recomputed from scratch every [`ArxConfig::refactor_every`] windows (to
//! bound drift), when a downdate fails or would lose more than 4 digits
//! (`α² < 1e-4`: the window (nearly) lost rank),
//! and when the reference moved far from the frame `r₀` (`|r − r₀|·√W` more
//! than the norm of the deviation output column), so the frame shift cancels
//! no digit (a bound of 16 let coefficients drift by up to 1e-6 relative on
//! slowly excited windows). The result equals a fresh
//! fit to rounding (tested to 1e-9).
//!
//! # Per-window checks and fallback
//!
//! A window is **not informative** when the command is standing still in it
//! (standard deviation of `u[k−nk]` over the rows below
//! [`ArxConfig::min_excitation`]), or the scaled regression is numerically
//! rank deficient (condition estimate above [`ArxConfig::max_condition`], or
//! numerical rank below the parameter count without ridge).
//! An identified model is **rejected** when a coefficient is not finite, a
//! pole lies outside the radius [`ArxConfig::max_pole_radius`] (Schur–Cohn
//! step-down test on `A`, allocation-free), or the DC gain `B(1)/A(1)` is
//! outside [`ArxConfig::dc_gain_bounds`]. In both cases the last good model
//! is kept and the window reports [`Termination::Fallback`]; without any
//! good model yet the fit is an error ([`Error::Singular`]) and the engine
//! records the window as failed.
//!
//! # Prediction (k-step ahead)
//!
//! For the horizon `[e, e+H)`: the past outputs are the measured `ỹ[k]`
//! for `k < e`, the command is known over the horizon, and the model runs
//! forward feeding back its own predictions:
//! `ŷ[t] = r − Σ a_i·ỹ*[t−i] + Σ b_j·ũ[t−j]`, `ỹ*` measured before `e`,
//! predicted after.
//!
//! References: L. Ljung, *System Identification*, 2nd ed., §4.2, §7.3, §10.1;
//! Golub & Van Loan, *Matrix Computations*, 4th ed., §6.5 (updating QR);
//! J.J. Dongarra et al., *LINPACK Users' Guide* (1979), `dchud`/`dchdd`;
//! E.I. Jury, *Theory and Application of the z-Transform Method* (Schur–Cohn).
//!
//! ```
//! use feedid::ident::{engine, ArxConfig, ArxOrders, EngineConfig, Signals};
//! // y[k] = 0.6·y[k−1] + 0.4·u[k−1] driven by a sine command
//! let n = 400;
//! let dt = 1e-3;
//! let u: Vec<f64> = (0..n).map(|k| 1e-3 * (0.05 * k as f64).sin()).collect();
//! let mut y = vec![0.0; n];
//! for k in 1..n {
//!     y[k] = 0.6 * y[k - 1] + 0.4 * u[k - 1];
//! }
//! let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
//! let mut arx = ArxConfig { orders: ArxOrders::new(1, 1, 1), ridge: 0.0, ..ArxConfig::default() }
//!     .build()
//!     .unwrap();
//! let cfg = EngineConfig { window: 50, horizon: 10, hop: Some(1), warm_up: 0 };
//! let res = engine::run(&mut arx, &Signals::new(&t, &u, &y, dt, 0.0), &cfg).unwrap();
//! assert!(res.stats.rms < 1e-12);
//! ```

// Negated comparisons are deliberate (they reject NaN); index loops mirror the
// matrix formulas.
#![allow(
    clippy::neg_cmp_op_on_partial_ord,
    clippy::needless_range_loop,
    clippy::too_many_arguments
)]

use std::ops::Range;

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::ident::{Estimator, LinearModel, Signals, WindowFit};
use crate::solve::{lstsq_in_place, LstsqOptions, QrWorkspace, Termination};

/// Largest accepted `na` and `nb` (guards against absurd allocations).
pub const MAX_ARX_ORDER: usize = 64;

/// Smallest `α² = 1 − ‖a‖²` of a sliding downdate; below it the factor is
/// recomputed from scratch.
const MIN_DOWNDATE_ALPHA2: f64 = 1e-4;

/// ARX structure: `na` poles, `nb` input coefficients, input delay `nk` \[samples\].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct ArxOrders {
    /// Number of `a` coefficients (order of `A`); ≥ 0.
    pub na: usize,
    /// Number of `b` coefficients; ≥ 1.
    pub nb: usize,
    /// Input delay \[samples\]; 0 is allowed (the command is known ahead).
    pub nk: usize,
}

impl Default for ArxOrders {
    /// `na = 8, nb = 8, nk = 1` (chosen on the virtual rig, see [`ArxConfig`]).
    fn default() -> Self {
        Self {
            na: 8,
            nb: 8,
            nk: 1,
        }
    }
}

impl ArxOrders {
    /// Orders `(na, nb, nk)`.
    pub const fn new(na: usize, nb: usize, nk: usize) -> Self {
        Self { na, nb, nk }
    }

    /// Number of parameters `na + nb`.
    pub fn n_params(&self) -> usize {
        self.na + self.nb
    }

    /// Samples needed before the first regression row: `max(na, nk + nb − 1)`.
    pub fn lag(&self) -> usize {
        self.na.max(self.nk + self.nb.saturating_sub(1))
    }

    /// Coefficient names `a1 … a_na, b_nk … b_(nk+nb−1)`.
    pub fn coefficient_names(&self) -> Vec<String> {
        (1..=self.na)
            .map(|i| format!("a{i}"))
            .chain((0..self.nb).map(|j| format!("b{}", self.nk + j)))
            .collect()
    }

    /// Check the orders (`nb ≥ 1`, `na, nb ≤` [`MAX_ARX_ORDER`], `nk ≤ 1000`).
    pub fn validate(&self) -> Result<()> {
        if self.nb == 0 {
            return Err(Error::InvalidParameter {
                name: "nb",
                value: 0.0,
                reason: "must be at least 1",
            });
        }
        for (name, v, max) in [
            ("na", self.na, MAX_ARX_ORDER),
            ("nb", self.nb, MAX_ARX_ORDER),
            ("nk", self.nk, 1000),
        ] {
            if v > max {
                return Err(Error::InvalidParameter {
                    name,
                    value: v as f64,
                    reason: "order too large",
                });
            }
        }
        Ok(())
    }

    /// The discrete model `B(q)/A(q)` of coefficients `theta` (layout as the names).
    pub fn model(&self, theta: &[f64], dt: f64) -> Result<LinearModel> {
        if theta.len() != self.n_params() {
            return Err(Error::LengthMismatch {
                what: "ARX coefficients",
                expected: self.n_params(),
                actual: theta.len(),
            });
        }
        let mut a = Vec::with_capacity(self.na + 1);
        a.push(1.0);
        a.extend_from_slice(&theta[..self.na]);
        let mut b = vec![0.0; self.nk + self.nb];
        b[self.nk..].copy_from_slice(&theta[self.na..]);
        LinearModel::discrete(b, a, dt)
    }
}

/// Configuration of the windowed ARX estimator (defaults tuned on the virtual rig).
///
/// With these defaults and engine windows of W = 200 samples (40 ms at
/// 5 kHz), H = 10, hop = H, the 2 ms-ahead rms error on the virtual rig is
/// 0.23 … 0.48 µm on the ramp, S-curve, chirp, PRBS and multisine, and about
/// 4 µm on the saturating paper step (`tests/arx_rls_targets.rs`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArxConfig {
    /// Model orders; default `na = 8, nb = 8, nk = 1`.
    pub orders: ArxOrders,
    /// Relative ridge `ρ` on the column-normalised coefficients; default 1e-8.
    pub ridge: f64,
    /// Poles must lie strictly inside this radius; default 1.0 (stable).
    /// `f64::INFINITY` disables the stability check.
    pub max_pole_radius: f64,
    /// Accepted DC gain `B(1)/A(1)` interval; default `(0.5, 2.0)` (a position
    /// servo has gain 1). `(−∞, ∞)` disables the check.
    pub dc_gain_bounds: (f64, f64),
    /// Minimum standard deviation of the command over the window's rows \[m\];
    /// below it the window is a standstill and the last model is kept. Default 1e-7 (0.1 µm).
    pub min_excitation: f64,
    /// Largest condition estimate of the column-scaled regression; above it
    /// the window counts as rank deficient. Default ∞: with the ridge the
    /// solution stays defined on collinear data (on a constant-speed ramp
    /// the command columns span only `{1, k}`, condition ~1e15) and such
    /// windows predict well on the rig. Without ridge, a numerically rank
    /// deficient regression always counts as not informative.
    pub max_condition: f64,
    /// Recompute the sliding factor from scratch after this many windows; default 64.
    pub refactor_every: usize,
    /// Use the exact sliding update when windows overlap (default true);
    /// `false` refits every window from scratch (same result, slower).
    pub sliding: bool,
    /// Estimate an offset `c` as well, `A·ỹ = B·ũ + c` (coefficient name `"c"`);
    /// default false (a position servo has unit DC gain and needs none). Use
    /// it for systems whose DC gain is not 1.
    pub offset: bool,
}

impl Default for ArxConfig {
    fn default() -> Self {
        Self {
            orders: ArxOrders::default(),
            ridge: 1e-8,
            max_pole_radius: 1.0,
            dc_gain_bounds: (0.5, 2.0),
            min_excitation: 1e-7,
            max_condition: f64::INFINITY,
            refactor_every: 64,
            sliding: true,
            offset: false,
        }
    }
}

impl ArxConfig {
    /// Validate and build the estimator.
    pub fn build(self) -> Result<ArxEstimator> {
        self.validate()?;
        Ok(ArxEstimator::new(self))
    }

    /// Check every setting.
    pub fn validate(&self) -> Result<()> {
        self.orders.validate()?;
        for (name, v) in [
            ("ridge", self.ridge),
            ("min_excitation", self.min_excitation),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::InvalidParameter {
                    name,
                    value: v,
                    reason: "must be finite and >= 0",
                });
            }
        }
        if !(self.max_pole_radius > 0.0) {
            return Err(Error::InvalidParameter {
                name: "max_pole_radius",
                value: self.max_pole_radius,
                reason: "must be > 0",
            });
        }
        if !(self.max_condition > 1.0) {
            return Err(Error::InvalidParameter {
                name: "max_condition",
                value: self.max_condition,
                reason: "must be > 1",
            });
        }
        let (lo, hi) = self.dc_gain_bounds;
        if lo.is_nan() || hi.is_nan() || lo >= hi {
            return Err(Error::InvalidParameter {
                name: "dc_gain_bounds",
                value: lo,
                reason: "need lower < upper",
            });
        }
        if self.refactor_every == 0 {
            return Err(Error::InvalidParameter {
                name: "refactor_every",
                value: 0.0,
                reason: "must be at least 1",
            });
        }
        Ok(())
    }
}

// ------------------------------------------------------------------ helpers

/// Regression row `k` in the frame `r`: writes `ψ_k` into `psi` and returns `ỹ[k]`.
/// `y`, `u` are indexed so that element `k` is sample `k`.
#[inline]
pub(crate) fn regressor(
    orders: &ArxOrders,
    y: &[f64],
    u: &[f64],
    k: usize,
    r: f64,
    psi: &mut [f64],
) -> f64 {
    let na = orders.na;
    for i in 1..=na {
        psi[i - 1] = -(y[k - i] - r);
    }
    for j in 0..orders.nb {
        psi[na + j] = u[k - orders.nk - j] - r;
    }
    y[k] - r
}

/// k-step-ahead prediction of `out.len()` samples starting at sample `e`.
///
/// `y`, `u` indexed by sample (`y` is read only below `e`, `u` up to
/// `e + out.len()`), `r` the reference, `past` a scratch of length `≥ na + out.len()`.
pub(crate) fn predict_k_step(
    orders: &ArxOrders,
    theta: &[f64],
    y: &[f64],
    u: &[f64],
    e: usize,
    r: f64,
    offset: f64,
    past: &mut [f64],
    out: &mut [f64],
) {
    let na = orders.na;
    // past[0..na] = ỹ[e−na .. e), then predictions appended
    for i in 0..na {
        past[i] = y[e - na + i] - r;
    }
    for (h, o) in out.iter_mut().enumerate() {
        let t = e + h;
        let mut v = offset;
        for i in 1..=na {
            v -= theta[i - 1] * past[na + h - i];
        }
        for j in 0..orders.nb {
            v += theta[na + j] * (u[t - orders.nk - j] - r);
        }
        past[na + h] = v;
        *o = v + r;
    }
}

/// Whether every root of `z^n + a1·z^(n−1) + … + a_n` lies strictly inside
/// the radius `radius` (Schur–Cohn step-down recursion on the reflection
/// coefficients; `scratch.len() ≥ a.len()`). Allocation-free.
pub(crate) fn poles_inside(a: &[f64], radius: f64, scratch: &mut [f64]) -> bool {
    let n = a.len();
    if n == 0 {
        return true;
    }
    if !radius.is_finite() {
        return a.iter().all(|v| v.is_finite());
    }
    // p[i] = coefficient of z^(n−i), p[0] = 1, scaled for the radius
    let p = &mut scratch[..n + 1];
    p[0] = 1.0;
    let mut s = 1.0;
    for i in 1..=n {
        s /= radius;
        p[i] = a[i - 1] * s;
        if !p[i].is_finite() {
            return false;
        }
    }
    for m in (1..=n).rev() {
        let k = p[m];
        if !(k.abs() < 1.0) {
            return false;
        }
        let d = 1.0 - k * k;
        // p_(m−1)[i] = (p[i] − k·p[m−i]) / (1 − k²), i = 0..m−1
        for i in 0..=(m / 2) {
            let j = m - i;
            let (pi, pj) = (p[i], p[j]);
            p[i] = (pi - k * pj) / d;
            if j != i && j < m {
                p[j] = (pj - k * pi) / d;
            }
        }
    }
    true
}

/// DC gain `B(1)/A(1)` of ARX coefficients.
pub(crate) fn dc_gain(orders: &ArxOrders, theta: &[f64]) -> f64 {
    let sa: f64 = 1.0 + theta[..orders.na].iter().sum::<f64>();
    let sb: f64 = theta[orders.na..orders.na + orders.nb].iter().sum();
    sb / sa
}

/// Check the signals cover `r` (absolute indices) with `lag` samples before it.
pub(crate) fn check_window(signals: &Signals<'_>, r: &Range<usize>, lag: usize) -> Result<()> {
    let n = signals.time.len();
    if signals.command.len() != n || signals.position.len() != n {
        return Err(Error::LengthMismatch {
            what: "signals",
            expected: n,
            actual: signals.command.len().min(signals.position.len()),
        });
    }
    if r.start > r.end || r.end > signals.end() || r.start < signals.offset + lag {
        return Err(Error::TooFewSamples {
            what: "ARX window (past samples + window)",
            needed: r.end.max(signals.offset + lag + r.len()),
            actual: signals.end(),
        });
    }
    Ok(())
}

// ------------------------------------------------------ sliding QR factor

/// Upper-triangular factor of the scaled rows `[1, ψ, y]` of a window.
#[derive(Debug, Clone)]
struct SlidingFactor {
    /// Columns `p = n + 2`.
    p: usize,
    /// Row-major `p×p` upper triangle.
    r: Vec<f64>,
    /// Column scale factors (fixed between refactorisations).
    scale: Vec<f64>,
    /// Frame of the stored rows.
    r0: f64,
    /// Rows currently in the factor (absolute sample indices).
    rows: Range<usize>,
    /// Windows since the last refactorisation.
    age: usize,
    valid: bool,
    /// Scratch: one row, downdate vectors.
    x: Vec<f64>,
    a: Vec<f64>,
    c: Vec<f64>,
    psi: Vec<f64>,
}

impl SlidingFactor {
    fn new(n: usize) -> Self {
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
    fn load_row(&mut self, orders: &ArxOrders, y: &[f64], u: &[f64], k: usize) {
        let n = self.p - 2;
        let t = regressor(orders, y, u, k, self.r0, &mut self.psi);
        self.x[0] = 1.0 / self.scale[0];
        for j in 0..n {
            self.x[j + 1] = self.psi[j] / self.scale[j + 1];
        }
        self.x[n + 1] = t / self.scale[n + 1];
    }

    /// Givens update `RᵀR ← RᵀR + xxᵀ`.
    fn add_loaded(&mut self) {
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
    fn remove_loaded(&mut self) -> bool {
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
    fn refactor(
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
    fn slide(
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
    fn rs(&self, i: usize, j: usize) -> f64 {
        self.r[i * self.p + j] * self.scale[j]
    }

    /// Centred norm of unscaled data column `j` (frame-independent; column 0 is the ones column).
    fn centred_norm(&self, j: usize) -> f64 {
        (1..=j.min(self.p - 1))
            .map(|i| self.rs(i, j).powi(2))
            .sum::<f64>()
            .sqrt()
    }
}

// -------------------------------------------------------------- estimator

/// Diagnostics of the last ARX window.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ArxDiagnostics {
    /// Whether the window's model was accepted (false: fallback or failure).
    pub accepted: bool,
    /// Why the model was not accepted (`""` when accepted).
    pub reason: &'static str,
    /// Condition estimate of the column-scaled regression.
    pub condition: f64,
    /// Standard deviation of the command over the rows \[m\].
    pub excitation: f64,
    /// DC gain of the window's model.
    pub dc_gain: f64,
    /// Whether the window used the sliding update (false: factored from scratch).
    pub slid: bool,
}

/// Windowed ARX estimator (method name `"arx"`); see the module doc.
#[derive(Debug, Clone)]
pub struct ArxEstimator {
    config: ArxConfig,
    factor: SlidingFactor,
    ws: QrWorkspace,
    small_a: Vec<f64>,
    small_b: Vec<f64>,
    z: Vec<f64>,
    theta: Vec<f64>,
    has_model: bool,
    scratch: Vec<f64>,
    past: Vec<f64>,
    diagnostics: Option<ArxDiagnostics>,
}

impl ArxEstimator {
    fn new(config: ArxConfig) -> Self {
        let n = config.orders.n_params();
        let p = n + 2;
        Self {
            config,
            factor: SlidingFactor::new(n),
            ws: QrWorkspace::new(n + 1),
            small_a: vec![0.0; p * (n + 1)],
            small_b: vec![0.0; p],
            z: vec![0.0; n + 1],
            theta: vec![0.0; n + 1],
            has_model: false,
            scratch: vec![0.0; config.orders.na + 1],
            past: Vec::new(),
            diagnostics: None,
        }
    }

    /// The configuration.
    pub fn config(&self) -> &ArxConfig {
        &self.config
    }

    /// The current (last good) coefficients `[a…, b…]`, if any.
    pub fn theta(&self) -> Option<&[f64]> {
        let n = self.config.orders.n_params();
        self.has_model.then_some(&self.theta[..n])
    }

    /// The current offset `c` in the window's deviation frame (0 without [`ArxConfig::offset`]).
    pub fn offset(&self) -> f64 {
        self.theta[self.config.orders.n_params()]
    }

    /// The current model as a [`LinearModel`] at sample time `dt` \[s\].
    pub fn model(&self, dt: f64) -> Option<Result<LinearModel>> {
        self.theta().map(|t| self.config.orders.model(t, dt))
    }

    /// Diagnostics of the last window.
    pub fn diagnostics(&self) -> Option<&ArxDiagnostics> {
        self.diagnostics.as_ref()
    }

    /// Bring the factor to `rows`; returns whether the sliding update was used.
    fn update_factor(
        &mut self,
        y: &[f64],
        u: &[f64],
        base: usize,
        rows: Range<usize>,
        reference: f64,
    ) -> bool {
        let orders = self.config.orders;
        let f = &mut self.factor;
        let old = f.rows.clone();
        let can_slide = self.config.sliding
            && f.valid
            && rows.start > old.start
            && rows.start < old.end
            && rows.end - rows.start == old.end - old.start
            && f.age + 1 < self.config.refactor_every;
        if can_slide && f.slide(&orders, y, u, base, rows.clone()) {
            // frame check: the shift to the reference must not exceed the data
            // (every digit it cancels is lost in the coefficients)
            let n = f.p - 2;
            let d = (reference - f.r0).abs() * (rows.len() as f64).sqrt();
            let out_norm = (0..f.p)
                .map(|i| (f.rs(i, n + 1) - (reference - f.r0) * f.rs(i, 0)).powi(2))
                .sum::<f64>()
                .sqrt();
            if d <= 1.0 * out_norm {
                return true;
            }
        }
        f.refactor(&orders, y, u, base, rows, reference);
        false
    }
}

impl Estimator for ArxEstimator {
    fn name(&self) -> &'static str {
        "arx"
    }

    fn coefficient_names(&self) -> Vec<String> {
        let mut names = self.config.orders.coefficient_names();
        if self.config.offset {
            names.push("c".to_string());
        }
        names
    }

    fn warm_up(&self) -> usize {
        self.config.orders.lag()
    }

    fn reset(&mut self) {
        self.factor.valid = false;
        self.factor.rows = 0..0;
        self.has_model = false;
        self.diagnostics = None;
    }

    fn fit(
        &mut self,
        signals: &Signals<'_>,
        window: Range<usize>,
        coef: &mut [f64],
    ) -> Result<WindowFit> {
        let orders = self.config.orders;
        let n = orders.n_params();
        let lag = orders.lag();
        check_window(signals, &window, lag)?;
        if window.is_empty() {
            return Err(Error::TooFewSamples {
                what: "ARX window",
                needed: 1,
                actual: 0,
            });
        }
        // slices indexed by (absolute index − base); the base reaches back to
        // the oldest row still in the sliding factor (to remove it)
        let mut base = window.start - lag;
        if self.factor.valid {
            let old = self.factor.rows.start;
            if old < window.start && old >= signals.offset + lag {
                base = base.min(old - lag);
            } else if old < window.start {
                self.factor.valid = false;
            }
        }
        let y = signals.position(base..window.end);
        let u = signals.command(base..window.end);
        if let Some(i) = y.iter().chain(u).position(|v| !v.is_finite()) {
            let ch = if i < y.len() { "position" } else { "command" };
            return Err(Error::NonFinite {
                channel: ch.to_string(),
                index: base + i % y.len(),
                value: f64::NAN,
            });
        }
        let reference = y[window.end - 1 - base];
        let slid = self.update_factor(y, u, base, window.clone(), reference);

        let f = &self.factor;
        let p = f.p;
        let m = window.len() as f64;
        let excitation = f.centred_norm(1 + orders.na) / m.sqrt();
        let mut diag = ArxDiagnostics {
            accepted: false,
            reason: "",
            condition: f64::INFINITY,
            excitation,
            dc_gain: f64::NAN,
            slid,
        };

        // small problem R·S·M: columns ψ_j − (r − r0)·w_j·1, target likewise
        let d = reference - f.r0;
        let mut residual_rms = 0.0;
        let mut reason = "";
        if !(excitation >= self.config.min_excitation) || excitation == 0.0 {
            reason = "standstill (command not exciting)";
        } else {
            // regressor columns 0..n (ψ), n (ones, with an offset), then the target
            let nr = n + usize::from(self.config.offset);
            for j in 0..=n {
                let w = if j < orders.na { -1.0 } else { 1.0 };
                for i in 0..p {
                    let v = f.rs(i, j + 1) - d * w * f.rs(i, 0);
                    if j < n {
                        self.small_a[i + j * p] = v;
                    } else {
                        self.small_b[i] = v;
                    }
                }
            }
            if self.config.offset {
                for i in 0..p {
                    self.small_a[i + n * p] = f.rs(i, 0);
                }
            }
            let mut colscale = [1.0f64; 2 * MAX_ARX_ORDER + 1];
            for j in 0..nr {
                let col = &mut self.small_a[j * p..(j + 1) * p];
                let nrm = col.iter().map(|v| v * v).sum::<f64>().sqrt();
                if nrm > 0.0 {
                    colscale[j] = nrm;
                    for v in col.iter_mut() {
                        *v /= nrm;
                    }
                }
            }
            let opts = LstsqOptions {
                ridge: self.config.ridge,
                rank_tolerance: None,
            };
            match lstsq_in_place(
                p,
                nr,
                &mut self.small_a[..p * nr],
                &mut self.small_b,
                &mut self.z[..nr],
                &mut self.ws,
                &opts,
            ) {
                Err(_) => reason = "rank deficient",
                Ok(info) => {
                    diag.condition = info.cond_estimate;
                    residual_rms = info.residual_norm / m.sqrt();
                    for j in 0..nr {
                        self.z[j] /= colscale[j];
                    }
                    if !self.config.offset {
                        self.z[n] = 0.0;
                    }
                    let th = &self.z[..=n];
                    let g = dc_gain(&orders, th);
                    diag.dc_gain = g;
                    let (lo, hi) = self.config.dc_gain_bounds;
                    let deficient = (self.config.ridge == 0.0 && info.rank < nr)
                        || !(info.cond_estimate <= self.config.max_condition);
                    if deficient {
                        reason = "rank deficient";
                    } else if !th.iter().all(|v| v.is_finite()) {
                        reason = "non-finite coefficients";
                    } else if !poles_inside(
                        &th[..orders.na],
                        self.config.max_pole_radius,
                        &mut self.scratch,
                    ) {
                        reason = "unstable poles";
                    } else if !(g >= lo && g <= hi) {
                        reason = "implausible DC gain";
                    } else {
                        self.theta.copy_from_slice(th);
                        self.has_model = true;
                        diag.accepted = true;
                    }
                }
            }
        }
        diag.reason = reason;
        self.diagnostics = Some(diag);
        if !self.has_model {
            coef.fill(0.0);
            return Err(Error::Singular {
                context: "arx window (not informative and no earlier model)",
            });
        }
        let nc = coef.len().min(n + usize::from(self.config.offset));
        coef[..nc].copy_from_slice(&self.theta[..nc]);
        Ok(WindowFit {
            residual_rms: if residual_rms.is_finite() {
                residual_rms
            } else {
                0.0
            },
            iterations: 0,
            termination: if diag.accepted {
                Termination::Exact
            } else {
                Termination::Fallback
            },
        })
    }

    fn predict(
        &mut self,
        signals: &Signals<'_>,
        window: Range<usize>,
        horizon: Range<usize>,
        out: &mut [f64],
    ) -> Result<()> {
        let orders = self.config.orders;
        if !self.has_model {
            return Err(Error::Singular {
                context: "arx prediction (no model)",
            });
        }
        let offset = self.theta[orders.n_params()];
        predict_horizon(
            &orders,
            &self.theta,
            offset,
            signals,
            window,
            horizon,
            &mut self.past,
            out,
            "ARX",
        )
    }
}

/// k-step-ahead prediction of an ARX model over `horizon` (which starts at
/// `window.end`): the past from the measurements, the future command known,
/// predicted outputs fed back. Shared by [`ArxEstimator`] and the RLS estimator.
#[allow(clippy::too_many_arguments)]
pub(crate) fn predict_horizon(
    orders: &ArxOrders,
    theta: &[f64],
    offset: f64,
    signals: &Signals<'_>,
    window: Range<usize>,
    horizon: Range<usize>,
    past: &mut Vec<f64>,
    out: &mut [f64],
    what: &'static str,
) -> Result<()> {
    if horizon.start != window.end || out.len() != horizon.len() || window.is_empty() {
        return Err(Error::LengthMismatch {
            what: "ARX/RLS horizon",
            expected: horizon.len(),
            actual: out.len(),
        });
    }
    let lag = orders.lag().max(1);
    check_window(signals, &(window.end..horizon.end), lag)?;
    let base = window.end - lag;
    let y = signals.position(base..window.end);
    let u = signals.command(base..horizon.end);
    let need = orders.na + out.len();
    if past.len() < need {
        past.resize(need, 0.0);
    }
    let e = window.end - base;
    let reference = y[e - 1];
    predict_k_step(orders, theta, y, u, e, reference, offset, past, out);
    match out.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => Err(Error::NonFinite {
            channel: format!("{what} prediction"),
            index: horizon.start + i,
            value: out[i],
        }),
    }
}

// ---------------------------------------------------------------- batch fit

/// Result of a batch ARX fit ([`fit_arx`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ArxFit {
    /// Orders.
    pub orders: ArxOrders,
    /// The identified model `B(q)/A(q)` with sample time `dt`.
    pub model: LinearModel,
    /// Coefficients `[a1 … a_na, b_nk …]` (and the offset `c` last with [`ArxConfig::offset`]).
    pub theta: Vec<f64>,
    /// Standard errors of `theta` from `σ²·(ΨᵀΨ)⁻¹`, `σ² = Σe²/(N − np)`.
    pub std_errors: Vec<f64>,
    /// Loss `V = Σe²/N` (one-step prediction errors, \[m²\]).
    pub loss: f64,
    /// Number of regression rows `N`.
    pub n: usize,
    /// Number of parameters `np`.
    pub np: usize,
    /// One-step prediction residuals `e[k]` of the rows (`k = first_row …`).
    pub residuals: Vec<f64>,
    /// First sample index of the rows.
    pub first_row: usize,
    /// Reference `r` of the deviation coordinates (`y[first]`).
    pub reference: f64,
}

impl ArxFit {
    /// RMS of the residuals \[m\].
    pub fn residual_rms(&self) -> f64 {
        self.loss.sqrt()
    }
}

/// Batch ARX fit over a whole recording (rows `k = lag … len−1`).
///
/// Deviation coordinates from `r = y[0]` (exact for data starting at rest or
/// a unit-DC-gain system; set `cfg.offset` otherwise); least squares by QR on
/// scaled columns with the relative ridge and the offset option of `cfg`
/// (`cfg.orders` is ignored, the `orders` argument is used). The standard
/// errors ignore the (tiny) ridge.
///
/// ```
/// use feedid::ident::{fit_arx, ArxConfig, ArxOrders};
/// let n = 300;
/// let u: Vec<f64> = (0..n).map(|k| ((k * 7919) % 101) as f64 / 101.0 - 0.5).collect();
/// let mut y = vec![0.0; n];
/// for k in 2..n {
///     y[k] = 1.2 * y[k - 1] - 0.5 * y[k - 2] + 0.3 * u[k - 1];
/// }
/// let fit = fit_arx(&u, &y, 1e-3, ArxOrders::new(2, 1, 1), &ArxConfig { ridge: 0.0, ..Default::default() }).unwrap();
/// assert!((fit.theta[0] + 1.2).abs() < 1e-10 && (fit.theta[2] - 0.3).abs() < 1e-10);
/// ```
pub fn fit_arx(
    u: &[f64],
    y: &[f64],
    dt: f64,
    orders: ArxOrders,
    cfg: &ArxConfig,
) -> Result<ArxFit> {
    fit_arx_rows(u, y, dt, orders, cfg, orders.lag(), y.len(), true)
}

/// Batch ARX fit over the rows `first_row .. end` (`first_row ≥ lag`).
pub(crate) fn fit_arx_rows(
    u: &[f64],
    y: &[f64],
    dt: f64,
    orders: ArxOrders,
    cfg: &ArxConfig,
    first_row: usize,
    end: usize,
    with_std_errors: bool,
) -> Result<ArxFit> {
    orders.validate()?;
    if u.len() != y.len() {
        return Err(Error::LengthMismatch {
            what: "command",
            expected: y.len(),
            actual: u.len(),
        });
    }
    let np = orders.n_params() + usize::from(cfg.offset);
    let first_row = first_row.max(orders.lag());
    let end = end.min(y.len());
    let m = end.saturating_sub(first_row);
    if m <= np {
        return Err(Error::TooFewSamples {
            what: "ARX fit (rows > parameters)",
            needed: first_row + np + 1,
            actual: end,
        });
    }
    if let Some(i) = y.iter().chain(u).position(|v| !v.is_finite()) {
        return Err(Error::NonFinite {
            channel: if i < y.len() { "position" } else { "command" }.to_string(),
            index: i % y.len(),
            value: f64::NAN,
        });
    }
    let reference = y[0];
    let mut a = vec![0.0; m * np];
    let mut b = vec![0.0; m];
    let mut psi = vec![1.0; np];
    for (row, k) in (first_row..end).enumerate() {
        b[row] = regressor(&orders, y, u, k, reference, &mut psi);
        for j in 0..np {
            a[row + j * m] = psi[j];
        }
    }
    let a_copy = a.clone();
    let b_copy = b.clone();
    // relative ridge: scale columns to unit norm first
    let mut scale = vec![1.0; np];
    for j in 0..np {
        let nrm = a[j * m..(j + 1) * m]
            .iter()
            .map(|v| v * v)
            .sum::<f64>()
            .sqrt();
        if nrm > 0.0 {
            scale[j] = nrm;
            for v in &mut a[j * m..(j + 1) * m] {
                *v /= nrm;
            }
        }
    }
    let mut z = vec![0.0; np];
    let mut ws = QrWorkspace::new(np);
    lstsq_in_place(
        m,
        np,
        &mut a,
        &mut b,
        &mut z,
        &mut ws,
        &LstsqOptions {
            ridge: cfg.ridge,
            rank_tolerance: None,
        },
    )?;
    let theta: Vec<f64> = z.iter().zip(&scale).map(|(z, s)| z / s).collect();
    let mut residuals = vec![0.0; m];
    for i in 0..m {
        let mut v = b_copy[i];
        for j in 0..np {
            v -= a_copy[i + j * m] * theta[j];
        }
        residuals[i] = v;
    }
    let sse: f64 = residuals.iter().map(|e| e * e).sum();
    let loss = sse / m as f64;
    let std_errors = if with_std_errors {
        standard_errors(&a_copy, m, np, &scale, sse / (m - np) as f64)
    } else {
        vec![f64::NAN; np]
    };
    let model = orders.model(&theta[..orders.n_params()], dt)?;
    Ok(ArxFit {
        orders,
        model,
        theta,
        std_errors,
        loss,
        n: m,
        np,
        residuals,
        first_row,
        reference,
    })
}

/// `sqrt(diag(σ²·(AᵀA)⁻¹))` via the QR of the column-scaled `A` (`NaN` if singular).
fn standard_errors(a: &[f64], m: usize, np: usize, scale: &[f64], sigma2: f64) -> Vec<f64> {
    let scaled = DMatrix::from_fn(m, np, |i, j| a[i + j * m] / scale[j]);
    let r = scaled.qr().r();
    let mut out = vec![f64::NAN; np];
    // R⁻¹ column by column; diag((RᵀR)⁻¹) = row norms² of R⁻¹
    let Some(rinv) = r.clone().try_inverse() else {
        return out;
    };
    for (j, o) in out.iter_mut().enumerate() {
        let s2: f64 = (0..np).map(|k| rinv[(j, k)].powi(2)).sum();
        *o = (sigma2 * s2).sqrt() / scale[j];
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ident::engine::{run, EngineConfig};
    use crate::lti::poly_roots;
    use nalgebra::DVector;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, Normal};

    /// Simulate `A y = B u + e` from rest.
    pub(crate) fn simulate_arx(
        a: &[f64],
        b: &[f64],
        nk: usize,
        u: &[f64],
        noise: &[f64],
    ) -> Vec<f64> {
        let n = u.len();
        let mut y = vec![0.0; n];
        for k in 0..n {
            let mut v = noise[k];
            for (i, ai) in a.iter().enumerate() {
                if k > i {
                    v -= ai * y[k - i - 1];
                }
            }
            for (j, bj) in b.iter().enumerate() {
                if k >= nk + j {
                    v += bj * u[k - nk - j];
                }
            }
            y[k] = v;
        }
        y
    }

    fn random_input(rng: &mut ChaCha8Rng, n: usize) -> Vec<f64> {
        (0..n).map(|_| rng.random_range(-1.0..1.0)).collect()
    }

    fn time(n: usize, dt: f64) -> Vec<f64> {
        (0..n).map(|k| k as f64 * dt).collect()
    }

    /// Reference: windowed ridge LS on the deviation rows by nalgebra SVD.
    fn reference_fit(
        orders: &ArxOrders,
        y: &[f64],
        u: &[f64],
        window: Range<usize>,
        ridge: f64,
    ) -> Vec<f64> {
        let n = orders.n_params();
        let m = window.len();
        let r = y[window.end - 1];
        let mut psi = vec![0.0; n];
        let mut a = DMatrix::zeros(m, n);
        let mut b = DVector::zeros(m);
        for (i, k) in window.clone().enumerate() {
            b[i] = regressor(orders, y, u, k, r, &mut psi);
            for j in 0..n {
                a[(i, j)] = psi[j];
            }
        }
        let d: Vec<f64> = (0..n).map(|j| a.column(j).norm()).collect();
        let mut aa = DMatrix::zeros(m + n, n);
        let mut bb = DVector::zeros(m + n);
        for j in 0..n {
            for i in 0..m {
                aa[(i, j)] = a[(i, j)] / d[j];
            }
            aa[(m + j, j)] = ridge.sqrt();
        }
        bb.rows_mut(0, m).copy_from(&b);
        let z = aa.svd(true, true).solve(&bb, 1e-300).unwrap();
        (0..n).map(|j| z[j] / d[j]).collect()
    }

    #[test]
    fn schur_cohn_agrees_with_polynomial_roots() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let mut scratch = vec![0.0; 8];
        for _ in 0..500 {
            let n = rng.random_range(1..7);
            let a: Vec<f64> = (0..n).map(|_| rng.random_range(-1.5..1.5)).collect();
            let mut poly = vec![1.0];
            poly.extend_from_slice(&a);
            let roots = poly_roots(&poly).unwrap();
            let rho = roots.iter().map(|z| z.norm()).fold(0.0, f64::max);
            if (rho - 1.0).abs() < 1e-6 || (rho - 0.9).abs() < 1e-6 {
                continue;
            }
            assert_eq!(
                poles_inside(&a, 1.0, &mut scratch),
                rho < 1.0,
                "{a:?} rho {rho}"
            );
            assert_eq!(
                poles_inside(&a, 0.9, &mut scratch),
                rho < 0.9,
                "{a:?} rho {rho}"
            );
        }
    }

    #[test]
    fn noise_free_arx_parameters_are_recovered_to_1e_8_per_window() {
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let n = 600;
        let u = random_input(&mut rng, n);
        let (a, b) = ([-1.5, 0.7], [0.3, 0.2]);
        let y = simulate_arx(&a, &b, 2, &u, &vec![0.0; n]);
        let t = time(n, 1e-3);
        let s = Signals::new(&t, &u, &y, 1e-3, 0.0);
        let mut est = ArxConfig {
            orders: ArxOrders::new(2, 2, 2),
            ridge: 0.0,
            dc_gain_bounds: (f64::NEG_INFINITY, f64::INFINITY),
            offset: true,
            ..ArxConfig::default()
        }
        .build()
        .unwrap();
        let mut coef = [0.0; 5];
        for start in [3, 100, 400] {
            est.fit(&s, start..start + 60, &mut coef).unwrap();
            let want = [a[0], a[1], b[0], b[1]];
            for j in 0..4 {
                assert!((coef[j] - want[j]).abs() < 1e-8, "{start} {j}: {coef:?}");
            }
        }
        assert_eq!(est.coefficient_names(), vec!["a1", "a2", "b2", "b3", "c"]);
    }

    #[test]
    fn window_fit_matches_svd_reference_with_ridge_and_offset() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let n = 400;
        let u: Vec<f64> = random_input(&mut rng, n)
            .iter()
            .map(|v| 0.25 + 1e-3 * v)
            .collect();
        let noise: Vec<f64> = (0..n).map(|_| 1e-6 * rng.random_range(-1.0..1.0)).collect();
        let y0 = simulate_arx(&[-0.8], &[0.1, 0.1], 1, &u, &noise);
        let y: Vec<f64> = y0.to_vec();
        let t = time(n, 1e-3);
        let s = Signals::new(&t, &u, &y, 1e-3, 0.0);
        for ridge in [0.0, 1e-6, 1e-2] {
            let orders = ArxOrders::new(2, 3, 0);
            let mut est = ArxConfig {
                orders,
                ridge,
                max_pole_radius: f64::INFINITY,
                dc_gain_bounds: (f64::NEG_INFINITY, f64::INFINITY),
                ..ArxConfig::default()
            }
            .build()
            .unwrap();
            let mut coef = [0.0; 5];
            est.fit(&s, 150..250, &mut coef).unwrap();
            let want = reference_fit(&orders, &y, &u, 150..250, ridge);
            for j in 0..5 {
                assert!(
                    (coef[j] - want[j]).abs() <= 1e-9 * want[j].abs().max(1e-3),
                    "ridge {ridge} j {j}: {} vs {}",
                    coef[j],
                    want[j]
                );
            }
        }
    }

    #[test]
    fn sliding_update_equals_fresh_fit_on_random_data() {
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let n = 3000;
        let normal = Normal::new(0.0, 1.0).unwrap();
        let u: Vec<f64> = (0..n)
            .map(|k| 0.1 * (k as f64 * 0.01).sin() + 0.01 * normal.sample(&mut rng))
            .collect();
        let noise: Vec<f64> = (0..n).map(|_| 1e-4 * normal.sample(&mut rng)).collect();
        let y = simulate_arx(&[-1.6, 0.8, -0.1], &[0.1, 0.15, 0.05], 1, &u, &noise);
        let t = time(n, 1e-3);
        let s = Signals::new(&t, &u, &y, 1e-3, 0.0);
        let base = ArxConfig {
            orders: ArxOrders::new(3, 3, 1),
            ridge: 1e-6,
            max_pole_radius: f64::INFINITY,
            dc_gain_bounds: (f64::NEG_INFINITY, f64::INFINITY),
            refactor_every: 1000,
            ..ArxConfig::default()
        };
        let mut sliding = base.build().unwrap();
        let mut fresh = ArxConfig {
            sliding: false,
            ..base
        }
        .build()
        .unwrap();
        let (mut c1, mut c2) = ([0.0; 6], [0.0; 6]);
        let mut slid = 0;
        let mut worst: f64 = 0.0;
        for (w, hop) in [(80usize, 1usize), (120, 7), (50, 3)] {
            sliding.reset();
            let mut start = 10;
            while start + w < n {
                sliding.fit(&s, start..start + w, &mut c1).unwrap();
                fresh.fit(&s, start..start + w, &mut c2).unwrap();
                if sliding.diagnostics().unwrap().slid {
                    slid += 1;
                }
                let scale = c2.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                for j in 0..6 {
                    worst = worst.max((c1[j] - c2[j]).abs() / scale);
                }
                start += hop;
            }
        }
        assert!(slid > 2000, "sliding used {slid} times");
        assert!(worst < 1e-9, "worst relative difference {worst}");
    }

    #[test]
    fn standstill_keeps_last_model_and_reports_fallback() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let n = 400;
        let mut u = random_input(&mut rng, n);
        for v in &mut u[200..] {
            *v = 0.0;
        }
        let y = simulate_arx(&[-0.5], &[0.5], 1, &u, &vec![0.0; n]);
        let t = time(n, 1e-3);
        let s = Signals::new(&t, &u, &y, 1e-3, 0.0);
        let mut est = ArxConfig {
            orders: ArxOrders::new(1, 1, 1),
            min_excitation: 1e-9,
            ridge: 0.0,
            ..ArxConfig::default()
        }
        .build()
        .unwrap();
        let mut coef = [0.0; 2];
        // no model yet and a standstill window: error
        let zeros = vec![0.0; 100];
        let still = Signals::new(&t[..100], &zeros, &zeros, 1e-3, 0.0);
        assert!(est.fit(&still, 10..60, &mut coef).is_err());
        let f = est.fit(&s, 100..160, &mut coef).unwrap();
        assert_eq!(f.termination, Termination::Exact);
        let f = est.fit(&s, 300..360, &mut coef).unwrap();
        assert_eq!(f.termination, Termination::Fallback);
        assert!((coef[0] + 0.5).abs() < 1e-9 && (coef[1] - 0.5).abs() < 1e-9);
        assert_eq!(
            est.diagnostics().unwrap().reason,
            "standstill (command not exciting)"
        );
    }

    #[test]
    fn unstable_window_model_is_rejected() {
        // data from an unstable system: y[k] = 1.05 y[k-1] + u[k-1]
        let mut rng = ChaCha8Rng::seed_from_u64(6);
        let n = 100;
        let u = random_input(&mut rng, n);
        let y = simulate_arx(&[-1.05], &[1.0], 1, &u, &vec![0.0; n]);
        let t = time(n, 1e-3);
        let s = Signals::new(&t, &u, &y, 1e-3, 0.0);
        let mut est = ArxConfig {
            orders: ArxOrders::new(1, 1, 1),
            dc_gain_bounds: (f64::NEG_INFINITY, f64::INFINITY),
            offset: true,
            ..ArxConfig::default()
        }
        .build()
        .unwrap();
        let mut coef = [0.0; 3];
        assert!(est.fit(&s, 5..60, &mut coef).is_err());
        assert_eq!(est.diagnostics().unwrap().reason, "unstable poles");
    }

    #[test]
    fn k_step_prediction_is_exact_for_noise_free_data_far_from_zero() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let n = 500;
        let du = random_input(&mut rng, n);
        // unit DC gain system, offset 0.25 m: the deviation frame is exact
        let a = [-1.2, 0.4];
        let b = [0.1, 0.1];
        let dy = simulate_arx(&a, &b, 1, &du, &vec![0.0; n]);
        let u: Vec<f64> = du.iter().map(|v| 0.25 + 1e-3 * v).collect();
        let y: Vec<f64> = dy.iter().map(|v| 0.25 + 1e-3 * v).collect();
        let t = time(n, 1e-3);
        let s = Signals::new(&t, &u, &y, 1e-3, 0.0);
        let mut est = ArxConfig {
            orders: ArxOrders::new(2, 2, 1),
            ridge: 0.0,
            ..ArxConfig::default()
        }
        .build()
        .unwrap();
        let r = run(
            &mut est,
            &s,
            &EngineConfig {
                window: 40,
                horizon: 10,
                hop: Some(5),
                warm_up: 0,
            },
        )
        .unwrap();
        assert!(r.stats.rms < 1e-13, "{}", r.stats.rms);
        assert_eq!(r.failed_windows(), 0);
    }

    #[test]
    fn batch_fit_standard_errors_cover_the_true_parameters() {
        let mut rng = ChaCha8Rng::seed_from_u64(8);
        let n = 5000;
        let mut u = random_input(&mut rng, n);
        u[0] = 0.0;
        let normal = Normal::new(0.0, 0.05).unwrap();
        let mut e: Vec<f64> = (0..n).map(|_| normal.sample(&mut rng)).collect();
        e[0] = 0.0; // start at rest: the frame r = y[0] = 0 is exact
        let truth = [-1.5, 0.7, 1.0, 0.5];
        let y = simulate_arx(&truth[..2], &truth[2..], 1, &u, &e);
        let fit = fit_arx(
            &u,
            &y,
            1e-3,
            ArxOrders::new(2, 2, 1),
            &ArxConfig {
                ridge: 0.0,
                ..Default::default()
            },
        )
        .unwrap();
        for j in 0..4 {
            let z = (fit.theta[j] - truth[j]) / fit.std_errors[j];
            assert!(z.abs() < 4.0, "j {j}: z = {z}");
            assert!(fit.std_errors[j] < 0.01);
        }
        assert!((fit.loss.sqrt() - 0.05).abs() < 0.005);
        assert_eq!(fit.n, n - 2);
        // the model simulates like the data without noise
        let sim = fit.model.simulate(&u).unwrap();
        let clean = simulate_arx(&truth[..2], &truth[2..], 1, &u, &vec![0.0; n]);
        let err = sim
            .iter()
            .zip(&clean)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        let amp = clean.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(err < 0.02 * amp, "{err} vs amplitude {amp}");
    }

    #[test]
    fn bad_configurations_are_rejected() {
        assert!(ArxConfig {
            orders: ArxOrders::new(2, 0, 1),
            ..Default::default()
        }
        .build()
        .is_err());
        assert!(ArxConfig {
            ridge: -1.0,
            ..Default::default()
        }
        .build()
        .is_err());
        assert!(ArxConfig {
            dc_gain_bounds: (2.0, 1.0),
            ..Default::default()
        }
        .build()
        .is_err());
        assert!(ArxConfig {
            refactor_every: 0,
            ..Default::default()
        }
        .build()
        .is_err());
    }
}
