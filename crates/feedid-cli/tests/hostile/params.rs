//! Unstable physical models, as a table: every family of
//! unstable parameters (high position gain, high velocity gain, high
//! integral gains, a soft screw) × every command that uses a rig file.
//! `model` says UNSTABLE (`"stable": false` in JSON); every command that
//! simulates or inverts the model refuses it naming the poles, exit 2, and
//! with `--allow-unstable` runs without ever writing a non-finite number.

use super::{check, csv, rows, run, Expect};
use crate::common::stderr;

/// Families of unstable parameter sets.
const UNSTABLE: [(&str, &str); 4] = [
    ("high position gain", "[control]\nkv = 3000.0\n"),
    ("high velocity gain", "[control]\nkp = 3000.0\n"),
    (
        "high integral gains",
        "[control]\nki = 5000.0\nkii = 50000.0\n",
    ),
    ("soft screw", "[stiffness]\nnut = 2e5\nbearing = 2e5\n"),
];

/// Commands that use a rig file, `{rig}` the file, `{out}` the output directory.
const USERS: [(&str, &[&str]); 7] = [
    (
        "simulate",
        &[
            "simulate",
            "--scenario",
            "step",
            "--duration",
            "0.05",
            "--params",
            "{rig}",
            "-o",
            "{out}/s.csv",
        ],
    ),
    (
        "identify",
        &[
            "identify",
            "{good}",
            "--method",
            "arx",
            "--order",
            "2,2,1",
            "--window",
            "40",
            "--params",
            "{rig}",
            "-o",
            "{out}/p.csv",
            "--summary",
            "{out}/s.json",
        ],
    ),
    (
        "report",
        &[
            "report",
            "{good}",
            "--methods",
            "arx",
            "--order",
            "2,2,1",
            "--window",
            "40",
            "--params",
            "{rig}",
            "-o",
            "{out}/r.html",
        ],
    ),
    (
        "compensate --params",
        &[
            "compensate",
            "--desired",
            "{des}",
            "--params",
            "{rig}",
            "-o",
            "{out}/c.csv",
        ],
    ),
    (
        "compensate --rig",
        &[
            "compensate",
            "--desired",
            "{des}",
            "--params",
            "{stable}",
            "--verify",
            "--rig",
            "{rig}",
            "-o",
            "{out}/c.csv",
        ],
    ),
    (
        "greybox",
        &[
            "greybox",
            "{good}",
            "--estimate",
            "Kv",
            "--max-iterations",
            "3",
            "--restarts",
            "0",
            "--params",
            "{rig}",
            "--summary",
            "{out}/g.json",
        ],
    ),
    (
        "reproduce",
        &[
            "reproduce",
            "--compare",
            "none",
            "--params",
            "{rig}",
            "--out",
            "{out}",
        ],
    ),
];

