//! The sliding prediction engine, generic over [`Estimator`]s.
//!
//! Windows of `W` samples start at `s = warm_up + estimator.warm_up()` and
//! advance by `hop` samples: window `[s, s+W)`, horizon `[s+W, s+W+H)`
//! (shortened at the end of the recording). For each window the estimator
//! fits, then predicts the horizon. With `hop = H` (the paper's setting) every
//! sample after the first window is predicted exactly once; with `hop < H`
//! horizons overlap and the most recent prediction of a sample is kept.
//!
//! Each window ends with a [`WindowOutcome`] — predicted (with the
//! solver's termination), fallback (the last good model predicted),
//! withheld (an implausible prediction, see [`GuardConfig::plausibility`],
//! after which the estimator restarts), or failed — a value, apart from how
//! a solver stopped. A window whose fit or prediction fails (singular problem,
//! non-finite result) gives no prediction and is recorded as
//! [`WindowOutcome::Failed`]; no NaN ever reaches the prediction series.
//!
//! A recording with gaps of dropped samples ([`Signals::gaps`]) is run one
//! segment at a time: the windows of each segment start at its own first
//! sample (warm-up and window counted from there), no window or horizon
//! reaches across a gap, the estimator sees a view of its segment only and
//! is told of the gap ([`Estimator::gap`]: `arx`, `rls`, `oe` and `auto`
//! keep their models, `paper` starts afresh), and the guard's error history
//! starts again — as the stream does at a gap.
//!
//! ```
//! # use feedid::ident::{engine::{run, EngineConfig}, Estimator, PredictStatus, Signals, WindowFit};
//! # use feedid::solve::Termination;
//! /// Predicts the last measured value (a "hold" estimator).
//! struct Hold;
//! impl Estimator for Hold {
//!     fn name(&self) -> &'static str { "hold" }
//!     fn coefficient_names(&self) -> Vec<String> { vec![] }
//!     fn fit(&mut self, _: &Signals<'_>, _: std::ops::Range<usize>, _: &mut [f64]) -> feedid::Result<WindowFit> {
//!         Ok(WindowFit::identified(0.0, 0, Termination::Exact))
//!     }
//!     fn predict(&mut self, s: &Signals<'_>, w: std::ops::Range<usize>, _: std::ops::Range<usize>, out: &mut [f64]) -> feedid::Result<PredictStatus> {
//!         out.fill(s.window(w.end - 1..w.end, 0, "hold")?.position[0]);
//!         Ok(PredictStatus::Predicted)
//!     }
//! }
//! let t: Vec<f64> = (0..100).map(|k| k as f64 * 1e-3).collect();
//! let y = vec![1.0; 100];
//! let res = run(&mut Hold, &Signals::new(&t, &y, &y, 1e-3, 0.0), &EngineConfig::default()).unwrap();
//! assert_eq!(res.stats.rms, 0.0);
//! assert_eq!(res.stats.samples, 80);
//! ```

use std::ops::Range;
use std::time::{Duration, Instant};

use crate::error::{Error, Result};
use crate::ident::engine::guard::{CommandBasis, Guard, GuardConfig};
use crate::ident::engine::regime::Regime;
use crate::ident::engine::{Estimator, PredictStatus, Signals, WindowOutcome};
use crate::stats::{ErrorAccumulator, ErrorStats};

/// How often [`run_with_progress`] reports over a recording.
const PROGRESS_REPORTS: usize = 500;

/// Sliding-window settings.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EngineConfig {
    /// Window length W \[samples\]; default 20 (4 ms at 5 kHz, the paper's).
    pub window: usize,
    /// Prediction horizon H \[samples\]; default 10 (2 ms at 5 kHz).
    pub horizon: usize,
    /// Shift between windows \[samples\]; `None` = the horizon (default).
    pub hop: Option<usize>,
    /// Samples skipped before the first window (in addition to the estimator's own); default 0.
    pub warm_up: usize,
}

impl Default for EngineConfig {
    fn default() -> Self {
        Self {
            window: 20,
            horizon: 10,
            hop: None,
            warm_up: 0,
        }
    }
}

impl EngineConfig {
    /// The effective hop.
    pub fn hop(&self) -> usize {
        self.hop.unwrap_or(self.horizon)
    }

