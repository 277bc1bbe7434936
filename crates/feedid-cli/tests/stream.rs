//! `feedid stream`: predictions written before the line of their
//! measurement is read (driven through a pipe line by line), the batch
//! pipeline's predictions where the stream has the same data, any recording
//! read with `identify`'s options, gaps reported, and loud failures.

use std::io::{BufRead, BufReader, Write};
use std::process::{Command, Output, Stdio};
use std::sync::mpsc;
use std::time::Duration;

use feedid::drive::{RigParams, VirtualRig};
use feedid::ident::engine::run;
use feedid::ident::stream::{CommandExtrapolation, StreamOptions, Streamer};
use feedid::ident::{EngineConfig, Method, PaperConfig, Solver};
use feedid::signal::Scenario;
use feedid::Recording;

const BIN: &str = env!("CARGO_BIN_EXE_feedid");

fn rig_recording(scenario: Scenario, duration: f64) -> Recording {
    let rate = 5000.0;
    let command = scenario.command(rate, duration, 1).unwrap();
    let out = VirtualRig::new(RigParams::default())
        .with_seed(5)
        .simulate(&command, rate)
        .unwrap();
    Recording::new(out.time, out.command, out.position).unwrap()
}

/// Samples `a..b` of `rec`.
fn slice(rec: &Recording, a: usize, b: usize) -> Recording {
    Recording::new(
        rec.time()[a..b].to_vec(),
        rec.command()[a..b].to_vec(),
        rec.position()[a..b].to_vec(),
    )
    .unwrap()
}

const HEADER: &str = "time_s,command_m,position_m";

/// Data lines of `rec` with the command `lead` samples ahead: line `i` is
/// `t_i, u_{i+lead}, y_i` (shortest round-trip numbers), `i < n − lead`.
fn lead_lines(rec: &Recording, lead: usize) -> Vec<String> {
    let (t, u, y) = (rec.time(), rec.command(), rec.position());
    (0..rec.len() - lead)
        .map(|i| format!("{},{},{}\n", t[i], u[i + lead], y[i]))
        .collect()
}

/// The recording as CSV text with a header (`with_time`: the time column).
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

/// Run `feedid stream ARGS` on `input` at once.
fn stream_output(args: &[&str], input: &str) -> Output {
    let mut child = Command::new(BIN)
        .arg("stream")
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let text = input.to_string();
    // (the writer may find the pipe closed when the stream fails early)
    let writer = std::thread::spawn(move || {
        let _ = stdin.write_all(text.as_bytes());
    });
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap();
    out
}

/// Run `feedid stream ARGS` on `input`; (stdout, stderr); it must succeed.
fn stream(args: &[&str], input: &str) -> (String, String) {
    let out = stream_output(args, input);
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

/// Parse `time_s,predicted_m,lower_m,upper_m` rows (time and prediction;
/// the prediction lies inside its interval).
fn rows(stdout: &str) -> Vec<(f64, f64)> {
    let mut lines = stdout.lines();
    assert_eq!(lines.next(), Some(HEADER_OUT));
    lines.map(parse_row).collect()
}

/// The header of the predictions a stream writes.
const HEADER_OUT: &str = "time_s,predicted_m,lower_m,upper_m";

/// Time and prediction of one output row, its interval checked around it.
fn parse_row(l: &str) -> (f64, f64) {
    let v: Vec<f64> = l.split(',').map(|c| c.parse().unwrap()).collect();
    assert_eq!(v.len(), 4, "{l}");
    assert!(v[2] <= v[1] && v[1] <= v[3], "{l}");
    (v[0], v[1])
}

/// What the library's streamer writes for `lines` (`t,u,y` text), with the
/// CLI's defaults for `method`: the rows due after each line, and all rows.
fn library_rows(
    method: &Method,
    lead: usize,
    extrapolation: CommandExtrapolation,
    lines: &[String],
) -> (Vec<usize>, Vec<(f64, f64)>) {
    let cfg = EngineConfig {
        window: method.default_window(),
        ..EngineConfig::default()
    };
    let opts = StreamOptions {
        command_lead: lead,
        extrapolation,
        ..StreamOptions::default()
    };
    let mut s = Streamer::with_options(method.build().unwrap(), cfg, opts).unwrap();
    let mut after = Vec::new();
    let mut all = Vec::new();
    let take = |p: feedid::ident::Prediction<'_>, all: &mut Vec<(f64, f64)>| -> usize {
        if !p.is_ok() {
            return 0;
        }
        all.extend(p.time.iter().copied().zip(p.position.iter().copied()));
        p.time.len()
    };
    for l in lines {
        let v: Vec<f64> = l.trim().split(',').map(|c| c.parse().unwrap()).collect();
        s.push(v[0], v[1], v[2]).unwrap();
        let mut n = 0;
        while let Some(p) = s.poll().unwrap() {
            n += take(p, &mut all);
        }
        after.push(n);
    }
    s.finish();
    while let Some(p) = s.poll().unwrap() {
        take(p, &mut all);
    }
    (after, all)
}

