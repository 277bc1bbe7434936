//! Tests of the streamer: the batch engine's windows and predictions where
//! the stream has the same data, when predictions are made, extrapolation,
//! gaps, scores and misuse.
#![allow(clippy::needless_range_loop)]

use std::ops::Range;

use super::*;
use crate::drive::{RigParams, VirtualRig};
use crate::error::{Error, Result};
use crate::ident::engine::test_estimators::{follow, follow7, Linear, Wild};
use crate::ident::engine::{run, EngineConfig, GuardConfig, SlidingResult};
use crate::ident::{Estimator, PaperConfig, PaperMethod, Solver, WindowOutcome};
use crate::recording::MOTION_THRESHOLD;
use crate::signal::Scenario;
use crate::stats::ErrorStats;
use crate::Recording;

mod gaps;

/// How samples are fed.
#[derive(Debug, Clone, Copy)]
enum Feed {
    /// `push(t, u, y)` lines with a command lead (0: each line's own command).
    Lines(usize),
    /// `push_command` `l` samples ahead of `push_position`.
    Ahead(usize),
}

/// Window, horizon, outcome and coefficients of one processed window.
type WindowSummary = (Range<usize>, Range<usize>, WindowOutcome, Vec<f64>);

/// What a stream produced, in the batch engine's layout (sample indices of the stream).
struct Collected {
    windows: Vec<WindowSummary>,
    predicted: Vec<f64>,
    lower: Vec<f64>,
    upper: Vec<f64>,
    has: Vec<bool>,
    /// Time stamp each prediction gave its sample.
    time: Vec<f64>,
    /// (samples measured when the prediction arrived, horizon start, already measured)
    arrivals: Vec<(usize, usize, usize)>,
    arrivals_at_gap: Vec<Interval>,
    stats: StreamStats,
}

fn collect_from(out: &mut Collected, p: Prediction<'_>, measured: usize) {
    assert_eq!(p.time.len(), p.horizon.len());
    if p.is_ok() {
        assert_eq!(p.position.len(), p.horizon.len());
        assert_eq!(p.lower.len(), p.horizon.len());
        assert_eq!(p.upper.len(), p.horizon.len());
        for (j, k) in p.horizon.clone().enumerate() {
            if k < out.predicted.len() {
                out.predicted[k] = p.position[j];
                out.lower[k] = p.lower[j];
                out.upper[k] = p.upper[j];
                out.time[k] = p.time[j];
                out.has[k] = true;
            }
        }
    }
    out.arrivals
        .push((measured, p.horizon.start, p.already_measured));
    out.windows.push((
        p.window.clone(),
        p.horizon.clone(),
        p.outcome,
        p.coefficients.to_vec(),
    ));
}

fn empty_stats() -> StreamStats {
    StreamStats::default()
}

/// Stream `rec` (`Lines(l)`: its samples `l..` are the stream's, the lines
/// carrying the commands `l` ahead; `Ahead(l)`: all its samples) and collect.
fn stream<E: Estimator>(
    est: E,
    cfg: EngineConfig,
    rec: &Recording,
    feed: Feed,
    extrapolation: CommandExtrapolation,
) -> Collected {
    stream_guarded(est, cfg, rec, feed, extrapolation, GuardConfig::default())
}

