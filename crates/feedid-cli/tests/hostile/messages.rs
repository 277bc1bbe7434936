//! Messages that name the value and the limit, in the units a user reads:
//! a command lead that leaves nothing to use or more than a stream may
//! keep, a tiny interval probability, an oversized parameter file.

use super::{csv, rows, run};
use crate::common::stderr;

fn strings(a: &[&str]) -> Vec<String> {
    a.iter().map(|s| s.to_string()).collect()
}

#[test]
fn a_command_lead_that_leaves_nothing_to_use_is_an_error() {
    let input = csv(&rows(400, 0.0, 1e-3, 1.0));
    for lead in ["400", "1000"] {
        let o = run(&strings(&["stream", "--command-lead", lead]), Some(&input));
        assert_eq!(o.status.code(), Some(2), "lead {lead}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains("no sample could be used"), "{e}");
        assert!(
            e.contains(&format!("--command-lead {lead}")) && e.contains("400 data lines"),
            "{e}"
        );
    }
    // one line shorter than the input: one sample, not an error
    let o = run(&strings(&["stream", "--command-lead", "399"]), Some(&input));
    assert!(
        !stderr(&o).contains("no sample could be used"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn a_command_lead_beyond_the_stream_buffer_names_the_value_and_the_limit() {
    let input = csv(&rows(50, 0.0, 1e-3, 1.0));
    let o = run(
        &strings(&["stream", "--command-lead", "100000000"]),
        Some(&input),
    );
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(!e.contains("inf"), "{e}");
    assert!(
        e.contains("100000000") && e.contains("more than the 3355"),
        "{e}"
    );
    assert!(e.contains("shorten the command lead"), "{e}");
}

#[test]
fn a_tiny_interval_probability_is_printed_in_e_notation() {
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("r.csv");
    std::fs::write(&rec, csv(&rows(300, 0.0, 1e-3, 1.0))).unwrap();
    let o = run(
        &strings(&[
            "identify",
            rec.to_str().unwrap(),
            "--method",
            "arx",
            "--interval",
            "1e-300",
            "-o",
            "/dev/null",
        ]),
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("inside the 1e-300 % interval"), "{text}");
    assert!(!text.contains("0.0000000000"), "{text}");
}

#[test]
fn an_oversized_parameter_file_is_called_what_it_is() {
    let dir = tempfile::tempdir().unwrap();
    let big = dir.path().join("big.toml");
    let mut text = String::from("[control]\nkv = 30.0\n");
    text.push_str(&"# padding\n".repeat(1_700_000));
    std::fs::write(&big, text).unwrap();
    let o = run(
        &strings(&["model", "--params", big.to_str().unwrap()]),
        None,
    );
    assert_eq!(o.status.code(), Some(2));
    let e = stderr(&o);
    assert!(
        e.contains("big.toml") && e.contains("larger than 16777216 bytes"),
        "{e}"
    );
    assert!(
        !e.contains("pipe or device") && !e.contains("feedid stream"),
        "{e}"
    );
}

#[test]
fn a_plain_command_sent_instead_must_meet_the_limits_too() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    for a in [
        vec!["simulate", "--scenario", "ramp", "-o", &p("ramp.csv")],
        vec!["simulate", "--scenario", "prbs", "-o", &p("prbs.csv")],
    ] {
        assert!(run(&strings(&a), None).status.success());
    }
    let o = run(
        &strings(&[
            "identify",
            &p("prbs.csv"),
            "-o",
            &p("pred.csv"),
            "--model-out",
            &p("m.json"),
            "--model-kind",
            "oe",
        ]),
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    // `compensate` of the ramp's command with the model, and `extra` options
    let compensate = |extra: &[&str]| {
        let mut a = strings(&[
            "compensate",
            "--desired",
            &p("ramp.csv"),
            "--desired-column",
            "command_m",
            "--model",
            &p("m.json"),
            "-o",
            &p("cmd.csv"),
        ]);
        a.extend(strings(extra));
        run(&a, None)
    };
    // --min-fit 100: the plain command is sent; the ramp's start asks 250 m/s²
    let o = compensate(&["--min-fit", "100", "--max-acceleration", "30"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("the plain command") && e.contains("acceleration of 250.0000 m/s²"),
        "{e}"
    );
    assert!(e.contains("beyond the limit 30 m/s²"), "{e}");
    assert!(!dir.path().join("cmd.csv").exists());
    // a smoothing whose buffers would grow with σ² beyond memory: refused
    // at once with the value and the bound, whatever its size
    for (flag, v) in [
        ("--smooth", "1"),
        ("--smooth", "10"),
        ("--smooth", "1e9"),
        ("--max-smoothing", "1e3"),
    ] {
        let o = compensate(&[flag, v]);
        assert_eq!(o.status.code(), Some(2), "{flag} {v}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains("more than the 1000 samples (0.2 s)"), "{e}");
        assert!(!dir.path().join("cmd.csv").exists());
    }
}
