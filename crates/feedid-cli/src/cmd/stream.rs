//! `feedid stream`: online identification in a pipe.
//!
//! Reads standard input line by line with the recording options of
//! `identify` (`feedid::io::StreamReader`: what `feedid simulate` writes
//! needs none), pushes each sample into the library's streamer
//! (`feedid::ident::stream::Streamer`, with `--command-lead` and
//! `--extrapolate`), writes each prediction as soon as it is due as
//! `time_s,predicted_m,lower_m,upper_m` rows (`feedid::io::PredictionRows`) and flushes
//! before the next line is read. With a hop shorter than the horizon a time
//! appears in several windows' rows; the later row supersedes the earlier.
//!
//! On standard error: each skipped line, gap and irregular interval with its
//! line number (the first hundred of each kind), and at the end a summary.
//! The header row goes out with the first usable sample: an input without
//! one leaves standard output empty. Exit code 2 (after the summary) when no
//! line was usable, or at once when standard output cannot be written; a
//! reader that closes the pipe ends the stream quietly (exit code 0).

use std::io::{BufRead, BufWriter, ErrorKind, Write};
use std::path::Path;

use anyhow::{bail, Result};
use feedid::error::Syntax;
use feedid::ident::stream::{
    CommandExtrapolation, HoldLoss, HoldWatch, HorizonCommand, Interval, Prediction, StreamOptions,
    StreamStats,
};
use feedid::ident::{EngineConfig, Estimator, GuardConfig, Regime, Span, Streamer};
use feedid::io::{PredictionRows, StreamLine, StreamReader};

use crate::args::StreamArgs;
use crate::cmd::method::OrderOption;
use crate::cmd::recording::read_options;

/// Messages of one kind printed at most (the summary counts them all).
const MAX_MESSAGES: usize = 100;

/// Blocks over which the predictions are compared with holding \[s\].
const WATCH_SECONDS: f64 = 2.0;

/// Run on the process's standard streams.
pub fn run(a: &StreamArgs) -> Result<()> {
    let stdin = std::io::stdin();
    let stdout = std::io::stdout();
    let stderr = std::io::stderr();
    run_on(
        a,
        stdin.lock(),
        BufWriter::new(stdout.lock()),
        stderr.lock(),
    )
}

/// The streamer `a` asks for.
fn streamer(a: &StreamArgs, rate: Option<f64>) -> Result<Streamer<Box<dyn Estimator + Send>>> {
    if a.options.order_option()? == Some(OrderOption::Select) {
        bail!("--order auto chooses the orders from a whole recording; a stream needs them given (na,nb,nk; `feedid order` chooses them)");
    }
    let method = a.options.method(&a.method)?;
    #[allow(clippy::neg_cmp_op_on_partial_ord)] // rejects NaN
    if !(a.interval > 0.0 && a.interval < 100.0) {
        bail!(
            "invalid --interval {}: the probability of the prediction intervals must be in (0, 100) % (e.g. 95)",
            a.interval
        );
    }
    let spans = [a.windows.window, Some(a.windows.horizon), a.windows.hop];
    let rate_hz = match rate {
        Some(r) => r,
        None if spans
            .iter()
            .flatten()
            .any(|s| matches!(s, Span::Seconds(_))) =>
        {
            bail!(
                "a window, horizon or hop given as a time needs --rate in a stream (the rate is \
             not known before the samples arrive); or give it in samples"
            )
        }
        None => f64::NAN,
    };
    let config = EngineConfig {
        window: method.window_for(a.windows.window, rate_hz)?,
        horizon: a.windows.horizon.samples(rate_hz, "horizon")?,
        hop: a
            .windows
            .hop
            .map(|h| h.samples(rate_hz, "hop"))
            .transpose()?,
        warm_up: 0,
    };
    let extrapolation: CommandExtrapolation = match &a.extrapolate {
        Some(s) => s.parse()?,
        None => CommandExtrapolation::default(),
    };
    let options = StreamOptions {
        command_lead: a.command_lead,
        extrapolation,
        // with a rate the intervals are exact: a skipped line is a gap
        dt: rate.map(|r| 1.0 / r),
        jitter_tolerance: a.recording.jitter_tol,
        guard: GuardConfig {
            interval: a.interval / 100.0,
            runaway: a.runaway.0,
            ..GuardConfig::default()
        },
        ..StreamOptions::default()
    };
    let s = Streamer::with_options(method.build()?, config, options)?;
    if a.extrapolate.is_some() {
        match s.horizon_command() {
            HorizonCommand::NotRead => bail!(
                "--extrapolate does not apply to --method {}{}: it does not read the command over the horizon",
                method.name(),
                if method.name() == "paper" { " with its polynomial prediction" } else { "" }
            ),
            HorizonCommand::Known { lead } => bail!(
                "--extrapolate does not apply with --command-lead {lead} ≥ --horizon {}: the command over the horizon is known",
                config.horizon
            ),
            _ => {}
        }
    }
    Ok(s)
}

