//! Time-scaled continuous transfer functions in controllable companion form,
//! with an allocation-free exact discretisation (zero-order and first-order
//! hold) — the simulation core of the output-error ([`super::oe`]) and SRIVC
//! ([`super::srivc`]) estimators.
//!
//! **Parameterisation.** With a reference frequency `ω_r` \[rad/s\] and the
//! scaled Laplace variable `σ = s/ω_r` (scaled time `τ = ω_r·t`),
//!
//! ```text
//!     G(s) = B(σ)/A(σ),   A(σ) = σⁿ + α_{n−1}·σⁿ⁻¹ + … + α₀   (monic),
//!                         B(σ) = β_m·σᵐ + … + β₀              (m < n)
//! ```
//!
//! and `θ = [α_{n−1} … α₀, β_m … β₀]` (descending, like the reported
//! coefficient names). In physical units `D(s) = ω_rⁿ·A(s/ω_r)` is monic in `s`
//! with `D_i = α_i·ω_r^{n−i}` and `N_j = β_j·ω_r^{n−j}`.
//!
//! **Realisation.** The states are `x_i = σⁱ·X`, `X = U/A(σ)`, `i = 0 … n−1`:
//! `dx_i/dτ = x_{i+1}`, `dx_{n−1}/dτ = u − Σ α_i·x_i`, output `Σ β_j·x_j`.
//! So the states of one filter `1/A` give every `σʲ/A·u` at once, and
//! `σⁿ/A·u = u − Σ α_i·x_i`.
//!
//! **Discretisation** over a scaled step `h = ω_r·Δt`: one exponential of
//! the block upper triangular `(n+2)×(n+2)` matrix (Van Loan 1978)
//!
//! ```text
//!     M = [[A·h, e_n·h, 0], [0, 0, h], [0, 0, 0]],   e^M = [[A_d, Γ₀, Γ₁·h], [0, 1, h], [0, 0, 1]]
//! ```
//!
//! gives the zero-order-hold pair `(A_d, Γ₀)` (exact for piecewise-constant
//! inputs) and the first-order-hold term `Γ₁` (exact for piecewise-linear
//! inputs): `x[k+1] = A_d·x[k] + Γ₀·v[k] + Γ₁·(v[k+1] − v[k])`. The
//! exponential is scaling and squaring with a degree-16 Taylor polynomial at
//! `‖M/2ˢ‖₁ ≤ 1/2` (truncation < 1e-19), evaluated by Horner's rule in
//! preallocated matrices. With `ω_r` at the geometric mean of the pole
//! magnitudes the companion matrix has O(1) entries, so no balancing is needed
//! for the low orders identified here (n ≤ [`MAX_ORDER`]).
//!
//! **Stability** is tested without root finding by the Routh–Hurwitz array.
//!
//! Reference: C.F. Van Loan, "Computing integrals involving the matrix
//! exponential", IEEE TAC 23 (1978); N.J. Higham, *Functions of Matrices*, §10.3.

// Index loops mirror the matrix formulas.
#![allow(clippy::needless_range_loop)]

use nalgebra::Complex;

use crate::error::{Error, Result};
use crate::lti::{poly_from_roots, poly_roots};

/// Largest denominator order supported.
pub const MAX_ORDER: usize = 12;

/// Taylor degree of the exponential.
const TAYLOR_DEGREE: usize = 16;

/// Exact discretisation of `1/A(σ)` in companion form, reusable for any
/// coefficients of the same order (allocation-free after construction).
/// Plain column-major arrays: the matrices are at most 14×14, and the
/// stepping loop runs for every sample of every window.
#[derive(Debug, Clone)]
pub(crate) struct Companion {
    n: usize,
    /// A_d (n×n, column-major: `ad[i + j·n]`).
    ad: Vec<f64>,
    /// Γ₀ (ZOH input vector).
    g0: Vec<f64>,
    /// Γ₁ (FOH increment vector).
    g1: Vec<f64>,
    /// `(n+2)×(n+2)` column-major scratch of the exponential.
    m: Vec<f64>,
    e: Vec<f64>,
    t: Vec<f64>,
    scratch: Vec<f64>,
}

