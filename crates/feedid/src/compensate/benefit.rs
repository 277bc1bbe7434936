//! "Never worse": how good the model is, what the compensation is expected
//! to gain, and when to send the plain command instead.
//!
//! The model `G` predicts, for the plain command `y_d` and for the
//! compensated command `u`, the tracking errors
//!
//! ```text
//! e_plain = G·y_d − y_d,      e_comp = G·u − y_d            (rms over the trajectory)
//! ```
//!
//! The model is not the axis: on a recording of the axis (the identification
//! run or another) its free-run error `y − ŷ` is compared with the following
//! error `y − u` there. The **error fit**
//!
//! ```text
//! fit_e = 100·(1 − ‖y − ŷ‖ / ‖(y − u) − mean(y − u)‖)   [%]
//! ```
//!
//! is the share of the axis's following error that the model explains,
//! both norms without the recording's measurement noise (`σ̂` per sample,
//! the noise level of the residual: second differences, as the learning
//! estimates it), which no model explains and the axis does not follow (the
//! position fit, `100·(1 − ‖y − ŷ‖/‖y − ȳ‖)`, is dominated by the motion
//! itself and says little on an axis with feed-forward, whose following
//! error is tiny). What the model does not explain stays after compensation:
//! the expectation can never be below the model's own error, so the
//! expected rms and benefit are
//!
//! ```text
//! e_model    = (1 − fit_e/100)·rms(e_plain)                  (error fit known: --check)
//!            = (1 − fit_y/100)·rms(y_d − mean(y_d))          (else: the position fit)
//! e_expected = max(√(rms(e_comp)² + e_model²), rms(e_plain)/1000)
//! benefit    = rms(e_plain) / e_expected                     (≤ 1000, MAX_BENEFIT)
//! ```
//!
//! The model's error and the residual it predicts add in quadrature: what
//! the model misses is uncorrelated with what it predicts (their plain sum
//! would double the expectation where the two are of one size).
//!
//! With **two runs of the same program** ([`ModelQuality::from_two_runs`]:
//! the identification run and a check run) the noise is taken out by the
//! cross-products of the two runs' residuals instead of an estimate of its
//! level: independent between the runs, it leaves `Σ r₁·r₂` the noise-free
//! squared error in expectation, whatever its spectrum (an encoder's
//! rounding, constant at rest, is invisible to second differences). The
//! rounding both runs share (the same trajectory reads the same counts) is
//! taken out: from the positions' grid, or from the encoder's resolution
//! counted on the model's trajectory (`shared_rounding`).
//!
//! The second form scales the model's free-run error on its identification
//! recording (a share `1 − fit_y` of that recording's motion) to the motion
//! of the desired trajectory: a model that misses 0.07 % of a 20 mm move
//! misses micrometres, whatever its prediction of the compensated error
//! says. With neither fit known the expectation is the model's prediction
//! alone ([`Benefit::model_error_from`] says which). The plain command is
//! sent instead — a [`Fallback`], reported with a warning — when the
//! position fit is below [`super::CompensateConfig::min_fit_percent`], when
//! the benefit is below [`super::CompensateConfig::min_benefit`], or when
//! the compensated command cannot meet the limits but the plain one does.

use serde::Serialize;

use crate::error::{Error, Result};
use crate::ident::LinearModel;
use crate::recording::Recording;
use crate::stats::{error_fit_percent, noise_level_of_run, resolution};

/// The largest expected benefit stated (plain rms over expected rms): the
/// expected compensated error is never below `1/MAX_BENEFIT` of the plain
/// one.
pub const MAX_BENEFIT: f64 = 1000.0;

/// How well a model reproduces the axis (free run over a recording).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct ModelQuality {
    /// Free-run position fit \[%\] (NRMSE; e.g. `identify --model-out`'s).
    pub position_fit_percent: Option<f64>,
    /// Share of the following error the model explains \[%\] (module doc).
    pub error_fit_percent: Option<f64>,
    /// Noise of the recording the fits were measured on \[m\] (module doc;
    /// `None`: not measured, the fits count it as the model's error).
    pub noise_rms_m: Option<f64>,
}

impl ModelQuality {
    /// [`ModelQuality::from_run`] on a check recording of the axis, whose
    /// sampling must be a discrete model's (else
    /// [`Error::SampleTimeMismatch`]). Across dropped samples
    /// ([`Recording::gaps`]) the model runs on through the regular grid on
    /// the command interpolated there ([`Recording::fill_gaps`]) and only
    /// the measured samples are compared.
    pub fn from_recording<S: AsRef<[f64]>>(
        model: &LinearModel,
        check: &Recording<S>,
    ) -> Result<Self> {
        at_model_rate(model, check.dt())?;
        if check.gaps().is_empty() {
            return Self::from_run(model, check.command(), check.position(), check.dt());
        }
        let grid = check.fill_gaps(check.command())?;
        Self::from_grid(
            model,
            &grid,
            check.command(),
            check.position(),
            &check.grid_indices(),
            check.dt(),
        )
    }

