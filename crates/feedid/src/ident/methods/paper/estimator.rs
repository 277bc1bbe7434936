//! The paper's method as an [`Estimator`]: per window, the output and input
//! polynomials fitted by QR or the simplex in the scaled basis, mapped to
//! `N`, `D`, and the prediction over the horizon.

use std::ops::Range;

use super::basis::{affine_to_monomial, legendre_monomials};
use super::config::{
    shift_amplification, PaperConfig, PredictionMode, SimplexStart, Solver, TimeOrigin,
};
use super::polynomials::{coefficients_from_polynomials, NAMES, NC, NP, NQ};
use super::projection::{LegendreTables, Projection};
use super::simplex::{simplex_fit, Reduced};
use crate::error::{Error, Result};
use crate::ident::engine::{Estimator, PredictStatus, Signals, WindowFit};
use crate::ident::methods::regressor::first_non_finite;
use crate::lti::TransferFunction;
use crate::solve::{lstsq_fixed, LstsqInfo, NelderMead, QrWorkspace, Termination};

/// Per-window diagnostics of the last fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PaperDiagnostics {
    /// QR information of the output fit (`None` with the simplex solver).
    pub output_qr: Option<LstsqInfo>,
    /// QR information of the input fit (`None` with the simplex solver).
    pub input_qr: Option<LstsqInfo>,
    /// Growth factor `(1 + |τ_c|/h)⁷` of the change from the window basis to
    /// monomial coefficients in `τ`: roughly, the relative accuracy of `P`,
    /// `Q` (hence `N`, `D`) is this times the fit's relative accuracy.
    pub shift_amplification: f64,
    /// Relative rms of the input (command) fit residual `‖r_u‖/‖u‖`.
    pub input_residual_rel: f64,
    /// The last transfer-function prediction of this window fell back to the
    /// polynomial (identified `Tf` unusable: unstable, non-finite, improper).
    pub tf_fallback: bool,
}

/// State of the last window fit, in the scaled basis.
#[derive(Debug, Clone, Copy)]
pub(super) struct LastFit {
    /// Time origin used for `τ` \[s\].
    pub(super) origin: f64,
    /// `T = max |τ|` over the window \[s\].
    pub(super) t_scale: f64,
    /// Centre `τ_c` and half width `h` of the window in `τ` \[s\].
    pub(super) centre: f64,
    pub(super) half: f64,
    /// Output coefficients of `(τ/T)⁵·L_k(s)` (unnormalised basis).
    pub(super) out: [f64; NP],
    /// Input coefficients of `L_k(s)` (unnormalised basis).
    pub(super) inp: [f64; NQ],
    /// Identified `[N2, N1, N0, D7, …, D0]`.
    pub(super) coef: [f64; NC],
    /// Rest position and command subtracted before fitting (0 for window-local time).
    pub(super) y_ref: f64,
    pub(super) u_ref: f64,
}

/// The paper's identification method as an [`Estimator`] (name `"paper"`).
///
/// Build with [`PaperConfig::build`]. Buffers are sized by the first window
/// and grown once if a longer window comes; fitting allocates nothing after that.
#[derive(Debug, Clone)]
pub struct PaperMethod {
    pub(super) config: PaperConfig,
    /// Held position of the last window if it was a rest window.
    pub(super) rest_hold: Option<f64>,
    pub(super) tables: LegendreTables,
    pub(super) cap: usize,
    /// The window's `τ`, then its grid `s`.
    pub(super) tau: Vec<f64>,
    pub(super) data: Vec<f64>,
    pub(super) work: Vec<f64>,
    /// The window basis's QR, reused while the grid repeats.
    pub(super) projection: Projection,
    pub(super) rhs: Vec<f64>,
    pub(super) resid: Vec<f64>,
    pub(super) qr: QrWorkspace,
    pub(super) nm_out: NelderMead,
    pub(super) nm_in: NelderMead,
    pub(super) last: Option<LastFit>,
    /// Rest position at the motion start, fixed by the first motion window.
    pub(super) reference: Option<f64>,
    pub(super) diagnostics: Option<PaperDiagnostics>,
    pub(super) tf_fallbacks: usize,
    pub(super) du: Vec<f64>,
    pub(super) ysim: Vec<f64>,
}

