//! `feedid stream`: online identification in a pipe.
//!
//! Reads samples from standard input, one per line: `time,command,position`
//! (seconds, metres), or `command,position` with `--rate`. Fields may be
//! separated by commas, semicolons, tabs or blanks; a first line that is not
//! numeric is a header; lines starting with `#` and empty lines are ignored.
//! Each window's prediction is written to standard output as soon as it is
//! due (see `feedid::ident::stream` for when that is), one row
//! `time_s,predicted_m` per horizon sample, and flushed. With a hop shorter
//! than the horizon a time appears in several windows' rows; the later row
//! supersedes the earlier.
//!
//! A malformed line (wrong field count, not a number, not finite, time not
//! increasing) gets a message with its line number on standard error and is
//! skipped; the stream goes on. At the end of input the last windows are
//! processed and a summary goes to standard error.

use std::io::{BufRead, ErrorKind, Read, Write};

use anyhow::{bail, Result};
use feedid::ident::{EngineConfig, Prediction, Streamer};

use crate::args::StreamArgs;
use crate::cmd::method::OrderOption;

/// Run on the process's standard streams.
pub fn run(a: &StreamArgs) -> Result<()> {
    let stdin = std::io::stdin();
    let stdout = std::io::stdout();
    let stderr = std::io::stderr();
    run_on(a, stdin.lock(), stdout.lock(), stderr.lock())
}

/// Counters for the summary.
#[derive(Default)]
struct Counts {
    skipped: usize,
    rows: usize,
}

/// Outcome of writing rows: keep going, or the reader has gone away.
enum Sink {
    Open,
    Closed,
}

fn run_on<R: BufRead, W: Write, E: Write>(
    a: &StreamArgs,
    input: R,
    mut out: W,
    mut err: E,
) -> Result<()> {
    if let Some(rate) = a.rate {
        if !(rate.is_finite() && rate > 0.0) {
            bail!("--rate must be a positive number of Hz, got {rate}");
        }
    }
    if a.options.order_option()? == Some(OrderOption::Select) {
        bail!("--order auto chooses the orders from a whole recording; a stream needs them given (na,nb,nk; `feedid order` chooses them)");
    }
    let method = a.options.method(&a.method)?;
    let config = EngineConfig {
        window: a.windows.window.unwrap_or_else(|| method.default_window()),
        horizon: a.windows.horizon,
        hop: a.windows.hop,
        warm_up: 0,
    };
    let mut streamer = Streamer::new(method.build()?, config)?;
    let fields = if a.rate.is_some() { 2 } else { 3 };
    let layout = if a.rate.is_some() {
        "command,position"
    } else {
        "time,command,position"
    };

    let mut counts = Counts::default();
    let mut sink = write_rows(&mut out, None, &mut counts, true);
    let mut seen_data_line = false;
    let mut values = [0.0; 3];
    let mut line: Vec<u8> = Vec::new();
    let mut input = input;
    let mut number = 0usize;
    while matches!(sink, Sink::Open) {
        line.clear();
        // at most MAX_LINE bytes per line: a stream without newlines
        // (`cat /dev/zero | feedid stream`) must not exhaust memory
        match (&mut input).take(MAX_LINE).read_until(b'\n', &mut line) {
            Ok(0) => break,
            Ok(_) => {}
            Err(e) if e.kind() == ErrorKind::Interrupted => continue,
            Err(e) => return Err(e.into()),
        }
        number += 1;
        if line.len() as u64 >= MAX_LINE && line.last() != Some(&b'\n') {
            skip_rest_of_line(&mut input)?;
            counts.skipped += 1;
            let _ = writeln!(err, "line {number}: longer than {MAX_LINE} bytes; skipped");
            continue;
        }
        let Ok(text) = std::str::from_utf8(&line) else {
            counts.skipped += 1;
            let _ = writeln!(err, "line {number}: not UTF-8 text; skipped");
            continue;
        };
        let text = text.trim();
        if text.is_empty() || text.starts_with('#') {
            continue;
        }
        let first = !seen_data_line;
        seen_data_line = true;
        match parse_fields(text, &mut values[..fields]) {
            Ok(()) => {}
            Err(FieldError::NotNumeric) if first => continue, // a header line
            Err(_) => {
                counts.skipped += 1;
                // quote at most 60 characters of the line (it may be megabytes)
                let cut = text.char_indices().nth(60).map_or(text.len(), |(i, _)| i);
                let more = if cut < text.len() { "…" } else { "" };
                let _ = writeln!(
                    err,
                    "line {number}: expected {fields} numbers `{layout}`, got `{}{more}`; skipped",
                    &text[..cut]
                );
                continue;
            }
        }
        let (t, u, y) = match a.rate {
            Some(rate) => (streamer.stats().samples as f64 / rate, values[0], values[1]),
            None => (values[0], values[1], values[2]),
        };
        match streamer.push(t, u, y) {
            Ok(p) => sink = write_rows(&mut out, p, &mut counts, false),
            Err(e) => {
                counts.skipped += 1;
                let _ = writeln!(err, "line {number}: {e}; skipped");
            }
        }
    }
    if matches!(sink, Sink::Open) {
        streamer.finish();
        while let Some(p) = streamer.poll()? {
            if let Sink::Closed = write_rows(&mut out, Some(p), &mut counts, false) {
                break;
            }
        }
    }
    let s = streamer.stats();
    let _ = writeln!(
        err,
        "samples {}, predictions {} ({} windows, {} failed, {} withheld, {} rows), skipped lines {}, \
         rms error {:.6e} m over {} scored samples (max {:.6e} m)",
        s.samples,
        s.windows - s.failed_windows - s.withheld_windows,
        s.windows,
        s.failed_windows,
        s.withheld_windows,
        counts.rows,
        counts.skipped,
        s.scored.rms,
        s.scored.samples,
        s.scored.max_abs,
    );
    Ok(())
}