/// [`stream`] with the guard settings `guard`.
fn stream_guarded<E: Estimator>(
    est: E,
    cfg: EngineConfig,
    rec: &Recording,
    feed: Feed,
    extrapolation: CommandExtrapolation,
    guard: GuardConfig,
) -> Collected {
    let (t, u, y) = (rec.time(), rec.command(), rec.position());
    let n = t.len();
    let (opts, shift) = match feed {
        Feed::Lines(l) => (
            StreamOptions {
                command_lead: l,
                extrapolation,
                guard,
                ..StreamOptions::default()
            },
            l,
        ),
        Feed::Ahead(l) => (
            StreamOptions {
                lookahead: Some(l),
                extrapolation,
                guard,
                ..StreamOptions::default()
            },
            0,
        ),
    };
    // the stream's samples are rec's samples `shift..n − shift` (the lines
    // stop `shift` before the end, where the commands run out)
    let (ts, m) = (&t[shift..n - shift], n - 2 * shift);
    let mut out = Collected {
        windows: Vec::new(),
        predicted: vec![0.0; m],
        lower: vec![0.0; m],
        upper: vec![0.0; m],
        has: vec![false; m],
        time: vec![0.0; m],
        arrivals: Vec::new(),
        arrivals_at_gap: Vec::new(),
        stats: empty_stats(),
    };
    let mut s = Streamer::with_options(est, cfg, opts).unwrap();
    match feed {
        Feed::Lines(l) => {
            // line i: time and position of sample i, command of sample i + l;
            // the last lines would need commands past the recording: stop there
            for i in 0..n - l {
                let a = s.push(t[i], u[i + l], y[i]).unwrap();
                if a.interval != Interval::Regular {
                    out.arrivals_at_gap.push(a.interval);
                }
                if let (Interval::Gap(_), Some(k)) = (a.interval, a.sample) {
                    // predictions made before the gap of samples after it are void
                    out.has[k..].fill(false);
                } else {
                    assert_eq!(a.sample, i.checked_sub(l), "line {i}");
                }
                while let Some(p) = s.poll().unwrap() {
                    collect_from(&mut out, p, s_np(i, l));
                }
            }
        }
        Feed::Ahead(l) => {
            for k in 0..n + l {
                if k < n {
                    s.push_command(u[k]).unwrap();
                    while let Some(p) = s.poll().unwrap() {
                        collect_from(&mut out, p, k.saturating_sub(l));
                    }
                }
                if k >= l {
                    let a = s.push_position(t[k - l], y[k - l]).unwrap();
                    assert_eq!(a.sample, Some(k - l));
                    while let Some(p) = s.poll().unwrap() {
                        collect_from(&mut out, p, k - l + 1);
                    }
                }
            }
        }
    }
    s.finish();
    let measured = s.stats().samples;
    while let Some(p) = s.poll().unwrap() {
        collect_from(&mut out, p, measured);
    }
    out.stats = s.stats();
    // time stamps: actual or extrapolated to rounding
    for k in 0..m {
        if out.has[k] {
            let (a, b) = (out.time[k], ts[k]);
            assert!(
                (a - b).abs() < 1e-12 * b.abs().max(1.0),
                "time of {k}: {a} vs {b}"
            );
        }
    }
    out
}

/// Samples measured after line `i` with lead `l`.
fn s_np(i: usize, l: usize) -> usize {
    (i + 1).saturating_sub(l)
}

/// Stream and batch give the same windows, coefficients and predictions
/// (`batch` on the stream's samples; `cut`: samples of the stream at the end
/// whose batch horizon is cut are not compared).
fn assert_same(c: &Collected, b: &SlidingResult, rel: f64, what: &str) {
    let n = c.predicted.len();
    // a window-end estimator may also process the window ending at the
    // last sample, which has nothing left to predict in batch
    let ws: Vec<_> = c.windows.iter().filter(|w| w.0.end < n).collect();
    let bws: Vec<_> = b.windows.iter().filter(|w| w.window.end < n).collect();
    assert_eq!(ws.len(), bws.len(), "{what}: window count");
    for (i, (w, bw)) in ws.iter().zip(&bws).enumerate() {
        assert_eq!(w.0, bw.window, "{what}: window {i}");
        assert_eq!(w.1.start, bw.horizon.start, "{what}: window {i}");
        assert_eq!(w.1.end.min(n), bw.horizon.end.min(n), "{what}: window {i}");
        assert_eq!(w.2, bw.outcome, "{what}: window {i}");
        assert_eq!(&w.3[..], b.window_coefficients(i), "{what}: window {i}");
    }
    let scale = b.predicted.iter().fold(1e-300_f64, |m, v| m.max(v.abs()));
    for k in 0..n {
        assert_eq!(c.has[k], b.has_prediction[k], "{what}: sample {k}");
        if c.has[k] {
            for (a, e) in [
                (c.predicted[k], b.predicted[k]),
                (c.lower[k], b.lower[k]),
                (c.upper[k], b.upper[k]),
            ] {
                assert!(
                    (a - e).abs() <= rel * scale,
                    "{what}: sample {k}: {a:e} vs {e:e}"
                );
            }
        }
    }
    assert_eq!(c.stats.samples, n);
    assert_eq!(
        c.stats.failed_windows,
        c.windows
            .iter()
            .filter(|w| w.2 == WindowOutcome::Failed)
            .count()
    );
}

