//! The paper's windowed polynomial least squares (see [`estimator`]).

mod estimator;

pub use estimator::{
    coefficients_from_polynomials, polynomials_from_coefficients, PaperConfig, PaperDiagnostics,
    PaperMethod, PredictionMode, SimplexSettings, Solver, TimeOrigin, SHIFT_AMPLIFICATION_WARNING,
};
