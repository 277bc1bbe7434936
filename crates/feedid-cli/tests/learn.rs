//! End-to-end tests of learning from measured runs (`feedid compensate
//! --measured`) with `feedid simulate --command` as the axis: the loop a
//! user runs, its history, and bad input (exit code 2, one line naming the
//! culprit, nothing written).

mod common;

use std::path::{Path, PathBuf};

use common::{assert_fails, csv_column as column, feedid, stderr, stdout};

fn run_ok(args: &[&str]) -> String {
    let o = feedid(args);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    stdout(&o)
}

fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// A heavy axis with velocity feed-forward and 25 N of Coulomb friction: a
/// linear model identified on it leaves a few µm that learning removes.
fn heavy_axis(dir: &Path) -> (PathBuf, PathBuf) {
    let params = dir.join("heavy.toml");
    std::fs::write(
        &params,
        "[table]\nmass = 60.0\n[control]\nkv = 60.0\nkvff = 0.9\n",
    )
    .unwrap();
    let effects = dir.join("fx.toml");
    std::fs::write(
        &effects,
        "[table_friction]\ncoulomb = 25.0\nbreakaway = 30.0\nstribeck_velocity = 1e-3\nsmoothing_velocity = 1e-4\n",
    )
    .unwrap();
    (params, effects)
}

/// The built-in rig's S-curve in `dir` (`prog.csv`) and the model
/// `identify` writes of it (`m.json`).
fn scurve_and_model(dir: &Path) -> (PathBuf, PathBuf) {
    let prog = dir.join("prog.csv");
    run_ok(&["simulate", "--scenario", "scurve", "-o", p(&prog)]);
    let model = dir.join("m.json");
    run_ok(&[
        "identify",
        p(&prog),
        "-o",
        p(&dir.join("pred.csv")),
        "--model-out",
        p(&model),
    ]);
    (prog, model)
}

/// Run `command` on the axis (fresh noise per seed); the recording's path.
fn run_on_axis(dir: &Path, axis: &(PathBuf, PathBuf), command: &Path, seed: u64) -> PathBuf {
    let out = dir.join(format!("run{seed}.csv"));
    let seed = seed.to_string();
    run_ok(&[
        "simulate",
        "--command",
        p(command),
        "--params",
        p(&axis.0),
        "--effects",
        p(&axis.1),
        "--seed",
        &seed,
        "-o",
        p(&out),
    ]);
    out
}

#[test]
fn learning_from_runs_lowers_the_measured_error_run_by_run() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let axis = heavy_axis(d);
    let prog = d.join("prog.csv");
    run_ok(&[
        "simulate",
        "--scenario",
        "scurve",
        "--params",
        p(&axis.0),
        "--effects",
        p(&axis.1),
        "-o",
        p(&prog),
    ]);
    let model = d.join("m.json");
    run_ok(&[
        "identify",
        p(&prog),
        "-o",
        p(&d.join("pred.csv")),
        "--model-out",
        p(&model),
    ]);
    let cmd1 = d.join("cmd1.csv");
    run_ok(&[
        "compensate",
        "--desired",
        p(&prog),
        "--desired-column",
        "command_m",
        "--model",
        p(&model),
        "-o",
        p(&cmd1),
    ]);
    let history = d.join("history.json");
    let mut command = cmd1;
    let mut rms = Vec::new();
    for run in 1..=4u64 {
        let rec = run_on_axis(d, &axis, &command, run);
        let next = d.join(format!("cmd{}.csv", run + 1));
        let summary = d.join(format!("s{run}.json"));
        let text = run_ok(&[
            "compensate",
            "--desired",
            p(&prog),
            "--desired-column",
            "command_m",
            "--model",
            p(&model),
            "--measured",
            p(&rec),
            "--history",
            p(&history),
            "-o",
            p(&next),
            "--summary",
            p(&summary),
        ]);
        assert!(text.contains(&format!("run {run} of")), "{text}");
        let s = json(&summary);
        assert_eq!(s["run"], run);
        // the robustness filter needs an answer to a step: none in run 1;
        // it floors the step's filter
        let robust = s["robustness_filter_s"].as_f64().unwrap();
        assert!(run > 1 || robust == 0.0, "{s}");
        assert!(s["noise_filter_s"].as_f64().unwrap() >= robust, "{s}");
        rms.push(s["measured"]["rms"].as_f64().unwrap());
        let h = json(&history);
        assert_eq!(h["runs"].as_array().unwrap().len(), run as usize);
        assert_eq!(h["format"], "feedid-learning-history");
        command = next;
    }
    // the compensated run is a few µm off (friction), learning takes it
    // well below: each run no worse than the one before beyond the noise
    assert!(rms[0] > 2e-6, "{rms:?}");
    for w in rms.windows(2) {
        assert!(w[1] < w[0] + 0.2e-6, "{rms:?}");
    }
    assert!(rms[3] < 0.5 * rms[0], "{rms:?}");
}