/// The scores equal the batch engine's (same predictions, same samples).
fn assert_same_score(c: &Collected, b: &SlidingResult, rel: f64, what: &str) {
    let scale = b.predicted.iter().fold(1e-300_f64, |m, v| m.max(v.abs()));
    assert_eq!(c.stats.scored.samples, b.stats.samples, "{what}");
    assert_eq!(c.stats.outliers, b.outliers.len(), "{what}");
    assert!(
        (c.stats.scored.rms - b.stats.rms).abs() <= 1e-9 * b.stats.rms + rel * scale,
        "{what}: rms {} vs {}",
        c.stats.scored.rms,
        b.stats.rms
    );
}

fn rig_recording(scenario: Scenario, duration: f64) -> Recording {
    let rate = 5000.0;
    let command = scenario.command(rate, duration, 1).unwrap();
    let out = VirtualRig::new(RigParams::default())
        .with_seed(7)
        .simulate(&command, rate)
        .unwrap();
    Recording::new(out.time, out.command, out.position).unwrap()
}

/// Samples `from..` of `rec` as a recording.
fn tail(rec: &Recording, from: usize) -> Recording {
    Recording::new(
        rec.time()[from..].to_vec(),
        rec.command()[from..].to_vec(),
        rec.position()[from..].to_vec(),
    )
    .unwrap()
}

fn configs() -> [EngineConfig; 4] {
    [
        EngineConfig::default(),
        EngineConfig {
            window: 9,
            horizon: 3,
            hop: Some(1),
            warm_up: 5,
        },
        EngineConfig {
            window: 12,
            horizon: 6,
            hop: Some(4),
            warm_up: 0,
        },
        EngineConfig {
            window: 5,
            horizon: 8,
            hop: Some(13),
            warm_up: 2,
        },
    ]
}

use CommandExtrapolation::{Acceleration, Hold, Velocity, Wait};

#[test]
fn with_the_real_command_the_stream_equals_the_batch_engine() {
    let rec = rig_recording(Scenario::Ramp, 0.08);
    for cfg in configs() {
        // the real command over every horizon: waiting for it, or a look-ahead ≥ H
        let feeds = [
            (Feed::Lines(0), Wait),
            (Feed::Ahead(1), Wait),
            (Feed::Ahead(3), Wait),
            (Feed::Ahead(12), Velocity),
            (Feed::Lines(12), Hold),
            (Feed::Lines(cfg.horizon), Acceleration),
        ];
        for (feed, x) in feeds {
            let what = format!("{cfg:?} {feed:?} {x:?}");
            let shift = match feed {
                Feed::Lines(l) => l,
                Feed::Ahead(_) => 0,
            };
            // the stream's samples: rec's from `shift` on (the lines stop
            // `shift` before the end, where the commands run out)
            let end = rec.len() - shift;
            let batch_rec = Recording::new(
                rec.time()[shift..end].to_vec(),
                rec.command()[shift..end].to_vec(),
                rec.position()[shift..end].to_vec(),
            )
            .unwrap();
            let b = run(&mut Linear, &batch_rec.signals(), &cfg).unwrap();
            let c = stream(Linear, cfg, &rec, feed, x);
            // extrapolated time stamps are not used by these estimators
            assert_same(&c, &b, 0.0, &format!("linear {what}"));
            assert_same_score(&c, &b, 0.0, &format!("linear {what}"));
            // `Follow` reads the command over the horizon: with a lead its
            // windows at the end of the lines see commands the batch
            // recording does not have, so compare with batch on the longer data
            let longer = tail(&rec, shift);
            let b = run(&mut follow7(), &longer.signals(), &cfg).unwrap();
            assert!(b.failed_windows() > 0);
            let c = stream(follow7(), cfg, &rec, feed, x);
            let mut b_cut = b.clone();
            b_cut.predicted.truncate(end - shift);
            b_cut.has_prediction.truncate(end - shift);
            assert_same(&c, &b_cut, 0.0, &format!("follow {what}"));
        }
    }
}

