//! Gains retuned from a drive structure's model: for a P position loop
//! around a P velocity loop on a force-source drive and a rigid mass (the
//! EMPS class), the linear closed loop is the second-order system
//!
//! ```text
//! X/X_s = g·kv·kp / (M·s² + (Fv + g·kv)·s + g·kv·kp)
//! ```
//!
//! so a natural frequency `ω_n` and a damping ratio `ζ` give the gains in
//! closed form, `kv = (2ζω_n·M − Fv)/g` and `kp = ω_n²·M/(g·kv)`; a −3 dB
//! bandwidth `ω_b` asked for is `ω_n·√(1 − 2ζ² + √(4ζ⁴ − 4ζ² + 2))`. The
//! result reports both gain sets' closed loops (poles, bandwidth, following
//! error) and step overshoot, and [`DriveStructure::run_figures`] runs a
//! program through the nonlinear simulation (friction, saturation, a sampled
//! controller) for either gain set.
//! Other loop structures are refused with the reason.

use serde::Serialize;

use super::{DriveStructure, LoopKind, StructureSummary};
use crate::error::{Error, Result};
use crate::stats::ErrorStats;

/// What the tuned loop should do.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TuneTarget {
    /// −3 dB bandwidth of the closed loop \[Hz\].
    pub bandwidth_hz: f64,
    /// Damping ratio ζ of its poles; default 1/√2 in the CLI.
    pub damping: f64,
}

/// The gains proposed and what they change.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Tuned {
    /// The structure with the new gains.
    pub structure: DriveStructure,
    /// Position-loop gain before and after.
    pub position_kp: (f64, f64),
    /// Velocity-loop gain before and after.
    pub velocity_kp: (f64, f64),
    /// The closed loop before.
    pub before: StructureSummary,
    /// The closed loop after.
    pub after: StructureSummary,
    /// Step overshoot of the linear closed loop before and after \[%\].
    pub overshoot_percent: (f64, f64),
}

/// The largest overshoot of the step response above 1 \[%\] (0 without).
fn overshoot(s: &DriveStructure, summary: &StructureSummary) -> Result<f64> {
    let fastest = summary
        .poles
        .iter()
        .fold(0.0f64, |m, p| m.max((p.re * p.re + p.im * p.im).sqrt()));
    let slowest = summary
        .poles
        .iter()
        .fold(f64::INFINITY, |m, p| m.min(p.re.abs().max(1e-9)));
    let dt = 0.05 / fastest.max(1e-9);
    let n = ((10.0 / slowest / dt).ceil() as usize).clamp(100, 200_000);
    let y = s.transfer_function()?.step_response(dt, n)?;
    Ok(100.0 * (y.iter().fold(f64::NEG_INFINITY, |m, v| m.max(*v)) - 1.0).max(0.0))
}

