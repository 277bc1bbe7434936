//! One learning step within the command's limits ([`super::learn`]): the
//! step is the compensation of the filtered error, smoothed (σ from the
//! compensation's levels) until the command meets the limits, held back
//! locally where it still would not, its gain halved when nothing else does.

use serde::Serialize;

use super::command::{compensate_model, levels, CompensateConfig, Peaks, Smoothing, StartMode};
use super::learn::LearnConfig;
use super::smoothing::smooth_step;
use crate::error::Result;
use crate::ident::LinearModel;

/// Peak |velocity| and |acceleration| of a command (finite differences, from
/// its rest before the first sample, or its first velocity when moving).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct CommandPeaks {
    /// Peak velocity \[m/s\].
    pub velocity: f64,
    /// Its time from the first sample \[s\].
    pub velocity_time_s: f64,
    /// Peak acceleration \[m/s²\].
    pub acceleration: f64,
    /// Its time \[s\].
    pub acceleration_time_s: f64,
}

impl CommandPeaks {
    /// The peaks of `u` at interval `dt` \[s\] (all 0 for no samples).
    pub fn of(u: &[f64], dt: f64, start: StartMode) -> Self {
        let n = u.len();
        if n == 0 {
            return Self::default();
        }
        let before = match start {
            StartMode::Rest => u[0],
            StartMode::Moving if n > 1 => 2.0 * u[0] - u[1],
            StartMode::Moving => u[0],
        };
        // the command from the sample before the first (index 0 of `ext`)
        let mut ext = Vec::with_capacity(n + 1);
        ext.push(before);
        ext.extend_from_slice(u);
        let p = Peaks::of(&ext, 1, dt);
        CommandPeaks {
            velocity: p.velocity,
            velocity_time_s: p.velocity_at.saturating_sub(1) as f64 * dt,
            acceleration: p.acceleration,
            acceleration_time_s: p.acceleration_at.saturating_sub(1) as f64 * dt,
        }
    }
}

/// The learning step `u + g·Δ` (module doc): `Δ = e + F·(G⁻¹ − 1)·e` the
/// compensation of the filtered error `e` with a zero-phase smoothing `F`
/// of σ from the compensation's levels; where the new command exceeds a
/// limit the step is held back locally (`(1 − W)·Δ`, `W` one around the
/// violating samples and easing to zero over as many samples on each side,
/// widened up to [`HOLD_ROUNDS`] times). The smallest σ whose step is held
/// back on at most [`HOLD_SHARE`] of the samples is taken, else the one held
/// back least; when none meets the limits the gain is halved (at most
/// [`LearnConfig::max_halvings`] times). `None`: no step meets them.
pub(super) fn increment(
    model: &LinearModel,
    base: &[f64],
    error: &[f64],
    moves: usize,
    dt: f64,
    cfg: &LearnConfig,
    gain: f64,
) -> Result<Option<Step>> {
    let comp = &cfg.compensate;
    let sigmas: Vec<f64> = match comp.smoothing {
        Smoothing::Fixed(s) => vec![s / dt],
        Smoothing::Auto => levels(comp.max_smoothing / dt),
    };
    let base_peaks = CommandPeaks::of(base, dt, comp.start);
    let mut deltas: Vec<Option<Vec<f64>>> = vec![None; sigmas.len()];
    let error_rms = rms(error);
    let mut g = gain;
    for _ in 0..=cfg.max_halvings {
        // first the steps the inverse does not amplify beyond
        // MAX_AMPLIFICATION, then, if none of those meets the limits, any
        for any in [false, true] {
            let mut best: Option<Step> = None;
            for (i, &sigma) in sigmas.iter().enumerate() {
                if deltas[i].is_none() {
                    let inc_cfg = CompensateConfig {
                        smoothing: Smoothing::Fixed(sigma * dt),
                        max_velocity: f64::INFINITY,
                        max_acceleration: f64::INFINITY,
                        fallback: false,
                        ..*comp
                    };
                    let eased = if cfg.ease_start {
                        ease_in(error, moves, sigma, comp.start)
                    } else {
                        error.to_vec()
                    };
                    deltas[i] = Some(compensate_model(model, &eased, dt, &inc_cfg)?.command);
                }
                let delta = deltas[i].as_deref().unwrap_or(&[]);
                if !any && rms(delta) > MAX_AMPLIFICATION * error_rms {
                    continue;
                }
                if let Some((command, held)) = held_back(base, delta, g, dt, comp, &base_peaks) {
                    let step = Step {
                        command,
                        gain: g,
                        sigma,
                        held_share: held,
                    };
                    if held <= HOLD_SHARE {
                        return Ok(Some(step));
                    }
                    if best.as_ref().is_none_or(|b| held < b.held_share) {
                        best = Some(step);
                    }
                }
            }
            if best.is_some() {
                return Ok(best);
            }
        }
        g *= 0.5;
    }
    Ok(None)
}

