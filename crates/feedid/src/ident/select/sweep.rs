//! The paper's proposed study of the window size (and the model order): run
//! every combination of method × order × window × horizon over one
//! recording, in parallel over the cores (rayon), and tabulate the errors.
//!
//! Larger windows start predicting later and so skip the hardest part of a
//! move (the first milliseconds after the motion start). Each combination is
//! therefore also scored over the **common samples**: the samples from
//!
//! ```text
//! k₀ = max over the runnable combinations of (estimator warm-up + W)
//! ```
//!
//! on, which every combination could predict; `rms_common_m` over them is
//! what the best choice and the heat map use. A recording with dropped
//! samples ([`Recording::gaps`]) is run segment by segment (the engine
//! restarts at every gap), a combination runs if it fits the longest
//! segment, and the common samples are those from `k₀` on in each segment. Combinations that cannot run
//! (a window longer than the recording) are rows with an error message and
//! no numbers, never NaN.
//!
//! Orders (`na, nb, nk`) apply to the methods with an ARX regressor (`arx`,
//! `rls`, and `auto`'s long-memory candidate, see [`Method::set_orders`]);
//! other methods run once per window and horizon with their own settings. The per-window time is measured while other combinations run
//! on the other cores.
//!
//! Progress is reported through a callback `progress(done, total)` (called
//! from worker threads, after each combination), so the library needs no
//! terminal.
//!
//! ```
//! use feedid::ident::{sweep, Method, SweepConfig};
//! use feedid::Recording;
//! let t: Vec<f64> = (0..600).map(|k| k as f64 * 2e-4).collect();
//! let u: Vec<f64> = t.iter().map(|&t| if t > 0.01 { 0.05 * (t - 0.01) } else { 0.0 }).collect();
//! let rec = Recording::new(t, u.clone(), u).unwrap();
//! let cfg = SweepConfig {
//!     methods: vec!["paper".parse::<Method>().unwrap()],
//!     windows: vec![10, 20, 40],
//!     horizons: vec![10],
//!     orders: vec![],
//!     hop: None,
//! };
//! let res = sweep(&rec, &cfg, &|_done, _total| {}).unwrap();
//! assert_eq!(res.rows.len(), 3);
//! assert!(res.best().is_some());
//! ```

use std::fmt::Write as _;
use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::ident::engine::{run as run_engine, EngineConfig};
use crate::ident::method::Method;
use crate::ident::methods::ArxOrders;
use crate::recording::Recording;
use crate::stats::sig3;
use crate::stats::ErrorAccumulator;

/// The paper's window \[samples\] (4 ms at 5 kHz), highlighted in comparisons.
pub const PAPER_WINDOW: usize = 20;

/// What to sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepConfig {
    /// Methods with their settings.
    pub methods: Vec<Method>,
    /// Window lengths W \[samples\].
    pub windows: Vec<usize>,
    /// Horizons H \[samples\].
    pub horizons: Vec<usize>,
    /// ARX orders for the methods that take them (`arx`, `rls`, `auto`); empty = each method's own.
    pub orders: Vec<ArxOrders>,
    /// Hop \[samples\]; `None` = the horizon (the paper's setting).
    pub hop: Option<usize>,
}

/// One combination and its errors.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepRow {
    /// Method name.
    pub method: String,
    /// ARX orders (methods with an ARX regressor only).
    pub order: Option<ArxOrders>,
    /// Window W \[samples\].
    pub window: usize,
    /// Horizon H \[samples\].
    pub horizon: usize,
    /// Windows visited.
    pub windows: usize,
    /// Windows whose fit or prediction failed.
    pub failed_windows: usize,
    /// Samples with a prediction.
    pub samples_predicted: usize,
    /// RMS prediction error over its own predicted samples \[m\].
    pub rms_m: f64,
    /// Largest absolute prediction error \[m\].
    pub max_abs_m: f64,
    /// NRMSE fit over its own predicted samples \[%\].
    pub fit_percent: f64,
    /// RMS prediction error over the common samples \[m\] (see the module doc).
    pub rms_common_m: f64,
    /// Mean wall time per window \[µs\].
    pub per_window_us: f64,
    /// Why the combination could not run (then the numbers are 0 and meaningless).
    pub error: Option<String>,
}

impl SweepRow {
    /// Whether the combination ran and predicted something.
    pub fn ok(&self) -> bool {
        self.error.is_none() && self.samples_predicted > 0
    }