impl PaperMethod {
    pub(super) fn new(config: PaperConfig) -> Self {
        Self {
            config,
            rest_hold: None,
            tables: LegendreTables::new(legendre_monomials()),
            cap: 0,
            tau: Vec::new(),
            data: Vec::new(),
            work: Vec::new(),
            projection: Projection::new(),
            rhs: Vec::new(),
            resid: Vec::new(),
            qr: QrWorkspace::new(NQ),
            nm_out: NelderMead::new(NP),
            nm_in: NelderMead::new(NQ),
            last: None,
            reference: None,
            diagnostics: None,
            tf_fallbacks: 0,
            du: Vec::new(),
            ysim: Vec::new(),
        }
    }

    /// The configuration this estimator was built from.
    pub fn config(&self) -> &PaperConfig {
        &self.config
    }

    /// Diagnostics of the last successful fit (`None` before the first fit).
    pub fn diagnostics(&self) -> Option<&PaperDiagnostics> {
        self.diagnostics.as_ref()
    }

    /// Number of transfer-function predictions that fell back to the
    /// polynomial since construction or [`Estimator::reset`].
    pub fn tf_fallbacks(&self) -> usize {
        self.tf_fallbacks
    }

    /// The last window's fitted output polynomial `P(τ)` at time `t` \[s\]
    /// (`None` before the first fit and after a rest window).
    pub fn fitted_position(&self, t: f64) -> Option<f64> {
        self.last
            .as_ref()
            .map(|fit| fit.y_ref + Self::eval_output(fit, t))
    }

    /// The last window's fitted input polynomial `Q(τ)` at time `t` \[s\]
    /// (`None` before the first fit).
    pub fn fitted_command(&self, t: f64) -> Option<f64> {
        self.last
            .as_ref()
            .map(|fit| fit.u_ref + Self::eval_input(fit, t))
    }

    /// A window entirely at rest (see the module doc): coefficients 0, hold the last position.
    fn rest_window(&mut self, pos: &[f64], coef: &mut [f64]) -> WindowFit {
        let hold = pos.last().copied().unwrap_or(0.0);
        coef.fill(0.0);
        self.rest_hold = Some(hold);
        self.last = None;
        self.diagnostics = None;
        let sse: f64 = pos.iter().map(|y| (y - hold) * (y - hold)).sum();
        WindowFit::fallback((sse / pos.len().max(1) as f64).sqrt(), 0)
    }

    fn ensure_capacity(&mut self, w: usize) {
        if w > self.cap {
            self.tau.resize(w, 0.0);
            self.data.resize(w, 0.0);
            self.work.resize(w, 0.0);
            self.rhs.resize(w, 0.0);
            self.resid.resize(w, 0.0);
            self.cap = w;
        }
    }

    /// Input polynomial at time `t` from a fit (Legendre series via the three-term recurrence).
    fn eval_input(fit: &LastFit, t: f64) -> f64 {
        let s = ((t - fit.origin) - fit.centre) / fit.half;
        let mut lm1 = 1.0;
        let mut l = s;
        let mut acc = fit.inp[0] + fit.inp[1] * s;
        for (k, ak) in fit.inp.iter().enumerate().skip(2) {
            let km = (k - 1) as f64;
            let next = ((2.0 * km + 1.0) * s * l - km * lm1) / (km + 1.0);
            lm1 = l;
            l = next;
            acc += ak * l;
        }
        acc
    }

