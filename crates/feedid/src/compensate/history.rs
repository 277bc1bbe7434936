//! The runs of a learned program: what each step did, and the best run so
//! far to return to ([`super::learn`]). Kept as a JSON file by `feedid
//! compensate --history`; a history is refused for another program (its
//! samples, interval and a fingerprint of the desired trajectory differ).

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// Format name of a learning history file.
pub const HISTORY_FORMAT: &str = "feedid-learning-history";
/// Version of the learning history format.
pub const HISTORY_VERSION: u32 = 1;

/// What the learning step did.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum LearnStatus {
    /// No earlier run known: a step from this run.
    First,
    /// The run is no worse than the best so far: a step from it.
    Improving,
    /// The run's rms is within 1.25× its noise: nothing can be told from
    /// the noise, the same command is sent again.
    AtNoise,
    /// The run was worse than the best: the step is taken again from the
    /// best run with half the gain and twice the noise filter.
    Damped {
        /// The best run so far.
        best_run: usize,
        /// Its measured rms \[m\].
        best_rms_m: f64,
    },
    /// The last step lowered the error by less than a tenth of what the
    /// model predicted for it, or the model expects the next to lower it by
    /// less than a tenth: what is left is not what the model can correct,
    /// and the best run's command is sent again (in every later step too).
    Settled {
        /// The best run so far, whose command is sent again.
        best_run: usize,
        /// Its measured rms \[m\].
        best_rms_m: f64,
        /// Share of the predicted reduction of the rms that the last step
        /// achieved; `None` when it is the next step that the model
        /// expected to lower the rms by less than a tenth.
        achieved_share: Option<f64>,
    },
    /// The error kept growing after the gain was halved the most allowed:
    /// the best run's command is sent again.
    Stopped {
        /// The best run so far, whose command is sent again.
        best_run: usize,
        /// Its measured rms \[m\].
        best_rms_m: f64,
    },
}

/// One measured run of a learning history.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LearningRun {
    /// Run number (1: the first run measured).
    pub run: usize,
    /// RMS of desired − measured \[m\].
    pub measured_rms_m: f64,
    /// Largest |desired − measured| \[m\].
    pub measured_max_m: f64,
    /// Noise level of the measured error \[m\] (module doc).
    pub noise_m: f64,
    /// What the step after this run did.
    pub status: LearnStatus,
    /// Learning gain decided for that step (before any halving for the
    /// limits; 0 when stopped).
    pub gain: f64,
    /// σ of its noise filter \[s\].
    pub noise_filter_s: f64,
    /// The model's prediction of the next run's rms, noise-free \[m\].
    pub predicted_next_rms_m: f64,
    /// The axis's measured response to the step before, relative to the
    /// model's (`None`: not measurable).
    #[serde(default)]
    pub response_ratio: Option<f64>,
}

/// The best run so far: what a damped step starts from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BestRun {
    /// Its run number.
    pub run: usize,
    /// Its measured rms \[m\].
    pub measured_rms_m: f64,
    /// The command sent in it \[m\].
    pub command: Vec<f64>,
    /// Its measured error, wild samples held (not noise filtered) \[m\].
    pub error: Vec<f64>,
}

/// The runs of one program so far (the file `--history` keeps).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LearningHistory {
    /// Always [`HISTORY_FORMAT`].
    pub format: String,
    /// [`HISTORY_VERSION`].
    pub version: u32,
    /// Samples of the desired trajectory.
    pub samples: usize,
    /// Its sample interval \[s\].
    pub dt: f64,
    /// Its first and last value and its mean \[m\] (to recognise it).
    pub desired_fingerprint: [f64; 3],
    /// The measured runs, oldest first.
    pub runs: Vec<LearningRun>,
    /// The best run so far.
    pub best: Option<BestRun>,
    /// The run before this one (its command and error): how the axis
    /// answered the last step.
    #[serde(default)]
    pub last: Option<BestRun>,
}

impl LearningHistory {
    /// An empty history of the program `desired` at interval `dt` \[s\].
    pub fn new(desired: &[f64], dt: f64) -> Self {
        Self {
            format: HISTORY_FORMAT.to_string(),
            version: HISTORY_VERSION,
            samples: desired.len(),
            dt,
            desired_fingerprint: fingerprint(desired),
            runs: Vec::new(),
            best: None,
            last: None,
        }
    }

    /// Check that the history is of this program (format, samples, interval,
    /// fingerprint) and well formed.
    pub fn check(&self, desired: &[f64], dt: f64) -> Result<()> {
        if self.format != HISTORY_FORMAT || self.version != HISTORY_VERSION {
            return Err(Error::HistoryMismatch {
                what: "format version",
                history: self.version as f64,
                actual: HISTORY_VERSION as f64,
            });
        }
        if self.samples != desired.len() {
            return Err(Error::HistoryMismatch {
                what: "number of samples",
                history: self.samples as f64,
                actual: desired.len() as f64,
            });
        }
        if (self.dt - dt).abs() > 1e-9 * dt {
            return Err(Error::HistoryMismatch {
                what: "sample interval (s)",
                history: self.dt,
                actual: dt,
            });
        }
        let f = fingerprint(desired);
        let scale = desired
            .iter()
            .fold(0.0_f64, |m, v| m.max(v.abs()))
            .max(1e-300);
        for (what, a, b) in [
            ("first desired value (m)", self.desired_fingerprint[0], f[0]),
            ("last desired value (m)", self.desired_fingerprint[1], f[1]),
            ("mean desired value (m)", self.desired_fingerprint[2], f[2]),
        ] {
            if (a - b).is_nan() || (a - b).abs() > 1e-9 * scale {
                return Err(Error::HistoryMismatch {
                    what,
                    history: a,
                    actual: b,
                });
            }
        }
        for (what, run) in [("best run", &self.best), ("run before", &self.last)] {
            let Some(b) = run else { continue };
            if b.command.len() != desired.len() || b.error.len() != desired.len() {
                return Err(Error::HistoryMismatch {
                    what: "samples of a run kept",
                    history: b.command.len().min(b.error.len()) as f64,
                    actual: desired.len() as f64,
                });
            }
            if let Some(i) = b
                .command
                .iter()
                .chain(&b.error)
                .position(|v| !v.is_finite())
            {
                return Err(Error::NonFinite {
                    channel: format!("learning history's {what}"),
                    index: i % desired.len(),
                    value: f64::NAN,
                });
            }
        }
        Ok(())
    }
}

fn fingerprint(desired: &[f64]) -> [f64; 3] {
    let n = desired.len().max(1) as f64;
    [
        desired.first().copied().unwrap_or(0.0),
        desired.last().copied().unwrap_or(0.0),
        desired.iter().sum::<f64>() / n,
    ]
}
