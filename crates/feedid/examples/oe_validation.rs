//! Output-error (`oe`) on the virtual rig (six scenarios, all effects on) and
//! on EMPS: global free-run fit % and sliding k-step-ahead errors.
//!
//! `cargo run -p feedid --example oe_validation -- [np] [nz] [window] [emps.mat]`

use std::path::Path;

use feedid::drive::{RigParams, VirtualRig};
use feedid::ident::engine::{run, EngineConfig};
use feedid::ident::{fit_oe, OeConfig, Signals};
use feedid::io::{read_recording, ChannelRef, ReadOptions};
use feedid::signal::Scenario;

fn main() -> feedid::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let np: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(3);
    let nz: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1);
    let window: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(200);
    let emps = args
        .get(4)
        .cloned()
        .unwrap_or_else(|| "/work/shared/data/emps/DATA_EMPS.mat".to_string());
    let cfg = OeConfig {
        poles: np,
        zeros: nz,
        ..OeConfig::default()
    };
    println!("oe np={np} nz={nz} window={window} horizon=10");
    println!(
        "{:<10} {:>9} {:>10} {:>10} {:>10} {:>8} {:>6}",
        "data", "sim fit%", "rms [um]", "max [um]", "k-fit %", "failed", "fallbk"
    );
    let rig = VirtualRig::new(RigParams::default()).with_seed(1);
    for sc in Scenario::ALL {
        let rate = 5000.0;
        let cmd = sc.command(rate, sc.default_duration(), 1)?;
        let out = rig.simulate(&cmd, rate)?;
        report(
            sc.name(),
            &out.time,
            &out.command,
            &out.position,
            1.0 / rate,
            &cfg,
            window,
        )?;
    }
    if Path::new(&emps).exists() {
        let opts = ReadOptions {
            time: Some(ChannelRef::Name("t".into())),
            command: Some(ChannelRef::Name("qg".into())),
            position: Some(ChannelRef::Name("qm".into())),
            ..ReadOptions::default()
        };
        let rec = read_recording(Path::new(&emps), &opts)?;
        report(
            "emps",
            rec.time(),
            rec.command(),
            rec.position(),
            rec.dt(),
            &cfg,
            window,
        )?;
    }
    Ok(())
}

fn report(
    name: &str,
    t: &[f64],
    u: &[f64],
    y: &[f64],
    dt: f64,
    cfg: &OeConfig,
    window: usize,
) -> feedid::Result<()> {
    let sim = match fit_oe(u, y, dt, cfg) {
        Ok(f) => {
            eprintln!(
                "{name}: poles {:?} iters {} {:?}",
                f.poles()?
                    .iter()
                    .map(|p| format!(
                        "{:.1}{:+.1}i Hz",
                        p.re / std::f64::consts::TAU,
                        p.im / std::f64::consts::TAU
                    ))
                    .collect::<Vec<_>>(),
                f.report.iterations,
                f.report.termination
            );
            format!("{:.3}", f.fit_percent)
        }
        Err(e) => format!("err: {e}"),
    };
    let mut est = cfg.clone().build()?;
    let ecfg = EngineConfig {
        window,
        horizon: 10,
        hop: None,
        warm_up: 0,
    };
    let res = run(&mut est, &Signals::new(t, u, y, dt, 0.0), &ecfg)?;
    let fallbacks = res
        .windows
        .iter()
        .filter(|w| w.outcome == feedid::ident::WindowOutcome::Fallback)
        .count();
    println!(
        "{:<10} {:>9} {:>10.4} {:>10.3} {:>10.4} {:>8} {:>6}",
        name,
        sim,
        res.stats.rms * 1e6,
        res.stats.max_abs * 1e6,
        res.stats.fit_percent,
        res.failed_windows(),
        fallbacks
    );
    Ok(())
}
