//! Solvers, kept apart from the problems they solve: dense least squares by
//! Householder QR on scaled columns, ridge least squares on problems already
//! in Hessenberg form, the Nelder–Mead simplex and Levenberg–Marquardt.
//! Each iterative solver returns a report with its termination reason.

mod hessenberg;
mod lm;
mod nelder_mead;
mod qr;
pub(crate) mod rows;
mod termination;

pub(crate) use hessenberg::lstsq_hessenberg_view;
pub use hessenberg::{hessenberg_condition, lstsq_hessenberg, HessenbergInfo, HessenbergWorkspace};
pub use lm::{LevenbergMarquardt, LmConfig, LmReport};
pub use nelder_mead::{nelder_mead, NelderMead, NelderMeadConfig, NelderMeadReport};
pub(crate) use qr::lstsq_fixed;
pub use qr::{
    lstsq, lstsq_in_place, lstsq_with, LstsqInfo, LstsqOptions, LstsqSolution, QrWorkspace,
};
pub use termination::Termination;