impl DriveStructure {
    /// Gains for `target` (module doc of `tune.rs`).
    ///
    /// ```
    /// use feedid::drive::{DriveStructure, TuneTarget};
    /// let s = DriveStructure::from_toml_str(
    ///     "[position]\nkp = 160.18\n[velocity]\nkp = 243.45\n[drive]\ngain = 35.1507\n\
    ///      [mechanics]\nmass = 95.1089\n[friction]\nviscous = 203.5034\n",
    ///     None,
    /// )
    /// .unwrap();
    /// let t = s.tune(&TuneTarget { bandwidth_hz: 40.0, damping: std::f64::consts::FRAC_1_SQRT_2 }).unwrap();
    /// assert!((t.after.bandwidth_hz.unwrap() - 40.0).abs() < 1e-3);
    /// assert!(t.overshoot_percent.1 < 5.0);
    /// ```
    pub fn tune(&self, target: &TuneTarget) -> Result<Tuned> {
        if self.mechanics.two_mass() {
            return Err(Error::InvalidParameter {
                name: "tune",
                value: f64::NAN,
                reason: "gains are retuned for rigid mechanics only (a two-mass axis's mode needs more than two gains)",
            });
        }
        if self.position.kind != LoopKind::P || self.velocity.kind != LoopKind::P {
            return Err(Error::InvalidParameter {
                name: "tune",
                value: f64::NAN,
                reason: "gains are retuned for a P position loop around a P velocity loop (the EMPS class) only",
            });
        }
        let z = target.damping;
        if !(z.is_finite() && z > 0.0 && z <= 2.0) {
            return Err(Error::InvalidParameter {
                name: "damping",
                value: z,
                reason: "must be in (0, 2]",
            });
        }
        let fb = target.bandwidth_hz;
        if !(fb.is_finite() && fb > 0.0) {
            return Err(Error::InvalidParameter {
                name: "bandwidth",
                value: fb,
                reason: "must be finite and > 0 Hz",
            });
        }
        let ratio = (1.0 - 2.0 * z * z + (4.0 * z.powi(4) - 4.0 * z * z + 2.0).sqrt()).sqrt();
        let wn = 2.0 * std::f64::consts::PI * fb / ratio;
        let (g, m, fv) = (
            self.drive.gain,
            self.mechanics.total_mass(),
            self.friction.viscous,
        );
        let kv = (2.0 * z * wn * m - fv) / g;
        if kv.is_nan() || kv <= 0.0 {
            return Err(Error::InvalidParameter {
                name: "bandwidth",
                value: fb,
                reason:
                    "is below what the viscous friction alone gives at this damping: ask for more",
            });
        }
        let kp = wn * wn * m / (g * kv);
        let mut structure = self.clone();
        structure.position.kp = kp;
        structure.velocity.kp = kv;
        let before = self.closed_loop()?;
        let after = structure.closed_loop()?;
        Ok(Tuned {
            position_kp: (self.position.kp, kp),
            velocity_kp: (self.velocity.kp, kv),
            overshoot_percent: (overshoot(self, &before)?, overshoot(&structure, &after)?),
            before,
            after,
            structure,
        })
    }
}

/// A program run through a structure's nonlinear simulation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RunFigures {
    /// Rms of command − position \[m\].
    pub rms_error: f64,
    /// Largest |command − position| \[m\].
    pub max_error: f64,
    /// Largest position beyond the command's final value, after it settles,
    /// as a share of the command's travel \[%\].
    pub overshoot_percent: f64,
    /// Largest |controller output|.
    pub peak_output: f64,
    /// Share of the samples whose output sits at the drive's limit \[%\].
    pub saturated_percent: f64,
}

impl DriveStructure {
    /// Run `command` (from rest at its first value) through the nonlinear
    /// simulation and measure the following error, overshoot and output.
    pub fn run_figures(&self, command: &[f64], rate_hz: f64) -> Result<RunFigures> {
        let first = command.first().copied().unwrap_or(0.0);
        let run = self.simulate(command, rate_hz, first)?;
        let n = command.len();
        let following =
            ErrorStats::from_pairs(command.iter().copied().zip(run.position.iter().copied()));
        let last = command[n - 1];
        let travel = command.iter().fold(0.0f64, |m, c| m.max((c - first).abs()));
        let dir = (last - first).signum();
        let settled = command
            .iter()
            .rposition(|c| *c != last)
            .map_or(0, |k| k + 1);
        let beyond = run.position[settled..]
            .iter()
            .fold(0.0f64, |m, y| m.max(dir * (y - last)));
        let limit = self.drive.limit;
        Ok(RunFigures {
            rms_error: following.rms,
            max_error: following.max_abs,
            overshoot_percent: if travel > 0.0 {
                100.0 * beyond / travel
            } else {
                0.0
            },
            peak_output: run.output.iter().fold(0.0, |m, u| m.max(u.abs())),
            saturated_percent: match limit {
                Some(l) => {
                    100.0
                        * run
                            .output
                            .iter()
                            .filter(|u| u.abs() >= l * (1.0 - 1e-12))
                            .count() as f64
                        / n as f64
                }
                None => 0.0,
            },
        })
    }
}
