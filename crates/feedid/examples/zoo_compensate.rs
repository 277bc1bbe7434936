//! Compensation on the drive zoo: for every regular zoo member
//! whose command is a ramp, an S-curve, a point-to-point program or a
//! contour axis, identify a global model from a **first run of the
//! member's own program** (or, with `--ident chirp`, a chirp run) on the
//! same axis, compensate the member's command with it (library defaults:
//! smoothing only where the limits need it, held back or slewed where it
//! does not suffice, "never worse" fall-back with the model's fits) and run
//! both commands on the axis.
//!
//! ```sh
//! cargo run --release -p feedid --example zoo_compensate
//! cargo run --release -p feedid --example zoo_compensate -- --ident chirp
//! cargo run --release -p feedid --example zoo_compensate -- --limit 20 --csv comp.csv
//! cargo run --release -p feedid --example zoo_compensate -- --only 47,147 --runs 5
//! ```
//!
//! Per member:
//!
//! * the identification run (noise seed + 1, as long as the member's
//!   recording): `--ident program` (default) the member's program itself —
//!   record the program once, identify, compensate; `--ident chirp`
//!   [`feedid::zoo::MemberSpec::identification_chirp`] (a logarithmic sine
//!   sweep from `f_max/100` to `f_max = min(rate/8, max(6·Kv/2π, 5 Hz))`,
//!   amplitude `0.8·min(A, 10 mm, v/(2π·f_max), a/(2π·f_max)²)`; `A`, `v`,
//!   `a`: the member's amplitude, command speed and acceleration — for a
//!   ramp `a = v·Kv`);
//! * the model: `fit_global_model(.., Auto)` (the best of arx 8,8,1, oe 7,2
//!   and oe 5,1 by free-run error) and its free-run position fit on the
//!   identification run; the share of the following error it explains on
//!   the member's own recording — the plain program run once more, with its
//!   noise and glitches: with `--ident program` from the two runs of the
//!   program ([`ModelQuality::from_two_runs`], the noise taken out by their
//!   cross-products, the encoder's rounding with the member's resolution as
//!   a data sheet gives it), with `--ident chirp` from the recording alone
//!   ([`ModelQuality::from_run`], as `compensate --check` uses it);
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
//! per member, with the model's predicted error for the command sent, the
//! error it assumed for itself, and its true error (true position minus the
//! model's) on the plain program and on the command sent. The expected benefit agrees with the achieved one when
//! within a factor 2, or when both are at least
//! [`feedid::compensate::MAX_BENEFIT`] (an expectation at that cap says
//! "at least").
//!
//! **Learning from runs** (`--runs R`, R ≥ 2): the command sent (run 1) and
//! then R − 1 learning steps ([`feedid::compensate::learn`], library
//! defaults, the same limits and a history), each run on the axis with fresh
//! noise (seed `noise_seed + 1000 + run`). Per run the **measured** rms of
//! position − desired (with the noise, as a user sees it) against the axis's
//! noise floor `√(σ_n² + q²/12)` (σ_n its noise, q its resolution) and
//! against the plain command's measured rms. A member reaches the target
//! when within the runs its measured rms is ≤ 3× the noise floor or ≥ 20×
//! below the plain command's; it grows when one run's rms exceeds the run
//! before by more than the noise floor. The axis's own repeatability is
//! the spread of the measured rms of the command sent run three times with
//! fresh noise (seeds `+1000`, `+2000`, `+2001`); growth beyond the noise
//! floor plus that spread is counted beside it.
//!
//! **Wrong models** (`--wrong gain|delay|pole`): the identified model,
//! written as a discrete `B(q)/A(q)` at the member's rate, is spoiled before
//! it is used — its gain doubled (and kept: unit DC gain off), two samples
//! of delay added, or its slowest pole moved 30 % (`s → 1.3·s`, `z → z^1.3`).
//!
//! ```sh
//! cargo run --release -p feedid --example zoo_compensate -- --runs 5
//! cargo run --release -p feedid --example zoo_compensate -- --runs 5 --wrong delay
//! ```

use std::path::PathBuf;

