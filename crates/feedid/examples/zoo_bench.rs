//! The drive-zoo benchmark: every identification method with its
//! defaults and three simple baselines on every zoo member, 10-sample-ahead
//! (H = 10) prediction, every comparison scored on the samples both predict.
//!
//! ```sh
//! cargo run --release -p feedid --example zoo_bench                     # all 250 members
//! cargo run --release -p feedid --example zoo_bench -- --members small --csv zoo.csv
//! ```
//!
//! `--members` takes all (default), regular, even, odd, gapped, disturbed, small, a range `A..B` /
//! `A..=B` or a list `1,5,9`; `--csv FILE` writes one row per member and
//! method. The summary is printed as a Markdown table.
//!
//! Methods: `paper`, `arx`, `rls`, `oe`, `auto`, `nn` with their default windows
//! (the library, through [`run_library_methods`] alone), and the baselines,
//! written here simply and independently of the library:
//!
//! * `command`: the prediction of y\[k\] is the command u\[k\];
//! * `hold`: in blocks of 10 from sample 10 on, y\[t₀ … t₀+9\] = y\[t₀−1\];
//! * `arx220`: ARX(2,2,0), `y[k] = −a₁y[k−1] − a₂y[k−2] + b₀u[k] + b₁u[k−1]`,
//!   fitted by least squares (SVD, NumPy's `lstsq` cut-off) on the 100 samples
//!   before each block of 10 and run 10 samples ahead on the known command.
//!
//! Scoring (against the measured position; the rows of glitches are left out
//! of every score, since no method can predict a wild sample):
//!
//! * `rms`, `max` over the samples a method predicts; `coverage` = share of
//!   the samples after the method's first window (its first horizon's
//!   start) that it predicts (the CSV has the share of all samples too);
//! * `ratio` = rms of the method / rms of the best fixed method (paper, arx,
//!   rls, oe with defaults), each pair compared on the samples both predict:
//!   `max over fixed f of rms_m(S_m ∩ S_f) / rms_f(S_m ∩ S_f)` (at least 50
//!   shared samples, else the pair is skipped); 1 for the best fixed method;
//! * `loses` = the method's rms exceeds a baseline's on the samples both
//!   predict, for some baseline (a baseline against the other two);
//! * `beyond chance` = it loses, and the Diebold–Mariano test says the
//!   method's squared errors exceed the baseline's by more than chance (one-
//!   sided, 5 %; the differences summed in blocks of H samples, Newey–West
//!   long-run variance: [`dm_statistic`]). Where the best prediction is a
//!   baseline itself — an axis resting on its command, where the command is
//!   exact and every estimated model adds the noise of its estimate — a
//!   method can only tie it, and which of the two is ahead by a fraction of
//!   a percent is decided by the noise: the same predictions lose on 7 to 15
//!   members depending only on where the baselines' blocks start
//!   (`--baseline-phase`). Both counts are printed;
//! * interval coverage: the share of the scored predicted samples whose
//!   measured position lies inside the method's 95 % prediction interval
//!   (the library's default [`feedid::ident::GuardConfig`]); `n/a` for the
//!   baselines.
//!
//! `--candidates` also runs each of `auto`'s candidates alone (`auto` with
//! that one candidate) and prints `auto`'s rms against the best of them on
//! each member.
//!
//! `--baseline-phase P` (0 … 9) starts the blocks of `hold` and `arx220` `P`
//! samples later for the main table; a second table counts each library
//! method's losses at every phase. The methods' own blocks start where their first window
//! ends, so the phase decides which lead time each baseline has at each
//! sample the two share: on a short recording whose error is made in its
//! first horizons this alone moves the ratio by tens of percent (docs/RESULTS.md,
//! "The zoo benchmark").
//!
//! `--offset M` adds `M` metres to every member's command and position
//! before anything runs (a recording in machine coordinates, far from the
//! origin): the library methods that are offset-invariant predict the same
//! motion, while `arx220`, whose equations are in absolute coordinates,
//! changes (see docs/RESULTS.md, the zoo benchmark).
//!
//! `--via-unit mm|um|nm` converts every member's command and position to
//! that unit and back as the reader does with `--unit` (`v·10³`, then
//! `·10⁻³` for mm): the same recording up to the last bits, which shows how
//! far the predictions depend on them (a unit-invariant method changes
//! nothing beyond rounding).
//!
//! Members with dropped rows are read with their gaps (as by `feedid
//! identify`): every method restarts its windows after a gap, and so do the
//! baselines. They are scored apart from the regular members, in a table of
//! their own (coverage after each segment's first window, losses, and the
//! rms against the same method on the member they were cut from).
//!
//! Disturbed members (force pulses, strong friction, a coarse encoder at
//! ≤ 1 kHz: copies of regular members, [`feedid::zoo::Disturbance`]) are
//! scored like the regular ones but apart, in tables of their own, so the
//! main table stays comparable from one version to the next.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;

use feedid::ident::{engine, AutoConfig, EngineConfig, Method, Regime};
use feedid::zoo::{Zoo, ZooMember};
use feedid::Recording;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

/// `--offset`: metres added to command and position of every member.
static OFFSET: std::sync::OnceLock<f64> = std::sync::OnceLock::new();
/// `--via-unit`: metres per unit of the round trip (1 = none).
static VIA: std::sync::OnceLock<f64> = std::sync::OnceLock::new();
/// `--baseline-phase`: samples by which the baselines' blocks start later.
static PHASE: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
/// `--candidates`: also run each of `auto`'s candidates alone.
static CANDIDATES: std::sync::OnceLock<bool> = std::sync::OnceLock::new();

/// Horizon of the benchmark \[samples\].
const H: usize = 10;
/// Fewest shared samples for a pairwise comparison.
const MIN_SHARED: usize = 50;
/// The library methods, in table order.
const LIBRARY: [&str; 6] = ["paper", "arx", "rls", "oe", "auto", "nn"];
/// The fixed (non-auto) library methods.
const FIXED: [&str; 4] = ["paper", "arx", "rls", "oe"];
/// The baselines.
const BASELINES: [&str; 3] = ["command", "hold", "arx220"];

/// Predictions of one method over one recording.
struct Predictions {
    /// Method name.
    name: &'static str,
    /// Predicted position per sample \[m\] (meaningful where `has`).
    value: Vec<f64>,
    /// Whether the sample is predicted.
    has: Vec<bool>,
    /// Lower and upper 95 % interval bounds and each sample's command
    /// regime, when the method gives them.
    interval: Option<(Vec<f64>, Vec<f64>, Vec<Regime>)>,
    /// First sample the method can predict (the end of its first window).
    first: usize,
    /// Wall time \[s\].
    seconds: f64,
    /// Why the method gave nothing, if it failed.
    error: Option<String>,
}

/// Predictions, their flags, the interval bounds and the first predicted sample.
type RunOutput = (
    Vec<f64>,
    Vec<bool>,
    (Vec<f64>, Vec<f64>, Vec<Regime>),
    usize,
);

