//! Write a virtual-rig recording as CSV `time_s,command_m,position_m`.
//!
//! ```text
//! cargo run --release -p feedid --example make_recording -- ramp out.csv [duration_s] [seed]
//! ```
//!
//! The scenario's default command at 5 kHz (see `feedid::signal::Scenario`)
//! through the nonlinear virtual rig with its default parameters (every
//! effect on, seeded measurement noise). Numbers use Rust's shortest
//! round-trip formatting, so a reader gets the exact values back. Stands in
//! for `feedid simulate --scenario … -o …` where that command is absent.

use std::io::Write;
use std::path::PathBuf;

use feedid::drive::{RigParams, VirtualRig};
use feedid::io::write_atomic;
use feedid::signal::Scenario;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 {
        return Err("usage: make_recording <scenario> <out.csv> [duration_s] [seed]".into());
    }
    let scenario: Scenario = args[0].parse()?;
    let path = PathBuf::from(&args[1]);
    let duration = match args.get(2) {
        Some(d) => d.parse()?,
        None => scenario.default_duration(),
    };
    let seed = match args.get(3) {
        Some(s) => s.parse()?,
        None => 1,
    };
    let rate = scenario.default_rate();
    let command = scenario.command(rate, duration, seed)?;
    let out = VirtualRig::new(RigParams::default())
        .with_seed(seed)
        .simulate(&command, rate)?;
    write_atomic(&path, |w: &mut dyn Write| {
        writeln!(w, "time_s,command_m,position_m")?;
        for k in 0..out.len() {
            writeln!(w, "{},{},{}", out.time[k], out.command[k], out.position[k])?;
        }
        Ok(())
    })?;
    eprintln!(
        "{}: {} samples of `{}`",
        path.display(),
        out.len(),
        scenario.name()
    );
    Ok(())
}
