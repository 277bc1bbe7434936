//! Learning from measured runs: iterative learning control (ILC) of the
//! command of a repeated program, with the identified model as its learning
//! filter.
//!
//! A machine tool repeats its programs, and the measured tracking error of
//! the last run is the best information there is about the next. With the
//! desired trajectory `y_d`, the command `u_j` sent in run `j` and the
//! measured position `y_j`, the update with the model `G` (rescaled to unit
//! DC gain as [`super::compensate_model`] uses it) is the model-inverse ILC
//! (Arimoto, Kawamura & Miyazaki 1984; Bristow, Tharayil & Alleyne, "A
//! survey of iterative learning control", IEEE Control Systems Magazine
//! 26(3), 2006):
//!
//! ```text
//! e_j     = y_d − y_j                                (measured tracking error)
//! ẽ_j     = N·H(e_j)                                 (wild samples held, noise filtered)
//! u_{j+1} = u_j + α·G⁻¹·ẽ_j
//! ```
//!
//! The step `G⁻¹·ẽ_j` is the compensation ([`super::compensate_model`]) of
//! `ẽ_j` as a trajectory, `Δ = ẽ + F·(G⁻¹ − 1)·ẽ`: the stable inverse
//! (anti-causal for zeros outside the unit circle) with a zero-phase
//! Gaussian smoothing `F` of the step only — the last command is kept as it
//! was sent. σ of `F` starts at 0 and is raised (the compensation's σ
//! levels, up to [`super::CompensateConfig::max_smoothing`]) only until the
//! new command meets the velocity and acceleration limits (or is no worse
//! than the last one where that one exceeds them), the step held back
//! locally where it still would not (`(1 − W)·Δ`, `W` a smooth window around
//! those samples; [`Learning::held_back_share`]); when no σ allowed does,
//! the gain is halved (up to [`LearnConfig::max_halvings`] times,
//! [`Learning::gain_limited`]). Where the program rests at its start
//! ([`StartMode::Rest`]) nothing is learned before it moves, and the error
//! learned eases in over `8 + 8σ` samples after it starts to (a kink of the
//! noise there would ask the inverse for an unbounded command that the
//! smoothing, which may not move anything before the first sample, cannot
//! round).
//!
//! **Trust in the model.** The share of the base run's error that the model
//! explains, `1 − ‖y − ŷ‖/‖e − ē‖` (`ŷ` the model's position for the
//! command sent), scales the step's gain (clamped to
//! \[[`LearnConfig::min_trust`], 1\], default ¼): a model as
//! wrong as the axis's own error cannot be relied on to correct it. On the
//! drive zoo the compensated run's error is mostly what the model did not
//! predict (the share is near 0 on most axes), and a first step of a
//! quarter of the gain grows the error on fewer axes than one of half (8
//! against 14 of 120) at the cost of two axes at the target within five
//! runs (72 against 74; the answer below sets every later step).
//!
//! **The axis's answer.** From the second step on, the measured change of
//! the error between the last two runs is compared with the model's
//! prediction of it (`Δe` against `Δê = −G·(u_j − u_{j−1})`): their
//! least-squares ratio `ρ = <Δe, Δê>/‖Δê‖²` is how strongly the axis answers
//! relative to the model, and the step is scaled by `1/ρ` (clamped to
//! \[½, 2\], above 1 only after a run whose error shrank) instead of the
//! trust above — a model with twice the axis's
//! gain then converges in one more run instead of halving the error each
//! run (above 1 only where the axis answered as predicted on at least half
//! the samples, below: elsewhere the ratio measures the misfit, not the
//! gain). A ratio at or below 0.1 (the step did not act as predicted) or a
//! change lost in the noise leaves the trust.
//!
//! **The robustness filter** (the Q-filter of ILC, chosen from the model's
//! measured error): the same two changes, `Δe` and `Δê`, smoothed with the
//! zero-phase Gaussian `L_σ` of each of the compensation's σ levels from 0
//! up, are compared in shape — `‖L·Δe − ρ·L·Δê‖ ≤ ½·‖L·Δe‖` at their
//! least-squares ratio `ρ` (three quarters of the change's energy predicted,
//! the band where `|Δ|` is small enough to learn in). The smallest σ that
//! passes (the largest allowed, [`super::CompensateConfig::max_smoothing`],
//! when none does) is a floor of the step's filter
//! ([`Learning::robustness_filter_s`]): what the axis did not answer as the
//! model predicted — a delay, a mode, friction at the stops — is not learned
//! again.
//!
//! **Where the axis answered.** What the axis does not answer as predicted
//! (friction at a stop, backlash at a reversal, the current limit at a
//! corner) lives at some samples, not in a band: the same two changes,
//! smoothed with the robustness filter, are compared locally, in a Gaussian
//! window `W` of the model's slowest time constant (`−1/ln|p|` samples, at
//! least 2):
//!
//! ```text
//! w_k = 1 − √( W·(L·Δe − ρ·L·Δê)² / W·½((L·Δe)² + ρ²(L·Δê)²) )_k   clamped to [0, 1]
//! ```
//!
//! (1 where the axis moved as predicted, 0 where it did not move as asked;
//! 1 where neither changed), and the error learned is `w·ẽ`: what the axis
//! did not answer is not learned again, and stays in the prediction of the
//! next run ([`Learning::unanswered_share`]: the samples with `w < ½`).
//!
//! **Convergence.** With the axis `P = G·(1 + Δ)` the noise-free tracking
//! error of the next run is `ε_{j+1} = (1 − α·(1 + Δ))·ε_j` at each
//! frequency the filters pass, so the error shrinks monotonically where
//! `|1 − α(1 + Δ)| < 1`: for `α = 1` wherever the model's relative error
//! `|Δ| < 1` — a model off by a factor 2 in gain still converges (half the
//! error each run), one with twice the gain oscillates. Where the model is
//! wrong at high frequency (a delay, a resonance) the error there grows.
//!
//! **Noise.** `G⁻¹` has a large high-frequency gain, so the measurement
//! noise of `e_j` must not reach it: `N` is a zero-phase Gaussian smoothing
//! whose σ is chosen by Morozov's discrepancy principle — the largest σ (of
//! 0, ½, 1, 1½, 2, 3, 4, 6, … samples) for which what it removes,
//! `rms(e − N·e)`, is no more than the noise level `σ̂` (estimated from the
//! second differences of `e`, median absolute deviation, so that a smooth
//! error and a few corners do not count as noise). Isolated wild samples
//! (`|e_k − median₅(e)_k| > 6σ̂`, Hampel's identifier) are replaced by the
//! local median first. With noise of variance `σ²` and `α`, the stationary
//! noise-driven error is `α·var(N·n)/(2 − α)`, below the noise itself.
//!
//! **Monotone convergence is checked.** With a history of the earlier runs
//! ([`LearningHistory`]) each measured run is compared with the best run so
//! far: when its rms grew by more than [`LearnConfig::growth_tolerance`]
//! (relative) plus a tenth of the noise, the step is taken again **from the
//! best run** (its command and filtered error are in the history) with half
//! the gain and twice the noise filter ([`LearnStatus::Damped`]); after
//! [`LearnConfig::max_halvings`] halvings the learning stops and the best
//! run's command is sent again ([`LearnStatus::Stopped`]), and in every
//! later step of that history.
//!
//! **The learning settles** ([`LearnStatus::Settled`]: the best run's
//! command again, in every later step) when what is left is not what the
//! model can correct — a step is a chance to grow the error, and one the
//! model does not expect to pay is not taken:
//! - the last step achieved less than a tenth of the reduction of the rms
//!   the model predicted for it, `(r_{j−1} − r_j) < 0.1·(r_{j−1} − r̂_j)`,
//!   and the model did not predict the axis's answer to it in shape in any
//!   band (the robustness filter found none; a wrong gain alone, whose
//!   answer has the predicted shape, is corrected by the ratio instead);
//! - or the model expects the next step to lower the rms by less than a
//!   tenth.
//!
//! On the drive zoo (`zoo_compensate --runs 5`) these rules take the axes
//! whose error grows in some run from 42 to 6 of 120, and the axes at the
//! target within five runs from 68 to 70 (docs/RESULTS.md).
//!
//! A run whose rms is within 1.25× its noise level is **at the noise**: what
//! is left cannot be told from the noise, and the same command is sent again
//! ([`LearnStatus::AtNoise`]) — learning the noise would only add it.
//!
//! **The next run's error** is predicted with the model and the axis's
//! measured answer: `e_{j+1} ≈ ẽ_j − ρ·G·(u_{j+1} − u_j)` (`ρ` = 1 before
//! an answer, `ẽ_j` the filtered error before the local weight), its rms
//! noise-free and, with the noise `σ̂`, as it will be measured `√(rms² +
//! σ̂²)`.
//!
//! ```
//! use feedid::compensate::{learn, LearnConfig, LearnStatus};
//! use feedid::ident::LinearModel;
//! // the axis: a lag with one sample of delay; the model: 30 % too slow
//! let axis = LinearModel::discrete(vec![0.0, 0.2], vec![1.0, -0.8], 1e-3).unwrap();
//! let model = LinearModel::discrete(vec![0.0, 0.14], vec![1.0, -0.86], 1e-3).unwrap();
//! let desired: Vec<f64> = (0..400)
//!     .map(|k| 1e-3 * ((k as f64 - 50.0) / 200.0).clamp(0.0, 1.0))
//!     .collect();
//! let cfg = LearnConfig::exact();
//! let mut command = desired.clone();
//! let mut history = None;
//! let mut rms = Vec::new();
//! for _ in 0..6 {
//!     let y = axis.simulate(&command).unwrap();
//!     let step = learn(&model, &desired, &command, &y, 1e-3, &cfg, history.as_ref()).unwrap();
//!     rms.push(step.measured.rms);
//!     command = step.command;
//!     history = Some(step.history);
//! }
//! assert!(rms[5] < 1e-2 * rms[0], "{rms:?}");
//! ```

