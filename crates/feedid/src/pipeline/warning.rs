//! What a run found that the user should know, without failing it.

use std::fmt;

use serde::{Serialize, Serializer};

use crate::error::{phrase_hints, Hint, Syntax};

/// A warning of an identification run ([`crate::pipeline::Identification::warnings`];
/// printed on standard error by the CLI). Serialises as its text.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Warning {
    /// The recording itself is implausible (a frozen position, different
    /// units, …): see [`crate::plausibility`].
    Recording(crate::recording::plausibility::Warning),
    /// Paper method with the motion time origin: the windows lie so far
    /// from the origin that the change of basis to the coefficients `N`,
    /// `D` loses digits (see
    /// [`crate::ident::PaperConfig::worst_shift_amplification`]); the
    /// predictions are not affected.
    PaperCoefficientAccuracy {
        /// The largest growth factor of the change of basis over the windows.
        amplification: f64,
    },
    /// No sample was predicted: no error figure is reported.
    NothingPredicted {
        /// Windows visited.
        windows: usize,
        /// Windows whose fit or prediction failed.
        failed: usize,
        /// Windows whose prediction the method withheld.
        withheld: usize,
    },
    /// Some predictions left the last measured position by more than the
    /// plausibility factor times the motion the recording has shown: they
    /// were withheld and the method restarted after each
    /// ([`GuardConfig::plausibility`](crate::ident::GuardConfig::plausibility)).
    ImplausibleWithheld {
        /// Windows whose prediction was withheld.
        withheld: usize,
        /// Windows visited.
        windows: usize,
        /// The plausibility factor.
        factor: f64,
    },
    /// The recording has gaps of dropped samples
    /// ([`crate::Recording::gaps`]): the windows restarted after each, so
    /// the samples at the start of every later segment are not predicted;
    /// order selection and global models use the stretch without gaps
    /// where the command moves most ([`crate::Recording::moving_segment`]).
    DroppedSamples {
        /// Gaps.
        gaps: usize,
        /// Samples that look missing in all gaps.
        missing: usize,
        /// Zero-based index of the first sample after the first gap.
        first: usize,
        /// Its time stamp \[s\].
        first_time_s: f64,
        /// Samples of the later segments before their first prediction
        /// (not predicted because of the restarts).
        unpredicted: usize,
        /// Samples in the stretch without gaps that order selection uses
        /// (the global models run through the gaps).
        stretch: usize,
    },
    /// Paper method with the window time origin: the output model
    /// `P5·τ⁵ + P6·τ⁶ + P7·τ⁷` is zero with its first four derivatives at each
    /// window's first sample, so it cannot represent an axis that is away from
    /// zero or moving there; the coefficients are accurate, the predictions are
    /// not (docs/METHODS.md §4: window-local time is an option for studying the
    /// coefficients).
    PaperWindowOrigin,
    /// Paper method with `--prediction tf`: in these windows the identified
    /// `N(s)/D(s)` was unstable (or not realisable) and the prediction fell
    /// back to the polynomial one (see
    /// [`crate::ident::PaperMethod::tf_fallbacks`]). The identified `D(s)`
    /// holds the command's Taylor coefficients, which rarely form a Hurwitz
    /// polynomial, so on most recordings most windows fall back.
    PaperTfFallback {
        /// Windows whose transfer-function prediction fell back.
        fallbacks: usize,
        /// Windows predicted.
        windows: usize,
    },
    /// The nominal simulation model (unstable parameters, allowed) ran away:
    /// from `from_s` on it is farther from the measured position than
    /// [`DIVERGED_SPAN`](crate::pipeline::DIVERGED_SPAN) times the motion
    /// the recording spans; its error figures and its simulated positions
    /// from there are left out of every output.
    NominalDiverged {
        /// Time of the first sample left out \[s\].
        from_s: f64,
    },
}

impl Warning {
    /// The settings the text suggests, in the order it names them.
    pub fn hints(&self) -> Vec<Hint> {
        let set = |key, value| Hint::SetOption { key, value };
        match self {
            Warning::Recording(w) => w.hints.clone(),
            Warning::NothingPredicted { windows, .. } if *windows > 0 => {
                vec![set("method", "auto")]
            }
            Warning::PaperWindowOrigin => vec![set("time_origin", "window")],
            Warning::PaperTfFallback { .. } => vec![set("prediction", "polynomial")],
            _ => Vec::new(),
        }
    }

