//! Tests of the recording report.

use super::analysis::*;
use super::diagnostics::*;
use crate::html::Block;
use feedid::drive::{RigParams, VirtualRig};
use feedid::ident::{EngineConfig, LinearModel, Method};
use feedid::lti::Complex;
use feedid::pipeline::MIN_ZOOM_SAMPLES;
use feedid::signal::Scenario;
use feedid::Recording;

fn ramp() -> Recording {
    let cmd = Scenario::Ramp.command(5000.0, 0.2, 1).unwrap();
    let out = VirtualRig::new(RigParams::default())
        .with_seed(1)
        .simulate(&cmd, 5000.0)
        .unwrap();
    Recording::new(out.time, out.command, out.position).unwrap()
}

fn opts() -> ReportOptions {
    ReportOptions::new(
        ["paper", "arx"]
            .iter()
            .map(|n| {
                let spec: Method = n.parse().unwrap();
                let cfg = EngineConfig {
                    window: spec.default_window(),
                    ..EngineConfig::default()
                };
                (spec, cfg)
            })
            .collect(),
    )
}

#[test]
fn report_has_every_section_and_figure_and_no_external_reference() {
    let a = RecordingAnalysis::run("ramp <test>.csv", ramp(), &opts()).unwrap();
    assert_eq!(a.runs.len(), 2);
    let page = recording_report(&a).unwrap();
    let ids = page.figure_ids();
    let mut expected = vec![
        "rec-overview",
        "rec-tracking",
        "rec-response",
        "rec-response-zoom",
        "rec-error",
        "rec-error-zoom",
        "rec-error-zoom-detail",
        "rec-coef-paper1",
        "rec-coef-paper1-2",
        "rec-coef-arx2",
    ]
    .into_iter()
    .map(String::from)
    .collect::<Vec<_>>();
    for m in ["paper1", "arx2"] {
        expected.push(format!("rec-ree-{m}"));
        expected.push(format!("rec-rue-{m}"));
    }
    expected.push("rec-bode-mag".into());
    expected.push("rec-bode-phase".into());
    let mut got = ids.clone();
    got.sort();
    expected.sort();
    assert_eq!(got, expected);
    let html = page.to_html();
    for id in &ids {
        assert!(html.contains(&format!("<figure id=\"{id}\">")), "{id}");
    }
    for sec in [
        "overview-sec",
        "response-sec",
        "error-sec",
        "coef-sec",
        "resid-sec",
        "bode-sec",
        "summary-sec",
    ] {
        assert!(
            html.contains(&format!("<section id=\"rec-{sec}\">")),
            "{sec}"
        );
    }
    assert_eq!(html.matches("<svg ").count(), ids.len());
    assert!(html.contains("ramp &lt;test&gt;.csv"));
    assert!(!html.contains("ramp <test>"));
    for bad in [
        "http://", "https://", "<script", "<link", "<img", "<iframe", "NaN", "inf\"",
    ] {
        assert!(!html.contains(bad), "{bad}");
    }
    assert!(html.contains("[µm]") && html.contains("[ms]"));
    // two global models on a clean ramp
    assert_eq!(a.global.len() + a.notes.len(), 2);
    // reasonable size: well under 4 MB
    assert!(html.len() < 4_000_000, "{}", html.len());
}

#[test]
fn summary_table_numbers_match_the_runs() {
    let a = RecordingAnalysis::run("r", ramp(), &opts()).unwrap();
    let sec = a.summary_section("x");
    let Block::Table(t) = &sec.blocks[1] else {
        panic!("table expected")
    };
    assert_eq!(t.rows.len(), 3);
    let s = a.runs[1].identification.summary();
    assert_eq!(t.rows[1][6], format!("{:.3}", 1e6 * s.rms_error_m.unwrap()));
    assert_eq!(t.rows[2][0], "simulation model (nominal)");
}

#[test]
fn discrete_frequency_response_matches_closed_form() {
    // y[k] = 0.5 y[k−1] + 0.5 u[k−1]: G(z) = 0.5 z⁻¹ / (1 − 0.5 z⁻¹)
    let m = LinearModel::discrete(vec![0.0, 0.5], vec![1.0, -0.5], 1e-3).unwrap();
    let f = [0.0, 125.0, 250.0];
    let r = response_model(&m, &f).unwrap();
    assert!((r[0].norm() - 1.0).abs() < 1e-12);
    for (i, &fi) in f.iter().enumerate() {
        let z = Complex::from_polar(1.0, 2.0 * std::f64::consts::PI * fi * 1e-3);
        let g = Complex::new(0.5, 0.0) / (z - Complex::new(0.5, 0.0));
        assert!((r[i] - g).norm() < 1e-12);
    }
}

