//! What the engine does around every estimator: prediction intervals from
//! the method's own scored errors, and the rejection of isolated wild
//! samples (outliers) before any estimator fits them.
//!
//! # Prediction intervals
//!
//! Every prediction of a window is *scored* once its samples are measured:
//! `e = |y[k] − ŷ[k]|` is the error of the prediction `j` samples ahead
//! (`j = 0 … H−1`). A new prediction `ŷ` at `j` samples ahead, in the
//! command regime `r` ([`Regime`]: at rest, a start of motion, constant
//! velocity, accelerating, a reversal — classified from the command over
//! the horizon), gets the interval `ŷ ± s_r·m_{r,j}`:
//!
//! * `m_{r,j}`, the *scale*: the median of the last [`SCALE_MEMORY`](super::calibration::SCALE_MEMORY) (20)
//!   errors at step `j` in regime `r` (their mean while the median is 0,
//!   a held position read by a coarse encoder). Errors
//!   differ most between the regimes — a start of motion or a square
//!   wave's edge misses by orders of magnitude more than a position at
//!   rest — and the median follows a fall of the errors (a window model
//!   that has converged) within half its memory.
//! * `s_r`, the regime's *factor*, calibrates the scale to the probability
//!   `P` ([`GuardConfig::interval`]) by adaptive conformal inference
//!   (Gibbs & Candès, *Adaptive conformal inference under distribution
//!   shift*, NeurIPS 2021; in the multiplicative form of Angelopoulos,
//!   Candès & Tibshirani, *Conformal PID control for time series
//!   prediction*, 2023): after each scored sample of the regime,
//!
//!   ```text
//!   s_r ← s_r · e^{η·P}        if y[k] was outside the interval it was given,
//!   s_r ← s_r · e^{−η·(1−P)}   otherwise        (η = GuardConfig::adaptation)
//!   ```
//!
//!   (faster while the factor is young: `η_n = max(η, 1/√(n+1))` after
//!   `n` updates; `s_r` starts at 3, about the ratio of the 95 % quantile
//!   to the median of Gaussian errors, and stays within [`FACTOR_RANGE`](super::calibration::FACTOR_RANGE)).
//!   Each update takes whether the interval *as given* missed, so
//!   `ln s_r` changes by `η·(miss − (1 − P))` per sample and the share of
//!   misses over the regime's `n_r` scored samples is
//!   `1 − P + ln(s_end/s_start)/(η·n_r)`: within a few percent of `1 − P`
//!   on a thousand samples whatever the errors do, since `s_r` only has to
//!   absorb the ratio of the quantile to the median, not the errors'
//!   scale. The updates are multiplicative and the scale is a median, so
//!   a recording in other units gives proportional widths.
//!
//! Design rationale: a single online quantile per step (the tracker of
//! conformal prediction applied to the errors themselves, with per-regime
//! factors judged against the factor's present value) was tried first.
//! Its width shrinks by only `e^{−η(1−P)}` per error, so after the first,
//! large errors of a window model it stayed wide for thousands of samples
//! (99–100 % inside on short recordings), and judging the factors against
//! their present value rather than the width given let quantised errors
//! settle at 84–89 % on long ones: 183–203 of the zoo's 210 members were
//! within [90, 98] % per method, 206–210 with the scheme above.
//!
//! Until a regime has [`CALIBRATED`] errors at a step, the half-width
//! there is the distance from the last measured position to the prediction
//! plus the range of the measured position over the window plus the
//! distance of the command there from the last position (wide, not
//! calibrated: a start from rest is as wide as the command's move; borrowing the scale of the other regimes, of a position at
//! rest for the first starts of motion, gave the zoo's worst regimes 84 %
//! instead of 87–92 %). The
//! share of measured samples inside their interval is reported as the
//! interval coverage, in all and per regime, with the median width.
//!
//! # Runaway predictions
//!
//! A prediction whose samples leave the envelope of the motion the axis has
//! shown ([`Envelope`]: `κ` times the largest distance travelled and the
//! largest departure from the last velocity in `j` samples, `κ` =
//! [`GuardConfig::runaway`]) or the hull of where its command goes
//! ([`CommandHull`]: between the last position, where it would coast at its
//! recent velocity and the command since, widened by the largest overshoot
//! past it seen) is cut back to the edge, and the interval of a cut sample
//! spans the hold and the cut value; from a sample beyond `κ` times the
//! envelope's edge on, the prediction has run away and the rest of its
//! horizon holds the last position. The hull follows the
//! command the method reads ([`CommandBasis`]). It applies to
//! every method (the paper's reproduction turns it off to stay as
//! published); the windows and samples cut are counted.
//!
//! # Outliers
//!
//! Before each fit, the samples measured since the last fit are compared
//! with their most recent prediction (`j` samples ahead). A sample is an
//! *outlier* when its error exceeds [`GuardConfig::outlier`] times the
//! error scale at `j` — the exponentially weighted rms of the recent errors
//! there (weight [`OUTLIER_MEMORY`]), at least the resolution
//! of the data (the smallest non-zero change between consecutive samples,
//! one count of a quantised encoder) — once [`MIN_HISTORY`] errors are
//! known at `j`, while the samples just before and after it are within
//! theirs: a wild sample is isolated, two in a row are a change of the
//! motion and are kept. The last sample before a fit has no successor yet:
//! it is an outlier only if its error also exceeds the factor times the
//! largest change of the position between two consecutive samples seen so
//! far (a jump within one sample that no motion of the recording has come
//! near; the largest change over `H` samples, used before, let a glitch of
//! 0.35 mm through on a fast sine sweep, and every method then predicted
//! its next horizon from it). The measurement itself must also
//! stand out from its neighbours — depart from the mean of the samples on
//! both sides (for the last sample: from the sample before it) by at least
//! half its error — so that a wild *prediction* of a smooth motion (a model
//! oscillating from one step ahead to the next) never makes the measured
//! sample an outlier. An outlier is replaced, in what
//! the estimators see, by its prediction: it is neither fitted nor used as
//! the start of a prediction, and its error does not join the history. The
//! measured value is kept for the scores: the statistics of a run are over
//! the measured positions.
//!
//! # Implausible predictions
//!
//! A prediction is *implausible* when it leaves the last measured position
//! by more than [`GuardConfig::plausibility`] (default 4) times the motion
//! the recording has shown — the larger of the largest range of the
//! measured position over one window so far and the range of the command
//! over the window and the horizon ([`Guard::plausible`]). A position servo
//! follows its command: within a horizon it does not travel four times
//! farther than it ever did within a window and than it is commanded to.
//! Such a prediction comes from a model that has wound up or diverged (on
//! a zoo recording read in mm, an output-error fit thrown off by the
//! rounding predicted 113 mm away on a 0.8 mm motion). The engine withholds
//! it — the window's outcome is `withheld` and none of its samples is
//! scored — and calls [`Estimator::restart`](crate::ident::Estimator::restart):
//! `rls` forgets its model and learns again, `oe` fits the next window
//! with a moving command from its initial estimate. The bound is a ratio
//! of lengths of the recording itself, so it has no unit. `auto` applies
//! the same bound to each of its candidates and so never has a prediction
//! withheld; the paper's method is reproduced as published and is not
//! checked ([`Estimator::checks_plausibility`](crate::ident::Estimator::checks_plausibility)).
//! Until anything has moved there is no scale and nothing is withheld.
//!
//! All buffers are allocated in [`Guard::new`]; the per-sample work is a
//! constant number of operations per pending prediction (at most
//! `⌈H / hop⌉ + 1`).

