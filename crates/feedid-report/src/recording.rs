//! Everything the report shows about one recording: the sliding
//! identification of every chosen method, the nominal simulation model,
//! residual analysis, global models fitted over the whole recording, and the
//! figures and tables built from them.
//!
//! Quantities (y measured, ŷ predicted, u command, all in metres):
//!
//! ```text
//! prediction error      e[k] = y[k] − ŷ[k]                (samples with a prediction)
//! error per horizon     rms of e over each window's horizon of H samples
//! normalised coefficient c_i(w) / median_w |c_i(w)|       (steady → flat line at ±1)
//! residual correlations r_ee(τ), r_ue(τ) with the 99 % band ±2.58/√N   (see ResidualAnalysis)
//! Bode                  |G(j2πf)| in dB and arg G in degrees; discrete models at z = e^{j2πfΔt}
//! ```
//!
//! Global models: ARX (orders of the `arx`/`rls` method if chosen, else
//! 8,8,1) by [`fit_arx`] and a continuous-time output-error model (3 poles, 1
//! zero, or the `oe` method's orders) by [`fit_oe`], both over at most the
//! first [`GLOBAL_FIT_MAX_SAMPLES`] samples; their free-run simulation fit is
//! tabulated. A fit that fails is reported in the text, not as an error.
//!
//! ```
//! use feedid::ident::{EngineConfig, MethodKind, MethodSpec};
//! use feedid_report::{recording_report, RecordingAnalysis, ReportOptions};
//! use feedid::Recording;
//! let t: Vec<f64> = (0..400).map(|k| k as f64 * 2e-4).collect();
//! let u: Vec<f64> = t.iter().map(|&t| if t > 0.01 { 0.05 * (t - 0.01) } else { 0.0 }).collect();
//! let y: Vec<f64> = (0..400).map(|k| if k > 5 { u[k - 5] } else { 0.0 }).collect();
//! let rec = Recording::new(t, u, y).unwrap();
//! let opts = ReportOptions::new(vec![(
//!     MethodSpec::new(MethodKind::Paper),
//!     EngineConfig::default(),
//! )]);
//! let a = RecordingAnalysis::run("ramp.csv", rec, &opts).unwrap();
//! let page = recording_report(&a).unwrap();
//! assert!(page.to_html().contains("id=\"rec-response-zoom\""));
//! ```

use rayon::prelude::*;

use crate::error::Result;
use crate::html::{Block, Figure, HtmlReport, Section, Table};
use crate::plot::{decimate_minmax, Band, LegendPosition, LineChart, Series};
use feedid::drive::{closed_loop_coefficients, simulate_nominal, D1Variant, RigParams};
use feedid::ident::{
    fit_arx, fit_oe, identify, ArxConfig, ArxOrders, EngineConfig, Identification, LinearModel,
    MethodKind, MethodSpec, OeConfig, ResidualAnalysis, WindowOutcome,
};
use feedid::lti::{Complex, TransferFunction};

use feedid::stats::ErrorStats;
use feedid::Recording;

/// Palette colours of the methods (0 = measurement, 5 = simulation model, 8 = command).
const METHOD_COLORS: [usize; 6] = [1, 2, 3, 4, 6, 7];
const MEASUREMENT: usize = 0;
const SIMULATION: usize = 5;
const COMMAND: usize = 8;

fn method_color(i: usize) -> usize {
    METHOD_COLORS[i % METHOD_COLORS.len()]
}

/// Longest stretch fitted by the global models \[samples\].
pub const GLOBAL_FIT_MAX_SAMPLES: usize = 100_000;

