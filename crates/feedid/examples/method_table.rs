//! The method × recording table of README.md and docs/RESULTS.md: 2 ms-ahead (H = 10) prediction
//! error of every method, with its default window, on the six rig scenarios
//! (all effects, 0.2 µm noise, 0.1 µm quantisation, 5 kHz, seed 7) and on
//! EMPS (1 kHz, `qg` → `qm`, path in `FEEDID_EMPS_MAT` or the workplace's).
//!
//! `cargo run --release -p feedid --example method_table`

use feedid::drive::{RigParams, VirtualRig};
use feedid::ident::{engine, EngineConfig, Method, Signals};
use feedid::io::{read_recording, ChannelRef, ReadOptions};
use feedid::signal::Scenario;
use feedid::Recording;

const METHODS: [&str; 5] = ["paper", "arx", "rls", "oe", "auto"];

fn row(name: &str, s: &Signals<'_>) -> feedid::Result<String> {
    let mut line = format!("| {name} |");
    for name in METHODS {
        let spec: Method = name.parse()?;
        let mut est = spec.build()?;
        let cfg = EngineConfig {
            window: spec.default_window(),
            horizon: 10,
            hop: None,
            warm_up: 0,
        };
        let r = engine::run(&mut est, s, &cfg)?;
        let cov = 100.0 * r.stats.samples as f64 / s.len() as f64;
        line += &format!(
            " {:.3} / {:.2} ({:.0} %) |",
            r.stats.rms * 1e6,
            r.stats.max_abs * 1e6,
            cov
        );
    }
    Ok(line)
}

fn main() -> feedid::Result<()> {
    println!("| recording | paper (W 20) | arx (W 100) | rls (W 100) | oe (W 200) | auto (W 50) |");
    println!("|---|---|---|---|---|---|");
    for scenario in Scenario::ALL {
        let rate = 5000.0;
        let command = scenario.command(rate, scenario.default_duration(), 1)?;
        let out = VirtualRig::new(RigParams::default())
            .with_seed(7)
            .simulate(&command, rate)?;
        // through a Recording, as the CLI does (motion start from the data)
        let rec = Recording::new(out.time, out.command, out.position)?;
        println!("{}", row(scenario.name(), &rec.signals())?);
    }
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
        println!("{}", row("EMPS (10 ms ahead)", &rec.signals())?);
    } else {
        eprintln!("EMPS skipped: {path} not found (set FEEDID_EMPS_MAT)");
    }
    println!("\nEach cell: rms / max error [µm] (coverage: share of samples predicted).");
    Ok(())
}