    /// Check the settings against a recording of `n` samples and an estimator warm-up.
    pub fn validate(&self, n: usize, estimator_warm_up: usize) -> Result<()> {
        for (name, v) in [
            ("window", self.window),
            ("horizon", self.horizon),
            ("hop", self.hop()),
        ] {
            if v == 0 {
                return Err(Error::InvalidParameter {
                    name,
                    value: 0.0,
                    reason: "must be at least 1 sample",
                });
            }
        }
        // saturating: lengths come from the user (`--window 18446744073709551615`)
        let needed = self
            .warm_up
            .saturating_add(estimator_warm_up)
            .saturating_add(self.window)
            .saturating_add(self.horizon);
        if n < needed {
            return Err(Error::TooFewSamples {
                what: "warm-up + window + horizon",
                needed,
                actual: n,
            });
        }
        Ok(())
    }

    /// The window and horizon ranges visited over `n` samples.
    pub fn windows(&self, n: usize, estimator_warm_up: usize) -> WindowIter {
        WindowIter {
            next: self.warm_up.saturating_add(estimator_warm_up),
            window: self.window,
            horizon: self.horizon,
            hop: self.hop().max(1),
            n,
        }
    }
}

/// Iterator over `(window, horizon)` ranges.
#[derive(Debug, Clone)]
pub struct WindowIter {
    next: usize,
    window: usize,
    horizon: usize,
    hop: usize,
    n: usize,
}

impl Iterator for WindowIter {
    type Item = (Range<usize>, Range<usize>);

    fn next(&mut self) -> Option<Self::Item> {
        let s = self.next;
        let we = s.checked_add(self.window)?;
        if we >= self.n {
            return None;
        }
        let he = we.saturating_add(self.horizon).min(self.n);
        self.next = s.saturating_add(self.hop);
        Some((s..we, we..he))
    }
}

/// One visited window.
#[derive(Debug, Clone, PartialEq)]
pub struct WindowRecord {
    /// Samples fitted.
    pub window: Range<usize>,
    /// Samples predicted.
    pub horizon: Range<usize>,
    /// RMS of the fit residual over the window \[m\] (0 if the fit failed).
    pub residual_rms: f64,
    /// Solver iterations (0 if the fit or the prediction failed).
    pub iterations: usize,
    /// What became of the window.
    pub outcome: WindowOutcome,
}

/// Everything a sliding run produces.
#[derive(Debug, Clone)]
pub struct SlidingResult {
    /// Method name.
    pub method: &'static str,
    /// Coefficient names (columns of [`SlidingResult::coefficients`]).
    pub coefficient_names: Vec<String>,
    /// Per-window coefficients, row-major `windows.len() × coefficient_names.len()`.
    pub coefficients: Vec<f64>,
    /// Visited windows.
    pub windows: Vec<WindowRecord>,
    /// Predicted position per sample \[m\]; meaningful only where `has_prediction`.
    pub predicted: Vec<f64>,
    /// Whether sample k was predicted.
    pub has_prediction: Vec<bool>,
    /// Lower bound of the prediction interval per sample \[m\]; meaningful only where `has_prediction`.
    pub lower: Vec<f64>,
    /// Upper bound of the prediction interval per sample \[m\]; meaningful only where `has_prediction`.
    pub upper: Vec<f64>,
    /// Probability of the prediction intervals ([`GuardConfig::interval`]).
    pub interval: f64,
    /// Predicted samples whose measured position lies inside its interval.
    pub inside_interval: usize,
    /// Samples rejected as outliers (absolute indices, ascending): replaced
    /// by their prediction in what the estimator saw; scored as measured.
    pub outliers: Vec<usize>,
    /// The command regime of each sample's prediction ([`Regime`]);
    /// meaningful only where `has_prediction`.
    pub regimes: Vec<Regime>,
    /// Windows whose prediction was cut back as a runaway
    /// ([`GuardConfig::runaway`]).
    pub runaway_windows: usize,
    /// Predicted samples cut back as runaways.
    pub runaway_samples: usize,
    /// Interval coverage and median width per command regime over the
    /// predicted samples ([`Regime::ALL`] order; a regime without samples
    /// has `samples == 0`).
    pub by_regime: [RegimeCoverage; 5],
    /// Error statistics over all predicted samples (against the measured position).
    pub stats: ErrorStats,
    /// Wall time of identification and prediction only (no I/O).
    pub elapsed: Duration,
}

impl SlidingResult {
    /// Prediction at sample `k`, if there is one.
    pub fn prediction(&self, k: usize) -> Option<f64> {
        match self.has_prediction.get(k) {
            Some(true) => self.predicted.get(k).copied(),
            _ => None,
        }
    }

    /// Interval bounds at sample `k`, if it was predicted.
    pub fn interval_at(&self, k: usize) -> Option<(f64, f64)> {
        match self.has_prediction.get(k) {
            Some(true) => Some((self.lower[k], self.upper[k])),
            _ => None,
        }
    }

