//! The global output-error fit over a whole recording ([`fit_oe`]), and
//! through the gaps of one with dropped samples ([`fit_oe_measured`]): the
//! start from SRIVC (several where it cycles, refined in parallel), then
//! Levenberg–Marquardt on the free-run simulation error; see the module doc
//! of `estimator` for the model, its scaling and the references.

use nalgebra::DMatrix;
use rayon::prelude::*;

use super::companion::{is_hurwitz, output, Companion};
use super::estimator::{check_signals, initial_estimate, lm_config, OeConfig, Structure};
use crate::error::{Error, Result};
use crate::ident::model::LinearModel;
use crate::lti::TransferFunction;
use crate::solve::{LevenbergMarquardt, LmReport};
use nalgebra::Complex;

/// A global output-error model fitted over a whole recording ([`fit_oe`]).
#[derive(Debug, Clone, PartialEq)]
pub struct OeFit {
    /// The identified model, `LinearModel::Continuous` with monic denominator.
    pub model: LinearModel,
    /// Numerator `N{nz} … N0` (descending powers of s).
    pub num: Vec<f64>,
    /// Denominator `D{np} … D0` (descending powers of s, `D{np}` = 1).
    pub den: Vec<f64>,
    /// Standard errors of `num`.
    pub num_std: Vec<f64>,
    /// Standard errors of `den` (0 for the fixed leading 1).
    pub den_std: Vec<f64>,
    /// Scaled parameters `[α_{np−1} … α₀, β_nz … β₀]`.
    pub theta: Vec<f64>,
    /// Standard errors of `theta`.
    pub theta_std: Vec<f64>,
    /// Reference frequency `ω_r` \[rad/s\] of the scaled parameters.
    pub time_scale: f64,
    /// Levenberg–Marquardt report.
    pub report: LmReport,
    /// Free-run simulation fit \[%\] (NRMSE, 100 = perfect).
    pub fit_percent: f64,
    /// RMS of the simulation error \[m\].
    pub residual_rms: f64,
    /// SRIVC iterations of the initial estimate (0 with a user initial model).
    pub srivc_iterations: usize,
}

impl OeFit {
    /// Poles of the identified model \[rad/s\].
    pub fn poles(&self) -> Result<Vec<Complex<f64>>> {
        TransferFunction::new(self.num.clone(), self.den.clone())?.poles()
    }

    /// Free-run simulation on a command sampled every `dt` \[s\], from rest at `command[0]`.
    pub fn simulate(&self, command: &[f64], dt: f64) -> Result<Vec<f64>> {
        self.model.simulate_at(command, dt)
    }
}

/// Fit a continuous-time output-error model `N(s)/D(s)` over a whole
/// recording: command `u` \[m\], measured position `y` \[m\], sample interval
/// `dt` \[s\]. The recording should start at rest (see the module doc).
/// Where SRIVC cycles, each of its best-fitting iterates is refined (in
/// parallel, on rayon's pool) and the smallest residual wins, the first of
/// equals in a fixed order: the result does not depend on the threads.
///
/// Errors: [`Error::LengthMismatch`], [`Error::TooFewSamples`] (fewer than
/// `2·(np + nz + 1) + 2` samples), [`Error::NonFinite`], [`Error::InvalidParameter`],
/// [`Error::Singular`] for data without excitation, [`Error::InvalidModel`]
/// if no stable model is found.
///
/// ```
/// use feedid::ident::{fit_oe, OeConfig};
/// use feedid::lti::TransferFunction;
/// let g = TransferFunction::new(vec![2.0e4], vec![1.0, 300.0, 2.0e4]).unwrap();
/// let dt = 1e-3;
/// let u: Vec<f64> = (0..800).map(|k| if (k / 50) % 2 == 1 { 1e-3 } else { 0.0 }).collect();
/// let y = g.to_state_space().unwrap().discretize_zoh(dt).unwrap().simulate(&u, None).unwrap();
/// let fit = fit_oe(&u, &y, dt, &OeConfig { poles: 2, zeros: 0, ..OeConfig::default() }).unwrap();
/// assert!((fit.den[1] / 300.0 - 1.0).abs() < 1e-8);
/// assert!((fit.den[2] / 2.0e4 - 1.0).abs() < 1e-8);
/// assert!(fit.fit_percent > 99.999);
/// ```
pub fn fit_oe(u: &[f64], y: &[f64], dt: f64, cfg: &OeConfig) -> Result<OeFit> {
    fit_rows(u, y, dt, None, cfg)
}

