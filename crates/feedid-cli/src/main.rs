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

use clap::Parser;

fn main() -> ExitCode {
    let cli = args::Cli::parse();
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

/// An error with its whole cause chain on one line, `outer: cause: root`
/// (as anyhow's `{:#}`), except that a cause whose text its parent already
/// shows is not repeated: the library's messages embed the error they wrap
/// (`bad.csv: line 3, column …: <cause>`) and also expose it as their
/// source.
fn one_line(e: &anyhow::Error) -> String {
    let mut out = String::new();
    let mut previous = String::new();
    for cause in e.chain() {
        let text = cause.to_string().replace(['\n', '\r'], " ");
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
