//! The command of a member: a generator of `signal` with parameters the axis
//! can follow (speeds and accelerations a share of its capability), fitted
//! into the member's length.
//!
//! | kind | amplitude | parameters |
//! |---|---|---|
//! | ramp | ±A | speed `v = [0.2, 0.8]·v_cap`, raised so the move ends by 60 % of the recording |
//! | step | ±min(A, 2 mm) | rise one loop sample |
//! | S-curve | ±A | `v`, `a = [0.2, 0.6]·a_cap`, jerk time a/j 10–100 ms |
//! | sine sweep | min(A, 10 mm) | 0.5–2 Hz up to 10–200 Hz, below rate/10, `A·(2πf)² ≤ a`, `A·2πf ≤ v`; linear or logarithmic |
//! | square wave | ±min(A, 2 mm) | period ≥ 16/Kv, ≥ 20 samples, three or more periods |
//! | point-to-point | targets in ±A | `v`, `a`, jerk; dwells 20–200 ms up to 1.5–4× that; three or more moves |
//! | contour | R = A (sine axis) or A/2 (cosine axis) | feed `min(v, √(a·R), 2π·R·f_c)` with `f_c = min(10 Hz, rate/20)` turns per second, 0.5–10 turns |
//!
//! When a move does not fit, the recording is lengthened up to its sample
//! cap; the zoo then lowers the recording rate (a trace buffer of fixed size
//! records a long move at a lower rate, down to the lowest rate the loop
//! allows), and only then is the amplitude reduced (the manifest records the
//! amplitude actually commanded).

use super::design::{Dim, Draws};
use super::spec::CommandSpec;
use crate::error::Result;
use crate::signal::{Chirp, Contour, ContourAxis, PointToPoint, Ramp, Scurve, Square, Step, Sweep};

/// The seven command kinds, in design order (`i mod 7`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum CommandKind {
    Ramp,
    Step,
    Scurve,
    Sweep,
    Square,
    PointToPoint,
    Contour,
}

impl CommandKind {
    /// Kind of member `i`.
    pub fn of(i: usize) -> Self {
        [
            CommandKind::Ramp,
            CommandKind::Step,
            CommandKind::Scurve,
            CommandKind::Sweep,
            CommandKind::Square,
            CommandKind::PointToPoint,
            CommandKind::Contour,
        ][i % 7]
    }
}

/// What bounds a member's command.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Limits {
    /// Amplitude asked for \[m\].
    pub amplitude: f64,
    /// Top speed of the axis \[m/s\].
    pub velocity: f64,
    /// Peak acceleration of the axis \[m/s²\].
    pub acceleration: f64,
    /// Position-loop gain \[1/s\].
    pub kv: f64,
    /// Recording rate \[Hz\].
    pub rate: f64,
    /// Loop rate \[Hz\].
    pub loop_rate: f64,
    /// Length asked for \[s\].
    pub duration: f64,
    /// Longest allowed length \[s\].
    pub max_duration: f64,
}

/// A planned command.
pub(crate) struct Planned {
    /// The command.
    pub spec: CommandSpec,
    /// The member's length \[s\].
    pub duration: f64,
    /// The length the command would need at the amplitude asked \[s\]
    /// (above `max_duration` when the amplitude was reduced).
    pub needed: f64,
}

/// Plan the command of a member (see the module doc).
pub(crate) fn plan(kind: CommandKind, lim: &Limits, d: &mut Draws) -> Planned {
    let (spec, duration, needed) = plan_kind(kind, lim, d);
    Planned {
        spec,
        duration,
        needed: needed.max(duration),
    }
}

