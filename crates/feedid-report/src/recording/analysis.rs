//! The analysis behind a recording's report: every method's run, the
//! nominal simulation, the global models, and the helpers the figures share.

use rayon::prelude::*;

use crate::error::Result;
use crate::html::{Figure, HtmlReport, Section};
use crate::plot::{decimate_minmax, LineChart, Series};
use feedid::drive::{closed_loop_coefficients, simulate_nominal_recording, D1Variant, RigParams};
use feedid::ident::{
    fit_global_model, prediction_errors, simulation_error, EngineConfig, GlobalModelKind,
    LinearModel, Method, OeConfig, ResidualAnalysis, GLOBAL_FIT_SAMPLES,
};
use feedid::lti::TransferFunction;
use feedid::pipeline::{Identification, Pipeline};
use feedid::stats::ErrorStats;
use feedid::Recording;

/// Palette colours of the methods (0 = measurement, 5 = simulation model, 8 = command).
pub(super) const METHOD_COLORS: [usize; 6] = [1, 2, 3, 4, 6, 7];
pub(super) const MEASUREMENT: usize = 0;
pub(super) const SIMULATION: usize = 5;
pub(super) const COMMAND: usize = 8;

/// Fewest samples the zoom after the motion start shows (see
/// [`RecordingAnalysis::zoom_s`]).
pub const MIN_ZOOM_SAMPLES: usize = 30;

pub(super) fn method_color(i: usize) -> usize {
    METHOD_COLORS[i % METHOD_COLORS.len()]
}

/// What to analyse and how to draw it.
#[derive(Debug, Clone, PartialEq)]
pub struct ReportOptions {
    /// Methods with their sliding-window settings.
    pub methods: Vec<(Method, EngineConfig)>,
    /// Rig parameters of the nominal model; default: the default rig.
    pub params: RigParams,
    /// Where the parameters came from (shown in the header); default "the built-in default rig".
    pub params_source: String,
    /// Zoom after the motion start \[s\]; default 0.06 (the paper's figures
    /// 5 and 7). Widened on a coarse or slow-starting recording so that the
    /// zoom shows data (see [`RecordingAnalysis::zoom_s`]).
    pub zoom_s: f64,
    /// Points per curve after min/max decimation; default 3000 (coefficient
    /// curves, up to 16 per figure, get a fifth of it).
    pub max_points: usize,
    /// Largest lag of the residual analysis \[samples\]; default 30.
    pub max_lag: usize,
    /// Fit and plot the global models (Bode figure); default true.
    pub global_models: bool,
}

