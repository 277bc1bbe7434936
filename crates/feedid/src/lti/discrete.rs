//! Discrete-time SISO state-space model x[k+1] = Ad·x[k] + Bd·u[k], y[k] = C·x[k] + D·u[k].

use nalgebra::{DMatrix, DVector, RowDVector};

/// A discrete-time SISO state-space model with its sample time.
#[derive(Debug, Clone, PartialEq)]
pub struct DiscreteStateSpace {
    /// State matrix.
    pub a: DMatrix<f64>,
    /// Input vector.
    pub b: DVector<f64>,
    /// Output row.
    pub c: RowDVector<f64>,
    /// Feed-through.
    pub d: f64,
    /// Sample time \[s\].
    pub dt: f64,
}
