//! The one estimator trait that the sliding engine, the streaming path, the CLI
//! and the benchmarks use for every method.

use std::ops::Range;

use crate::error::Result;
use crate::ident::engine::Signals;
use crate::solve::Termination;

/// What a window's fit produced (returned by [`Estimator::fit`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindowFit {
    /// RMS of the output fit residual over the window \[m\].
    pub residual_rms: f64,
    /// Solver iterations (0 for direct solutions).
    pub iterations: usize,
    /// Whether a model was identified from this window, and how its solver stopped.
    pub status: FitStatus,
}

impl WindowFit {
    /// A model identified from this window; `termination`: how its solver stopped.
    pub fn identified(residual_rms: f64, iterations: usize, termination: Termination) -> Self {
        Self {
            residual_rms,
            iterations,
            status: FitStatus::Identified(termination),
        }
    }

    /// The window was not informative (or its model was rejected): the last
    /// good model is kept and predicts.
    pub fn fallback(residual_rms: f64, iterations: usize) -> Self {
        Self {
            residual_rms,
            iterations,
            status: FitStatus::Fallback,
        }
    }
}

/// Whether a window identified a model of its own.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FitStatus {
    /// A model was identified from this window; how its solver stopped.
    Identified(Termination),
    /// The window was not informative or its model was rejected; the last
    /// good model is kept (a value, not an error: the window still predicts).
    Fallback,
}

/// What [`Estimator::predict`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PredictStatus {
    /// The prediction was written.
    Predicted,
    /// The method declined to predict this horizon (its model is not
    /// validated for it, `auto`); nothing in the output is used.
    Withheld {
        /// Why, in a few words.
        reason: &'static str,
    },
}

/// What became of one window in the engine (fit and prediction together),
/// kept apart from how a solver terminated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum WindowOutcome {
    /// A model was identified and predicted; how its solver stopped.
    Predicted(Termination),
    /// The window kept the last good model, which predicted.
    Fallback,
    /// A model was identified but its prediction was withheld: the method
    /// declined ([`PredictStatus::Withheld`]) or the engine found it
    /// implausible ([`GuardConfig::plausibility`](crate::ident::GuardConfig::plausibility)).
    Withheld,
    /// The fit or the prediction failed (an error or a non-finite value): no prediction.
    Failed,
}

impl WindowOutcome {
    /// The outcome of a window from its fit and prediction status.
    pub fn of(fit: FitStatus, predicted: PredictStatus) -> Self {
        match (predicted, fit) {
            (PredictStatus::Withheld { .. }, _) => WindowOutcome::Withheld,
            (PredictStatus::Predicted, FitStatus::Identified(t)) => WindowOutcome::Predicted(t),
            (PredictStatus::Predicted, FitStatus::Fallback) => WindowOutcome::Fallback,
        }
    }

    /// Whether the window produced a prediction (neither failed nor withheld).
    pub fn predicted(self) -> bool {
        matches!(self, WindowOutcome::Predicted(_) | WindowOutcome::Fallback)
    }

    /// Short lowercase label for tables and CSV files: the solver's
    /// termination of a predicting window (`exact`, `converged`,
    /// `max_iterations`), else `fallback`, `withheld` or `failed`.
    pub fn label(self) -> &'static str {
        match self {
            WindowOutcome::Predicted(t) => t.label(),
            WindowOutcome::Fallback => "fallback",
            WindowOutcome::Withheld => "withheld",
            WindowOutcome::Failed => "failed",
        }
    }
}

/// An identification method usable over sliding windows.
///
/// Causality contract: `fit` reads position and command only in
/// `..window.end`; `predict` reads position in `..window.end` and command in
/// `..horizon.end` (the command is known ahead, it is the set-point).
/// Implementations allocate nothing in `fit`/`predict` after the first call
/// with a given window size.
pub trait Estimator {
    /// Short method name (`"paper"`, `"arx"`, ...).
    fn name(&self) -> &'static str;

    /// Names of the coefficients `fit` writes (column headers), in order.
    fn coefficient_names(&self) -> Vec<String>;

    /// Samples needed before a window's first sample (e.g. past outputs of an ARX model).
    fn warm_up(&self) -> usize {
        0
    }

