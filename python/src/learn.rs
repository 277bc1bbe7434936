//! Learning from measured runs (`feedid.learn`, `feedid compensate
//! --measured`): the next run's command from the last one.

use std::path::Path;

use feedid::compensate::{
    learn as learn_step, CompensateConfig, LearnConfig, LearningHistory, NoiseFilter, Smoothing,
    StartMode,
};
use feedid::ident::ModelFile;
use feedid::Recording;
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;

use crate::errors::{input, IntoPy};
use crate::recording::slice;

/// One learning step: returns `(command, predicted, summary_json, history_json)`.
#[pyfunction]
#[pyo3(signature = (time, desired, sent, measured, *, model_json = None, model_path = None,
    history_json = None, gain = 1.0, noise_filter = None, smooth = None, max_smoothing = 0.02,
    max_velocity = 1.0, max_acceleration = 30.0, keep_dc_gain = false, start = "rest"))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
pub fn learn<'py>(
    py: Python<'py>,
    time: PyReadonlyArray1<'py, f64>,
    desired: PyReadonlyArray1<'py, f64>,
    sent: PyReadonlyArray1<'py, f64>,
    measured: PyReadonlyArray1<'py, f64>,
    model_json: Option<String>,
    model_path: Option<String>,
    history_json: Option<String>,
    gain: f64,
    noise_filter: Option<f64>,
    smooth: Option<f64>,
    max_smoothing: f64,
    max_velocity: f64,
    max_acceleration: f64,
    keep_dc_gain: bool,
    start: &str,
) -> PyResult<(
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    String,
    String,
)> {
    let (t, x) = (slice(&time, "time")?, slice(&desired, "desired")?);
    // the desired trajectory is checked as a recording (time increasing, finite)
    let rec = Recording::new(t.to_vec(), x.to_vec(), x.to_vec()).py_err()?;
    let (u, y) = (slice(&sent, "sent")?, slice(&measured, "measured")?);
    let cfg = LearnConfig {
        gain,
        noise_filter: noise_filter.map_or(NoiseFilter::Auto, NoiseFilter::Fixed),
        compensate: CompensateConfig {
            smoothing: smooth.map_or(Smoothing::Auto, Smoothing::Fixed),
            max_velocity,
            max_acceleration,
            max_smoothing,
            unit_dc_gain: !keep_dc_gain,
            start: start.parse::<StartMode>().py_err()?,
            ..CompensateConfig::default()
        },
        ..LearnConfig::default()
    };
    cfg.validate().py_err()?;
    let file =
        match (model_json, model_path) {
            (Some(text), _) => ModelFile::from_json(&text).py_err()?,
            (None, Some(path)) => {
                let text = feedid::io::read_small_text(Path::new(&path)).py_err()?;
                ModelFile::from_json_file(&text, Path::new(&path)).py_err()?
            }
            (None, None) => return Err(input(
                "learning needs an identified model (a model dict, model.json or Identification)"
                    .to_string(),
            )),
        };
    let history: Option<LearningHistory> = match history_json {
        Some(text) => Some(
            serde_json::from_str(&text)
                .map_err(|e| input(format!("not a feedid learning history: {e}")))?,
        ),
        None => None,
    };
    let dt = rec.dt();
    let (u, y) = (u.to_vec(), y.to_vec());
    let step = py
        .detach(|| {
            learn_step(
                &file.model,
                rec.position(),
                &u,
                &y,
                dt,
                &cfg,
                history.as_ref(),
            )
        })
        .py_err()?;
    let summary = serde_json::to_string(&step).map_err(|e| input(format!("learn: {e}")))?;
    let history = serde_json::to_string(&step.history).map_err(|e| input(format!("learn: {e}")))?;
    Ok((
        PyArray1::from_vec(py, step.command),
        PyArray1::from_vec(py, step.predicted),
        summary,
        history,
    ))
}
