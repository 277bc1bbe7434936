//! Negative numbers typed as option values: every numeric option
//! of every command takes `-5` or `-1e-6` as its value, so the validator
//! answers with its own message naming the option and the value — never
//! clap's "unexpected argument".

use super::{csv, rows, run};
use crate::common::stderr;

/// (command line, what the one error line must contain); `{good}` a
/// recording, `{des}` a desired trajectory.
const NEGATIVE: &[(&[&str], &[&str])] = &[
    (
        &[
            "simulate",
            "--scenario",
            "ramp",
            "--rate",
            "-5000",
            "-o",
            "/dev/null",
        ],
        &["rate", "-5000"],
    ),
    (
        &[
            "simulate",
            "--scenario",
            "ramp",
            "--rate",
            "-5e3",
            "-o",
            "/dev/null",
        ],
        &["rate", "-5000"],
    ),
    (
        &[
            "simulate",
            "--scenario",
            "ramp",
            "--duration",
            "-1",
            "-o",
            "/dev/null",
        ],
        &["duration", "-1"],
    ),
    (&["info", "{good}", "--scale", "-0"], &["scale"]),
    (
        &["info", "{good}", "--jitter-tol", "-0.1"],
        &["jitter", "-0.1"],
    ),
    (
        &["info", "{good}", "--rate", "-5", "--time", "1"],
        &["rate", "-5"],
    ),
    (
        &["identify", "{good}", "-o", "/dev/null", "--window", "-5"],
        &["-5", "--window"],
    ),
    (
        &["identify", "{good}", "-o", "/dev/null", "--horizon", "-1"],
        &["-1", "--horizon"],
    ),
    (
        &["identify", "{good}", "-o", "/dev/null", "--hop", "-2"],
        &["-2", "--hop"],
    ),
    (
        &[
            "identify",
            "{good}",
            "-o",
            "/dev/null",
            "--method",
            "rls",
            "--lambda",
            "-0.5",
        ],
        &["lambda", "-0.5"],
    ),
    (
        &["identify", "{good}", "-o", "/dev/null", "--ridge", "-3"],
        &["ridge", "-3"],
    ),
    (
        &["report", "{good}", "-o", "/dev/null", "--zoom", "-3"],
        &["zoom", "-3"],
    ),
    (
        &["sweep", "{good}", "-o", "/dev/null", "--hop", "-1"],
        &["-1", "--hop"],
    ),
    (
        &["order", "{good}", "--validation", "-0.3"],
        &["validation", "-0.3"],
    ),
    (&["stream", "--rate", "-5"], &["rate", "-5"]),
    (
        &[
            "compensate",
            "--desired",
            "{des}",
            "--params",
            "{rig}",
            "-o",
            "/dev/null",
            "--max-velocity",
            "-1",
        ],
        &["velocity", "-1"],
    ),
    (
        &[
            "compensate",
            "--desired",
            "{des}",
            "--params",
            "{rig}",
            "-o",
            "/dev/null",
            "--max-acceleration",
            "-2e1",
        ],
        &["acceleration", "-20"],
    ),
    (
        &[
            "compensate",
            "--desired",
            "{des}",
            "--params",
            "{rig}",
            "-o",
            "/dev/null",
            "--max-smoothing",
            "-0.1",
        ],
        &["smoothing", "-0.1"],
    ),
    (
        &[
            "compensate",
            "--desired",
            "{des}",
            "--params",
            "{rig}",
            "-o",
            "/dev/null",
            "--smooth",
            "-0.5",
        ],
        &["-0.5"],
    ),
    (
        &[
            "greybox",
            "{good}",
            "--estimate",
            "Kv",
            "--track-window",
            "-0.1",
            "--track-out",
            "/dev/null",
        ],
        &["track-window", "-0.1"],
    ),
    (
        &[
            "greybox",
            "{good}",
            "--estimate",
            "Kv",
            "--max-iterations",
            "-3",
        ],
        &["-3", "--max-iterations"],
    ),
    (
        &["greybox", "{good}", "--estimate", "Kv", "--restarts", "-1"],
        &["-1", "--restarts"],
    ),
];

#[test]
fn negative_option_values_reach_their_validator() {
    let tmp = tempfile::tempdir().unwrap();
    let good = tmp.path().join("good.csv");
    std::fs::write(&good, csv(&rows(300, 0.0, 1e-3, 1.0))).unwrap();
    let des = tmp.path().join("des.csv");
    let mut d = String::from("time_s,position_m\n");
    for k in 0..400 {
        d += &format!("{},{}\n", k as f64 * 2e-4, 1e-6 * k as f64);
    }
    std::fs::write(&des, d).unwrap();
    let rig = tmp.path().join("rig.toml");
    std::fs::write(&rig, "").unwrap();
    let mut failures = Vec::new();
    for (line, needles) in NEGATIVE {
        let args: Vec<String> = line
            .iter()
            .map(|a| {
                a.replace("{good}", good.to_str().unwrap())
                    .replace("{des}", des.to_str().unwrap())
                    .replace("{rig}", rig.to_str().unwrap())
            })
            .collect();
        let stdin = (args[0] == "stream").then_some(&b"0,0,0\n"[..]);
        let o = run(&args, stdin);
        let err = stderr(&o);
        let first = err.lines().find(|l| l.starts_with("error:")).unwrap_or("");
        let ok = o.status.code() == Some(2)
            && !err.contains("unexpected argument")
            && needles.iter().all(|n| first.contains(n));
        if !ok {
            failures.push(format!("{line:?}: exit {:?}\n{err}", o.status.code()));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}