/// Rows of `feedid stream ARGS` driven line by line: write one data line,
/// then read the rows due after it (`due[i]`, waiting up to a minute for
/// each); at the end close the input and read the rest. Each row comes with
/// the number of data lines written when it arrived.
fn interleaved(args: &[&str], lines: &[String], due: &[usize]) -> (Vec<(usize, f64, f64)>, String) {
    let mut child = Command::new(BIN)
        .arg("stream")
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let stdout = child.stdout.take().unwrap();
    let mut stderr = child.stderr.take().unwrap();
    let err = std::thread::spawn(move || {
        let mut s = String::new();
        std::io::Read::read_to_string(&mut stderr, &mut s).unwrap();
        s
    });
    let (tx, rx) = mpsc::channel::<String>();
    let reader = std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines() {
            if tx.send(line.unwrap()).is_err() {
                break;
            }
        }
    });
    let parse = parse_row;
    let wait = Duration::from_secs(60);
    let mut out = Vec::new();
    stdin.write_all(format!("{HEADER}\n").as_bytes()).unwrap();
    for (i, l) in lines.iter().enumerate() {
        stdin.write_all(l.as_bytes()).unwrap();
        stdin.flush().unwrap();
        if i == 0 {
            let h = rx
                .recv_timeout(wait)
                .expect("the header after the first sample");
            assert_eq!(h, HEADER_OUT);
        }
        for r in 0..due[i] {
            let row = rx.recv_timeout(wait).unwrap_or_else(|_| {
                panic!("{args:?}: row {r} of {} due after data line {i} did not come before the next line", due[i])
            });
            let (t, y) = parse(&row);
            out.push((i + 1, t, y));
        }
    }
    drop(stdin);
    for row in rx.iter() {
        let (t, y) = parse(&row);
        out.push((lines.len(), t, y));
    }
    reader.join().unwrap();
    assert!(child.wait().unwrap().success());
    (out, err.join().unwrap())
}

/// Every method, by its command-line arguments.
fn every_method() -> Vec<(Vec<&'static str>, Method)> {
    let mut tf: Method = "paper".parse().unwrap();
    if let Method::Paper(c) = &mut tf {
        c.prediction = feedid::ident::PredictionMode::TransferFunction;
    }
    let m = |n: &str| -> Method { n.parse().unwrap() };
    vec![
        (vec!["--method", "auto"], m("auto")),
        (vec!["--method", "paper"], m("paper")),
        (vec!["--method", "paper", "--prediction", "tf"], tf),
        (vec!["--method", "arx"], m("arx")),
        (vec!["--method", "rls"], m("rls")),
        (vec!["--method", "oe"], m("oe")),
    ]
}