    /// Both fits of `model` run free (deviations from the first sample,
    /// the model rescaled to unit DC gain as the compensation uses it) on
    /// the `command` of a recording of the axis at interval `dt` \[s\],
    /// against its measured `position`.
    ///
    /// ```
    /// use feedid::compensate::ModelQuality;
    /// use feedid::ident::LinearModel;
    /// let m = LinearModel::discrete(vec![0.0, 0.2], vec![1.0, -0.8], 1e-3).unwrap();
    /// let u: Vec<f64> = (0..500).map(|k| ((k / 50) % 2) as f64).collect();
    /// let y = m.simulate(&u).unwrap();
    /// let q = ModelQuality::from_run(&m, &u, &y, 1e-3).unwrap();
    /// assert!(q.error_fit_percent.unwrap() > 99.999);
    /// ```
    pub fn from_run(
        model: &LinearModel,
        command: &[f64],
        position: &[f64],
        dt: f64,
    ) -> Result<Self> {
        if command.len() != position.len() {
            return Err(Error::LengthMismatch {
                what: "command and position of the model check",
                expected: command.len(),
                actual: position.len(),
            });
        }
        let rows: Vec<usize> = (0..command.len()).collect();
        Self::from_grid(model, command, command, position, &rows, dt)
    }

    /// [`ModelQuality::from_run`] with the model run on `grid` (the command
    /// on the regular grid through dropped samples) and compared at the
    /// measured samples: `command[j]`, `position[j]` at grid index `rows[j]`.
    fn from_grid(
        model: &LinearModel,
        grid: &[f64],
        command: &[f64],
        position: &[f64],
        rows: &[usize],
        dt: f64,
    ) -> Result<Self> {
        let run = FreeRun::of(model, grid, command, position, rows, dt)?;
        // the measurement noise is in the residual and in the following
        // error alike, and no model explains it: both without it
        let noise = noise_level_of_run(&run.residual, position);
        Ok(Self {
            position_fit_percent: run.position_fit(noise),
            error_fit_percent: error_fit_percent(&run.residual, &run.following, noise),
            noise_rms_m: Some(noise),
        })
    }

    /// [`ModelQuality::from_two_runs`] on two recordings of the same program
    /// on the axis, complete (no dropped samples, else
    /// [`Error::GapsInCheckRun`]) and, for a discrete model, at its sampling
    /// (else [`Error::SampleTimeMismatch`]).
    pub fn from_two_recordings<S: AsRef<[f64]>, T: AsRef<[f64]>>(
        model: &LinearModel,
        first: &Recording<S>,
        second: &Recording<T>,
        encoder: Option<f64>,
    ) -> Result<Self> {
        for (run, (dt, gaps)) in [(first.dt(), &first.gaps()), (second.dt(), &second.gaps())]
            .into_iter()
            .enumerate()
        {
            at_model_rate(model, dt)?;
            if !gaps.is_empty() {
                return Err(Error::GapsInCheckRun {
                    run: run + 1,
                    dropped: gaps.iter().map(|g| g.missing).sum(),
                });
            }
        }
        Self::from_two_runs(
            model,
            (first.command(), first.position()),
            (second.command(), second.position()),
            first.dt(),
            encoder,
        )
    }

