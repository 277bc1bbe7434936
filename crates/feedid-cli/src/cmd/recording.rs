//! Turning the shared recording options into a library read.

use std::path::Path;

use anyhow::{bail, Result};
use feedid::error::Syntax;
use feedid::io::{read_recording, read_recording_with_progress, ChannelRef, ReadOptions};
use feedid::plausibility::check_recording;
use feedid::Recording;

use crate::args::RecordingArgs;

/// Library read options from the command-line options.
pub fn read_options(a: &RecordingArgs) -> Result<ReadOptions> {
    let channel = |s: &Option<String>| -> Result<Option<ChannelRef>> {
        Ok(match s {
            Some(s) => Some(ChannelRef::parse(s)?),
            None => None,
        })
    };
    let delimiter = match a.delimiter.as_deref() {
        None => None,
        Some("," | "comma") => Some(b','),
        Some(";" | "semicolon") => Some(b';'),
        Some("\t" | "tab" | "\\t") => Some(b'\t'),
        Some(" " | "space" | "whitespace") => Some(b' '),
        Some(other) => bail!("invalid delimiter `{other}`; expected one of: ',', ';', tab, space"),
    };
    let header = if a.no_header {
        Some(false)
    } else if a.header {
        Some(true)
    } else {
        None
    };
    let opts = ReadOptions {
        time: channel(&a.time)?,
        command: channel(&a.command)?,
        position: channel(&a.position)?,
        rate_hz: a.rate,
        delimiter,
        header,
        position_unit: a.unit.parse()?,
        scale: a.scale,
        time_unit: a.time_unit.parse()?,
        jitter_tolerance: a.jitter_tol,
        signals_only: false,
        allow_gaps: false,
    };
    opts.validate()?;
    Ok(opts)
}

/// Read and check the time, command and position only (no extra channels:
/// three `f64` per sample in memory), dropped samples accepted as gaps
/// (the sliding engine restarts its windows after each), reporting
/// `progress(bytes read, file size)`, without printing its plausibility
/// warnings (for commands whose library call reports them, as the pipeline
/// does).
pub fn read_signals(
    path: &Path,
    a: &RecordingArgs,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<Recording> {
    let opts = ReadOptions {
        signals_only: true,
        allow_gaps: true,
        ..read_options(a)?
    };
    Ok(read_recording_with_progress(path, &opts, Some(progress))?)
}

/// [`load_checked`] without the warnings.
pub fn load(path: &Path, a: &RecordingArgs) -> Result<Recording> {
    Ok(load_checked(path, a)?.0)
}

/// Read and check a recording; its plausibility warnings
/// (`feedid::plausibility`) go to standard error and are returned for the
/// summaries. Dropped samples are accepted as gaps ([`Recording::gaps`]):
/// every command that reads a recording handles them (restarting its
/// windows, using one stretch between them, or simulating through them).
pub fn load_checked(path: &Path, a: &RecordingArgs) -> Result<(Recording, Vec<String>)> {
    let opts = ReadOptions {
        allow_gaps: true,
        ..read_options(a)?
    };
    let rec = read_recording(path, &opts)?;
    let warnings: Vec<String> = check_recording(&rec)
        .into_iter()
        .map(|w| w.phrased(Syntax::Cli))
        .collect();
    for w in &warnings {
        eprintln!("warning: {}: {w}", path.display());
    }
    Ok((rec, warnings))
}
