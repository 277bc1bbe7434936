//! Choosing an identification method by name at run time (command line,
//! configuration files): [`build_estimator`] returns a boxed [`Estimator`]
//! that the batch engine ([`crate::ident::engine::run`]) and the streaming
//! path ([`crate::ident::stream::Streamer`]) accept alike.
//!
//! ```
//! use feedid::ident::{build_estimator, MethodOptions};
//! let est = build_estimator("paper", &MethodOptions::default()).unwrap();
//! assert_eq!(est.name(), "paper");
//! assert!(build_estimator("magic", &MethodOptions::default()).is_err());
//! ```

use crate::error::{Error, Result};
use crate::ident::{Estimator, PaperConfig};

/// Method names accepted by [`build_estimator`], comma separated.
pub const METHOD_NAMES: &str = "paper";

/// Settings of every method; [`build_estimator`] uses those of the chosen one.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MethodOptions {
    /// The paper method (`"paper"`); default [`PaperConfig::default`].
    pub paper: PaperConfig,
}

/// Build the estimator named `name` (case-insensitive, see [`METHOD_NAMES`]).
pub fn build_estimator(name: &str, options: &MethodOptions) -> Result<Box<dyn Estimator + Send>> {
    match name.to_ascii_lowercase().as_str() {
        "paper" => Ok(Box::new(options.paper.build()?)),
        _ => Err(Error::InvalidChoice {
            what: "method",
            value: name.to_string(),
            expected: METHOD_NAMES,
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ident::{PredictionMode, Solver};

    #[test]
    fn methods_are_built_by_case_insensitive_name_with_their_options() {
        let mut opts = MethodOptions::default();
        opts.paper.solver = Solver::Simplex;
        let est = build_estimator("Paper", &opts).unwrap();
        assert_eq!(est.name(), "paper");
        assert!(!est.uses_future_command());
        opts.paper.prediction = PredictionMode::TransferFunction;
        // the options reach the builder (the TF mode is refused until it lands)
        let tf = build_estimator("paper", &opts);
        assert!(tf.map_or(true, |e| e.uses_future_command()));
        match build_estimator("arx2", &opts) {
            Err(Error::InvalidChoice { what, value, .. }) => {
                assert_eq!((what, value.as_str()), ("method", "arx2"))
            }
            other => panic!("{:?}", other.map(|e| e.name())),
        }
    }
}