/// Every use of the identification API: the six library methods with their
/// defaults (window per method, H = 10, hop = H), as `feedid identify` runs
/// them. Keep the library calls here and nowhere else in this file.
fn run_library_methods(rec: &Recording) -> Vec<Predictions> {
    let signals = rec.signals();
    let n = rec.len();
    LIBRARY
        .iter()
        .map(|&name| {
            let t = Instant::now();
            let run = || -> feedid::Result<RunOutput> {
                let spec: Method = name.parse()?;
                let mut est = spec.build()?;
                let cfg = EngineConfig {
                    window: spec.default_window(),
                    horizon: H,
                    hop: None,
                    warm_up: 0,
                };
                let r = engine::run(&mut est, &signals, &cfg)?;
                let first = r.windows.first().map_or(n, |w| w.horizon.start);
                Ok((
                    r.predicted,
                    r.has_prediction,
                    (r.lower, r.upper, r.regimes),
                    first,
                ))
            };
            match run() {
                Ok((value, has, interval, first)) => Predictions {
                    name,
                    value,
                    has,
                    interval: Some(interval),
                    first,
                    seconds: t.elapsed().as_secs_f64(),
                    error: None,
                },
                Err(e) => Predictions {
                    name,
                    value: vec![0.0; n],
                    has: vec![false; n],
                    interval: None,
                    first: n,
                    seconds: t.elapsed().as_secs_f64(),
                    error: Some(e.to_string()),
                },
            }
        })
        .collect()
}

/// Each of `auto`'s default candidates alone (`auto` with that one
/// candidate, its default window, H = 10): their names and predictions.
fn run_auto_candidates(rec: &Recording) -> Vec<(String, Vec<f64>, Vec<bool>)> {
    let signals = rec.signals();
    AutoConfig::default_candidates()
        .into_iter()
        .filter_map(|c| {
            let name = c.to_string();
            let spec = Method::Auto(AutoConfig {
                candidates: vec![c],
                ..AutoConfig::default()
            });
            let mut est = spec.build().ok()?;
            let cfg = EngineConfig {
                window: spec.default_window(),
                horizon: H,
                hop: None,
                warm_up: 0,
            };
            let r = engine::run(&mut est, &signals, &cfg).ok()?;
            Some((name, r.predicted, r.has_prediction))
        })
        .collect()
}

/// Baseline `command`: ŷ\[k\] = u\[k\].
fn baseline_command(u: &[f64]) -> Predictions {
    Predictions {
        name: "command",
        value: u.to_vec(),
        has: vec![true; u.len()],
        interval: None,
        first: 0,
        seconds: 0.0,
        error: None,
    }
}

/// Baseline `hold`: blocks of H from sample H + `phase` on hold the last measured value.
fn baseline_hold(y: &[f64], phase: usize) -> Predictions {
    let n = y.len();
    let mut value = vec![0.0; n];
    let mut has = vec![false; n];
    let mut t0 = H + phase;
    while t0 < n {
        for k in t0..(t0 + H).min(n) {
            value[k] = y[t0 - 1];
            has[k] = true;
        }
        t0 += H;
    }
    Predictions {
        name: "hold",
        value,
        has,
        interval: None,
        first: H + phase,
        seconds: 0.0,
        error: None,
    }
}

/// Baseline `arx220`: sliding ARX(2,2,0) over 100 samples, refitted every
/// H, its first block at sample 102 + `phase`.
fn baseline_arx220(u: &[f64], y: &[f64], phase: usize) -> Predictions {
    const W: usize = 100;
    let t = Instant::now();
    let n = y.len();
    let mut value = vec![0.0; n];
    let mut has = vec![false; n];
    let mut t0 = W + 2 + phase;
    while t0 < n {
        // equations k = t0 − W … t0 − 1: y[k] = [−y[k−1], −y[k−2], u[k], u[k−1]]·θ
        let a = DMatrix::from_fn(W, 4, |i, j| {
            let k = t0 - W + i;
            match j {
                0 => -y[k - 1],
                1 => -y[k - 2],
                2 => u[k],
                _ => u[k - 1],
            }
        });
        let b = DVector::from_fn(W, |i, _| y[t0 - W + i]);
        let svd = a.svd(true, true);
        let cutoff = svd.singular_values.max() * f64::EPSILON * W as f64;
        if let Ok(theta) = svd.solve(&b, cutoff) {
            let (mut y1, mut y2) = (y[t0 - 1], y[t0 - 2]);
            let end = (t0 + H).min(n);
            let mut block = Vec::with_capacity(H);
            for k in t0..end {
                let p = -theta[0] * y1 - theta[1] * y2 + theta[2] * u[k] + theta[3] * u[k - 1];
                block.push(p);
                y2 = y1;
                y1 = p;
            }
            if block.iter().all(|v| v.is_finite()) {
                for (k, p) in (t0..end).zip(block) {
                    value[k] = p;
                    has[k] = true;
                }
            }
        }
        t0 += H;
    }
    Predictions {
        name: "arx220",
        value,
        has,
        interval: None,
        first: W + 2 + phase,
        seconds: t.elapsed().as_secs_f64(),
        error: None,
    }
}

/// A baseline run on each segment between gaps on its own (`f(u, y)` of
/// the segment), stitched into the recording's samples.
fn per_segment(
    segments: &[std::ops::Range<usize>],
    name: &'static str,
    f: impl Fn(&[f64], &[f64]) -> Predictions,
    u: &[f64],
    y: &[f64],
) -> Predictions {
    let n = y.len();
    let mut out = Predictions {
        name,
        value: vec![0.0; n],
        has: vec![false; n],
        interval: None,
        first: n,
        seconds: 0.0,
        error: None,
    };
    for r in segments {
        let p = f(&u[r.clone()], &y[r.clone()]);
        out.value[r.clone()].copy_from_slice(&p.value);
        out.has[r.clone()].copy_from_slice(&p.has);
        out.first = out.first.min(r.start + p.first);
        out.seconds += p.seconds;
    }
    out
}

/// Share of the samples after the method's first window in each segment
/// between gaps (the first window's length counted from the segment's
/// start) that the method predicts \[%\].
fn coverage_after(p: &Predictions, segments: &[std::ops::Range<usize>]) -> f64 {
    let (mut predicted, mut total) = (0usize, 0usize);
    for r in segments {
        let from = (r.start + p.first).min(r.end);
        total += r.end - from;
        predicted += p.has[from..r.end].iter().filter(|&&h| h).count();
    }
    100.0 * predicted as f64 / total.max(1) as f64
}

/// rms and max of `y − ŷ` over the samples where `mask` holds.
fn stats(y: &[f64], p: &Predictions, mask: impl Fn(usize) -> bool) -> Option<(f64, f64, usize)> {
    let (mut sse, mut max, mut n) = (0.0, 0.0f64, 0usize);
    for (k, (&yk, &pk)) in y.iter().zip(&p.value).enumerate() {
        if p.has[k] && mask(k) {
            let e = yk - pk;
            sse += e * e;
            max = max.max(e.abs());
            n += 1;
        }
    }
    (n > 0).then(|| ((sse / n as f64).sqrt(), max, n))
}

