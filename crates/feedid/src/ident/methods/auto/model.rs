//! The model of `auto`'s identified candidates: an ARX model with unit DC
//! gain, written in increments from the last measured position, so that no
//! offset, frame or unit enters it.
//!
//! A position servo follows its set-point with unit gain: `A(1) = B(1)` for
//!
//! ```text
//! A(q)·y[k] = B(q)·u[k],   A = 1 + a₁q⁻¹ + … + a_na·q⁻ⁿᵃ,   B = q⁻ⁿᵏ(b₀ + … + b_(nb−1)q⁻⁽ⁿᵇ⁻¹⁾).
//! ```
//!
//! Then `A(q)(y − ρ) = B(q)(u − ρ)` for every constant `ρ`; with `ρ = y[k−1]`
//! the term of `a₁` vanishes and the model reads, for every sample `k`,
//!
//! ```text
//! y[k] − y[k−1] = −Σ_{i=2..na} a_i·(y[k−i] − y[k−1]) + Σ_{j=0..nb−1} b_j·(u[k−nk−j] − y[k−1]),
//! ```
//!
//! a linear regression in the `n = na − 1 + nb` free parameters
//! `θ = [a₂ … a_na, b₀ … b_(nb−1)]` (`a₁ = Σb − 1 − Σ_{i≥2} a_i`). Every
//! regressor and the target are differences of positions: an offset of the
//! recording cancels exactly, a change of unit scales them all alike and
//! leaves `θ` unchanged. `θ = 0` is the hold predictor. The k-step
//! prediction runs the same equation forward from the last measured
//! position, on the known command, feeding back its own predictions.
//!
//! A candidate may add a constant `c` to every increment (a *bias*: a
//! constant disturbance such as friction during a one-directional move,
//! gravity, or a following-error bias),
//!
//! ```text
//! y[k] − y[k−1] = ψ[k]ᵀθ + c.
//! ```
//!
//! The target is a difference of positions, so `c` is a speed (a length per
//! sample): it cancels no offset, an offset still changes nothing, and a
//! change of unit scales it like the target. The candidates append its
//! column to `ψ` with a value fixed from the data (see `candidate`); the
//! prediction adds `c` at every step.

// Index loops mirror the formulas.
#![allow(clippy::needless_range_loop)]

use crate::ident::methods::regressor::ArxOrders;

/// Samples needed before a regression row: `max(na, nk + nb − 1, 1)`.
pub(crate) fn lag(o: &ArxOrders) -> usize {
    o.na.max(o.nk + o.nb.saturating_sub(1)).max(1)
}

/// Number of free parameters `na − 1 + nb` (`na ≥ 1`).
pub(crate) fn n_free(o: &ArxOrders) -> usize {
    o.na.saturating_sub(1) + o.nb
}

/// The orders a row or a prediction is computed with: at run time
/// ([`ArxOrders`]) or known at compile time ([`Fixed`], the default
/// candidates': the loops are unrolled). Both give the same values.
pub(crate) trait Dims: Copy {
    /// `na − 1` (0 for `na = 0`): the free autoregressive coefficients.
    fn na1(self) -> usize;
    /// `nb`.
    fn nb(self) -> usize;
    /// `nk`.
    fn nk(self) -> usize;
}

impl Dims for ArxOrders {
    #[inline(always)]
    fn na1(self) -> usize {
        self.na.max(1) - 1
    }
    #[inline(always)]
    fn nb(self) -> usize {
        self.nb
    }
    #[inline(always)]
    fn nk(self) -> usize {
        self.nk
    }
}

/// Orders `na = NA1 + 1`, `nb = NB` known at compile time, delay `nk` (the field).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Fixed<const NA1: usize, const NB: usize>(pub usize);

impl<const NA1: usize, const NB: usize> Dims for Fixed<NA1, NB> {
    #[inline(always)]
    fn na1(self) -> usize {
        NA1
    }
    #[inline(always)]
    fn nb(self) -> usize {
        NB
    }
    #[inline(always)]
    fn nk(self) -> usize {
        self.0
    }
}

/// Call `$f` (a generic function's name, its first argument the orders)
/// with `$o` (an [`ArxOrders`]) as [`Fixed`] orders when they are a default
/// candidate's, else as they are, and the remaining arguments.
macro_rules! with_dims {
    ($o:expr, $f:ident ( $($arg:expr),* $(,)? )) => {{
        let o: ArxOrders = $o;
        match (o.na.max(1) - 1, o.nb) {
            (1, 2) => $f($crate::ident::methods::auto::model::Fixed::<1, 2>(o.nk), $($arg),*),
            (2, 3) => $f($crate::ident::methods::auto::model::Fixed::<2, 3>(o.nk), $($arg),*),
            (3, 4) => $f($crate::ident::methods::auto::model::Fixed::<3, 4>(o.nk), $($arg),*),
            (5, 6) => $f($crate::ident::methods::auto::model::Fixed::<5, 6>(o.nk), $($arg),*),
            (7, 8) => $f($crate::ident::methods::auto::model::Fixed::<7, 8>(o.nk), $($arg),*),
            _ => $f(o, $($arg),*),
        }
    }};
}
pub(crate) use with_dims;