/// Line counts for the summary.
#[derive(Default)]
struct Lines {
    read: usize,
    headers: usize,
    skipped: usize,
    gaps_shown: usize,
    irregular_shown: usize,
}

/// Why writing stopped.
pub(super) enum Output {
    Open,
    /// The reader closed the pipe: stop quietly.
    Closed,
}

/// Write a prediction's rows.
fn write<W: Write>(rows: &mut PredictionRows<W>, p: &Prediction<'_>) -> Result<Output> {
    check(rows.write(p.time, p.position, p.lower, p.upper))
}

/// A closed pipe ends the stream quietly, other write failures are errors.
fn check(r: std::io::Result<()>) -> Result<Output> {
    check_writing(r, "predictions")
}

/// As [`check`], naming what could not be written.
pub(super) fn check_writing(r: std::io::Result<()>, what: &str) -> Result<Output> {
    match r {
        Ok(()) => Ok(Output::Open),
        Err(e) if e.kind() == ErrorKind::BrokenPipe => Ok(Output::Closed),
        Err(e) => bail!("cannot write the {what} to standard output: {e}"),
    }
}

pub(super) fn run_on<R: BufRead, W: Write, E: Write>(
    a: &StreamArgs,
    input: R,
    out: W,
    mut err: E,
) -> Result<()> {
    if a.compensate {
        return super::stream_compensate::run_on(a, input, out, err);
    }
    let opts = read_options(&a.recording)?;
    let mut s = streamer(a, opts.rate_hz)?;
    let mut reader = StreamReader::new(input, Path::new("stdin"), &opts)?;
    let mut rows = PredictionRows::new(out);
    // the header goes out with the first usable sample: an input with none
    // leaves standard output empty
    let mut output = Output::Open;
    let mut header = false;
    let mut lines = Lines::default();
    let mut watch = HoldWatch::new(WATCH_SECONDS);
    let mut probe = Plausibility::default();
    while let Output::Open = output {
        let Some(line) = reader.next_line()? else {
            break;
        };
        lines.read += 1;
        let Some((no, t, u, y)) = sample(line, &mut lines.headers, &mut lines.skipped, &mut err)
        else {
            continue;
        };
        match s.push(t, u, y) {
            Ok(arrival) => {
                probe.push(t, u, y, &mut err);
                report_interval(&mut err, &mut lines, no, arrival.interval);
                if !header {
                    header = true;
                    output = check(rows.header())?;
                    if let Output::Closed = output {
                        break;
                    }
                }
            }
            Err(e) => {
                refuse(&mut err, &mut lines.skipped, no, &e);
                continue;
            }
        }
        while let Some(p) = s.poll()? {
            if p.is_ok() {
                output = write(&mut rows, &p)?;
                if let Output::Closed = output {
                    break;
                }
            }
        }
        if let Some(loss) = watch.check(&s.stats(), s.dt()) {
            if watch.blocks().1 == 1 {
                let dt = s.dt().unwrap_or(f64::NAN);
                let _ = writeln!(
                    err,
                    "warning: up to line {no}, over the last {:.1} s ({} scored samples), the \
                     predictions lost to holding the last position: rms {:.3} µm against {:.3} µm; \
                     {} (further blocks lost are counted in the summary)",
                    loss.seconds,
                    loss.samples,
                    1e6 * loss.rms,
                    1e6 * loss.hold_rms,
                    loss.advice_in(s.horizon_command(), s.config().horizon, dt, Syntax::Cli)
                );
            }
        }
    }
    if let Output::Open = output {
        s.finish();
        while let Some(p) = s.poll()? {
            if p.is_ok() {
                if let Output::Closed = write(&mut rows, &p)? {
                    break;
                }
            }
        }
    }
    probe.finish(&mut err);
    let st = s.stats();
    let _ = write!(
        err,
        "{}",
        summary(&lines, &st, s.horizon_command(), rows.rows(), a.interval)
    );
    let (blocks, lost) = watch.blocks();
    if lost > 0 {
        let _ = writeln!(
            err,
            "lost to holding the last position in {lost} of {blocks} blocks of {WATCH_SECONDS} s \
             (see the warning above)"
        );
    } else if st.scored.samples > 0 && st.scored.rms > st.hold.rms {
        let dt = s.dt().unwrap_or(f64::NAN);
        let loss = HoldLoss {
            seconds: st.scored.samples as f64 * dt,
            samples: st.scored.samples,
            rms: st.scored.rms,
            hold_rms: st.hold.rms,
        };
        let _ = writeln!(
            err,
            "warning: the predictions lost to holding the last position: {}",
            loss.advice_in(s.horizon_command(), s.config().horizon, dt, Syntax::Cli)
        );
    }
    if st.lines == 0 {
        if lines.read == 0 {
            bail!("no data line in the input (it is empty or has only blank and comment lines)");
        }
        bail!(
            "no usable line in the input ({} read: {} header, {} skipped)",
            lines.read,
            lines.headers,
            lines.skipped
        );
    }
    if st.samples == 0 && st.unused_positions > 0 {
        // every position waited for a command that never came
        bail!(
            "no sample could be used: with --command-lead {} each position is paired with the \
             command {} lines later, and the input has {} data lines; the command lead must be \
             shorter than the input",
            a.command_lead,
            a.command_lead,
            st.lines
        );
    }
    Ok(())
}