fn paper(solver: Solver) -> PaperMethod {
    PaperConfig {
        solver,
        ..PaperConfig::default()
    }
    .build()
    .unwrap()
}

#[test]
fn paper_method_streams_as_the_batch_engine_with_qr_and_simplex() {
    // 10 ms of rest then the ramp: rest windows, the motion start and moving windows
    let rec = rig_recording(Scenario::Ramp, 0.1);
    let cases = [
        (Solver::Qr, EngineConfig::default(), Feed::Lines(0)),
        (Solver::Qr, configs()[1], Feed::Lines(0)),
        (Solver::Qr, configs()[2], Feed::Ahead(3)),
        (Solver::Simplex, EngineConfig::default(), Feed::Lines(0)),
        // a lead: the motion start found from a command ahead of its position
        (Solver::Qr, EngineConfig::default(), Feed::Lines(10)),
    ];
    for (solver, cfg, feed) in cases {
        let what = format!("{solver:?} {cfg:?} {feed:?}");
        let shift = match feed {
            Feed::Lines(l) => l,
            Feed::Ahead(_) => 0,
        };
        let sub = Recording::new(
            rec.time()[shift..rec.len() - shift].to_vec(),
            rec.command()[shift..rec.len() - shift].to_vec(),
            rec.position()[shift..rec.len() - shift].to_vec(),
        )
        .unwrap();
        let b = run(&mut paper(solver), &sub.signals(), &cfg).unwrap();
        let rest = b
            .windows
            .iter()
            .filter(|w| w.outcome == WindowOutcome::Fallback)
            .count();
        assert!(rest > 0 && rest < b.windows.len() / 2, "{what}: {rest}");
        assert_eq!(b.failed_windows(), 0);
        let c = stream(paper(solver), cfg, &rec, feed, Velocity);
        // extrapolated horizon time stamps: equal to rounding
        assert_same(&c, &b, 1e-12, &what);
        assert_same_score(&c, &b, 1e-12, &what);
        // window-end emission: each prediction arrives with the window's last sample
        for &(at, h, already) in &c.arrivals {
            assert!(at == h || at == c.stats.samples, "{what}: {at} {h}");
            assert_eq!(already, at.min(h + cfg.horizon) - h.min(at), "{what}");
        }
    }
}

#[test]
fn motion_start_is_found_causally_with_the_batch_value() {
    let rec = rig_recording(Scenario::Ramp, 0.03);
    let k0 = rec.motion_start_index(MOTION_THRESHOLD).unwrap();
    // lines with the own command: found with the first moving command
    let mut s = Streamer::new(Linear, EngineConfig::default()).unwrap();
    for k in 0..rec.len() {
        s.push(rec.time()[k], rec.command()[k], rec.position()[k])
            .unwrap();
        while s.poll().unwrap().is_some() {}
        if k <= k0 {
            assert_eq!(s.motion_start(), f64::INFINITY, "{k}");
        } else {
            assert_eq!(s.motion_start(), rec.motion_start_time());
        }
    }
    // commands 5 ahead: the sample is known early, its time once measured
    let opts = StreamOptions {
        lookahead: Some(5),
        ..StreamOptions::default()
    };
    let mut s = Streamer::with_options(Linear, EngineConfig::default(), opts).unwrap();
    for k in 0..5 {
        s.push_command(rec.command()[k]).unwrap();
    }
    for k in 0..rec.len() - 5 {
        s.push_command(rec.command()[k + 5]).unwrap();
        s.push_position(rec.time()[k], rec.position()[k]).unwrap();
        while s.poll().unwrap().is_some() {}
        if k < k0 {
            assert_eq!(s.motion_start(), f64::INFINITY, "{k}");
        } else {
            assert_eq!(s.motion_start(), rec.motion_start_time(), "{k}");
        }
    }
}

