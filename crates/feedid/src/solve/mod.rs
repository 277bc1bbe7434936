//! Solvers, kept apart from the problems they solve: dense least squares by
//! Householder QR on scaled columns, the Nelder–Mead simplex and
//! Levenberg–Marquardt. Each iterative solver returns a report with its
//! termination reason.

mod termination;

pub use termination::Termination;
