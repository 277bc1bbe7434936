//! A fixed workload for instruction-count profiles of the per-window
//! paths (callgrind counts instructions and is repeatable on a shared,
//! noisy machine, unlike wall time):
//!
//! ```text
//! cargo build --profile bench -p feedid --example profile_window
//! valgrind --tool=callgrind --callgrind-out-file=cg.out \
//!     target/release/examples/profile_window arx 3
//! callgrind_annotate cg.out | head -40
//! ```
//!
//! Arguments: a method name (`arx`, `oe`, `rls`, `auto`, `paper` (QR,
//! motion origin: the defaults), `paper-window` (window origin),
//! `paper-simplex`, `paper-simplex-previous`), a repetition count and,
//! optionally, `no-runaway` (the engine's guard without its runaway cut:
//! the difference is the cut's cost). The workload is the
//! benches' (`benches/methods.rs`, `benches/paper_window.rs`): the virtual
//! rig's chirp (1 s at 5 kHz, seed 1) through the sliding engine with the
//! method's default window, H = 10, hop 10; the paper variants on the ramp
//! (0.8 s) with W = 20. A method name followed by `@hour` (`auto@hour`)
//! runs on the one-hour benchmark's recording instead (`benches/batch_hour.rs`:
//! one 1.4 s period of a 30 mm back-and-forth move simulated once and
//! tiled), three periods of it. Prints the windows and the mean wall time
//! per window (indicative only).

use feedid::drive::{RigParams, VirtualRig};
use feedid::ident::engine::run_with;
use feedid::ident::{
    EngineConfig, GuardConfig, Method, PaperConfig, SimplexStart, Solver, TimeOrigin,
};
use feedid::signal::Scenario;
use feedid::Recording;

fn recording(scenario: Scenario, seconds: f64) -> feedid::Result<Recording> {
    let rate = 5000.0;
    let command = scenario.command(rate, seconds, 1)?;
    let out = VirtualRig::new(RigParams::default())
        .with_seed(1)
        .simulate(&command, rate)?;
    Recording::new(out.time, out.command, out.position)
}

/// The one-hour benchmark's recording, `periods` periods of it: 50 ms at
/// rest, 30 mm forward at 50 mm/s, 100 ms held, back, 50 ms at rest (at 5
/// kHz), simulated once and tiled.
fn hour_recording(periods: usize) -> feedid::Result<Recording> {
    let rate = 5000.0f64;
    let (rest, hold, v, d) = (0.05f64, 0.1, 0.05, 0.03);
    let ramp = d / v;
    let n = ((2.0 * rest + 2.0 * ramp + hold) * rate).round() as usize;
    let cmd: Vec<f64> = (0..n)
        .map(|k| {
            let t = k as f64 / rate;
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
        .collect();
    let sim = VirtualRig::new(RigParams::default())
        .with_seed(1)
        .simulate(&cmd, rate)?;
    let m = n * periods;
    Recording::new(
        (0..m).map(|k| k as f64 / rate).collect(),
        (0..m).map(|k| cmd[k % n]).collect(),
        (0..m).map(|k| sim.position[k % n]).collect(),
    )
}

fn main() -> feedid::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map_or("arx", String::as_str);
    let reps: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(3);
    let guard = GuardConfig {
        runaway: if args.get(3).map(String::as_str) == Some("no-runaway") {
            None
        } else {
            GuardConfig::default().runaway
        },
        ..GuardConfig::default()
    };
    let (spec, rec) = if let Some(method) = name.strip_suffix("@hour") {
        (method.parse::<Method>()?, hour_recording(3)?)
    } else if let Some(rest) = name.strip_prefix("paper") {
        let mut cfg = PaperConfig::default();
        if rest.contains("simplex") {
            cfg.solver = Solver::Simplex;
        }
        if rest.contains("previous") {
            cfg.simplex_start = SimplexStart::Previous;
        }
        if rest.contains("window") {
            cfg.time_origin = TimeOrigin::Window;
        }
        (Method::Paper(cfg), recording(Scenario::Ramp, 0.8)?)
    } else {
        (name.parse::<Method>()?, recording(Scenario::Chirp, 1.0)?)
    };
    let signals = rec.signals();
    let cfg = EngineConfig {
        window: spec.default_window(),
        ..EngineConfig::default()
    };
    let mut est = spec.build()?;
    let mut total = 0.0;
    let mut windows = 0;
    let mut rms = 0.0;
    for _ in 0..reps {
        let r = run_with(est.as_mut(), &signals, &cfg, &guard, None)?;
        total += r.elapsed.as_secs_f64();
        windows += r.windows.len();
        rms = r.stats.rms;
    }
    println!(
        "{name}: {windows} windows, {:.2} µs/window, rms {:.3} µm",
        1e6 * total / windows.max(1) as f64,
        rms * 1e6
    );
    Ok(())
}
