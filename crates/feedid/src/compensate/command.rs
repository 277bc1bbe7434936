//! Model-based compensation of the command: the command that makes the
//! predicted table position follow a desired trajectory.
//!
//! With the model `G` sampled at the trajectory's interval (an identified
//! discrete model at its own sample time, a continuous one or the physical
//! rig model by exact zero-order hold), the desired positions `y_d` relative
//! to their first value, and two zero-phase smoothings `F` and `F_p`
//! ([`super::gaussian_smooth_profile`], σ varying along the trajectory):
//!
//! ```text
//! s = F_p·y_d                                       (the plain part)
//! u = y_d[0]/G(1) + s + F·(G⁻¹ − 1)·s               (stable inverse, super::StableInverse)
//! ŷ = y_d[0] + G·(u − y_d[0]/G(1))                  (the prediction)
//! ```
//!
//! **The residual, not the command.** The command is the plain trajectory
//! plus a correction `F·(G⁻¹ − 1)·y_d`: the model is of the axis as it runs
//! (with whatever feed-forward its drive applies), and the correction is
//! what that axis still needs. Without smoothing `u = G⁻¹·y_d` and the
//! prediction is exact; with `F` alone (σ constant) the predicted error is
//! `(G − 1)·(1 − F)·y_d` — the axis's own error filtered by the smoothing's
//! high pass, smaller than the rounding `(1 − F)·y_d` of smoothing the
//! whole trajectory, and near zero on an axis that already follows well.
//! The smoothing `F` acts on the correction after the inverse, so a σ that
//! varies along the trajectory is never amplified by the inverse's large
//! high-frequency gain.
//!
//! **Limits, smoothing only where needed.** A model of a feed drive has a
//! large high-frequency gain, so a velocity step (the paper's ramp) or a
//! jerk step asks for very large, short command accelerations at the
//! corner. The command's velocity and acceleration (finite differences of
//! the command actually sent, from its rest value before the first sample)
//! are checked against [`CompensateConfig::max_velocity`] and
//! [`CompensateConfig::max_acceleration`]. With [`Smoothing::Auto`] σ starts
//! at 0 everywhere and is raised step by step (0, ½, 1, 1½, 2, 3, 4, 6, …
//! samples, up to [`CompensateConfig::max_smoothing`]) only around the
//! samples that exceed a limit; `F_p` stays the identity except where the
//! plain trajectory itself exceeds the limit there. When even the largest σ
//! cannot meet a limit and the plain command meets them, the correction of
//! the smoothest command is **held back locally** towards the plain command
//! where it still exceeds a limit (`plain + (1 − W)·(u − plain)`, `W` one
//! around those samples and easing to zero over as many on each side,
//! widened until the limits hold; [`Compensation::held_back_share`]): the
//! axis is compensated everywhere else. The smoothest command is also
//! **slewed** at the limits until it has caught up (`compensate/slew.rs`;
//! what a slow axis needs to build its following error's lead at a ramp's
//! corner) and the one of the two the model expects to track better is
//! sent ([`Compensation::slewed`]). Only when neither meets them is the
//! plain command sent (a [`Fallback::Limits`]); when the plain command
//! itself exceeds a limit, [`Error::LimitUnreachable`] quotes the smallest
//! peak reached, its time and the trajectory's own peak.
//! [`Smoothing::Fixed`] smooths the correction with one σ everywhere and
//! reports [`Error::LimitExceeded`] (figures of that command) over a limit.
//!
//! **The start eased in.** With a rest start the smoothing may never move
//! the trajectory before its first sample, so where the program starts
//! moving soon after its first sample σ is capped there and a velocity or
//! jerk step at the start of motion cannot be smoothed enough. There the
//! inverse aims at the start **eased in causally**: from the first sample
//! that moves, `(1 − w)·H·y + w·y`, `H` four first-order lags of time
//! constant τ (unit gain, causal: nothing moves before the trajectory does)
//! and `w` a step from 0 to 1 with every derivative continuous over
//! `16·τ`. The command then compensates fully only after the easing (mean
//! lag `4τ`, [`Compensation::start_ease_s`]); the model's prediction shows
//! what is left at the start. τ (from ½ sample in the σ levels) is raised
//! only when a limit is exceeded where the cap binds.
//!
//! **Ends.** The trajectory is a segment: before its first sample the axis
//! rests at `y_d[0]` ([`StartMode::Rest`], default; whatever the command
//! would need before — smoothing, pre-actuation of non-minimum-phase zeros —
//! is lost and shows in the prediction) or has been moving at the first
//! sample's velocity under the same compensation ([`StartMode::Moving`]).
//! After the last sample the trajectory is extended by holding its **end
//! velocity** (a straight line, so a trajectory at rest at its end stays at
//! rest) long enough for every section of the inverse and the smoothing to
//! settle; only the given samples are output.
//!
//! **Never worse.** The model predicts the plain and the compensated
//! tracking errors ([`Benefit`], with the model's quality
//! [`CompensateConfig::quality`] when known); where the benefit expected is
//! small or the model's fit is poor the plain command is sent, with the
//! reason ([`Compensation::fallback`]).
//!
//! A position servo closed on the table encoder has unit DC gain; an
//! identified model is off by a little (say 1e-3), which on a 30 mm move
//! would leave 30 µm of final error, so by default the model's gain is
//! rescaled to make `G(1) = 1` ([`CompensateConfig::unit_dc_gain`]).
//!
//! ```
//! use feedid::compensate::{compensate_model, CompensateConfig, Smoothing};
//! use feedid::ident::LinearModel;
//! // first-order lag with one sample of delay
//! let m = LinearModel::discrete(vec![0.0, 0.2], vec![1.0, -0.8], 1e-3).unwrap();
//! let desired: Vec<f64> = (0..200).map(|k| 1e-3 * (k as f64 / 100.0).min(1.0)).collect();
//! let cfg = CompensateConfig {
//!     smoothing: Smoothing::Fixed(0.0),
//!     max_acceleration: f64::INFINITY,
//!     ..CompensateConfig::default()
//! };
//! let c = compensate_model(&m, &desired, 1e-3, &cfg).unwrap();
//! assert!(c.fallback.is_none());
//! assert!(c.predicted_error.max_abs < 1e-15);
//! ```

use serde::Serialize;

use super::benefit::{Benefit, Fallback, ModelQuality};
use super::inverse::{StableInverse, ZeroInfo};
use super::smoothing::{gaussian_smooth_profile, smooth_step, taper_profile};
use super::step::{held_back, CommandPeaks};
use crate::drive::RigParams;
use crate::error::{Error, Result};
use crate::greybox::{linear_discrete, LoopModel};
use crate::ident::LinearModel;
use crate::lti::DiscreteStateSpace;
use crate::stats::ErrorStats;

/// Smoothing of the desired trajectory before inversion.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Smoothing {
    /// σ raised only where the command exceeds a limit (default).
    Auto,
    /// One σ \[s\] for the correction everywhere (0: none).
    Fixed(f64),
}

/// What the axis did before the trajectory's first sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StartMode {
    /// At rest at the first desired value (default).
    Rest,
    /// Moving at the first sample's velocity, under the same compensation
    /// (a segment cut from a longer program).
    Moving,
}

impl std::str::FromStr for StartMode {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "rest" => Ok(StartMode::Rest),
            "moving" => Ok(StartMode::Moving),
            _ => Err(Error::InvalidChoice {
                what: "start",
                value: s.to_string(),
                expected: "rest, moving",
            }),
        }
    }
}

/// Settings of the compensation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CompensateConfig {
    /// Smoothing; default [`Smoothing::Auto`].
    pub smoothing: Smoothing,
    /// Command velocity limit \[m/s\]; default 1.0 (∞ disables).
    pub max_velocity: f64,
    /// Command acceleration limit \[m/s²\]; default 30 (∞ disables).
    pub max_acceleration: f64,
    /// Largest σ tried by [`Smoothing::Auto`] \[s\]; default 0.02.
    pub max_smoothing: f64,
    /// Zeros in the left half plane closer than this to the unit circle get
    /// the zero-phase approximation instead of an exact inverse; default 0.05.
    pub unit_circle_margin: f64,
    /// Rescale the model to unit DC gain (a position loop); default true.
    pub unit_dc_gain: bool,
    /// The axis before the first sample; default [`StartMode::Rest`].
    pub start: StartMode,
    /// Send the plain command when the expected benefit (plain rms over
    /// compensated rms, [`Benefit`]) is below this; default 1.25.
    pub min_benefit: f64,
    /// Send the plain command when the model's position fit is below this
    /// \[%\]; default 90.
    pub min_fit_percent: f64,
    /// The model's quality, when known; default unknown.
    pub quality: ModelQuality,
    /// Allow the fall-back to the plain command ("never worse"); default true.
    pub fallback: bool,
}

