//! The summary of a run: `summary.json` (serde) and the text
//! `feedid identify` prints (`Display`).

use std::fmt;

use serde::Serialize;

use crate::ident::ResidualAnalysis;
use crate::pipeline::OrderChoice;

/// The machine-readable summary of a run (`summary.json`) and, as
/// `Display`, the text `feedid identify` prints after the file name
/// (`"{file}: {summary}"`). Optional values that do not apply (no nominal
/// model, no global model, too few predictions for the residual analysis)
/// are left out of the JSON, so a `null` never stands for a number.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[non_exhaustive]
pub struct IdentifySummary {
    /// Method name.
    pub method: String,
    /// Samples in the recording.
    pub samples: usize,
    /// Sampling rate \[Hz\].
    pub rate_hz: f64,
    /// Window W \[samples\].
    pub window: usize,
    /// Horizon H \[samples\].
    pub horizon: usize,
    /// Hop \[samples\].
    pub hop: usize,
    /// Windows visited.
    pub windows: usize,
    /// Windows whose fit or prediction failed (no prediction).
    pub failed_windows: usize,
    /// Windows that kept the previous model (not informative).
    pub fallback_windows: usize,
    /// Windows whose prediction was withheld: implausible, beyond 4× the
    /// motion the recording has shown (the estimator then restarts; see
    /// [`GuardConfig::plausibility`](crate::ident::GuardConfig::plausibility)).
    pub withheld_windows: usize,
    /// Gaps in the recording: dropped samples, after each of which the
    /// windows restarted ([`crate::Recording::gaps`]; 0 for a regular recording).
    pub gaps: usize,
    /// Samples that look missing in those gaps (not in `samples`).
    pub missing_samples: usize,
    /// Samples with a prediction.
    pub samples_predicted: usize,
    /// Share of the recording's samples with a prediction \[%\].
    pub coverage_percent: f64,
    /// RMS prediction error over the predicted samples \[m\] (`None`, left
    /// out of the JSON, when nothing was predicted: no figure over nothing).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rms_error_m: Option<f64>,
    /// Largest absolute prediction error \[m\] (`None` when nothing was predicted).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_abs_error_m: Option<f64>,
    /// NRMSE fit of the k-step (k = horizon) predictions \[%\] (`None`
    /// when nothing was predicted).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fit_percent: Option<f64>,
    /// Probability of the prediction intervals \[%\] (`--interval`; default 95).
    pub interval_percent: f64,
    /// Share of the predicted samples whose measured position lies inside
    /// its prediction interval \[%\] (`None` when nothing was predicted).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub interval_coverage_percent: Option<f64>,
    /// Median width of the prediction intervals over the predicted samples
    /// \[m\] (`None` when nothing was predicted).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub interval_median_width_m: Option<f64>,
    /// Coverage and median width of the intervals per command regime
    /// ([`crate::ident::Regime`]), for the regimes with predicted samples.
    pub interval_by_regime: Vec<RegimeInterval>,
    /// Windows whose prediction was cut back as a runaway: it left the
    /// envelope of the motion the axis has shown or the hull of where its
    /// command goes (see
    /// [`GuardConfig::runaway`](crate::ident::GuardConfig::runaway)).
    pub runaway_windows: usize,
    /// Predicted samples cut back as runaways.
    pub runaway_samples: usize,
    /// Measured samples rejected as isolated outliers (not fitted; still scored).
    pub outliers: usize,
    /// NRMSE fit of the free-run simulation of the method's global model
    /// over the samples it was fitted on \[%\] (`None` without one, e.g.
    /// `paper`, or when it is not finite).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sim_fit_percent: Option<f64>,
    /// Structure of the global model (e.g. `"arx 8,8,1"`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub global_model: Option<String>,
    /// Samples the global model was fitted and simulated on: the first
    /// ones of the recording, at most [`crate::ident::GLOBAL_FIT_SAMPLES`]
    /// (`sim_fit_percent` covers these only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub global_model_samples: Option<usize>,
    /// RMS error of the nominal simulation model over the predicted samples \[m\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sim_rms_error_m: Option<f64>,
    /// Largest absolute error of the nominal simulation model \[m\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sim_max_abs_error_m: Option<f64>,
    /// NRMSE fit of the nominal simulation model \[%\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nominal_fit_percent: Option<f64>,
    /// Whose parameters the nominal simulation model has: `"built-in"`
    /// (the paper's rig, not the recorded drive unless it is that rig) or
    /// the rig file given (`--params`); set by the caller, `None` = not said.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nominal_rig: Option<String>,
    /// Wall time of identification and prediction only (no I/O) \[s\].
    pub identification_seconds: f64,
    /// Mean wall time per window \[µs\].
    pub per_window_us: f64,
    /// What the run found that the user should know: the recording's
    /// plausibility warnings ([`crate::plausibility`]) and the method's.
    pub warnings: Vec<String>,
    /// The nominal simulation ran away (an unstable model allowed by the
    /// caller); its error figures are left out (text only).
    #[serde(skip)]
    pub simulation_diverged: bool,
    /// Residual analysis of the prediction errors `y − ŷ` over the predicted
    /// samples (at most the last 200 000) against the command, lags
    /// 0 … max(25, 2H) (`None` when fewer than 52 samples were predicted).
    /// The k-step errors of one horizon share the state they were predicted
    /// from, so `r_ee` is positive for lags below the horizon H whatever the
    /// model: its verdict `ee_inside` tests the lags H … max(25, 2H) only
    /// (`ee_first_lag`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub residuals: Option<ResidualAnalysis>,
    /// Orders chosen from the recording, if asked (text only).
    #[serde(skip)]
    pub order_choice: Option<OrderChoice>,
    /// The global model's free-run fit as computed, finite or not (text only).
    #[serde(skip)]
    pub global_fit_percent: Option<f64>,
    /// Why the method's global model is missing (text only).
    #[serde(skip)]
    pub global_note: Option<String>,
}

