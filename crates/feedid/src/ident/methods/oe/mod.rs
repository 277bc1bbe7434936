//! Continuous-time output error over sliding windows (see [`estimator`]),
//! with its companion-form simulation and SRIVC start.

mod companion;
mod estimator;
mod srivc;

pub use estimator::{fit_oe, OeConfig, OeEstimator, OeFit, OeJacobian};