use serde::Serialize;

use super::answer::{Answer, MIN_RESPONSE};
use super::command::{model_settle, CompensateConfig, StartMode};
use super::history::{BestRun, LearnStatus, LearningHistory, LearningRun};
use super::smoothing::gaussian_smooth;
use super::step::{increment, CommandPeaks};
use crate::error::{Error, Result};
use crate::ident::LinearModel;
use crate::lti::DiscreteStateSpace;
use crate::stats::{error_fit_percent, median, noise_level_of_run, ErrorStats};

/// How the measured error is filtered before it is learned.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum NoiseFilter {
    /// σ by the discrepancy principle from the run's own noise (default).
    Auto,
    /// One σ \[s\] (0: none).
    Fixed(f64),
}

/// Settings of a learning step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LearnConfig {
    /// Learning gain α of the first step (0 < α < 2); default 1.
    pub gain: f64,
    /// Noise filter of the measured error; default [`NoiseFilter::Auto`].
    pub noise_filter: NoiseFilter,
    /// A run is worse than the best so far when its rms exceeds the best's
    /// by more than this share (plus a tenth of the noise); default 0.01.
    pub growth_tolerance: f64,
    /// Halvings of the gain after which the learning stops; default 3.
    pub max_halvings: u32,
    /// Smallest factor of the gain for a model that explains little of the
    /// run's error (module doc, 1: the gain as decided); default 0.25.
    pub min_trust: f64,
    /// Ease the learned error in after a rest start (module doc); default true.
    pub ease_start: bool,
    /// Limits, smoothing, start and DC gain of the command, as for
    /// [`super::compensate_model`] (its fall-back settings do not apply:
    /// the measured runs, not the model's fit, decide).
    pub compensate: CompensateConfig,
}

impl Default for LearnConfig {
    fn default() -> Self {
        Self {
            gain: 1.0,
            noise_filter: NoiseFilter::Auto,
            growth_tolerance: 0.01,
            max_halvings: 3,
            min_trust: 0.25,
            ease_start: true,
            compensate: CompensateConfig::default(),
        }
    }
}

impl LearnConfig {
    /// No limits, no smoothing, no noise filter, no easing, the gain as
    /// given: the plain ILC update (for noise-free data and tests).
    pub fn exact() -> Self {
        Self {
            noise_filter: NoiseFilter::Fixed(0.0),
            min_trust: 1.0,
            ease_start: false,
            compensate: CompensateConfig {
                smoothing: super::Smoothing::Fixed(0.0),
                max_velocity: f64::INFINITY,
                max_acceleration: f64::INFINITY,
                ..CompensateConfig::default()
            },
            ..Self::default()
        }
    }

    /// Check the settings.
    pub fn validate(&self) -> Result<()> {
        if !(self.gain > 0.0 && self.gain < 2.0) {
            return Err(Error::InvalidParameter {
                name: "learning gain",
                value: self.gain,
                reason: "must be > 0 and < 2 (1: the model's full correction)",
            });
        }
        if let NoiseFilter::Fixed(s) = self.noise_filter {
            if !(s.is_finite() && s >= 0.0) {
                return Err(Error::InvalidParameter {
                    name: "noise filter",
                    value: s,
                    reason: "must be finite and >= 0 (s)",
                });
            }
        }
        if !(self.growth_tolerance.is_finite() && self.growth_tolerance >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "growth tolerance",
                value: self.growth_tolerance,
                reason: "must be finite and >= 0",
            });
        }
        if !(self.min_trust > 0.0 && self.min_trust <= 1.0) {
            return Err(Error::InvalidParameter {
                name: "min trust",
                value: self.min_trust,
                reason: "must be > 0 and <= 1",
            });
        }
        if self.max_halvings > 30 {
            return Err(Error::InvalidParameter {
                name: "max halvings",
                value: self.max_halvings as f64,
                reason: "must be <= 30",
            });
        }
        self.compensate.validate()
    }
}

