//! `feedid stream --compensate`: online compensation through a pipe — each
//! command written before the drive needs it, the virtual rig in the loop
//! gives the library's co-simulation, a replayed recording gives the
//! library's command stream, and loud failures.

use std::io::{BufRead, BufReader, Write};
use std::process::{Command, Output, Stdio};

use feedid::compensate::{co_simulate, CommandStream, OnlineConfig};
use feedid::drive::{RigParams, VirtualRig};
use feedid::signal::Scenario;

const BIN: &str = env!("CARGO_BIN_EXE_feedid");

/// `feedid` with `args`, `input` on its standard input, run to the end.
fn run(args: &[&str], input: &[u8]) -> Output {
    let mut child = Command::new(BIN)
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // a refused command exits before it reads: its closed pipe is no failure here
    let _ = child.stdin.take().unwrap().write_all(input);
    child.wait_with_output().unwrap()
}

#[test]
fn in_a_closed_loop_each_command_comes_before_its_sample_and_equals_the_co_simulation() {
    let rate = 5000.0;
    let dt = 1.0 / rate;
    let lead = 4;
    let desired = Scenario::Scurve.command(rate, 0.3, 0).unwrap();
    let rig = VirtualRig::new(RigParams::default()).with_seed(9);
    let cfg = OnlineConfig {
        preview: lead - 1,
        ..OnlineConfig::default()
    };
    let sim = co_simulate(|f| rig.stepper(rate, f), &desired, dt, &cfg, 1, None).unwrap();
    let mut child = Command::new(BIN)
        .args(["stream", "--compensate", "--command-lead", "4"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    let mut line = String::new();
    let mut axis = rig.stepper(rate, desired[0]).unwrap();
    let mut commands = Vec::new();
    for (i, &ahead) in desired.iter().enumerate() {
        // line i: its time, the program `lead` samples ahead (the stream's
        // sample i + lead is the co-simulation's sample i), the position of
        // its own sample
        writeln!(stdin, "{},{},{}", i as f64 * dt, ahead, axis.position()).unwrap();
        stdin.flush().unwrap();
        // the interval comes from the first two lines: the header and the
        // first command (for the stream's sample `lead`) follow the second
        if i == 1 {
            line.clear();
            stdout.read_line(&mut line).unwrap();
            assert_eq!(line.trim(), "time_s,desired_m,command_m");
        }
        if i == 1 || i >= lead {
            // the command of the next sample, written before the next line is read
            line.clear();
            stdout.read_line(&mut line).unwrap();
            let f: Vec<f64> = line.trim().split(',').map(|v| v.parse().unwrap()).collect();
            let k = commands.len();
            assert!((f[0] - (k + lead) as f64 * dt).abs() < 1e-9, "{line}");
            assert_eq!(f[1], desired[k], "{line}");
            commands.push(f[2]);
            if k > 0 {
                axis.advance(f[2]).unwrap();
            }
        }
    }
    drop(stdin);
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success());
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(err.contains("compensated"), "{err}");
    assert!(commands.len() > desired.len() - lead);
    for (k, (a, b)) in commands.iter().zip(&sim.command).enumerate() {
        assert_eq!(a, b, "sample {k}");
    }
    // and the loop compensated: less error than the plain command
    assert!(sim.last.reduction > 2.0, "{}", sim.last.reduction);
}

#[test]
fn a_replayed_recording_gives_the_librarys_command_stream() {
    let rate = 5000.0;
    let dt = 1.0 / rate;
    let command = Scenario::Scurve.command(rate, 0.4, 0).unwrap();
    let out = VirtualRig::new(RigParams::default())
        .with_seed(3)
        .simulate(&command, rate)
        .unwrap();
    let mut input = String::from("time_s,command_m,position_m\n");
    let mut lib = CommandStream::new(OnlineConfig::default(), 5, dt, true).unwrap();
    let mut expected = String::from("time_s,desired_m,command_m\n");
    for ((&t, &u), &y) in out.time.iter().zip(&command).zip(&out.position) {
        input += &format!("{t},{u},{y}\n");
        if let Some(r) = lib.push(t, u, y).unwrap() {
            expected += &format!("{},{},{}\n", r.time, r.desired, r.command);
        }
    }
    let o = run(
        &["stream", "--compensate", "--replay", "--command-lead", "5"],
        input.as_bytes(),
    );
    let err = String::from_utf8(o.stderr).unwrap();
    assert!(o.status.success(), "{err}");
    let got = String::from_utf8(o.stdout).unwrap();
    // the interval comes from the first two lines: the same up to rounding
    let parse = |s: &str| -> Vec<Vec<f64>> {
        s.lines()
            .skip(1)
            .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
            .collect()
    };
    let (g, e) = (parse(&got), parse(&expected));
    assert_eq!(g.len(), e.len());
    for (a, b) in g.iter().zip(&e) {
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() <= 1e-12 * y.abs().max(1e-3), "{a:?} vs {b:?}");
        }
    }
    assert!(err.contains("replayed"), "{err}");
    assert!(err.contains("model in use: lag T1"), "{err}");
}