#[test]
fn an_unstable_model_is_named_and_refused_unless_allowed() {
    let tmp = tempfile::tempdir().unwrap();
    let good = tmp.path().join("good.csv");
    std::fs::write(&good, csv(&rows(300, 0.0, 1e-3, 1.0))).unwrap();
    let des = tmp.path().join("des.csv");
    let mut d = String::from("time_s,position_m\n");
    for k in 0..400 {
        let t = k as f64 * 2e-4;
        // 0.1 mm in 40 ms, at rest before and after
        let x = ((t - 0.02) / 0.04).clamp(0.0, 1.0);
        d += &format!(
            "{t},{}\n",
            0.5e-4 * (1.0 - (std::f64::consts::PI * x).cos())
        );
    }
    std::fs::write(&des, d).unwrap();
    let stable = tmp.path().join("stable.toml");
    std::fs::write(&stable, "").unwrap();
    let mut failures = Vec::new();
    for (family, text) in UNSTABLE {
        let rig = tmp.path().join("rig.toml");
        std::fs::write(&rig, text).unwrap();
        // model: says so, in text and JSON, and gives no bandwidth
        let o = run(
            &["model".into(), "--params".into(), rig.display().to_string()],
            None,
        );
        let out = crate::common::stdout(&o);
        if !o.status.success() || !out.contains("UNSTABLE") || !out.contains("none (unstable)") {
            failures.push(format!("{family} / model:\n{out}{}", stderr(&o)));
        }
        let o = run(
            &[
                "model".into(),
                "--json".into(),
                "--params".into(),
                rig.display().to_string(),
            ],
            None,
        );
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        if v["stable"] != serde_json::Value::Bool(false) || !v["bandwidth_hz"].is_null() {
            failures.push(format!("{family} / model --json: {v}"));
        }
        for (name, line) in USERS {
            for allow in [false, true] {
                let out = tmp.path().join("out");
                std::fs::create_dir_all(&out).unwrap();
                let mut args: Vec<String> = line
                    .iter()
                    .map(|a| {
                        a.replace("{rig}", rig.to_str().unwrap())
                            .replace("{stable}", stable.to_str().unwrap())
                            .replace("{good}", good.to_str().unwrap())
                            .replace("{des}", des.to_str().unwrap())
                            .replace("{out}", out.to_str().unwrap())
                    })
                    .collect();
                if allow {
                    args.push("--allow-unstable".into());
                }
                let o = run(&args, None);
                let expect = if allow {
                    // it runs; a model that runs away is still never written
                    Expect::SucceedsOrFails(&["runs away", "diverged"])
                } else {
                    Expect::Fails(&["rig.toml", "unstable", "rad/s", "--allow-unstable"])
                };
                let res = match expect {
                    // either refusal names what ran away
                    Expect::SucceedsOrFails(_) if !o.status.success() => {
                        let err = stderr(&o);
                        if err.contains("runs away") || err.contains("diverged") {
                            check(&o, Expect::Fails(&[]), "", &out)
                        } else {
                            Err(format!("unexpected failure\n{err}"))
                        }
                    }
                    Expect::SucceedsOrFails(_) => check(&o, Expect::Succeeds, "", &out),
                    e => check(&o, e, "", &out),
                };
                if let Err(e) = res {
                    failures.push(format!("{family} / {name} (allow {allow}): {e}"));
                }
                if allow && o.status.success() && !stderr(&o).contains("warning") {
                    failures.push(format!("{family} / {name}: allowed without a warning"));
                }
                std::fs::remove_dir_all(&out).unwrap();
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

#[test]
fn values_that_overflow_together_are_refused_by_every_command_alike() {
    // `model` refused kv = 1e300 but `simulate` accepted it
    let tmp = tempfile::tempdir().unwrap();
    let rig = tmp.path().join("huge.toml");
    std::fs::write(&rig, "[control]\nkv = 1e300\n").unwrap();
    let good = tmp.path().join("good.csv");
    std::fs::write(&good, csv(&rows(300, 0.0, 1e-3, 1.0))).unwrap();
    let r = rig.display().to_string();
    let g = good.display().to_string();
    for args in [
        vec!["model", "--params", &r],
        vec![
            "simulate",
            "--scenario",
            "step",
            "--params",
            &r,
            "-o",
            "/dev/null",
        ],
        vec!["identify", &g, "--params", &r, "-o", "/dev/null"],
        vec!["greybox", &g, "--estimate", "Kv", "--params", &r],
        vec!["report", &g, "--params", &r, "-o", "/dev/null"],
    ] {
        let args: Vec<String> = args.iter().map(|s| s.to_string()).collect();
        let o = run(&args, None);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains("huge.toml") && err.contains("non-finite"),
            "{args:?}: {err}"
        );
    }
}

#[test]
fn an_allowed_unstable_model_leaves_no_placeholder_number_in_any_output() {
    let tmp = tempfile::tempdir().unwrap();
    let p = |n: &str| tmp.path().join(n).display().to_string();
    std::fs::write(p("rig.toml"), "[control]\nkv = 3000.0\n").unwrap();
    let o = run(
        &["simulate", "--scenario", "ramp", "-o", &p("ramp.csv")].map(String::from),
        None,
    );
    assert!(o.status.success());
    let o = run(
        &[
            "identify",
            &p("ramp.csv"),
            "--method",
            "arx",
            "--params",
            &p("rig.toml"),
            "--allow-unstable",
            "-o",
            &p("pred.csv"),
            "--summary",
            &p("s.json"),
        ]
        .map(String::from),
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("ran away from t ="), "{}", stderr(&o));
    // every number in both files is of the recording's scale or a count
    for f in ["pred.csv", "s.json"] {
        let text = std::fs::read_to_string(p(f)).unwrap();
        for tok in text.split(|c: char| ",:[]{}\n ".contains(c)) {
            if let Ok(v) = tok.trim_matches('"').parse::<f64>() {
                assert!(v.abs() < 1e9, "{f}: {v}");
            }
        }
    }
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(p("s.json")).unwrap()).unwrap();
    assert!(s.get("nominal_fit_percent").is_none() && s.get("sim_max_abs_error_m").is_none());
    assert!(
        s["warnings"].to_string().contains("ran away"),
        "{}",
        s["warnings"]
    );
}

#[test]
fn gains_of_absurd_sizes_are_named_not_printed_as_long_numbers() {
    let tmp = tempfile::tempdir().unwrap();
    let rig = tmp.path().join("rig.toml");
    let r = rig.display().to_string();
    let model = |text: &str| {
        std::fs::write(&rig, text).unwrap();
        run(&["model", "--params", &r].map(String::from), None)
    };
    // a velocity gain a million times too small: stable, but the axis
    // barely follows; no line of digits
    for kv in ["1e-6", "1e-300"] {
        let o = model(&format!("[control]\nkv = {kv}\n"));
        let out = crate::common::stdout(&o);
        assert!(
            out.contains("the axis barely follows its command"),
            "{kv}: {out}"
        );
        assert!(out.lines().all(|l| l.len() < 200), "{kv}: {out}");
    }
    // a current-loop gain of 1e-300: the axis never moves, whatever the
    // position loop's following error says
    let o = model("[control]\nkpi = 1e-300\n");
    let out = crate::common::stdout(&o);
    assert!(
        out.contains("the axis barely follows its command"),
        "kpi: {out}"
    );
    // poles that cannot be computed are not "0 poles with a positive real part"
    let o = model("[control]\nkp = 1e-300\n");
    let out = crate::common::stdout(&o) + &stderr(&o);
    assert!(!out.contains("UNSTABLE: 0 poles"), "{out}");
    // simulate says the axis did not follow
    std::fs::write(&rig, "[control]\nkv = 1e-6\n").unwrap();
    let o = run(
        &[
            "simulate",
            "--scenario",
            "ramp",
            "--params",
            &r,
            "-o",
            &tmp.path().join("s.csv").display().to_string(),
        ]
        .map(String::from),
        None,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("far too slow for this command"),
        "{}",
        stderr(&o)
    );
}
