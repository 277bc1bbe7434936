//! Analysis of the prediction errors: residual auto- and cross-correlation.

mod residuals;

pub use residuals::{ResidualAnalysis, Z_99};