#[test]
fn without_extrapolation_predictions_wait_for_the_command_over_the_horizon() {
    let rec = rig_recording(Scenario::Ramp, 0.05);
    let cfg = EngineConfig::default();
    let c = stream(follow7(), cfg, &rec, Feed::Lines(0), Wait);
    assert!(!c.arrivals.is_empty());
    for &(at, h, already) in &c.arrivals {
        // H − 1 samples after the window end, or at the end of input
        assert!(at == h + cfg.horizon || at == rec.len(), "{at} {h}");
        assert_eq!(already, at - h);
    }
    assert_eq!(c.stats.predicted_ahead, 0);
    assert!(c.stats.predicted_late > 0);
    // with a look-ahead of H, at the window end
    let c = stream(follow7(), cfg, &rec, Feed::Ahead(cfg.horizon), Wait);
    for &(at, h, already) in &c.arrivals {
        assert!(at == h || at == rec.len(), "{at} {h}");
        assert!(already == 0 || at == rec.len());
    }
    let s = Streamer::new(follow7(), cfg).unwrap();
    assert!(s.uses_future_command());
    assert_eq!(
        s.horizon_command(),
        HorizonCommand::Extrapolated {
            extrapolation: Acceleration,
            known: 0
        }
    );
    assert!(!Streamer::new(Linear, cfg).unwrap().uses_future_command());
    assert_eq!(
        Streamer::new(Linear, cfg).unwrap().horizon_command(),
        HorizonCommand::NotRead
    );
}

#[test]
fn extrapolated_predictions_come_at_the_window_end_with_the_extrapolated_command() {
    // a command that is a parabola (constant acceleration): acceleration is
    // exact, velocity and hold are not; `Follow` predicts y0 + u[k] − u0
    let n = 400;
    let dt = 1e-3;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
    let u: Vec<f64> = (0..n).map(|k| 1e-6 * (k as f64).powi(2)).collect();
    let y: Vec<f64> = (0..n).map(|k| 0.5e-6 * (k as f64).powi(2)).collect();
    let rec = Recording::new(t, u.clone(), y.clone()).unwrap();
    let cfg = EngineConfig::default();
    // the extrapolation's arithmetic: the predictions as made (a held or
    // linear command on this accelerating axis is cut back by the guard)
    let batch = crate::ident::engine::run_as_made(&mut follow(), &rec.signals(), &cfg).unwrap();
    let scale = 0.16;
    let as_made = GuardConfig {
        runaway: None,
        ..GuardConfig::default()
    };
    for x in [Hold, Velocity, Acceleration] {
        let c = stream_guarded(follow(), cfg, &rec, Feed::Lines(0), x, as_made);
        assert_eq!(c.stats.predicted_late, 0, "{x:?}");
        assert!(c.stats.predicted_ahead > n / 2, "{x:?}");
        for &(at, h, already) in &c.arrivals {
            assert_eq!((at, already), (h, 0), "{x:?}");
        }
        let mut checked = 0;
        // hop = H: each sample is predicted by one window
        for w in c.windows.iter().filter(|w| w.1.end <= n) {
            let we = w.1.start;
            // the command the estimator saw, from the three samples before the window end
            let (a, b, d) = (u[we - 3], u[we - 2], u[we - 1]);
            for (m, k) in w.1.clone().enumerate() {
                let step = (m + 1) as f64;
                let seen = match x {
                    Hold => d,
                    Velocity => d + step * (d - b),
                    _ => d + step * (d - b) + 0.5 * step * (step + 1.0) * ((d - b) - (b - a)),
                };
                let want = y[we - 1] + seen - u[we - 1];
                assert!(
                    (c.predicted[k] - want).abs() < 1e-12 * scale,
                    "{x:?}: {k}: {} vs {want}",
                    c.predicted[k]
                );
                let exact = (c.predicted[k] - batch.predicted[k]).abs() < 1e-12 * scale;
                assert_eq!(exact, x == Acceleration, "{x:?}: {k}");
                checked += 1;
            }
        }
        assert!(checked > n * 8 / 10, "{checked}");
    }
}

