//! The analysis behind a recording's report: the library's comparison of
//! every method on the recording ([`Comparison`]), with the report's
//! options and the helpers the figures share.

use crate::error::Result;
use crate::html::{Figure, HtmlReport, Section};
use crate::plot::{decimate_minmax, LineChart, Series};
use feedid::drive::RigParams;
use feedid::ident::{EngineConfig, Method};
use feedid::pipeline::{CompareOptions, Comparison};
pub use feedid::pipeline::{GlobalModel, MethodRun};
use feedid::Recording;

/// Palette colours of the methods (0 = measurement, 5 = simulation model, 8 = command).
pub(super) const METHOD_COLORS: [usize; 6] = [1, 2, 3, 4, 6, 7];
pub(super) const MEASUREMENT: usize = 0;
pub(super) const SIMULATION: usize = 5;
pub(super) const COMMAND: usize = 8;

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
    /// zoom shows data (see [`Comparison::zoom_s`]).
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

/// The analysis behind one recording's report.
#[derive(Debug, Clone)]
pub struct RecordingAnalysis {
    /// Display name (file name).
    pub name: String,
    /// Every method on the recording, the nominal and the global models
    /// (its fields read through this analysis: `a.runs`, `a.zoom_s`, …).
    pub comparison: Comparison,
    /// Options used.
    pub options: ReportOptions,
}

impl std::ops::Deref for RecordingAnalysis {
    type Target = Comparison;

    fn deref(&self) -> &Comparison {
        &self.comparison
    }
}

impl RecordingAnalysis {
    /// Identify `recording` with every method (in parallel, each through
    /// the library's identification [`Pipeline`](feedid::pipeline::Pipeline)), analyse the residuals of
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
        let compare = CompareOptions {
            methods: opts.methods.clone(),
            params: opts.params,
            zoom_s: opts.zoom_s,
            max_lag: opts.max_lag,
            global_models: opts.global_models,
        };
        Ok(Self {
            name: name.to_string(),
            comparison: Comparison::run(recording, &compare, progress)?,
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
