//! Settings of the paper's method: solver, time origin, prediction mode,
//! simplex tolerances, and how far from the time origin the windows lie.

use std::str::FromStr;

use super::estimator::PaperMethod;
use crate::error::{Error, Result};
use crate::ident::engine::Signals;
use crate::ident::option::{MethodOption, MethodSettings, OptionKind, OptionSpec, OptionValue};

/// Option `solver` of `paper` ([`PaperConfig::solver`]).
const SOLVER_OPTION: OptionSpec = OptionSpec {
    key: "solver",
    python: None,
    value_name: "NAME",
    kind: OptionKind::Choice(&["qr", "simplex"]),
    range: None,
    unit: None,
    help: "solver, qr (exact least squares) or simplex (Nelder–Mead, as in the paper)",
    requires: None,
};

/// Option `time_origin` of `paper` ([`PaperConfig::time_origin`]).
const TIME_ORIGIN_OPTION: OptionSpec = OptionSpec {
    key: "time_origin",
    python: None,
    value_name: "NAME",
    kind: OptionKind::Choice(&["motion", "window"]),
    range: None,
    unit: None,
    help: "time origin, motion (start of motion) or window (each window's first sample; \
           accurate coefficients, but it cannot predict a moving axis)",
    requires: None,
};

/// Option `prediction` of `paper` ([`PaperConfig::prediction`]).
const PREDICTION_OPTION: OptionSpec = OptionSpec {
    key: "prediction",
    python: None,
    value_name: "NAME",
    kind: OptionKind::Choice(&["polynomial", "tf"]),
    range: None,
    unit: None,
    help: "prediction, polynomial (fitted output continued) or tf (identified Tf on the next \
           command)",
    requires: None,
};

/// Option `simplex_start` of `paper` ([`PaperConfig::simplex_start`]).
const SIMPLEX_START_OPTION: OptionSpec = OptionSpec {
    key: "simplex_start",
    python: None,
    value_name: "NAME",
    kind: OptionKind::Choice(&["zeros", "previous"]),
    range: None,
    unit: None,
    help: "start of each window's simplex, zeros (every window on its own) or previous (the \
           previous window's fit: fewer iterations, about 2.5× faster)",
    requires: Some(("solver", "simplex")),
};

impl MethodSettings for PaperConfig {
    fn options(&self) -> &'static [MethodOption] {
        const OPTIONS: &[MethodOption] = &[
            MethodOption::new(&SOLVER_OPTION),
            MethodOption::new(&TIME_ORIGIN_OPTION),
            MethodOption::new(&PREDICTION_OPTION),
            MethodOption::new(&SIMPLEX_START_OPTION),
        ];
        OPTIONS
    }

    fn option(&self, key: &str) -> Option<OptionValue> {
        let label = match key {
            "solver" => self.solver.label(),
            "time_origin" => self.time_origin.label(),
            "prediction" => self.prediction.label(),
            "simplex_start" => self.simplex_start.label(),
            _ => return None,
        };
        Some(OptionValue::Choice(label.to_string()))
    }

    fn set_option(&mut self, key: &str, value: &OptionValue) -> Result<()> {
        let s = match value {
            OptionValue::Choice(s) => s.as_str(),
            _ => "",
        };
        match key {
            "solver" => self.solver = s.parse()?,
            "time_origin" => self.time_origin = s.parse()?,
            "prediction" => self.prediction = s.parse()?,
            "simplex_start" => self.simplex_start = s.parse()?,
            _ => {
                return Err(Error::UnknownOption {
                    key: key.to_string(),
                    known: "solver, time_origin, prediction, simplex_start".to_string(),
                })
            }
        }
        Ok(())
    }
}

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

/// Where the simplex starts in each window ([`Solver::Simplex`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SimplexStart {
    /// Zero coefficients, start steps `step_rel·‖b‖` (default; every window
    /// independent of the others, as the paper's description reads).
    #[default]
    Zeros,
    /// The previous window's fitted polynomials, projected on this window's
    /// basis (zero after a rest window or [`Estimator::reset`](crate::ident::Estimator::reset)), with start
    /// steps `step_rel` times the distance of that start from the best
    /// polynomial of degree 7 (at least `100·xtol_data·‖b‖`). Fewer
    /// iterations; results then depend on the previous window (the same in
    /// batch and streaming use, which visit the same windows in order).
    Previous,
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

impl SimplexStart {
    /// Lowercase name as used on the command line.
    pub fn label(self) -> &'static str {
        match self {
            SimplexStart::Zeros => "zeros",
            SimplexStart::Previous => "previous",
        }
    }
}

impl FromStr for SimplexStart {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s.to_ascii_lowercase().as_str() {
            "zeros" | "zero" => Ok(SimplexStart::Zeros),
            "previous" => Ok(SimplexStart::Previous),
            _ => Err(Error::InvalidChoice {
                what: "simplex start",
                value: s.to_string(),
                expected: "zeros, previous",
            }),
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
/// The fit stops ([`Termination::Converged`](crate::solve::Termination::Converged)) when the simplex size is
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
    /// Start of the simplex in each window (used with [`Solver::Simplex`]).
    /// Default [`SimplexStart::Zeros`].
    pub simplex_start: SimplexStart,
}

/// Growth factor `(1 + |τ_c|/h)⁷` of the change of basis to monomial
/// coefficients for a window spanning `τ_first … τ_last` (see
/// [`PaperDiagnostics::shift_amplification`](crate::ident::PaperDiagnostics::shift_amplification)); infinite for an empty span.
pub(super) fn shift_amplification(tau_first: f64, tau_last: f64) -> f64 {
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
    /// The largest [`PaperDiagnostics::shift_amplification`](crate::ident::PaperDiagnostics::shift_amplification) over the windows
    /// that `config` visits on `signals` (offset 0): how far from the time
    /// origin the windows lie. Above [`SHIFT_AMPLIFICATION_WARNING`] the
    /// identified `N`, `D` lose accuracy (predictions in
    /// [`PredictionMode::Polynomial`] do not). `1.0` when no window fits.
    pub fn worst_shift_amplification(
        &self,
        signals: &Signals<'_>,
        config: &crate::ident::engine::EngineConfig,
    ) -> f64 {
        let time = signals.all().time;
        let mut worst = 1.0f64;
        for (w, _) in config.windows(time.len(), 0) {
            let (Some(&first), Some(&last)) = (
                time.get(w.start),
                w.end.checked_sub(1).and_then(|e| time.get(e)),
            ) else {
                continue;
            };
            let origin = match self.time_origin {
                TimeOrigin::Motion => signals.motion_start(),
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
        self.validate()?;
        Ok(PaperMethod::new(self))
    }

    /// Check the simplex settings (finite non-negative tolerances, positive
    /// start step, iteration and evaluation caps of at least 1; a simplex
    /// start other than zeros only with the simplex solver).
    pub fn validate(&self) -> Result<()> {
        if self.simplex_start != SimplexStart::Zeros && self.solver != Solver::Simplex {
            return Err(Error::NotApplicable {
                setting: "simplex start",
                method: "paper (qr solver)",
                applies_to: "paper with the simplex solver",
            });
        }
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
        Ok(())
    }
}
