//! Online compensation in closed loop on the drive zoo: every regular zoo
//! member whose command is a ramp, an S-curve, a point-to-point program or
//! a contour axis is stepped sample by sample ([`feedid::zoo::PlantStepper`])
//! with the [`feedid::compensate::OnlineCompensator`] in the loop (library
//! defaults, the command known `preview` samples ahead), against the same
//! axis with the same noise driven by the plain command.
//!
//! ```sh
//! cargo run --release -p feedid --example zoo_online
//! cargo run --release -p feedid --example zoo_online -- --limit 20 --terms 3 --csv online.csv
//! ```
//!
//! Limits: velocity `max(2·v, 1.5·v_plain)`, acceleration `1.5·a_plain`
//! (the plain command's own finite-difference peaks), as `zoo_compensate`
//! sets them. The program runs `--passes K` times back to back (default 2;
//! the compensator starts from nothing and keeps its model from pass to
//! pass; with `--prior` it starts from the following-error model of a model
//! identified on a chirp run of the same axis,
//! [`feedid::zoo::MemberSpec::identification_chirp`] and
//! `fit_global_model(auto)`, as `zoo_compensate` identifies it). Tracking error: rms of the **true** position minus the desired
//! over the last pass (the first pass's reduction beside it). A run is **unstable** when its
//! compensated error exceeds 10× the plain one or the axis diverges.

use feedid::compensate::{co_simulate, following_error_of, OnlineConfig};
use feedid::ident::{fit_global_model, GlobalModelKind};
use feedid::zoo::{CommandSpec, Zoo};
use feedid::Recording;
use rayon::prelude::*;

/// Smallest following-error fit on the chirp [%] for its model to be the prior.
const PRIOR_MIN_ERROR_FIT: f64 = 90.0;

struct Row {
    index: usize,
    kind: &'static str,
    label: String,
    plain_rms: f64,
    rms: f64,
    reduction: f64,
    first_reduction: f64,
    compensated_share: f64,
    limited_share: f64,
}

fn kind(c: &CommandSpec) -> &'static str {
    match c {
        CommandSpec::Ramp(_) => "ramp",
        CommandSpec::Scurve(_) => "scurve",
        CommandSpec::PointToPoint { .. } => "p2p",
        CommandSpec::Contour(_) => "contour",
        _ => "other",
    }
}

fn run(
    zoo: &Zoo,
    index: usize,
    base: &OnlineConfig,
    passes: usize,
    with_prior: bool,
) -> Result<Row, String> {
    let member = zoo.member(index).map_err(|e| e.to_string())?;
    let spec = &member.spec;
    let desired = &member.command;
    let dt = 1.0 / spec.rate_hz;
    let peak = |f: &dyn Fn(&[f64]) -> f64, w: usize| {
        desired
            .windows(w)
            .map(|x| f(x).abs())
            .fold(0.0_f64, f64::max)
    };
    let v = peak(&|w: &[f64]| (w[1] - w[0]) / dt, 2);
    let a = peak(&|w: &[f64]| (w[2] - 2.0 * w[1] + w[0]) / (dt * dt), 3);
    let cfg = OnlineConfig {
        max_velocity: 2.0 * v,
        max_acceleration: 1.5 * a,
        ..*base
    };
    let seed = spec.noise_seed;
    let prior = if with_prior {
        // a model identified on a chirp run of the same axis (another noise seed)
        let chirp = spec
            .identification_chirp(desired)
            .map_err(|e| e.to_string())?;
        let run = spec
            .run_plant(&chirp, seed.wrapping_add(1))
            .map_err(|e| e.to_string())?;
        let rec = Recording::from_rate(spec.rate_hz, run.command, run.position)
            .map_err(|e| e.to_string())?;
        let file = fit_global_model(&rec, &GlobalModelKind::Auto).map_err(|e| e.to_string())?;
        // only a model that explains the chirp's following error well
        let explains = file
            .identified_by
            .as_ref()
            .and_then(|p| p.error_fit_percent)
            .is_some_and(|f| f >= PRIOR_MIN_ERROR_FIT);
        explains
            .then(|| following_error_of(&file.model, dt).ok())
            .flatten()
    } else {
        None
    };
    let sim = co_simulate(
        |first| spec.stepper(first, seed),
        desired,
        dt,
        &cfg,
        passes,
        prior,
    )
    .map_err(|e| e.to_string())?;
    let n = sim.desired.len() as f64;
    let first = sim.passes[0];
    Ok(Row {
        index,
        kind: kind(&spec.command),
        label: spec.label.clone(),
        plain_rms: sim.last.plain_error.rms,
        rms: sim.last.error.rms,
        reduction: sim.last.reduction,
        first_reduction: first.reduction,
        compensated_share: sim.stats.compensated as f64 / n,
        limited_share: sim.stats.limited as f64 / n,
    })
}

fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(|a, b| a.total_cmp(b));
    let m = v.len() / 2;
    if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut limit = usize::MAX;
    let mut base = OnlineConfig::default();
    let mut passes = 2;
    let mut with_prior = false;
    let mut csv: Option<String> = None;
    let mut i = 0;
    while i < args.len() {
        let value = args.get(i + 1).cloned().unwrap_or_default();
        match args[i].as_str() {
            "--limit" => limit = value.parse().unwrap_or(limit),
            "--preview" => base.preview = value.parse().unwrap_or(base.preview),
            "--terms" => base.terms = value.parse().unwrap_or(base.terms),
            "--lambda" => base.lambda = value.parse().unwrap_or(base.lambda),
            "--share" => {
                base.max_unexplained_share = value.parse().unwrap_or(base.max_unexplained_share)
            }
            "--min-updates" => base.min_updates = value.parse().unwrap_or(base.min_updates),
            "--blend" => base.blend_samples = value.parse().unwrap_or(base.blend_samples),
            "--passes" => passes = value.parse().unwrap_or(passes).max(1),
            "--prior" => {
                with_prior = true;
                i += 1;
                continue;
            }
            "--csv" => csv = Some(value),
            other => {
                eprintln!(
                    "unknown argument {other}; use --limit N, --preview P, --terms T, --lambda L, --share S, --min-updates N, --blend N, --prior, --passes K, --csv FILE"
                );
                std::process::exit(2);
            }
        }
        i += 2;
    }
    let zoo = Zoo::standard();
    let indices: Vec<usize> = zoo
        .regular()
        .filter(|&i| zoo.spec(i).is_ok_and(|s| kind(&s.command) != "other"))
        .take(limit)
        .collect();
    let start = std::time::Instant::now();
    let results: Vec<(usize, Result<Row, String>)> = indices
        .par_iter()
        .map(|&i| (i, run(&zoo, i, &base, passes, with_prior)))
        .collect();
    let mut rows = Vec::new();
    let mut failed = 0;
    for (i, r) in results {
        match r {
            Ok(row) => rows.push(row),
            Err(e) => {
                failed += 1;
                println!("member {i}: unstable or failed: {e}");
            }
        }
    }
    println!(
        "{} members co-simulated ({} failed) in {:.0} s, preview {} samples, {} pass(es){}; figures of the last pass\n",
        rows.len(),
        failed,
        start.elapsed().as_secs_f64(),
        base.preview,
        passes,
        if with_prior {
            ", starting from a model identified on a chirp run"
        } else {
            ""
        }
    );
    println!("| axes | n | median rms plain | median rms online | median reduction | first pass | smallest | worse than plain | unstable (> 10× plain) |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    for k in ["ramp", "scurve", "p2p", "contour", "all"] {
        let sel: Vec<&Row> = rows.iter().filter(|r| k == "all" || r.kind == k).collect();
        if sel.is_empty() {
            continue;
        }
        let smallest = sel
            .iter()
            .map(|r| r.reduction)
            .fold(f64::INFINITY, f64::min);
        println!(
            "| {k} | {} | {:.3} µm | {:.3} µm | {:.1}× | {:.1}× | {:.2}× | {} | {} |",
            sel.len(),
            1e6 * median(sel.iter().map(|r| r.plain_rms).collect()),
            1e6 * median(sel.iter().map(|r| r.rms).collect()),
            median(sel.iter().map(|r| r.reduction).collect()),
            median(sel.iter().map(|r| r.first_reduction).collect()),
            smallest,
            sel.iter()
                .filter(|r| r.rms > r.plain_rms * (1.0 + 1e-9))
                .count(),
            sel.iter().filter(|r| r.rms > 10.0 * r.plain_rms).count(),
        );
    }
    println!("\nworse than plain:");
    for r in rows.iter().filter(|r| r.rms > r.plain_rms * (1.0 + 1e-9)) {
        println!(
            "  #{} {}: plain {:.3} µm, online {:.3} µm (compensated {:.0} % of the samples, limited {:.1} %)",
            r.index,
            r.label,
            1e6 * r.plain_rms,
            1e6 * r.rms,
            100.0 * r.compensated_share,
            100.0 * r.limited_share
        );
    }
    if let Some(path) = csv {
        let mut out = String::from(
            "index,kind,plain_rms_m,online_rms_m,reduction,compensated_share,limited_share,label\n",
        );
        for r in &rows {
            out.push_str(&format!(
                "{},{},{:e},{:e},{:.4},{:.4},{:.4},\"{}\"\n",
                r.index,
                r.kind,
                r.plain_rms,
                r.rms,
                r.reduction,
                r.compensated_share,
                r.limited_share,
                r.label
            ));
        }
        if let Err(e) = std::fs::write(&path, out) {
            eprintln!("{path}: {e}");
            std::process::exit(2);
        }
    }
}