impl Companion {
    /// Workspace for order `n` (1 ≤ n ≤ [`MAX_ORDER`]).
    pub(crate) fn new(n: usize) -> Self {
        let k = n + 2;
        Self {
            n,
            ad: vec![0.0; n * n],
            g0: vec![0.0; n],
            g1: vec![0.0; n],
            m: vec![0.0; k * k],
            e: vec![0.0; k * k],
            t: vec![0.0; k * k],
            scratch: vec![0.0; n],
        }
    }

    /// Discretise `1/A(σ)` with `alpha_desc = [α_{n−1} … α₀]` over the scaled step `h`.
    pub(crate) fn discretize(&mut self, alpha_desc: &[f64], h: f64) -> Result<()> {
        let n = self.n;
        if alpha_desc.len() != n {
            return Err(Error::LengthMismatch {
                what: "companion denominator",
                expected: n,
                actual: alpha_desc.len(),
            });
        }
        if !(h.is_finite() && h > 0.0) || alpha_desc.iter().any(|a| !a.is_finite()) {
            return Err(Error::InvalidModel {
                reason: "non-finite coefficient or step in companion discretisation",
            });
        }
        let k = n + 2;
        let m = &mut self.m;
        m.fill(0.0);
        for i in 0..n.saturating_sub(1) {
            m[i + (i + 1) * k] = h;
        }
        for i in 0..n {
            // α_i multiplies x_i; alpha_desc[0] = α_{n−1}
            m[(n - 1) + i * k] = -alpha_desc[n - 1 - i] * h;
        }
        m[(n - 1) + n * k] = h;
        m[n + (n + 1) * k] = h;
        // scaling: ‖M/2ˢ‖₁ ≤ 1/2
        let norm = m
            .chunks_exact(k)
            .map(|col| col.iter().map(|v| v.abs()).sum::<f64>())
            .fold(0.0f64, f64::max);
        let mut s = 0u32;
        if norm > 0.5 {
            s = (norm / 0.5).log2().ceil() as u32;
        }
        if s > 200 {
            return Err(Error::InvalidModel {
                reason: "companion matrix too large to exponentiate",
            });
        }
        let scale = 0.5f64.powi(s as i32);
        m.iter_mut().for_each(|v| *v *= scale);
        // Horner: E = I + X/K·(I + X/(K−1)·(…))
        self.e.fill(0.0);
        for i in 0..k {
            self.e[i + i * k] = 1.0;
        }
        for d in (1..=TAYLOR_DEGREE).rev() {
            companion_product(n, 1.0 / d as f64, &self.m, &self.e, &mut self.t);
            for i in 0..k {
                self.t[i + i * k] += 1.0;
            }
            std::mem::swap(&mut self.t, &mut self.e);
        }
        for _ in 0..s {
            gemm(k, 1.0, &self.e, &self.e, &mut self.t);
            std::mem::swap(&mut self.t, &mut self.e);
        }
        for j in 0..n {
            for i in 0..n {
                self.ad[i + j * n] = self.e[i + j * k];
            }
        }
        for i in 0..n {
            self.g0[i] = self.e[i + n * k];
            self.g1[i] = self.e[i + (n + 1) * k] / h;
        }
        if self
            .ad
            .iter()
            .chain(&self.g0)
            .chain(&self.g1)
            .any(|v| !v.is_finite())
        {
            return Err(Error::InvalidModel {
                reason: "non-finite companion discretisation",
            });
        }
        Ok(())
    }

    /// One zero-order-hold step `x ← A_d·x + Γ₀·v`.
    pub(crate) fn step_zoh(&mut self, x: &mut [f64], v: f64) {
        self.step(x, v, 0.0);
    }

    /// One first-order-hold step `x ← A_d·x + Γ₀·v + Γ₁·(v_next − v)`.
    pub(crate) fn step_foh(&mut self, x: &mut [f64], v: f64, v_next: f64) {
        self.step(x, v, v_next - v);
    }