use feedid::compensate::{
    compensate_model, learn, CompensateConfig, LearnConfig, ModelQuality, MAX_BENEFIT,
};
use feedid::ident::{fit_global_model, GlobalModelKind, LinearModel};
use feedid::lti::{poly_from_roots, poly_roots, Complex, StateSpace};
use feedid::zoo::{CommandSpec, Zoo};
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
    /// Measured rms per run (run 1: the command sent).
    runs: Vec<f64>,
    /// Measured rms of the plain command.
    plain_measured: f64,
    /// Noise floor √(σ² + q²/12).
    floor: f64,
    /// Spread (largest − smallest) of the measured rms of the command sent
    /// run three times with fresh noise: the axis's own repeatability
    /// (learning only; 0 otherwise).
    repeat_spread: f64,
    /// Why the learning ended early, if it did.
    learn_note: String,
    /// What the last learning step did ("" without learning).
    ended: &'static str,
    /// The model's predicted rms error of the command sent \[m\].
    predicted_sent_rms: f64,
    /// The model's own error the expectation assumed \[m\].
    model_error_assumed: f64,
    /// rms of the true position minus the model's, plain command \[m\].
    model_error_plain: f64,
    /// rms of the true position minus the model's, command sent \[m\].
    model_error_sent: f64,
}

/// What the model is identified from (`--ident`).
#[derive(Clone, Copy, PartialEq)]
enum IdentRun {
    /// A first run of the member's own program.
    Program,
    /// The identification chirp.
    Chirp,
}

/// How the model is spoiled (`--wrong`).
#[derive(Clone, Copy, PartialEq)]
enum Wrong {
    None,
    Gain,
    Delay,
    Pole,
}

/// The model as a discrete `B(q)/A(q)` at interval `dt`.
fn as_discrete(model: &LinearModel, dt: f64) -> Result<(Vec<f64>, Vec<f64>), String> {
    let sys = model
        .discrete_state_space(Some(dt))
        .map_err(|e| e.to_string())?;
    let tf = StateSpace::new(sys.a.clone(), sys.b.clone(), sys.c.clone(), sys.d)
        .and_then(|s| s.to_tf())
        .map_err(|e| e.to_string())?;
    let a = tf.den().to_vec();
    let mut b = vec![0.0; a.len() - tf.num().len()];
    b.extend_from_slice(tf.num());
    Ok((b, a))
}

/// The model spoiled as `wrong` says (module doc).
fn spoil(model: &LinearModel, dt: f64, wrong: Wrong) -> Result<LinearModel, String> {
    if wrong == Wrong::None {
        return Ok(model.clone());
    }
    let (mut b, mut a) = as_discrete(model, dt)?;
    match wrong {
        Wrong::None => {}
        Wrong::Gain => b.iter_mut().for_each(|v| *v *= 2.0),
        Wrong::Delay => b.splice(0..0, [0.0, 0.0]).for_each(drop),
        Wrong::Pole => {
            let mut roots = poly_roots(&a).map_err(|e| e.to_string())?;
            let slowest = roots
                .iter()
                .filter(|z| z.norm() < 1.0)
                .map(|z| z.norm())
                .fold(0.0_f64, f64::max);
            for z in roots.iter_mut() {
                if (z.norm() - slowest).abs() < 1e-12 * slowest.max(1e-300) && slowest > 0.0 {
                    let (r, th) = (z.norm(), z.arg());
                    *z = Complex::from_polar(r.powf(1.3), 1.3 * th);
                }
            }
            a = poly_from_roots(&roots);
        }
    }
    LinearModel::discrete(b, a, dt).map_err(|e| e.to_string())
}