#[test]
fn the_sent_command_can_be_given_apart_from_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let axis = heavy_axis(d);
    let (prog, model) = scurve_and_model(d);
    let rec = run_on_axis(d, &axis, &prog, 1);
    let a = d.join("a.csv");
    let b = d.join("b.csv");
    let base = [
        "compensate",
        "--desired",
        p(&prog),
        "--desired-column",
        "command_m",
        "--model",
        p(&model),
        "--measured",
        p(&rec),
    ];
    let mut with_sent = base.to_vec();
    with_sent.extend_from_slice(&["--sent", p(&prog), "-o", p(&a)]);
    run_ok(&with_sent);
    let mut own = base.to_vec();
    own.extend_from_slice(&["-o", p(&b)]);
    run_ok(&own);
    // the run's own command column is the program: the same next command
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
}

#[test]
fn a_run_of_another_length_or_a_foreign_history_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (prog, model) = scurve_and_model(d);
    let short = d.join("short.csv");
    run_ok(&[
        "simulate",
        "--scenario",
        "scurve",
        "--duration",
        "0.2",
        "-o",
        p(&short),
    ]);
    let out = d.join("next.csv");
    let o = feedid(&[
        "compensate",
        "--desired",
        p(&prog),
        "--desired-column",
        "command_m",
        "--model",
        p(&model),
        "--measured",
        p(&short),
        "-o",
        p(&out),
    ]);
    assert_fails(&o, &["short.csv", "1000 samples", "2000"]);
    assert!(!out.exists());

    // a history of another program
    let other = d.join("ramp.csv");
    run_ok(&[
        "simulate",
        "--scenario",
        "ramp",
        "--duration",
        "0.4",
        "-o",
        p(&other),
    ]);
    let history = d.join("h.json");
    run_ok(&[
        "compensate",
        "--desired",
        p(&other),
        "--desired-column",
        "command_m",
        "--model",
        p(&model),
        "--measured",
        p(&other),
        "--history",
        p(&history),
        "-o",
        p(&out),
    ]);
    std::fs::remove_file(&out).unwrap();
    let before = std::fs::read(&history).unwrap();
    let o = feedid(&[
        "compensate",
        "--desired",
        p(&prog),
        "--desired-column",
        "command_m",
        "--model",
        p(&model),
        "--measured",
        p(&prog),
        "--history",
        p(&history),
        "-o",
        p(&out),
    ]);
    assert_fails(&o, &["learning history is of another program"]);
    assert!(!out.exists());
    assert_eq!(std::fs::read(&history).unwrap(), before);

    // not a history at all
    std::fs::write(&history, "{\"runs\": 3}").unwrap();
    let o = feedid(&[
        "compensate",
        "--desired",
        p(&prog),
        "--desired-column",
        "command_m",
        "--model",
        p(&model),
        "--measured",
        p(&prog),
        "--history",
        p(&history),
        "-o",
        p(&out),
    ]);
    assert_fails(&o, &["h.json", "not a feedid learning history"]);
    assert!(!out.exists());

    // a bad gain
    let o = feedid(&[
        "compensate",
        "--desired",
        p(&prog),
        "--desired-column",
        "command_m",
        "--model",
        p(&model),
        "--measured",
        p(&prog),
        "--learning-gain",
        "2.5",
        "-o",
        p(&out),
    ]);
    assert_fails(&o, &["learning gain", "2.5"]);
}

