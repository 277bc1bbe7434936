//! Every method on one recording, compared on the same footing: each
//! method's sliding identification through the [`Pipeline`] (in parallel),
//! its errors over a zoom after the motion start and the residual analysis
//! of all its predictions, the nominal physical model driven by the
//! measured command (the paper's simulation model), and the global ARX and
//! OE models of the whole recording. The HTML report of a recording draws
//! this; a binding or a script can use the numbers directly.
//!
//! The zoom after the motion start is the requested span (the paper's
//! 60 ms by default), widened to 1, 2 or 5 × 10ⁿ s when it would hold
//! fewer than [`MIN_ZOOM_SAMPLES`] samples or end before some method's
//! first predicted horizon (at 100 Hz, 60 ms are 6 samples and lie inside
//! the first window), so that every figure and figure of merit over it
//! has data.

use rayon::prelude::*;

use super::{Identification, Pipeline};
use crate::drive::{closed_loop_coefficients, simulate_nominal_recording, D1Variant, RigParams};
use crate::error::Result;
use crate::ident::{
    fit_global_model, prediction_errors, simulation_error, EngineConfig, GlobalModelKind,
    LinearModel, Method, OeConfig, ResidualAnalysis, GLOBAL_FIT_SAMPLES,
};
use crate::lti::TransferFunction;
use crate::stats::ErrorStats;
use crate::Recording;

/// Fewest samples the zoom after the motion start holds (see
/// [`Comparison::zoom_s`]).
pub const MIN_ZOOM_SAMPLES: usize = 30;

/// What to compare and how.
#[derive(Debug, Clone, PartialEq)]
pub struct CompareOptions {
    /// Methods with their sliding-window settings.
    pub methods: Vec<(Method, EngineConfig)>,
    /// Rig parameters of the nominal model; default: the default rig.
    pub params: RigParams,
    /// Zoom after the motion start \[s\]; default 0.06 (the paper's figures
    /// 5 and 7), widened where it would show no data ([`Comparison::zoom_s`]).
    pub zoom_s: f64,
    /// Largest lag of the residual analysis \[samples\]; default 30.
    pub max_lag: usize,
    /// Fit the global models; default true.
    pub global_models: bool,
}

impl CompareOptions {
    /// Defaults with the given methods.
    pub fn new(methods: Vec<(Method, EngineConfig)>) -> Self {
        Self {
            methods,
            params: RigParams::default(),
            zoom_s: 0.06,
            max_lag: 30,
            global_models: true,
        }
    }
}

/// One method's sliding identification and its diagnostics.
#[derive(Debug, Clone)]
pub struct MethodRun {
    /// Label for legends and tables (method and its main settings).
    pub label: String,
    /// Short id for element ids.
    pub slug: String,
    /// The method as it ran.
    pub method: Method,
    /// The run.
    pub identification: Identification,
    /// Errors over the zoom window after the motion start.
    pub zoom_stats: ErrorStats,
    /// Residual analysis of the prediction errors (`None` if too few predictions).
    pub residuals: Option<ResidualAnalysis>,
}

/// A model fitted over the whole recording.
#[derive(Debug, Clone, PartialEq)]
pub struct GlobalModel {
    /// Label (structure and orders).
    pub label: String,
    /// The model.
    pub model: LinearModel,
    /// Errors of its free-run simulation against the measurement.
    pub simulation: ErrorStats,
}

/// Every method on one recording ([`Comparison::run`]).
#[derive(Debug, Clone)]
pub struct Comparison {
    /// The recording.
    pub recording: Recording,
    /// One run per method, in the order given.
    pub runs: Vec<MethodRun>,
    /// Nominal model driven by the measured command \[m\].
    pub simulated: Vec<f64>,
    /// Errors of the nominal model over the whole recording.
    pub simulation_stats: ErrorStats,
    /// Errors of the nominal model over the zoom window.
    pub simulation_zoom: ErrorStats,
    /// The nominal closed-loop transfer function.
    pub nominal: TransferFunction,
    /// Global models that could be fitted.
    pub global: Vec<GlobalModel>,
    /// Why a global model is missing, and the gaps (one line each).
    pub notes: Vec<String>,
    /// Motion start \[s\].
    pub motion_start: f64,
    /// The zoom after the motion start \[s\]: [`CompareOptions::zoom_s`],
    /// widened (to 1, 2 or 5 × 10ⁿ s, at most to the recording's end) when
    /// it would hold fewer than [`MIN_ZOOM_SAMPLES`] samples or miss a
    /// method's first predicted horizon after the motion start.
    pub zoom_s: f64,
}