/// Regression row of sample `k` (local index `≥ lag`) into `psi`; returns the target `y[k] − y[k−1]`.
#[inline]
pub(crate) fn row(o: &ArxOrders, y: &[f64], u: &[f64], k: usize, psi: &mut [f64]) -> f64 {
    // (× 1 is exact)
    row_scaled(*o, y, u, k, 1.0, psi).0
}

/// Regression row of sample `k` (local index `≥ lag`) into `psi`, every
/// entry multiplied by `inv` (scaled as it is built: bit-identical to
/// scaling afterwards); returns the target `y[k] − y[k−1]` times `inv` and
/// whether the unscaled row or target has a non-zero entry.
#[inline(always)]
pub(crate) fn row_scaled<D: Dims>(
    o: D,
    y: &[f64],
    u: &[f64],
    k: usize,
    inv: f64,
    psi: &mut [f64],
) -> (f64, bool) {
    let (na1, nb) = (o.na1(), o.nb());
    let rho = y[k - 1];
    let t = y[k] - rho;
    let mut any = t != 0.0;
    // y[k−2] … y[k−na] and u[k−nk] … u[k−nk−nb+1], newest first (slices:
    // one bounds check each)
    let ya = &y[k - 1 - na1..k - 1];
    let newest = k - o.nk();
    let ub = &u[newest + 1 - nb..=newest];
    let (pa, pb) = psi[..na1 + nb].split_at_mut(na1);
    for i in 0..na1 {
        let d = -(ya[na1 - 1 - i] - rho);
        any |= d != 0.0;
        pa[i] = d * inv;
    }
    for j in 0..nb {
        let d = ub[nb - 1 - j] - rho;
        any |= d != 0.0;
        pb[j] = d * inv;
    }
    (t * inv, any)
}

/// k-step prediction of `out.len()` samples from the local index `e`: `y`
/// measured below `e`, `u` known up to `e + out.len()`; `c` the constant
/// added to every increment (0 without a bias); `past` a scratch of length
/// `≥ na + out.len()`.
///
/// Computed relative to the last measured position `r = y[e−1]` (an offset
/// of the recording cancels before any product): with `d` the positions
/// and `ū` the commands minus `r`, the increment of the unit-gain model is
/// `−Σ θ_a·d(h−a) + Σ θ_b·ū + d(h−1)·(Σθ_a − Σθ_b)`. The command's share
/// does not depend on the predictions and is summed first; the recursion
/// then only carries one product and one addition from one step to the
/// next (the step-by-step form chained every term through the previous
/// prediction).
#[allow(clippy::too_many_arguments)]
pub(crate) fn predict<D: Dims>(
    o: D,
    theta: &[f64],
    c: f64,
    y: &[f64],
    u: &[f64],
    e: usize,
    past: &mut [f64],
    out: &mut [f64],
) {
    let (na1, nb) = (o.na1(), o.nb());
    let na = na1 + 1;
    let r = y[e - 1];
    let (ta, tb) = theta[..na1 + nb].split_at(na1);
    let mut sum = 0.0;
    for &a in ta {
        sum += a;
    }
    for &b in tb {
        sum -= b;
    }
    // the command's share of each increment (off the recursion)
    for (h, v) in out.iter_mut().enumerate() {
        let t = e + h - o.nk();
        let ub = &u[t + 1 - nb..=t];
        let mut acc = 0.0;
        for j in 0..nb {
            acc += tb[j] * (ub[nb - 1 - j] - r);
        }
        *v = acc + c;
    }
    for i in 0..na {
        past[i] = y[e - na + i] - r;
    }
    let keep = 1.0 + sum;
    // the previous prediction stays in a register (not reloaded from `past`)
    let mut prev = past[na - 1];
    for h in 0..out.len() {
        // the oldest terms first: the newest prediction enters last
        let mut v = out[h];
        for a in (2..=na1 + 1).rev() {
            v -= ta[a - 2] * past[na + h - a];
        }
        let d = v + prev * keep;
        past[na + h] = d;
        out[h] = r + d;
        prev = d;
    }
}