impl Default for CompensateConfig {
    fn default() -> Self {
        Self {
            smoothing: Smoothing::Auto,
            max_velocity: 1.0,
            max_acceleration: 30.0,
            max_smoothing: 0.02,
            unit_circle_margin: 0.05,
            unit_dc_gain: true,
            start: StartMode::Rest,
            min_benefit: 1.25,
            min_fit_percent: 90.0,
            quality: ModelQuality::default(),
            fallback: true,
        }
    }
}

/// The longest smoothing σ a compensation uses \[samples\] (0.2 s at
/// 5 kHz, 10 s at 100 Hz): the smoothing keeps a kernel for every ⅛ sample
/// of σ up to the largest, about 32·σ² numbers (≤ 260 MB here).
pub const MAX_SMOOTHING_SAMPLES: usize = 1000;

impl CompensateConfig {
    /// Check the settings.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("max velocity", self.max_velocity),
            ("max acceleration", self.max_acceleration),
        ] {
            if v.is_nan() || v <= 0.0 {
                return Err(Error::InvalidParameter {
                    name,
                    value: v,
                    reason: "must be > 0 (inf disables the limit)",
                });
            }
        }
        if !(self.max_smoothing.is_finite() && self.max_smoothing >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "max smoothing",
                value: self.max_smoothing,
                reason: "must be finite and >= 0 (s)",
            });
        }
        if let Smoothing::Fixed(s) = self.smoothing {
            if !(s.is_finite() && s >= 0.0) {
                return Err(Error::InvalidParameter {
                    name: "smoothing",
                    value: s,
                    reason: "must be finite and >= 0 (s)",
                });
            }
        }
        if !(self.min_benefit.is_finite() && self.min_benefit >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "min benefit",
                value: self.min_benefit,
                reason: "must be finite and >= 0",
            });
        }
        if !(self.min_fit_percent.is_finite() && self.min_fit_percent <= 100.0) {
            return Err(Error::InvalidParameter {
                name: "min fit",
                value: self.min_fit_percent,
                reason: "must be finite and <= 100 (%)",
            });
        }
        if !(self.unit_circle_margin.is_finite() && self.unit_circle_margin >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "unit-circle margin",
                value: self.unit_circle_margin,
                reason: "must be finite and >= 0",
            });
        }
        Ok(())
    }
}

/// A command for a desired trajectory and what the model predicts for it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Compensation {
    /// The command to send \[m\], one per desired sample (the plain desired
    /// trajectory when [`Compensation::fallback`] is set).
    #[serde(skip)]
    pub command: Vec<f64>,
    /// The model's position for that command \[m\].
    #[serde(skip)]
    pub predicted: Vec<f64>,
    /// The model's position for the plain command \[m\].
    #[serde(skip)]
    pub predicted_plain: Vec<f64>,
    /// Predicted minus desired for the command sent: rms, max (and fit) \[m\].
    pub predicted_error: ErrorStats,
    /// Predicted minus desired for the plain command \[m\].
    pub predicted_plain_error: ErrorStats,
    /// The model's prediction of the benefit of the compensated command.
    pub benefit: Benefit,
    /// Why the plain command is sent instead (`None`: the compensated one is).
    pub fallback: Option<Fallback>,
    /// Largest σ of the smoothing used \[s\].
    pub smoothing_s: f64,
    /// Share of the samples where the smoothing acts (σ > 0).
    pub smoothed_share: f64,
    /// Share of the samples where the correction is held back towards the
    /// plain command because no smoothing up to
    /// [`CompensateConfig::max_smoothing`] meets a limit there (0: nowhere).
    pub held_back_share: f64,
    /// The command slews at the limits where it is off the compensated one
    /// (until it has caught up, `compensate/slew.rs`) instead of holding the
    /// correction back; [`Compensation::held_back_share`] is then the share
    /// of the samples where it is off.
    pub slewed: bool,
    /// Peak velocity of the command sent \[m/s\].
    pub peak_velocity: f64,
    /// Time of that peak \[s\] (from the first sample).
    pub peak_velocity_time_s: f64,
    /// Peak acceleration of the command sent \[m/s²\].
    pub peak_acceleration: f64,
    /// Time of that peak \[s\].
    pub peak_acceleration_time_s: f64,
    /// DC gain of the model before any rescaling.
    pub model_dc_gain: f64,
    /// Delay of the sampled model \[samples\].
    pub delay_samples: usize,
    /// Zeros of the sampled model and how each was inverted.
    pub zeros: Vec<ZeroInfo>,
    /// True when every zero was inverted exactly.
    pub exact_inverse: bool,
    /// Largest command offset the compensation would have needed before the
    /// first sample (lost with [`StartMode::Rest`]) \[m\].
    pub pre_actuation_m: f64,
    /// Mean lag of the causal easing of the start (the command reaches the
    /// full compensation over about 4× this after the first move) \[s\];
    /// 0: none.
    pub start_ease_s: f64,
    /// What the axis did before the first sample.
    pub start: StartMode,
    /// Velocity held after the last sample \[m/s\].
    pub end_velocity: f64,
}

/// Peak |velocity| and |acceleration| of `u` and their sample indices.
#[cfg(test)]
fn peaks(u: &[f64], dt: f64) -> ((f64, usize), (f64, usize)) {
    let p = Peaks::of(u, 1, dt);
    (
        (p.velocity, p.velocity_at),
        (p.acceleration, p.acceleration_at),
    )
}

/// Peaks of a command sent from extended index `from` on.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Peaks {
    pub(super) velocity: f64,
    pub(super) velocity_at: usize,
    pub(super) acceleration: f64,
    pub(super) acceleration_at: usize,
}

impl Peaks {
    /// Velocities `(s[i] − s[i−1])/dt` for `i ≥ from` and accelerations at
    /// `i ≥ from − 1` (the step from the rest before the first sample counts).
    pub(super) fn of(s: &[f64], from: usize, dt: f64) -> Self {
        let mut p = Peaks::default();
        for i in from.max(1)..s.len() {
            let v = ((s[i] - s[i - 1]) / dt).abs();
            if v > p.velocity {
                p.velocity = v;
                p.velocity_at = i;
            }
        }
        for i in from.saturating_sub(1).max(1)..s.len().saturating_sub(1) {
            let a = ((s[i + 1] - 2.0 * s[i] + s[i - 1]) / (dt * dt)).abs();
            if a > p.acceleration {
                p.acceleration = a;
                p.acceleration_at = i;
            }
        }
        p
    }
}

/// Compensate with a sampled model `sys` whose sample time equals the
/// trajectory's (`sys.dt`); `desired` \[m\] one value per sample.
pub fn compensate(
    sys: &DiscreteStateSpace,
    desired: &[f64],
    cfg: &CompensateConfig,
) -> Result<Compensation> {
    cfg.validate()?;
    let inverse = StableInverse::from_state_space(sys, cfg.unit_circle_margin)?;
    compensate_with(sys, inverse, desired, cfg)
}

/// Compensate with an identified model (discrete: its sample time must equal
/// `dt`; continuous: sampled at `dt` by zero-order hold). Pole–zero pairs
/// negligible over the trajectory are cancelled first
/// ([`LinearModel::without_negligible_pairs`]).
pub fn compensate_model(
    model: &LinearModel,
    desired: &[f64],
    dt: f64,
    cfg: &CompensateConfig,
) -> Result<Compensation> {
    cfg.validate()?;
    // a pole–zero pair that acts on no time scale of the trajectory (an
    // output-error fit's differentiator behind a pole at 1e-11 rad/s) would
    // leave nothing to invert
    let span = dt * desired.len().max(1) as f64;
    let (model, _) = model.without_negligible_pairs(span)?;
    let sys = model.discrete_state_space(Some(dt))?;
    let inverse = match &model {
        LinearModel::Discrete { b, a, .. } => {
            StableInverse::from_polynomials(b, a, cfg.unit_circle_margin)?
        }
        LinearModel::Continuous { .. } => {
            StableInverse::from_state_space(&sys, cfg.unit_circle_margin)?
        }
    };
    compensate_with(&sys, inverse, desired, cfg)
}