#[test]
fn finish_cuts_the_last_horizons_at_the_last_sample() {
    let rec = rig_recording(Scenario::Ramp, 0.02); // 100 samples
    let c = stream(
        follow7(),
        EngineConfig::default(),
        &rec,
        Feed::Lines(0),
        Wait,
    );
    let last = c.windows.last().unwrap();
    // windows at 1, 11, …, 71 (warm-up 1); the last one ends at 91 and its horizon is cut
    assert_eq!(last.0, 71..91);
    assert_eq!(last.1, 91..100);
}

#[test]
fn rejected_samples_leave_the_stream_unchanged() {
    let rec = rig_recording(Scenario::Ramp, 0.04);
    let (t, u, y) = (rec.time(), rec.command(), rec.position());
    let mut s = Streamer::new(paper(Solver::Qr), EngineConfig::default()).unwrap();
    let mut got = Vec::new();
    for k in 0..rec.len() {
        if k == 37 {
            assert!(matches!(
                s.push(t[k - 1], u[k], y[k]),
                Err(Error::NonMonotoneTime { index: 37, .. })
            ));
            assert!(matches!(
                s.push(t[k], f64::NAN, y[k]),
                Err(Error::NonFinite { index: 37, .. })
            ));
            assert!(matches!(
                s.push(t[k], u[k], f64::INFINITY),
                Err(Error::NonFinite { index: 37, .. })
            ));
        }
        s.push(t[k], u[k], y[k]).unwrap();
        while let Some(p) = s.poll().unwrap() {
            got.push(p.position.to_vec());
        }
    }
    let mut clean = Streamer::new(paper(Solver::Qr), EngineConfig::default()).unwrap();
    let mut want = Vec::new();
    for k in 0..rec.len() {
        clean.push(t[k], u[k], y[k]).unwrap();
        while let Some(p) = clean.poll().unwrap() {
            want.push(p.position.to_vec());
        }
    }
    assert_eq!(got, want);
    assert_eq!(s.stats(), clean.stats());
}

#[test]
fn values_a_recording_refuses_are_refused_per_sample() {
    let mut s = Streamer::new(Linear, EngineConfig::default()).unwrap();
    s.push(0.0, 0.0, 0.0).unwrap();
    for (t, u, y) in [(1e-3, 1e101, 0.0), (1e-3, 0.0, -1e300), (1e200, 0.0, 0.0)] {
        let e = s.push(t, u, y).unwrap_err();
        assert!(matches!(e, Error::OutOfRange { .. }), "{e}");
    }
    assert_eq!(s.stats().samples, 1);
    s.push(1e-3, 1e100, 0.0).unwrap();
}

#[test]
fn the_hold_baseline_is_scored_on_the_same_samples() {
    let rec = rig_recording(Scenario::Ramp, 0.1);
    let cfg = EngineConfig {
        hop: Some(3),
        ..EngineConfig::default()
    };
    let b = run(&mut paper(Solver::Qr), &rec.signals(), &cfg).unwrap();
    // independent: the latest window predicting each sample holds its last position
    let y = rec.position();
    let mut hold = vec![None; rec.len()];
    for w in &b.windows {
        if w.outcome.predicted() {
            for k in w.horizon.clone() {
                hold[k] = Some(y[w.window.end - 1]);
            }
        }
    }
    let want = ErrorStats::from_pairs((0..rec.len()).filter_map(|k| hold[k].map(|h| (y[k], h))));
    let c = stream(paper(Solver::Qr), cfg, &rec, Feed::Lines(0), Velocity);
    assert_eq!(c.stats.hold.samples, want.samples);
    assert!((c.stats.hold.rms - want.rms).abs() <= 1e-12 * want.rms);
    assert_eq!(c.stats.hold.max_abs, want.max_abs);
}

