//! Physical parameters on a generated family of drive structures whose
//! truth is known ([`feedid::zoo::StructureAxis`]: P/P, P/PI with
//! feed-forward, PID commanding force, two-mass; 100 Hz–20 kHz; viscous,
//! Coulomb, Stribeck friction and constant forces): every estimate the
//! restarts call identifiable is checked against the truth it came from.
//!
//! ```sh
//! cargo run --release -p feedid --example structure_zoo
//! cargo run --release -p feedid --example structure_zoo -- --axes 40 --csv structures.csv
//! cargo run --release -p feedid --example structure_zoo -- --tune --axes 40
//! ```
//!
//! With `--tune`, `DriveStructure::tune` on every rigid axis instead: the
//! bandwidth 1.5× the axis's own (at most a fifteenth of the rate, a
//! thirtieth with a sampled controller; an axis already within 10 % of that
//! is not retuned), damping 1/√2, and an S-curve move run through the
//! nonlinear simulation with both gain sets.
//!
//! The fit (`DriveStructure::fit_with_restarts`, two restarts ±22 %) starts
//! from the truth moved 30 % (`StructureAxis::start`; 15 % or 5 % where the
//! loop cannot run from there) on the measured position (the true one plus
//! its noise). An estimate is **within** when it is within 5 % of the truth
//! (a constant force: within 5 % of the Coulomb level). An estimate is not
//! identifiable because three standard errors exceed 5 % of it
//! (**imprecise**; the constant force against the drive gain when smaller)
//! or because equally good restarts disagree.

use feedid::drive::{StructureParam as P, StructureVerdict, TuneTarget};
use feedid::signal::Scenario;
use feedid::zoo::StructureAxis;
use rayon::prelude::*;

/// Largest relative error of an estimate called within.
const WITHIN: f64 = 0.05;

/// One estimate against its truth.
struct Checked {
    param: P,
    truth: f64,
    value: f64,
    /// `value − truth` relative to the truth (the constant force: to the
    /// Coulomb level).
    signed: f64,
    /// Its size.
    error: f64,
    verdict: StructureVerdict,
    spread: f64,
    /// Standard error relative to the estimate.
    rel_std: f64,
    /// The truth lies within three standard errors of the estimate.
    within_3_sigma: bool,
}

impl Checked {
    fn identifiable(&self) -> bool {
        self.verdict == StructureVerdict::Identifiable
    }
}

struct Outcome {
    index: usize,
    label: String,
    fit_percent: f64,
    /// Fits that ended in a local minimum (not compared).
    elsewhere: usize,
    checked: Vec<Checked>,
}

fn run(i: usize) -> Result<Outcome, String> {
    let a = StructureAxis::new(i).map_err(|e| format!("#{i}: {e}"))?;
    let measured = a.measured();
    let mut fitted = Err(String::new());
    for share in [0.3, 0.15, 0.05] {
        fitted = a
            .start(share)
            .fit_with_restarts(&a.command, &measured, a.rate_hz, &a.estimate, 2)
            .map_err(|e| format!("#{i} {}: {e}", a.label));
        if fitted.is_ok() {
            break;
        }
    }
    let fit = fitted?;
    let checked = fit
        .estimates
        .iter()
        .map(|e| {
            let truth = e.param.get(&a.truth);
            let scale = match e.param {
                P::Offset => a.truth.friction.coulomb,
                _ => truth.abs(),
            };
            Checked {
                param: e.param,
                truth,
                value: e.value,
                signed: (e.value - truth) / scale,
                error: (e.value - truth).abs() / scale,
                verdict: e.verdict,
                spread: e.restart_spread.unwrap_or(f64::NAN),
                rel_std: e.std_error / e.value.abs(),
                within_3_sigma: (e.value - truth).abs() <= 3.0 * e.std_error,
            }
        })
        .collect();
    Ok(Outcome {
        index: i,
        label: a.label,
        fit_percent: fit.fit_percent,
        elsewhere: fit.restarts_elsewhere,
        checked,
    })
}

/// The gains retuned on one rigid axis, and the standard program through
/// both gain sets.
struct Retuned {
    index: usize,
    label: String,
    bandwidth: (f64, f64),
    rms: (f64, f64),
    max: (f64, f64),
    overshoot: (f64, f64),
    stable: bool,
}