// Negated comparisons are deliberate (they reject NaN).
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use crate::error::{Error, Result};
use crate::ident::engine::calibration::{adaptation_rates, StepErrors, Tracker, CALIBRATED};
use crate::ident::engine::envelope::Envelope;
use crate::ident::engine::hull::CommandHull;
use crate::ident::engine::regime::{Regime, RegimeClassifier};

/// Errors needed at a step ahead before outliers are detected there.
pub const MIN_HISTORY: usize = 20;

/// Weight of the newest error in the error scale the outlier test uses
/// (an exponentially weighted mean square: a memory of about ten errors).
pub const OUTLIER_MEMORY: f64 = 0.1;

/// Settings of the engine's prediction intervals and outlier rejection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GuardConfig {
    /// Probability `P` of the prediction interval, in (0, 1); default 0.95.
    pub interval: f64,
    /// A measured sample whose error exceeds this many times the recent rms
    /// error at its step ahead (at least the data's resolution), its
    /// neighbours' not, is an outlier (see the module doc); `None` keeps
    /// every sample; default `Some(8.0)`.
    pub outlier: Option<f64>,
    /// Rate η of the interval's adaptation, in (0, 1]: after a scored
    /// sample its regime's factor is multiplied by `e^{η·P}` (the sample
    /// outside its interval) or `e^{−η·(1−P)}` (inside), faster while the
    /// factor is young (`max(η, 1/√(n+1))`, see the module doc); default
    /// 0.2 (chosen on the drive zoo: with 0.1 the paper's method had 198
    /// of 210 members within [90, 98] % and a regime at 78.8 %, against
    /// 209 and 84 %; 0.3 gave as many members within for every method and
    /// intervals 2–12 % wider).
    pub adaptation: f64,
    /// A prediction that leaves the last measured position by more than
    /// this many times the motion the recording has shown (see the module
    /// doc, *Implausible predictions*) is withheld and the estimator
    /// restarts; `None` keeps every prediction; default `Some(4.0)`.
    pub plausibility: Option<f64>,
    /// A predicted sample farther from the last measured position than this
    /// many times the motion the axis has shown in as many samples, or
    /// outside the hull of where its command goes, is cut back (see the
    /// module doc, *Runaway predictions*); `None` keeps every prediction as
    /// the method made it (and tracks neither); default `Some(1.5)`.
    pub runaway: Option<f64>,
}

impl Default for GuardConfig {
    fn default() -> Self {
        Self {
            interval: 0.95,
            outlier: Some(8.0),
            adaptation: 0.2,
            plausibility: Some(4.0),
            runaway: Some(1.5),
        }
    }
}

impl GuardConfig {
    /// Check the settings (`interval` in (0, 1), `outlier` > 1, `adaptation` in (0, 1]).
    pub fn validate(&self) -> Result<()> {
        if !(self.interval > 0.0 && self.interval < 1.0) {
            return Err(Error::InvalidParameter {
                name: "interval",
                value: self.interval,
                reason: "must be in (0, 1) (e.g. 0.95)",
            });
        }
        if let Some(k) = self.outlier {
            if !(k.is_finite() && k > 1.0) {
                return Err(Error::InvalidParameter {
                    name: "outlier",
                    value: k,
                    reason: "must be finite and > 1",
                });
            }
        }
        if !(self.adaptation > 0.0 && self.adaptation <= 1.0) {
            return Err(Error::InvalidParameter {
                name: "interval adaptation",
                value: self.adaptation,
                reason: "must be in (0, 1]",
            });
        }
        if let Some(k) = self.plausibility {
            if !(k.is_finite() && k >= 1.0) {
                return Err(Error::InvalidParameter {
                    name: "plausibility",
                    value: k,
                    reason: "must be finite and ≥ 1",
                });
            }
        }
        if let Some(k) = self.runaway {
            if !(k.is_finite() && k >= 1.0) {
                return Err(Error::InvalidParameter {
                    name: "runaway",
                    value: k,
                    reason: "must be finite and ≥ 1",
                });
            }
        }
        Ok(())
    }
}

