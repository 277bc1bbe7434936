//! Drive structures (`examples/emps.toml`): the closed loop
//! (`feedid.structure`), the simulation (`feedid.simulate_structure`), the
//! estimation (`feedid.fit_structure`) and the retuned gains
//! (`feedid.tune`). The structure arrives as a TOML file path.

use std::path::Path;

use feedid::drive::{DriveStructure, StructureParam, TuneTarget};
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;

use crate::errors::{input, IntoPy};
use crate::recording::slice;

fn load(path: &str) -> PyResult<DriveStructure> {
    let p = Path::new(path);
    let text = feedid::io::read_small_text(p).py_err()?;
    if !DriveStructure::describes(&text) {
        return Err(input(format!(
            "{path}: not a drive structure file (it needs [drive] and [mechanics] tables)"
        )));
    }
    DriveStructure::from_toml_str(&text, Some(p)).py_err()
}

fn json(what: &str, v: serde_json::Result<String>) -> PyResult<String> {
    v.map_err(|e| input(format!("{what}: {e}")))
}

/// The closed loop of a structure as JSON (`feedid model --params s.toml --json`).
#[pyfunction]
pub fn structure_model(path: &str) -> PyResult<String> {
    let s = load(path)?;
    json(
        "structure",
        serde_json::to_string(&s.closed_loop().py_err()?),
    )
}

/// Simulate a structure on `command` at `rate`: `(position, velocity, output)`.
#[pyfunction]
#[pyo3(signature = (path, command, rate, *, initial_position = None))]
#[allow(clippy::type_complexity)]
pub fn structure_simulate<'py>(
    py: Python<'py>,
    path: &str,
    command: PyReadonlyArray1<'py, f64>,
    rate: f64,
    initial_position: Option<f64>,
) -> PyResult<(
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
)> {
    let s = load(path)?;
    let c = slice(&command, "command")?.to_vec();
    let x0 = initial_position.unwrap_or_else(|| c.first().copied().unwrap_or(0.0));
    let run = py.detach(|| s.simulate(&c, rate, x0)).py_err()?;
    Ok((
        PyArray1::from_vec(py, run.position),
        PyArray1::from_vec(py, run.velocity),
        PyArray1::from_vec(py, run.output),
    ))
}

/// Estimate the named parameters from command and position (`feedid greybox
/// --params s.toml`), with `restarts` fits from ±22 % away; the fit as
/// JSON, the structure's new TOML beside.
#[pyfunction]
#[pyo3(signature = (path, command, position, rate, estimate, *, restarts = 2))]
pub fn structure_fit<'py>(
    py: Python<'py>,
    path: &str,
    command: PyReadonlyArray1<'py, f64>,
    position: PyReadonlyArray1<'py, f64>,
    rate: f64,
    estimate: Vec<String>,
    restarts: usize,
) -> PyResult<(String, String)> {
    let s = load(path)?;
    let names = estimate
        .iter()
        .map(|n| n.parse::<StructureParam>())
        .collect::<feedid::Result<Vec<_>>>()
        .py_err()?;
    let (c, y) = (
        slice(&command, "command")?.to_vec(),
        slice(&position, "position")?.to_vec(),
    );
    if restarts > 100 {
        return Err(input(format!("restarts {restarts}: at most 100")));
    }
    let fit = py
        .detach(|| s.fit_with_restarts(&c, &y, rate, &names, restarts))
        .py_err()?;
    Ok((
        json("fit", serde_json::to_string(&fit))?,
        fit.structure.to_toml_string(),
    ))
}

/// Gains for a bandwidth and damping (`feedid tune`): JSON, and the retuned TOML.
#[pyfunction]
pub fn structure_tune(path: &str, bandwidth: f64, damping: f64) -> PyResult<(String, String)> {
    let s = load(path)?;
    let t = s
        .tune(&TuneTarget {
            bandwidth_hz: bandwidth,
            damping,
        })
        .py_err()?;
    Ok((
        json("tune", serde_json::to_string(&t))?,
        t.structure.to_toml_string(),
    ))
}