/// The command for the next run and what the last run showed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Learning {
    /// The command for the next run \[m\].
    #[serde(skip)]
    pub command: Vec<f64>,
    /// The model's prediction of the next run's position \[m\].
    #[serde(skip)]
    pub predicted: Vec<f64>,
    /// Number of the run measured (1 without a history).
    pub run: usize,
    /// Desired − measured of that run \[m\] (`fit_percent` against the desired).
    pub measured: ErrorStats,
    /// Its noise level \[m\] (module doc).
    pub noise_m: f64,
    /// Wild samples held in the measured error.
    pub wild_samples: usize,
    /// The previous run's measured rms, when the history has it \[m\].
    pub previous_rms_m: Option<f64>,
    /// What the step did.
    pub status: LearnStatus,
    /// Learning gain of the step.
    pub gain: f64,
    /// True when the gain was halved (from the history's or the settings')
    /// to keep the command within its limits (gain 0: no step could).
    pub gain_limited: bool,
    /// σ of the filter of the step \[s\]: the noise filter, and at least
    /// [`Learning::robustness_filter_s`].
    pub noise_filter_s: f64,
    /// σ of the robustness filter (module doc) \[s\]: the smoothing at which
    /// the axis's answer to the last step agreed in shape with the model's
    /// prediction; 0 for the first step, or when every band agreed.
    pub robustness_filter_s: f64,
    /// Share of the samples after the program starts to move where the
    /// axis did not answer the last step as the model predicted (local
    /// misfit above half the change, module doc): little or nothing of
    /// their error is learned again; 0 for the first step.
    pub unanswered_share: f64,
    /// Share of the base run's error the model explains (`1 − ‖y − ŷ‖/‖e − ē‖`);
    /// the step's gain is the decided one times this, clamped to
    /// \[[`LearnConfig::min_trust`], 1\].
    pub explained_share: f64,
    /// The axis's answer to the step before this run relative to the
    /// model's prediction of it (`<Δe, Δê>/‖Δê‖²`, module doc); `None`
    /// without a run before or when the step was lost in the noise.
    pub response_ratio: Option<f64>,
    /// The model's prediction of the next run's rms error, noise-free \[m\].
    pub predicted_next_rms_m: f64,
    /// The same as it will be measured, with the noise \[m\].
    pub predicted_next_measured_rms_m: f64,
    /// σ of the zero-phase smoothing of the step (raised only to keep the
    /// command within its limits) \[s\].
    pub step_smoothing_s: f64,
    /// Share of the samples where the step was held back to keep the
    /// command within its limits (nothing learned there this run; for a
    /// step not taken because the learning settled, the share it would
    /// have been held back on).
    pub held_back_share: f64,
    /// Peak velocity and acceleration of the command and their times.
    pub peaks: CommandPeaks,
    /// The history with this run added.
    #[serde(skip)]
    pub history: LearningHistory,
}

/// A run whose rms is at most this many times its noise level is at the
/// noise: what is left cannot be told from the noise, and is not learned.
const AT_NOISE: f64 = 1.25;

/// The share of a run's tracking error the model explains:
/// `1 − ‖y − ŷ‖ / ‖e − ē‖` with the run's position `y = y_d − e` and the
/// model's `ŷ` for its command (`−∞…1`; 1 when there is no error).
fn explained_share(desired: &[f64], error: &[f64], model: &[f64]) -> f64 {
    let residual: Vec<f64> = (0..error.len())
        .map(|k| desired[k] - error[k] - model[k])
        .collect();
    error_fit_percent(&residual, error, 0.0).map_or(1.0, |f| f / 100.0)
}

/// A step that achieved less than this share of the reduction of the rms
/// the model predicted for it settles the learning (module doc).
const MIN_ACHIEVED: f64 = 0.1;

/// A step the model expects to lower the rms by less than this share is not
/// taken: the learning settles (module doc).
const MIN_PREDICTED_GAIN: f64 = 0.1;

/// The slowest time constant of the model \[samples\], `−1/ln|p|` of its
/// pole of largest modulus (1 for a model without poles).
fn slowest_time_constant(sys: &DiscreteStateSpace) -> Result<f64> {
    let r = sys.poles()?.iter().fold(0.0_f64, |m, p| m.max(p.norm()));
    Ok(if r > 0.0 && r < 1.0 {
        -1.0 / r.ln()
    } else {
        1.0
    })
}

/// Multiplier of the noise level for a wild sample (Hampel's identifier).
const WILD: f64 = 6.0;

