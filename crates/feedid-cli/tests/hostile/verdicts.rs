//! Results that never mislead: verdicts agree with the data.
//!
//! - grey-box: a model that leaves structure in the residuals (the linear
//!   model of a rig with friction, position alone or with the current, any
//!   excitation) calls no estimate identifiable; the friction model of the
//!   same data does;
//! - tracking: windows without excitation of the tracked parameter give no
//!   estimate (a plain ramp for the stiffness, whatever the window);
//! - residual analysis: the `r_ee` verdict starts at the horizon, and the
//!   report's captions count the lags outside the band.

use super::run;
use crate::common::{stderr, stdout};

fn simulate(dir: &std::path::Path, name: &str, args: &[&str]) -> std::path::PathBuf {
    let p = dir.join(name);
    let mut a: Vec<String> = vec!["simulate".into()];
    a.extend(args.iter().map(|s| s.to_string()));
    a.extend(["-o".into(), p.display().to_string()]);
    let o = run(&a, None);
    assert!(o.status.success(), "{}", stderr(&o));
    p
}

fn json(p: &std::path::Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

#[test]
fn a_model_that_leaves_structure_calls_nothing_identifiable() {
    let tmp = tempfile::tempdir().unwrap();
    let mut failures = Vec::new();
    // (scenario, extra greybox arguments): the linear model of the rig's data
    let cases: [(&str, &[&str]); 4] = [
        ("prbs", &["--current", "current_a"]),
        ("prbs", &[]),
        ("chirp", &["--current", "current_a"]),
        ("multisine", &["--current", "current_a"]),
    ];
    for (scenario, extra) in cases {
        let rec = simulate(
            tmp.path(),
            &format!("{scenario}.csv"),
            &["--scenario", scenario, "--seed", "2"],
        );
        let summary = tmp.path().join("gb.json");
        let mut args: Vec<String> = [
            "greybox",
            rec.to_str().unwrap(),
            "--estimate",
            "Kv,Kp,Ki,C2,M",
            "--summary",
            summary.to_str().unwrap(),
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        args.extend(extra.iter().map(|s| s.to_string()));
        let o = run(&args, None);
        if !o.status.success() {
            failures.push(format!("{scenario} {extra:?}: {}", stderr(&o)));
            continue;
        }
        let v = json(&summary);
        for e in v["estimates"].as_array().unwrap() {
            if e["verdict"] == "identifiable" {
                failures.push(format!(
                    "{scenario} {extra:?}: {} called identifiable: {e}",
                    e["name"]
                ));
            }
        }
        if !stderr(&o).contains("not white") {
            failures.push(format!("{scenario} {extra:?}: no warning\n{}", stderr(&o)));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

#[test]
fn the_friction_model_of_the_same_data_is_identifiable() {
    let tmp = tempfile::tempdir().unwrap();
    let rec = simulate(
        tmp.path(),
        "prbs.csv",
        &["--scenario", "prbs", "--seed", "2", "--duration", "0.6"],
    );
    let summary = tmp.path().join("gb.json");
    let o = run(
        &[
            "greybox",
            rec.to_str().unwrap(),
            "--estimate",
            "Kv,Kp,M",
            "--friction",
            "--current",
            "current_a",
            "--summary",
            summary.to_str().unwrap(),
        ]
        .map(String::from),
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let v = json(&summary);
    for e in v["estimates"].as_array().unwrap() {
        assert_eq!(e["verdict"], "identifiable", "{e}\n{}", stdout(&o));
    }
    for s in v["residual_structure"].as_array().unwrap() {
        assert_eq!(s["structured"], false, "{s}");
    }
}

#[test]
fn tracking_gives_no_estimate_in_windows_without_excitation() {
    let tmp = tempfile::tempdir().unwrap();
    let rec = simulate(tmp.path(), "ramp.csv", &["--scenario", "ramp"]);
    let k0 = 3.0e7;
    for (window, hop) in [("0.1", "0.05"), ("0.05", "0.05"), ("0.2", "0.1")] {
        let track = tmp.path().join("k.csv");
        let o = run(
            &[
                "greybox",
                rec.to_str().unwrap(),
                "--estimate",
                "K",
                "--track-window",
                window,
                "--track-hop",
                hop,
                "--track-out",
                track.to_str().unwrap(),
            ]
            .map(String::from),
            None,
        );
        assert!(o.status.success(), "{}", stderr(&o));
        let text = std::fs::read_to_string(&track).unwrap();
        let mut lines = text.lines();
        let head: Vec<&str> = lines.next().unwrap().split(',').collect();
        let col = |n: &str| head.iter().position(|h| *h == n).unwrap();
        let (k, verdict, term) = (col("K"), col("K_verdict"), col("termination"));
        let mut skipped = 0;
        for l in lines {
            let f: Vec<&str> = l.split(',').collect();
            if f[term] == "not_excited" {
                skipped += 1;
                assert_eq!(f[k], "", "{l}");
                assert_eq!(f[verdict], "not identifiable", "{l}");
            } else {
                let v: f64 = f[k].parse().unwrap();
                assert!(v < 10.0 * k0 && v > 0.1 * k0, "window {window}: K {v}");
                assert_ne!(f[verdict], "not identifiable", "{l}");
            }
        }
        assert!(
            skipped > 0,
            "window {window}: every window of a plain ramp excited K?\n{text}"
        );
    }
}

#[test]
fn the_residual_verdict_starts_at_the_horizon_and_captions_count_right() {
    let tmp = tempfile::tempdir().unwrap();
    let rec = simulate(tmp.path(), "chirp.csv", &["--scenario", "chirp"]);
    for h in ["1", "10", "20"] {
        let summary = tmp.path().join("s.json");
        let o = run(
            &[
                "identify",
                rec.to_str().unwrap(),
                "--method",
                "arx",
                "--horizon",
                h,
                "-o",
                "/dev/null",
                "--summary",
                summary.to_str().unwrap(),
            ]
            .map(String::from),
            None,
        );
        assert!(o.status.success(), "{}", stderr(&o));
        let r = &json(&summary)["residuals"];
        let h: u64 = h.parse().unwrap();
        assert_eq!(r["ee_first_lag"], h, "{r}");
        assert!(r["max_lag"].as_u64().unwrap() >= 2 * h, "{r}");
        // the count is over the lags from the horizon on
        let outside = r["r_ee"].as_array().unwrap()[h as usize..]
            .iter()
            .filter(|v| v.as_f64().unwrap().abs() > r["bound"].as_f64().unwrap())
            .count();
        assert_eq!(r["ee_outside"], outside as u64, "{r}");
    }
    let html = tmp.path().join("r.html");
    let o = run(
        &[
            "report",
            rec.to_str().unwrap(),
            "--methods",
            "arx",
            "-o",
            html.to_str().unwrap(),
        ]
        .map(String::from),
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let page = std::fs::read_to_string(&html).unwrap();
    assert!(
        !page.contains("lags inside the band"),
        "a count of lags said to be inside"
    );
    assert!(
        page.contains("lags outside the 99 % band"),
        "no count of lags outside"
    );
    assert!(
        page.contains("lags τ = 10 … 30 outside"),
        "r_ee caption without the horizon"
    );
}

#[test]
fn restarts_beyond_the_bound_are_refused_at_once_for_every_structure() {
    let dir = tempfile::tempdir().unwrap();
    let rec = simulate(
        dir.path(),
        "prbs.csv",
        &["--scenario", "prbs", "--duration", "0.2"],
    );
    let emps = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/emps.toml");
    for (extra, restarts) in [
        (&["--estimate", "Kv"][..], "1000000000"),
        (&["--params", emps, "--estimate", "M"][..], "101"),
    ] {
        let mut a: Vec<String> = vec!["greybox".into(), rec.display().to_string()];
        a.extend(extra.iter().map(|s| s.to_string()));
        a.extend(["--restarts".into(), restarts.into()]);
        let o = run(&a, None);
        assert_eq!(o.status.code(), Some(2), "{extra:?}");
        let err = stderr(&o);
        assert!(
            err.contains("restarts") && err.contains(restarts) && err.contains("at most 100"),
            "{err}"
        );
        assert!(stdout(&o).is_empty(), "{extra:?}");
    }
}

#[test]
fn a_model_that_explains_nothing_of_a_dead_encoder_determines_nothing() {
    // the command moves, the position stays at 0: whatever the standard
    // errors say, no parameter is determined by such data
    let dir = tempfile::tempdir().unwrap();
    let rec = simulate(dir.path(), "prbs.csv", &["--scenario", "prbs"]);
    let text = std::fs::read_to_string(&rec).unwrap();
    let mut dead = String::new();
    for (i, line) in text.lines().enumerate() {
        let f: Vec<&str> = line.split(',').collect();
        if i == 0 {
            dead += "time_s,command_m,position_m\n";
        } else {
            dead += &format!("{},{},0\n", f[0], f[1]);
        }
    }
    let path = dir.path().join("dead.csv");
    std::fs::write(&path, dead).unwrap();
    let summary = dir.path().join("g.json");
    let o = run(
        &[
            "greybox",
            path.to_str().unwrap(),
            "--estimate",
            "Kv",
            "--restarts",
            "0",
            "--summary",
            summary.to_str().unwrap(),
        ]
        .map(String::from),
        None,
    );
    if o.status.success() {
        let v = json(&summary);
        for e in v["estimates"].as_array().unwrap() {
            assert_ne!(e["verdict"], "identifiable", "{e}");
        }
        assert!(stdout(&o).contains("not identifiable"), "{}", stdout(&o));
    } else {
        assert!(stderr(&o).contains("not identifiable"), "{}", stderr(&o));
    }
}