fn rms_against(truth: &[f64], desired: &[f64]) -> f64 {
    let s: f64 = truth
        .iter()
        .zip(desired)
        .map(|(a, b)| (a - b) * (a - b))
        .sum();
    (s / desired.len() as f64).sqrt()
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

fn run(
    zoo: &Zoo,
    index: usize,
    max_smoothing: f64,
    runs: usize,
    wrong: Wrong,
    ident_run: IdentRun,
) -> Result<Row, String> {
    let member = zoo.member(index).map_err(|e| e.to_string())?;
    let spec = &member.spec;
    let desired = &member.command;
    let rate = spec.rate_hz;
    let dt = 1.0 / rate;
    let (v, a) = spec.program_references(desired);
    // the identification run, another noise seed than the member's own
    // recording (which checks the model)
    let command = match ident_run {
        IdentRun::Program => desired.clone(),
        IdentRun::Chirp => spec
            .identification_chirp(desired)
            .map_err(|e| e.to_string())?,
    };
    let ident = spec
        .run_plant(&command, spec.noise_seed.wrapping_add(1))
        .map_err(|e| e.to_string())?;
    let ident_position = ident.position.clone();
    let rec = Recording::from_rate(rate, command, ident.position).map_err(|e| e.to_string())?;
    let mut file = fit_global_model(&rec, &GlobalModelKind::Auto).map_err(|e| e.to_string())?;
    file.model = spoil(&file.model, dt, wrong)?;
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
    // with the program as identification run, its two runs take the noise
    // out by their cross-products (`ModelQuality::from_two_runs`)
    let on_plain = match ident_run {
        IdentRun::Program => ModelQuality::from_two_runs(
            &file.model,
            (rec.command(), &ident_position),
            (desired, &measured),
            dt,
            // the encoder's resolution, as its data sheet gives it
            Some(spec.resolution_m),
        ),
        IdentRun::Chirp => ModelQuality::from_run(&file.model, desired, &measured, dt),
    }
    .map_err(|e| e.to_string())?;
    let quality = ModelQuality {
        position_fit_percent: on_chirp.position_fit_percent,
        error_fit_percent: on_plain.error_fit_percent,
        noise_rms_m: on_plain.noise_rms_m,
    };
    // limits the axis already accepts: the plain command's own peaks (a
    // ramp's velocity step is v/Δt) and some headroom
    let (pv, pa) = command_peaks(desired, dt);
    let cfg = CompensateConfig {
        max_velocity: (2.0 * v).max(1.5 * pv),
        max_acceleration: (1.5 * a).max(1.5 * pa),
        max_smoothing,
        quality,
        unit_dc_gain: wrong != Wrong::Gain,
        ..CompensateConfig::default()
    };
    let (command, sent, predicted_benefit, outcome) =
        match compensate_model(&file.model, desired, dt, &cfg) {
            Ok(c) => {
                let sent = match &c.fallback {
                    None => "compensated".to_string(),
                    Some(f) => format!("plain: {f}"),
                };
                let b = c.benefit.expected_benefit;
                (c.command.clone(), sent, b, Some(c))
            }
            Err(e) => (desired.clone(), format!("refused: {e}"), f64::NAN, None),
        };
    let plain = spec
        .run_plant(desired, spec.noise_seed)
        .map_err(|e| e.to_string())?;
    let comp = spec
        .run_plant(&command, spec.noise_seed)
        .map_err(|e| e.to_string())?;
    let (predicted_sent_rms, model_error_assumed, model_error_plain, model_error_sent) =
        match &outcome {
            Some(c) => (
                c.predicted_error.rms,
                c.benefit.model_error_rms_m,
                rms_against(&plain.truth, &c.predicted_plain),
                rms_against(&comp.truth, &c.predicted),
            ),
            None => (f64::NAN, f64::NAN, f64::NAN, f64::NAN),
        };
    // learning from runs: run 1 is the command sent, each run fresh noise
    let measured_rms = |p: &[f64]| rms_against(p, desired);
    let mut sent_cmd = command.clone();
    let mut history = None;
    let mut run_rms = Vec::new();
    let mut learn_note = String::new();
    let mut ended = "";
    let lcfg = LearnConfig {
        compensate: cfg,
        ..LearnConfig::default()
    };
    for j in 0..runs.max(1) {
        let r = spec
            .run_plant(&sent_cmd, spec.noise_seed.wrapping_add(1000 + j as u64))
            .map_err(|e| e.to_string())?;
        run_rms.push(measured_rms(&r.position));
        if j + 1 >= runs {
            break;
        }
        match learn(
            &file.model,
            desired,
            &sent_cmd,
            &r.position,
            dt,
            &lcfg,
            history.as_ref(),
        ) {
            Ok(step) => {
                use feedid::compensate::LearnStatus as S;
                let tag = match step.status {
                    S::First => "first",
                    S::Improving => "improving",
                    S::AtNoise => "at noise",
                    S::Damped { .. } => "damped",
                    S::Stopped { .. } => "stopped",
                    S::Settled { .. } => "settled",
                };
                ended = tag;
                if !learn_note.is_empty() {
                    learn_note.push_str(", ");
                }
                learn_note.push_str(&format!(
                    "{tag} (noise {:.3} µm, filter {:.2} ms, gain {}{}, σ {:.2} ms, held {:.1} %)",
                    1e6 * step.noise_m,
                    1e3 * step.noise_filter_s,
                    step.gain,
                    if step.gain_limited { " limited" } else { "" },
                    1e3 * step.step_smoothing_s,
                    100.0 * step.held_back_share
                ));
                sent_cmd = step.command;
                history = Some(step.history);
            }
            Err(e) => {
                learn_note.push_str(&format!("; run {}: {e}", j + 1));
                break;
            }
        }
    }
    let floor = (spec.noise_std_m.powi(2) + spec.resolution_m.powi(2) / 12.0).sqrt();
    // the same command run again with fresh noise: how much the measured rms
    // of one run varies by itself
    let mut repeat_spread = 0.0;
    if runs > 1 {
        let mut v = vec![run_rms[0]];
        for s in [2000, 2001] {
            let r = spec
                .run_plant(&command, spec.noise_seed.wrapping_add(s))
                .map_err(|e| e.to_string())?;
            v.push(measured_rms(&r.position));
        }
        let (lo, hi) = v
            .iter()
            .fold((f64::INFINITY, 0.0_f64), |(l, h), x| (l.min(*x), h.max(*x)));
        repeat_spread = hi - lo;
    }
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
        runs: run_rms,
        plain_measured: measured_rms(&plain.position),
        floor,
        repeat_spread,
        learn_note,
        ended,
        predicted_sent_rms,
        model_error_assumed,
        model_error_plain,
        model_error_sent,
    })
}

