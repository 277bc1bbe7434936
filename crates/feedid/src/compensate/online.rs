//! Online compensation: each command corrected, before the drive needs it,
//! from a model of the axis's following error identified while it runs.
//!
//! **The model: feed-forward time constants.** A position loop `G` with unit
//! DC gain, expanded at low frequency, leaves the following error
//!
//! ```text
//! e = u − y = (1 − G)·u ≈ α₁·u̇ + α₂·ü + α₃·u⃛
//! ```
//!
//! (velocity, acceleration and jerk of the command sent; `α₁` is the lag,
//! `1/Kv` for a P loop without feed-forward, less with it; dead time adds
//! to every term). The `α` are identified by recursive least squares with
//! exponential forgetting ([`OnlineConfig::lambda`], the update of
//! [`crate::ident::RlsEstimator`]) on the samples around a moving command,
//! the command's derivatives by centred differences (noise-free: only the
//! measured position is noisy, so the estimate is unbiased). The
//! derivatives are scaled by the lag measured on the first moves and
//! regressor and target divided by their recent largest entry, so units
//! and sample rates never change the estimate.
//!
//! ([`OnlineConfig::terms`] of them: velocity and acceleration by default;
//! the jerk term is the least excited and the noisiest.)
//!
//! **The correction** is the inverse of that model to the same order,
//! `G⁻¹ = 1/(1 − x) ≈ 1 + x + x² + x³` with `x = α₁s + α₂s² + α₃s³`:
//!
//! ```text
//! u = r + w·(T₁·ṙ + T₂·r̈ + T₃·r⃛),   T₁ = α₁,  T₂ = α₂ + α₁²,  T₃ = α₃ + 2α₁α₂ + α₁³
//! ```
//!
//! — velocity, acceleration and jerk feed-forward of the desired trajectory
//! `r` (centred differences: two samples of preview; the terms beyond
//! [`OnlineConfig::terms`] are zero — exact for a first-order lag with one
//! term, for a second-order loop with two), the classical
//! feed-forward of a CNC axis with its gains identified and retuned as the
//! axis runs. Exact for the model where the trajectory is slow against the
//! servo's bandwidth; what it does not capture shows in the check below.
//!
//! **The guard.** The correction's weight `w` moves by at most
//! `1/`[`OnlineConfig::blend_samples`] per sample towards 1 while the model
//! is plausible and towards 0 (the plain command) while it is not
//! ([`OnlineState`]): too few updates, a compensation that does worse than
//! plain (the following error achieved, over the recent samples where the
//! command moves, above what the model says the plain command would have
//! left: withheld for the model's memory), a model that does not explain the
//! following error — the mean square of its a-priori error above
//! [`OnlineConfig::max_unexplained_share`]² of the following error's own,
//! over the recent samples where the command moves (regressor at least a
//! tenth of its recent largest; forgetting λ) — or non-finite time
//! constants. Every command then meets [`OnlineConfig::max_velocity`] and
//! [`OnlineConfig::max_acceleration`] (finite differences from the two
//! commands before; where the plain trajectory itself exceeds a limit, its
//! own value there): the correction applied moves towards the one wanted
//! no faster than it can stop there with the acceleration the plain
//! trajectory leaves (so it never overshoots and drifts), and the command
//! is clamped into the interval both limits allow.
//!
//! **Timing.** At sample `k` the position `y[k]` is measured and the
//! command of sample `k + 1` is returned ([`OnlineCompensator::step`]); the
//! desired trajectory must be known [`OnlineConfig::preview`] samples
//! beyond it ([`OnlineCompensator::push_desired`], or
//! [`OnlineCompensator::finish_desired`] at its end: then it rests at its
//! last value). Nothing allocates after [`OnlineCompensator::new`].
//!
//! References: L. Ljung, *System Identification*, 2nd ed., §11.2 (RLS with
//! forgetting); M. Tomizuka, "Zero phase error tracking algorithm for
//! digital control", J. Dyn. Sys. Meas. Control 109 (1987) (model-inverse
//! feed-forward with preview); Y. Altintas, *Manufacturing Automation*,
//! 2nd ed., ch. 6 (velocity and acceleration feed-forward of feed drives).
//!
//! ```
//! use feedid::compensate::{OnlineCompensator, OnlineConfig};
//! // a first-order lag with one sample of delay: y[k] = 0.8·y[k−1] + 0.2·u[k−1]
//! let dt = 1e-3;
//! let mut comp = OnlineCompensator::new(OnlineConfig::default(), dt).unwrap();
//! let preview = comp.config().preview;
//! let desired: Vec<f64> = (0..3000).map(|k| 1e-3 * (k as f64 * dt * 3.0).sin()).collect();
//! for &r in &desired[..=preview] {
//!     comp.push_desired(r).unwrap();
//! }
//! let (mut y, mut u) = (0.0, comp.first_command().unwrap());
//! let (mut y_plain, mut worst, mut worst_plain) = (0.0, 0.0_f64, 0.0_f64);
//! for k in 0..desired.len() - 1 {
//!     match desired.get(k + 1 + preview) {
//!         Some(&r) => comp.push_desired(r).unwrap(),
//!         None => comp.finish_desired(),
//!     }
//!     let next = comp.step(y).unwrap();
//!     y = 0.8 * y + 0.2 * u;
//!     y_plain = 0.8 * y_plain + 0.2 * desired[k];
//!     u = next;
//!     if (2000..2900).contains(&k) {
//!         worst = worst.max((y - desired[k + 1]).abs());
//!         worst_plain = worst_plain.max((y_plain - desired[k + 1]).abs());
//!     }
//! }
//! // the plain command lags by 5 ms (15 µm here); compensated, less than 0.15 µm is left
//! assert!(worst < 0.01 * worst_plain, "{worst} vs {worst_plain}");
//! //! ```

