//! Compensation on the drive zoo (issue 18): for every regular zoo member
//! whose command is a ramp, an S-curve, a point-to-point program or a
//! contour axis, identify a global model from a **chirp** run on the same
//! axis, compensate the member's command with it (library defaults: smoothing
//! only where the limits need it, "never worse" fall-back with the model's
//! fits measured on the chirp run) and run both commands on the axis.
//!
//! ```sh
//! cargo run --release -p feedid --example zoo_compensate
//! cargo run --release -p feedid --example zoo_compensate -- --limit 20 --csv comp.csv
//! ```
//!
//! Per member:
//!
//! * the identification run: a logarithmic sine sweep from `f_max/100` to
//!   `f_max = min(rate/8, max(6·Kv/2π, 5 Hz))`, amplitude
//!   `0.8·min(A, 10 mm, v/(2π·f_max), a/(2π·f_max)²)` (`A`, `v`, `a`: the
//!   member's amplitude, command speed and acceleration — for a ramp
//!   `a = v·Kv`), as long as the member's recording, noise seed + 1;
//! * the model: `fit_global_model(.., Auto)` (the best of arx 8,8,1, oe 7,2
//!   and oe 5,1 by free-run error) and its free-run position fit on the
//!   chirp run; the share of the following error it explains
//!   ([`ModelQuality::from_run`]) on the member's own recording — the plain
//!   program run once, with its noise and glitches, as `compensate --check`
//!   uses it;
//! * limits: velocity `max(2·v, 1.5·v_plain)`, acceleration
//!   `max(1.5·a, 1.5·a_plain)` (`v_plain`, `a_plain`: the plain command's own
//!   finite-difference peaks — limits the axis already accepts; a ramp's
//!   velocity step asks `v/Δt`); `--max-smoothing S` (default the library's
//!   0.02 s);
//! * tracking error: rms of the **true** (noise-free) position minus the
//!   desired over the whole recording, plain command vs the command the tool
//!   sends (compensated or, on a fall-back, the plain one), same noise seed.
//!
//! The summary is printed as a Markdown table; `--csv FILE` writes one row
//! per member.

use std::path::PathBuf;

use feedid::compensate::{compensate_model, CompensateConfig, ModelQuality};
use feedid::ident::{fit_global_model, GlobalModelKind};
use feedid::signal::{Chirp, Sweep};
use feedid::zoo::{CommandSpec, MemberSpec, Zoo};
use feedid::Recording;
use rayon::prelude::*;

/// One member's outcome.
struct Row {
    index: usize,
    label: String,
    kind: &'static str,
    feed_forward: &'static str,
    model: String,
    fit: f64,
    error_fit: f64,
    plain_rms: f64,
    sent_rms: f64,
    predicted_benefit: f64,
    sent: String,
}

fn rms_against(truth: &[f64], desired: &[f64]) -> f64 {
    let s: f64 = truth
        .iter()
        .zip(desired)
        .map(|(a, b)| (a - b) * (a - b))
        .sum();
    (s / desired.len() as f64).sqrt()
}

/// Speed and acceleration the member's command asks of the axis.
fn references(spec: &MemberSpec, desired: &[f64], dt: f64) -> (f64, f64) {
    let v = desired
        .windows(2)
        .map(|w| ((w[1] - w[0]) / dt).abs())
        .fold(0.0, f64::max);
    let a = match &spec.command {
        CommandSpec::Scurve(s) => s.max_acceleration,
        CommandSpec::PointToPoint { program, .. } => program.max_acceleration,
        CommandSpec::Contour(c) => c.max_acceleration.min(c.feed * c.feed / c.radius.abs()),
        _ => v * spec.kv,
    };
    (v, a)
}

/// Peak finite-difference velocity and acceleration of a command.
fn command_peaks(u: &[f64], dt: f64) -> (f64, f64) {
    let v = u
        .windows(2)
        .map(|w| ((w[1] - w[0]) / dt).abs())
        .fold(0.0, f64::max);
    let a = u
        .windows(3)
        .map(|w| ((w[2] - 2.0 * w[1] + w[0]) / (dt * dt)).abs())
        .fold(0.0, f64::max);
    (v, a)
}

