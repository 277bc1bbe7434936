//! The virtual rig (`feedid.simulate`), the nominal model in numbers
//! (`feedid.model`) and the command compensation (`feedid.compensate`).

use std::path::Path;

use feedid::compensate::{
    compensate_model, compensate_params, CompensateConfig, ModelQuality, Smoothing, StartMode,
};
use feedid::drive::{D1Variant, ModelSummary, RigEffects, VirtualRig};
use feedid::greybox::LoopModel;
use feedid::ident::ModelFile;
use feedid::signal::Scenario;
use feedid::Recording;
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;

use crate::errors::{input, IntoPy};
use crate::recording::{slice, PyRecording};

/// Simulate a scenario on the virtual rig (`feedid simulate`).
#[pyfunction]
#[pyo3(signature = (scenario, *, seed = 0, duration = None, rate = 5000.0, params_path = None,
    params_json = None, linear = false, effects = None, allow_unstable = false))]
#[allow(clippy::too_many_arguments)]
pub fn simulate(
    py: Python<'_>,
    scenario: &str,
    seed: u64,
    duration: Option<f64>,
    rate: f64,
    params_path: Option<String>,
    params_json: Option<String>,
    linear: bool,
    effects: Option<String>,
    allow_unstable: bool,
) -> PyResult<PyRecording> {
    let scenario: Scenario = scenario.parse().py_err()?;
    let params = crate::params::load(
        params_path.as_deref(),
        params_json.as_deref(),
        allow_unstable,
    )?;
    let effects = match (&effects, linear) {
        (Some(_), true) => return Err(input("effects and linear=True exclude each other")),
        (Some(p), false) => crate::params::effects(p)?,
        (None, true) => RigEffects::linear(),
        (None, false) => RigEffects::default(),
    };
    let duration = duration.unwrap_or_else(|| scenario.default_duration());
    let out = py
        .detach(|| {
            let command = scenario.command(rate, duration, seed)?;
            VirtualRig::new(params)
                .with_effects(effects)
                .with_seed(seed)
                .simulate(&command, rate)
        })
        .py_err()?;
    for (name, v) in [
        ("position", &out.position),
        ("true_position", &out.true_position),
        ("current", &out.motor_current),
        ("velocity", &out.velocity),
    ] {
        if let Some(k) = v.iter().position(|x| !feedid::recording::is_usable(*x)) {
            return Err(input(format!(
                "the simulation diverged: {name} reaches {:e} at t = {} s (beyond ±1e100 or not finite)",
                v[k], out.time[k]
            )));
        }
    }
    let inner = Recording::new(out.time, out.command, out.position)
        .and_then(|r| r.with_channel("true_position", out.true_position))
        .and_then(|r| r.with_channel("current", out.motor_current))
        .and_then(|r| r.with_channel("velocity", out.velocity))
        .py_err()?;
    Ok(PyRecording { inner })
}

/// The nominal model's summary as JSON (`feedid model --json`).
#[pyfunction]
#[pyo3(signature = (*, params_path = None, params_json = None, d1 = "corrected"))]
pub fn model(
    params_path: Option<String>,
    params_json: Option<String>,
    d1: &str,
) -> PyResult<String> {
    // `feedid model` shows unstable parameter sets too (it only describes them)
    let params = crate::params::load(params_path.as_deref(), params_json.as_deref(), true)?;
    let variant = match d1 {
        "corrected" => D1Variant::Corrected,
        "paper" => D1Variant::PaperPrinted,
        other => {
            return Err(input(format!(
                "invalid d1 `{other}`; expected one of: corrected, paper"
            )))
        }
    };
    let summary = ModelSummary::new(&params, variant).py_err()?;
    serde_json::to_string(&summary).map_err(|e| input(format!("model: {e}")))
}

/// What is known of an identified model's quality without a check
/// recording: its fits on its identification recording (as `feedid
/// compensate --model` without `--check`).
fn quality(file: &ModelFile) -> ModelQuality {
    ModelQuality {
        position_fit_percent: file.identified_by.as_ref().map(|p| p.fit_percent),
        error_fit_percent: file
            .identified_by
            .as_ref()
            .and_then(|p| p.error_fit_percent),
        noise_rms_m: None,
    }
}

