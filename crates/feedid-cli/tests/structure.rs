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

/// Run `scenario` at 1 kHz on the EMPS structure into `out`.
fn simulate_emps(scenario: &str, out: &std::path::Path) {
    let f = emps_toml();
    let o = feedid(&[
        "simulate",
        "--params",
        &f,
        "--scenario",
        scenario,
        "--rate",
        "1000",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn greybox_recovers_a_structures_parameters_from_its_simulated_run() {
    // the EMPS structure run on a multisine at its 1 kHz; estimated from a
    // file whose mass, viscous and Coulomb friction are 25 % off and whose
    // offset is 0, and validated on a chirp run of the same axis
    let dir = tempfile::tempdir().unwrap();
    let (rec, other) = (dir.path().join("run.csv"), dir.path().join("chirp.csv"));
    simulate_emps("multisine", &rec);
    simulate_emps("chirp", &other);
    let f = emps_toml();
    let text = std::fs::read_to_string(&f).unwrap();
    let off = text
        .replace("mass = 95.1089", "mass = 118.886")
        .replace("viscous = 203.5034", "viscous = 152.6276")
        .replace("coulomb = 20.3935", "coulomb = 25.4919")
        .replace("offset = -3.1648", "offset = 0.0");
    let start = dir.path().join("start.toml");
    std::fs::write(&start, off).unwrap();
    let out = dir.path().join("estimated.toml");
    let summary = dir.path().join("gb.json");
    let o = feedid(&[
        "greybox",
        rec.to_str().unwrap(),
        "--params",
        start.to_str().unwrap(),
        "--estimate",
        "M,Fv,Fc,offset",
        "--params-out",
        out.to_str().unwrap(),
        "--summary",
        summary.to_str().unwrap(),
        "--validate",
        other.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("validation on"), "{}", stdout(&o));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&summary).unwrap()).unwrap();
    let value = |name: &str| {
        v["estimates"]
            .as_array()
            .unwrap()
            .iter()
            .find(|e| e["param"] == name)
            .unwrap()["value"]
            .as_f64()
            .unwrap()
    };
    for (name, truth) in [("M", 95.1089), ("Fv", 203.5034), ("Fc", 20.3935)] {
        let rel = (value(name) - truth) / truth;
        assert!(rel.abs() < 1e-3, "{name}: {rel:e}");
    }
    assert!((value("offset") + 3.1648).abs() < 0.01);
    // each estimate carries its verdict, printed and in the summary
    for e in v["estimates"].as_array().unwrap() {
        assert_eq!(e["verdict"], "identifiable", "{e}");
    }
    assert!(stdout(&o).contains("verdict"), "{}", stdout(&o));
    // the estimates explain the other run
    let fit = v["validation"]["fit_percent"].as_f64().unwrap();
    assert!(fit > 99.9, "{fit}");
    // the written structure reads back as a structure
    let o = feedid(&["model", "--params", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    // an unknown name is refused with the known ones
    let o = feedid(&[
        "greybox",
        rec.to_str().unwrap(),
        "--params",
        &f,
        "--estimate",
        "M,Kv",
    ]);
    assert_fails(&o, &["Kv", "M, Fv, Fc, offset"]);
}

#[test]
fn tune_proposes_gains_and_writes_the_retuned_structure() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("tuned.toml");
    let f = emps_toml();
    let o = feedid(&[
        "tune",
        "--params",
        &f,
        "--bandwidth",
        "40",
        "--verify",
        "scurve",
        "--params-out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s = stdout(&o);
    assert!(s.contains("40.000 Hz") && s.contains("proposed"), "{s}");
    assert!(s.contains("nonlinear simulation, scurve"), "{s}");
    // the written structure has the new gains and the same axis
    let o = feedid(&["model", "--params", out.to_str().unwrap(), "--json"]);
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert!((v["bandwidth_hz"].as_f64().unwrap() - 40.0).abs() < 1e-3);
    let o = feedid(&["tune", "--params", &f, "--bandwidth", "40", "--json"]);
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert!(v["overshoot_percent"][1].as_f64().unwrap() < 5.0);
    // not a structure, or a bandwidth below what friction gives: exit 2
    let rig = dir.path().join("rig.toml");
    std::fs::write(&rig, "[control]\nkv = 30.0\n").unwrap();
    let o = feedid(&[
        "tune",
        "--params",
        rig.to_str().unwrap(),
        "--bandwidth",
        "40",
    ]);
    assert_fails(&o, &["rig.toml", "drive structure"]);
    let o = feedid(&["tune", "--params", &f, "--bandwidth", "0.1"]);
    assert_fails(&o, &["bandwidth", "viscous friction"]);
}
