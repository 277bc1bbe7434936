//! Gaps: a stream restarts its windows after a gap as if a new recording
//! began, the batch engine restarts at a recording's gaps alike, and a
//! reset returns every method to its fresh state.

use super::*;

/// Time, command and position of a rig ramp with 7 samples missing at 220
/// and a pause of 10 ms (50 samples) at 498 (a longer one shifts the times
/// far from 0 and costs digits).
fn gapped_ramp() -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let full = rig_recording(Scenario::Ramp, 0.16);
    let keep: Vec<usize> = (0..full.len())
        .filter(|k| !(220..227).contains(k))
        .collect();
    let pick = |v: &[f64]| keep.iter().map(|&k| v[k]).collect::<Vec<f64>>();
    let mut t = pick(full.time());
    for v in &mut t[498..] {
        *v += 0.01;
    }
    (t, pick(full.command()), pick(full.position()))
}

/// Batch predictions of a recording split into segments at `cuts`, in the
/// stream's sample indices (each segment run on its own).
fn batch_by_segments<E: Estimator>(
    make: impl Fn() -> E,
    rec: &Recording,
    cuts: &[usize],
    cfg: &EngineConfig,
) -> (Vec<Option<f64>>, usize) {
    let n = rec.len();
    let mut out = vec![None; n];
    let mut scored = 0;
    let mut bounds = vec![0];
    bounds.extend_from_slice(cuts);
    bounds.push(n);
    for w in bounds.windows(2) {
        let seg = Recording::new(
            rec.time()[w[0]..w[1]].to_vec(),
            rec.command()[w[0]..w[1]].to_vec(),
            rec.position()[w[0]..w[1]].to_vec(),
        )
        .unwrap();
        let b = run(&mut make(), &seg.signals(), cfg).unwrap();
        for k in 0..seg.len() {
            out[w[0] + k] = b.prediction(k);
        }
        scored += b.stats.samples;
    }
    (out, scored)
}

#[test]
fn a_gap_restarts_the_windows_as_if_a_new_recording_began() {
    // a rig ramp with 7 samples missing at 220 and a pause of 1 s at 505
    let (t, u, y) = gapped_ramp();
    let rec = Recording::with_tolerance(t, u, y, 1e9).unwrap();
    let cuts = [220, 498];
    let cfg = EngineConfig::default();
    for x in [Wait, Velocity] {
        let c = stream(paper(Solver::Qr), cfg, &rec, Feed::Lines(0), x);
        let gaps: Vec<_> = c
            .arrivals_at_gap
            .iter()
            .filter_map(|i| match i {
                Interval::Gap(j) => Some(*j),
                _ => None,
            })
            .collect();
        assert_eq!(gaps.len(), 2, "{x:?}: {:?}", c.arrivals_at_gap);
        assert_eq!(gaps[0].missing_samples(), 7);
        assert!((gaps[0].expected - 2e-4).abs() < 1e-9);
        assert_eq!(gaps[1].missing_samples(), 50);
        assert_eq!(c.stats.gaps, 2);
        let (want, scored) = batch_by_segments(|| paper(Solver::Qr), &rec, &cuts, &cfg);
        let scale = rec.position().iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        for k in 0..rec.len() {
            match (c.has[k], want[k]) {
                (true, Some(b)) => assert!(
                    (c.predicted[k] - b).abs() <= 1e-12 * scale,
                    "{x:?}: {k}: {} vs {b}",
                    c.predicted[k]
                ),
                (false, None) => {}
                (a, b) => panic!("{x:?}: sample {k}: stream {a} batch {b:?}"),
            }
        }
        // the first window after each gap starts at the gap
        assert!(c.windows.iter().any(|w| w.0 == (220..240)));
        assert!(c.windows.iter().any(|w| w.0 == (498..518)));
        assert!(!c
            .windows
            .iter()
            .any(|w| w.0.contains(&219) && w.0.contains(&220)));
        assert_eq!(c.stats.scored.samples, scored);
    }
    // Follow waits for its command: its windows before the gap are cut there
    let c = stream(follow7(), cfg, &rec, Feed::Lines(0), Wait);
    let (want, _) = batch_by_segments(follow7, &rec, &cuts, &cfg);
    for k in 0..rec.len() {
        assert_eq!(c.has[k], want[k].is_some(), "{k}");
        if let Some(b) = want[k] {
            assert_eq!(c.predicted[k], b, "{k}");
        }
    }
}

