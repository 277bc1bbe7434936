//! Outputs that never destroy, as tables over every command that
//! writes a file:
//!
//! - [`destinations`]: what an output path names — a character device
//!   (`/dev/null`, `/dev/full`), a FIFO with a reader, standard output (`-`),
//!   a symbolic link (to a file elsewhere, or dangling), a 250-byte name —
//!   × [`WRITERS`]: it is written directly or atomically, never replaced,
//!   and nothing is left behind on failure;
//! - [`collisions`]: every way an output can name an input (the same path,
//!   another spelling, a symbolic link, a hard link) in every command;
//! - signals (SIGINT, SIGTERM, SIGHUP) while a set of outputs is being
//!   written, a file-size limit, and a failing member of a set.

use std::io::Read;
use std::os::unix::fs::FileTypeExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use super::{csv, rows, run};
use crate::common::stderr;

/// A command that writes one output given as `{o}` (other inputs prepared in `dir`).
struct Writer {
    name: &'static str,
    args: &'static [&'static str],
}

/// Every command that writes a file, each with one output `{o}`; `{good}`
/// is a recording, `{des}` a desired trajectory, `{rig}` a parameter file.
const WRITERS: [Writer; 10] = [
    Writer {
        name: "simulate",
        args: &[
            "simulate",
            "--scenario",
            "step",
            "--duration",
            "0.02",
            "-o",
            "{o}",
        ],
    },
    Writer {
        name: "identify predictions",
        args: &[
            "identify", "{good}", "--method", "arx", "--order", "2,2,1", "--window", "40", "-o",
            "{o}",
        ],
    },
    Writer {
        name: "identify summary",
        args: &[
            "identify",
            "{good}",
            "--method",
            "arx",
            "--order",
            "2,2,1",
            "--window",
            "40",
            "-o",
            "/dev/null",
            "--summary",
            "{o}",
        ],
    },
    Writer {
        name: "report",
        args: &[
            "report",
            "{good}",
            "--methods",
            "arx",
            "--order",
            "2,2,1",
            "--window",
            "40",
            "-o",
            "{o}",
        ],
    },
    Writer {
        name: "sweep",
        args: &[
            "sweep",
            "{good}",
            "--windows",
            "20,40",
            "--methods",
            "arx",
            "--orders",
            "2,2,1",
            "-o",
            "{o}",
        ],
    },
    Writer {
        name: "sweep plot",
        args: &[
            "sweep",
            "{good}",
            "--windows",
            "20,40",
            "--methods",
            "arx",
            "--orders",
            "2,2,1",
            "-o",
            "/dev/null",
            "--plot",
            "{o}",
        ],
    },
    Writer {
        name: "compensate",
        args: &[
            "compensate",
            "--desired",
            "{des}",
            "--params",
            "{rig}",
            "-o",
            "{o}",
        ],
    },
    Writer {
        name: "greybox summary",
        args: &[
            "greybox",
            "{good}",
            "--estimate",
            "Kv",
            "--max-iterations",
            "3",
            "--restarts",
            "0",
            "--allow-unidentifiable",
            "--summary",
            "{o}",
        ],
    },
    Writer {
        name: "greybox params",
        args: &[
            "greybox",
            "{good}",
            "--estimate",
            "Kv",
            "--max-iterations",
            "3",
            "--restarts",
            "0",
            "--allow-unidentifiable",
            "--params-out",
            "{o}",
        ],
    },
    Writer {
        name: "model template",
        args: &["model", "--save-params", "{o}"],
    },
];

/// Inputs every writer needs, in `dir`.
struct Inputs {
    good: PathBuf,
    des: PathBuf,
    rig: PathBuf,
}

