//! Estimating a drive structure's physical parameters from a recording of
//! its command and position (closed loop, output error): the parameters
//! named are varied, the others kept at the file's values, until the
//! simulated position ([`DriveStructure::simulate`], from the measured first
//! position) matches the measured one in least squares
//! (Levenberg–Marquardt, [`crate::solve::LevenbergMarquardt`]).
//!
//! Positive parameters (mass, friction levels, gains) are varied as their
//! logarithms, so that no step makes them negative and their scale does not
//! matter; the offset as itself over the drive gain (controller-output
//! units). Standard errors come from the Jacobian at the solution,
//! `σ²·(JᵀJ)⁻¹` by SVD (`σ²` the residual variance): they assume white
//! residuals and are optimistic when the residuals are correlated, as a
//! simulation's residuals usually are.

use std::fmt;
use std::str::FromStr;

use nalgebra::DMatrix;
use serde::Serialize;

use super::DriveStructure;
use crate::error::{Error, Result};
use crate::solve::{LevenbergMarquardt, LmConfig, Termination};
use crate::stats::ErrorStats;

/// A parameter of a drive structure that can be estimated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum StructureParam {
    /// Moving mass `M` \[kg\] (`M`, `mass`).
    #[serde(rename = "M")]
    Mass,
    /// Viscous friction `Fv` \[N·s/m\] (`Fv`, `viscous`).
    #[serde(rename = "Fv")]
    Viscous,
    /// Coulomb friction `Fc` \[N\] (`Fc`, `coulomb`).
    #[serde(rename = "Fc")]
    Coulomb,
    /// Constant force `F0` \[N\] (`offset`, `F0`).
    #[serde(rename = "offset")]
    Offset,
    /// Drive gain `g` \[N/unit\] (`gain`, `gtau`).
    #[serde(rename = "gain")]
    DriveGain,
    /// Position-loop gain (`kp`, `position.kp`).
    #[serde(rename = "kp")]
    PositionKp,
    /// Velocity-loop gain (`kv`, `velocity.kp`).
    #[serde(rename = "kv")]
    VelocityKp,
    /// Motor-side mass of a two-mass axis \[kg\] (`Mm`, `motor_mass`).
    #[serde(rename = "Mm")]
    MotorMass,
    /// Transmission stiffness \[N/m\] (`k`, `stiffness`).
    #[serde(rename = "k")]
    Stiffness,
    /// Transmission damping \[N·s/m\] (`c`, `damping`).
    #[serde(rename = "c")]
    Damping,
    /// Static (breakaway) friction level \[N\] (`Fs`, `static`).
    #[serde(rename = "Fs")]
    Static,
}

