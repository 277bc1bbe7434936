//! Solvers, kept apart from the problems they solve: dense least squares by
//! Householder QR on scaled columns, the Nelder–Mead simplex and
//! Levenberg–Marquardt. Each iterative solver returns a report with its
//! termination reason.

mod lm;
mod nelder_mead;
mod qr;
mod termination;

pub use lm::{LevenbergMarquardt, LmConfig, LmReport};
pub use nelder_mead::{nelder_mead, NelderMead, NelderMeadConfig, NelderMeadReport};
pub use qr::{
    lstsq, lstsq_in_place, lstsq_with, LstsqInfo, LstsqOptions, LstsqSolution, QrWorkspace,
};
pub use termination::Termination;
