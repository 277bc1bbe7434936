//! Analysis of the prediction errors: residual auto- and cross-correlation
//! of a run's predictions against the command.

mod residuals;

pub use residuals::{
    prediction_errors, prediction_residuals, ResidualAnalysis, RESIDUAL_LAGS, RESIDUAL_SAMPLES,
    Z_99,
};