    /// Polynomial prediction at time `t` from a fit (evaluated in the fit's basis).
    fn eval_output(fit: &LastFit, t: f64) -> f64 {
        let tau = t - fit.origin;
        let s = (tau - fit.centre) / fit.half;
        let l1 = s;
        let l2 = 1.5 * s * s - 0.5;
        let w = (tau / fit.t_scale).powi(5);
        w * (fit.out[0] + fit.out[1] * l1 + fit.out[2] * l2)
    }
}

impl Estimator for PaperMethod {
    fn name(&self) -> &'static str {
        "paper"
    }

    fn uses_future_command(&self) -> bool {
        self.config.prediction != PredictionMode::Polynomial
    }

    /// The paper's method is reproduced as published: its predictions are
    /// kept however far its polynomial extrapolates.
    fn checks_plausibility(&self) -> bool {
        false
    }

    fn coefficient_names(&self) -> Vec<String> {
        NAMES.iter().map(|s| s.to_string()).collect()
    }

    fn reset(&mut self) {
        self.rest_hold = None;
        self.last = None;
        self.reference = None;
        self.diagnostics = None;
        self.tf_fallbacks = 0;
    }

    fn fit(
        &mut self,
        signals: &Signals<'_>,
        window: Range<usize>,
        coef: &mut [f64],
    ) -> Result<WindowFit> {
        if coef.len() != NC {
            return Err(Error::LengthMismatch {
                what: "paper coefficients",
                expected: NC,
                actual: coef.len(),
            });
        }
        let w = window.len();
        if w < NQ {
            return Err(Error::TooFewSamples {
                what: "paper window (8 input coefficients)",
                needed: NQ,
                actual: w,
            });
        }
        let samples = signals.window(window.clone(), 0, "paper window")?;
        let (time, pos, cmd) = (samples.time, samples.position, samples.command);
        first_non_finite(time, window.start, "time")?;
        first_non_finite(pos, window.start, "position")?;
        first_non_finite(cmd, window.start, "command")?;
        if self.config.time_origin == TimeOrigin::Motion && time[w - 1] <= signals.motion_start() {
            return Ok(self.rest_window(pos, coef));
        }
        self.rest_hold = None;
        self.ensure_capacity(w);

        let (y_ref, u_ref) = self.rest_reference(signals);
        let axis = self.time_axis(signals, time)?;
        let problem = self.project(pos, cmd, y_ref, u_ref, &axis);
        let solution = match self.config.solver {
            Solver::Qr => self.solve_qr(&problem)?,
            Solver::Simplex => self.solve_simplex(&problem, time, y_ref, u_ref)?,
        };
        let (c, out, inp) = self.assemble(&solution, &problem, &axis, window.start)?;
        coef.copy_from_slice(&c);

        let in_norm = cmd
            .iter()
            .map(|v| (v - u_ref) * (v - u_ref))
            .sum::<f64>()
            .sqrt();
        self.last = Some(LastFit {
            origin: axis.origin,
            t_scale: axis.t_scale,
            centre: axis.centre,
            half: axis.half,
            out,
            inp,
            coef: c,
            y_ref,
            u_ref,
        });
        self.diagnostics = Some(PaperDiagnostics {
            output_qr: solution.out_info,
            input_qr: solution.in_info,
            shift_amplification: shift_amplification(axis.t_first, axis.t_last),
            tf_fallback: false,
            input_residual_rel: if in_norm > 0.0 {
                solution.in_sse.max(0.0).sqrt() / in_norm
            } else {
                0.0
            },
        });
        Ok(WindowFit::identified(
            (solution.out_sse.max(0.0) / w as f64).sqrt(),
            solution.iterations,
            solution.termination,
        ))
    }

    fn predict(
        &mut self,
        signals: &Signals<'_>,
        _window: Range<usize>,
        horizon: Range<usize>,
        out: &mut [f64],
    ) -> Result<PredictStatus> {
        if out.len() != horizon.len() {
            return Err(Error::LengthMismatch {
                what: "paper prediction",
                expected: horizon.len(),
                actual: out.len(),
            });
        }
        let hz = signals.window(horizon.clone(), 0, "paper horizon")?;
        if let Some(hold) = self.rest_hold {
            out.fill(hold);
            return Ok(PredictStatus::Predicted);
        }
        let fit = self.last.ok_or(Error::InvalidModel {
            reason: "paper: predict called before a successful fit",
        })?;
        let time = hz.time;
        for (o, &t) in out.iter_mut().zip(time) {
            *o = fit.y_ref + Self::eval_output(&fit, t);
        }
        if self.config.prediction == PredictionMode::TransferFunction {
            let h = horizon.len();
            if self.du.len() < h {
                self.du.resize(h, 0.0);
                self.ysim.resize(h, 0.0);
            }
            let cmd = hz.command;
            for ((d, &u), &t) in self.du.iter_mut().zip(cmd).zip(time) {
                *d = u - fit.u_ref - Self::eval_input(&fit, t);
            }
            let ok = tf_response(&fit.coef, signals.dt(), &self.du[..h], &mut self.ysim[..h])
                .is_ok()
                && out
                    .iter()
                    .zip(&self.ysim[..h])
                    .all(|(o, y)| (o + y).is_finite());
            if ok {
                for (o, y) in out.iter_mut().zip(&self.ysim[..h]) {
                    *o += y;
                }
            } else {
                self.tf_fallbacks += 1;
                if let Some(d) = self.diagnostics.as_mut() {
                    d.tf_fallback = true;
                }
            }
        }
        if let Some(i) = out.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                channel: "paper prediction".to_string(),
                index: horizon.start + i,
                value: out[i],
            });
        }
        Ok(PredictStatus::Predicted)
    }
}

