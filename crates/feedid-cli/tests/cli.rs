//! End-to-end tests of the `feedid` binary: every subcommand as a user calls
//! it, its outputs, and its behaviour on bad input (exit code 2, a one-line
//! reason naming the place, no output file left behind).

mod common;

use std::path::{Path, PathBuf};

use common::{data, emps, feedid, stderr, stdout};

fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    (header, rows)
}

fn column(header: &[String], rows: &[Vec<String>], name: &str) -> Vec<Option<f64>> {
    let i = header.iter().position(|h| h == name).unwrap();
    rows.iter().map(|r| r[i].parse().ok()).collect()
}

fn assert_fails(o: &std::process::Output, needle: &str) {
    common::assert_fails(o, &[needle]);
}

#[test]
fn model_prints_stiffness_coefficients_and_poles() {
    let o = feedid(&["model"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s = stdout(&o);
    assert!(s.contains("3.0000e7 N/m"), "{s}");
    assert!(s.contains("D7 = 1.680000e-8"), "{s}");
    assert!(s.contains("561.0"), "{s}");
    assert!(s.contains("71.4 µm at 50 mm/s"), "{s}");
}

#[test]
fn model_json_has_the_documented_fields() {
    let o = feedid(&["model", "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!((v["K"].as_f64().unwrap() / 3.0e7 - 1.0).abs() < 1e-9);
    assert!((v["J"].as_f64().unwrap() / 1.6e-5 - 1.0).abs() < 1e-9);
    let num = v["num"].as_array().unwrap();
    let den = v["den"].as_array().unwrap();
    assert_eq!(num.len(), 3);
    assert_eq!(den.len(), 8);
    assert!((den[0].as_f64().unwrap() / 1.68e-8 - 1.0).abs() < 1e-9);
    let poles = v["poles"].as_array().unwrap();
    assert_eq!(poles.len(), 7);
    assert!(poles
        .iter()
        .all(|p| p.as_array().unwrap().len() == 2 && p[0].as_f64().unwrap() < 0.0));
}

#[test]
fn model_with_printed_d1_shows_the_wrong_following_error() {
    let o = feedid(&["model", "--d1", "paper", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let e = v["following_error_s"].as_f64().unwrap();
    let want = 1.0 / 700.0 - 1.0 / 471.2 - 1.0 / 3428.6;
    assert!((e - want).abs() < 1e-12, "{e}");
}

#[test]
fn model_reads_a_parameter_file_and_rejects_bad_ones() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("rig.toml");
    std::fs::write(&good, "[control]\nkv = 350.0\n").unwrap();
    let o = feedid(&["model", "--params", good.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!((v["following_error_s"].as_f64().unwrap() - 1.0 / 350.0).abs() < 1e-12);

    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "[table]\nmass = -3.0\n").unwrap();
    assert_fails(
        &feedid(&["model", "--params", bad.to_str().unwrap()]),
        "table.mass",
    );
    std::fs::write(&bad, "[control]\nkvv = 3.0\n").unwrap();
    assert_fails(
        &feedid(&["model", "--params", bad.to_str().unwrap()]),
        "kvv",
    );
    assert_fails(
        &feedid(&["model", "--params", "/nonexistent/rig.toml"]),
        "/nonexistent/rig.toml",
    );
}

#[test]
fn model_saves_a_parameter_template_that_reads_back() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("rig.toml");
    let o = feedid(&["model", "--save-params", p.to_str().unwrap()]);
    assert!(o.status.success());
    let o = feedid(&["model", "--params", p.to_str().unwrap(), "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!((v["K"].as_f64().unwrap() / 3.0e7 - 1.0).abs() < 1e-9);
}

#[test]
fn simulate_ramp_gives_a_30_mm_move_with_the_notes_following_error() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ramp.csv");
    let o = feedid(&[
        "simulate",
        "--scenario",
        "ramp",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (h, rows) = read_csv(&out);
    assert_eq!(&h[..3], &["time_s", "command_m", "position_m"]);
    assert_eq!(rows.len(), 4000);
    let t = column(&h, &rows, "time_s");
    let c = column(&h, &rows, "command_m");
    let x = column(&h, &rows, "true_position_m");
    let y = column(&h, &rows, "position_m");
    assert!((t[1].unwrap() - 2e-4).abs() < 1e-15);
    assert!((c.last().unwrap().unwrap() - 0.03).abs() < 1e-12);
    assert!((y.last().unwrap().unwrap() - 0.03).abs() < 2e-6);
    // steady following error during the constant-velocity phase: v/Kv = 71.4 µm
    let errs: Vec<f64> = (0..rows.len())
        .filter(|&k| (0.3..=0.55).contains(&t[k].unwrap()))
        .map(|k| c[k].unwrap() - x[k].unwrap())
        .collect();
    let mean = errs.iter().sum::<f64>() / errs.len() as f64;
    assert!((mean - 71.43e-6).abs() < 0.3e-6, "{mean}");
}

#[test]
fn simulate_is_reproducible_per_seed_and_covers_every_scenario() {
    let dir = tempfile::tempdir().unwrap();
    for s in ["ramp", "step", "scurve", "chirp", "prbs", "multisine"] {
        let a = dir.path().join(format!("{s}_a.csv"));
        let b = dir.path().join(format!("{s}_b.csv"));
        for p in [&a, &b] {
            let o = feedid(&[
                "simulate",
                "--scenario",
                s,
                "--seed",
                "7",
                "--duration",
                "0.3",
                "-o",
                p.to_str().unwrap(),
            ]);
            assert!(o.status.success(), "{s}: {}", stderr(&o));
        }
        assert_eq!(
            std::fs::read(&a).unwrap(),
            std::fs::read(&b).unwrap(),
            "{s}"
        );
    }
    assert_fails(
        &feedid(&["simulate", "--scenario", "zigzag", "-o", "/tmp/never.csv"]),
        "zigzag",
    );
    assert!(!Path::new("/tmp/never.csv").exists());
}

fn simulated(dir: &Path, scenario: &str) -> PathBuf {
    let p = dir.join(format!("{scenario}.csv"));
    let o = feedid(&[
        "simulate",
        "--scenario",
        scenario,
        "-o",
        p.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    p
}

#[test]
fn identify_writes_predictions_coefficients_and_summary() {
    let dir = tempfile::tempdir().unwrap();
    let input = simulated(dir.path(), "ramp");
    let pred = dir.path().join("pred.csv");
    let coef = dir.path().join("coef.csv");
    let summ = dir.path().join("summary.json");
    let o = feedid(&[
        "identify",
        input.to_str().unwrap(),
        "--method",
        "paper",
        "-o",
        pred.to_str().unwrap(),
        "--coefficients",
        coef.to_str().unwrap(),
        "--summary",
        summ.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("prediction error"));

    let (h, rows) = read_csv(&pred);
    assert_eq!(
        h,
        [
            "time_s",
            "command_m",
            "measured_m",
            "predicted_m",
            "lower_m",
            "upper_m",
            "simulated_m"
        ]
    );
    assert_eq!(rows.len(), 4000);
    let p = column(&h, &rows, "predicted_m");
    assert!(
        p[..20].iter().all(Option::is_none),
        "first window not predicted"
    );
    assert!(p[20..].iter().all(Option::is_some));
    assert!(column(&h, &rows, "simulated_m").iter().all(Option::is_some));

    let (ch, crows) = read_csv(&coef);
    assert_eq!(
        ch[6..],
        ["N2", "N1", "N0", "D7", "D6", "D5", "D4", "D3", "D2", "D1", "D0"]
    );
    assert_eq!(crows.len(), 398);

    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&summ).unwrap()).unwrap();
    for key in [
        "method",
        "samples",
        "windows",
        "samples_predicted",
        "rms_error_m",
        "max_abs_error_m",
        "fit_percent",
        "sim_rms_error_m",
        "sim_max_abs_error_m",
        "identification_seconds",
        "per_window_us",
    ] {
        assert!(!v[key].is_null(), "missing {key}");
    }
    assert_eq!(v["method"], "paper");
    assert_eq!(v["samples"], 4000);
    assert_eq!(v["windows"], 398);
    assert_eq!(v["samples_predicted"], 3980);
    // the rms over predicted samples recomputed from the CSV
    let y = column(&h, &rows, "measured_m");
    let se: f64 = (20..4000)
        .map(|k| (y[k].unwrap() - p[k].unwrap()).powi(2))
        .sum();
    let rms = (se / 3980.0).sqrt();
    assert!((rms / v["rms_error_m"].as_f64().unwrap() - 1.0).abs() < 1e-9);
}

#[test]
fn identify_says_whose_parameters_the_simulation_model_has() {
    let dir = tempfile::tempdir().unwrap();
    let input = simulated(dir.path(), "ramp");
    let rig = dir.path().join("my-axis.toml");
    std::fs::write(&rig, "[control]\nkv = 350.0\n").unwrap();
    let summary = |extra: &[&str]| {
        let (pred, summ) = (dir.path().join("p.csv"), dir.path().join("s.json"));
        let mut args = vec![
            "identify",
            input.to_str().unwrap(),
            "-o",
            pred.to_str().unwrap(),
            "--summary",
            summ.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let o = feedid(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&summ).unwrap()).unwrap();
        (String::from_utf8(o.stdout).unwrap(), v)
    };
    let (text, built_in) = summary(&[]);
    assert_eq!(built_in["nominal_rig"], "built-in");
    assert!(
        text.contains("simulation model (the built-in rig's nominal model):"),
        "{text}"
    );
    let (text, v) = summary(&["--params", rig.to_str().unwrap()]);
    assert_eq!(v["nominal_rig"], rig.to_str().unwrap());
    assert!(
        text.contains(&format!(
            "simulation model (nominal model of {}):",
            rig.display()
        )),
        "{text}"
    );
    // the other rig's model was simulated (Kv 350 instead of 700 lags more)
    let sim = |v: &serde_json::Value| v["sim_rms_error_m"].as_f64().unwrap();
    assert!(
        sim(&v) > 1.5 * sim(&built_in),
        "{} vs {}",
        sim(&v),
        sim(&built_in)
    );
}

#[test]
fn identify_simplex_agrees_with_qr_on_the_ramp() {
    let dir = tempfile::tempdir().unwrap();
    let input = simulated(dir.path(), "ramp");
    let mut preds = Vec::new();
    for (name, extra) in [
        ("qr", vec!["--solver", "qr"]),
        ("simplex", vec!["--solver", "simplex"]),
        (
            "previous",
            vec!["--solver", "simplex", "--simplex-start", "previous"],
        ),
    ] {
        let out = dir.path().join(format!("{name}.csv"));
        let mut args = vec!["identify", input.to_str().unwrap(), "--method", "paper"];
        args.extend(extra);
        args.extend(["-o", out.to_str().unwrap()]);
        let o = feedid(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        let (h, rows) = read_csv(&out);
        preds.push(column(&h, &rows, "predicted_m"));
    }
    for other in &preds[1..] {
        let worst = preds[0]
            .iter()
            .zip(other)
            .filter_map(|(a, b)| Some((a.as_ref()? - b.as_ref()?).abs()))
            .fold(0.0, f64::max);
        // same least-squares problems; the simplex stops within its tolerances
        assert!(worst < 1e-6 * 0.03, "{worst}");
    }
    // the simplex start needs the simplex
    let o = feedid(&[
        "identify",
        input.to_str().unwrap(),
        "--method",
        "paper",
        "--simplex-start",
        "previous",
    ]);
    assert_fails(&o, "simplex");
    let o = feedid(&[
        "identify",
        input.to_str().unwrap(),
        "--method",
        "arx",
        "--simplex-start",
        "previous",
    ]);
    assert_fails(&o, "--simplex-start");
}

/// `feedid identify INPUT ARGS -o DIR/NAME.csv --summary DIR/NAME.json`,
/// which must succeed: (standard output, predictions file, summary).
fn identify_with_summary(
    dir: &Path,
    input: &Path,
    args: &[&str],
    name: &str,
) -> (String, String, serde_json::Value) {
    let out = dir.join(format!("{name}.csv"));
    let summ = dir.join(format!("{name}.json"));
    let mut all = vec!["identify", input.to_str().unwrap()];
    all.extend_from_slice(args);
    all.extend_from_slice(&[
        "-o",
        out.to_str().unwrap(),
        "--summary",
        summ.to_str().unwrap(),
    ]);
    let o = feedid(&all);
    assert!(o.status.success(), "{}", stderr(&o));
    (
        stdout(&o),
        std::fs::read_to_string(&out).unwrap(),
        serde_json::from_str(&std::fs::read_to_string(&summ).unwrap()).unwrap(),
    )
}

#[test]
fn window_horizon_and_hop_in_time_are_the_samples_at_the_recordings_rate() {
    // the rig's ramp at 5 kHz: 10ms = 50 samples, 2ms = 10, 0.6ms = 3
    let dir = tempfile::tempdir().unwrap();
    let input = simulated(dir.path(), "ramp");
    let time = ["--window", "10ms", "--horizon", "2ms", "--hop", "0.6ms"];
    let (_, a, va) = identify_with_summary(dir.path(), &input, &time, "time");
    let samples = ["--window", "50", "--horizon", "10", "--hop", "3"];
    let (_, b, vb) = identify_with_summary(dir.path(), &input, &samples, "samples");
    for key in ["window", "horizon", "hop"] {
        assert_eq!(va[key], vb[key], "{key}");
    }
    assert_eq!(vb["horizon"], 10);
    assert_eq!(a, b);
    // a time shorter than a sample, or not a length: exit 2, named
    let out = dir.path().join("x.csv");
    let (i, o) = (input.to_str().unwrap(), out.to_str().unwrap());
    let r = feedid(&["identify", i, "--horizon", "50us", "-o", o]);
    assert_fails(&r, "shorter than one sample");
    assert!(!out.exists());
    let r = feedid(&["identify", i, "--horizon", "2 meters", "-o", o]);
    assert_fails(&r, "2ms");
}

#[test]
fn runaways_are_cut_back_by_default_counted_and_can_be_turned_off() {
    // paper on the rig's ramp: its polynomials run away at the start of
    // the motion; the summary counts the windows cut back, its intervals
    // per command regime and their median width
    let dir = tempfile::tempdir().unwrap();
    let input = simulated(dir.path(), "ramp");
    let paper = |extra: &[&str], name: &str| {
        let mut args = vec!["--method", "paper"];
        args.extend_from_slice(extra);
        let (text, _, v) = identify_with_summary(dir.path(), &input, &args, name);
        (text, v)
    };
    let (text, on) = paper(&[], "on");
    let (_, off) = paper(&["--runaway", "off"], "off");
    let cut = on["runaway_windows"].as_u64().unwrap();
    assert!(cut > 0, "{on}");
    assert!(text.contains("cut back as runaways"), "{text}");
    assert_eq!(off["runaway_windows"], 0);
    let max = |v: &serde_json::Value| v["max_abs_error_m"].as_f64().unwrap();
    assert!(max(&on) < max(&off), "{} vs {}", max(&on), max(&off));
    let regimes = on["interval_by_regime"].as_array().unwrap();
    let n: u64 = regimes.iter().map(|r| r["samples"].as_u64().unwrap()).sum();
    assert_eq!(n, on["samples_predicted"].as_u64().unwrap());
    assert!(on["interval_median_width_m"].as_f64().unwrap() > 0.0);
    let i = input.to_str().unwrap();
    let r = feedid(&["identify", i, "--runaway", "0.5", "-o", "x.csv"]);
    assert_fails(&r, "expected a factor ≥ 1");
}

#[test]
fn identify_options_window_horizon_hop_time_origin_and_tf_prediction() {
    let dir = tempfile::tempdir().unwrap();
    let input = simulated(dir.path(), "ramp");
    let summ = dir.path().join("s.json");
    let out = dir.path().join("p.csv");
    let o = feedid(&[
        "identify",
        input.to_str().unwrap(),
        "--method",
        "paper",
        "--window",
        "40",
        "--horizon",
        "5",
        "--hop",
        "3",
        "--time-origin",
        "window",
        "--prediction",
        "tf",
        "-o",
        out.to_str().unwrap(),
        "--summary",
        summ.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&summ).unwrap()).unwrap();
    assert_eq!(v["window"], 40);
    assert_eq!(v["horizon"], 5);
    assert_eq!(v["hop"], 3);
    assert_eq!(v["windows"], (4000 - 40 + 2) / 3);
}

#[test]
fn identify_picks_columns_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("renamed.csv");
    let mut text = String::from("t,x_set,x_meas\n");
    for k in 0..200 {
        let t = k as f64 * 2e-4;
        text.push_str(&format!("{t},{},{}\n", 0.05 * t, 0.05 * t));
    }
    std::fs::write(&input, text).unwrap();
    let out = dir.path().join("p.csv");
    let o = feedid(&[
        "identify",
        input.to_str().unwrap(),
        "--time",
        "t",
        "--command",
        "x_set",
        "--position",
        "x_meas",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out.exists());
}

#[test]
fn reproduce_writes_the_four_figures_and_the_summary() {
    let dir = tempfile::tempdir().unwrap();
    let o = feedid(&["reproduce", "--out", dir.path().to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    for f in [
        "ramp_response.svg",
        "ramp_error.svg",
        "step_response.svg",
        "step_error.svg",
    ] {
        let svg = std::fs::read_to_string(dir.path().join(f)).unwrap();
        assert!(
            svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"),
            "{f}"
        );
        assert!(svg.contains("[µm]") && svg.contains("[ms]"), "{f}");
        assert!(!svg.contains("NaN"), "{f}");
    }
    let md = std::fs::read_to_string(dir.path().join("summary.md")).unwrap();
    assert!(md.contains("| ramp | paper LSM, QR |"));
    assert!(md.contains("| step | simulation model |"));
    assert!(stdout(&o).contains("| ramp | paper LSM, simplex |"));
}

#[test]
fn reproduce_on_a_real_axis_puts_the_papers_figures_beside_ours_with_a_verdict() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("real");
    let o = feedid(&[
        "reproduce",
        "--axis",
        "real",
        "--compare",
        "none",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let md = std::fs::read_to_string(out.join("summary.md")).unwrap();
    assert!(
        md.contains("a real axis off the nominal simulation model"),
        "{md}"
    );
    assert!(md.contains("## The paper's figures and ours"), "{md}");
    assert!(
        md.contains("| identified model (LSM, simplex) | ≈ 40 µm |"),
        "{md}"
    );
    assert!(
        md.contains("Verdict: over the whole ramp")
            && md.contains("The measured axis here is off the nominal model"),
        "{md}"
    );
    // the default axis says the simulation model starts with an advantage
    let o = feedid(&[
        "reproduce",
        "--axis",
        "ideal",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("ideal"), "{}", stderr(&o));
}

#[test]
fn info_summarises_a_recording() {
    let o = feedid(&["info", data("comma_header.csv").to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s = stdout(&o);
    assert!(s.contains("samples"), "{s}");
    assert!(s.contains("motion segments"), "{s}");
    let o = feedid(&["info", data("comma_header.csv").to_str().unwrap(), "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(v["samples"].as_u64().unwrap() > 0);
}

#[test]
fn bad_inputs_end_with_exit_2_a_one_line_reason_and_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("pred.csv");
    let o = out.to_str().unwrap();
    let cases: Vec<(Vec<String>, &str)> = vec![
        (vec![data("empty.csv").display().to_string()], "empty.csv"),
        (
            vec![data("header_only.csv").display().to_string()],
            "header_only.csv",
        ),
        (vec![data("text_cell.csv").display().to_string()], "line"),
        (vec![data("nan.csv").display().to_string()], "NaN"),
        (
            vec![data("decreasing_time.csv").display().to_string()],
            "not strictly increasing",
        ),
        (
            vec![data("decimal_comma.csv").display().to_string()],
            "decimal comma",
        ),
        (
            vec![
                data("truncated.mat").display().to_string(),
                "--time".into(),
                "t".into(),
                "--command".into(),
                "u".into(),
                "--position".into(),
                "y".into(),
            ],
            "truncated.mat",
        ),
        (
            vec!["/nonexistent/file.csv".into()],
            "/nonexistent/file.csv",
        ),
        (
            vec![
                data("comma_header.csv").display().to_string(),
                "--position".into(),
                "nope".into(),
            ],
            "nope",
        ),
        (
            vec![
                data("comma_header.csv").display().to_string(),
                "--window".into(),
                "100000".into(),
            ],
            "too few samples",
        ),
        (
            vec![
                data("comma_header.csv").display().to_string(),
                "--method".into(),
                "magic".into(),
            ],
            "magic",
        ),
    ];
    for (args, needle) in cases {
        let mut full = vec!["identify".to_string()];
        full.extend(args.iter().cloned());
        full.extend(["-o".to_string(), o.to_string()]);
        let refs: Vec<&str> = full.iter().map(String::as_str).collect();
        let r = feedid(&refs);
        assert_fails(&r, needle);
        assert!(!out.exists(), "output left behind for {args:?}");
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            0,
            "{args:?}"
        );
    }
}

#[test]
fn unwritable_output_path_is_reported_and_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let input = data("comma_header.csv");
    let r = feedid(&[
        "identify",
        input.to_str().unwrap(),
        "--window",
        "8",
        "--horizon",
        "2",
        "-o",
        "/nonexistent-dir/pred.csv",
    ]);
    assert_fails(&r, "/nonexistent-dir/pred.csv");
    // a failing second output removes the first
    let pred = dir.path().join("pred.csv");
    let r = feedid(&[
        "identify",
        input.to_str().unwrap(),
        "--window",
        "8",
        "--horizon",
        "2",
        "-o",
        pred.to_str().unwrap(),
        "--summary",
        "/nonexistent-dir/s.json",
    ]);
    assert_fails(&r, "/nonexistent-dir/s.json");
    assert!(!pred.exists());
}

#[test]
fn emps_info_and_identify_work_as_a_new_user_calls_them() {
    let Some(path) = emps() else { return };
    let p = path.to_str().unwrap();
    let o = feedid(&[
        "info",
        p,
        "--time",
        "t",
        "--command",
        "qg",
        "--position",
        "qm",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("24841"));
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("p.csv");
    let summ = dir.path().join("s.json");
    let o = feedid(&[
        "identify",
        p,
        "--time",
        "t",
        "--command",
        "qg",
        "--position",
        "qm",
        "--method",
        "paper",
        "-o",
        out.to_str().unwrap(),
        "--summary",
        summ.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&summ).unwrap()).unwrap();
    assert_eq!(v["samples"], 24841);
    let rms = v["rms_error_m"].as_f64().unwrap();
    assert!(rms.is_finite() && rms > 0.0 && rms < 0.01, "{rms}");
    assert_fails(
        &feedid(&[
            "identify",
            p,
            "--time",
            "t",
            "--command",
            "qg",
            "--position",
            "qx",
            "-o",
            out.to_str().unwrap(),
        ]),
        "qx",
    );
}

#[test]
fn identify_batch_writes_one_set_of_outputs_per_input_and_reports_failures() {
    let dir = tempfile::tempdir().unwrap();
    let a = simulated(dir.path(), "ramp");
    let b = simulated(dir.path(), "scurve");
    let out = dir.path().join("out");
    let o = feedid(&[
        "identify",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "--method",
        "arx",
        "--out-dir",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    for stem in ["ramp", "scurve"] {
        for ext in ["predictions.csv", "coefficients.csv", "summary.json"] {
            assert!(out.join(format!("{stem}.{ext}")).exists(), "{stem}.{ext}");
        }
        // the same as identifying the file alone
        let single = dir.path().join(format!("{stem}_single.csv"));
        let input = dir.path().join(format!("{stem}.csv"));
        let o = feedid(&[
            "identify",
            input.to_str().unwrap(),
            "--method",
            "arx",
            "-o",
            single.to_str().unwrap(),
        ]);
        assert!(o.status.success());
        assert_eq!(
            std::fs::read(&single).unwrap(),
            std::fs::read(out.join(format!("{stem}.predictions.csv"))).unwrap()
        );
    }
    // one bad file: the others are written, exit code 2, the bad one named
    let bad = data("nan.csv");
    let out2 = dir.path().join("out2");
    let o = feedid(&[
        "identify",
        a.to_str().unwrap(),
        bad.to_str().unwrap(),
        "--out-dir",
        out2.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("nan.csv: line 16"), "{}", stderr(&o));
    assert!(out2.join("ramp.predictions.csv").exists());
    assert!(!out2.join("nan.predictions.csv").exists());
    // several inputs without --out-dir
    let o = feedid(&[
        "identify",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "-o",
        "x.csv",
    ]);
    assert_fails(&o, "--out-dir");
}

#[test]
fn identify_defaults_to_auto_and_reports_coverage_and_residuals() {
    let dir = tempfile::tempdir().unwrap();
    let input = simulated(dir.path(), "ramp");
    let pred = dir.path().join("pred.csv");
    let summ = dir.path().join("summary.json");
    let o = feedid(&[
        "identify",
        input.to_str().unwrap(),
        "-o",
        pred.to_str().unwrap(),
        "--summary",
        summ.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("method auto"), "{}", stdout(&o));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&summ).unwrap()).unwrap();
    assert_eq!(v["method"], "auto");
    assert_eq!(v["window"], 50);
    let cov = v["coverage_percent"].as_f64().unwrap();
    let n = v["samples"].as_f64().unwrap();
    let np = v["samples_predicted"].as_f64().unwrap();
    assert!((cov - 100.0 * np / n).abs() < 1e-9);
    assert!(cov > 90.0, "{cov}");
    assert_eq!(v["withheld_windows"].as_u64(), Some(0));
    // auto predicts from its first window on: the start of the motion,
    // before any model has seen it, is predicted too (by holding), so the
    // error over every predicted sample is larger than once it has learnt
    assert!(v["rms_error_m"].as_f64().unwrap() < 5e-6, "{v}");
    // the 2 ms-ahead error once the axis has moved for 350 samples: below
    // 1 µm rms (0.64 µm; the ramp's stop, a change no model has seen, costs
    // up to ~12 µm for a horizon)
    let (h, rows) = read_csv(&pred);
    let (y, p) = (
        column(&h, &rows, "measured_m"),
        column(&h, &rows, "predicted_m"),
    );
    let (mut se, mut c) = (0.0, 0);
    for k in 400..y.len() {
        if let (Some(y), Some(p)) = (y[k], p[k]) {
            se += (y - p) * (y - p);
            c += 1;
        }
    }
    assert!(
        c > 3400 && (se / c as f64).sqrt() < 1e-6,
        "{}",
        (se / c as f64).sqrt()
    );
    let r = &v["residuals"];
    assert_eq!(r["r_ee"].as_array().unwrap().len(), 26);
    assert_eq!(r["r_ue"].as_array().unwrap().len(), 51);
    assert!((r["r_ee"][0].as_f64().unwrap() - 1.0).abs() < 1e-12);
    let bound = r["bound"].as_f64().unwrap();
    assert!((bound - 2.58 / np.sqrt()).abs() < 1e-12);
}

#[test]
fn order_auto_chooses_the_orders_from_the_recording() {
    let dir = tempfile::tempdir().unwrap();
    let input = simulated(dir.path(), "ramp");
    let pred = dir.path().join("pred.csv");
    let o = feedid(&[
        "identify",
        input.to_str().unwrap(),
        "--method",
        "arx",
        "--order",
        "auto",
        "-o",
        pred.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("order auto (bic): na "),
        "{}",
        stdout(&o)
    );
}

#[test]
fn summary_has_the_free_run_fit_of_the_global_model_except_for_paper() {
    let dir = tempfile::tempdir().unwrap();
    let input = simulated(dir.path(), "chirp");
    for (method, expect) in [("arx", true), ("auto", true), ("paper", false)] {
        let summ = dir.path().join(format!("{method}.json"));
        let pred = dir.path().join(format!("{method}.csv"));
        let o = feedid(&[
            "identify",
            input.to_str().unwrap(),
            "--method",
            method,
            "-o",
            pred.to_str().unwrap(),
            "--summary",
            summ.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&summ).unwrap()).unwrap();
        if expect {
            let f = v["sim_fit_percent"].as_f64().unwrap();
            assert!(f > 90.0 && f <= 100.0, "{method}: {f}");
            let g = v["global_model"].as_str().unwrap();
            // arx: its orders; auto: its least-squares candidate arx 8,8,1
            // (the output-error ones only with --model-out)
            let expect = if method == "arx" {
                "arx 3,3,0"
            } else {
                "arx 8,8,1"
            };
            assert_eq!(g, expect, "{method}");
            // fitted on the whole (short) recording, and the summary says so
            let n = v["samples"].as_u64().unwrap();
            assert_eq!(v["global_model_samples"].as_u64(), Some(n));
            assert!(
                stdout(&o).contains(&format!("free-run fit {f:.3} % on all {n} samples")),
                "{}",
                stdout(&o)
            );
        } else {
            assert!(v["sim_fit_percent"].is_null());
            assert!(v["global_model_samples"].is_null());
        }
    }
}

#[test]
fn order_changes_auto_and_is_refused_by_methods_without_orders() {
    let dir = tempfile::tempdir().unwrap();
    let input = simulated(dir.path(), "ramp");
    let predictions = |extra: &[&str], name: &str| {
        let out = dir.path().join(name);
        let mut args = vec![
            "identify",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let o = feedid(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        let (h, rows) = read_csv(&out);
        column(&h, &rows, "predicted_m")
    };
    // auto takes the orders for its long-memory RLS candidate: a different result
    let default = predictions(&["--method", "auto"], "a.csv");
    let low = predictions(&["--method", "auto", "--order", "2,2,1"], "b.csv");
    let differ = default
        .iter()
        .zip(&low)
        .filter(|(a, b)| a.is_some() && b.is_some() && a != b)
        .count();
    assert!(differ > 100, "{differ} samples differ");
    // the same orders given explicitly change nothing
    assert_eq!(
        predictions(&["--method", "auto", "--order", "8,8,0"], "c.csv"),
        default
    );
    // methods without ARX orders refuse them, naming the flag and who takes it
    for (method, order) in [("paper", "2,2,1"), ("oe", "2,2,1"), ("paper", "auto")] {
        let out = dir.path().join("refused.csv");
        let o = feedid(&[
            "identify",
            input.to_str().unwrap(),
            "--method",
            method,
            "--order",
            order,
            "-o",
            out.to_str().unwrap(),
        ]);
        common::assert_fails(&o, &["--order", method, "arx, rls, nn, auto"]);
        assert!(!out.exists());
    }
    // so do other options given to a method without them
    let o = feedid(&[
        "identify",
        input.to_str().unwrap(),
        "--method",
        "arx",
        "--solver",
        "simplex",
        "-o",
        dir.path().join("x.csv").to_str().unwrap(),
    ]);
    common::assert_fails(&o, &["--solver", "arx", "paper"]);
}

#[test]
fn error_lines_carry_their_cause_and_name_the_file_once() {
    let dir = tempfile::tempdir().unwrap();
    // a command that never moves: nothing to choose orders from
    let flat = dir.path().join("flat.csv");
    let mut text = String::from("time_s,command_m,position_m\n");
    for k in 0..200 {
        text += &format!("{},0.001,0.001\n", k as f64 * 1e-3);
    }
    std::fs::write(&flat, text).unwrap();
    let out = dir.path().join("p.csv");
    let o = feedid(&[
        "identify",
        flat.to_str().unwrap(),
        "--method",
        "arx",
        "--order",
        "auto",
        "-o",
        out.to_str().unwrap(),
    ]);
    common::assert_fails(&o, &["order selection: "]);
    let err = stderr(&o);
    let line = err.lines().find(|l| l.starts_with("error:")).unwrap();
    // the reason follows the stage: `…: order selection: <why>`
    let why = line.split("order selection: ").nth(1).unwrap_or("");
    assert!(why.len() > 5, "no cause in `{line}`");
    assert_eq!(line.matches("flat.csv").count(), 1, "{line}");
    assert!(!out.exists());

    // a batch names each bad file once
    let bad = dir.path().join("bad.csv");
    std::fs::write(&bad, "time_s,command_m,position_m\n0,0,0\n0.001,0,x\n").unwrap();
    let o = feedid(&[
        "identify",
        bad.to_str().unwrap(),
        "--out-dir",
        dir.path().join("batch").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = stderr(&o);
    let line = err
        .lines()
        .find(|l| l.contains("bad.csv"))
        .unwrap_or_else(|| panic!("{err}"));
    assert_eq!(line.matches("bad.csv").count(), 1, "{line}");
    assert!(line.contains("line 3") && line.contains("`x`"), "{line}");
}

#[test]
fn identify_writes_intervals_and_reports_their_coverage_beside_the_error() {
    let dir = tempfile::tempdir().unwrap();
    let input = simulated(dir.path(), "ramp");
    let pred = dir.path().join("pred.csv");
    let summ = dir.path().join("summary.json");
    let run = |p: &str| {
        feedid(&[
            "identify",
            input.to_str().unwrap(),
            "-o",
            pred.to_str().unwrap(),
            "--summary",
            summ.to_str().unwrap(),
            "--interval",
            p,
        ])
    };
    let o = run("90");
    assert!(o.status.success(), "{}", stderr(&o));
    // rms, max, fit, coverage and the interval's share on one line
    let line = stdout(&o)
        .lines()
        .find(|l| l.contains("prediction error"))
        .unwrap()
        .to_string();
    for part in [
        "rms",
        "max",
        "fit",
        "of the samples",
        "inside the 90 % interval",
    ] {
        assert!(line.contains(part), "{line}");
    }
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&summ).unwrap()).unwrap();
    assert_eq!(v["interval_percent"].as_f64(), Some(90.0));
    // the share inside, recomputed from predictions.csv
    let (h, rows) = read_csv(&pred);
    let (y, p) = (
        column(&h, &rows, "measured_m"),
        column(&h, &rows, "predicted_m"),
    );
    let (lo, hi) = (column(&h, &rows, "lower_m"), column(&h, &rows, "upper_m"));
    let (mut inside, mut n) = (0, 0);
    for k in 0..y.len() {
        match (p[k], lo[k], hi[k]) {
            (Some(p), Some(l), Some(u)) => {
                assert!(l <= p && p <= u, "row {k}");
                n += 1;
                inside += usize::from(l <= y[k].unwrap() && y[k].unwrap() <= u);
            }
            (None, None, None) => {}
            other => panic!("row {k}: {other:?}"),
        }
    }
    let share = v["interval_coverage_percent"].as_f64().unwrap();
    assert!(
        (share - 100.0 * inside as f64 / n as f64).abs() < 1e-9,
        "{share}"
    );
    assert!((70.0..=100.0).contains(&share), "{share}");
    // a probability outside (0, 100) is refused, naming the option
    for bad in ["0", "100", "150", "NaN"] {
        assert_fails(&run(bad), "--interval");
    }
}

#[test]
fn a_run_that_predicts_nothing_reports_no_error_warns_and_writes_its_outputs() {
    // a still axis: rls has nothing to learn from, every window fails
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("still.csv");
    let mut text = String::from("time_s,command_m,position_m\n");
    for k in 0..400 {
        text += &format!("{},0.01,0.01\n", k as f64 * 2e-4);
    }
    std::fs::write(&input, text).unwrap();
    let pred = dir.path().join("pred.csv");
    let summ = dir.path().join("summary.json");
    let o = feedid(&[
        "identify",
        input.to_str().unwrap(),
        "--method",
        "rls",
        "-o",
        pred.to_str().unwrap(),
        "--summary",
        summ.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("no sample was predicted"),
        "{}",
        stderr(&o)
    );
    assert!(
        stdout(&o).contains("prediction error: none")
            && !stdout(&o).contains("prediction error: rms"),
        "{}",
        stdout(&o)
    );
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&summ).unwrap()).unwrap();
    assert_eq!(v["samples_predicted"].as_u64(), Some(0));
    for absent in [
        "rms_error_m",
        "max_abs_error_m",
        "fit_percent",
        "interval_coverage_percent",
    ] {
        assert!(v.get(absent).is_none(), "{absent}: {v}");
    }
    assert!(v["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .any(|w| w.as_str().unwrap().contains("no sample was predicted")));
    let (h, rows) = read_csv(&pred);
    assert_eq!(rows.len(), 400);
    assert!(column(&h, &rows, "predicted_m").iter().all(Option::is_none));
}

#[test]
fn simulate_help_lists_every_effects_key_with_its_unit_and_default() {
    let o = feedid(&["simulate", "--help"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let help = String::from_utf8_lossy(&o.stdout).to_string();
    for key in [
        "friction = true",
        "[motor_friction]",
        "[table_friction]",
        "stribeck_velocity = 0.5",
        "current_limit = 10",
        "resolution = 1e-7",
        "noise_std = 2e-7",
        "position_loop = \"sampled\"",
        "backlash_width = 5e-6",
        "dead_time = 0",
        "[pulses]",
        "period = 0.5",
    ] {
        assert!(help.contains(key), "{key} in\n{help}");
    }
    assert!(
        help.contains("[samples]") && help.contains("[N·m]"),
        "{help}"
    );
    assert!(!help.contains("see `feedid simulate --help`"), "{help}");
    // the short help stays short
    let o = feedid(&["simulate", "-h"]);
    let short = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(!short.contains("stribeck_velocity"), "{short}");
}