#[test]
fn phase_unwrapping_removes_jumps() {
    let resp: Vec<Complex<f64>> = (0..50)
        .map(|k| Complex::from_polar(1.0, -0.2 * k as f64))
        .collect();
    let p = unwrap_phase(&resp);
    for (k, v) in p.iter().enumerate() {
        assert!((v + (0.2 * k as f64).to_degrees()).abs() < 1e-9, "{k}: {v}");
    }
}

#[test]
fn report_opens_with_the_answer_and_folds_the_diagnostics() {
    let a = RecordingAnalysis::run("ramp.csv", ramp(), &opts()).unwrap();
    let secs = a.sections("rec").unwrap();
    // the summary (answer) comes first, with the verdict before its table
    assert_eq!(secs[0].id, "rec-summary-sec");
    let Block::Answer { id, text: verdict } = &secs[0].blocks[0] else {
        panic!("the summary opens with the answer: {:?}", secs[0].blocks[0]);
    };
    assert_eq!(id, "rec-answer");
    assert!(verdict.starts_with("Answer: "), "{verdict}");
    // the best method named is the one with the lowest rms among those with
    // (nearly) full coverage; its rms is the summary's
    let n = a.recording.len() as f64;
    let cov = |m: &MethodRun| m.identification.summary().samples_predicted as f64 / n;
    let max_cov = a.runs.iter().map(cov).fold(0.0, f64::max);
    let best = a
        .runs
        .iter()
        .filter(|m| cov(m) >= 0.95 * max_cov)
        .min_by(|x, y| {
            let r = |m: &MethodRun| m.identification.summary().rms_error_m.unwrap();
            r(x).total_cmp(&r(y))
        })
        .unwrap();
    let rms = best.identification.summary().rms_error_m.unwrap();
    assert!(
        verdict.contains(&format!("{} predicts best", best.label))
            && verdict.contains(&format!("rms {:.3} µm", 1e6 * rms)),
        "{verdict}"
    );
    // the diagnostics are folded, the figures that answer are not
    for s in &secs {
        let diagnostic = s.id.contains("coef") || s.id.contains("resid") || s.id.contains("bode");
        assert_eq!(s.folded, diagnostic, "{}", s.id);
    }
    let html = recording_report(&a).unwrap().to_html();
    assert!(html.contains("<details><summary>"));
    let answer = html
        .find("<p class=\"answer\" id=\"rec-answer\">Answer: ")
        .unwrap();
    let first_figure = html.find("<figure").unwrap();
    assert!(answer < first_figure);
    // the answer comes before the (one-line) contents, and the intro says so
    let contents = html.find("<nav class=\"toc\" id=\"contents\">").unwrap();
    assert!(answer < contents && contents < first_figure);
    let intro = &html[html.find("How to read this report").unwrap()..];
    assert!(intro.starts_with("How to read this report: the answer comes first."));
    assert!(!html.contains("summary table at the end"));
}

/// A recording at `rate` Hz: the ramp scenario over `duration` s.
fn ramp_at(rate: f64, duration: f64) -> Recording {
    let cmd = Scenario::Ramp.command(rate, duration, 1).unwrap();
    let out = VirtualRig::new(RigParams::default())
        .with_seed(1)
        .simulate(&cmd, rate)
        .unwrap();
    Recording::new(out.time, out.command, out.position).unwrap()
}

#[test]
fn a_100_hz_report_has_method_data_in_every_zoom_figure_and_a_named_zoom_column() {
    let mut o = opts();
    o.methods = ["paper", "arx", "auto"]
        .iter()
        .map(|n| {
            let spec: Method = n.parse().unwrap();
            let cfg = EngineConfig {
                window: spec.default_window(),
                ..EngineConfig::default()
            };
            (spec, cfg)
        })
        .collect();
    let a = RecordingAnalysis::run("ramp100.csv", ramp_at(100.0, 5.0), &o).unwrap();
    // 60 ms are 6 samples inside the first window: the zoom is widened to a
    // round span that holds every method's first predictions
    assert!(a.zoom_s > 0.06, "{}", a.zoom_s);
    assert!(a.zoom_indices().len() >= MIN_ZOOM_SAMPLES);
    let label = super::analysis::span_text(a.zoom_s);
    // every method has predictions in the zoomed figures
    let ((full, _), (zoom, _)) = a.response_charts();
    for m in &a.runs {
        for chart in [&full, &zoom] {
            let s = chart.series.iter().find(|s| s.label == m.label).unwrap();
            assert!(
                s.y.iter().filter(|v| v.is_finite()).count() >= 3,
                "{}: {} in {}",
                a.zoom_s,
                m.label,
                chart.title
            );
        }
        assert!(m.zoom_stats.samples > 0, "{}", m.label);
    }
    // the summary names the span and has no all-"–" column
    let sec = a.summary_section("rec");
    let Block::Table(t) = &sec.blocks[1] else {
        panic!("table expected")
    };
    assert!(
        t.header.contains(&format!("rms first {label} [µm]")),
        "{:?}",
        t.header
    );
    assert!(!t.header.iter().any(|h| h.contains("60 ms")));
    for j in 1..t.header.len() {
        assert!(
            t.rows.iter().any(|r| r[j] != "–"),
            "column {} is all –",
            t.header[j]
        );
    }
    // nor has any other table: a regime without samples is left out, and said so
    for b in &sec.blocks {
        let Block::Table(t) = b else { continue };
        for j in 1..t.header.len() {
            assert!(
                t.rows.iter().any(|r| r[j] != "–"),
                "{}: column {} is all –",
                t.id,
                t.header[j]
            );
        }
    }
    let Block::Table(intervals) = &sec.blocks[2] else {
        panic!("interval table expected")
    };
    assert!(
        intervals.caption.contains("(not shown)"),
        "{}",
        intervals.caption
    );
    let html = recording_report(&a).unwrap().to_html();
    assert!(html.contains(&format!("Zoom on the first {label} of the motion")));
    assert!(html.contains("The zoom is widened from the requested 60 ms"));
    // at 5 kHz the requested 60 ms stay
    let b = RecordingAnalysis::run("ramp.csv", ramp(), &opts()).unwrap();
    assert_eq!(b.zoom_s, 0.06);
    assert!(!recording_report(&b).unwrap().to_html().contains("widened"));
}