    /// Share of the predicted samples whose measured position lies inside
    /// its prediction interval \[%\]; `None` if nothing was predicted.
    pub fn interval_coverage_percent(&self) -> Option<f64> {
        (self.stats.samples > 0)
            .then(|| 100.0 * self.inside_interval as f64 / self.stats.samples as f64)
    }

    /// Median width of the prediction intervals over the predicted samples
    /// \[m\]; `None` if nothing was predicted.
    pub fn interval_median_width(&self) -> Option<f64> {
        let mut w: Vec<f64> = (0..self.predicted.len())
            .filter(|&k| self.has_prediction[k])
            .map(|k| self.upper[k] - self.lower[k])
            .collect();
        (!w.is_empty()).then(|| crate::stats::median(&mut w))
    }

    /// Coefficients of window `w`.
    pub fn window_coefficients(&self, w: usize) -> &[f64] {
        let n = self.coefficient_names.len();
        &self.coefficients[w * n..(w + 1) * n]
    }

    /// Number of windows whose fit or prediction failed.
    pub fn failed_windows(&self) -> usize {
        self.windows
            .iter()
            .filter(|w| w.outcome == WindowOutcome::Failed)
            .count()
    }

    /// Number of windows whose prediction was withheld (implausible, see
    /// [`GuardConfig::plausibility`], or declined by the method).
    pub fn withheld_windows(&self) -> usize {
        self.windows
            .iter()
            .filter(|w| w.outcome == WindowOutcome::Withheld)
            .count()
    }

    /// Mean wall time per window \[µs\].
    pub fn per_window_us(&self) -> f64 {
        if self.windows.is_empty() {
            0.0
        } else {
            self.elapsed.as_secs_f64() * 1e6 / self.windows.len() as f64
        }
    }
}

/// The prediction intervals of one command regime over a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RegimeCoverage {
    /// The regime.
    pub regime: Regime,
    /// Predicted samples in it.
    pub samples: usize,
    /// Of which inside their interval.
    pub inside: usize,
    /// Median interval width there \[m\]; `None` without samples.
    pub median_width: Option<f64>,
}

impl RegimeCoverage {
    /// Share of its samples inside their interval \[%\]; `None` without samples.
    pub fn coverage_percent(&self) -> Option<f64> {
        (self.samples > 0).then(|| 100.0 * self.inside as f64 / self.samples as f64)
    }
}

/// Slide `estimator` over `signals` (offset 0) and collect predictions,
/// intervals and statistics (default [`GuardConfig`]).
pub fn run<E: Estimator + ?Sized>(
    estimator: &mut E,
    signals: &Signals<'_>,
    config: &EngineConfig,
) -> Result<SlidingResult> {
    run_with(estimator, signals, config, &GuardConfig::default(), None)
}

/// [`run`] without the runaway cut ([`GuardConfig::runaway`] `None`): the
/// predictions as the estimator made them, for tests of its arithmetic.
#[cfg(test)]
pub(crate) fn run_as_made<E: Estimator + ?Sized>(
    estimator: &mut E,
    signals: &Signals<'_>,
    config: &EngineConfig,
) -> Result<SlidingResult> {
    let guard = GuardConfig {
        runaway: None,
        ..GuardConfig::default()
    };
    run_with(estimator, signals, config, &guard, None)
}

/// A progress hook: `progress(done, total)` in samples (called from the
/// thread that runs the engine).
pub type Progress<'a> = &'a (dyn Fn(u64, u64) + Sync);

/// [`run`], reporting `progress(done, total)` in samples: about 500 times
/// over a recording (never per window on long ones), and `(n, n)` at the end.
pub fn run_with_progress<E: Estimator + ?Sized>(
    estimator: &mut E,
    signals: &Signals<'_>,
    config: &EngineConfig,
    progress: Option<Progress<'_>>,
) -> Result<SlidingResult> {
    run_with(
        estimator,
        signals,
        config,
        &GuardConfig::default(),
        progress,
    )
}