/// The window's time axis: `τ = t − origin`, its first and last value, the
/// centre `τ_c` and half width `h`, and `T = max |τ|` \[s\].
#[derive(Debug, Clone, Copy)]
struct TimeAxis {
    origin: f64,
    t_first: f64,
    t_last: f64,
    centre: f64,
    half: f64,
    t_scale: f64,
}

/// A window's two least-squares problems in the projected coordinates: the
/// data's Legendre coefficients, what the projection leaves, and the output
/// basis with unit-norm columns (and their norms).
struct Problem {
    w: usize,
    cy: [f64; NQ],
    cu: [f64; NQ],
    rest_y: f64,
    rest_u: f64,
    m_out: [f64; NQ * NP],
    norm_out: [f64; NP],
    rank_tol: Option<f64>,
}

/// Both problems solved, in the coordinates of the unit-norm bases, with
/// what the solver reports.
struct Solution {
    z_out: [f64; NP],
    z_in: [f64; NQ],
    out_sse: f64,
    in_sse: f64,
    iterations: usize,
    termination: Termination,
    out_info: Option<LstsqInfo>,
    in_info: Option<LstsqInfo>,
}

/// The steps of a window fit ([`Estimator::fit`]): the rest reference, the
/// time axis and grid, the projected problem, its solution by QR or the
/// simplex, and the coefficients `N`, `D`.
impl PaperMethod {
    /// The position and command subtracted before fitting.
    fn rest_reference(&mut self, signals: &Signals<'_>) -> (f64, f64) {
        match self.config.time_origin {
            TimeOrigin::Window => (0.0, 0.0),
            TimeOrigin::Motion => {
                // The output model has no constant term, so positions are
                // measured from the rest position at the motion start. The
                // input model has one (Q0 = D7), so the command is fitted as
                // given, as in the paper.
                // The reference is fixed by the first motion window, which
                // holds the motion-start sample when windows overlap or touch
                // (hop ≤ W), in batch and streaming alike. If the recording
                // starts in motion (no sample at or before the motion start),
                // positions are taken as given.
                let y_ref = *self.reference.get_or_insert_with(|| {
                    let all = signals.all();
                    all.time
                        .iter()
                        .rposition(|&t| t <= signals.motion_start())
                        .map_or(0.0, |k| all.position[k])
                });
                (y_ref, 0.0)
            }
        }
    }