/// The learning table (module doc).
fn learning_summary(rows: &[Row], runs: usize) {
    let reached = |r: &Row, upto: usize| {
        r.runs[..upto.min(r.runs.len())]
            .iter()
            .any(|&v| v <= 3.0 * r.floor || v <= r.plain_measured / 20.0)
    };
    let grows = |r: &Row| r.runs.windows(2).any(|w| w[1] > w[0] + r.floor);
    let grows_beyond_repeat = |r: &Row| {
        r.runs
            .windows(2)
            .any(|w| w[1] > w[0] + r.floor + r.repeat_spread)
    };
    println!("\nlearning from runs (measured rms, with the noise):\n");
    println!("| run | median rms / noise floor | median plain / rms | at target by this run | grew since the run before |");
    println!("|---:|---:|---:|---:|---:|");
    for j in 0..runs {
        let with: Vec<&Row> = rows.iter().filter(|r| r.runs.len() > j).collect();
        let mut ratio: Vec<f64> = with.iter().map(|r| r.runs[j] / r.floor).collect();
        let mut red: Vec<f64> = with.iter().map(|r| r.plain_measured / r.runs[j]).collect();
        let at = rows.iter().filter(|r| reached(r, j + 1)).count();
        let grew = with
            .iter()
            .filter(|r| j > 0 && r.runs[j] > r.runs[j - 1] + r.floor)
            .count();
        println!(
            "| {} | {:.2} | {:.1}× | {} of {} | {} |",
            j + 1,
            median(&mut ratio),
            median(&mut red),
            at,
            rows.len(),
            grew
        );
    }
    for (name, sel) in [
        (
            "fit ≥ 95 %",
            rows.iter().filter(|r| r.fit >= 95.0).collect::<Vec<_>>(),
        ),
        (
            "fit < 95 %",
            rows.iter()
                .filter(|r| r.fit.is_nan() || r.fit < 95.0)
                .collect(),
        ),
    ] {
        let mut last: Vec<f64> = sel
            .iter()
            .map(|r| r.plain_measured / r.runs[r.runs.len() - 1])
            .collect();
        println!(
            "{name}: {} of {} at the target within {runs} runs, {} grew, median plain / last run {:.1}×, {} end settled",
            sel.iter().filter(|r| reached(r, runs)).count(),
            sel.len(),
            sel.iter().filter(|r| grows(r)).count(),
            median(&mut last),
            sel.iter().filter(|r| r.ended == "settled").count()
        );
    }
    let missed: Vec<&Row> = rows.iter().filter(|r| !reached(r, runs)).collect();
    // how the learning ended: the last step's status, all and not at the target
    let tags = [
        "improving",
        "damped",
        "settled",
        "stopped",
        "at noise",
        "first",
    ];
    for (name, sel) in [
        ("all", rows.iter().collect::<Vec<_>>()),
        ("not at the target", missed.clone()),
    ] {
        let counts: Vec<String> = tags
            .iter()
            .map(|t| format!("{} {t}", sel.iter().filter(|r| r.ended == *t).count()))
            .collect();
        println!("last step, {name} ({}): {}", sel.len(), counts.join(", "));
    }
    println!(
        "\n{} of {} members at the target within {runs} runs; {} grew by more than the noise in some run",
        rows.len() - missed.len(),
        rows.len(),
        rows.iter().filter(|r| grows(r)).count()
    );
    println!(
        "{} grew by more than the noise and the axis's own repeatability (the spread of the measured rms of the first command run three times)",
        rows.iter().filter(|r| grows_beyond_repeat(r)).count()
    );
    for r in missed
        .iter()
        .chain(rows.iter().filter(|r| grows(r)).collect::<Vec<_>>().iter())
    {
        println!(
            "  #{} {} ({}): floor {:.3} µm, repeatability {:.3} µm, plain {:.3} µm, runs {} µm{}",
            r.index,
            r.label,
            r.model,
            1e6 * r.floor,
            1e6 * r.repeat_spread,
            1e6 * r.plain_measured,
            r.runs
                .iter()
                .map(|v| format!("{:.3}", 1e6 * v))
                .collect::<Vec<_>>()
                .join(" → "),
            if r.learn_note.is_empty() {
                String::new()
            } else {
                format!("; {}", r.learn_note)
            }
        );
    }
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
    let mut only: Option<Vec<usize>> = None;
    let mut max_smoothing = CompensateConfig::default().max_smoothing;
    let mut csv: Option<PathBuf> = None;
    let mut runs = 1usize;
    let mut wrong = Wrong::None;
    let mut ident_run = IdentRun::Program;
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
            "--only" => {
                only = args
                    .get(i + 1)
                    .map(|s| s.split(',').filter_map(|v| v.parse().ok()).collect());
                i += 1;
            }
            "--max-smoothing" => {
                max_smoothing = args
                    .get(i + 1)
                    .and_then(|s| s.parse().ok())
                    .unwrap_or(max_smoothing);
                i += 1;
            }
            "--runs" => {
                runs = args.get(i + 1).and_then(|s| s.parse().ok()).unwrap_or(runs);
                i += 1;
            }
            "--wrong" => {
                wrong = match args.get(i + 1).map(String::as_str) {
                    Some("gain") => Wrong::Gain,
                    Some("delay") => Wrong::Delay,
                    Some("pole") => Wrong::Pole,
                    other => {
                        eprintln!("--wrong {other:?}: expected gain, delay or pole");
                        std::process::exit(2);
                    }
                };
                i += 1;
            }
            "--ident" => {
                ident_run = match args.get(i + 1).map(String::as_str) {
                    Some("program") => IdentRun::Program,
                    Some("chirp") => IdentRun::Chirp,
                    other => {
                        eprintln!("--ident {other:?}: expected program or chirp");
                        std::process::exit(2);
                    }
                };
                i += 1;
            }
            "--csv" => {
                csv = args.get(i + 1).map(PathBuf::from);
                i += 1;
            }
            other => {
                eprintln!("unknown argument {other}; use --limit N, --only I,J, --max-smoothing S, --runs R, --wrong gain|delay|pole, --ident program|chirp, --csv FILE");
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
        .filter(|i| only.as_ref().is_none_or(|o| o.contains(i)))
        .take(limit)
        .collect();
    let start = std::time::Instant::now();
    let results: Vec<(usize, Result<Row, String>)> = indices
        .par_iter()
        .map(|&i| (i, run(&zoo, i, max_smoothing, runs, wrong, ident_run)))
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
    // the model's expectation against what the axis did, where compensated
    let comp: Vec<&Row> = rows.iter().filter(|r| r.sent == "compensated").collect();
    // an expectation at the library's cap claims "at least MAX_BENEFIT"
    let agrees = |r: &Row| {
        let achieved = r.plain_rms / r.sent_rms;
        let q = r.predicted_benefit / achieved;
        (0.5..=2.0).contains(&q)
            || (r.predicted_benefit >= MAX_BENEFIT * (1.0 - 1e-9) && achieved >= 0.5 * MAX_BENEFIT)
    };
    let agree = comp.iter().filter(|r| agrees(r)).count();
    println!(
        "\nexpected benefit within a factor 2 of the achieved one (or both at least {MAX_BENEFIT}×, the cap of an expectation): {agree} of {} compensated axes",
        comp.len()
    );
    for r in comp.iter().filter(|r| !agrees(r)) {
        println!(
            "  #{} {}: expected {:.2}×, achieved {:.2}× (error fit {:.1} %)",
            r.index,
            r.label,
            r.predicted_benefit,
            r.plain_rms / r.sent_rms,
            r.error_fit
        );
    }
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
    if runs > 1 {
        learning_summary(&rows, runs);
    }
    if let Some(path) = csv {
        let mut text = String::from(
            "index,kind,feed_forward,model,fit_percent,error_fit_percent,plain_rms_m,sent_rms_m,reduction,predicted_benefit,predicted_sent_rms_m,model_error_assumed_m,model_error_plain_m,model_error_sent_m,sent,label\n",
        );
        for r in &rows {
            text.push_str(&format!(
                "{},{},{},\"{}\",{:.3},{:.3},{:e},{:e},{:.4},{:.4},{:e},{:e},{:e},{:e},\"{}\",\"{}\"\n",
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
                r.predicted_sent_rms,
                r.model_error_assumed,
                r.model_error_plain,
                r.model_error_sent,
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
