//! A settings sweep on the drive zoo: the tool that chose the defaults of
//! `arx`, `rls` and `auto`'s candidates. A development tool, not
//! a benchmark: it panics on a bad configuration line.
//!
//! ```sh
//! cargo run --release -p feedid --example zoo_sweep -- SET configs.txt sweep.csv
//! ```
//!
//! `SET` is `all` (the regular members), `even`, `odd` (halves: choose on
//! one, check on the other), `small` (members 0–19), `m3,17,…` (these
//! members) or `emps` (the EMPS recording, printed). Each
//! line of `configs.txt` is a method and its settings, e.g.
//! `arx o=3,3,0 w=100 ridge=1e-10 dc=1`, `rls o=8,8,0 lambda=0.999`,
//! `auto cands=ls:2,2,0:100:1e-6;rls:8,8,0:0.9995;rest mem=0.1 cons=20` (`lsb:…`,
//! `rlsb:…`: the same with a constant term; `hold`, `command`, `rest` =
//! the command at rest), `arx220frame` (the baseline
//! in the frame of the last measured position) or `arx220unitW` (unit DC
//! gain, W rows); `#` starts a comment. The CSV has per member and
//! configuration the rms over the predicted samples, the coverage, the rms
//! of the configuration and of `arx220` on the samples both predict, and
//! the largest ratio to a baseline (command, hold, arx220), and the rms
//! over the samples that every configuration of the file predicts
//! (`rms_common`, `common_samples`: settings compared on the same
//! samples). `oe` takes
//! `poles=`, `zeros=`, `prior=` (the sliding prior's weight) and `iters=`
//! (LM iterations per window).
//!
//! Environment: `ZOO_SWEEP_PHASE=P` starts the baselines' blocks `P`
//! samples later (as `zoo_bench --baseline-phase`); `ZOO_SWEEP_WHO=1`
//! prints every loss to a baseline on stderr (`all`: every comparison,
//! with both sums of squares); `ZOO_SWEEP_VIA=mm|um` has the methods read
//! every member converted to that unit and back (the baselines and the
//! scores keep the metre values); `ZOO_SWEEP_DUMP=PREFIX` writes
//! `PREFIX-N.csv` per member (k, u, y, prediction, flag, arx220, chosen
//! candidate, scored flag, arx220 flag).

use std::time::Instant;

use feedid::ident::{engine, ArxOrders, Candidate, EngineConfig, Method};

fn orders(v: &str) -> ArxOrders {
    let p: Vec<usize> = v.split(',').map(|x| x.parse().unwrap()).collect();
    ArxOrders::new(p[0], p[1], p[2])
}

fn cand(s: &str) -> Candidate {
    let f: Vec<&str> = s.split(':').collect();
    match f[0] {
        "hold" => Candidate::Hold,
        "command" => Candidate::Command,
        "rest" => Candidate::CommandAtRest,
        "ls" | "lsb" => Candidate::Windowed {
            orders: orders(f[1]),
            window: f[2].parse().unwrap(),
            ridge: f.get(3).map_or(0.0, |v| v.parse().unwrap()),
            bias: f[0] == "lsb",
        },
        "rls" | "rlsb" => Candidate::Recursive {
            orders: orders(f[1]),
            lambda: f[2].parse().unwrap(),
            bias: f[0] == "rlsb",
        },
        _ => panic!("candidate {s}"),
    }
}
use feedid::zoo::Zoo;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

const H: usize = 10;

