//! The paper's short-time identification (Nassef et al., sections III–V).
//!
//! The closed loop `X_a/X_s = N(s)/D(s)` with `N = N2·s² + N1·s + N0` and
//! `D = D7·s⁷ + … + D0` is divided by `s⁸` and read as a pair of Laplace
//! transforms (eq. 4–6). Their inverse transforms are polynomials in the time
//! `τ` since the time origin:
//!
//! ```text
//!     X_a(τ) = P5·τ⁵ + P6·τ⁶ + P7·τ⁷,      P5 = N2/120, P6 = N1/720, P7 = N0/5040
//!     X_s(τ) = Σ_{i=0..7} Q_i·τⁱ,           Q_i = D_{7−i}/i!
//! ```
//!
//! Per window of `W` samples the output model is fitted to the measured
//! position and the input model to the command, each by least squares
//! (eq. 8), and mapped to `N2, N1, N0, D7 … D0`
//! ([`coefficients_from_polynomials`]).
//!
//! **Time origin** ([`TimeOrigin`]): `τ = t − motion_start` (the paper's
//! reading, default) or `τ = t − t_first` of each window.
//!
//! **Scaled coordinates.** In seconds the basis `τ⁵, τ⁶, τ⁷` is tiny and nearly
//! collinear, and `1 … τ⁷` far from the origin is numerically degenerate
//! (column-scaled monomials have condition numbers of 1e7 … 1e13 for
//! windows 4 … 50 ms after the motion start). Both solvers therefore work on
//! the *same* well-conditioned basis of the *same* model families, with the
//! window mapped to `s = (τ − τ_c)/h ∈ [−1, 1]` (`τ_c`, `h`: centre and
//! half-width of the window in `τ`) and `T = max |τ|` over the window:
//!
//! ```text
//!     output:  φ_k(τ) = (τ/T)⁵·L_k(s),  k = 0, 1, 2   (span = {τ⁵, τ⁶, τ⁷})
//!     input:   ψ_k(τ) = L_k(s),          k = 0 … 7     (span = {1, …, τ⁷})
//! ```
//!
//! with `L_k` the Legendre polynomials, each column normalised to unit
//! 2-norm over the window. The fitted functions are identical to the fits on
//! the raw monomials (same least-squares problem, eq. 8); only the
//! coordinates differ. The coefficients `P`, `Q` are then obtained by an
//! exact change of basis (Legendre → powers of `s` → Taylor shift to powers of
//! `τ`). That last step is intrinsically ill-conditioned far from the origin
//! (the monomial coefficients of a window 25 s after the origin cancel over
//! ~30 decades); its growth factor is reported as
//! [`PaperDiagnostics::shift_amplification`]. Predictions in
//! [`PredictionMode::Polynomial`] are evaluated in the fitted basis and stay
//! accurate regardless.
//!
//! **Solvers** ([`Solver`]): `Qr` is the exact linear least-squares solution
//! (Householder QR, [`crate::solve::lstsq_in_place`]); `Simplex` is the
//! paper's Nelder–Mead minimisation of the same sums of squares, evaluated
//! directly from the residuals on the scaled basis: once for the 3 output
//! coefficients and once for the 8 input coefficients. The paper is silent on
//! the start and the tolerances; here every window starts from **zero
//! coefficients** (each window is then independent of the previous ones, so
//! results do not depend on the hop, on the order of processing or on
//! batch vs streaming use) with start steps `step_rel·‖b‖` and tolerances
//! relative to the window's data norm `‖b‖` (see [`SimplexSettings`]). With
//! the defaults the simplex resolves exactly representable data to
//! `‖G·Δz‖ ≈ 1e-13·‖b‖` and otherwise to the rounding level of the sum of
//! squares, so that simplex and QR coefficients agree to 1e-6 relative where
//! the change of basis is benign, and predictions agree to 1e-6 of the data
//! scale everywhere. This costs about 150 iterations for the 3-parameter
//! output fit and 600–1000 for the 8-parameter input fit per window (one or
//! two objective evaluations of `W·n` multiply-adds each): the simplex is two
//! orders of magnitude slower than QR, which is the default.
//!
//! **Prediction** ([`PredictionMode`]): `Polynomial` (default) continues the
//! fitted output polynomial over the horizon — the response of the identified
//! `Tf` to the fitted input polynomial is `N(s)/s⁸`, exactly that polynomial.
//! `TransferFunction` drives the identified `Tf` with the actual next command:
//! by superposition,
//!
//! ```text
//!     ŷ(t) = P(τ) + [Tf ∗ Δu](t − t_h),   Δu = u_actual − Q(τ) over the horizon,
//! ```
//!
//! with `t_h` the first horizon time, the convolution simulated from the zero
//! state with the exact zero-order-hold discretisation of the identified
//! `N(s)/D(s)` at the nominal sample interval (balanced realisation,
//! [`crate::lti`]). If the fitted command continues exactly, `Δu = 0` and
//! both modes coincide. If the identified `Tf` cannot be built, is unstable
//! or gives a non-finite response, the window falls back to the polynomial
//! prediction; this is counted ([`PaperMethod::tf_fallbacks`]) and flagged in
//! [`PaperDiagnostics::tf_fallback`]. Building and discretising a model per
//! window allocates (inside [`crate::lti`]); the polynomial mode does not.
//!
//! **Rest and reference** (with [`TimeOrigin::Motion`]): the output model
//! passes through zero at `τ = 0`, so positions are measured from the rest
//! position at the motion start (the measured position of the last sample at
//! or before the motion start, fixed by the first window that reaches past
//! it; predictions add it back). A window whose last sample is at or before the
//! motion start (or when the motion start is not known yet, `+∞` while
//! streaming) holds only rest data: there is nothing to identify, so it
//! predicts the last measured position held, writes zero coefficients and
//! reports [`Termination::Fallback`]. The command is fitted as given: its
//! model has a constant term (`Q0 = D7`).
//!
//! Reference: M.G.A. Nassef, L. Li, C. Schenck, B. Kuhfuss, "Short Time
//! Identification of Feed Drive Systems using Nonlinear Least Squares Method",
//! eq. (3)–(8); design notes §2.

use std::ops::Range;
use std::str::FromStr;

use crate::error::{Error, Result};
use crate::ident::{Estimator, Signals, WindowFit};
use crate::lti::TransferFunction;
use crate::solve::{
    lstsq_in_place, LstsqInfo, LstsqOptions, NelderMead, NelderMeadConfig, QrWorkspace, Termination,
};

/// Number of output-model coefficients (`P5, P6, P7`).
const NP: usize = 3;
/// Number of input-model coefficients (`Q0 … Q7`).
const NQ: usize = 8;
/// Number of identified coefficients (`N2, N1, N0, D7 … D0`).
const NC: usize = NP + NQ;
/// Legendre recurrence factors `(2k+1)/(k+1)` and `k/(k+1)`, `k = 0 … 6`.
const LEGENDRE_A: [f64; NQ - 1] = [1.0, 1.5, 5.0 / 3.0, 1.75, 1.8, 11.0 / 6.0, 13.0 / 7.0];
const LEGENDRE_B: [f64; NQ - 1] = [0.0, 0.5, 2.0 / 3.0, 0.75, 0.8, 5.0 / 6.0, 6.0 / 7.0];
/// `i!` for `i = 0 … 7`.
const FACT: [f64; 8] = [1.0, 1.0, 2.0, 6.0, 24.0, 120.0, 720.0, 5040.0];
const NAMES: [&str; NC] = [
    "N2", "N1", "N0", "D7", "D6", "D5", "D4", "D3", "D2", "D1", "D0",
];

/// How the window's least-squares problems are solved.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Solver {
    /// Exact linear least squares by Householder QR (default).
    #[default]
    Qr,
    /// Nelder–Mead simplex on the sum of squares, as in the paper.
    Simplex,
}

/// Where the time `τ` of the polynomial models starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TimeOrigin {
    /// `τ = t − motion_start` (the paper's reading, default).
    #[default]
    Motion,
    /// `τ = t − t_first`, the first sample time of each window.
    Window,
}

/// How the next samples are predicted from a window's fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PredictionMode {
    /// The fitted output polynomial continued over the horizon (default; `N(s)/s⁸`).
    #[default]
    Polynomial,
    /// The identified `N(s)/D(s)` driven by the actual next command.
    TransferFunction,
}

impl Solver {
    /// Lowercase name as used on the command line.
    pub fn label(self) -> &'static str {
        match self {
            Solver::Qr => "qr",
            Solver::Simplex => "simplex",
        }
    }
}

impl TimeOrigin {
    /// Lowercase name as used on the command line.
    pub fn label(self) -> &'static str {
        match self {
            TimeOrigin::Motion => "motion",
            TimeOrigin::Window => "window",
        }
    }
}

impl PredictionMode {
    /// Lowercase name as used on the command line.
    pub fn label(self) -> &'static str {
        match self {
            PredictionMode::Polynomial => "polynomial",
            PredictionMode::TransferFunction => "tf",
        }
    }
}