/// The ARX coefficients `[a₁ … a_na, b₀ … b_(nb−1)]` of free parameters `theta`.
pub(crate) fn arx_coefficients(o: &ArxOrders, theta: &[f64], out: &mut [f64]) {
    let na = o.na;
    let a_rest: f64 = theta[..na.saturating_sub(1)].iter().sum();
    let b_sum: f64 = theta[na.saturating_sub(1)..].iter().sum();
    if na >= 1 {
        out[0] = b_sum - 1.0 - a_rest;
        out[1..na].copy_from_slice(&theta[..na - 1]);
    }
    out[na..na + o.nb].copy_from_slice(&theta[na.saturating_sub(1)..]);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ident::methods::regressor::predict_k_step;

    /// y[k] = 1.5 y[k−1] − 0.6 y[k−2] + 0.05 u[k] + 0.05 u[k−1] (DC gain 1).
    fn system(n: usize, offset: f64) -> (Vec<f64>, Vec<f64>) {
        let u: Vec<f64> = (0..n)
            .map(|k| offset + 1e-3 * ((k as f64 * 0.07).sin() + (k as f64 * 0.011).cos()))
            .collect();
        let mut y = vec![offset; n];
        for k in 2..n {
            y[k] = 1.5 * y[k - 1] - 0.6 * y[k - 2] + 0.05 * u[k] + 0.05 * u[k - 1];
        }
        (u, y)
    }

    #[test]
    fn the_true_unit_gain_model_fits_every_row_exactly() {
        let o = ArxOrders::new(2, 2, 0);
        // a1 = −1.5, a2 = 0.6, b0 = 0.05, b1 = 0.05: free θ = [a2, b0, b1]
        let theta = [0.6, 0.05, 0.05];
        let (u, y) = system(300, 0.2);
        let mut psi = [0.0; 3];
        for k in 2..300 {
            let t = row(&o, &y, &u, k, &mut psi);
            let fit: f64 = psi.iter().zip(&theta).map(|(p, t)| p * t).sum();
            assert!((t - fit).abs() < 1e-15, "row {k}");
        }
        let mut c = [0.0; 4];
        arx_coefficients(&o, &theta, &mut c);
        assert!((c[0] + 1.5).abs() < 1e-15 && c[1] == 0.6 && c[2] == 0.05 && c[3] == 0.05);
    }

    #[test]
    fn prediction_equals_the_arx_prediction_of_the_same_model() {
        let o = ArxOrders::new(2, 2, 0);
        let theta = [0.6, 0.05, 0.05];
        let (u, y) = system(200, 0.0);
        let mut out = [0.0; 10];
        let mut past = [0.0; 12];
        predict(o, &theta, 0.0, &y, &u, 150, &mut past, &mut out);
        let mut reference = [0.0; 10];
        let mut past2 = [0.0; 12];
        predict_k_step(
            &o,
            &[-1.5, 0.6, 0.05, 0.05],
            &y,
            &u,
            150,
            0.0,
            0.0,
            &mut past2,
            &mut reference,
        );
        for (a, b) in out.iter().zip(&reference) {
            assert!((a - b).abs() < 1e-15);
        }
        // and the system itself (noise-free): exact
        for (h, a) in out.iter().enumerate() {
            assert!((a - y[150 + h]).abs() < 1e-15);
        }
    }

    #[test]
    fn an_offset_changes_neither_rows_nor_predictions() {
        let o = ArxOrders::new(3, 2, 1);
        let theta = [0.1, 0.3, 0.2, -0.05];
        let (u0, y0) = system(100, 0.0);
        let shift = 1000.0;
        let u1: Vec<f64> = u0.iter().map(|v| v + shift).collect();
        let y1: Vec<f64> = y0.iter().map(|v| v + shift).collect();
        let (mut p0, mut p1) = ([0.0; 4], [0.0; 4]);
        for k in 3..100 {
            let t0 = row(&o, &y0, &u0, k, &mut p0);
            let t1 = row(&o, &y1, &u1, k, &mut p1);
            assert!((t0 - t1).abs() < 1e-12);
            for (a, b) in p0.iter().zip(&p1) {
                assert!((a - b).abs() < 1e-12);
            }
        }
        let (mut a, mut b) = ([0.0; 10], [0.0; 10]);
        predict(o, &theta, 0.0, &y0, &u0, 80, &mut [0.0; 13], &mut a);
        predict(o, &theta, 0.0, &y1, &u1, 80, &mut [0.0; 13], &mut b);
        for (a, b) in a.iter().zip(&b) {
            assert!((a + shift - b).abs() < 1e-12);
        }
    }

    #[test]
    fn zero_parameters_hold_the_last_position() {
        let o = ArxOrders::new(2, 3, 0);
        let (u, y) = system(50, 0.0);
        let mut out = [0.0; 5];
        predict(o, &[0.0; 4], 0.0, &y, &u, 40, &mut [0.0; 7], &mut out);
        assert!(out.iter().all(|&v| v == y[39]));
    }
}
