//! Every input format and every validation error of the readers, through the
//! binary as a user calls it (fixtures under `tests/data/`, made by
//! `tests/data/make_fixtures.py`), and real data: the EMPS benchmark with
//! every method.

mod common;

use common::{assert_fails, emps, feedid, stderr};

fn data(name: &str) -> String {
    common::data(name).display().to_string()
}

/// `feedid info --json` on a fixture with extra arguments.
fn info(name: &str, extra: &[&str]) -> serde_json::Value {
    let file = data(name);
    let mut args = vec!["info", file.as_str(), "--json"];
    args.extend_from_slice(extra);
    let o = feedid(&args);
    assert!(o.status.success(), "{name}: {}", stderr(&o));
    serde_json::from_slice(&o.stdout).unwrap()
}

/// The maximum of channel `name` ("command" or "position") \[m\].
fn channel_max(v: &serde_json::Value, name: &str) -> f64 {
    v["channels"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["name"] == name)
        .unwrap()["max"]
        .as_f64()
        .unwrap()
}

/// Every fixture of the reference recording: 40 samples at 1 kHz, a 3 mm move
/// (position 2.8 mm at the end).
fn assert_reference(v: &serde_json::Value, what: &str) {
    assert_eq!(v["samples"], 40, "{what}: {v}");
    let rate = v["rate_hz"].as_f64().unwrap();
    assert!((rate - 1000.0).abs() < 1e-6, "{what}: rate {rate}");
    assert!(
        (channel_max(v, "command") - 0.003).abs() < 1e-9,
        "{what}: {v}"
    );
    assert!(
        (channel_max(v, "position") - 0.0028).abs() < 1e-9,
        "{what}: {v}"
    );
}

#[test]
fn delimiters_are_detected() {
    for f in [
        "comma_header.csv",
        "semicolon.csv",
        "tab.tsv",
        "whitespace.txt",
    ] {
        assert_reference(&info(f, &[]), f);
    }
    // and can be forced
    assert_reference(&info("semicolon.csv", &["--delimiter", ";"]), "forced ;");
    assert_reference(&info("tab.tsv", &["--delimiter", "tab"]), "forced tab");
}

#[test]
fn headerless_files_take_columns_by_index() {
    let v = info(
        "no_header.csv",
        &["--time", "1", "--command", "2", "--position", "3"],
    );
    assert_reference(&v, "no header");
    let v = info(
        "comma_header.csv",
        &["--time", "1", "--command", "2", "--position", "3"],
    );
    assert_reference(&v, "header, by index");
}

#[test]
fn units_and_scale_convert_to_metres_and_seconds() {
    let v = info(
        "mm_ms.csv",
        &[
            "--time",
            "time_ms",
            "--command",
            "command_mm",
            "--position",
            "position_mm",
            "--unit",
            "mm",
            "--time-unit",
            "ms",
        ],
    );
    assert_reference(&v, "mm/ms");
    // encoder counts without a time column
    let v = info("encoder_counts.csv", &["--rate", "1000", "--scale", "1e-7"]);
    assert_reference(&v, "encoder counts");
}

#[test]
fn mat_files_in_every_supported_form() {
    let vars = ["--time", "t", "--command", "qg", "--position", "qm"];
    for f in ["double_v6.mat", "compressed_v7.mat", "big_endian.mat"] {
        assert_reference(&info(f, &vars), f);
    }
    let v = info(
        "int_types.mat",
        &[
            "--time",
            "t",
            "--command",
            "cmd_counts",
            "--position",
            "pos_counts",
            "--scale",
            "1e-7",
        ],
    );
    assert_eq!(v["samples"], 40);
}

#[test]
fn standstill_is_a_warning_not_a_crash() {
    let file = data("standstill.csv");
    let o = feedid(&["info", &file]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("never moves"), "{}", stderr(&o));
}