impl FromStr for Solver {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s.to_ascii_lowercase().as_str() {
            "qr" => Ok(Solver::Qr),
            "simplex" | "nelder-mead" => Ok(Solver::Simplex),
            _ => Err(Error::InvalidChoice {
                what: "solver",
                value: s.to_string(),
                expected: "qr, simplex",
            }),
        }
    }
}

impl FromStr for TimeOrigin {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s.to_ascii_lowercase().as_str() {
            "motion" => Ok(TimeOrigin::Motion),
            "window" => Ok(TimeOrigin::Window),
            _ => Err(Error::InvalidChoice {
                what: "time origin",
                value: s.to_string(),
                expected: "motion, window",
            }),
        }
    }
}

impl FromStr for PredictionMode {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s.to_ascii_lowercase().as_str() {
            "polynomial" | "poly" => Ok(PredictionMode::Polynomial),
            "tf" | "transfer-function" => Ok(PredictionMode::TransferFunction),
            _ => Err(Error::InvalidChoice {
                what: "prediction mode",
                value: s.to_string(),
                expected: "polynomial, tf",
            }),
        }
    }
}

/// Tolerances, caps and start steps of the simplex solver, relative to the
/// 2-norm `‖b‖` of the window's data (position for the output fit, command
/// for the input fit); the coordinates are the coefficients of the
/// unit-norm basis columns, so they carry the units of the data.
///
/// The fit stops ([`Termination::Converged`]) when the simplex size is
/// `≤ xtol_data·‖b‖` and the spread of the sum of squares `f` over the
/// simplex is `≤ ftol_data·‖b‖² + noise_factor·ε·√W·‖b‖·√f_best`. The second
/// term is the rounding level of `f` (its residuals cancel against the data to
/// `≈ ε‖b‖`); without it, windows whose data do not fit exactly could never
/// meet the tolerance. On exactly representable data (`f → 0`) the first term
/// binds and the fit is resolved to `‖G·Δz‖ ≈ 1e-13·‖b‖`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimplexSettings {
    /// Simplex-size tolerance, relative to `‖b‖`. Default `1e-10` (a
    /// safeguard: the spread tolerance is the binding one).
    pub xtol_data: f64,
    /// Absolute objective-spread tolerance, relative to `‖b‖²`. Default `1e-26`.
    pub ftol_data: f64,
    /// Multiple of the rounding level of the sum of squares allowed as spread. Default 100.
    pub noise_factor: f64,
    /// Start step of every coordinate, `step_rel·‖b‖`. Default `0.5`.
    pub step_rel: f64,
    /// Iteration cap per fit (output and input fit each). Default 4000.
    pub max_iterations: usize,
    /// Evaluation cap per fit. Default 8000.
    pub max_evaluations: usize,
}

impl Default for SimplexSettings {
    fn default() -> Self {
        Self {
            xtol_data: 1e-10,
            ftol_data: 1e-26,
            noise_factor: 100.0,
            step_rel: 0.5,
            max_iterations: 4000,
            max_evaluations: 8000,
        }
    }
}

/// Configuration of the paper's method.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PaperConfig {
    /// Least-squares solver. Default [`Solver::Qr`].
    pub solver: Solver,
    /// Time origin of the polynomial models. Default [`TimeOrigin::Motion`].
    pub time_origin: TimeOrigin,
    /// Prediction variant. Default [`PredictionMode::Polynomial`].
    pub prediction: PredictionMode,
    /// Simplex settings (used with [`Solver::Simplex`]).
    pub simplex: SimplexSettings,
}

/// Growth factor `(1 + |τ_c|/h)⁷` of the change of basis to monomial
/// coefficients for a window spanning `τ_first … τ_last` (see
/// [`PaperDiagnostics::shift_amplification`]); infinite for an empty span.
fn shift_amplification(tau_first: f64, tau_last: f64) -> f64 {
    let centre = 0.5 * (tau_first + tau_last);
    let half = 0.5 * (tau_last - tau_first);
    let g = (1.0 + centre.abs() / half).powi(7);
    if g.is_nan() {
        f64::INFINITY
    } else {
        g
    }
}

/// [`PaperConfig::worst_shift_amplification`] above which the coefficients
/// `N`, `D` keep fewer than about 8 significant digits (1e8 × 1e-16).
pub const SHIFT_AMPLIFICATION_WARNING: f64 = 1e8;

impl PaperConfig {
    /// The largest [`PaperDiagnostics::shift_amplification`] over the windows
    /// that `config` visits on `signals` (offset 0): how far from the time
    /// origin the windows lie. Above [`SHIFT_AMPLIFICATION_WARNING`] the
    /// identified `N`, `D` lose accuracy (predictions in
    /// [`PredictionMode::Polynomial`] do not). `1.0` when no window fits.
    pub fn worst_shift_amplification(
        &self,
        signals: &Signals<'_>,
        config: &crate::ident::EngineConfig,
    ) -> f64 {
        let n = signals.time.len();
        let mut worst = 1.0f64;
        for (w, _) in config.windows(n, 0) {
            let (Some(&first), Some(&last)) = (
                signals.time.get(w.start),
                w.end.checked_sub(1).and_then(|e| signals.time.get(e)),
            ) else {
                continue;
            };
            let origin = match self.time_origin {
                TimeOrigin::Motion => signals.motion_start,
                TimeOrigin::Window => first,
            };
            worst = worst.max(shift_amplification(first - origin, last - origin));
        }
        worst
    }

    /// Validate and build the estimator.
    ///
    /// ```
    /// use feedid::ident::{Estimator, PaperConfig, Signals};
    /// let dt = 2e-4;
    /// let t: Vec<f64> = (0..30).map(|k| k as f64 * dt).collect();
    /// let y: Vec<f64> = t.iter().map(|&t| 3e7 * t.powi(5)).collect();
    /// let u: Vec<f64> = t.iter().map(|&t| 0.05 * t).collect();
    /// let signals = Signals::new(&t, &u, &y, dt, 0.0);
    /// let mut paper = PaperConfig::default().build().unwrap();
    /// let mut coef = vec![0.0; paper.coefficient_names().len()];
    /// paper.fit(&signals, 0..20, &mut coef).unwrap();
    /// assert!((coef[0] / (120.0 * 3e7) - 1.0).abs() < 1e-9); // N2 = 120·P5
    /// let mut next = [0.0; 10];
    /// paper.predict(&signals, 0..20, 20..30, &mut next).unwrap();
    /// assert!((next[9] / y[29] - 1.0).abs() < 1e-9);
    /// ```
    pub fn build(self) -> Result<PaperMethod> {
        let s = &self.simplex;
        for (name, v) in [
            ("simplex.xtol_data", s.xtol_data),
            ("simplex.ftol_data", s.ftol_data),
            ("simplex.noise_factor", s.noise_factor),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::InvalidParameter {
                    name,
                    value: v,
                    reason: "must be finite and >= 0",
                });
            }
        }
        if !(s.step_rel.is_finite() && s.step_rel > 0.0) {
            return Err(Error::InvalidParameter {
                name: "simplex.step_rel",
                value: s.step_rel,
                reason: "must be finite and > 0",
            });
        }
        if s.max_iterations == 0 || s.max_evaluations == 0 {
            return Err(Error::InvalidParameter {
                name: "simplex.max_iterations",
                value: s.max_iterations.min(s.max_evaluations) as f64,
                reason: "must be >= 1",
            });
        }
        Ok(PaperMethod::new(self))
    }
}

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
struct LastFit {
    /// Time origin used for `τ` \[s\].
    origin: f64,
    /// `T = max |τ|` over the window \[s\].
    t_scale: f64,
    /// Centre `τ_c` and half width `h` of the window in `τ` \[s\].
    centre: f64,
    half: f64,
    /// Output coefficients of `(τ/T)⁵·L_k(s)` (unnormalised basis).
    out: [f64; NP],
    /// Input coefficients of `L_k(s)` (unnormalised basis).
    inp: [f64; NQ],
    /// Identified `[N2, N1, N0, D7, …, D0]`.
    coef: [f64; NC],
    /// Rest position and command subtracted before fitting (0 for window-local time).
    y_ref: f64,
    u_ref: f64,
}

/// The paper's identification method as an [`Estimator`] (name `"paper"`).
///
/// Build with [`PaperConfig::build`]. Buffers are sized by the first window
/// and grown once if a longer window comes; fitting allocates nothing after that.
#[derive(Debug, Clone)]
pub struct PaperMethod {
    config: PaperConfig,
    /// Held position of the last window if it was a rest window.
    rest_hold: Option<f64>,
    legendre: [[f64; NQ]; NQ],
    cap: usize,
    tau: Vec<f64>,
    data: Vec<f64>,
    design_out: Vec<f64>,
    design_in: Vec<f64>,
    work: Vec<f64>,
    rhs: Vec<f64>,
    resid: Vec<f64>,
    qr: QrWorkspace,
    nm_out: NelderMead,
    nm_in: NelderMead,
    last: Option<LastFit>,
    /// Rest position at the motion start, fixed by the first motion window.
    reference: Option<f64>,
    diagnostics: Option<PaperDiagnostics>,
    tf_fallbacks: usize,
    du: Vec<f64>,
    ysim: Vec<f64>,
}