    /// The time axis of the window, the grid `s_i` in `self.tau`, and the
    /// projection on it (the cached one if the grid repeats).
    fn time_axis(&mut self, signals: &Signals<'_>, time: &[f64]) -> Result<TimeAxis> {
        let w = time.len();
        let origin = match self.config.time_origin {
            TimeOrigin::Motion => signals.motion_start(),
            TimeOrigin::Window => time[0],
        };
        if !origin.is_finite() {
            return Err(Error::InvalidParameter {
                name: "motion_start",
                value: origin,
                reason: "must be finite",
            });
        }
        let tau = &mut self.tau[..w];
        for (ti, t) in tau.iter_mut().zip(time) {
            *ti = t - origin;
        }
        let t_first = tau[0];
        let t_last = tau[w - 1];
        let centre = 0.5 * (t_first + t_last);
        let half = 0.5 * (t_last - t_first);
        let t_scale = tau.iter().fold(0.0f64, |a, t| a.max(t.abs()));
        if !(half > 0.0 && t_scale > 0.0 && half.is_finite() && t_scale.is_finite()) {
            return Err(Error::InvalidParameter {
                name: "window time span",
                value: half,
                reason: "time must increase over the window",
            });
        }

        // the grid s_i; the cached projection if the grid repeats
        let inv_half = 1.0 / half;
        for v in tau.iter_mut() {
            *v = (*v - centre) * inv_half;
        }
        let tol = (8.0 * (time[0].abs() + time[w - 1].abs() + origin.abs()) * inv_half + 64.0)
            * f64::EPSILON;
        if !self.projection.matches(&self.tau[..w], tol) {
            self.projection.build(&self.tau[..w], &mut self.qr)?;
        }
        Ok(TimeAxis {
            origin,
            t_first,
            t_last,
            centre,
            half,
            t_scale,
        })
    }

    /// The data projected on the 8 Legendre polynomials of the window, and
    /// the output basis `(τ/T)⁵·L_k(s)` in the projected coordinates.
    fn project(
        &mut self,
        pos: &[f64],
        cmd: &[f64],
        y_ref: f64,
        u_ref: f64,
        axis: &TimeAxis,
    ) -> Problem {
        let w = pos.len();
        let proj = &self.projection;
        for (r, p) in self.rhs[..w].iter_mut().zip(pos) {
            *r = p - y_ref;
        }
        for (r, c) in self.data[..w].iter_mut().zip(cmd) {
            *r = c - u_ref;
        }
        let (mut cy, mut cu) = ([0.0; NQ], [0.0; NQ]);
        let (rest_y, rest_u) = proj.project2(&self.rhs[..w], &self.data[..w], &mut cy, &mut cu);
        // unit-norm columns
        let mut m_out = [0.0; NQ * NP];
        let mut norm_out = [0.0; NP];
        proj.output_matrix(
            &self.tables,
            axis.centre / axis.t_scale,
            axis.half / axis.t_scale,
            &mut m_out,
            &mut norm_out,
        );
        for (k, nk) in norm_out.iter_mut().enumerate() {
            if !(*nk > 0.0 && nk.is_finite()) {
                *nk = 1.0;
            }
            m_out[k * NQ..(k + 1) * NQ]
                .iter_mut()
                .for_each(|v| *v /= *nk);
        }
        Problem {
            w,
            cy,
            cu,
            rest_y,
            rest_u,
            m_out,
            norm_out,
            // rank tolerance of the direct W×3 fit
            rank_tol: Some(w as f64 * f64::EPSILON),
        }
    }

