//! Continuous-time SISO state-space model ẋ = A·x + B·u, y = C·x + D·u.

use nalgebra::{DMatrix, DVector, RowDVector};

use crate::error::{Error, Result};

/// A continuous-time SISO state-space model.
#[derive(Debug, Clone, PartialEq)]
pub struct StateSpace {
    /// State matrix A (n×n).
    pub a: DMatrix<f64>,
    /// Input vector B (n).
    pub b: DVector<f64>,
    /// Output row C (1×n).
    pub c: RowDVector<f64>,
    /// Feed-through D.
    pub d: f64,
}

impl StateSpace {
    /// Build and check dimensions and finiteness.
    pub fn new(a: DMatrix<f64>, b: DVector<f64>, c: RowDVector<f64>, d: f64) -> Result<Self> {
        let n = a.nrows();
        if a.ncols() != n {
            return Err(Error::LengthMismatch {
                what: "A columns",
                expected: n,
                actual: a.ncols(),
            });
        }
        if b.len() != n {
            return Err(Error::LengthMismatch {
                what: "B rows",
                expected: n,
                actual: b.len(),
            });
        }
        if c.len() != n {
            return Err(Error::LengthMismatch {
                what: "C columns",
                expected: n,
                actual: c.len(),
            });
        }
        if a.iter()
            .chain(b.iter())
            .chain(c.iter())
            .any(|v| !v.is_finite())
            || !d.is_finite()
        {
            return Err(Error::InvalidModel {
                reason: "non-finite state-space entry",
            });
        }
        Ok(Self { a, b, c, d })
    }

    /// Number of states.
    pub fn order(&self) -> usize {
        self.a.nrows()
    }
}