/// rms of `a` and of `b` over the samples both predict (and `scored`).
fn shared_rms(y: &[f64], a: &Predictions, b: &Predictions, scored: &[bool]) -> Option<(f64, f64)> {
    let both = |k: usize| scored[k] && a.has[k] && b.has[k];
    let ra = stats(y, a, both)?;
    let rb = stats(y, b, both)?;
    (ra.2 >= MIN_SHARED).then_some((ra.0, rb.0))
}

/// One-sided 5 % critical value of the standard normal distribution.
const Z_95: f64 = 1.6448536269514722;
/// Fewest blocks of `H` samples for a significance test (with fewer, a loss
/// counts as significant).
const MIN_BLOCKS: usize = 10;

/// The Diebold–Mariano statistic of "`a` predicts worse than `b`" over the
/// samples both predict (and `scored`): the loss differential
/// `d[k] = (y[k] − a[k])² − (y[k] − b[k])²` summed in blocks of `H`
/// consecutive samples (`k / H`: a horizon's errors are correlated), its
/// mean over the blocks divided by its standard error from the Newey–West
/// (Bartlett) long-run variance with `⌊4·(n/100)^(2/9)⌋` lags (n blocks).
/// Large and positive: `a` is worse beyond chance. `None` with fewer than
/// [`MIN_BLOCKS`] blocks; `+∞` when every block differs alike (no variance).
/// Diebold, F. X. & Mariano, R. S. (1995), *Comparing predictive accuracy*,
/// J. Business & Economic Statistics 13(3).
fn dm_statistic(y: &[f64], a: &Predictions, b: &Predictions, scored: &[bool]) -> Option<f64> {
    let mut blocks: Vec<f64> = Vec::new();
    let mut current: Option<usize> = None;
    for k in 0..y.len() {
        if !(scored[k] && a.has[k] && b.has[k]) {
            continue;
        }
        let d = (y[k] - a.value[k]).powi(2) - (y[k] - b.value[k]).powi(2);
        if current == Some(k / H) {
            if let Some(last) = blocks.last_mut() {
                *last += d;
            }
        } else {
            current = Some(k / H);
            blocks.push(d);
        }
    }
    let n = blocks.len();
    if n < MIN_BLOCKS {
        return None;
    }
    let mean = blocks.iter().sum::<f64>() / n as f64;
    let c: Vec<f64> = blocks.iter().map(|d| d - mean).collect();
    let lags = (4.0 * (n as f64 / 100.0).powf(2.0 / 9.0)).floor() as usize;
    let gamma = |l: usize| c[l..].iter().zip(&c).map(|(x, y)| x * y).sum::<f64>() / n as f64;
    let mut lrv = gamma(0);
    for l in 1..=lags.min(n - 1) {
        lrv += 2.0 * (1.0 - l as f64 / (lags + 1) as f64) * gamma(l);
    }
    if lrv.is_nan() || lrv <= 0.0 {
        return Some(if mean > 0.0 { f64::INFINITY } else { 0.0 });
    }
    Some(mean / (lrv / n as f64).sqrt())
}

/// Whether `a` loses to `b` beyond chance: its rms on the shared samples is
/// larger and the Diebold–Mariano statistic exceeds the one-sided 5 %
/// critical value (or there are too few blocks to test).
fn loses_significantly(y: &[f64], a: &Predictions, b: &Predictions, scored: &[bool]) -> bool {
    shared_rms(y, a, b, scored).is_some_and(|(x, r)| x > r)
        && dm_statistic(y, a, b, scored).is_none_or(|t| t > Z_95)
}

/// One method on one member.
/// Fewest scored samples of a command regime for its coverage to count.
const MIN_REGIME: usize = 200;

/// The regime with at least [`MIN_REGIME`] scored samples whose coverage
/// is lowest on a row, and that coverage \[%\].
fn worst_regime(r: &Row) -> Option<(Regime, f64)> {
    Regime::ALL
        .iter()
        .zip(r.by_regime.iter())
        .filter(|(_, &(total, _))| total >= MIN_REGIME)
        .map(|(&g, &(total, inside))| (g, 100.0 * inside as f64 / total as f64))
        .min_by(|a, b| a.1.total_cmp(&b.1))
}

#[derive(Clone)]
struct Row {
    member: usize,
    label: String,
    /// The disturbance of a disturbed member (`pulses`, `friction`, `encoder`).
    disturbance: Option<&'static str>,
    plant: &'static str,
    command: &'static str,
    method: &'static str,
    samples: usize,
    predicted: usize,
    rms: Option<f64>,
    max: Option<f64>,
    coverage: f64,
    /// Share of the samples after the method's first window that it predicts \[%\].
    coverage_after: f64,
    ratio: Option<f64>,
    beaten_by: Option<&'static str>,
    baseline_ratio: Option<f64>,
    interval_coverage: Option<f64>,
    /// Median half-width of the intervals over the rms error, on the same
    /// scored samples (1.96 for Gaussian errors of a constant spread).
    width_ratio: Option<f64>,
    /// Scored samples and of them inside their interval, per command regime.
    by_regime: [(usize, usize); 5],
    /// At the samples of a start of motion: the squared errors of the method
    /// and of the hold baseline, and their number.
    starts: (f64, f64, usize),
    /// The same at the first start of the recording (the command's first
    /// motion and the 2H samples after it): nothing has moved before.
    first_starts: (f64, f64, usize),
    /// `auto` only, with `--candidates`: its rms over that of its best
    /// candidate alone (each pair on the samples both predict; the largest
    /// ratio over the candidates) and that candidate's name.
    candidate_ratio: Option<(f64, String)>,
    seconds: f64,
    note: String,
    /// Gaps of dropped samples in the member (0 for a regular one).
    gaps: usize,
    /// With dropped rows: rms over the samples this method predicts both
    /// here and on the member without the gaps, divided by the rms of its
    /// predictions there on the same samples.
    gap_cost: Option<f64>,
    /// Whether it loses to a baseline when the baselines' blocks start
    /// `q` = 0 … H − 1 samples later (library methods only).
    loses_by_phase: [bool; H],
    /// The same, beyond chance ([`loses_significantly`]).
    significant_by_phase: [bool; H],
    /// Whether it loses to a baseline beyond chance (at `--baseline-phase`).
    significant: bool,
}