/// What to analyse and how to draw it.
#[derive(Debug, Clone, PartialEq)]
pub struct ReportOptions {
    /// Methods with their sliding-window settings.
    pub methods: Vec<(MethodSpec, EngineConfig)>,
    /// Rig parameters of the nominal model; default: the default rig.
    pub params: RigParams,
    /// Where the parameters came from (shown in the header); default "the built-in default rig".
    pub params_source: String,
    /// Zoom after the motion start \[s\]; default 0.06 (the paper's figures 5 and 7).
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
    pub fn new(methods: Vec<(MethodSpec, EngineConfig)>) -> Self {
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
    /// The method.
    pub spec: MethodSpec,
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
    /// Options used.
    pub options: ReportOptions,
}

/// A label for legends: the method and its main settings.
pub fn method_label(spec: &MethodSpec, cfg: &EngineConfig) -> String {
    let detail = match spec.kind.name() {
        "paper" => format!("paper LSM, {}", spec.paper.solver.label()),
        "arx" => {
            let o = spec.arx.orders;
            format!("ARX {},{},{}", o.na, o.nb, o.nk)
        }
        "rls" => {
            let o = spec.rls.orders;
            format!("RLS {},{},{} λ={}", o.na, o.nb, o.nk, spec.rls.lambda)
        }
        "oe" => format!("OE {}p/{}z", spec.oe.poles, spec.oe.zeros),
        other => other.to_string(),
    };
    format!("{detail} (W={})", cfg.window)
}

impl RecordingAnalysis {
    /// Identify `recording` with every method (in parallel), simulate the
    /// nominal model, analyse residuals and fit the global models.
    pub fn run(name: &str, recording: Recording, opts: &ReportOptions) -> Result<Self> {
        let dt = recording.dt();
        let simulated = simulate_nominal(&opts.params, recording.command(), dt)?;
        let nominal =
            closed_loop_coefficients(&opts.params, D1Variant::Corrected).transfer_function()?;
        let motion_start = recording.motion_start_time();
        let t = recording.time();
        let y = recording.position();
        let u = recording.command();
        let in_zoom = |k: usize| t[k] >= motion_start && t[k] <= motion_start + opts.zoom_s;

        let runs: Vec<Result<(MethodSpec, EngineConfig, Identification)>> = opts
            .methods
            .par_iter()
            .map(|(spec, cfg)| {
                let mut est = spec.build()?;
                let id = identify(&recording, est.as_mut(), cfg, None)?;
                Ok((spec.clone(), *cfg, id))
            })
            .collect();
        let mut out_runs = Vec::with_capacity(runs.len());
        for (i, r) in runs.into_iter().enumerate() {
            let (spec, cfg, identification) = r?;
            let s = &identification.sliding;
            let zoom_stats = ErrorStats::from_pairs(
                (0..y.len())
                    .filter(|&k| in_zoom(k))
                    .filter_map(|k| s.prediction(k).map(|p| (y[k], p))),
            );
            let (mut uu, mut ee) = (Vec::new(), Vec::new());
            for k in 0..y.len() {
                if let Some(p) = s.prediction(k) {
                    uu.push(u[k]);
                    ee.push(y[k] - p);
                }
            }
            let lag = opts.max_lag.min(ee.len().saturating_sub(2));
            let residuals = if lag >= 1 {
                ResidualAnalysis::new(&uu, &ee, lag).ok()
            } else {
                None
            };
            out_runs.push(MethodRun {
                label: method_label(&spec, &cfg),
                slug: format!("{}{}", spec.kind.name(), i + 1),
                spec,
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
        let mut global = Vec::new();
        let mut notes = Vec::new();
        if opts.global_models {
            let n = y.len().min(GLOBAL_FIT_MAX_SAMPLES);
            let (ug, yg) = (&u[..n], &y[..n]);
            let orders = opts
                .methods
                .iter()
                .find(|(s, _)| matches!(s.kind, MethodKind::Arx))
                .map(|(s, _)| s.arx.orders)
                .or_else(|| {
                    opts.methods
                        .iter()
                        .find(|(s, _)| matches!(s.kind, MethodKind::Rls))
                        .map(|(s, _)| s.rls.orders)
                })
                .unwrap_or_default();
            let oe_cfg = opts
                .methods
                .iter()
                .find(|(s, _)| matches!(s.kind, MethodKind::Oe))
                .map(|(s, _)| s.oe.clone())
                .unwrap_or_default();
            let arx_label = format!("global ARX {},{},{}", orders.na, orders.nb, orders.nk);
            let plural = |n: usize, what: &str| {
                if n == 1 {
                    format!("1 {what}")
                } else {
                    format!("{n} {what}s")
                }
            };
            let oe_label = format!(
                "global OE {}, {}",
                plural(oe_cfg.poles, "pole"),
                plural(oe_cfg.zeros, "zero")
            );
            let (arx, oe) = rayon::join(
                || global_arx(ug, yg, dt, orders),
                || global_oe(ug, yg, dt, &oe_cfg),
            );
            for (label, fit) in [(arx_label, arx), (oe_label, oe)] {
                match fit {
                    Ok(model) => match model.simulate_at(ug, dt) {
                        Ok(sim) if sim.iter().all(|v| v.is_finite()) => {
                            global.push(GlobalModel {
                                label,
                                simulation: ErrorStats::from_pairs(
                                    yg.iter().copied().zip(sim.iter().copied()),
                                ),
                                model,
                            })
                        }
                        _ => notes.push(format!(
                            "{label}: fitted, but its free-run simulation diverges (unstable model); not shown."
                        )),
                    },
                    Err(e) => notes.push(format!("{label}: could not be fitted ({e}); not shown.")),
                }
            }
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
        vec![
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
        ]
    }

    /// The report's sections for this recording; element ids start with `prefix`.
    pub fn sections(&self, prefix: &str) -> Result<Vec<Section>> {
        Ok(vec![
            self.overview_section(prefix)?,
            self.response_section(prefix)?,
            self.error_section(prefix)?,
            self.coefficient_section(prefix)?,
            self.residual_section(prefix)?,
            self.bode_section(prefix)?,
            self.summary_section(prefix),
        ])
    }

    // ------------------------------------------------------------ helpers

    fn time_axis(&self) -> (f64, &'static str) {
        if self.recording.duration() <= 10.0 {
            (1e3, "time [ms]")
        } else {
            (1.0, "time [s]")
        }
    }

    fn position_unit(&self) -> (f64, &'static str) {
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
    fn whole(&self, label: &str, f: &dyn Fn(usize) -> Option<f64>, scale: f64) -> Series {
        let t = self.recording.time();
        let (tf, _) = self.time_axis();
        let x: Vec<f64> = t.iter().map(|&v| tf * (v - t[0])).collect();
        let y: Vec<f64> = (0..t.len())
            .map(|k| f(k).map_or(f64::NAN, |v| scale * v))
            .collect();
        let (x, y) = decimate_minmax(&x, &y, self.options.max_points);
        Series::new(label, x, y)
    }

    fn zoom_indices(&self) -> Vec<usize> {
        let t = self.recording.time();
        (0..t.len())
            .filter(|&k| {
                t[k] >= self.motion_start && t[k] <= self.motion_start + self.options.zoom_s
            })
            .collect()
    }

    /// Series over the zoom window, time in ms since the motion start.
    fn zoomed(&self, label: &str, f: &dyn Fn(usize) -> Option<f64>, scale: f64) -> Series {
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

    fn zoom_ms(&self) -> f64 {
        1e3 * self.options.zoom_s
    }

    fn figure(id: String, title: &str, chart: &LineChart, caption: &str) -> Result<Figure> {
        Ok(Figure::new(&id, title, &chart.to_svg()?, caption))
    }

    // ------------------------------------------------------------ sections

    fn overview_section(&self, p: &str) -> Result<Section> {
        let (sc, unit) = self.position_unit();
        let (_, tl) = self.time_axis();
        let r = &self.recording;
        let mut c = LineChart::new(
            "Command and measured position",
            tl,
            &format!("position [{unit}]"),
        )
        .with_legend(LegendPosition::Below);
        c.push(
            self.whole("measured position", &|k| Some(r.position()[k]), sc)
                .with_color(MEASUREMENT),
        );
        c.push(
            self.whole("command (set-point)", &|k| Some(r.command()[k]), sc)
                .dashed()
                .with_color(COMMAND),
        );
        let mut e = LineChart::new(
            "Tracking error: command − measured position",
            tl,
            "tracking error [µm]",
        )
        .with_legend(LegendPosition::Hidden);
        e.push(
            self.whole(
                "command − position",
                &|k| Some(r.command()[k] - r.position()[k]),
                1e6,
            )
            .with_color(1),
        );
        Ok(Section::new(&format!("{p}-overview-sec"), "Recording overview")
            .with(Block::Paragraph(format!(
                "The whole recording as read: the command the controller received and the position the encoder measured. \
                 The motion starts {:.1} ms after the first sample; the zoomed figures below start there.",
                1e3 * (self.motion_start - r.time()[0])
            )))
            .with(Block::Figure(Self::figure(
                format!("{p}-overview"),
                "Command and measured position",
                &c,
                "The dashed line is the command, the solid line the measurement. Check that the move looks as intended \
                 and that the two lie on top of each other at this scale.",
            )?))
            .with(Block::Figure(Self::figure(
                format!("{p}-tracking"),
                "Tracking error",
                &e,
                "Command minus measured position in µm. A constant offset during a constant-speed move is the \
                 following error of the position loop (speed/Kv); peaks mark accelerations.",
            )?)))
    }

    fn response_section(&self, p: &str) -> Result<Section> {
        let (sc, unit) = self.position_unit();
        let (_, tl) = self.time_axis();
        let r = &self.recording;
        let y0 = {
            let k = r
                .time()
                .iter()
                .position(|&t| t >= self.motion_start)
                .unwrap_or(0);
            r.position()[k]
        };
        let mut full = LineChart::new(
            "Measured position, simulation model and predictions",
            tl,
            &format!("position [{unit}]"),
        )
        .with_legend(LegendPosition::Below);
        let mut zoom = LineChart::new(
            &format!("First {:.0} ms after the motion start", self.zoom_ms()),
            "time since motion start [ms]",
            "position from rest [µm]",
        )
        .with_legend(LegendPosition::Below);
        zoom.x_range = Some((0.0, self.zoom_ms()));
        let sim = &self.simulated;
        zoom.push(
            self.zoomed("command", &|k| Some(r.command()[k] - y0), 1e6)
                .with_color(COMMAND)
                .dashed(),
        );
        for (i, m) in self.runs.iter().enumerate() {
            let s = &m.identification.sliding;
            full.push(
                self.whole(&m.label, &|k| s.prediction(k), sc)
                    .with_color(method_color(i)),
            );
            zoom.push(
                self.zoomed(&m.label, &|k| s.prediction(k).map(|v| v - y0), 1e6)
                    .with_color(method_color(i)),
            );
        }
        // measurement and simulation model on top, as the references
        full.push(
            self.whole("simulation model (nominal)", &|k| Some(sim[k]), sc)
                .with_color(SIMULATION)
                .dashed(),
        );
        full.push(
            self.whole("measurement", &|k| Some(r.position()[k]), sc)
                .with_color(MEASUREMENT),
        );
        zoom.push(
            self.zoomed("simulation model (nominal)", &|k| Some(sim[k] - y0), 1e6)
                .with_color(SIMULATION)
                .dashed(),
        );
        zoom.push(
            self.zoomed("measurement", &|k| Some(r.position()[k] - y0), 1e6)
                .with_color(MEASUREMENT),
        );
        // Keep the zoom readable when a method blows up: the y range covers
        // the measurement and the command with a margin; lines leaving it are cut.
        let idx = self.zoom_indices();
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for &k in &idx {
            for v in [r.position()[k] - y0, r.command()[k] - y0] {
                lo = lo.min(1e6 * v);
                hi = hi.max(1e6 * v);
            }
        }
        if lo.is_finite() && hi > lo {
            let m = 0.15 * (hi - lo);
            zoom.y_range = Some((lo - m, hi + m));
        }
        let h = self
            .runs
            .first()
            .map_or(10, |m| m.identification.config.horizon);
        Ok(Section::new(&format!("{p}-response-sec"), "Measured vs simulation model vs predictions")
            .with(Block::Paragraph(format!(
                "Each method fits a model to the last W samples and predicts the next H = {h} samples ({:.1} ms) \
                 from it and the known command; the window then moves on by H. The simulation model is the nominal \
                 physical model of the rig parameters driven by the measured command from the start (no data used).",
                1e3 * h as f64 * r.dt()
            )))
            .with(Block::Figure(Self::figure(
                format!("{p}-response"),
                "Whole recording",
                &full,
                "The black measurement is drawn on top; at this scale all curves should lie under it, and a \
                 coloured curve that leaves it shows where a method blows up. Gaps are samples without a prediction (before the first window, or a failed window).",
            )?))
            .with(Block::Figure(Self::figure(
                format!("{p}-response-zoom"),
                &format!("Zoom on the first {:.0} ms of the motion (as the paper's figures 5 and 7)", self.zoom_ms()),
                &zoom,
                "Positions relative to the rest position at the motion start. This is where identification is \
                 hardest: the window still contains the standstill. Lines leaving the plot are cut at its edge; \
                 the error figures below show by how much.",
            )?)))
    }

    fn error_section(&self, p: &str) -> Result<Section> {
        let r = &self.recording;
        let t = r.time();
        let y = r.position();
        let (tf, tl) = self.time_axis();
        let mut per = LineChart::new(
            "Prediction error per horizon (rms over each predicted stretch)",
            tl,
            "rms error [µm] (log scale)",
        )
        .with_legend(LegendPosition::Below);
        per.log_y = true;
        // simulation model over blocks as long as the first method's horizon
        let h = self
            .runs
            .first()
            .map_or(10, |m| m.identification.config.horizon)
            .max(1);
        let (mut xs, mut ys) = (Vec::new(), Vec::new());
        for start in (0..y.len()).step_by(h) {
            let end = (start + h).min(y.len());
            let s = ErrorStats::from_pairs((start..end).map(|k| (y[k], self.simulated[k])));
            xs.push(tf * (t[end - 1] - t[0]));
            ys.push(1e6 * s.rms);
        }
        let (xs, ys) = decimate_minmax(&xs, &ys, self.options.max_points);
        per.push(
            Series::new("simulation model (nominal)", xs, ys)
                .with_color(SIMULATION)
                .dashed(),
        );
        let mut zoom = LineChart::new(
            &format!(
                "Error in the first {:.0} ms (as the paper's figures 6 and 8)",
                self.zoom_ms()
            ),
            "time since motion start [ms]",
            "measurement − model [µm]",
        )
        .with_legend(LegendPosition::Below);
        zoom.x_range = Some((0.0, self.zoom_ms()));
        for (i, m) in self.runs.iter().enumerate() {
            let s = &m.identification.sliding;
            let color = method_color(i);
            let (mut xs, mut ys) = (Vec::new(), Vec::new());
            for w in &s.windows {
                let pairs = w
                    .horizon
                    .clone()
                    .filter_map(|k| s.prediction(k).map(|v| (y[k], v)));
                let st = ErrorStats::from_pairs(pairs);
                if st.samples > 0 && w.horizon.end > 0 {
                    xs.push(tf * (t[w.horizon.end - 1] - t[0]));
                    ys.push(1e6 * st.rms);
                } else if let Some(k) = w.horizon.end.checked_sub(1) {
                    xs.push(tf * (t[k] - t[0]));
                    ys.push(f64::NAN);
                }
            }
            let (xs, ys) = decimate_minmax(&xs, &ys, self.options.max_points);
            per.push(Series::new(&m.label, xs, ys).with_color(color));
            zoom.push(
                self.zoomed(&m.label, &|k| s.prediction(k).map(|v| y[k] - v), 1e6)
                    .with_color(color),
            );
        }
        zoom.push(
            self.zoomed(
                "simulation model (nominal)",
                &|k| Some(y[k] - self.simulated[k]),
                1e6,
            )
            .with_color(SIMULATION)
            .dashed(),
        );
        // the same, with the y axis at the simulation model's error scale
        let mut detail = zoom.clone();
        detail.title = format!(
            "Error in the first {:.0} ms, detail at the simulation model's scale",
            self.zoom_ms()
        );
        let lim = 1.3 * (1e6 * self.simulation_zoom.max_abs).max(1.0);
        detail.y_range = Some((-lim, lim));
        Ok(Section::new(&format!("{p}-error-sec"), "Prediction error per method")
            .with(Block::Figure(Self::figure(
                format!("{p}-error"),
                "Prediction error over the recording",
                &per,
                "One point per prediction horizon: the rms of measurement − prediction over the H predicted samples \
                 (log scale, so µm and mm errors are both visible). Lower is better; the dashed line is the nominal \
                 simulation model over blocks of the same length. Spikes show where a method fails.",
            )?))
            .with(Block::Figure(Self::figure(
                format!("{p}-error-zoom"),
                &format!("Error in the first {:.0} ms of the motion", self.zoom_ms()),
                &zoom,
                "Measurement − model, sample by sample, in µm, at full scale: the largest errors of any method.",
            )?))
            .with(Block::Figure(Self::figure(
                format!("{p}-error-zoom-detail"),
                &format!("Error in the first {:.0} ms, detail", self.zoom_ms()),
                &detail,
                &format!(
                    "The same errors with the y axis limited to ±{lim:.1} µm (1.3 × the simulation model's largest \
                     error here), so the accurate methods can be compared with the simulation model; larger errors \
                     are cut at the edge. The paper reports its identified model tracking the measurement better \
                     than the simulation model."
                ),
            )?)))
    }

    /// One chart of the coefficients `idx` of run `m`; returns it and whether its y axis is log.
    fn coefficient_chart(
        &self,
        m: &MethodRun,
        idx: &[usize],
        title: &str,
        size: (u32, u32),
    ) -> (LineChart, bool) {
        let t = self.recording.time();
        let (tf, tl) = self.time_axis();
        let s = &m.identification.sliding;
        let mut c = LineChart::new(title, tl, "coef. / median |coef.|")
            .with_legend(LegendPosition::Below)
            .with_size(size.0, size.1);
        c.pin_to_edges = true;
        let x: Vec<f64> = s
            .windows
            .iter()
            .map(|w| tf * (t[w.window.end.saturating_sub(1)] - t[0]))
            .collect();
        let mut all = Vec::new();
        for (k, &j) in idx.iter().enumerate() {
            let vals: Vec<f64> = (0..s.windows.len())
                .map(|w| {
                    if s.windows[w].outcome == WindowOutcome::Failed {
                        f64::NAN
                    } else {
                        s.window_coefficients(w)[j]
                    }
                })
                .collect();
            let mut mags: Vec<f64> = vals
                .iter()
                .filter(|v| v.is_finite())
                .map(|v| v.abs())
                .collect();
            mags.sort_by(f64::total_cmp);
            let med = mags.get(mags.len() / 2).copied().unwrap_or(0.0);
            let y: Vec<f64> = vals
                .iter()
                .map(|&v| if med > 0.0 { v / med } else { f64::NAN })
                .collect();
            all.extend(y.iter().copied().filter(|v| v.is_finite()));
            let (xd, yd) = decimate_minmax(&x, &y, self.options.max_points / 5);
            c.push(Series::new(&s.coefficient_names[j], xd, yd).with_color(k % 8));
        }
        all.sort_by(f64::total_cmp);
        let mut log = false;
        if !all.is_empty() {
            let q = |f: f64| all[((all.len() - 1) as f64 * f).round() as usize];
            let (a, b) = (q(0.02), q(0.98));
            // keep ±1 in view (only +1 when every value is positive, −1 when negative)
            let lo = a.min(if a >= 0.0 { 0.8 } else { -1.2 });
            let hi = b.max(if b <= 0.0 { -0.8 } else { 1.2 });
            if hi - lo > 40.0 {
                // coefficients spanning decades: magnitudes on a log axis
                log = true;
                c.log_y = true;
                c.y_label = "|coef.| / median |coef.| (log scale)".into();
                c.y_range = Some((1e-3, 1e3));
                for series in &mut c.series {
                    for v in &mut series.y {
                        *v = v.abs();
                    }
                }
            } else {
                let pad = 0.08 * (hi - lo);
                c.y_range = Some((lo - pad, hi + pad));
            }
        }
        (c, log)
    }

    fn coefficient_section(&self, p: &str) -> Result<Section> {
        let mut sec = Section::new(
            &format!("{p}-coef-sec"),
            "Identified coefficients over time",
        );
        sec.blocks.push(Block::Paragraph(
            "One point per window, at the window's last sample, each coefficient divided by the median of its \
             magnitude over all windows so that all share one scale: a steady coefficient is a flat line at +1 or \
             −1 (at 1 on a log axis, used when the values span decades; the sign is then not shown). A method that \
             identifies a consistent model gives flat lines while the motion is informative. Lines leaving the plot \
             (beyond the 2nd/98th percentile, or 1/1000 and 1000 of the median on a log axis) run along its edge. \
             Names as in the coefficients file of feedid identify: the paper method's N2…N0, D7…D0 (eq. 6), ARX/RLS \
             a1…a_na, b_nk…, OE N…, D…."
                .into(),
        ));
        for m in &self.runs {
            let names = &m.identification.sliding.coefficient_names;
            // groups by the name's first letter (N/D, a/b), merged while they fit 8 colours
            let mut groups: Vec<Vec<usize>> = Vec::new();
            let mut prev: Option<char> = None;
            for (j, name) in names.iter().enumerate() {
                let first = name.chars().next();
                match groups.last_mut() {
                    Some(g) if first == prev && g.len() < 8 => g.push(j),
                    _ => groups.push(vec![j]),
                }
                prev = first;
            }
            let mut merged: Vec<Vec<usize>> = Vec::new();
            for g in groups {
                match merged.last_mut() {
                    Some(last) if last.len() + g.len() <= 8 => last.extend(g),
                    _ => merged.push(g),
                }
            }
            let mut figs = Vec::new();
            for (gi, idx) in merged.iter().enumerate() {
                let (Some(&first), Some(&last)) = (idx.first(), idx.last()) else {
                    continue;
                };
                let span = if first == last {
                    names[first].clone()
                } else {
                    format!("{} … {}", names[first], names[last])
                };
                let title = format!("{}: coefficients {span}", m.label);
                let size = if merged.len() > 1 {
                    (620, 400)
                } else {
                    (900, 360)
                };
                let (chart, log) = self.coefficient_chart(m, idx, &title, size);
                let id = if gi == 0 {
                    format!("{p}-coef-{}", m.slug)
                } else {
                    format!("{p}-coef-{}-{}", m.slug, gi + 1)
                };
                figs.push(Self::figure(
                    id,
                    &format!("{} coefficients {span} over time", m.label),
                    &chart,
                    if log {
                        "Magnitudes relative to their medians on a log axis (the values span decades)."
                    } else {
                        "Values relative to their median magnitudes."
                    },
                )?);
            }
            match figs.len() {
                0 => {}
                1 => sec.blocks.extend(figs.into_iter().map(Block::Figure)),
                _ => sec.blocks.push(Block::Grid(figs)),
            }
        }
        Ok(sec)
    }

    fn residual_section(&self, p: &str) -> Result<Section> {
        let dt_ms = 1e3 * self.recording.dt();
        let mut sec = Section::new(&format!("{p}-resid-sec"), "Residual analysis");
        sec.blocks.push(Block::Paragraph(
            "Correlations of the prediction errors (residuals) e = measurement − prediction over all predicted samples. \
             Left: autocorrelation r_ee(τ); for a model that captured all predictable dynamics the residual is white and \
             every bar for τ > 0 stays inside the grey 99 % band ±2.58/√N. Right: cross-correlation r_ue(τ) of the \
             command and the residual; bars outside the band at τ > 0 mean part of the command's effect was missed."
                .into(),
        ));
        for m in &self.runs {
            let Some(ra) = &m.residuals else {
                sec.blocks.push(Block::Paragraph(format!(
                    "{}: too few predicted samples for a residual analysis.",
                    m.label
                )));
                continue;
            };
            let band = Band {
                y0: -ra.bound,
                y1: ra.bound,
                label: "99 % confidence band".into(),
            };
            let stems = |lags: &mut dyn Iterator<Item = (isize, f64)>| {
                let (mut x, mut y) = (Vec::new(), Vec::new());
                for (tau, v) in lags {
                    let xv = tau as f64 * dt_ms;
                    x.extend([xv, xv, f64::NAN]);
                    y.extend([0.0, v, f64::NAN]);
                }
                (x, y)
            };
            let mut ee = LineChart::new(
                &format!("{}: r_ee", m.label),
                "lag τ [ms]",
                "autocorrelation [–]",
            )
            .with_legend(LegendPosition::Below)
            .with_size(560, 320);
            let (x, y) = stems(&mut ra.r_ee.iter().enumerate().map(|(k, &v)| (k as isize, v)));
            ee.push(Series::new("r_ee(τ)", x, y).with_color(1));
            ee.bands.push(band.clone());
            ee.y_range = Some((-1.05, 1.05));
            let mut ue = LineChart::new(
                &format!("{}: r_ue", m.label),
                "lag τ [ms]",
                "cross-correlation [–]",
            )
            .with_legend(LegendPosition::Below)
            .with_size(560, 320);
            let ml = ra.max_lag as isize;
            let (x, y) = stems(
                &mut ra
                    .r_ue
                    .iter()
                    .enumerate()
                    .map(|(k, &v)| (k as isize - ml, v)),
            );
            ue.push(Series::new("r_ue(τ)", x, y).with_color(2));
            ue.bands.push(band);
            let peak = ra.r_ue.iter().fold(ra.bound, |a, v| a.max(v.abs()));
            ue.y_range = Some((-1.1 * peak, 1.1 * peak));
            let verdict = |inside: bool| {
                if inside {
                    "inside the band"
                } else {
                    "outside the band"
                }
            };
            sec.blocks.push(Block::Grid(vec![
                Self::figure(
                    format!("{p}-ree-{}", m.slug),
                    &format!("{}: residual autocorrelation", m.label),
                    &ee,
                    &format!(
                        "{} of {} lags outside the 99 % band (N = {}): {}.",
                        ra.ee_outside,
                        ra.max_lag,
                        ra.samples,
                        if ra.ee_inside {
                            "white enough"
                        } else {
                            "correlated — predictable structure is left in the error"
                        }
                    ),
                )?,
                Self::figure(
                    format!("{p}-rue-{}", m.slug),
                    &format!("{}: command–residual cross-correlation", m.label),
                    &ue,
                    &format!(
                        "{} of {} lags {} (τ > 0: residual after the command).",
                        ra.ue_outside,
                        2 * ra.max_lag + 1,
                        verdict(ra.ue_inside)
                    ),
                )?,
            ]));
        }
        Ok(sec)
    }

    fn bode_section(&self, p: &str) -> Result<Section> {
        let r = &self.recording;
        let nyq = 0.5 * r.rate_hz();
        let f_lo = (1.0 / r.duration().max(1e-9)).max(0.1).min(nyq / 100.0);
        let f_hi = 0.98 * nyq;
        let n = 400;
        let freqs: Vec<f64> = (0..n)
            .map(|i| f_lo * (f_hi / f_lo).powf(i as f64 / (n - 1) as f64))
            .collect();
        let mut mag = LineChart::new(
            "Bode magnitude",
            "frequency [Hz] (log scale)",
            "magnitude [dB]",
        )
        .with_legend(LegendPosition::Below);
        mag.log_x = true;
        let mut ph = LineChart::new("Bode phase", "frequency [Hz] (log scale)", "phase [deg]")
            .with_legend(LegendPosition::Below);
        ph.log_x = true;
        let mut curves = vec![(
            "nominal physical model (7 poles, 2 zeros)".to_string(),
            response_tf(&self.nominal, &freqs),
            0usize,
        )];
        for (i, g) in self.global.iter().enumerate() {
            curves.push((
                format!(
                    "{} (free-run rms {:.2} µm)",
                    g.label,
                    1e6 * g.simulation.rms
                ),
                response_model(&g.model, &freqs)?,
                i + 1,
            ));
        }
        for (label, resp, color) in &curves {
            let db: Vec<f64> = resp.iter().map(|c| 20.0 * c.norm().log10()).collect();
            let phase = unwrap_phase(resp);
            let mut s = Series::new(label, freqs.clone(), db).with_color(*color);
            let mut q = Series::new(label, freqs.clone(), phase).with_color(*color);
            if *color == 0 {
                s = s.dashed();
                q = q.dashed();
            }
            mag.push(s);
            ph.push(q);
        }
        // magnitudes far below the pass band carry no information: floor at −80 dB below the peak
        let top = curves
            .iter()
            .flat_map(|(_, r, _)| r.iter().map(|c| 20.0 * c.norm().log10()))
            .filter(|v| v.is_finite())
            .fold(f64::NEG_INFINITY, f64::max);
        if top.is_finite() {
            mag.y_range = Some((top - 80.0, top + 10.0));
        }
        let mut sec = Section::new(&format!("{p}-bode-sec"), "Frequency response: identified global models vs nominal model")
            .with(Block::Paragraph(format!(
                "Models fitted over the whole recording (not per window), next to the nominal physical model from {}. \
                 The rms error of each global model's free-run simulation is in the legend. An identified model is only \
                 trustworthy at frequencies the command excited: a ramp or step mostly determines the low-frequency \
                 gain and lag; chirps, PRBS or multisines reveal the resonances.",
                self.options.params_source
            )))
            .with(Block::Figure(Self::figure(
                format!("{p}-bode-mag"),
                "Bode magnitude",
                &mag,
                "0 dB at low frequencies means the table follows the command; the bandwidth is where the magnitude \
                 drops 3 dB; peaks are resonances. Compare the identified curves with the dashed nominal model.",
            )?))
            .with(Block::Figure(Self::figure(
                format!("{p}-bode-phase"),
                "Bode phase",
                &ph,
                "Phase lag of the table behind the command; at low frequency the slope corresponds to the following \
                 error (delay 1/Kv).",
            )?));
        for n in &self.notes {
            sec.blocks.push(Block::Paragraph(n.clone()));
        }
        Ok(sec)
    }

    fn summary_section(&self, p: &str) -> Section {
        let um = |v: f64| {
            if v.is_finite() {
                format!("{:.3}", 1e6 * v)
            } else {
                "–".into()
            }
        };
        let pct = |v: f64| {
            if v.is_finite() && v > -1e6 {
                format!("{v:.2}")
            } else {
                "–".into()
            }
        };
        let z = self.zoom_ms();
        let mut rows = Vec::new();
        for m in &self.runs {
            let s = m.identification.summary();
            rows.push(vec![
                m.label.clone(),
                format!("{}", s.window),
                format!("{}", s.horizon),
                format!("{}", s.windows),
                format!("{}", s.failed_windows),
                format!("{}", s.samples_predicted),
                um(s.rms_error_m),
                um(s.max_abs_error_m),
                pct(s.fit_percent),
                if m.zoom_stats.samples > 0 {
                    um(m.zoom_stats.rms)
                } else {
                    "–".into()
                },
                format!("{:.2}", s.per_window_us),
            ]);
        }
        rows.push(vec![
            "simulation model (nominal)".into(),
            "–".into(),
            "–".into(),
            "–".into(),
            "–".into(),
            format!("{}", self.simulation_stats.samples),
            um(self.simulation_stats.rms),
            um(self.simulation_stats.max_abs),
            pct(self.simulation_stats.fit_percent),
            um(self.simulation_zoom.rms),
            "–".into(),
        ]);
        let table = Table {
            id: format!("{p}-summary"),
            caption:
                "k-step-ahead prediction errors (measurement − prediction) over every predicted sample; the \
                 simulation model over all samples. Fit = NRMSE fit (100 % is perfect). Time = identification and \
                 prediction per window, methods run in parallel."
                .into(),
            header: vec![
                "method".into(),
                "W".into(),
                "H".into(),
                "windows".into(),
                "failed".into(),
                "samples".into(),
                "rms [µm]".into(),
                "max [µm]".into(),
                "fit [%]".into(),
                format!("rms first {z:.0} ms [µm]"),
                "time per window [µs]".into(),
            ],
            rows,
        };
        let mut sec =
            Section::new(&format!("{p}-summary-sec"), "Summary").with(Block::Table(table));
        if !self.global.is_empty() {
            sec.blocks.push(Block::Table(Table {
                id: format!("{p}-global"),
                caption: "Global models: free-run simulation from the first sample (no measured positions used), \
                          against the measurement."
                    .into(),
                header: vec!["model".into(), "rms [µm]".into(), "max [µm]".into(), "fit [%]".into()],
                rows: self
                    .global
                    .iter()
                    .map(|g| {
                        vec![
                            g.label.clone(),
                            um(g.simulation.rms),
                            um(g.simulation.max_abs),
                            pct(g.simulation.fit_percent),
                        ]
                    })
                    .collect(),
            }));
        }
        sec
    }
}

fn global_arx(u: &[f64], y: &[f64], dt: f64, orders: ArxOrders) -> Result<LinearModel> {
    Ok(fit_arx(u, y, dt, orders, &ArxConfig::default())?.model)
}

fn global_oe(u: &[f64], y: &[f64], dt: f64, cfg: &OeConfig) -> Result<LinearModel> {
    Ok(fit_oe(u, y, dt, cfg)?.model)
}

/// Complex frequency response of a continuous transfer function.
fn response_tf(tf: &TransferFunction, freqs: &[f64]) -> Vec<Complex<f64>> {
    freqs
        .iter()
        .map(|&f| tf.eval(Complex::new(0.0, 2.0 * std::f64::consts::PI * f)))
        .collect()
}

/// Complex frequency response of an identified model (discrete at `z = e^{jωΔt}`).
fn response_model(m: &LinearModel, freqs: &[f64]) -> Result<Vec<Complex<f64>>> {
    Ok(match m {
        LinearModel::Continuous { num, den } => {
            response_tf(&TransferFunction::new(num.clone(), den.clone())?, freqs)
        }
        LinearModel::Discrete { b, a, dt } => freqs
            .iter()
            .map(|&f| {
                let w = 2.0 * std::f64::consts::PI * f * dt;
                let zinv = |k: usize| Complex::from_polar(1.0, -w * k as f64);
                let num: Complex<f64> = b.iter().enumerate().map(|(k, &c)| zinv(k) * c).sum();
                let den: Complex<f64> = a.iter().enumerate().map(|(k, &c)| zinv(k) * c).sum();
                num / den
            })
            .collect(),
    })
}

/// Phase in degrees, unwrapped along the list (jumps of more than 180° removed).
fn unwrap_phase(resp: &[Complex<f64>]) -> Vec<f64> {
    let mut out = Vec::with_capacity(resp.len());
    let mut prev: Option<f64> = None;
    for c in resp {
        let raw = c.im.atan2(c.re).to_degrees();
        let v = match prev {
            Some(q) if raw.is_finite() => raw + 360.0 * ((q - raw) / 360.0).round(),
            _ => raw,
        };
        if v.is_finite() {
            prev = Some(v);
        }
        out.push(v);
    }
    out
}

/// The stand-alone report of one recording.
pub fn recording_report(a: &RecordingAnalysis) -> Result<HtmlReport> {
    let mut page = HtmlReport::new(&format!("feedid report — {}", a.name));
    page.facts = a.facts();
    page.intro.push(
        "How to read this report: the recording is identified in short sliding windows by each method; every \
         window's model predicts the next H samples, which are compared with what was then measured. The \
         figures go from the raw data to the predictions, their errors, the identified coefficients, the \
         whiteness of the errors, and the frequency response; the summary table at the end has the numbers. \
         Units: time in ms (s for long recordings), positions in µm or mm as labelled on each axis."
            .into(),
    );
    page.sections = a.sections("rec")?;
    Ok(page)
}

#[cfg(test)]
mod tests {
    use super::*;
    use feedid::drive::VirtualRig;
    use feedid::signal::Scenario;

    fn ramp() -> Recording {
        let cmd = Scenario::Ramp.command(5000.0, 0.2, 1).unwrap();
        let out = VirtualRig::new(RigParams::default())
            .with_seed(1)
            .simulate(&cmd, 5000.0)
            .unwrap();
        Recording::new(out.time, out.command, out.position).unwrap()
    }

    fn opts() -> ReportOptions {
        ReportOptions::new(
            ["paper", "arx"]
                .iter()
                .map(|n| {
                    let spec = MethodSpec::new(n.parse().unwrap());
                    let cfg = EngineConfig {
                        window: spec.default_window(),
                        ..EngineConfig::default()
                    };
                    (spec, cfg)
                })
                .collect(),
        )
    }

    #[test]
    fn report_has_every_section_and_figure_and_no_external_reference() {
        let a = RecordingAnalysis::run("ramp <test>.csv", ramp(), &opts()).unwrap();
        assert_eq!(a.runs.len(), 2);
        let page = recording_report(&a).unwrap();
        let ids = page.figure_ids();
        let mut expected = vec![
            "rec-overview",
            "rec-tracking",
            "rec-response",
            "rec-response-zoom",
            "rec-error",
            "rec-error-zoom",
            "rec-error-zoom-detail",
            "rec-coef-paper1",
            "rec-coef-paper1-2",
            "rec-coef-arx2",
            "rec-coef-arx2-2",
        ]
        .into_iter()
        .map(String::from)
        .collect::<Vec<_>>();
        for m in ["paper1", "arx2"] {
            expected.push(format!("rec-ree-{m}"));
            expected.push(format!("rec-rue-{m}"));
        }
        expected.push("rec-bode-mag".into());
        expected.push("rec-bode-phase".into());
        let mut got = ids.clone();
        got.sort();
        expected.sort();
        assert_eq!(got, expected);
        let html = page.to_html();
        for id in &ids {
            assert!(html.contains(&format!("<figure id=\"{id}\">")), "{id}");
        }
        for sec in [
            "overview-sec",
            "response-sec",
            "error-sec",
            "coef-sec",
            "resid-sec",
            "bode-sec",
            "summary-sec",
        ] {
            assert!(
                html.contains(&format!("<section id=\"rec-{sec}\">")),
                "{sec}"
            );
        }
        assert_eq!(html.matches("<svg ").count(), ids.len());
        assert!(html.contains("ramp &lt;test&gt;.csv"));
        assert!(!html.contains("ramp <test>"));
        for bad in [
            "http://", "https://", "<script", "<link", "<img", "<iframe", "NaN", "inf\"",
        ] {
            assert!(!html.contains(bad), "{bad}");
        }
        assert!(html.contains("[µm]") && html.contains("[ms]"));
        // two global models on a clean ramp
        assert_eq!(a.global.len() + a.notes.len(), 2);
        // reasonable size: well under 4 MB
        assert!(html.len() < 4_000_000, "{}", html.len());
    }

    #[test]
    fn summary_table_numbers_match_the_runs() {
        let a = RecordingAnalysis::run("r", ramp(), &opts()).unwrap();
        let sec = a.summary_section("x");
        let Block::Table(t) = &sec.blocks[0] else {
            panic!("table expected")
        };
        assert_eq!(t.rows.len(), 3);
        let s = a.runs[1].identification.summary();
        assert_eq!(t.rows[1][6], format!("{:.3}", 1e6 * s.rms_error_m));
        assert_eq!(t.rows[2][0], "simulation model (nominal)");
    }

    #[test]
    fn discrete_frequency_response_matches_closed_form() {
        // y[k] = 0.5 y[k−1] + 0.5 u[k−1]: G(z) = 0.5 z⁻¹ / (1 − 0.5 z⁻¹)
        let m = LinearModel::discrete(vec![0.0, 0.5], vec![1.0, -0.5], 1e-3).unwrap();
        let f = [0.0, 125.0, 250.0];
        let r = response_model(&m, &f).unwrap();
        assert!((r[0].norm() - 1.0).abs() < 1e-12);
        for (i, &fi) in f.iter().enumerate() {
            let z = Complex::from_polar(1.0, 2.0 * std::f64::consts::PI * fi * 1e-3);
            let g = Complex::new(0.5, 0.0) / (z - Complex::new(0.5, 0.0));
            assert!((r[i] - g).norm() < 1e-12);
        }
    }

    #[test]
    fn phase_unwrapping_removes_jumps() {
        let resp: Vec<Complex<f64>> = (0..50)
            .map(|k| Complex::from_polar(1.0, -0.2 * k as f64))
            .collect();
        let p = unwrap_phase(&resp);
        for (k, v) in p.iter().enumerate() {
            assert!((v + (0.2 * k as f64).to_degrees()).abs() < 1e-9, "{k}: {v}");
        }
    }
}
