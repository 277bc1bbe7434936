//! The report of `feedid reproduce`: the paper's ramp and step experiments
//! on the virtual rig, the comparison with the paper's reported errors, and
//! for each experiment the same sections as a recording report (the paper's
//! method next to other methods).
//!
//! ```no_run
//! use feedid::experiment::{run_experiment, PaperExperimentConfig};
//! use feedid::ident::Method;
//! use feedid_report::paper_report;
//! use feedid::signal::Scenario;
//! let cfg = PaperExperimentConfig::default();
//! let runs = vec![run_experiment(Scenario::Ramp, &cfg).unwrap()];
//! let page = paper_report(&runs, &cfg, &["arx".parse::<Method>().unwrap()]).unwrap();
//! std::fs::write("report.html", page.to_html()).unwrap();
//! ```

use crate::error::Result;
use crate::html::{Block, HtmlReport, Section, Table};
use crate::recording::{RecordingAnalysis, ReportOptions};
use feedid::drive::RigEffects;
use feedid::experiment::{paper_verdict, Axis, ExperimentResult, PaperExperimentConfig};
use feedid::ident::{EngineConfig, Method, PaperConfig};

/// Title of an experiment's section.
fn experiment_title(name: &str) -> String {
    match name {
        "ramp" => "Ramp experiment: 30 mm at 50 mm/s (paper figures 5 and 6)".into(),
        "step" => "Step experiment: 1 mm in 0.2 ms (paper figures 7 and 8)".into(),
        other => format!("Experiment: {other}"),
    }
}

/// The reproduce report: comparison table, then one part per experiment with
/// the paper's method (solver and W, H of `cfg`) and each of `others` (its
/// default window, the horizon of `cfg`).
pub fn paper_report(
    results: &[ExperimentResult],
    cfg: &PaperExperimentConfig,
    others: &[Method],
) -> Result<HtmlReport> {
    let mut methods = vec![(
        Method::Paper(PaperConfig {
            solver: cfg.solver,
            ..PaperConfig::default()
        }),
        cfg.engine,
    )];
    for spec in others {
        methods.push((
            spec.clone(),
            EngineConfig {
                window: spec.default_window(),
                ..cfg.engine
            },
        ));
    }
    let mut opts = ReportOptions::new(methods);
    opts.params = cfg.params;
    opts.params_source = "the virtual rig's own parameters (linear part only)".into();
    opts.zoom_s = cfg.zoom;

    let mut page = HtmlReport::new("feedid reproduce — the paper's experiments on the virtual rig");
    page.facts = vec![
        (
            "paper".into(),
            "Nassef, Li, Schenck, Kuhfuss: Short Time Identification of Feed Drive Systems using Nonlinear \
             Least Squares Method"
                .into(),
        ),
        (
            "measurement".into(),
            format!(
                "virtual rig, {}, nonlinear effects {}, noise seed {}",
                match cfg.axis {
                    Axis::Nominal => "default parameters (the nominal model)",
                    Axis::Real(_) => "a real axis: parameters off the nominal model (--axis real)",
                },
                if cfg.effects == RigEffects::default() {
                    "all on (friction, variable stiffness, current/voltage limits, sampled position loop, 0.1 µm encoder, 0.2 µm noise)"
                } else {
                    "as configured"
                },
                cfg.seed
            ),
        ),
        ("sampling rate".into(), format!("{} Hz", cfg.rate_hz)),
        (
            "paper method".into(),
            format!(
                "window W = {} samples ({:.1} ms), horizon H = {} ({:.1} ms), solver {}",
                cfg.engine.window,
                1e3 * cfg.engine.window as f64 / cfg.rate_hz,
                cfg.engine.horizon,
                1e3 * cfg.engine.horizon as f64 / cfg.rate_hz,
                cfg.solver.label()
            ),
        ),
        (
            "experiments".into(),
            results
                .iter()
                .map(|r| r.name)
                .collect::<Vec<_>>()
                .join(", "),
        ),
    ];
    page.intro.push(
        "The paper identifies a feed drive in windows of 20 samples (4 ms at 5 kHz) with a polynomial least-squares \
         method, predicts the next 10 samples (2 ms), and compares the prediction and the nominal simulation model \
         with the measurement for a ramp and a step. This page repeats both experiments on the built-in virtual rig \
         and adds other identification methods for comparison. The answer comes first: the verdict on the paper's \
         question and the table against the paper's numbers; each experiment then has its summary and the figures \
         that answer it, with the diagnostics (coefficients, residuals, frequency responses) folded one click \
         away."
            .into(),
    );

    let um = |v: f64| format!("{:.2}", 1e6 * v);
    let z = 1e3 * cfg.zoom;
    let mut rows = Vec::new();
    for r in results {
        for (label, e, us) in [
            ("paper LSM, QR", &r.qr, Some(r.qr_us)),
            ("paper LSM, simplex", &r.simplex, Some(r.simplex_us)),
            ("simulation model", &r.simulation, None),
        ] {
            rows.push(vec![
                r.name.to_string(),
                label.to_string(),
                um(e.whole.rms),
                um(e.whole.max_abs),
                um(e.zoom.rms),
                um(e.zoom.max_abs),
                um(e.after.rms),
                us.map_or("–".into(), |v| format!("{v:.2}")),
            ]);
        }
    }
    let mut comparison = Section::new("paper-sec", "Answer: the paper's question on this axis");
    if let Some(v) = paper_verdict(results, cfg) {
        comparison.blocks.push(Block::Answer {
            id: "paper-verdict".into(),
            text: v,
        });
    }
    let axis_note = match cfg.axis {
        Axis::Nominal => {
            "Here the measurement comes from a virtual rig whose linear part is the nominal model itself, so the \
             simulation model is far better than on a real axis (run `feedid reproduce --axis real` for an axis off \
             its data sheet); the paper method's error is dominated by the first windows after the motion start, \
             where its polynomial family cannot follow the response."
        }
        Axis::Real(_) => {
            "Here the measurement comes from the virtual rig moved off the nominal model as a real axis is off its \
             data sheet (mass, stiffness, damping, motor constants, friction, dead time; see docs/METHODS.md), while the \
             simulation model stays nominal — the paper's situation; the paper method's error is still dominated \
             by the first windows after the motion start."
        }
    };
    let comparison = comparison
        .with(Block::Table(Table {
            id: "paper-table".into(),
            caption: format!(
                "Measurement − model over every predicted sample (whole move), over the first {z:.0} ms after the \
                 motion start (the paper's figures) and after them (the settled part)."
            ),
            header: vec![
                "experiment".into(),
                "model".into(),
                "rms whole [µm]".into(),
                "max whole [µm]".into(),
                format!("rms first {z:.0} ms [µm]"),
                format!("max first {z:.0} ms [µm]"),
                format!("rms after {z:.0} ms [µm]"),
                "per window [µs]".into(),
            ],
            rows,
        }))
        .with(Block::List(vec![
            "Paper (measured axis): ramp — error of the identified (LSM) model about 40 µm, simulation model about 80 µm."
                .into(),
            "Paper: step — LSM error up to 0.15 mm at the start of motion, decreasing with time.".into(),
            axis_note.into(),
        ]));
    page.sections.push(comparison);
    // the verdict and its table before the contents: on the first screen
    page.lead_sections = 1;

    for r in results {
        let analysis = RecordingAnalysis::run(
            &format!("{} (virtual rig)", r.name),
            r.recording.clone(),
            &opts,
        )?;
        let mut sec = Section::new(r.name, &experiment_title(r.name));
        sec.blocks.push(Block::Paragraph(format!(
            "{} samples over {:.3} s; the motion starts at {:.1} ms.",
            r.recording.len(),
            r.recording.duration(),
            1e3 * r.motion_start
        )));
        sec.subsections = analysis.sections(r.name)?;
        page.sections.push(sec);
    }
    Ok(page)
}