    #[inline]
    fn step(&mut self, x: &mut [f64], v: f64, dv: f64) {
        let n = self.n;
        let s = &mut self.scratch[..n];
        for ((si, g0), g1) in s.iter_mut().zip(&self.g0).zip(&self.g1) {
            *si = g0 * v + g1 * dv;
        }
        for (col, &xj) in self.ad.chunks_exact(n).zip(x.iter()) {
            if xj != 0.0 {
                for (si, aij) in s.iter_mut().zip(col) {
                    *si += aij * xj;
                }
            }
        }
        x[..n].copy_from_slice(s);
    }
}

/// The window quantities of the output-error fit from the last
/// discretisation: the forced response from the zero state `forced[k]`, the
/// observability rows `obs[k + j·w] = (C·A_dᵏ)_j` (`C` from `beta_desc`) and
/// `rhs = y − forced`. The order is a constant for `n ≤ 8` (the state lives
/// in registers); the same operations in the same order as stepping with
/// [`Companion::step_zoh`] and [`output`].
pub(crate) fn window_responses(
    comp: &Companion,
    beta_desc: &[f64],
    u: &[f64],
    y: &[f64],
    forced: &mut [f64],
    obs: &mut [f64],
    rhs: &mut [f64],
) {
    macro_rules! fixed {
        ($($n:literal),*) => {
            match comp.n {
                $($n => responses::<$n>(&comp.ad, &comp.g0, beta_desc, u, y, forced, obs, rhs),)*
                _ => responses_dyn(comp, beta_desc, u, y, forced, obs, rhs),
            }
        };
    }
    fixed!(1, 2, 3, 4, 5, 6, 7, 8);
}

#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn responses<const N: usize>(
    ad: &[f64],
    g0: &[f64],
    beta_desc: &[f64],
    u: &[f64],
    y: &[f64],
    forced: &mut [f64],
    obs: &mut [f64],
    rhs: &mut [f64],
) {
    let w = u.len();
    let mut a = [[0.0; N]; N]; // a[j] = column j of A_d
    for (j, col) in a.iter_mut().enumerate() {
        col.copy_from_slice(&ad[j * N..(j + 1) * N]);
    }
    let mut g = [0.0; N];
    g.copy_from_slice(&g0[..N]);
    let mb = beta_desc.len();
    // The forced response from the zero state and the observability rows
    // o_0 = C (c_i = β_i), o_{k+1} = o_k·A_d, in one loop: two independent
    // recursions whose latencies overlap.
    let mut x = [0.0; N];
    let mut row = [0.0; N];
    for (i, b) in beta_desc.iter().enumerate() {
        row[mb - 1 - i] = *b;
    }
    for k in 0..w {
        let uk = u[k];
        let mut f = 0.0;
        for (kk, b) in beta_desc.iter().enumerate() {
            f += b * x[mb - 1 - kk];
        }
        forced[k] = f;
        rhs[k] = y[k] - f;
        let mut s = [0.0; N];
        for i in 0..N {
            s[i] = g[i] * uk + 0.0;
        }
        // (A_d is finite: the terms of zero states add exact zeros, as the
        // skipped ones of `step`)
        for j in 0..N {
            for i in 0..N {
                s[i] += a[j][i] * x[j];
            }
        }
        x = s;
        let mut next = [0.0; N];
        for j in 0..N {
            obs[k + j * w] = row[j];
            let mut v = 0.0;
            for i in 0..N {
                v += row[i] * a[j][i];
            }
            next[j] = v;
        }
        row = next;
    }
}

/// The output `ŷ_k = C·x_k` of the last discretisation over `u` from the
/// state `x0` (`beta_desc` as in [`output`]), with the states `x_k` into
/// `states` (`states[k + j·w]`, state `j`) if given. Fixed order up to 8.
pub(crate) fn simulate_from(
    comp: &Companion,
    beta_desc: &[f64],
    x0: &[f64],
    u: &[f64],
    out: &mut [f64],
    states: Option<&mut [f64]>,
) {
    macro_rules! fixed {
        ($($n:literal),*) => {
            match comp.n {
                $($n => simulate::<$n>(comp, beta_desc, x0, u, out, states),)*
                _ => simulate::<0>(comp, beta_desc, x0, u, out, states),
            }
        };
    }
    fixed!(1, 2, 3, 4, 5, 6, 7, 8);
}