/// [`fit_oe`] through the gaps of a recording with dropped samples: `u`
/// and `y` on the regular time grid through the gaps (as
/// [`crate::Recording::fill_gaps`] gives them: the command interpolated
/// where samples were dropped, and the position too, which only the
/// initial estimate sees), `measured` the grid indices of the samples that
/// were measured (ascending, as [`crate::Recording::grid_indices`]). The
/// model is simulated over the whole grid and its error is taken at the
/// measured samples only: the fit, its standard errors (`N` = the measured
/// samples), [`OeFit::fit_percent`] and [`OeFit::residual_rms`] are over
/// them. With every index measured it is [`fit_oe`]. Errors: as
/// [`fit_oe`] (with the measured samples counted); indices not ascending
/// or beyond the grid ([`Error::InvalidParameter`]).
///
/// ```
/// use feedid::ident::{fit_oe_measured, OeConfig};
/// use feedid::lti::TransferFunction;
/// let g = TransferFunction::new(vec![2.0e4], vec![1.0, 300.0, 2.0e4]).unwrap();
/// let dt = 1e-3;
/// let u: Vec<f64> = (0..800).map(|k| if (k / 50) % 2 == 1 { 1e-3 } else { 0.0 }).collect();
/// let mut y = g.to_state_space().unwrap().discretize_zoh(dt).unwrap().simulate(&u, None).unwrap();
/// // samples 300 … 304 were lost: what stands there is never compared
/// y[300..305].fill(1.0);
/// let measured: Vec<usize> = (0..800).filter(|k| !(300..305).contains(k)).collect();
/// let cfg = OeConfig { poles: 2, zeros: 0, ..OeConfig::default() };
/// let fit = fit_oe_measured(&u, &y, dt, &measured, &cfg).unwrap();
/// assert!((fit.den[1] / 300.0 - 1.0).abs() < 1e-6);
/// assert!(fit.fit_percent > 99.99);
/// ```
pub fn fit_oe_measured(
    u: &[f64],
    y: &[f64],
    dt: f64,
    measured: &[usize],
    cfg: &OeConfig,
) -> Result<OeFit> {
    if let Some(w) = measured.windows(2).find(|w| w[1] <= w[0]) {
        return Err(Error::InvalidParameter {
            name: "measured",
            value: w[1] as f64,
            reason: "grid indices of the measured samples must be strictly ascending",
        });
    }
    if let Some(&k) = measured.last().filter(|&&k| k >= y.len()) {
        return Err(Error::InvalidParameter {
            name: "measured",
            value: k as f64,
            reason: "grid index beyond the recording",
        });
    }
    fit_rows(u, y, dt, Some(measured), cfg)
}

/// [`fit_oe`] with the residual at the grid indices `rows` (all: `None`).
fn fit_rows(
    u: &[f64],
    y: &[f64],
    dt: f64,
    rows: Option<&[usize]>,
    cfg: &OeConfig,
) -> Result<OeFit> {
    cfg.validate()?;
    let p = cfg.parameter_count();
    check_signals(u, y, dt, 2 * p + 2)?;
    let len = rows.map_or(u.len(), <[usize]>::len);
    if len < 2 * p + 2 {
        return Err(Error::TooFewSamples {
            what: "output-error fit (measured samples)",
            needed: 2 * p + 2,
            actual: len,
        });
    }
    let (starts, srivc_iterations) = initial_estimate(u, y, dt, cfg)?;
    let y_rms = crate::stats::rms(y).max(f64::MIN_POSITIVE);
    let penalty = 1e6 * y_rms;
    // each start refined; the stable fit with the smallest residual wins
    // (the first of equals)
    // (the starts are independent: refined in parallel, compared in order,
    // so the result is the sequential one)
    let refined: Vec<_> = starts
        .into_par_iter()
        .map(|(st, mut theta)| {
            global_lm(
                u,
                y,
                rows,
                dt,
                &st,
                &mut theta,
                penalty,
                cfg,
                cfg.max_iterations,
            )
            .map(|(report, lm)| (st, theta, report, lm))
        })
        .collect();
    let mut best: Option<(Structure, Vec<f64>, LmReport, LevenbergMarquardt)> = None;
    let mut failure = None;
    for fit in refined {
        let (st, theta, report, lm) = match fit {
            Ok(r) => r,
            Err(e) => {
                failure.get_or_insert(e);
                continue;
            }
        };
        let stable = is_hurwitz(&theta[..st.n]) && theta.iter().all(|v| v.is_finite());
        let better = best
            .as_ref()
            .is_none_or(|b| report.residual_norm < b.2.residual_norm);
        if stable && better {
            best = Some((st, theta, report, lm));
        }
    }
    let Some((st, theta, report, lm)) = best else {
        return Err(failure.unwrap_or(Error::InvalidModel {
            reason: "output-error fit did not find a stable model",
        }));
    };
    let (n, m) = (st.n, st.m);
    // standard errors from the Jacobian at the solution
    let jac = DMatrix::from_column_slice(len, p, lm.jacobian());
    let sse = report.residual_norm * report.residual_norm;
    let dof = (len - p) as f64;
    let sigma2 = sse / dof;
    let theta_std = standard_errors(&jac, sigma2);
    let mut num = vec![0.0; m + 1];
    let mut den = vec![0.0; n + 1];
    st.physical(&theta, &mut num, &mut den);
    let mut den_std = vec![0.0; n + 1];
    let mut num_std = vec![0.0; m + 1];
    for k in 0..n {
        den_std[k + 1] = theta_std[k] * st.physical_factor(k);
    }
    for k in 0..=m {
        num_std[k] = theta_std[n + k] * st.physical_factor(n + k);
    }
    let tf = TransferFunction::new(num.clone(), den.clone())?;
    // over the compared samples
    let compared = || (0..len).map(|j| y[rows.map_or(j, |r| r[j])]);
    let mean = compared().sum::<f64>() / len as f64;
    let spread = compared()
        .map(|v| (v - mean) * (v - mean))
        .sum::<f64>()
        .sqrt();
    let fit_percent = if spread > 0.0 {
        100.0 * (1.0 - report.residual_norm / spread)
    } else {
        0.0
    };
    Ok(OeFit {
        model: LinearModel::continuous(&tf),
        num,
        den,
        num_std,
        den_std,
        theta,
        theta_std,
        time_scale: st.omega,
        report,
        fit_percent,
        residual_rms: (sse / len as f64).sqrt(),
        srivc_iterations,
    })
}

