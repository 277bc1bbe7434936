//! The one error type of the report crate: the core's errors, and figures
//! that cannot be rendered.

/// Result alias of the report crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Everything that can go wrong while building figures and reports.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// An error of the numerical core (reading, identifying, fitting).
    #[error(transparent)]
    Core(#[from] feedid::Error),

    /// A figure could not be rendered.
    #[error("cannot render figure: {reason}")]
    Plot {
        /// Renderer message.
        reason: String,
    },
}

impl Error {
    /// The innermost core error, if this is one (see [`feedid::Error::root`]).
    pub fn core_root(&self) -> Option<&feedid::Error> {
        match self {
            Error::Core(e) => Some(e.root()),
            Error::Plot { .. } => None,
        }
    }
}
