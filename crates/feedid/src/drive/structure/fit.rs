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
//! `σ²·(JᵀJ)⁻¹` by QR (`σ²` the residual variance): they assume white
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

    fn get(self, s: &DriveStructure) -> f64 {
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

    fn set(self, s: &mut DriveStructure, v: f64) {
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
    /// The restarts ended within `max(10⁻³, 3·std_error/|value|)` of it
    /// (true without restarts): the data pin it.
    pub identifiable: bool,
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
}

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
        // standard errors: σ²·(JᵀJ)⁻¹ = σ²·R⁻¹R⁻ᵀ from the QR of J, in the
        // varied coordinates, then through the chain rule
        let n = x.len();
        let j = DMatrix::from_column_slice(m, n, lm.jacobian());
        let sigma2 = r.iter().map(|v| v * v).sum::<f64>() / (m.saturating_sub(n).max(1)) as f64;
        let rmat = j.qr().r();
        let std: Vec<f64> = match rmat.clone().try_inverse() {
            Some(ri) => {
                let cov = &ri * ri.transpose() * sigma2;
                (0..n).map(|i| cov[(i, i)].max(0.0).sqrt()).collect()
            }
            None => vec![f64::INFINITY; n],
        };
        let structure = build(&x);
        let estimates = estimate
            .iter()
            .zip(&x)
            .zip(&std)
            .map(|((&p, &xi), &si)| {
                let value = from_p(p, xi);
                StructureEstimate {
                    param: p,
                    start: p.get(self),
                    value,
                    // d value / d x: value for a logarithm, the scale otherwise
                    std_error: si * if p.logarithmic() { value } else { scale_of(p) },
                    restart_spread: None,
                    identifiable: true,
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
        })
    }
}

impl DriveStructure {
    /// [`DriveStructure::fit`], then `restarts` fits started from the
    /// estimate moved ±22 % (parameter `i` of restart `r` up when `i + r` is
    /// even, down otherwise; the offset by 22 % of its size plus 1 % of the
    /// drive gain): an estimate whose restarts end farther than
    /// `max(10⁻³, 3·σ/|value|)` from it is flagged not identifiable — the
    /// data do not pin it, whatever its standard error says.
    pub fn fit_with_restarts(
        &self,
        command: &[f64],
        position: &[f64],
        rate_hz: f64,
        estimate: &[StructureParam],
        restarts: usize,
    ) -> Result<StructureFit> {
        check_restarts(restarts)?;
        let mut fit = self.fit(command, position, rate_hz, estimate)?;
        for r in 0..restarts {
            let mut moved = fit.structure.clone();
            for (i, &p) in estimate.iter().enumerate() {
                let v = p.get(&fit.structure);
                let up = (i + r) % 2 == 0;
                let w = if p.logarithmic() {
                    if up {
                        v * 1.22
                    } else {
                        v / 1.22
                    }
                } else {
                    let step = 0.22 * v.abs() + 0.01 * self.drive.gain;
                    if up {
                        v + step
                    } else {
                        v - step
                    }
                };
                p.set(&mut moved, w);
            }
            let again = match moved.fit(command, position, rate_hz, estimate) {
                Ok(f) => f,
                // a restart that cannot be fitted pins nothing
                Err(_) => {
                    for e in &mut fit.estimates {
                        e.restart_spread = Some(f64::INFINITY);
                        e.identifiable = false;
                    }
                    continue;
                }
            };
            for (e, a) in fit.estimates.iter_mut().zip(&again.estimates) {
                let rel = (a.value - e.value).abs() / e.value.abs().max(f64::MIN_POSITIVE);
                e.restart_spread = Some(e.restart_spread.map_or(rel, |s| s.max(rel)));
                let tolerance =
                    (3.0 * e.std_error / e.value.abs().max(f64::MIN_POSITIVE)).max(1e-3);
                if rel.is_nan() || rel > tolerance {
                    e.identifiable = false;
                }
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
            "{:<8} {:>14} {:>14} {:>12} {:>14}  unit",
            "param", "file", "estimate", "std error", "restarts"
        )?;
        for e in &self.estimates {
            let verdict = match e.restart_spread {
                None => "–".to_string(),
                Some(_) if !e.identifiable => "NOT PINNED".to_string(),
                Some(s) => format!("{:.1e}", s),
            };
            writeln!(
                f,
                "{:<8} {:>14.6} {:>14.6} {:>12.3e} {:>14}  {}",
                e.param.name(),
                e.start,
                e.value,
                e.std_error,
                verdict,
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
        )
    }
}