impl StructureParam {
    /// The name printed.
    pub fn name(self) -> &'static str {
        match self {
            StructureParam::Mass => "M",
            StructureParam::Viscous => "Fv",
            StructureParam::Coulomb => "Fc",
            StructureParam::Offset => "offset",
            StructureParam::DriveGain => "gain",
            StructureParam::PositionKp => "kp",
            StructureParam::VelocityKp => "kv",
            StructureParam::MotorMass => "Mm",
            StructureParam::Stiffness => "k",
            StructureParam::Damping => "c",
            StructureParam::Static => "Fs",
        }
    }

    /// Its unit.
    pub fn unit(self) -> &'static str {
        match self {
            StructureParam::Mass | StructureParam::MotorMass => "kg",
            StructureParam::Viscous | StructureParam::Damping => "N·s/m",
            StructureParam::Stiffness => "N/m",
            StructureParam::Static => "N",
            StructureParam::Coulomb | StructureParam::Offset => "N",
            StructureParam::DriveGain => "N/unit",
            StructureParam::PositionKp => "1/s",
            StructureParam::VelocityKp => "unit/(m/s)",
        }
    }

    /// Its value in the structure `s` (the static level: the Coulomb
    /// level when absent; the motor mass and stiffness: 0 when rigid).
    pub fn get(self, s: &DriveStructure) -> f64 {
        match self {
            StructureParam::Mass => s.mechanics.mass,
            StructureParam::Viscous => s.friction.viscous,
            StructureParam::Coulomb => s.friction.coulomb,
            StructureParam::Offset => s.friction.offset,
            StructureParam::DriveGain => s.drive.gain,
            StructureParam::PositionKp => s.position.kp,
            StructureParam::VelocityKp => s.velocity.kp,
            StructureParam::MotorMass => s.mechanics.motor_mass.unwrap_or(0.0),
            StructureParam::Stiffness => s.mechanics.stiffness.unwrap_or(0.0),
            StructureParam::Damping => s.mechanics.damping,
            StructureParam::Static => s.friction.r#static.unwrap_or(s.friction.coulomb),
        }
    }

    /// `s` with this parameter set to `v`.
    pub fn set(self, s: &mut DriveStructure, v: f64) {
        match self {
            StructureParam::Mass => s.mechanics.mass = v,
            StructureParam::Viscous => s.friction.viscous = v,
            StructureParam::Coulomb => s.friction.coulomb = v,
            StructureParam::Offset => s.friction.offset = v,
            StructureParam::DriveGain => s.drive.gain = v,
            StructureParam::PositionKp => s.position.kp = v,
            StructureParam::VelocityKp => s.velocity.kp = v,
            StructureParam::MotorMass => s.mechanics.motor_mass = Some(v),
            StructureParam::Stiffness => s.mechanics.stiffness = Some(v),
            StructureParam::Damping => s.mechanics.damping = v,
            StructureParam::Static => s.friction.r#static = Some(v),
        }
    }

    /// Varied as its logarithm (every parameter but the offset).
    fn logarithmic(self) -> bool {
        self != StructureParam::Offset
    }

    /// What an estimate `value` is measured against for [`PINNED`]: its
    /// size, and for a constant force (which may be near 0) at least the
    /// drive's unit of output, `drive_gain`.
    fn size(self, value: f64, drive_gain: f64) -> f64 {
        if self.logarithmic() {
            value.abs()
        } else {
            value.abs().max(drive_gain)
        }
    }
}

impl FromStr for StructureParam {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        Ok(match s.trim() {
            "M" | "mass" => StructureParam::Mass,
            "Fv" | "viscous" => StructureParam::Viscous,
            "Fc" | "coulomb" => StructureParam::Coulomb,
            "offset" | "F0" => StructureParam::Offset,
            "gain" | "gtau" => StructureParam::DriveGain,
            "kp" | "position.kp" => StructureParam::PositionKp,
            "kv" | "velocity.kp" => StructureParam::VelocityKp,
            "Mm" | "motor_mass" => StructureParam::MotorMass,
            "k" | "stiffness" => StructureParam::Stiffness,
            "c" | "damping" => StructureParam::Damping,
            "Fs" | "static" => StructureParam::Static,
            other => {
                return Err(Error::InvalidChoice {
                    what: "structure parameter",
                    value: other.to_string(),
                    expected: "M, Fv, Fc, offset, gain, kp, kv, Mm, k, c, Fs",
                })
            }
        })
    }
}

/// One estimate.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct StructureEstimate {
    /// The parameter.
    pub param: StructureParam,
    /// Its value in the file (the start).
    pub start: f64,
    /// The estimate.
    pub value: f64,
    /// Its standard error (white residuals assumed; module doc).
    pub std_error: f64,
    /// Largest relative difference from this estimate of the fits restarted
    /// ±22 % away from it (`None` without restarts).
    pub restart_spread: Option<f64>,
    /// What the data say of it ([`StructureVerdict`]).
    pub verdict: StructureVerdict,
}

impl StructureEstimate {
    /// The data pin it ([`StructureVerdict::Identifiable`]).
    pub fn identifiable(&self) -> bool {
        self.verdict == StructureVerdict::Identifiable
    }
}

