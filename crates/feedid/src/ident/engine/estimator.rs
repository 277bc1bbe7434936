//! The one estimator trait that the sliding engine, the streaming path, the CLI
//! and the benchmarks use for every method.

use std::ops::Range;

use crate::error::Result;
use crate::ident::Signals;
use crate::solve::Termination;

/// Outcome of fitting one window.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindowFit {
    /// RMS of the output fit residual over the window \[m\].
    pub residual_rms: f64,
    /// Solver iterations (0 for direct solutions).
    pub iterations: usize,
    /// Why the fit stopped.
    pub termination: Termination,
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

    /// Identify from the samples `window` (absolute indices) and write the
    /// coefficients into `coef` (length `coefficient_names().len()`).
    fn fit(
        &mut self,
        signals: &Signals<'_>,
        window: Range<usize>,
        coef: &mut [f64],
    ) -> Result<WindowFit>;

    /// Predict the measured position over `horizon` (which starts at
    /// `window.end`) into `out` (length `horizon.len()`), from the last fit.
    fn predict(
        &mut self,
        signals: &Signals<'_>,
        window: Range<usize>,
        horizon: Range<usize>,
        out: &mut [f64],
    ) -> Result<()>;
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
    ) -> Result<()> {
        (**self).predict(signals, window, horizon, out)
    }
}