#[test]
fn the_batch_engine_restarts_after_dropped_samples_as_if_a_new_recording_began() {
    // the same gaps as above, now in one recording that allows them: the
    // batch engine runs each segment on its own, as the stream does
    let (t, u, y) = gapped_ramp();
    let rec = Recording::allowing_gaps(t, u, y, 1e-6).unwrap();
    let gaps: Vec<(usize, usize)> = rec.gaps().iter().map(|g| (g.index, g.missing)).collect();
    assert_eq!(gaps, [(220, 7), (498, 50)]);
    assert!((rec.dt() - 2e-4).abs() < 1e-12, "{}", rec.dt());
    let cuts = [220, 498];
    let cfg = EngineConfig::default();
    let scale = rec.position().iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let check = |b: &SlidingResult, want: &[Option<f64>], scored: usize, what: &str| {
        for k in 0..rec.len() {
            match (b.prediction(k), want[k]) {
                // (absolute sample indices change the last bits)
                (Some(a), Some(w)) => {
                    assert!((a - w).abs() <= 1e-12 * scale, "{what}: {k}: {a} vs {w}")
                }
                (a, w) => assert_eq!(a, w, "{what}: sample {k}"),
            }
        }
        assert_eq!(b.stats.samples, scored, "{what}");
        // no window reaches across a gap
        for w in &b.windows {
            for c in cuts {
                assert!(w.window.end <= c || w.window.start >= c, "{what}: {w:?}");
                assert!(w.horizon.end <= c || w.horizon.start >= c, "{what}: {w:?}");
            }
        }
    };
    let b = run(&mut paper(Solver::Qr), &rec.signals(), &cfg).unwrap();
    let (want, scored) = batch_by_segments(|| paper(Solver::Qr), &rec, &cuts, &cfg);
    check(&b, &want, scored, "paper");
    assert!(b.windows.iter().any(|w| w.window == (220..240)));
    let auto = || {
        crate::ident::Method::Auto(Default::default())
            .build()
            .unwrap()
    };
    let cfg = EngineConfig { window: 50, ..cfg };
    let b = run(&mut auto(), &rec.signals(), &cfg).unwrap();
    // `auto` keeps its candidates' models and scores across a gap: the
    // stream's predictions, not those of a fresh start on each segment
    let c = stream(auto(), cfg, &rec, Feed::Lines(0), Wait);
    for k in 0..rec.len() {
        assert_eq!(c.has[k], b.has_prediction[k], "auto: {k}");
        if c.has[k] {
            assert!(
                (c.predicted[k] - b.predicted[k]).abs() <= 1e-12 * scale,
                "auto: {k}"
            );
        }
    }
    let (fresh, _) = batch_by_segments(auto, &rec, &cuts, &cfg);
    assert_eq!(
        fresh[..220],
        (0..220).map(|k| b.prediction(k)).collect::<Vec<_>>()[..]
    );
    assert!((220..rec.len()).any(|k| fresh[k] != b.prediction(k)));
    for w in &b.windows {
        for c in cuts {
            assert!(w.window.end <= c || w.window.start >= c, "auto: {w:?}");
            assert!(w.horizon.end <= c || w.horizon.start >= c, "auto: {w:?}");
        }
    }
    // the stream of the same lines predicts the same samples
    let c = stream(follow7(), cfg, &rec, Feed::Lines(0), Wait);
    let b = run(&mut follow7(), &rec.signals(), &cfg).unwrap();
    for k in 0..rec.len() {
        assert_eq!(c.has[k], b.has_prediction[k], "{k}");
        if c.has[k] {
            assert_eq!(c.predicted[k], b.predicted[k], "{k}");
        }
    }
    // a segment too short for one window is skipped; none long enough is an error
    let short = rec.head(260).unwrap();
    assert_eq!(short.gaps().len(), 1);
    let b = run(&mut follow7(), &short.signals(), &cfg).unwrap();
    assert!(b.windows.iter().all(|w| w.window.end <= 220));
    let e = run(
        &mut follow7(),
        &short.signals(),
        &EngineConfig { window: 250, ..cfg },
    )
    .unwrap_err();
    assert!(
        matches!(e, Error::TooFewSamples { actual: 220, .. })
            && e.to_string().contains("between dropped samples"),
        "{e}"
    );
}