fn inputs(dir: &Path) -> Inputs {
    let good = dir.join("good.csv");
    std::fs::write(&good, csv(&rows(300, 0.0, 1e-3, 1.0))).unwrap();
    let des = dir.join("des.csv");
    let mut d = String::from("time_s,position_m\n");
    for k in 0..400 {
        let t = k as f64 * 2e-4;
        // 0.1 mm in 40 ms, at rest before and after
        let x = ((t - 0.02) / 0.04).clamp(0.0, 1.0);
        d += &format!(
            "{t},{}\n",
            0.5e-4 * (1.0 - (std::f64::consts::PI * x).cos())
        );
    }
    std::fs::write(&des, d).unwrap();
    let rig = dir.join("rig.toml");
    std::fs::write(&rig, "[table]\nmass = 3.0\n").unwrap();
    Inputs { good, des, rig }
}

fn args(w: &Writer, inp: &Inputs, out: &str) -> Vec<String> {
    w.args
        .iter()
        .map(|a| {
            a.replace("{o}", out)
                .replace("{good}", inp.good.to_str().unwrap())
                .replace("{des}", inp.des.to_str().unwrap())
                .replace("{rig}", inp.rig.to_str().unwrap())
        })
        .collect()
}

/// Files in `dir` whose name marks them temporary (`.fd….tmp`).
fn temporaries(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".fd") && n.ends_with(".tmp"))
        .collect()
}

fn is_char_device(p: &Path) -> bool {
    std::fs::metadata(p).is_ok_and(|m| m.file_type().is_char_device())
}

/// What an output path is made to name before the command runs.
#[derive(Debug, Clone, Copy)]
enum Dest {
    DevNull,
    DevFull,
    Stdout,
    Fifo,
    Symlink,
    DanglingSymlink,
    LongName,
}

const DESTS: [Dest; 7] = [
    Dest::DevNull,
    Dest::DevFull,
    Dest::Stdout,
    Dest::Fifo,
    Dest::Symlink,
    Dest::DanglingSymlink,
    Dest::LongName,
];

