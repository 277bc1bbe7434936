//! `feedid.Recording` (a checked recording: time, command, position and any
//! further channels) and `feedid.read` (CSV or MAT, as the command-line
//! tool's recording options).
//!
//! The arrays a `Recording` hands out are read-only NumPy views of the
//! library's own buffers (no copy); the view keeps the recording alive.

use feedid::io::{read_recording, ChannelRef, ReadOptions};
use feedid::Recording;
use numpy::ndarray::ArrayView1;
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{input, IntoPy};

/// A checked recording: strictly increasing, finite time [s] and finite
/// command and measured position [m] of equal length (≥ 2 samples).
#[pyclass(frozen, module = "feedid", name = "Recording")]
pub struct PyRecording {
    /// The library's recording.
    pub inner: Recording,
}

/// A slice owned by `owner` as a read-only NumPy array that keeps `owner`
/// alive (no copy).
fn view<'py>(owner: &Bound<'py, PyRecording>, data: &[f64]) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let a = ArrayView1::from(data);
    // SAFETY: `data` lives in the frozen (immutable) `PyRecording` that the
    // array holds as its base object, so it outlives the array and never
    // changes; the array is made read-only below.
    let arr = unsafe { PyArray1::borrow_from_array(&a, owner.clone().into_any()) };
    arr.call_method1("setflags", (false,))?;
    Ok(arr)
}

/// A contiguous float64 array's data (the Python layer converts others).
pub fn slice<'a>(a: &'a PyReadonlyArray1<'_, f64>, name: &str) -> PyResult<&'a [f64]> {
    a.as_slice()
        .map_err(|_| input(format!("{name}: expected a contiguous float64 array")))
}

/// The three arrays of a `push_many` (time, command, position) as slices
/// of equal length.
#[allow(clippy::type_complexity)]
pub fn lines<'a>(
    t: &'a PyReadonlyArray1<'_, f64>,
    u: &'a PyReadonlyArray1<'_, f64>,
    y: &'a PyReadonlyArray1<'_, f64>,
) -> PyResult<(&'a [f64], &'a [f64], &'a [f64])> {
    let (t, u, y) = (slice(t, "t")?, slice(u, "u")?, slice(y, "y")?);
    if t.len() != u.len() || t.len() != y.len() {
        return Err(input(format!(
            "push_many: arrays of different lengths ({}, {}, {})",
            t.len(),
            u.len(),
            y.len()
        )));
    }
    Ok((t, u, y))
}

#[pymethods]
impl PyRecording {
    /// Check and store time [s], command [m] and measured position [m]
    /// (copied once into the library's recording); `allow_gaps` accepts
    /// dropped samples (an interval of a whole number ≥ 2 of typical ones)
    /// as gaps between segments.
    #[new]
    #[pyo3(signature = (time, command, position, *, jitter_tol = 0.01, allow_gaps = false))]
    fn new(
        py: Python<'_>,
        time: PyReadonlyArray1<'_, f64>,
        command: PyReadonlyArray1<'_, f64>,
        position: PyReadonlyArray1<'_, f64>,
        jitter_tol: f64,
        allow_gaps: bool,
    ) -> PyResult<Self> {
        let (t, u, y) = (
            slice(&time, "time")?,
            slice(&command, "command")?,
            slice(&position, "position")?,
        );
        let inner = py
            .detach(|| {
                let (t, u, y) = (t.to_vec(), u.to_vec(), y.to_vec());
                if allow_gaps {
                    Recording::allowing_gaps(t, u, y, jitter_tol)
                } else {
                    Recording::with_tolerance(t, u, y, jitter_tol)
                }
            })
            .py_err()?;
        Ok(Self { inner })
    }

    /// Gaps of dropped samples as `(index, missing)`: the first sample after
    /// each gap and how many samples look missing there (empty without).
    #[getter]
    fn gaps(&self) -> Vec<(usize, usize)> {
        self.inner
            .gaps()
            .iter()
            .map(|g| (g.index, g.missing))
            .collect()
    }