impl Comparison {
    /// Identify `recording` with every method (in parallel, each through
    /// the [`Pipeline`]), analyse the residuals of every predicted sample up
    /// to [`CompareOptions::max_lag`] (shortened for short series), simulate
    /// the nominal model and fit the global models; `progress(done, total)`
    /// in samples: every method's identification of every sample, then each
    /// global model as one recording's worth (a plain callback, called from
    /// the worker threads).
    ///
    /// Errors: the first method whose run fails, or the nominal model's.
    pub fn run(
        recording: Recording,
        opts: &CompareOptions,
        progress: Option<&(dyn Fn(u64, u64) + Sync)>,
    ) -> Result<Self> {
        let n = recording.len() as u64;
        let globals = if opts.global_models { 2 } else { 0 };
        let total = n * (opts.methods.len() as u64 + globals);
        let done: Vec<std::sync::atomic::AtomicU64> = opts
            .methods
            .iter()
            .map(|_| std::sync::atomic::AtomicU64::new(0))
            .collect();
        let report = |i: usize, d: u64| {
            if let Some(p) = progress {
                done[i].store(d, std::sync::atomic::Ordering::Relaxed);
                let sum: u64 = done
                    .iter()
                    .map(|a| a.load(std::sync::atomic::Ordering::Relaxed))
                    .sum();
                p(sum.min(total), total);
            }
        };
        // (through the gaps of dropped samples, if any, at the measured ones)
        let simulated = simulate_nominal_recording(&opts.params, &recording)?;
        let nominal =
            closed_loop_coefficients(&opts.params, D1Variant::Corrected).transfer_function()?;
        let motion_start = recording.motion_start_time();
        let t = recording.time();
        let y = recording.position();

        let runs: Vec<Result<Identification>> = opts
            .methods
            .par_iter()
            .enumerate()
            .map(|(i, (method, cfg))| {
                let hook = |d: u64, _: u64| report(i, d);
                let mut p = Pipeline::new(method.clone())
                    .engine(*cfg)
                    .method_global_model(false)
                    .residuals(None);
                if progress.is_some() {
                    p = p.progress(&hook);
                }
                p.run(&recording)
            })
            .collect();
        let runs = runs.into_iter().collect::<Result<Vec<_>>>()?;
        let zoom_s = zoom_span(&recording, motion_start, opts.zoom_s, &runs);
        let in_zoom = |k: usize| t[k] >= motion_start && t[k] <= motion_start + zoom_s;
        let mut out_runs = Vec::with_capacity(runs.len());
        for (i, identification) in runs.into_iter().enumerate() {
            let s = &identification.sliding;
            let zoom_stats = ErrorStats::from_pairs(
                (0..y.len())
                    .filter(|&k| in_zoom(k))
                    .filter_map(|k| s.prediction(k).map(|p| (y[k], p))),
            );
            // every predicted sample, the lag shortened to fit a short series
            let (uu, ee) = prediction_errors(s, recording.command(), y, usize::MAX);
            let lag = opts.max_lag.min(ee.len().saturating_sub(2));
            let residuals = if lag >= 1 {
                ResidualAnalysis::for_horizon(&uu, &ee, lag, identification.config.horizon).ok()
            } else {
                None
            };
            let method = identification.method.clone();
            out_runs.push(MethodRun {
                label: format!("{} (W={})", method.label(), identification.config.window),
                slug: format!("{}{}", method.name(), i + 1),
                method,
                identification,
                zoom_stats,
                residuals,
            });
        }
        let simulation_stats =
            ErrorStats::from_pairs(y.iter().copied().zip(simulated.iter().copied()));
        let simulation_zoom = ErrorStats::from_pairs(
            (0..y.len())
                .filter(|&k| in_zoom(k))
                .map(|k| (y[k], simulated[k])),
        );
        let (global, mut notes) = if opts.global_models {
            let (global, mut notes) = global_models(&recording, opts);
            if let Some(g) = recording.gaps().first() {
                notes.push(format!(
                    "Global models: fitted and simulated through the {} gap(s) of dropped samples \
                     (the first before sample {}; the command interpolated there), compared with \
                     the measured samples only.",
                    recording.gaps().len(),
                    g.index
                ));
            }
            (global, notes)
        } else {
            (Vec::new(), Vec::new())
        };
        if let Some(g) = recording.gaps().first() {
            notes.insert(
                0,
                format!(
                    "{} sample(s) missing in {} gap(s) (the first before sample {}): every method \
                     restarts its windows after each gap, so the start of every later segment is \
                     not predicted; the nominal model runs through the gaps.",
                    recording.missing_samples(),
                    recording.gaps().len(),
                    g.index
                ),
            );
        }
        if let Some(p) = progress {
            p(total, total);
        }
        Ok(Self {
            recording,
            runs: out_runs,
            simulated,
            simulation_stats,
            simulation_zoom,
            nominal,
            global,
            notes,
            motion_start,
            zoom_s,
        })
    }
}