/// `tune` on axis `i` (rigid axes only; `None` for the others): the
/// bandwidth 1.5× its own, at most a fifteenth of the rate (a thirtieth
/// with a sampled controller; an axis whose own is within 10 % of that is
/// not retuned), damping 1/√2; the standard program an S-curve move
/// (`Scenario::Scurve`, 20 mm) through the nonlinear simulation.
fn retune(i: usize) -> Option<Result<Retuned, String>> {
    let a = match StructureAxis::new(i) {
        Ok(a) => a,
        Err(e) => return Some(Err(format!("#{i}: {e}"))),
    };
    if a.truth.mechanics.two_mass() {
        return None;
    }
    Some((|| {
        let s = &a.truth;
        let now = s
            .closed_loop()
            .map_err(|e| e.to_string())?
            .bandwidth_hz
            .ok_or("no bandwidth")?;
        let cap = a.rate_hz
            / if s.controller.sample_time.is_some() {
                30.0
            } else {
                15.0
            };
        let target = (1.5 * now).min(cap);
        if target < 1.1 * now {
            return Err(format!(
                "#{i} {}: its bandwidth {now:.1} Hz is at the rate's limit ({cap:.1} Hz), not retuned",
                a.label
            ));
        }
        let t = s
            .tune(&TuneTarget {
                bandwidth_hz: target,
                damping: std::f64::consts::FRAC_1_SQRT_2,
            })
            .map_err(|e| format!("#{i} {}: {e}", a.label))?;
        let program = Scenario::Scurve
            .command(a.rate_hz, Scenario::Scurve.default_duration(), 0)
            .map_err(|e| e.to_string())?;
        let before = s
            .run_figures(&program, a.rate_hz)
            .map_err(|e| e.to_string())?;
        let after = t
            .structure
            .run_figures(&program, a.rate_hz)
            .map_err(|e| e.to_string())?;
        let travel = program.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        Ok(Retuned {
            index: i,
            label: a.label.clone(),
            bandwidth: (now, t.after.bandwidth_hz.unwrap_or(f64::NAN)),
            rms: (before.rms_error, after.rms_error),
            max: (before.max_error, after.max_error),
            overshoot: (before.overshoot_percent, after.overshoot_percent),
            stable: t.after.stable && after.max_error.is_finite() && after.max_error < travel,
        })
    })())
}

fn tune_table(axes: usize, only: Option<usize>) {
    let rows: Vec<Result<Retuned, String>> = (0..axes)
        .into_par_iter()
        .filter(|i| only.is_none_or(|o| o == *i))
        .filter_map(retune)
        .collect();
    println!("\n`tune` on the rigid axes (bandwidth 1.5× its own, at most rate/15, rate/30 sampled; ζ 0.707), an S-curve through the nonlinear simulation:\n");
    println!("| axis | bandwidth now → tuned | rms following error now → tuned | max | overshoot tuned | stable |");
    println!("|---|---:|---:|---:|---:|---|");
    let mut n = 0;
    let mut lower = 0;
    let mut within = 0;
    let mut stable = 0;
    for r in &rows {
        match r {
            Ok(t) => {
                n += 1;
                lower += usize::from(t.rms.1 < t.rms.0);
                within += usize::from(t.overshoot.1 <= 5.0);
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
                    t.overshoot.1,
                    if t.stable { "yes" } else { "NO" }
                );
            }
            Err(e) => println!("| {e} | | | | | |"),
        }
    }
    println!(
        "\n{n} rigid axes tuned: the rms following error lower on {lower}, overshoot ≤ 5 % on {within}, stable on {stable}"
    );
}

