//! What a [`super::Streamer`] is told beyond the window configuration (the
//! command lead, how to fill the command over a horizon that has not arrived,
//! the sampling interval) and what it reports about each pushed sample (its
//! interval: regular, irregular, a gap).

use std::fmt;
use std::str::FromStr;

use crate::error::{Error, Result};
use crate::ident::engine::{CommandBasis, GuardConfig};
use crate::recording::DEFAULT_JITTER_TOLERANCE;

/// Relative deviation of a sampling interval from the expected one beyond
/// which it is a gap (or a change of the sampling) and the windows restart:
/// 0.5, so one missing sample (twice the interval) is a gap.
pub const GAP_DEVIATION: f64 = 0.5;

/// How the command over a prediction horizon is filled where it has not
/// arrived yet (its samples `n, n+1, …` after the last command received,
/// `u[n−1]`; `Δ = u[n−1] − u[n−2]`, `Δ² = u[n−1] − 2u[n−2] + u[n−3]`).
///
/// With [`StreamOptions::command_lead`] ≥ the horizon the command has always
/// arrived and this is not used; nor is it by estimators that do not read the
/// command over the horizon ([`crate::ident::Estimator::uses_future_command`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum CommandExtrapolation {
    /// Do not extrapolate: a window waits until the command up to its horizon
    /// end has arrived. Without a lead its prediction then comes after the
    /// horizon has been measured (a reconstruction, equal to the batch
    /// engine's prediction); for scoring, not for real time.
    Wait,
    /// The last command held: `u[n−1+m] = u[n−1]`.
    Hold,
    /// Constant velocity from the last two command samples:
    /// `u[n−1+m] = u[n−1] + m·Δ`.
    Velocity,
    /// Constant acceleration from the last three command samples (the
    /// parabola through them): `u[n−1+m] = u[n−1] + m·Δ + m(m+1)/2·Δ²`.
    /// The default: of the three, the smallest prediction error on the rig
    /// scenarios and on most of the drive zoo (example
    /// `stream_extrapolation`; the figures are in docs/RESULTS.md, "Streaming").
    #[default]
    Acceleration,
}

impl CommandExtrapolation {
    /// Every variant, in the order of [`CommandExtrapolation::NAMES`].
    pub const ALL: [CommandExtrapolation; 4] = [
        CommandExtrapolation::Wait,
        CommandExtrapolation::Hold,
        CommandExtrapolation::Velocity,
        CommandExtrapolation::Acceleration,
    ];

    /// Accepted names, for messages.
    pub const NAMES: &'static str = "wait, hold, velocity, acceleration";

    /// Short name, as on the command line (`wait`, `hold`, `velocity`, `acceleration`).
    pub fn name(self) -> &'static str {
        match self {
            CommandExtrapolation::Wait => "wait",
            CommandExtrapolation::Hold => "hold",
            CommandExtrapolation::Velocity => "velocity",
            CommandExtrapolation::Acceleration => "acceleration",
        }
    }

    /// A phrase for summaries ("constant velocity from the last two command samples").
    pub fn describe(self) -> &'static str {
        match self {
            CommandExtrapolation::Wait => "not extrapolated: each window waits for its command",
            CommandExtrapolation::Hold => "the last command held",
            CommandExtrapolation::Velocity => "constant velocity from the last two command samples",
            CommandExtrapolation::Acceleration => {
                "constant acceleration from the last three command samples"
            }
        }
    }

    /// Command samples the extrapolation reads (0 for wait).
    pub fn history(self) -> usize {
        match self {
            CommandExtrapolation::Wait => 0,
            CommandExtrapolation::Hold => 1,
            CommandExtrapolation::Velocity => 2,
            CommandExtrapolation::Acceleration => 3,
        }
    }

    /// Fill `out[m]` (`m = 0, 1, …`) with the command `m + 1` samples after
    /// the last of `past` (the most recent command samples, oldest first).
    /// Uses as many of the last samples as the extrapolation needs and `past`
    /// has (fewer: a lower order); an empty `past` leaves `out` unchanged.
    /// [`CommandExtrapolation::Wait`] holds.
    ///
    /// ```
    /// use feedid::ident::stream::CommandExtrapolation;
    /// let mut out = [0.0; 3];
    /// CommandExtrapolation::Velocity.fill(&[1.0, 2.0, 4.0], &mut out);
    /// assert_eq!(out, [6.0, 8.0, 10.0]);
    /// CommandExtrapolation::Acceleration.fill(&[1.0, 2.0, 4.0], &mut out);
    /// assert_eq!(out, [7.0, 11.0, 16.0]); // 1, 2, 4, 7, 11, 16: differences 1, 2, 3, 4, 5
    /// ```
    pub fn fill(self, past: &[f64], out: &mut [f64]) {
        let n = past.len();
        let Some(&last) = past.last() else { return };
        let order = self.history().max(1).min(n);
        let d1 = if order >= 2 { last - past[n - 2] } else { 0.0 };
        let d2 = if order >= 3 {
            d1 - (past[n - 2] - past[n - 3])
        } else {
            0.0
        };
        for (j, o) in out.iter_mut().enumerate() {
            let m = (j + 1) as f64;
            *o = last + m * d1 + 0.5 * m * (m + 1.0) * d2;
        }
    }
}