impl PaperMethod {
    fn new(config: PaperConfig) -> Self {
        Self {
            config,
            rest_hold: None,
            legendre: legendre_monomials(),
            cap: 0,
            tau: Vec::new(),
            data: Vec::new(),
            design_out: Vec::new(),
            design_in: Vec::new(),
            work: Vec::new(),
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
        WindowFit {
            residual_rms: (sse / pos.len().max(1) as f64).sqrt(),
            iterations: 0,
            termination: Termination::Fallback,
        }
    }

    fn ensure_capacity(&mut self, w: usize) {
        if w > self.cap {
            self.tau.resize(w, 0.0);
            self.data.resize(w, 0.0);
            self.design_out.resize(NP * w, 0.0);
            self.design_in.resize(NQ * w, 0.0);
            self.work.resize(NQ * w, 0.0);
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

/// Check that the signals cover `r` and the channels have equal lengths.
fn check_range(signals: &Signals<'_>, r: &Range<usize>, what: &'static str) -> Result<()> {
    let n = signals.time.len();
    if signals.command.len() != n {
        return Err(Error::LengthMismatch {
            what: "command",
            expected: n,
            actual: signals.command.len(),
        });
    }
    if signals.position.len() != n {
        return Err(Error::LengthMismatch {
            what: "position",
            expected: n,
            actual: signals.position.len(),
        });
    }
    if r.start < signals.offset || r.end > signals.end() || r.start > r.end {
        return Err(Error::TooFewSamples {
            what,
            needed: r.end,
            actual: signals.end(),
        });
    }
    Ok(())
}

fn first_non_finite(v: &[f64], offset: usize, channel: &str) -> Result<()> {
    match v.iter().position(|x| !x.is_finite()) {
        Some(i) => Err(Error::NonFinite {
            channel: channel.to_string(),
            index: offset + i,
            value: v[i],
        }),
        None => Ok(()),
    }
}

/// Minimise `‖G·z − b‖²` (G column-major `m×n`, unit-norm columns) by the simplex from `z = 0`.
#[allow(clippy::too_many_arguments)]
fn simplex_fit(
    nm: &mut NelderMead,
    g: &[f64],
    b: &[f64],
    resid: &mut [f64],
    z: &mut [f64],
    settings: &SimplexSettings,
    steps: &mut [f64],
) -> Result<(f64, usize, Termination)> {
    let m = b.len();
    let n = z.len();
    let bnorm = b.iter().map(|v| v * v).sum::<f64>().sqrt();
    for v in z.iter_mut() {
        *v = 0.0;
    }
    if bnorm == 0.0 {
        return Ok((0.0, 0, Termination::Converged));
    }
    for s in steps.iter_mut() {
        *s = settings.step_rel * bnorm;
    }
    let cfg = NelderMeadConfig {
        xtol: settings.xtol_data * bnorm,
        ftol: settings.ftol_data * bnorm * bnorm,
        ftol_rel: 0.0,
        ftol_root: settings.noise_factor * f64::EPSILON * (m as f64).sqrt() * bnorm,
        max_iterations: settings.max_iterations,
        max_evaluations: settings.max_evaluations,
    };
    let objective = |p: &[f64]| -> f64 {
        for (r, bi) in resid.iter_mut().zip(b) {
            *r = -bi;
        }
        for (k, pk) in p.iter().enumerate() {
            let col = &g[k * m..(k + 1) * m];
            for (r, gi) in resid.iter_mut().zip(col) {
                *r += gi * pk;
            }
        }
        resid.iter().map(|r| r * r).sum()
    };
    let rep = nm.minimize(objective, z, &steps[..n], &cfg)?;
    Ok((rep.f, rep.iterations, rep.termination))
}

impl Estimator for PaperMethod {
    fn name(&self) -> &'static str {
        "paper"
    }

    fn uses_future_command(&self) -> bool {
        self.config.prediction != PredictionMode::Polynomial
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
        check_range(signals, &window, "paper window")?;
        let w = window.len();
        if w < NQ {
            return Err(Error::TooFewSamples {
                what: "paper window (8 input coefficients)",
                needed: NQ,
                actual: w,
            });
        }
        let time = signals.time(window.clone());
        let pos = signals.position(window.clone());
        let cmd = signals.command(window.clone());
        first_non_finite(time, window.start, "time")?;
        first_non_finite(pos, window.start, "position")?;
        first_non_finite(cmd, window.start, "command")?;
        if self.config.time_origin == TimeOrigin::Motion && time[w - 1] <= signals.motion_start {
            return Ok(self.rest_window(pos, coef));
        }
        self.rest_hold = None;
        self.ensure_capacity(w);

        // --- rest windows and the rest reference (motion time origin)
        let (y_ref, u_ref) = match self.config.time_origin {
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
                    signals
                        .time
                        .iter()
                        .rposition(|&t| t <= signals.motion_start)
                        .map_or(0.0, |k| signals.position[k])
                });
                (y_ref, 0.0)
            }
        };

        // --- time scaling
        let origin = match self.config.time_origin {
            TimeOrigin::Motion => signals.motion_start,
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

        // --- bases (column-major), columns normalised to unit norm
        let mut norm_out = [0.0; NP];
        let mut norm_in = [0.0; NQ];
        {
            let g_out = &mut self.design_out[..NP * w];
            let g_in = &mut self.design_in[..NQ * w];
            // multiplications by reciprocals: no division in the per-sample loop
            let (inv_half, inv_t) = (1.0 / half, 1.0 / t_scale);
            for i in 0..w {
                let s = (tau[i] - centre) * inv_half;
                let wt = (tau[i] * inv_t).powi(5);
                // Legendre recurrence L_{k+1} = ((2k+1) s L_k − k L_{k−1})/(k+1)
                let mut lm1 = 1.0;
                let mut l = s;
                g_in[i] = 1.0;
                g_in[i + w] = s;
                for k in 1..NQ - 1 {
                    let next = LEGENDRE_A[k] * s * l - LEGENDRE_B[k] * lm1;
                    lm1 = l;
                    l = next;
                    g_in[i + (k + 1) * w] = l;
                }
                for k in 0..NP {
                    g_out[i + k * w] = wt * g_in[i + k * w];
                }
            }
            for (k, nk) in norm_out.iter_mut().enumerate() {
                let col = &mut g_out[k * w..(k + 1) * w];
                *nk = normalise(col);
            }
            for (k, nk) in norm_in.iter_mut().enumerate() {
                let col = &mut g_in[k * w..(k + 1) * w];
                *nk = normalise(col);
            }
        }

        // --- solve both problems in the normalised basis
        let mut z_out = [0.0; NP];
        let mut z_in = [0.0; NQ];
        let (out_sse, in_sse, iterations, termination, out_info, in_info);
        match self.config.solver {
            Solver::Qr => {
                let opts = LstsqOptions::default();
                self.work[..NP * w].copy_from_slice(&self.design_out[..NP * w]);
                for (r, p) in self.rhs[..w].iter_mut().zip(pos) {
                    *r = p - y_ref;
                }
                let io = lstsq_in_place(
                    w,
                    NP,
                    &mut self.work[..NP * w],
                    &mut self.rhs[..w],
                    &mut z_out,
                    &mut self.qr,
                    &opts,
                )?;
                self.work[..NQ * w].copy_from_slice(&self.design_in[..NQ * w]);
                for (r, c) in self.rhs[..w].iter_mut().zip(cmd) {
                    *r = c - u_ref;
                }
                let ii = lstsq_in_place(
                    w,
                    NQ,
                    &mut self.work[..NQ * w],
                    &mut self.rhs[..w],
                    &mut z_in,
                    &mut self.qr,
                    &opts,
                )?;
                out_sse = io.residual_norm * io.residual_norm;
                in_sse = ii.residual_norm * ii.residual_norm;
                iterations = 0;
                termination = Termination::Exact;
                out_info = Some(io);
                in_info = Some(ii);
            }
            Solver::Simplex => {
                let settings = self.config.simplex;
                let mut steps = [0.0; NQ];
                for (r, p) in self.data[..w].iter_mut().zip(pos) {
                    *r = p - y_ref;
                }
                let (fo, it_o, term_o) = simplex_fit(
                    &mut self.nm_out,
                    &self.design_out[..NP * w],
                    &self.data[..w],
                    &mut self.resid[..w],
                    &mut z_out,
                    &settings,
                    &mut steps[..NP],
                )?;
                for (r, c) in self.data[..w].iter_mut().zip(cmd) {
                    *r = c - u_ref;
                }
                let (fi, it_i, term_i) = simplex_fit(
                    &mut self.nm_in,
                    &self.design_in[..NQ * w],
                    &self.data[..w],
                    &mut self.resid[..w],
                    &mut z_in,
                    &settings,
                    &mut steps,
                )?;
                out_sse = fo;
                in_sse = fi;
                iterations = it_o + it_i;
                termination = if term_o == Termination::MaxIterations
                    || term_i == Termination::MaxIterations
                {
                    Termination::MaxIterations
                } else {
                    Termination::Converged
                };
                out_info = None;
                in_info = None;
            }
        }

        // --- back to the unnormalised Legendre basis, then to monomials in τ
        let mut a_out = [0.0; NP];
        let mut a_in = [0.0; NQ];
        for k in 0..NP {
            a_out[k] = z_out[k] / norm_out[k];
        }
        for k in 0..NQ {
            a_in[k] = z_in[k] / norm_in[k];
        }
        let mut ms = [0.0; NQ];
        for (ak, lk) in a_out.iter().zip(&self.legendre) {
            for (mj, lkj) in ms.iter_mut().zip(lk).take(NP) {
                *mj += ak * lkj;
            }
        }
        let mut r = [0.0; NQ];
        affine_to_monomial(&ms[..NP], centre, half, &mut r[..NP]);
        let t5 = t_scale.powi(5);
        let p = [r[0] / t5, r[1] / t5, r[2] / t5];
        let mut ms = [0.0; NQ];
        for (ak, lk) in a_in.iter().zip(&self.legendre) {
            for (mj, lkj) in ms.iter_mut().zip(lk) {
                *mj += ak * lkj;
            }
        }
        let mut q = [0.0; NQ];
        affine_to_monomial(&ms, centre, half, &mut q);
        let c = coefficients_from_polynomials(p, q);
        if let Some(i) = c.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                channel: format!("paper coefficient {}", NAMES[i]),
                index: window.start,
                value: c[i],
            });
        }
        coef.copy_from_slice(&c);

        let in_norm = cmd
            .iter()
            .map(|v| (v - u_ref) * (v - u_ref))
            .sum::<f64>()
            .sqrt();
        self.last = Some(LastFit {
            origin,
            t_scale,
            centre,
            half,
            out: a_out,
            inp: a_in,
            coef: c,
            y_ref,
            u_ref,
        });
        self.diagnostics = Some(PaperDiagnostics {
            output_qr: out_info,
            input_qr: in_info,
            shift_amplification: shift_amplification(t_first, t_last),
            tf_fallback: false,
            input_residual_rel: if in_norm > 0.0 {
                in_sse.max(0.0).sqrt() / in_norm
            } else {
                0.0
            },
        });
        Ok(WindowFit {
            residual_rms: (out_sse.max(0.0) / w as f64).sqrt(),
            iterations,
            termination,
        })
    }

    fn predict(
        &mut self,
        signals: &Signals<'_>,
        _window: Range<usize>,
        horizon: Range<usize>,
        out: &mut [f64],
    ) -> Result<()> {
        if out.len() != horizon.len() {
            return Err(Error::LengthMismatch {
                what: "paper prediction",
                expected: horizon.len(),
                actual: out.len(),
            });
        }
        check_range(signals, &horizon, "paper horizon")?;
        if let Some(hold) = self.rest_hold {
            out.fill(hold);
            return Ok(());
        }
        let fit = self.last.ok_or(Error::InvalidModel {
            reason: "paper: predict called before a successful fit",
        })?;
        let time = signals.time(horizon.clone());
        for (o, &t) in out.iter_mut().zip(time) {
            *o = fit.y_ref + Self::eval_output(&fit, t);
        }
        if self.config.prediction == PredictionMode::TransferFunction {
            let h = horizon.len();
            if self.du.len() < h {
                self.du.resize(h, 0.0);
                self.ysim.resize(h, 0.0);
            }
            let cmd = signals.command(horizon.clone());
            for ((d, &u), &t) in self.du.iter_mut().zip(cmd).zip(time) {
                *d = u - fit.u_ref - Self::eval_input(&fit, t);
            }
            let ok = tf_response(&fit.coef, signals.dt, &self.du[..h], &mut self.ysim[..h]).is_ok()
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
        Ok(())
    }
}