#[test]
fn a_gap_with_a_command_lead_leaves_the_next_lead_positions_unused() {
    let rec = rig_recording(Scenario::Ramp, 0.08);
    let (t, u, y) = (rec.time(), rec.command(), rec.position());
    let lead = 10;
    let opts = StreamOptions {
        command_lead: lead,
        ..StreamOptions::default()
    };
    let mut s = Streamer::with_options(paper(Solver::Qr), EngineConfig::default(), opts).unwrap();
    let mut samples = Vec::new();
    for i in 0..200 {
        // a pause of 0.5 s before line 100
        let ti = t[i] + if i >= 100 { 0.5 } else { 0.0 };
        let a = s.push(ti, u[i + lead], y[i]).unwrap();
        assert_eq!(matches!(a.interval, Interval::Gap(_)), i == 100, "{i}");
        samples.push(a.sample);
        while s.poll().unwrap().is_some() {}
    }
    // positions unused: lines 0..10 and 100..110
    for (i, a) in samples.iter().enumerate() {
        let unused = i < 10 || (100..110).contains(&i);
        assert_eq!(a.is_none(), unused, "line {i}: {a:?}");
    }
    assert_eq!(samples[110], Some(90));
    let st = s.stats();
    assert_eq!((st.lines, st.samples, st.unused_positions), (200, 180, 20));
    assert_eq!(st.predicted_late, 0);
}

#[test]
fn a_gap_between_positions_keeps_the_commands_pushed_ahead() {
    let rec = rig_recording(Scenario::Ramp, 0.06);
    let (t, u, y) = (rec.time(), rec.command(), rec.position());
    let n = rec.len();
    let cut = 150;
    let opts = StreamOptions {
        lookahead: Some(4),
        ..StreamOptions::default()
    };
    let cfg = EngineConfig::default();
    let mut s = Streamer::with_options(paper(Solver::Qr), cfg, opts).unwrap();
    let mut got = vec![None; n];
    let take = |got: &mut Vec<Option<f64>>, p: Prediction<'_>| {
        for (k, v) in p.horizon.clone().zip(p.position) {
            if k < n {
                got[k] = Some(*v);
            }
        }
    };
    for k in 0..4 {
        s.push_command(u[k]).unwrap();
    }
    for k in 0..n {
        if k + 4 < n {
            s.push_command(u[k + 4]).unwrap();
        }
        let tk = t[k] + if k >= cut { 0.01 } else { 0.0 };
        let a = s.push_position(tk, y[k]).unwrap();
        assert_eq!(matches!(a.interval, Interval::Gap(_)), k == cut);
        assert_eq!(a.sample, Some(k));
        if k == cut {
            // predictions made before the gap of samples after it are void
            got[cut..].fill(None);
        }
        while let Some(p) = s.poll().unwrap() {
            take(&mut got, p);
        }
    }
    let shifted: Vec<f64> = (0..n)
        .map(|k| t[k] + if k >= cut { 0.01 } else { 0.0 })
        .collect();
    let rec2 = Recording::with_tolerance(shifted, u.to_vec(), y.to_vec(), 1e9).unwrap();
    let (want, _) = batch_by_segments(|| paper(Solver::Qr), &rec2, &[cut], &cfg);
    let scale = rec.position().iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    for k in 0..n {
        match (got[k], want[k]) {
            (Some(a), Some(b)) => assert!((a - b).abs() <= 1e-12 * scale, "{k}: {a} {b}"),
            (None, None) => {}
            (a, b) => panic!("{k}: {a:?} {b:?}"),
        }
    }
}