/// How the method has the command over its horizon, for the runaway cut's
/// command hull ([`CommandHull`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum CommandBasis {
    /// The command measured (a recording's, or a stream's led far enough
    /// or awaited).
    #[default]
    Measured,
    /// Not read by the method: the guard goes on at the command's last
    /// velocity, and so does the hull.
    Extrapolated,
    /// A guess of the caller's (a stream's extrapolation): no hull.
    Other,
}

/// A newly measured sample during [`Guard::observe`].
#[derive(Debug, Clone, Copy)]
struct Checked {
    y: f64,
    /// Its latest prediction and how many samples ahead it was made.
    latest: Option<(f64, usize)>,
    /// `|y − prediction|` (0 without a prediction).
    excess: f64,
    exceeds: bool,
}

/// A prediction not yet fully measured.
#[derive(Debug, Clone)]
struct Pending {
    start: usize,
    len: usize,
    values: Vec<f64>,
    /// Each value's interval as given, and whether it was calibrated.
    lower: Vec<f64>,
    upper: Vec<f64>,
    calibrated: Vec<bool>,
    /// Each value's regime.
    regime: Vec<Regime>,
    /// The command hull of each value (NaN: none) and the measured
    /// sample, once scored (NaN: an outlier).
    hull_lower: Vec<f64>,
    hull_upper: Vec<f64>,
    measured: Vec<f64>,
}

/// The engine's interval and outlier state for one run (see the module doc).
#[derive(Debug, Clone)]
pub struct Guard {
    config: GuardConfig,
    horizon: usize,
    /// Errors scored per step ahead since the reset.
    scored: Vec<usize>,
    /// The recent errors and their scale per regime and step ahead
    /// (`regime.index() * horizon + j`).
    regime_steps: Vec<StepErrors>,
    /// `(e^{η_n·P}, e^{−η_n·(1−P)})` for a tracker with `n` errors,
    /// `η_n = max(η, 1/√(n+1))`; the last entry (`η`) from then on.
    rates: Vec<(f64, f64)>,
    /// Pending predictions, oldest first (a ring of `slots.len()`).
    slots: Vec<Pending>,
    first: usize,
    count: usize,
    /// Samples below this absolute index have been checked.
    checked: Option<usize>,
    /// Whether the last checked sample exceeded its outlier limit.
    previous_exceeds: bool,
    /// The samples of the current check (scratch).
    batch: Vec<Checked>,
    /// Largest change of the cleaned position between consecutive samples
    /// so far \[m\].
    step: f64,
    /// The last cleaned sample (for `step`).
    last_clean: Option<f64>,
    /// Exponentially weighted mean squared error per step ahead \[m²\].
    mean_square: Vec<f64>,
    /// Smallest non-zero change between consecutive measured samples \[m\]
    /// (the encoder's resolution, for quantised data).
    resolution: f64,
    /// The last measured sample (for the resolution).
    last: Option<f64>,
    outliers: usize,
    /// Largest range of the measured position over one window so far \[m\].
    motion: f64,
    /// Predictions withheld as implausible since the reset.
    implausible: usize,
    /// Per-regime factors on the per-step half-widths.
    factors: [Tracker; 5],
    classifier: RegimeClassifier,
    envelope: Envelope,
    /// The command's reach and swerve over the windows so far, the command
    /// tracked up to this absolute index, and the figures around the
    /// current horizon (scratch).
    command_seen: Envelope,
    command_tracked: Option<usize>,
    /// The command with its horizon extrapolated (scratch).
    command: Vec<f64>,
    /// Where the command goes, on the basis of the command the method is
    /// given (`None`: the horizon's command is neither measured nor the
    /// guard's own extrapolation, and bounds nothing).
    hull: Option<CommandHull>,
    /// The hull's bounds of the current horizon (scratch).
    hull_lower: Vec<f64>,
    hull_upper: Vec<f64>,
    /// Windows and samples cut back as runaways since the reset.
    runaway_windows: usize,
    runaway_samples: usize,
}

impl Guard {
    /// A guard for horizons of `horizon` samples made every `hop` samples.
    pub fn new(config: GuardConfig, horizon: usize, hop: usize) -> Result<Self> {
        config.validate()?;
        let horizon = horizon.max(1);
        let slots = horizon.div_ceil(hop.max(1)) + 1;
        Ok(Self {
            config,
            horizon,
            scored: vec![0; horizon],
            regime_steps: vec![StepErrors::NEW; 5 * horizon],
            rates: adaptation_rates(config.adaptation, config.interval),
            slots: (0..slots)
                .map(|_| Pending {
                    start: 0,
                    len: 0,
                    values: vec![0.0; horizon],
                    lower: vec![0.0; horizon],
                    upper: vec![0.0; horizon],
                    calibrated: vec![false; horizon],
                    regime: vec![Regime::Rest; horizon],
                    hull_lower: vec![f64::NAN; horizon],
                    hull_upper: vec![f64::NAN; horizon],
                    measured: vec![f64::NAN; horizon],
                })
                .collect(),
            first: 0,
            count: 0,
            checked: None,
            previous_exceeds: false,
            batch: Vec::new(),
            step: 0.0,
            last_clean: None,
            mean_square: vec![0.0; horizon],
            resolution: f64::INFINITY,
            last: None,
            outliers: 0,
            motion: 0.0,
            implausible: 0,
            factors: [Tracker::START; 5],
            classifier: RegimeClassifier::default(),
            envelope: Envelope::new(horizon),
            command_seen: Envelope::horizon_only(horizon),
            command_tracked: None,
            command: Vec::new(),
            hull: config.runaway.map(|_| CommandHull::new(horizon, false)),
            hull_lower: vec![f64::NAN; horizon],
            hull_upper: vec![f64::NAN; horizon],
            runaway_windows: 0,
            runaway_samples: 0,
        })
    }

