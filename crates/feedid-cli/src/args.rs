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
    /// Summarise a recording: samples, rate and jitter, channel ranges, motion segments.
    Info(InfoArgs),
    /// Print the nominal model: stiffness, inertia, N and D, poles, bandwidth, following error.
    Model(ModelArgs),
    /// Identify and predict online: CSV samples on stdin, predictions on stdout as they are due.
    Stream(StreamArgs),
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

/// How to read a recording (every command that reads one uses these).
#[derive(Debug, Clone, Args)]
pub struct RecordingArgs {
    /// Time column/variable, by name or 1-based index [default: time_s in text files].
    #[arg(long, value_name = "NAME|N")]
    pub time: Option<String>,
    /// Command (set-point) column/variable [default: command_m in text files].
    #[arg(long, value_name = "NAME|N")]
    pub command: Option<String>,
    /// Measured-position column/variable [default: position_m in text files].
    #[arg(long, value_name = "NAME|N")]
    pub position: Option<String>,
    /// Sampling rate when the file has no time column [Hz].
    #[arg(long, value_name = "HZ")]
    pub rate: Option<f64>,
    /// Delimiter of text files: ',', ';', 'tab', 'space' [default: detected].
    #[arg(long, value_name = "CHAR")]
    pub delimiter: Option<String>,
    /// The first row is data, not a header [default: detected].
    #[arg(long, conflicts_with = "header")]
    pub no_header: bool,
    /// The first row is a header [default: detected].
    #[arg(long)]
    pub header: bool,
    /// Unit of command and position in the file: m, mm, um, nm.
    #[arg(long, value_name = "UNIT", default_value = "m")]
    pub unit: String,
    /// Metres per file unit of command and position (e.g. encoder counts → m).
    #[arg(long, value_name = "M_PER_UNIT")]
    pub scale: Option<f64>,
    /// Unit of the time column: s, ms, us.
    #[arg(long, value_name = "UNIT", default_value = "s")]
    pub time_unit: String,
    /// Allowed relative deviation of a sampling interval from the mean one.
    #[arg(long, value_name = "FRACTION", default_value_t = 0.01)]
    pub jitter_tol: f64,
}

/// `feedid info`.
#[derive(Debug, Args)]
pub struct InfoArgs {
    /// Recording: CSV/text or MATLAB v5 .mat file.
    pub input: PathBuf,
    /// How to read it.
    #[command(flatten)]
    pub recording: RecordingArgs,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// `feedid stream`.
#[derive(Debug, Args)]
pub struct StreamArgs {
    /// Identification method.
    #[arg(long, value_name = "M", default_value = "paper")]
    pub method: String,
    /// Least-squares solver of the paper method: qr, simplex.
    #[arg(long, value_name = "S", default_value = "qr")]
    pub solver: String,
    /// Window length W [samples].
    #[arg(long, value_name = "W", default_value_t = 20)]
    pub window: usize,
    /// Prediction horizon H [samples].
    #[arg(long, value_name = "H", default_value_t = 10)]
    pub horizon: usize,
    /// Shift between windows [samples; default: the horizon].
    #[arg(long, value_name = "K")]
    pub hop: Option<usize>,
    /// Sampling rate [Hz]: input lines are `command,position` without a time column.
    #[arg(long, value_name = "HZ")]
    pub rate: Option<f64>,
}
