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
use crate::ident::methods::regressor::{dc_gain, poles_inside, predict_horizon, MAX_ARX_ORDER};
use crate::ident::{Estimator, LinearModel, PredictStatus, Signals, WindowFit};
use crate::solve::{lstsq_in_place, LstsqOptions, QrWorkspace, Termination};

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
    pub(super) fn new(config: ArxConfig) -> Self {
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
        signals.window(window.clone(), lag, "ARX window (past samples + window)")?;
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
            if old < window.start && old >= signals.offset() + lag {
                base = base.min(old - lag);
            } else if old < window.start {
                self.factor.valid = false;
            }
        }
        let w = signals.window(base..window.end, 0, "ARX window (past samples + window)")?;
        let (y, u) = (w.position, w.command);
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
