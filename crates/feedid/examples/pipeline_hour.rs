//! One hour of 5 kHz data through the single-threaded engine and through
//! the whole pipeline (`feedid identify`'s computation: engine, nominal
//! simulation, global model, residual analysis), timed here and written as
//! raw little-endian f64 files for the Python binding's timing of the same
//! data (`python/examples/bench_hour.py`; docs/RESULTS.md, "Speed").
//!
//! ```sh
//! cargo run --release -p feedid --example pipeline_hour -- /tmp/hour [REPEATS]
//! ```
//!
//! The hour is the `batch_hour` benchmark's: one 1.4 s back-and-forth period
//! simulated on the nonlinear virtual rig (seed 1) and tiled, time `k/5000`.
//! `FEEDID_BENCH_SECONDS` changes the length. Prints the minimum and median
//! wall time of each over the repeats (default 3).

use std::io::Write;
use std::time::Instant;

use feedid::drive::{RigParams, VirtualRig};
use feedid::ident::engine::run;
use feedid::ident::{EngineConfig, Method};
use feedid::pipeline::Pipeline;
use feedid::Recording;

const RATE: f64 = 5000.0;

/// One period of the back-and-forth command \[m\] (as in `benches/batch_hour.rs`).
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

fn write_f64(path: &str, v: &[f64]) -> std::io::Result<()> {
    let mut w = std::io::BufWriter::new(std::fs::File::create(path)?);
    for x in v {
        w.write_all(&x.to_le_bytes())?;
    }
    w.flush()
}

/// CPU time of this process \[s\] (user + system, from `/proc/self/stat`;
/// 0 where it cannot be read): with other jobs on the cores it varies less
/// than the wall time.
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    // fields after the command name in parentheses; utime and stime are 14 and 15
    let Some(rest) = stat.rsplit(')').next() else {
        return 0.0;
    };
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0);
    // fields 14 and 15 of the whole line are 11 and 12 after the name and state
    (ticks(11) + ticks(12)) / 100.0
}

fn stats(mut v: Vec<f64>) -> (f64, f64) {
    v.sort_by(f64::total_cmp);
    (v[0], v[v.len() / 2])
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let prefix = args.next().ok_or("usage: pipeline_hour PREFIX [REPEATS]")?;
    let repeats: usize = args.next().map(|s| s.parse()).transpose()?.unwrap_or(3);
    let seconds: f64 = std::env::var("FEEDID_BENCH_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(3600.0);
    let n = (seconds * RATE).round() as usize;
    let cmd = period_command();
    let sim = VirtualRig::new(RigParams::default())
        .with_seed(1)
        .simulate(&cmd, RATE)?;
    let time: Vec<f64> = (0..n).map(|k| k as f64 / RATE).collect();
    let command: Vec<f64> = (0..n).map(|k| cmd[k % cmd.len()]).collect();
    let position: Vec<f64> = (0..n).map(|k| sim.position[k % cmd.len()]).collect();
    write_f64(&format!("{prefix}.time.f64"), &time)?;
    write_f64(&format!("{prefix}.command.f64"), &command)?;
    write_f64(&format!("{prefix}.position.f64"), &position)?;
    let rec = Recording::new(time, command, position)?;
    println!("{n} samples ({seconds} s at 5 kHz) written to {prefix}.*.f64");

    let method = Method::default();
    let cfg = EngineConfig {
        window: method.default_window(),
        ..EngineConfig::default()
    };
    let pipeline = Pipeline::new(method.clone()).nominal(RigParams::default());
    // each extra alone, once: where the pipeline's time goes
    let bare = Pipeline::new(method.clone())
        .method_global_model(false)
        .residuals(None);
    let breakdown = std::env::var("FEEDID_BENCH_BREAKDOWN").map_or(true, |v| v != "0");
    for (what, p) in [
        ("sliding identification only", bare.clone()),
        (
            "+ nominal simulation",
            bare.clone().nominal(RigParams::default()),
        ),
        ("+ global model", bare.clone().method_global_model(true)),
        (
            "+ residual analysis",
            bare.clone().residuals(Some(feedid::ident::RESIDUAL_LAGS)),
        ),
    ]
    .into_iter()
    .filter(|_| breakdown)
    {
        let t0 = Instant::now();
        p.run(&rec)?;
        println!("pipeline, {what}: {:.2} s", t0.elapsed().as_secs_f64());
    }
    if breakdown {
        let t0 = Instant::now();
        pipeline.run(&rec)?;
        println!(
            "pipeline, all of feedid identify's: {:.2} s",
            t0.elapsed().as_secs_f64()
        );
    }
    let (mut engine, mut sliding) = (Vec::new(), Vec::new());
    let (mut engine_cpu, mut sliding_cpu) = (Vec::new(), Vec::new());
    for _ in 0..repeats {
        let mut est = method.build()?;
        let (t0, c0) = (Instant::now(), cpu_seconds());
        let r = run(&mut est, &rec.signals(), &cfg)?;
        engine.push(t0.elapsed().as_secs_f64());
        engine_cpu.push(cpu_seconds() - c0);
        let (t0, c0) = (Instant::now(), cpu_seconds());
        let p = bare.run(&rec)?;
        sliding.push(t0.elapsed().as_secs_f64());
        sliding_cpu.push(cpu_seconds() - c0);
        assert_eq!(p.sliding.predicted, r.predicted);
    }
    for (what, wall, cpu) in [
        ("engine (auto)", engine, engine_cpu),
        (
            "pipeline, sliding identification only",
            sliding,
            sliding_cpu,
        ),
    ] {
        let (wmin, wmed) = stats(wall);
        let (cmin, cmed) = stats(cpu);
        println!(
            "{what}: wall min {wmin:.2} s, median {wmed:.2} s; CPU min {cmin:.2} s, median {cmed:.2} s over {repeats} runs"
        );
    }
    Ok(())
}
