//! Models of a whole recording: the linear model type and the global models
//! (ARX, output error, the best of several) with where they came from.

mod global;
mod linear;

pub use global::{
    fit_global_model, simulation_error, GlobalModelKind, ModelFile, ModelProvenance,
    GLOBAL_FIT_SAMPLES,
};
pub use linear::LinearModel;