#[inline(always)]
fn simulate<const N: usize>(
    comp: &Companion,
    beta_desc: &[f64],
    x0: &[f64],
    u: &[f64],
    out: &mut [f64],
    states: Option<&mut [f64]>,
) {
    if N == 0 {
        return simulate_dyn(comp, beta_desc, x0, u, out, states);
    }
    let w = u.len();
    let mb = beta_desc.len();
    let mut a = [[0.0; N]; N]; // a[j] = column j of A_d
    for (j, col) in a.iter_mut().enumerate() {
        col.copy_from_slice(&comp.ad[j * N..(j + 1) * N]);
    }
    let mut g = [0.0; N];
    g.copy_from_slice(&comp.g0[..N]);
    let mut c = [0.0; N]; // the output row: c[mb−1−kk] = β_desc[kk]
    for (kk, b) in beta_desc.iter().enumerate() {
        c[mb - 1 - kk] = *b;
    }
    let mut x = [0.0; N];
    x.copy_from_slice(&x0[..N]);
    let (u, out) = (&u[..w], &mut out[..w]);
    if let Some(st) = states {
        let st = &mut st[..w * N];
        for k in 0..w {
            out[k] = (0..N).map(|j| c[j] * x[j]).sum();
            for j in 0..N {
                st[k + j * w] = x[j];
            }
            x = step_fixed(&a, &g, &x, u[k]);
        }
    } else {
        for k in 0..w {
            out[k] = (0..N).map(|j| c[j] * x[j]).sum();
            x = step_fixed(&a, &g, &x, u[k]);
        }
    }
}

/// `A_d·x + Γ₀·v` for a fixed order.
#[inline(always)]
fn step_fixed<const N: usize>(a: &[[f64; N]; N], g: &[f64; N], x: &[f64; N], v: f64) -> [f64; N] {
    let mut s = [0.0; N];
    for i in 0..N {
        s[i] = g[i] * v;
    }
    for j in 0..N {
        for i in 0..N {
            s[i] += a[j][i] * x[j];
        }
    }
    s
}

/// [`simulate`] for any order.
fn simulate_dyn(
    comp: &Companion,
    beta_desc: &[f64],
    x0: &[f64],
    u: &[f64],
    out: &mut [f64],
    mut states: Option<&mut [f64]>,
) {
    let n = comp.n;
    let w = u.len();
    let mb = beta_desc.len();
    let mut x = [0.0; MAX_ORDER];
    let mut s = [0.0; MAX_ORDER];
    x[..n].copy_from_slice(&x0[..n]);
    for k in 0..w {
        let mut f = 0.0;
        for (kk, b) in beta_desc.iter().enumerate() {
            f += b * x[mb - 1 - kk];
        }
        out[k] = f;
        if let Some(st) = states.as_deref_mut() {
            for j in 0..n {
                st[k + j * w] = x[j];
            }
        }
        for i in 0..n {
            s[i] = comp.g0[i] * u[k];
        }
        for j in 0..n {
            for i in 0..n {
                s[i] += comp.ad[i + j * n] * x[j];
            }
        }
        x[..n].copy_from_slice(&s[..n]);
    }
}

/// [`responses`] for any order.
fn responses_dyn(
    comp: &Companion,
    beta_desc: &[f64],
    u: &[f64],
    y: &[f64],
    forced: &mut [f64],
    obs: &mut [f64],
    rhs: &mut [f64],
) {
    let n = comp.n;
    let w = u.len();
    let mut x = [0.0; MAX_ORDER];
    let mut s = [0.0; MAX_ORDER];
    for k in 0..w {
        forced[k] = output(beta_desc, &x[..n]);
        rhs[k] = y[k] - forced[k];
        for i in 0..n {
            s[i] = comp.g0[i] * u[k] + comp.g1[i] * 0.0;
        }
        for j in 0..n {
            if x[j] != 0.0 {
                for i in 0..n {
                    s[i] += comp.ad[i + j * n] * x[j];
                }
            }
        }
        x[..n].copy_from_slice(&s[..n]);
    }
    let mb = beta_desc.len();
    let mut row = [0.0; MAX_ORDER];
    let mut next = [0.0; MAX_ORDER];
    for (i, b) in beta_desc.iter().enumerate() {
        row[mb - 1 - i] = *b;
    }
    for k in 0..w {
        for j in 0..n {
            obs[k + j * w] = row[j];
        }
        for j in 0..n {
            next[j] = (0..n).map(|i| row[i] * comp.ad[i + j * n]).sum();
        }
        row[..n].copy_from_slice(&next[..n]);
    }
}

