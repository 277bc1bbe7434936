//! The drive zoo's members with dropped rows, which the strict reader
//! refuses, stream with every gap reported at the sample after it and no
//! window spanning one; read with their gaps, the batch engine restarts at
//! the same samples and `auto` predicts every sample after each segment's
//! first window.

use feedid::ident::stream::{Interval, StreamOptions, Streamer};
use feedid::ident::{EngineConfig, Method};
use feedid::zoo::Zoo;

#[test]
fn every_dropped_run_of_a_gapped_zoo_member_is_one_gap_and_no_window_spans_it() {
    let zoo = Zoo::standard();
    let idx: Vec<usize> = zoo.gapped().collect();
    assert!(!idx.is_empty());
    for (i, m) in idx.iter().zip(zoo.members(&idx)) {
        let m = m.unwrap();
        assert!(m.recording().is_err(), "#{i}: the file reader refuses it");
        // runs of consecutive dropped rows of the uniform recording
        let rows = &m.spec.dropped_rows;
        let mut runs = 0;
        for (j, &r) in rows.iter().enumerate() {
            if j == 0 || rows[j - 1] + 1 != r {
                runs += 1;
            }
        }
        // the sample after each run, in the member's (gapped) indexing
        let mut after = Vec::new();
        for (j, &r) in rows.iter().enumerate() {
            if j + 1 == rows.len() || rows[j + 1] != r + 1 {
                after.push(r + 1 - (j + 1));
            }
        }
        let method = Method::default();
        let cfg = EngineConfig {
            window: method.default_window(),
            ..EngineConfig::default()
        };
        let mut s =
            Streamer::with_options(method.build().unwrap(), cfg, StreamOptions::default()).unwrap();
        let mut gaps = Vec::new();
        let mut windows = Vec::new();
        for k in 0..m.len() {
            let a = s.push(m.time[k], m.command[k], m.position[k]).unwrap();
            if let Interval::Gap(j) = a.interval {
                assert!(j.missing_samples() >= 1, "#{i}: {j:?}");
                gaps.push(k);
            }
            while let Some(p) = s.poll().unwrap() {
                windows.push(p.window.clone());
            }
        }
        assert_eq!(gaps.len(), runs, "#{i}: {rows:?}");
        assert_eq!(gaps, after, "#{i}");
        assert_eq!(s.stats().samples, m.len());
        for w in &windows {
            assert!(
                !gaps.iter().any(|&g| w.start < g && g < w.end),
                "#{i}: window {w:?} spans a gap at {gaps:?}"
            );
        }
        assert!(!windows.is_empty());
    }
}

#[test]
fn the_batch_engine_restarts_at_the_streams_gaps_and_auto_predicts_every_segment() {
    let zoo = Zoo::standard();
    let idx: Vec<usize> = zoo.gapped().collect();
    for (i, m) in idx.iter().zip(zoo.members(&idx)) {
        let m = m.unwrap();
        let rec = m.recording_with_gaps().unwrap();
        // the gaps are the stream's (the sample after each run of dropped rows)
        let rows = &m.spec.dropped_rows;
        let after: Vec<usize> = (0..rows.len())
            .filter(|&j| j + 1 == rows.len() || rows[j + 1] != rows[j] + 1)
            .map(|j| rows[j] + 1 - (j + 1))
            .collect();
        assert_eq!(rec.gap_starts().collect::<Vec<_>>(), after, "#{i}");
        assert_eq!(rec.missing_samples(), rows.len(), "#{i}");
        let method = Method::default();
        let cfg = EngineConfig {
            window: method.default_window(),
            ..EngineConfig::default()
        };
        let r =
            feedid::ident::engine::run(&mut method.build().unwrap(), &rec.signals(), &cfg).unwrap();
        for seg in rec.segments() {
            // no window or horizon reaches across a gap
            for w in r.windows.iter().filter(|w| seg.contains(&w.window.start)) {
                assert!(
                    w.window.end <= seg.end && w.horizon.end <= seg.end,
                    "#{i}: {w:?}"
                );
            }
            // every sample after the segment's first window (warm-up and
            // window, as in the first segment) is predicted
            let first = seg.start + r.windows[0].horizon.start;
            if first < seg.end {
                let missed = (first..seg.end).filter(|&k| !r.has_prediction[k]).count();
                assert_eq!(missed, 0, "#{i}: segment {seg:?}");
            }
            assert!(!r.has_prediction[seg.start..first.min(seg.end)]
                .iter()
                .any(|&h| h));
        }
        assert!(r.predicted.iter().all(|v| v.is_finite()));
    }
}
