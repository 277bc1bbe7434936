//! The ARX regressor shared by every method built on it (`arx`, `rls`,
//! `auto`, order selection): the orders `na, nb, nk`, the regression row in
//! deviation coordinates, the k-step-ahead prediction feeding back its own
//! outputs, and the checks of an identified `A(q)`, `B(q)` (poles inside a
//! radius by Schur–Cohn, DC gain). See the `arx` method for the model.

// Negated comparisons are deliberate (they reject NaN); index loops mirror
// the formulas.
#![allow(
    clippy::neg_cmp_op_on_partial_ord,
    clippy::needless_range_loop,
    clippy::too_many_arguments
)]

use std::ops::Range;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::ident::engine::Signals;
use crate::ident::model::LinearModel;
use crate::ident::option::{OptionKind, OptionRange, OptionSpec};

/// Option `order` of the methods with an ARX regressor: its [`ArxOrders`]
/// (`auto` as a value — choose them from the recording — is the front
/// ends' to handle, before [`crate::ident::Method::set_option`]).
pub(crate) const ORDER_OPTION: OptionSpec = OptionSpec {
    key: "order",
    python: None,
    value_name: "NA,NB,NK|auto",
    kind: OptionKind::Orders,
    range: None,
    unit: None,
    help: "ARX orders `na,nb,nk` (poles, input terms, input delay in samples), or `auto` \
           (chosen from the recording by BIC; identify only)",
    requires: None,
};

/// Option `ridge` of the least-squares fits on the ARX regressor: `arx`
/// ([`crate::ident::ArxConfig::ridge`]) and `auto`'s windowed candidates.
pub(crate) const RIDGE_OPTION: OptionSpec = OptionSpec {
    key: "ridge",
    python: None,
    value_name: "R",
    kind: OptionKind::Float,
    range: Some(OptionRange::at_least(0.0)),
    unit: None,
    help: "ridge of the least squares, relative to the regressors' scale (arx: on the \
           column-normalised coefficients; 0 = none)",
    requires: None,
};

/// Largest accepted `na` and `nb` (guards against absurd allocations).
pub const MAX_ARX_ORDER: usize = 64;

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
    /// `na = 8, nb = 8, nk = 1` (chosen on the virtual rig, see [`ArxConfig`](crate::ident::ArxConfig)).
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
    let w = signals.window(
        window.end..horizon.end,
        lag,
        "ARX window (past samples + window)",
    )?;
    let base = w.start;
    let y = &w.position[..window.end - base];
    let u = w.command;
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

/// An error naming the first non-finite value of `v` (`channel`, absolute
/// index `offset + i`), if any.
pub(crate) fn first_non_finite(v: &[f64], offset: usize, channel: &str) -> Result<()> {
    match v.iter().position(|x| !x.is_finite()) {
        Some(i) => Err(Error::NonFinite {
            channel: channel.to_string(),
            index: offset + i,
            value: v[i],
        }),
        None => Ok(()),
    }
}