#[test]
fn with_a_command_lead_every_prediction_is_written_before_its_measurement_for_every_method() {
    let lead = 10;
    let rec = rig_recording(Scenario::Chirp, 0.14); // 700 samples
    let lines = lead_lines(&rec, lead);
    let dt = rec.dt();
    for (args, method) in every_method() {
        let (due, want) = library_rows(&method, lead, CommandExtrapolation::default(), &lines);
        let mut a = args.clone();
        a.extend(["--command-lead", "10"]);
        let (got, err) = interleaved(&a, &lines, &due);
        assert!(got.len() > 100, "{args:?}: {} rows\n{err}", got.len());
        // the CLI writes what the library's streamer predicts
        assert_eq!(got.len(), want.len(), "{args:?}");
        for ((_, t, y), (tw, yw)) in got.iter().zip(&want) {
            assert_eq!((t, y), (tw, yw), "{args:?}");
        }
        // row for sample k (time t_k) arrived while only data lines before
        // line k (the line carrying y_k) had been written
        for &(written, t, _) in &got {
            let k = (t / dt).round() as usize;
            assert!(
                written <= k,
                "{args:?}: the prediction of sample {k} came after its line ({written} lines written)"
            );
        }
        assert!(
            err.contains("known (command lead 10 covers the horizon)")
                || err.contains("not read by the method"),
            "{err}"
        );
        assert!(err.contains("(100.0 %)"), "{args:?}: {err}");
    }
}

#[test]
fn without_a_lead_the_default_method_predicts_before_the_measurement_with_the_extrapolated_command()
{
    let rec = rig_recording(Scenario::Chirp, 0.14);
    let lines = lead_lines(&rec, 0);
    let dt = rec.dt();
    let method = Method::default();
    let (due, want) = library_rows(&method, 0, CommandExtrapolation::default(), &lines);
    let (got, err) = interleaved(&[], &lines, &due);
    assert!(got.len() > 100, "{err}");
    assert_eq!(got.len(), want.len());
    for &(written, t, _) in &got {
        let k = (t / dt).round() as usize;
        assert!(written <= k, "sample {k}: {written} lines written");
    }
    assert!(
        err.contains("extrapolated: constant acceleration from the last three command samples"),
        "{err}"
    );
    assert!(err.contains("(100.0 %)"), "{err}");
    // waiting for the command instead: the batch engine's predictions, written late
    let text = format!("{HEADER}\n{}", lines.concat());
    let (_, err) = stream(&["--extrapolate", "wait"], &text);
    assert!(err.contains("awaited"), "{err}");
    assert!(
        err.contains("predicted before their measurement arrived: 0 of"),
        "{err}"
    );
}