use serde::Serialize;

use crate::error::{Error, Result};
use crate::ident::{fold_scale, has_avx2, rls_update, LinearModel};

/// Largest preview \[samples\].
pub const MAX_PREVIEW: usize = 32;

/// Samples kept per signal (a power of two).
const RING: usize = 128;
const MASK: usize = RING - 1;

/// Derivatives of the command in the model (velocity, acceleration, jerk).
const TERMS: usize = 3;

/// Preview the centred differences of the correction need \[samples\].
const MIN_PREVIEW: usize = 2;

/// Moving samples whose lag sets the time scale of the derivatives.
const SCALE_SAMPLES: usize = 8;

/// Initial covariance of the scaled parameters.
const P0: f64 = 1e4;

/// Covariance of the scaled parameters of a prior model.
const P_PRIOR: f64 = 1.0;

/// Settings of the online compensation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct OnlineConfig {
    /// Forgetting factor λ ∈ (0, 1); default 0.999 (memory ≈ 1000 samples).
    pub lambda: f64,
    /// Samples of the desired trajectory known beyond the sample commanded
    /// (a command lead of `N` samples gives `N − 1`); default 4, at least 2,
    /// at most [`MAX_PREVIEW`].
    pub preview: usize,
    /// Command velocity limit \[m/s\]; default 1.0 (∞ disables).
    pub max_velocity: f64,
    /// Command acceleration limit \[m/s²\]; default 30 (∞ disables).
    pub max_acceleration: f64,
    /// Model updates (samples around a moving command) before the model is
    /// used; default 64.
    pub min_updates: usize,
    /// Largest rms a-priori error of the model relative to the rms
    /// following error it is learnt on (module doc); default 0.5.
    pub max_unexplained_share: f64,
    /// Samples over which the correction is switched on or off; default 32.
    pub blend_samples: usize,
    /// Derivatives in the model and its inverse: 1 velocity, 2 and
    /// acceleration, 3 and jerk; default 2.
    pub terms: usize,
}

impl Default for OnlineConfig {
    fn default() -> Self {
        Self {
            lambda: 0.999,
            preview: 4,
            max_velocity: 1.0,
            max_acceleration: 30.0,
            min_updates: 64,
            max_unexplained_share: 0.5,
            blend_samples: 32,
            terms: 2,
        }
    }
}