    /// Sample times [s] (read-only view).
    #[getter]
    fn time<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        view(slf, slf.get().inner.time())
    }

    /// Position command [m] (read-only view).
    #[getter]
    fn command<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        view(slf, slf.get().inner.command())
    }

    /// Measured position [m] (read-only view).
    #[getter]
    fn position<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        view(slf, slf.get().inner.position())
    }

    /// Further channels by name (read-only views): a simulation's
    /// `true_position` [m], `current` [A], `velocity` [m/s].
    #[getter]
    fn channels<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(slf.py());
        for (name, v) in slf.get().inner.extra() {
            d.set_item(name, view(slf, v)?)?;
        }
        Ok(d)
    }

    /// Mean sampling interval [s].
    #[getter]
    fn dt(&self) -> f64 {
        self.inner.dt()
    }

    /// Mean sampling rate [Hz].
    #[getter]
    fn rate_hz(&self) -> f64 {
        self.inner.rate_hz()
    }

    /// Duration from the first to the last sample [s].
    #[getter]
    fn duration(&self) -> f64 {
        self.inner.duration()
    }

    /// Notes made while reading (unit conversions and the like).
    #[getter]
    fn notes(&self) -> Vec<String> {
        self.inner.notes().to_vec()
    }

    /// A further channel by name (`rec.true_position`).
    fn __getattr__<'py>(slf: &Bound<'py, Self>, name: &str) -> PyResult<Bound<'py, PyArray1<f64>>> {
        match slf.get().inner.extra().iter().find(|(n, _)| n == name) {
            Some((_, v)) => view(slf, v),
            None => Err(pyo3::exceptions::PyAttributeError::new_err(format!(
                "'Recording' object has no attribute or channel '{name}'"
            ))),
        }
    }

    fn __len__(&self) -> usize {
        self.inner.len()
    }

    fn __repr__(&self) -> String {
        let extra: Vec<&str> = self.inner.extra().iter().map(|(n, _)| n.as_str()).collect();
        format!(
            "Recording({} samples at {:.2} Hz, {:.4} s{}{})",
            self.inner.len(),
            self.inner.rate_hz(),
            self.inner.duration(),
            if extra.is_empty() { "" } else { ", channels " },
            extra.join(", ")
        )
    }
}

/// Read a recording (CSV or MAT) with the options of `feedid identify`.
#[pyfunction]
#[pyo3(signature = (path, *, time = None, command = None, position = None, rate = None,
    delimiter = None, header = None, unit = "m", scale = None, time_unit = "s", jitter_tol = 0.01,
    allow_gaps = false))]
#[allow(clippy::too_many_arguments)]
pub fn read(
    py: Python<'_>,
    path: String,
    time: Option<String>,
    command: Option<String>,
    position: Option<String>,
    rate: Option<f64>,
    delimiter: Option<String>,
    header: Option<bool>,
    unit: &str,
    scale: Option<f64>,
    time_unit: &str,
    jitter_tol: f64,
    allow_gaps: bool,
) -> PyResult<PyRecording> {
    let channel = |s: Option<String>| -> PyResult<Option<ChannelRef>> {
        s.map(|s| ChannelRef::parse(&s)).transpose().py_err()
    };
    let delimiter = match delimiter.as_deref() {
        None => None,
        Some("," | "comma") => Some(b','),
        Some(";" | "semicolon") => Some(b';'),
        Some("\t" | "tab" | "\\t") => Some(b'\t'),
        Some(" " | "space" | "whitespace") => Some(b' '),
        Some(other) => {
            return Err(input(format!(
                "invalid delimiter `{other}`; expected one of: ',', ';', tab, space"
            )))
        }
    };
    let opts = ReadOptions {
        time: channel(time)?,
        command: channel(command)?,
        position: channel(position)?,
        rate_hz: rate,
        delimiter,
        header,
        position_unit: unit.parse().py_err()?,
        scale,
        time_unit: time_unit.parse().py_err()?,
        jitter_tolerance: jitter_tol,
        // the Python recording exposes the extra channels
        signals_only: false,
        allow_gaps,
    };
    opts.validate().py_err()?;
    let path = std::path::PathBuf::from(path);
    let inner = py.detach(|| read_recording(&path, &opts)).py_err()?;
    Ok(PyRecording { inner })
}