/// Score every method on one member.
fn score(m: &ZooMember, zoo: &Zoo) -> Vec<Row> {
    let s = &m.spec;
    let base = Row {
        member: s.index,
        label: s.label.clone(),
        disturbance: s.disturbed.map(|d| d.disturbance.name()),
        plant: s.plant.name(),
        command: s.command.name(),
        method: "",
        samples: m.len(),
        predicted: 0,
        rms: None,
        max: None,
        coverage: 0.0,
        coverage_after: 0.0,
        ratio: None,
        beaten_by: None,
        baseline_ratio: None,
        interval_coverage: None,
        width_ratio: None,
        by_regime: [(0, 0); 5],
        starts: (0.0, 0.0, 0),
        first_starts: (0.0, 0.0, 0),
        candidate_ratio: None,
        seconds: 0.0,
        note: String::new(),
        gaps: 0,
        gap_cost: None,
        loses_by_phase: [false; H],
        significant_by_phase: [false; H],
        significant: false,
    };
    let rec = match m.recording_with_gaps() {
        Ok(r) => r,
        Err(e) => {
            return LIBRARY
                .iter()
                .chain(&BASELINES)
                .map(|&method| Row {
                    method,
                    note: format!("refused: {e}"),
                    ..base.clone()
                })
                .collect()
        }
    };
    let offset = OFFSET.get().copied().unwrap_or(0.0);
    let via = VIA.get().copied().unwrap_or(1.0);
    // written in the unit (× 1/f, an exact power of ten), read back (× f)
    let shift = |v: &[f64]| {
        v.iter()
            .map(|x| (x + offset) * (1.0 / via) * via)
            .collect::<Vec<f64>>()
    };
    let (u, y) = (&shift(&m.command), &shift(&m.position));
    let rec = if offset == 0.0 && via == 1.0 {
        rec
    } else {
        match Recording::allowing_gaps(rec.time().to_vec(), u.clone(), y.clone(), 0.01) {
            Ok(r) => r,
            Err(e) => panic!("member {}: shifted recording: {e}", s.index),
        }
    };
    let segments = rec.segments();
    let base = Row {
        gaps: rec.gaps().len(),
        ..base
    };
    let mut all = run_library_methods(&rec);
    let candidates = if CANDIDATES.get().copied().unwrap_or(false) && rec.gaps().is_empty() {
        run_auto_candidates(&rec)
    } else {
        Vec::new()
    };
    // the same methods on the member the rows were dropped from, for the cost
    // of the gaps on the samples both predict
    let without_gaps: Option<(Vec<Predictions>, Vec<usize>)> = s.gap_source.and_then(|src| {
        let full = zoo.member(src).ok()?;
        let rec = Recording::new(
            full.time.clone(),
            shift(&full.command),
            shift(&full.position),
        )
        .ok()?;
        let kept = (0..full.len())
            .filter(|k| !s.dropped_rows.contains(k))
            .collect();
        Some((run_library_methods(&rec), kept))
    });
    all.push(baseline_command(u));
    let phase = PHASE.get().copied().unwrap_or(0);
    // the baselines restart after a gap, as the methods do
    let hold = |q: usize| per_segment(&segments, "hold", |_, y| baseline_hold(y, q), u, y);
    let arx220 = |q: usize| per_segment(&segments, "arx220", |u, y| baseline_arx220(u, y, q), u, y);
    all.push(hold(phase));
    all.push(arx220(phase));
    let n = y.len();
    let mut scored = vec![true; n];
    for g in &s.glitches {
        scored[g.index] = false;
    }
    let by_name: BTreeMap<&str, &Predictions> = all.iter().map(|p| (p.name, p)).collect();
    // the baselines at every phase of their blocks (command has none)
    let phased: Vec<[Predictions; 2]> = (0..H).map(|q| [hold(q), arx220(q)]).collect();
    let loses_to = |p: &Predictions, b: &Predictions| {
        // (as the table: a baseline without error beats any error)
        shared_rms(y, p, b, &scored).is_some_and(|(a, r)| a > r)
    };
    let significantly = |p: &Predictions, b: &Predictions| loses_significantly(y, p, b, &scored);
    all.iter()
        .map(|p| {
            let own = stats(y, p, |k| scored[k]);
            let predicted = p.has.iter().filter(|&&h| h).count();
            // ratio to the best fixed method, pairwise on shared samples
            let ratio = FIXED
                .iter()
                .filter_map(|f| shared_rms(y, p, by_name[f], &scored))
                .map(|(a, b)| a / b)
                .filter(|r| r.is_finite())
                .fold(None, |acc: Option<f64>, r| {
                    Some(acc.map_or(r, |a| a.max(r)))
                });
            // the baseline that beats it most, pairwise on shared samples
            let mut worst: Option<(&'static str, f64)> = None;
            for b in BASELINES.iter().filter(|&&b| b != p.name) {
                if let Some((a, r)) = shared_rms(y, p, by_name[b], &scored) {
                    let q = a / r;
                    if !q.is_nan() && worst.is_none_or(|(_, w)| q > w) {
                        worst = Some((b, q));
                    }
                }
            }
            let mut by_regime = [(0usize, 0usize); 5];
            // at starts of motion: squared errors of the method and of holding
            // (the hold baseline) on the same samples
            let mut starts = (0.0, 0.0, 0usize);
            let mut first_starts = (0.0, 0.0, 0usize);
            let hold = by_name["hold"];
            // the command's first motion (a step of more than 1.83 % of its
            // largest): the start samples up to 2H after it are the first start
            let u = &m.command;
            let top = u
                .windows(2)
                .map(|w| (w[1] - w[0]).abs())
                .fold(0.0, f64::max);
            let first_move = u
                .windows(2)
                .position(|w| (w[1] - w[0]).abs() > 0.0183 * top)
                .map_or(n, |k| k + 1);
            let mut width_ratio = None;
            let interval_coverage = p.interval.as_ref().map(|(lo, hi, regime)| {
                let (mut inside, mut total) = (0usize, 0usize);
                let (mut half, mut squares) = (Vec::new(), 0.0);
                for k in 0..n {
                    if p.has[k] && scored[k] {
                        total += 1;
                        half.push(0.5 * (hi[k] - lo[k]));
                        squares += (y[k] - p.value[k]).powi(2);
                        let i = usize::from(lo[k] <= y[k] && y[k] <= hi[k]);
                        inside += i;
                        let r = &mut by_regime[regime[k].index()];
                        r.0 += 1;
                        r.1 += i;
                        if regime[k] == Regime::Start && hold.has[k] {
                            starts.0 += (y[k] - p.value[k]).powi(2);
                            starts.1 += (y[k] - hold.value[k]).powi(2);
                            starts.2 += 1;
                            if k < first_move + 2 * H {
                                first_starts.0 += (y[k] - p.value[k]).powi(2);
                                first_starts.1 += (y[k] - hold.value[k]).powi(2);
                                first_starts.2 += 1;
                            }
                        }
                    }
                }
                let rms = (squares / total.max(1) as f64).sqrt();
                width_ratio = quantile(&half, 0.5)
                    .map(|w| w / rms)
                    .filter(|q| q.is_finite());
                100.0 * inside as f64 / total.max(1) as f64
            });
            Row {
                method: p.name,
                predicted,
                rms: own.map(|o| o.0),
                max: own.map(|o| o.1),
                coverage: 100.0 * predicted as f64 / n as f64,
                coverage_after: coverage_after(p, &segments),
                ratio,
                beaten_by: worst.filter(|w| w.1 > 1.0).map(|w| w.0),
                baseline_ratio: worst.map(|w| w.1),
                interval_coverage,
                width_ratio,
                by_regime,
                starts,
                first_starts,
                candidate_ratio: (p.name == "auto" && !candidates.is_empty())
                    .then(|| {
                        candidates
                            .iter()
                            .filter_map(|(name, value, has)| {
                                let c = Predictions {
                                    name: "candidate",
                                    value: value.clone(),
                                    has: has.clone(),
                                    interval: None,
                                    first: 0,
                                    seconds: 0.0,
                                    error: None,
                                };
                                let (a, b) = shared_rms(y, p, &c, &scored)?;
                                Some((a / b, name.clone()))
                            })
                            .filter(|(q, _)| q.is_finite())
                            .max_by(|a, b| a.0.total_cmp(&b.0))
                    })
                    .flatten(),
                gap_cost: without_gaps.as_ref().and_then(|(full, kept)| {
                    let q = full.iter().find(|q| q.name == p.name)?;
                    let (mut a, mut b, mut n_shared) = (0.0, 0.0, 0usize);
                    for (j, &k) in kept.iter().enumerate() {
                        if p.has[j] && q.has[k] && scored[j] {
                            a += (y[j] - p.value[j]).powi(2);
                            b += (y[j] - q.value[k]).powi(2);
                            n_shared += 1;
                        }
                    }
                    (n_shared >= MIN_SHARED && b > 0.0).then(|| (a / b).sqrt())
                }),
                seconds: p.seconds,
                note: p.error.clone().unwrap_or_default(),
                loses_by_phase: std::array::from_fn(|q| {
                    LIBRARY.contains(&p.name)
                        && (loses_to(p, by_name["command"])
                            || phased[q].iter().any(|b| loses_to(p, b)))
                }),
                significant_by_phase: std::array::from_fn(|q| {
                    LIBRARY.contains(&p.name)
                        && (significantly(p, by_name["command"])
                            || phased[q].iter().any(|b| significantly(p, b)))
                }),
                significant: BASELINES
                    .iter()
                    .filter(|&&b| b != p.name)
                    .any(|b| significantly(p, by_name[b])),
                ..base.clone()
            }
        })
        .collect()
}

/// The q-quantile (0 … 1) of `v` (linear interpolation), `None` if empty.
fn quantile(v: &[f64], q: f64) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let x = q * (s.len() - 1) as f64;
    let (i, f) = (x.floor() as usize, x.fract());
    Some(if i + 1 < s.len() {
        s[i] * (1.0 - f) + s[i + 1] * f
    } else {
        s[i]
    })
}