#[test]
fn with_a_lead_covering_the_horizon_the_stream_equals_identify_for_every_method() {
    // identify (the batch pipeline) on the samples the stream sees: rec from
    // `lead` on; the stream's lines stop `lead` before the end
    //
    // The time stamps are k/4096 s, exact in binary, so that the stream's
    // running mean interval and the recording's mean interval are the same
    // number: oe's continuous-time model depends on it, and a last-digit
    // difference (decimal time stamps) moves its Levenberg–Marquardt
    // iterations by ~1e-10 of the range.
    let lead = 12;
    let rig = rig_recording(Scenario::Ramp, 0.2);
    let rec = Recording::new(
        (0..rig.len()).map(|k| k as f64 / 4096.0).collect(),
        rig.command().to_vec(),
        rig.position().to_vec(),
    )
    .unwrap();
    let n = rec.len();
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("tail.csv");
    std::fs::write(&input, csv(&slice(&rec, lead, n), true)).unwrap();
    let text = format!("{HEADER}\n{}", lead_lines(&rec, lead).concat());
    let scale = rec.position().iter().fold(0.0_f64, |m, v| m.max(v.abs()))
        - rec.position().iter().fold(f64::INFINITY, |m, v| m.min(*v));
    let dt = rec.dt();
    for (args, _) in every_method() {
        let pred = dir.path().join("pred.csv");
        let mut id = vec![
            "identify",
            input.to_str().unwrap(),
            "-o",
            pred.to_str().unwrap(),
        ];
        id.extend(args.iter().copied());
        let o = Command::new(BIN).args(&id).output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let batch: Vec<Option<f64>> = std::fs::read_to_string(&pred)
            .unwrap()
            .lines()
            .skip(1)
            .map(|l| l.split(',').nth(3).and_then(|c| c.parse().ok()))
            .collect();
        let mut sargs = args.clone();
        sargs.extend(["--command-lead", "12"]);
        let (out, err) = stream(&sargs, &text);
        // samples of the stream: rec's lead..n − lead = batch's 0..n − 2·lead
        let m = n - 2 * lead;
        let mut streamed = vec![None; n];
        for (t, y) in rows(&out) {
            let k = (t / dt).round() as usize - lead;
            streamed[k] = Some(y);
        }
        let mut compared = 0;
        for k in 0..m {
            match (streamed[k], batch[k]) {
                (Some(a), Some(b)) => {
                    assert!(
                        (a - b).abs() <= 1e-12 * scale,
                        "{args:?}: sample {k}: {a} vs {b} ({:e} of the range)",
                        (a - b).abs() / scale
                    );
                    compared += 1;
                }
                (None, None) => {}
                (a, b) => panic!("{args:?}: sample {k}: stream {a:?} vs identify {b:?}\n{err}"),
            }
        }
        assert!(compared > m / 3, "{args:?}: {compared} of {m}");
    }
}

#[test]
fn waiting_for_the_command_gives_the_batch_engine_predictions() {
    let rec = rig_recording(Scenario::Ramp, 0.12);
    let n = rec.len();
    let dt = rec.dt();
    let scale = rec.position().iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let cases: [(&[&str], Method, EngineConfig); 4] = [
        (
            &["--method", "paper"],
            Method::Paper(PaperConfig::default()),
            EngineConfig::default(),
        ),
        (
            &["--method", "paper", "--hop", "3"],
            Method::Paper(PaperConfig::default()),
            EngineConfig {
                hop: Some(3),
                ..EngineConfig::default()
            },
        ),
        (
            &["--method", "paper", "--solver", "simplex"],
            Method::Paper(PaperConfig {
                solver: Solver::Simplex,
                ..PaperConfig::default()
            }),
            EngineConfig::default(),
        ),
        (
            &["--method", "auto", "--extrapolate", "wait"],
            Method::default(),
            EngineConfig {
                window: Method::default().default_window(),
                ..EngineConfig::default()
            },
        ),
    ];
    for (args, method, cfg) in cases {
        let batch = run(method.build().unwrap().as_mut(), &rec.signals(), &cfg).unwrap();
        let (out, err) = stream(args, &csv(&rec, true));
        let mut predicted = vec![None; n + 10];
        for (t, y) in rows(&out) {
            let k = (t / dt).round() as usize;
            assert!((t - rec.time().get(k).copied().unwrap_or(k as f64 * dt)).abs() < 1e-12);
            predicted[k] = Some(y);
        }
        for (k, &streamed) in predicted.iter().enumerate().take(n) {
            match (streamed, batch.prediction(k)) {
                (Some(a), Some(b)) => assert!(
                    (a - b).abs() <= 1e-12 * scale,
                    "{args:?}: sample {k}: {a} vs {b}"
                ),
                (None, None) => {}
                (a, b) => panic!("{args:?}: sample {k}: {a:?} vs {b:?}"),
            }
        }
        assert!(batch.stats.samples > n / 2, "{args:?}");
        assert!(
            err.contains(&format!("samples {n},")) && err.contains("skipped lines 0"),
            "{err}"
        );
        assert!(
            err.contains(&format!("scored {} of {n} samples", batch.stats.samples)),
            "{args:?}: {err}"
        );
    }
}

