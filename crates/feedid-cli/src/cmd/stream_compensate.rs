//! `feedid stream --compensate`: online compensation in a pipe.
//!
//! Reads standard input line by line as `feedid stream` does; each line's
//! command is the desired program `--command-lead N` lines ahead. Feeds the
//! library's `feedid::compensate::CommandStream` and writes each command as
//! soon as it is computed, as `time_s,desired_m,command_m` rows
//! (`feedid::io::CommandRows`), flushed before the next line is read. The
//! sample interval is `--rate`'s, or that of the first two lines. On
//! standard error: skipped lines (the first hundred) and a summary.

use std::io::{BufRead, Write};
use std::path::Path;

use anyhow::{bail, Context, Result};
use feedid::compensate::{following_error_of, CommandStream, OnlineConfig, OnlineState};
use feedid::io::{CommandRows, StreamReader};

use super::stream::{check_writing, refuse, sample, Output};
use crate::args::StreamArgs;
use crate::cmd::recording::read_options;

pub(super) fn run_on<R: BufRead, W: Write, E: Write>(
    a: &StreamArgs,
    input: R,
    out: W,
    mut err: E,
) -> Result<()> {
    // The compensator identifies its own feed-forward model: the options of
    // the sliding identification are refused, never ignored.
    let w = &a.windows;
    let mut given: Vec<String> = a
        .options
        .values
        .iter()
        .map(|(key, _)| feedid::error::Hint::Option { key }.phrase(feedid::error::Syntax::Cli))
        .collect();
    for (flag, on) in [
        ("--window", w.window.is_some()),
        ("--hop", w.hop.is_some()),
        ("--horizon", w.horizon != feedid::ident::Span::Samples(10)),
        ("--interval", a.interval != 95.0),
        ("--extrapolate", a.extrapolate.is_some()),
    ] {
        if on {
            given.push(flag.to_string());
        }
    }
    if !given.is_empty() {
        bail!(
            "{} not used by --compensate (the online compensator identifies its own feed-forward model); leave {} out",
            given.join(", "),
            if given.len() == 1 { "it" } else { "them" }
        );
    }
    if a.command_lead < 3 {
        bail!(
            "--compensate needs the desired program at least 3 lines ahead (--command-lead {} given): the command of a sample is computed from the desired positions two samples beyond it, before the drive needs it",
            a.command_lead
        );
    }
    let cfg = OnlineConfig {
        max_velocity: a.max_velocity,
        max_acceleration: a.max_acceleration,
        ..OnlineConfig::default()
    };
    cfg.validate()?;
    let model = match &a.model {
        Some(p) => {
            let file = super::load_model_file(p)?;
            let explains = file
                .identified_by
                .as_ref()
                .and_then(|q| q.error_fit_percent);
            if !explains.is_some_and(|f| f >= 90.0) {
                let _ = writeln!(
                    err,
                    "warning: {} explains {} of its recording's following error: a poor start (on the drive zoo such models made the compensation worse than starting from nothing)",
                    p.display(),
                    explains.map_or("an unknown share".to_string(), |f| format!("{f:.1} %"))
                );
            }
            Some((p, file.model))
        }
        None => None,
    };
    let opts = read_options(&a.recording)?;
    let mut reader = StreamReader::new(input, Path::new("stdin"), &opts)?;
    let mut rows = CommandRows::new(out);
    let mut stream: Option<CommandStream> = None;
    // without --rate the interval comes from the first two lines
    let mut first: Option<(f64, f64, f64)> = None;
    let (mut read, mut headers, mut skipped, mut used) = (0usize, 0usize, 0usize, 0usize);
    let mut output = Output::Open;
    while let Output::Open = output {
        let Some(line) = reader.next_line()? else {
            break;
        };
        read += 1;
        let Some((no, t, u, y)) = sample(line, &mut headers, &mut skipped, &mut err) else {
            continue;
        };
        let s = match &mut stream {
            Some(s) => s,
            None => {
                if let Some(bad) = [t, u, y].iter().find(|v| !v.is_finite()) {
                    refuse(&mut err, &mut skipped, no, &format!("not finite: {bad}"));
                    continue;
                }
                let dt = match (opts.rate_hz, first) {
                    (Some(r), _) => 1.0 / r,
                    (None, None) => {
                        first = Some((t, u, y));
                        used += 1;
                        continue;
                    }
                    (None, Some((t0, ..))) if t <= t0 => {
                        refuse(
                            &mut err,
                            &mut skipped,
                            no,
                            &format!("time {t} s is not after {t0} s"),
                        );
                        continue;
                    }
                    (None, Some((t0, ..))) => t - t0,
                };
                let mut s = CommandStream::new(cfg, a.command_lead, dt, a.replay)?;
                if let Some((path, m)) = &model {
                    let alpha = following_error_of(m, dt).with_context(|| {
                        format!("{}: at the stream's interval {dt} s", path.display())
                    })?;
                    s.set_prior(alpha)?;
                    let _ = writeln!(
                        err,
                        "starting from {}: lag {:.4} ms",
                        path.display(),
                        1e3 * alpha[0]
                    );
                }
                output = check_writing(rows.header(), "commands")?;
                if let Some((t0, u0, y0)) = first.take() {
                    if let Some(r) = s.push(t0, u0, y0)? {
                        output =
                            check_writing(rows.write(r.time, r.desired, r.command), "commands")?;
                    }
                }
                stream.insert(s)
            }
        };
        if let Output::Closed = output {
            break;
        }
        match s.push(t, u, y) {
            Ok(row) => {
                used += 1;
                if let Some(r) = row {
                    output = check_writing(rows.write(r.time, r.desired, r.command), "commands")?;
                }
            }
            Err(e) => refuse(&mut err, &mut skipped, no, &e),
        }
    }
    let _ = write!(
        err,
        "{}",
        summary(stream.as_ref(), read, skipped, rows.rows(), a)
    );
    if used == 0 {
        bail!("no usable line in the input ({read} read, {skipped} skipped)");
    }
    Ok(())
}

