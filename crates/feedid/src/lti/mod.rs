//! Linear time-invariant systems: continuous transfer functions and state-space
//! models, exact zero-order-hold discretisation, simulation, poles, zeros and
//! frequency response.
//!
//! Coefficients of feed-drive models span 1e-8 … 1e16, so every conversion goes
//! through a balanced state-space realisation; nothing is simulated from raw
//! polynomial coefficients.

mod discrete;
mod poly;
mod ss;
mod tf;

pub use discrete::DiscreteStateSpace;
pub use nalgebra::Complex;

pub use ss::StateSpace;
pub use tf::{FrequencyPoint, TransferFunction};