    /// Whether `predict` reads the command over the horizon (default `true`).
    ///
    /// The command is the set-point, known ahead in a CNC; the streaming path
    /// ([`crate::ident::stream::Streamer`]) emits a prediction of such an
    /// estimator only once the command over its horizon has arrived. Methods
    /// that predict from the window alone return `false` and are emitted at
    /// the window end.
    fn uses_future_command(&self) -> bool {
        true
    }

    /// Forget all state (start of a new recording).
    fn reset(&mut self) {}

    /// Learn again: the engine found the last prediction implausible (see
    /// [`GuardConfig::plausibility`](crate::ident::GuardConfig::plausibility)),
    /// so the model behind it is not to be trusted. Default:
    /// [`Estimator::reset`].
    fn restart(&mut self) {
        self.reset()
    }

    /// A gap of dropped samples: the samples after it are not consecutive
    /// with those before ([`crate::Recording::gaps`]), so nothing may pair
    /// them (no regressor, no window across the gap), but the drive is the
    /// same. The engine calls this at the start of every segment after the
    /// first, and the stream at a gap. Default: [`Estimator::reset`] (the
    /// paper's method, which needs a motion start); `arx`, `rls`, `oe` and
    /// `auto` (its candidates and their scores) keep the model they learnt
    /// (and predict from it until the new segment has informed a better
    /// one) and forget only what pairs samples — unless the sample interval
    /// changed (a stream's gap may be a change of the rate, by more than
    /// 5 %: a discrete model then no longer holds and they reset).
    fn gap(&mut self) {
        self.reset()
    }

    /// Whether the engine withholds this method's implausible predictions
    /// ([`GuardConfig::plausibility`](crate::ident::GuardConfig::plausibility);
    /// default `true`). The paper's method answers `false`: it is
    /// reproduced as published, wild polynomial extrapolations included.
    fn checks_plausibility(&self) -> bool {
        true
    }

    /// Identify from the samples `window` (absolute indices) and write the
    /// coefficients into `coef` (length `coefficient_names().len()`).
    fn fit(
        &mut self,
        signals: &Signals<'_>,
        window: Range<usize>,
        coef: &mut [f64],
    ) -> Result<WindowFit>;

    /// Predict the measured position over `horizon` (which starts at
    /// `window.end`) into `out` (length `horizon.len()`), from the last fit;
    /// or decline to ([`PredictStatus::Withheld`]).
    fn predict(
        &mut self,
        signals: &Signals<'_>,
        window: Range<usize>,
        horizon: Range<usize>,
        out: &mut [f64],
    ) -> Result<PredictStatus>;
}

/// A boxed estimator is an estimator (so `Streamer<Box<dyn Estimator>>` and
/// [`crate::ident::engine::run`] work with methods chosen at run time).
impl<E: Estimator + ?Sized> Estimator for Box<E> {
    fn name(&self) -> &'static str {
        (**self).name()
    }
    fn coefficient_names(&self) -> Vec<String> {
        (**self).coefficient_names()
    }
    fn warm_up(&self) -> usize {
        (**self).warm_up()
    }
    fn uses_future_command(&self) -> bool {
        (**self).uses_future_command()
    }
    fn reset(&mut self) {
        (**self).reset()
    }
    fn restart(&mut self) {
        (**self).restart()
    }
    fn gap(&mut self) {
        (**self).gap()
    }
    fn checks_plausibility(&self) -> bool {
        (**self).checks_plausibility()
    }
    fn fit(
        &mut self,
        signals: &Signals<'_>,
        window: Range<usize>,
        coef: &mut [f64],
    ) -> Result<WindowFit> {
        (**self).fit(signals, window, coef)
    }
    fn predict(
        &mut self,
        signals: &Signals<'_>,
        window: Range<usize>,
        horizon: Range<usize>,
        out: &mut [f64],
    ) -> Result<PredictStatus> {
        (**self).predict(signals, window, horizon, out)
    }
}

/// Whether the sample interval `dt` differs from the one a model was
/// learnt at (`learnt`, 0 = none yet) by more than 5 %: a discrete-time
/// model does not carry over (a stream's gap may be a change of the rate).
pub(crate) fn rate_changed(learnt: f64, dt: f64) -> bool {
    learnt > 0.0 && ((dt - learnt).abs() > 0.05 * learnt || dt.is_nan())
}