#[test]
fn a_short_lead_or_replay_without_compensate_exits_2() {
    let run = |args: &[&str]| run(args, b"0,0,0\n0.001,0,0\n");
    let o = run(&["stream", "--compensate", "--command-lead", "2"]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8(o.stderr).unwrap();
    assert!(err.contains("at least 3 lines ahead"), "{err}");
    assert!(o.stdout.is_empty());
    let o = run(&["stream", "--compensate", "--command-lead", "40"]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8(o.stderr).unwrap();
    assert!(err.contains("3 to 33 samples ahead"), "{err}");
    let o = run(&["stream", "--replay"]);
    assert_eq!(o.status.code(), Some(2));
    let o = run(&[
        "stream",
        "--compensate",
        "--command-lead",
        "3",
        "--max-velocity",
        "-1",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8(o.stderr)
        .unwrap()
        .contains("max velocity"));
}

#[test]
fn identification_options_with_compensate_are_refused_not_ignored() {
    let run = |args: &[&str]| run(args, b"0,0,0\n0.001,0,0\n");
    let base = ["stream", "--compensate", "--command-lead", "4"];
    for extra in [
        &["--method", "arx"][..],
        &["--window", "50"],
        &["--horizon", "5"],
        &["--interval", "90"],
        &["--lambda", "0.99"],
        &["--extrapolate", "velocity"],
    ] {
        let args: Vec<&str> = base.iter().chain(extra).copied().collect();
        let o = run(&args);
        assert_eq!(o.status.code(), Some(2), "{extra:?}");
        let err = String::from_utf8(o.stderr).unwrap();
        assert!(err.contains(extra[0]), "{extra:?}: {err}");
        assert!(o.stdout.is_empty(), "{extra:?}");
    }
}

#[test]
fn refused_lines_are_reported_with_their_number_and_skipped() {
    let mut input = String::new();
    for k in 0..40 {
        let t = k as f64 * 1e-3;
        if k == 10 {
            input += "0.0005,0,0\n"; // time backwards
        } else if k == 20 {
            input += &format!("{t},nan,0\n");
        } else {
            input += &format!("{t},{},0\n", 1e-4 * k as f64);
        }
    }
    let o = run(
        &["stream", "--compensate", "--command-lead", "3"],
        input.as_bytes(),
    );
    let err = String::from_utf8(o.stderr).unwrap();
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("stdin: line 11: time is not strictly increasing"),
        "{err}"
    );
    assert!(
        err.contains("stdin: line 21: ") && err.contains("NaN"),
        "{err}"
    );
    assert!(err.contains("skipped 2"), "{err}");
    let out = String::from_utf8(o.stdout).unwrap();
    // every row a finite command for a later sample
    let mut last = f64::NEG_INFINITY;
    for l in out.lines().skip(1) {
        let f: Vec<f64> = l.split(',').map(|v| v.parse().unwrap()).collect();
        assert!(f.iter().all(|v| v.is_finite()), "{l}");
        assert!(f[0] > last, "{l}");
        last = f[0];
    }
}

#[test]
fn an_unwritable_output_exits_2_naming_the_commands() {
    let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") else {
        return; // no /dev/full here
    };
    let mut child = Command::new(BIN)
        .args(["stream", "--compensate", "--command-lead", "3"])
        .stdin(Stdio::piped())
        .stdout(full)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let input: String = (0..20)
        .map(|k| format!("{},0,0\n", k as f64 * 1e-3))
        .collect();
    let _ = child.stdin.take().unwrap().write_all(input.as_bytes());
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8(o.stderr).unwrap();
    assert!(
        err.contains("cannot write the commands to standard output"),
        "{err}"
    );
}
