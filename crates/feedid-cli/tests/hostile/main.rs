//! The bad-input catalogue: hostile files and arguments through every command
//! that reads a file or standard input, as a user would call it.
//!
//! Three tables, each row a name, the input and what must happen:
//!
//! - [`catalogue`]: recordings (text and MAT) × every command that reads one
//!   ([`RECORDING_COMMANDS`]; `stream` gets the bytes on standard input);
//! - [`toml_catalogue`]: parameter and effects files × every command that
//!   reads one ([`TomlCmd::ALL`]);
//! - [`arg_catalogue`]: command lines with unwritable outputs, outputs over
//!   inputs and numbers a user can type.
//!
//! A failure must be exit code 2 with exactly one `error:` line (under 400
//! bytes) naming the place (no panic, which exits 101), and must leave no
//! output file behind. Odd but legal inputs succeed with every number in the
//! outputs finite, with a warning where the user should know (a command that
//! never moves); `stream` skips a bad line and reports it by number.
//!
//! To cover a new command: add a [`Cmd`] (or [`TomlCmd`]) variant with its
//! arguments and list it in [`RECORDING_COMMANDS`] (or [`TomlCmd::ALL`]);
//! every row then runs through it, and [`expectation`] takes per-command
//! exceptions.
//!
//! The inputs are small (at most a few hundred samples, a few MB for the long
//! lines) so that the whole catalogue runs in a few seconds.

mod args;
#[path = "../common/mod.rs"]
mod common;
mod messages;
mod outputs;
mod params;
mod verdicts;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

use common::stderr;

/// A command that reads a recording.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Cmd {
    Info,
    Identify,
    Order,
    /// `stream`, with the file on standard input.
    Stream,
    Report,
    Sweep,
    Greybox,
}

/// Every command that reads a recording.
const RECORDING_COMMANDS: [Cmd; 7] = [
    Cmd::Info,
    Cmd::Identify,
    Cmd::Order,
    Cmd::Stream,
    Cmd::Report,
    Cmd::Sweep,
    Cmd::Greybox,
];

impl Cmd {
    /// Arguments for reading `input`, writing outputs (if any) under `out`.
    fn args(self, input: &Path, out: &Path) -> Vec<String> {
        let s = |p: PathBuf| p.display().to_string();
        let i = s(input.to_path_buf());
        match self {
            Cmd::Info => vec!["info".into(), i, "--json".into()],
            Cmd::Identify => vec![
                "identify".into(),
                i,
                "--window".into(),
                "20".into(),
                "--horizon".into(),
                "5".into(),
                "-o".into(),
                s(out.join("pred.csv")),
                "--coefficients".into(),
                s(out.join("coef.csv")),
                "--summary".into(),
                s(out.join("summary.json")),
            ],
            Cmd::Order => vec![
                "order".into(),
                i,
                "--na".into(),
                "1..3".into(),
                "--nb".into(),
                "1..3".into(),
                "--json".into(),
            ],
            Cmd::Stream => vec![
                "stream".into(),
                "--window".into(),
                "20".into(),
                "--horizon".into(),
                "5".into(),
            ],
            Cmd::Report => vec![
                "report".into(),
                i,
                "--methods".into(),
                "paper,arx,auto".into(),
                "--window".into(),
                "20".into(),
                "--horizon".into(),
                "5".into(),
                "-o".into(),
                s(out.join("report.html")),
            ],
            Cmd::Sweep => vec![
                "sweep".into(),
                i,
                "--windows".into(),
                "10,20".into(),
                "--horizons".into(),
                "5".into(),
                "-o".into(),
                s(out.join("sweep.csv")),
                "--plot".into(),
                s(out.join("sweep.svg")),
            ],
            Cmd::Greybox => vec![
                "greybox".into(),
                i,
                "--estimate".into(),
                "Kv".into(),
                "--max-iterations".into(),
                "5".into(),
                "--summary".into(),
                s(out.join("gb.json")),
            ],
        }
    }
}

/// What a command must do with an input.
#[derive(Debug, Clone, Copy)]
enum Expect {
    /// Exit 2, one `error:` line containing every needle (`{file}` = the
    /// input's file name), nothing written.
    Fails(&'static [&'static str]),
    /// Exit 0; every number on stdout and in the output files finite.
    Succeeds,
    /// Exit 0 as [`Expect::Succeeds`], or 2 as [`Expect::Fails`] with these
    /// needles: legal but odd data, where refusing with a reason is fine too.
    SucceedsOrFails(&'static [&'static str]),
    /// Exit 0 as [`Expect::Succeeds`], and standard error reports every
    /// needle (`stream` skips a bad line and says so: nothing is lost silently).
    Reports(&'static [&'static str]),
}

/// One row of the catalogue.
struct Case {
    name: &'static str,
    /// File name (its extension selects the reader).
    file: &'static str,
    bytes: Vec<u8>,
    /// Extra arguments for the file-reading commands (e.g. MAT variable names).
    extra: &'static [&'static str],
    /// Expectation for every command in [`RECORDING_COMMANDS`] but `stream`…
    expect: Expect,
    /// …and for `stream`, which reports and skips bad lines and goes on
    /// (and fails when no line was usable).
    stream: Expect,
}

const HEADER: &str = "time_s,command_m,position_m\n";

/// `n` rows of a 1 mm move (command ramps over 10 samples from sample 5,
/// position lags one sample), times `t0 + k·dt`, values scaled by `scale`.
fn rows(n: usize, t0: f64, dt: f64, scale: f64) -> String {
    let mut s = String::new();
    for k in 0..n {
        let ramp = |j: f64| 1e-3 * ((j - 5.0) / 10.0).clamp(0.0, 1.0);
        let (u, y) = (ramp(k as f64), ramp(k as f64 - 1.0));
        s += &format!("{},{},{}\n", t0 + k as f64 * dt, scale * u, scale * y);
    }
    s
}

fn csv(body: &str) -> Vec<u8> {
    format!("{HEADER}{body}").into_bytes()
}

