//! Tests of the recording report.

use super::analysis::*;
use super::diagnostics::*;
use crate::html::Block;
use feedid::drive::{RigParams, VirtualRig};
use feedid::ident::{EngineConfig, LinearModel, Method};
use feedid::lti::Complex;
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
    let Block::Paragraph(verdict) = &secs[0].blocks[0] else {
        panic!(
            "the summary opens with a paragraph: {:?}",
            secs[0].blocks[0]
        );
    };
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
    let answer = html.find("Answer: ").unwrap();
    let first_figure = html.find("<figure").unwrap();
    assert!(answer < first_figure);
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
