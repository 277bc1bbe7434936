//! `auto`: a multiple-model predictor that picks the model, its order and
//! its memory from the data while it runs, and always predicts.
//!
//! (Documentation being rewritten.)

mod candidate;
mod config;
mod estimator;
mod model;

pub use candidate::Candidate;
pub use config::AutoConfig;
pub use estimator::AutoEstimator;