fn fmt(v: Option<f64>, digits: usize) -> String {
    v.map_or("n/a".to_string(), |x| format!("{x:.digits$}"))
}

fn parse_members(s: &str, zoo: &Zoo) -> Result<Vec<usize>, String> {
    let n = zoo.len();
    let bad = || {
        format!(
            "invalid --members `{s}` (all, regular, even, odd, gapped, disturbed, small, A..B, A..=B, 1,5,9)"
        )
    };
    let v: Vec<usize> = match s {
        "all" => (0..n).collect(),
        "regular" => zoo.regular().collect(),
        "even" => zoo.regular().filter(|i| i % 2 == 0).collect(),
        "odd" => zoo.regular().filter(|i| i % 2 == 1).collect(),
        "gapped" => zoo.gapped().collect(),
        "disturbed" => zoo.disturbed().collect(),
        "small" => zoo.small().collect(),
        _ if s.contains("..") => {
            let (a, b) = s.split_once("..").ok_or_else(bad)?;
            let a: usize = a.parse().map_err(|_| bad())?;
            let b: usize = match b.strip_prefix('=') {
                Some(b) => b.parse::<usize>().map_err(|_| bad())? + 1,
                None => b.parse().map_err(|_| bad())?,
            };
            (a..b.min(n)).collect()
        }
        _ => s
            .split(',')
            .map(|x| x.trim().parse().map_err(|_| bad()))
            .collect::<Result<_, _>>()?,
    };
    if v.is_empty() || v.iter().any(|&i| i >= n) {
        return Err(bad());
    }
    Ok(v)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let zoo = Zoo::standard();
    let mut members = (0..zoo.len()).collect::<Vec<_>>();
    let mut csv: Option<PathBuf> = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--members" => members = parse_members(&args.next().unwrap_or_default(), &zoo)?,
            "--csv" => csv = args.next().map(PathBuf::from),
            "--candidates" => CANDIDATES
                .set(true)
                .map_err(|_| "--candidates given twice")?,
            "--offset" => {
                let v: f64 = args
                    .next()
                    .unwrap_or_default()
                    .parse()
                    .map_err(|e| format!("--offset: {e} (metres)"))?;
                OFFSET.set(v).map_err(|_| "--offset given twice")?;
            }
            "--via-unit" => {
                let f = match args.next().unwrap_or_default().as_str() {
                    "mm" => 1e-3,
                    "um" => 1e-6,
                    "nm" => 1e-9,
                    other => return Err(format!("--via-unit `{other}`: mm, um or nm").into()),
                };
                VIA.set(f).map_err(|_| "--via-unit given twice")?;
            }
            "--baseline-phase" => {
                let v: usize = args
                    .next()
                    .unwrap_or_default()
                    .parse()
                    .map_err(|e| format!("--baseline-phase: {e} (0 … {})", H - 1))?;
                if v >= H {
                    return Err(format!("--baseline-phase {v}: 0 … {}", H - 1).into());
                }
                PHASE.set(v).map_err(|_| "--baseline-phase given twice")?;
            }
            _ => {
                return Err(format!(
                    "unknown argument `{a}` (--members SET, --csv FILE, --offset METRES, \
                     --via-unit mm|um|nm, --baseline-phase P, --candidates)"
                )
                .into())
            }
        }
    }
    let t = Instant::now();
    let rows: Vec<Row> = members
        .par_iter()
        .map(|&i| zoo.member(i).map(|m| score(&m, &zoo)))
        .collect::<feedid::Result<Vec<_>>>()?
        .into_iter()
        .flatten()
        .collect();
    let wall = t.elapsed().as_secs_f64();

    if let Some(path) = &csv {
        let mut text = String::from(
            "member,method,plant,command,samples,predicted,coverage_percent,\
             coverage_after_first_window_percent,rms_m,max_m,ratio_to_best_fixed,beaten_by_baseline,worst_baseline_ratio,loses_significantly,interval_coverage_percent,\
             worst_regime,worst_regime_coverage_percent,seconds,note,disturbance,candidate_ratio,candidate,label\n",
        );
        for r in &rows {
            let worst = worst_regime(r);
            text += &format!(
                "{},{},{},{},{},{},{:.3},{:.3},{},{},{},{},{},{},{},{},{},{:.6},\"{}\",{},{},\"{}\",\"{}\"\n",
                r.member,
                r.method,
                r.plant,
                r.command,
                r.samples,
                r.predicted,
                r.coverage,
                r.coverage_after,
                r.rms.map_or(String::new(), |v| v.to_string()),
                r.max.map_or(String::new(), |v| v.to_string()),
                r.ratio.map_or(String::new(), |v| v.to_string()),
                r.beaten_by.unwrap_or(""),
                r.baseline_ratio.map_or(String::new(), |v| v.to_string()),
                u8::from(r.significant),
                fmt(r.interval_coverage, 2),
                worst.map_or("", |w| w.0.name()),
                fmt(worst.map(|w| w.1), 2),
                r.seconds,
                r.note.replace('"', "'"),
                r.disturbance.unwrap_or(""),
                r.candidate_ratio
                    .as_ref()
                    .map_or(String::new(), |c| c.0.to_string()),
                r.candidate_ratio.as_ref().map_or("", |c| c.1.as_str()),
                r.label.replace('"', "'")
            );
        }
        std::fs::write(path, text)?;
        eprintln!("{}: {} rows", path.display(), rows.len());
    }

    let scored: Vec<&Row> = rows
        .iter()
        .filter(|r| !r.note.starts_with("refused") && r.gaps == 0 && r.disturbance.is_none())
        .collect();
    let disturbed: Vec<&Row> = rows
        .iter()
        .filter(|r| !r.note.starts_with("refused") && r.disturbance.is_some())
        .collect();
    let gapped: Vec<&Row> = rows
        .iter()
        .filter(|r| !r.note.starts_with("refused") && r.gaps > 0)
        .collect();
    let recordings = scored
        .iter()
        .map(|r| r.member)
        .collect::<std::collections::BTreeSet<_>>();
    let refused = rows
        .iter()
        .filter(|r| r.note.starts_with("refused"))
        .map(|r| r.member)
        .collect::<std::collections::BTreeSet<_>>();
    let gapped_members = gapped
        .iter()
        .map(|r| r.member)
        .collect::<std::collections::BTreeSet<_>>();
    let disturbed_members = disturbed
        .iter()
        .map(|r| r.member)
        .collect::<std::collections::BTreeSet<_>>();
    println!(
        "Drive zoo benchmark: {} recordings scored (and {} with dropped rows and {} disturbed, apart below; {} refused by the reader), H = {H}, {:.1} s wall on {} threads\n",
        recordings.len(),
        gapped_members.len(),
        disturbed_members.len(),
        refused.len(),
        wall,
        rayon::current_num_threads()
    );
    main_table(&scored);
    println!(
        "\nPrediction intervals and largest errors: members whose 95 % interval coverage is \
         within [90, 98] %; (member, command regime) pairs with ≥ {MIN_REGIME} scored samples \
         and of them those below 80 %; the median over the members of the median interval \
         half-width over the rms error on the same samples (1.96 for Gaussian errors of one \
         spread; lower where the intervals are tight at rest and wide where the errors are); \
         members whose largest error is at most 1.5× the hold's on the same member:\n"
    );
    interval_table(&scored);
    candidate_table(&scored);
    // the same count for every phase of the baselines' blocks
    println!(
        "\nRecordings where each library method loses to a baseline when the baselines' blocks \
         start 0 … {} samples later (`--baseline-phase`; the table above: phase {}):\n",
        H - 1,
        PHASE.get().copied().unwrap_or(0)
    );
    println!(
        "| method | {} | median |",
        (0..H)
            .map(|q| q.to_string())
            .collect::<Vec<_>>()
            .join(" | ")
    );
    println!("|---|{}---:|", "---:|".repeat(H));
    for (method, significant) in LIBRARY
        .iter()
        .map(|m| (m, false))
        .chain(LIBRARY.iter().map(|m| (m, true)))
    {
        let counts: Vec<f64> = (0..H)
            .map(|q| {
                scored
                    .iter()
                    .filter(|r| {
                        r.method == *method
                            && if significant {
                                r.significant_by_phase[q]
                            } else {
                                r.loses_by_phase[q]
                            }
                    })
                    .count() as f64
            })
            .collect();
        let method = if significant {
            format!("{method}, beyond chance")
        } else {
            method.to_string()
        };
        println!(
            "| {method} | {} | {} |",
            counts
                .iter()
                .map(|c| c.to_string())
                .collect::<Vec<_>>()
                .join(" | "),
            fmt(quantile(&counts, 0.5), 1)
        );
    }
    // where the library methods lose to the baselines, by command and plant
    println!("\nRecordings where each library method loses to a baseline, by command:\n");
    let commands = [
        "ramp", "step", "scurve", "sweep", "square", "p2p", "contour",
    ];
    println!("| method | {} |", commands.join(" | "));
    println!("|---|{}", "---:|".repeat(commands.len()));
    for method in LIBRARY {
        let cells: Vec<String> = commands
            .iter()
            .map(|c| {
                let of: Vec<&&Row> = scored
                    .iter()
                    .filter(|r| r.method == method && r.command == *c)
                    .collect();
                format!(
                    "{} / {}",
                    of.iter().filter(|r| r.beaten_by.is_some()).count(),
                    of.len()
                )
            })
            .collect();
        println!("| {method} | {} |", cells.join(" | "));
    }
    let plants = [
        "rig-heavy",
        "rig-conventional",
        "rig-stiff",
        "first-order",
        "second-order",
    ];
    println!("\nBy plant:\n");
    println!("| method | {} |", plants.join(" | "));
    println!("|---|{}", "---:|".repeat(plants.len()));
    for method in LIBRARY {
        let cells: Vec<String> = plants
            .iter()
            .map(|pl| {
                let of: Vec<&&Row> = scored
                    .iter()
                    .filter(|r| r.method == method && r.plant == *pl)
                    .collect();
                format!(
                    "{} / {}",
                    of.iter().filter(|r| r.beaten_by.is_some()).count(),
                    of.len()
                )
            })
            .collect();
        println!("| {method} | {} |", cells.join(" | "));
    }
    if !gapped.is_empty() {
        gapped_table(&gapped);
    }
    if !disturbed.is_empty() {
        let kinds = ["pulses", "friction", "encoder"];
        let count = |k: &str| {
            disturbed_members
                .iter()
                .filter(|&&m| {
                    disturbed
                        .iter()
                        .any(|r| r.member == m && r.disturbance == Some(k))
                })
                .count()
        };
        println!(
            "\nDisturbed members ({} force pulses, {} strong friction, {} coarse encoder at \
             ≤ 1 kHz; each a copy of a regular member, see `feedid zoo --list --members disturbed`):\n",
            count(kinds[0]),
            count(kinds[1]),
            count(kinds[2])
        );
        main_table(&disturbed);
        println!();
        interval_table(&disturbed);
    }
    println!(
        "\ncompared: recordings where the method shares ≥ {MIN_SHARED} predicted samples with a \
         fixed method; ratio: rms of the method / rms of the best fixed method (paper, arx, rls, oe \
         with defaults), each pair on the samples both predict; loses: its rms exceeds a baseline's \
         (command, hold, arx220) on the samples both predict (a recording it does not predict is \
         not a loss: see coverage); beyond chance: and the Diebold–Mariano statistic of the squared \
         errors (blocks of {H} samples, Newey–West variance) exceeds the one-sided 5 % critical \
         value {Z_95:.3}; own rms: over the method's own predicted samples. Glitch rows \
         are not scored. Coverage: share of the samples after the method's first window that it \
         predicts. Interval coverage: share of the scored predicted samples inside the method's 95 % \
         prediction interval (median over the recordings)."
    );
    Ok(())
}