#[test]
fn every_reader_error_names_the_place_and_exits_2() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("p.csv");
    let out = out.to_str().unwrap();
    let vars = ["--time", "t", "--command", "qg", "--position", "qm"];
    let cases: Vec<(String, Vec<&str>, Vec<&str>)> = vec![
        (data("empty.csv"), vec![], vec!["empty.csv"]),
        (data("header_only.csv"), vec![], vec!["header_only.csv"]),
        (
            data("text_cell.csv"),
            vec![],
            vec!["text_cell.csv", "line 21", "command_m", "abc"],
        ),
        (
            data("nan.csv"),
            vec![],
            vec!["nan.csv", "line 16", "position_m", "NaN"],
        ),
        (
            data("decreasing_time.csv"),
            vec![],
            vec!["decreasing_time.csv", "time_s", "not strictly increasing"],
        ),
        (
            data("duplicate_time.csv"),
            vec![],
            vec!["duplicate_time.csv", "not strictly increasing"],
        ),
        (
            data("jitter.csv"),
            vec![],
            vec!["jitter.csv", "jitter", "%"],
        ),
        (data("ragged.csv"), vec![], vec!["ragged.csv", "line 9"]),
        (
            data("invalid_utf8.csv"),
            vec![],
            vec!["invalid_utf8.csv", "line 3"],
        ),
        (
            data("decimal_comma.csv"),
            vec![],
            vec!["decimal_comma.csv", "decimal comma"],
        ),
        (
            data("comma_header.csv"),
            vec!["--command", "cmd"],
            vec!["comma_header.csv", "cmd", "command_m"],
        ),
        (
            data("comma_header.csv"),
            vec!["--position", "9"],
            vec!["comma_header.csv", "9"],
        ),
        (
            data("comma_header.csv"),
            vec!["--unit", "inch"],
            vec!["inch"],
        ),
        (data("no_header.csv"), vec![], vec!["no_header.csv"]),
        (data("truncated.mat"), vars.to_vec(), vec!["truncated.mat"]),
        (data("v73.mat"), vars.to_vec(), vec!["v73.mat", "7.3"]),
        (
            data("nan_v7.mat"),
            vars.to_vec(),
            vec!["nan_v7.mat", "qm", "15"],
        ),
        (
            data("compressed_v7.mat"),
            vec!["--time", "t", "--command", "qg", "--position", "qx"],
            vec!["compressed_v7.mat", "qx", "qm"],
        ),
        (
            data("compressed_v7.mat"),
            vec!["--time", "t", "--command", "M", "--position", "qm"],
            vec!["compressed_v7.mat", "M"],
        ),
        (data("compressed_v7.mat"), vec![], vec!["compressed_v7.mat"]),
        (
            "/nonexistent/x.mat".to_string(),
            vars.to_vec(),
            vec!["/nonexistent/x.mat"],
        ),
    ];
    for (file, extra, needles) in cases {
        for cmd in ["info", "identify"] {
            let mut args = vec![cmd, file.as_str()];
            args.extend_from_slice(&extra);
            if cmd == "identify" {
                args.extend_from_slice(&["-o", out]);
            }
            let o = feedid(&args);
            assert_fails(&o, &needles);
            assert_eq!(
                std::fs::read_dir(dir.path()).unwrap().count(),
                0,
                "{cmd} {file}: output left behind"
            );
        }
    }
}

#[test]
fn emps_identifies_with_every_method() {
    let Some(file) = emps() else { return };
    let dir = tempfile::tempdir().unwrap();
    for method in ["paper", "arx", "rls", "oe"] {
        let out = dir.path().join(format!("{method}.csv"));
        let summ = dir.path().join(format!("{method}.json"));
        let o = feedid(&[
            "identify",
            file.to_str().unwrap(),
            "--time",
            "t",
            "--command",
            "qg",
            "--position",
            "qm",
            "--method",
            method,
            "-o",
            out.to_str().unwrap(),
            "--summary",
            summ.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{method}: {}", stderr(&o));
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&summ).unwrap()).unwrap();
        let rms = v["rms_error_m"].as_f64().unwrap();
        let max = v["max_abs_error_m"].as_f64().unwrap();
        assert!(rms.is_finite() && max.is_finite(), "{method}");
        assert!(v["samples_predicted"].as_u64().unwrap() > 24000, "{method}");
        // The paper's polynomial extrapolation is far off on EMPS; the
        // identifying methods predict 10 ms ahead within a few µm (arx 2.3,
        // rls 0.6, oe 2.6 µm rms).
        let bound = if method == "paper" { 1e-3 } else { 1e-5 };
        assert!(rms < bound, "{method}: rms {rms}");
        // predictions are never NaN
        let text = std::fs::read_to_string(&out).unwrap();
        assert!(!text.contains("NaN") && !text.contains("inf"), "{method}");
    }
}