/// Compensate with the physical model of `params` (linear cascade, sampled
/// or continuous position loop) sampled at `dt`.
pub fn compensate_params(
    params: &RigParams,
    position_loop: LoopModel,
    desired: &[f64],
    dt: f64,
    cfg: &CompensateConfig,
) -> Result<Compensation> {
    params.validate()?;
    let sys = linear_discrete(params, position_loop, dt)?;
    compensate(&sys, desired, cfg)
}

/// Longest extension before the trajectory for [`StartMode::Moving`].
const MAX_SETTLE: usize = 2_000_000;

/// Most rounds of raising the smoothing.
const MAX_ROUNDS: usize = 80;

/// The trajectory on the extended grid, the inverse and its scratch.
struct Problem<'a> {
    inverse: &'a StableInverse,
    /// Relative desired positions on the extended grid.
    ext: Vec<f64>,
    /// Extended samples before the first desired one.
    pre: usize,
    /// Desired samples.
    n: usize,
    start: StartMode,
    dt: f64,
    /// Largest σ per extended sample (rest start: the smoothing never moves
    /// the trajectory before its first sample), `None`: no cap.
    cap: Option<Vec<f64>>,
}

/// With a rest start, σ\[i\] ≤ (f − 1 − i)/4 before the first sample
/// (`f`: first extended sample that moves), and growing from there by at
/// most one sample per [`super::smoothing::TAPER`] samples.
fn rest_cap(ext: &[f64], pre: usize) -> Vec<f64> {
    let scale = ext.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let f = ext
        .iter()
        .position(|v| v.abs() > 1e-12 * scale)
        .unwrap_or(ext.len())
        .max(pre);
    let at_start = (f - pre) as f64 / 4.0;
    (0..ext.len())
        .map(|i| {
            if i < pre {
                (f.saturating_sub(i + 1)) as f64 / 4.0
            } else {
                at_start + (i + 1 - pre) as f64 / super::smoothing::TAPER
            }
        })
        .collect()
}

/// One candidate command on the extended grid.
struct Candidate {
    /// Command as computed (relative).
    raw: Vec<f64>,
    /// Command as sent (relative): `raw` from the first sample on, the rest
    /// value before it with [`StartMode::Rest`].
    sent: Vec<f64>,
    /// The plain part `F_p·y_d`.
    plain: Vec<f64>,
    /// Share of the desired samples where the correction is held back
    /// (limits no smoothing could meet).
    held_share: f64,
    /// Off the compensated command by slewing rather than holding back.
    slewed: bool,
}

impl Problem<'_> {
    /// Apply the cap to a profile.
    fn capped(&self, sigma: &mut [f64]) {
        if let Some(cap) = &self.cap {
            for (s, c) in sigma.iter_mut().zip(cap) {
                *s = s.min(*c);
            }
        }
    }

    fn command(&self, sigma: &[f64], sigma_plain: &[f64], start_tau: f64) -> Result<Candidate> {
        let len = self.ext.len();
        let mut plain = vec![0.0; len];
        gaussian_smooth_profile(&self.ext, sigma_plain, &mut plain);
        // what the inverse aims at: the plain part, its start eased in
        let target = self.eased(&plain, start_tau);
        let mut corr = vec![0.0; len];
        let mut work = Vec::new();
        self.inverse.apply_into(&target, &mut corr, &mut work)?;
        for (c, p) in corr.iter_mut().zip(&target) {
            *c -= p;
        }
        let mut fc = vec![0.0; len];
        gaussian_smooth_profile(&corr, sigma, &mut fc);
        let raw: Vec<f64> = (0..len).map(|i| plain[i] + fc[i]).collect();
        let sent = self.sent(&raw);
        Ok(Candidate {
            raw,
            sent,
            plain,
            held_share: 0.0,
            slewed: false,
        })
    }

    /// The start eased in (module doc): from the first sample that moves,
    /// `(1 − w)·H·y + w·y` with `H` [`START_LAGS`] first-order lags of time
    /// constant `tau` \[samples\] (causal: nothing moves earlier) and `w` a
    /// smooth step from 0 to 1 over `4·START_LAGS·tau` samples; `tau = 0`
    /// or a moving start: `y` unchanged.
    fn eased(&self, y: &[f64], tau: f64) -> Vec<f64> {
        if tau <= 0.0 || self.start != StartMode::Rest {
            return y.to_vec();
        }
        let scale = y.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let Some(f) = y.iter().position(|v| v.abs() > 1e-12 * scale) else {
            return y.to_vec();
        };
        let a = (-1.0 / tau).exp();
        let mut lagged = y.to_vec();
        for _ in 0..START_LAGS {
            let mut state = 0.0;
            for v in lagged.iter_mut() {
                state = a * state + (1.0 - a) * *v;
                *v = state;
            }
        }
        let span = 4.0 * START_LAGS as f64 * tau;
        y.iter()
            .zip(&lagged)
            .enumerate()
            .map(|(i, (&v, &h))| {
                let x = if i < f { 0.0 } else { (i - f) as f64 / span };
                let w = smooth_step(x);
                (1.0 - w) * h + w * v
            })
            .collect()
    }

    /// What is sent of `raw`: with a rest start nothing before the first sample.
    fn sent(&self, raw: &[f64]) -> Vec<f64> {
        match self.start {
            StartMode::Rest => (0..raw.len())
                .map(|i| if i < self.pre { 0.0 } else { raw[i] })
                .collect(),
            StartMode::Moving => raw.to_vec(),
        }
    }

    /// A candidate that exceeds a limit held back locally towards the plain
    /// command where it does ([`super::step`]): `plain + (1 − W)·(c − plain)`
    /// over the sent samples; `None` when even the widest hold exceeds a
    /// limit. The share held back is recorded in the candidate.
    #[allow(clippy::type_complexity)]
    fn held_back(
        &self,
        (mut c, sigma, sigma_p, tau): (Candidate, Vec<f64>, Vec<f64>, f64),
        plain: &[f64],
        cfg: &CompensateConfig,
    ) -> Option<(Candidate, Vec<f64>, Vec<f64>, f64)> {
        // from two samples before the first (at rest, or the moving start's
        // own compensated history), so that the first velocity and
        // acceleration are checked as sent
        let from = self.pre.saturating_sub(2);
        let to = self.pre + self.n;
        let delta: Vec<f64> = (from..to).map(|i| c.sent[i] - plain[i]).collect();
        let rest = CompensateConfig {
            start: StartMode::Rest,
            ..*cfg
        };
        let base_peaks = CommandPeaks::of(&plain[from..to], self.dt, StartMode::Rest);
        let (held, share) = held_back(&plain[from..to], &delta, 1.0, self.dt, &rest, &base_peaks)?;
        c.sent[from..to].copy_from_slice(&held);
        c.held_share = share * (to - from) as f64 / self.n as f64;
        Some((c, sigma, sigma_p, tau))
    }

    /// A candidate that exceeds a limit followed within the limits
    /// ([`super::slew`]) over the sent samples; the share of the desired
    /// samples where it is off the candidate by more than 1 % of the
    /// largest correction is recorded as held back.
    #[allow(clippy::type_complexity)]
    fn slewed(
        &self,
        (c, sigma, sigma_p, tau): &(Candidate, Vec<f64>, Vec<f64>, f64),
        plain: &[f64],
        cfg: &CompensateConfig,
    ) -> (Candidate, Vec<f64>, Vec<f64>, f64) {
        // as `held_back` checks them: from two samples before the first,
        // the limits raised to the plain command's own peaks
        let from = self.pre.saturating_sub(2);
        let to = self.pre + self.n;
        let base = CommandPeaks::of(&plain[from..to], self.dt, StartMode::Rest);
        let vmax = cfg.max_velocity.max(base.velocity);
        let amax = cfg.max_acceleration.max(base.acceleration);
        let followed = super::slew::within_limits(&c.sent[from..to], 0.0, vmax, amax, self.dt);
        let largest = (from..to).fold(0.0_f64, |m, i| m.max((c.sent[i] - plain[i]).abs()));
        let off = (self.pre..to)
            .filter(|&i| (followed[i - from] - c.sent[i]).abs() > 0.01 * largest)
            .count();
        let mut sent = c.sent.clone();
        sent[from..to].copy_from_slice(&followed);
        let candidate = Candidate {
            raw: c.raw.clone(),
            sent,
            plain: c.plain.clone(),
            held_share: off as f64 / self.n as f64,
            slewed: true,
        };
        (candidate, sigma.clone(), sigma_p.clone(), *tau)
    }

    /// Peaks of a sent command over the given samples.
    fn peaks(&self, sent: &[f64]) -> Peaks {
        let mut p = Peaks::of(&sent[..self.pre + self.n], self.pre, self.dt);
        p.velocity_at = p.velocity_at.saturating_sub(self.pre);
        p.acceleration_at = p.acceleration_at.saturating_sub(self.pre);
        p
    }
}

