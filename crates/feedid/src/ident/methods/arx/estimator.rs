//! The windowed ARX estimator: per window, the sliding factor updated or
//! recomputed, the ridge least squares solved in deviation coordinates, the
//! model checked, and the k-step prediction.

// Negated comparisons are deliberate (they reject NaN); index loops mirror the
// matrix formulas.
#![allow(
    clippy::neg_cmp_op_on_partial_ord,
    clippy::needless_range_loop,
    clippy::too_many_arguments
)]

use std::ops::Range;

use serde::Serialize;

use super::config::ArxConfig;
use super::factor::SlidingFactor;
use crate::error::{Error, Result};
use crate::ident::engine::rate_changed;
use crate::ident::engine::{Estimator, PredictStatus, Signals, WindowFit};
use crate::ident::methods::regressor::{dc_gain, poles_inside, predict_horizon, MAX_ARX_ORDER};
use crate::ident::model::LinearModel;
use crate::solve::{
    hessenberg_condition, lstsq_hessenberg_view, lstsq_in_place, HessenbergWorkspace, LstsqOptions,
    QrWorkspace, Termination,
};

/// Diagnostics of the last ARX window.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ArxDiagnostics {
    /// Whether the window's model was accepted (false: fallback or failure).
    pub accepted: bool,
    /// Why the model was not accepted (`""` when accepted).
    pub reason: &'static str,
    /// Condition estimate of the column-scaled regression: `max|T_kk|/min|T_kk|`
    /// of its triangular factor (with the default ridge and no
    /// [`ArxConfig::max_condition`] the factor is not pivoted, so this is a
    /// rougher lower bound than the pivoted one used otherwise).
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
    hess: HessenbergWorkspace,
    /// Scratch: squared column norms of the factor, the ridge per unknown.
    colnorm2: Vec<f64>,
    lambda: Vec<f64>,
    small_a: Vec<f64>,
    small_b: Vec<f64>,
    z: Vec<f64>,
    theta: Vec<f64>,
    has_model: bool,
    scratch: Vec<f64>,
    past: Vec<f64>,
    diagnostics: Option<ArxDiagnostics>,
    /// Samples (absolute) checked finite while the factor stayed valid.
    checked: Range<usize>,
    /// The last window was solved without a condition estimate; the factor still holds it.
    condition_pending: bool,
    /// Sample interval the model was learnt at \[s\] (0 before the first fit).
    dt: f64,
}

impl ArxEstimator {
    pub(super) fn new(config: ArxConfig) -> Self {
        let n = config.orders.n_params();
        let p = n + 2;
        Self {
            config,
            factor: SlidingFactor::new(&config.orders),
            ws: QrWorkspace::new(n + 1),
            hess: HessenbergWorkspace::new(n + 1),
            colnorm2: vec![0.0; p.div_ceil(4) * 4],
            lambda: vec![0.0; n + 1],
            small_a: vec![0.0; p * (n + 1)],
            small_b: vec![0.0; p],
            z: vec![0.0; n + 1],
            theta: vec![0.0; n + 1],
            has_model: false,
            scratch: vec![0.0; config.orders.na + 1],
            past: Vec::new(),
            diagnostics: None,
            checked: 0..0,
            condition_pending: false,
            dt: 0.0,
        }
    }