/// What the data say of an estimate: structural identifiability, judged by
/// fits restarted elsewhere, apart from practical identifiability, judged by
/// the standard error (Raue et al., *Bioinformatics* 25 (2009) 1923–1929,
/// make the same distinction with profile likelihoods).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StructureVerdict {
    /// Three standard errors are at most [`PINNED`] of it (of the drive
    /// gain, for a constant force smaller than that) and the equally good
    /// restarts, if any, ended where it did.
    Identifiable,
    /// The restarts ended where it did, but three standard errors exceed
    /// [`PINNED`] of it (or are infinite): the data locate it, not to 5 %.
    Imprecise,
    /// Equally good restarts ended apart, farther than
    /// `max(10⁻³, min(3·std_error, PINNED·size)/|value|)`, or a restart
    /// could not be fitted: the data do not decide it.
    NotIdentifiable,
}

impl StructureVerdict {
    /// The word printed for it.
    pub fn label(self) -> &'static str {
        match self {
            StructureVerdict::Identifiable => "identifiable",
            StructureVerdict::Imprecise => "imprecise",
            StructureVerdict::NotIdentifiable => "NOT IDENTIFIABLE",
        }
    }
}

/// The result of [`DriveStructure::fit`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StructureFit {
    /// The structure with the estimates in place.
    pub structure: DriveStructure,
    /// The estimates, in the order asked.
    pub estimates: Vec<StructureEstimate>,
    /// Rms of simulated − measured position with the file's values \[m\].
    pub start_rms: f64,
    /// The same with the estimates \[m\].
    pub rms: f64,
    /// Fit `100·(1 − ‖y − ŷ‖/‖y − ȳ‖)` of the simulated position \[%\].
    pub fit_percent: f64,
    /// Levenberg–Marquardt iterations.
    pub iterations: usize,
    /// Why it stopped.
    pub termination: Termination,
    /// Fits of [`DriveStructure::fit_with_restarts`] (the first one or
    /// restarts) that ended with a simulation error more than
    /// [`EQUALLY_GOOD`] above the best's: local minima, not compared.
    pub restarts_elsewhere: usize,
}

/// Largest share of an estimate its three standard errors may make for the
/// estimate to be called identifiable: beyond, the data do not pin it to
/// 5 %, whatever the restarts say (a parameter the output hardly depends
/// on ends where it starts, restarted or not).
pub const PINNED: f64 = 0.05;

/// How far a restart starts from the estimate (a share of it).
const RESTART_MOVE: f64 = 0.22;

/// A restart whose simulation error is within this share of the best fit's
/// (or within a millionth of the rms motion, on data without noise) is as
/// good a fit: its parameters must agree with the best's for them to be
/// pinned. Beyond, it ended in a local minimum and is not compared.
pub const EQUALLY_GOOD: f64 = 0.01;

/// The most restarts a fit accepts: each restart is a full fit, so the
/// bound keeps the work of one call finite.
pub const MAX_RESTARTS: usize = 100;

/// [`Error::InvalidParameter`] unless `restarts ≤ MAX_RESTARTS`.
pub fn check_restarts(restarts: usize) -> Result<()> {
    if restarts > MAX_RESTARTS {
        return Err(Error::InvalidParameter {
            name: "restarts",
            value: restarts as f64,
            reason: "at most 100, each restart being a full fit",
        });
    }
    Ok(())
}

