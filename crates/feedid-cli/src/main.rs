//! `feedid`: identify feed-drive dynamics from command and position
//! recordings, predict the next milliseconds, and reproduce the paper.
//!
//! A thin front end: arguments → library calls → output. Every error ends
//! with a one-line message on standard error and exit code 2.

// `print!`/`println!`/`eprintln!` for every command (defined before `mod cmd`,
// so they shadow the standard ones there): the standard macros panic when a
// stream cannot be written (`feedid info x.csv | head -1`, a full disk). Here
// standard output that the reader closed ends the program quietly (exit 0:
// the reader wanted no more), any other failure to write it is an error
// (exit 2, one line on standard error); writes to standard error never fail.
macro_rules! print {
    ($($arg:tt)*) => {
        $crate::write_stdout(format_args!($($arg)*))
    };
}
macro_rules! println {
    () => {
        $crate::write_stdout(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::write_stdout(format_args!("{}\n", format_args!($($arg)*)))
    };
}
macro_rules! eprintln {
    ($($arg:tt)*) => {
        $crate::write_stderr(format_args!("{}\n", format_args!($($arg)*)))
    };
}

mod args;
mod cmd;

use std::io::{ErrorKind, Write};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use clap::{CommandFactory, FromArgMatches};

fn main() -> ExitCode {
    install_signal_handlers();
    // `--scale -1e-6`, `--rate -5000`: a negative number is a value (for the
    // validators to judge), not an unknown flag
    let matches = match numbers_take_a_minus(args::Cli::command()).try_get_matches() {
        Ok(m) => m,
        // `--help`, `--version`: printed on standard output, whose failure
        // (`> /dev/full`) is an error like any other output's
        Err(e) if !e.use_stderr() => {
            return match e.print().and_then(|()| std::io::stdout().lock().flush()) {
                Ok(()) => ExitCode::SUCCESS,
                Err(err) => stdout_failed(&err),
            };
        }
        Err(e) => e.exit(),
    };
    let cli = match args::Cli::from_arg_matches(&matches) {
        Ok(c) => c,
        Err(e) => e.exit(),
    };
    match cmd::run(cli) {
        Ok(()) => match std::io::stdout().lock().flush() {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => stdout_failed(&e),
        },
        Err(e) => {
            eprintln!("error: {}", one_line(&e));
            ExitCode::from(2)
        }
    }
}

/// `--scale -1e-6`, `--rate -5000`, `--window -5`: an option that takes a
/// number takes a value starting with `-` (clap would read `-1e-6` as the
/// flags `-1`, `-e`, `-6`), so that its validator names the value; any
/// other negative number is accepted as a value too.
fn numbers_take_a_minus(c: clap::Command) -> clap::Command {
    use std::any::TypeId;
    let numeric = [
        TypeId::of::<f64>(),
        TypeId::of::<usize>(),
        TypeId::of::<u64>(),
    ];
    c.allow_negative_numbers(true)
        .mut_args(move |a| {
            if numeric.iter().any(|t| a.get_value_parser().type_id() == *t) {
                a.allow_hyphen_values(true)
            } else {
                a
            }
        })
        .mut_subcommands(numbers_take_a_minus)
}

/// Signals: SIGINT, SIGTERM and SIGHUP remove the temporary files of
/// unfinished outputs (a set being renamed is finished first) and then end
/// the process as the signal would; SIGXFSZ (a write beyond `ulimit -f`) no
/// longer kills the process, so the write fails with `EFBIG` and is reported.
fn install_signal_handlers() {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM, SIGXFSZ};
    let _ = signal_hook::flag::register(SIGXFSZ, Arc::new(AtomicBool::new(false)));
    if let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) {
        std::thread::spawn(move || {
            if let Some(sig) = signals.forever().next() {
                feedid::io::abandon_pending_outputs(|_| {
                    let _ = signal_hook::low_level::emulate_default_handler(sig);
                    std::process::exit(128 + sig)
                });
            }
        });
    }
}

/// Set when an output of the command is standard output (`-o -`): the
/// command's own text then goes to standard error.
static STDOUT_TAKEN: AtomicBool = AtomicBool::new(false);

/// Send the command's printed text to standard error from now on.
fn stdout_taken_by_output() {
    STDOUT_TAKEN.store(true, Ordering::SeqCst);
}

/// An error with its whole cause chain on one line, `outer: cause: root`
/// (as anyhow's `{:#}`), except that a cause whose text its parent already
/// shows is not repeated: the library's messages embed the error they wrap
/// (`bad.csv: line 3, column …: <cause>`) and also expose it as their
/// source.
fn one_line(e: &anyhow::Error) -> String {
    let mut out = String::new();
    let mut previous = String::new();
    for cause in e.chain() {
        // the library's hints in the command line's syntax (`--max-smoothing`)
        let text = match cause.downcast_ref::<feedid::Error>() {
            Some(e) => e.message(feedid::error::Syntax::Cli),
            None => cause.to_string(),
        };
        let text = text.replace(['\n', '\r'], " ");
        if !out.is_empty() && previous.contains(&text) {
            previous = text;
            continue;
        }
        if !out.is_empty() {
            out.push_str(": ");
        }
        out.push_str(&text);
        previous = text;
    }
    out
}

/// Write to standard output (see the macros above).
fn write_stdout(args: std::fmt::Arguments<'_>) {
    if STDOUT_TAKEN.load(Ordering::SeqCst) {
        write_stderr(args);
        return;
    }
    if let Err(e) = std::io::stdout().lock().write_fmt(args) {
        stdout_failed(&e);
    }
}

/// Standard output failed: quietly if the reader went away, else with a reason.
fn stdout_failed(e: &std::io::Error) -> ! {
    if e.kind() == ErrorKind::BrokenPipe {
        std::process::exit(0);
    }
    write_stderr(format_args!(
        "error: cannot write to standard output: {e}\n"
    ));
    std::process::exit(2);
}

/// Write to standard error, ignoring failures (there is nowhere left to report them).
fn write_stderr(args: std::fmt::Arguments<'_>) {
    let _ = std::io::stderr().lock().write_fmt(args);
}