    /// The guard for a method given the horizon's command as `basis` says
    /// (default [`CommandBasis::Measured`]): the runaway cut's command hull
    /// is measured and applied on that basis, or not at all (and not with
    /// the runaway cut off).
    pub fn with_command_basis(mut self, basis: CommandBasis) -> Self {
        self.hull = match basis {
            _ if self.config.runaway.is_none() => None,
            CommandBasis::Measured => Some(CommandHull::new(self.horizon, false)),
            CommandBasis::Extrapolated => Some(CommandHull::new(self.horizon, true)),
            CommandBasis::Other => None,
        };
        self
    }

    /// The settings.
    pub fn config(&self) -> &GuardConfig {
        &self.config
    }

    /// Forget everything (a new recording).
    pub fn reset(&mut self) {
        self.reset_segment();
        self.outliers = 0;
        self.motion = 0.0;
        self.implausible = 0;
        self.runaway_windows = 0;
        self.runaway_samples = 0;
    }

    /// Forget the errors and pending predictions but keep the outlier count
    /// (a new segment of a stream).
    pub fn reset_segment(&mut self) {
        self.scored.fill(0);
        self.regime_steps.fill(StepErrors::NEW);
        self.first = 0;
        self.count = 0;
        self.checked = None;
        self.previous_exceeds = false;
        self.step = 0.0;
        self.last_clean = None;
        self.mean_square.fill(0.0);
        self.resolution = f64::INFINITY;
        self.last = None;
        self.factors = [Tracker::START; 5];
        self.classifier.reset();
        self.envelope.reset();
        self.command_seen.reset();
        self.command_tracked = None;
        if let Some(h) = &mut self.hull {
            h.reset();
        }
    }

    /// Set the outlier count to 0.
    pub fn reset_outliers(&mut self) {
        self.outliers = 0;
    }

    /// Outliers found since the reset.
    pub fn outliers(&self) -> usize {
        self.outliers
    }

    /// Predictions found implausible since the reset ([`Guard::plausible`]).
    pub fn implausible(&self) -> usize {
        self.implausible
    }

    /// Windows whose prediction was cut back as a runaway since the reset.
    pub fn runaway_windows(&self) -> usize {
        self.runaway_windows
    }

    /// Predicted samples cut back as runaways since the reset.
    pub fn runaway_samples(&self) -> usize {
        self.runaway_samples
    }

    /// Whether the prediction `values` of a window is plausible: it leaves
    /// the last measured position `last` by at most
    /// [`GuardConfig::plausibility`] times the larger of the largest range
    /// of the measured position over a window so far (this one's, `spread`,
    /// included) and the range of the command over the window and the
    /// horizon (`command_span`). Counts the implausible ones.
    pub fn plausible(&mut self, values: &[f64], last: f64, spread: f64, command_span: f64) -> bool {
        if spread > self.motion {
            self.motion = spread;
        }
        let Some(f) = self.config.plausibility else {
            return true;
        };
        let motion = self.motion.max(command_span);
        if !(motion > 0.0) {
            // nothing has moved yet: no scale to judge by
            return true;
        }
        let limit = f * motion;
        let ok = values.iter().all(|v| (v - last).abs() <= limit);
        if !ok {
            self.implausible += 1;
        }
        ok
    }