/// Samples from the stream's start that the plausibility checks of a
/// recording (`feedid::plausibility`: a frozen position, a unit mismatch, a
/// sign or offset, an implausible speed or lag) look at, as `identify` does
/// on a file: bounded, so a stream of any length keeps at most this many.
const PLAUSIBILITY_SAMPLES: usize = 20_000;

/// The first [`PLAUSIBILITY_SAMPLES`] samples, checked once when they are
/// all in or the stream ends, whichever comes first; the warnings go to
/// standard error, as `identify`'s do.
#[derive(Default)]
struct Plausibility {
    t: Vec<f64>,
    u: Vec<f64>,
    y: Vec<f64>,
    done: bool,
}

impl Plausibility {
    fn push<E: Write>(&mut self, t: f64, u: f64, y: f64, err: &mut E) {
        if self.done {
            return;
        }
        self.t.push(t);
        self.u.push(u);
        self.y.push(y);
        if self.t.len() >= PLAUSIBILITY_SAMPLES {
            self.finish(err);
        }
    }

    fn finish<E: Write>(&mut self, err: &mut E) {
        if self.done {
            return;
        }
        self.done = true;
        let n = self.t.len();
        let (t, u, y) = (
            std::mem::take(&mut self.t),
            std::mem::take(&mut self.u),
            std::mem::take(&mut self.y),
        );
        // samples a recording would refuse (a gap, a repeated time) leave
        // the check to what `identify` says of the saved file
        let Ok(rec) = feedid::Recording::new(t, u, y) else {
            return;
        };
        for w in feedid::plausibility::check_recording(&rec) {
            let _ = writeln!(
                err,
                "warning: stdin (its first {n} samples): {}",
                w.phrased(Syntax::Cli)
            );
        }
    }
}

/// The sample a line carries: `(line number, time, command, position)`;
/// `None` for a header (counted) or a line the reader skipped (counted and
/// reported, the first hundred).
pub(super) fn sample<E: Write>(
    line: StreamLine,
    headers: &mut usize,
    skipped: &mut usize,
    err: &mut E,
) -> Option<(usize, f64, f64, f64)> {
    match line {
        StreamLine::Header { .. } => {
            *headers += 1;
            None
        }
        StreamLine::Skipped { error, .. } => {
            *skipped += 1;
            if *skipped <= MAX_MESSAGES {
                let _ = writeln!(err, "{error}; skipped");
            }
            None
        }
        StreamLine::Sample {
            line,
            time,
            command,
            position,
        } => Some((line, time, command, position)),
    }
}

/// A line the streamer refuses (its time, a value) is reported with its
/// number (the first hundred) and skipped.
pub(super) fn refuse<E: Write>(
    err: &mut E,
    skipped: &mut usize,
    no: usize,
    e: &dyn std::fmt::Display,
) {
    *skipped += 1;
    if *skipped <= MAX_MESSAGES {
        let _ = writeln!(err, "stdin: line {no}: {e}; skipped");
    }
}

