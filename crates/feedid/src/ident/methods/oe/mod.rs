//! Continuous-time output error over sliding windows (see [`estimator`]),
//! with its companion-form simulation and SRIVC start.

mod companion;
mod estimator;
mod global;
mod srivc;
mod window;

pub use estimator::{OeConfig, OeEstimator, OeJacobian};
pub use global::{fit_oe, fit_oe_measured, OeFit};
