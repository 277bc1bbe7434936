//! Drive structure files (`examples/emps.toml`) in `feedid model` and
//! `feedid simulate`, and refused where the paper's rig is needed.

mod common;

use common::{assert_fails, feedid, stderr, stdout};

fn emps_toml() -> String {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/emps.toml")
        .to_string_lossy()
        .into_owned()
}

#[test]
fn model_prints_the_closed_loop_of_a_structure() {
    let f = emps_toml();
    let o = feedid(&["model", "--params", &f]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s = stdout(&o);
    assert!(s.contains("source: A. Janot"), "{s}");
    assert!(
        s.contains("poles (stable)") && s.contains("19.107 Hz"),
        "{s}"
    );
    assert!(s.contains("damping 0.384"), "{s}");
    assert!(
        s.contains("following error of a ramp: 6.3914 µm per mm/s"),
        "{s}"
    );
    let o = feedid(&["model", "--params", &f, "--json"]);
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(v["stable"], true);
    assert_eq!(v["denominator"].as_array().unwrap().len(), 3);
    let e = v["following_error_per_velocity"].as_f64().unwrap();
    assert!((e - 6.39144e-3).abs() < 1e-8, "{e}");
}

#[test]
fn simulate_runs_a_structure_at_its_controller_rate() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("emps-ramp.csv");
    let f = emps_toml();
    let o = feedid(&[
        "simulate",
        "--params",
        &f,
        "--scenario",
        "ramp",
        "--rate",
        "1000",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&out).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "time_s,command_m,position_m,velocity_m_per_s,output"
    );
    assert_eq!(lines.count(), 800);
    // the recording reads back and identifies
    let p = dir.path().join("p.csv");
    let o = feedid(&["identify", out.to_str().unwrap(), "-o", p.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    // a sampled controller at another rate is refused, nothing written
    let other = dir.path().join("other.csv");
    let o = feedid(&[
        "simulate",
        "--params",
        &f,
        "--scenario",
        "ramp",
        "-o",
        other.to_str().unwrap(),
    ]);
    assert_fails(&o, &["controller.sample_time", "sample interval"]);
    assert!(!other.exists());
    // the rig's effects do not apply to a structure
    let fx = dir.path().join("fx.toml");
    std::fs::write(&fx, "noise = false\n").unwrap();
    let o = feedid(&[
        "simulate",
        "--params",
        &f,
        "--scenario",
        "ramp",
        "--rate",
        "1000",
        "--effects",
        fx.to_str().unwrap(),
        "-o",
        other.to_str().unwrap(),
    ]);
    assert_fails(&o, &["--effects", "paper's rig"]);
}

#[test]
fn commands_that_need_the_papers_rig_name_a_structure_file() {
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("ramp.csv");
    let o = feedid(&[
        "simulate",
        "--scenario",
        "ramp",
        "-o",
        rec.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let p = dir.path().join("p.csv");
    let o = feedid(&[
        "identify",
        rec.to_str().unwrap(),
        "-o",
        p.to_str().unwrap(),
        "--params",
        &emps_toml(),
    ]);
    assert_fails(&o, &["emps.toml", "drive structure", "feedid model"]);
    assert!(!p.exists());
}