fn plan_kind(kind: CommandKind, lim: &Limits, d: &mut Draws) -> (CommandSpec, f64, f64) {
    let rest = (10.0 / lim.rate).max(0.01);
    let v = lim.velocity * d.lin_in(Dim::CommandSpeed, (0.2, 0.8));
    let a = lim.acceleration * d.lin_in(Dim::CommandAcceleration, (0.2, 0.6));
    let jerk = a / d.log_uniform(0.01, 0.1);
    let mut t = lim.duration;
    let mut amp = lim.amplitude;
    let two_pi = 2.0 * std::f64::consts::PI;
    match kind {
        CommandKind::Ramp => {
            let sign = d.sign();
            // the move ends by 60 % of the recording at no more than the top speed
            let needed = rest + amp / lim.velocity / 0.6;
            if needed > t {
                t = needed.min(lim.max_duration);
            }
            let speed = v.max(amp / (0.6 * t - rest)).min(lim.velocity);
            amp = amp.min(speed * (0.6 * t - rest));
            let ramp = Ramp {
                distance: sign * amp,
                velocity: speed,
                rest,
            };
            (CommandSpec::Ramp(ramp), t, needed)
        }
        CommandKind::Step => {
            let step = Step {
                height: d.sign() * amp.min(2e-3),
                rise_time: 1.0 / lim.loop_rate,
                rest,
            };
            (CommandSpec::Step(step), t, t)
        }
        CommandKind::Scurve => {
            let sign = d.sign();
            let mut s = Scurve {
                distance: sign * amp,
                max_velocity: v,
                max_acceleration: a,
                jerk,
                rest,
            };
            let needed = (rest + s.plan().duration()) / 0.8;
            loop {
                let needed = (rest + s.plan().duration()) / 0.8;
                if needed <= t {
                    break;
                }
                if needed <= lim.max_duration {
                    t = needed;
                    break;
                }
                s.distance *= 0.7;
            }
            (CommandSpec::Scurve(s), t, needed)
        }
        CommandKind::Sweep => {
            let mut amp = amp.min(0.01);
            let f0 = d.log_uniform(0.5, 2.0);
            let mut f1 = d
                .log_uniform(10.0, 200.0)
                .min(lim.rate / 10.0)
                .min(lim.loop_rate / 20.0);
            // the axis's acceleration and speed bound the top frequency
            f1 = f1.min((a / amp).sqrt() / two_pi).min(v / (two_pi * amp));
            if f1 < 4.0 * f0 {
                f1 = 4.0 * f0;
                amp = amp.min(a / (two_pi * f1).powi(2)).min(v / (two_pi * f1));
            }
            let sweep = if d.rng_bool() {
                Sweep::Logarithmic
            } else {
                Sweep::Linear
            };
            // at least two periods of the lowest frequency
            t = t.max((rest + 2.0 / f0) / 0.8).min(lim.max_duration);
            let chirp = Chirp {
                amplitude: amp,
                f_start: f0,
                f_end: f1,
                sweep,
                taper: 0.1 * (t - rest),
                rest,
            };
            (CommandSpec::Sweep(chirp), t, t)
        }
        CommandKind::Square => {
            let lo = (16.0 / lim.kv).max(20.0 / lim.rate).max(0.05);
            let mut period = d.log_uniform(lo, lo.max(1.0));
            let needed = rest + 3.0 * period;
            if needed > t {
                t = needed.min(lim.max_duration);
                period = period.min((t - rest) / 3.0);
            }
            let sq = Square {
                amplitude: d.sign() * amp.min(2e-3),
                period,
                edge_time: 0.0,
                rest,
            };
            (CommandSpec::Square(sq), t, t)
        }
        CommandKind::PointToPoint => {
            let dwell_min = d.log_uniform(0.02, 0.2);
            let dwell_max = dwell_min * d.uniform(1.5, 4.0);
            let mut p = PointToPoint {
                amplitude: amp,
                max_velocity: v,
                max_acceleration: a,
                jerk,
                dwell_min,
                dwell_max,
                min_move: 0.1,
                rest,
            };
            let mut needed = 0.0;
            loop {
                // three moves over the whole range
                let one = Scurve {
                    distance: 2.0 * p.amplitude,
                    max_velocity: v,
                    max_acceleration: a,
                    jerk,
                    rest: 0.0,
                };
                let need = rest + 3.0 * (one.plan().duration() + dwell_max);
                if needed == 0.0 {
                    needed = need;
                }
                if need <= t {
                    break;
                }
                if need <= lim.max_duration {
                    t = need;
                    break;
                }
                p.amplitude *= 0.7;
            }
            let seed = d.seed();
            (CommandSpec::PointToPoint { program: p, seed }, t, needed)
        }
        CommandKind::Contour => {
            let axis = if d.rng_bool() {
                ContourAxis::Sine
            } else {
                ContourAxis::Cosine
            };
            let mut radius = match axis {
                ContourAxis::Sine => amp,
                ContourAxis::Cosine => 0.5 * amp,
            };
            // circles of at most 10 Hz and 20 rows per turn
            let turn_rate = (lim.rate / 20.0).min(10.0);
            let mut c;
            let mut needed = 0.0;
            loop {
                let feed = v.min((a * radius).sqrt()).min(two_pi * turn_rate * radius);
                let turn = two_pi * radius / feed;
                let turns = (0.7 * (t - rest) / turn).clamp(0.5, 10.0);
                c = Contour {
                    radius,
                    feed,
                    max_acceleration: a,
                    jerk,
                    turns,
                    axis,
                    rest,
                };
                let need = c.end_of_motion() / 0.9;
                if needed == 0.0 {
                    needed = need;
                }
                if need <= t {
                    break;
                }
                if need <= lim.max_duration {
                    t = need;
                    break;
                }
                radius *= 0.7;
            }
            (CommandSpec::Contour(c), t, needed)
        }
    }
}

/// The command of `spec` sampled at `rate_hz` for `n` samples.
pub(crate) fn sample(spec: &CommandSpec, rate_hz: f64, n: usize) -> Result<Vec<f64>> {
    let mut out = vec![0.0; n];
    match spec {
        CommandSpec::Ramp(g) => g.fill(rate_hz, &mut out)?,
        CommandSpec::Step(g) => g.fill(rate_hz, &mut out)?,
        CommandSpec::Scurve(g) => g.fill(rate_hz, &mut out)?,
        CommandSpec::Sweep(g) => g.fill(rate_hz, &mut out)?,
        CommandSpec::Square(g) => g.fill(rate_hz, &mut out)?,
        CommandSpec::PointToPoint { program, seed } => program.fill(rate_hz, *seed, &mut out)?,
        CommandSpec::Contour(g) => g.fill(rate_hz, &mut out)?,
    }
    Ok(out)
}