/// A recording with one bad line at data row 10 (file line 12).
fn with_bad_row(row: &str) -> Vec<u8> {
    csv(&format!(
        "{}{row}\n{}",
        rows(10, 0.0, 1e-3, 1.0),
        rows(30, 0.011, 1e-3, 1.0)
    ))
}

/// A first-order loop (lag 2 ms) following a 3 mm ramp at 1 kHz, 200 samples,
/// columns scaled: command × `c`, position × `x`, time × `t`.
fn scaled_columns(c: f64, x: f64, t: f64) -> String {
    let mut s = String::new();
    let mut y = 0.0;
    for k in 0..200 {
        let u = 3e-5 * (k as f64 - 20.0).clamp(0.0, 100.0);
        s += &format!("{},{},{}\n", t * k as f64 * 1e-3, c * u, x * y);
        y += 0.5 * (u - y);
    }
    s
}

/// The loop of [`scaled_columns`] whose position (with a 1 nm dither, so the
/// encoder's resolution is fine) stops changing from sample 80 on while the
/// command goes on moving.
fn frozen_mid_move() -> String {
    let mut s = String::new();
    let (mut y, mut x) = (0.0, 0.0);
    for k in 0..200 {
        let u = 3e-5 * (k as f64 - 20.0).clamp(0.0, 100.0);
        if k < 80 {
            x = y + if k % 2 == 0 { 1e-9 } else { -1e-9 };
        }
        s += &format!("{},{u},{x}\n", k as f64 * 1e-3);
        y += 0.5 * (u - y);
    }
    s
}

/// A fixture under `tests/data/`.
fn fixture(name: &str) -> Vec<u8> {
    std::fs::read(common::data(name)).unwrap()
}

const MAT_VARS: &[&str] = &["--time", "t", "--command", "qg", "--position", "qm"];

