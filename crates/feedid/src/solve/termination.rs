//! Why a solver stopped.

use serde::Serialize;

/// Why a fit or solver stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Termination {
    /// A direct (non-iterative) solution was computed.
    Exact,
    /// Converged: the function-value and parameter tolerances were met.
    Converged,
    /// Stopped at the iteration (or evaluation) cap.
    MaxIterations,
    /// The window was not informative; the last good model was kept.
    Fallback,
    /// No model could be identified and none was available to fall back on.
    Failed,
    /// A model was identified but not validated for this horizon; no
    /// prediction was emitted (the `auto` method).
    Withheld,
}

impl Termination {
    /// Whether the window produced a prediction (neither failed nor withheld).
    pub fn predicted(self) -> bool {
        !matches!(self, Termination::Failed | Termination::Withheld)
    }

    /// Short lowercase label for tables and CSV files.
    pub fn label(self) -> &'static str {
        match self {
            Termination::Exact => "exact",
            Termination::Converged => "converged",
            Termination::MaxIterations => "max_iterations",
            Termination::Fallback => "fallback",
            Termination::Failed => "failed",
            Termination::Withheld => "withheld",
        }
    }
}