/// The prediction intervals of one command regime in a summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RegimeInterval {
    /// The regime's name ([`crate::ident::Regime::name`]).
    pub regime: &'static str,
    /// Predicted samples in it.
    pub samples: usize,
    /// Share of them inside their interval \[%\].
    pub coverage_percent: f64,
    /// Median interval width there \[m\].
    pub median_width_m: f64,
}

impl fmt::Display for IdentifySummary {
    /// The lines `feedid identify` prints after `"{file}: "`, each ending
    /// with a newline.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{} samples at {:.2} Hz, method {}, window {}, horizon {}, hop {}",
            self.samples, self.rate_hz, self.method, self.window, self.horizon, self.hop
        )?;
        if let Some(c) = &self.order_choice {
            let o = c.orders;
            writeln!(
                f,
                "  order auto ({}): na {}, nb {}, nk {}",
                c.criterion.label(),
                o.na,
                o.nb,
                o.nk
            )?;
        }
        writeln!(
            f,
            "  {} windows ({} failed, {} fallback, {} withheld), {} samples predicted ({:.1} %)",
            self.windows,
            self.failed_windows,
            self.fallback_windows,
            self.withheld_windows,
            self.samples_predicted,
            self.coverage_percent
        )?;
        match (self.rms_error_m, self.max_abs_error_m, self.fit_percent) {
            (Some(rms), Some(max), Some(fit)) => writeln!(
                f,
                "  prediction error: rms {:.3} µm, max {:.3} µm, fit {:.3} % over {:.1} % of the samples{}{}",
                1e6 * rms,
                1e6 * max,
                fit,
                self.coverage_percent,
                match self.interval_coverage_percent {
                    Some(c) => format!(
                        ", {c:.1} % inside the {} % interval",
                        crate::error::short_number(self.interval_percent)
                    ),
                    None => String::new(),
                },
                if self.warnings.is_empty() {
                    ""
                } else {
                    " (see the warnings)"
                }
            )?,
            // no figure over nothing
            _ => writeln!(
                f,
                "  prediction error: none (no sample was predicted, coverage 0 %; see the warnings)"
            )?,
        }
        if let Some(w) = self.interval_median_width_m {
            let parts: Vec<String> = self
                .interval_by_regime
                .iter()
                .map(|r| {
                    format!(
                        "{} {:.1} % ({} samples, width {:.3} µm)",
                        r.regime.replace('_', " "),
                        r.coverage_percent,
                        r.samples,
                        1e6 * r.median_width_m
                    )
                })
                .collect();
            writeln!(
                f,
                "  {} % intervals: median width {:.3} µm; inside by command regime: {}",
                crate::error::short_number(self.interval_percent),
                1e6 * w,
                parts.join(", ")
            )?;
        }
        if self.runaway_windows > 0 {
            writeln!(
                f,
                "  {} window(s) cut back as runaways ({} samples, {:.2} % of the predicted): \
                 they left the motion the axis has shown or where its command goes",
                self.runaway_windows,
                self.runaway_samples,
                100.0 * self.runaway_samples as f64 / self.samples_predicted.max(1) as f64
            )?;
        }
        if self.gaps > 0 {
            writeln!(
                f,
                "  {} gap(s) of dropped samples ({} missing): the windows restarted after each gap",
                self.gaps, self.missing_samples
            )?;
        }
        if self.outliers > 0 {
            writeln!(
                f,
                "  {} isolated outlier sample(s) not fitted (scored as measured)",
                self.outliers
            )?;
        }
        if let (Some(m), Some(fit)) = (&self.global_model, self.global_fit_percent) {
            let share = match self.global_model_samples {
                Some(n) if self.gaps > 0 => format!(
                    " on {n} measured samples (simulated through the {} gap(s), compared where \
                     measured)",
                    self.gaps
                ),
                Some(n) if n < self.samples => format!(
                    " on the first {n} samples ({:.1} %)",
                    100.0 * n as f64 / self.samples as f64
                ),
                Some(n) => format!(" on all {n} samples"),
                None => String::new(),
            };
            writeln!(
                f,
                "  global model of the method ({m}): free-run fit {fit:.3} %{share}"
            )?;
        }
        if let Some(n) = &self.global_note {
            writeln!(f, "  global model: {n}")?;
        }
        let whose = match self.nominal_rig.as_deref() {
            Some("built-in") => "the built-in rig's nominal model".to_string(),
            Some(rig) => format!("nominal model of {rig}"),
            None => "nominal".to_string(),
        };
        if let (Some(r), Some(m)) = (self.sim_rms_error_m, self.sim_max_abs_error_m) {
            writeln!(
                f,
                "  simulation model ({whose}):  rms {:.3} µm, max {:.3} µm",
                1e6 * r,
                1e6 * m
            )?;
        } else if self.simulation_diverged {
            writeln!(
                f,
                "  simulation model ({whose}):  diverged (unstable parameters)"
            )?;
        }
        writeln!(
            f,
            "  time: {:.3} ms identification and prediction, {:.2} µs per window",
            1e3 * self.identification_seconds,
            self.per_window_us
        )
    }
}