fn catalogue() -> Vec<Case> {
    use Expect::*;
    let good = rows(60, 0.0, 1e-3, 1.0);
    let mut corrupted = fixture("double_v6.mat");
    // the size of the first element's tag: far beyond the file
    corrupted[132..136].copy_from_slice(&0x7fff_fff0_u32.to_le_bytes());
    let mut compressed_bad = fixture("compressed_v7.mat");
    let n = compressed_bad.len();
    for b in &mut compressed_bad[150..n - 20] {
        *b ^= 0x5a;
    }
    let truncated_v7 = fixture("compressed_v7.mat")[..300].to_vec();
    vec![
        Case {
            name: "empty file",
            file: "empty.csv",
            bytes: vec![],
            extra: &[],
            expect: Fails(&["{file}", "empty"]),
            stream: Fails(&["no data line"]),
        },
        Case {
            name: "header only",
            file: "header.csv",
            bytes: HEADER.into(),
            extra: &[],
            expect: Fails(&["{file}", "header only"]),
            stream: Fails(&["no usable line"]),
        },
        Case {
            name: "one sample",
            file: "one.csv",
            bytes: csv("0,0,0\n"),
            extra: &[],
            expect: Fails(&["{file}", "need at least 2", "got 1"]),
            stream: Succeeds,
        },
        Case {
            name: "NaN",
            file: "nan.csv",
            bytes: with_bad_row("0.01,0.001,NaN"),
            extra: &[],
            expect: Fails(&["{file}", "line 12", "position_m", "NaN"]),
            stream: Reports(&["line 12:", "skipped lines 1"]),
        },
        Case {
            name: "Inf",
            file: "inf.csv",
            bytes: with_bad_row("0.01,-inf,0"),
            extra: &[],
            expect: Fails(&["{file}", "line 12", "command_m", "inf"]),
            stream: Reports(&["line 12:", "skipped lines 1"]),
        },
        Case {
            name: "number overflowing to Inf",
            file: "overflow.csv",
            bytes: with_bad_row("0.01,1e999,0"),
            extra: &[],
            expect: Fails(&["{file}", "line 12", "command_m", "inf"]),
            stream: Reports(&["line 12:", "skipped lines 1"]),
        },
        Case {
            name: "value beyond ±1e100",
            file: "beyond.csv",
            bytes: with_bad_row("0.01,1e150,0"),
            extra: &[],
            expect: Fails(&["{file}", "line 12", "command_m", "beyond"]),
            stream: Reports(&["line 12:", "beyond", "skipped lines 1"]),
        },
        Case {
            name: "text in a number column",
            file: "text.csv",
            bytes: with_bad_row("0.01,abc,0"),
            extra: &[],
            expect: Fails(&["{file}", "line 12", "command_m", "abc"]),
            stream: Reports(&["line 12, column `command_m`", "skipped lines 1"]),
        },
        Case {
            name: "missing field",
            file: "ragged.csv",
            bytes: with_bad_row("0.01,0"),
            extra: &[],
            expect: Fails(&["{file}", "line 12", "2 fields, expected 3"]),
            stream: Reports(&["line 12:", "skipped lines 1"]),
        },
        Case {
            name: "duplicate time",
            file: "dup.csv",
            bytes: with_bad_row("0.009,0,0"),
            extra: &[],
            expect: Fails(&["{file}", "line 12", "time_s", "not strictly increasing"]),
            stream: Reports(&["line 12:", "skipped lines 1"]),
        },
        Case {
            name: "decreasing time",
            file: "decr.csv",
            bytes: with_bad_row("0.005,0,0"),
            extra: &[],
            expect: Fails(&["{file}", "line 12", "time_s", "not strictly increasing"]),
            stream: Reports(&["line 12:", "skipped lines 1"]),
        },
        Case {
            name: "invalid UTF-8",
            file: "latin1.csv",
            bytes: {
                let mut b = csv(&rows(5, 0.0, 1e-3, 1.0));
                b.extend_from_slice(b"0.005,\xe9\xff,0\n");
                b.extend_from_slice(rows(30, 0.006, 1e-3, 1.0).as_bytes());
                b
            },
            extra: &[],
            expect: Fails(&["{file}", "line 7", "UTF-8"]),
            stream: Reports(&["line 7:", "skipped lines 1"]),
        },
        Case {
            name: "extremely long number",
            file: "long_number.csv",
            bytes: with_bad_row(&format!("0.01,{},0", "1".repeat(1 << 20))),
            extra: &[],
            // the line is over 1 MiB: refused as a line before any number is read
            expect: Fails(&["{file}", "line 12", "longer than 1048576 bytes"]),
            stream: Reports(&["line 12:", "skipped lines 1"]),
        },
        Case {
            name: "extremely long line of text",
            file: "long_text.csv",
            bytes: with_bad_row(&"x".repeat(2 << 20)),
            extra: &[],
            expect: Fails(&["{file}", "line 12"]),
            stream: Reports(&["line 12:", "skipped lines 1"]),
        },
        Case {
            name: "100 000 columns",
            file: "wide.csv",
            bytes: {
                let head: Vec<String> = (0..100_000).map(|i| format!("c{i}")).collect();
                let row = vec!["1"; 100_000].join(",");
                format!("{}\n{row}\n{row}\n", head.join(",")).into_bytes()
            },
            extra: &[],
            expect: Fails(&["{file}", "time_s"]),
            stream: Fails(&["no column `time_s`"]),
        },
        Case {
            name: "window longer than the data",
            file: "short.csv",
            bytes: csv(&rows(12, 0.0, 1e-3, 1.0)),
            extra: &[],
            expect: Succeeds, // info, order; identify: see the overrides
            stream: Succeeds,
        },
        Case {
            name: "huge magnitudes (1e12)",
            file: "huge.csv",
            bytes: csv(&rows(60, 0.0, 1e-3, 1e15)), // up to 1e12 m
            extra: &[],
            expect: Succeeds,
            stream: Succeeds,
        },
        Case {
            name: "tiny magnitudes (1e-12)",
            file: "tiny.csv",
            bytes: csv(&rows(60, 0.0, 1e-3, 1e-9)), // up to 1e-12 m
            extra: &[],
            expect: Reports(&["never moves"]),
            stream: Succeeds,
        },
        Case {
            name: "constant signals",
            file: "constant.csv",
            bytes: csv(&rows(60, 0.0, 1e-3, 0.0).replace(",0,0\n", ",0.5,0.5\n")),
            extra: &[],
            expect: Reports(&["never moves"]),
            stream: Succeeds,
        },
        Case {
            name: "time far from zero (1e12 s)",
            file: "late.csv",
            bytes: csv(&rows(60, 1e12, 1e-3, 1.0)),
            extra: &[],
            expect: SucceedsOrFails(&["{file}"]),
            stream: Succeeds,
        },
        Case {
            name: "time span overflowing",
            file: "span.csv",
            bytes: csv("-1.5e308,0,0\n0,1e-3,0\n1.5e308,2e-3,1e-3\n"),
            extra: &[],
            expect: Fails(&["{file}", "time"]),
            stream: Succeeds,
        },
        Case {
            name: "time step too small for a rate",
            file: "subnormal.csv",
            bytes: csv("0,0,0\n5e-324,1e-3,0\n1e-323,2e-3,1e-3\n"),
            extra: &[],
            expect: Fails(&["{file}", "time"]),
            stream: Succeeds,
        },
        Case {
            name: "good recording (control row)",
            file: "good.csv",
            bytes: csv(&good),
            extra: &[],
            expect: Succeeds,
            stream: Succeeds,
        },
        Case {
            name: "truncated .mat",
            file: "truncated.mat",
            bytes: fixture("double_v6.mat")[..400].to_vec(),
            extra: MAT_VARS,
            expect: Fails(&["{file}", "truncated"]),
            stream: Fails(&["no usable line"]),
        },
        Case {
            name: "truncated compressed .mat",
            file: "truncated_v7.mat",
            bytes: truncated_v7,
            extra: MAT_VARS,
            expect: Fails(&["{file}"]),
            stream: Fails(&["no usable line"]),
        },
        Case {
            name: "corrupted .mat (size field)",
            file: "corrupted.mat",
            bytes: corrupted,
            extra: MAT_VARS,
            expect: Fails(&["{file}", "byte 128"]),
            stream: Fails(&["no usable line"]),
        },
        Case {
            name: "corrupted compressed .mat",
            file: "corrupted_v7.mat",
            bytes: compressed_bad,
            extra: MAT_VARS,
            expect: Fails(&["{file}", "compressed"]),
            stream: Fails(&["no usable line"]),
        },
        Case {
            name: "header-only .mat",
            file: "header.mat",
            bytes: fixture("double_v6.mat")[..128].to_vec(),
            extra: MAT_VARS,
            expect: Fails(&["{file}", "no variable `t`", "available: none"]),
            stream: Fails(&["no usable line"]),
        },
        Case {
            name: "wrong variable names",
            file: "vars.mat",
            bytes: fixture("double_v6.mat"),
            extra: &["--time", "time", "--command", "qg", "--position", "qm"],
            expect: Fails(&["{file}", "no variable `time`", "qg"]),
            stream: Fails(&["no usable line"]),
        },
        // --- hostile text and implausible recordings
        Case {
            name: "CR-only line endings",
            file: "mac.csv",
            bytes: csv(&good)
                .iter()
                .map(|&b| if b == b'\n' { b'\r' } else { b })
                .collect(),
            extra: &[],
            expect: Succeeds,
            stream: Succeeds,
        },
        Case {
            name: "NUL byte in a row",
            file: "nul.csv",
            bytes: with_bad_row("0.01,\u{0}0.001,0"),
            extra: &[],
            expect: Fails(&["{file}", "line 12", "NUL byte"]),
            stream: Reports(&["line 12:", "NUL byte", "skipped lines 1"]),
        },
        Case {
            name: "zeros from the first byte (/dev/zero)",
            file: "zero.csv",
            bytes: vec![0u8; 4 << 20],
            extra: &[],
            expect: Fails(&["{file}", "line 1", "NUL byte at byte 1"]),
            stream: Fails(&["no usable line"]),
        },
        Case {
            name: "two columns named position_m",
            file: "twice.csv",
            bytes: format!(
                "time_s,command_m,position_m,position_m\n{}",
                good.lines().map(|l| format!("{l},0\n")).collect::<String>()
            )
            .into_bytes(),
            extra: &[],
            expect: Fails(&[
                "{file}",
                "line 1",
                "position column `position_m` is ambiguous",
                "3, 4",
            ]),
            stream: Fails(&["position column `position_m` is ambiguous", "3, 4"]),
        },
        Case {
            name: "dead encoder (position never changes)",
            file: "dead.csv",
            bytes: csv(&rows(60, 0.0, 1e-3, 1.0)
                .lines()
                .map(|l| {
                    let f: Vec<&str> = l.split(',').collect();
                    format!("{},{},0\n", f[0], f[1])
                })
                .collect::<String>()),
            extra: &[],
            expect: Reports(&["never changes", "dead encoder"]),
            // the same plausibility checks as a file's, on the stream's start
            stream: Reports(&["never changes", "dead encoder"]),
        },
        Case {
            name: "encoder stops counting mid-move",
            file: "frozen.csv",
            bytes: csv(&frozen_mid_move()),
            extra: &[],
            expect: Reports(&["stays at", "dead encoder"]),
            stream: Succeeds,
        },
        Case {
            name: "position in mm, command in m",
            file: "mixed_units.csv",
            bytes: csv(&scaled_columns(1.0, 1e3, 1.0)),
            extra: &[],
            expect: Reports(&["10^3", "different units"]),
            stream: Reports(&["10^3", "different units"]),
        },
        Case {
            name: "lengths in mm read as metres",
            file: "mm_as_m.csv",
            bytes: csv(&scaled_columns(1e3, 1e3, 1.0)),
            extra: &[],
            expect: Reports(&["m/s", "--unit mm"]),
            stream: Succeeds,
        },
        Case {
            name: "time in ms read as seconds",
            file: "ms_as_s.csv",
            bytes: csv(&scaled_columns(1.0, 1.0, 1e3)),
            extra: &[],
            expect: Reports(&["lags the command", "--time-unit ms"]),
            stream: Succeeds,
        },
        Case {
            name: "text named .mat",
            file: "text.mat",
            bytes: csv(&good),
            extra: MAT_VARS,
            expect: Fails(&["{file}", "not a MATLAB"]),
            stream: Succeeds,
        },
    ]
}