impl DriveStructure {
    /// Estimate the parameters `estimate` from `command` and the measured
    /// `position` at `rate_hz` (module doc of `fit.rs`).
    pub fn fit(
        &self,
        command: &[f64],
        position: &[f64],
        rate_hz: f64,
        estimate: &[StructureParam],
    ) -> Result<StructureFit> {
        if command.len() != position.len() {
            return Err(Error::LengthMismatch {
                what: "command and position",
                expected: command.len(),
                actual: position.len(),
            });
        }
        if estimate.is_empty() {
            return Err(Error::InvalidParameter {
                name: "estimate",
                value: 0.0,
                reason: "name at least one parameter",
            });
        }
        if let Some((index, &value)) = position.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(Error::NonFinite {
                channel: "position".to_string(),
                index,
                value,
            });
        }
        let x0 = position[0];
        let scale_of = |p: StructureParam| {
            if p.logarithmic() {
                1.0
            } else {
                self.drive.gain
            }
        };
        let to_p = |p: StructureParam, v: f64| {
            if p.logarithmic() {
                v.ln()
            } else {
                v / scale_of(p)
            }
        };
        let from_p = |p: StructureParam, x: f64| {
            if p.logarithmic() {
                x.exp()
            } else {
                x * scale_of(p)
            }
        };
        for &p in estimate {
            if matches!(
                p,
                StructureParam::MotorMass | StructureParam::Stiffness | StructureParam::Damping
            ) && !self.mechanics.two_mass()
            {
                return Err(Error::InvalidParameter {
                    name: "estimate",
                    value: f64::NAN,
                    reason: "Mm, k and c belong to two-mass mechanics: give stiffness and motor_mass in the file",
                });
            }
            let v = p.get(self);
            if p.logarithmic() && (v.is_nan() || v <= 0.0) {
                return Err(Error::InvalidParameter {
                    name: "estimate",
                    value: v,
                    reason: "a parameter estimated as positive needs a positive start in the file",
                });
            }
        }
        let build = |x: &[f64]| {
            let mut s = self.clone();
            for (&p, &xi) in estimate.iter().zip(x) {
                p.set(&mut s, from_p(p, xi));
            }
            s
        };
        let m = position.len();
        let residual = |x: &[f64], r: &mut [f64]| match build(x).simulate(command, rate_hz, x0) {
            Ok(run) => {
                for ((ri, s), y) in r.iter_mut().zip(&run.position).zip(position) {
                    *ri = s - y;
                }
            }
            // a parameter set that cannot be simulated is as far as it gets
            Err(_) => r.fill(f64::MAX.sqrt()),
        };
        let mut r0 = vec![0.0; m];
        residual(
            &estimate
                .iter()
                .map(|&p| to_p(p, p.get(self)))
                .collect::<Vec<_>>(),
            &mut r0,
        );
        let start_rms = crate::stats::rms(&r0);
        if !start_rms.is_finite() || start_rms >= f64::MAX.sqrt() {
            return Err(Error::InvalidModel {
                reason: "the structure with the file's values cannot be simulated on this command",
            });
        }
        let mut x: Vec<f64> = estimate.iter().map(|&p| to_p(p, p.get(self))).collect();
        let mut lm = LevenbergMarquardt::new(m, x.len());
        let config = LmConfig {
            max_iterations: 60,
            fd_step: 1e-6,
            ftol: 1e-10,
            xtol: 1e-10,
            ..LmConfig::default()
        };
        let report = lm.minimize(residual, &mut x, &config)?;
        let r = lm.residuals().to_vec();
        let rms = crate::stats::rms(&r);
        // standard errors: σ²·(JᵀJ)⁻¹ from the SVD of J, in the varied
        // coordinates, then through the chain rule
        let n = x.len();
        let j = DMatrix::from_column_slice(m, n, lm.jacobian());
        let sigma2 = r.iter().map(|v| v * v).sum::<f64>() / (m.saturating_sub(n).max(1)) as f64;
        let std = standard_errors(j, sigma2);
        let structure = build(&x);
        let estimates = estimate
            .iter()
            .zip(&x)
            .zip(&std)
            .map(|((&p, &xi), &si)| {
                let value = from_p(p, xi);
                // d value / d x: value for a logarithm, the scale otherwise
                let std_error = si * if p.logarithmic() { value } else { scale_of(p) };
                let size = p.size(value, self.drive.gain);
                StructureEstimate {
                    param: p,
                    start: p.get(self),
                    value,
                    std_error,
                    restart_spread: None,
                    verdict: if std_error.is_finite() && 3.0 * std_error <= PINNED * size {
                        StructureVerdict::Identifiable
                    } else {
                        StructureVerdict::Imprecise
                    },
                }
            })
            .collect();
        // the simulated position is the measured one plus the residual
        let simulated = ErrorStats::from_pairs(position.iter().zip(&r).map(|(&y, &e)| (y, y + e)));
        Ok(StructureFit {
            structure,
            estimates,
            start_rms,
            rms,
            fit_percent: simulated.fit_percent,
            iterations: report.iterations,
            termination: report.termination,
            restarts_elsewhere: 0,
        })
    }
}