    /// Whether the window's problem is solved from the regularised factor by
    /// [`lstsq_hessenberg`] (a ridge and no condition limit: the defaults).
    fn hessenberg(config: &ArxConfig) -> bool {
        config.ridge > 0.0 && config.max_condition == f64::INFINITY
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
    ///
    /// With the default settings the window's condition estimate is not
    /// needed by the fit; it is computed here, from the window's factor, on
    /// request (`O(n²)`, allocates).
    pub fn diagnostics(&self) -> Option<ArxDiagnostics> {
        let mut d = self.diagnostics?;
        if self.condition_pending {
            let n = self.config.orders.n_params();
            let nr = n + usize::from(self.config.offset);
            let mut h = vec![0.0; (n + 1) * nr];
            let mut colnorm = vec![1.0; nr];
            hessenberg_rows(&self.factor, n, self.config.offset, &mut h, &mut colnorm);
            d.condition = hessenberg_condition(n + 1, nr, &h, &mut HessenbergWorkspace::new(nr))
                .unwrap_or(f64::INFINITY);
        }
        Some(d)
    }

    /// Bring the factor to `rows` in the frame `reference`; returns whether
    /// the two stacks were used (false: factored from scratch).
    fn update_factor(
        &mut self,
        y: &[f64],
        u: &[f64],
        base: usize,
        rows: Range<usize>,
        reference: f64,
    ) -> bool {
        let orders = self.config.orders;
        self.factor.update(
            &orders,
            y,
            u,
            base,
            rows,
            reference,
            self.config.sliding,
            self.config.refactor_every,
        )
    }

    /// Solve the window's ridge problem from the factor (frame = the
    /// reference): `z[..=n]` the coefficients `[θ, c]` (unscaled); returns
    /// the condition estimate (`NaN` where it is left to
    /// [`ArxEstimator::diagnostics`]), the numerical rank and the residual
    /// norm.
    ///
    /// With a ridge and no condition limit the factor's columns already form
    /// an upper-Hessenberg matrix ([`lstsq_hessenberg`], `n³/3 + O(n²)`);
    /// otherwise the pivoted Householder QR of the same small matrix reveals
    /// the rank and estimates the condition ([`lstsq_in_place`]).
    fn solve_window(&mut self) -> Result<(f64, usize, f64)> {
        let n = self.config.orders.n_params();
        let offset = self.config.offset;
        let nr = n + usize::from(offset);
        let p = self.factor.p;
        if Self::hessenberg(&self.config) {
            // Rows 0 ..= n of R from column `first` on are [H | b] for the
            // unknowns β_j = S_j·θ_j/S_t (S the column scales, S_t the
            // target's): upper Hessenberg without the offset (row 0 is
            // dense), triangular with it. The window's ridge ρ·d_j²·θ_j² is
            // ρ·c_j²·β_j² with c_j the norm of R's column j.
            let f = &self.factor;
            let first = usize::from(!offset);
            let t = n + 1;
            let c2 = &mut self.colnorm2[..f.ps];
            f.column_norms2(c2);
            for (l, &c) in self.lambda[..nr].iter_mut().zip(&c2[first..]) {
                *l = self.config.ridge * c;
            }
            let info = lstsq_hessenberg_view(
                n + 1,
                nr,
                &f.r,
                f.ps,
                first,
                &self.lambda[..nr],
                &mut self.z[..nr],
                &mut self.hess,
            )?;
            // θ_j = β_j·S_t/S_j, in estimator order (offset last)
            let z = &mut self.z;
            let scale = &f.scale;
            if offset {
                let c = z[0] * scale[t] / scale[0];
                for j in 0..n {
                    z[j] = z[j + 1] * scale[t] / scale[j + 1];
                }
                z[n] = c;
            } else {
                for j in 0..n {
                    z[j] *= scale[t] / scale[j + 1];
                }
                z[n] = 0.0;
            }
            let last = f.at(t, t);
            let residual = (info.residual_norm.powi(2) + last * last).sqrt() * scale[t];
            return Ok((f64::NAN, nr, residual));
        }
        let f = &self.factor;
        // regressor columns 0..n (ψ), n (ones, with an offset), then the target
        for j in 0..=n {
            for i in 0..p {
                let v = f.rs(i, j + 1);
                if j < n {
                    self.small_a[i + j * p] = v;
                } else {
                    self.small_b[i] = v;
                }
            }
        }
        if offset {
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
        let info = lstsq_in_place(
            p,
            nr,
            &mut self.small_a[..p * nr],
            &mut self.small_b,
            &mut self.z[..nr],
            &mut self.ws,
            &opts,
        )?;
        for j in 0..nr {
            self.z[j] /= colscale[j];
        }
        if !offset {
            self.z[n] = 0.0;
        }
        Ok((info.cond_estimate, info.rank, info.residual_norm))
    }
}

/// The window's regression from the factor `f` as an upper-Hessenberg
/// matrix for [`lstsq_hessenberg`]: unknowns `[ones (offset only), ψ_1 …
/// ψ_n]` in the coordinates `z_j = c_j·S_j·θ_j/S_t` (`c_j` the norm of the
/// factor's column, `S` the column scales, `S_t` the target's), rows
/// `0 ..= n` of `R` with each column scaled to unit norm, into `h`
/// (row-major `(n+1) × nr`), the `c_j` into `colnorm`.
fn hessenberg_rows(f: &SlidingFactor, n: usize, offset: bool, h: &mut [f64], colnorm: &mut [f64]) {
    let nr = n + usize::from(offset);
    let first = usize::from(!offset);
    let m = n + 1;
    let h = &mut h[..m * nr];
    for (jj, col) in (first..=n).enumerate() {
        let ss: f64 = (0..=col).map(|i| f.at(i, col).powi(2)).sum();
        let nrm = ss.sqrt();
        let inv = if nrm > 0.0 { 1.0 / nrm } else { 1.0 };
        colnorm[jj] = if nrm > 0.0 { nrm } else { 1.0 };
        for i in 0..m {
            h[i * nr + jj] = if i <= col { f.at(i, col) * inv } else { 0.0 };
        }
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
        self.factor.invalidate();
        self.has_model = false;
        self.diagnostics = None;
        self.checked = 0..0;
        self.condition_pending = false;
        self.dt = 0.0;
    }

    /// The window's factor pairs samples: it is rebuilt after the gap; the
    /// model (the fallback of an uninformative window) is kept.
    fn gap(&mut self) {
        self.factor.invalidate();
        self.checked = 0..0;
        self.condition_pending = false;
    }

    fn fit(
        &mut self,
        signals: &Signals<'_>,
        window: Range<usize>,
        coef: &mut [f64],
    ) -> Result<WindowFit> {
        if rate_changed(self.dt, signals.dt()) {
            self.reset();
        }
        self.dt = signals.dt();
        let orders = self.config.orders;
        let n = orders.n_params();
        let lag = orders.lag();
        signals.window(window.clone(), lag, "ARX window (past samples + window)")?;
        if window.is_empty() {
            return Err(Error::TooFewSamples {
                what: "ARX window",
                needed: 1,
                actual: 0,
            });
        }
        // slices indexed by (absolute index − base)
        let base = window.start - lag;
        let w = signals.window(base..window.end, 0, "ARX window (past samples + window)")?;
        let (y, u) = (w.position, w.command);
        // samples checked for an earlier window of the same factor are not checked again
        let known = self.factor.valid && self.checked.start <= base;
        let from = if known {
            self.checked.end.clamp(base, window.end)
        } else {
            base
        };
        for (ch, v) in [("position", y), ("command", u)] {
            if let Some(i) = v[from - base..].iter().position(|v| !v.is_finite()) {
                self.factor.invalidate();
                return Err(Error::NonFinite {
                    channel: ch.to_string(),
                    index: from + i,
                    value: f64::NAN,
                });
            }
        }
        self.checked = if known {
            self.checked.start..self.checked.end.max(window.end)
        } else {
            base..window.end
        };
        let reference = y[window.end - 1 - base];
        let slid = self.update_factor(y, u, base, window.clone(), reference);

        let f = &self.factor;
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

        let mut residual_rms = 0.0;
        let mut reason = "";
        self.condition_pending = false;
        if !(excitation >= self.config.min_excitation) || excitation == 0.0 {
            reason = "standstill (command not exciting)";
        } else {
            let nr = n + usize::from(self.config.offset);
            match self.solve_window() {
                Err(_) => reason = "rank deficient",
                Ok((condition, rank, residual_norm)) => {
                    diag.condition = condition;
                    self.condition_pending = condition.is_nan();
                    residual_rms = residual_norm / m.sqrt();
                    let th = &self.z[..=n];
                    let g = dc_gain(&orders, th);
                    diag.dc_gain = g;
                    let (lo, hi) = self.config.dc_gain_bounds;
                    let deficient = (self.config.ridge == 0.0 && rank < nr)
                        || (self.config.max_condition < f64::INFINITY
                            && !(condition <= self.config.max_condition));
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
        let residual_rms = if residual_rms.is_finite() {
            residual_rms
        } else {
            0.0
        };
        Ok(if diag.accepted {
            WindowFit::identified(residual_rms, 0, Termination::Exact)
        } else {
            WindowFit::fallback(residual_rms, 0)
        })
    }

    fn predict(
        &mut self,
        signals: &Signals<'_>,
        window: Range<usize>,
        horizon: Range<usize>,
        out: &mut [f64],
    ) -> Result<PredictStatus> {
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
        )?;
        Ok(PredictStatus::Predicted)
    }
}