fn run(zoo: &Zoo, index: usize, max_smoothing: f64) -> Result<Row, String> {
    let member = zoo.member(index).map_err(|e| e.to_string())?;
    let spec = &member.spec;
    let desired = &member.command;
    let n = desired.len();
    let rate = spec.rate_hz;
    let dt = 1.0 / rate;
    let (v, a) = references(spec, desired, dt);
    let two_pi = 2.0 * std::f64::consts::PI;
    let mut f_max = (rate / 8.0).min((6.0 * spec.kv / two_pi).max(5.0));
    let amp = |f: f64| {
        0.8 * spec
            .amplitude_m
            .min(1e-2)
            .min(v / (two_pi * f))
            .min(a / (two_pi * f).powi(2))
    };
    while amp(f_max) < 50.0 * spec.resolution_m && f_max > 2.0 {
        f_max /= 1.5;
    }
    let chirp = Chirp {
        amplitude: amp(f_max),
        f_start: f_max / 100.0,
        f_end: f_max,
        sweep: Sweep::Logarithmic,
        taper: 0.05_f64.min(0.1 * n as f64 * dt),
        rest: 10.0 * dt,
    };
    let excitation = chirp
        .generate(rate, n as f64 * dt)
        .map_err(|e| e.to_string())?;
    let ident = spec
        .run_plant(&excitation, spec.noise_seed.wrapping_add(1))
        .map_err(|e| e.to_string())?;
    let rec = Recording::from_rate(rate, ident.command.clone(), ident.position.clone())
        .map_err(|e| e.to_string())?;
    let file = fit_global_model(&rec, &GlobalModelKind::Auto).map_err(|e| e.to_string())?;
    // the identification fit (what `identify` reports), and the share of the
    // following error the model explains on the member's own recording (the
    // plain program run once, as `compensate --check` would use it)
    let on_chirp = ModelQuality::from_run(&file.model, rec.command(), rec.position(), dt)
        .map_err(|e| e.to_string())?;
    // the glitches (wild samples) of the recording are known: hold the
    // previous sample there
    let mut measured = member.position.clone();
    for g in &spec.glitches {
        if g.index > 0 && g.index < measured.len() {
            measured[g.index] = measured[g.index - 1];
        }
    }
    let on_plain =
        ModelQuality::from_run(&file.model, desired, &measured, dt).map_err(|e| e.to_string())?;
    let quality = ModelQuality {
        position_fit_percent: on_chirp.position_fit_percent,
        error_fit_percent: on_plain.error_fit_percent,
    };
    // limits the axis already accepts: the plain command's own peaks (a
    // ramp's velocity step is v/Δt) and some headroom
    let (pv, pa) = command_peaks(desired, dt);
    let cfg = CompensateConfig {
        max_velocity: (2.0 * v).max(1.5 * pv),
        max_acceleration: (1.5 * a).max(1.5 * pa),
        max_smoothing,
        quality,
        ..CompensateConfig::default()
    };
    let (command, sent, predicted_benefit) = match compensate_model(&file.model, desired, dt, &cfg)
    {
        Ok(c) => {
            let sent = match &c.fallback {
                None => "compensated".to_string(),
                Some(f) => format!("plain: {f}"),
            };
            (c.command, sent, c.benefit.expected_benefit)
        }
        Err(e) => (desired.clone(), format!("refused: {e}"), f64::NAN),
    };
    let plain = spec
        .run_plant(desired, spec.noise_seed)
        .map_err(|e| e.to_string())?;
    let comp = spec
        .run_plant(&command, spec.noise_seed)
        .map_err(|e| e.to_string())?;
    let prov = file.identified_by.as_ref();
    Ok(Row {
        index,
        label: spec.label.clone(),
        kind: spec.command.name(),
        feed_forward: spec.feed_forward(),
        model: prov.map_or("?".into(), |p| format!("{} {}", p.method, p.orders)),
        fit: quality.position_fit_percent.unwrap_or(f64::NAN),
        error_fit: quality.error_fit_percent.unwrap_or(f64::NAN),
        plain_rms: rms_against(&plain.truth, desired),
        sent_rms: rms_against(&comp.truth, desired),
        predicted_benefit,
        sent,
    })
}

fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let m = v.len() / 2;
    if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    }
}