/// First-order lags of the eased start ([`Problem::eased`]).
const START_LAGS: usize = 4;

/// Build the extended grid: `pre` samples before (rest, or the first
/// velocity held backwards) and `post` after (the end velocity held).
fn extend(e: &[f64], pre: usize, post: usize, start: StartMode) -> Vec<f64> {
    let n = e.len();
    let v0 = e[1] - e[0];
    let v1 = e[n - 1] - e[n - 2];
    let mut ext = Vec::with_capacity(pre + n + post);
    for i in 0..pre {
        let back = (pre - i) as f64;
        ext.push(match start {
            StartMode::Rest => 0.0,
            StartMode::Moving => e[0] - v0 * back,
        });
    }
    ext.extend_from_slice(e);
    for j in 1..=post {
        ext.push(e[n - 1] + v1 * j as f64);
    }
    ext
}

/// Samples for the slowest pole of `sys` to decay to 1e-12.
pub(super) fn model_settle(sys: &DiscreteStateSpace) -> Result<usize> {
    let r = sys.poles()?.iter().fold(0.0_f64, |m, p| m.max(p.norm()));
    if r >= 1.0 {
        return Err(Error::InvalidModel {
            reason: "the model is unstable or has an integrator: it cannot run a segment that is already moving at its start (use start rest)",
        });
    }
    if r <= 0.0 {
        return Ok(1);
    }
    let n = ((1e-12_f64).ln() / r.ln()).ceil();
    if n.is_finite() && (n as usize) < MAX_SETTLE {
        Ok(n as usize)
    } else {
        Err(Error::InvalidModel {
            reason: "the model's slowest pole takes too long to settle for a segment moving at its start (use start rest)",
        })
    }
}

/// The model's relative position (before rescaling by `out_scale`) for a
/// relative command on the extended grid, over the desired samples.
fn predict(sys: &DiscreteStateSpace, p: &Problem<'_>, sent: &[f64]) -> Result<Vec<f64>> {
    let from = match p.start {
        StartMode::Rest => p.pre,
        StartMode::Moving => 0,
    };
    let u = &sent[from..p.pre + p.n];
    let mut x = vec![0.0; sys.order()];
    let mut y = vec![0.0; u.len()];
    let mut scratch = vec![0.0; sys.order()];
    sys.simulate_into(u, &mut x, &mut y, &mut scratch)?;
    Ok(y[p.pre - from..].to_vec())
}

/// σ levels \[samples\] tried by [`Smoothing::Auto`], up to `max`.
pub(super) fn levels(max: f64) -> Vec<f64> {
    let mut c = vec![0.0, 0.5, 1.0, 1.5];
    let mut s = 2.0;
    while s <= max {
        c.push(s);
        c.push(1.5 * s);
        s *= 2.0;
    }
    c.retain(|&x| x <= max.max(0.0));
    if c.is_empty() {
        c.push(0.0);
    }
    c
}

fn check_desired(desired: &[f64]) -> Result<()> {
    let n = desired.len();
    if n < 2 {
        return Err(Error::TooFewSamples {
            what: "a desired trajectory",
            needed: 2,
            actual: n,
        });
    }
    if let Some(i) = desired.iter().position(|v| !v.is_finite()) {
        return Err(Error::NonFinite {
            channel: "desired".to_string(),
            index: i,
            value: desired[i],
        });
    }
    Ok(())
}

/// The outcome of the limit search.
enum Search {
    Met(Candidate, Vec<f64>, Vec<f64>, f64),
    /// No σ met the limits: the smallest peaks reached and the candidate
    /// (with its σ profiles and start easing) that reached them.
    Unreachable(Peaks, Option<(Candidate, Vec<f64>, Vec<f64>, f64)>),
}

fn search_limits(p: &Problem<'_>, cfg: &CompensateConfig) -> Result<Search> {
    let len = p.ext.len();
    let dt = p.dt;
    let over = |v: f64, lim: f64| v > lim * (1.0 + 1e-9);
    if let Smoothing::Fixed(s) = cfg.smoothing {
        let mut sigma = vec![s / dt; len];
        p.capped(&mut sigma);
        let zero = vec![0.0; len];
        let c = p.command(&sigma, &zero, 0.0)?;
        let pk = p.peaks(&c.sent);
        if over(pk.velocity, cfg.max_velocity) {
            return Err(Error::LimitExceeded {
                quantity: "velocity",
                value: pk.velocity,
                limit: cfg.max_velocity,
                unit: "m/s",
                time: pk.velocity_at as f64 * dt,
                hints: LIMIT_HINT,
            });
        }
        if over(pk.acceleration, cfg.max_acceleration) {
            return Err(Error::LimitExceeded {
                quantity: "acceleration",
                value: pk.acceleration,
                limit: cfg.max_acceleration,
                unit: "m/s²",
                time: pk.acceleration_at as f64 * dt,
                hints: LIMIT_HINT,
            });
        }
        return Ok(Search::Met(c, sigma, zero, 0.0));
    }
    let lv = levels(cfg.max_smoothing / dt);
    let next = |s: f64| lv.iter().copied().find(|&l| l > s + 1e-12);
    let mut raw_c = vec![0.0; len];
    let mut raw_p = vec![0.0; len];
    let mut sigma = raw_c.clone();
    let mut sigma_p = raw_p.clone();
    let mut best: Option<Peaks> = None;
    let mut best_candidate = None;
    let d = p.inverse.delay();
    let mut tau = 0.0;
    for _ in 0..MAX_ROUNDS {
        let c = p.command(&sigma, &sigma_p, tau)?;
        let pk = p.peaks(&c.sent);
        let score =
            |q: &Peaks| (q.velocity / cfg.max_velocity).max(q.acceleration / cfg.max_acceleration);
        let better = best.as_ref().is_none_or(|b| score(&pk) < score(b));
        if better {
            best = Some(pk);
        }
        // every violating sample of the sent command
        let lo = p.pre.saturating_sub(1).max(1);
        let hi = p.pre + p.n;
        let mut raised = false;
        let snap_c = raw_c.clone();
        let snap_p = raw_p.clone();
        let mut violations = 0usize;
        // a violation where the rest start caps the smoothing
        let mut capped = false;
        for i in lo..hi {
            let vel = |s: &[f64]| ((s[i] - s[i - 1]) / dt).abs();
            let acc = |s: &[f64]| ((s[i + 1] - 2.0 * s[i] + s[i - 1]) / (dt * dt)).abs();
            let bad_v = i >= p.pre && over(vel(&c.sent), cfg.max_velocity);
            let bad_a = over(acc(&c.sent), cfg.max_acceleration);
            if !(bad_v || bad_a) {
                continue;
            }
            violations += 1;
            let plain_bad = (bad_v && over(vel(&c.plain), cfg.max_velocity))
                || (bad_a && over(acc(&c.plain), cfg.max_acceleration));
            for (raw, snap, also) in [
                (&mut raw_c, &snap_c, true),
                (&mut raw_p, &snap_p, plain_bad),
            ] {
                if !also {
                    continue;
                }
                if let Some(to) = next(snap[i]) {
                    if also && p.cap.as_ref().is_some_and(|cap| cap[i] < to) {
                        capped = true;
                    }
                    let r = (4.0 * to).ceil() as usize + 4;
                    let a = i.saturating_sub(r);
                    let b = (i + d + r + 1).min(len);
                    for v in &mut raw[a..b] {
                        *v = v.max(to);
                    }
                    raised = true;
                }
            }
        }
        if violations == 0 {
            return Ok(Search::Met(c, sigma, sigma_p, tau));
        }
        if better {
            best_candidate = Some((c, sigma.clone(), sigma_p.clone(), tau));
        }
        if capped {
            // ease the start in more slowly (causal: the rest start allows it)
            if let Some(t) = next(tau) {
                tau = t.max(1.0);
                raised = true;
            }
        }
        if !raised {
            break;
        }
        sigma.copy_from_slice(&raw_c);
        sigma_p.copy_from_slice(&raw_p);
        taper_profile(&mut sigma);
        taper_profile(&mut sigma_p);
        p.capped(&mut sigma);
        p.capped(&mut sigma_p);
    }
    Ok(Search::Unreachable(
        best.unwrap_or_default(),
        best_candidate,
    ))
}