#[test]
fn a_method_that_blows_up_is_cut_at_the_frame_of_the_measurement_and_named() {
    let mut a = RecordingAnalysis::run("ramp.csv", ramp(), &opts()).unwrap();
    // nothing leaves the whole figure: its own data range, no note
    let ((full, note), _) = a.response_charts();
    assert!(full.y_range.is_none() && note.is_empty(), "{note}");
    // one method blows up to 1.09 m on one stretch of predictions
    let label = a.runs[1].label.clone();
    let s = &mut a.comparison.runs[1].identification.sliding;
    let k = (500..s.has_prediction.len())
        .find(|&k| s.has_prediction[k])
        .unwrap();
    for v in &mut s.predicted[k..k + 5] {
        *v = 1.09;
    }
    let ((full, note), _) = a.response_charts();
    let r = &a.recording;
    let (lo, hi) = r
        .position()
        .iter()
        .chain(r.command())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    // the y range follows the measurement and the command (in mm), with a margin
    let (y0, y1) = full.y_range.unwrap();
    let span = 1e3 * (hi - lo);
    assert!((y0 - (1e3 * lo - 0.1 * span)).abs() < 1e-9 * span, "{y0}");
    assert!((y1 - (1e3 * hi + 0.1 * span)).abs() < 1e-9 * span, "{y1}");
    // the caption names the method and how far it went
    assert!(
        note.contains(&format!("{label} reaches 1090 mm at ")),
        "{note}"
    );
    assert!(note.contains("beyond it"), "{note}");
    assert!(!note.contains("measurement reaches"), "{note}");
    let html = a.response_section("rec").unwrap();
    let Block::Figure(f) = &html.blocks[1] else {
        panic!("figure expected")
    };
    assert!(f.caption.contains(&format!("{label} reaches 1090 mm")));
}

#[test]
fn a_recording_with_dropped_samples_is_reported_segment_by_segment() {
    let full = ramp();
    let rec = full.dropping(&[400, 401, 402]).unwrap();
    let grid = rec.grid_indices();
    let a = RecordingAnalysis::run("gapped.csv", rec, &opts()).unwrap();
    // the nominal model ran through the gap: as on the full recording
    let whole = RecordingAnalysis::run("full.csv", full, &opts()).unwrap();
    for (i, &k) in grid.iter().enumerate() {
        assert!((a.simulated[i] - whole.simulated[k]).abs() < 1e-12, "{k}");
    }
    // no method predicts the first window after the gap
    for run in &a.runs {
        let s = &run.identification.sliding;
        assert!(!s.has_prediction[400..400 + 20].iter().any(|&h| h));
        assert!(s.stats.samples > 0);
    }
    assert!(
        a.notes[0].contains("3 sample(s) missing in 1 gap(s)"),
        "{:?}",
        a.notes
    );
    assert!(
        a.notes.iter().any(|n| n.contains(
            "Global models: fitted and simulated through the 1 gap(s) of dropped samples"
        )),
        "{:?}",
        a.notes
    );
    // the global models are those of the whole recording, through the gap
    assert!(!a.global.is_empty());
    for g in &a.global {
        assert_eq!(g.simulation.samples, a.recording.len(), "{}", g.label);
    }
    assert!(a
        .facts()
        .iter()
        .any(|(k, v)| k == "dropped samples" && v.starts_with("3 missing in 1 gap")));
    let html = recording_report(&a).unwrap().to_html();
    assert!(!html.contains("NaN"));
}