impl OnlineConfig {
    /// Check the settings.
    pub fn validate(&self) -> Result<()> {
        if !(MIN_PREVIEW..=MAX_PREVIEW).contains(&self.preview) {
            return Err(Error::InvalidParameter {
                name: "preview",
                value: self.preview as f64,
                reason: "must be 2..=32 samples (a command lead of 3..=33)",
            });
        }
        if !(self.lambda > 0.0 && self.lambda < 1.0) {
            return Err(Error::InvalidParameter {
                name: "lambda",
                value: self.lambda,
                reason: "must be in (0, 1)",
            });
        }
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
        if !(self.max_unexplained_share.is_finite() && self.max_unexplained_share > 0.0) {
            return Err(Error::InvalidParameter {
                name: "max unexplained share",
                value: self.max_unexplained_share,
                reason: "must be finite and > 0",
            });
        }
        if !(1..=TERMS).contains(&self.terms) {
            return Err(Error::InvalidParameter {
                name: "terms",
                value: self.terms as f64,
                reason: "must be 1 (velocity), 2 (and acceleration) or 3 (and jerk)",
            });
        }
        if self.blend_samples == 0 {
            return Err(Error::InvalidParameter {
                name: "blend samples",
                value: 0.0,
                reason: "must be at least 1",
            });
        }
        Ok(())
    }
}

/// What the guard thinks of the current model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum OnlineState {
    /// Too few updates yet (the command has not moved enough).
    Learning,
    /// The model explains too little of the following error
    /// ([`OnlineConfig::max_unexplained_share`]).
    Unexplained,
    /// Non-finite time constants.
    Invalid,
    /// The compensation left more following error than the model says the
    /// plain command would: withheld for the model's memory (`1/(1 − λ)`
    /// samples).
    Worse,
    /// The model is used.
    Active,
}

/// Counters of an online compensation.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct OnlineStats {
    /// Commands returned (the first one included).
    pub commands: usize,
    /// Samples that updated the model.
    pub model_updates: usize,
    /// Commands with the correction's weight ≥ ½.
    pub compensated: usize,
    /// Commands clamped to the velocity or acceleration limit.
    pub limited: usize,
    /// Commands with the model implausible (the weight going to 0).
    pub implausible: usize,
    /// Times the compensation was withheld for doing worse than plain.
    pub withheld: usize,
}

/// Compensation of a command one sample at a time (module doc).
#[derive(Debug, Clone)]
pub struct OnlineCompensator {
    cfg: OnlineConfig,
    dt: f64,
    /// Desired, issued, received (sent) and measured by absolute sample (rings).
    r: Vec<f64>,
    u: Vec<f64>,
    s: Vec<f64>,
    y: Vec<f64>,
    /// Desired samples pushed; whether the trajectory has ended.
    nr: usize,
    finished: bool,
    /// Measurements taken (`y[0..ny]`); commands issued (`u[0..nu]`).
    ny: usize,
    nu: usize,
    // RLS (P = κ·P̃) on θ = [α₁/T, α₂/T², α₃/T³]
    theta: [f64; TERMS],
    p: [f64; TERMS * TERMS],
    kappa: f64,
    psi: [f64; TERMS],
    g: [f64; TERMS],
    avx: bool,
    updates: usize,
    /// Time scale of the derivatives `T` \[s\] (0 until measured), and the
    /// sums that measure it: Σe·u̇, Σu̇², moving samples.
    scale: f64,
    sum_eu: f64,
    sum_uu: f64,
    scale_samples: usize,
    /// Recent largest regressor or target entry, and regressor entry
    /// (decaying with λ).
    typical: f64,
    typical_regressor: f64,
    /// Mean squares of the a-priori error and of the following error.
    ms_error: f64,
    ms_follow: f64,
    /// Mean squares of the following error achieved while compensating and
    /// of the model's estimate of the plain command's, same samples; how
    /// many; compensation withheld until this sample after it did worse.
    ms_achieved: f64,
    ms_plain: f64,
    compared: usize,
    worse_until: usize,
    /// Samples since the command last moved.
    still: usize,
    /// Time constants of the correction `T₁, T₂, T₃` \[s, s², s³\].
    tau: [f64; TERMS],
    /// The following-error model to start from (`[α₁, α₂, α₃]`), if any.
    prior: Option<[f64; TERMS]>,
    /// The correction wanted for the last command \[m\].
    last_target: f64,
    state: OnlineState,
    weight: f64,
    stats: OnlineStats,
}