/// Report a gap or an irregular interval (the first hundred of each).
fn report_interval<E: Write>(err: &mut E, lines: &mut Lines, no: usize, interval: Interval) {
    match interval {
        Interval::Regular => {}
        Interval::Gap(j) => {
            lines.gaps_shown += 1;
            if lines.gaps_shown <= MAX_MESSAGES {
                let what = match j.missing_samples() {
                    0 => format!(
                        "the interval {} s is not the {} s so far (the sampling changed?)",
                        short(j.interval()),
                        short(j.expected)
                    ),
                    m => format!(
                        "time jumps from {} s to {} s: {m} sample{} of {} s missing",
                        j.previous_time,
                        j.time,
                        if m == 1 { "" } else { "s" },
                        short(j.expected)
                    ),
                };
                let _ = writeln!(err, "stdin: line {no}: gap: {what}; the windows restart");
            }
        }
        Interval::Irregular(j) => {
            lines.irregular_shown += 1;
            if lines.irregular_shown <= MAX_MESSAGES {
                let _ = writeln!(
                    err,
                    "stdin: line {no}: interval {} s is {:+.1} % off the {} s so far; kept",
                    short(j.interval()),
                    100.0 * (j.interval() / j.expected - 1.0),
                    short(j.expected)
                );
            }
        }
    }
}

/// A number with 6 significant digits.
fn short(v: f64) -> String {
    format!("{v:.6e}")
        .parse::<f64>()
        .map_or_else(|_| v.to_string(), |x| x.to_string())
}

/// A share in per cent of `n` over `of` (`of` > 0).
fn percent(n: usize, of: usize) -> String {
    format!("{:.1} %", 100.0 * n as f64 / of as f64)
}

/// The summary on standard error (several lines; never an rms over nothing).
fn summary(
    lines: &Lines,
    st: &StreamStats,
    command: HorizonCommand,
    rows: usize,
    interval_percent: f64,
) -> String {
    let mut o = String::new();
    let unused = if st.unused_positions > 0 {
        format!(
            " ({} positions before the command lead unused)",
            st.unused_positions
        )
    } else {
        String::new()
    };
    o += &format!(
        "lines {} ({} header), skipped lines {}, samples {}{unused}, gaps {}, irregular intervals {}\n",
        lines.read, lines.headers, lines.skipped, st.samples, st.gaps, st.irregular_intervals
    );
    let predicted = st.windows - st.failed_windows - st.withheld_windows;
    // (the stream runs with the default plausibility bound)
    let why = match GuardConfig::default().plausibility {
        Some(f) if st.withheld_windows > 0 => {
            format!(" (implausible: beyond {f}× the motion seen; the method restarted)")
        }
        _ => String::new(),
    };
    o += &format!(
        "windows {}: {predicted} predicted, {} withheld{why}, {} failed; {rows} rows written\n",
        st.windows, st.withheld_windows, st.failed_windows
    );
    o += &format!("command over the horizon: {command}\n");
    let made = st.predicted_ahead + st.predicted_late;
    if made > 0 {
        o += &format!(
            "predicted before their measurement arrived: {} of {made} predicted samples ({})\n",
            st.predicted_ahead,
            percent(st.predicted_ahead, made)
        );
    }
    if st.scored.samples > 0 {
        o += &format!(
            "scored {} of {} samples ({}); prediction error: rms {:.3} µm, max {:.3} µm; \
             holding each window's last position on the same samples: rms {:.3} µm\n",
            st.scored.samples,
            st.samples,
            percent(st.scored.samples, st.samples),
            1e6 * st.scored.rms,
            1e6 * st.scored.max_abs,
            1e6 * st.hold.rms
        );
        o += &format!(
            "inside the {} % prediction interval: {} of the scored samples ({}); isolated outliers not fitted: {}\n",
            feedid::error::short_number(interval_percent),
            st.inside_interval,
            percent(st.inside_interval, st.scored.samples),
            st.outliers
        );
        let by: Vec<String> = Regime::ALL
            .iter()
            .filter(|r| st.regime_samples[r.index()] > 0)
            .map(|r| {
                let (n, inside) = (st.regime_samples[r.index()], st.regime_inside[r.index()]);
                format!("{} {} of {n}", r.label(), percent(inside, n))
            })
            .collect();
        o += &format!("inside the interval by command regime: {}\n", by.join(", "));
    } else {
        o += "scored: no sample (no prediction was compared with a measurement)\n";
    }
    if st.runaway_windows > 0 {
        o += &format!(
            "cut back as runaways: {} windows ({} samples): they left the motion the axis has shown or where its command goes\n",
            st.runaway_windows, st.runaway_samples
        );
    }
    o
}