/// The members with dropped rows: what the gaps cost each method.
/// The main table: ratios to the best fixed method, losses, coverage, intervals.
fn main_table(scored: &[&Row]) {
    println!("| method | compared | median rms / best fixed | 90th pct rms / best fixed | loses to a baseline | of which beyond chance | coverage after the first window, min / median [%] | median own rms [µm] | failed | 95 % interval coverage |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for method in LIBRARY.iter().chain(&BASELINES) {
        let mine: Vec<&&Row> = scored.iter().filter(|r| r.method == *method).collect();
        let ratios: Vec<f64> = mine.iter().filter_map(|r| r.ratio).collect();
        let losses = mine.iter().filter(|r| r.beaten_by.is_some()).count();
        let significant = mine.iter().filter(|r| r.significant).count();
        let cov: Vec<f64> = mine.iter().map(|r| r.coverage_after).collect();
        let rms: Vec<f64> = mine.iter().filter_map(|r| r.rms).map(|v| v * 1e6).collect();
        let failed = mine.iter().filter(|r| !r.note.is_empty()).count();
        let intervals: Vec<f64> = mine.iter().filter_map(|r| r.interval_coverage).collect();
        println!(
            "| {method} | {} | {} | {} | {losses} of {} | {significant} | {} / {} | {} | {failed} | {} |",
            ratios.len(),
            fmt(quantile(&ratios, 0.5), 2),
            fmt(quantile(&ratios, 0.9), 2),
            mine.len(),
            fmt(quantile(&cov, 0.0), 1),
            fmt(quantile(&cov, 0.5), 1),
            fmt(quantile(&rms, 0.5), 3),
            fmt(quantile(&intervals, 0.5), 1),
        );
    }
}