impl ReportOptions {
    /// Defaults with the given methods.
    pub fn new(methods: Vec<(Method, EngineConfig)>) -> Self {
        Self {
            methods,
            params: RigParams::default(),
            params_source: "the built-in default rig".to_string(),
            zoom_s: 0.06,
            max_points: 3000,
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

/// The analysis behind one recording's report.
#[derive(Debug, Clone)]
pub struct RecordingAnalysis {
    /// Display name (file name).
    pub name: String,
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
    /// Why a global model is missing (one line each).
    pub notes: Vec<String>,
    /// Motion start \[s\].
    pub motion_start: f64,
    /// The zoom after the motion start shown in the figures and the
    /// summary \[s\]: [`ReportOptions::zoom_s`], widened (to 1, 2 or 5 ×
    /// 10ⁿ s, at most to the recording's end) when it would hold fewer than
    /// [`MIN_ZOOM_SAMPLES`] samples or miss a method's first predicted
    /// horizon after the motion start (at 100 Hz, 60 ms are 6 samples and
    /// lie inside the first window).
    pub zoom_s: f64,
    /// Options used.
    pub options: ReportOptions,
}

impl RecordingAnalysis {
    /// Identify `recording` with every method (in parallel, each through
    /// the library's identification [`Pipeline`]), analyse the residuals of
    /// every predicted sample up to [`ReportOptions::max_lag`] (shortened
    /// for short series), simulate the nominal model and fit the global
    /// models.
    pub fn run(name: &str, recording: Recording, opts: &ReportOptions) -> Result<Self> {
        Self::run_with_progress(name, recording, opts, None)
    }

    /// [`RecordingAnalysis::run`], reporting `progress(done, total)` in
    /// samples: every method's identification of every sample, then each
    /// global model as one recording's worth (a plain callback; called from
    /// the worker threads).
    pub fn run_with_progress(
        name: &str,
        recording: Recording,
        opts: &ReportOptions,
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

        let runs: Vec<feedid::Result<Identification>> = opts
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
        let runs = runs.into_iter().collect::<feedid::Result<Vec<_>>>()?;
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
            name: name.to_string(),
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
            options: opts.clone(),
        })
    }

    /// Header facts: samples, rate, duration, motion, methods, parameters.
    pub fn facts(&self) -> Vec<(String, String)> {
        let r = &self.recording;
        let c = r.command();
        let (lo, hi) = c
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        let mut facts: Vec<(String, String)> = vec![
            ("recording".into(), self.name.clone()),
            ("samples".into(), format!("{}", r.len())),
            (
                "sampling rate".into(),
                format!("{:.2} Hz (Δt = {:.4} ms)", r.rate_hz(), 1e3 * r.dt()),
            ),
            ("duration".into(), format!("{:.4} s", r.duration())),
            (
                "motion start".into(),
                format!(
                    "{:.2} ms after the first sample",
                    1e3 * (self.motion_start - r.time()[0])
                ),
            ),
            (
                "command range".into(),
                format!("{:.3} mm … {:.3} mm", 1e3 * lo, 1e3 * hi),
            ),
            (
                "methods".into(),
                self.runs
                    .iter()
                    .map(|m| m.label.clone())
                    .collect::<Vec<_>>()
                    .join("; "),
            ),
            (
                "prediction horizon".into(),
                self.runs.first().map_or("–".into(), |m| {
                    let h = m.identification.config.horizon;
                    format!("H = {h} samples ({:.2} ms)", 1e3 * h as f64 * r.dt())
                }),
            ),
            ("nominal model".into(), self.options.params_source.clone()),
        ];
        if !r.gaps().is_empty() {
            facts.insert(
                2,
                (
                    "dropped samples".into(),
                    format!(
                        "{} missing in {} gap(s); the windows restart after each",
                        r.missing_samples(),
                        r.gaps().len()
                    ),
                ),
            );
        }
        facts
    }

    /// The report's sections for this recording; element ids start with `prefix`.
    pub fn sections(&self, prefix: &str) -> Result<Vec<Section>> {
        // the answer first (summary table and verdict), then the figures
        // that show it; the diagnostics one click away
        Ok(vec![
            self.summary_section(prefix),
            self.overview_section(prefix)?,
            self.response_section(prefix)?,
            self.error_section(prefix)?,
            self.coefficient_section(prefix)?.fold(),
            self.residual_section(prefix)?.fold(),
            self.bode_section(prefix)?.fold(),
        ])
    }

    // ------------------------------------------------------------ helpers

    pub(super) fn time_axis(&self) -> (f64, &'static str) {
        if self.recording.duration() <= 10.0 {
            (1e3, "time [ms]")
        } else {
            (1.0, "time [s]")
        }
    }

    pub(super) fn position_unit(&self) -> (f64, &'static str) {
        let c = self.recording.command();
        let (lo, hi) = c
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        if hi - lo >= 5e-3 {
            (1e3, "mm")
        } else {
            (1e6, "µm")
        }
    }

    /// Decimated series over the whole recording.
    pub(super) fn whole(
        &self,
        label: &str,
        f: &dyn Fn(usize) -> Option<f64>,
        scale: f64,
    ) -> Series {
        let t = self.recording.time();
        let (tf, _) = self.time_axis();
        let x: Vec<f64> = t.iter().map(|&v| tf * (v - t[0])).collect();
        let y: Vec<f64> = (0..t.len())
            .map(|k| f(k).map_or(f64::NAN, |v| scale * v))
            .collect();
        let (x, y) = decimate_minmax(&x, &y, self.options.max_points);
        Series::new(label, x, y)
    }

    pub(super) fn zoom_indices(&self) -> Vec<usize> {
        let t = self.recording.time();
        (0..t.len())
            .filter(|&k| t[k] >= self.motion_start && t[k] <= self.motion_start + self.zoom_s)
            .collect()
    }

    /// Series over the zoom window, time in ms since the motion start.
    pub(super) fn zoomed(
        &self,
        label: &str,
        f: &dyn Fn(usize) -> Option<f64>,
        scale: f64,
    ) -> Series {
        let idx = self.zoom_indices();
        let t = self.recording.time();
        let x: Vec<f64> = idx
            .iter()
            .map(|&k| 1e3 * (t[k] - self.motion_start))
            .collect();
        let y: Vec<f64> = idx
            .iter()
            .map(|&k| f(k).map_or(f64::NAN, |v| scale * v))
            .collect();
        let (x, y) = decimate_minmax(&x, &y, self.options.max_points);
        Series::new(label, x, y)
    }

    pub(super) fn zoom_ms(&self) -> f64 {
        1e3 * self.zoom_s
    }

    /// The zoom span as text: "60 ms", "1 s", "2.5 s".
    pub(super) fn zoom_text(&self) -> String {
        span_text(self.zoom_s)
    }

    /// A sentence saying that and why the zoom was widened; empty when it was not.
    pub(super) fn zoom_note(&self) -> String {
        if self.zoom_s > self.options.zoom_s {
            format!(
                " The zoom is widened from the requested {} to {}: at {:.0} Hz the requested span \
                 holds too few samples or no method's prediction yet.",
                span_text(self.options.zoom_s),
                self.zoom_text(),
                self.recording.rate_hz()
            )
        } else {
            String::new()
        }
    }

    pub(super) fn figure(
        id: String,
        title: &str,
        chart: &LineChart,
        caption: &str,
    ) -> Result<Figure> {
        Ok(Figure::new(&id, title, &chart.to_svg()?, caption))
    }
}

/// A time span as text: whole ms below a second ("60 ms"), else seconds
/// to three significant digits ("1 s", "2.5 s"); sub-ms spans to three digits.
pub(super) fn span_text(s: f64) -> String {
    let sig3 = |v: f64| {
        format!("{v:.2e}")
            .parse::<f64>()
            .map_or_else(|_| v.to_string(), |x| x.to_string())
    };
    let ms = 1e3 * s;
    if ms >= 999.5 {
        format!("{} s", sig3(s))
    } else if ms >= 1.0 {
        format!("{ms:.0} ms")
    } else {
        format!("{} ms", sig3(ms))
    }
}

/// The zoom after the motion start actually shown \[s\] (see
/// [`RecordingAnalysis::zoom_s`]): `requested`, unless it holds fewer than
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
fn global_models(recording: &Recording, opts: &ReportOptions) -> (Vec<GlobalModel>, Vec<String>) {
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

/// The stand-alone report of one recording.
pub fn recording_report(a: &RecordingAnalysis) -> Result<HtmlReport> {
    let mut page = HtmlReport::new(&format!("feedid report — {}", a.name));
    page.facts = a.facts();
    page.intro.push(
        "How to read this report: the answer comes first. The summary below names the method that predicts \
         best and has every method's numbers; the one-line contents follow it. The recording is identified in \
         short sliding windows by each method; every window's model predicts the next H samples, which are \
         compared with what was then measured. After the summary, the figures go from the raw data to the \
         predictions and their errors; the identified coefficients, the whiteness of the errors and the \
         frequency response are folded at the end, one click away. Units: time in ms, or s for long \
         recordings; positions in µm or mm as labelled on each axis."
            .into(),
    );
    page.sections = a.sections("rec")?;
    // the summary with the answer before the contents: on the first screen
    page.lead_sections = 1;
    Ok(page)
}
