//! The result of one identification run.

use crate::error::Syntax;
use crate::ident::{
    ArxOrders, Criterion, EngineConfig, Method, ModelFile, ResidualAnalysis, SlidingResult,
    WindowOutcome,
};
use crate::pipeline::{IdentifySummary, RegimeInterval, Warning};
use crate::stats::ErrorStats;

/// Orders chosen from the recording ([`crate::pipeline::Pipeline::select_orders`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrderChoice {
    /// The orders the method ran with.
    pub orders: ArxOrders,
    /// The criterion that chose them.
    pub criterion: Criterion,
}

/// Everything one identification of a recording produced.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct Identification {
    /// The method as it ran (with chosen orders, if any).
    pub method: Method,
    /// The engine settings used (window resolved).
    pub config: EngineConfig,
    /// Samples in the recording.
    pub samples: usize,
    /// Sampling rate \[Hz\].
    pub rate_hz: f64,
    /// Gaps of dropped samples in the recording (the windows restarted after each).
    pub gaps: usize,
    /// Samples that look missing in those gaps.
    pub missing_samples: usize,
    /// Orders chosen from the recording, if asked.
    pub order_choice: Option<OrderChoice>,
    /// The sliding-window predictions (per sample) and the per-window
    /// coefficients and outcomes.
    pub sliding: SlidingResult,
    /// Nominal linear model driven by the measured command \[m\] (if asked).
    pub simulated: Option<Vec<f64>>,
    /// Error of the nominal model against the measurement over the same
    /// samples as the predictions (all samples if nothing was predicted).
    pub simulation_stats: Option<ErrorStats>,
    /// Residual analysis of the prediction errors (`None` if not asked or
    /// too few predictions).
    pub residuals: Option<ResidualAnalysis>,
    /// The method's global model, if fitted.
    pub global: Option<ModelFile>,
    /// Why the method's global model is missing (`"not fitted (…)"`), if it is.
    pub global_note: Option<String>,
    /// The extra global model asked for ([`crate::pipeline::Pipeline::extra_model`]).
    pub model: Option<ModelFile>,
    /// What the user should know about this run (also in the summary).
    pub warnings: Vec<Warning>,
}

impl Identification {
    /// The summary of this run (`summary.json`, and the text `feedid identify` prints),
    /// its warnings in [`Syntax::Library`].
    pub fn summary(&self) -> IdentifySummary {
        self.summary_in(Syntax::Library)
    }

    /// [`Identification::summary`] with the warnings' hints in a front end's
    /// syntax ([`Warning::phrased`]).
    pub fn summary_in(&self, syntax: Syntax) -> IdentifySummary {
        let s = &self.sliding;
        let fallback = s
            .windows
            .iter()
            .filter(|w| w.outcome == WindowOutcome::Fallback)
            .count();
        IdentifySummary {
            method: s.method.to_string(),
            samples: self.samples,
            rate_hz: self.rate_hz,
            window: self.config.window,
            horizon: self.config.horizon,
            hop: self.config.hop(),
            windows: s.windows.len(),
            failed_windows: s.failed_windows(),
            fallback_windows: fallback,
            withheld_windows: s.withheld_windows(),
            gaps: self.gaps,
            missing_samples: self.missing_samples,
            samples_predicted: s.stats.samples,
            coverage_percent: if self.samples > 0 {
                100.0 * s.stats.samples as f64 / self.samples as f64
            } else {
                0.0
            },
            rms_error_m: (s.stats.samples > 0).then_some(s.stats.rms),
            max_abs_error_m: (s.stats.samples > 0).then_some(s.stats.max_abs),
            fit_percent: (s.stats.samples > 0)
                .then_some(s.stats.fit_percent)
                .filter(|v| v.is_finite()),
            interval_percent: 100.0 * s.interval,
            interval_coverage_percent: s.interval_coverage_percent(),
            interval_median_width_m: s.interval_median_width(),
            interval_by_regime: s
                .by_regime
                .iter()
                .filter_map(|r| {
                    Some(RegimeInterval {
                        regime: r.regime.name(),
                        samples: r.samples,
                        coverage_percent: r.coverage_percent()?,
                        median_width_m: r.median_width?,
                    })
                })
                .collect(),
            runaway_windows: s.runaway_windows,
            runaway_samples: s.runaway_samples,
            outliers: s.outliers.len(),
            sim_fit_percent: self
                .global
                .as_ref()
                .and_then(|g| g.identified_by.as_ref())
                .map(|p| p.fit_percent)
                .filter(|f| f.is_finite()),
            global_model: self
                .global
                .as_ref()
                .and_then(|g| g.identified_by.as_ref())
                .map(|p| format!("{} {}", p.method, p.orders)),
            global_model_samples: self
                .global
                .as_ref()
                .and_then(|g| g.identified_by.as_ref())
                .map(|p| p.samples),
            sim_rms_error_m: self
                .simulation_stats
                .map(|x| x.rms)
                .filter(|v| v.is_finite()),
            sim_max_abs_error_m: self
                .simulation_stats
                .map(|x| x.max_abs)
                .filter(|v| v.is_finite()),
            nominal_fit_percent: self
                .simulation_stats
                .map(|x| x.fit_percent)
                .filter(|v| v.is_finite()),
            nominal_rig: None,
            simulation_diverged: self
                .simulation_stats
                .is_some_and(|x| !(x.rms.is_finite() && x.max_abs.is_finite())),
            warnings: self.warnings.iter().map(|w| w.phrased(syntax)).collect(),
            identification_seconds: s.elapsed.as_secs_f64(),
            per_window_us: s.per_window_us(),
            residuals: self.residuals.clone(),
            order_choice: self.order_choice,
            global_fit_percent: self
                .global
                .as_ref()
                .and_then(|g| g.identified_by.as_ref())
                .map(|p| p.fit_percent),
            global_note: self.global_note.clone(),
        }
    }
}
