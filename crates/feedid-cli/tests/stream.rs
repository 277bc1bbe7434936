//! `feedid stream`: same predictions as the batch engine, works in a pipe,
//! survives malformed lines.

use std::io::{BufRead, BufReader, Write};
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

use feedid::drive::{RigParams, VirtualRig};
use feedid::ident::engine::run;
use feedid::ident::{EngineConfig, Method, PaperConfig, Solver};
use feedid::signal::Scenario;
use feedid::Recording;

const BIN: &str = env!("CARGO_BIN_EXE_feedid");

fn rig_recording(duration: f64) -> Recording {
    let rate = 5000.0;
    let command = Scenario::Ramp.command(rate, duration, 1).unwrap();
    let out = VirtualRig::new(RigParams::default())
        .with_seed(5)
        .simulate(&command, rate)
        .unwrap();
    Recording::new(out.time, out.command, out.position).unwrap()
}

/// The recording as CSV text (shortest round-trip numbers), with a header.
fn csv(rec: &Recording, with_time: bool) -> String {
    let mut s = String::from(if with_time {
        "time_s,command_m,position_m\n"
    } else {
        "command_m,position_m\n"
    });
    for k in 0..rec.len() {
        if with_time {
            s += &format!("{},", rec.time()[k]);
        }
        s += &format!("{},{}\n", rec.command()[k], rec.position()[k]);
    }
    s
}