    /// Both fits of `model` from **two runs of the same command** on the
    /// axis (`first` and `second`: command and measured position, equal
    /// lengths, at interval `dt` \[s\]), with the noise taken out by
    /// their cross-products instead of an estimate of its level: the
    /// measurement noise of two runs is independent, what the model does
    /// not explain is the same in both, so
    ///
    /// ```text
    /// ‖y − ŷ‖²_sys = Σ r₁·r₂,   ‖f − f̄‖²_sys = Σ (f₁ − f̄₁)·(f₂ − f̄₂)   (r = y − ŷ, f = y − u)
    /// ```
    ///
    /// are the noise-free squared norms in expectation, whatever the noise's
    /// spectrum — an encoder's rounding, constant at rest and slowly varying
    /// in slow motion, escapes the second differences a single run's noise
    /// level is estimated from ([`ModelQuality::from_run`]) and would count
    /// as the model's error. The rounding both runs share is taken out too
    /// (`shared_rounding`): from the positions' own grid where they lie on
    /// one, else from `encoder`, the encoder's resolution \[m\] as its data
    /// sheet gives it (`None`: unknown). The position fit and the noise
    /// level are the second run's ([`ModelQuality::from_run`]). The
    /// commands must agree (to a millionth of their range; else
    /// [`Error::DifferentPrograms`]).
    ///
    /// ```
    /// use feedid::compensate::ModelQuality;
    /// use feedid::ident::LinearModel;
    /// let m = LinearModel::discrete(vec![0.0, 0.2], vec![1.0, -0.8], 1e-3).unwrap();
    /// let u: Vec<f64> = (0..2000).map(|k| ((k / 200) % 2) as f64).collect();
    /// let y = m.simulate(&u).unwrap();
    /// // two runs with independent "noise" of ±0.01
    /// let y1: Vec<f64> = y.iter().enumerate().map(|(k, v)| v + 0.01 * ((k * 7 % 13) as f64 - 6.0) / 6.0).collect();
    /// let y2: Vec<f64> = y.iter().enumerate().map(|(k, v)| v + 0.01 * ((k * 5 % 11) as f64 - 5.0) / 5.0).collect();
    /// let q = ModelQuality::from_two_runs(&m, (&u, &y1), (&u, &y2), 1e-3, None).unwrap();
    /// assert!(q.error_fit_percent.unwrap() > 95.0);
    /// ```
    pub fn from_two_runs(
        model: &LinearModel,
        first: (&[f64], &[f64]),
        second: (&[f64], &[f64]),
        dt: f64,
        encoder: Option<f64>,
    ) -> Result<Self> {
        if let Some(q) = encoder {
            if !(q.is_finite() && q > 0.0) {
                return Err(Error::InvalidParameter {
                    name: "encoder resolution",
                    value: q,
                    reason: "must be a positive length",
                });
            }
        }
        let (u1, y1) = first;
        let (u2, y2) = second;
        for (what, u, y) in [
            ("command and position of the first model check run", u1, y1),
            ("command and position of the second model check run", u2, y2),
            ("commands of the two model check runs", u1, u2),
        ] {
            if u.len() != y.len() {
                return Err(Error::LengthMismatch {
                    what,
                    expected: u.len(),
                    actual: y.len(),
                });
            }
        }
        let range = u1.iter().fold(f64::NEG_INFINITY, |m, v| m.max(*v))
            - u1.iter().fold(f64::INFINITY, |m, v| m.min(*v));
        if let Some(k) = (0..u1.len()).find(|&k| (u1[k] - u2[k]).abs() > 1e-6 * range.max(0.0)) {
            return Err(Error::DifferentPrograms {
                sample: k,
                first: u1[k],
                second: u2[k],
            });
        }
        let rows: Vec<usize> = (0..u1.len()).collect();
        let a = FreeRun::of(model, u1, u1, y1, &rows, dt)?;
        let b = FreeRun::of(model, u2, u2, y2, &rows, dt)?;
        let noise = noise_level_of_run(&b.residual, y2);
        let n = a.following.len() as f64;
        let (mf1, mf2) = (
            a.following.iter().sum::<f64>() / n,
            b.following.iter().sum::<f64>() / n,
        );
        let (mut rr, mut ff) = (0.0, 0.0);
        for k in 0..a.residual.len() {
            rr += a.residual[k] * b.residual[k];
            ff += (a.following[k] - mf1) * (b.following[k] - mf2);
        }
        rr = match shared_rounding(y1, y2, encoder, &b.travel) {
            Rounding::Grid(v) => rr - n * v,
            // counted on the model's trajectory, not the axis's: off by as
            // much as itself where the motion spans few counts, so it
            // takes out at most three quarters of the cross-products
            // (the model's error at least half their rms)
            Rounding::Travel(v) => (rr - n * v).max(rr / 4.0),
            Rounding::None => rr,
        };
        let error_fit =
            (ff > 0.0 && rr.is_finite()).then(|| 100.0 * (1.0 - (rr.max(0.0) / ff).sqrt()));
        Ok(Self {
            position_fit_percent: b.position_fit(noise),
            error_fit_percent: error_fit,
            noise_rms_m: Some(noise),
        })
    }
}