impl OnlineCompensator {
    /// A compensator for samples `dt` \[s\] apart; allocates every buffer it uses.
    pub fn new(cfg: OnlineConfig, dt: f64) -> Result<Self> {
        cfg.validate()?;
        if !(dt.is_finite() && dt > 0.0) {
            return Err(Error::InvalidParameter {
                name: "sample interval",
                value: dt,
                reason: "must be finite and > 0 (s)",
            });
        }
        let mut s = Self {
            cfg,
            dt,
            r: vec![0.0; RING],
            u: vec![0.0; RING],
            s: vec![0.0; RING],
            y: vec![0.0; RING],
            nr: 0,
            finished: false,
            ny: 0,
            nu: 0,
            theta: [0.0; TERMS],
            p: [0.0; TERMS * TERMS],
            kappa: 1.0,
            psi: [0.0; TERMS],
            g: [0.0; TERMS],
            avx: has_avx2(),
            updates: 0,
            scale: 0.0,
            sum_eu: 0.0,
            sum_uu: 0.0,
            scale_samples: 0,
            typical: 0.0,
            typical_regressor: 0.0,
            ms_error: 0.0,
            ms_follow: 0.0,
            ms_achieved: 0.0,
            ms_plain: 0.0,
            compared: 0,
            worse_until: 0,
            still: usize::MAX,
            tau: [0.0; TERMS],
            prior: None,
            last_target: 0.0,
            state: OnlineState::Learning,
            weight: 0.0,
            stats: OnlineStats::default(),
        };
        s.reset();
        Ok(s)
    }

    /// Forget everything (model, trajectory, counters).
    pub fn reset(&mut self) {
        self.nr = 0;
        self.finished = false;
        self.ny = 0;
        self.nu = 0;
        self.r.fill(0.0);
        self.u.fill(0.0);
        self.s.fill(0.0);
        self.y.fill(0.0);
        self.scale = 0.0;
        self.reset_model();
        self.sum_eu = 0.0;
        self.sum_uu = 0.0;
        self.scale_samples = 0;
        self.worse_until = 0;
        self.still = usize::MAX;
        self.tau = [0.0; TERMS];
        self.last_target = 0.0;
        self.state = OnlineState::Learning;
        self.weight = 0.0;
        self.stats = OnlineStats::default();
    }

    fn reset_model(&mut self) {
        let n = self.cfg.terms;
        self.theta = [0.0; TERMS];
        self.p = [0.0; TERMS * TERMS];
        for i in 0..n {
            self.p[i * n + i] = P0;
        }
        self.kappa = 1.0;
        self.updates = 0;
        if let Some(alpha) = self.prior {
            // the prior's lag sets the time scale; its coefficients start the
            // estimate with a unit covariance (scaled): a few hundred samples
            // of data outweigh it
            self.scale = alpha[0].abs().clamp(self.dt, 1e5 * self.dt);
            let mut f = 1.0;
            for (i, (t, a)) in self.theta.iter_mut().zip(alpha).take(n).enumerate() {
                f *= self.scale;
                *t = a / f;
                self.p[i * n + i] = P_PRIOR;
            }
            self.updates = self.cfg.min_updates;
        }
        self.typical = 0.0;
        self.typical_regressor = 0.0;
        self.ms_error = 0.0;
        self.ms_follow = 0.0;
        self.reset_comparison();
    }

    fn reset_comparison(&mut self) {
        self.ms_achieved = 0.0;
        self.ms_plain = 0.0;
        self.compared = 0;
    }

    /// The settings.
    pub fn config(&self) -> &OnlineConfig {
        &self.cfg
    }

