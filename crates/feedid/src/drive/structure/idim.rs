//! Inverse-dynamics least squares (IDIM-LS) of a rigid axis, the
//! cross-check of an output-error fit when the force (or the controller
//! output times the drive gain) is measured beside the position, as the
//! EMPS benchmark's reference model was obtained:
//!
//! ```text
//! F[k] = M·q̈[k] + Fv·q̇[k] + Fc·sign(q̇[k]) + F0
//! ```
//!
//! The position and the force are filtered alike by a zero-phase
//! Butterworth low-pass ([`crate::lti::filtfilt`], 4th order, default
//! cutoff 100 Hz), the velocity and acceleration taken by central
//! differences, the rows kept every `decimation`-th sample (default 10) and
//! where the axis moves faster than 1 % of its top speed (the sign of a
//! velocity at rest is noise), and the four parameters solved by QR
//! ([`crate::solve::lstsq`]), with standard errors `σ²·(AᵀA)⁻¹`.

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use crate::error::{Error, Result};
use crate::lti::{butterworth_lowpass, filtfilt};
use crate::solve::lstsq;

/// Settings of [`inverse_dynamics`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IdimConfig {
    /// Cutoff of the zero-phase low-pass \[Hz\]; default 100.
    pub cutoff_hz: f64,
    /// Order of the Butterworth filter; default 4.
    pub order: usize,
    /// Keep every `decimation`-th row; default 10.
    pub decimation: usize,
}

impl Default for IdimConfig {
    fn default() -> Self {
        Self {
            cutoff_hz: 100.0,
            order: 4,
            decimation: 10,
        }
    }
}

/// The estimates of [`inverse_dynamics`], each with its standard error.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct IdimFit {
    /// Mass `M` \[kg\] and its standard error.
    pub mass: (f64, f64),
    /// Viscous friction `Fv` \[N·s/m\].
    pub viscous: (f64, f64),
    /// Coulomb friction `Fc` \[N\].
    pub coulomb: (f64, f64),
    /// Constant force `F0` \[N\].
    pub offset: (f64, f64),
    /// Rows of the regression.
    pub rows: usize,
    /// Rms of the force residual \[N\].
    pub residual_rms: f64,
}

/// Inverse-dynamics least squares of `force` \[N\] on the `position` \[m\]
/// sampled at `rate_hz` (module doc).
///
/// ```
/// use feedid::drive::{inverse_dynamics, IdimConfig};
/// // a known axis: F = 10·q̈ + 50·q̇ + 3·sign(q̇) − 1 on a slow sine
/// let rate = 1000.0;
/// let q: Vec<f64> = (0..5000).map(|k| 0.01 * (k as f64 / rate * 3.0).sin()).collect();
/// let f: Vec<f64> = (0..5000)
///     .map(|k| {
///         let t = k as f64 / rate;
///         let (v, a) = (0.03 * (3.0 * t).cos(), -0.09 * (3.0 * t).sin());
///         10.0 * a + 50.0 * v + 3.0 * v.signum() - 1.0
///     })
///     .collect();
/// let fit = inverse_dynamics(&q, &f, rate, &IdimConfig::default()).unwrap();
/// assert!((fit.mass.0 - 10.0).abs() < 0.05 && (fit.coulomb.0 - 3.0).abs() < 0.05);
/// ```
pub fn inverse_dynamics(
    position: &[f64],
    force: &[f64],
    rate_hz: f64,
    config: &IdimConfig,
) -> Result<IdimFit> {
    if position.len() != force.len() {
        return Err(Error::LengthMismatch {
            what: "position and force",
            expected: position.len(),
            actual: force.len(),
        });
    }
    for (channel, v) in [("position", position), ("force", force)] {
        if let Some((index, &value)) = v.iter().enumerate().find(|(_, x)| !x.is_finite()) {
            return Err(Error::NonFinite {
                channel: channel.to_string(),
                index,
                value,
            });
        }
    }
    if config.decimation == 0 {
        return Err(Error::InvalidParameter {
            name: "decimation",
            value: 0.0,
            reason: "must be at least 1",
        });
    }
    let filter = butterworth_lowpass(config.order, config.cutoff_hz, rate_hz)?;
    let q = filtfilt(&filter, position);
    let f = filtfilt(&filter, force);
    let n = q.len();
    let dt = 1.0 / rate_hz;
    let v: Vec<f64> = (0..n)
        .map(|k| {
            if k == 0 || k + 1 == n {
                0.0
            } else {
                (q[k + 1] - q[k - 1]) / (2.0 * dt)
            }
        })
        .collect();
    let top = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    // rows away from the ends (the differences and the filter's edges) and
    // where the axis moves
    let edge = (rate_hz / config.cutoff_hz).ceil() as usize + 2;
    let rows: Vec<usize> = (edge..n.saturating_sub(edge))
        .step_by(config.decimation)
        .filter(|&k| v[k].abs() > 0.01 * top)
        .collect();
    if rows.len() < 8 {
        return Err(Error::TooFewSamples {
            what: "moving samples for inverse dynamics",
            needed: 8,
            actual: rows.len(),
        });
    }
    let m = rows.len();
    let mut a = DMatrix::zeros(m, 4);
    let mut b = DVector::zeros(m);
    for (i, &k) in rows.iter().enumerate() {
        let acc = (v[k + 1] - v[k - 1]) / (2.0 * dt);
        a[(i, 0)] = acc;
        a[(i, 1)] = v[k];
        a[(i, 2)] = v[k].signum();
        a[(i, 3)] = 1.0;
        b[i] = f[k];
    }
    let sol = lstsq(&a, &b)?;
    let x = &sol.x;
    let r = &b - &a * x;
    let sigma2 = r.norm_squared() / (m - 4).max(1) as f64;
    let std: Vec<f64> = match a.clone().qr().r().try_inverse() {
        Some(ri) => {
            let cov = &ri * ri.transpose() * sigma2;
            (0..4).map(|i| cov[(i, i)].max(0.0).sqrt()).collect()
        }
        None => vec![f64::INFINITY; 4],
    };
    Ok(IdimFit {
        mass: (x[0], std[0]),
        viscous: (x[1], std[1]),
        coulomb: (x[2], std[2]),
        offset: (x[3], std[3]),
        rows: m,
        residual_rms: (r.norm_squared() / m as f64).sqrt(),
    })
}