/// The zoom after the motion start actually shown \[s\] (see
/// [`Comparison::zoom_s`]): `requested`, unless it holds fewer than
/// [`MIN_ZOOM_SAMPLES`] samples or ends before some method's first full
/// horizon of predictions after the motion start; then the smallest 1, 2 or
/// 5 × 10ⁿ s that holds them, at most up to the recording's last sample.
fn zoom_span(
    recording: &Recording,
    motion_start: f64,
    requested: f64,
    runs: &[Identification],
) -> f64 {
    let t = recording.time();
    let n = t.len();
    let Some(first) = t.iter().position(|&v| v >= motion_start) else {
        return requested;
    };
    let last = t[n - 1] - motion_start;
    let at = |k: usize| t[k.min(n - 1)] - motion_start;
    let mut need = at(first + MIN_ZOOM_SAMPLES - 1);
    for run in runs {
        let s = &run.sliding;
        let h = run.config.horizon.max(1);
        if let Some(k) = (first..n).find(|&k| s.has_prediction.get(k) == Some(&true)) {
            need = need.max(at(k + h - 1));
        }
    }
    if need <= requested || !need.is_finite() || last <= requested {
        return requested;
    }
    // the next 1, 2 or 5 × 10ⁿ at or above what is needed
    let decade = 10f64.powf(need.log10().floor());
    let nice = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * decade)
        .find(|&v| v >= need * (1.0 - 1e-12))
        .unwrap_or(10.0 * decade);
    nice.min(last)
}