/// The summary on standard error.
fn summary(
    s: Option<&CommandStream>,
    read: usize,
    skipped: usize,
    written: usize,
    a: &StreamArgs,
) -> String {
    let mut o = format!(
        "lines {read}, skipped {skipped}; commands written {written} (the program {} lines ahead{})\n",
        a.command_lead,
        if a.replay {
            "; replayed: the positions answer the input's own command"
        } else {
            ""
        }
    );
    let Some(s) = s else {
        o += "no command: fewer than two samples (give --rate to start with the first)\n";
        return o;
    };
    let st = s.stats();
    if st.commands > 0 {
        let share = |n: usize| 100.0 * n as f64 / st.commands as f64;
        o += &format!(
            "compensated {} of {} commands ({:.1} %), limited by --max-velocity/--max-acceleration {} ({:.1} %), model updates {}, segments {}\n",
            st.compensated,
            st.commands,
            share(st.compensated),
            st.limited,
            share(st.limited),
            st.model_updates,
            s.segments()
        );
    }
    let c = s.compensator();
    let [t1, t2, _] = c.time_constants();
    o += &match s.state() {
        OnlineState::Active => format!(
            "model in use: lag T1 = {:.4} ms, T2 = {:.4e} s² (command = desired + T1·velocity + T2·acceleration)\n",
            1e3 * t1,
            t2
        ),
        OnlineState::Learning => {
            "model: still learning (the command has not moved enough); the plain command is sent\n"
                .to_string()
        }
        OnlineState::Unexplained => "model: explains too little of the following error; the plain command is sent\n".to_string(),
        OnlineState::Invalid => "model: not finite; the plain command is sent\n".to_string(),
        OnlineState::Worse => "model: its compensation left more error than the plain command would; withheld for now, the plain command is sent\n".to_string(),
    };
    if st.withheld > 0 {
        o += &format!(
            "withheld {} time(s) for doing worse than the plain command\n",
            st.withheld
        );
    }
    o
}