fn parse(cfg: &str) -> Result<(Method, usize), String> {
    let mut it = cfg.split_whitespace();
    let name = it.next().ok_or("empty")?;
    let mut m: Method = name.parse().map_err(|e| format!("{e}"))?;
    let mut w = m.default_window();
    for kv in it {
        let (k, v) = kv.split_once('=').ok_or(format!("bad {kv}"))?;
        let f = || v.parse::<f64>().map_err(|e| format!("{kv}: {e}"));
        match k {
            "o" => {
                let p: Vec<usize> = v.split(',').map(|x| x.parse().unwrap()).collect();
                m.set_orders(ArxOrders::new(p[0], p[1], p[2]))
                    .map_err(|e| e.to_string())?;
            }
            "w" => w = v.parse().map_err(|e| format!("{e}"))?,
            _ => match (&mut m, k) {
                (Method::Arx(c), "ridge") => c.ridge = f()?,
                (Method::Arx(c), "minx") => c.min_excitation = f()?,
                (Method::Arx(c), "dc") => c.dc_gain_bounds = (-f64::INFINITY, f64::INFINITY),
                (Method::Arx(c), "dcw") => c.dc_gain_bounds = (1.0 / f()?, f()?),
                (Method::Arx(c), "offset") => c.offset = v == "1",
                (Method::Arx(c), "radius") => c.max_pole_radius = f()?,
                (Method::Arx(c), "refac") => c.refactor_every = v.parse().unwrap(),
                (Method::Arx(c), "slide") => c.sliding = v == "1",
                (Method::Rls(c), "lambda") => c.lambda = f()?,
                (Method::Rls(c), "p0") => c.p0 = f()?,
                (Method::Rls(c), "trace") => c.max_trace = Some(f()?),
                (Method::Rls(c), "minx") => c.min_excitation = f()?,
                (Method::Rls(c), "scale") => c.scale = Some(f()?),
                (Method::Rls(c), "span") => c.frame_span = f()?,
                (Method::Auto(c), "cands") => c.candidates = v.split(';').map(cand).collect(),
                (Method::Auto(c), "mem") => c.memory = f()?,
                (Method::Auto(c), "plaus") => c.plausibility = f()?,
                (Method::Auto(c), "cons") => c.consensus = f()?,
                (Method::Oe(c), "poles") => c.poles = v.parse().map_err(|e| format!("{e}"))?,
                (Method::Oe(c), "zeros") => c.zeros = v.parse().map_err(|e| format!("{e}"))?,
                (Method::Oe(c), "prior") => c.prior_weight = f()?,
                (Method::Oe(c), "iters") => {
                    c.window_iterations = v.parse().map_err(|e| format!("{e}"))?
                }
                (Method::Rls(c), "radius") => c.max_pole_radius = f()?,
                (Method::Rls(c), "win") => c.window = Some(v.parse().unwrap()),
                _ => return Err(format!("unknown {k} for {name}")),
            },
        }
    }
    Ok((m, w))
}

/// Shift of the baselines' horizon grid (`ZOO_SWEEP_PHASE`, samples; 0).
fn phase() -> usize {
    std::env::var("ZOO_SWEEP_PHASE")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0)
}

fn arx220(u: &[f64], y: &[f64]) -> (Vec<f64>, Vec<bool>) {
    arx220f(u, y, false)
}

fn arx220f(u: &[f64], y: &[f64], frame: bool) -> (Vec<f64>, Vec<bool>) {
    const W: usize = 100;
    let n = y.len();
    let mut value = vec![0.0; n];
    let mut has = vec![false; n];
    let mut t0 = W + 2 + phase();
    while t0 < n {
        let r = if frame { y[t0 - 1] } else { 0.0 };
        let a = DMatrix::from_fn(W, 4, |i, j| {
            let k = t0 - W + i;
            match j {
                0 => -(y[k - 1] - r),
                1 => -(y[k - 2] - r),
                2 => u[k] - r,
                _ => u[k - 1] - r,
            }
        });
        let b = DVector::from_fn(W, |i, _| y[t0 - W + i] - r);
        let svd = a.svd(true, true);
        let cutoff = svd.singular_values.max() * f64::EPSILON * W as f64;
        if let Ok(theta) = svd.solve(&b, cutoff) {
            let (mut y1, mut y2) = (y[t0 - 1] - r, y[t0 - 2] - r);
            let end = (t0 + H).min(n);
            for k in t0..end {
                let p = -theta[0] * y1 - theta[1] * y2
                    + theta[2] * (u[k] - r)
                    + theta[3] * (u[k - 1] - r);
                value[k] = p + r;
                has[k] = p.is_finite();
                y2 = y1;
                y1 = p;
            }
        }
        t0 += H;
    }
    (value, has)
}