fn compensate_with(
    sys: &DiscreteStateSpace,
    mut inverse: StableInverse,
    desired: &[f64],
    cfg: &CompensateConfig,
) -> Result<Compensation> {
    cfg.validate()?;
    check_desired(desired)?;
    let n = desired.len();
    let dt = sys.dt;
    let model_dc_gain = inverse.dc_gain();
    if !(model_dc_gain.is_finite() && model_dc_gain.abs() > 1e-12) {
        return Err(Error::InvalidModel {
            reason: "the model's DC gain is zero or infinite; a position model must have a finite non-zero DC gain",
        });
    }
    let out_scale = if cfg.unit_dc_gain {
        inverse.scale_gain(1.0 / model_dc_gain);
        1.0 / model_dc_gain
    } else {
        1.0
    };
    let g = model_dc_gain * out_scale;
    let y0 = desired[0];
    let e: Vec<f64> = desired.iter().map(|v| v - y0).collect();
    let (what, seconds) = match cfg.smoothing {
        Smoothing::Auto => ("max smoothing", cfg.max_smoothing),
        Smoothing::Fixed(s) => ("smoothing", s),
    };
    let sigma_max = seconds / dt;
    if sigma_max > MAX_SMOOTHING_SAMPLES as f64 {
        // the kernels of every σ up to the largest are kept: memory grows
        // with σ², and a σ this long flattens any trajectory anyway
        return Err(Error::SmoothingTooLong {
            what,
            seconds,
            samples: sigma_max,
            max_samples: MAX_SMOOTHING_SAMPLES,
            max_seconds: MAX_SMOOTHING_SAMPLES as f64 * dt,
        });
    }
    let h = (4.0 * sigma_max).ceil() as usize + 1;
    let margin = inverse.settle() + inverse.delay() + 2 * h + 8;
    let pre = match cfg.start {
        StartMode::Rest => margin,
        StartMode::Moving => margin + model_settle(sys)?,
    };
    let post = margin;
    let ext = extend(&e, pre, post, cfg.start);
    let cap = match cfg.start {
        StartMode::Rest => Some(rest_cap(&ext, pre)),
        StartMode::Moving => None,
    };
    let problem = Problem {
        inverse: &inverse,
        ext,
        pre,
        n,
        start: cfg.start,
        dt,
        cap,
    };
    let plain_sent = problem.sent(&problem.ext);
    let plain_peaks = problem.peaks(&plain_sent);
    let yp = predict(sys, &problem, &plain_sent)?;
    let predicted_plain: Vec<f64> = yp.iter().map(|v| y0 + out_scale * v).collect();
    let predicted_plain_error =
        ErrorStats::from_pairs(desired.iter().copied().zip(predicted_plain.iter().copied()));

    let (candidate, sigma, sigma_p, start_tau, limit_fallback) = match search_limits(&problem, cfg)?
    {
        Search::Met(c, s, sp, tau) => (Some(c), s, sp, tau, None),
        Search::Unreachable(best, candidate) => {
            // quote the quantity the trajectory itself exceeds, if any
            let plain_v = plain_peaks.velocity > cfg.max_velocity * (1.0 + 1e-9);
            let plain_a = plain_peaks.acceleration > cfg.max_acceleration * (1.0 + 1e-9);
            let comp_v = best.velocity > cfg.max_velocity * (1.0 + 1e-9);
            let (quantity, achievable, limit, unit, at, plain) = if plain_v || (!plain_a && comp_v)
            {
                (
                    "velocity",
                    best.velocity,
                    cfg.max_velocity,
                    "m/s",
                    best.velocity_at,
                    plain_peaks.velocity,
                )
            } else {
                (
                    "acceleration",
                    best.acceleration,
                    cfg.max_acceleration,
                    "m/s²",
                    best.acceleration_at,
                    plain_peaks.acceleration,
                )
            };
            let plain_ok = plain_peaks.velocity <= cfg.max_velocity * (1.0 + 1e-9)
                && plain_peaks.acceleration <= cfg.max_acceleration * (1.0 + 1e-9);
            if !(plain_ok && cfg.fallback) {
                return Err(Error::LimitUnreachable {
                    quantity,
                    achievable,
                    time: at as f64 * dt,
                    limit,
                    plain,
                    unit,
                    smoothing_ms: 1e3 * cfg.max_smoothing,
                });
            }
            // the correction held back where it exceeds a limit, or the
            // command slewed at the limits: the one the model expects to
            // track better
            let kept = match candidate {
                None => None,
                Some(c) => {
                    let slewed = problem.slewed(&c, &plain_sent, cfg);
                    let error = |s: &[f64]| -> Result<f64> {
                        Ok(rms_error(&e, &predict(sys, &problem, s)?, out_scale))
                    };
                    let slewed_error = error(&slewed.0.sent)?;
                    match problem.held_back(c, &plain_sent, cfg) {
                        Some(h) if error(&h.0.sent)? <= slewed_error => Some(h),
                        _ => Some(slewed),
                    }
                }
            };
            match kept {
                Some((c, s, sp, tau)) => (Some(c), s, sp, tau, None),
                None => {
                    let fb = Fallback::Limits {
                        quantity,
                        achievable,
                        limit,
                    };
                    (None, Vec::new(), Vec::new(), 0.0, Some(fb))
                }
            }
        }
    };

    let window = pre..pre + n;
    let (mut sent_rel, mut smoothing_s, mut smoothed_share, mut pre_actuation) =
        (plain_sent.clone(), 0.0, 0.0, 0.0);
    let mut held_back_share = 0.0;
    let mut slewed = false;
    let mut predicted_rel = yp.clone();
    let mean = desired.iter().sum::<f64>() / n as f64;
    let motion_rms = (desired.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n as f64).sqrt();
    let mut benefit = Benefit::new(
        predicted_plain_error.rms,
        predicted_plain_error.rms,
        motion_rms,
        &cfg.quality,
    );
    let mut fallback = limit_fallback;
    if let Some(c) = candidate {
        let yc = predict(sys, &problem, &c.sent)?;
        let err = rms_error(&e, &yc, out_scale);
        benefit = Benefit::new(predicted_plain_error.rms, err, motion_rms, &cfg.quality);
        smoothing_s = dt
            * sigma[window.clone()]
                .iter()
                .chain(&sigma_p[window.clone()])
                .fold(0.0_f64, |m, v| m.max(*v));
        smoothed_share = window
            .clone()
            .filter(|&i| sigma[i] >= 0.125 || sigma_p[i] >= 0.125)
            .count() as f64
            / n as f64;
        pre_actuation = match cfg.start {
            StartMode::Rest => c.raw[..pre].iter().fold(0.0_f64, |m, v| m.max(v.abs())),
            StartMode::Moving => 0.0,
        };
        if cfg.fallback {
            let fit = cfg.quality.position_fit_percent;
            fallback = match fit {
                Some(f) if f < cfg.min_fit_percent => Some(Fallback::PoorFit {
                    fit_percent: f,
                    min_percent: cfg.min_fit_percent,
                }),
                _ if benefit.expected_benefit < cfg.min_benefit => Some(Fallback::SmallBenefit {
                    expected: benefit.expected_benefit,
                    min: cfg.min_benefit,
                }),
                _ => None,
            };
        }
        if fallback.is_none() {
            held_back_share = c.held_share;
            slewed = c.slewed;
            sent_rel = c.sent;
            predicted_rel = yc;
        } else {
            smoothing_s = 0.0;
            smoothed_share = 0.0;
        }
    }
    let start_ease_s = if fallback.is_none() {
        dt * START_LAGS as f64 * start_tau
    } else {
        0.0
    };
    let peaks = problem.peaks(&sent_rel);
    if let Some(fb) = fallback {
        // the plain command is sent: it must meet the limits too
        let over = |v: f64, lim: f64| v > lim * (1.0 + 1e-9);
        let because = match fb {
            Fallback::PoorFit { .. } => "the model's fit is below the minimum",
            Fallback::SmallBenefit { .. } => "the expected benefit is below the minimum",
            Fallback::Limits { .. } => "the compensated command cannot meet the limits",
        };
        for (quantity, value, at, limit, unit) in [
            (
                "velocity",
                peaks.velocity,
                peaks.velocity_at,
                cfg.max_velocity,
                "m/s",
            ),
            (
                "acceleration",
                peaks.acceleration,
                peaks.acceleration_at,
                cfg.max_acceleration,
                "m/s²",
            ),
        ] {
            if over(value, limit) {
                return Err(Error::PlainOverLimit {
                    quantity,
                    value,
                    limit,
                    unit,
                    time: at as f64 * dt,
                    because,
                });
            }
        }
    }
    let u_rest = y0 / g;
    let command: Vec<f64> = sent_rel[window].iter().map(|v| u_rest + v).collect();
    let predicted: Vec<f64> = predicted_rel.iter().map(|v| y0 + out_scale * v).collect();
    let predicted_error =
        ErrorStats::from_pairs(desired.iter().copied().zip(predicted.iter().copied()));
    Ok(Compensation {
        command,
        predicted,
        predicted_plain,
        predicted_error,
        predicted_plain_error,
        benefit,
        fallback,
        smoothing_s,
        smoothed_share,
        held_back_share,
        slewed,
        peak_velocity: peaks.velocity,
        peak_velocity_time_s: peaks.velocity_at as f64 * dt,
        peak_acceleration: peaks.acceleration,
        peak_acceleration_time_s: peaks.acceleration_at as f64 * dt,
        model_dc_gain,
        delay_samples: inverse.delay(),
        zeros: inverse.zeros().to_vec(),
        exact_inverse: inverse.is_exact(),
        pre_actuation_m: pre_actuation,
        start_ease_s,
        start: cfg.start,
        end_velocity: (e[n - 1] - e[n - 2]) / dt,
    })
}

