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
            let chain: Vec<String> = e.chain().map(|c| c.to_string()).collect();
            eprintln!("error: {}", chain.join(": ").replace('\n', " "));
            ExitCode::from(2)
        }
    }
}