    /// Check the samples measured since the last call, up to `end`
    /// (exclusive): score the pending predictions on `position(k)` (the
    /// measured value) and call `replace(k, prediction)` for each outlier.
    /// `start` is the first sample of the window that ends at `end` (the
    /// first call of a segment takes the motion of its window from there).
    pub fn observe(
        &mut self,
        start: usize,
        end: usize,
        position: impl Fn(usize) -> f64,
        mut replace: impl FnMut(usize, f64),
    ) {
        let from = match self.checked {
            Some(c) => c,
            None => {
                // nothing was predicted before the first window ends; its
                // samples show the motion so far
                if self.config.runaway.is_some() {
                    for k in start..end {
                        self.envelope.track(position(k));
                    }
                }
                self.checked = Some(end);
                return;
            }
        };
        let n_slots = self.slots.len();
        // pass 1: each new sample, its latest prediction and whether its
        // error exceeds the limit
        self.batch.clear();
        for k in from..end {
            let y = position(k);
            let mut latest: Option<(f64, usize)> = None;
            for i in 0..self.count {
                let p = &self.slots[wrap(self.first + i, n_slots)];
                if k >= p.start && k < p.start + p.len {
                    latest = Some((p.values[k - p.start], k - p.start));
                }
            }
            let limit = |j: usize| {
                self.config
                    .outlier
                    .filter(|_| self.scored[j] >= MIN_HISTORY)
                    .map(|f| f * self.mean_square[j].sqrt().max(self.resolution))
            };
            let (excess, exceeds) = match latest {
                Some((yh, j)) => {
                    let e = (y - yh).abs();
                    (e, limit(j).is_some_and(|l| e > l))
                }
                None => (0.0, false),
            };
            self.batch.push(Checked {
                y,
                latest,
                excess,
                exceeds,
            });
        }
        // pass 2: an outlier exceeds its limit, the samples on both sides do
        // not; the last sample (its successor unknown) must also exceed the
        // largest change between two samples seen so far
        let n = self.batch.len();
        for i in 0..n {
            let c = self.batch[i];
            let k = from + i;
            let before = if i == 0 {
                self.previous_exceeds
            } else {
                self.batch[i - 1].exceeds
            };
            // the measurement itself must stand out from its neighbours by
            // half its error: a wild prediction of a smooth motion (an
            // oscillating model) does not make the measurement an outlier
            let previous = if i == 0 {
                self.last
            } else {
                Some(self.batch[i - 1].y)
            };
            let spike = match (previous, self.batch.get(i + 1)) {
                (Some(a), Some(b)) => (c.y - 0.5 * (a + b.y)).abs(),
                (Some(a), None) => (c.y - a).abs(),
                (None, _) => 0.0,
            };
            let outlier = c.exceeds
                && !before
                && spike > 0.5 * c.excess
                && if i + 1 < n {
                    !self.batch[i + 1].exceeds
                } else {
                    c.excess > self.config.outlier.unwrap_or(f64::INFINITY) * self.step
                };
            let y_clean = match (outlier, c.latest) {
                (true, Some((yh, _))) => {
                    replace(k, yh);
                    self.outliers += 1;
                    yh
                }
                _ => c.y,
            };
            if let Some(prev) = self.last {
                let d = (c.y - prev).abs();
                if d > 0.0 && d < self.resolution {
                    self.resolution = d;
                }
            }
            self.last = Some(c.y);
            // the largest change between two samples, on the cleaned ones
            if let Some(p) = self.last_clean {
                self.step = self.step.max((y_clean - p).abs());
            }
            self.last_clean = Some(y_clean);
            if self.config.runaway.is_some() {
                self.envelope.track(y_clean);
            }
            let w = OUTLIER_MEMORY;
            for s in 0..self.count {
                let p = &mut self.slots[wrap(self.first + s, n_slots)];
                if k >= p.start && k < p.start + p.len {
                    let j = k - p.start;
                    // kept for the hull's overshoot (an outlier's value is
                    // not known)
                    p.measured[j] = if outlier { f64::NAN } else { c.y };
                    if !outlier {
                        let e = (c.y - p.values[j]).abs();
                        if e.is_finite() {
                            if p.calibrated[j] {
                                // the interval as given, not as the factor
                                // is now: the long-run share of misses then
                                // follows from the factor's bounds alone
                                let miss = !(c.y >= p.lower[j] && c.y <= p.upper[j]);
                                self.factors[p.regime[j].index()].step(miss, &self.rates);
                            }
                            self.scored[j] += 1;
                            self.regime_steps[p.regime[j].index() * self.horizon + j].push(e);
                            let ms = &mut self.mean_square[j];
                            *ms = if self.scored[j] == 1 {
                                e * e
                            } else {
                                (1.0 - w) * *ms + w * e * e
                            };
                        }
                    }
                }
            }
        }
        if let Some(c) = self.batch.last() {
            self.previous_exceeds = c.exceeds;
        }
        // drop the predictions whose samples are all checked, their
        // samples' departures from the hull taken into its overshoot
        while self.count > 0 {
            let p = &self.slots[self.first];
            if p.start + p.len <= end {
                if let Some(hull) = &mut self.hull {
                    let n = p.len;
                    hull.score(&p.hull_lower[..n], &p.hull_upper[..n], &p.measured[..n]);
                }
                self.first = (self.first + 1) % n_slots;
                self.count -= 1;
            } else {
                break;
            }
        }
        self.checked = Some(end.max(from));
    }