/// The global models of the Bode figure, through the library's one
/// global-model path ([`fit_global_model`], at most
/// [`GLOBAL_FIT_SAMPLES`] samples): ARX with the orders of the first method
/// whose global model is ARX (`arx`, `rls`; else 8,8,1) and continuous OE
/// with the poles and zeros of the first `oe` method (else 3 poles, 1
/// zero); a model that cannot be fitted is a note, not an error.
fn global_models(recording: &Recording, opts: &CompareOptions) -> (Vec<GlobalModel>, Vec<String>) {
    let kinds: Vec<GlobalModelKind> = opts
        .methods
        .iter()
        .filter_map(|(m, _)| m.global_model())
        .collect();
    let orders = kinds
        .iter()
        .find_map(|k| match k {
            GlobalModelKind::Arx(o) => Some(*o),
            _ => None,
        })
        .unwrap_or_default();
    let default_oe = OeConfig::default();
    let (poles, zeros) = kinds
        .iter()
        .find_map(|k| match k {
            GlobalModelKind::Oe { poles, zeros } => Some((*poles, *zeros)),
            _ => None,
        })
        .unwrap_or((default_oe.poles, default_oe.zeros));
    let plural = |n: usize, what: &str| {
        if n == 1 {
            format!("1 {what}")
        } else {
            format!("{n} {what}s")
        }
    };
    let arx_label = format!("global ARX {},{},{}", orders.na, orders.nb, orders.nk);
    let oe_label = format!(
        "global OE {}, {}",
        plural(poles, "pole"),
        plural(zeros, "zero")
    );
    let (arx, oe) = rayon::join(
        || fit_global_model(recording, &GlobalModelKind::Arx(orders)),
        || fit_global_model(recording, &GlobalModelKind::Oe { poles, zeros }),
    );
    let (mut global, mut notes) = (Vec::new(), Vec::new());
    // simulated over the fitted samples (through any gaps)
    let head = recording.head(GLOBAL_FIT_SAMPLES);
    for (label, fit) in [(arx_label, arx), (oe_label, oe)] {
        match fit {
            Ok(file) => match head
                .as_ref()
                .map_err(|e| e.to_string())
                .and_then(|h| simulation_error(&file.model, h).map_err(|e| e.to_string()))
            {
                Ok(simulation) if simulation.rms.is_finite() => global.push(GlobalModel {
                    label,
                    simulation,
                    model: file.model,
                }),
                _ => notes.push(format!(
                    "{label}: fitted, but its free-run simulation diverges (unstable model); not shown."
                )),
            },
            Err(e) => notes.push(format!("{label}: could not be fitted ({e}); not shown.")),
        }
    }
    (global, notes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::VirtualRig;
    use crate::signal::Scenario;

    fn rig(scenario: Scenario, rate: f64, duration: f64) -> Recording {
        let c = scenario.command(rate, duration, 1).unwrap();
        let o = VirtualRig::new(RigParams::default())
            .with_seed(3)
            .simulate(&c, rate)
            .unwrap();
        Recording::new(o.time, o.command, o.position).unwrap()
    }

    fn methods(names: &[&str]) -> Vec<(Method, EngineConfig)> {
        names
            .iter()
            .map(|n| {
                let m: Method = n.parse().unwrap();
                let cfg = EngineConfig {
                    window: m.default_window(),
                    ..EngineConfig::default()
                };
                (m, cfg)
            })
            .collect()
    }

    #[test]
    fn each_method_predicts_as_its_pipeline_alone_and_the_zoom_holds_its_samples() {
        let rec = rig(Scenario::Ramp, 5000.0, 0.2);
        let opts = CompareOptions::new(methods(&["paper", "arx"]));
        let c = Comparison::run(rec.clone(), &opts, None).unwrap();
        assert_eq!(c.runs.len(), 2);
        for (run, (m, cfg)) in c.runs.iter().zip(&opts.methods) {
            let alone = Pipeline::new(m.clone())
                .engine(*cfg)
                .method_global_model(false)
                .residuals(None)
                .run(&rec)
                .unwrap();
            assert_eq!(
                run.identification.sliding.predicted,
                alone.sliding.predicted
            );
            // the zoom's figures are over the predicted samples inside it
            let t = rec.time();
            let inside = (0..rec.len())
                .filter(|&k| t[k] >= c.motion_start && t[k] <= c.motion_start + c.zoom_s)
                .filter(|&k| alone.sliding.prediction(k).is_some())
                .count();
            assert_eq!(run.zoom_stats.samples, inside);
            assert!(run.residuals.is_some());
        }
        // 60 ms at 5 kHz hold 300 samples: the zoom stays as asked
        assert!((c.zoom_s - 0.06).abs() < 1e-12, "{}", c.zoom_s);
        assert_eq!(c.simulated.len(), rec.len());
        assert_eq!(c.global.len() + c.notes.len(), 2, "{:?}", c.notes);
    }

    #[test]
    fn at_100_hz_the_zoom_widens_until_every_method_has_predictions_in_it() {
        let rec = rig(Scenario::Prbs, 100.0, 20.0);
        let mut opts = CompareOptions::new(methods(&["arx", "auto"]));
        opts.global_models = false;
        let c = Comparison::run(rec, &opts, None).unwrap();
        assert!(c.zoom_s > 0.06);
        // a 1, 2 or 5 × 10ⁿ span
        let m = c.zoom_s / 10f64.powf(c.zoom_s.log10().floor());
        assert!(
            [1.0, 2.0, 5.0, 10.0].iter().any(|v| (m - v).abs() < 1e-9),
            "{}",
            c.zoom_s
        );
        for run in &c.runs {
            assert!(run.zoom_stats.samples > 0, "{}", run.label);
        }
        assert!(c.global.is_empty() && c.notes.is_empty());
    }
}
