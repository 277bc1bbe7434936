//! Which extrapolation of the command over the horizon gives the smallest
//! prediction error when the stream has no command lead: hold, constant
//! velocity or constant acceleration, against the real command (a lead ≥ H),
//! for each method that reads the command over the horizon.
//!
//! ```text
//! cargo run --release -p feedid --example stream_extrapolation -- [zoo|rig|emps|all] [methods]
//! ```
//!
//! Recordings: the six rig scenarios of `feedid simulate` (seed 0, default
//! durations), the EMPS recording (`../shared/data/emps/DATA_EMPS.mat`,
//! skipped when absent) and the 210 regular members of the drive zoo. Each
//! is streamed line by line ([`Streamer::push`], default windows, H = 10)
//! once per extrapolation; the real command is [`CommandExtrapolation::Wait`]
//! (the batch engine's predictions). Per recording and method, the rms error
//! of each extrapolation is taken **on the samples it and the real command
//! both predicted** (auto withholds predictions it cannot vouch for, so
//! coverage differs) and divided by the rms with the real command on the
//! same samples; the table gives the median and
//! the 90th percentile of that ratio over the recordings, how often each
//! extrapolation was the best of the three (or tied within 0.1 %), and the
//! mean coverage (share of the samples predicted).

use std::path::Path;

use feedid::ident::stream::{CommandExtrapolation, StreamOptions, Streamer};
use feedid::ident::{EngineConfig, Method};
use feedid::io::{read_recording, ChannelRef, ReadOptions};
use feedid::signal::Scenario;
use feedid::zoo::Zoo;
use feedid::Recording;
use rayon::prelude::*;

const VARIANTS: [CommandExtrapolation; 4] = [
    CommandExtrapolation::Wait,
    CommandExtrapolation::Hold,
    CommandExtrapolation::Velocity,
    CommandExtrapolation::Acceleration,
];

/// Per variant: the latest prediction of each sample.
fn stream(rec: &Recording, method: &Method, x: CommandExtrapolation) -> Vec<Option<f64>> {
    let cfg = EngineConfig {
        window: method.default_window(),
        ..EngineConfig::default()
    };
    let opts = StreamOptions {
        extrapolation: x,
        ..StreamOptions::default()
    };
    let mut out = vec![None; rec.len()];
    let Ok(est) = method.build() else {
        return out;
    };
    let Ok(mut s) = Streamer::with_options(est, cfg, opts) else {
        return out;
    };
    let mut take = |p: feedid::ident::Prediction<'_>| {
        for (k, v) in p.horizon.clone().zip(p.position) {
            if let Some(o) = out.get_mut(k) {
                *o = Some(*v);
            }
        }
    };
    for k in 0..rec.len() {
        if s.push(rec.time()[k], rec.command()[k], rec.position()[k])
            .is_err()
        {
            continue;
        }
        while let Ok(Some(p)) = s.poll() {
            take(p);
        }
    }
    s.finish();
    while let Ok(Some(p)) = s.poll() {
        take(p);
    }
    out
}

/// One recording and method: rms ratios to the real command (hold, velocity,
/// acceleration) on the common samples, and the coverage of each variant.
struct Row {
    ratio: [f64; 3],
    coverage: [f64; 4],
    common: usize,
}

fn evaluate(rec: &Recording, method: &Method) -> Option<Row> {
    let preds: Vec<Vec<Option<f64>>> = VARIANTS.iter().map(|&x| stream(rec, method, x)).collect();
    let n = rec.len();
    let y = rec.position();
    let mut ratio = [0.0; 3];
    let mut common = 0;
    for v in 1..4 {
        // this variant against the real command, on the samples both predicted
        let (mut sse, mut sse_real, mut m) = (0.0, 0.0, 0);
        for k in 0..n {
            if let (Some(a), Some(b)) = (preds[v][k], preds[0][k]) {
                sse += (y[k] - a).powi(2);
                sse_real += (y[k] - b).powi(2);
                m += 1;
            }
        }
        if m < 10 || sse_real <= 0.0 {
            return None;
        }
        ratio[v - 1] = (sse / sse_real).sqrt();
        common += m;
    }
    let mut coverage = [0.0; 4];
    for (v, p) in preds.iter().enumerate() {
        coverage[v] = p.iter().filter(|v| v.is_some()).count() as f64 / n as f64;
    }
    Some(Row {
        ratio,
        coverage,
        common: common / 3,
    })
}

fn quantile(v: &mut [f64], q: f64) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    let i = ((v.len() - 1) as f64 * q).round() as usize;
    v[i]
}

