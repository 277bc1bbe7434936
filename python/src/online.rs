//! `feedid.OnlineCompensator`: online compensation fed line by line
//! ([`feedid::compensate::CommandStream`], `feedid stream --compensate`);
//! each push returns the command due next.

use std::sync::{Mutex, MutexGuard};

use std::path::Path;

use feedid::compensate::{following_error_of, CommandStream, OnlineConfig, OnlineState};
use feedid::ident::ModelFile;
use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{input, IntoPy};
use crate::recording::lines;

/// One command: the time of its sample [s], desired position [m], command [m].
type Row = (f64, f64, f64);

/// Online compensation (see the Python class's docstring).
#[pyclass(module = "feedid", name = "OnlineCompensator")]
pub struct PyOnlineCompensator {
    // a Python object may be shared between threads: one push at a time
    inner: Mutex<CommandStream>,
}

impl PyOnlineCompensator {
    fn lock(&self) -> PyResult<MutexGuard<'_, CommandStream>> {
        self.inner
            .lock()
            .map_err(|_| input("the compensator failed in another thread; make a new one"))
    }
}

#[pymethods]
impl PyOnlineCompensator {
    #[new]
    #[pyo3(signature = (*, rate, command_lead, replay = false, max_velocity = 1.0,
        max_acceleration = 30.0, model_json = None, model_path = None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        rate: f64,
        command_lead: usize,
        replay: bool,
        max_velocity: f64,
        max_acceleration: f64,
        model_json: Option<String>,
        model_path: Option<String>,
    ) -> PyResult<Self> {
        if !(rate.is_finite() && rate > 0.0) {
            return Err(input(format!(
                "invalid rate {rate}: must be finite and > 0 Hz"
            )));
        }
        let cfg = OnlineConfig {
            max_velocity,
            max_acceleration,
            ..OnlineConfig::default()
        };
        let mut inner = CommandStream::new(cfg, command_lead, 1.0 / rate, replay).py_err()?;
        let file = match (model_json, model_path) {
            (Some(text), _) => Some(ModelFile::from_json(&text).py_err()?),
            (None, Some(path)) => {
                let text = feedid::io::read_small_text(Path::new(&path)).py_err()?;
                Some(ModelFile::from_json_file(&text, Path::new(&path)).py_err()?)
            }
            (None, None) => None,
        };
        if let Some(f) = file {
            let alpha = following_error_of(&f.model, 1.0 / rate).py_err()?;
            inner.set_prior(alpha).py_err()?;
        }
        Ok(Self {
            inner: Mutex::new(inner),
        })
    }

    /// Push one line; returns the command due next, if any.
    fn push(&self, t: f64, u: f64, y: f64) -> PyResult<Option<Row>> {
        let mut s = self.lock()?;
        Ok(s.push(t, u, y)
            .py_err()?
            .map(|r| (r.time, r.desired, r.command)))
    }

    /// Push many lines at once (equal-length arrays); returns the commands
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
                if let Some(r) = s.push(t[k], u[k], y[k]).map_err(|e| (k, e))? {
                    out.push((r.time, r.desired, r.command));
                }
            }
            Ok(out)
        })
        .map_err(|(k, e): (usize, feedid::Error)| input(format!("sample {k} of this push: {e}")))
    }

    /// Counters, the guard's state and the model in use.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self.lock()?;
        let st = s.stats();
        let d = PyDict::new(py);
        d.set_item("commands", st.commands)?;
        d.set_item("compensated", st.compensated)?;
        d.set_item("limited", st.limited)?;
        d.set_item("model_updates", st.model_updates)?;
        d.set_item("implausible", st.implausible)?;
        d.set_item("withheld", st.withheld)?;
        d.set_item("segments", s.segments())?;
        let state = match s.state() {
            OnlineState::Learning => "learning",
            OnlineState::Unexplained => "unexplained",
            OnlineState::Invalid => "invalid",
            OnlineState::Worse => "worse",
            OnlineState::Active => "active",
        };
        d.set_item("state", state)?;
        let c = s.compensator();
        d.set_item("time_constants", c.time_constants().to_vec())?;
        d.set_item("following_error_model", c.following_error_model().to_vec())?;
        d.set_item("weight", c.weight())?;
        Ok(d)
    }
}