#[cfg(test)]
mod tests {
    use super::*;
    use feedid::experiment::run_experiment;
    use feedid::ident::Solver;
    use feedid::signal::Scenario;

    #[test]
    fn reproduce_report_has_both_experiments_and_the_paper_table() {
        let cfg = PaperExperimentConfig {
            solver: Solver::Qr,
            ..Default::default()
        };
        let results: Vec<_> = [Scenario::Ramp, Scenario::Step]
            .iter()
            .map(|&s| run_experiment(s, &cfg).unwrap())
            .collect();
        let page = paper_report(&results, &cfg, &["arx".parse::<Method>().unwrap()]).unwrap();
        let ids = page.figure_ids();
        for exp in ["ramp", "step"] {
            for f in [
                "overview",
                "response-zoom",
                "error-zoom",
                "bode-mag",
                "coef-paper1",
                "coef-arx2",
                "ree-arx2",
            ] {
                let id = format!("{exp}-{f}");
                assert!(ids.contains(&id), "{id} in {ids:?}");
            }
        }
        let html = page.to_html();
        assert!(html.contains("<table id=\"paper-table\">"));
        assert!(html.contains("<td>ramp</td><td>paper LSM, QR</td>"));
        assert!(!html.contains("http://") && !html.contains("<script"));
        // the answer before any figure: the verdict on the paper's question
        let answer = html
            .find("<p class=\"answer\" id=\"paper-verdict\">Verdict: ")
            .unwrap();
        assert!(answer < html.find("id=\"contents\"").unwrap());
        let verdict = &html[answer..answer + html[answer..].find("</p>").unwrap()];
        // plain sentences: code as code, no literal backticks, no nested parentheses
        assert!(!verdict.contains('`'), "{verdict}");
        assert!(
            verdict.contains("<code>feedid reproduce --axis real</code>"),
            "{verdict}"
        );
        let mut depth = 0;
        for c in verdict.chars() {
            match c {
                '(' => depth += 1,
                ')' => depth -= 1,
                _ => {}
            }
            assert!(depth <= 1, "nested parentheses: {verdict}");
        }
        assert!(answer < html.find("<figure").unwrap());
        assert!(html.find("paper-table").unwrap() < html.find("<figure").unwrap());
        // the diagnostics of both experiments are folded, one click away
        assert_eq!(html.matches("<details><summary>").count(), 6);
    }
}
