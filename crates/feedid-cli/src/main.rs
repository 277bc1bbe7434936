//! `feedid`: identify feed-drive dynamics from command and position
//! recordings, predict the next milliseconds, and reproduce the paper.
//!
//! A thin front end: arguments → library calls → output. Every error ends
//! with a one-line message on standard error and exit code 2.

mod args;
mod cmd;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    let cli = args::Cli::parse();
    match cmd::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // The library's messages already carry their causes (file, line,
            // column, value): print the outermost one, on one line.
            eprintln!("error: {}", e.to_string().replace('\n', " "));
            ExitCode::from(2)
        }
    }
}
