//! Reading the fixture files under `tests/data/` (repository root) and the
//! EMPS benchmark file, through the public `feedid::io` API.

mod common;

use std::path::{Path, PathBuf};

use feedid::io::{
    list_mat_variables, read_csv, read_mat, read_recording, recording_info, ChannelRef,
    ReadOptions, TimeUnit, Unit, DECIMAL_COMMA_HINT,
};
use feedid::{Error, Recording};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data")
        .join(name)
}

fn name(s: &str) -> Option<ChannelRef> {
    Some(ChannelRef::Name(s.to_string()))
}

fn mat_opts() -> ReadOptions {
    ReadOptions {
        time: name("t"),
        command: name("qg"),
        position: name("qm"),
        ..Default::default()
    }
}

/// The fixture move: rest for 10 samples, then 0.1 mm per sample; position 2 samples late.
fn expected_command(k: usize) -> f64 {
    if k < 10 {
        0.0
    } else {
        (k as f64 - 9.0) * 1e-4
    }
}

fn assert_fixture_move(r: &Recording, tol: f64) {
    assert_eq!(r.len(), 40);
    assert!((r.rate_hz() - 1000.0).abs() < 1e-3, "rate {}", r.rate_hz());
    for k in 0..40 {
        assert!(
            (r.command()[k] - expected_command(k)).abs() <= tol,
            "command[{k}]"
        );
        let p = if k < 2 { 0.0 } else { expected_command(k - 2) };
        assert!((r.position()[k] - p).abs() <= tol, "position[{k}]");
    }
}

fn err(name_: &str, opts: &ReadOptions) -> Error {
    let e = read_recording(&data(name_), opts).expect_err(name_);
    let msg = e.to_string();
    assert!(!msg.contains('\n'), "multi-line message: {msg}");
    assert!(msg.contains(name_), "message does not name the file: {msg}");
    e
}