#[test]
fn irregular_intervals_are_kept_and_a_change_of_rate_is_a_gap() {
    let mut s = Streamer::new(Linear, EngineConfig::default()).unwrap();
    let mut t = 0.0;
    let mut push = |s: &mut Streamer<Linear>, dt: f64| {
        t += dt;
        let i = s.push(t, 0.0, 0.0).unwrap().interval;
        while s.poll().unwrap().is_some() {}
        i
    };
    for _ in 0..30 {
        assert_eq!(push(&mut s, 1e-3), Interval::Regular);
    }
    // 5 % long: irregular, kept
    assert!(
        matches!(push(&mut s, 1.05e-3), Interval::Irregular(j) if (j.expected - 1e-3).abs() < 1e-12)
    );
    assert_eq!(push(&mut s, 1e-3), Interval::Regular);
    // half the interval: the sampling changed
    assert!(matches!(push(&mut s, 0.5e-3 - 1e-9), Interval::Gap(j) if j.missing_samples() == 0));
    // the new segment learns its interval from its first one
    assert_eq!(push(&mut s, 0.5e-3), Interval::Regular);
    assert_eq!(push(&mut s, 0.5e-3), Interval::Regular);
    assert!((s.dt().unwrap() - 0.5e-3).abs() < 1e-12);
    let st = s.stats();
    assert_eq!((st.gaps, st.irregular_intervals, st.samples), (1, 1, 35));
    // a given interval is the reference from the start
    let opts = StreamOptions {
        dt: Some(1e-3),
        ..StreamOptions::default()
    };
    let mut s = Streamer::with_options(Linear, EngineConfig::default(), opts).unwrap();
    s.push(0.0, 0.0, 0.0).unwrap();
    assert!(matches!(
        s.push(3e-3, 0.0, 0.0).unwrap().interval,
        Interval::Gap(j) if j.missing_samples() == 2
    ));
}

#[test]
fn predictions_due_before_a_gap_must_be_polled_first() {
    let rec = rig_recording(Scenario::Ramp, 0.04);
    let (t, u, y) = (rec.time(), rec.command(), rec.position());
    let opts = StreamOptions {
        extrapolation: Wait,
        ..StreamOptions::default()
    };
    let mut s = Streamer::with_options(follow7(), EngineConfig::default(), opts).unwrap();
    // windows at 1, 11, …: the one ending at 51 waits for the command to 60
    for k in 0..55 {
        s.push(t[k], u[k], y[k]).unwrap();
        while s.poll().unwrap().is_some() {}
    }
    assert!(matches!(
        s.push(t[55] + 1.0, u[55], y[55]).unwrap().interval,
        Interval::Gap(_)
    ));
    let e = s.push(t[56] + 1.0, u[56], y[56]).unwrap_err();
    assert!(e.to_string().contains("poll"), "{e}");
    let p = s.poll().unwrap().unwrap();
    assert_eq!((p.window.clone(), p.horizon.clone()), (31..51, 51..55));
    assert!(s.poll().unwrap().is_none());
    assert_eq!(s.stats().samples, 56);
    s.push(t[56] + 1.0, u[56], y[56]).unwrap();
}

#[test]
fn a_reset_returns_every_method_to_its_fresh_state() {
    // what a gap does to an estimator (stream and batch): after a reset it
    // predicts the next segment exactly as a new one would
    let full = rig_recording(Scenario::Ramp, 0.16);
    let first = full.slice(0..223).unwrap(); // its last horizon cut short
    let second = full.slice(227..498).unwrap();
    for method in crate::ident::Method::all() {
        let cfg = EngineConfig {
            window: 50,
            ..EngineConfig::default()
        };
        let fresh = run(&mut method.build().unwrap(), &second.signals(), &cfg).unwrap();
        let mut used = method.build().unwrap();
        run(&mut used, &first.signals(), &cfg).unwrap();
        let again = run(&mut used, &second.signals(), &cfg).unwrap();
        assert!(fresh.stats.samples > 0, "{}", method.name());
        // (the paper's method reuses its basis while the time grid repeats
        // to rounding: the last bits may differ)
        let scale = second
            .position()
            .iter()
            .fold(0.0_f64, |m, v| m.max(v.abs()));
        for k in 0..second.len() {
            match (fresh.prediction(k), again.prediction(k)) {
                (Some(a), Some(b)) => assert!(
                    (a - b).abs() <= 1e-12 * scale,
                    "{}: {k}: {a} vs {b}",
                    method.name()
                ),
                (a, b) => assert_eq!(a, b, "{}: {k}", method.name()),
            }
        }
    }
}

