//! Write a virtual-rig recording of a long move with a small PRBS dither on
//! top, as CSV `time_s,command_m,position_m,current_a` — a recording in
//! which the axial stiffness can be tracked along the move
//! (`feedid greybox … --estimate K --track-window …`).
//!
//! ```text
//! cargo run --release -p feedid --example dithered_move -- move.csv [distance_m] [velocity_m_per_s] [seed]
//! ```
//!
//! Defaults: 0.1 m at 0.1 m/s after 10 ms of rest (the nut moves from 0.16 m
//! to 0.26 m from the fixed bearing, so the screw softens by about 20 %),
//! plus the default PRBS (0.03 mm, 2 ms clock), 1.2 s at 5 kHz, through the
//! nonlinear virtual rig with every effect on (seeded noise).

use std::io::Write;
use std::path::PathBuf;

use feedid::drive::{RigParams, VirtualRig};
use feedid::io::write_atomic;
use feedid::signal::{Prbs, Ramp};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(path) = args.first().map(PathBuf::from) else {
        return Err("usage: dithered_move <out.csv> [distance_m] [velocity_m_per_s] [seed]".into());
    };
    let distance: f64 = args.get(1).map_or(Ok(0.1), |s| s.parse())?;
    let velocity: f64 = args.get(2).map_or(Ok(0.1), |s| s.parse())?;
    let seed: u64 = args.get(3).map_or(Ok(1), |s| s.parse())?;
    let rate = 5000.0;
    let ramp = Ramp {
        distance,
        velocity,
        ..Ramp::default()
    };
    let duration = ramp.end_of_motion() + 0.1;
    let mut command = ramp.generate(rate, duration)?;
    let dither = Prbs::default().generate(rate, duration, seed)?;
    for (c, d) in command.iter_mut().zip(&dither) {
        *c += d;
    }
    let out = VirtualRig::new(RigParams::default())
        .with_seed(seed)
        .simulate(&command, rate)?;
    write_atomic(&path, |w: &mut dyn Write| {
        writeln!(w, "time_s,command_m,position_m,current_a")?;
        for k in 0..out.len() {
            writeln!(
                w,
                "{},{},{},{}",
                out.time[k], out.command[k], out.position[k], out.motor_current[k]
            )?;
        }
        Ok(())
    })?;
    eprintln!(
        "{}: {} samples, {:.3} m at {:.3} m/s with a PRBS dither",
        path.display(),
        out.len(),
        distance,
        velocity
    );
    Ok(())
}