/// One learning step (module doc): `desired`, the command `sent` in the run
/// and its `measured` position, one value per sample at interval `dt` \[s\];
/// `history` the earlier runs of the same program (`None`: the first).
pub fn learn(
    model: &LinearModel,
    desired: &[f64],
    sent: &[f64],
    measured: &[f64],
    dt: f64,
    cfg: &LearnConfig,
    history: Option<&LearningHistory>,
) -> Result<Learning> {
    cfg.validate()?;
    let n = desired.len();
    if n < 10 {
        return Err(Error::TooFewSamples {
            what: "a learning step",
            needed: 10,
            actual: n,
        });
    }
    for (what, v) in [("sent command", sent), ("measured position", measured)] {
        if v.len() != n {
            return Err(Error::LengthMismatch {
                what,
                expected: n,
                actual: v.len(),
            });
        }
    }
    for (channel, v) in [
        ("desired", desired),
        ("sent command", sent),
        ("measured position", measured),
    ] {
        if let Some(i) = v.iter().position(|x| !x.is_finite()) {
            return Err(Error::NonFinite {
                channel: channel.to_string(),
                index: i,
                value: v[i],
            });
        }
    }
    if !(dt.is_finite() && dt > 0.0) {
        return Err(Error::InvalidParameter {
            name: "sample interval",
            value: dt,
            reason: "must be finite and > 0 (s)",
        });
    }
    let mut history = match history {
        Some(h) => {
            h.check(desired, dt)?;
            h.clone()
        }
        None => LearningHistory::new(desired, dt),
    };
    let run = history.runs.last().map_or(1, |r| r.run + 1);
    let previous_rms_m = history.runs.last().map(|r| r.measured_rms_m);

    // the measured error, its noise and its wild samples
    let raw: Vec<f64> = desired.iter().zip(measured).map(|(d, y)| d - y).collect();
    let noise = noise_level_of_run(&raw, measured);
    let (error, wild_samples) = hold_wild(&raw, noise);
    let stats = ErrorStats::from_pairs(desired.iter().copied().zip(measured.iter().copied()));

    // the model as the compensation uses it
    let comp_cfg = CompensateConfig {
        fallback: false,
        ..cfg.compensate
    };
    let sys = model.discrete_state_space(Some(dt))?;
    let g_dc = sys.dc_gain()?;
    if !(g_dc.is_finite() && g_dc.abs() > 1e-12) {
        return Err(Error::InvalidModel {
            reason: "the model's DC gain is zero or infinite; a position model must have a finite non-zero DC gain",
        });
    }
    let out_scale = if comp_cfg.unit_dc_gain {
        1.0 / g_dc
    } else {
        1.0
    };
    // the axis's measured answer to the last step beside the model's
    // prediction of it
    let answer = match &history.last {
        Some(last) => Answer::new(
            (
                &error,
                &simulate_run(&sys, sent, out_scale, g_dc, comp_cfg.start)?,
            ),
            (
                &last.error,
                &simulate_run(&sys, &last.command, out_scale, g_dc, comp_cfg.start)?,
            ),
            noise,
        ),
        None => None,
    };
    // the robustness filter: only the band in which the axis answered the
    // last step as the model predicted is learned
    let robust_sigma = answer
        .as_ref()
        .map(|a| a.robustness_sigma(comp_cfg.max_smoothing / dt));
    // the model predicted the answer in shape in some band (its size may
    // differ: a wrong gain is corrected by the ratio)
    let answer_explained = matches!(robust_sigma, Some(Some(_)));
    let robust_sigma = match robust_sigma {
        Some(s) => s.unwrap_or(comp_cfg.max_smoothing / dt),
        None => 0.0,
    };

    // the decision against the best run so far
    let last_gain = history.runs.last().map(|r| r.gain);
    let last_filter = history.runs.last().map(|r| r.noise_filter_s);
    // the best run so far with this one: (run, rms, command, error)
    let best_with_this = || match &history.best {
        Some(b) if b.measured_rms_m <= stats.rms => {
            (b.run, b.measured_rms_m, b.command.clone(), b.error.clone())
        }
        _ => (run, stats.rms, sent.to_vec(), error.clone()),
    };
    let grew = history
        .best
        .as_ref()
        .is_some_and(|b| stats.rms > b.measured_rms_m * (1.0 + cfg.growth_tolerance) + 0.1 * noise);
    // the share of the reduction the model predicted for the last step
    // that it achieved (from the run it was taken from: the best one for a
    // damped step)
    let achieved = history.runs.last().and_then(|r| {
        let from = match r.status {
            LearnStatus::Damped { best_rms_m, .. } => best_rms_m,
            _ => r.measured_rms_m,
        };
        let want = from - r.predicted_next_rms_m.hypot(noise);
        (r.gain > 0.0 && want > 0.0).then(|| (from - stats.rms) / want)
    });
    let settles = !grew
        && !answer_explained
        && stats.rms > AT_NOISE * noise
        && achieved.is_some_and(|s| s < MIN_ACHIEVED);
    let stopped = history
        .runs
        .last()
        .is_some_and(|r| matches!(r.status, LearnStatus::Stopped { .. }));
    let settled = history.runs.last().and_then(|r| match r.status {
        LearnStatus::Settled { achieved_share, .. } => Some(achieved_share),
        _ => None,
    });
    // the last damped or learning gain (a run at the noise took no step)
    let last_gain = history
        .runs
        .iter()
        .rev()
        .find(|r| r.gain > 0.0 || matches!(r.status, LearnStatus::Stopped { .. }))
        .map(|r| r.gain)
        .or(last_gain);
    let halvings = |g: f64| (cfg.gain / g).log2().round().max(0.0) as u32;
    let (status, gain, base_cmd, base_err, filter_floor) = match (&history.best, grew) {
        // the best run's command again: this run's when it is the best
        (Some(_), _) if !stopped && (settled.is_some() || settles) => {
            let (best_run, best_rms_m, command, error) = best_with_this();
            let status = LearnStatus::Settled {
                best_run,
                best_rms_m,
                achieved_share: settled.unwrap_or(achieved),
            };
            (status, 0.0, command, error, 0.0)
        }
        (Some(b), worse) if worse || stopped => {
            let g = 0.5 * last_gain.unwrap_or(cfg.gain);
            if stopped || halvings(g) > cfg.max_halvings {
                (
                    LearnStatus::Stopped {
                        best_run: b.run,
                        best_rms_m: b.measured_rms_m,
                    },
                    0.0,
                    b.command.clone(),
                    b.error.clone(),
                    0.0,
                )
            } else {
                (
                    LearnStatus::Damped {
                        best_run: b.run,
                        best_rms_m: b.measured_rms_m,
                    },
                    g,
                    b.command.clone(),
                    b.error.clone(),
                    (2.0 * last_filter.unwrap_or(0.0)).max(dt),
                )
            }
        }
        (best, _) => {
            let first = best.is_none();
            let at_noise = stats.rms <= AT_NOISE * noise;
            let status = if at_noise {
                LearnStatus::AtNoise
            } else if first {
                LearnStatus::First
            } else {
                LearnStatus::Improving
            };
            // a damped gain is kept while the runs improve; at the noise
            // there is nothing left to learn: the same command again
            let g = if at_noise {
                0.0
            } else {
                history
                    .runs
                    .iter()
                    .rev()
                    .map(|r| r.gain)
                    .find(|g| *g > 0.0)
                    .unwrap_or(cfg.gain)
            };
            // and so is a damped step's noise filter
            let floor = history
                .runs
                .iter()
                .rev()
                .find(|r| matches!(r.status, LearnStatus::Damped { .. }))
                .map_or(0.0, |r| r.noise_filter_s);
            (status, g, sent.to_vec(), error.clone(), floor)
        }
    };

    // the model's prediction of the base run
    let y_base = simulate_run(&sys, &base_cmd, out_scale, g_dc, comp_cfg.start)?;
    // the share of the base run's error that the model explains scales the
    // gain: a model as wrong as the axis's own error cannot correct it
    let explained = explained_share(desired, &base_err, &y_base);
    let trust = explained.clamp(cfg.min_trust, 1.0);
    let response_ratio = answer.as_ref().map(Answer::ratio);
    // a larger step only after one that lowered the error
    let shrank = previous_rms_m.is_some_and(|p| stats.rms < p);
    let scale_step = |unanswered: f64| match response_ratio {
        // and only where the axis answered the last step as predicted on
        // most samples (elsewhere the ratio measures the misfit, not the gain)
        Some(r) if r > MIN_RESPONSE => {
            let boost = shrank && unanswered < 0.5;
            (1.0 / r).clamp(0.5, if boost { 2.0 } else { 1.0 })
        }
        _ => trust,
    };

    let sigma = match cfg.noise_filter {
        NoiseFilter::Fixed(s) => s / dt,
        NoiseFilter::Auto => discrepancy_sigma(&base_err, noise),
    }
    .max(filter_floor / dt)
    .max(robust_sigma);
    let mut filtered = vec![0.0; n];
    gaussian_smooth(&base_err, sigma, &mut filtered);
    // before the program moves the axis rests: nothing to learn there but
    // noise (and a step into the learned error would ask the inverse for an
    // unbounded command at the very start); the step eases in from there
    let scale = desired
        .iter()
        .fold(0.0_f64, |m, v| m.max((v - desired[0]).abs()));
    let moves = match comp_cfg.start {
        StartMode::Rest => desired
            .iter()
            .position(|v| (v - desired[0]).abs() > 1e-12 * scale)
            .unwrap_or(n),
        StartMode::Moving => 0,
    };
    filtered[..moves].fill(0.0);

    // where the axis did not answer the last step as the model predicted,
    // its error is not learned again (the prediction of the next run keeps
    // it: it stays)
    let kept = filtered.clone();
    let mut unanswered_share = 0.0;
    if let Some(a) = &answer {
        let window = slowest_time_constant(&sys)?.clamp(2.0, n as f64 / 8.0);
        let w = a.local_weight(robust_sigma, window);
        let mut low = 0;
        for k in moves..n {
            filtered[k] *= w[k];
            if w[k] < 0.5 {
                low += 1;
            }
        }
        if n > moves {
            unanswered_share = low as f64 / (n - moves) as f64;
        }
    }

    let scale_step = scale_step(unanswered_share);
    let mut decided_gain = gain;
    let (command, gain, step_sigma, gain_limited, held_share) = if gain > 0.0 {
        match increment(
            model,
            &base_cmd,
            &filtered,
            moves,
            dt,
            cfg,
            gain * scale_step,
        )? {
            Some(st) => (
                st.command,
                st.gain,
                st.sigma,
                st.gain < gain * scale_step,
                st.held_share,
            ),
            None => (base_cmd.clone(), 0.0, 0.0, true, 0.0),
        }
    } else {
        // stopped (the best run's command) or at the noise (this run's) again
        (base_cmd.clone(), 0.0, 0.0, false, 0.0)
    };
    if let Some(i) = command.iter().position(|v| !v.is_finite()) {
        return Err(Error::NonFinite {
            channel: "learned command".to_string(),
            index: i,
            value: command[i],
        });
    }
    // e_{j+1} ≈ ẽ − ρ·(ŷ_{j+1} − ŷ_base) on the base run's filtered error,
    // ρ the axis's measured answer relative to the model (1 before one)
    let answers = match response_ratio {
        Some(r) if r > MIN_RESPONSE => r,
        _ => 1.0,
    };
    let next_rms = |command: &[f64]| -> Result<(Vec<f64>, f64)> {
        let predicted = simulate_run(&sys, command, out_scale, g_dc, comp_cfg.start)?;
        let mut ss = 0.0;
        for k in 0..n {
            let e = kept[k] - answers * (predicted[k] - y_base[k]);
            ss += e * e;
        }
        Ok((predicted, (ss / n as f64).sqrt()))
    };
    let (mut predicted, mut predicted_next_rms_m) = next_rms(&command)?;
    // a step the model expects to lower the rms by less than a tenth is not
    // worth its risk: the best run's command again (what held it back, the
    // limits or the model, stays in the report)
    let from_rms = match status {
        LearnStatus::Damped { best_rms_m, .. } => best_rms_m,
        _ => stats.rms,
    };
    let (mut status, mut command, mut gain, mut gain_limited) =
        (status, command, gain, gain_limited);
    if gain > 0.0 && predicted_next_rms_m.hypot(noise) > (1.0 - MIN_PREDICTED_GAIN) * from_rms {
        let (best_run, best_rms_m, best_cmd, _) = best_with_this();
        status = LearnStatus::Settled {
            best_run,
            best_rms_m,
            achieved_share: None,
        };
        command = best_cmd;
        gain = 0.0;
        decided_gain = 0.0;
        gain_limited = false;
        (predicted, predicted_next_rms_m) = next_rms(&command)?;
    }
    let peaks = CommandPeaks::of(&command, dt, comp_cfg.start);
    let predicted_next_measured_rms_m = predicted_next_rms_m.hypot(noise);
    let noise_filter_s = sigma * dt;

    history.runs.push(LearningRun {
        run,
        measured_rms_m: stats.rms,
        measured_max_m: stats.max_abs,
        noise_m: noise,
        status,
        gain: decided_gain,
        noise_filter_s,
        predicted_next_rms_m,
        response_ratio,
    });
    let better = history
        .best
        .as_ref()
        .is_none_or(|b| stats.rms < b.measured_rms_m);
    let this = BestRun {
        run,
        measured_rms_m: stats.rms,
        command: sent.to_vec(),
        error,
    };
    if better {
        history.best = Some(this.clone());
    }
    history.last = Some(this);
    Ok(Learning {
        command,
        predicted,
        run,
        measured: stats,
        noise_m: noise,
        wild_samples,
        previous_rms_m,
        status,
        gain,
        gain_limited,
        noise_filter_s,
        robustness_filter_s: robust_sigma * dt,
        unanswered_share,
        explained_share: explained,
        response_ratio,
        predicted_next_rms_m,
        predicted_next_measured_rms_m,
        step_smoothing_s: step_sigma * dt,
        held_back_share: held_share,
        peaks,
        history,
    })
}