/// Run `feedid stream ARGS` on `input` (the paper method unless ARGS name
/// one); (stdout, stderr).
fn stream(args: &[&str], input: &str) -> (String, String) {
    let method: &[&str] = if args.contains(&"--method") {
        &[]
    } else {
        &["--method", "paper"]
    };
    let mut child = Command::new(BIN)
        .arg("stream")
        .args(method)
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let text = input.to_string();
    let writer = std::thread::spawn(move || stdin.write_all(text.as_bytes()).unwrap());
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    (
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

/// Parse `time_s,predicted_m` rows.
fn rows(stdout: &str) -> Vec<(f64, f64)> {
    let mut lines = stdout.lines();
    assert_eq!(lines.next(), Some("time_s,predicted_m"));
    lines
        .map(|l| {
            let (t, y) = l.split_once(',').unwrap();
            (t.parse().unwrap(), y.parse().unwrap())
        })
        .collect()
}

#[test]
fn stream_output_equals_the_batch_engine_predictions() {
    let rec = rig_recording(0.12);
    let n = rec.len();
    let dt = rec.dt();
    for (solver, hop) in [("qr", None), ("qr", Some(3)), ("simplex", None)] {
        let cfg = EngineConfig {
            hop,
            ..EngineConfig::default()
        };
        let mut paper = PaperConfig {
            solver: solver.parse::<Solver>().unwrap(),
            ..PaperConfig::default()
        }
        .build()
        .unwrap();
        let batch = run(&mut paper, &rec.signals(), &cfg).unwrap();
        let mut args = vec!["--solver", solver];
        let hop_s = hop.map(|h| h.to_string());
        if let Some(h) = &hop_s {
            args.extend(["--hop", h]);
        }
        let (out, err) = stream(&args, &csv(&rec, true));
        // later rows of a sample supersede earlier ones, as in batch
        let mut predicted = vec![None; n + 10];
        for (t, y) in rows(&out) {
            let k = (t / dt).round() as usize;
            assert!((t - rec.time().get(k).copied().unwrap_or(k as f64 * dt)).abs() < 1e-12);
            predicted[k] = Some(y);
        }
        let scale = rec.position().iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        for (k, &streamed) in predicted.iter().enumerate().take(n) {
            match (streamed, batch.prediction(k)) {
                (Some(a), Some(b)) => assert!(
                    (a - b).abs() <= 1e-12 * scale,
                    "{solver} {hop:?}: sample {k}: {a} vs {b}"
                ),
                (None, None) => {}
                (a, b) => panic!("{solver} {hop:?}: sample {k}: {a:?} vs {b:?}"),
            }
        }
        assert!(batch.stats.samples > n / 2);
        assert!(
            err.contains(&format!("samples {n},")) && err.contains("skipped lines 0"),
            "{err}"
        );
        assert!(
            err.contains(&format!("over {} scored samples", batch.stats.samples)),
            "{err}"
        );
    }
    // the default method, auto: the same predictions as the batch engine
    let spec = Method::default();
    let cfg = EngineConfig {
        window: spec.default_window(),
        ..EngineConfig::default()
    };
    let mut auto = spec.build().unwrap();
    let batch = run(&mut auto, &rec.signals(), &cfg).unwrap();
    let (out, err) = stream(&["--method", "auto"], &csv(&rec, true));
    let mut predicted = vec![None; n + 10];
    for (t, y) in rows(&out) {
        predicted[(t / dt).round() as usize] = Some(y);
    }
    let scale = rec.position().iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    for (k, &streamed) in predicted.iter().enumerate().take(n) {
        match (streamed, batch.prediction(k)) {
            (Some(a), Some(b)) => assert!((a - b).abs() <= 1e-12 * scale, "auto: sample {k}"),
            (None, None) => {}
            (a, b) => panic!("auto: sample {k}: {a:?} vs {b:?}"),
        }
    }
    assert!(batch.stats.samples > n / 2, "{}", batch.stats.samples);
    assert!(err.contains("withheld"), "{err}");
    // without a time column, at a given rate: the same rows
    let (with_time, _) = stream(&[], &csv(&rec, true));
    let (with_rate, _) = stream(&["--rate", "5000"], &csv(&rec, false));
    let (a, b) = (rows(&with_time), rows(&with_rate));
    assert_eq!(a.len(), b.len());
    for ((ta, ya), (tb, yb)) in a.iter().zip(&b) {
        assert!((ta - tb).abs() < 1e-12 && (ya - yb).abs() <= 1e-12 * ya.abs().max(1e-9));
    }
}

#[test]
fn stream_works_in_a_pipe_behind_a_slow_writer() {
    let rec = rig_recording(0.04); // 200 samples
    let text = csv(&rec, true);
    let lines: Vec<String> = text.lines().map(|l| format!("{l}\n")).collect();
    let mut child = Command::new(BIN)
        .args(["stream", "--method", "paper"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let stdout = child.stdout.take().unwrap();
    let (seen_tx, seen_rx) = mpsc::channel::<()>();
    // the writer sends the first window (header + 20 samples + a few), then
    // waits until the reader has seen a prediction before sending the rest
    let writer = std::thread::spawn(move || {
        for l in &lines[..25] {
            stdin.write_all(l.as_bytes()).unwrap();
            stdin.flush().unwrap();
            std::thread::sleep(Duration::from_millis(2));
        }
        let got_one = seen_rx.recv_timeout(Duration::from_secs(60)).is_ok();
        for l in &lines[25..] {
            stdin.write_all(l.as_bytes()).unwrap();
        }
        got_one // stdin is closed here
    });
    let mut reader = BufReader::new(stdout);
    let mut header = String::new();
    reader.read_line(&mut header).unwrap();
    assert_eq!(header.trim(), "time_s,predicted_m");
    let mut first = String::new();
    reader.read_line(&mut first).unwrap();
    // the first prediction is for sample 20, made from samples 0..20
    let t: f64 = first.split(',').next().unwrap().parse().unwrap();
    assert!((t - rec.time()[20]).abs() < 1e-12, "{first}");
    seen_tx.send(()).unwrap();
    assert!(
        writer.join().unwrap(),
        "a prediction arrived before the input ended"
    );
    let mut rest = String::new();
    std::io::Read::read_to_string(&mut reader, &mut rest).unwrap();
    assert_eq!(rest.lines().count() + 1, 190); // windows ending at 20, 30, …, 200
    assert!(child.wait().unwrap().success());
}

#[test]
fn malformed_lines_are_reported_with_their_number_and_skipped() {
    let rec = rig_recording(0.03);
    let clean = csv(&rec, true);
    let mut lines: Vec<String> = clean.lines().map(String::from).collect();
    // insert bad lines after data line 30 (file line 31)
    let bad = [
        "# a comment is fine",
        "0.1,abc,0.0",
        "0.1,0.0",
        "",
        &format!("{},0,0", rec.time()[3]), // time goes backwards
        "0.1,nan,0",
        "1,2,3,4",
    ];
    for (i, b) in bad.iter().enumerate() {
        lines.insert(31 + i, b.to_string());
    }
    let dirty = lines.join("\n") + "\n";
    let (out_clean, _) = stream(&[], &clean);
    let (out_dirty, err) = stream(&[], &dirty);
    assert_eq!(out_clean, out_dirty);
    for n in [33, 34, 36, 37, 38] {
        assert!(err.contains(&format!("line {n}:")), "line {n} in\n{err}");
    }
    assert!(
        !err.contains("line 32:") && !err.contains("line 35:"),
        "{err}"
    );
    assert!(err.contains("skipped lines 5"), "{err}");
    assert!(err.contains(&format!("samples {},", rec.len())), "{err}");
    // a bad option is an error with exit code 2
    let st = Command::new(BIN)
        .args(["stream", "--method", "magic"])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .unwrap();
    assert_eq!(st.code(), Some(2));
}

#[test]
fn stream_equals_identify_on_the_same_file_for_every_method() {
    let rec = rig_recording(0.15);
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("ramp.csv");
    let text = csv(&rec, true);
    std::fs::write(&input, &text).unwrap();
    let n = rec.len();
    let dt = rec.dt();
    for (method, extra) in [
        ("paper", vec![]),
        ("paper", vec!["--prediction", "tf"]),
        ("arx", vec!["--window", "100", "--order", "4,4,1"]),
        ("rls", vec![]),
        ("oe", vec!["--window", "100"]),
    ] {
        let pred = dir.path().join("pred.csv");
        let mut args = vec![
            "identify",
            input.to_str().unwrap(),
            "--method",
            method,
            "-o",
            pred.to_str().unwrap(),
        ];
        args.extend(extra.iter().copied());
        let o = Command::new(BIN).args(&args).output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let batch: Vec<Option<f64>> = std::fs::read_to_string(&pred)
            .unwrap()
            .lines()
            .skip(1)
            .map(|l| l.split(',').nth(3).and_then(|c| c.parse().ok()))
            .collect();
        let mut sargs = vec!["--method", method];
        sargs.extend(extra.iter().copied());
        let (out, _) = stream(&sargs, &text);
        let mut streamed = vec![None; n + 20];
        for (t, y) in rows(&out) {
            streamed[(t / dt).round() as usize] = Some(y);
        }
        let scale = rec.position().iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let mut compared = 0;
        for k in 0..n {
            match (streamed[k], batch[k]) {
                (Some(a), Some(b)) => {
                    // identify writes shortest round-trip decimals: exact
                    assert!(
                        (a - b).abs() <= 1e-12 * scale,
                        "{method} {extra:?}: sample {k}: {a} vs {b}"
                    );
                    compared += 1;
                }
                (None, None) => {}
                (a, b) => panic!("{method} {extra:?}: sample {k}: stream {a:?} vs identify {b:?}"),
            }
        }
        assert!(compared > n / 3, "{method}: {compared}");
    }
}