    /// Record a window's prediction `values` of the samples from `start`:
    /// classify their regimes into `regimes` from `command` (the command
    /// over the window and the horizon: its last `values.len()` samples are
    /// the horizon's; with `horizon_known` false those are not read — the
    /// method predicts without them — and the command goes on at its last
    /// velocity instead), write their interval bounds, and cut back a
    /// runaway (`values` and the bounds changed in place; see the module doc).
    /// `last` is the last measured position and `spread` the range of the
    /// measured position over the window (the interval's half-width before
    /// the errors are known). Returns the number of samples cut back.
    #[allow(clippy::too_many_arguments)]
    pub fn predicted(
        &mut self,
        start: usize,
        values: &mut [f64],
        last: f64,
        spread: f64,
        command: &[f64],
        horizon_known: bool,
        lower: &mut [f64],
        upper: &mut [f64],
        regimes: &mut [Regime],
    ) -> usize {
        let given = values.len();
        let len = given
            .min(self.horizon)
            .min(lower.len())
            .min(upper.len())
            .min(regimes.len());
        let (values, lower, upper, regimes) = (
            &mut values[..len],
            &mut lower[..len],
            &mut upper[..len],
            &mut regimes[..len],
        );
        // what the command asks for that the axis has not answered yet: the
        // pairs ending in the horizon, or, where the method predicts without
        // the horizon's command, in the window's last `len` samples (an
        // extrapolated command is a guess, not something asked for)
        let asked = if horizon_known || command.len() < len {
            command
        } else {
            &command[..command.len() - len]
        };
        let (asked_reach, asked_swerve) = if self.config.runaway.is_some() {
            self.command_seen.whole_horizon_of(asked, len)
        } else {
            (0.0, 0.0)
        };
        // index in the recording of the command's first sample, and how
        // many of its samples are the recording's own
        let first = (start + given).saturating_sub(command.len());
        let own = if horizon_known || command.len() < len + 2 {
            command.len()
        } else {
            command.len() - len
        };
        let extrapolated = !(horizon_known || command.len() < len + 2);
        let command = if !extrapolated {
            command
        } else {
            // the command over the horizon as the method knows it: going on
            // at the velocity of the window's last two samples
            let n = command.len();
            self.command.clear();
            self.command.extend_from_slice(&command[..n - len]);
            let (a, b) = (command[n - len - 2], command[n - len - 1]);
            self.command
                .extend((1..=len).map(|j| b + j as f64 * (b - a)));
            &self.command[..]
        };
        if command.len() >= len {
            self.classifier
                .classify(command, first, own, self.horizon, regimes);
        } else {
            regimes.fill(Regime::Rest);
        }
        let n_slots = self.slots.len();
        if self.count == n_slots {
            self.first = (self.first + 1) % n_slots;
            self.count -= 1;
        }
        let slot_index = (self.first + self.count) % n_slots;
        for (j, ((v, lo), hi)) in values
            .iter()
            .zip(lower.iter_mut())
            .zip(upper.iter_mut())
            .enumerate()
        {
            // the scale of the regime's errors at this step, once it has a
            // few (a regime rare so far is not calibrated: wide)
            let t = &self.regime_steps[regimes[j].index() * self.horizon + j];
            let calibrated = t.n >= CALIBRATED;
            let q = if calibrated {
                t.scale() * self.factors[regimes[j].index()].q
            } else {
                // where the prediction goes, how far the window moved and
                // how far the command is from the axis: a start from rest
                // is as wide as the command's first move
                let asked = command
                    .len()
                    .checked_sub(len - j)
                    .map_or(0.0, |i| (command[i] - last).abs());
                (v - last).abs() + spread + if asked.is_finite() { asked } else { 0.0 }
            };
            self.slots[slot_index].calibrated[j] = calibrated;
            *lo = v - q;
            *hi = v + q;
        }
        // the commands up to H samples before the window's end (those the
        // axis has had a horizon to answer) join the command's envelope
        let cut = match self.config.runaway {
            Some(k) => {
                let answered = start.saturating_sub(self.horizon);
                let from = self.command_tracked.unwrap_or(first).max(first);
                for i in from..answered {
                    self.command_seen.track(command[i - first]);
                }
                self.command_tracked = Some(answered.max(from));
                // the command's whole-horizon figures now and as answered
                let (reach, swerve) = (asked_reach, asked_swerve);
                let (r, s) = self.command_seen.seen(self.horizon);
                // figures below a millionth of the command's travel over a
                // horizon are its rounding (a ramp's swerve), not a motion
                let floor = 1e-6 * r.max(reach);
                // the following error now: the axis may close it within
                // the horizon on top of what the command asks
                let lag = command
                    .len()
                    .checked_sub(len + 1)
                    .map_or(0.0, |i| (command[i] - last).abs());
                let lag = if lag.is_finite() { lag } else { 0.0 };
                // the axis's own figure, grown with the command where the
                // command asks for more than it has before (a command that
                // has never moved gives no scale), but never beyond the
                // command's own figure plus the following error: a command
                // that has barely moved would otherwise grow it without end
                let allow = |seen: f64, now: f64, before: f64| {
                    if before > floor && now > before {
                        // (numbers only: selects, not `f64::max`)
                        let grown = seen * (now / before);
                        let grown = if grown < now + lag { grown } else { now + lag };
                        k * if grown > seen { grown } else { seen }
                    } else {
                        k * seen
                    }
                };
                // where the command goes, on the basis the hull was tracked
                // on (the measured command, or the guard's extrapolation)
                // (the hull as given is kept with the prediction: the
                // departures of the measured samples from it are the
                // overshoot)
                let (lo, hi) = (&mut self.hull_lower[..len], &mut self.hull_upper[..len]);
                let slot = &mut self.slots[slot_index];
                let hull = match &self.hull {
                    Some(h)
                        if h.extrapolated() == extrapolated
                            && (horizon_known || extrapolated)
                            && command.len() > len =>
                    {
                        let u = &command[command.len() - len - 1..];
                        let (raw_lo, raw_hi) =
                            (&mut slot.hull_lower[..len], &mut slot.hull_upper[..len]);
                        CommandHull::hull(last, self.envelope.velocity(), u, raw_lo, raw_hi);
                        h.widen(raw_lo, raw_hi, lo, hi);
                        Some((&self.hull_lower[..len], &self.hull_upper[..len]))
                    }
                    _ => {
                        slot.hull_lower.fill(f64::NAN);
                        slot.hull_upper.fill(f64::NAN);
                        None
                    }
                };
                slot.measured.fill(f64::NAN);
                self.envelope.cut(
                    values,
                    last,
                    |_, d, sw| (allow(d, reach, r), allow(sw, swerve, s)),
                    k,
                    hull,
                    lower,
                    upper,
                )
            }
            None => 0,
        };
        if cut > 0 {
            self.runaway_windows += 1;
            self.runaway_samples += cut;
        }
        let slot = &mut self.slots[slot_index];
        slot.start = start;
        slot.len = len;
        slot.values[..len].copy_from_slice(values);
        slot.lower[..len].copy_from_slice(lower);
        slot.upper[..len].copy_from_slice(upper);
        slot.regime[..len].copy_from_slice(regimes);
        self.count += 1;
        if self.checked.is_none() {
            self.checked = Some(start);
        }
        cut
    }
}