fn report(group: &str, recordings: &[(String, Recording)], methods: &[Method]) {
    println!("\n### {group} ({} recordings)\n", recordings.len());
    println!("| method | rms / rms with the real command: hold | velocity | acceleration | best: hold / velocity / acceleration / tie | coverage real / hold / velocity / acceleration | samples compared (mean of the three) |");
    println!("|---|---|---|---|---|---|---|");
    for method in methods {
        let rows: Vec<(String, Option<Row>)> = recordings
            .par_iter()
            .map(|(name, rec)| (name.clone(), evaluate(rec, method)))
            .collect();
        if recordings.len() <= 8 {
            for (name, r) in &rows {
                if let Some(r) = r {
                    eprintln!(
                        "{} {name}: hold {:.4} velocity {:.4} acceleration {:.4} (coverage {:.2} {:.2} {:.2} {:.2}, {} common)",
                        method.name(),
                        r.ratio[0],
                        r.ratio[1],
                        r.ratio[2],
                        r.coverage[0],
                        r.coverage[1],
                        r.coverage[2],
                        r.coverage[3],
                        r.common
                    );
                }
            }
        }
        let rows: Vec<Row> = rows.into_iter().filter_map(|(_, r)| r).collect();
        if rows.is_empty() {
            println!("| {} | — | — | — | — | — | 0 |", method.name());
            continue;
        }
        let mut cells = Vec::new();
        for v in 0..3 {
            let mut r: Vec<f64> = rows.iter().map(|r| r.ratio[v]).collect();
            cells.push(format!(
                "{:.3} (p90 {:.2})",
                quantile(&mut r, 0.5),
                quantile(&mut r, 0.9)
            ));
        }
        // the best of the three, or a tie (within 0.1 %)
        let mut best = [0usize; 4];
        for r in &rows {
            let min = r.ratio.iter().copied().fold(f64::INFINITY, f64::min);
            let at: Vec<usize> = (0..3).filter(|&v| r.ratio[v] <= min * 1.001).collect();
            match at.as_slice() {
                [b] => best[*b] += 1,
                _ => best[3] += 1,
            }
        }
        let cov: Vec<String> = (0..4)
            .map(|v| {
                let m = rows.iter().map(|r| r.coverage[v]).sum::<f64>() / rows.len() as f64;
                format!("{:.0} %", 100.0 * m)
            })
            .collect();
        let common: usize = rows.iter().map(|r| r.common).sum();
        println!(
            "| {} | {} | {} | {} | {} / {} / {} / {} | {} | {} |",
            method.name(),
            cells[0],
            cells[1],
            cells[2],
            best[0],
            best[1],
            best[2],
            best[3],
            cov.join(" / "),
            common
        );
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let which = args.first().map_or("all", String::as_str);
    let methods: Vec<Method> = match args.get(1) {
        Some(list) => list
            .split(',')
            .map(|m| m.parse())
            .collect::<Result<_, _>>()?,
        None => ["auto", "arx", "rls", "oe"]
            .iter()
            .map(|m| m.parse())
            .collect::<Result<_, _>>()?,
    };
    let mut paper_tf: Method = "paper".parse()?;
    if let Method::Paper(c) = &mut paper_tf {
        c.prediction = feedid::ident::PredictionMode::TransferFunction;
    }
    if which == "rig" || which == "all" {
        let mut recs = Vec::new();
        for name in ["ramp", "step", "scurve", "chirp", "prbs", "multisine"] {
            let sc: Scenario = name.parse()?;
            let rate = 5000.0;
            let command = sc.command(rate, sc.default_duration(), 0)?;
            let out = feedid::drive::VirtualRig::new(feedid::drive::RigParams::default())
                .with_seed(0)
                .simulate(&command, rate)?;
            recs.push((
                name.to_string(),
                Recording::new(out.time, out.command, out.position)?,
            ));
        }
        let mut m = methods.clone();
        m.push(paper_tf.clone());
        report("rig scenarios (feedid simulate, seed 0)", &recs, &m);
    }
    if which == "emps" || which == "all" {
        let path = Path::new("../shared/data/emps/DATA_EMPS.mat");
        if path.exists() {
            let opts = ReadOptions {
                time: Some(ChannelRef::Name("t".into())),
                command: Some(ChannelRef::Name("qg".into())),
                position: Some(ChannelRef::Name("qm".into())),
                ..ReadOptions::default()
            };
            let rec = read_recording(path, &opts)?;
            report("EMPS (qg → qm, 1 kHz)", &[("emps".into(), rec)], &methods);
        } else {
            eprintln!("skipped: {} absent", path.display());
        }
    }
    if which == "zoo" || which == "all" {
        let zoo = Zoo::standard();
        let idx: Vec<usize> = zoo.regular().collect();
        let recs: Vec<(String, Recording)> = zoo
            .members(&idx)
            .into_iter()
            .zip(&idx)
            .filter_map(|(m, i)| Some((format!("zoo-{i:03}"), m.ok()?.recording().ok()?)))
            .collect();
        let zm: Vec<Method> = methods
            .iter()
            .filter(|m| m.name() != "oe")
            .cloned()
            .collect();
        report("drive zoo, regular members", &recs, &zm);
    }
    Ok(())
}
