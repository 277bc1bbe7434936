//! Python bindings of feedid: the extension module `feedid._feedid`, wrapped
//! by the pure-Python package `feedid` (python/feedid). Thin: every call goes
//! to the library (`feedid::pipeline::Pipeline`, `feedid::ident::Streamer`,
//! `feedid::io::read_recording`, the virtual rig, the compensation), never to
//! the command-line tool. Arguments arrive already normalised by the Python
//! layer (paths as `str`, parameter dictionaries as JSON text).
#![deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod errors;
mod identify;
mod learn;
mod method;
mod online;
mod params;
mod recording;
mod rig;
mod stream;
mod structure;

use pyo3::prelude::*;

/// The native part of the `feedid` package (use `import feedid`).
#[pymodule]
fn _feedid(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<recording::PyRecording>()?;
    m.add_class::<stream::PyStreamer>()?;
    m.add_class::<online::PyOnlineCompensator>()?;
    m.add_function(wrap_pyfunction!(recording::read, m)?)?;
    m.add_function(wrap_pyfunction!(identify::identify, m)?)?;
    m.add_function(wrap_pyfunction!(method::method_options, m)?)?;
    m.add_function(wrap_pyfunction!(method::methods, m)?)?;
    m.add_function(wrap_pyfunction!(rig::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(rig::model, m)?)?;
    m.add_function(wrap_pyfunction!(rig::compensate, m)?)?;
    m.add_function(wrap_pyfunction!(learn::learn, m)?)?;
    m.add_function(wrap_pyfunction!(structure::structure_model, m)?)?;
    m.add_function(wrap_pyfunction!(structure::structure_simulate, m)?)?;
    m.add_function(wrap_pyfunction!(structure::structure_fit, m)?)?;
    m.add_function(wrap_pyfunction!(structure::structure_tune, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