/// RMS of `scale·y − e`.
fn rms_error(e: &[f64], y: &[f64], scale: f64) -> f64 {
    let s: f64 = e.iter().zip(y).map(|(a, b)| (scale * b - a).powi(2)).sum();
    (s / e.len() as f64).sqrt()
}

const LIMIT_HINT: &[crate::error::Hint] = crate::error::SMOOTHING_HINTS;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compensate::ModelQuality;

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(48))]

        /// Any options and trajectory: an error or a finite command within
        /// the limits it was given (the plain one sent instead too), never a
        /// panic and never an unbounded buffer (the fuzz target
        /// `compensate_options` runs the same property on arbitrary bytes).
        #[test]
        fn every_command_sent_meets_its_limits_whatever_the_options(
            fixed in proptest::bool::ANY,
            moving in proptest::bool::ANY,
            smooth in -1e-3..5.0f64,
            max_smoothing in -1e-3..5.0f64,
            vmax in -0.1..2.0f64,
            amax in -1.0..400.0f64,
            min_benefit in 0.0..1e4f64,
            steps in proptest::collection::vec(-2e-3..2e-3f64, 2..60),
        ) {
            let mut desired = vec![0.0; 40];
            for (i, s) in steps.iter().enumerate() {
                let last = *desired.last().unwrap_or(&0.0);
                desired.extend((0..10).map(|k| last + s * (k + 1) as f64 / 10.0 * (i % 3) as f64));
            }
            let cfg = CompensateConfig {
                smoothing: if fixed { Smoothing::Fixed(smooth) } else { Smoothing::Auto },
                max_smoothing,
                max_velocity: vmax,
                max_acceleration: amax,
                min_benefit,
                start: if moving { StartMode::Moving } else { StartMode::Rest },
                ..CompensateConfig::default()
            };
            let model = LinearModel::discrete(vec![0.0, 0.2], vec![1.0, -0.8], 1e-3).unwrap();
            if let Ok(c) = compensate_model(&model, &desired, 1e-3, &cfg) {
                proptest::prop_assert!(c.command.iter().all(|v| v.is_finite()));
                proptest::prop_assert!(c.peak_velocity <= vmax * (1.0 + 1e-6));
                proptest::prop_assert!(c.peak_acceleration <= amax * (1.0 + 1e-6));
            }
        }
    }
    use crate::drive::{closed_loop_coefficients, simulate_nominal, D1Variant};
    use crate::signal::{Ramp, Scenario, Scurve};

    const DT: f64 = 2e-4;

    fn exact() -> CompensateConfig {
        CompensateConfig {
            smoothing: Smoothing::Fixed(0.0),
            max_velocity: f64::INFINITY,
            max_acceleration: f64::INFINITY,
            ..CompensateConfig::default()
        }
    }

    #[test]
    fn exact_continuous_model_gives_rounding_level_tracking() {
        let p = RigParams::default();
        let tf = closed_loop_coefficients(&p, D1Variant::Corrected)
            .transfer_function()
            .unwrap();
        let model = LinearModel::continuous(&tf);
        let desired = Scenario::Scurve.command(5000.0, 0.4, 0).unwrap();
        let c = compensate_model(&model, &desired, DT, &exact()).unwrap();
        assert!(c.exact_inverse);
        assert!(
            c.predicted_error.max_abs < 1e-12,
            "{}",
            c.predicted_error.max_abs
        );
        // the model as an independent user would simulate it
        let y = model.simulate_at(&c.command, DT).unwrap();
        let err = y
            .iter()
            .zip(&desired)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-12, "{err}");
        // and the physical 7-state model (another realisation of the same G)
        let y = simulate_nominal(&p, &c.command, DT).unwrap();
        let err = y
            .iter()
            .zip(&desired)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-11, "{err}");
        // sampling zeros of relative degree 5 lie outside the unit circle
        assert!(c
            .zeros
            .iter()
            .any(|z| z.handling == super::super::ZeroHandling::AntiCausal));
    }

    #[test]
    fn exact_sampled_loop_model_gives_rounding_level_tracking_of_the_ramp() {
        let p = RigParams::default();
        let desired = Scenario::Ramp.command(5000.0, 0.8, 0).unwrap();
        let c = compensate_params(&p, LoopModel::Sampled, &desired, DT, &exact()).unwrap();
        assert!(
            c.predicted_error.max_abs < 1e-12,
            "{}",
            c.predicted_error.max_abs
        );
        let y = crate::greybox::PhysicalModel::linear(p, LoopModel::Sampled)
            .simulate(&c.command, DT)
            .unwrap();
        let err = y
            .iter()
            .zip(&desired)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-12, "{err}");
        // uncompensated: the 71.4 µm following error
        let y = crate::greybox::PhysicalModel::linear(p, LoopModel::Sampled)
            .simulate(&desired, DT)
            .unwrap();
        assert!((desired[2000] - y[2000] - 71.43e-6).abs() < 0.01e-6);
    }

    #[test]
    fn limits_choose_the_smoothing_and_bound_the_command() {
        let p = RigParams::default();
        let desired = Ramp::default().generate(5000.0, 0.8).unwrap();
        let cfg = CompensateConfig::default();
        let c = compensate_params(&p, LoopModel::Sampled, &desired, DT, &cfg).unwrap();
        assert!(c.smoothing_s > 0.0);
        assert!(c.peak_acceleration <= cfg.max_acceleration);
        assert!(c.peak_velocity <= cfg.max_velocity);
        let ((_, _), (a, _)) = peaks(&c.command, DT);
        assert!(a <= cfg.max_acceleration * (1.0 + 1e-9));
        // the remaining error is the rounding of the two corners (within
        // twice Δv·σ/√(2π): plain part and correction are smoothed apart)
        let corner = 0.05 * c.smoothing_s / (2.0 * std::f64::consts::PI).sqrt();
        assert!(
            c.predicted_error.rms < 0.05 * c.predicted_plain_error.rms,
            "{} vs {}",
            c.predicted_error.rms,
            c.predicted_plain_error.rms
        );
        assert!(
            c.predicted_error.max_abs < 2.0 * corner,
            "{} vs {corner}",
            c.predicted_error.max_abs
        );
        // a fixed smoothing that is too small is an error naming the limit
        let tight = CompensateConfig {
            smoothing: Smoothing::Fixed(0.0),
            ..cfg
        };
        let e = compensate_params(&p, LoopModel::Sampled, &desired, DT, &tight)
            .unwrap_err()
            .to_string();
        assert!(e.contains("velocity") && e.contains("limit 1 m/s"), "{e}");
    }

    #[test]
    fn unit_dc_gain_rescales_an_identified_model() {
        // a lag with DC gain 1.01 (a slightly wrong identified model)
        let m = LinearModel::discrete(vec![0.0, 0.202], vec![1.0, -0.8], 1e-3).unwrap();
        let desired: Vec<f64> = (0..300)
            .map(|k| 0.03 * (k as f64 / 100.0 - 0.5).clamp(0.0, 1.0))
            .collect();
        let cfg = CompensateConfig {
            max_acceleration: f64::INFINITY,
            ..CompensateConfig::default()
        };
        let c = compensate_model(&m, &desired, 1e-3, &cfg).unwrap();
        assert!((c.model_dc_gain - 1.01).abs() < 1e-12);
        // the command ends at the desired end (unit gain assumed)
        assert!((c.command[299] - 0.03).abs() < 1e-12);
        let keep = CompensateConfig {
            unit_dc_gain: false,
            ..cfg
        };
        let c = compensate_model(&m, &desired, 1e-3, &keep).unwrap();
        assert!((c.command[299] - 0.03 / 1.01).abs() < 1e-12);
    }

    #[test]
    fn sample_time_mismatch_is_an_error() {
        let m = LinearModel::discrete(vec![0.0, 0.2], vec![1.0, -0.8], 1e-3).unwrap();
        let e = compensate_model(&m, &[0.0, 1.0, 1.0], 2e-4, &exact()).unwrap_err();
        assert!(e.to_string().contains("sample time"), "{e}");
    }

    fn rig_model() -> LinearModel {
        let tf = closed_loop_coefficients(&RigParams::default(), D1Variant::Corrected)
            .transfer_function()
            .unwrap();
        LinearModel::continuous(&tf)
    }

    fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn a_segment_moving_at_its_last_sample_is_compensated_with_the_end_velocity_held() {
        // the issue's case: a ramp still moving at the end of the file
        let desired = Ramp {
            distance: 1.0,
            velocity: 0.05,
            rest: 0.01,
        }
        .generate(5000.0, 0.2)
        .unwrap();
        let n = desired.len();
        assert!(desired[n - 1] - desired[n - 2] > 0.0);
        let cfg = CompensateConfig::default();
        let c = compensate_model(&rig_model(), &desired, DT, &cfg).unwrap();
        assert!(c.fallback.is_none(), "{:?}", c.fallback);
        assert!(c.peak_velocity <= cfg.max_velocity);
        assert!(c.peak_acceleration <= cfg.max_acceleration * (1.0 + 1e-9));
        // the figures quoted are those of the command sent (from rest)
        let mut sent = vec![0.0, 0.0];
        sent.extend_from_slice(&c.command);
        let ((v, _), (a, _)) = peaks(&sent, DT);
        assert!((v - c.peak_velocity).abs() < 1e-12 && (a - c.peak_acceleration).abs() < 1e-9);
        // at the end the command leads by the ramp's following error v/Kv
        // (the zero-order hold adds half a sample: v·(1/Kv + Δt/2))
        let lead = c.command[n - 1] - desired[n - 1];
        assert!(
            (lead - 0.05 * (1.0 / 700.0 + DT / 2.0)).abs() < 0.01e-6,
            "{lead}"
        );
        assert!((c.end_velocity - 0.05).abs() < 1e-9);
        // and the prediction is exact there (the start corner is long gone)
        let tail = max_abs_diff(&c.predicted[n - 200..], &desired[n - 200..]);
        assert!(tail < 1e-10, "{tail}");
        // smoothing only at the start corner
        assert!(c.smoothed_share < 0.2, "{}", c.smoothed_share);
        assert!(c.predicted_error.rms < 0.05 * c.predicted_plain_error.rms);
    }

    #[test]
    fn a_trajectory_moving_from_its_first_sample_is_compensated() {
        // a jerk-limited move with no rest, from rest at t = 0
        let desired = Scurve {
            distance: 0.01,
            max_velocity: 0.1,
            max_acceleration: 2.0,
            jerk: 200.0,
            rest: 0.0,
        }
        .generate(5000.0, 0.3)
        .unwrap();
        assert!(desired[1] > desired[0]);
        let c = compensate_model(&rig_model(), &desired, DT, &CompensateConfig::default()).unwrap();
        assert!(c.fallback.is_none(), "{:?}", c.fallback);
        assert!(
            c.predicted_error.rms < 0.01 * c.predicted_plain_error.rms,
            "{} vs {}",
            c.predicted_error.rms,
            c.predicted_plain_error.rms
        );
        // a ramp that was already moving before t = 0 (a cut segment)
        let ramp: Vec<f64> = (0..1000).map(|k| 0.05 * k as f64 * DT).collect();
        let cfg = CompensateConfig {
            start: StartMode::Moving,
            ..CompensateConfig::default()
        };
        let c = compensate_model(&rig_model(), &ramp, DT, &cfg).unwrap();
        assert!(c.fallback.is_none());
        assert_eq!(c.smoothing_s, 0.0);
        assert!(
            c.predicted_error.max_abs < 1e-10,
            "{}",
            c.predicted_error.max_abs
        );
        // the plain command lags by v·(1/Kv + Δt/2) from the first sample on
        let lag = c.predicted_plain_error.max_abs;
        assert!(
            (lag - 0.05 * (1.0 / 700.0 + DT / 2.0)).abs() < 1e-8,
            "{lag}"
        );
        // the same ramp from rest at t = 0 within its own figures
        let rest = CompensateConfig {
            max_acceleration: f64::INFINITY,
            max_velocity: f64::INFINITY,
            ..CompensateConfig::default()
        };
        let c = compensate_model(&rig_model(), &ramp, DT, &rest).unwrap();
        assert!(c.fallback.is_none());
        let tail = max_abs_diff(&c.predicted[500..], &ramp[500..]);
        assert!(tail < 1e-9, "{tail}");
    }

    #[test]
    fn an_explicit_smoothing_is_capped_by_the_rest_not_refused() {
        let desired: Vec<f64> = (0..2000).map(|k| 0.05 * k as f64 * DT).collect();
        let cfg = CompensateConfig {
            smoothing: Smoothing::Fixed(1e-3),
            max_velocity: f64::INFINITY,
            max_acceleration: f64::INFINITY,
            ..CompensateConfig::default()
        };
        let c = compensate_model(&rig_model(), &desired, DT, &cfg).unwrap();
        // σ grows from 0 at the start by one sample per TAPER samples
        assert!(c.smoothing_s > 0.9e-3 && c.smoothing_s <= 1e-3 + 1e-12);
    }

    #[test]
    fn smoothing_acts_only_where_a_limit_needs_it() {
        // a jerk-limited move, then a move with velocity steps
        let mut desired = Scurve {
            distance: 0.01,
            max_velocity: 0.1,
            max_acceleration: 2.0,
            jerk: 200.0,
            rest: 0.01,
        }
        .generate(5000.0, 0.3)
        .unwrap();
        let top = desired[desired.len() - 1];
        let ramp = Ramp {
            distance: 0.01,
            velocity: 0.05,
            rest: 0.01,
        }
        .generate(5000.0, 0.4)
        .unwrap();
        desired.extend(ramp.iter().map(|v| top + v));
        let c = compensate_model(&rig_model(), &desired, DT, &CompensateConfig::default()).unwrap();
        assert!(c.fallback.is_none());
        assert!(
            c.smoothing_s > 0.0 && c.smoothed_share < 0.3,
            "{}",
            c.smoothed_share
        );
        // the jerk-limited move is followed exactly
        let first = max_abs_diff(&c.predicted[..1400], &desired[..1400]);
        assert!(first < 1e-10, "{first}");
        // what is left is the rounding of the ramp's corners, ~Δv·σ/√(2π)
        let rounding = 0.05 * c.smoothing_s / (2.0 * std::f64::consts::PI).sqrt();
        assert!(
            c.predicted_error.max_abs < 2.0 * rounding,
            "{} vs {rounding}",
            c.predicted_error.max_abs
        );
    }

    #[test]
    fn an_unreachable_limit_is_refused_with_the_achievable_figures() {
        let desired = Ramp::default().generate(5000.0, 0.8).unwrap();
        let cfg = CompensateConfig {
            max_velocity: 0.01,
            ..CompensateConfig::default()
        };
        let e = compensate_model(&rig_model(), &desired, DT, &cfg).unwrap_err();
        let Error::LimitUnreachable {
            achievable, plain, ..
        } = e
        else {
            panic!("{e}")
        };
        assert!((plain - 0.05).abs() < 1e-9);
        assert!(achievable >= 0.05);
        assert!(e.to_string().contains("limit 0.01 m/s"), "{e}");
        // a compensated command that cannot meet a limit the plain one meets: plain
        let cfg = CompensateConfig {
            max_velocity: 0.06,
            max_acceleration: f64::INFINITY,
            max_smoothing: 0.0,
            ..CompensateConfig::default()
        };
        let c = compensate_model(&rig_model(), &desired, DT, &cfg).unwrap();
        assert!(c.fallback.is_none(), "{:?}", c.fallback);
        // held back where it exceeds the limit, compensated elsewhere
        assert!(
            c.held_back_share > 0.0 && c.held_back_share < 0.5,
            "{}",
            c.held_back_share
        );
        assert!(
            c.peak_velocity <= 0.06 * (1.0 + 1e-9),
            "{}",
            c.peak_velocity
        );
        let (v, _) = peaks(&c.command, DT).0;
        assert!(v <= 0.06 * (1.0 + 1e-9), "{v}");
        assert!(c.benefit.expected_benefit > 2.0, "{:?}", c.benefit);
        assert!(c.command.iter().zip(&desired).any(|(a, b)| a != b));
        // a limit the plain ramp meets only just: held back everywhere it moves → plain
        let cfg = CompensateConfig {
            max_velocity: 0.05 * (1.0 + 1e-12),
            ..cfg
        };
        let c = compensate_model(&rig_model(), &desired, DT, &cfg).unwrap();
        assert!(
            c.peak_velocity <= 0.05 * (1.0 + 1e-9),
            "{}",
            c.peak_velocity
        );
    }

    #[test]
    fn a_slow_axis_ramp_is_slewed_to_its_correction_within_the_limits() {
        // a lag of τ = 50 ms (Kv = 20 1/s) on a 0.1 m/s ramp: a following
        // error of τ·v = 5 mm that no smoothing of ≤ 20 ms can build within
        // twice the ramp's velocity; slewed at the limits it is built in
        // ~0.1 s around each corner and the ramp between is exact
        let dt = 1e-3;
        let tau = 0.05;
        let tf = crate::lti::TransferFunction::new(vec![1.0], vec![tau, 1.0]).unwrap();
        let model = LinearModel::continuous(&tf);
        let v = 0.1;
        let desired: Vec<f64> = (0..2000)
            .map(|k| v * dt * (k as f64 - 200.0).clamp(0.0, 1000.0))
            .collect();
        let cfg = CompensateConfig {
            max_velocity: 2.0 * v,
            max_acceleration: 1.5 * v / dt,
            ..CompensateConfig::default()
        };
        let c = compensate_model(&model, &desired, dt, &cfg).unwrap();
        assert!(c.fallback.is_none(), "{:?}", c.fallback);
        let ((pv, _), (pa, _)) = peaks(&c.command, dt);
        assert!(pv <= 2.0 * v * (1.0 + 1e-9), "velocity {pv}");
        assert!(pa <= 1.5 * v / dt * (1.0 + 1e-9), "acceleration {pa}");
        // the plain ramp leaves τ·v over the ramp; the slewed command only
        // the corners: rms by the model several times lower
        let plain = c.predicted_plain_error.rms;
        assert!((plain - 3.45e-3).abs() < 0.3e-3, "plain {plain}");
        assert!(
            c.predicted_error.rms < plain / 4.0,
            "{} vs {plain}",
            c.predicted_error.rms
        );
        assert!(c.slewed);
        assert!(
            c.held_back_share > 0.0 && c.held_back_share < 0.3,
            "{}",
            c.held_back_share
        );
        // mid-ramp the command leads the desired by the sampled lag's ramp
        // error, v·Δt/(1 − e^{−Δt/τ}) (τ·v and half a sample)
        let lead = c.command[700] - desired[700];
        let want = v * dt / (1.0 - (-dt / tau).exp());
        assert!((lead - want).abs() < 1e-9, "lead {lead}, want {want}");
    }

    #[test]
    fn the_plain_command_is_sent_when_the_model_expects_little_or_fits_poorly() {
        let desired = Scenario::Scurve.command(5000.0, 0.4, 0).unwrap();
        let good =
            compensate_model(&rig_model(), &desired, DT, &CompensateConfig::default()).unwrap();
        assert!(good.fallback.is_none());
        let b = good.benefit;
        assert!(b.expected_benefit > 100.0);
        // a model that explains only 20 % of the following error
        let cfg = CompensateConfig {
            quality: ModelQuality {
                position_fit_percent: Some(99.9),
                error_fit_percent: Some(20.0),
                noise_rms_m: None,
            },
            ..CompensateConfig::default()
        };
        let c = compensate_model(&rig_model(), &desired, DT, &cfg).unwrap();
        let Some(Fallback::SmallBenefit { expected, .. }) = c.fallback else {
            panic!("{:?}", c.fallback)
        };
        let want = b.predicted_plain_rms_m
            / (b.predicted_compensated_rms_m + 0.8 * b.predicted_plain_rms_m);
        assert!((expected - want).abs() < 1e-9 * want);
        assert_eq!(c.command, desired);
        assert_eq!(c.predicted, c.predicted_plain);
        assert_eq!(c.predicted_error, c.predicted_plain_error);
        // a poor free-run fit
        let cfg = CompensateConfig {
            quality: ModelQuality {
                position_fit_percent: Some(80.0),
                error_fit_percent: None,
                noise_rms_m: None,
            },
            ..CompensateConfig::default()
        };
        let c = compensate_model(&rig_model(), &desired, DT, &cfg).unwrap();
        assert!(matches!(c.fallback, Some(Fallback::PoorFit { .. })));
        // and never when disabled
        let cfg = CompensateConfig {
            fallback: false,
            ..cfg
        };
        let c = compensate_model(&rig_model(), &desired, DT, &cfg).unwrap();
        assert!(c.fallback.is_none());
    }

    #[test]
    fn a_model_of_an_axis_that_already_follows_adds_only_the_residual() {
        // an axis with feed-forward: G = (1 + 0.02·(q⁻¹ − 1))-like, error tiny
        let m = LinearModel::discrete(vec![0.98, 0.02], vec![1.0], DT).unwrap();
        let desired = Scenario::Scurve.command(5000.0, 0.4, 0).unwrap();
        let c = compensate_model(&m, &desired, DT, &CompensateConfig::default()).unwrap();
        assert!(c.fallback.is_none());
        // u − y_d = (G⁻¹ − 1)·y_d: the inverse of 0.98 + 0.02 q⁻¹ is a causal recursion
        let mut want = vec![0.0; desired.len()];
        let mut prev = 0.0;
        for k in 0..desired.len() {
            let d = desired[k] - desired[0];
            want[k] = (d - 0.02 * prev) / 0.98;
            prev = want[k];
        }
        let diff = c
            .command
            .iter()
            .zip(&want)
            .map(|(u, w)| (u - desired[0] - w).abs())
            .fold(0.0, f64::max);
        assert!(diff < 1e-15, "{diff}");
    }
}