/// Standard errors `√diag(σ²·(JᵀJ)⁺)` from the SVD of the Jacobian `J`: a
/// direction the data do not see (a singular value below 10⁻¹⁰ of the
/// largest) makes infinite the errors of the parameters it moves, and only
/// theirs.
fn standard_errors(j: DMatrix<f64>, sigma2: f64) -> Vec<f64> {
    let n = j.ncols();
    if j.nrows() < n {
        // fewer samples than parameters: some direction is never seen
        return vec![f64::INFINITY; n];
    }
    let svd = j.svd(false, true);
    let Some(vt) = svd.v_t else {
        return vec![f64::INFINITY; n];
    };
    let largest = svd.singular_values.iter().fold(0.0_f64, |m, v| m.max(*v));
    let mut var = vec![0.0; n];
    for (i, &s) in svd.singular_values.iter().enumerate() {
        let seen = s > 1e-10 * largest && s > 0.0;
        for (k, v) in var.iter_mut().enumerate() {
            let w = vt[(i, k)] * vt[(i, k)];
            if seen {
                *v += w / (s * s);
            } else if w > 1e-12 {
                *v = f64::INFINITY;
            }
        }
    }
    var.iter().map(|v| (v * sigma2).sqrt()).collect()
}

impl DriveStructure {
    /// [`DriveStructure::fit`], then `restarts` fits started from the
    /// estimate moved ±22 % (parameter `i` of restart `r` up when `i + r` is
    /// even, down otherwise; the offset by 22 % of its size plus 1 % of the
    /// drive gain; 11 % or 5.5 % when the loop cannot run from the moved
    /// start). The fit with the smallest simulation error is the estimate;
    /// of the others, those within [`EQUALLY_GOOD`] of its error are as
    /// good a fit, and an estimate they leave farther than
    /// `max(10⁻³, min(3·σ, PINNED·size)/|value|)` from it is
    /// [`StructureVerdict::NotIdentifiable`] — the data do not decide it,
    /// whatever its standard error says; one the restarts confirm but
    /// whose three standard errors exceed [`PINNED`] of it is
    /// [`StructureVerdict::Imprecise`]. Fits that ended
    /// clearly worse are local minima of the simulation error, counted in
    /// [`StructureFit::restarts_elsewhere`]; a restart that cannot be
    /// fitted at all flags every estimate.
    pub fn fit_with_restarts(
        &self,
        command: &[f64],
        position: &[f64],
        rate_hz: f64,
        estimate: &[StructureParam],
        restarts: usize,
    ) -> Result<StructureFit> {
        check_restarts(restarts)?;
        let first = self.fit(command, position, rate_hz, estimate)?;
        let mut fits = Vec::with_capacity(restarts);
        let mut failed = 0;
        for r in 0..restarts {
            let moved_by = |share: f64| {
                let mut moved = first.structure.clone();
                for (i, &p) in estimate.iter().enumerate() {
                    let v = p.get(&first.structure);
                    let up = (i + r) % 2 == 0;
                    let w = if p.logarithmic() {
                        if up {
                            v * (1.0 + share)
                        } else {
                            v / (1.0 + share)
                        }
                    } else {
                        let step = share * v.abs() + 0.01 * self.drive.gain;
                        if up {
                            v + step
                        } else {
                            v - step
                        }
                    };
                    p.set(&mut moved, w);
                }
                moved
            };
            // a start the loop cannot run from (a sampled loop made
            // unstable by the move) is moved half as far, twice at most
            let again = [RESTART_MOVE, RESTART_MOVE / 2.0, RESTART_MOVE / 4.0]
                .into_iter()
                .find_map(|share| {
                    moved_by(share)
                        .fit(command, position, rate_hz, estimate)
                        .ok()
                });
            match again {
                Some(f) => fits.push(f),
                None => failed += 1,
            }
        }
        // the best of all is the estimate; a fit that ended clearly worse
        // (a local minimum of the simulation error) says nothing of what
        // the data pin
        let (start_rms, starts) = (
            first.start_rms,
            first.estimates.iter().map(|e| e.start).collect::<Vec<_>>(),
        );
        fits.push(first);
        let best = fits
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.rms.total_cmp(&b.1.rms))
            .map_or(0, |(i, _)| i);
        let mut fit = fits.swap_remove(best);
        // the start reported is the caller's, whichever fit ended best
        fit.start_rms = start_rms;
        for (e, start) in fit.estimates.iter_mut().zip(starts) {
            e.start = start;
        }
        // (and on data without noise, a fit within a millionth of the
        // motion: what is left there is the solver's tolerance)
        let n = position.len().max(1) as f64;
        let mean = position.iter().sum::<f64>() / n;
        let motion = (position.iter().map(|y| (y - mean).powi(2)).sum::<f64>() / n).sqrt();
        let as_good = (fit.rms * (1.0 + EQUALLY_GOOD)).max(1e-6 * motion);
        for e in &mut fit.estimates {
            e.restart_spread = (restarts > 0).then_some(0.0);
        }
        for again in &fits {
            if again.rms > as_good {
                fit.restarts_elsewhere += 1;
                continue;
            }
            for (e, a) in fit.estimates.iter_mut().zip(&again.estimates) {
                let magnitude = e.value.abs().max(f64::MIN_POSITIVE);
                let rel = (a.value - e.value).abs() / magnitude;
                e.restart_spread = Some(e.restart_spread.map_or(rel, |s| s.max(rel)));
                // apart beyond the noise (three standard errors), and in
                // any case beyond what an identifiable estimate may be off
                let size = e.param.size(e.value, self.drive.gain);
                let tolerance = ((3.0 * e.std_error).min(PINNED * size) / magnitude).max(1e-3);
                if rel.is_nan() || rel > tolerance {
                    e.verdict = StructureVerdict::NotIdentifiable;
                }
            }
        }
        // a restart that cannot be fitted at all decides nothing
        if failed > 0 {
            for e in &mut fit.estimates {
                e.restart_spread = Some(f64::INFINITY);
                e.verdict = StructureVerdict::NotIdentifiable;
            }
        }
        Ok(fit)
    }
}