/// Unit-DC-gain ARX(2,2,0), W rows, per-row frame u[k−1].
fn arx220unit(u: &[f64], y: &[f64], w: usize) -> (Vec<f64>, Vec<bool>) {
    let n = y.len();
    let mut value = vec![0.0; n];
    let mut has = vec![false; n];
    let mut t0 = w + 2;
    while t0 < n {
        let a = DMatrix::from_fn(w, 3, |i, j| {
            let k = t0 - w + i;
            let r = u[k - 1];
            match j {
                0 => -(y[k - 1] - r),
                1 => -(y[k - 2] - r),
                _ => u[k] - r,
            }
        });
        let b = DVector::from_fn(w, |i, _| {
            let k = t0 - w + i;
            y[k] - u[k - 1]
        });
        let svd = a.svd(true, true);
        let cutoff = svd.singular_values.max() * f64::EPSILON * w as f64;
        if let Ok(th) = svd.solve(&b, cutoff) {
            let (mut y1, mut y2) = (y[t0 - 1], y[t0 - 2]);
            let end = (t0 + H).min(n);
            for k in t0..end {
                let r = u[k - 1];
                let p = r - th[0] * (y1 - r) - th[1] * (y2 - r) + th[2] * (u[k] - r);
                value[k] = p;
                has[k] = p.is_finite();
                y2 = y1;
                y1 = p;
            }
        }
        t0 += H;
    }
    (value, has)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let set = args.first().cloned().unwrap_or("all".into());
    let cfgfile = args.get(1).cloned().unwrap_or("configs.txt".into());
    let out = args.get(2).cloned().unwrap_or("sweep.csv".into());
    let configs: Vec<String> = std::fs::read_to_string(&cfgfile)
        .unwrap()
        .lines()
        .map(|l| l.trim().to_string())
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .collect();
    for c in configs.iter().filter(|c| !c.starts_with("arx220")) {
        parse(c).unwrap();
    }
    if set == "emps" {
        use feedid::io::{read_recording, ChannelRef, ReadOptions};
        let rec = read_recording(
            std::path::Path::new("../shared/data/emps/DATA_EMPS.mat"),
            &ReadOptions {
                time: Some(ChannelRef::Name("t".into())),
                command: Some(ChannelRef::Name("qg".into())),
                position: Some(ChannelRef::Name("qm".into())),
                ..Default::default()
            },
        )
        .unwrap();
        for c in &configs {
            let (spec, w) = parse(c).unwrap();
            let mut est = spec.build().unwrap();
            let cfg = EngineConfig {
                window: w,
                horizon: H,
                hop: None,
                warm_up: 0,
            };
            let r = engine::run(&mut est, &rec.signals(), &cfg).unwrap();
            println!(
                "{c:60} rms {:.3} µm max {:.2} µm coverage {:.1} % interval {:.1} %",
                r.stats.rms * 1e6,
                r.stats.max_abs * 1e6,
                100.0 * r.stats.samples as f64 / rec.len() as f64,
                r.interval_coverage_percent().unwrap_or(f64::NAN)
            );
        }
        return;
    }
    let zoo = Zoo::standard();
    let members: Vec<usize> = zoo
        .regular()
        .filter(|i| match set.as_str() {
            "even" => i % 2 == 0,
            "odd" => i % 2 == 1,
            "small" => *i < 20,
            x if x.starts_with('m') => x[1..].split(',').any(|v| v.parse::<usize>().unwrap() == *i),
            _ => true,
        })
        .collect();
    let t = Instant::now();
    let rows: Vec<String> = members
        .par_iter()
        .flat_map(|&i| {
            let m = zoo.member(i).unwrap();
            let rec = m.recording().unwrap();
            // ZOO_SWEEP_VIA=mm|um: the methods see the recording converted
            // to that unit and back (as `zoo_bench --via-unit`)
            let via = match std::env::var("ZOO_SWEEP_VIA").as_deref() {
                Ok("mm") => 1e-3,
                Ok("um") => 1e-6,
                _ => 1.0,
            };
            let rec = if via == 1.0 {
                rec
            } else {
                let f = |v: &[f64]| {
                    v.iter()
                        .map(|x| x * (1.0 / via) * via)
                        .collect::<Vec<f64>>()
                };
                feedid::Recording::new(rec.time().to_vec(), f(rec.command()), f(rec.position()))
                    .unwrap()
            };
            let s = rec.signals();
            let y = &m.position;
            let n = y.len();
            let mut scored = vec![true; n];
            for g in &m.spec.glitches {
                scored[g.index] = false;
            }
            let (bv, bh) = arx220(&m.command, y);
            let mut rows = Vec::new();
            let mut outs: Vec<(Vec<f64>, Vec<bool>)> = Vec::new();
            for c in &configs {
                let t = Instant::now();
                let mut cand = vec![f64::NAN; n];
                let (p, has) = if c == "arx220frame" {
                    arx220f(&m.command, y, true)
                } else if let Some(w) = c.strip_prefix("arx220unit") {
                    arx220unit(&m.command, y, w.trim().parse().unwrap_or(100))
                } else {
                    let (spec, w) = parse(c).unwrap();
                    let mut est = spec.build().unwrap();
                    let cfg = EngineConfig {
                        window: w,
                        horizon: H,
                        hop: None,
                        warm_up: 0,
                    };
                    match engine::run(&mut est, &s, &cfg) {
                        Ok(r) => {
                            let nc = r.coefficient_names.len();
                            for (wi, w) in r.windows.iter().enumerate() {
                                for k in w.horizon.clone() {
                                    if nc > 0 && k < n {
                                        cand[k] = r.coefficients[wi * nc];
                                    }
                                }
                            }
                            (r.predicted, r.has_prediction)
                        }
                        Err(_) => (vec![0.0; n], vec![false; n]),
                    }
                };
                let secs = t.elapsed().as_secs_f64();
                if let Ok(d) = std::env::var("ZOO_SWEEP_DUMP") {
                    let mut text = String::from("k,u,y,p,has,arx220,cand,scored,arxhas\n");
                    for k in 0..n {
                        text += &format!(
                            "{k},{},{},{},{},{},{},{},{}\n",
                            m.command[k],
                            y[k],
                            p[k],
                            has[k] as u8,
                            bv[k],
                            cand[k],
                            scored[k] as u8,
                            bh[k] as u8
                        );
                    }
                    std::fs::write(format!("{d}-{i}.csv"), text).unwrap();
                }
                let (mut se, mut cnt, mut seb, mut cb) = (0.0, 0usize, 0.0, 0usize);
                for k in 0..n {
                    if has[k] && scored[k] {
                        se += (y[k] - p[k]).powi(2);
                        cnt += 1;
                        if bh[k] {
                            seb += (y[k] - bv[k]).powi(2);
                            cb += 1;
                        }
                    }
                }
                let (mut se2, mut c2) = (0.0, 0usize);
                for k in 0..n {
                    if has[k] && scored[k] && bh[k] {
                        se2 += (y[k] - p[k]).powi(2);
                        c2 += 1;
                    }
                }
                let _ = cb;
                // worst ratio to a baseline (command, hold, arx220) on the shared samples
                let h0 = H + phase();
                let hold_has = |k: usize| k >= h0;
                let hold_at = |k: usize| y[k - 1 - (k - h0) % H];
                let mut worst = 0.0f64;
                for b in 0..3 {
                    let (mut sa, mut sb, mut nn) = (0.0, 0.0, 0usize);
                    for k in 0..n {
                        let (bh_k, bv_k) = match b {
                            0 => (true, m.command[k]),
                            1 => (hold_has(k), if hold_has(k) { hold_at(k) } else { 0.0 }),
                            _ => (bh[k], bv[k]),
                        };
                        if has[k] && scored[k] && bh_k {
                            sa += (y[k] - p[k]).powi(2);
                            sb += (y[k] - bv_k).powi(2);
                            nn += 1;
                        }
                    }
                    if nn >= 50 {
                        if std::env::var("ZOO_SWEEP_WHO").is_ok_and(|v| v == "all" || sa > sb) {
                            eprintln!(
                                "LOSS {i} to {} {:.5} {sa:e} {sb:e}",
                                ["command", "hold", "arx220"][b],
                                (sa / sb).sqrt()
                            );
                        }
                        worst = worst.max((sa / sb).sqrt());
                    }
                }
                rows.push(format!(
                    "{i},\"{c}\",{},{},{},{},{},{secs:.4},{},{worst}",
                    if cnt > 0 {
                        (se / cnt as f64).sqrt()
                    } else {
                        f64::NAN
                    },
                    100.0 * cnt as f64 / n as f64,
                    if c2 > 0 {
                        (se2 / c2 as f64).sqrt()
                    } else {
                        f64::NAN
                    },
                    if c2 > 0 {
                        (seb / c2 as f64).sqrt()
                    } else {
                        f64::NAN
                    },
                    n,
                    m.spec.plant.name()
                ));
                outs.push((p, has));
            }
            // every configuration scored on the samples all of them predict
            let common: Vec<bool> = (0..n)
                .map(|k| scored[k] && outs.iter().all(|(_, h)| h[k]))
                .collect();
            let shared = common.iter().filter(|&&c| c).count();
            for (row, (p, _)) in rows.iter_mut().zip(&outs) {
                let se: f64 = (0..n)
                    .filter(|&k| common[k])
                    .map(|k| (y[k] - p[k]).powi(2))
                    .sum();
                let rms = if shared > 0 {
                    (se / shared as f64).sqrt()
                } else {
                    f64::NAN
                };
                *row += &format!(",{rms},{shared}");
            }
            rows
        })
        .collect();
    let mut text =
        String::from("member,config,rms,coverage,rms_shared_arx220,arx220_rms,n,secs,plant,worst_baseline_ratio,rms_common,common_samples\n");
    for r in rows {
        text += &r;
        text += "\n";
    }
    std::fs::write(&out, text).unwrap();
    eprintln!(
        "{} configs × {} members in {:.1} s",
        configs.len(),
        members.len(),
        t.elapsed().as_secs_f64()
    );
}