/// `c = α·m·e` for the scaled Van Loan matrix `m` of [`Companion::discretize`]
/// (`k = n + 2`, column-major): only its superdiagonal and row `n − 1`
/// are non-zero, so row `i` of the product is `m[i][i+1]·e[i+1]` (`i ≠ n−1`)
/// or `Σ_{j ≤ n} m[n−1][j]·e[j]`, `O(k·n)` instead of `O(k³)`.
fn companion_product(n: usize, alpha: f64, m: &[f64], e: &[f64], c: &mut [f64]) {
    let k = n + 2;
    // the superdiagonal entries are all the scaled step; row n−1 is dense up to column n
    let row: [f64; MAX_ORDER + 1] =
        std::array::from_fn(|l| if l <= n { m[(n - 1) + l * k] } else { 0.0 });
    for (cj, ej) in c.chunks_exact_mut(k).zip(e.chunks_exact(k)) {
        for i in 0..n - 1 {
            cj[i] = m[i + (i + 1) * k] * (alpha * ej[i + 1]);
        }
        let mut s = 0.0;
        for (r, &elj) in row[..=n].iter().zip(ej) {
            s += r * (alpha * elj);
        }
        cj[n - 1] = s;
        cj[n] = m[n + (n + 1) * k] * (alpha * ej[n + 1]);
        cj[n + 1] = 0.0;
    }
}

/// `c = α·a·b` for column-major `k×k` matrices.
fn gemm(k: usize, alpha: f64, a: &[f64], b: &[f64], c: &mut [f64]) {
    for (cj, bj) in c.chunks_exact_mut(k).zip(b.chunks_exact(k)) {
        cj.fill(0.0);
        for (al, &blj) in a.chunks_exact(k).zip(bj) {
            if blj != 0.0 {
                let f = alpha * blj;
                for (ci, &ail) in cj.iter_mut().zip(al) {
                    *ci += ail * f;
                }
            }
        }
    }
}

/// Output `Σ β_j·x_j` with `beta_desc = [β_m … β₀]`.
pub(crate) fn output(beta_desc: &[f64], x: &[f64]) -> f64 {
    let m = beta_desc.len();
    beta_desc
        .iter()
        .enumerate()
        .map(|(k, b)| b * x[m - 1 - k])
        .sum()
}

/// Routh–Hurwitz test: true if every root of the monic `σⁿ + α_{n−1}σⁿ⁻¹ + … + α₀`
/// (`alpha_desc = [α_{n−1} … α₀]`) has a negative real part. Allocation-free.
pub(crate) fn is_hurwitz(alpha_desc: &[f64]) -> bool {
    let n = alpha_desc.len();
    if n > MAX_ORDER || alpha_desc.iter().any(|a| !(a.is_finite() && *a > 0.0)) {
        return false;
    }
    let coef = |i: usize| -> f64 {
        if i == 0 {
            1.0
        } else {
            alpha_desc.get(i - 1).copied().unwrap_or(0.0)
        }
    };
    const W: usize = MAX_ORDER / 2 + 2;
    let mut a = [0.0; W];
    let mut b = [0.0; W];
    let mut c = [0.0; W];
    for k in 0..W {
        a[k] = coef(2 * k);
        b[k] = coef(2 * k + 1);
    }
    for _ in 0..n {
        if !(b[0] > 0.0 && b[0].is_finite()) {
            return false;
        }
        for k in 0..W {
            let a1 = if k + 1 < W { a[k + 1] } else { 0.0 };
            let b1 = if k + 1 < W { b[k + 1] } else { 0.0 };
            c[k] = a1 - a[0] / b[0] * b1;
        }
        a = b;
        b = c;
    }
    true
}