    /// The text with its hints in a front end's syntax (`Display` is
    /// [`Syntax::Library`]'s): the CLI names `--method auto`, Python
    /// `method="auto"`.
    pub fn phrased(&self, syntax: Syntax) -> String {
        match self {
            Warning::Recording(w) => w.phrased(syntax),
            other => phrase_hints(&other.to_string(), &other.hints(), syntax),
        }
    }
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Warning::Recording(w) => write!(f, "{w}"),
            Warning::PaperCoefficientAccuracy { amplification: g } => write!(
                f,
                "paper method: windows lie far from the time origin; the coefficients N, D \
                 lose about {:.0} of their 16 digits (amplification {g:.1e}); predictions are \
                 not affected (the time origin `window` keeps the coefficients accurate but \
                 cannot predict a moving axis)",
                g.log10().min(16.0)
            ),
            Warning::NothingPredicted {
                windows,
                failed,
                withheld,
            } => {
                write!(f, "no sample was predicted, so no error is reported: ")?;
                if *windows == 0 {
                    write!(
                        f,
                        "the recording is too short for one window and its horizon"
                    )
                } else {
                    write!(
                        f,
                        "of {windows} windows, {failed} failed (the method could not fit or \
                         predict them: too little motion, an unstable or non-finite model) and \
                         {withheld} were withheld; try another method, a longer window or \
                         `method = auto`, which always predicts"
                    )
                }
            }
            Warning::ImplausibleWithheld {
                withheld,
                windows,
                factor,
            } => write!(
                f,
                "{withheld} of {windows} windows predicted implausibly (more than {factor} times \
                 the motion the recording has shown, away from the last measured position: a \
                 model that wound up or diverged); those predictions were withheld, are not in \
                 the error figures, and the method restarted after each"
            ),
            Warning::DroppedSamples {
                gaps,
                missing,
                first,
                first_time_s,
                unpredicted,
                stretch,
            } => write!(
                f,
                "{missing} sample{} missing in {gaps} gap{} (dropped by the acquisition?; the \
                 first before sample {first}, t = {first_time_s} s): the windows restarted after \
                 each gap, as `feedid stream` does, so {unpredicted} samples at the start of the \
                 later segments are not predicted; global models are fitted and simulated through \
                 the gaps (compared with the measured samples only); order selection uses the \
                 stretch without gaps where the command moves most ({stretch} samples)",
                if *missing == 1 { " looks" } else { "s look" },
                if *gaps == 1 { "" } else { "s" },
            ),
            Warning::PaperWindowOrigin => write!(
                f,
                "paper method, time origin window: the output model P5·τ⁵ + P6·τ⁶ + P7·τ⁷ \
                 starts at zero position and velocity in every window, so it cannot represent \
                 an axis away from 0 or moving at a window's start; its predictions are far off \
                 there (use time_origin = window to study the coefficients, motion to predict)"
            ),
            Warning::NominalDiverged { from_s } => write!(
                f,
                "the nominal simulation model ran away from t = {from_s:.4} s (unstable \
                 parameters); its simulated positions from there and its error figures are left \
                 out"
            ),
            Warning::PaperTfFallback { fallbacks, windows } => write!(
                f,
                "paper method, prediction tf: the identified transfer function was unstable in \
                 {fallbacks} of {windows} windows ({:.1} %), which were predicted by the \
                 polynomial instead (as prediction = polynomial)",
                100.0 * *fallbacks as f64 / (*windows).max(1) as f64
            ),
        }
    }
}

impl Serialize for Warning {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names_a_flag(s: &str) -> bool {
        s.as_bytes()
            .windows(3)
            .any(|w| w[0] == b'-' && w[1] == b'-' && w[2].is_ascii_alphabetic())
    }

    #[test]
    fn texts_name_no_command_line_flags_and_the_cli_phrasing_does() {
        let all = [
            Warning::PaperCoefficientAccuracy { amplification: 1e9 },
            Warning::NothingPredicted {
                windows: 0,
                failed: 0,
                withheld: 0,
            },
            Warning::NothingPredicted {
                windows: 10,
                failed: 4,
                withheld: 6,
            },
            Warning::ImplausibleWithheld {
                withheld: 2,
                windows: 10,
                factor: 10.0,
            },
            Warning::DroppedSamples {
                gaps: 1,
                missing: 3,
                first: 300,
                first_time_s: 0.3,
                unpredicted: 5,
                stretch: 200,
            },
            Warning::PaperWindowOrigin,
            Warning::PaperTfFallback {
                fallbacks: 3,
                windows: 10,
            },
            Warning::NominalDiverged { from_s: 0.25 },
        ];
        for w in &all {
            let text = w.to_string();
            assert!(!names_a_flag(&text), "{text}");
            assert_eq!(w.phrased(Syntax::Library), text);
            let cli = w.phrased(Syntax::Cli);
            assert_eq!(names_a_flag(&cli), !w.hints().is_empty(), "{cli}");
            assert!(!names_a_flag(&w.phrased(Syntax::Python)), "{w:?}");
        }
        let cli = all[6].phrased(Syntax::Cli);
        assert!(cli.contains("(as --prediction polynomial)"), "{cli}");
        let py = all[5].phrased(Syntax::Python);
        assert!(py.contains("(use time_origin=\"window\" to study"), "{py}");
    }
}
