//! One identification run over a recording: the sliding prediction of an
//! estimator, the nominal simulation model next to it (the paper's third
//! curve), and the summary that `feedid identify` writes.
//!
//! ```
//! use feedid::ident::{identify, EngineConfig, PaperConfig};
//! use feedid::{drive::RigParams, Recording};
//! let t: Vec<f64> = (0..200).map(|k| k as f64 * 2e-4).collect();
//! let u: Vec<f64> = t.iter().map(|&t| 0.05 * t).collect();
//! let rec = Recording::new(t, u.clone(), u).unwrap();
//! let mut est = PaperConfig::default().build().unwrap();
//! let run = identify(&rec, &mut est, &EngineConfig::default(), Some(&RigParams::default())).unwrap();
//! let s = run.summary();
//! assert_eq!(s.method, "paper");
//! assert!(s.samples_predicted > 0);
//! ```

use serde::Serialize;

use crate::drive::{simulate_nominal, RigParams};
use crate::error::Result;
use crate::ident::engine::{run as run_engine, EngineConfig, SlidingResult};
use crate::ident::{Estimator, ModelFile, ResidualAnalysis, WindowOutcome};
use crate::recording::Recording;
use crate::stats::ErrorStats;

/// The outcome of identifying one recording.
#[derive(Debug, Clone)]
pub struct Identification {
    /// The sliding-window predictions and per-window coefficients.
    pub sliding: SlidingResult,
    /// Nominal linear model driven by the measured command (if parameters were given).
    pub simulated: Option<Vec<f64>>,
    /// Error of the nominal model against the measurement over the same samples
    /// as the predictions (all samples if nothing was predicted).
    pub simulation_stats: Option<ErrorStats>,
    /// The engine settings used.
    pub config: EngineConfig,
    /// Samples in the recording.
    pub samples: usize,
    /// Sampling rate \[Hz\].
    pub rate_hz: f64,
    /// Residual analysis of the prediction errors (see [`IdentifySummary::residuals`]).
    pub residuals: Option<ResidualAnalysis>,
    /// The method's global model, if one was fitted (set it with
    /// [`crate::ident::global_model_for`]; `identify` leaves it `None`).
    pub global: Option<ModelFile>,
}

/// Slide `estimator` over `recording` and compare with the nominal model of `params`.
pub fn identify<E: Estimator + ?Sized>(
    recording: &Recording,
    estimator: &mut E,
    config: &EngineConfig,
    params: Option<&RigParams>,
) -> Result<Identification> {
    let signals = recording.signals();
    let sliding = run_engine(estimator, &signals, config)?;
    let simulated = match params {
        Some(p) => Some(simulate_nominal(p, recording.command(), recording.dt())?),
        None => None,
    };
    let simulation_stats = simulated.as_ref().map(|sim| {
        let y = recording.position();
        let any = sliding.stats.samples > 0;
        ErrorStats::from_pairs(
            (0..y.len())
                .filter(|&k| !any || sliding.has_prediction[k])
                .map(|k| (y[k], sim[k])),
        )
    });
    Ok(Identification {
        simulated,
        simulation_stats,
        config: *config,
        samples: recording.len(),
        rate_hz: recording.rate_hz(),
        residuals: prediction_residuals(
            &sliding,
            recording.command(),
            recording.position(),
            RESIDUAL_LAGS,
        ),
        sliding,
        global: None,
    })
}

/// The machine-readable summary of a run (`summary.json`). Optional values
/// that do not apply (no nominal model, no global model, too few predictions
/// for the residual analysis) are left out of the JSON, so a `null` never
/// stands for a number.
#[derive(Debug, Clone, PartialEq, Serialize)]
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
    /// Windows whose prediction the method withheld (not validated; `auto`).
    pub withheld_windows: usize,
    /// Samples with a prediction.
    pub samples_predicted: usize,
    /// Share of the recording's samples with a prediction \[%\].
    pub coverage_percent: f64,
    /// RMS prediction error \[m\].
    pub rms_error_m: f64,
    /// Largest absolute prediction error \[m\].
    pub max_abs_error_m: f64,
    /// NRMSE fit of the k-step (k = horizon) predictions \[%\].
    pub fit_percent: f64,
    /// NRMSE fit of the free-run simulation of the method's global model
    /// over the whole recording \[%\] (`None` without one, e.g. `paper`;
    /// `null` in JSON also when the model is unstable).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sim_fit_percent: Option<f64>,
    /// Structure of the global model (e.g. `"arx na=8 nb=8 nk=1"`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub global_model: Option<String>,
    /// RMS error of the nominal simulation model over the predicted samples \[m\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sim_rms_error_m: Option<f64>,
    /// Largest absolute error of the nominal simulation model \[m\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sim_max_abs_error_m: Option<f64>,
    /// NRMSE fit of the nominal simulation model \[%\].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nominal_fit_percent: Option<f64>,
    /// Wall time of identification and prediction only (no I/O) \[s\].
    pub identification_seconds: f64,
    /// Mean wall time per window \[µs\].
    pub per_window_us: f64,
    /// Residual analysis of the prediction errors `y − ŷ` over the predicted
    /// samples (at most the last 200 000) against the command, lags 0 … 25
    /// (`None` when fewer than 52 samples were predicted). The k-step errors of one horizon share the
    /// state they were predicted from, so `r_ee` is expected to be
    /// positive for lags below the horizon.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub residuals: Option<ResidualAnalysis>,
}

/// Largest lag of the residual analysis in the summary.
pub const RESIDUAL_LAGS: usize = 25;

/// Most recent predicted samples used by the residual analysis.
const RESIDUAL_SAMPLES: usize = 200_000;

/// Residual analysis of `y − ŷ` over the predicted samples (at most the last
/// [`RESIDUAL_SAMPLES`]) against the command; `None` if too few were predicted.
fn prediction_residuals(
    s: &SlidingResult,
    command: &[f64],
    position: &[f64],
    max_lag: usize,
) -> Option<ResidualAnalysis> {
    let (mut u, mut e) = (Vec::new(), Vec::new());
    for k in (0..s.predicted.len()).rev() {
        if e.len() >= RESIDUAL_SAMPLES {
            break;
        }
        if s.has_prediction[k] {
            u.push(command.get(k).copied().unwrap_or(0.0));
            e.push(position.get(k).copied().unwrap_or(0.0) - s.predicted[k]);
        }
    }
    if e.len() <= 2 * max_lag + 1 {
        return None;
    }
    u.reverse();
    e.reverse();
    ResidualAnalysis::new(&u, &e, max_lag).ok()
}

impl Identification {
    /// The summary of this run.
    pub fn summary(&self) -> IdentifySummary {
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
            samples_predicted: s.stats.samples,
            coverage_percent: if self.samples > 0 {
                100.0 * s.stats.samples as f64 / self.samples as f64
            } else {
                0.0
            },
            rms_error_m: s.stats.rms,
            max_abs_error_m: s.stats.max_abs,
            fit_percent: s.stats.fit_percent,
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
            sim_rms_error_m: self.simulation_stats.map(|x| x.rms),
            sim_max_abs_error_m: self.simulation_stats.map(|x| x.max_abs),
            nominal_fit_percent: self.simulation_stats.map(|x| x.fit_percent),
            identification_seconds: s.elapsed.as_secs_f64(),
            per_window_us: s.per_window_us(),
            residuals: self.residuals.clone(),
        }
    }
}