fn main() {
    let mut only: Option<usize> = None;
    let mut tune = false;
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut axes = 24usize;
    let mut csv: Option<String> = None;
    let mut i = 0;
    while i < args.len() {
        let value = args.get(i + 1).cloned().unwrap_or_default();
        match args[i].as_str() {
            "--axes" => axes = value.parse().unwrap_or(axes),
            "--csv" => csv = Some(value),
            "--only" => only = value.parse().ok(),
            "--tune" => {
                tune = true;
                i += 1;
                continue;
            }
            other => {
                eprintln!("unknown argument {other}; use --axes N, --only I, --tune, --csv FILE");
                std::process::exit(2);
            }
        }
        i += 2;
    }
    if tune {
        tune_table(axes, only);
        return;
    }
    let start = std::time::Instant::now();
    let results: Vec<Result<Outcome, String>> = (0..axes)
        .into_par_iter()
        .filter(|i| only.is_none_or(|o| o == *i))
        .map(run)
        .collect();
    let mut rows = Vec::new();
    let mut failed = 0;
    for r in results {
        match r {
            Ok(o) => rows.push(o),
            Err(e) => {
                failed += 1;
                println!("failed: {e}");
            }
        }
    }
    println!(
        "{} axes fitted ({} failed) in {:.0} s\n",
        rows.len(),
        failed,
        start.elapsed().as_secs_f64()
    );
    for o in &rows {
        let items: Vec<String> = o
            .checked
            .iter()
            .map(|c| {
                format!(
                    "{} {:+.2} % (σ {:.2} %, spread {:.1e}){}",
                    c.param.name(),
                    100.0 * c.signed,
                    100.0 * c.rel_std,
                    c.spread,
                    match c.verdict {
                        StructureVerdict::Identifiable => "",
                        StructureVerdict::Imprecise => " (imprecise)",
                        StructureVerdict::NotIdentifiable => " (NOT IDENTIFIABLE)",
                    }
                )
            })
            .collect();
        println!(
            "  #{} {}: fit {:.3} %; {}",
            o.index,
            o.label,
            o.fit_percent,
            items.join(", ")
        );
    }
    println!("\n| parameter | estimated | identifiable | within 5 % of the truth | largest error (identifiable) | imprecise: truth within 3σ | not identifiable: restarts apart | not identifiable: error |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|");
    let names = [
        P::Mass,
        P::Viscous,
        P::Coulomb,
        P::Offset,
        P::Static,
        P::MotorMass,
        P::Stiffness,
    ];
    let mut total = (0, 0, 0);
    for p in names.into_iter().map(Some).chain([None]) {
        let all: Vec<&Checked> = rows
            .iter()
            .flat_map(|o| o.checked.iter())
            .filter(|c| p.is_none_or(|p| c.param == p))
            .collect();
        if all.is_empty() {
            continue;
        }
        let ident: Vec<&&Checked> = all.iter().filter(|c| c.identifiable()).collect();
        let within = ident.iter().filter(|c| c.error <= WITHIN).count();
        let worst = ident.iter().map(|c| c.error).fold(0.0_f64, f64::max);
        let imprecise: Vec<&&Checked> = all
            .iter()
            .filter(|c| c.verdict == StructureVerdict::Imprecise)
            .collect();
        let not: Vec<&&Checked> = all
            .iter()
            .filter(|c| c.verdict == StructureVerdict::NotIdentifiable)
            .collect();
        let apart: Vec<String> = not
            .iter()
            .map(|c| format!("{:.0} %", 100.0 * c.spread))
            .collect();
        let errors: Vec<String> = not
            .iter()
            .map(|c| format!("{:.0} %", 100.0 * c.error))
            .collect();
        let name = p.map_or("all".to_string(), |p| p.name().to_string());
        let or_dash = |v: Vec<String>| {
            if v.is_empty() {
                "–".to_string()
            } else {
                v.join(", ")
            }
        };
        println!(
            "| {name} | {} | {} | {} | {:.2} % | {} of {} | {} | {} |",
            all.len(),
            ident.len(),
            within,
            100.0 * worst,
            imprecise.iter().filter(|c| c.within_3_sigma).count(),
            imprecise.len(),
            if p.is_none() {
                not.len().to_string()
            } else {
                or_dash(apart)
            },
            if p.is_none() {
                format!(
                    "{} off > 5 %",
                    not.iter().filter(|c| c.error > WITHIN).count()
                )
            } else {
                or_dash(errors)
            }
        );
        if p.is_none() {
            total = (all.len(), ident.len(), within);
        }
    }
    let count = |v: StructureVerdict| {
        rows.iter()
            .flat_map(|o| o.checked.iter())
            .filter(|c| c.verdict == v)
            .count()
    };
    println!(
        "\n{} of {} estimates identifiable, {} of those within 5 % of the truth; {} imprecise (restarts agree, three standard errors above 5 % or infinite); {} not identifiable (equally good restarts ended apart); {} fits ended in a local minimum (not compared)",
        total.1,
        total.0,
        total.2,
        count(StructureVerdict::Imprecise),
        count(StructureVerdict::NotIdentifiable),
        rows.iter().map(|o| o.elsewhere).sum::<usize>()
    );
    let wrong: Vec<(usize, &Checked)> = rows
        .iter()
        .flat_map(|o| o.checked.iter().map(move |c| (o.index, c)))
        .filter(|(_, c)| c.identifiable() && c.error > WITHIN)
        .collect();
    if !wrong.is_empty() {
        println!("identifiable but off by more than 5 %:");
        for (i, c) in wrong {
            println!(
                "  #{i} {}: {:.4e} against {:.4e} ({:.1} %, restart spread {:.2e})",
                c.param.name(),
                c.value,
                c.truth,
                100.0 * c.error,
                c.spread
            );
        }
    }
    if let Some(path) = csv {
        let mut s = String::from(
            "axis,label,fit_percent,param,truth,estimate,error,verdict,restart_spread\n",
        );
        for o in &rows {
            for c in &o.checked {
                s.push_str(&format!(
                    "{},\"{}\",{:.4},{},{},{},{},{},{}\n",
                    o.index,
                    o.label,
                    o.fit_percent,
                    c.param.name(),
                    c.truth,
                    c.value,
                    c.error,
                    c.verdict.label(),
                    c.spread
                ));
            }
        }
        if let Err(e) = std::fs::write(&path, s) {
            eprintln!("{path}: {e}");
            std::process::exit(2);
        }
    }
}