#[test]
fn simulate_runs_a_command_from_a_file_at_its_own_rate() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let prog = d.join("prog.csv");
    run_ok(&[
        "simulate",
        "--scenario",
        "scurve",
        "--rate",
        "2000",
        "--seed",
        "4",
        "-o",
        p(&prog),
    ]);
    let again = d.join("again.csv");
    let text = run_ok(&[
        "simulate",
        "--command",
        p(&prog),
        "--seed",
        "4",
        "-o",
        p(&again),
    ]);
    assert!(text.contains("800 samples at 2000"), "{text}");
    // the same command from rest at 0 with the same seed: the same recording
    assert_eq!(
        std::fs::read_to_string(&prog).unwrap(),
        std::fs::read_to_string(&again).unwrap()
    );
    let o = feedid(&[
        "simulate",
        "--command",
        p(&prog),
        "--scenario",
        "ramp",
        "-o",
        p(&again),
    ]);
    assert_eq!(o.status.code(), Some(2));
}

#[cfg(unix)]
#[test]
fn a_history_that_is_not_a_regular_file_is_refused_and_left_alone() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (prog, model) = scurve_and_model(d);
    let target = d.join("precious.txt");
    std::fs::write(&target, "keep me").unwrap();
    let link = d.join("h.json");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    let out = d.join("next.csv");
    let o = feedid(&[
        "compensate",
        "--desired",
        p(&prog),
        "--desired-column",
        "command_m",
        "--model",
        p(&model),
        "--measured",
        p(&prog),
        "--history",
        p(&link),
        "-o",
        p(&out),
    ]);
    assert_fails(&o, &["h.json", "not a regular file"]);
    assert!(!out.exists());
    assert_eq!(std::fs::read_to_string(&target).unwrap(), "keep me");
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
}

#[test]
fn a_step_the_axis_did_not_answer_settles_on_the_best_run_and_says_why() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (prog, model) = scurve_and_model(d);
    let history = d.join("h.json");
    let learn = |sent: Option<&Path>, out: &Path, summary: &Path| {
        let mut args = vec![
            "compensate",
            "--desired",
            p(&prog),
            "--desired-column",
            "command_m",
            "--model",
            p(&model),
            "--measured",
            p(&prog),
            "--history",
            p(&history),
            "-o",
            p(out),
            "--summary",
            p(summary),
        ];
        if let Some(s) = sent {
            args.extend_from_slice(&["--sent", p(s)]);
        }
        let o = feedid(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        (stdout(&o), stderr(&o))
    };
    // run 1: the plain program; a step from it
    let cmd2 = d.join("cmd2.csv");
    learn(None, &cmd2, &d.join("s1.json"));
    // run 2 "measured" the same position although cmd2 was sent: the step
    // achieved nothing of what the model predicted
    let cmd3 = d.join("cmd3.csv");
    let s2 = d.join("s2.json");
    let (out, err) = learn(Some(&cmd2), &cmd3, &s2);
    let s = json(&s2);
    assert_eq!(s["status"]["status"], "settled", "{s}");
    assert_eq!(s["status"]["best_run"], 1, "{s}");
    assert!(
        s["status"]["achieved_share"].as_f64().unwrap().abs() < 0.01,
        "{s}"
    );
    assert_eq!(s["gain"], 0.0);
    assert!(out.contains("settled: the last step achieved 0 %"), "{out}");
    assert!(out.contains("run 1's command"), "{out}");
    assert!(err.contains("the learning has settled"), "{err}");
    // run 1's command, the program, is written again
    let sent = column(&cmd3, "command_m");
    let plain = column(&prog, "command_m");
    assert_eq!(sent.len(), plain.len());
    for (a, b) in sent.iter().zip(&plain) {
        assert!((a - b).abs() <= 1e-12 * b.abs().max(1e-3), "{a} {b}");
    }
}