/// The model's position for the command `u` of a run: from rest at `u[0]`
/// ([`StartMode::Rest`]) or moving at `u`'s first velocity
/// ([`StartMode::Moving`], the velocity held back until the model settles);
/// `out_scale` rescales the model's deviations, `g_dc` its DC gain.
fn simulate_run(
    sys: &DiscreteStateSpace,
    u: &[f64],
    out_scale: f64,
    g_dc: f64,
    start: StartMode,
) -> Result<Vec<f64>> {
    let u0 = u[0];
    let rest = u0 * g_dc * out_scale;
    let pre = match start {
        StartMode::Rest => 0,
        StartMode::Moving => model_settle(sys)?,
    };
    let v0 = u[1] - u[0];
    let mut ext: Vec<f64> = (0..pre).map(|i| -v0 * (pre - i) as f64).collect();
    ext.extend(u.iter().map(|v| v - u0));
    let mut x = vec![0.0; sys.order()];
    let mut y = vec![0.0; ext.len()];
    let mut scratch = vec![0.0; sys.order()];
    // from a rest state at the extended start (zero deviation there)
    let first = ext[0];
    for v in &mut ext {
        *v -= first;
    }
    sys.simulate_into(&ext, &mut x, &mut y, &mut scratch)?;
    let offset = first * g_dc * out_scale;
    Ok(y[pre..]
        .iter()
        .map(|v| rest + offset + out_scale * v)
        .collect())
}

