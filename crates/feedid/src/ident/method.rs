//! Choosing a method by name: one place that turns a method name and its
//! settings into an [`Estimator`], so the CLI, the streaming path, sweeps and
//! benchmarks build every method alike.
//!
//! | name | estimator | default window |
//! |---|---|---|
//! | `paper` | the paper's polynomial method ([`PaperConfig`]) | 20 |
//! | `arx` | windowed ARX with exact sliding update ([`ArxConfig`]) | 200 |
//! | `rls` | recursive least squares with forgetting ([`RlsConfig`]) | 100 |
//! | `oe` | continuous-time output error over sliding windows ([`OeConfig`]) | 200 |
//! | `auto` | validated choice among RLS models and hold ([`AutoConfig`]); the default | 50 |
//!
//! ```
//! use feedid::ident::{MethodKind, MethodSpec};
//! let spec = MethodSpec::new("arx".parse::<MethodKind>().unwrap());
//! let est = spec.build().unwrap();
//! assert_eq!(est.name(), "arx");
//! assert_eq!(spec.default_window(), 200);
//! ```

use std::fmt;
use std::str::FromStr;

use crate::error::{Error, Result};
use crate::ident::{ArxConfig, AutoConfig, Estimator, OeConfig, PaperConfig, RlsConfig};

/// The identification methods by name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MethodKind {
    /// The paper's windowed polynomial least squares.
    Paper,
    /// Windowed ARX.
    Arx,
    /// Recursive least squares.
    Rls,
    /// Continuous-time output error.
    Oe,
    /// Validated choice of model, order and memory from the data (the default).
    Auto,
}

/// Accepted method names, for messages.
pub const METHOD_NAMES: &str = "auto, paper, arx, rls, oe";

impl MethodKind {
    /// Lowercase name.
    pub fn name(self) -> &'static str {
        match self {
            MethodKind::Paper => "paper",
            MethodKind::Arx => "arx",
            MethodKind::Rls => "rls",
            MethodKind::Oe => "oe",
            MethodKind::Auto => "auto",
        }
    }
}

impl fmt::Display for MethodKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for MethodKind {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s.to_ascii_lowercase().as_str() {
            "paper" | "lsm" => Ok(MethodKind::Paper),
            "arx" => Ok(MethodKind::Arx),
            "rls" => Ok(MethodKind::Rls),
            "oe" => Ok(MethodKind::Oe),
            "auto" => Ok(MethodKind::Auto),
            _ => Err(Error::InvalidChoice {
                what: "method",
                value: s.to_string(),
                expected: METHOD_NAMES,
            }),
        }
    }
}

/// A method and the settings of every method (only the chosen one is used).
#[derive(Debug, Clone, PartialEq)]
pub struct MethodSpec {
    /// Which method.
    pub kind: MethodKind,
    /// Settings of `paper`.
    pub paper: PaperConfig,
    /// Settings of `arx`.
    pub arx: ArxConfig,
    /// Settings of `rls`.
    pub rls: RlsConfig,
    /// Settings of `oe`.
    pub oe: OeConfig,
    /// Settings of `auto`.
    pub auto: AutoConfig,
}

impl MethodSpec {
    /// A method with its default settings.
    pub fn new(kind: MethodKind) -> Self {
        Self {
            kind,
            paper: PaperConfig::default(),
            arx: ArxConfig::default(),
            rls: RlsConfig::default(),
            oe: OeConfig::default(),
            auto: AutoConfig::default(),
        }
    }

    /// The window a method works best with at kHz rates \[samples\]:
    /// paper 20 (4 ms at 5 kHz, the paper's), arx 200, oe 200, auto 50, rls 100 (it decides only
    /// when the first prediction is made; rls remembers ≈ 1/(1 − λ) samples).
    pub fn default_window(&self) -> usize {
        match self.kind {
            MethodKind::Paper => 20,
            MethodKind::Arx => 200,
            MethodKind::Rls => 100,
            MethodKind::Oe => 200,
            MethodKind::Auto => 50,
        }
    }

    /// Validate the settings and build the estimator.
    pub fn build(&self) -> Result<Box<dyn Estimator + Send>> {
        Ok(match self.kind {
            MethodKind::Paper => Box::new(self.paper.build()?),
            MethodKind::Arx => Box::new(self.arx.build()?),
            MethodKind::Rls => Box::new(self.rls.build()?),
            MethodKind::Oe => Box::new(self.oe.clone().build()?),
            MethodKind::Auto => Box::new(self.auto.build()?),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_name_builds_its_estimator() {
        for name in ["paper", "arx", "rls", "oe", "auto"] {
            let kind: MethodKind = name.parse().unwrap();
            assert_eq!(kind.name(), name);
            assert_eq!(MethodSpec::new(kind).build().unwrap().name(), name);
        }
    }

    #[test]
    fn unknown_name_lists_the_choices() {
        let e = "magic".parse::<MethodKind>().unwrap_err();
        assert!(e.to_string().contains("auto, paper, arx, rls, oe"), "{e}");
    }
}