    /// Method and order, e.g. `arx 8,8,1` or `paper`.
    pub fn model_label(&self) -> String {
        match self.order {
            Some(o) => format!("{} {},{},{}", self.method, o.na, o.nb, o.nk),
            None => self.method.clone(),
        }
    }
}

/// All combinations.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepResult {
    /// One row per combination, in the order method, order, horizon, window.
    pub rows: Vec<SweepRow>,
    /// First sample of the common samples, `k₀` (of each segment between
    /// dropped samples: `k₀` samples after its start).
    pub common_start: usize,
    /// Gaps of dropped samples in the recording (0 for a regular one).
    pub gaps: usize,
    /// Samples in the recording.
    pub samples: usize,
    /// Sampling rate \[Hz\].
    pub rate_hz: f64,
}

/// One combination to run.
struct Combo {
    method: Method,
    order: Option<ArxOrders>,
    engine: EngineConfig,
}

/// Run every combination of `cfg` over `recording` in parallel; `progress(done, total)`
/// is called after each combination.
///
/// Errors: empty lists, a zero window or horizon, and method settings that
/// do not build (e.g. `nb = 0`); a combination that does not fit the
/// recording is a row with [`SweepRow::error`] instead.
pub fn sweep(
    recording: &Recording,
    cfg: &SweepConfig,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<SweepResult> {
    for (name, list) in [("windows", &cfg.windows), ("horizons", &cfg.horizons)] {
        if list.is_empty() {
            return Err(Error::InvalidParameter {
                name,
                value: 0.0,
                reason: "needs at least one value",
            });
        }
        if list.contains(&0) {
            return Err(Error::InvalidParameter {
                name,
                value: 0.0,
                reason: "must be at least 1 sample",
            });
        }
    }
    if cfg.methods.is_empty() {
        return Err(Error::InvalidParameter {
            name: "methods",
            value: 0.0,
            reason: "needs at least one method",
        });
    }
    let mut combos = Vec::new();
    for method in &cfg.methods {
        let orders: Vec<Option<ArxOrders>> = match method.orders() {
            Some(_) if !cfg.orders.is_empty() => cfg.orders.iter().copied().map(Some).collect(),
            own => vec![own],
        };
        for order in orders {
            let mut m = method.clone();
            if let Some(o) = order {
                m.set_orders(o)?;
            }
            m.validate()?; // settings errors are the caller's, not a row's
            for &horizon in &cfg.horizons {
                for &window in &cfg.windows {
                    combos.push(Combo {
                        method: m.clone(),
                        order,
                        engine: EngineConfig {
                            window,
                            horizon,
                            hop: cfg.hop,
                            warm_up: 0,
                        },
                    });
                }
            }
        }
    }
    // with dropped samples the engine restarts at every gap: a combination
    // runs if it fits the longest segment, and the common samples are those
    // from k₀ on in each segment
    let longest = recording.longest_segment().len();
    let segments = recording.segments();
    let signals = recording.signals();
    // k₀ over the runnable combinations
    let mut common_start = 0;
    for c in &combos {
        let warm = c.method.build()?.warm_up();
        if c.engine.validate(longest, warm).is_ok() {
            common_start = common_start.max(warm + c.engine.window);
        }
    }
    let common: Vec<std::ops::Range<usize>> = segments
        .iter()
        .map(|s| (s.start + common_start).min(s.end)..s.end)
        .filter(|r| !r.is_empty())
        .collect();
    let total = combos.len();
    let done = AtomicUsize::new(0);
    progress(0, total);
    let y = recording.position();
    let rows: Vec<SweepRow> = combos
        .par_iter()
        .map(|c| {
            let mut row = SweepRow {
                method: c.method.name().to_string(),
                order: c.order,
                window: c.engine.window,
                horizon: c.engine.horizon,
                windows: 0,
                failed_windows: 0,
                samples_predicted: 0,
                rms_m: 0.0,
                max_abs_m: 0.0,
                fit_percent: 0.0,
                rms_common_m: 0.0,
                per_window_us: 0.0,
                error: None,
            };
            let outcome = c
                .method
                .build()
                .and_then(|mut est| run_engine(est.as_mut(), &signals, &c.engine));
            match outcome {
                Ok(res) => {
                    let mut acc = ErrorAccumulator::default();
                    for k in common.iter().flat_map(|r| r.clone()) {
                        if let Some(p) = res.prediction(k) {
                            acc.push(y[k], p);
                        }
                    }
                    let common = acc.finish();
                    row.windows = res.windows.len();
                    row.failed_windows = res.failed_windows();
                    row.samples_predicted = res.stats.samples;
                    row.rms_m = res.stats.rms;
                    row.max_abs_m = res.stats.max_abs;
                    row.fit_percent = res.stats.fit_percent;
                    row.rms_common_m = common.rms;
                    row.per_window_us = res.per_window_us();
                    if res.stats.samples == 0 {
                        row.error = Some("no window gave a prediction".into());
                    }
                }
                Err(e) => row.error = Some(e.to_string()),
            }
            let d = done.fetch_add(1, Ordering::Relaxed) + 1;
            progress(d, total);
            row
        })
        .collect();
    Ok(SweepResult {
        rows,
        common_start,
        gaps: recording.gaps().len(),
        samples: recording.len(),
        rate_hz: recording.rate_hz(),
    })
}

/// A CSV cell: the value, or empty when not finite or the row failed.
fn cell(ok: bool, v: f64) -> String {
    if ok && v.is_finite() {
        format!("{v}")
    } else {
        String::new()
    }
}

/// A CSV field, quoted when needed.
fn quoted(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

impl SweepResult {
    /// The combination with the smallest common-sample rms.
    pub fn best(&self) -> Option<&SweepRow> {
        self.rows
            .iter()
            .filter(|r| r.ok())
            .min_by(|a, b| a.rms_common_m.total_cmp(&b.rms_common_m))
    }

    /// The best combination for one horizon.
    pub fn best_for_horizon(&self, horizon: usize) -> Option<&SweepRow> {
        self.rows
            .iter()
            .filter(|r| r.ok() && r.horizon == horizon)
            .min_by(|a, b| a.rms_common_m.total_cmp(&b.rms_common_m))
    }

    /// Distinct `(model label, horizon)` groups in row order.
    pub fn groups(&self) -> Vec<(String, usize)> {
        let mut g: Vec<(String, usize)> = Vec::new();
        for r in &self.rows {
            let key = (r.model_label(), r.horizon);
            if !g.contains(&key) {
                g.push(key);
            }
        }
        g
    }

    /// Distinct windows, ascending.
    pub fn window_list(&self) -> Vec<usize> {
        let mut w: Vec<usize> = self.rows.iter().map(|r| r.window).collect();
        w.sort_unstable();
        w.dedup();
        w
    }

    /// Distinct horizons, ascending.
    pub fn horizon_list(&self) -> Vec<usize> {
        let mut h: Vec<usize> = self.rows.iter().map(|r| r.horizon).collect();
        h.sort_unstable();
        h.dedup();
        h
    }

    /// The CSV table: `method,window,horizon,na,nb,nk,rms_m,max_abs_m,fit_percent,
    /// per_window_us,failed_windows,windows,samples_predicted,rms_common_m,error`.
    pub fn to_csv(&self) -> String {
        let mut s = String::from(
            "method,window,horizon,na,nb,nk,rms_m,max_abs_m,fit_percent,per_window_us,\
             failed_windows,windows,samples_predicted,rms_common_m,error\n",
        );
        for r in &self.rows {
            let ok = r.ok();
            let (na, nb, nk) = r
                .order
                .map_or((String::new(), String::new(), String::new()), |o| {
                    (o.na.to_string(), o.nb.to_string(), o.nk.to_string())
                });
            let _ = writeln!(
                s,
                "{},{},{},{na},{nb},{nk},{},{},{},{},{},{},{},{},{}",
                quoted(&r.method),
                r.window,
                r.horizon,
                cell(ok, r.rms_m),
                cell(ok, r.max_abs_m),
                cell(ok, r.fit_percent),
                cell(r.error.is_none(), r.per_window_us),
                r.failed_windows,
                r.windows,
                r.samples_predicted,
                cell(ok, r.rms_common_m),
                quoted(r.error.as_deref().unwrap_or(""))
            );
        }
        s
    }

    /// Human-readable conclusion: the best combination (per horizon) and, for
    /// every method/order, the paper's W = 20 against that method's best window.
    pub fn summary_text(&self) -> String {
        let mut s = String::new();
        let dt_ms = if self.rate_hz > 0.0 {
            1e3 / self.rate_hz
        } else {
            0.0
        };
        let um = |v: f64| format!("{} µm", sig3(1e6 * v));
        if self.gaps == 0 {
            let _ = writeln!(
                s,
                "errors are rms over the samples every combination predicts (from sample {}, {:.1} ms)",
                self.common_start,
                self.common_start as f64 * dt_ms
            );
        } else {
            let _ = writeln!(
                s,
                "errors are rms over the samples every combination predicts (from sample {}, {:.1} ms, \
                 of each of the {} segments between the {} gap(s) of dropped samples, where every \
                 combination starts again)",
                self.common_start,
                self.common_start as f64 * dt_ms,
                self.gaps + 1,
                self.gaps
            );
        }
        for hz in self.horizon_list() {
            if let Some(b) = self.best_for_horizon(hz) {
                let _ = writeln!(
                    s,
                    "best for H={hz}: {} with W={} ({:.1} ms): {} rms, max {}",
                    b.model_label(),
                    b.window,
                    b.window as f64 * dt_ms,
                    um(b.rms_common_m),
                    um(b.max_abs_m)
                );
            }
        }
        let failed = self.rows.iter().filter(|r| !r.ok()).count();
        for (model, hz) in self.groups() {
            let rows: Vec<&SweepRow> = self
                .rows
                .iter()
                .filter(|r| r.ok() && r.model_label() == model && r.horizon == hz)
                .collect();
            let Some(best) = rows
                .iter()
                .min_by(|a, b| a.rms_common_m.total_cmp(&b.rms_common_m))
            else {
                continue;
            };
            let at20 = rows.iter().find(|r| r.window == PAPER_WINDOW);
            let worst = rows
                .iter()
                .map(|r| r.rms_common_m)
                .fold(f64::NEG_INFINITY, f64::max);
            let same = |a: f64, b: f64| (a - b).abs() <= 1e-9 * a.abs().max(b.abs());
            let line = if rows.len() > 1 && same(worst, best.rms_common_m) {
                format!(
                    "{model}, H={hz}: {} for every window (the window does not change this method here)",
                    um(best.rms_common_m)
                )
            } else {
                match at20 {
                    Some(p) if same(p.rms_common_m, best.rms_common_m) => format!(
                        "{model}, H={hz}: the paper's W={PAPER_WINDOW} is the best window here ({})",
                        um(p.rms_common_m)
                    ),
                    Some(p) => format!(
                        "{model}, H={hz}: paper's W={PAPER_WINDOW} gives {}; best W={} gives {} ({:.1}× lower)",
                        um(p.rms_common_m),
                        best.window,
                        um(best.rms_common_m),
                        if best.rms_common_m > 0.0 {
                            p.rms_common_m / best.rms_common_m
                        } else {
                            f64::INFINITY
                        }
                    ),
                    None => format!(
                        "{model}, H={hz}: best W={} gives {} (W={PAPER_WINDOW} not in the sweep)",
                        best.window,
                        um(best.rms_common_m)
                    ),
                }
            };
            let _ = writeln!(s, "{line}");
        }
        if failed > 0 {
            let _ = writeln!(
                s,
                "{failed} of {} combinations could not run (see the error column)",
                self.rows.len()
            );
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{RigParams, VirtualRig};
    use crate::signal::Scenario;

    fn ramp() -> Recording {
        let cmd = Scenario::Ramp.command(5000.0, 0.12, 1).unwrap();
        let out = VirtualRig::new(RigParams::default())
            .with_seed(1)
            .simulate(&cmd, 5000.0)
            .unwrap();
        Recording::new(out.time, out.command, out.position).unwrap()
    }

    fn cfg() -> SweepConfig {
        SweepConfig {
            methods: vec!["paper".parse().unwrap(), "arx".parse().unwrap()],
            windows: vec![20, 40, 80],
            horizons: vec![5, 10],
            orders: vec![ArxOrders::new(2, 2, 1), ArxOrders::new(4, 4, 1)],
            hop: None,
        }
    }

    #[test]
    fn with_dropped_samples_every_combination_restarts_and_is_scored_in_each_segment() {
        let rec = ramp().dropping(&[250, 400, 401, 402]).unwrap();
        assert_eq!(rec.gaps().len(), 2);
        let cfg = SweepConfig {
            methods: vec!["paper".parse().unwrap()],
            windows: vec![20, 40],
            horizons: vec![10],
            orders: vec![],
            hop: None,
        };
        let res = sweep(&rec, &cfg, &|_, _| {}).unwrap();
        assert_eq!((res.gaps, res.samples), (2, rec.len()));
        assert!(res
            .summary_text()
            .contains("3 segments between the 2 gap(s)"));
        let k0 = res.common_start;
        assert_eq!(k0, 40);
        // each segment run as a recording of its own, scored from k₀ in it
        for row in &res.rows {
            let (mut sum, mut count) = (0.0, 0usize);
            for seg in rec.segments() {
                let part = rec.slice(seg).unwrap();
                let mut est = cfg.methods[0].build().unwrap();
                let engine = EngineConfig {
                    window: row.window,
                    horizon: 10,
                    hop: None,
                    warm_up: 0,
                };
                let r = run_engine(est.as_mut(), &part.signals(), &engine).unwrap();
                for k in k0..part.len() {
                    if let Some(p) = r.prediction(k) {
                        sum += (part.position()[k] - p).powi(2);
                        count += 1;
                    }
                }
            }
            assert!(count > 400, "{count}");
            let want = (sum / count as f64).sqrt();
            assert!(
                (row.rms_common_m / want - 1.0).abs() < 1e-12,
                "W={}: {} vs {want}",
                row.window,
                row.rms_common_m
            );
        }
    }

    #[test]
    fn every_combination_has_a_row_equal_to_a_single_run() {
        let rec = ramp();
        let calls = AtomicUsize::new(0);
        let res = sweep(&rec, &cfg(), &|d, t| {
            assert!(d <= t && t == 18);
            calls.fetch_add(1, Ordering::Relaxed);
        })
        .unwrap();
        // paper: 3 windows × 2 horizons; arx: 2 orders × 3 × 2
        assert_eq!(res.rows.len(), 18);
        assert_eq!(
            calls.load(Ordering::Relaxed),
            19,
            "once at 0, then once per combination"
        );
        // largest window 80 + the ARX 4,4,1 warm-up of 4 samples
        assert_eq!(res.common_start, 84);
        // a row equals the same run done alone
        let r = res
            .rows
            .iter()
            .find(|r| {
                r.method == "arx"
                    && r.order == Some(ArxOrders::new(4, 4, 1))
                    && r.window == 40
                    && r.horizon == 10
            })
            .unwrap();
        let mut method: Method = "arx".parse().unwrap();
        method.set_orders(ArxOrders::new(4, 4, 1)).unwrap();
        let mut est = method.build().unwrap();
        let run = run_engine(
            est.as_mut(),
            &rec.signals(),
            &EngineConfig {
                window: 40,
                horizon: 10,
                hop: None,
                warm_up: 0,
            },
        )
        .unwrap();
        assert_eq!(r.rms_m, run.stats.rms);
        assert_eq!(r.samples_predicted, run.stats.samples);
        let common = crate::stats::ErrorStats::from_pairs(
            (84..rec.len()).filter_map(|k| run.prediction(k).map(|p| (rec.position()[k], p))),
        );
        assert_eq!(r.rms_common_m, common.rms);
        let best = res.best().unwrap();
        assert!(res
            .rows
            .iter()
            .filter(|r| r.ok())
            .all(|r| r.rms_common_m >= best.rms_common_m));
    }

    #[test]
    fn csv_has_the_documented_columns_and_no_nan() {
        let mut c = cfg();
        c.windows.push(100_000); // longer than the recording: an error row
        let res = sweep(&ramp(), &c, &|_, _| {}).unwrap();
        let csv = res.to_csv();
        let mut lines = csv.lines();
        assert_eq!(
            lines.next().unwrap(),
            "method,window,horizon,na,nb,nk,rms_m,max_abs_m,fit_percent,per_window_us,failed_windows,windows,samples_predicted,rms_common_m,error"
        );
        assert_eq!(lines.clone().count(), res.rows.len());
        assert!(!csv.contains("NaN") && !csv.contains("inf"));
        let bad: Vec<&str> = lines.filter(|l| l.contains(",100000,")).collect();
        assert_eq!(bad.len(), 6);
        assert!(bad.iter().all(|l| l.contains("samples")), "{bad:?}");
        // the oversized window does not move the common start
        assert_eq!(res.common_start, 84);
        let text = res.summary_text();
        assert!(
            text.contains("paper, H=10: paper's W=20 gives")
                || text.contains("paper, H=10: the paper's W=20 is the best"),
            "{text}"
        );
        assert!(
            text.contains("6 of 24 combinations could not run"),
            "{text}"
        );
    }

    #[test]
    fn empty_or_zero_lists_and_bad_orders_are_errors() {
        let rec = ramp();
        let mut c = cfg();
        c.windows = vec![];
        assert!(sweep(&rec, &c, &|_, _| {}).is_err());
        let mut c = cfg();
        c.horizons = vec![10, 0];
        assert!(sweep(&rec, &c, &|_, _| {}).is_err());
        let mut c = cfg();
        c.orders = vec![ArxOrders::new(2, 0, 1)];
        assert!(sweep(&rec, &c, &|_, _| {}).is_err());
    }
}
