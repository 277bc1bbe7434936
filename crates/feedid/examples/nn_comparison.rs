//! The neural predictor against the least-squares methods, as the paper's
//! outlook asks: every method with its defaults (H = 10, hop 10) on the
//! virtual rig's ramp and step (all effects, seed 7, 5 kHz), a 10 s PRBS of
//! the rig, and EMPS (1 kHz, `qg` → `qm`; path in `FEEDID_EMPS_MAT` or the
//! workplace's). Errors are scored on the samples *every* method predicts;
//! the time is the whole run (for `nn` its trainings included) and per
//! window.
//!
//! `cargo run --release -p feedid --example nn_comparison`

use std::time::Instant;

use feedid::drive::{RigParams, VirtualRig};
use feedid::ident::{engine, EngineConfig, Method, SlidingResult};
use feedid::io::{read_recording, ChannelRef, ReadOptions};
use feedid::signal::Scenario;
use feedid::Recording;

const METHODS: [&str; 6] = ["paper", "arx", "rls", "oe", "auto", "nn"];

fn table(name: &str, rec: &Recording) -> feedid::Result<()> {
    let s = rec.signals();
    let mut runs: Vec<(&str, SlidingResult, f64)> = Vec::new();
    for m in METHODS {
        let spec: Method = m.parse()?;
        let mut est = spec.build()?;
        let cfg = EngineConfig {
            window: spec.default_window(),
            horizon: 10,
            hop: None,
            warm_up: 0,
        };
        let t = Instant::now();
        let r = engine::run(&mut est, &s, &cfg)?;
        runs.push((m, r, t.elapsed().as_secs_f64()));
    }
    let y = rec.position();
    let shared: Vec<usize> = (0..rec.len())
        .filter(|&k| runs.iter().all(|(_, r, _)| r.has_prediction[k]))
        .collect();
    println!(
        "\n{name}: {} samples, {} predicted by every method ({:.1} %)\n",
        rec.len(),
        shared.len(),
        100.0 * shared.len() as f64 / rec.len() as f64
    );
    println!("| method | rms [µm] | max [µm] | own coverage [%] | 95 % interval coverage [%] | run [ms] | per window [µs] |");
    println!("|---|---:|---:|---:|---:|---:|---:|");
    for (m, r, secs) in &runs {
        if shared.is_empty() {
            println!("| {m} | — | — | {:.1} | — | {:.1} | — |", 0.0, 1e3 * secs);
            continue;
        }
        let (mut ss, mut mx) = (0.0, 0.0_f64);
        for &k in &shared {
            let e = r.predicted[k] - y[k];
            ss += e * e;
            mx = mx.max(e.abs());
        }
        let own = 100.0 * r.stats.samples as f64 / rec.len() as f64;
        let inside = r
            .interval_coverage_percent()
            .map_or("—".to_string(), |v| format!("{v:.1}"));
        println!(
            "| {m} | {:.3} | {:.2} | {own:.1} | {inside} | {:.1} | {:.1} |",
            1e6 * (ss / shared.len() as f64).sqrt(),
            1e6 * mx,
            1e3 * secs,
            1e6 * secs / r.windows.len().max(1) as f64
        );
    }
    Ok(())
}

fn rig(scenario: Scenario, seconds: Option<f64>) -> feedid::Result<Recording> {
    let rate = 5000.0;
    let d = seconds.unwrap_or(scenario.default_duration());
    let command = scenario.command(rate, d, 1)?;
    let out = VirtualRig::new(RigParams::default())
        .with_seed(7)
        .simulate(&command, rate)?;
    Recording::new(out.time, out.command, out.position)
}

fn main() -> feedid::Result<()> {
    table("rig ramp", &rig(Scenario::Ramp, None)?)?;
    table("rig step", &rig(Scenario::Step, None)?)?;
    table("rig PRBS, 10 s at 5 kHz", &rig(Scenario::Prbs, Some(10.0))?)?;
    let path = std::env::var("FEEDID_EMPS_MAT").unwrap_or_else(|_| {
        format!(
            "{}/../../../shared/data/emps/DATA_EMPS.mat",
            env!("CARGO_MANIFEST_DIR")
        )
    });
    if std::path::Path::new(&path).exists() {
        let rec = read_recording(
            std::path::Path::new(&path),
            &ReadOptions {
                time: Some(ChannelRef::Name("t".into())),
                command: Some(ChannelRef::Name("qg".into())),
                position: Some(ChannelRef::Name("qm".into())),
                ..Default::default()
            },
        )?;
        table("EMPS (10 ms ahead)", &rec)?;
    } else {
        eprintln!("EMPS skipped: {path} not found (set FEEDID_EMPS_MAT)");
    }
    Ok(())
}