/// Overrides of a row's expectation for one command.
fn expectation(case: &Case, cmd: Cmd) -> Expect {
    use Expect::*;
    match (case.name, cmd) {
        (_, Cmd::Stream) => case.stream,
        ("window longer than the data", Cmd::Identify) => {
            Fails(&["too few samples", "need at least", "got 12"])
        }
        ("window longer than the data", Cmd::Order) => Fails(&["too few samples", "got 12"]),
        ("window longer than the data", Cmd::Report | Cmd::Sweep) => {
            Fails(&["too few samples", "got 12"])
        }
        // nothing moves: Kv cannot be told from the data, and the tool says so
        ("constant signals", Cmd::Greybox) => Fails(&["{file}", "not identifiable", "Kv"]),
        // nothing moves: the warning, then no regression to solve
        ("constant signals", Cmd::Order) => Fails(&["{file}", "singular"]),
        // at 1 Hz the rig's dynamics are invisible: Kv cannot be told (after the warning)
        ("time in ms read as seconds", Cmd::Greybox) => Fails(&["{file}", "not identifiable"]),
        // a position that never changes has no output energy to select terms by
        ("dead encoder (position never changes)", Cmd::Order) => Fails(&["{file}", "singular"]),
        _ => case.expect,
    }
}

/// Run `feedid args`, with `stdin` piped in.
fn run(args: &[String], stdin: Option<&[u8]>) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_feedid"))
        .args(args)
        .stdin(if stdin.is_some() {
            Stdio::piped()
        } else {
            Stdio::null()
        })
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    if let Some(bytes) = stdin {
        let mut pipe = child.stdin.take().unwrap();
        let bytes = bytes.to_vec();
        // write from a thread: the child may exit (or block on stdout) early
        std::thread::spawn(move || {
            let _ = pipe.write_all(&bytes);
        });
    }
    child.wait_with_output().unwrap()
}

/// JSON fields that are `null` when absent (optional values), not when non-finite.
const OPTIONAL_FIELDS: [&str; 5] = [
    "bandwidth_hz",
    "validation_loss",
    "sim_rms_error_m",
    "sim_max_abs_error_m",
    "nominal_fit_percent",
];

/// The first token of `text` that is not a finite number but looks like one
/// (`NaN`, `inf`, JSON `null` — serde's NaN —, an overflowing literal), if any.
fn non_finite_token(text: &str) -> Option<String> {
    let mut text = text.to_string();
    for f in OPTIONAL_FIELDS {
        text = text.replace(&format!("\"{f}\": null"), "");
    }
    let seps =
        |c: char| c == ',' || c == ':' || c == ';' || c.is_whitespace() || "[]{}()".contains(c);
    for tok in text.split(seps) {
        let tok = tok.trim_matches('"');
        let lower = tok.to_ascii_lowercase();
        let named = matches!(
            lower.trim_start_matches(['-', '+']),
            "nan" | "inf" | "infinity" | "null"
        );
        if named || tok.parse::<f64>().is_ok_and(|v| !v.is_finite()) {
            return Some(tok.to_string());
        }
    }
    None
}