/// Hampel's identifier: samples farther than [`WILD`]·`noise` from the
/// median of their five neighbours are replaced by it; returns the count.
fn hold_wild(e: &[f64], noise: f64) -> (Vec<f64>, usize) {
    let mut out = e.to_vec();
    if noise <= 0.0 || e.len() < 5 {
        return (out, 0);
    }
    let mut count = 0;
    let mut w = [0.0; 5];
    for k in 0..e.len() {
        let lo = k.saturating_sub(2).min(e.len() - 5);
        w.copy_from_slice(&e[lo..lo + 5]);
        let m = median(&mut w);
        if (e[k] - m).abs() > WILD * noise {
            out[k] = m;
            count += 1;
        }
    }
    (out, count)
}

/// σ levels \[samples\] of the noise filter.
const LEVELS: [f64; 14] = [
    0.0, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0, 16.0, 24.0, 32.0, 48.0,
];

/// The largest σ of [`LEVELS`] whose smoothing removes no more than the noise
/// (`rms(e − N·e) ≤ noise`, Morozov's discrepancy principle).
fn discrepancy_sigma(e: &[f64], noise: f64) -> f64 {
    if noise <= 0.0 {
        return 0.0;
    }
    let n = e.len();
    let mut out = vec![0.0; n];
    let mut chosen = 0.0;
    for &s in &LEVELS[1..] {
        if 4.0 * s >= n as f64 {
            break;
        }
        gaussian_smooth(e, s, &mut out);
        let ss: f64 = e.iter().zip(&out).map(|(a, b)| (a - b).powi(2)).sum();
        if (ss / n as f64).sqrt() > noise {
            break;
        }
        chosen = s;
    }
    chosen
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::stats::noise_level;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    pub(in crate::compensate) const DT: f64 = 1e-3;

    /// A second-order position loop with one sample of delay, unit DC gain.
    pub(in crate::compensate) fn axis() -> LinearModel {
        LinearModel::discrete(vec![0.0, 0.05, 0.03], vec![1.0, -1.5, 0.58], DT).unwrap()
    }

    /// Rest, a smooth move of 2 mm, rest.
    pub(in crate::compensate) fn program() -> Vec<f64> {
        (0..600)
            .map(|k| {
                let s = ((k as f64 - 50.0) / 300.0).clamp(0.0, 1.0);
                2e-3 * (3.0 * s * s - 2.0 * s * s * s)
            })
            .collect()
    }

    /// `model` with its gain times `k` (a wrong model).
    fn scaled(model: &LinearModel, k: f64) -> LinearModel {
        let LinearModel::Discrete { b, a, dt } = model.clone() else {
            unreachable!()
        };
        LinearModel::discrete(b.iter().map(|v| k * v).collect(), a, dt).unwrap()
    }

    /// [`LearnConfig::exact`] with the model's gain as it is (not rescaled
    /// to unit DC gain, so that a wrong gain stays wrong).
    fn exact_keeping_gain() -> LearnConfig {
        LearnConfig {
            compensate: CompensateConfig {
                unit_dc_gain: false,
                ..LearnConfig::exact().compensate
            },
            ..LearnConfig::exact()
        }
    }

    fn rms(v: &[f64]) -> f64 {
        (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
    }

    /// Runs of `learn` on `plant` from the plain command, noise `sigma`.
    fn runs(
        plant: &LinearModel,
        model: &LinearModel,
        cfg: &LearnConfig,
        sigma: f64,
        count: usize,
    ) -> (Vec<f64>, Vec<f64>, Vec<LearnStatus>) {
        let desired = program();
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let mut command = desired.clone();
        let mut history: Option<LearningHistory> = None;
        let (mut measured, mut truth, mut status) = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..count {
            let y = plant.simulate(&command).unwrap();
            truth.push(rms(&y
                .iter()
                .zip(&desired)
                .map(|(a, b)| a - b)
                .collect::<Vec<_>>()));
            let noisy: Vec<f64> = y
                .iter()
                .map(|v| v + sigma * (rng.random::<f64>() - 0.5) * 12f64.sqrt())
                .collect();
            let s = learn(model, &desired, &command, &noisy, DT, cfg, history.as_ref()).unwrap();
            measured.push(s.measured.rms);
            status.push(s.status);
            command = s.command;
            history = Some(s.history);
        }
        (measured, truth, status)
    }

    #[test]
    fn an_exact_model_learns_the_exact_inverse_in_one_step() {
        let a = axis();
        let (_, truth, status) = runs(&a, &a, &LearnConfig::exact(), 0.0, 3);
        assert_eq!(status[0], LearnStatus::First);
        assert!(truth[0] > 1e-5, "{truth:?}");
        // the inverse is exact: the second run follows to rounding
        assert!(truth[1] < 1e-12 * truth[0] + 1e-18, "{truth:?}");
    }

    #[test]
    fn a_step_the_inverse_would_amplify_into_noise_is_smoothed_first() {
        // no noise filter: the measured error carries its noise into the
        // step, and the axis's inverse multiplies noise at Nyquist by
        // |A(−1)/B(−1)| ≈ 150; a smoothed step that stays within 3× the
        // error (`step::MAX_AMPLIFICATION`) is taken instead
        let a = axis();
        let desired = program();
        // no limits either: nothing else asks for a smoother step
        let cfg = LearnConfig {
            noise_filter: NoiseFilter::Fixed(0.0),
            compensate: CompensateConfig {
                max_velocity: f64::INFINITY,
                max_acceleration: f64::INFINITY,
                ..CompensateConfig::default()
            },
            ..LearnConfig::default()
        };
        let y = a.simulate(&desired).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let noisy: Vec<f64> = y
            .iter()
            .map(|v| v + 2e-6 * (rng.random::<f64>() - 0.5) * 12f64.sqrt())
            .collect();
        let error: Vec<f64> = desired.iter().zip(&noisy).map(|(d, y)| d - y).collect();
        // the unsmoothed inverse of this error is more than 3× its size,
        // most of it amplified noise
        let exact = CompensateConfig {
            smoothing: super::super::Smoothing::Fixed(0.0),
            max_velocity: f64::INFINITY,
            max_acceleration: f64::INFINITY,
            fallback: false,
            ..CompensateConfig::default()
        };
        let raw = super::super::compensate_model(&a, &error, DT, &exact).unwrap();
        assert!(
            rms(&raw.command) > 3.0 * rms(&error),
            "{} {}",
            rms(&raw.command),
            rms(&error)
        );
        let s = learn(&a, &desired, &desired, &noisy, DT, &cfg, None).unwrap();
        assert!(s.step_smoothing_s > 0.0, "{}", s.step_smoothing_s);
        let step: Vec<f64> = s.command.iter().zip(&desired).map(|(u, d)| u - d).collect();
        assert!(
            rms(&step) <= 3.0 * rms(&error),
            "{} vs {}",
            rms(&step),
            rms(&error)
        );
        // and the next run is better for it
        let next = a.simulate(&s.command).unwrap();
        let after: Vec<f64> = desired.iter().zip(&next).map(|(d, y)| d - y).collect();
        let before: Vec<f64> = desired.iter().zip(&y).map(|(d, y)| d - y).collect();
        assert!(
            rms(&after) < 0.5 * rms(&before),
            "{} vs {}",
            rms(&after),
            rms(&before)
        );
    }

    #[test]
    fn half_the_gain_halves_the_error_each_run() {
        // exact model, α = ½: ε_{j+1} = ½·ε_j (closed form)
        let a = axis();
        let cfg = LearnConfig {
            gain: 0.5,
            ..LearnConfig::exact()
        };
        let (_, truth, _) = runs(&a, &a, &cfg, 0.0, 5);
        for j in 1..5 {
            let r = truth[j] / truth[j - 1];
            assert!((r - 0.5).abs() < 1e-9, "run {j}: ratio {r}");
        }
    }

    #[test]
    fn a_model_with_twice_the_gain_converges_once_the_axis_has_answered() {
        // P = G/2: the first step halves the error (1 − ½); the axis answered
        // with half the predicted change (ρ = ½), so the second step is
        // doubled and removes the rest
        let a = axis();
        let double = scaled(&a, 2.0);
        let cfg = exact_keeping_gain();
        let (_, truth, _) = runs(&a, &double, &cfg, 0.0, 4);
        let r = truth[1] / truth[0];
        assert!((r - 0.5).abs() < 1e-9, "ratio {r}");
        assert!(truth[2] < 1e-9 * truth[0], "{truth:?}");
        assert!(truth[3] < 1e-9 * truth[0], "{truth:?}");
    }

    #[test]
    fn noisy_runs_converge_to_the_noise_and_stay_there() {
        let a = axis();
        let sigma = 0.2e-6;
        let (measured, truth, _) = runs(&a, &a, &LearnConfig::default(), sigma, 8);
        assert!(truth[0] > 100.0 * sigma, "{truth:?}");
        for j in 2..8 {
            // measured at the noise floor, the true error below it
            assert!(measured[j] < 1.5 * sigma, "run {j}: {measured:?}");
            assert!(truth[j] < sigma, "run {j}: {truth:?}");
        }
    }

    #[test]
    fn a_model_with_half_the_gain_converges_once_the_axis_has_answered() {
        // P = 2G: with α = 1 the error flips sign and keeps its size
        // (1 − 2 = −1); the axis's answer, twice the model's, scales the
        // next step by ½ (1 − 2·½ = 0), and nothing is left to learn
        let a = axis();
        let half = scaled(&a, 0.5);
        let cfg = LearnConfig {
            growth_tolerance: 0.0,
            ..exact_keeping_gain()
        };
        let (_, truth, status) = runs(&a, &half, &cfg, 0.0, 5);
        assert!(
            (truth[1] / truth[0] - 1.0).abs() < 0.05,
            "{truth:?} {status:?}"
        );
        assert_eq!(status[1], LearnStatus::Improving, "{status:?}");
        assert!(truth[2] < 1e-9 * truth[0], "{truth:?}");
        // no later run leaves it
        for j in 3..5 {
            assert!(truth[j] <= truth[2] + 1e-12 * truth[0], "{truth:?}");
            assert!(
                matches!(
                    status[j],
                    LearnStatus::Settled { .. } | LearnStatus::AtNoise
                ),
                "{status:?}"
            );
        }
    }

    #[test]
    fn a_step_that_achieves_little_of_its_prediction_settles_on_the_best_run() {
        // the axis does not answer the command at all in run 2: the step
        // from run 1 achieved nothing of the reduction the model predicted
        let a = axis();
        let desired = program();
        let cfg = LearnConfig::exact();
        let y1 = a.simulate(&desired).unwrap();
        let s1 = learn(&a, &desired, &desired, &y1, DT, &cfg, None).unwrap();
        assert!(s1.predicted_next_rms_m < 1e-6 * s1.measured.rms);
        // the same position again, though another command was sent
        let s2 = learn(&a, &desired, &s1.command, &y1, DT, &cfg, Some(&s1.history)).unwrap();
        match s2.status {
            LearnStatus::Settled {
                best_run,
                achieved_share: Some(share),
                ..
            } => {
                assert_eq!(best_run, 1);
                assert!(share.abs() < 1e-9, "{share}");
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(s2.gain, 0.0);
        // run 1's command again, and in every later step
        assert_eq!(s2.command, desired);
        let s3 = learn(&a, &desired, &s2.command, &y1, DT, &cfg, Some(&s2.history)).unwrap();
        assert!(
            matches!(s3.status, LearnStatus::Settled { .. }),
            "{:?}",
            s3.status
        );
        assert_eq!(s3.command, desired);
    }

    #[test]
    fn a_step_the_model_expects_to_achieve_little_is_not_taken() {
        // a gain of 5 %: the model expects the rms to fall by 5 % only
        let a = axis();
        let desired = program();
        let cfg = LearnConfig {
            gain: 0.05,
            ..LearnConfig::exact()
        };
        let y = a.simulate(&desired).unwrap();
        let s = learn(&a, &desired, &desired, &y, DT, &cfg, None).unwrap();
        assert!(
            matches!(
                s.status,
                LearnStatus::Settled {
                    best_run: 1,
                    achieved_share: None,
                    ..
                }
            ),
            "{:?}",
            s.status
        );
        assert_eq!(s.gain, 0.0);
        assert_eq!(s.command, desired);
        // the prediction is that of the command sent again
        assert!((s.predicted_next_rms_m - s.measured.rms).abs() < 1e-9 * s.measured.rms);
        // with 20 % the step is taken
        let cfg = LearnConfig {
            gain: 0.2,
            ..LearnConfig::exact()
        };
        let s = learn(&a, &desired, &desired, &y, DT, &cfg, None).unwrap();
        assert_eq!(s.status, LearnStatus::First);
        assert!((s.gain - 0.2).abs() < 1e-12);
    }

    #[test]
    fn a_model_that_cannot_learn_stops_and_sends_the_best_command_again() {
        // the model's sign is wrong: every step makes it worse
        let a = axis();
        let wrong = scaled(&a, -1.0);
        let cfg = exact_keeping_gain();
        let desired = program();
        let mut command = desired.clone();
        let mut history = None;
        let mut last = None;
        for _ in 0..8 {
            let y = a.simulate(&command).unwrap();
            let s = learn(&wrong, &desired, &command, &y, DT, &cfg, history.as_ref()).unwrap();
            command = s.command.clone();
            history = Some(s.history.clone());
            last = Some(s);
        }
        let s = last.unwrap();
        assert!(
            matches!(s.status, LearnStatus::Stopped { best_run: 1, .. }),
            "{:?}",
            s.status
        );
        // the best run was the plain command
        assert_eq!(s.command, desired);
    }

    #[test]
    fn a_learned_command_keeps_its_limits() {
        // a ramp asks the inverse for a velocity kick at its corners; with
        // an acceleration limit the step is smoothed or held back there
        let a = axis();
        let desired: Vec<f64> = (0..800)
            .map(|k| 1e-3 * ((k as f64 - 50.0) / 500.0).clamp(0.0, 1.0))
            .collect();
        let plain = CommandPeaks::of(&desired, DT, StartMode::Rest);
        let cfg = LearnConfig {
            compensate: CompensateConfig {
                max_velocity: 2.0 * plain.velocity,
                max_acceleration: 1.5 * plain.acceleration,
                ..CompensateConfig::default()
            },
            ..LearnConfig::default()
        };
        let mut command = desired.clone();
        let mut history = None;
        let mut rms = Vec::new();
        for _ in 0..4 {
            let y = a.simulate(&command).unwrap();
            let s = learn(&a, &desired, &command, &y, DT, &cfg, history.as_ref()).unwrap();
            let p = CommandPeaks::of(&s.command, DT, StartMode::Rest);
            assert!(
                p.velocity <= cfg.compensate.max_velocity * (1.0 + 1e-9),
                "{p:?}"
            );
            assert!(
                p.acceleration <= cfg.compensate.max_acceleration * (1.0 + 1e-9),
                "{p:?}"
            );
            assert_eq!(p, s.peaks);
            rms.push(s.measured.rms);
            command = s.command;
            history = Some(s.history);
        }
        // and still learns
        assert!(rms[3] < 0.2 * rms[0], "{rms:?}");
    }

    #[test]
    fn a_model_that_explains_little_of_the_error_takes_smaller_steps() {
        // the model: the axis's lag with 3× its time constant
        let a = axis();
        let slow = LinearModel::discrete(vec![0.0, 0.01], vec![1.0, -0.99], DT).unwrap();
        let desired = program();
        let y = a.simulate(&desired).unwrap();
        let trusting = LearnConfig {
            min_trust: 1.0,
            ..LearnConfig::exact()
        };
        let wary = LearnConfig {
            min_trust: 0.5,
            ..LearnConfig::exact()
        };
        let s1 = learn(&slow, &desired, &desired, &y, DT, &trusting, None).unwrap();
        let s2 = learn(&slow, &desired, &desired, &y, DT, &wary, None).unwrap();
        assert!(s1.explained_share < 0.5, "{}", s1.explained_share);
        assert_eq!(s1.gain, 1.0);
        assert_eq!(s2.gain, 0.5);
        // the decided gain is what the history keeps
        assert_eq!(s2.history.runs[0].gain, 1.0);
        // the exact model explains all of it
        let s3 = learn(&a, &desired, &desired, &y, DT, &wary, None).unwrap();
        assert!(s3.explained_share > 1.0 - 1e-9, "{}", s3.explained_share);
        assert!((s3.gain - 1.0).abs() < 1e-9, "{}", s3.gain);
    }

    #[test]
    fn nothing_is_learned_before_the_program_moves() {
        let a = axis();
        let desired = program();
        let mut y = a.simulate(&desired).unwrap();
        // an offset of the measurement at rest before the move
        for v in y.iter_mut().take(50) {
            *v += 1e-6;
        }
        let s = learn(
            &a,
            &desired,
            &desired,
            &y,
            DT,
            &LearnConfig::default(),
            None,
        )
        .unwrap();
        assert_eq!(s.command[..50], desired[..50]);
    }

    #[test]
    fn the_noise_level_of_white_noise_is_its_standard_deviation() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let e: Vec<f64> = (0..20_000)
            .map(|k| {
                // a smooth signal plus Gaussian noise (Box–Muller)
                let (u1, u2): (f64, f64) = (rng.random(), rng.random());
                let g = (-2.0 * (1.0 - u1).ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos();
                1e-3 * (k as f64 * 1e-3).sin() + 1e-6 * g
            })
            .collect();
        let s = noise_level(&e);
        assert!((s / 1e-6 - 1.0).abs() < 0.03, "{s}");
        // a smooth signal alone has (almost) none
        let smooth: Vec<f64> = (0..2000).map(|k| (k as f64 * 1e-3).sin()).collect();
        assert!(noise_level(&smooth) < 1e-6);
    }

    #[test]
    fn a_wild_sample_is_held_and_not_learned() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let mut e: Vec<f64> = (0..500)
            .map(|_| 1e-7 * (rng.random::<f64>() - 0.5))
            .collect();
        e[200] = 1e-3;
        let noise = noise_level(&e);
        let (held, count) = hold_wild(&e, noise);
        assert_eq!(count, 1);
        assert!(held[200].abs() < 1e-6);
        assert_eq!(held[199], e[199]);
    }

    #[test]
    fn the_discrepancy_filter_removes_about_the_noise() {
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let e: Vec<f64> = (0..4000)
            .map(|k| {
                1e-4 * (k as f64 * 2e-3).sin() + 1e-6 * (rng.random::<f64>() - 0.5) * 12f64.sqrt()
            })
            .collect();
        let noise = noise_level(&e);
        let s = discrepancy_sigma(&e, noise);
        assert!(s >= 3.0, "{s}");
        let mut out = vec![0.0; e.len()];
        gaussian_smooth(&e, s, &mut out);
        let removed = rms(&e.iter().zip(&out).map(|(a, b)| a - b).collect::<Vec<_>>());
        assert!(
            removed <= noise && removed > 0.8 * noise,
            "{removed} vs {noise}"
        );
        // noise-free: no filter
        let clean: Vec<f64> = (0..4000).map(|k| 1e-4 * (k as f64 * 2e-3).sin()).collect();
        assert_eq!(discrepancy_sigma(&clean, noise_level(&clean)), 0.0);
    }

    #[test]
    fn a_history_of_another_program_is_refused() {
        let a = axis();
        let desired = program();
        let y = a.simulate(&desired).unwrap();
        let s = learn(
            &a,
            &desired,
            &desired,
            &y,
            DT,
            &LearnConfig::default(),
            None,
        )
        .unwrap();
        let other: Vec<f64> = desired.iter().map(|v| 2.0 * v).collect();
        let e = learn(
            &a,
            &other,
            &other,
            &y,
            DT,
            &LearnConfig::default(),
            Some(&s.history),
        )
        .unwrap_err();
        assert!(matches!(e, Error::HistoryMismatch { .. }), "{e}");
        let e = learn(
            &a,
            &desired,
            &desired,
            &y,
            2.0 * DT,
            &LearnConfig::default(),
            Some(&s.history),
        )
        .unwrap_err();
        assert!(e.to_string().contains("sample interval"), "{e}");
    }

    #[test]
    fn the_history_round_trips_through_json() {
        let a = axis();
        let desired = program();
        let y = a.simulate(&desired).unwrap();
        let s = learn(
            &a,
            &desired,
            &desired,
            &y,
            DT,
            &LearnConfig::default(),
            None,
        )
        .unwrap();
        let text = serde_json::to_string(&s.history).unwrap();
        let back: LearningHistory = serde_json::from_str(&text).unwrap();
        assert_eq!(back, s.history);
    }
}
