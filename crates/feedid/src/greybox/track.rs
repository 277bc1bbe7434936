//! Tracking physical parameters along a move: a grey-box fit per sliding
//! window (e.g. the axial stiffness `K` against the nut position).
//!
//! Window `w` covers samples `[s, s + W)`; windows start every `hop` samples.
//! The linear model (sampled or continuous position loop, physical state
//! coordinates) is simulated from `b = max(0, s − warm_up)` with the
//! candidate parameters, starting from the state a reference simulation
//! reached at `b`; residuals are taken on `[s, s + W)` only, so the state
//! error at `b` (the reference ran with the earlier windows' estimates) decays
//! over the warm-up before it is scored. The reference simulation is then
//! advanced to the next window's `b` with this window's estimate. Each window
//! is fitted by Levenberg–Marquardt on the log-parameters, warm-started from
//! the previous window's estimate, with standard errors from the window's
//! Jacobian and residuals as in [`super::fit_greybox`]. A window that leaves
//! a parameter *not identifiable* (it does not excite it: a plain ramp for
//! the stiffness) keeps the previous window's estimates, reported as not
//! excited and without standard errors.
//!
//! With dropped samples ([`super::Measurements::measured`]) the reference
//! simulation runs on through them (on the command given there) and the
//! windows lie between them: none contains a dropped sample; a window's
//! `start`/`end` count the measured samples (the rows of the file).
//!
//! The nut position of a window is `geometry.nut_position` plus the mean
//! measured position over the window (the virtual rig's convention: position
//! 0 puts the nut at `geometry.nut_position`).
//!
//! ```
//! use feedid::drive::RigParams;
//! use feedid::greybox::{track_greybox, GreyboxConfig, PhysicalModel, PhysicalParameter, TrackConfig};
//! use feedid::signal::Scenario;
//! let u = Scenario::Prbs.command(5000.0, 0.4, 1).unwrap();
//! let y = PhysicalModel::linear(RigParams::default(), Default::default()).simulate(&u, 2e-4).unwrap();
//! let mut start = RigParams::default();
//! start.control.kv = 650.0;
//! let cfg = TrackConfig { window: 500, hop: 500, warm_up: 100, max_iterations: 30 };
//! let data = feedid::greybox::Measurements::new(&u, &y, 2e-4);
//! let rows = track_greybox(&data, &start, &[PhysicalParameter::Kv], &Default::default(), &cfg).unwrap();
//! assert_eq!(rows.len(), 4);
//! assert!(rows.iter().all(|r| (r.values[0] - 700.0).abs() < 1e-6));
//! ```

use serde::Serialize;

use super::fit::{apply, central_jacobian, check_set, GreyboxConfig, Measurements};
use super::identifiability::{analyse, Verdict};
use super::model::{linear_discrete, Dynamics};
use super::names::PhysicalParameter;
use crate::drive::RigParams;
use crate::error::{Error, Result};
use crate::solve::{LevenbergMarquardt, LmConfig, Termination};

/// Windows of a tracking run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TrackConfig {
    /// Window length W \[samples\]; default 500 (0.1 s at 5 kHz).
    pub window: usize,
    /// Shift between windows \[samples\]; default 250.
    pub hop: usize,
    /// Samples simulated before each window with its parameters; default 100.
    pub warm_up: usize,
    /// LM iteration cap per window; default 30.
    pub max_iterations: usize,
}

impl Default for TrackConfig {
    fn default() -> Self {
        Self {
            window: 500,
            hop: 250,
            warm_up: 100,
            max_iterations: 30,
        }
    }
}

/// The estimates of one window.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TrackWindow {
    /// First sample of the window.
    pub start: usize,
    /// One past the last sample.
    pub end: usize,
    /// Time of the window centre \[s\] (from the first sample).
    pub time_s: f64,
    /// Mean measured position over the window \[m\].
    pub mean_position_m: f64,
    /// Nut position `geometry.nut_position + mean_position_m` \[m\].
    pub nut_position_m: f64,
    /// Estimates, in the order asked for (SI).
    pub values: Vec<f64>,
    /// Their standard errors (`None` when not determined in this window).
    pub std_errors: Vec<Option<f64>>,
    /// How well this window determines each parameter.
    pub verdicts: Vec<Verdict>,
    /// Whether the window excites every parameter (no verdict *not
    /// identifiable* at the previous estimate nor at this one); a window
    /// that does not keeps the previous window's estimates in `values`, has
    /// no standard errors, and is not fitted when it fails already at the
    /// previous estimate (`iterations` 0).
    pub excited: bool,
    /// RMS of the window's residuals \[m\].
    pub residual_rms_m: f64,
    /// LM termination.
    pub termination: Termination,
    /// LM iterations.
    pub iterations: usize,
}