/// Check the outcome of one run against `expect`; `dir` holds the outputs.
fn check(o: &Output, expect: Expect, file: &str, dir: &Path) -> Result<(), String> {
    let err = stderr(o);
    if err.contains("panicked") || o.status.code() == Some(101) {
        return Err(format!("panic\n{err}"));
    }
    let outputs: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    let fails = |needles: &[&str]| -> Result<(), String> {
        if o.status.code() != Some(2) {
            return Err(format!(
                "exit code {:?}, expected 2\n{err}",
                o.status.code()
            ));
        }
        let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("error:")).collect();
        if lines.len() != 1 {
            return Err(format!("one error line expected\n{err}"));
        }
        if lines[0].len() > 400 {
            return Err(format!("error line of {} bytes", lines[0].len()));
        }
        for n in needles {
            let n = n.replace("{file}", file);
            if !lines[0].contains(&n) {
                return Err(format!("`{n}` not in\n{err}"));
            }
        }
        if !outputs.is_empty() {
            return Err(format!("output left behind: {outputs:?}"));
        }
        Ok(())
    };
    let succeeds = || -> Result<(), String> {
        if o.status.code() != Some(0) {
            return Err(format!(
                "exit code {:?}, expected 0\n{err}",
                o.status.code()
            ));
        }
        if let Some(t) = non_finite_token(&common::stdout(o)) {
            return Err(format!("non-finite `{t}` on stdout\n{}", common::stdout(o)));
        }
        for p in &outputs {
            let text = std::fs::read_to_string(p).unwrap();
            if let Some(t) = non_finite_token(&text) {
                return Err(format!("non-finite `{t}` in {}", p.display()));
            }
        }
        Ok(())
    };
    match expect {
        Expect::Fails(needles) => fails(needles),
        Expect::Succeeds => succeeds(),
        Expect::SucceedsOrFails(needles) => {
            if o.status.success() {
                succeeds()
            } else {
                fails(needles)
            }
        }
        Expect::Reports(needles) => {
            succeeds()?;
            if let Some(l) = err.lines().find(|l| l.len() > 400) {
                return Err(format!("a report line of {} bytes", l.len()));
            }
            match needles.iter().find(|n| !err.contains(*n)) {
                Some(n) => Err(format!("`{n}` not reported in\n{err}")),
                None => Ok(()),
            }
        }
    }
}

#[test]
fn non_finite_tokens_are_found() {
    assert_eq!(non_finite_token("a,1.5,-2e-3\n{\"x\": 3}"), None);
    assert_eq!(non_finite_token("{\"validation_loss\": null}"), None);
    for bad in [
        "1,NaN",
        "x: -inf",
        "{\"rms\": null}",
        "[1e999]",
        "+Infinity",
    ] {
        assert!(non_finite_token(bad).is_some(), "{bad}");
    }
}