/// `auto` against its best candidate alone (`--candidates`).
fn candidate_table(scored: &[&Row]) {
    let ratios: Vec<(f64, &str, usize)> = scored
        .iter()
        .filter(|r| r.method == "auto")
        .filter_map(|r| {
            r.candidate_ratio
                .as_ref()
                .map(|(q, n)| (*q, n.as_str(), r.member))
        })
        .collect();
    if ratios.is_empty() {
        return;
    }
    let q: Vec<f64> = ratios.iter().map(|r| r.0).collect();
    let within = q.iter().filter(|&&v| v <= 1.2).count();
    let worst = ratios
        .iter()
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map_or(String::new(), |w| {
            format!("{:.2} (member {}, {})", w.0, w.2, w.1)
        });
    println!(
        "\n`auto` against each of its candidates alone (`--candidates`; rms of auto / rms of the \
         candidate on the samples both predict, the largest over the candidates):\n"
    );
    println!("| members | auto within 1.2× its best candidate | median | 90th pct | worst |");
    println!("|---:|---:|---:|---:|---|");
    println!(
        "| {} | {within} | {} | {} | {worst} |",
        q.len(),
        fmt(quantile(&q, 0.5), 3),
        fmt(quantile(&q, 0.9), 3)
    );
}

/// Intervals and largest errors: coverage per member and per regime, the
/// largest error against the hold's, the starts of motion.
fn interval_table(scored: &[&Row]) {
    println!("| method | coverage within [90, 98] % | regimes with ≥ {MIN_REGIME} samples | of which below 80 % | worst regime coverage [%] | median half-width / rms, median | largest error ≤ 1.5× hold's | worst ratio to hold's | members with starts of motion (of them above the hold's rms there) | at starts: rms / hold's, median | first starts: members (above the hold's) | first starts: rms / hold's, median |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for method in LIBRARY {
        let mine: Vec<&&Row> = scored.iter().filter(|r| r.method == method).collect();
        let widths: Vec<f64> = mine.iter().filter_map(|r| r.width_ratio).collect();
        let within = mine
            .iter()
            .filter(|r| {
                r.interval_coverage
                    .is_some_and(|c| (90.0..=98.0).contains(&c))
            })
            .count();
        let pairs: Vec<f64> = mine
            .iter()
            .flat_map(|r| r.by_regime.iter())
            .filter(|(n, _)| *n >= MIN_REGIME)
            .map(|(n, i)| 100.0 * *i as f64 / *n as f64)
            .collect();
        let below = pairs.iter().filter(|&&c| c < 80.0).count();
        let worst_regime = pairs.iter().copied().fold(f64::INFINITY, f64::min);
        let ratios: Vec<f64> = mine
            .iter()
            .filter_map(|r| {
                let hold = scored
                    .iter()
                    .find(|h| h.method == "hold" && h.member == r.member)?;
                Some(r.max? / hold.max?)
            })
            .filter(|q| q.is_finite())
            .collect();
        let bounded = ratios.iter().filter(|&&q| q <= 1.5).count();
        // members with start-of-motion samples: the method's rms there
        // against holding's on the same samples
        let start_ratios: Vec<f64> = mine
            .iter()
            .filter(|r| r.starts.2 > 0 && r.starts.1 > 0.0)
            .map(|r| (r.starts.0 / r.starts.1).sqrt())
            .collect();
        let above = start_ratios.iter().filter(|&&q| q > 1.0).count();
        let first_ratios: Vec<f64> = mine
            .iter()
            .filter(|r| r.first_starts.2 > 0 && r.first_starts.1 > 0.0)
            .map(|r| (r.first_starts.0 / r.first_starts.1).sqrt())
            .collect();
        let first_above = first_ratios.iter().filter(|&&q| q > 1.0).count();
        println!(
            "| {method} | {within} of {} | {} | {below} | {} | {} | {bounded} of {} | {} | {} ({above}) | {} | {} ({first_above}) | {} |",
            mine.len(),
            pairs.len(),
            if worst_regime.is_finite() {
                format!("{worst_regime:.1}")
            } else {
                "–".into()
            },
            fmt(quantile(&widths, 0.5), 2),
            ratios.len(),
            fmt(
                ratios
                    .iter()
                    .copied()
                    .fold(None, |a: Option<f64>, q| Some(a.map_or(q, |a| a.max(q)))),
                2
            ),
            start_ratios.len(),
            fmt(quantile(&start_ratios, 0.5), 3),
            first_ratios.len(),
            fmt(quantile(&first_ratios, 0.5), 3),
        );
    }
}