#[test]
fn after_a_gap_arx_rls_and_oe_predict_a_still_axis_from_the_model_learnt_before() {
    // a step, then rest, read by a coarse encoder that stands still from 300
    // samples after the step on; 3 samples dropped while it does
    let full = rig_recording(Scenario::Step, 0.2);
    let c = full.command();
    let last_move = (1..c.len()).rev().find(|&k| c[k] != c[k - 1]).unwrap();
    let (rest, g) = (last_move + 300, last_move + 400);
    assert!(g + 400 < full.len(), "{last_move}");
    let mut y = full.position().to_vec();
    let y_rest = y[rest];
    y[rest..].fill(y_rest);
    let keep: Vec<usize> = (0..full.len())
        .filter(|k| !(g..g + 3).contains(k))
        .collect();
    let pick = |v: &[f64]| keep.iter().map(|&k| v[k]).collect::<Vec<f64>>();
    let rec = Recording::allowing_gaps(pick(full.time()), pick(c), pick(&y), 1e-6).unwrap();
    assert_eq!(rec.gap_starts().collect::<Vec<_>>(), [g]);
    let still = rec.slice(g..rec.len()).unwrap();
    for name in ["arx", "rls", "oe"] {
        let method: crate::ident::Method = name.parse().unwrap();
        let cfg = EngineConfig {
            window: method.default_window(),
            ..EngineConfig::default()
        };
        // alone, the still segment teaches nothing: no prediction
        let alone = run(&mut method.build().unwrap(), &still.signals(), &cfg).unwrap();
        assert_eq!(alone.stats.samples, 0, "{name}");
        // after the gap, the model learnt before predicts it
        let b = run(&mut method.build().unwrap(), &rec.signals(), &cfg).unwrap();
        let after = b.has_prediction[g..].iter().filter(|&&h| h).count();
        assert!(
            after > (rec.len() - g) / 2,
            "{name}: {after} of {}",
            rec.len() - g
        );
        // no window across the gap, and the stream does the same
        assert!(b
            .windows
            .iter()
            .all(|w| w.window.end <= g || w.window.start >= g));
        let s = stream(method.build().unwrap(), cfg, &rec, Feed::Lines(0), Wait);
        for k in 0..rec.len() {
            assert_eq!(s.has[k], b.has_prediction[k], "{name}: {k}");
        }
    }
}

#[test]
fn a_change_of_the_rate_makes_arx_rls_and_auto_start_afresh() {
    use crate::ident::Estimator;
    let full = rig_recording(Scenario::Ramp, 0.1);
    let half = |v: &[f64]| v.iter().step_by(2).copied().collect::<Vec<f64>>();
    let slow = Recording::new(
        half(full.time()),
        half(full.command()),
        half(full.position()),
    )
    .unwrap();
    for name in ["arx", "rls", "auto"] {
        let method: crate::ident::Method = name.parse().unwrap();
        let cfg = EngineConfig {
            window: method.default_window(),
            ..EngineConfig::default()
        };
        let fresh = run(&mut method.build().unwrap(), &slow.signals(), &cfg).unwrap();
        let mut used = method.build().unwrap();
        run(&mut used, &full.signals(), &cfg).unwrap();
        // what a stream does at a gap that is a change of the rate
        used.gap();
        let (mut coef, mut out) = (vec![0.0; used.coefficient_names().len()], vec![0.0; 10]);
        for (w, h) in cfg.windows(slow.len(), used.warm_up()) {
            let a = crate::ident::engine::fit_and_predict(
                &mut used,
                &slow.signals(),
                w.clone(),
                h.clone(),
                &mut coef,
                &mut out[..h.len()],
            );
            match (a.outcome.predicted(), fresh.prediction(h.start)) {
                (true, Some(p)) => assert!((out[0] - p).abs() <= 1e-12, "{name}: {w:?}"),
                (false, None) => {}
                (x, y) => panic!("{name}: {w:?}: {x} vs {y:?}"),
            }
        }
    }
}