/// The encoder's rounding that two runs of one program share, per sample
/// \[m²\] (it is not the axis's error: the true position has none, but
/// the cross-products count it as the model's).
///
/// * Positions on a grid ([`resolution`] of both runs, one `q`): the noise
///   is before the encoder's count, and where it is below `q` the rounding
///   repeats from run to run. Its share is what the rounding's `q²/12`
///   leaves beyond half the variance of the runs' difference (the part of
///   rounding and noise that does not repeat): `max(0, q²/12 − var(y₁ −
///   y₂)/2)`.
/// * Positions off any grid, with the encoder's resolution `q` given: the
///   noise is after the count (an analogue chain, an interpolator) and does
///   not change which count the same trajectory reads, so the rounding
///   repeats whole. The true trajectory is not known; the model's, `travel`
///   (its position from the start, where the axis rests on a count), is
///   counted instead: `mean((q·round(d/q) − d)²)` over its samples — `q²/12`
///   in motion over many counts, nothing while the axis rests at its start.
/// * Otherwise 0.
fn shared_rounding(y1: &[f64], y2: &[f64], encoder: Option<f64>, travel: &[f64]) -> Rounding {
    let n = y1.len().min(y2.len());
    if n == 0 {
        return Rounding::None;
    }
    match (resolution(y1), resolution(y2), encoder) {
        (Some(q1), Some(q2), _) if (q1 - q2).abs() <= 1e-6 * q1.max(q2) => {
            let mean = (0..n).map(|k| y1[k] - y2[k]).sum::<f64>() / n as f64;
            let var = (0..n).map(|k| (y1[k] - y2[k] - mean).powi(2)).sum::<f64>() / n as f64;
            Rounding::Grid((q1 * q1 / 12.0 - var / 2.0).max(0.0))
        }
        (None, None, Some(q)) if !travel.is_empty() => Rounding::Travel(
            travel
                .iter()
                .map(|d| (q * (d / q).round() - d).powi(2))
                .sum::<f64>()
                / travel.len() as f64,
        ),
        _ => Rounding::None,
    }
}

/// The rounding two runs share, per sample \[m²\], and how it was found.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Rounding {
    /// From the positions' own grid.
    Grid(f64),
    /// From the encoder's resolution, counted on the model's trajectory.
    Travel(f64),
    /// None found.
    None,
}

/// A check recording sampled every `dt` \[s\] must be at a discrete
/// model's own sampling ([`Error::SampleTimeMismatch`]).
fn at_model_rate(model: &LinearModel, dt: f64) -> Result<()> {
    match model {
        LinearModel::Discrete { dt: m, .. } if (dt - m).abs() > 1e-6 * m => {
            Err(Error::SampleTimeMismatch {
                model: *m,
                actual: dt,
            })
        }
        _ => Ok(()),
    }
}

/// A model run free on a recording of the axis: its residual `y − ŷ` and
/// the following error `y − u` at the measured samples.
struct FreeRun {
    residual: Vec<f64>,
    following: Vec<f64>,
    /// The model's position from its start, `ŷ − y₀`.
    travel: Vec<f64>,
    /// `Σ (y − ȳ)²`.
    ssy: f64,
}

impl FreeRun {
    /// The model (deviations from the first sample, rescaled to unit DC
    /// gain as the compensation uses it) run on `grid`, compared at grid
    /// index `rows[j]` with `command[j]`, `position[j]`.
    fn of(
        model: &LinearModel,
        grid: &[f64],
        command: &[f64],
        position: &[f64],
        rows: &[usize],
        dt: f64,
    ) -> Result<Self> {
        if command.len() < 10 {
            return Err(Error::TooFewSamples {
                what: "a model check",
                needed: 10,
                actual: command.len(),
            });
        }
        // the model starts from rest at the first sample's position: the
        // mean over the rest before the command moves, so that one sample's
        // noise does not offset the whole residual
        let u0 = grid[0];
        let scale = command.iter().fold(0.0_f64, |m, v| m.max((v - u0).abs()));
        let rest = command
            .iter()
            .position(|v| (v - u0).abs() > 1e-12 * scale)
            .unwrap_or(command.len())
            .max(1);
        let y0 = position[..rest].iter().sum::<f64>() / rest as f64;
        let (model, _) = model.without_negligible_pairs(dt * grid.len() as f64)?;
        let model = &model;
        let dev: Vec<f64> = grid.iter().map(|u| u - u0).collect();
        let mut yd = model.simulate_at(&dev, dt)?;
        // as the compensation uses it: rescaled to unit DC gain
        let g = model.discrete_state_space(Some(dt))?.dc_gain()?;
        if g.is_finite() && g.abs() > 1e-12 {
            for v in &mut yd {
                *v /= g;
            }
        }
        let n = command.len() as f64;
        let mean_y = position.iter().sum::<f64>() / n;
        let mut ssy = 0.0;
        let mut residual = Vec::with_capacity(rows.len());
        let mut following = Vec::with_capacity(rows.len());
        let mut travel = Vec::with_capacity(rows.len());
        for (k, &i) in rows.iter().enumerate() {
            residual.push(position[k] - (y0 + yd[i]));
            following.push(position[k] - command[k]);
            travel.push(yd[i]);
            ssy += (position[k] - mean_y).powi(2);
        }
        Ok(Self {
            residual,
            following,
            travel,
            ssy,
        })
    }

    /// Free-run position fit \[%\] without a noise of `noise` per sample.
    fn position_fit(&self, noise: f64) -> Option<f64> {
        let sse = self.residual.iter().map(|r| r * r).sum::<f64>();
        let sse = (sse - noise * noise * self.residual.len() as f64).max(0.0);
        (self.ssy > 0.0 && sse.is_finite()).then(|| 100.0 * (1.0 - (sse / self.ssy).sqrt()))
    }
}