    /// Both problems by QR: the output fit directly, the input from the
    /// projection.
    fn solve_qr(&self, pb: &Problem) -> Result<Solution> {
        let proj = &self.projection;
        let (z_out, io) = lstsq_fixed::<NQ, NP>(&columns(&pb.m_out), &pb.cy, pb.rank_tol)?;
        let mut a = [0.0; NQ];
        proj.input_coefficients(&pb.cu, &mut a);
        let mut z_in = [0.0; NQ];
        for k in 0..NQ {
            z_in[k] = a[k] * proj.vnorm[k];
        }
        let out_sse = io.residual_norm * io.residual_norm + pb.rest_y * pb.rest_y;
        Ok(Solution {
            z_out,
            z_in,
            out_sse,
            in_sse: pb.rest_u * pb.rest_u,
            iterations: 0,
            termination: Termination::Exact,
            out_info: Some(LstsqInfo {
                residual_norm: out_sse.sqrt(),
                ..io
            }),
            in_info: Some(proj.input_info(pb.rest_u)),
        })
    }

    /// The start of the simplex: the previous window's polynomials on this
    /// window (if asked and finite), written to `z_out`, `z_in`; whether it
    /// is used.
    fn simplex_start(
        &mut self,
        pb: &Problem,
        time: &[f64],
        y_ref: f64,
        u_ref: f64,
        z_out: &mut [f64; NP],
        z_in: &mut [f64; NQ],
    ) -> bool {
        let (SimplexStart::Previous, Some(prev)) = (self.config.simplex_start, self.last) else {
            return false;
        };
        let w = pb.w;
        let proj = &self.projection;
        for ((v, &t), r) in self.resid[..w]
            .iter_mut()
            .zip(time)
            .zip(self.work.iter_mut())
        {
            *v = prev.y_ref + Self::eval_output(&prev, t) - y_ref;
            *r = prev.u_ref + Self::eval_input(&prev, t) - u_ref;
        }
        let (mut py, mut pu) = ([0.0; NQ], [0.0; NQ]);
        proj.project2(&self.resid[..w], &self.work[..w], &mut py, &mut pu);
        *z_out = lstsq_fixed::<NQ, NP>(&columns(&pb.m_out), &py, pb.rank_tol)
            .map_or([0.0; NP], |(z, _)| z);
        let mut a = [0.0; NQ];
        proj.input_coefficients(&pu, &mut a);
        for k in 0..NQ {
            z_in[k] = a[k] * proj.vnorm[k];
        }
        let finite = z_out.iter().chain(z_in.iter()).all(|v| v.is_finite());
        if !finite {
            *z_out = [0.0; NP];
            *z_in = [0.0; NQ];
        }
        finite
    }

    /// Both problems by the simplex, from zeros or the previous window.
    fn solve_simplex(
        &mut self,
        pb: &Problem,
        time: &[f64],
        y_ref: f64,
        u_ref: f64,
    ) -> Result<Solution> {
        let w = pb.w;
        let settings = self.config.simplex;
        let mut m_in = [0.0; NQ * NQ];
        self.projection.input_matrix(&mut m_in);
        let mut z_out = [0.0; NP];
        let mut z_in = [0.0; NQ];
        let start = self.simplex_start(pb, time, y_ref, u_ref, &mut z_out, &mut z_in);
        let ynorm = (self.rhs[..w].iter().map(|v| v * v).sum::<f64>()).sqrt();
        let unorm = (self.data[..w].iter().map(|v| v * v).sum::<f64>()).sqrt();
        let mut steps = [0.0; NQ];
        let (fo, it_o, term_o) = simplex_fit(
            &mut self.nm_out,
            &Reduced {
                m: &pb.m_out,
                c: &pb.cy,
                rest2: pb.rest_y * pb.rest_y,
                bnorm: ynorm,
                rows: w,
                triangular: false,
            },
            &mut z_out,
            start,
            &settings,
            &mut steps[..NP],
        )?;
        let (fi, it_i, term_i) = simplex_fit(
            &mut self.nm_in,
            &Reduced {
                m: &m_in,
                c: &pb.cu,
                rest2: pb.rest_u * pb.rest_u,
                bnorm: unorm,
                rows: w,
                triangular: true,
            },
            &mut z_in,
            start,
            &settings,
            &mut steps,
        )?;
        let termination =
            if term_o == Termination::MaxIterations || term_i == Termination::MaxIterations {
                Termination::MaxIterations
            } else {
                Termination::Converged
            };
        Ok(Solution {
            z_out,
            z_in,
            out_sse: fo,
            in_sse: fi,
            iterations: it_o + it_i,
            termination,
            out_info: None,
            in_info: None,
        })
    }