    /// Start from a following-error model `[α₁, α₂, α₃]` \[s, s², s³\]
    /// (e.g. [`following_error_of`] an identified model) instead of from
    /// nothing: the compensation is used from the first sample and the
    /// estimate goes on from there (kept across [`OnlineCompensator::reset`]).
    pub fn set_prior(&mut self, alpha: [f64; TERMS]) -> Result<()> {
        if let Some(v) = alpha.iter().find(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                channel: "prior following-error model".to_string(),
                index: 0,
                value: *v,
            });
        }
        self.prior = Some(alpha);
        self.reset();
        Ok(())
    }

    /// Counters so far.
    pub fn stats(&self) -> OnlineStats {
        self.stats
    }

    /// What the guard thinks of the current model.
    pub fn state(&self) -> OnlineState {
        self.state
    }

    /// Weight of the correction in the last command (0: plain, 1: full).
    pub fn weight(&self) -> f64 {
        self.weight
    }

    /// The identified following-error model `[α₁, α₂, α₃]` \[s, s², s³\]
    /// (zeros before the first moves).
    pub fn following_error_model(&self) -> [f64; TERMS] {
        let t = self.scale;
        [
            self.theta[0] * t,
            self.theta[1] * t * t,
            self.theta[2] * t * t * t,
        ]
    }

    /// Time constants of the correction `[T₁, T₂, T₃]` \[s, s², s³\] in use
    /// (the last plausible model's; zeros before any).
    pub fn time_constants(&self) -> [f64; TERMS] {
        self.tau
    }

    /// Commands issued so far (the next one is for this sample index).
    pub fn commands(&self) -> usize {
        self.nu
    }

    /// Append the next sample of the desired trajectory \[m\] (at most
    /// 64 samples ahead of the next command).
    pub fn push_desired(&mut self, r: f64) -> Result<()> {
        if !r.is_finite() {
            return Err(Error::NonFinite {
                channel: "desired".to_string(),
                index: self.nr,
                value: r,
            });
        }
        if self.finished {
            return Err(Error::InvalidParameter {
                name: "desired sample",
                value: r,
                reason: "the desired trajectory was already finished",
            });
        }
        if self.nr >= self.nu + RING / 2 {
            return Err(Error::InvalidParameter {
                name: "desired look-ahead",
                value: (self.nr - self.nu) as f64,
                reason: "at most 64 samples of the desired trajectory ahead of the next command",
            });
        }
        self.r[self.nr & MASK] = r;
        self.nr += 1;
        Ok(())
    }

    /// The desired trajectory has ended: it rests at its last value.
    pub fn finish_desired(&mut self) {
        self.finished = true;
    }

    /// The first command (sample 0): the first desired value, sent plain.
    pub fn first_command(&mut self) -> Result<f64> {
        if self.nu != 0 {
            return Err(Error::InvalidParameter {
                name: "first command",
                value: self.nu as f64,
                reason: "already issued; call step for the next ones",
            });
        }
        if self.nr == 0 {
            return Err(Error::TooFewSamples {
                what: "desired samples before the first command",
                needed: 1,
                actual: 0,
            });
        }
        let r0 = self.r[0];
        self.u[0] = r0;
        self.s[0] = r0;
        self.nu = 1;
        self.stats.commands = 1;
        Ok(r0)
    }

    /// Desired position at absolute sample `i` (rest at the first value
    /// before 0, at the last value after a finished trajectory).
    fn desired(&self, i: isize) -> f64 {
        if i <= 0 {
            self.r[0]
        } else if (i as usize) < self.nr {
            self.r[i as usize & MASK]
        } else {
            self.r[(self.nr.max(1) - 1) & MASK]
        }
    }

    /// Command issued for absolute sample `i` (rest at the first before 0).
    fn issued(&self, i: isize) -> f64 {
        self.u[i.max(0) as usize & MASK]
    }

    /// Command the axis received at absolute sample `i` (rest at the first
    /// before 0): the one issued, or the one [`OnlineCompensator::step_sent`]
    /// was told.
    fn sent(&self, i: isize) -> f64 {
        self.s[i.max(0) as usize & MASK]
    }

    /// Measure `y[k]` (the position at the sample of the last command) and
    /// get the command of sample `k + 1` \[m\].
    pub fn step(&mut self, measured: f64) -> Result<f64> {
        let k = self.ny;
        let sent = self.u[k & MASK];
        self.step_sent(measured, sent)
    }

    /// As [`OnlineCompensator::step`] when the axis received another
    /// command than the one issued for sample `k` (a recorded run replayed:
    /// its own command): the model learns from what the axis received; the
    /// commands issued stay within the limits from the ones issued before.
    pub fn step_sent(&mut self, measured: f64, sent: f64) -> Result<f64> {
        let k = self.ny;
        if !sent.is_finite() {
            return Err(Error::NonFinite {
                channel: "command sent".to_string(),
                index: k,
                value: sent,
            });
        }
        if !measured.is_finite() {
            return Err(Error::NonFinite {
                channel: "position".to_string(),
                index: k,
                value: measured,
            });
        }
        if self.nu != k + 1 {
            return Err(Error::InvalidParameter {
                name: "measurement",
                value: k as f64,
                reason: "each measurement follows one command (call first_command first)",
            });
        }
        let j = k + 1;
        let need = j + self.cfg.preview;
        if !self.finished && self.nr <= need {
            return Err(Error::TooFewSamples {
                what: "desired samples ahead of the next command (the preview)",
                needed: need + 1,
                actual: self.nr,
            });
        }
        self.y[k & MASK] = measured;
        self.s[k & MASK] = sent;
        self.ny = k + 1;
        self.learn(k);
        self.judge();
        let target = if self.state == OnlineState::Active {
            1.0
        } else {
            0.0
        };
        let step = 1.0 / self.cfg.blend_samples as f64;
        self.weight += (target - self.weight).clamp(-step, step);
        let (r, c) = self.correction(j as isize);
        let u = self.limited(j, r, self.weight * c);
        self.u[j & MASK] = u;
        self.nu = j + 1;
        self.stats.commands += 1;
        if self.weight >= 0.5 {
            self.stats.compensated += 1;
        }
        if self.state != OnlineState::Active {
            self.stats.implausible += 1;
        }
        Ok(u)
    }

    /// Velocity, acceleration and jerk at sample `m` of a signal (centred
    /// differences, samples `m − 2 … m + 2`).
    fn derivatives(&self, at: impl Fn(isize) -> f64, m: isize) -> [f64; TERMS] {
        let dt = self.dt;
        let (a, b, c, d, e) = (at(m - 2), at(m - 1), at(m), at(m + 1), at(m + 2));
        [
            (d - b) / (2.0 * dt),
            (d - 2.0 * c + b) / (dt * dt),
            (e - 2.0 * d + 2.0 * b - a) / (2.0 * dt * dt * dt),
        ]
    }

    /// One RLS update with the sample two before `k` (its centred
    /// derivatives need the commands up to `k`), when the command moved
    /// recently.
    fn learn(&mut self, k: usize) {
        if k < 4 {
            return;
        }
        let moved = self.s[k & MASK] != self.s[(k - 1) & MASK];
        self.still = if moved {
            0
        } else {
            self.still.saturating_add(1)
        };
        // the response of a move is informative until it has settled; a
        // command at rest for long teaches only the noise
        if self.still > RING / 2 {
            return;
        }
        let m = k as isize - 2;
        let du = self.derivatives(|i| self.sent(i), m);
        let e = self.s[m as usize & MASK] - self.y[m as usize & MASK];
        if self.scale == 0.0 {
            // the time scale of the derivatives: the lag on the first moves
            if du[0] != 0.0 {
                self.sum_eu += e * du[0];
                self.sum_uu += du[0] * du[0];
                self.scale_samples += 1;
            }
            if self.scale_samples >= SCALE_SAMPLES {
                let lag = (self.sum_eu / self.sum_uu).abs();
                self.scale = if lag.is_finite() {
                    lag.clamp(self.dt, 1e5 * self.dt)
                } else {
                    self.dt
                };
            }
            return;
        }
        let t = self.scale;
        let n = self.cfg.terms;
        let mut f = 1.0;
        for (i, (p, d)) in self.psi.iter_mut().zip(du).enumerate() {
            f *= t;
            *p = if i < n { d * f } else { 0.0 };
        }
        // one scale for regressor and target: the recent largest entries
        // (decaying with λ), so that units never matter and P stays scaled
        let lambda = self.cfg.lambda;
        let size = self.psi.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
        self.typical = (lambda * self.typical).max(size).max(e.abs());
        let norm = self.typical;
        if !(norm > 0.0 && norm.is_finite()) {
            return;
        }
        for p in self.psi.iter_mut() {
            *p /= norm;
        }
        let target = e / norm;
        // the check counts the samples where the command moves substantially
        self.typical_regressor = (lambda * self.typical_regressor).max(size);
        let counted = size >= 0.1 * self.typical_regressor;
        let r = rls_update(
            self.avx,
            &mut self.p[..n * n],
            &mut self.kappa,
            &self.psi[..n],
            &mut self.theta[..n],
            &mut self.g[..n],
            target,
            lambda,
            n as f64 * P0,
        );
        fold_scale(&mut self.p, &mut self.kappa);
        if !self.theta.iter().all(|v| v.is_finite()) {
            self.reset_model();
            return;
        }
        // (only where the axis received the commands issued: a replayed
        // run's positions answer its own command)
        let received = self.s[m as usize & MASK] == self.u[m as usize & MASK];
        if counted && received && self.weight >= 0.5 {
            // what the compensation achieves against what the model says
            // the plain command would have left, same samples, same scale
            let [a1, a2, a3] = self.following_error_model();
            let dr = self.derivatives(|i| self.desired(i), m);
            let plain = a1 * dr[0] + a2 * dr[1] + a3 * dr[2];
            let achieved = self.desired(m) - self.y[m as usize & MASK];
            if plain.is_finite() {
                self.ms_achieved =
                    lambda * self.ms_achieved + (1.0 - lambda) * (achieved / norm).powi(2);
                self.ms_plain = lambda * self.ms_plain + (1.0 - lambda) * (plain / norm).powi(2);
                self.compared += 1;
            }
        }
        if let Ok(err) = r {
            if counted {
                // in units of the current scale (the ratio is what counts)
                self.ms_error = lambda * self.ms_error + (1.0 - lambda) * err * err;
                self.ms_follow = lambda * self.ms_follow + (1.0 - lambda) * target * target;
            }
            self.updates += 1;
            self.stats.model_updates += 1;
        }
    }

    /// Judge the current model; when plausible, take its time constants.
    fn judge(&mut self) {
        let k = self.ny;
        if k < self.worse_until {
            self.state = OnlineState::Worse;
            return;
        }
        // never worse: compensation that leaves more error than the model
        // says the plain command would is withheld for the model's memory
        if self.compared >= 4 * self.cfg.blend_samples && self.ms_achieved > self.ms_plain {
            let memory = (1.0 / (1.0 - self.cfg.lambda)).min(1e9) as usize;
            self.worse_until = k + memory;
            self.stats.withheld += 1;
            self.reset_comparison();
            self.state = OnlineState::Worse;
            return;
        }
        if self.updates < self.cfg.min_updates {
            self.state = OnlineState::Learning;
            return;
        }
        let share = self.cfg.max_unexplained_share;
        let explained = self.ms_error <= share * share * self.ms_follow;
        if !explained {
            self.state = OnlineState::Unexplained;
            return;
        }
        let [a1, a2, a3] = self.following_error_model();
        let mut tau = [a1, a2 + a1 * a1, a3 + 2.0 * a1 * a2 + a1 * a1 * a1];
        // the inverse to the model's own order
        tau[self.cfg.terms..].fill(0.0);
        if !tau.iter().all(|v| v.is_finite()) {
            self.state = OnlineState::Invalid;
            return;
        }
        self.tau = tau;
        self.state = OnlineState::Active;
    }

    /// The desired position of sample `j` and its correction
    /// `T₁·ṙ + T₂·r̈ + T₃·r⃛`.
    fn correction(&self, j: isize) -> (f64, f64) {
        let d = self.derivatives(|i| self.desired(i), j);
        let c = self.tau.iter().zip(d).map(|(t, v)| t * v).sum::<f64>();
        (self.desired(j), if c.is_finite() { c } else { 0.0 })
    }

    /// The command of sample `j`: the plain `r` plus the part of the
    /// correction `target` the limits allow (module doc): the correction
    /// applied `d = u − r` follows `target` (moving by `Δt`) and closes the
    /// gap no faster than it can stop there (`|Δd − Δt| ≤ √(2·A′·|gap|)`,
    /// `A′` the acceleration the
    /// plain trajectory leaves, at least a quarter of the limit), its change
    /// of speed at most `A′`, the command's velocity within the limit; the
    /// command finally clamped into what both limits allow.
    fn limited(&mut self, j: usize, r: f64, target: f64) -> f64 {
        let dt = self.dt;
        let j = j as isize;
        let (u1, u2) = (self.issued(j - 1), self.issued(j - 2));
        let (r1, r2) = (self.desired(j - 1), self.desired(j - 2));
        let (d1, d2) = (u1 - r1, u2 - r2);
        let vr = r - r1;
        let ar = r - 2.0 * r1 + r2;
        let v = (self.cfg.max_velocity * dt).max(vr.abs());
        let a = (self.cfg.max_acceleration * dt * dt).max(ar.abs());
        let a_free = (a - ar.abs()).max(0.25 * a);
        // in the frame of the wanted correction, which moves by `vt`
        let vt = target - self.last_target;
        self.last_target = target;
        let err = target - d1 - vt;
        let brake = if err == 0.0 {
            0.0
        } else {
            (2.0 * a_free * err.abs()).sqrt()
        };
        let vd = d1 - d2;
        let mut step = vt + err.clamp(-brake, brake);
        step = step.clamp(vd - a_free, vd + a_free);
        step = step.clamp(-v - vr, v - vr);
        // what both limits allow from the two commands before
        let (vlo, vhi) = (u1 - v, u1 + v);
        let (alo, ahi) = (2.0 * u1 - u2 - a, 2.0 * u1 - u2 + a);
        let (lo, hi) = if vlo.max(alo) <= vhi.min(ahi) {
            (vlo.max(alo), vhi.min(ahi))
        } else {
            // the velocity cannot be kept within one sample: acceleration first
            (alo, ahi)
        };
        let u = (r + d1 + step).clamp(lo, hi);
        if (u - (r + target)).abs() > 1e-12 * (r.abs() + target.abs()).max(f64::MIN_POSITIVE) {
            self.stats.limited += 1;
        }
        u
    }
}