/// Where the model's own error in the expectation comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ModelErrorSource {
    /// The share of the following error the model explains on a recording
    /// of the axis ([`ModelQuality::error_fit_percent`]).
    ErrorFit,
    /// The model's free-run position fit, scaled to the desired motion
    /// ([`ModelQuality::position_fit_percent`]).
    PositionFit,
    /// Neither is known: the model's prediction alone.
    Unknown,
}

/// The model's prediction of the benefit (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Benefit {
    /// Predicted rms of the plain command's tracking error \[m\].
    pub predicted_plain_rms_m: f64,
    /// Predicted rms of the compensated command's tracking error \[m\].
    pub predicted_compensated_rms_m: f64,
    /// The model's own error on this trajectory, the floor of the
    /// expectation (module doc) \[m\].
    pub model_error_rms_m: f64,
    /// Where that floor comes from.
    pub model_error_from: ModelErrorSource,
    /// Expected rms after compensation: the prediction plus the floor \[m\].
    pub expected_compensated_rms_m: f64,
    /// `predicted_plain_rms_m / expected_compensated_rms_m`.
    pub expected_benefit: f64,
}

impl Benefit {
    /// From the predicted rms errors, the rms of the desired motion about its
    /// mean `motion_rms` \[m\] and the model's quality.
    pub fn new(
        plain_rms: f64,
        compensated_rms: f64,
        motion_rms: f64,
        quality: &ModelQuality,
    ) -> Self {
        let share = |fit: f64| (1.0 - fit / 100.0).clamp(0.0, 1.0);
        let (model_error, from) = match (quality.error_fit_percent, quality.position_fit_percent) {
            (Some(f), _) => (share(f) * plain_rms, ModelErrorSource::ErrorFit),
            (None, Some(f)) => (share(f) * motion_rms, ModelErrorSource::PositionFit),
            (None, None) => (0.0, ModelErrorSource::Unknown),
        };
        // no model is trusted to cut the error more than MAX_BENEFIT-fold:
        // beyond that the axis's noise, its encoder and the model's own
        // rounding decide, and a model of unknown error would otherwise
        // promise a billion-fold gain
        let expected = compensated_rms
            .hypot(model_error)
            .max(plain_rms / MAX_BENEFIT);
        let expected_benefit = if expected > 0.0 {
            plain_rms / expected
        } else if plain_rms > 0.0 {
            f64::INFINITY
        } else {
            1.0
        };
        Self {
            predicted_plain_rms_m: plain_rms,
            predicted_compensated_rms_m: compensated_rms,
            model_error_rms_m: model_error,
            model_error_from: from,
            expected_compensated_rms_m: expected,
            expected_benefit,
        }
    }
}

/// Why the plain command is sent instead of the compensated one.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "reason", rename_all = "snake_case")]
pub enum Fallback {
    /// The model's free-run position fit is below the minimum.
    PoorFit {
        /// The fit \[%\].
        fit_percent: f64,
        /// The minimum \[%\].
        min_percent: f64,
    },
    /// The expected benefit is below the minimum.
    SmallBenefit {
        /// The expected benefit (plain rms / compensated rms).
        expected: f64,
        /// The minimum.
        min: f64,
    },
    /// The compensated command exceeds a limit even with the most smoothing
    /// allowed, and the plain command does not.
    Limits {
        /// `"velocity"` or `"acceleration"`.
        quantity: &'static str,
        /// The smallest peak the compensated command reached.
        achievable: f64,
        /// The limit.
        limit: f64,
    },
}