    /// Back to the unnormalised Legendre basis, then to monomials in `τ`:
    /// the coefficients `[N2, N1, N0, D7, …, D0]` and the Legendre
    /// coefficients of the output and input fits.
    fn assemble(
        &self,
        sol: &Solution,
        pb: &Problem,
        axis: &TimeAxis,
        first_sample: usize,
    ) -> Result<([f64; NC], [f64; NP], [f64; NQ])> {
        let norm_in = self.projection.vnorm;
        let mut a_out = [0.0; NP];
        let mut a_in = [0.0; NQ];
        for ((a, z), nk) in a_out.iter_mut().zip(&sol.z_out).zip(&pb.norm_out) {
            *a = z / nk;
        }
        for ((a, z), nk) in a_in.iter_mut().zip(&sol.z_in).zip(&norm_in) {
            *a = z / nk;
        }
        let mut ms = [0.0; NQ];
        for (ak, lk) in a_out.iter().zip(&self.tables.table) {
            for (mj, lkj) in ms.iter_mut().zip(lk).take(NP) {
                *mj += ak * lkj;
            }
        }
        let mut r = [0.0; NQ];
        affine_to_monomial(&ms[..NP], axis.centre, axis.half, &mut r[..NP]);
        let t5 = axis.t_scale.powi(5);
        let p = [r[0] / t5, r[1] / t5, r[2] / t5];
        let mut ms = [0.0; NQ];
        for (ak, lk) in a_in.iter().zip(&self.tables.table) {
            for (mj, lkj) in ms.iter_mut().zip(lk) {
                *mj += ak * lkj;
            }
        }
        let mut q = [0.0; NQ];
        affine_to_monomial(&ms, axis.centre, axis.half, &mut q);
        let c = coefficients_from_polynomials(p, q);
        if let Some(i) = c.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                channel: format!("paper coefficient {}", NAMES[i]),
                index: first_sample,
                value: c[i],
            });
        }
        Ok((c, a_out, a_in))
    }
}

/// The 8×3 column-major output matrix as three columns.
fn columns(m: &[f64; NQ * NP]) -> [[f64; NQ]; NP] {
    let mut c = [[0.0; NQ]; NP];
    for (k, col) in c.iter_mut().enumerate() {
        col.copy_from_slice(&m[k * NQ..(k + 1) * NQ]);
    }
    c
}

/// Response of the identified `N(s)/D(s)` (coefficients `[N2, N1, N0, D7 … D0]`)
/// to the sampled input `du` (zero-order hold, interval `dt`), from the zero state.
pub(super) fn tf_response(coef: &[f64; NC], dt: f64, du: &[f64], y: &mut [f64]) -> Result<()> {
    let tf = TransferFunction::new(coef[..NP].to_vec(), coef[NP..].to_vec())?;
    let sys = tf.to_state_space()?.discretize_zoh(dt)?;
    if !sys.is_stable()? {
        return Err(Error::InvalidModel {
            reason: "identified transfer function is unstable",
        });
    }
    let n = sys.order();
    let mut x = [0.0; NQ];
    let mut scratch = [0.0; NQ];
    if n > NQ {
        return Err(Error::InvalidModel {
            reason: "identified transfer function has order > 7",
        });
    }
    sys.simulate_into(du, &mut x[..n], y, &mut scratch[..n])
}
