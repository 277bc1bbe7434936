//! `feedid report`, `feedid sweep` and the report of `feedid reproduce` as a
//! user runs them: the files they write, what they print, and their
//! behaviour on bad input (exit code 2, the bad value named, no output left).

mod common;

use std::path::{Path, PathBuf};

use common::{assert_fails, feedid, stderr, stdout};

/// A short simulated ramp (0.15 s at 5 kHz) in `dir` under `name`.
fn ramp(dir: &Path, name: &str) -> PathBuf {
    let p = dir.join(name);
    let o = feedid(&[
        "simulate",
        "--scenario",
        "ramp",
        "--duration",
        "0.15",
        "-o",
        p.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    p
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// No file in `dir` other than `keep` (no output, no temporary file).
fn only(dir: &Path, keep: &[&Path]) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        assert!(
            keep.contains(&p.as_path()),
            "unexpected file {}",
            p.display()
        );
    }
}

#[test]
fn report_writes_one_self_contained_page_with_every_figure() {
    let dir = tempfile::tempdir().unwrap();
    let input = ramp(dir.path(), "ramp&<1>.csv");
    let out = dir.path().join("report.html");
    let o = feedid(&["report", s(&input), "--methods", "paper,arx", "-o", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(
        text.contains("paper LSM, qr (W=20)") && text.contains("ARX 3,3,0 (W=100)"),
        "{text}"
    );
    assert!(text.contains("simulation model (nominal)"), "{text}");
    assert!(text.contains("written"), "{text}");
    let html = std::fs::read_to_string(&out).unwrap();
    assert!(html.starts_with("<!DOCTYPE html>"));
    let figures = [
        "overview",
        "tracking",
        "response",
        "response-zoom",
        "error",
        "error-zoom",
        "error-zoom-detail",
        "coef-paper1",
        "coef-paper1-2",
        "coef-arx2",
        "ree-paper1",
        "rue-paper1",
        "ree-arx2",
        "rue-arx2",
        "bode-mag",
        "bode-phase",
    ];
    for f in figures {
        assert!(html.contains(&format!("<figure id=\"rec-{f}\">")), "{f}");
    }
    assert_eq!(html.matches("<figure id=").count(), figures.len());
    assert_eq!(html.matches("<svg ").count(), figures.len());
    assert!(html.contains("<table id=\"rec-summary\">"));
    // the file name is escaped, never raw
    assert!(html.contains("ramp&amp;&lt;1&gt;.csv") && !html.contains("ramp&<1>"));
    // self-contained: nothing loaded from elsewhere, no scripts
    for bad in [
        "http://", "https://", "<script", "<link", "<img", "@import", "url(",
    ] {
        assert!(!html.contains(bad), "{bad}");
    }
    assert!(html.contains("[µm]") && html.contains("[ms]") && html.contains("[Hz]"));
    assert!(!html.contains("NaN"));
    only(dir.path(), &[&input, &out]);
}

#[test]
fn report_rejects_bad_options_and_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let input = ramp(dir.path(), "ramp.csv");
    let out = dir.path().join("r.html");
    let o = feedid(&[
        "report",
        s(&input),
        "--methods",
        "paper,magic",
        "-o",
        s(&out),
    ]);
    assert_fails(&o, &["magic"]);
    let o = feedid(&[
        "report",
        s(&input),
        "--methods",
        "paper,,arx",
        "-o",
        s(&out),
    ]);
    assert_fails(&o, &["--methods"]);
    let o = feedid(&["report", s(&input), "--zoom", "0", "-o", s(&out)]);
    assert_fails(&o, &["--zoom"]);
    let o = feedid(&["report", s(&dir.path().join("missing.csv")), "-o", s(&out)]);
    assert_fails(&o, &["missing.csv"]);
    let o = feedid(&[
        "report",
        s(&input),
        "-o",
        s(&dir.path().join("no/such/dir/r.html")),
    ]);
    assert_fails(&o, &["r.html"]);
    only(dir.path(), &[&input]);
}

fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    (header, rows)
}

#[test]
fn sweep_writes_every_combination_a_heat_map_and_the_best_choice() {
    let dir = tempfile::tempdir().unwrap();
    let input = ramp(dir.path(), "ramp.csv");
    let csv = dir.path().join("sweep.csv");
    let svg = dir.path().join("sweep.svg");
    let o = feedid(&[
        "sweep",
        s(&input),
        "--windows",
        "10,20,40",
        "--horizons",
        "5,10",
        "--methods",
        "paper,arx",
        "--orders",
        "2,2,1",
        "4,4,1",
        "-o",
        s(&csv),
        "--plot",
        s(&svg),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    // not a terminal here: no progress bar, nothing on stderr
    assert_eq!(stderr(&o), "");
    let (header, rows) = read_csv(&csv);
    assert_eq!(
        header,
        [
            "method",
            "window",
            "horizon",
            "na",
            "nb",
            "nk",
            "rms_m",
            "max_abs_m",
            "fit_percent",
            "per_window_us",
            "failed_windows",
            "windows",
            "samples_predicted",
            "rms_common_m",
            "error"
        ]
    );
    // paper: 3 windows × 2 horizons; arx: 2 orders × 3 × 2
    assert_eq!(rows.len(), 18);
    let rms: Vec<f64> = rows.iter().map(|r| r[13].parse().unwrap()).collect();
    assert!(rms.iter().all(|v| v.is_finite() && *v > 0.0));
    assert!(rows.iter().filter(|r| r[0] == "arx").all(|r| r[5] == "1"));
    assert!(rows
        .iter()
        .filter(|r| r[0] == "paper")
        .all(|r| r[3].is_empty()));
    // the printed best is the smallest rms of its horizon in the CSV
    let text = stdout(&o);
    let best10 = rows
        .iter()
        .filter(|r| r[2] == "10")
        .min_by(|a, b| {
            a[13]
                .parse::<f64>()
                .unwrap()
                .total_cmp(&b[13].parse::<f64>().unwrap())
        })
        .unwrap();
    let label = if best10[0] == "arx" {
        format!("arx {},{},{}", best10[3], best10[4], best10[5])
    } else {
        "paper".to_string()
    };
    assert!(
        text.contains(&format!("best for H=10: {label} with W={}", best10[1])),
        "{text}"
    );
    assert!(text.contains("paper, H=10: "), "{text}");
    assert!(text.contains("W=20"), "{text}");
    let map = std::fs::read_to_string(&svg).unwrap();
    assert_eq!(map.matches("class=\"cell\"").count(), 18);
    assert!(map.contains("20 (paper)"));
}

#[test]
fn sweep_rejects_bad_lists_naming_the_value_and_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let input = ramp(dir.path(), "ramp.csv");
    let csv = dir.path().join("sweep.csv");
    let cases: [(&[&str], &str); 6] = [
        (&["--windows", "0,abc"], "`0`"),
        (&["--windows", "10,abc"], "`abc`"),
        (&["--horizons", "10,-3"], "`-3`"),
        (&["--orders", "4,4"], "`4,4`"),
        (&["--methods", "paper,magic"], "magic"),
        (&["--hop", "0"], "--hop"),
    ];
    for (extra, needle) in cases {
        let mut args = vec!["sweep", s(&input), "-o", s(&csv)];
        args.extend_from_slice(extra);
        let o = feedid(&args);
        assert_fails(&o, &[needle]);
    }
    // every window longer than the recording: nothing could run
    let o = feedid(&["sweep", s(&input), "--windows", "100000", "-o", s(&csv)]);
    assert_fails(&o, &["no combination could run"]);
    // the heat map cannot be written: the CSV written before it is removed
    let o = feedid(&[
        "sweep",
        s(&input),
        "--windows",
        "20",
        "-o",
        s(&csv),
        "--plot",
        s(&dir.path().join("no/such/dir/map.svg")),
    ]);
    assert_fails(&o, &["map.svg"]);
    only(dir.path(), &[&input]);
}

#[test]
fn reproduce_writes_the_report_of_both_experiments() {
    let dir = tempfile::tempdir().unwrap();
    let o = feedid(&[
        "reproduce",
        "--out",
        s(dir.path()),
        "--solver",
        "qr",
        "--compare",
        "arx",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let html = std::fs::read_to_string(dir.path().join("report.html")).unwrap();
    for exp in ["ramp", "step"] {
        for f in [
            "overview",
            "response-zoom",
            "error-zoom",
            "coef-paper1",
            "coef-arx2",
            "bode-mag",
        ] {
            assert!(
                html.contains(&format!("<figure id=\"{exp}-{f}\">")),
                "{exp}-{f}"
            );
        }
    }
    assert!(html.contains("<table id=\"paper-table\">"));
    assert!(!html.contains("http://") && !html.contains("<script"));
    let o = feedid(&[
        "reproduce",
        "--out",
        s(&dir.path().join("x")),
        "--compare",
        "magic",
    ]);
    assert_fails(&o, &["magic"]);
}