impl std::fmt::Display for Fallback {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Fallback::PoorFit {
                fit_percent,
                min_percent,
            } => write!(
                f,
                "the model's free-run fit {fit_percent:.2} % is below {min_percent} %"
            ),
            Fallback::SmallBenefit { expected, min } => write!(
                f,
                "the model expects the compensation to reduce the rms error only {expected:.2}-fold (minimum {min})"
            ),
            Fallback::Limits {
                quantity,
                achievable,
                limit,
            } => write!(
                f,
                "the compensated command's {quantity} cannot be brought below {achievable:.4} (limit {limit}) with the smoothing allowed, and the plain command's can"
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_benefit_beyond_the_bound_is_promised_whatever_the_model_claims() {
        // a model of unknown error predicting a perfect compensation
        let b = Benefit::new(70e-6, 3e-14, 1e-3, &ModelQuality::default());
        assert_eq!(b.model_error_from, ModelErrorSource::Unknown);
        assert!((b.expected_benefit - MAX_BENEFIT).abs() < 1e-9, "{b:?}");
        assert!((b.expected_compensated_rms_m - 70e-9).abs() < 1e-20);
        // below the bound nothing changes
        let b = Benefit::new(70e-6, 1e-6, 1e-3, &ModelQuality::default());
        assert!((b.expected_benefit - 70.0).abs() < 1e-9);
    }

    #[test]
    fn a_check_recording_must_have_the_discrete_models_sample_time() {
        let m = LinearModel::discrete(vec![0.0, 0.2], vec![1.0, -0.8], 1e-3).unwrap();
        let u: Vec<f64> = (0..500).map(|k| ((k / 50) % 2) as f64).collect();
        let y = m.simulate(&u).unwrap();
        let t = |dt: f64| (0..500).map(|k| k as f64 * dt).collect::<Vec<f64>>();
        let ok = Recording::new(t(1e-3), u.clone(), y.clone()).unwrap();
        assert_eq!(
            ModelQuality::from_recording(&m, &ok).unwrap(),
            ModelQuality::from_run(&m, &u, &y, 1e-3).unwrap()
        );
        let slow = Recording::new(t(2e-3), u, y).unwrap();
        let e = ModelQuality::from_recording(&m, &slow).unwrap_err();
        assert!(
            matches!(e, Error::SampleTimeMismatch { model, actual } if model == 1e-3 && (actual - 2e-3).abs() < 1e-15),
            "{e}"
        );
    }

    #[test]
    fn a_check_recording_with_dropped_samples_is_simulated_through_them() {
        // exact data of the model; samples 120..123 and 333 dropped (the
        // command constant there, so interpolating it is exact): the model
        // explains every measured sample, which it would not if it ran on
        // the measured samples as if they were contiguous
        let m = LinearModel::discrete(vec![0.0, 0.2], vec![1.0, -0.8], 1e-3).unwrap();
        let u: Vec<f64> = (0..500).map(|k| ((k / 50) % 2) as f64).collect();
        let y = m.simulate(&u).unwrap();
        let t: Vec<f64> = (0..500).map(|k| k as f64 * 1e-3).collect();
        let full = Recording::new(t, u, y).unwrap();
        let gapped = full.dropping(&[120, 121, 122, 333]).unwrap();
        assert_eq!(gapped.gaps().len(), 2);
        let q = ModelQuality::from_recording(&m, &gapped).unwrap();
        assert!(q.error_fit_percent.unwrap() > 99.999_999, "{q:?}");
        assert!(q.position_fit_percent.unwrap() > 99.999_999, "{q:?}");
        let contiguous =
            ModelQuality::from_run(&m, gapped.command(), gapped.position(), 1e-3).unwrap();
        assert!(
            contiguous.error_fit_percent.unwrap() < 99.9,
            "{contiguous:?}"
        );
    }

    #[test]
    fn error_fit_measures_the_explained_share_of_the_following_error() {
        // axis: first-order lag; model: the same lag with a 10 % wrong pole shift
        let axis = LinearModel::discrete(vec![0.0, 0.2], vec![1.0, -0.8], 1e-3).unwrap();
        let u: Vec<f64> = (0..2000).map(|k| (k as f64 * 0.01).sin()).collect();
        let y = axis.simulate(&u).unwrap();
        let exact = ModelQuality::from_run(&axis, &u, &y, 1e-3).unwrap();
        assert!(exact.error_fit_percent.unwrap() > 100.0 - 1e-9);
        // a model that predicts y = u (no dynamics) explains none of it
        let none = LinearModel::discrete(vec![1.0], vec![1.0], 1e-3).unwrap();
        let q = ModelQuality::from_run(&none, &u, &y, 1e-3).unwrap();
        let e = q.error_fit_percent.unwrap();
        // ‖y − u‖ / ‖(y − u) − mean‖ ≥ 1 → fit ≤ 0
        assert!(e <= 1e-9, "{e}");
        assert!(q.position_fit_percent.unwrap() > 50.0);
    }

    #[test]
    fn benefit_adds_the_unexplained_share_in_quadrature() {
        let q = ModelQuality {
            position_fit_percent: Some(99.0),
            error_fit_percent: Some(90.0),
            noise_rms_m: None,
        };
        // 0.5 predicted, 10 % of 10 unexplained: √(0.5² + 1²)
        let b = Benefit::new(10.0, 0.5, 1000.0, &q);
        let want = (0.25_f64 + 1.0).sqrt();
        assert!((b.expected_compensated_rms_m - want).abs() < 1e-12);
        assert!((b.expected_benefit - 10.0 / want).abs() < 1e-12);
        assert_eq!(b.model_error_from, ModelErrorSource::ErrorFit);
        let b = Benefit::new(10.0, 0.5, 1000.0, &ModelQuality::default());
        assert!((b.expected_benefit - 20.0).abs() < 1e-12);
        assert_eq!(b.model_error_from, ModelErrorSource::Unknown);
        assert_eq!(Benefit::new(0.0, 0.0, 0.0, &q).expected_benefit, 1.0);
    }

    #[test]
    fn without_an_error_fit_the_position_fit_bounds_the_expectation() {
        // a model that misses 0.07 % of its identification run's motion,
        // on a trajectory of 7 mm rms: 4.9 µm, whatever it predicts
        let q = ModelQuality {
            position_fit_percent: Some(99.93),
            error_fit_percent: None,
            noise_rms_m: None,
        };
        let b = Benefit::new(109e-6, 0.01e-6, 7e-3, &q);
        assert_eq!(b.model_error_from, ModelErrorSource::PositionFit);
        assert!((b.model_error_rms_m - 4.9e-6).abs() < 1e-12, "{b:?}");
        let want = 109.0 / 0.01_f64.hypot(4.9);
        assert!((b.expected_benefit - want).abs() < 1e-9, "{b:?}");
        // a fit above 100 % or below 0 is clamped to a share in [0, 1]
        let q = ModelQuality {
            position_fit_percent: Some(-50.0),
            error_fit_percent: None,
            noise_rms_m: None,
        };
        assert!((Benefit::new(1.0, 0.0, 2.0, &q).model_error_rms_m - 2.0).abs() < 1e-15);
    }

    /// A lag, an axis 10 % slower, and two runs with independent noise of
    /// `noise` rms (seeded), slowly varying (a moving average over 50
    /// samples: as an encoder's rounding in slow motion) when `slow`.
    fn two_noisy_runs(
        noise: f64,
        slow: bool,
    ) -> (LinearModel, Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
        use rand::{Rng, SeedableRng};
        let model = LinearModel::discrete(vec![0.0, 0.2], vec![1.0, -0.8], 1e-3).unwrap();
        let axis = LinearModel::discrete(vec![0.0, 0.18], vec![1.0, -0.82], 1e-3).unwrap();
        let u: Vec<f64> = (0..4000)
            .map(|k| 1e-3 * ((k as f64 - 200.0) / 800.0).clamp(0.0, 1.0))
            .collect();
        let y = axis.simulate(&u).unwrap();
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        let mut noisy = || -> Vec<f64> {
            let w: Vec<f64> = (0..y.len() + 50)
                .map(|_| 3.0_f64.sqrt() * (2.0 * rng.random::<f64>() - 1.0))
                .collect();
            y.iter()
                .enumerate()
                .map(|(k, v)| {
                    let n = if slow {
                        w[k..k + 50].iter().sum::<f64>() / 50.0_f64.sqrt()
                    } else {
                        w[k]
                    };
                    v + noise * n
                })
                .collect()
        };
        let (y1, y2) = (noisy(), noisy());
        (model, u, y, y1, y2)
    }

    #[test]
    fn two_runs_take_out_slowly_varying_noise_one_run_cannot() {
        // the noise-free share of the following error the model misses
        let (model, u, y, _, _) = two_noisy_runs(0.0, false);
        let missed = |q: ModelQuality| 1.0 - q.error_fit_percent.unwrap() / 100.0;
        let exact = missed(ModelQuality::from_run(&model, &u, &y, 1e-3).unwrap());
        assert!(exact > 0.05 && exact < 0.3, "{exact}");
        // white noise up to a third of the following error (6.2 µm at the
        // ramp's speed), or slowly varying noise (fewer independent samples)
        // up to a tenth of it: the cross-products find that share to within
        // 1.5×
        for (slow, levels) in [(false, [1e-7, 1e-6, 2e-6]), (true, [1e-7, 3e-7, 5e-7])] {
            for noise in levels {
                let (model, u, _, y1, y2) = two_noisy_runs(noise, slow);
                let q =
                    ModelQuality::from_two_runs(&model, (&u, &y1), (&u, &y2), 1e-3, None).unwrap();
                let m = missed(q);
                assert!(
                    m < 1.5 * exact && m > exact / 1.5,
                    "noise {noise} (slow: {slow}): {m} against {exact}"
                );
            }
        }
        // one run cannot tell slowly varying noise from the model's error
        let (model, u, _, _, y2) = two_noisy_runs(5e-7, true);
        let one = missed(ModelQuality::from_run(&model, &u, &y2, 1e-3).unwrap());
        assert!(one > 1.5 * exact, "{one} against {exact}");
    }

    #[test]
    fn an_encoders_rounding_that_repeats_in_both_runs_is_not_the_models_error() {
        // the exact model; the positions counted by an encoder of 0.5 µm
        // (a tenth of the ramp's 6 µm following error), noise before it of
        // 1 % of a count (the rounding repeats) or of 2 counts (it does not)
        use rand::{Rng, SeedableRng};
        let (_, u, y, _, _) = two_noisy_runs(0.0, false);
        let axis = LinearModel::discrete(vec![0.0, 0.18], vec![1.0, -0.82], 1e-3).unwrap();
        let q = 0.5e-6;
        let missed = |noise: f64, seed: u64| {
            let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
            let mut run = || -> Vec<f64> {
                y.iter()
                    .map(|v| {
                        let n = noise * 3.0_f64.sqrt() * (2.0 * rng.random::<f64>() - 1.0);
                        q * ((v + n) / q).round()
                    })
                    .collect()
            };
            let (y1, y2) = (run(), run());
            let m = ModelQuality::from_two_runs(&axis, (&u, &y1), (&u, &y2), 1e-3, None).unwrap();
            1.0 - m.error_fit_percent.unwrap() / 100.0
        };
        // what the rounding alone would leave as the model's error
        let f = &y.iter().zip(&u).map(|(a, b)| a - b).collect::<Vec<_>>();
        let mean = f.iter().sum::<f64>() / f.len() as f64;
        let ff = (f.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / f.len() as f64).sqrt();
        let rounding = (q / 12.0_f64.sqrt()) / ff;
        assert!(rounding > 0.02, "{rounding}");
        for (noise, seed) in [(0.01 * q, 1), (2.0 * q, 2)] {
            let m = missed(noise, seed);
            assert!(m < 0.25 * rounding, "noise {noise}: {m} against {rounding}");
        }
        // without the grid (noise after the encoder) and no resolution
        // given, nothing is taken out
        assert_eq!(shared_rounding(&y, &y, None, &y), Rounding::None);
    }

    #[test]
    fn two_runs_of_different_programs_are_refused() {
        let (model, u, _, y1, y2) = two_noisy_runs(1e-7, false);
        let mut other = u.clone();
        other[1000] += 1e-4;
        let e =
            ModelQuality::from_two_runs(&model, (&u, &y1), (&other, &y2), 1e-3, None).unwrap_err();
        assert!(
            matches!(e, Error::DifferentPrograms { sample: 1000, .. }),
            "{e}"
        );
        let e = ModelQuality::from_two_runs(&model, (&u, &y1), (&u[..10], &y2[..10]), 1e-3, None)
            .unwrap_err();
        assert!(matches!(e, Error::LengthMismatch { .. }), "{e}");
        // an encoder resolution that is no length
        for q in [0.0, -1e-6, f64::NAN] {
            let e = ModelQuality::from_two_runs(&model, (&u, &y1), (&u, &y2), 1e-3, Some(q))
                .unwrap_err();
            assert!(matches!(e, Error::InvalidParameter { .. }), "{e}");
        }
    }

    #[test]
    fn rounding_under_noise_after_the_count_is_taken_out_with_the_encoders_resolution() {
        // a model that misses a share of the following error; the positions
        // counted by an encoder whose rounding is half that share, and
        // noise of a fifth of a count added after the count (an analogue
        // chain): off any grid, the rounding repeats whole in both runs
        use rand::{Rng, SeedableRng};
        let (model, u, y, _, _) = two_noisy_runs(0.0, false);
        let missed = |q: ModelQuality| 1.0 - q.error_fit_percent.unwrap() / 100.0;
        let exact = missed(ModelQuality::from_run(&model, &u, &y, 1e-3).unwrap());
        let f = &y.iter().zip(&u).map(|(a, b)| a - b).collect::<Vec<_>>();
        let mean = f.iter().sum::<f64>() / f.len() as f64;
        let ff = (f.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / f.len() as f64).sqrt();
        let q = 0.5 * exact * ff * 12.0_f64.sqrt();
        let mut rng = rand::rngs::StdRng::seed_from_u64(3);
        let mut run = || -> Vec<f64> {
            y.iter()
                .map(|v| {
                    let n = 0.2 * q * 3.0_f64.sqrt() * (2.0 * rng.random::<f64>() - 1.0);
                    q * (v / q).round() + n
                })
                .collect()
        };
        let (y1, y2) = (run(), run());
        assert_eq!(resolution(&y1), None);
        let with = |encoder: Option<f64>| {
            missed(
                ModelQuality::from_two_runs(&model, (&u, &y1), (&u, &y2), 1e-3, encoder).unwrap(),
            )
        };
        // unknown: the rounding counts as the model's error
        let unknown = with(None);
        assert!(unknown > 1.15 * exact, "{unknown} against {exact}");
        // known: most of it taken out (counted on the model's trajectory,
        // whose rounding at the final rest is not the axis's)
        let known = with(Some(q));
        assert!(
            (known - exact).abs() < 0.35 * (unknown - exact),
            "{known} against {exact} ({unknown} unknown)"
        );
        // an encoder far coarser than the model's error: what is taken out
        // leaves at least half the cross-products' rms
        let coarse = with(Some(20.0 * q));
        assert!(
            coarse >= 0.5 * unknown * 0.999,
            "{coarse} against {unknown}"
        );
    }
}