#[test]
fn every_bad_recording_fails_cleanly_in_every_command() {
    let tmp = tempfile::tempdir().unwrap();
    let mut failures = Vec::new();
    for case in catalogue() {
        let input_dir = tmp.path().join(case.name.replace(' ', "_"));
        std::fs::create_dir_all(&input_dir).unwrap();
        let input = input_dir.join(case.file);
        std::fs::write(&input, &case.bytes).unwrap();
        for cmd in RECORDING_COMMANDS {
            let out = tmp.path().join("out");
            std::fs::create_dir_all(&out).unwrap();
            let mut args = cmd.args(&input, &out);
            let stdin = if cmd == Cmd::Stream {
                Some(case.bytes.as_slice())
            } else {
                args.extend(case.extra.iter().map(|s| s.to_string()));
                None
            };
            let o = run(&args, stdin);
            if let Err(e) = check(&o, expectation(&case, cmd), case.file, &out) {
                failures.push(format!("{} / {cmd:?}: {e}", case.name));
            }
            std::fs::remove_dir_all(&out).unwrap();
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

/// A command that reads a TOML file given by `--params` or `--effects`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum TomlCmd {
    Model,
    ModelJson,
    SimulateParams,
    SimulateEffects,
    IdentifyParams,
    GreyboxParams,
    ReportParams,
    /// Only for files that fail: a reproduce run takes seconds.
    ReproduceParams,
}

/// Which of the TOML files a command reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum TomlKind {
    Params,
    Effects,
}

impl TomlCmd {
    const ALL: [TomlCmd; 8] = [
        TomlCmd::Model,
        TomlCmd::ModelJson,
        TomlCmd::SimulateParams,
        TomlCmd::SimulateEffects,
        TomlCmd::IdentifyParams,
        TomlCmd::GreyboxParams,
        TomlCmd::ReportParams,
        TomlCmd::ReproduceParams,
    ];

    fn kind(self) -> TomlKind {
        match self {
            TomlCmd::SimulateEffects => TomlKind::Effects,
            _ => TomlKind::Params,
        }
    }

    fn args(self, toml: &Path, out: &Path) -> Vec<String> {
        let t = toml.display().to_string();
        let o = |name: &str| out.join(name).display().to_string();
        let v = |a: &[&str]| a.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        let sim = |flag: &str| {
            let mut a = v(&["simulate", "--scenario", "step", "--duration", "0.02"]);
            a.extend([flag.to_string(), t.clone(), "-o".into(), o("sim.csv")]);
            a
        };
        match self {
            TomlCmd::Model => v(&["model", "--params", &t]),
            TomlCmd::ModelJson => v(&["model", "--json", "--params", &t]),
            TomlCmd::SimulateParams => sim("--params"),
            TomlCmd::SimulateEffects => sim("--effects"),
            TomlCmd::IdentifyParams => {
                let input = common::data("comma_header.csv").display().to_string();
                let mut a = v(&["identify", &input, "--window", "8", "--horizon", "2"]);
                a.extend(["--params".into(), t, "-o".into(), o("pred.csv")]);
                a.extend(["--summary".into(), o("summary.json")]);
                a
            }
            TomlCmd::GreyboxParams => {
                let input = common::data("comma_header.csv").display().to_string();
                let mut a = v(&[
                    "greybox",
                    &input,
                    "--estimate",
                    "Kv",
                    "--max-iterations",
                    "3",
                ]);
                a.extend(["--params".into(), t, "--summary".into(), o("gb.json")]);
                a
            }
            TomlCmd::ReportParams => {
                let input = common::data("comma_header.csv").display().to_string();
                let mut a = v(&["report", &input, "--methods", "paper", "--window", "8"]);
                a.extend(["--horizon".into(), "2".into(), "--params".into(), t]);
                a.extend(["-o".into(), o("report.html")]);
                a
            }
            TomlCmd::ReproduceParams => v(&["reproduce", "--params", &t, "--out", &o("repro")]),
        }
    }
}

/// One TOML row: the file's text (or bytes) and what every command that reads
/// such a file (`kind`) must do with it.
struct TomlCase {
    name: &'static str,
    kind: TomlKind,
    bytes: Vec<u8>,
    expect: Expect,
}

fn toml_catalogue() -> Vec<TomlCase> {
    use Expect::*;
    use TomlKind::*;
    let case = |name, kind, text: &str, expect| TomlCase {
        name,
        kind,
        bytes: text.as_bytes().to_vec(),
        expect,
    };
    vec![
        case("empty (all defaults)", Params, "", Succeeds),
        case(
            "unknown key",
            Params,
            "[control]\nkvv = 3.0\n",
            Fails(&["{file}", "kvv", "line 2"]),
        ),
        case(
            "unknown table",
            Params,
            "[controller]\nkv = 3.0\n",
            Fails(&["{file}", "controller"]),
        ),
        case(
            "wrong type",
            Params,
            "[table]\nmass = \"heavy\"\n",
            Fails(&["{file}", "line 2", "heavy", "expected f64"]),
        ),
        case(
            "table where a value belongs",
            Params,
            "control = 3\n",
            Fails(&["{file}", "line 1", "control"]),
        ),
        case(
            "negative mass",
            Params,
            "[table]\nmass = -3.0\n",
            Fails(&["{file}", "table.mass", "-3", "> 0"]),
        ),
        case(
            "NaN gain",
            Params,
            "[control]\nkv = nan\n",
            Fails(&["{file}", "control.kv", "NaN"]),
        ),
        case(
            "infinite stiffness",
            Params,
            "[stiffness]\nbearing = inf\n",
            Fails(&["{file}", "stiffness.bearing", "inf"]),
        ),
        case(
            "syntax error",
            Params,
            "[control\nkv = 3\n",
            Fails(&["{file}", "line 1"]),
        ),
        case(
            "root diameter above the screw diameter",
            Params,
            "[geometry]\nroot_diameter = 1.0\n",
            Fails(&["{file}", "geometry.root_diameter"]),
        ),
        case(
            "values that overflow together (found by fuzzing)",
            Params,
            "[geometry]\nscrew_diameter = 2.2e104\n",
            Fails(&["{file}", "inertia J", "inf"]),
        ),
        TomlCase {
            name: "invalid UTF-8",
            kind: Params,
            bytes: b"[control]\nkv = 3\xff\n".to_vec(),
            expect: Fails(&["{file}", "UTF-8"]),
        },
        // legal but extreme values: a finite answer or a reason naming the file
        case(
            "huge mass (1e300)",
            Params,
            "[table]\nmass = 1e300\n",
            SucceedsOrFails(&["{file}"]),
        ),
        case(
            "tiny mass (1e-300)",
            Params,
            "[table]\nmass = 1e-300\n",
            SucceedsOrFails(&["{file}"]),
        ),
        case(
            "tiny gain (1e-300)",
            Params,
            "[control]\nkv = 1e-300\n",
            SucceedsOrFails(&["{file}"]),
        ),
        case(
            "huge damping (1e300)",
            Params,
            "[damping]\nc1 = 1e300\n",
            SucceedsOrFails(&["{file}"]),
        ),
        case(
            "huge torque constant (1e200)",
            Params,
            "[motor]\nkt = 1e200\n",
            SucceedsOrFails(&["{file}"]),
        ),
        case("effects: empty (all on)", Effects, "", Succeeds),
        case(
            "effects: unknown key",
            Effects,
            "frictions = false\n",
            Fails(&["{file}", "frictions"]),
        ),
        case(
            "effects: wrong type",
            Effects,
            "friction = 3\n",
            Fails(&["{file}", "friction"]),
        ),
        case(
            "effects: negative noise",
            Effects,
            "noise_std = -1e-6\n",
            Fails(&["noise_std"]),
        ),
        case(
            "effects: zero current limit",
            Effects,
            "current_limit = 0.0\n",
            Fails(&["current_limit"]),
        ),
    ]
}

#[test]
fn every_bad_parameter_file_fails_cleanly_in_every_command() {
    let tmp = tempfile::tempdir().unwrap();
    let mut failures = Vec::new();
    for (i, case) in toml_catalogue().into_iter().enumerate() {
        let toml = tmp.path().join(format!("case{i}.toml"));
        std::fs::write(&toml, &case.bytes).unwrap();
        let file = toml.file_name().unwrap().to_str().unwrap().to_string();
        for cmd in TomlCmd::ALL {
            let slow = cmd == TomlCmd::ReproduceParams && !matches!(case.expect, Expect::Fails(_));
            if cmd.kind() != case.kind || slow {
                continue;
            }
            let out = tmp.path().join("out");
            std::fs::create_dir_all(&out).unwrap();
            let o = run(&cmd.args(&toml, &out), None);
            // extreme but valid parameters: those whose model is usable reach
            // greybox's fit, which finds that the data cannot identify Kv
            // under a vanishing gain, and says so naming the recording
            let expect = match (cmd, case.expect) {
                (TomlCmd::GreyboxParams, Expect::SucceedsOrFails(_))
                    if case.name.starts_with("tiny gain") =>
                {
                    Expect::SucceedsOrFails(&["not identifiable", "Kv"])
                }
                (_, e) => e,
            };
            if let Err(e) = check(&o, expect, &file, &out) {
                failures.push(format!("{} / {cmd:?}: {e}", case.name));
            }
            std::fs::remove_dir_all(&out).unwrap();
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

/// One row of the argument catalogue: a command line with placeholders —
/// `{out}` the output directory (must stay empty on failure), `{plain}` a
/// regular file (so `{plain}/x` can be neither written nor created, even by
/// root), `{good}` a good recording — and what it must do. `stream` reads
/// the good recording on standard input.
struct ArgCase {
    name: &'static str,
    args: &'static [&'static str],
    expect: Expect,
}

fn arg_catalogue() -> Vec<ArgCase> {
    use Expect::*;
    let case = |name, args, expect| ArgCase { name, args, expect };
    const MAX: &str = "18446744073709551615";
    vec![
        // unwritable outputs: a reason naming the path, nothing left behind
        case(
            "identify: predictions into a file's subdirectory",
            &["identify", "{good}", "-o", "{plain}/p.csv"],
            Fails(&["{plain}/p.csv"]),
        ),
        case(
            "identify: unwritable coefficients after the predictions",
            &[
                "identify",
                "{good}",
                "-o",
                "{out}/p.csv",
                "--coefficients",
                "{plain}/c.csv",
            ],
            Fails(&["{plain}/c.csv"]),
        ),
        case(
            "identify: unwritable summary after two outputs",
            &[
                "identify",
                "{good}",
                "-o",
                "{out}/p.csv",
                "--coefficients",
                "{out}/c.csv",
                "--summary",
                "{plain}/s.json",
            ],
            Fails(&["{plain}/s.json"]),
        ),
        case(
            "identify: output path is a directory",
            &["identify", "{good}", "-o", "{out}"],
            Fails(&["{out}"]),
        ),
        case(
            "identify: --out-dir is a file",
            &["identify", "{good}", "--out-dir", "{plain}"],
            Fails(&["{plain}"]),
        ),
        case(
            "identify: predictions over the input",
            &["identify", "{good}", "-o", "{good}"],
            Fails(&["{good}", "overwrite the input"]),
        ),
        case(
            "identify: predictions over the input by another path",
            &["identify", "{good}", "-o", "{out}/../good.csv"],
            Fails(&["overwrite the input"]),
        ),
        case(
            "identify: summary and predictions to one file",
            &[
                "identify",
                "{good}",
                "-o",
                "{out}/p.csv",
                "--summary",
                "{out}/p.csv",
            ],
            Fails(&["{out}/p.csv", "two outputs"]),
        ),
        case(
            "identify: two inputs of the same name into one --out-dir",
            &[
                "identify",
                "{good}",
                "{out}/../sub/good.csv",
                "--out-dir",
                "{out}/batch",
            ],
            Fails(&["would both write", "good.*"]),
        ),
        case(
            "simulate: output into a file's subdirectory",
            &[
                "simulate",
                "--scenario",
                "step",
                "--duration",
                "0.02",
                "-o",
                "{plain}/s.csv",
            ],
            Fails(&["{plain}/s.csv"]),
        ),
        case(
            "model: parameters saved into a file's subdirectory",
            &["model", "--save-params", "{plain}/rig.toml"],
            Fails(&["{plain}/rig.toml"]),
        ),
        case(
            "reproduce: output directory below a file",
            &["reproduce", "--out", "{plain}/figures"],
            Fails(&["{plain}/figures"]),
        ),
        // numbers a user can type
        case(
            "identify: window 2^64-1",
            &["identify", "{good}", "-o", "{out}/p.csv", "--window", MAX],
            Fails(&["too few samples", MAX]),
        ),
        case(
            "identify: horizon 2^64-1",
            &[
                "identify",
                "{good}",
                "-o",
                "{out}/p.csv",
                "--window",
                "5",
                "--horizon",
                MAX,
            ],
            Fails(&["too few samples"]),
        ),
        case(
            "identify: hop 2^64-1 with a warm-up (arx)",
            &[
                "identify",
                "{good}",
                "-o",
                "{out}/p.csv",
                "--method",
                "arx",
                "--order",
                "2,2,1",
                "--window",
                "10",
                "--horizon",
                "2",
                "--hop",
                MAX,
            ],
            Succeeds,
        ),
        case(
            "identify: zero window",
            &["identify", "{good}", "-o", "{out}/p.csv", "--window", "0"],
            Fails(&["window", "at least 1"]),
        ),
        case(
            "identify: delay 2^64-1",
            &[
                "identify",
                "{good}",
                "-o",
                "{out}/p.csv",
                "--method",
                "arx",
                "--order",
                "1,1,18446744073709551615",
            ],
            Fails(&["nk"]),
        ),
        case(
            "identify: forgetting factor NaN",
            &[
                "identify",
                "{good}",
                "-o",
                "{out}/p.csv",
                "--method",
                "rls",
                "--lambda",
                "NaN",
            ],
            Fails(&["lambda", "NaN"]),
        ),
        case(
            "info: sampling rate 0 without a time column",
            &["info", "{good}", "--rate", "0"],
            Fails(&["rate", "0"]),
        ),
        case(
            "info: sampling rate 1e-300 (times beyond range)",
            &[
                "info",
                "{good}",
                "--rate",
                "1e-300",
                "--command",
                "2",
                "--position",
                "3",
            ],
            Fails(&["beyond"]),
        ),
        case(
            "info: scale 1e308 (values beyond range)",
            &["info", "{good}", "--scale", "1e308"],
            Fails(&["command_m", "beyond", "scale"]),
        ),
        case(
            "info: jitter tolerance NaN",
            &["info", "{good}", "--jitter-tol", "NaN"],
            Fails(&["jitter", "NaN"]),
        ),
        case(
            "order: grid beyond the largest order",
            &["order", "{good}", "--na", "0..100000"],
            Fails(&["na", "100000"]),
        ),
        case(
            "order: validation fraction NaN",
            &["order", "{good}", "--validation", "NaN"],
            Fails(&["validation", "NaN"]),
        ),
        case(
            "simulate: duration 1e300",
            &[
                "simulate",
                "--scenario",
                "ramp",
                "--duration",
                "1e300",
                "-o",
                "{out}/s.csv",
            ],
            Fails(&["duration", "1e300"]),
        ),
        case(
            "simulate: multisine at 1 GHz",
            &[
                "simulate",
                "--scenario",
                "multisine",
                "--rate",
                "1e9",
                "--duration",
                "1e-6",
                "-o",
                "{out}/s.csv",
            ],
            Fails(&["rate", "multisine"]),
        ),
        case(
            "simulate: rate NaN",
            &[
                "simulate",
                "--scenario",
                "ramp",
                "--rate",
                "NaN",
                "-o",
                "{out}/s.csv",
            ],
            Fails(&["rate", "NaN"]),
        ),
        case(
            "stream: window 2^64-1",
            &["stream", "--window", MAX],
            Fails(&["18446744073709551615", "more than the", "it may keep"]),
        ),
        case(
            "stream: rate -1",
            &["stream", "--rate=-1"],
            Fails(&["rate", "-1"]),
        ),
    ]
}

#[test]
fn every_bad_argument_and_unwritable_output_fails_cleanly() {
    let tmp = tempfile::tempdir().unwrap();
    let plain = tmp.path().join("plain");
    std::fs::write(&plain, "a regular file\n").unwrap();
    let good = tmp.path().join("good.csv");
    let good_bytes = csv(&rows(200, 0.0, 1e-3, 1.0));
    std::fs::write(&good, &good_bytes).unwrap();
    let out = tmp.path().join("out");
    let mut failures = Vec::new();
    for case in arg_catalogue() {
        std::fs::create_dir_all(&out).unwrap();
        let fill = |s: &str| {
            s.replace("{out}", out.to_str().unwrap())
                .replace("{plain}", plain.to_str().unwrap())
                .replace("{good}", good.to_str().unwrap())
        };
        let args: Vec<String> = case.args.iter().map(|a| fill(a)).collect();
        let stdin = (args[0] == "stream").then_some(good_bytes.as_slice());
        let o = run(&args, stdin);
        let expect = match case.expect {
            Expect::Fails(needles) => {
                // placeholders in needles too
                let filled: Vec<String> = needles.iter().map(|n| fill(n)).collect();
                let leaked: &'static [String] = Box::leak(filled.into_boxed_slice());
                let refs: Vec<&'static str> = leaked.iter().map(String::as_str).collect();
                Expect::Fails(Box::leak(refs.into_boxed_slice()))
            }
            e => e,
        };
        if let Err(e) = check(&o, expect, "", &out) {
            failures.push(format!("{}: {e}", case.name));
        }
        std::fs::remove_dir_all(&out).unwrap();
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

#[test]
fn a_full_disk_on_standard_output_is_an_error_not_a_panic() {
    let full = Path::new("/dev/full");
    if !full.exists() {
        eprintln!("skipped: no /dev/full");
        return;
    }
    let good = common::data("comma_header.csv").display().to_string();
    for args in [
        vec!["model"],
        vec!["model", "--json"],
        vec!["info", good.as_str()],
        vec!["order", good.as_str(), "--na", "1..2", "--nb", "1..2"],
    ] {
        let o = Command::new(env!("CARGO_BIN_EXE_feedid"))
            .args(&args)
            .stdout(std::fs::File::create(full).unwrap())
            .stderr(Stdio::piped())
            .output()
            .unwrap();
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains("error: cannot write to standard output"),
            "{args:?}: {err}"
        );
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
    }
}

#[test]
fn a_reader_that_goes_away_ends_the_output_quietly() {
    // `feedid info big.csv | head -1`: the pipe closes after the first line
    let tmp = tempfile::tempdir().unwrap();
    let wide = tmp.path().join("wide.csv");
    // a long error message to a closed standard error must not panic either
    let head: Vec<String> = (0..100_000).map(|i| format!("c{i}")).collect();
    std::fs::write(&wide, format!("{}\n1\n2\n", head.join(","))).unwrap();
    let big = tmp.path().join("big.csv");
    std::fs::write(&big, csv(&rows(20_000, 0.0, 1e-3, 1.0))).unwrap();
    for (args, code) in [
        (vec!["model".to_string()], 0),
        (vec!["info".to_string(), big.display().to_string()], 0),
        (vec!["info".to_string(), wide.display().to_string()], 2),
    ] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_feedid"))
            .args(&args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // close both pipes at once: every write fails with a broken pipe
        drop(child.stdout.take());
        drop(child.stderr.take());
        let status = child.wait().unwrap();
        assert_eq!(status.code(), Some(code), "{args:?}");
    }
}

#[test]
fn paper_method_far_from_the_time_origin_warns_and_stays_finite() {
    // 2 s with the motion from 10 ms on: late windows lie ~2 s after the
    // motion start, 200 window widths (as the EMPS file's 25 s at 1 kHz)
    let tmp = tempfile::tempdir().unwrap();
    let input = tmp.path().join("late.csv");
    let mut body = String::new();
    for k in 0..2000 {
        let t = k as f64 * 1e-3;
        let move_ = |t: f64| {
            if t < 0.01 {
                0.0
            } else {
                0.01 * (1.0 - (3.0 * (t - 0.01)).cos())
            }
        };
        body += &format!("{t},{},{}\n", move_(t), move_(t - 1.4e-3));
    }
    std::fs::write(&input, csv(&body)).unwrap();
    let out = tmp.path().join("out");
    for (origin, warns) in [("motion", true), ("window", false)] {
        for solver in ["qr", "simplex"] {
            for prediction in ["polynomial", "tf"] {
                std::fs::create_dir_all(&out).unwrap();
                let mut args = Cmd::Identify.args(&input, &out);
                args.extend(
                    [
                        "--method",
                        "paper",
                        "--time-origin",
                        origin,
                        "--solver",
                        solver,
                        "--prediction",
                        prediction,
                    ]
                    .map(String::from),
                );
                let o = run(&args, None);
                let what = format!("{origin} {solver} {prediction}");
                check(&o, Expect::Succeeds, "late.csv", &out)
                    .unwrap_or_else(|e| panic!("{what}: {e}"));
                let err = stderr(&o);
                assert_eq!(
                    err.contains("warning: ") && err.contains("lose about 16"),
                    warns,
                    "{what}: {err}"
                );
                std::fs::remove_dir_all(&out).unwrap();
            }
        }
    }
}

#[test]
fn stream_skips_an_endless_line_without_holding_it() {
    // 8 MB of NUL bytes without a newline (`cat /dev/zero | feedid stream`),
    // then a good recording: the binary line is reported and skipped (read
    // to its end without being held), the rest is used
    let mut input = vec![0u8; 8 << 20];
    input.push(b'\n');
    input.extend_from_slice(&csv(&rows(60, 0.0, 1e-3, 1.0)));
    let args = Cmd::Stream.args(Path::new(""), Path::new(""));
    let o = run(&args, Some(&input));
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(
        err.contains("line 1: NUL byte at byte 1") && err.contains("; skipped"),
        "{err}"
    );
    assert!(err.contains("samples 60,"), "{err}");
    assert!(common::stdout(&o).lines().count() > 10);
    assert!(err.lines().all(|l| l.len() < 400));
}