#[test]
fn simulate_output_streams_with_no_options_and_the_reading_options_of_identify_work() {
    let dir = tempfile::tempdir().unwrap();
    let r = dir.path().join("r.csv");
    let o = Command::new(BIN)
        .args([
            "simulate",
            "--scenario",
            "ramp",
            "--duration",
            "0.1",
            "-o",
            r.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(o.status.success());
    let text = std::fs::read_to_string(&r).unwrap();
    let (plain, err) = stream(&["--method", "paper"], &text);
    assert!(
        err.contains("lines 501 (1 header), skipped lines 0, samples 500"),
        "{err}"
    );
    let want = rows(&plain);
    assert!(want.len() > 400);
    // the same samples in other units, orders, delimiters, with or without header
    let rec = feedid::io::read_csv_from_str(&text, "r".as_ref(), &Default::default()).unwrap();
    let (t, u, y) = (rec.time(), rec.command(), rec.position());
    let variants: Vec<(Vec<&str>, String)> = vec![
        (
            vec!["--unit", "mm", "--time-unit", "ms"],
            (0..rec.len())
                .map(|k| format!("{},{},{}\n", t[k] * 1e3, u[k] * 1e3, y[k] * 1e3))
                .collect(),
        ),
        (
            vec![
                "--time",
                "t",
                "--command",
                "3",
                "--position",
                "Pos",
                "--delimiter",
                ";",
            ],
            format!(
                "pos;t;cmd\n{}",
                (0..rec.len())
                    .map(|k| format!("{};{};{}\n", y[k], t[k], u[k]))
                    .collect::<String>()
            ),
        ),
        (
            vec!["--scale", "1e-9"],
            (0..rec.len())
                .map(|k| format!("{}\t{}\t{}\n", t[k], u[k] * 1e9, y[k] * 1e9))
                .collect(),
        ),
        (
            vec!["--rate", "5000", "--no-header"],
            (0..rec.len())
                .map(|k| format!("{} {}\n", u[k], y[k]))
                .collect(),
        ),
    ];
    for (args, body) in variants {
        let mut a = vec!["--method", "paper"];
        a.extend(args.iter().copied());
        let (out, err) = stream(&a, &body);
        let got = rows(&out);
        assert_eq!(got.len(), want.len(), "{args:?}: {err}");
        for ((ta, ya), (tb, yb)) in got.iter().zip(&want) {
            assert!((ta - tb).abs() < 1e-12, "{args:?}: {ta} vs {tb}");
            assert!(
                (ya - yb).abs() <= 1e-9 * yb.abs().max(1e-6),
                "{args:?}: {ya} vs {yb}"
            );
        }
    }
    // a bad column is fatal at once
    let o = stream_output(&["--position", "nope"], &text);
    assert_eq!(o.status.code(), Some(2));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("nope") && e.contains("position_m"), "{e}");
}

#[test]
fn gaps_and_backward_times_are_reported_with_their_line() {
    let rec = rig_recording(Scenario::Ramp, 0.1);
    let mut lines: Vec<String> = csv(&rec, true).lines().map(|l| format!("{l}\n")).collect();
    // file lines: 1 header, sample k on line k + 2; drop samples 200..205,
    // repeat an old time after sample 300
    lines.drain(201..206);
    lines.insert(297, format!("{},0,0\n", rec.time()[10]));
    let (out, err) = stream(&["--method", "paper"], &lines.concat());
    assert!(
        err.contains("stdin: line 202: gap: time jumps from 0.0398 s to 0.041 s: 5 samples of 0.0002 s missing; the windows restart"),
        "{err}"
    );
    assert!(
        err.contains("stdin: line 298: time is not strictly increasing"),
        "{err}"
    );
    assert!(
        err.contains("gaps 1,") && err.contains("skipped lines 1,"),
        "{err}"
    );
    // no window spans the gap: after the last window before it (predicting
    // samples 200..210 at 0.04 … 0.0418 s, written before the gap was
    // known), the first prediction is for the sample one window (20) after it
    let t: Vec<f64> = rows(&out).iter().map(|r| r.0).collect();
    let after_gap: Vec<f64> = t.iter().copied().filter(|&t| t > 0.0418 + 1e-9).collect();
    assert!(
        (after_gap[0] - rec.time()[205 + 20]).abs() < 1e-12,
        "{:?}",
        &after_gap[..3]
    );
}

#[test]
fn malformed_lines_are_reported_with_their_number_and_skipped() {
    let rec = rig_recording(Scenario::Ramp, 0.03);
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
    let (out_clean, _) = stream(&["--method", "paper"], &clean);
    let (out_dirty, err) = stream(&["--method", "paper"], &dirty);
    assert_eq!(out_clean, out_dirty);
    for n in [33, 34, 36, 37, 38] {
        assert!(err.contains(&format!("line {n}")), "line {n} in\n{err}");
    }
    assert!(
        !err.contains("line 32") && !err.contains("line 35"),
        "{err}"
    );
    assert!(err.contains("skipped lines 5,"), "{err}");
    assert!(err.contains(&format!("samples {},", rec.len())), "{err}");
    // a bad option is an error with exit code 2
    for args in [
        &["--method", "magic"][..],
        &["--extrapolate", "cubic"],
        &["--method", "paper", "--extrapolate", "hold"],
        &["--command-lead", "10", "--extrapolate", "velocity"],
        &["--order", "auto"],
        &["--rate", "5000", "--time", "1"],
    ] {
        let o = stream_output(args, &clean);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        assert!(o.stdout.is_empty(), "{args:?}");
    }
}

#[test]
fn no_usable_line_and_an_unwritable_output_exit_2_and_a_closed_reader_exits_0() {
    // nothing usable: exit 2, nothing on standard output, no rms
    for input in [
        "",
        "\n# only comments\n",
        "a,b,c\nx,y,z\n",
        "time_s,command_m,position_m\n1,2\nfoo\n",
    ] {
        let o = stream_output(&[], input);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{input:?}: {err}");
        assert!(o.stdout.is_empty(), "{input:?}");
        assert!(err.contains("error: no "), "{err}");
        assert!(!err.contains("rms"), "{err}");
        assert!(err.contains("scored: no sample"), "{err}");
    }
    // too few samples for a window: exit 0, no rms over nothing
    let rec = rig_recording(Scenario::Ramp, 0.004);
    let (out, err) = stream(&[], &csv(&rec, true));
    assert_eq!(out, format!("{HEADER_OUT}\n"));
    assert!(
        err.contains("scored: no sample") && !err.contains("rms"),
        "{err}"
    );
    // a full disk
    let rec = rig_recording(Scenario::Ramp, 0.1);
    let text = csv(&rec, true);
    if std::path::Path::new("/dev/full").exists() {
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let mut child = Command::new(BIN)
            .args(["stream", "--method", "paper"])
            .stdin(Stdio::piped())
            .stdout(full)
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let mut stdin = child.stdin.take().unwrap();
        let t = text.clone();
        let w = std::thread::spawn(move || {
            let _ = stdin.write_all(t.as_bytes());
        });
        let o = child.wait_with_output().unwrap();
        w.join().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(
            err.contains("cannot write the predictions to standard output")
                && err.contains("No space left"),
            "{err}"
        );
    } else {
        eprintln!("skipped: /dev/full absent");
    }
    // a reader that closes the pipe after the first rows: exit 0
    let mut child = Command::new(BIN)
        .args(["stream", "--method", "paper"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let w = std::thread::spawn(move || {
        let _ = stdin.write_all(text.as_bytes());
    });
    let mut out = BufReader::new(child.stdout.take().unwrap());
    let mut first = String::new();
    out.read_line(&mut first).unwrap();
    out.read_line(&mut first).unwrap();
    drop(out);
    w.join().unwrap();
    assert_eq!(child.wait().unwrap().code(), Some(0));
}

#[test]
fn a_stream_that_loses_to_holding_says_so_with_figures_cause_and_options() {
    // a heavy 100 Hz axis of the drive zoo (member 112: a ramp program,
    // Kv 10.8) with the held command over a 20-sample (200 ms) horizon:
    // the predictions lose to holding the last position
    let rec = feedid::zoo::Zoo::standard()
        .member(112)
        .unwrap()
        .recording()
        .unwrap();
    assert!((rec.rate_hz() - 100.0).abs() < 1e-6);
    let (_, err) = stream(
        &["--extrapolate", "hold", "--horizon", "20"],
        &csv(&rec, true),
    );
    assert!(err.contains("lost to holding the last position"), "{err}");
    for needle in [
        "200.000 ms",
        "--command-lead",
        "--extrapolate wait",
        "µm against",
    ] {
        assert!(err.contains(needle), "{needle}: {err}");
    }
    // a time needs the rate in a stream
    let o = stream_output(&["--horizon", "2ms"], &csv(&rec, true));
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--rate"));
    // with it, 20ms is 2 samples at 100 Hz
    let (out, err) = stream(&["--horizon", "20ms", "--rate", "100"], &csv(&rec, true));
    assert!(err.contains("scored"), "{err}");
    // each window predicts 2 samples: "windows N: P predicted, …; R rows written"
    let line = err.lines().find(|l| l.starts_with("windows ")).unwrap();
    let predicted: usize = line
        .split(": ")
        .nth(1)
        .unwrap()
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(rows(&out).len(), 2 * predicted, "{line}");
}

#[test]
fn stream_numbers_and_summary_read_like_identify() {
    let rec = rig_recording(Scenario::Ramp, 0.2);
    let text = csv(&rec, true);
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("r.csv");
    std::fs::write(&input, &text).unwrap();
    let predictions = dir.path().join("p.csv");
    let o = Command::new(BIN)
        .args(["identify", input.to_str().unwrap(), "--method", "arx", "-o"])
        .arg(&predictions)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let identify_summary = String::from_utf8_lossy(&o.stdout).to_string();
    let (out, err) = stream(&["--method", "arx"], &text);
    // numbers: the formatter of identify's CSV, the shortest text that reads
    // back as the same f64 (and an empty cell, never NaN, for no number)
    let identify_csv = std::fs::read_to_string(&predictions).unwrap();
    for (what, table) in [("stream", &out), ("identify", &identify_csv)] {
        let mut cells = 0;
        for line in table.lines().skip(1) {
            for cell in line.split(',').filter(|c| !c.is_empty()) {
                let v: f64 = cell.parse().unwrap();
                assert_eq!(cell, format!("{v}"), "{what}: {line}");
                cells += 1;
            }
        }
        assert!(cells > 1000, "{what}: {cells}");
    }
    assert!(!out.contains("NaN") && !out.contains("inf"));
    // errors in µm, worded as identify's summary
    assert!(
        identify_summary.contains("prediction error: rms "),
        "{identify_summary}"
    );
    let line = err
        .lines()
        .find(|l| l.starts_with("scored "))
        .unwrap_or_else(|| panic!("{err}"));
    assert!(line.contains("; prediction error: rms "), "{line}");
    for part in line.split("rms ").skip(1) {
        let (value, rest) = part.split_once(' ').unwrap();
        assert!(
            value.parse::<f64>().is_ok() && !value.contains('e'),
            "{line}"
        );
        assert!(rest.starts_with("µm"), "{line}");
    }
    assert!(!line.contains(" m;") && !line.contains(" m,"), "{line}");
}