#[test]
fn every_delimiter_fixture_reads_the_same_move() {
    for f in [
        "comma_header.csv",
        "semicolon.csv",
        "tab.tsv",
        "whitespace.txt",
    ] {
        let r = read_recording(&data(f), &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
        assert_fixture_move(&r, 0.0);
    }
}

#[test]
fn headerless_file_reads_by_index() {
    let opts = ReadOptions {
        time: Some(ChannelRef::Index(1)),
        command: Some(ChannelRef::Index(2)),
        position: Some(ChannelRef::Index(3)),
        ..Default::default()
    };
    assert_fixture_move(&read_csv(&data("no_header.csv"), &opts).unwrap(), 0.0);
    let e = err("no_header.csv", &ReadOptions::default());
    assert!(matches!(e, Error::MissingChannel { .. }), "{e}");
}

#[test]
fn millimetre_and_millisecond_units_convert_to_si() {
    let opts = ReadOptions {
        time: name("time_ms"),
        command: name("command_mm"),
        position: name("position_mm"),
        position_unit: Unit::Mm,
        time_unit: TimeUnit::Ms,
        ..Default::default()
    };
    assert_fixture_move(&read_recording(&data("mm_ms.csv"), &opts).unwrap(), 1e-15);
}

#[test]
fn encoder_counts_with_rate_and_scale() {
    let opts = ReadOptions {
        rate_hz: Some(1000.0),
        scale: Some(1e-7),
        ..Default::default()
    };
    let r = read_recording(&data("encoder_counts.csv"), &opts).unwrap();
    assert_fixture_move(&r, 1e-15);
    assert_eq!(r.time()[0], 0.0);
}

#[test]
fn extra_numeric_columns_become_channels_and_text_columns_are_ignored() {
    let r = read_recording(&data("extra_columns.csv"), &ReadOptions::default()).unwrap();
    assert_fixture_move(&r, 0.0);
    assert_eq!(r.extra().len(), 1);
    assert_eq!(r.extra()[0].0, "current_A");
    assert!((r.extra()[0].1[3] - 0.3).abs() < 1e-15);
}

#[test]
fn decimal_comma_is_reported_with_hint() {
    let e = err("decimal_comma.csv", &ReadOptions::default());
    match e {
        Error::BadNumber { line, hint, .. } => {
            assert_eq!(line, 2);
            assert_eq!(hint, DECIMAL_COMMA_HINT);
        }
        other => panic!("unexpected {other}"),
    }
}

#[test]
fn text_cell_names_line_column_and_text() {
    let e = err("text_cell.csv", &ReadOptions::default());
    assert!(
        matches!(&e, Error::BadNumber { line: 21, column, text, .. } if column == "command_m" && text == "abc"),
        "{e}"
    );
}

#[test]
fn nan_names_file_line_and_column() {
    let e = err("nan.csv", &ReadOptions::default());
    assert!(
        matches!(e.root(), Error::NonFinite { index: 14, .. }),
        "{e}"
    );
    assert!(
        e.to_string().contains("line 16, column `position_m`"),
        "{e}"
    );
    let e = err("nan_v7.mat", &mat_opts());
    assert!(
        matches!(e.root(), Error::NonFinite { index: 14, .. }),
        "{e}"
    );
    assert!(e.to_string().contains("variable `qm`, element 15"), "{e}");
}

#[test]
fn decreasing_and_duplicate_time_name_line_and_values() {
    let e = err("decreasing_time.csv", &ReadOptions::default());
    assert!(
        matches!(e.root(), Error::NonMonotoneTime { index: 21, .. }),
        "{e}"
    );
    let msg = e.to_string();
    assert!(
        msg.contains("line 23, column `time_s`") && msg.contains("0.021") && msg.contains("0.02 "),
        "{msg}"
    );
    let e = err("duplicate_time.csv", &ReadOptions::default());
    assert!(
        matches!(e.root(), Error::NonMonotoneTime { index: 21, .. }),
        "{e}"
    );
}

#[test]
fn jitter_is_reported_with_its_size_and_can_be_tolerated() {
    let e = err("jitter.csv", &ReadOptions::default());
    match e.root() {
        Error::SamplingJitter {
            relative_percent, ..
        } => {
            // one 1.2 ms interval among 1 ms ones; nominal = mean interval (39.2 ms / 39)
            let nominal = 39.2e-3 / 39.0;
            let want = 100.0 * (1.2e-3 - nominal) / nominal;
            assert!((relative_percent - want).abs() < 1e-6, "{relative_percent}")
        }
        other => panic!("unexpected {other}"),
    }
    let opts = ReadOptions {
        jitter_tolerance: 0.25,
        ..Default::default()
    };
    let r = read_recording(&data("jitter.csv"), &opts).unwrap();
    let info = recording_info(&r);
    let nominal = 39.2e-3 / 39.0;
    assert!((info.jitter_max_relative - (1.2e-3 - nominal) / nominal).abs() < 1e-6);
    assert!((info.jitter_max_abs_s - (1.2e-3 - nominal)).abs() < 1e-9);
}

#[test]
fn empty_header_only_ragged_and_invalid_utf8_are_malformed() {
    for (f, line) in [
        ("empty.csv", 1),
        ("header_only.csv", 1),
        ("ragged.csv", 9),
        ("invalid_utf8.csv", 3),
    ] {
        let e = err(f, &ReadOptions::default());
        assert!(
            matches!(e, Error::Malformed { line: l, .. } if l == line),
            "{f}: {e}"
        );
    }
}

#[test]
fn standstill_reads_and_warns() {
    let r = read_recording(&data("standstill.csv"), &ReadOptions::default()).unwrap();
    let info = recording_info(&r);
    assert!(info.segments.is_empty());
    assert!(info
        .warnings
        .iter()
        .any(|w| w.contains("command never moves")));
}

#[test]
fn fixture_move_has_one_motion_segment() {
    let r = read_recording(&data("comma_header.csv"), &ReadOptions::default()).unwrap();
    let info = recording_info(&r);
    assert_eq!(info.segments.len(), 1, "{info}");
    let s = info.segments[0];
    assert!(
        (s.start_s - 0.009).abs() < 1e-12 && (s.end_s - 0.039).abs() < 1e-12,
        "{s:?}"
    );
    assert!((s.distance_m - 3e-3).abs() < 1e-12);
    assert!((s.peak_speed_m_per_s - 0.1).abs() < 1e-9);
    assert!((info.tracking_error_max_m - 2e-4).abs() < 1e-12);
}

#[test]
fn mat_files_of_every_flavour_read_the_same_move() {
    for f in ["double_v6.mat", "compressed_v7.mat", "big_endian.mat"] {
        let r = read_recording(&data(f), &mat_opts()).unwrap_or_else(|e| panic!("{f}: {e}"));
        assert_fixture_move(&r, 0.0);
    }
    // Extra vector of the same length is attached; the scalar and matrix are not.
    let r = read_mat(&data("compressed_v7.mat"), &mat_opts()).unwrap();
    let names: Vec<&str> = r.extra().iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["vir"]);
    // Integer classes (counts) with a scale, time in single precision.
    let opts = ReadOptions {
        time: name("t"),
        command: name("cmd_counts"),
        position: name("pos_counts"),
        scale: Some(1e-7),
        ..Default::default()
    };
    let r = read_mat(&data("int_types.mat"), &opts).unwrap();
    assert_fixture_move(&r, 1e-15);
}

