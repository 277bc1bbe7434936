//! Benchmark: batch throughput of the default method `auto` (W = 50, H =
//! hop = 10) and of the paper method (QR, W = 20) with the single-threaded
//! engine over one hour of 5 kHz data (18 million samples, 1.8 million
//! windows). Target for the default method: ≤ 10 s. `auto` runs twice: with
//! the engine's default guard and with its runaway cut off
//! ([`GuardConfig::runaway`] `None`): the difference is the runaway cut's cost.
//!
//! The hour is generated cheaply: one 1.4 s period of a back-and-forth move
//! (50 ms rest, 30 mm forward at 50 mm/s, 100 ms hold, back, 50 ms rest) is
//! simulated once with the nonlinear virtual rig (every effect on) and tiled,
//! with time running on (`k/5000`). The axis is back at rest at the period
//! boundaries, so the tiling is continuous up to the rig's stick-slip offset
//! and noise. The time origin is the first motion start, so later windows
//! are far (up to an hour) from it: the paper's worst case for the change of
//! basis, which this measures too. `FEEDID_BENCH_SECONDS` changes the length.

use criterion::{black_box, criterion_group, criterion_main, Criterion, SamplingMode, Throughput};
use feedid::drive::{RigParams, VirtualRig};
use feedid::ident::engine::run_with;
use feedid::ident::{EngineConfig, Estimator, GuardConfig, Method, Signals};
use std::time::{Duration, Instant};

const RATE: f64 = 5000.0;

/// One period of the back-and-forth command \[m\].
fn period_command() -> Vec<f64> {
    let (rest, hold, v, d) = (0.05, 0.1, 0.05, 0.03);
    let ramp = d / v;
    let period = 2.0 * rest + 2.0 * ramp + hold;
    let n = (period * RATE).round() as usize;
    (0..n)
        .map(|k| {
            let t = k as f64 / RATE;
            if t < rest {
                0.0
            } else if t < rest + ramp {
                v * (t - rest)
            } else if t < rest + ramp + hold {
                d
            } else if t < rest + 2.0 * ramp + hold {
                d - v * (t - rest - ramp - hold)
            } else {
                0.0
            }
        })
        .collect()
}

fn hour(c: &mut Criterion) {
    let seconds: f64 = std::env::var("FEEDID_BENCH_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(3600.0);
    let n = (seconds * RATE).round() as usize;
    let t0 = Instant::now();
    let cmd = period_command();
    let sim = VirtualRig::new(RigParams::default())
        .with_seed(1)
        .simulate(&cmd, RATE)
        .unwrap_or_else(|e| panic!("{e}"));
    let time: Vec<f64> = (0..n).map(|k| k as f64 / RATE).collect();
    let command: Vec<f64> = (0..n).map(|k| cmd[k % cmd.len()]).collect();
    let position: Vec<f64> = (0..n).map(|k| sim.position[k % cmd.len()]).collect();
    let first_move = command.iter().position(|&c| c.abs() > 1e-9).unwrap_or(1);
    let motion_start = time[first_move.saturating_sub(1)];
    let signals = Signals::new(&time, &command, &position, 1.0 / RATE, motion_start);
    eprintln!(
        "generated {n} samples ({seconds} s at 5 kHz) in {:.2} s",
        t0.elapsed().as_secs_f64()
    );
    let mut g = c.benchmark_group("batch");
    g.sampling_mode(SamplingMode::Flat)
        .sample_size(10)
        .warm_up_time(Duration::from_millis(1))
        .measurement_time(Duration::from_secs(1))
        .throughput(Throughput::Elements(n as u64));
    let uncut = GuardConfig {
        runaway: None,
        ..GuardConfig::default()
    };
    for (name, label, guard) in [
        ("auto", "auto_engine_one_hour_5khz", GuardConfig::default()),
        ("auto", "auto_engine_one_hour_5khz_no_runaway_cut", uncut),
        (
            "paper",
            "paper_qr_engine_one_hour_5khz",
            GuardConfig::default(),
        ),
    ] {
        let spec: Method = name.parse().unwrap_or_else(|e| panic!("{e}"));
        let cfg = EngineConfig {
            window: spec.default_window(),
            ..EngineConfig::default()
        };
        let mut est = spec.build().unwrap_or_else(|e| panic!("{e}"));
        // one reported run first: failures and the engine's own timing
        let r = run_with(&mut est, &signals, &cfg, &guard, None).unwrap_or_else(|e| panic!("{e}"));
        eprintln!(
            "{}: {} windows, {} failed, {} withheld, {} predicted samples, rms {:.3e} m; engine time {:.2} s ({:.3} µs/window)",
            est.name(),
            r.windows.len(),
            r.failed_windows(),
            r.withheld_windows(),
            r.stats.samples,
            r.stats.rms,
            r.elapsed.as_secs_f64(),
            r.per_window_us()
        );
        drop(r);
        g.bench_function(label, |b| {
            b.iter(|| {
                let r = run_with(&mut est, &signals, &cfg, &guard, None)
                    .unwrap_or_else(|e| panic!("{e}"));
                black_box(r.stats.rms)
            })
        });
    }
    g.finish();
}

criterion_group!(benches, hour);
criterion_main!(benches);