impl FromStr for CommandExtrapolation {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        let t = s.trim().to_ascii_lowercase();
        CommandExtrapolation::ALL
            .into_iter()
            .find(|e| e.name() == t)
            .ok_or_else(|| Error::InvalidChoice {
                what: "command extrapolation",
                value: s.to_string(),
                expected: CommandExtrapolation::NAMES,
            })
    }
}

impl fmt::Display for CommandExtrapolation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Options of a [`super::Streamer`] beyond the window configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StreamOptions {
    /// Command lead of [`super::Streamer::push`] \[samples\]: the command on
    /// each pushed line belongs to the sample `command_lead` lines later (a
    /// CNC interpolator runs ahead of the measurement). Default 0 (the
    /// command of the line's own sample).
    pub command_lead: usize,
    /// Most commands [`super::Streamer::push_command`] accepts ahead of the
    /// positions \[samples\]; `None` = the larger of the horizon and the
    /// command lead (default).
    pub lookahead: Option<usize>,
    /// How the command over a horizon is filled where it has not arrived
    /// yet. Default [`CommandExtrapolation::Acceleration`].
    pub extrapolation: CommandExtrapolation,
    /// Nominal sample interval \[s\]; `None` = the running mean interval of
    /// the current segment (default).
    pub dt: Option<f64>,
    /// Relative deviation of an interval from the expected one beyond which
    /// it is reported as irregular (kept); beyond the larger of this and
    /// [`GAP_DEVIATION`] it is a gap. Default 0.01, as for a recording.
    pub jitter_tolerance: f64,
    /// Prediction intervals and outlier rejection, as in the batch engine;
    /// default [`GuardConfig::default`] (95 %).
    pub guard: GuardConfig,
}

impl Default for StreamOptions {
    fn default() -> Self {
        Self {
            command_lead: 0,
            lookahead: None,
            extrapolation: CommandExtrapolation::default(),
            dt: None,
            jitter_tolerance: DEFAULT_JITTER_TOLERANCE,
            guard: GuardConfig::default(),
        }
    }
}

impl StreamOptions {
    /// The command the runaway cut's hull is over, for a method that reads
    /// the horizon's command (`future`) or not, with horizons of `horizon`
    /// samples: measured where it is led far enough or awaited, the guard's
    /// own extrapolation where the method reads none, and none where the
    /// stream fills the horizon with its guess.
    pub fn command_basis(&self, future: bool, horizon: usize) -> CommandBasis {
        if !future {
            CommandBasis::Extrapolated
        } else if self.command_lead >= horizon || self.extrapolation == CommandExtrapolation::Wait {
            CommandBasis::Measured
        } else {
            CommandBasis::Other
        }
    }