#[test]
fn destinations_are_written_never_replaced_in_every_command() {
    if !Path::new("/dev/null").exists() || !Path::new("/dev/full").exists() {
        eprintln!("skipped: no /dev/null or /dev/full");
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let inp = inputs(tmp.path());
    let mut failures = Vec::new();
    for w in &WRITERS {
        for dest in DESTS {
            let dir = tmp.path().join("out");
            std::fs::create_dir_all(&dir).unwrap();
            let other = tmp.path().join("elsewhere");
            std::fs::create_dir_all(&other).unwrap();
            let what = format!("{} → {dest:?}", w.name);
            let res = (|| -> Result<(), String> {
                match dest {
                    Dest::DevNull | Dest::DevFull => {
                        let dev = if matches!(dest, Dest::DevNull) {
                            "/dev/null"
                        } else {
                            "/dev/full"
                        };
                        let o = run(&args(w, &inp, dev), None);
                        let ok = matches!(dest, Dest::DevNull);
                        if o.status.success() != ok {
                            return Err(format!("exit {:?}\n{}", o.status.code(), stderr(&o)));
                        }
                        if !ok && (o.status.code() != Some(2) || !stderr(&o).contains("/dev/full"))
                        {
                            return Err(format!("no error naming /dev/full\n{}", stderr(&o)));
                        }
                        if !is_char_device(Path::new(dev)) {
                            return Err(format!("{dev} is no longer a device"));
                        }
                    }
                    Dest::Stdout => {
                        let o = run(&args(w, &inp, "-"), None);
                        if !o.status.success() || o.stdout.len() < 10 {
                            return Err(format!("stdout {} bytes\n{}", o.stdout.len(), stderr(&o)));
                        }
                        if dir.join("-").exists() || tmp.path().join("-").exists() {
                            return Err("a file named `-` was written".into());
                        }
                    }
                    Dest::Fifo => {
                        let fifo = dir.join("pipe");
                        let st = Command::new("mkfifo").arg(&fifo).status();
                        if !st.is_ok_and(|s| s.success()) {
                            return Ok(()); // no mkfifo: nothing to test
                        }
                        let reader = {
                            let fifo = fifo.clone();
                            std::thread::spawn(move || {
                                let mut got = Vec::new();
                                std::fs::File::open(fifo)
                                    .unwrap()
                                    .read_to_end(&mut got)
                                    .unwrap();
                                got.len()
                            })
                        };
                        let o = run(&args(w, &inp, fifo.to_str().unwrap()), None);
                        // a command that failed before opening the FIFO leaves the
                        // reader waiting: a non-blocking open for writing releases it
                        {
                            use std::os::unix::fs::OpenOptionsExt;
                            let _ = std::fs::OpenOptions::new()
                                .write(true)
                                .custom_flags(0o4000) // O_NONBLOCK
                                .open(&fifo);
                        }
                        let got = reader.join().unwrap();
                        if !o.status.success() || got < 10 {
                            return Err(format!("reader got {got} bytes\n{}", stderr(&o)));
                        }
                        let ft = std::fs::symlink_metadata(&fifo).unwrap().file_type();
                        if !ft.is_fifo() {
                            return Err("the FIFO was replaced".into());
                        }
                        std::fs::remove_file(&fifo).unwrap();
                    }
                    Dest::Symlink | Dest::DanglingSymlink => {
                        let target = other.join("target.out");
                        if matches!(dest, Dest::Symlink) {
                            std::fs::write(&target, "old").unwrap();
                        }
                        let link = dir.join("link.out");
                        std::os::unix::fs::symlink(&target, &link).unwrap();
                        let o = run(&args(w, &inp, link.to_str().unwrap()), None);
                        if !o.status.success() {
                            return Err(stderr(&o));
                        }
                        if !std::fs::symlink_metadata(&link)
                            .unwrap()
                            .file_type()
                            .is_symlink()
                        {
                            return Err("the link was replaced by a file".into());
                        }
                        let text = std::fs::read(&target).unwrap();
                        if text == b"old" || text.len() < 10 {
                            return Err("the link's target was not written".into());
                        }
                        std::fs::remove_file(&link).unwrap();
                        std::fs::remove_file(&target).unwrap();
                    }
                    Dest::LongName => {
                        let name = format!("{}.out", "n".repeat(246));
                        assert_eq!(name.len(), 250);
                        let p = dir.join(&name);
                        let o = run(&args(w, &inp, p.to_str().unwrap()), None);
                        if !o.status.success() || !p.exists() {
                            return Err(stderr(&o));
                        }
                        std::fs::remove_file(&p).unwrap();
                    }
                }
                let left = temporaries(&dir);
                if !left.is_empty() {
                    return Err(format!("temporary files left: {left:?}"));
                }
                Ok(())
            })();
            if let Err(e) = res {
                failures.push(format!("{what}: {e}"));
            }
            std::fs::remove_dir_all(&dir).unwrap();
            std::fs::remove_dir_all(&other).unwrap();
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

/// How an output is made to name an input.
#[derive(Debug, Clone, Copy)]
enum Alias {
    Same,
    OtherSpelling,
    Symlink,
    HardLink,
}

/// Command lines with `{in}` (an input) and `{alias}` (an output naming it);
/// every one must be refused, the input untouched.
const COLLISIONS: &[(&str, &[&str])] = &[
    ("identify -o", &["identify", "{in:good}", "-o", "{alias}"]),
    (
        "identify --coefficients",
        &[
            "identify",
            "{in:good}",
            "-o",
            "/dev/null",
            "--coefficients",
            "{alias}",
        ],
    ),
    (
        "identify --summary",
        &[
            "identify",
            "{in:good}",
            "-o",
            "/dev/null",
            "--summary",
            "{alias}",
        ],
    ),
    (
        "identify --model-out over --params",
        &[
            "identify",
            "{good}",
            "--params",
            "{in:rig}",
            "-o",
            "/dev/null",
            "--model-out",
            "{alias}",
        ],
    ),
    (
        "report -o",
        &["report", "{in:good}", "--methods", "arx", "-o", "{alias}"],
    ),
    ("sweep -o", &["sweep", "{in:good}", "-o", "{alias}"]),
    (
        "sweep --plot",
        &["sweep", "{in:good}", "-o", "/dev/null", "--plot", "{alias}"],
    ),
    (
        "simulate -o over --params",
        &[
            "simulate",
            "--scenario",
            "step",
            "--params",
            "{in:rig}",
            "-o",
            "{alias}",
        ],
    ),
    (
        "model --save-params over --params",
        &["model", "--params", "{in:rig}", "--save-params", "{alias}"],
    ),
    (
        "compensate -o over --desired",
        &[
            "compensate",
            "--desired",
            "{in:des}",
            "--params",
            "{rig}",
            "-o",
            "{alias}",
        ],
    ),
    (
        "compensate --summary over --params",
        &[
            "compensate",
            "--desired",
            "{des}",
            "--params",
            "{in:rig}",
            "-o",
            "/dev/null",
            "--summary",
            "{alias}",
        ],
    ),
    (
        "greybox --params-out over --params",
        &[
            "greybox",
            "{good}",
            "--estimate",
            "Kv",
            "--params",
            "{in:rig}",
            "--params-out",
            "{alias}",
        ],
    ),
    (
        "greybox --summary over the recording",
        &[
            "greybox",
            "{in:good}",
            "--estimate",
            "Kv",
            "--summary",
            "{alias}",
        ],
    ),
    (
        "greybox --track-out over the recording",
        &[
            "greybox",
            "{in:good}",
            "--estimate",
            "Kv",
            "--track-window",
            "0.1",
            "--track-out",
            "{alias}",
        ],
    ),
];

#[test]
fn every_output_over_an_input_is_refused_in_every_command_by_any_path() {
    let tmp = tempfile::tempdir().unwrap();
    let mut failures = Vec::new();
    for (name, line) in COLLISIONS {
        for alias in [
            Alias::Same,
            Alias::OtherSpelling,
            Alias::Symlink,
            Alias::HardLink,
        ] {
            let dir = tmp.path().join("case");
            std::fs::create_dir_all(dir.join("sub")).unwrap();
            let inp = inputs(&dir);
            let which = line
                .iter()
                .find_map(|a| a.strip_prefix("{in:").and_then(|r| r.strip_suffix('}')))
                .unwrap();
            let input = match which {
                "good" => &inp.good,
                "des" => &inp.des,
                _ => &inp.rig,
            };
            let before = std::fs::read(input).unwrap();
            let file = input.file_name().unwrap().to_str().unwrap();
            let alias_path = match alias {
                Alias::Same => input.clone(),
                Alias::OtherSpelling => dir.join("sub").join("..").join(file),
                Alias::Symlink => {
                    let l = dir.join("sub").join("link");
                    std::os::unix::fs::symlink(input, &l).unwrap();
                    l
                }
                Alias::HardLink => {
                    let l = dir.join("sub").join("hard");
                    std::fs::hard_link(input, &l).unwrap();
                    l
                }
            };
            let args: Vec<String> = line
                .iter()
                .map(|a| {
                    if a.starts_with("{in:") {
                        input.display().to_string()
                    } else {
                        a.replace("{alias}", alias_path.to_str().unwrap())
                            .replace("{good}", inp.good.to_str().unwrap())
                            .replace("{des}", inp.des.to_str().unwrap())
                            .replace("{rig}", inp.rig.to_str().unwrap())
                    }
                })
                .collect();
            let o = run(&args, None);
            let err = stderr(&o);
            let refused = o.status.code() == Some(2) && err.contains("would overwrite the input");
            if !refused {
                failures.push(format!(
                    "{name} / {alias:?}: exit {:?}\n{err}",
                    o.status.code()
                ));
            } else if std::fs::read(input).unwrap() != before {
                failures.push(format!("{name} / {alias:?}: the input changed"));
            }
            std::fs::remove_dir_all(&dir).unwrap();
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

/// Start `feedid identify` with its predictions into a FIFO nobody reads:
/// its other outputs are then complete temporary files, waiting.
fn blocked_identify(dir: &Path) -> Option<std::process::Child> {
    let good = dir.join("good.csv");
    std::fs::write(&good, csv(&rows(2000, 0.0, 1e-3, 1.0))).unwrap();
    let fifo = dir.join("pipe");
    if !Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .is_ok_and(|s| s.success())
    {
        return None;
    }
    let child = Command::new(env!("CARGO_BIN_EXE_feedid"))
        .args([
            "identify",
            good.to_str().unwrap(),
            "-o",
            fifo.to_str().unwrap(),
        ])
        .arg("--summary")
        .arg(dir.join("summary.json"))
        .arg("--coefficients")
        .arg(dir.join("coef.csv"))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    Some(child)
}

#[test]
fn a_signal_while_writing_leaves_no_temporary_file_and_no_partial_set() {
    use std::os::unix::process::ExitStatusExt;
    for (sig, num) in [("INT", 2), ("TERM", 15), ("HUP", 1)] {
        let tmp = tempfile::tempdir().unwrap();
        let Some(mut child) = blocked_identify(tmp.path()) else {
            eprintln!("skipped: no mkfifo");
            return;
        };
        // wait for the two complete temporary files
        let t0 = Instant::now();
        while temporaries(tmp.path()).len() < 2 && t0.elapsed() < Duration::from_secs(30) {
            std::thread::sleep(Duration::from_millis(20));
        }
        assert_eq!(
            temporaries(tmp.path()).len(),
            2,
            "SIG{sig}: no temporary files appeared"
        );
        let st = Command::new("kill")
            .arg(format!("-{sig}"))
            .arg(child.id().to_string())
            .status()
            .unwrap();
        assert!(st.success());
        let status = child.wait().unwrap();
        assert_eq!(status.signal(), Some(num), "SIG{sig}: {status:?}");
        assert!(
            temporaries(tmp.path()).is_empty(),
            "SIG{sig}: {:?}",
            temporaries(tmp.path())
        );
        for f in ["summary.json", "coef.csv"] {
            assert!(!tmp.path().join(f).exists(), "SIG{sig}: {f} written");
        }
    }
}

#[test]
fn a_file_size_limit_is_an_error_with_a_message_not_a_kill() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("s.csv");
    let script = format!(
        "ulimit -f 8 && exec '{}' simulate --scenario ramp -o '{}'",
        env!("CARGO_BIN_EXE_feedid"),
        out.display()
    );
    let Ok(o) = Command::new("sh").arg("-c").arg(&script).output() else {
        eprintln!("skipped: no sh");
        return;
    };
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("s.csv") && err.contains("ulimit -f"), "{err}");
    assert!(!out.exists());
    assert!(temporaries(tmp.path()).is_empty());
}

#[test]
fn a_failing_member_of_a_set_keeps_the_previous_set_whole() {
    let tmp = tempfile::tempdir().unwrap();
    let good = tmp.path().join("good.csv");
    std::fs::write(&good, csv(&rows(300, 0.0, 1e-3, 1.0))).unwrap();
    let plain = tmp.path().join("plain");
    std::fs::write(&plain, "a file, not a directory").unwrap();
    let pred = tmp.path().join("pred.csv");
    let summary = tmp.path().join("summary.json");
    std::fs::write(&pred, "old predictions").unwrap();
    std::fs::write(&summary, "old summary").unwrap();
    // the coefficients cannot be written (below a file): nothing of the new set lands
    let o = run(
        &[
            "identify".into(),
            good.display().to_string(),
            "-o".into(),
            pred.display().to_string(),
            "--coefficients".into(),
            plain.join("coef.csv").display().to_string(),
            "--summary".into(),
            summary.display().to_string(),
        ],
        None,
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert_eq!(std::fs::read_to_string(&pred).unwrap(), "old predictions");
    assert_eq!(std::fs::read_to_string(&summary).unwrap(), "old summary");
    assert!(temporaries(tmp.path()).is_empty());
}

/// `feedid args` with standard output opened on `out` for appending (as
/// the shell's `>> out`).
fn run_appending(args: &[String], out: &Path) -> std::process::Output {
    let file = std::fs::OpenOptions::new()
        .append(true)
        .create(true)
        .open(out)
        .unwrap();
    Command::new(env!("CARGO_BIN_EXE_feedid"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::from(file))
        .stderr(Stdio::piped())
        .output()
        .unwrap()
}

#[test]
fn standard_output_under_another_name_is_standard_output() {
    let dir = tempfile::tempdir().unwrap();
    let inp = inputs(dir.path());
    let good = inp.good.to_str().unwrap().to_string();
    let base = ["identify", &good, "--method", "arx", "--window", "40"].map(String::from);
    for alias in ["/dev/stdout", "/dev/fd/1", "/proc/self/fd/1"] {
        // appended after what the log holds, as `-` is (not written from offset 0)
        let log = dir.path().join("log.txt");
        std::fs::write(&log, "first line of the log\n").unwrap();
        let mut a = base.to_vec();
        a.extend(["-o".to_string(), alias.to_string()]);
        let o = run_appending(&a, &log);
        assert!(o.status.success(), "{alias}: {}", stderr(&o));
        let text = std::fs::read_to_string(&log).unwrap();
        assert!(
            text.starts_with("first line of the log\ntime_s,"),
            "{alias}: {text:.80}"
        );
        // with `-` for another output: the same file twice, refused
        for (x, y) in [("-", alias), (alias, "-")] {
            let mut a = base.to_vec();
            a.extend(["-o", x, "--summary", y].map(String::from));
            let o = run(&a, None);
            assert_eq!(o.status.code(), Some(2), "{x} {y}: {}", stderr(&o));
            assert!(
                stderr(&o).contains("given for two outputs"),
                "{}",
                stderr(&o)
            );
            assert!(o.stdout.is_empty(), "{x} {y}: something was written");
        }
    }
}

#[test]
fn help_and_version_that_cannot_be_written_fail() {
    if !Path::new("/dev/full").exists() {
        eprintln!("skipped: no /dev/full on this machine");
        return;
    }
    for args in [
        &["--help"][..],
        &["--version"],
        &["identify", "--help"],
        &["help"],
    ] {
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let o = Command::new(env!("CARGO_BIN_EXE_feedid"))
            .args(args)
            .stdout(Stdio::from(full))
            .stderr(Stdio::piped())
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        assert!(
            stderr(&o).contains("cannot write to standard output"),
            "{args:?}: {}",
            stderr(&o)
        );
    }
}

#[test]
fn two_runs_writing_one_set_at_once_leave_one_whole_set() {
    // two recordings of different lengths written to the same pair of
    // outputs at once: whichever wins, its predictions and its summary
    // are on disk together
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.csv");
    let b = dir.path().join("b.csv");
    std::fs::write(&a, csv(&rows(400, 0.0, 1e-3, 1.0))).unwrap();
    std::fs::write(&b, csv(&rows(700, 0.0, 1e-3, 1.0))).unwrap();
    let out = dir.path().join("out.csv");
    let summary = dir.path().join("s.json");
    let spawn = |rec: &Path| {
        Command::new(env!("CARGO_BIN_EXE_feedid"))
            .args([
                "identify",
                rec.to_str().unwrap(),
                "--method",
                "arx",
                "--window",
                "40",
            ])
            .args([
                "-o",
                out.to_str().unwrap(),
                "--summary",
                summary.to_str().unwrap(),
            ])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap()
    };
    for round in 0..30 {
        let (mut x, mut y) = (spawn(&a), spawn(&b));
        assert!(x.wait().unwrap().success() && y.wait().unwrap().success());
        let rows = std::fs::read_to_string(&out).unwrap().lines().count() - 1;
        let s: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&summary).unwrap()).unwrap();
        assert_eq!(
            s["samples"].as_u64(),
            Some(rows as u64),
            "round {round}: predictions of one run beside the summary of the other"
        );
        assert!(temporaries(dir.path()).is_empty());
    }
}