fn gapped_table(gapped: &[&Row]) {
    println!(
        "\nMembers with dropped rows ({}): every method and baseline restarts its windows \
         after each gap.\n",
        gapped
            .iter()
            .map(|r| r.member)
            .collect::<std::collections::BTreeSet<_>>()
            .len()
    );
    println!("| method | coverage, min / median [%] | coverage after each segment's first window, min / median [%] | loses to a baseline | rms / rms on the member without the gaps, same samples, median / max |");
    println!("|---|---:|---:|---:|---:|");
    for method in LIBRARY {
        let mine: Vec<&&Row> = gapped.iter().filter(|r| r.method == method).collect();
        let cov: Vec<f64> = mine.iter().map(|r| r.coverage).collect();
        let after: Vec<f64> = mine.iter().map(|r| r.coverage_after).collect();
        let losses = mine.iter().filter(|r| r.beaten_by.is_some()).count();
        let significant = mine.iter().filter(|r| r.significant).count();
        let cost: Vec<f64> = mine
            .iter()
            .filter_map(|r| r.gap_cost)
            .filter(|v| v.is_finite())
            .collect();
        println!(
            "| {method} | {} / {} | {} / {} | {losses} of {} ({significant} beyond chance) | {} / {} ({} compared) |",
            fmt(quantile(&cov, 0.0), 1),
            fmt(quantile(&cov, 0.5), 1),
            fmt(quantile(&after, 0.0), 1),
            fmt(quantile(&after, 0.5), 1),
            mine.len(),
            fmt(quantile(&cost, 0.5), 3),
            fmt(quantile(&cost, 1.0), 3),
            cost.len(),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arx220_predicts_an_exact_arx_system_ten_samples_ahead() {
        // y[k] = 1.5 y[k−1] − 0.6 y[k−2] + 0.07 u[k] + 0.03 u[k−1]  (DC gain 1)
        let n = 600;
        let u: Vec<f64> = (0..n)
            .map(|k| (k as f64 * 0.05).sin() + (k as f64 * 0.013).cos())
            .collect();
        let mut y = vec![0.0; n];
        for k in 2..n {
            y[k] = 1.5 * y[k - 1] - 0.6 * y[k - 2] + 0.07 * u[k] + 0.03 * u[k - 1];
        }
        let p = baseline_arx220(&u, &y, 0);
        assert!(!p.has[101] && p.has[102] && p.has[n - 1]);
        for (k, (pk, yk)) in p.value.iter().zip(&y).enumerate().skip(102) {
            assert!((pk - yk).abs() < 1e-9, "k {k}");
        }
        let p = baseline_arx220(&u, &y, 4);
        assert!(!p.has[105] && p.has[106] && p.first == 106);
    }

    #[test]
    fn hold_and_command_baselines_are_what_they_say() {
        let y: Vec<f64> = (0..35).map(|k| k as f64).collect();
        let h = baseline_hold(&y, 0);
        assert!(!h.has[9] && h.has[10]);
        assert_eq!(h.value[10], 9.0);
        assert_eq!(h.value[19], 9.0);
        assert_eq!(h.value[20], 19.0);
        assert_eq!(h.value[34], 29.0);
        // a phase of 3 starts every block 3 samples later
        let h = baseline_hold(&y, 3);
        assert!(!h.has[12] && h.has[13]);
        assert_eq!(h.value[13], 12.0);
        assert_eq!(h.value[22], 12.0);
        assert_eq!(h.value[23], 22.0);
        assert_eq!(h.first, 13);
        let c = baseline_command(&y);
        assert_eq!(c.value, y);
    }

    fn predictions(value: Vec<f64>) -> Predictions {
        let n = value.len();
        Predictions {
            name: "p",
            value,
            has: vec![true; n],
            interval: None,
            first: 0,
            seconds: 0.0,
            error: None,
        }
    }

    #[test]
    fn the_diebold_mariano_statistic_matches_a_hand_computation() {
        // y = 0, b exact, a off by 1 in every even block of 10: block sums
        // d = 10, 0, 10, 0, … (20 blocks), mean 5, deviations ±5;
        // γ₀ = 25, γ₁ = −25·19/20, γ₂ = 25·18/20; lags ⌊4·0.2^(2/9)⌋ = 2;
        // lrv = 25 + 2·(2/3)·γ₁ + 2·(1/3)·γ₂ = 8.3333…; t = 5 / √(lrv/20)
        let y = vec![0.0; 200];
        let a = predictions((0..200).map(|k| ((k / 10 + 1) % 2) as f64).collect());
        let b = predictions(vec![0.0; 200]);
        let scored = vec![true; 200];
        let lrv = 25.0 - (4.0 / 3.0) * 23.75 + (2.0 / 3.0) * 22.5;
        let t = dm_statistic(&y, &a, &b, &scored).unwrap();
        assert!((t - 5.0 / (lrv / 20.0f64).sqrt()).abs() < 1e-12, "{t}");
        // the other way round: the same statistic, negated
        let back = dm_statistic(&y, &b, &a, &scored).unwrap();
        assert!((back + t).abs() < 1e-12);
        assert!(loses_significantly(&y, &a, &b, &scored));
        assert!(!loses_significantly(&y, &b, &a, &scored));
        // fewer than MIN_BLOCKS blocks: no test, a loss counts
        let few: Vec<bool> = (0..200).map(|k| k < 90).collect();
        assert_eq!(dm_statistic(&y, &a, &b, &few), None);
        assert!(loses_significantly(&y, &a, &b, &few));
    }

    #[test]
    fn equal_noise_is_no_significant_loss_and_larger_noise_is() {
        // seeded uniform noise (xorshift): a and b equally noisy, then a 20 % noisier
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut noise = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let n = 2000;
        let y: Vec<f64> = (0..n).map(|k| (k as f64 * 0.01).sin()).collect();
        let ea: Vec<f64> = (0..n).map(|_| noise()).collect();
        let eb: Vec<f64> = (0..n).map(|_| noise()).collect();
        let scored = vec![true; n];
        let b = predictions(y.iter().zip(&eb).map(|(y, e)| y + e).collect());
        let same = predictions(y.iter().zip(&ea).map(|(y, e)| y + e).collect());
        let t = dm_statistic(&y, &same, &b, &scored).unwrap();
        assert!(t.abs() < Z_95, "equal noise: t = {t}");
        assert!(!loses_significantly(&y, &same, &b, &scored));
        let worse = predictions(y.iter().zip(&ea).map(|(y, e)| y + 1.2 * e).collect());
        let t = dm_statistic(&y, &worse, &b, &scored).unwrap();
        assert!(t > 3.0, "20 % more noise: t = {t}");
        assert!(loses_significantly(&y, &worse, &b, &scored));
    }

    #[test]
    fn comparisons_use_only_the_samples_both_predict() {
        let y = vec![0.0; 200];
        let a = Predictions {
            name: "a",
            value: vec![1.0; 200],
            has: (0..200).map(|k| k < 150).collect(),
            interval: None,
            first: 0,
            seconds: 0.0,
            error: None,
        };
        let b = Predictions {
            name: "b",
            value: (0..200).map(|k| if k < 100 { 5.0 } else { 2.0 }).collect(),
            has: (0..200).map(|k| k >= 100).collect(),
            interval: None,
            first: 100,
            seconds: 0.0,
            error: None,
        };
        let scored = vec![true; 200];
        // shared: 100 … 149 (50 samples): rms 1 vs 2
        assert_eq!(shared_rms(&y, &a, &b, &scored), Some((1.0, 2.0)));
        let mut fewer = scored.clone();
        fewer[120] = false;
        assert_eq!(
            shared_rms(&y, &a, &b, &fewer),
            None,
            "below 50 shared samples"
        );
        assert_eq!(quantile(&[3.0, 1.0, 2.0], 0.5), Some(2.0));
        assert_eq!(quantile(&[1.0, 2.0], 0.9), Some(1.9));
        assert_eq!(quantile(&[], 0.5), None);
    }
}