    /// Check the values (a positive finite `dt`, a finite non-negative tolerance).
    pub fn validate(&self) -> Result<()> {
        self.guard.validate()?;
        if let Some(dt) = self.dt {
            if !(dt.is_finite() && dt > 0.0) {
                return Err(Error::InvalidParameter {
                    name: "dt",
                    value: dt,
                    reason: "must be finite and > 0",
                });
            }
        }
        if !(self.jitter_tolerance.is_finite() && self.jitter_tolerance >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "jitter tolerance",
                value: self.jitter_tolerance,
                reason: "must be finite and >= 0",
            });
        }
        if let Some(l) = self.lookahead {
            if l < self.command_lead {
                return Err(Error::InvalidParameter {
                    name: "lookahead",
                    value: l as f64,
                    reason: "must be at least the command lead",
                });
            }
        }
        Ok(())
    }

    /// The relative deviation beyond which an interval is a gap:
    /// `max(GAP_DEVIATION, jitter_tolerance)`.
    pub fn gap_deviation(&self) -> f64 {
        GAP_DEVIATION.max(self.jitter_tolerance)
    }
}

/// Two consecutive time stamps whose interval is not the expected one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jump {
    /// Time of the previous line (or position) \[s\].
    pub previous_time: f64,
    /// Time of this one \[s\].
    pub time: f64,
    /// The interval expected \[s\]: [`StreamOptions::dt`], else the mean
    /// interval of the segment so far.
    pub expected: f64,
}

impl Jump {
    /// The interval \[s\].
    pub fn interval(&self) -> f64 {
        self.time - self.previous_time
    }

    /// Samples missing in the interval (`round(interval / expected) − 1`),
    /// 0 for an interval shorter than expected.
    pub fn missing_samples(&self) -> usize {
        let r = (self.interval() / self.expected).round() - 1.0;
        if r >= 1.0 && r.is_finite() {
            // saturating: a huge jump is a huge number of missing samples
            r.min(usize::MAX as f64) as usize
        } else {
            0
        }
    }
}

/// The interval since the previous time stamp of the stream.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Interval {
    /// The expected interval within the jitter tolerance (or the first
    /// interval of a segment, which sets the expectation).
    Regular,
    /// Off by more than the jitter tolerance but less than a gap: kept, the
    /// windows go on across it (bridged).
    Irregular(Jump),
    /// Off by more than [`StreamOptions::gap_deviation`] — samples missing,
    /// a pause, a change of the sampling: the windows restart (see the module
    /// doc, *Gaps*).
    Gap(Jump),
}

/// What became of one pushed line or position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Arrival {
    /// The absolute index of the sample it became, or `None` for a line whose
    /// position was not used (one of the first `command_lead` lines of a
    /// segment: its own command was sent before the segment began).
    pub sample: Option<usize>,
    /// Its interval from the previous one.
    pub interval: Interval,
}

/// Where the command over a horizon comes from, for summaries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HorizonCommand {
    /// The estimator does not read the command over the horizon (the paper's
    /// polynomial prediction): predicted at the window end.
    NotRead,
    /// The command lead covers the horizon: the real command, at the window end.
    Known {
        /// The command lead \[samples\].
        lead: usize,
    },
    /// The first `known` samples of each horizon have their real command, the
    /// rest is extrapolated; predicted at the window end.
    Extrapolated {
        /// How.
        extrapolation: CommandExtrapolation,
        /// Horizon samples whose command has arrived at the window end (the command lead).
        known: usize,
    },
    /// Each window waits for its command ([`CommandExtrapolation::Wait`]):
    /// predicted `H − lead − 1` samples after the window end.
    Awaited {
        /// The command lead \[samples\].
        lead: usize,
    },
}

impl HorizonCommand {
    /// Whether every prediction is made at its window end, before any of its
    /// horizon has been measured.
    pub fn at_window_end(self) -> bool {
        !matches!(self, HorizonCommand::Awaited { .. })
    }
}