/// The command that makes a model follow `desired` (`feedid compensate`):
/// returns `(command, predicted, summary_json)`.
#[pyfunction]
#[pyo3(signature = (time, desired, *, model_json = None, model_path = None, params_path = None,
    params_json = None, position_loop = "sampled", smooth = None, max_smoothing = 0.02,
    max_velocity = 1.0, max_acceleration = 30.0, keep_dc_gain = false, allow_unstable = false,
    start = "rest", min_benefit = 1.25, min_fit = 90.0, fallback = true, check = None,
    check2 = None, encoder_resolution = None))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
pub fn compensate<'py>(
    py: Python<'py>,
    time: PyReadonlyArray1<'py, f64>,
    desired: PyReadonlyArray1<'py, f64>,
    model_json: Option<String>,
    model_path: Option<String>,
    params_path: Option<String>,
    params_json: Option<String>,
    position_loop: &str,
    smooth: Option<f64>,
    max_smoothing: f64,
    max_velocity: f64,
    max_acceleration: f64,
    keep_dc_gain: bool,
    allow_unstable: bool,
    start: &str,
    min_benefit: f64,
    min_fit: f64,
    fallback: bool,
    check: Option<&Bound<'py, PyRecording>>,
    check2: Option<&Bound<'py, PyRecording>>,
    encoder_resolution: Option<f64>,
) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>, String)> {
    // one recording of the axis, or two runs of the same program
    let checked = |file: &ModelFile| -> PyResult<ModelQuality> {
        match (check, check2) {
            (Some(a), Some(b)) => ModelQuality::from_two_recordings(
                &file.model,
                &a.get().inner,
                &b.get().inner,
                encoder_resolution,
            )
            .map_err(|e| input(format!("check: {e}"))),
            (Some(c), None) => ModelQuality::from_recording(&file.model, &c.get().inner)
                .map_err(|e| input(format!("check: {e}"))),
            (None, _) => Ok(quality(file)),
        }
    };
    let (t, x) = (slice(&time, "time")?, slice(&desired, "desired")?);
    // the desired trajectory is checked as a recording (time increasing, finite)
    let rec = Recording::new(t.to_vec(), x.to_vec(), x.to_vec()).py_err()?;
    let mut cfg = CompensateConfig {
        smoothing: smooth.map_or(Smoothing::Auto, Smoothing::Fixed),
        max_velocity,
        max_acceleration,
        max_smoothing,
        unit_dc_gain: !keep_dc_gain,
        start: start.parse::<StartMode>().py_err()?,
        min_benefit,
        min_fit_percent: min_fit,
        fallback,
        ..CompensateConfig::default()
    };
    cfg.validate().py_err()?;
    let dt = rec.dt();
    let comp = match (model_json, model_path) {
        (Some(text), _) => {
            let file = ModelFile::from_json(&text).py_err()?;
            cfg.quality = checked(&file)?;
            py.detach(|| compensate_model(&file.model, rec.position(), dt, &cfg))
                .py_err()?
        }
        (None, Some(path)) => {
            let text = feedid::io::read_small_text(Path::new(&path)).py_err()?;
            let file = ModelFile::from_json_file(&text, Path::new(&path)).py_err()?;
            cfg.quality = checked(&file)?;
            py.detach(|| compensate_model(&file.model, rec.position(), dt, &cfg))
                .map_err(|e| input(format!("{path}: {e}")))?
        }
        (None, None) => {
            if check.is_some() {
                return Err(input(
                    "check applies to an identified model (a model dict, model.json or \
                     Identification), not to a physical one"
                        .to_string(),
                ));
            }
            let params = crate::params::load(
                params_path.as_deref(),
                params_json.as_deref(),
                allow_unstable,
            )?;
            let position_loop: LoopModel = position_loop.parse().py_err()?;
            py.detach(|| compensate_params(&params, position_loop, rec.position(), dt, &cfg))
                .py_err()?
        }
    };
    for (name, v) in [
        ("command", &comp.command),
        ("predicted position", &comp.predicted),
    ] {
        if let Some(k) = v.iter().position(|x| !feedid::recording::is_usable(*x)) {
            return Err(input(format!(
                "the {name} runs away ({:e} at t = {} s): the model cannot be inverted here",
                v[k],
                rec.time()[k]
            )));
        }
    }
    let summary = serde_json::to_string(&comp).map_err(|e| input(format!("compensate: {e}")))?;
    Ok((
        PyArray1::from_vec(py, comp.command),
        PyArray1::from_vec(py, comp.predicted),
        summary,
    ))
}