/// How a fitted model's simulation (a drive structure's, or the paper's
/// rig's from `greybox`) matches a recording it was not fitted on.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct StructureValidation {
    /// Samples compared.
    pub samples: usize,
    /// Rms of simulated − measured position \[m\].
    pub rms: f64,
    /// Largest |simulated − measured| \[m\].
    pub max: f64,
    /// Fit `100·(1 − ‖y − ŷ‖/‖y − ȳ‖)` \[%\].
    pub fit_percent: f64,
    /// Rms of command − measured position (the tracking error it explains) \[m\].
    pub tracking_rms: f64,
}

impl StructureValidation {
    /// A model's simulation `simulated` of a recording's `command` compared
    /// with its measured `position` (all the same length), beside the
    /// tracking error `command − position`.
    pub fn compare(command: &[f64], position: &[f64], simulated: &[f64]) -> Result<Self> {
        for (what, len) in [
            ("command and position", position.len()),
            ("command and simulated position", simulated.len()),
        ] {
            if len != command.len() {
                return Err(Error::LengthMismatch {
                    what,
                    expected: command.len(),
                    actual: len,
                });
            }
        }
        let error = ErrorStats::from_pairs(position.iter().copied().zip(simulated.iter().copied()));
        let tracking =
            ErrorStats::from_pairs(position.iter().copied().zip(command.iter().copied()));
        Ok(Self {
            samples: error.samples,
            rms: error.rms,
            max: error.max_abs,
            fit_percent: error.fit_percent,
            tracking_rms: tracking.rms,
        })
    }
}