/// The error to learn eased in after a rest start, where the program
/// starts moving at sample `moves`: `w·e`, `w` a step with every derivative
/// continuous from 0 at `moves` to 1 after `8 + 8σ` samples (σ of the step's
/// smoothing \[samples\]), so that the inverse meets no kink of the noise
/// there, which the smoothing may not round (it may not move anything before
/// the first sample).
fn ease_in(e: &[f64], moves: usize, sigma: f64, start: StartMode) -> Vec<f64> {
    if start == StartMode::Moving {
        return e.to_vec();
    }
    let span = 8.0 + 8.0 * sigma;
    e.iter()
        .enumerate()
        .map(|(k, v)| {
            if k < moves {
                0.0
            } else {
                v * smooth_step((k - moves) as f64 / span)
            }
        })
        .collect()
}

/// Largest rms of a step `G⁻¹·e` relative to the rms of the error `e` it
/// corrects that is taken while a smoother step meets the limits as well:
/// a unit-gain servo's inverse needs about the error itself plus its lead
/// (1–2×); far more is the inverse's high-frequency gain acting on what is
/// left of the noise, which the axis does not answer as the model says.
const MAX_AMPLIFICATION: f64 = 3.0;

/// Root mean square (0 for no samples).
fn rms(v: &[f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

/// Most rounds of widening where a step is held back.
const HOLD_ROUNDS: usize = 8;

/// Largest share of the samples a step may be held back on before a
/// smoother step is tried.
const HOLD_SHARE: f64 = 0.05;

/// A learning step that meets the limits.
pub(super) struct Step {
    pub(super) command: Vec<f64>,
    pub(super) gain: f64,
    /// σ of its smoothing \[samples\].
    pub(super) sigma: f64,
    /// Share of the samples where it is held back (W > ½).
    pub(super) held_share: f64,
}

/// `base + g·(1 − W)·delta` within the limits (or no worse than `base`),
/// with `W` as small as the rounds allow, and the share held back; `None`
/// when even the widest hold does not meet them.
pub(super) fn held_back(
    base: &[f64],
    delta: &[f64],
    g: f64,
    dt: f64,
    comp: &CompensateConfig,
    base_peaks: &CommandPeaks,
) -> Option<(Vec<f64>, f64)> {
    let n = base.len();
    let mut hold = vec![false; n];
    let mut width = 4usize;
    let mut w = vec![0.0; n];
    for _ in 0..=HOLD_ROUNDS {
        let command: Vec<f64> = (0..n)
            .map(|k| base[k] + g * (1.0 - w[k]) * delta[k])
            .collect();
        let bad = violations(&command, dt, comp, base_peaks);
        if bad.is_empty() {
            let share = w.iter().filter(|v| **v > 0.5).count() as f64 / n as f64;
            return Some((command, share));
        }
        for k in bad {
            hold[k] = true;
        }
        // W: one within `width` of a held sample, easing to 0 over `width` more
        let mut dist = vec![usize::MAX; n];
        let mut last: Option<usize> = None;
        for k in 0..n {
            if hold[k] {
                last = Some(k);
            }
            if let Some(l) = last {
                dist[k] = k - l;
            }
        }
        last = None;
        for k in (0..n).rev() {
            if hold[k] {
                last = Some(k);
            }
            if let Some(l) = last {
                dist[k] = dist[k].min(l - k);
            }
        }
        for k in 0..n {
            w[k] = if dist[k] == usize::MAX {
                0.0
            } else if dist[k] <= width {
                1.0
            } else {
                1.0 - smooth_step((dist[k] - width) as f64 / width as f64)
            };
        }
        width *= 2;
    }
    None
}

/// Samples of `u` whose velocity (with the one before) or acceleration
/// (with its neighbours) exceeds the limits of `comp` (or `base`'s peaks
/// where those exceed them).
fn violations(u: &[f64], dt: f64, comp: &CompensateConfig, base: &CommandPeaks) -> Vec<usize> {
    let n = u.len();
    if n == 0 {
        return Vec::new();
    }
    let before = match comp.start {
        StartMode::Rest => u[0],
        StartMode::Moving if n > 1 => 2.0 * u[0] - u[1],
        StartMode::Moving => u[0],
    };
    let at = |k: isize| if k < 0 { before } else { u[k as usize] };
    let vlim = comp.max_velocity.max(base.velocity) * (1.0 + 1e-9);
    let alim = comp.max_acceleration.max(base.acceleration) * (1.0 + 1e-9);
    let mut out = Vec::new();
    for k in 0..n as isize {
        let v = ((at(k) - at(k - 1)) / dt).abs();
        let a = if (k as usize) + 1 < n {
            ((at(k + 1) - 2.0 * at(k) + at(k - 1)) / (dt * dt)).abs()
        } else {
            0.0
        };
        if v > vlim || a > alim {
            out.push(k as usize);
        }
    }
    out
}
