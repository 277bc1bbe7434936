//! Gains retuned from a drive structure's model, by placing the poles of
//! its linear closed loop on a force-source drive and a rigid mass. For a P
//! position loop around a P velocity loop (the EMPS class) the closed loop
//! is the second-order system
//!
//! ```text
//! X/X_s = g·kv·kp / (M·s² + (Fv + g·kv)·s + g·kv·kp)
//! ```
//!
//! so a natural frequency `ω_n` and a damping ratio `ζ` give the gains in
//! closed form, `kv = (2ζω_n·M − Fv)/g` and `kp = ω_n²·M/(g·kv)`; a −3 dB
//! bandwidth `ω_b` asked for is `ω_n·√(1 − 2ζ² + √(4ζ⁴ − 4ζ² + 2))`. A PD
//! position loop commanding the force is the same second-order system
//! (`M·s² + (Fv + g·kp·kd)·s + g·kp`). With an integral — a PI velocity
//! loop, or a PID position loop commanding the force — the closed loop is
//! of third order, and its poles are placed at `(s + p)(s² + 2ζω_n·s +
//! ω_n²)`, `p = ω_n/4` (0.15 or 0.1 `ω_n` where that leaves no real gains):
//!
//! ```text
//! P/PI:  M·s³ + (Fv + g·kv)·s² + g·kv·(ki + kp)·s + g·kv·ki·kp
//!        kv = (M·(p + 2ζω_n) − Fv)/g;  ki, kp the roots of t² − S·t + P,
//!        S = M·(ω_n² + 2ζω_n·p)/(g·kv), P = M·p·ω_n²/(g·kv), ki the smaller
//!        (its zero −ki beside the pole −p)
//! PID:   M·s³ + (Fv + g·kp·kd)·s² + g·kp·s + g·kp·ki
//!        kp = M·(ω_n² + 2ζω_n·p)/g,  ki = M·p·ω_n²/(g·kp),  kd = (M·(p + 2ζω_n) − Fv)/(g·kp)
//! ```
//!
//! and `ω_n` is found by bisection where the closed loop's −3 dB bandwidth
//! is the one asked (the zeros shift it from the second-order formula).
//! A two-mass axis or a modelled current loop (the paper's cascade) gets
//! the gains of its rigid, force-source equivalent (every moving mass, both
//! sides' viscous friction, the current loop ideal) — the cascade designed
//! from the inside out — with `ω_n` found by bisection on the whole closed
//! loop's bandwidth, mode and current loop included; whether that loop is
//! stable and how damped its poles are is reported, not assumed.
//! Feed-forward gains are kept. The result reports both gain sets' closed
//! loops (poles, bandwidth, following error) and step overshoot, and
//! [`DriveStructure::run_figures`] runs a program through the nonlinear
//! simulation (friction, saturation, a sampled controller) for either gain
//! set. Other loop structures are refused with the reason.

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
    /// Position-loop integral rate before and after \[1/s\] (0 without).
    pub position_ki: (f64, f64),
    /// Position-loop derivative time before and after \[s\] (0 without).
    pub position_kd: (f64, f64),
    /// Velocity-loop integral rate before and after \[1/s\] (0 without).
    pub velocity_ki: (f64, f64),
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
        let class = match (self.position.kind, self.velocity.kind) {
            (LoopKind::P, LoopKind::P) => Class::CascadeP,
            (LoopKind::P, LoopKind::PI) => Class::CascadePi,
            (LoopKind::PD, LoopKind::None) => Class::ForcePd,
            (LoopKind::PID, LoopKind::None) => Class::ForcePid,
            _ => {
                return Err(Error::InvalidParameter {
                    name: "tune",
                    value: f64::NAN,
                    reason: "gains are retuned for a P position loop around a P or PI velocity loop, or a PD or PID position loop commanding the force",
                })
            }
        };
        let ratio = (1.0 - 2.0 * z * z + (4.0 * z.powi(4) - 4.0 * z * z + 2.0).sqrt()).sqrt();
        let wn = 2.0 * std::f64::consts::PI * fb / ratio;
        let exact = !self.mechanics.two_mass() && self.current.is_none();
        let structure = match class {
            // second order on a rigid mass and a force source: the
            // bandwidth gives ω_n in closed form
            Class::CascadeP | Class::ForcePd if exact => self.placed(class, wn, z)?,
            // third order (the integral's pole at ω_n/4 and its zero near
            // it), or the poles placed on the rigid, force-source equivalent
            // of a two-mass axis or a modelled current loop: ω_n found where
            // the whole closed loop's bandwidth is the one asked
            _ => {
                // the bandwidth of the whole loop placed at ω (None: no
                // such gains, or the loop unstable)
                let bandwidth = |w: f64| -> Option<f64> {
                    let cl = self.placed(class, w, z).ok()?.closed_loop().ok()?;
                    cl.stable.then_some(cl.bandwidth_hz).flatten()
                };
                // bracket: down from ω_n until below the target, up until
                // above it while the loop stays stable
                let mut lo = wn;
                while bandwidth(lo).is_none_or(|b| b >= fb) {
                    lo /= 2.0;
                    if lo < wn / 1e3 {
                        return Err(Error::InvalidParameter {
                            name: "bandwidth",
                            value: fb,
                            reason:
                                "is below what the loop gives with the lowest gains at this damping",
                        });
                    }
                }
                let mut hi = lo;
                while bandwidth(hi).is_some_and(|b| b < fb) {
                    hi *= 1.25;
                    if hi > wn * 1e3 {
                        break;
                    }
                }
                if bandwidth(hi).is_none_or(|b| b < fb) {
                    return Err(Error::InvalidParameter {
                        name: "bandwidth",
                        value: fb,
                        reason: "cannot be reached at this damping: the whole loop (its mode, its current loop) turns unstable first",
                    });
                }
                for _ in 0..80 {
                    let mid = (lo * hi).sqrt();
                    if bandwidth(mid).is_some_and(|b| b < fb) {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                    if hi / lo - 1.0 < 1e-12 {
                        break;
                    }
                }
                let w = (lo * hi).sqrt();
                // a resonance can make the bandwidth jump across the target
                if bandwidth(w).is_none_or(|b| (b - fb).abs() > 1e-6 * fb) {
                    return Err(Error::InvalidParameter {
                        name: "bandwidth",
                        value: fb,
                        reason: "cannot be placed: the whole loop's bandwidth jumps across it as the gains rise (a resonance of the mode or the current loop lifts the response above −3 dB)",
                    });
                }
                self.placed(class, w, z)?
            }
        };
        let before = self.closed_loop()?;
        let after = structure.closed_loop()?;
        let pair = |f: fn(&DriveStructure) -> f64| (f(self), f(&structure));
        Ok(Tuned {
            position_kp: pair(|s| s.position.kp),
            velocity_kp: pair(|s| s.velocity.kp),
            position_ki: pair(|s| s.position.terms().1),
            position_kd: pair(|s| s.position.terms().2),
            velocity_ki: pair(|s| s.velocity.terms().1),
            overshoot_percent: (overshoot(self, &before)?, overshoot(&structure, &after)?),
            before,
            after,
            structure,
        })
    }

    /// The structure with the gains that place its closed-loop poles at
    /// `s² + 2ζω_n·s + ω_n²` (and, with an integral, at `s + ω_n/4`; closer
    /// to the origin where that leaves no real gains).
    fn placed(&self, class: Class, wn: f64, z: f64) -> Result<DriveStructure> {
        // the rigid, force-source equivalent: every moving mass, both
        // sides' viscous friction, the current loop ideal
        let (g, m, fv) = (
            self.drive.gain,
            self.mechanics.total_mass(),
            self.friction.viscous + self.mechanics.motor_viscous,
        );
        let too_low = Error::InvalidParameter {
            name: "bandwidth",
            value: wn,
            reason: "is below what the viscous friction alone gives at this damping: ask for more",
        };
        let mut s = self.clone();
        match class {
            Class::CascadeP => {
                let kv = (2.0 * z * wn * m - fv) / g;
                if kv.is_nan() || kv <= 0.0 {
                    return Err(too_low);
                }
                s.velocity.kp = kv;
                s.position.kp = wn * wn * m / (g * kv);
            }
            Class::ForcePd => {
                // M·s² + (Fv + g·kp·kd)·s + g·kp
                let kp = wn * wn * m / g;
                let kd = (2.0 * z * wn * m - fv) / (g * kp);
                if kd.is_nan() || kd < 0.0 {
                    return Err(too_low);
                }
                s.position.kp = kp;
                s.position.kd = kd;
            }
            Class::CascadePi => {
                // M·s³ + (Fv + g·kv)·s² + g·kv·(ki + kp)·s + g·kv·ki·kp
                let placed = INTEGRAL_POLES.iter().find_map(|share| {
                    let p = share * wn;
                    let kv = (m * (p + 2.0 * z * wn) - fv) / g;
                    if kv.is_nan() || kv <= 0.0 {
                        return None;
                    }
                    let sum = m * (wn * wn + 2.0 * z * wn * p) / (g * kv);
                    let product = m * p * wn * wn / (g * kv);
                    let disc = sum * sum - 4.0 * product;
                    // the integral's zero (−ki) is the smaller root, beside
                    // its pole: little overshoot from it
                    (disc >= 0.0).then(|| {
                        let root = disc.sqrt();
                        (kv, 0.5 * (sum + root), 0.5 * (sum - root))
                    })
                });
                let Some((kv, kp, ki)) = placed else {
                    return Err(too_low);
                };
                s.velocity.kp = kv;
                s.velocity.ki = ki;
                s.position.kp = kp;
            }
            Class::ForcePid => {
                // M·s³ + (Fv + g·kp·kd)·s² + g·kp·s + g·kp·ki
                let p = INTEGRAL_POLES[0] * wn;
                let kp = m * (wn * wn + 2.0 * z * wn * p) / g;
                let ki = m * p * wn * wn / (g * kp);
                let kd = (m * (p + 2.0 * z * wn) - fv) / (g * kp);
                if kd.is_nan() || kd < 0.0 {
                    return Err(too_low);
                }
                s.position.kp = kp;
                s.position.ki = ki;
                s.position.kd = kd;
            }
        }
        Ok(s)
    }
}

/// The loop structures `tune` retunes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Class {
    /// P position loop around a P velocity loop.
    CascadeP,
    /// P position loop around a PI velocity loop.
    CascadePi,
    /// PD position loop commanding the force.
    ForcePd,
    /// PID position loop commanding the force.
    ForcePid,
}

/// Places of the integral's pole tried, as shares of `ω_n`: the first that
/// leaves real gains.
const INTEGRAL_POLES: [f64; 3] = [0.25, 0.15, 0.1];

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
