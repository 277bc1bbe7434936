//! Windowed ARX (see [`estimator`]).

mod estimator;

pub(crate) use estimator::{check_window, fit_arx_rows, poles_inside, predict_horizon, regressor};
pub use estimator::{
    fit_arx, ArxConfig, ArxDiagnostics, ArxEstimator, ArxFit, ArxOrders, MAX_ARX_ORDER,
};