/// [`run_with_progress`] with the interval and outlier settings `guard`.
pub fn run_with<E: Estimator + ?Sized>(
    estimator: &mut E,
    signals: &Signals<'_>,
    config: &EngineConfig,
    guard: &GuardConfig,
    progress: Option<Progress<'_>>,
) -> Result<SlidingResult> {
    signals.check_lengths()?;
    let n = signals.len();
    let est_warm = estimator.warm_up();
    // each segment between dropped samples on its own (one without gaps)
    let segments = signals.segments();
    if segments.len() <= 1 {
        config.validate(n, est_warm)?;
    } else {
        let longest = segments.iter().map(|r| r.len()).max().unwrap_or(0);
        config.validate(longest, est_warm).map_err(|e| match e {
            Error::TooFewSamples { needed, actual, .. } => Error::TooFewSamples {
                what: "warm-up + window + horizon in the longest stretch between dropped samples",
                needed,
                actual,
            },
            other => other,
        })?;
    }
    let names = estimator.coefficient_names();
    let nc = names.len();
    let segment_windows = |r: &Range<usize>| {
        let a = r.start;
        config
            .windows(r.len(), est_warm)
            .map(move |(w, h)| (w.start + a..w.end + a, h.start + a..h.end + a))
    };
    let windows_expected: usize = segments.iter().map(|r| segment_windows(r).count()).sum();

    let mut coefficients = vec![0.0; windows_expected * nc];
    let mut windows = Vec::with_capacity(windows_expected);
    let mut predicted = vec![0.0; n];
    let mut has_prediction = vec![false; n];
    let mut lower = vec![0.0; n];
    let mut upper = vec![0.0; n];
    let mut regimes = vec![Regime::Rest; n];
    let mut buf = vec![0.0; config.horizon];
    let mut lo = vec![0.0; config.horizon];
    let mut hi = vec![0.0; config.horizon];
    let mut reg = vec![Regime::Rest; config.horizon];
    let mut guard = Guard::new(*guard, config.horizon, config.hop())?.with_command_basis(
        if estimator.uses_future_command() {
            CommandBasis::Measured
        } else {
            CommandBasis::Extrapolated
        },
    );
    let raw = signals.all();
    // what the estimator sees: the measured position with outliers replaced
    // (a copy made at the first outlier)
    let mut cleaned: Option<Vec<f64>> = None;
    let mut outliers = Vec::new();

    estimator.reset();
    let total = n as u64;
    let step = (n / PROGRESS_REPORTS).max(1);
    let mut next_report = 0;
    if let Some(p) = progress {
        p(0, total);
    }
    let start = Instant::now();
    let mut w = 0;
    for (s, segment) in segments.iter().enumerate() {
        if s > 0 {
            // a gap: nothing pairs samples across it, as in the stream
            // (module `stream`, *Gaps*)
            estimator.gap();
            guard.reset_segment();
        }
        // after a gap, the segment is a recording of its own (its motion start)
        let motion_start = if segments.len() > 1 {
            signals.segment(segment.clone()).motion_start()
        } else {
            signals.motion_start()
        };
        for (window, horizon) in segment_windows(segment) {
            if let Some(p) = progress {
                if horizon.start >= next_report {
                    p(horizon.start as u64, total);
                    next_report = horizon.start.saturating_add(step);
                }
            }
            guard.observe(
                segment.start,
                window.end,
                |k| raw.position[k],
                |k, v| {
                    cleaned.get_or_insert_with(|| raw.position.to_vec())[k] = v;
                    outliers.push(k);
                },
            );
            let whole = match &cleaned {
                Some(c) => Signals::new(
                    raw.time,
                    raw.command,
                    c,
                    signals.dt(),
                    signals.motion_start(),
                ),
                None => *signals,
            };
            let seen = whole.part(segment.clone()).with_motion_start(motion_start);
            let coef = &mut coefficients[w * nc..(w + 1) * nc];
            w += 1;
            let h = horizon.len();
            let out = &mut buf[..h];
            let mut record = fit_and_predict(estimator, &seen, window.clone(), horizon, coef, out);
            let all = whole.all();
            let spread = range(&all.position[window.clone()]);
            let last = all.position[window.end - 1];
            if record.outcome.predicted()
                && estimator.checks_plausibility()
                && !guard.plausible(
                    out,
                    last,
                    spread,
                    range(&all.command[window.start..record.horizon.end]),
                )
            {
                record.outcome = WindowOutcome::Withheld;
                estimator.restart();
            }
            if record.outcome.predicted() {
                let (lo, hi, reg) = (&mut lo[..h], &mut hi[..h], &mut reg[..h]);
                let command = &all.command[window.start..record.horizon.end];
                guard.predicted(
                    record.horizon.start,
                    out,
                    last,
                    spread,
                    command,
                    estimator.uses_future_command(),
                    lo,
                    hi,
                    reg,
                );
                predicted[record.horizon.clone()].copy_from_slice(out);
                has_prediction[record.horizon.clone()].fill(true);
                lower[record.horizon.clone()].copy_from_slice(lo);
                upper[record.horizon.clone()].copy_from_slice(hi);
                regimes[record.horizon.clone()].copy_from_slice(reg);
            }
            windows.push(record);
        }
    }
    let elapsed = start.elapsed();
    if let Some(p) = progress {
        p(total, total);
    }

    let mut acc = ErrorAccumulator::default();
    let mut inside_interval = 0;
    let y = raw.position;
    let mut by_regime = Regime::ALL.map(|regime| RegimeCoverage {
        regime,
        samples: 0,
        inside: 0,
        median_width: None,
    });
    let mut widths: [Vec<f64>; 5] = Default::default();
    for k in 0..n {
        if has_prediction[k] {
            acc.push(y[k], predicted[k]);
            let inside = usize::from(lower[k] <= y[k] && y[k] <= upper[k]);
            inside_interval += inside;
            let r = &mut by_regime[regimes[k].index()];
            r.samples += 1;
            r.inside += inside;
            widths[regimes[k].index()].push(upper[k] - lower[k]);
        }
    }
    for (r, w) in by_regime.iter_mut().zip(widths.iter_mut()) {
        r.median_width = (!w.is_empty()).then(|| crate::stats::median(w));
    }
    Ok(SlidingResult {
        method: estimator.name(),
        coefficient_names: names,
        coefficients,
        windows,
        predicted,
        has_prediction,
        lower,
        upper,
        interval: guard.config().interval,
        inside_interval,
        outliers,
        regimes,
        runaway_windows: guard.runaway_windows(),
        runaway_samples: guard.runaway_samples(),
        by_regime,
        stats: acc.finish(),
        elapsed,
    })
}

