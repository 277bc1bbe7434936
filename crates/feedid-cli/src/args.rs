//! Command-line arguments.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};

/// Identify feed-drive dynamics in short sliding windows and predict the next milliseconds.
#[derive(Debug, Parser)]
#[command(name = "feedid", version, about, propagate_version = true)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// Subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Print the nominal model: stiffness, inertia, N and D, poles, bandwidth, following error.
    Model(ModelArgs),
}

/// Which D1 coefficient to use.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum D1Arg {
    /// Consistent with the state equations (following error 1/Kv).
    Corrected,
    /// As printed in the paper's appendix (lacks +N1; for comparison only).
    Paper,
}

/// `feedid model`.
#[derive(Debug, Args)]
pub struct ModelArgs {
    /// Rig parameters (TOML); default: the built-in default rig.
    #[arg(long, value_name = "rig.toml")]
    pub params: Option<PathBuf>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// D1 coefficient variant.
    #[arg(long, value_enum, default_value = "corrected")]
    pub d1: D1Arg,
    /// Write the parameters used as TOML to this file (a template to edit).
    #[arg(long, value_name = "rig.toml")]
    pub save_params: Option<PathBuf>,
}
