//! `feedid.Streamer`: the library's streaming engine
//! ([`feedid::ident::Streamer`]) fed one line at a time; each push returns
//! the predictions that became due.

use feedid::ident::stream::{CommandExtrapolation, StreamOptions, StreamStats};
use feedid::ident::{EngineConfig, Estimator, GuardConfig, Regime, Span, Streamer};
use std::sync::{Mutex, MutexGuard};

use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{input, IntoPy};
use crate::method::{MethodOptions, OrderOption};
use crate::recording::lines;

/// One predicted sample: time [s], predicted position [m], interval lower
/// and upper bounds [m] (NaN where the method gives none).
type Row = (f64, f64, f64, f64);

/// Streaming identification (see the Python class's docstring).
#[pyclass(module = "feedid", name = "Streamer")]
pub struct PyStreamer {
    // a Python object may be shared between threads: one push at a time
    inner: Mutex<Streamer<Box<dyn Estimator + Send>>>,
}

type Inner = Streamer<Box<dyn Estimator + Send>>;

/// Poll every due prediction into `out`.
fn drain(s: &mut Inner, out: &mut Vec<Row>) -> feedid::Result<()> {
    while let Some(p) = s.poll()? {
        if p.is_ok() {
            out.extend(
                p.time
                    .iter()
                    .zip(p.position)
                    .zip(p.lower.iter().zip(p.upper))
                    .map(|((&t, &y), (&lo, &hi))| (t, y, lo, hi)),
            );
        }
    }
    Ok(())
}

impl PyStreamer {
    /// The streamer, locked.
    fn lock(&self) -> PyResult<MutexGuard<'_, Inner>> {
        self.inner
            .lock()
            .map_err(|_| input("the streamer failed in another thread; make a new one"))
    }
}

/// The counters and scores of a stream as a dict.
fn stats_dict<'py>(py: Python<'py>, s: &StreamStats) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("lines", s.lines)?;
    d.set_item("samples", s.samples)?;
    d.set_item("commands", s.commands)?;
    d.set_item("unused_positions", s.unused_positions)?;
    d.set_item("windows", s.windows)?;
    d.set_item("failed_windows", s.failed_windows)?;
    d.set_item("withheld_windows", s.withheld_windows)?;
    d.set_item("predicted_ahead", s.predicted_ahead)?;
    d.set_item("predicted_late", s.predicted_late)?;
    d.set_item("gaps", s.gaps)?;
    d.set_item("irregular_intervals", s.irregular_intervals)?;
    d.set_item("samples_scored", s.scored.samples)?;
    let some = |v: f64| (s.scored.samples > 0).then_some(v);
    d.set_item("rms_error_m", some(s.scored.rms))?;
    d.set_item("max_abs_error_m", some(s.scored.max_abs))?;
    d.set_item("hold_rms_error_m", some(s.hold.rms))?;
    d.set_item("interval_coverage_percent", s.interval_coverage_percent())?;
    d.set_item("outliers", s.outliers)?;
    d.set_item("runaway_windows", s.runaway_windows)?;
    d.set_item("runaway_samples", s.runaway_samples)?;
    let regimes = PyDict::new(py);
    for r in Regime::ALL {
        let n = s.regime_samples[r.index()];
        if n > 0 {
            let c = PyDict::new(py);
            c.set_item("samples", n)?;
            c.set_item(
                "coverage_percent",
                100.0 * s.regime_inside[r.index()] as f64 / n as f64,
            )?;
            regimes.set_item(r.name(), c)?;
        }
    }
    d.set_item("interval_by_regime", regimes)?;
    Ok(d)
}

#[pymethods]
impl PyStreamer {
    #[new]
    #[pyo3(signature = (*, rate = None, method = "auto", window = None, horizon = 10, hop = None,
        command_lead = 0, extrapolate = None, jitter_tol = 0.01,
        interval = 95.0, runaway = Some(1.5), **options))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        rate: Option<f64>,
        method: &str,
        window: Option<usize>,
        horizon: usize,
        hop: Option<usize>,
        command_lead: usize,
        extrapolate: Option<String>,
        jitter_tol: f64,
        interval: f64,
        runaway: Option<f64>,
        options: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let options = MethodOptions::from_kwargs(options)?;
        if matches!(options.order_option()?, Some(OrderOption::Select)) {
            return Err(input(
                "order='auto' chooses the orders from a whole recording; a stream needs them given (na,nb,nk; `feedid order` chooses them)",
            ));
        }
        let method = options.method(method)?;
        let interval = crate::method::interval(interval)?;
        let runaway = crate::method::runaway(runaway)?;
        if let Some(r) = rate {
            if !(r.is_finite() && r > 0.0) {
                return Err(input(format!(
                    "invalid rate {r}: must be finite and > 0 Hz"
                )));
            }
        }
        let config = EngineConfig {
            window: method
                .window_for(window.map(Span::Samples), f64::NAN)
                .py_err()?,
            horizon,
            hop,
            warm_up: 0,
        };
        let extrapolation: CommandExtrapolation = match &extrapolate {
            Some(s) => s.parse().py_err()?,
            None => CommandExtrapolation::default(),
        };
        let opts = StreamOptions {
            command_lead,
            extrapolation,
            dt: rate.map(|r| 1.0 / r),
            jitter_tolerance: jitter_tol,
            guard: GuardConfig {
                interval,
                runaway,
                ..GuardConfig::default()
            },
            ..StreamOptions::default()
        };
        let inner = Streamer::with_options(method.build().py_err()?, config, opts).py_err()?;
        Ok(Self {
            inner: Mutex::new(inner),
        })
    }

    /// Push one line; returns the predictions that became due.
    fn push(&self, t: f64, u: f64, y: f64) -> PyResult<Vec<Row>> {
        let mut s = self.lock()?;
        s.push(t, u, y).py_err()?;
        let mut out = Vec::new();
        drain(&mut s, &mut out).py_err()?;
        Ok(out)
    }

    /// Push many lines at once (equal-length arrays); returns the predictions
    /// that became due, in order. Stops at the first refused line.
    fn push_many(
        &self,
        py: Python<'_>,
        t: PyReadonlyArray1<'_, f64>,
        u: PyReadonlyArray1<'_, f64>,
        y: PyReadonlyArray1<'_, f64>,
    ) -> PyResult<Vec<Row>> {
        let (t, u, y) = lines(&t, &u, &y)?;
        let mut s = self.lock()?;
        let s = &mut *s;
        py.detach(move || {
            let mut out = Vec::new();
            for k in 0..t.len() {
                s.push(t[k], u[k], y[k]).map_err(|e| (k, e))?;
                drain(s, &mut out).map_err(|e| (k, e))?;
            }
            Ok(out)
        })
        .map_err(|(k, e): (usize, feedid::Error)| input(format!("sample {k} of this push: {e}")))
    }

    /// End of the input: the predictions still due.
    fn finish(&self) -> PyResult<Vec<Row>> {
        let mut s = self.lock()?;
        s.finish();
        let mut out = Vec::new();
        drain(&mut s, &mut out).py_err()?;
        Ok(out)
    }

    /// Counters and scores so far.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        stats_dict(py, &self.lock()?.stats())
    }

    /// The sampling interval in use [s] (None before two samples).
    #[getter]
    fn dt(&self) -> PyResult<Option<f64>> {
        Ok(self.lock()?.dt())
    }
}