impl fmt::Display for HorizonCommand {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            HorizonCommand::NotRead => write!(f, "not read by the method"),
            HorizonCommand::Known { lead } => {
                write!(f, "known (command lead {lead} covers the horizon)")
            }
            HorizonCommand::Extrapolated {
                extrapolation,
                known,
            } => {
                if *known == 0 {
                    write!(f, "extrapolated: {}", extrapolation.describe())
                } else {
                    write!(
                        f,
                        "the first {known} samples known (command lead), the rest extrapolated: {}",
                        extrapolation.describe()
                    )
                }
            }
            HorizonCommand::Awaited { lead } => write!(
                f,
                "awaited (command lead {lead}, no extrapolation): predictions come after part of their horizon was measured"
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extrapolations_are_exact_on_the_polynomials_of_their_order() {
        let mut out = [0.0; 5];
        // hold: constants
        CommandExtrapolation::Hold.fill(&[3.0, 2.0], &mut out);
        assert_eq!(out, [2.0; 5]);
        // velocity: straight lines u = 2 + 3k, k = 0..3 → k = 3..8
        CommandExtrapolation::Velocity.fill(&[2.0, 5.0, 8.0], &mut out);
        assert_eq!(out, [11.0, 14.0, 17.0, 20.0, 23.0]);
        // acceleration: parabolas u = 1 − k + 0.5 k², k = 0..3
        let u = |k: f64| 1.0 - k + 0.5 * k * k;
        CommandExtrapolation::Acceleration.fill(&[u(0.0), u(1.0), u(2.0)], &mut out);
        for (j, o) in out.iter().enumerate() {
            assert!((o - u(3.0 + j as f64)).abs() < 1e-12, "{j}: {o}");
        }
        // fewer samples than the order: a lower order; none: unchanged
        CommandExtrapolation::Acceleration.fill(&[1.0, 2.0], &mut out);
        assert_eq!(out, [3.0, 4.0, 5.0, 6.0, 7.0]);
        CommandExtrapolation::Velocity.fill(&[4.0], &mut out);
        assert_eq!(out, [4.0; 5]);
        CommandExtrapolation::Velocity.fill(&[], &mut out);
        assert_eq!(out, [4.0; 5]);
        CommandExtrapolation::Wait.fill(&[1.0, 2.0], &mut out);
        assert_eq!(out, [2.0; 5]);
    }

    #[test]
    fn names_parse_back_and_unknown_names_list_the_choices() {
        for e in CommandExtrapolation::ALL {
            assert_eq!(e.name().parse::<CommandExtrapolation>().unwrap(), e);
        }
        let e = "cubic".parse::<CommandExtrapolation>().unwrap_err();
        assert!(e.to_string().contains(CommandExtrapolation::NAMES), "{e}");
    }

    #[test]
    fn jumps_count_their_missing_samples() {
        let j = |dt: f64| Jump {
            previous_time: 1.0,
            time: 1.0 + dt,
            expected: 0.1,
        };
        assert_eq!(j(0.2).missing_samples(), 1);
        assert_eq!(j(1.0).missing_samples(), 9);
        assert_eq!(j(0.04).missing_samples(), 0);
        assert_eq!(j(1e300).missing_samples(), usize::MAX);
    }

    #[test]
    fn options_are_validated() {
        StreamOptions::default().validate().unwrap();
        for o in [
            StreamOptions {
                dt: Some(0.0),
                ..Default::default()
            },
            StreamOptions {
                jitter_tolerance: f64::NAN,
                ..Default::default()
            },
            StreamOptions {
                command_lead: 5,
                lookahead: Some(4),
                ..Default::default()
            },
        ] {
            assert!(o.validate().is_err(), "{o:?}");
        }
        let o = StreamOptions {
            jitter_tolerance: 0.7,
            ..Default::default()
        };
        assert_eq!(o.gap_deviation(), 0.7);
        assert_eq!(StreamOptions::default().gap_deviation(), GAP_DEVIATION);
    }
}