/// Mirror roots with non-negative real part into the left half plane
/// (`alpha_desc` as in [`is_hurwitz`]); a root on the imaginary axis moves
/// to `−1e-3·max(|root|, 1)`. Allocates.
pub(crate) fn reflect_unstable(alpha_desc: &mut [f64]) -> Result<()> {
    let mut poly = Vec::with_capacity(alpha_desc.len() + 1);
    poly.push(1.0);
    poly.extend_from_slice(alpha_desc);
    let mut roots = poly_roots(&poly)?;
    for r in roots.iter_mut() {
        if r.re > 0.0 {
            *r = Complex::new(-r.re, r.im);
        } else if r.re == 0.0 {
            *r = Complex::new(-1e-3 * r.norm().max(1.0), r.im);
        }
    }
    let p = poly_from_roots(&roots);
    if p.len() != alpha_desc.len() + 1 || p.iter().any(|v| !v.is_finite()) {
        return Err(Error::InvalidModel {
            reason: "reflected denominator is not finite",
        });
    }
    alpha_desc.copy_from_slice(&p[1..]);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lti::TransferFunction;

    #[test]
    fn companion_zoh_matches_lti_discretisation() {
        // 1/(σ³ + 2σ² + 3σ + 1.5) with output β = [0.5, 1, 2] (σ² .. σ⁰)
        let alpha = [2.0, 3.0, 1.5];
        let beta = [0.5, 1.0, 2.0];
        let h = 0.37;
        let mut c = Companion::new(3);
        c.discretize(&alpha, h).unwrap();
        let tf = TransferFunction::new(beta.to_vec(), vec![1.0, 2.0, 3.0, 1.5]).unwrap();
        let sys = tf.to_state_space().unwrap().discretize_zoh(h).unwrap();
        let u: Vec<f64> = (0..60).map(|k| ((k as f64) * 0.7).sin() + 0.3).collect();
        let y_ref = sys.simulate(&u, None).unwrap();
        let mut x = [0.0; 3];
        for (k, &uk) in u.iter().enumerate() {
            let y = output(&beta, &x);
            assert!((y - y_ref[k]).abs() < 1e-13, "{k}: {y} vs {}", y_ref[k]);
            c.step_zoh(&mut x, uk);
        }
    }

    #[test]
    fn first_order_hold_is_exact_for_a_ramp() {
        // 1/(σ + 2) driven by v(τ) = τ: x(τ) = τ/2 − 1/4 + e^{−2τ}/4
        let mut c = Companion::new(1);
        let h = 0.1;
        c.discretize(&[2.0], h).unwrap();
        let mut x = [0.0];
        for k in 0..50 {
            let t = k as f64 * h;
            c.step_foh(&mut x, t, t + h);
            let t1 = t + h;
            let want = t1 / 2.0 - 0.25 + (-2.0 * t1).exp() / 4.0;
            assert!((x[0] - want).abs() < 1e-15, "{k}");
        }
    }

    #[test]
    fn routh_test_agrees_with_roots() {
        let cases: [(&[f64], bool); 6] = [
            (&[3.0, 3.0, 1.0], true),   // (σ+1)³
            (&[1.0, 1.0, 1.0], true),   // σ³+σ²+σ+1 has roots ±i: not stable
            (&[0.5, 4.0, 10.0], false), // unstable pair
            (&[2.0, 1.0], true),
            (&[-0.1, 1.0], false),
            (&[4.0, 6.0, 4.0, 1.0], true), // (σ+1)⁴
        ];
        for (i, (a, _)) in cases.iter().enumerate() {
            let mut p = vec![1.0];
            p.extend_from_slice(a);
            let roots = poly_roots(&p).unwrap();
            let stable = roots.iter().all(|r| r.re < -1e-9);
            assert_eq!(is_hurwitz(a), stable, "case {i}");
        }
    }

    #[test]
    fn reflection_mirrors_unstable_roots() {
        // (σ − 1)(σ + 2) = σ² + σ − 2 → (σ + 1)(σ + 2) = σ² + 3σ + 2
        let mut a = [1.0, -2.0];
        reflect_unstable(&mut a).unwrap();
        assert!((a[0] - 3.0).abs() < 1e-12 && (a[1] - 2.0).abs() < 1e-12);
        assert!(is_hurwitz(&a));
    }
}
