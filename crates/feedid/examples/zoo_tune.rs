//! `tune` on the drive zoo's rig axes: each axis's cascade (the paper's P /
//! PI / PI with the motor's winding and the screw, `DriveStructure::paper`
//! of its rig parameters) retuned for 1.5× the bandwidth of its own
//! feedback loops (without its feed-forward, which the rig keeps) at
//! ζ = 1/√2 (the gains of its rigid, force-source equivalent, the whole
//! loop's bandwidth found by bisection), the new position and velocity gains
//! written back into the rig parameters, and an S-curve move
//! (`Scenario::Scurve`, 20 mm) run through the member's **nonlinear
//! virtual rig** (its friction, backlash, limits, sampled position loop and
//! encoder) with its own gains and with the proposed ones.
//!
//! ```sh
//! cargo run --release -p feedid --example zoo_tune
//! cargo run --release -p feedid --example zoo_tune -- --limit 40
//! ```
//!
//! Error: rms and largest |true position − command| over the move;
//! overshoot: the largest true position beyond the move's end after the
//! command stops, as a share of its travel; stable: the run stays within the
//! move's travel of the command.

use feedid::drive::{DriveStructure, FeedForward, TuneTarget};
use feedid::signal::Scenario;
use feedid::stats::ErrorStats;
use feedid::zoo::{PlantKind, Zoo};
use rayon::prelude::*;

struct Row {
    index: usize,
    label: String,
    bandwidth: (f64, f64),
    rms: (f64, f64),
    max: (f64, f64),
    overshoot: f64,
    stable: bool,
}

/// Rms, largest error and overshoot [%] of a run of `program` (true
/// positions `truth`).
fn figures(program: &[f64], truth: &[f64]) -> (f64, f64, f64) {
    let n = program.len().min(truth.len());
    let error = ErrorStats::from_pairs(program.iter().copied().zip(truth.iter().copied()));
    let (first, last) = (program[0], program[n - 1]);
    let travel = (last - first).abs();
    let dir = (last - first).signum();
    let stop = program[..n]
        .iter()
        .rposition(|c| *c != last)
        .map_or(0, |k| k + 1);
    let beyond = truth[stop..n]
        .iter()
        .fold(0.0_f64, |m, y| m.max(dir * (y - last)));
    let overshoot = if travel > 0.0 {
        100.0 * beyond / travel
    } else {
        0.0
    };
    (error.rms, error.max_abs, overshoot)
}

fn run(zoo: &Zoo, index: usize) -> Option<Result<Row, String>> {
    let spec = zoo.spec(index).ok()?;
    if !matches!(spec.plant, PlantKind::Rig(_)) || spec.has_gaps() {
        return None;
    }
    let rig = spec.rig.as_ref()?;
    Some((|| {
        // the feedback loops are retuned: their bandwidth without the
        // feed-forward (which the rig keeps)
        let mut s = DriveStructure::paper(&rig.params).map_err(|e| e.to_string())?;
        s.feed_forward = FeedForward::default();
        let now = s
            .closed_loop()
            .map_err(|e| e.to_string())?
            .bandwidth_hz
            .ok_or("no bandwidth")?;
        let t = s
            .tune(&TuneTarget {
                bandwidth_hz: 1.5 * now,
                damping: std::f64::consts::FRAC_1_SQRT_2,
            })
            .map_err(|e| format!("#{index} {}: {e}", spec.label))?;
        let mut tuned = spec.clone();
        if let Some(r) = tuned.rig.as_mut() {
            r.params.control.kv = t.structure.position.kp;
            r.params.control.kp = t.structure.velocity.kp;
            r.params.control.ki = t.structure.velocity.ki;
        }
        let program = Scenario::Scurve
            .command(spec.rate_hz, Scenario::Scurve.default_duration(), 0)
            .map_err(|e| e.to_string())?;
        let before = spec
            .run_plant(&program, spec.noise_seed)
            .map_err(|e| e.to_string())?;
        let (stable_run, after) = match tuned.run_plant(&program, spec.noise_seed) {
            Ok(r) => (true, r),
            Err(e) => {
                return Err(format!(
                    "#{index} {}: the tuned rig failed: {e}",
                    spec.label
                ))
            }
        };
        let (rb, mb, _) = figures(&program, &before.truth);
        let (ra, ma, oa) = figures(&program, &after.truth);
        let travel = program.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        Ok(Row {
            index,
            label: spec.label.clone(),
            bandwidth: (now, t.after.bandwidth_hz.unwrap_or(f64::NAN)),
            rms: (rb, ra),
            max: (mb, ma),
            overshoot: oa,
            stable: stable_run && t.after.stable && ma.is_finite() && ma < travel,
        })
    })())
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut limit = 20usize;
    let mut i = 0;
    while i < args.len() {
        match args[i].as_str() {
            "--limit" => {
                limit = args
                    .get(i + 1)
                    .and_then(|v| v.parse().ok())
                    .unwrap_or(limit);
                i += 2;
            }
            other => {
                eprintln!("unknown argument {other}; use --limit N (rig axes)");
                std::process::exit(2);
            }
        }
    }
    let zoo = Zoo::standard();
    let indices: Vec<usize> = zoo.regular().collect();
    let mut rows: Vec<Result<Row, String>> =
        indices.par_iter().filter_map(|&i| run(&zoo, i)).collect();
    rows.truncate(limit);
    println!(
        "| axis | bandwidth own → tuned | rms error own → tuned | max | overshoot tuned | stable |"
    );
    println!("|---|---:|---:|---:|---:|---|");
    let (mut n, mut lower, mut within, mut stable) = (0, 0, 0, 0);
    for r in &rows {
        match r {
            Ok(t) => {
                n += 1;
                lower += usize::from(t.rms.1 < t.rms.0);
                within += usize::from(t.overshoot <= 5.0);
                stable += usize::from(t.stable);
                println!(
                    "| #{} {} | {:.1} → {:.1} Hz | {:.2} → {:.2} µm ({:.2}×) | {:.2} → {:.2} µm | {:.2} % | {} |",
                    t.index,
                    t.label,
                    t.bandwidth.0,
                    t.bandwidth.1,
                    1e6 * t.rms.0,
                    1e6 * t.rms.1,
                    t.rms.0 / t.rms.1,
                    1e6 * t.max.0,
                    1e6 * t.max.1,
                    t.overshoot,
                    if t.stable { "yes" } else { "NO" }
                );
            }
            Err(e) => println!("| {e} | | | | | |"),
        }
    }
    println!(
        "\n{n} rig axes tuned ({} refused): the rms following error lower on {lower}, overshoot ≤ 5 % on {within}, stable on {stable}",
        rows.len() - n
    );
}