/// Response of the identified `N(s)/D(s)` (coefficients `[N2, N1, N0, D7 … D0]`)
/// to the sampled input `du` (zero-order hold, interval `dt`), from the zero state.
fn tf_response(coef: &[f64; NC], dt: f64, du: &[f64], y: &mut [f64]) -> Result<()> {
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

/// Map the polynomial coefficients `P = [P5, P6, P7]` and `Q = [Q0, …, Q7]`
/// of eq. (6) to `[N2, N1, N0, D7, D6, …, D0]`:
/// `N2 = 120·P5`, `N1 = 720·P6`, `N0 = 5040·P7`, `D_{7−i} = i!·Q_i`.
pub fn coefficients_from_polynomials(p: [f64; 3], q: [f64; 8]) -> [f64; 11] {
    let mut c = [0.0; NC];
    c[0] = FACT[5] * p[0];
    c[1] = FACT[6] * p[1];
    c[2] = FACT[7] * p[2];
    for i in 0..NQ {
        c[NP + i] = FACT[i] * q[i];
    }
    c
}

/// Inverse of [`coefficients_from_polynomials`]: `[N2, N1, N0, D7, …, D0]` →
/// (`[P5, P6, P7]`, `[Q0, …, Q7]`) with `P5 = N2/120`, `P6 = N1/720`,
/// `P7 = N0/5040`, `Q_i = D_{7−i}/i!`.
pub fn polynomials_from_coefficients(c: &[f64; 11]) -> ([f64; 3], [f64; 8]) {
    let p = [c[0] / FACT[5], c[1] / FACT[6], c[2] / FACT[7]];
    let mut q = [0.0; NQ];
    for i in 0..NQ {
        q[i] = c[NP + i] / FACT[i];
    }
    (p, q)
}

/// Coefficients (powers of `s`) of the Legendre polynomials `L_0 … L_7`:
/// `L_k(s) = Σ_j table[k][j]·s^j`.
fn legendre_monomials() -> [[f64; NQ]; NQ] {
    let mut t = [[0.0; NQ]; NQ];
    t[0][0] = 1.0;
    t[1][1] = 1.0;
    for k in 1..NQ - 1 {
        for j in 0..NQ {
            let shifted = if j > 0 { t[k][j - 1] } else { 0.0 };
            t[k + 1][j] = ((2 * k + 1) as f64 * shifted - k as f64 * t[k - 1][j]) / (k + 1) as f64;
        }
    }
    t
}

/// Coefficients in powers of `τ` of `Σ_j m_j·((τ − c)/h)^j` (Horner in
/// polynomial arithmetic); `out.len() == m.len()`.
fn affine_to_monomial(m: &[f64], c: f64, h: f64, out: &mut [f64]) {
    let n = m.len();
    for v in out.iter_mut() {
        *v = 0.0;
    }
    for j in (0..n).rev() {
        // out ← out·(τ/h − c/h) + m_j
        for i in (0..n).rev() {
            let lower = if i > 0 { out[i - 1] } else { 0.0 };
            out[i] = lower / h - out[i] * c / h;
        }
        out[0] += m[j];
    }
}

/// Scale `v` to unit 2-norm and return the norm (1 for a zero vector, which is kept).
fn normalise(v: &mut [f64]) -> f64 {
    let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    if n > 0.0 && n.is_finite() {
        let inv = 1.0 / n;
        for x in v.iter_mut() {
            *x *= inv;
        }
        n
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DT: f64 = 2e-4;
    const W: usize = 20;
    const H: usize = 10;

    struct Data {
        t: Vec<f64>,
        u: Vec<f64>,
        y: Vec<f64>,
    }

    impl Data {
        fn signals(&self, motion_start: f64) -> Signals<'_> {
            Signals::new(&self.t, &self.u, &self.y, DT, motion_start)
        }
    }

    fn eval_p(p: &[f64; 3], tau: f64) -> f64 {
        p[0] * tau.powi(5) + p[1] * tau.powi(6) + p[2] * tau.powi(7)
    }

    fn eval_q(q: &[f64; 8], tau: f64) -> f64 {
        q.iter().rev().fold(0.0, |acc, c| acc * tau + c)
    }

    /// Samples `0..n` at `t = t0 + k·dt` of the model polynomials in `τ = t − origin`.
    fn model_data(p: &[f64; 3], q: &[f64; 8], t0: f64, origin: f64, n: usize) -> Data {
        let t: Vec<f64> = (0..n).map(|k| t0 + k as f64 * DT).collect();
        let y = t.iter().map(|&t| eval_p(p, t - origin)).collect();
        let u = t.iter().map(|&t| eval_q(q, t - origin)).collect();
        Data { t, u, y }
    }

    /// Polynomials whose terms are all O(1e-3) over `τ ∈ [0, span]`.
    fn balanced(span: f64) -> ([f64; 3], [f64; 8]) {
        let ph = [1.0e-3, -0.6e-3, 0.8e-3];
        let qh = [
            0.2e-3, 1.1e-3, -0.7e-3, 0.5e-3, 0.9e-3, -0.4e-3, 0.3e-3, 0.6e-3,
        ];
        let p = [
            ph[0] / span.powi(5),
            ph[1] / span.powi(6),
            ph[2] / span.powi(7),
        ];
        let mut q = [0.0; 8];
        for i in 0..8 {
            q[i] = qh[i] / span.powi(i as i32);
        }
        (p, q)
    }

    fn method(solver: Solver, origin: TimeOrigin) -> PaperMethod {
        PaperConfig {
            solver,
            time_origin: origin,
            ..PaperConfig::default()
        }
        .build()
        .unwrap()
    }

    fn fit(m: &mut PaperMethod, s: &Signals<'_>, window: Range<usize>) -> ([f64; 11], WindowFit) {
        let mut c = [0.0; 11];
        let f = m.fit(s, window, &mut c).unwrap();
        (c, f)
    }

    fn max_rel(a: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .map(|(x, y)| ((x - y) / y).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn coefficient_mapping_uses_the_factorials_of_eq_6() {
        let c = coefficients_from_polynomials([1.0; 3], [1.0; 8]);
        assert_eq!(
            c,
            [120.0, 720.0, 5040.0, 1.0, 1.0, 2.0, 6.0, 24.0, 120.0, 720.0, 5040.0]
        );
        let (p, q) = polynomials_from_coefficients(&[
            120.0, 720.0, 5040.0, 1.0, 1.0, 2.0, 6.0, 24.0, 120.0, 720.0, 5040.0,
        ]);
        assert_eq!(p, [1.0; 3]);
        assert_eq!(q, [1.0; 8]);
        // P5 = N2/120, Q7 = D0/5040, Q2 = D5/2
        let c = [
            4.10814e9, 1.60209e13, 6.63693e15, 1.68e-8, 2.69316e-4, 1.57906, 6.30146e3, 1.77277e7,
            2.71640e10, 2.55023e13, 6.63693e15,
        ];
        let (p, q) = polynomials_from_coefficients(&c);
        assert!((p[0] - 4.10814e9 / 120.0).abs() < 1e-6 * p[0]);
        assert!((q[7] - 6.63693e15 / 5040.0).abs() < 1e-6 * q[7]);
        assert!((q[2] - 1.57906 / 2.0).abs() < 1e-12);
        assert_eq!(q[0], 1.68e-8);
        let back = coefficients_from_polynomials(p, q);
        assert!(max_rel(&back, &c) < 1e-15);
    }

    #[test]
    fn coefficient_mapping_round_trips_from_polynomials() {
        let p = [3.3, -2.2e5, 7.1e-3];
        let q = [1.0, -2.0, 3.5, 4.25e3, -5.0e-4, 6.0, 7.0e9, -8.0];
        let (p2, q2) = polynomials_from_coefficients(&coefficients_from_polynomials(p, q));
        assert!(max_rel(&p2, &p) < 1e-15);
        assert!(max_rel(&q2, &q) < 1e-15);
    }

    #[test]
    fn legendre_table_matches_closed_forms() {
        let t = legendre_monomials();
        // L3 = (5s³ − 3s)/2, L7 = (429s⁷ − 693s⁵ + 315s³ − 35s)/16
        assert_eq!(t[3][..4], [0.0, -1.5, 0.0, 2.5]);
        let l7 = [
            0.0,
            -35.0 / 16.0,
            0.0,
            315.0 / 16.0,
            0.0,
            -693.0 / 16.0,
            0.0,
            429.0 / 16.0,
        ];
        assert!(
            max_rel(
                &t[7][1..].iter().step_by(2).copied().collect::<Vec<_>>(),
                &l7[1..].iter().step_by(2).copied().collect::<Vec<_>>()
            ) < 1e-15
        );
    }

    #[test]
    fn affine_change_of_variable_expands_binomially() {
        // 2 + 3·((τ − 1)/2) + 4·((τ − 1)/2)² = 2 − 1.5 + 1 + (1.5 − 2)τ + τ²
        let mut out = [0.0; 3];
        affine_to_monomial(&[2.0, 3.0, 4.0], 1.0, 2.0, &mut out);
        assert!(max_rel(&out, &[1.5, -0.5, 1.0]) < 1e-15);
    }

    #[test]
    fn exact_model_polynomial_is_reproduced_by_qr_to_rounding() {
        let span = (W - 1) as f64 * DT;
        // first window after the motion start, and window-local time
        let (p, q) = balanced(span);
        let d = model_data(&p, &q, 0.0, 0.0, W + H);
        let expected = coefficients_from_polynomials(p, q);
        for origin in [TimeOrigin::Motion, TimeOrigin::Window] {
            let mut m = method(Solver::Qr, origin);
            let (c, f) = fit(&mut m, &d.signals(0.0), 0..W);
            assert!(
                max_rel(&c, &expected) < 1e-9,
                "{origin:?}: {}",
                max_rel(&c, &expected)
            );
            assert_eq!(f.termination, Termination::Exact);
            assert!(f.residual_rms < 1e-16, "{}", f.residual_rms);
            let diag = m.diagnostics().unwrap();
            assert_eq!(diag.output_qr.unwrap().rank, 3);
            assert_eq!(diag.input_qr.unwrap().rank, 8);
        }
        // a later window (t0 = 10 ms): motion-origin polynomial balanced over [0, 14 ms]
        let t0 = 0.01;
        let (p, q) = balanced(t0 + span);
        let d = model_data(&p, &q, t0, 0.0, W);
        let mut m = method(Solver::Qr, TimeOrigin::Motion);
        let (c, f) = fit(&mut m, &d.signals(0.0), 0..W);
        let expected = coefficients_from_polynomials(p, q);
        // the fit itself is exact to rounding …
        assert!(f.residual_rms < 1e-17, "{}", f.residual_rms);
        // … the monomial coefficients lose the digits the change of basis
        // amplifies (~1e6 here): still 1e-6 relative
        assert!(m.diagnostics().unwrap().shift_amplification > 1e5);
        assert!(max_rel(&c, &expected) < 1e-6, "{}", max_rel(&c, &expected));
    }

    #[test]
    fn rig_coefficients_are_identified_from_noise_free_model_polynomials() {
        // N, D of the default rig (NOTES §1), first window after the motion start
        let c_true = [
            4.10814e9, 1.60209e13, 6.63693e15, 1.68e-8, 2.69316e-4, 1.57906, 6.30146e3, 1.77277e7,
            2.71640e10, 2.55023e13, 6.63693e15,
        ];
        let (p, q) = polynomials_from_coefficients(&c_true);
        let d = model_data(&p, &q, 0.0, 0.0, W);
        let mut m = method(Solver::Qr, TimeOrigin::Motion);
        let (c, _) = fit(&mut m, &d.signals(0.0), 0..W);
        // output coefficients and the dominant input terms to rounding level
        assert!(max_rel(&c[..3], &c_true[..3]) < 1e-9, "{:?}", &c[..3]);
        assert!(max_rel(&c[5..], &c_true[5..]) < 1e-7, "{:?}", &c[5..]);
        // D7 = Q0 contributes 3e-5 of the command over the window: relative
        // accuracy degrades accordingly but stays well below 1e-3
        assert!(max_rel(&c[3..5], &c_true[3..5]) < 1e-4, "{:?}", &c[3..5]);
    }

    #[test]
    fn simplex_and_qr_agree_to_1e_6_relative_on_exact_model_polynomials() {
        let span = (W - 1) as f64 * DT;
        let mut cases = Vec::new();
        let (p, q) = balanced(span);
        cases.push((TimeOrigin::Motion, model_data(&p, &q, 0.0, 0.0, W)));
        cases.push((TimeOrigin::Window, model_data(&p, &q, 0.0, 0.0, W)));
        // window-local polynomial 50 ms into the motion
        cases.push((TimeOrigin::Window, model_data(&p, &q, 0.05, 0.05, W)));
        let (p, q) = balanced(0.004 + span);
        cases.push((TimeOrigin::Motion, model_data(&p, &q, 0.004, 0.0, W)));
        let c_rig = [
            4.10814e9, 1.60209e13, 6.63693e15, 1.68e-8, 2.69316e-4, 1.57906, 6.30146e3, 1.77277e7,
            2.71640e10, 2.55023e13, 6.63693e15,
        ];
        let (p, q) = polynomials_from_coefficients(&c_rig);
        cases.push((TimeOrigin::Motion, model_data(&p, &q, 0.0, 0.0, W)));
        for (k, (origin, d)) in cases.iter().enumerate() {
            let s = d.signals(0.0);
            let (c_qr, _) = fit(&mut method(Solver::Qr, *origin), &s, 0..W);
            let (c_nm, f) = fit(&mut method(Solver::Simplex, *origin), &s, 0..W);
            assert_eq!(f.termination, Termination::Converged, "case {k}");
            assert!(f.iterations > 0);
            let e = max_rel(&c_nm, &c_qr);
            assert!(
                e < 1e-6,
                "case {k}: max relative difference {e:e}\n{c_nm:?}\n{c_qr:?}"
            );
        }
    }

    #[test]
    fn simplex_and_qr_predictions_agree_on_non_polynomial_data() {
        // a smooth non-polynomial motion: the fits are not exact, both solvers
        // must still find the same least-squares optimum
        let n = 200;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * DT).collect();
        let y: Vec<f64> = t
            .iter()
            .map(|&t| 1e-3 * (1.0 - (-40.0 * t).exp() * (1.0 + 40.0 * t)))
            .collect();
        let u: Vec<f64> = t
            .iter()
            .map(|&t| 1e-3 * (1.0 - (-60.0 * t).exp()))
            .collect();
        let d = Data { t, u, y };
        let s = d.signals(0.0);
        let mut qr = method(Solver::Qr, TimeOrigin::Motion);
        let mut nm = method(Solver::Simplex, TimeOrigin::Motion);
        for start in (0..n - W - H).step_by(H) {
            let win = start..start + W;
            let hor = start + W..start + W + H;
            let (_, fq) = fit(&mut qr, &s, win.clone());
            let (_, fs) = fit(&mut nm, &s, win.clone());
            assert!((fs.residual_rms - fq.residual_rms).abs() <= 1e-6 * fq.residual_rms + 1e-15);
            let mut pq = [0.0; H];
            let mut ps = [0.0; H];
            qr.predict(&s, win.clone(), hor.clone(), &mut pq).unwrap();
            nm.predict(&s, win, hor, &mut ps).unwrap();
            // the simplex resolves the optimum to the rounding level of the
            // sum of squares: agreement to 1e-6 of the data scale
            let scale = d.y[start..start + W]
                .iter()
                .fold(0.0f64, |a, v| a.max(v.abs()));
            for (a, b) in pq.iter().zip(&ps) {
                assert!((a - b).abs() < 1e-6 * scale, "window {start}: {a} vs {b}");
            }
        }
    }

    #[test]
    fn polynomial_prediction_is_the_fitted_output_polynomial_continued() {
        let n = W + H;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * DT).collect();
        // not of the model form: the fit is approximate
        let y: Vec<f64> = t
            .iter()
            .map(|&t| 2e-3 * (1.0 - (300.0 * t).cos()))
            .collect();
        let u: Vec<f64> = t.iter().map(|&t| 0.05 * t).collect();
        let d = Data { t, u, y };
        let s = d.signals(0.0);
        let mut m = method(Solver::Qr, TimeOrigin::Motion);
        let (c, f) = fit(&mut m, &s, 0..W);
        assert!(f.residual_rms > 0.0);
        let (p, _) = polynomials_from_coefficients(&c);
        let mut pred = [0.0; H];
        m.predict(&s, 0..W, W..n, &mut pred).unwrap();
        for (k, v) in pred.iter().enumerate() {
            let expected = eval_p(&p, d.t[W + k]);
            assert!(
                (v - expected).abs() < 1e-10 * expected.abs(),
                "{v} vs {expected}"
            );
        }
        // and on exact model data the continuation is the true continuation
        let (p, q) = balanced((W - 1) as f64 * DT);
        let d = model_data(&p, &q, 0.0, 0.0, n);
        let s = d.signals(0.0);
        fit(&mut m, &s, 0..W);
        m.predict(&s, 0..W, W..n, &mut pred).unwrap();
        for (k, v) in pred.iter().enumerate() {
            assert!((v - d.y[W + k]).abs() < 1e-12 * d.y[W + k].abs().max(1e-3));
        }
    }

    #[test]
    fn fitted_polynomials_match_the_identified_coefficients() {
        let n = W + H;
        let t: Vec<f64> = (0..n).map(|k| 0.003 + k as f64 * DT).collect();
        let y: Vec<f64> = t
            .iter()
            .map(|&t| 2e-3 * (1.0 - (300.0 * t).cos()))
            .collect();
        let u: Vec<f64> = t.iter().map(|&t| 1e-3 * (200.0 * t).sin()).collect();
        let d = Data { t, u, y };
        let s = d.signals(0.001);
        let mut m = method(Solver::Qr, TimeOrigin::Motion);
        assert!(m.fitted_command(0.0).is_none());
        let (c, _) = fit(&mut m, &s, 0..W);
        let (p, q) = polynomials_from_coefficients(&c);
        for &t in &d.t {
            let tau = t - 0.001;
            let (fy, fu) = (m.fitted_position(t).unwrap(), m.fitted_command(t).unwrap());
            assert!(
                (fy - eval_p(&p, tau)).abs() < 1e-9 * 2e-3,
                "{fy} vs {}",
                eval_p(&p, tau)
            );
            assert!(
                (fu - eval_q(&q, tau)).abs() < 1e-9 * 1e-3,
                "{fu} vs {}",
                eval_q(&q, tau)
            );
        }
        // and the fits are least-squares fits: residual orthogonal to a constant
        let mean_res: f64 = (0..W)
            .map(|k| d.u[k] - m.fitted_command(d.t[k]).unwrap())
            .sum::<f64>();
        assert!(mean_res.abs() < 1e-15, "{mean_res}");
    }

    #[test]
    fn window_local_time_origin_fits_polynomials_in_window_time() {
        let span = (W - 1) as f64 * DT;
        let (p, q) = balanced(span);
        let t0 = 0.0372;
        // data is a model polynomial in t − t0 (window-local time)
        let d = model_data(&p, &q, t0, t0, W + H);
        let s = d.signals(0.0);
        let mut local = method(Solver::Qr, TimeOrigin::Window);
        let (c, f) = fit(&mut local, &s, 0..W);
        let expected = coefficients_from_polynomials(p, q);
        assert!(max_rel(&c, &expected) < 1e-9, "{}", max_rel(&c, &expected));
        assert!(f.residual_rms < 1e-15);
        let mut pred = [0.0; H];
        local.predict(&s, 0..W, W..W + H, &mut pred).unwrap();
        for (k, v) in pred.iter().enumerate() {
            assert!((v - d.y[W + k]).abs() < 1e-12 * d.y[W + k].abs());
        }
        // the motion-origin model cannot represent it (non-zero value at the window start)
        let mut motion = method(Solver::Qr, TimeOrigin::Motion);
        let (_, f) = fit(&mut motion, &s, 0..W);
        assert!(f.residual_rms > 1e-6, "{}", f.residual_rms);
    }

    #[test]
    fn windows_far_from_the_origin_give_finite_coefficients_and_predictions() {
        // a 50 mm/s ramp observed 25 s after the motion start
        let t0 = 25.0;
        let n = W + H;
        let t: Vec<f64> = (0..n).map(|k| t0 + k as f64 * DT).collect();
        let y: Vec<f64> = t
            .iter()
            .map(|&t| 0.05 * (t - 0.0714) + 1e-6 * (50.0 * t).sin())
            .collect();
        let u: Vec<f64> = t.iter().map(|&t| 0.05 * t).collect();
        let d = Data { t, u, y };
        let s = d.signals(0.0);
        for solver in [Solver::Qr, Solver::Simplex] {
            let mut m = method(solver, TimeOrigin::Motion);
            let (c, f) = fit(&mut m, &s, 0..W);
            assert!(c.iter().all(|v| v.is_finite()), "{solver:?}: {c:?}");
            assert!(f.residual_rms.is_finite());
            let diag = m.diagnostics().unwrap();
            // the monomial coefficients are ill-conditioned and the diagnostics say so
            assert!(
                diag.shift_amplification > 1e20,
                "{}",
                diag.shift_amplification
            );
            let mut pred = [0.0; H];
            m.predict(&s, 0..W, W..n, &mut pred).unwrap();
            for (k, v) in pred.iter().enumerate() {
                assert!(v.is_finite());
                // the fitted family is locally smooth: a ramp is continued well
                assert!(
                    (v - d.y[W + k]).abs() < 1e-5,
                    "{solver:?} {k}: {v} vs {}",
                    d.y[W + k]
                );
            }
        }
    }

    #[test]
    fn worst_shift_amplification_matches_the_fit_diagnostics() {
        // windows 25 s after the motion start (the EMPS file's span)
        let n = 100;
        let t: Vec<f64> = (0..n).map(|k| 25.0 + k as f64 * DT).collect();
        let u: Vec<f64> = t.iter().map(|&t| 0.05 * t).collect();
        let s = Signals::new(&t, &u, &u, DT, 0.0);
        let cfg = crate::ident::EngineConfig {
            window: W,
            horizon: H,
            ..Default::default()
        };
        let mut m = method(Solver::Qr, TimeOrigin::Motion);
        let mut coef = [0.0; NAMES.len()];
        // the last window is the farthest from the origin
        let (last, _) = cfg.windows(n, 0).last().unwrap();
        m.fit(&s, last, &mut coef).unwrap();
        let fitted = m.diagnostics().unwrap().shift_amplification;
        let worst = m.config.worst_shift_amplification(&s, &cfg);
        assert!((worst / fitted - 1.0).abs() < 1e-12, "{worst} vs {fitted}");
        assert!(worst > SHIFT_AMPLIFICATION_WARNING);
        // each window's own origin: (1 + 1)⁷
        let w = PaperConfig {
            time_origin: TimeOrigin::Window,
            ..PaperConfig::default()
        };
        assert!((w.worst_shift_amplification(&s, &cfg) - 128.0).abs() < 1e-9);
    }

    #[test]
    fn window_straddling_the_motion_start_is_handled() {
        // rest before motion_start = 1 ms, then a model polynomial
        let (p, q) = balanced(0.004);
        let ms = 1e-3;
        let t: Vec<f64> = (0..W + H).map(|k| k as f64 * DT).collect();
        let y: Vec<f64> = t
            .iter()
            .map(|&t| if t < ms { 0.0 } else { eval_p(&p, t - ms) })
            .collect();
        let u: Vec<f64> = t
            .iter()
            .map(|&t| if t < ms { 0.0 } else { eval_q(&q, t - ms) })
            .collect();
        let d = Data { t, u, y };
        let s = d.signals(ms);
        for solver in [Solver::Qr, Solver::Simplex] {
            let mut m = method(solver, TimeOrigin::Motion);
            let (c, f) = fit(&mut m, &s, 0..W);
            assert!(c.iter().all(|v| v.is_finite()) && f.residual_rms.is_finite());
            let mut pred = [0.0; H];
            m.predict(&s, 0..W, W..W + H, &mut pred).unwrap();
            assert!(pred.iter().all(|v| v.is_finite()));
        }
    }

    #[test]
    fn zero_data_gives_zero_coefficients() {
        let d = Data {
            t: (0..W + H).map(|k| k as f64 * DT).collect(),
            u: vec![0.0; W + H],
            y: vec![0.0; W + H],
        };
        for solver in [Solver::Qr, Solver::Simplex] {
            let mut m = method(solver, TimeOrigin::Motion);
            let (c, f) = fit(&mut m, &d.signals(0.0), 0..W);
            assert!(c.iter().all(|v| *v == 0.0), "{c:?}");
            assert_eq!(f.residual_rms, 0.0);
        }
    }

    #[test]
    fn windows_ending_at_or_before_the_motion_start_are_rest_windows() {
        let (p, q) = balanced(0.004);
        let mut d = model_data(&p, &q, 0.0, 0.0, W + H);
        d.y.iter_mut().for_each(|y| *y += 1e-3);
        let last = d.y[W - 1];
        for (ms, rest) in [
            (f64::INFINITY, true),
            (d.t[W - 1], true),
            (d.t[W - 1] + 1e-9, true),
            (d.t[W - 2], false),
        ] {
            for solver in [Solver::Qr, Solver::Simplex] {
                let mut m = method(solver, TimeOrigin::Motion);
                let mut c = [1.0; 11];
                let s = d.signals(ms);
                let f = m.fit(&s, 0..W, &mut c).unwrap();
                let mut pred = [0.0; H];
                m.predict(&s, 0..W, W..W + H, &mut pred).unwrap();
                if rest {
                    assert_eq!(f.termination, Termination::Fallback);
                    assert_eq!(c, [0.0; 11]);
                    assert!(pred.iter().all(|&v| v == last), "{pred:?}");
                    assert!(m.fitted_position(d.t[0]).is_none());
                } else {
                    assert_ne!(f.termination, Termination::Fallback);
                    assert!(c.iter().any(|&v| v != 0.0));
                    assert!(pred.iter().all(|&v| v != last));
                }
            }
        }
        // the window-local origin ignores the motion start
        let mut m = method(Solver::Qr, TimeOrigin::Window);
        let f = m
            .fit(&d.signals(f64::INFINITY), 0..W, &mut [0.0; 11])
            .unwrap();
        assert_eq!(f.termination, Termination::Exact);
    }

    #[test]
    fn only_the_polynomial_prediction_does_without_the_future_command() {
        assert!(!method(Solver::Qr, TimeOrigin::Motion).uses_future_command());
        let mut m = method(Solver::Qr, TimeOrigin::Motion);
        m.config.prediction = PredictionMode::TransferFunction;
        assert!(m.uses_future_command());
    }

    #[test]
    fn buffers_are_not_regrown_for_windows_of_the_same_size() {
        let (p, q) = balanced(0.004);
        let d = model_data(&p, &q, 0.0, 0.0, 100);
        let s = d.signals(0.0);
        let mut m = method(Solver::Simplex, TimeOrigin::Motion);
        fit(&mut m, &s, 0..W);
        let ptrs = (m.tau.as_ptr(), m.design_in.as_ptr(), m.work.as_ptr(), m.cap);
        for start in (10..80).step_by(10) {
            fit(&mut m, &s, start..start + W);
            assert_eq!(
                ptrs,
                (m.tau.as_ptr(), m.design_in.as_ptr(), m.work.as_ptr(), m.cap)
            );
        }
        // a longer window grows once
        fit(&mut m, &s, 0..2 * W);
        assert_eq!(m.cap, 2 * W);
    }

    #[test]
    fn simplex_cap_is_reported_as_max_iterations() {
        let (p, q) = balanced(0.004);
        let d = model_data(&p, &q, 0.0, 0.0, W);
        let mut m = PaperConfig {
            solver: Solver::Simplex,
            simplex: SimplexSettings {
                max_iterations: 5,
                ..SimplexSettings::default()
            },
            ..PaperConfig::default()
        }
        .build()
        .unwrap();
        let (c, f) = fit(&mut m, &d.signals(0.0), 0..W);
        assert_eq!(f.termination, Termination::MaxIterations);
        assert_eq!(f.iterations, 10);
        assert!(c.iter().all(|v| v.is_finite()));
    }

    #[test]
    fn estimator_metadata_and_errors() {
        let m = method(Solver::Qr, TimeOrigin::Motion);
        assert_eq!(m.name(), "paper");
        assert_eq!(
            m.coefficient_names(),
            ["N2", "N1", "N0", "D7", "D6", "D5", "D4", "D3", "D2", "D1", "D0"]
        );
        let (p, q) = balanced(0.004);
        let mut d = model_data(&p, &q, 0.0, 0.0, W + H);
        let mut m = method(Solver::Qr, TimeOrigin::Motion);
        let mut c = [0.0; 11];
        let mut out = [0.0; H];
        assert!(matches!(
            m.predict(&d.signals(0.0), 0..W, W..W + H, &mut out),
            Err(Error::InvalidModel { .. })
        ));
        assert!(matches!(
            m.fit(&d.signals(0.0), 0..7, &mut c),
            Err(Error::TooFewSamples { .. })
        ));
        assert!(matches!(
            m.fit(&d.signals(0.0), 25..45, &mut c),
            Err(Error::TooFewSamples { .. })
        ));
        assert!(matches!(
            m.fit(&d.signals(0.0), 0..W, &mut c[..10]),
            Err(Error::LengthMismatch { .. })
        ));
        d.y[3] = f64::NAN;
        assert!(matches!(
            m.fit(&d.signals(0.0), 0..W, &mut c),
            Err(Error::NonFinite { index: 3, .. })
        ));
        assert_eq!(
            "tf".parse::<PredictionMode>().unwrap(),
            PredictionMode::TransferFunction
        );
        let bad = PaperConfig {
            simplex: SimplexSettings {
                step_rel: 0.0,
                ..SimplexSettings::default()
            },
            ..PaperConfig::default()
        };
        assert!(matches!(bad.build(), Err(Error::InvalidParameter { .. })));
        assert_eq!("simplex".parse::<Solver>().unwrap(), Solver::Simplex);
        assert_eq!("window".parse::<TimeOrigin>().unwrap(), TimeOrigin::Window);
        assert!("lsq".parse::<Solver>().is_err());
    }

    #[test]
    fn rest_windows_hold_the_last_position_and_report_fallback() {
        let n = 60;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * DT).collect();
        let y = vec![0.25; n];
        let u = vec![0.25; n];
        let d = Data { t, u, y };
        // motion starts after the data: every window is a rest window
        let s = d.signals(f64::INFINITY);
        let mut m = method(Solver::Qr, TimeOrigin::Motion);
        let (c, f) = fit(&mut m, &s, 0..W);
        assert_eq!(f.termination, Termination::Fallback);
        assert!(c.iter().all(|&v| v == 0.0));
        let mut pred = vec![0.0; H];
        m.predict(&s, 0..W, W..W + H, &mut pred).unwrap();
        assert!(pred.iter().all(|&v| v == 0.25));
    }

    #[test]
    fn rest_position_offset_does_not_change_the_prediction() {
        // The same motion measured from 0 and from a rest position of 0.1 m.
        let span = (W - 1) as f64 * DT;
        let (p, q) = balanced(span + 0.004);
        let rest = 10;
        let n = rest + W + H;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * DT).collect();
        let t_m = t[rest - 1];
        let shape = |tt: f64| if tt <= t_m { 0.0 } else { eval_p(&p, tt - t_m) };
        let y0: Vec<f64> = t.iter().map(|&tt| shape(tt)).collect();
        let y1: Vec<f64> = y0.iter().map(|v| v + 0.1).collect();
        let u: Vec<f64> = t
            .iter()
            .map(|&tt| eval_q(&q, (tt - t_m).max(0.0)))
            .collect();
        let mut preds = Vec::new();
        for y in [y0, y1] {
            let d = Data {
                t: t.clone(),
                u: u.clone(),
                y,
            };
            let s = d.signals(t_m);
            let mut m = method(Solver::Qr, TimeOrigin::Motion);
            let w = rest..rest + W;
            fit(&mut m, &s, w.clone());
            let mut pred = vec![0.0; H];
            m.predict(&s, w, rest + W..n, &mut pred).unwrap();
            preds.push(pred);
        }
        for (a, b) in preds[0].iter().zip(&preds[1]) {
            assert!((b - a - 0.1).abs() < 1e-12, "{a} {b}");
        }
    }

    #[test]
    fn reset_forgets_the_last_fit() {
        let (p, q) = balanced(0.004);
        let d = model_data(&p, &q, 0.0, 0.0, W + H);
        let mut m = method(Solver::Qr, TimeOrigin::Motion);
        fit(&mut m, &d.signals(0.0), 0..W);
        m.reset();
        let mut out = [0.0; H];
        assert!(m
            .predict(&d.signals(0.0), 0..W, W..W + H, &mut out)
            .is_err());
        assert!(m.diagnostics().is_none());
    }

    #[test]
    fn signals_with_offset_are_indexed_absolutely() {
        let (p, q) = balanced(0.004);
        let d = model_data(&p, &q, 0.0, 0.0, 60);
        let full = d.signals(0.0);
        let mut view = full;
        view.offset = 30;
        view.time = &d.t[30..];
        view.command = &d.u[30..];
        view.position = &d.y[30..];
        let mut a = method(Solver::Qr, TimeOrigin::Motion);
        let mut b = method(Solver::Qr, TimeOrigin::Motion);
        let (ca, _) = fit(&mut a, &full, 35..55);
        let (cb, _) = fit(&mut b, &view, 35..55);
        assert_eq!(ca, cb);
    }

    #[test]
    fn sliding_engine_runs_the_paper_method_on_a_lagged_ramp_without_nan() {
        use crate::ident::engine::{run, EngineConfig};
        // 50 mm/s ramp through a first-order lag 1/Kv (Kv = 700 1/s): the
        // following error settles at v/Kv = 71.4 µm
        let (v, tl) = (0.05, 1.0 / 700.0);
        let n = 600;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * DT).collect();
        let u: Vec<f64> = t.iter().map(|&t| v * t).collect();
        let y: Vec<f64> = t
            .iter()
            .map(|&t| v * (t - tl * (1.0 - (-t / tl).exp())))
            .collect();
        let s = Signals::new(&t, &u, &y, DT, 0.0);
        let mut qr = method(Solver::Qr, TimeOrigin::Motion);
        let rq = run(&mut qr, &s, &EngineConfig::default()).unwrap();
        assert!(rq
            .windows
            .iter()
            .all(|w| w.fit.termination == Termination::Exact));
        assert!(rq.stats.samples > 500);
        assert!(rq.stats.rms.is_finite() && rq.stats.max_abs.is_finite());
        // independent reference (NumPy lstsq on t⁵, t⁶, t⁷ over samples 0..20,
        // extrapolated to 20..30): residual rms 7.71355e-6 m and a horizon
        // error of 9.56182e-3 m — the t⁵…t⁷ model cannot follow the start
        // of a lagged ramp, and its extrapolation blows up (NOTES §2)
        let w0 = &rq.windows[0];
        let e0 = w0
            .horizon
            .clone()
            .map(|k| (rq.predicted[k] - y[k]).abs())
            .fold(0.0, f64::max);
        assert!(
            (w0.fit.residual_rms / 7.713548e-6 - 1.0).abs() < 1e-5,
            "{}",
            w0.fit.residual_rms
        );
        assert!((e0 / 9.5618237e-3 - 1.0).abs() < 1e-6, "{e0}");
        // once the motion is established the continuation improves steadily
        let last = rq.windows.last().unwrap();
        let el = last
            .horizon
            .clone()
            .map(|k| (rq.predicted[k] - y[k]).abs())
            .fold(0.0, f64::max);
        assert!(el < 5e-6, "{el}");
        let mut nm = method(Solver::Simplex, TimeOrigin::Motion);
        let rs = run(&mut nm, &s, &EngineConfig::default()).unwrap();
        assert!(rs
            .windows
            .iter()
            .all(|w| w.fit.termination == Termination::Converged));
        for k in 0..n {
            assert_eq!(rq.has_prediction[k], rs.has_prediction[k]);
            if rq.has_prediction[k] {
                assert!(
                    (rq.predicted[k] - rs.predicted[k]).abs() < 1e-6 * y[n - 1],
                    "sample {k}"
                );
            }
        }
    }

    /// Rig data: exact model polynomials of the default rig's `N`, `D` over `n` samples.
    fn rig_data(n: usize) -> ([f64; 11], Data) {
        use crate::drive::{closed_loop_coefficients, D1Variant, RigParams};
        let cl = closed_loop_coefficients(&RigParams::default(), D1Variant::Corrected);
        let mut c = [0.0; 11];
        c[..3].copy_from_slice(&cl.num);
        c[3..].copy_from_slice(&cl.den);
        let (p, q) = polynomials_from_coefficients(&c);
        (c, model_data(&p, &q, 0.0, 0.0, n))
    }

    fn tf_method() -> PaperMethod {
        PaperConfig {
            prediction: PredictionMode::TransferFunction,
            ..PaperConfig::default()
        }
        .build()
        .unwrap()
    }

    #[test]
    fn transfer_function_prediction_equals_polynomial_when_the_command_follows_the_fit() {
        let (_, d) = rig_data(W + H);
        let s = d.signals(0.0);
        let mut poly = method(Solver::Qr, TimeOrigin::Motion);
        let mut tf = tf_method();
        fit(&mut poly, &s, 0..W);
        fit(&mut tf, &s, 0..W);
        let (mut a, mut b) = ([0.0; H], [0.0; H]);
        poly.predict(&s, 0..W, W..W + H, &mut a).unwrap();
        tf.predict(&s, 0..W, W..W + H, &mut b).unwrap();
        assert_eq!(tf.tf_fallbacks(), 0);
        assert!(!tf.diagnostics().unwrap().tf_fallback);
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() < 1e-9 * x.abs(), "{x} vs {y}");
        }
    }

    #[test]
    fn transfer_function_prediction_adds_the_step_response_to_a_command_deviation() {
        use crate::drive::{closed_loop_state_space, RigParams};
        let (_, mut d) = rig_data(W + H);
        // the actual command leaves the fitted polynomial by a 1 µm step at the horizon start
        let delta = 1e-6;
        for k in W..W + H {
            d.u[k] += delta;
        }
        let s = d.signals(0.0);
        let mut poly = method(Solver::Qr, TimeOrigin::Motion);
        let mut tf = tf_method();
        fit(&mut poly, &s, 0..W);
        fit(&mut tf, &s, 0..W);
        let (mut a, mut b) = ([0.0; H], [0.0; H]);
        poly.predict(&s, 0..W, W..W + H, &mut a).unwrap();
        tf.predict(&s, 0..W, W..W + H, &mut b).unwrap();
        assert_eq!(tf.tf_fallbacks(), 0);
        // reference: step response of the physical 7-state model of the rig
        let step = closed_loop_state_space(&RigParams::default())
            .unwrap()
            .step_response(DT, H)
            .unwrap();
        assert!(
            step[H - 1] > 0.05,
            "the step response must be visible: {}",
            step[H - 1]
        );
        for k in 0..H {
            let added = b[k] - a[k];
            assert!(
                (added - delta * step[k]).abs() < 1e-4 * delta,
                "sample {k}: {added:e} vs {:e}",
                delta * step[k]
            );
        }
    }

    #[test]
    fn unstable_identified_transfer_function_falls_back_to_the_polynomial() {
        // balanced polynomials with mixed-sign D coefficients: not Hurwitz
        let (p, q) = balanced((W - 1) as f64 * DT);
        let mut d = model_data(&p, &q, 0.0, 0.0, W + H);
        for k in W..W + H {
            d.u[k] += 1e-4;
        }
        let s = d.signals(0.0);
        let mut poly = method(Solver::Qr, TimeOrigin::Motion);
        let mut tf = tf_method();
        let (c, _) = fit(&mut tf, &s, 0..W);
        assert!(c[3..].iter().any(|v| *v < 0.0) && c[3..].iter().any(|v| *v > 0.0));
        fit(&mut poly, &s, 0..W);
        let (mut a, mut b) = ([0.0; H], [0.0; H]);
        poly.predict(&s, 0..W, W..W + H, &mut a).unwrap();
        tf.predict(&s, 0..W, W..W + H, &mut b).unwrap();
        assert_eq!(a, b);
        assert!(b.iter().all(|v| v.is_finite()));
        assert_eq!(tf.tf_fallbacks(), 1);
        assert!(tf.diagnostics().unwrap().tf_fallback);
        tf.reset();
        assert_eq!(tf.tf_fallbacks(), 0);
    }

    #[test]
    fn transfer_function_mode_runs_in_the_engine_without_nan() {
        use crate::ident::engine::{run, EngineConfig};
        let (v, tl) = (0.05, 1.0 / 700.0);
        let n = 400;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * DT).collect();
        let u: Vec<f64> = t.iter().map(|&t| v * t).collect();
        let y: Vec<f64> = t
            .iter()
            .map(|&t| v * (t - tl * (1.0 - (-t / tl).exp())))
            .collect();
        let s = Signals::new(&t, &u, &y, DT, 0.0);
        let mut tf = tf_method();
        let r = run(&mut tf, &s, &EngineConfig::default()).unwrap();
        assert!(r.stats.samples > 300);
        assert!(r.stats.rms.is_finite() && r.stats.max_abs.is_finite());
        assert!(r
            .predicted
            .iter()
            .zip(&r.has_prediction)
            .all(|(p, h)| !h || p.is_finite()));
    }
}