/// The following-error model `[α₁, α₂, α₃]` \[s, s², s³\] of an identified
/// model sampled every `dt` \[s\], unit DC gain: the moments of its pulse
/// response `h` (`p = h/Σh`), `α₁ = dt·Σk·p_k`, `α₂ = −dt²/2·Σk²·p_k`,
/// `α₃ = dt³/6·Σk³·p_k` — the expansion of `1 − G(e^{s·dt})` the
/// [`OnlineCompensator`] identifies. A model that does not settle (an
/// integrator, an unstable pole, over two million samples) is refused.
///
/// ```
/// use feedid::compensate::following_error_of;
/// use feedid::ident::LinearModel;
/// // y[k] = 0.8·y[k−1] + 0.2·u[k−1]: mean delay 1/(1 − 0.8) = 5 samples
/// let m = LinearModel::discrete(vec![0.0, 0.2], vec![1.0, -0.8], 1e-3).unwrap();
/// let a = following_error_of(&m, 1e-3).unwrap();
/// assert!((a[0] - 5e-3).abs() < 1e-12);
/// ```
pub fn following_error_of(model: &LinearModel, dt: f64) -> Result<[f64; TERMS]> {
    const MAX_SAMPLES: usize = 2_000_000;
    let sys = model.discrete_state_space(Some(dt))?;
    let n = sys.order();
    let (mut x, mut scratch) = (vec![0.0; n], vec![0.0; n]);
    let mut m = [0.0_f64; 4];
    let (mut peak, mut quiet) = (0.0_f64, 0usize);
    for k in 0..MAX_SAMPLES {
        let u = if k == 0 { 1.0 } else { 0.0 };
        let h = sys.output(&x, u);
        sys.advance(&mut x, u, &mut scratch)?;
        let kf = k as f64;
        m[0] += h;
        m[1] += kf * h;
        m[2] += kf * kf * h;
        m[3] += kf * kf * kf * h;
        peak = peak.max(h.abs());
        let state = x.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
        quiet = if h.abs() <= 1e-15 * peak && state <= 1e-15 * peak.max(f64::MIN_POSITIVE) {
            quiet + 1
        } else {
            0
        };
        if !(h.is_finite() && state.is_finite()) {
            break;
        }
        if quiet >= 16 {
            if m[0].abs() <= 1e-12 || m[0].is_nan() {
                break;
            }
            let p = |i: usize| m[i] / m[0];
            return Ok([dt * p(1), -0.5 * dt * dt * p(2), dt * dt * dt / 6.0 * p(3)]);
        }
    }
    Err(Error::InvalidModel {
        reason: "the model's pulse response does not settle (an integrator, an unstable pole or a zero DC gain): it has no following-error time constants",
    })
}

#[cfg(test)]
mod tests;