/// Track `estimate` over sliding windows of the measurements `data` (its
/// command and position; a measured current is not used; linear model
/// only; see the module doc).
///
/// Errors: as [`super::fit_greybox`], plus [`Error::InvalidParameter`] for a
/// zero window or hop, [`Error::TooFewSamples`] when not one window fits,
/// [`Error::InvalidChoice`] for the nonlinear model.
pub fn track_greybox(
    data: &Measurements<'_>,
    start: &RigParams,
    estimate: &[PhysicalParameter],
    cfg: &GreyboxConfig,
    track: &TrackConfig,
) -> Result<Vec<TrackWindow>> {
    track_greybox_with_progress(data, start, estimate, cfg, track, None)
}

/// [`track_greybox`], reporting `progress(done, total)` in windows (a plain callback).
pub fn track_greybox_with_progress(
    data: &Measurements<'_>,
    start: &RigParams,
    estimate: &[PhysicalParameter],
    cfg: &GreyboxConfig,
    track: &TrackConfig,
    progress: Option<&(dyn Fn(u64, u64) + Sync)>,
) -> Result<Vec<TrackWindow>> {
    if cfg.dynamics != Dynamics::Linear {
        return Err(Error::InvalidChoice {
            what: "model for tracking",
            value: "nonlinear".to_string(),
            expected: "linear",
        });
    }
    let base = check_set(estimate, start, &cfg.effects, false)?;
    for (name, v) in [("track window", track.window), ("track hop", track.hop)] {
        if v == 0 {
            return Err(Error::InvalidParameter {
                name,
                value: 0.0,
                reason: "must be at least 1 sample",
            });
        }
    }
    let n = estimate.len();
    let w = track.window;
    data.check(w.max(2 * n + 2))?;
    let (command, position, dt) = (data.command, data.position, data.dt);
    // the stretches of measured samples (grid indices), and each measured
    // sample's row in the file
    let rows_of = data.rows();
    let mut stretches: Vec<std::ops::Range<usize>> = Vec::new();
    for &k in &rows_of {
        match stretches.last_mut() {
            Some(r) if r.end == k => r.end = k + 1,
            _ => stretches.push(k..k + 1),
        }
    }
    let row_of = |k: usize| rows_of.partition_point(|&i| i < k);
    let u0 = command[0];
    let scale = crate::stats::rms(position).max(1e-9);
    let penalty = 1e3 * scale;
    let lm_cfg = LmConfig {
        ftol: cfg.tolerance,
        xtol: cfg.tolerance,
        gtol: cfg.tolerance,
        max_iterations: track.max_iterations.max(1),
        ..LmConfig::default()
    };

    // reference simulation state
    let mut ref_params = *start;
    let mut ref_effects = cfg.effects;
    // the start of the fit (a feed-forward gain of 0 starts at FEED_FORWARD_START)
    apply(
        estimate,
        &base,
        &vec![0.0; n],
        &mut ref_params,
        &mut ref_effects,
    );
    // 7 states, 8 with feed-forward (the same for every estimate: the
    // feed-forward gains stay positive on their log scale)
    let order = linear_discrete(&ref_params, cfg.position_loop, dt)?.order();
    let mut x_ref = vec![0.0; order];
    let mut scratch7 = vec![0.0; order];
    let mut ref_at = 0usize;
    let mut theta = vec![0.0; n];
    let mut rows = Vec::new();
    let mut lm = LevenbergMarquardt::new(w, n);
    let mut jac = vec![0.0; w * n];
    let mut r = vec![0.0; w];
    let mut x = vec![0.0; order];

    let total: u64 = stretches
        .iter()
        .filter(|r| r.len() >= w)
        .map(|r| ((r.len() - w) / track.hop + 1) as u64)
        .sum();
    let starts = stretches.iter().flat_map(|r| {
        let last = r.end.saturating_sub(w);
        (r.start..=last)
            .step_by(track.hop)
            .filter(move |&s| s + w <= r.end)
    });
    for s in starts {
        if let Some(p) = progress {
            p(rows.len() as u64, total);
        }
        let b = s.saturating_sub(track.warm_up).max(ref_at);
        // advance the reference to b with the latest estimate
        if b > ref_at {
            let sys = linear_discrete(&ref_params, cfg.position_loop, dt)?;
            for &u in &command[ref_at..b] {
                sys.advance(&mut x_ref, u - u0, &mut scratch7)?;
            }
            ref_at = b;
        }
        let x_start = x_ref.clone();
        let mut params = *start;
        let mut effects = cfg.effects;
        let mut residual = |th: &[f64], out: &mut [f64]| {
            apply(estimate, &base, th, &mut params, &mut effects);
            let Ok(sys) = linear_discrete(&params, cfg.position_loop, dt) else {
                out.iter_mut().for_each(|v| *v = penalty);
                return;
            };
            x.copy_from_slice(&x_start);
            let mut sc = [0.0; 8];
            let mut ok = true;
            for k in b..s + w {
                if k >= s {
                    out[k - s] = u0 + sys.output(&x, command[k] - u0) - position[k];
                }
                if sys.advance(&mut x, command[k] - u0, &mut sc).is_err() {
                    ok = false;
                    break;
                }
            }
            if !ok || out.iter().any(|v| !v.is_finite()) {
                out.iter_mut().for_each(|v| *v = penalty);
            }
        };
        // Does the window excite every parameter? Judged at the previous
        // estimate, before any fit (a fit in a window that does not pin a
        // parameter can run it off to absurd values, where the local analysis
        // is fooled: on a plain ramp the stiffness went to 1e16 N/m,
        // "converged"), and again at the estimate.
        let before = theta.clone();
        central_jacobian(&mut residual, &theta, w, &mut r, &mut jac);
        residual(&theta, &mut r);
        let ss0: f64 = r.iter().map(|v| v * v).sum();
        let pre = analyse(&jac, w, estimate, ss0, &cfg.thresholds)?;
        let excited_before = pre.verdicts.iter().all(|v| *v != Verdict::NotIdentifiable);
        let (a, report, ss) = if excited_before {
            let report = lm.minimize(&mut residual, &mut theta, &lm_cfg)?;
            central_jacobian(&mut residual, &theta, w, &mut r, &mut jac);
            residual(&theta, &mut r);
            let ss: f64 = r.iter().map(|v| v * v).sum();
            (
                analyse(&jac, w, estimate, ss, &cfg.thresholds)?,
                Some(report),
                ss,
            )
        } else {
            (pre, None, ss0)
        };
        let excited = excited_before && a.verdicts.iter().all(|v| *v != Verdict::NotIdentifiable);
        let mut residual_ss = ss;
        if !excited && theta != before {
            theta.copy_from_slice(&before);
            residual(&theta, &mut r);
            residual_ss = r.iter().map(|v| v * v).sum();
        }
        let (termination, iterations) = match &report {
            Some(rep) => (rep.termination, rep.iterations),
            None => (Termination::Converged, 0),
        };
        let values: Vec<f64> = base.iter().zip(&theta).map(|(b, t)| b * t.exp()).collect();
        let mean = position[s..s + w].iter().sum::<f64>() / w as f64;
        rows.push(TrackWindow {
            start: row_of(s),
            end: row_of(s) + w,
            time_s: (s as f64 + 0.5 * (w as f64 - 1.0)) * dt,
            mean_position_m: mean,
            nut_position_m: start.geometry.nut_position + mean,
            std_errors: values
                .iter()
                .zip(&a.relative_std_errors)
                .map(|(v, e)| e.filter(|_| excited).map(|e| e * v))
                .collect(),
            values,
            verdicts: a.verdicts.clone(),
            excited,
            residual_rms_m: (residual_ss / w as f64).sqrt(),
            termination,
            iterations,
        });
        apply(estimate, &base, &theta, &mut ref_params, &mut ref_effects);
    }
    if rows.is_empty() {
        return Err(Error::TooFewSamples {
            what: "one tracking window",
            needed: w,
            actual: stretches.iter().map(|r| r.len()).max().unwrap_or(0),
        });
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{PositionLoop, RigEffects, VirtualRig};
    use crate::greybox::Measurements;
    use crate::signal::{Prbs, Ramp};

    #[test]
    fn stiffness_follows_the_nut_position_along_a_dithered_move() {
        // 100 mm at 100 mm/s with a PRBS dither; the rig's stiffness K(l)
        // falls as the nut moves away from the fixed bearing (eq. 1)
        let rate = 5000.0;
        let dt = 1.0 / rate;
        let ramp = Ramp {
            distance: 0.1,
            velocity: 0.1,
            ..Ramp::default()
        };
        let duration = 1.2;
        let mut u = ramp.generate(rate, duration).unwrap();
        let dither = Prbs::default().generate(rate, duration, 3).unwrap();
        for (a, b) in u.iter_mut().zip(&dither) {
            *a += b;
        }
        let truth = RigParams::default();
        let fx = RigEffects {
            variable_stiffness: true,
            position_loop: PositionLoop::Sampled,
            ..RigEffects::linear()
        };
        let y = VirtualRig::new(truth)
            .with_effects(fx)
            .simulate(&u, rate)
            .unwrap()
            .position;
        let cfg = TrackConfig {
            window: 500,
            hop: 500,
            warm_up: 100,
            max_iterations: 30,
        };
        let rows = track_greybox(
            &Measurements::new(&u, &y, dt),
            &truth,
            &[PhysicalParameter::K],
            &GreyboxConfig::default(),
            &cfg,
        )
        .unwrap();
        assert!(rows.len() >= 10);
        let mut moved = false;
        for r in &rows {
            let want = truth.stiffness_at(r.nut_position_m);
            let got = r.values[0];
            // the stiffness changes within a window; compare with the mean position's
            assert!(
                (got / want - 1.0).abs() < 0.01,
                "t {}: {got} vs {want}",
                r.time_s
            );
            moved |= want < 0.9 * truth.stiffness_k();
        }
        assert!(moved, "the move should soften the screw by more than 10 %");
    }

    #[test]
    fn a_window_without_excitation_keeps_the_last_estimate() {
        // K tracked on a plain ramp ran off to 1.18e16 N/m, "converged"
        let rate = 5000.0;
        let u = Ramp::default().generate(rate, 0.8).unwrap();
        let out = VirtualRig::new(RigParams::default())
            .simulate(&u, rate)
            .unwrap();
        let cfg = TrackConfig {
            window: 500,
            hop: 250,
            ..TrackConfig::default()
        };
        let rows = track_greybox(
            &Measurements::new(&u, &out.position, 1.0 / rate),
            &RigParams::default(),
            &[PhysicalParameter::K],
            &GreyboxConfig::default(),
            &cfg,
        )
        .unwrap();
        let k0 = RigParams::default().stiffness_k();
        let mut fallbacks = 0;
        for r in &rows {
            // never far from a plausible stiffness
            assert!(r.values[0] < 10.0 * k0 && r.values[0] > 0.1 * k0, "{r:?}");
            if !r.excited {
                fallbacks += 1;
                assert_eq!(r.verdicts[0], Verdict::NotIdentifiable);
                assert_eq!(r.std_errors[0], None);
            } else {
                assert_ne!(r.verdicts[0], Verdict::NotIdentifiable, "{r:?}");
            }
        }
        assert!(fallbacks > rows.len() / 2, "{fallbacks} of {}", rows.len());
    }

    #[test]
    fn dropped_samples_split_the_windows_and_the_reference_runs_through() {
        // Kv tracked on a PRBS whose samples 1000..1003 were dropped (garbage
        // there): no window contains them, the one after them starts at the
        // file's row 1000, and every estimate is exact
        let u = crate::signal::Scenario::Prbs
            .command(5000.0, 0.4, 1)
            .unwrap();
        let mut y = crate::greybox::PhysicalModel::linear(RigParams::default(), Default::default())
            .simulate(&u, 2e-4)
            .unwrap();
        for v in &mut y[1000..1003] {
            *v += 1.0;
        }
        let measured: Vec<usize> = (0..u.len()).filter(|k| !(1000..1003).contains(k)).collect();
        let mut start = RigParams::default();
        start.control.kv = 650.0;
        let cfg = TrackConfig {
            window: 500,
            hop: 500,
            warm_up: 100,
            max_iterations: 30,
        };
        let data = Measurements::new(&u, &y, 2e-4).with_measured(&measured);
        let rows = track_greybox(
            &data,
            &start,
            &[PhysicalParameter::Kv],
            &Default::default(),
            &cfg,
        )
        .unwrap();
        let spans: Vec<(usize, usize)> = rows.iter().map(|r| (r.start, r.end)).collect();
        assert_eq!(spans, [(0, 500), (500, 1000), (1000, 1500)]);
        assert!((rows[2].time_s - (1003.0 + 249.5) * 2e-4).abs() < 1e-12);
        for r in &rows {
            assert!((r.values[0] - 700.0).abs() < 1e-6, "{r:?}");
        }
        // without the mask the garbage lands in the third window
        let all = track_greybox(
            &Measurements::new(&u, &y, 2e-4),
            &start,
            &[PhysicalParameter::Kv],
            &Default::default(),
            &cfg,
        )
        .unwrap();
        assert!(all[2].residual_rms_m > 1e-3, "{:?}", all[2]);
    }

    #[test]
    fn nonlinear_tracking_is_refused() {
        let u = vec![0.0; 600];
        let cfg = GreyboxConfig {
            dynamics: Dynamics::Nonlinear,
            ..GreyboxConfig::default()
        };
        let e = track_greybox(
            &Measurements::new(&u, &u, 2e-4),
            &RigParams::default(),
            &[PhysicalParameter::K],
            &cfg,
            &TrackConfig::default(),
        )
        .unwrap_err();
        assert!(e.to_string().contains("nonlinear"));
    }
}