#[test]
fn misuse_is_reported() {
    let cfg = EngineConfig::default();
    let mut s = Streamer::new(Linear, cfg).unwrap();
    assert!(s.push_position(0.0, 0.0).is_err());
    for _ in 0..=cfg.horizon {
        s.push_command(0.0).unwrap();
    }
    assert!(matches!(
        s.push_command(0.0),
        Err(Error::InvalidParameter {
            name: "command look-ahead",
            ..
        })
    ));
    s.finish();
    assert!(s.push(100.0, 0.0, 0.0).is_err());
    s.reset();
    s.push(0.0, 0.0, 0.0).unwrap();
    assert!(s.poll().unwrap().is_none());
    // unpolled predictions eventually overflow the buffer instead of growing it
    let mut s = Streamer::with_options(
        Linear,
        EngineConfig {
            hop: Some(1),
            ..cfg
        },
        StreamOptions {
            lookahead: Some(0),
            dt: Some(1.0),
            ..StreamOptions::default()
        },
    )
    .unwrap();
    let r: Result<()> = (0..10_000).try_for_each(|k| {
        s.push_command(0.0)?;
        s.push_position(k as f64, 0.0).map(|_| ())
    });
    assert!(matches!(
        r,
        Err(Error::InvalidParameter {
            name: "stream buffer",
            ..
        })
    ));
    let zero = EngineConfig { window: 0, ..cfg };
    assert!(Streamer::new(Linear, zero).is_err());
    let bad_dt = StreamOptions {
        dt: Some(0.0),
        ..StreamOptions::default()
    };
    assert!(Streamer::with_options(Linear, cfg, bad_dt).is_err());
}

#[test]
fn boxed_estimators_stream_like_concrete_ones() {
    let rec = rig_recording(Scenario::Ramp, 0.04);
    let boxed: Box<dyn Estimator> = Box::new(paper(Solver::Qr));
    let a = stream(
        boxed,
        EngineConfig::default(),
        &rec,
        Feed::Lines(0),
        Velocity,
    );
    let b = stream(
        paper(Solver::Qr),
        EngineConfig::default(),
        &rec,
        Feed::Lines(0),
        Velocity,
    );
    assert_eq!(a.predicted, b.predicted);
    assert_eq!(a.stats, b.stats);
}

#[test]
fn an_implausible_prediction_is_withheld_in_the_stream_as_in_batch() {
    let rec = rig_recording(Scenario::Ramp, 0.08);
    let cfg = configs()[0];
    let wild = || Wild::new(12, 1.0);
    let b = run(&mut wild(), &rec.signals(), &cfg).unwrap();
    assert_eq!(b.withheld_windows(), 1);
    let c = stream(wild(), cfg, &rec, Feed::Lines(0), Wait);
    assert_same(&c, &b, 0.0, "wild");
    let withheld: Vec<usize> = (c.windows.iter())
        .enumerate()
        .filter(|(_, w)| w.2 == WindowOutcome::Withheld)
        .map(|(i, _)| i)
        .collect();
    assert_eq!(withheld, [11]);
}

#[test]
fn the_runaway_hull_follows_the_command_the_method_reads() {
    use crate::ident::engine::CommandBasis;
    let with = |command_lead, extrapolation| StreamOptions {
        command_lead,
        extrapolation,
        ..StreamOptions::default()
    };
    // a method that reads no horizon command: the guard's own extrapolation
    for lead in [0, 4, 10] {
        assert_eq!(
            with(lead, CommandExtrapolation::Velocity).command_basis(false, 10),
            CommandBasis::Extrapolated
        );
    }
    // one that does: measured when led a whole horizon or awaited, no hull
    // over the stream's own guess
    assert_eq!(
        with(10, CommandExtrapolation::Hold).command_basis(true, 10),
        CommandBasis::Measured
    );
    assert_eq!(
        with(0, CommandExtrapolation::Wait).command_basis(true, 10),
        CommandBasis::Measured
    );
    for x in [CommandExtrapolation::Hold, CommandExtrapolation::Velocity] {
        assert_eq!(with(9, x).command_basis(true, 10), CommandBasis::Other);
    }
}