/// Levenberg–Marquardt of the global output-error fit from `theta` (in
/// place), at most `iterations`, the error taken at the grid indices `rows`
/// (all: `None`); the solver is returned for its Jacobian.
#[allow(clippy::too_many_arguments)]
fn global_lm(
    u: &[f64],
    y: &[f64],
    rows: Option<&[usize]>,
    dt: f64,
    st: &Structure,
    theta: &mut [f64],
    penalty: f64,
    cfg: &OeConfig,
    iterations: usize,
) -> Result<(LmReport, LevenbergMarquardt)> {
    let (n, m) = (st.n, st.m);
    let (len, u0) = (u.len(), u[0]);
    let h = st.omega * dt;
    let mut comp = Companion::new(n);
    let mut x = vec![0.0; n];
    let mut residual = |th: &[f64], r: &mut [f64]| {
        let ok = is_hurwitz(&th[..n]) && comp.discretize(&th[..n], h).is_ok();
        if !ok {
            r.fill(penalty);
            return;
        }
        let g = th[n + m] / th[n - 1];
        x.fill(0.0);
        match rows {
            None => {
                for k in 0..len {
                    r[k] = output(&th[n..], &x) + g * u0 - y[k];
                    comp.step_zoh(&mut x, u[k] - u0);
                }
            }
            // simulated over the whole grid, compared where measured
            Some(rows) => {
                let mut next = rows.iter().copied().enumerate().peekable();
                for k in 0..len {
                    let Some(&(j, at)) = next.peek() else { break };
                    if at == k {
                        r[j] = output(&th[n..], &x) + g * u0 - y[k];
                        next.next();
                    }
                    comp.step_zoh(&mut x, u[k] - u0);
                }
            }
        }
        if r.iter().any(|v| !v.is_finite()) {
            r.fill(penalty);
        }
    };
    let mut lm = LevenbergMarquardt::new(rows.map_or(len, <[usize]>::len), st.p());
    let report = lm.minimize(&mut residual, theta, &lm_config(cfg, iterations))?;
    Ok((report, lm))
}

/// `sqrt(diag(σ²·(JᵀJ)⁻¹))` by SVD; directions with zero singular value give ∞.
fn standard_errors(jac: &DMatrix<f64>, sigma2: f64) -> Vec<f64> {
    let p = jac.ncols();
    let svd = jac.clone().svd(false, true);
    let Some(vt) = svd.v_t else {
        return vec![f64::INFINITY; p];
    };
    let smax = svd.singular_values.iter().fold(0.0f64, |a, &b| a.max(b));
    (0..p)
        .map(|j| {
            let mut v = 0.0;
            for (k, &s) in svd.singular_values.iter().enumerate() {
                if s <= smax * 1e-15 {
                    if vt[(k, j)] != 0.0 {
                        return f64::INFINITY;
                    }
                    continue;
                }
                v += (vt[(k, j)] / s).powi(2);
            }
            (sigma2 * v).sqrt()
        })
        .collect()
}
