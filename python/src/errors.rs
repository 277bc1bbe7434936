//! Library errors as Python exceptions: `feedid.FileError` (an `OSError`)
//! for files that cannot be opened or read, `feedid.InputError` (a
//! `ValueError`) for everything else; both are `feedid.Error`. The message
//! is the library's, its hints phrased as Python keywords (`max_smoothing`
//! where the command-line tool says `--max-smoothing`).

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// The exception class of `feedid` named `class`, raised with `message`.
fn raise(class: &str, message: String) -> PyErr {
    Python::attach(|py| {
        let made = py
            .import("feedid")
            .and_then(|m| m.getattr(class))
            .and_then(|c| c.call1((message.clone(),)));
        match made {
            Ok(exc) => PyErr::from_value(exc),
            // the native module used alone, without the package
            Err(_) => PyValueError::new_err(message),
        }
    })
}

/// A library error as `feedid.FileError` or `feedid.InputError`.
pub fn to_py(e: feedid::Error) -> PyErr {
    // the library's hints as Python keywords (`max_smoothing`)
    let message = e.message(feedid::error::Syntax::Python);
    match e {
        feedid::Error::Io { .. } | feedid::Error::InputTooLarge { .. } => {
            raise("FileError", message)
        }
        _ => raise("InputError", message),
    }
}

/// A message of the binding's own (a bad argument) as `feedid.InputError`.
pub fn input(message: impl Into<String>) -> PyErr {
    raise("InputError", message.into())
}

/// `Result<T, feedid::Error>` → `PyResult<T>`.
pub trait IntoPy<T> {
    /// Convert the error.
    fn py_err(self) -> PyResult<T>;
}

impl<T> IntoPy<T> for feedid::Result<T> {
    fn py_err(self) -> PyResult<T> {
        self.map_err(to_py)
    }
}