impl DriveStructure {
    /// Simulate the structure on another recording's `command` (from its
    /// measured first position) and compare with its measured `position`.
    pub fn validate_on(
        &self,
        command: &[f64],
        position: &[f64],
        rate_hz: f64,
    ) -> Result<StructureValidation> {
        let first = position.first().copied().unwrap_or(0.0);
        let run = self.simulate(command, rate_hz, first)?;
        StructureValidation::compare(command, position, &run.position)
    }
}

impl fmt::Display for StructureFit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{:<8} {:>14} {:>14} {:>12} {:>10}  {:<16} unit",
            "param", "file", "estimate", "std error", "restarts", "verdict"
        )?;
        for e in &self.estimates {
            let spread = e
                .restart_spread
                .map_or_else(|| "–".to_string(), |s| format!("{:.1e}", s));
            writeln!(
                f,
                "{:<8} {:>14.6} {:>14.6} {:>12.3e} {:>10}  {:<16} {}",
                e.param.name(),
                e.start,
                e.value,
                e.std_error,
                spread,
                e.verdict.label(),
                e.param.unit()
            )?;
        }
        writeln!(
            f,
            "simulated position: rms error {:.3} µm with the file's values, {:.3} µm with the estimates (fit {:.3} %); {} iterations, {}",
            1e6 * self.start_rms,
            1e6 * self.rms,
            self.fit_percent,
            self.iterations,
            self.termination.label()
        )?;
        if self.restarts_elsewhere > 0 {
            writeln!(
                f,
                "{} of the fits ended in a local minimum (simulation error more than {:.0} % above the best) and were not compared",
                self.restarts_elsewhere,
                100.0 * EQUALLY_GOOD
            )?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn standard_errors_of_orthogonal_columns_are_the_noise_over_their_norms() {
        // orthogonal columns of norms 2 and 4: σ/2 and σ/4
        let j = DMatrix::from_column_slice(3, 2, &[2.0, 0.0, 0.0, 0.0, 4.0, 0.0]);
        let s = standard_errors(j, 9.0);
        assert!((s[0] - 1.5).abs() < 1e-12, "{s:?}");
        assert!((s[1] - 0.75).abs() < 1e-12, "{s:?}");
    }

    #[test]
    fn a_direction_the_data_do_not_see_makes_only_its_parameters_unknown() {
        // the third parameter moves nothing: its error is infinite, the
        // others keep theirs (a QR inverse would have made all infinite)
        let j = DMatrix::from_column_slice(
            4,
            3,
            &[
                1.0, 1.0, 0.0, 0.0, //
                0.0, 0.0, 2.0, 0.0, //
                0.0, 0.0, 0.0, 0.0,
            ],
        );
        let s = standard_errors(j, 1.0);
        assert!((s[0] - 1.0 / 2f64.sqrt()).abs() < 1e-12, "{s:?}");
        assert!((s[1] - 0.5).abs() < 1e-12, "{s:?}");
        assert!(s[2].is_infinite(), "{s:?}");
        // two parameters that only act as their sum: both unknown, the
        // third still known
        let j = DMatrix::from_column_slice(
            3,
            3,
            &[
                1.0, 2.0, 0.0, //
                1.0, 2.0, 0.0, //
                0.0, 0.0, 3.0,
            ],
        );
        let s = standard_errors(j, 1.0);
        assert!(s[0].is_infinite() && s[1].is_infinite(), "{s:?}");
        assert!((s[2] - 1.0 / 3.0).abs() < 1e-12, "{s:?}");
        // fewer samples than parameters: nothing is known
        let s = standard_errors(DMatrix::from_column_slice(1, 2, &[1.0, 2.0]), 1.0);
        assert!(s.iter().all(|v| v.is_infinite()), "{s:?}");
    }
}
