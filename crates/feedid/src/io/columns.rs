//! From parsed columns to a checked recording, shared by the text and
//! MAT-file readers: unit conversion and the checks of [`Recording`]
//! ([`build_recording`]), the sample an error points at, the file context
//! of an error, and short quotes and lists for one-line messages.

use std::path::Path;

use crate::error::{Error, Result};
use crate::io::options::ReadOptions;
use crate::recording::Recording;

/// Which of the three signals an error concerns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Role {
    Time,
    Command,
    Position,
}

/// Convert units and build the checked recording. Errors are those of
/// [`Recording::with_tolerance`], without file context (see [`failing_sample`]).
pub(crate) fn build_recording(
    time: Option<Vec<f64>>,
    mut command: Vec<f64>,
    mut position: Vec<f64>,
    opts: &ReadOptions,
) -> Result<Recording> {
    let f = opts.position_factor();
    if f != 1.0 {
        command.iter_mut().for_each(|v| *v *= f);
        position.iter_mut().for_each(|v| *v *= f);
    }
    let time = match (time, opts.rate_hz) {
        (Some(mut t), _) => {
            let tf = opts.time_unit.factor();
            if tf != 1.0 {
                t.iter_mut().for_each(|v| *v *= tf);
            }
            t
        }
        (None, Some(rate)) => (0..command.len()).map(|k| k as f64 / rate).collect(),
        (None, None) => {
            return Err(Error::InvalidParameter {
                name: "rate",
                value: f64::NAN,
                reason: "needed when there is no time column or variable",
            })
        }
    };
    if opts.allow_gaps {
        Recording::allowing_gaps(time, command, position, opts.jitter_tolerance)
    } else {
        Recording::with_tolerance(time, command, position, opts.jitter_tolerance)
    }
}

/// The zero-based sample and the signal a [`Recording`] check error points at.
pub(crate) fn failing_sample(err: &Error) -> Option<(usize, Option<Role>)> {
    match err {
        Error::NonFinite { channel, index, .. } | Error::OutOfRange { channel, index, .. } => {
            let role = match channel.as_str() {
                "time" => Some(Role::Time),
                "command" => Some(Role::Command),
                "position" => Some(Role::Position),
                _ => None,
            };
            Some((*index, role))
        }
        Error::NonMonotoneTime { index, .. } => Some((*index, Some(Role::Time))),
        Error::SamplingJitter { index, .. } | Error::TooManyGaps { index, .. } => {
            Some((*index, Some(Role::Time)))
        }
        Error::SamplingInterval { .. } => Some((1, Some(Role::Time))),
        _ => None,
    }
}

/// Longest text of one item quoted in an error message \[chars\].
const MAX_QUOTED_CHARS: usize = 60;
/// Most items listed in an error message.
const MAX_LISTED: usize = 24;

/// `text` cut to a length fit for a one-line message (`…` marks the cut).
pub(crate) fn short_text(text: &str) -> String {
    match text.char_indices().nth(MAX_QUOTED_CHARS) {
        Some((cut, _)) => format!("{}… ({} bytes)", &text[..cut], text.len()),
        None => text.to_string(),
    }
}

/// `items` joined by `, `, each cut by [`short_text`], at most [`MAX_LISTED`]
/// of them (then `… and N more`).
pub(crate) fn short_list<I, S>(items: I) -> String
where
    I: IntoIterator<Item = S>,
    S: AsRef<str>,
{
    let mut out = String::new();
    let mut more = 0usize;
    for (i, item) in items.into_iter().enumerate() {
        if i >= MAX_LISTED {
            more += 1;
            continue;
        }
        if i > 0 {
            out.push_str(", ");
        }
        out.push_str(&short_text(item.as_ref()));
    }
    if more > 0 {
        out.push_str(&format!(", … and {more} more"));
    }
    out
}

/// Wrap `err` into [`Error::InFile`].
pub(crate) fn in_file(path: &Path, location: String, err: Error) -> Error {
    Error::InFile {
        path: path.to_path_buf(),
        location,
        source: Box::new(err),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::options::{TimeUnit, Unit};

    #[test]
    fn units_are_converted_to_si() {
        let opts = ReadOptions {
            position_unit: Unit::Mm,
            time_unit: TimeUnit::Ms,
            ..Default::default()
        };
        let r = build_recording(
            Some(vec![0.0, 1.0, 2.0]),
            vec![0.0, 1.0, 2.0],
            vec![0.0, 0.5, 1.5],
            &opts,
        )
        .unwrap();
        assert!((r.rate_hz() - 1000.0).abs() < 1e-9);
        assert!((r.command()[2] - 2e-3).abs() < 1e-18);
        assert!((r.position()[1] - 0.5e-3).abs() < 1e-18);
    }

    #[test]
    fn rate_synthesises_time_from_zero() {
        let opts = ReadOptions {
            rate_hz: Some(500.0),
            ..Default::default()
        };
        let r = build_recording(None, vec![0.0; 4], vec![0.0; 4], &opts).unwrap();
        assert_eq!(r.time(), &[0.0, 0.002, 0.004, 0.006]);
    }

    #[test]
    fn messages_quote_and_list_at_most_a_line() {
        let long = "é".repeat(5000);
        let t = short_text(&long);
        assert_eq!(t, format!("{}… (10000 bytes)", "é".repeat(60)));
        assert_eq!(short_text("abc"), "abc");
        let names: Vec<String> = (0..100).map(|i| format!("c{i}")).collect();
        let l = short_list(&names);
        assert!(
            l.starts_with("c0, c1, ") && l.ends_with("c23, … and 76 more"),
            "{l}"
        );
        assert_eq!(short_list(["a", "b"]), "a, b");
    }
}
