//! The batch (global) ARX fit over a whole recording, with standard errors.

// Negated comparisons are deliberate (they reject NaN); index loops mirror the
// matrix formulas.
#![allow(
    clippy::neg_cmp_op_on_partial_ord,
    clippy::needless_range_loop,
    clippy::too_many_arguments
)]

use nalgebra::DMatrix;
use serde::Serialize;

use super::config::ArxConfig;
use crate::error::{Error, Result};
use crate::ident::methods::regressor::{regressor, ArxOrders};
use crate::ident::model::LinearModel;
use crate::solve::{lstsq_in_place, LstsqOptions, QrWorkspace};

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

/// Batch ARX fit of a recording with dropped samples: the rows `k = start +
/// lag … end − 1` of every segment between the gaps (`segments`: sample
/// ranges, as [`crate::Recording::segments`]), stacked, so that no row pairs
/// samples across a gap; otherwise as [`fit_arx`] (one segment: the same
/// fit). [`ArxFit::residuals`] are the stacked rows' residuals and
/// [`ArxFit::first_row`] the first of them. Errors: as [`fit_arx`]; a
/// segment beyond the data ([`Error::LengthMismatch`]).
///
/// ```
/// use feedid::ident::{fit_arx, fit_arx_segments, ArxConfig, ArxOrders};
/// let n = 300;
/// let u: Vec<f64> = (0..n).map(|k| ((k * 7919) % 101) as f64 / 101.0 - 0.5).collect();
/// let mut y = vec![0.0; n];
/// for k in 2..n {
///     y[k] = 1.2 * y[k - 1] - 0.5 * y[k - 2] + 0.3 * u[k - 1];
/// }
/// let cfg = ArxConfig { ridge: 0.0, ..Default::default() };
/// // samples 150 and 151 lost: two segments, no row across the gap
/// let (u2, y2): (Vec<f64>, Vec<f64>) =
///     (0..n).filter(|k| !(150..152).contains(k)).map(|k| (u[k], y[k])).unzip();
/// let fit = fit_arx_segments(&u2, &y2, 1e-3, ArxOrders::new(2, 1, 1), &cfg, &[0..150, 150..298]).unwrap();
/// assert!((fit.theta[0] + 1.2).abs() < 1e-10 && (fit.theta[2] - 0.3).abs() < 1e-10);
/// assert_eq!(fit.n, 148 + 146);
/// ```
pub fn fit_arx_segments(
    u: &[f64],
    y: &[f64],
    dt: f64,
    orders: ArxOrders,
    cfg: &ArxConfig,
    segments: &[std::ops::Range<usize>],
) -> Result<ArxFit> {
    check_orders_and_lengths(u, y, orders)?;
    if let Some(r) = segments.iter().find(|r| r.end > y.len()) {
        return Err(Error::LengthMismatch {
            what: "segments (end of the last)",
            expected: y.len(),
            actual: r.end,
        });
    }
    let lag = orders.lag();
    let rows: Vec<std::ops::Range<usize>> = segments
        .iter()
        .filter(|r| r.end > r.start + lag)
        .map(|r| r.start + lag..r.end)
        .collect();
    let np = orders.n_params() + usize::from(cfg.offset);
    let m: usize = rows.iter().map(|r| r.len()).sum();
    if m <= np {
        return Err(Error::TooFewSamples {
            what: "ARX fit over the segments between dropped samples (rows > parameters)",
            needed: np + 1,
            actual: m,
        });
    }
    fit_arx_ranges(u, y, dt, orders, cfg, &rows, true)
}

/// Valid orders and one command sample per position sample.
fn check_orders_and_lengths(u: &[f64], y: &[f64], orders: ArxOrders) -> Result<()> {
    orders.validate()?;
    if u.len() != y.len() {
        return Err(Error::LengthMismatch {
            what: "command",
            expected: y.len(),
            actual: u.len(),
        });
    }
    Ok(())
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
    check_orders_and_lengths(u, y, orders)?;
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
    let rows = first_row..end;
    fit_arx_ranges(
        u,
        y,
        dt,
        orders,
        cfg,
        std::slice::from_ref(&rows),
        with_std_errors,
    )
}

/// The fit of the rows in `rows` (ranges of row indices `k ≥ lag`, more
/// rows than parameters: checked by the callers), stacked.
fn fit_arx_ranges(
    u: &[f64],
    y: &[f64],
    dt: f64,
    orders: ArxOrders,
    cfg: &ArxConfig,
    rows: &[std::ops::Range<usize>],
    with_std_errors: bool,
) -> Result<ArxFit> {
    let np = orders.n_params() + usize::from(cfg.offset);
    let m: usize = rows.iter().map(|r| r.len()).sum();
    let first_row = rows.first().map_or(orders.lag(), |r| r.start);
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
    for (row, k) in rows.iter().flat_map(|r| r.clone()).enumerate() {
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
