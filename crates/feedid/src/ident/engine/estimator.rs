//! The one estimator trait that the sliding engine, the streaming path, the CLI
//! and the benchmarks use for every method.

use std::ops::Range;

use crate::error::Result;
use crate::solve::Termination;

/// Read-only view of the signals an estimator may use.
///
/// Indices passed to estimators are *absolute* sample indices of the whole
/// recording; element 0 of the slices here is sample `offset`. Batch
/// processing uses `offset = 0`; the streaming path passes a moving buffer with
/// a growing offset. Always go through [`Signals::time`],
/// [`Signals::command`] and [`Signals::position`].
#[derive(Debug, Clone, Copy)]
pub struct Signals<'a> {
    /// Absolute index of element 0 of the slices.
    pub offset: usize,
    /// Time stamps \[s\].
    pub time: &'a [f64],
    /// Command (set-point) position \[m\].
    pub command: &'a [f64],
    /// Measured position \[m\].
    pub position: &'a [f64],
    /// Nominal sample interval \[s\].
    pub dt: f64,
    /// Time at which motion starts \[s\] (the paper's time origin).
    pub motion_start: f64,
}

impl<'a> Signals<'a> {
    /// A view of whole arrays (offset 0).
    pub fn new(
        time: &'a [f64],
        command: &'a [f64],
        position: &'a [f64],
        dt: f64,
        motion_start: f64,
    ) -> Self {
        Self {
            offset: 0,
            time,
            command,
            position,
            dt,
            motion_start,
        }
    }

    /// First absolute index past the available data.
    pub fn end(&self) -> usize {
        self.offset + self.time.len()
    }

    /// Time stamps for absolute indices `r`.
    pub fn time(&self, r: Range<usize>) -> &'a [f64] {
        &self.time[r.start - self.offset..r.end - self.offset]
    }

    /// Command for absolute indices `r`.
    pub fn command(&self, r: Range<usize>) -> &'a [f64] {
        &self.command[r.start - self.offset..r.end - self.offset]
    }

    /// Measured position for absolute indices `r`.
    pub fn position(&self, r: Range<usize>) -> &'a [f64] {
        &self.position[r.start - self.offset..r.end - self.offset]
    }
}

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