#[test]
fn mat_selection_errors_list_the_variables() {
    let e = err(
        "compressed_v7.mat",
        &ReadOptions {
            command: name("qx"),
            ..mat_opts()
        },
    );
    match &e {
        Error::MissingChannel {
            kind,
            name,
            available,
            ..
        } => {
            assert_eq!((*kind, name.as_str()), ("variable", "qx"));
            assert!(
                available.contains("qg (double 40×1)")
                    && available.contains("s (struct 1×1, unsupported)"),
                "{available}"
            );
        }
        other => panic!("unexpected {other}"),
    }
    let e = err(
        "compressed_v7.mat",
        &ReadOptions {
            command: None,
            ..mat_opts()
        },
    );
    assert!(
        e.to_string()
            .contains("no variable chosen for the command; available: t (double 1×40)"),
        "{e}"
    );
    let e = err(
        "compressed_v7.mat",
        &ReadOptions {
            command: name("M"),
            ..mat_opts()
        },
    );
    assert!(
        e.to_string()
            .contains("variable `M`: is a 3×3 matrix, not a vector"),
        "{e}"
    );
    let e = err(
        "compressed_v7.mat",
        &ReadOptions {
            command: name("label"),
            ..mat_opts()
        },
    );
    assert!(e.to_string().contains("variable `label`: is char"), "{e}");
    let e = err(
        "compressed_v7.mat",
        &ReadOptions {
            command: Some(ChannelRef::Index(2)),
            ..mat_opts()
        },
    );
    assert!(e.to_string().contains("picked by name"), "{e}");
    let e = err(
        "compressed_v7.mat",
        &ReadOptions {
            command: name("kp"),
            ..mat_opts()
        },
    );
    assert!(
        matches!(
            e.root(),
            Error::LengthMismatch {
                expected: 40,
                actual: 1,
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().contains("variables `t`, `kp`, `qm`"), "{e}");
}

#[test]
fn truncated_and_v73_mat_files_are_refused() {
    let e = err("truncated.mat", &mat_opts());
    assert!(
        matches!(e, Error::MatFile { .. }) && e.to_string().contains("truncated"),
        "{e}"
    );
    let e = err("v73.mat", &mat_opts());
    assert!(e.to_string().contains("v7.3 (HDF5)"), "{e}");
    // Recognised by content even without the extension.
    let bytes = std::fs::read(data("v73.mat")).unwrap();
    let e =
        feedid::io::read_recording_from_bytes(&bytes, Path::new("x.dat"), &mat_opts()).unwrap_err();
    assert!(e.to_string().contains("v7.3"), "{e}");
}

#[test]
fn emps_benchmark_reads_with_plausible_ranges() {
    let Some(path) = common::emps_path() else {
        return;
    };
    let vars = list_mat_variables(&path).unwrap();
    let names: Vec<&str> = vars.iter().map(|v| v.name.as_str()).collect();
    for n in ["t", "qg", "qm", "vir", "kp", "kv", "gtau"] {
        assert!(names.contains(&n), "{names:?}");
    }
    let r = read_recording(&path, &mat_opts()).unwrap();
    assert_eq!(r.len(), 24841);
    // The median interval of the stored time stamps is 0.99998 ms (rounding in `t`).
    assert!((r.rate_hz() - 1000.0).abs() < 0.05, "{}", r.rate_hz());
    assert!((r.duration() - 24.84).abs() < 1e-9);
    assert_eq!(r.extra().len(), 1); // vir
                                    // the columnar read of `feedid identify`: the same signals, no `vir`
    let only = read_recording(
        &path,
        &ReadOptions {
            signals_only: true,
            ..mat_opts()
        },
    )
    .unwrap();
    assert!(only.extra().is_empty());
    assert_eq!(
        (only.time(), only.command(), only.position()),
        (r.time(), r.command(), r.position())
    );
    let info = recording_info(&r);
    let (c, p) = (&info.channels[0], &info.channels[1]);
    // A prismatic axis of a few tens of cm; measured close to the reference.
    for s in [c, p] {
        assert!(
            s.min > -0.05 && s.max < 0.5 && s.max - s.min > 0.05,
            "{s:?}"
        );
    }
    assert!((c.min - p.min).abs() < 2e-3 && (c.max - p.max).abs() < 2e-3);
    // README: tracking error about 0.58 mm rms, 0.85 mm max.
    assert!(
        (info.tracking_error_rms_m - 0.58e-3).abs() < 0.05e-3,
        "{}",
        info.tracking_error_rms_m
    );
    assert!(
        (info.tracking_error_max_m - 0.85e-3).abs() < 0.1e-3,
        "{}",
        info.tracking_error_max_m
    );
    assert!(!info.segments.is_empty());
    println!("{info}");
}