/// Longest input line \[bytes\]; longer ones are reported and skipped.
const MAX_LINE: u64 = 1 << 20;

/// Discard input up to and including the next newline (or to the end).
fn skip_rest_of_line<R: BufRead>(input: &mut R) -> std::io::Result<()> {
    loop {
        let buf = match input.fill_buf() {
            Ok(b) => b,
            Err(e) if e.kind() == ErrorKind::Interrupted => continue,
            Err(e) => return Err(e),
        };
        if buf.is_empty() {
            return Ok(());
        }
        match buf.iter().position(|&b| b == b'\n') {
            Some(i) => {
                input.consume(i + 1);
                return Ok(());
            }
            None => {
                let n = buf.len();
                input.consume(n);
            }
        }
    }
}

/// Write the header (`header`) or a prediction's rows, and flush.
fn write_rows<W: Write>(
    out: &mut W,
    p: Option<Prediction<'_>>,
    counts: &mut Counts,
    header: bool,
) -> Sink {
    let res = (|| -> std::io::Result<bool> {
        if header {
            writeln!(out, "time_s,predicted_m")?;
        }
        let mut wrote = header;
        if let Some(p) = p {
            for (t, y) in p.time.iter().zip(p.position) {
                writeln!(out, "{t},{y}")?;
                counts.rows += 1;
                wrote = true;
            }
        }
        if wrote {
            out.flush()?;
        }
        Ok(wrote)
    })();
    match res {
        Ok(_) => Sink::Open,
        // the reader closed the pipe: stop quietly
        Err(_) => Sink::Closed,
    }
}

/// Why a line did not parse.
enum FieldError {
    /// Some field is not a number (a header if it is the first line).
    NotNumeric,
    /// Wrong number of fields.
    Count,
}

/// Split `text` into exactly `out.len()` numbers.
fn parse_fields(text: &str, out: &mut [f64]) -> std::result::Result<(), FieldError> {
    let separated = text.contains([',', ';', '\t']);
    let parts: Box<dyn Iterator<Item = &str>> = if separated {
        Box::new(text.split([',', ';', '\t']).map(str::trim))
    } else {
        Box::new(text.split_whitespace())
    };
    let mut n = 0;
    let mut numeric = true;
    for part in parts {
        match part.parse::<f64>() {
            Ok(v) if n < out.len() => out[n] = v,
            Ok(_) => {}
            Err(_) => numeric = false,
        }
        n += 1;
    }
    if !numeric {
        Err(FieldError::NotNumeric)
    } else if n != out.len() {
        Err(FieldError::Count)
    } else {
        Ok(())
    }
}