/// Fit one window and predict its horizon into `out`, the one place where
/// the outcome is decided for the batch engine and the streaming path: a
/// prediction counts only if it is finite; a withheld prediction is
/// [`WindowOutcome::Withheld`], an error or a non-finite prediction
/// [`WindowOutcome::Failed`]; non-finite coefficients are zeroed.
pub(crate) fn fit_and_predict<E: Estimator + ?Sized>(
    estimator: &mut E,
    signals: &Signals<'_>,
    window: Range<usize>,
    horizon: Range<usize>,
    coef: &mut [f64],
    out: &mut [f64],
) -> WindowRecord {
    let (residual_rms, iterations, outcome) = match estimator.fit(signals, window.clone(), coef) {
        Ok(fit) => match estimator.predict(signals, window.clone(), horizon.clone(), out) {
            Ok(p @ PredictStatus::Withheld { .. }) => (
                fit.residual_rms,
                fit.iterations,
                WindowOutcome::of(fit.status, p),
            ),
            Ok(p) if out.iter().all(|v| v.is_finite()) => (
                fit.residual_rms,
                fit.iterations,
                WindowOutcome::of(fit.status, p),
            ),
            _ => (finite_or_zero(fit.residual_rms), 0, WindowOutcome::Failed),
        },
        Err(_) => (0.0, 0, WindowOutcome::Failed),
    };
    if !coef.iter().all(|c| c.is_finite()) {
        coef.fill(0.0);
    }
    WindowRecord {
        window,
        horizon,
        residual_rms,
        iterations,
        outcome,
    }
}

/// `max − min` of `v` (NaN entries ignored; −∞ if all are NaN or `v` is empty).
pub(crate) fn range(v: &[f64]) -> f64 {
    let (mn, mx) = v
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    mx - mn
}