/// `i mod n` for `i < 2n` (the ring index of a slot; no division).
#[inline]
fn wrap(i: usize, n: usize) -> usize {
    if i >= n {
        i - n
    } else {
        i
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ramp of one unit per sample (measured `y`, with whatever glitches
    /// and steps) predicted as `k + 0.02` in horizons of `h` samples every
    /// `h` from sample 10; returns what the estimators see and the
    /// replaced samples.
    fn guard_a_ramp(y: &[f64], h: usize) -> (Vec<f64>, Vec<usize>) {
        let mut g = Guard::new(GuardConfig::default(), h, h).unwrap();
        let mut clean = y.to_vec();
        let (mut lo, mut hi) = (vec![0.0; h], vec![0.0; h]);
        let mut regimes = vec![Regime::Rest; h];
        let mut replaced = Vec::new();
        let mut start = 10;
        while start + h <= y.len() {
            g.observe(
                start - 10,
                start,
                |k| y[k],
                |k, v| {
                    replaced.push(k);
                    clean[k] = v;
                },
            );
            let mut pred: Vec<f64> = (start..start + h).map(|k| k as f64 + 0.02).collect();
            let command: Vec<f64> = (start - 10..start + h).map(|k| k as f64).collect();
            g.predicted(
                start,
                &mut pred,
                clean[start - 1],
                1.0,
                &command,
                true,
                &mut lo,
                &mut hi,
                &mut regimes,
            );
            start += h;
        }
        (clean, replaced)
    }

    #[test]
    fn an_isolated_wild_sample_is_replaced_by_its_prediction_and_a_step_is_not() {
        // a ramp predicted with small errors, then a glitch, later a real step
        let mut y: Vec<f64> = (0..400)
            .map(|k| k as f64 + 0.01 * ((k * 7 % 5) as f64))
            .collect();
        y[203] += 1e3;
        for v in &mut y[300..] {
            *v += 50.0;
        }
        let (clean, replaced) = guard_a_ramp(&y, 5);
        assert!(replaced.contains(&203), "{replaced:?}");
        assert!((clean[203] - 203.02).abs() < 1e-12);
        // the step at 300: its first sample may be taken for a glitch, the
        // second one is kept (a second wild sample in a row is a change)
        assert!(!replaced.contains(&301), "{replaced:?}");
        assert_eq!(clean[301], y[301]);
    }

    #[test]
    fn a_glitch_in_the_last_sample_before_a_fit_is_replaced_on_a_fast_motion() {
        // a ramp of one unit per sample (ten per horizon), predicted with
        // small errors; the last sample before the fit at 310 jumps by 30:
        // less than 8 times the motion over a horizon (80), far beyond 8
        // times any change between two samples (8)
        let h = 10;
        let mut y: Vec<f64> = (0..400)
            .map(|k| k as f64 + 0.01 * ((k * 7 % 5) as f64))
            .collect();
        y[309] += 30.0;
        let (clean, replaced) = guard_a_ramp(&y, h);
        // every horizon starts from what the estimators see
        for start in (10..=y.len() - h).step_by(h) {
            assert!(
                (clean[start - 1] - (start - 1) as f64).abs() < 0.1,
                "{start}"
            );
        }
        assert_eq!(replaced, vec![309]);
    }

    #[test]
    fn a_wild_prediction_of_a_smooth_motion_does_not_make_the_measurement_an_outlier() {
        // a smooth ramp predicted well, then by a model oscillating from
        // sample to sample (every other step ahead far off): the
        // measurement is kept, so the estimators never see the wild values
        let h = 10;
        // (the runaway guard off: it would cut the wild steps back)
        let config = GuardConfig {
            runaway: None,
            ..GuardConfig::default()
        };
        let mut g = Guard::new(config, h, h).unwrap();
        let y: Vec<f64> = (0..600).map(|k| 1e-3 * k as f64).collect();
        let (mut lo, mut hi) = (vec![0.0; h], vec![0.0; h]);
        let mut regimes = vec![Regime::Rest; h];
        let mut replaced = Vec::new();
        let mut start = 10;
        while start + h <= y.len() {
            g.observe(start - 10, start, |k| y[k], |k, _| replaced.push(k));
            let mut pred: Vec<f64> = (start..start + h)
                .map(|k| {
                    let wild = start >= 300 && (k - start) % 2 == 1;
                    y[k] + if wild { 1.0 } else { 1e-6 * ((k % 3) as f64) }
                })
                .collect();
            g.predicted(
                start,
                &mut pred,
                y[start - 1],
                1e-2,
                &y[start - 10..start + h],
                true,
                &mut lo,
                &mut hi,
                &mut regimes,
            );
            start += h;
        }
        assert!(replaced.is_empty(), "{replaced:?}");
    }

    /// Guard the predictions `predict(start)` of horizons of `h` samples
    /// every `h` from sample 20 (windows of 20) of the measured `y` under the
    /// command `u`; returns each horizon's start and its guarded values.
    fn guard_predictions(
        y: &[f64],
        u: &[f64],
        h: usize,
        horizon_known: bool,
        basis: CommandBasis,
        predict: impl Fn(usize) -> Vec<f64>,
    ) -> Vec<(usize, Vec<f64>)> {
        let mut g = Guard::new(GuardConfig::default(), h, h)
            .unwrap()
            .with_command_basis(basis);
        let (mut lo, mut hi) = (vec![0.0; h], vec![0.0; h]);
        let mut regimes = vec![Regime::Rest; h];
        let mut out = Vec::new();
        let mut start = 20;
        while start + h <= y.len() {
            g.observe(start - 20, start, |k| y[k], |_, _| {});
            let mut pred = predict(start);
            g.predicted(
                start,
                &mut pred,
                y[start - 1],
                1e-6,
                &u[start - 20..start + h],
                horizon_known,
                &mut lo,
                &mut hi,
                &mut regimes,
            );
            out.push((start, pred));
            start += h;
        }
        out
    }

    #[test]
    fn a_command_that_has_barely_moved_bounds_the_envelope_by_its_own_travel() {
        // an axis at rest (noise of 1 µm) under a command that creeps away
        // from rest as t³ from sample 100 (a jerk-limited start): a model
        // predicting a geometric run-away is cut back to what the axis and
        // the command have shown (µm), however small the command's travel
        // before was compared with now
        let h = 10;
        let n: usize = 200;
        let y: Vec<f64> = (0..n)
            .map(|k| 1e-6 * ((k * 7 % 5) as f64 - 2.0) / 2.0)
            .collect();
        let u: Vec<f64> = (0..n)
            .map(|k| {
                if k < 100 {
                    0.0
                } else {
                    1e-12 * ((k - 100) as f64).powi(3)
                }
            })
            .collect();
        let runaway = |start: usize| -> Vec<f64> {
            (1..=h)
                .map(|j| y[start - 1] - 1e-6 * 2f64.powi(j as i32 + 4))
                .collect()
        };
        for (start, pred) in guard_predictions(&y, &u, h, true, CommandBasis::Measured, runaway) {
            let travel = u[start + h - 1] - u[start.saturating_sub(2 * h)];
            let allowed = 1.5 * (2e-6 + travel.abs() + 2e-6) + 1e-12;
            for v in &pred {
                assert!(
                    (v - y[start - 1]).abs() <= allowed,
                    "start {start}: {v} from {} (allowed {allowed})",
                    y[start - 1]
                );
            }
        }
    }

    #[test]
    fn an_extrapolated_command_does_not_widen_the_envelope() {
        // a square wave of 1 followed with a lag of 5 samples: at the step
        // in the window's last sample, a method that predicts without the
        // horizon's command sees it extrapolated (ten times the step within
        // a horizon); a prediction that follows that guess is cut back to
        // 1.5 times the reach the axis has shown
        let h = 10;
        let n: usize = 400;
        let u: Vec<f64> = (0..n)
            .map(|k| if ((k + 1) / 60) % 2 == 1 { 1.0 } else { 0.0 })
            .collect();
        let y: Vec<f64> = (0..n).map(|k| u[k.saturating_sub(5)]).collect();
        let follow_the_guess = |start: usize| -> Vec<f64> {
            let (a, b) = (u[start - 2], u[start - 1]);
            (1..=h).map(|j| b + j as f64 * (b - a)).collect()
        };
        let guarded = guard_predictions(
            &y,
            &u,
            h,
            false,
            CommandBasis::Extrapolated,
            follow_the_guess,
        );
        // the steps at 119, 179, 239, … fall on the last sample of a window
        let at_steps: Vec<_> = guarded
            .iter()
            .filter(|(start, _)| start % 60 == 0 && *start >= 120)
            .collect();
        assert!(!at_steps.is_empty());
        for (start, pred) in at_steps {
            for v in pred {
                assert!(
                    (v - y[start - 1]).abs() <= 1.5 + 1e-12,
                    "start {start}: {v}"
                );
            }
        }
    }

    /// A first-order follower (no overshoot) of a command stepping by 1 at
    /// `steps`, with a noise of ±1e-4.
    fn follower(n: usize, steps: &[usize]) -> (Vec<f64>, Vec<f64>) {
        let mut c = 0.0;
        let u: Vec<f64> = (0..n)
            .map(|k| {
                if steps.contains(&k) {
                    c = 1.0 - c;
                }
                c
            })
            .collect();
        let mut x = 0.0;
        let y = (0..n)
            .map(|k| {
                x += 0.4 * (u[k.saturating_sub(1)] - x);
                x + 1e-4 * ((k * 7 % 5) as f64 - 2.0) / 2.0
            })
            .collect();
        (u, y)
    }

    #[test]
    fn a_prediction_at_rest_does_not_travel_as_far_as_an_earlier_move() {
        // after a move of 1, command and axis at rest: a model that predicts
        // the axis travelling 0.1 per sample (as far as it moved before) is
        // cut back to the overshoot the axis has shown (its noise), where
        // the envelope of the motion alone lets it travel most of the way
        let h = 10;
        let (u, y) = follower(300, &[45]);
        let travel =
            |start: usize| -> Vec<f64> { (1..=h).map(|j| y[start - 1] - 0.1 * j as f64).collect() };
        let farthest = |basis| {
            let mut far = 0.0f64;
            for (start, pred) in guard_predictions(&y, &u, h, true, basis, travel) {
                if start >= 120 {
                    for v in pred {
                        far = far.max((v - y[start - 1]).abs());
                    }
                }
            }
            far
        };
        let with_hull = farthest(CommandBasis::Measured);
        assert!(with_hull <= 1e-3, "{with_hull}");
        assert!(farthest(CommandBasis::Other) >= 0.5);
    }

    #[test]
    fn a_prediction_the_wrong_way_at_a_step_is_cut_at_the_axis() {
        // the command steps up by 1 two samples into a horizon; a model
        // that predicts the axis going down is cut back to where the axis
        // is (within its overshoot seen, the noise): nothing below it
        let h = 10;
        let (u, y) = follower(400, &[122, 222, 322]);
        let wrong_way = |start: usize| -> Vec<f64> {
            let down = if u[start + 2] > u[start - 1] {
                0.2
            } else {
                0.0
            };
            (1..=h).map(|j| y[start - 1] - down * j as f64).collect()
        };
        for (start, pred) in guard_predictions(&y, &u, h, true, CommandBasis::Measured, wrong_way) {
            if start == 220 || start == 320 {
                for v in pred {
                    assert!(
                        v >= y[start - 1] - 1e-3,
                        "start {start}: {v} from {}",
                        y[start - 1]
                    );
                }
            }
        }
    }

    #[test]
    fn invalid_settings_are_refused() {
        for c in [
            GuardConfig {
                interval: 1.0,
                ..GuardConfig::default()
            },
            GuardConfig {
                outlier: Some(0.5),
                ..GuardConfig::default()
            },
            GuardConfig {
                adaptation: 0.0,
                ..GuardConfig::default()
            },
            GuardConfig {
                runaway: Some(0.5),
                ..GuardConfig::default()
            },
        ] {
            assert!(c.validate().is_err());
        }
    }
}