fn summary(name: &str, rows: &[&Row]) {
    if rows.is_empty() {
        println!("| {name} | 0 | – | – | – | – | – | – | – |");
        return;
    }
    let mut ratio: Vec<f64> = rows.iter().map(|r| r.plain_rms / r.sent_rms).collect();
    let mut plain: Vec<f64> = rows.iter().map(|r| r.plain_rms).collect();
    let mut sent: Vec<f64> = rows.iter().map(|r| r.sent_rms).collect();
    let comp = rows.iter().filter(|r| r.sent == "compensated").count();
    let worse = rows
        .iter()
        .filter(|r| r.sent_rms > r.plain_rms * (1.0 + 1e-6))
        .count();
    let min = ratio.iter().copied().fold(f64::INFINITY, f64::min);
    println!(
        "| {name} | {} | {} | {:.3} µm | {:.3} µm | {:.1}× | {:.2}× | {} | {} |",
        rows.len(),
        comp,
        1e6 * median(&mut plain),
        1e6 * median(&mut sent),
        median(&mut ratio),
        min,
        worse,
        rows.len() - comp
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut limit = usize::MAX;
    let mut max_smoothing = CompensateConfig::default().max_smoothing;
    let mut csv: Option<PathBuf> = None;
    let mut i = 0;
    while i < args.len() {
        match args[i].as_str() {
            "--limit" => {
                limit = args
                    .get(i + 1)
                    .and_then(|s| s.parse().ok())
                    .unwrap_or(limit);
                i += 1;
            }
            "--max-smoothing" => {
                max_smoothing = args
                    .get(i + 1)
                    .and_then(|s| s.parse().ok())
                    .unwrap_or(max_smoothing);
                i += 1;
            }
            "--csv" => {
                csv = args.get(i + 1).map(PathBuf::from);
                i += 1;
            }
            other => {
                eprintln!("unknown argument {other}; use --limit N, --csv FILE");
                std::process::exit(2);
            }
        }
        i += 1;
    }
    let zoo = Zoo::standard();
    let indices: Vec<usize> = zoo
        .regular()
        .filter(|&i| {
            zoo.spec(i).is_ok_and(|s| {
                matches!(
                    s.command,
                    CommandSpec::Ramp(_)
                        | CommandSpec::Scurve(_)
                        | CommandSpec::PointToPoint { .. }
                        | CommandSpec::Contour(_)
                )
            })
        })
        .take(limit)
        .collect();
    let start = std::time::Instant::now();
    let results: Vec<(usize, Result<Row, String>)> = indices
        .par_iter()
        .map(|&i| (i, run(&zoo, i, max_smoothing)))
        .collect();
    let mut rows = Vec::new();
    for (i, r) in results {
        match r {
            Ok(row) => rows.push(row),
            Err(e) => println!("member {i}: failed: {e}"),
        }
    }
    println!(
        "{} members ({} failed) in {:.0} s\n",
        rows.len(),
        indices.len() - rows.len(),
        start.elapsed().as_secs_f64()
    );
    println!("| axes | n | compensated | median rms plain | median rms sent | median reduction | smallest reduction | worse than plain | fall-backs |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    let all: Vec<&Row> = rows.iter().collect();
    let good_noff: Vec<&Row> = rows
        .iter()
        .filter(|r| r.fit >= 95.0 && r.feed_forward == "none")
        .collect();
    let good_ff: Vec<&Row> = rows
        .iter()
        .filter(|r| r.fit >= 95.0 && r.feed_forward != "none")
        .collect();
    let poor: Vec<&Row> = rows
        .iter()
        .filter(|r| r.fit.is_nan() || r.fit < 95.0)
        .collect();
    summary("fit ≥ 95 %, no feed-forward", &good_noff);
    summary("fit ≥ 95 %, feed-forward", &good_ff);
    summary("fit < 95 %", &poor);
    for kind in ["ramp", "scurve", "p2p", "contour"] {
        let k: Vec<&Row> = rows.iter().filter(|r| r.kind == kind).collect();
        summary(&format!("all, {kind}"), &k);
    }
    summary("all", &all);
    println!("\nworse than plain (rms sent > plain):");
    for r in rows
        .iter()
        .filter(|r| r.sent_rms > r.plain_rms * (1.0 + 1e-6))
    {
        println!(
            "  #{} {}: model {} fit {:.1} % (error fit {:.1} %), plain {:.3} µm, sent {:.3} µm, predicted benefit {:.2}; {}",
            r.index,
            r.label,
            r.model,
            r.fit,
            r.error_fit,
            1e6 * r.plain_rms,
            1e6 * r.sent_rms,
            r.predicted_benefit,
            r.sent
        );
    }
    if let Some(path) = csv {
        let mut text = String::from(
            "index,kind,feed_forward,model,fit_percent,error_fit_percent,plain_rms_m,sent_rms_m,reduction,predicted_benefit,sent,label\n",
        );
        for r in &rows {
            text.push_str(&format!(
                "{},{},{},\"{}\",{:.3},{:.3},{:e},{:e},{:.4},{:.4},\"{}\",\"{}\"\n",
                r.index,
                r.kind,
                r.feed_forward,
                r.model,
                r.fit,
                r.error_fit,
                r.plain_rms,
                r.sent_rms,
                r.plain_rms / r.sent_rms,
                r.predicted_benefit,
                r.sent.replace('"', "'"),
                r.label.replace('"', "'")
            ));
        }
        if let Err(e) = std::fs::write(&path, text) {
            eprintln!("{}: {e}", path.display());
            std::process::exit(1);
        }
    }
}