fn finite_or_zero(v: f64) -> f64 {
    if v.is_finite() {
        v
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ident::engine::test_estimators::Wild;
    use crate::ident::engine::WindowFit;
    use crate::solve::Termination;

    /// Predicts a straight line through the last two samples of the window;
    /// writes [last value, slope] as coefficients.
    struct Linear {
        calls: usize,
    }

    impl Estimator for Linear {
        fn name(&self) -> &'static str {
            "linear"
        }
        fn coefficient_names(&self) -> Vec<String> {
            vec!["last".into(), "slope".into()]
        }
        fn fit(&mut self, s: &Signals<'_>, w: Range<usize>, coef: &mut [f64]) -> Result<WindowFit> {
            self.calls += 1;
            let y = s.window(w.end - 2..w.end, 0, "test").unwrap().position;
            coef[0] = y[1];
            coef[1] = y[1] - y[0];
            Ok(WindowFit::identified(0.0, 0, Termination::Exact))
        }
        fn predict(
            &mut self,
            s: &Signals<'_>,
            w: Range<usize>,
            h: Range<usize>,
            out: &mut [f64],
        ) -> Result<PredictStatus> {
            let y = s.window(w.end - 2..w.end, 0, "test").unwrap().position;
            assert_eq!(h.start, w.end);
            for (j, o) in out.iter_mut().enumerate() {
                *o = y[1] + (j as f64 + 1.0) * (y[1] - y[0]);
            }
            Ok(PredictStatus::Predicted)
        }
    }

    /// Fails on every other window and returns NaN predictions on the rest.
    struct Broken {
        k: usize,
    }

    impl Estimator for Broken {
        fn name(&self) -> &'static str {
            "broken"
        }
        fn coefficient_names(&self) -> Vec<String> {
            vec!["c".into()]
        }
        fn fit(&mut self, _: &Signals<'_>, _: Range<usize>, coef: &mut [f64]) -> Result<WindowFit> {
            self.k += 1;
            coef[0] = f64::NAN;
            if self.k.is_multiple_of(2) {
                Err(Error::Singular { context: "test" })
            } else {
                Ok(WindowFit::identified(0.0, 0, Termination::Exact))
            }
        }
        fn predict(
            &mut self,
            _: &Signals<'_>,
            _: Range<usize>,
            _: Range<usize>,
            out: &mut [f64],
        ) -> Result<PredictStatus> {
            out.fill(f64::NAN);
            Ok(PredictStatus::Predicted)
        }
    }

    #[test]
    fn a_prediction_far_beyond_the_recordings_motion_is_withheld_and_the_method_restarts() {
        // a ramp of 10 µm per sample: a window of 20 spans 190 µm, the
        // command (the same ramp) over window and horizon 290 µm
        let (t, _) = ramp(300);
        let y: Vec<f64> = (0..300).map(|k| 1e-5 * k as f64).collect();
        let s = Signals::new(&t, &y, &y, 2e-4, 0.0);
        let cfg = EngineConfig {
            window: 20,
            horizon: 10,
            hop: None,
            warm_up: 0,
        };
        for (jump, withheld) in [(4.0 * 290e-6 * 1.01, true), (4.0 * 290e-6 * 0.99, false)] {
            for sign in [1.0, -1.0] {
                let mut est = Wild::new(5, sign * jump);
                let r = run(&mut est, &s, &cfg).unwrap();
                assert_eq!(r.withheld_windows(), usize::from(withheld), "{jump}");
                assert_eq!(est.restarts, usize::from(withheld));
                let w = &r.windows[4];
                assert_eq!(w.outcome == WindowOutcome::Withheld, withheld);
                // nothing of the withheld window is scored; every other is
                assert_eq!(r.prediction(w.horizon.start).is_none(), withheld);
                assert_eq!(r.stats.samples, 280 - 10 * usize::from(withheld));
            }
        }
        // the bound disabled: every prediction is kept
        let mut est = Wild::new(5, 1.0);
        let guard = GuardConfig {
            plausibility: None,
            ..GuardConfig::default()
        };
        let r = run_with(&mut est, &s, &cfg, &guard, None).unwrap();
        assert_eq!((r.withheld_windows(), est.restarts), (0, 0));
    }

    #[test]
    fn a_prediction_beyond_the_motion_shown_is_cut_back_counted_and_its_interval_spans_the_hold() {
        // a sine of amplitude 1 (0.05 rad per sample): a hold that jumps by
        // 2 on its 30th window is plausible (below 4× the motion) but far
        // beyond what the axis has travelled in as many samples (the plain
        // holds are cut too, towards going on: the axis cannot stop within
        // a horizon as fast as a hold says)
        let n = 800;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let y: Vec<f64> = (0..n).map(|k| (0.05 * k as f64).sin()).collect();
        let s = Signals::new(&t, &y, &y, 1e-3, 0.0);
        let cfg = EngineConfig {
            window: 20,
            horizon: 10,
            hop: None,
            warm_up: 0,
        };
        let mut est = Wild::new(30, 2.0);
        let r = run(&mut est, &s, &cfg).unwrap();
        let w = &r.windows[29];
        let we = w.horizon.start;
        assert_eq!(r.withheld_windows(), 0);
        assert!(r.runaway_windows >= 1 && r.runaway_samples >= 10);
        // the independent reference: the largest distance travelled in j
        // samples before the window end, brute force
        let last = y[we - 1];
        for (j, k) in w.horizon.clone().enumerate() {
            let j = j + 1;
            let reach = (j..we).map(|i| (y[i] - y[i - j]).abs()).fold(0.0, f64::max);
            let p = r.prediction(k).unwrap();
            assert!(
                p - last <= 1.5 * reach + 1e-12,
                "{j}: {p} vs {last} + 1.5·{reach}"
            );
            let (lo, hi) = r.interval_at(k).unwrap();
            assert!(lo <= last && hi >= p, "{j}: [{lo}, {hi}]");
        }
        // turned off: the prediction as made
        let guard = GuardConfig {
            runaway: None,
            ..GuardConfig::default()
        };
        let r = run_with(&mut Wild::new(30, 2.0), &s, &cfg, &guard, None).unwrap();
        assert_eq!(r.runaway_windows, 0);
        assert_eq!(r.prediction(we), Some(last + 2.0));
        // the stream cuts the same window back, by the same amount
        // (each window waiting for its command, as the batch engine has it)
        let options = crate::ident::engine::StreamOptions {
            extrapolation: crate::ident::engine::stream::CommandExtrapolation::Wait,
            ..crate::ident::engine::StreamOptions::default()
        };
        let mut st =
            crate::ident::engine::Streamer::with_options(Wild::new(30, 2.0), cfg, options).unwrap();
        let mut cut = Vec::new();
        for k in 0..n {
            st.push(t[k], y[k], y[k]).unwrap();
            while let Some(p) = st.poll().unwrap() {
                if p.horizon.start == we {
                    cut = p.position.to_vec();
                }
            }
        }
        st.finish();
        while st.poll().unwrap().is_some() {}
        let b = run(&mut Wild::new(30, 2.0), &s, &cfg).unwrap();
        assert_eq!(cut, b.predicted[we..we + 10].to_vec());
        assert_eq!(
            (st.stats().runaway_windows, st.stats().runaway_samples),
            (b.runaway_windows, b.runaway_samples)
        );
    }

    #[test]
    fn intervals_are_counted_per_regime_and_sum_to_the_whole() {
        // moves and rests of a first-order follower: every regime but the
        // reversal occurs; the counts add up to the predicted samples
        let n = 3000;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let u: Vec<f64> = (0..n)
            .map(|k| {
                let phase = (k / 250) % 4;
                let x = (k % 250) as f64 / 250.0;
                match phase {
                    0 => 0.0,
                    1 => x,
                    2 => 1.0,
                    _ => 1.0 - x,
                }
            })
            .collect();
        let mut y = vec![0.0; n];
        for k in 1..n {
            y[k] = y[k - 1] + 0.2 * (u[k - 1] - y[k - 1]);
        }
        let s = Signals::new(&t, &u, &y, 1e-3, 0.0);
        let r = run(&mut Linear { calls: 0 }, &s, &EngineConfig::default()).unwrap();
        let total: usize = r.by_regime.iter().map(|c| c.samples).sum();
        let inside: usize = r.by_regime.iter().map(|c| c.inside).sum();
        assert_eq!((total, inside), (r.stats.samples, r.inside_interval));
        for regime in [
            Regime::Rest,
            Regime::Start,
            Regime::ConstantVelocity,
            Regime::Accelerating,
        ] {
            let c = &r.by_regime[regime.index()];
            assert!(c.samples > 0, "{regime:?}");
            assert!(c.median_width.is_some_and(|w| w > 0.0), "{regime:?}");
        }
        // a linear extrapolation misses most at a start and least at rest:
        // its intervals are wider at starts than at rest
        let w = |g: Regime| r.by_regime[g.index()].median_width.unwrap();
        assert!(
            w(Regime::Start) > w(Regime::Rest),
            "{} vs {}",
            w(Regime::Start),
            w(Regime::Rest)
        );
    }

    #[test]
    fn nothing_is_withheld_before_anything_has_moved() {
        // at rest with a still command, there is no scale: a prediction
        // 1 mm off stands (nothing says it is implausible)
        let (t, _) = ramp(100);
        let y = vec![0.5; 100];
        let s = Signals::new(&t, &y, &y, 2e-4, 0.0);
        let mut est = Wild::new(3, 1e-3);
        let r = run(&mut est, &s, &EngineConfig::default()).unwrap();
        assert_eq!((r.withheld_windows(), est.restarts), (0, 0));
    }

    fn ramp(n: usize) -> (Vec<f64>, Vec<f64>) {
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 2e-4).collect();
        let y: Vec<f64> = t.iter().map(|&t| 0.05 * t).collect();
        (t, y)
    }

    #[test]
    fn linear_estimator_predicts_a_ramp_exactly() {
        let (t, y) = ramp(105);
        let s = Signals::new(&t, &y, &y, 2e-4, 0.0);
        let mut est = Linear { calls: 0 };
        let r = run(&mut est, &s, &EngineConfig::default()).unwrap();
        // windows at 0,10,...,80 (window end 20..100 < 105) → 9 windows
        assert_eq!(r.windows.len(), 9);
        assert_eq!(est.calls, 9);
        assert_eq!(r.stats.samples, 85);
        assert!(r.stats.rms < 1e-15);
        assert!(r.prediction(19).is_none());
        assert!(r.prediction(20).is_some());
        assert!(r.prediction(104).is_some());
        // last window's horizon is shortened
        assert_eq!(r.windows[8].horizon, 100..105);
        assert!((r.window_coefficients(0)[1] - 0.05 * 2e-4).abs() < 1e-18);
    }

    #[test]
    fn every_sample_after_first_window_is_predicted_once_with_hop_equal_horizon() {
        let cfg = EngineConfig {
            window: 7,
            horizon: 3,
            hop: None,
            warm_up: 2,
        };
        let mut count = [0; 50];
        for (_, h) in cfg.windows(50, 1) {
            for k in h {
                count[k] += 1;
            }
        }
        assert!(count[..10].iter().all(|&c| c == 0));
        assert!(count[10..].iter().all(|&c| c == 1));
    }

    #[test]
    fn overlapping_horizons_keep_the_latest_prediction() {
        let (t, y) = ramp(60);
        // position quadratic so predictions from different windows differ
        let yq: Vec<f64> = t.iter().map(|&t| t * t).collect();
        let s = Signals::new(&t, &y, &yq, 2e-4, 0.0);
        let cfg = EngineConfig {
            window: 10,
            horizon: 5,
            hop: Some(1),
            warm_up: 0,
        };
        let r = run(&mut Linear { calls: 0 }, &s, &cfg).unwrap();
        // sample 30 was last predicted by the window ending at 30 (one step ahead)
        let y1 = yq[29];
        let y0 = yq[28];
        assert!((r.prediction(30).unwrap() - (2.0 * y1 - y0)).abs() < 1e-18);
    }

    #[test]
    fn failed_windows_give_no_prediction_and_no_nan() {
        let (t, y) = ramp(100);
        let s = Signals::new(&t, &y, &y, 2e-4, 0.0);
        let r = run(&mut Broken { k: 0 }, &s, &EngineConfig::default()).unwrap();
        assert_eq!(r.failed_windows(), r.windows.len());
        assert_eq!(r.stats.samples, 0);
        assert!(r.coefficients.iter().all(|c| c.is_finite()));
        assert!((0..100).all(|k| r.prediction(k).is_none()));
    }

    #[test]
    fn too_short_recording_is_an_error() {
        let (t, y) = ramp(29);
        let s = Signals::new(&t, &y, &y, 2e-4, 0.0);
        let e = run(&mut Linear { calls: 0 }, &s, &EngineConfig::default()).unwrap_err();
        assert!(matches!(
            e,
            Error::TooFewSamples {
                needed: 30,
                actual: 29,
                ..
            }
        ));
    }

    #[test]
    fn zero_window_is_rejected() {
        let cfg = EngineConfig {
            window: 0,
            ..EngineConfig::default()
        };
        assert!(cfg.validate(100, 0).is_err());
    }

    #[test]
    fn huge_window_horizon_or_hop_is_too_few_samples_not_an_overflow() {
        let (t, y) = ramp(100);
        let s = Signals::new(&t, &y, &y, 2e-4, 0.0);
        for (window, horizon) in [(usize::MAX, 10), (20, usize::MAX), (usize::MAX, usize::MAX)] {
            let cfg = EngineConfig {
                window,
                horizon,
                warm_up: 3,
                ..EngineConfig::default()
            };
            let e = run(&mut Linear { calls: 0 }, &s, &cfg).unwrap_err();
            assert!(
                matches!(
                    e,
                    Error::TooFewSamples {
                        needed: usize::MAX,
                        actual: 100,
                        ..
                    }
                ),
                "{e}"
            );
        }
        // a hop beyond the data visits one window
        let cfg = EngineConfig {
            hop: Some(usize::MAX),
            warm_up: 3,
            ..EngineConfig::default()
        };
        assert_eq!(cfg.windows(100, 2).count(), 1);
        let r = run(&mut Linear { calls: 0 }, &s, &cfg).unwrap();
        assert_eq!(r.windows.len(), 1);
    }

    #[test]
    fn progress_is_reported_from_zero_to_the_total_and_does_not_change_the_result() {
        let (t, y) = ramp(5000);
        let s = Signals::new(&t, &y, &y, 2e-4, 0.0);
        let calls = std::sync::Mutex::new(Vec::new());
        let hook = |d: u64, n: u64| calls.lock().unwrap().push((d, n));
        let with = run_with_progress(
            &mut Linear { calls: 0 },
            &s,
            &EngineConfig::default(),
            Some(&hook),
        )
        .unwrap();
        let without = run(&mut Linear { calls: 0 }, &s, &EngineConfig::default()).unwrap();
        assert_eq!(with.predicted, without.predicted);
        let calls = calls.into_inner().unwrap();
        assert_eq!(calls.first(), Some(&(0, 5000)));
        assert_eq!(calls.last(), Some(&(5000, 5000)));
        assert!(calls.windows(2).all(|w| w[0].0 <= w[1].0), "monotone");
        // throttled to about 500 reports (here about one per window)
        assert!(calls.len() > 100 && calls.len() <= 502, "{}", calls.len());
    }
}
