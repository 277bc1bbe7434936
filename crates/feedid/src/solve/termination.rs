//! Why a solver stopped. (What became of an identification window — kept
//! the previous model, withheld, failed — is the engine's business:
//! `ident::WindowOutcome`.)

use serde::Serialize;

/// Why a solver stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Termination {
    /// A direct (non-iterative) solution was computed.
    Exact,
    /// Converged: the function-value and parameter tolerances were met.
    Converged,
    /// Stopped at the iteration (or evaluation) cap.
    MaxIterations,
}

impl Termination {
    /// Short lowercase label for tables and CSV files.
    pub fn label(self) -> &'static str {
        match self {
            Termination::Exact => "exact",
            Termination::Converged => "converged",
            Termination::MaxIterations => "max_iterations",
        }
    }
}
