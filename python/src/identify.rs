//! `feedid._feedid.identify`: one library pipeline run
//! ([`feedid::pipeline::Pipeline`], as `feedid identify` makes it: the
//! nominal rig simulated beside the predictions, the method's global model
//! fitted for the summary) with the GIL released, reading NumPy arrays in
//! place (a borrowed, checked [`feedid::RecordingRef`]) and handing its
//! arrays to NumPy without copies.

use feedid::ident::{GuardConfig, OrderSearch, RESIDUAL_LAGS};
use feedid::pipeline::Pipeline;
use feedid::RecordingRef;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::IntoPy;
use crate::method::{MethodOptions, OrderOption};
use crate::recording::{slice, PyRecording};

/// Identify a `recording`, or `time` [s], `command` [m] and `position` [m]
/// given as contiguous float64 arrays (checked with `jitter_tol`, read in
/// place: not copied); returns the parts of an `Identification` as a dict
/// (`predicted`, `lower`, `upper` with NaN where nothing was predicted,
/// `coefficients` windows × names, `coefficient_names`, `window_start`,
/// `window_end`, `window_outcome`, `simulated`, `summary_json`,
/// `model_json`, `warnings`). The method options are keyword arguments
/// (`order`, `lambda_`, ...: [`feedid::ident::Method::options`]).
#[pyfunction]
#[pyo3(signature = (recording = None, *, time = None, command = None, position = None,
    jitter_tol = 0.01, method = "auto", window = None, horizon = 10, hop = None,
    interval = 95.0, runaway = Some(1.5), params_path = None, params_json = None, allow_unstable = false,
    nominal = true, global_model = true, residuals = true, **options))]
#[allow(clippy::too_many_arguments)]
pub fn identify<'py>(
    py: Python<'py>,
    recording: Option<&Bound<'py, PyRecording>>,
    time: Option<PyReadonlyArray1<'py, f64>>,
    command: Option<PyReadonlyArray1<'py, f64>>,
    position: Option<PyReadonlyArray1<'py, f64>>,
    jitter_tol: f64,
    method: &str,
    window: Option<usize>,
    horizon: usize,
    hop: Option<usize>,
    interval: f64,
    runaway: Option<f64>,
    params_path: Option<String>,
    params_json: Option<String>,
    allow_unstable: bool,
    nominal: bool,
    global_model: bool,
    residuals: bool,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let options = MethodOptions::from_kwargs(options)?;
    let method = options.method(method)?;
    let interval = crate::method::interval(interval)?;
    let runaway = crate::method::runaway(runaway)?;
    let select = matches!(options.order_option()?, Some(OrderOption::Select));
    let params = crate::params::load(
        params_path.as_deref(),
        params_json.as_deref(),
        allow_unstable,
    )?;
    let mut pipeline = Pipeline::new(method)
        .window_or_default(window)
        .horizon(horizon)
        .hop(hop)
        .guard(GuardConfig {
            interval,
            runaway,
            ..GuardConfig::default()
        })
        .method_global_model(global_model)
        .residuals(if residuals { Some(RESIDUAL_LAGS) } else { None });
    if nominal {
        pipeline = pipeline.nominal(params);
    }
    if select {
        pipeline = pipeline.select_orders(OrderSearch::default());
    }
    let run = match (recording, time, command, position) {
        (Some(rec), None, None, None) => {
            let rec = &rec.get().inner;
            py.detach(|| pipeline.run(rec))
        }
        (None, Some(t), Some(u), Some(y)) => {
            let (t, u, y) = (
                slice(&t, "time")?,
                slice(&u, "command")?,
                slice(&y, "position")?,
            );
            py.detach(|| {
                // dropped samples are gaps, as for `feedid identify`
                let rec = RecordingRef::borrowed_allowing_gaps(t, u, y, jitter_tol)?;
                pipeline.run(&rec)
            })
        }
        _ => {
            return Err(PyTypeError::new_err(
                "identify takes a recording or time, command and position arrays",
            ))
        }
    }
    .py_err()?;
    let mut summary = run.summary_in(feedid::error::Syntax::Python);
    if nominal {
        // whose parameters the simulation model has, as the command line says
        summary.nominal_rig = Some(match (&params_path, &params_json) {
            (Some(p), _) => p.clone(),
            (None, Some(_)) => "dict".to_string(),
            (None, None) => "built-in".to_string(),
        });
    }
    let summary_json = serde_json::to_string(&summary)
        .map_err(|e| crate::errors::input(format!("summary: {e}")))?;
    let s = run.sliding;
    let (mut predicted, mut lower, mut upper) = (s.predicted, s.lower, s.upper);
    for (k, &has) in s.has_prediction.iter().enumerate() {
        if !has {
            for v in [&mut predicted, &mut lower, &mut upper] {
                if let Some(x) = v.get_mut(k) {
                    *x = f64::NAN;
                }
            }
        }
    }
    let nc = s.coefficient_names.len();
    let nw = s.windows.len();
    let coefficients = PyArray1::from_vec(py, s.coefficients).reshape([nw, nc])?;
    let d = PyDict::new(py);
    d.set_item("predicted", PyArray1::from_vec(py, predicted))?;
    d.set_item("lower", PyArray1::from_vec(py, lower))?;
    d.set_item("upper", PyArray1::from_vec(py, upper))?;
    d.set_item("coefficients", coefficients)?;
    d.set_item("coefficient_names", s.coefficient_names)?;
    let starts: Vec<i64> = s.windows.iter().map(|w| w.window.start as i64).collect();
    let ends: Vec<i64> = s.windows.iter().map(|w| w.window.end as i64).collect();
    let outcomes: Vec<&str> = s.windows.iter().map(|w| w.outcome.label()).collect();
    d.set_item("window_start", PyArray1::from_vec(py, starts))?;
    d.set_item("window_end", PyArray1::from_vec(py, ends))?;
    d.set_item("window_outcome", outcomes)?;
    d.set_item(
        "simulated",
        run.simulated.map(|v| PyArray1::from_vec(py, v)),
    )?;
    d.set_item("summary_json", summary_json)?;
    d.set_item("model_json", run.global.map(|g| g.to_json()))?;
    d.set_item("warnings", summary.warnings)?;
    Ok(d)
}
