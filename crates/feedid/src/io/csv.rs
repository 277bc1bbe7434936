//! Reading recordings from CSV and other delimited text files.
//!
//! Format rules:
//!
//! - **Lines**: `\n` or `\r\n` endings; a UTF-8 byte-order mark is ignored;
//!   blank lines and lines starting with `#` are skipped (line numbers in
//!   errors are those of the file, 1-based).
//! - **Delimiter** ([`ReadOptions::delimiter`], default detected): the first of
//!   tab, `;`, `,`, runs of whitespace that splits the first 50 rows into the
//!   same number (> 1) of fields; failing that, the first that splits the first
//!   row into more than one field (`,` is skipped when it would leave cells
//!   like `5 1`, the mark of decimal commas in a whitespace-separated file).
//!   Cells are trimmed; a cell may be quoted
//!   (`"1.5"`); quotes are removed, with no escape sequences inside.
//! - **Header** ([`ReadOptions::header`], default detected): the first row is
//!   a header when one of its cells is not a number while the cell below it is
//!   (with a single row: when any cell is not a number).
//! - **Columns** by header name (exact, else case-insensitive) or 1-based
//!   index; defaults `time_s`, `command_m`, `position_m`. Without a time column,
//!   [`ReadOptions::rate_hz`] gives `t_k = k / rate`.
//! - **Numbers** are parsed strictly (Rust `f64` syntax: `-1.5e-3`, `.5`;
//!   `NaN`/`inf` are read and then refused as non-finite). A cell like `1,25`
//!   is reported as a decimal comma, which is not supported — never misread.
//!   Every row must have as many fields as the header (or the first row).
//! - **Extra columns**: every other column whose cells are all finite numbers
//!   is attached to the recording as an extra channel, unscaled, named by its
//!   header (or `col<N>` without header); other columns are ignored.
//!
//! Errors name the file and the 1-based line, and the column where one is
//! concerned: [`Error::BadNumber`], [`Error::Malformed`],
//! [`Error::MissingChannel`], and the checks of [`Recording`] wrapped in
//! [`Error::InFile`].
//!
//! ```
//! use feedid::io::{read_csv_from_str, ReadOptions};
//! let text = "time_s;command_m;position_m\n0;0;0\n0.001;1e-6;0\n0.002;2e-6;1e-6\n";
//! let rec = read_csv_from_str(text, "example.csv".as_ref(), &ReadOptions::default())?;
//! assert_eq!(rec.len(), 3);
//! assert!((rec.rate_hz() - 1000.0).abs() < 1e-6);
//! # Ok::<(), feedid::Error>(())
//! ```

use std::path::Path;

use crate::error::{Error, Result};
use crate::io::options::{
    ChannelRef, ReadOptions, DEFAULT_COMMAND_COLUMN, DEFAULT_POSITION_COLUMN, DEFAULT_TIME_COLUMN,
};
use crate::io::read::{
    build_recording, failing_sample, in_file, read_file, short_list, short_text, Role,
};
use crate::recording::Recording;

/// Hint appended to [`Error::BadNumber`] when a cell looks like a decimal comma.
pub const DECIMAL_COMMA_HINT: &str = "; decimal comma is not supported; convert to a decimal point";

/// Number of rows looked at to detect the delimiter.
const DETECT_ROWS: usize = 50;

/// A field delimiter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Delim {
    Byte(u8),
    Whitespace,
}

/// A non-blank, non-comment line with its 1-based number.
pub(super) struct Line<'a> {
    pub(super) no: usize,
    pub(super) text: &'a str,
}

/// Read a recording from a delimited text file (see the module doc for the format).
pub fn read_csv(path: &Path, opts: &ReadOptions) -> Result<Recording> {
    let bytes = read_file(path)?;
    read_csv_from_bytes(&bytes, path, opts)
}

/// Read a recording from text in memory; `source` names it in errors.
pub fn read_csv_from_str(text: &str, source: &Path, opts: &ReadOptions) -> Result<Recording> {
    read_csv_from_bytes(text.as_bytes(), source, opts)
}

/// Read a recording from bytes in memory (checked to be UTF-8 line by line); `source` names them in errors.
pub fn read_csv_from_bytes(bytes: &[u8], source: &Path, opts: &ReadOptions) -> Result<Recording> {
    opts.validate()?;
    let path = source;
    let lines = split_lines(bytes, path)?;
    let Some(first) = lines.first() else {
        return Err(Error::Malformed {
            path: path.to_path_buf(),
            line: 1,
            reason: "the file is empty (no header, no data rows)".into(),
        });
    };
    let delim = match opts.delimiter {
        None => detect_delimiter(&lines),
        Some(b' ') => Delim::Whitespace,
        Some(b) => Delim::Byte(b),
    };

    let mut fields: Vec<&str> = Vec::new();
    let mut below: Vec<&str> = Vec::new();
    split_checked(first, delim, path, &mut fields)?;
    let has_header = match opts.header {
        Some(h) => h,
        None => {
            if let Some(second) = lines.get(1) {
                split_checked(second, delim, path, &mut below)?;
                fields
                    .iter()
                    .enumerate()
                    .any(|(i, c)| !number_like(c) && below.get(i).is_some_and(|b| number_like(b)))
            } else {
                fields.iter().any(|c| !number_like(c))
            }
        }
    };
    let header: Option<Vec<String>> =
        has_header.then(|| fields.iter().map(|s| s.to_string()).collect());
    let ncols = fields.len();
    let data = if has_header {
        lines.get(1..).unwrap_or_default()
    } else {
        &lines[..]
    };
    if data.is_empty() {
        return Err(Error::Malformed {
            path: path.to_path_buf(),
            line: first.no,
            reason: "header only, no data rows".into(),
        });
    }

    // Resolve the columns.
    let names = header.as_deref();
    let resolve = |r: &ChannelRef| resolve_column(r, names, ncols, path);
    let default = |o: &Option<ChannelRef>, d: &str| {
        o.clone().unwrap_or_else(|| ChannelRef::Name(d.to_string()))
    };
    let time_col = match (&opts.time, opts.rate_hz) {
        (None, Some(_)) => None,
        (t, _) => Some(resolve(&default(t, DEFAULT_TIME_COLUMN))?),
    };
    let cmd_col = resolve(&default(&opts.command, DEFAULT_COMMAND_COLUMN))?;
    let pos_col = resolve(&default(&opts.position, DEFAULT_POSITION_COLUMN))?;
    let col_name = |i: usize| match names.and_then(|n| n.get(i)) {
        Some(n) if !n.is_empty() => n.clone(),
        _ => (i + 1).to_string(),
    };

    // Parse the rows.
    let n = data.len();
    let mut time = time_col.map(|_| Vec::with_capacity(n));
    let mut command = Vec::with_capacity(n);
    let mut position = Vec::with_capacity(n);
    let mut extras: Vec<Option<Vec<f64>>> = (0..ncols)
        .map(|c| {
            let used = Some(c) == time_col || c == cmd_col || c == pos_col;
            (!used).then(|| Vec::with_capacity(n))
        })
        .collect();
    let mut row_lines = Vec::with_capacity(n);
    let reference_line = data.first().map_or(first.no, |l| l.no);
    let reference_line = if has_header { first.no } else { reference_line };
    for line in data {
        split_checked(line, delim, path, &mut fields)?;
        if fields.len() != ncols {
            let hint = if delim == Delim::Byte(b',') && fields.len() > ncols {
                "; if the file uses decimal commas, convert them to decimal points"
            } else {
                ""
            };
            return Err(Error::Malformed {
                path: path.to_path_buf(),
                line: line.no,
                reason: format!(
                    "{} fields, expected {} as in line {}{}",
                    fields.len(),
                    ncols,
                    reference_line,
                    hint
                ),
            });
        }
        let cell = |c: usize| -> Result<f64> {
            let text = fields.get(c).copied().unwrap_or("");
            parse_number(text).ok_or_else(|| Error::BadNumber {
                path: path.to_path_buf(),
                line: line.no,
                column: col_name(c),
                text: short_text(text),
                hint: decimal_comma_hint(text, delim),
            })
        };
        if let (Some(t), Some(c)) = (time.as_mut(), time_col) {
            t.push(cell(c)?);
        }
        command.push(cell(cmd_col)?);
        position.push(cell(pos_col)?);
        for (c, slot) in extras.iter_mut().enumerate() {
            if let Some(v) = slot {
                match fields.get(c).and_then(|s| parse_number(s)) {
                    Some(x) if crate::recording::is_usable(x) => v.push(x),
                    _ => *slot = None,
                }
            }
        }
        row_lines.push(line.no);
    }

    let mut rec = build_recording(time, command, position, opts).map_err(|e| {
        let location = match failing_sample(&e) {
            Some((k, role)) => {
                let line = row_lines.get(k).copied().unwrap_or(0);
                let col = match role {
                    Some(Role::Time) => time_col,
                    Some(Role::Command) => Some(cmd_col),
                    Some(Role::Position) => Some(pos_col),
                    None => None,
                };
                match col {
                    Some(c) => format!("line {line}, column `{}`", col_name(c)),
                    None => format!("line {line}"),
                }
            }
            None => String::new(),
        };
        in_file(path, location, e)
    })?;
    for (c, slot) in extras.into_iter().enumerate() {
        if let Some(v) = slot {
            let name = match names.and_then(|n| n.get(c)) {
                Some(n) if !n.is_empty() => n.clone(),
                _ => format!("col{}", c + 1),
            };
            rec = rec.with_channel(&name, v)?;
        }
    }
    Ok(rec)
}

/// Split into lines, checking UTF-8 and skipping blank and `#` lines.
fn split_lines<'a>(bytes: &'a [u8], path: &Path) -> Result<Vec<Line<'a>>> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let mut out = Vec::new();
    for (i, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let raw = raw.strip_suffix(b"\r").unwrap_or(raw);
        let text = std::str::from_utf8(raw).map_err(|e| Error::Malformed {
            path: path.to_path_buf(),
            line: i + 1,
            reason: format!(
                "invalid UTF-8 at byte {} of the line (is this a text file?)",
                e.valid_up_to() + 1
            ),
        })?;
        let t = text.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        out.push(Line { no: i + 1, text });
    }
    Ok(out)
}

/// Pick the delimiter (see the module doc).
pub(super) fn detect_delimiter<'a>(lines: &[Line<'a>]) -> Delim {
    const CANDIDATES: [Delim; 4] = [
        Delim::Byte(b'\t'),
        Delim::Byte(b';'),
        Delim::Byte(b','),
        Delim::Whitespace,
    ];
    let sample = lines.get(..DETECT_ROWS).unwrap_or(lines);
    // Comma-splitting whitespace-separated decimal commas (`0,5 1,2`) leaves
    // cells like `5 1`; such a file is whitespace-separated.
    let mut cells: Vec<&'a str> = Vec::new();
    let split_numbers = sample.iter().any(|l| {
        split_fields(l.text, Delim::Byte(b','), &mut cells).is_ok()
            && cells.iter().any(|c| split_number(c))
    });
    let mut buf: Vec<&'a str> = Vec::new();
    let mut count = |line: &Line<'a>, d: Delim| -> Option<usize> {
        split_fields(line.text, d, &mut buf).ok().map(|_| buf.len())
    };
    for d in CANDIDATES {
        if d == Delim::Byte(b',') && split_numbers {
            continue;
        }
        let first = sample.first().and_then(|l| count(l, d));
        if let Some(n) = first.filter(|&n| n > 1) {
            if sample.iter().all(|l| count(l, d) == Some(n)) {
                return d;
            }
        }
    }
    for d in CANDIDATES {
        if sample
            .first()
            .and_then(|l| count(l, d))
            .is_some_and(|n| n > 1)
        {
            return d;
        }
    }
    Delim::Whitespace
}

/// Split a line, mapping quote errors to [`Error::Malformed`].
pub(super) fn split_checked<'a>(
    line: &Line<'a>,
    d: Delim,
    path: &Path,
    out: &mut Vec<&'a str>,
) -> Result<()> {
    split_fields(line.text, d, out).map_err(|reason| Error::Malformed {
        path: path.to_path_buf(),
        line: line.no,
        reason: reason.to_string(),
    })
}

/// Split `line` into trimmed fields; a field may be enclosed in double quotes.
fn split_fields<'a>(
    line: &'a str,
    d: Delim,
    out: &mut Vec<&'a str>,
) -> std::result::Result<(), &'static str> {
    out.clear();
    for_each_field(line, d, |f| out.push(f))
}

/// Call `field` with each trimmed field of `line` in order (see [`split_fields`]).
pub(super) fn for_each_field<'a>(
    line: &'a str,
    d: Delim,
    mut field: impl FnMut(&'a str),
) -> std::result::Result<(), &'static str> {
    let delim = match d {
        Delim::Whitespace => {
            for f in line.split_whitespace() {
                field(unquote(f));
            }
            return Ok(());
        }
        Delim::Byte(b) => b,
    };
    let bytes = line.as_bytes();
    let is_space = |b: u8| b != delim && (b == b' ' || b == b'\t');
    let mut i = 0;
    loop {
        while i < bytes.len() && is_space(bytes[i]) {
            i += 1;
        }
        if i < bytes.len() && bytes[i] == b'"' {
            let start = i + 1;
            let Some(len) = bytes[start..].iter().position(|&b| b == b'"') else {
                return Err("unterminated quoted field");
            };
            field(line.get(start..start + len).unwrap_or(""));
            i = start + len + 1;
            while i < bytes.len() && is_space(bytes[i]) {
                i += 1;
            }
            if i >= bytes.len() {
                return Ok(());
            }
            if bytes[i] != delim {
                return Err("text after a closing quote");
            }
            i += 1;
        } else {
            let end = bytes[i..]
                .iter()
                .position(|&b| b == delim)
                .map_or(bytes.len(), |p| i + p);
            field(line.get(i..end).unwrap_or("").trim());
            if end >= bytes.len() {
                return Ok(());
            }
            i = end + 1;
        }
    }
}

fn unquote(f: &str) -> &str {
    f.strip_prefix('"')
        .and_then(|s| s.strip_suffix('"'))
        .unwrap_or(f)
}

/// Strict number parse (trimmed Rust `f64` syntax).
pub(super) fn parse_number(s: &str) -> Option<f64> {
    s.trim().parse::<f64>().ok()
}

/// A number, or a number written with a decimal comma (for header detection).
pub(super) fn number_like(s: &str) -> bool {
    parse_number(s).is_some() || looks_decimal_comma(s)
}

/// `1,25` or `-0,5e-3`: exactly one comma, and a number once it is a point.
fn looks_decimal_comma(s: &str) -> bool {
    let t = s.trim();
    t.matches(',').count() == 1 && t.replace(',', ".").parse::<f64>().is_ok()
}

/// The decimal-comma hint for a cell that failed to parse, or `""`.
///
/// With `,` as delimiter, decimal commas in a whitespace-separated file show up
/// as cells like `5 1` (the tail of one number and the head of the next).
pub(super) fn decimal_comma_hint(text: &str, d: Delim) -> &'static str {
    if looks_decimal_comma(text) || (d == Delim::Byte(b',') && split_number(text)) {
        DECIMAL_COMMA_HINT
    } else {
        ""
    }
}

/// `5 1`: two digit groups separated by whitespace.
fn split_number(text: &str) -> bool {
    let mut parts = text.split_whitespace();
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit() || b == b'-');
    matches!((parts.next(), parts.next(), parts.next()), (Some(a), Some(b), None) if digits(a) && digits(b))
}

/// Find a column by name or 1-based index.
pub(super) fn resolve_column(
    r: &ChannelRef,
    header: Option<&[String]>,
    ncols: usize,
    path: &Path,
) -> Result<usize> {
    let missing = |available: String| Error::MissingChannel {
        path: path.to_path_buf(),
        kind: "column",
        name: r.to_string(),
        available,
    };
    let by_index = || format!("columns 1 to {ncols} by index (the file has no header row)");
    match (r, header) {
        (ChannelRef::Index(i), _) => {
            if (1..=ncols).contains(i) {
                Ok(i - 1)
            } else {
                Err(missing(match header {
                    Some(h) => format!("{} (columns 1 to {ncols})", short_list(h)),
                    None => by_index(),
                }))
            }
        }
        (ChannelRef::Name(n), Some(h)) => h
            .iter()
            .position(|c| c == n)
            .or_else(|| {
                let mut it = h
                    .iter()
                    .enumerate()
                    .filter(|(_, c)| c.eq_ignore_ascii_case(n));
                match (it.next(), it.next()) {
                    (Some((i, _)), None) => Some(i),
                    _ => None,
                }
            })
            .ok_or_else(|| missing(short_list(h))),
        (ChannelRef::Name(_), None) => Err(missing(by_index())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> Result<Recording> {
        read_csv_from_str(text, Path::new("t.csv"), &ReadOptions::default())
    }

    fn read_with(text: &str, opts: ReadOptions) -> Result<Recording> {
        read_csv_from_str(text, Path::new("t.csv"), &opts)
    }

    const ROWS: &str = "0 0 0\n0.001 1 0.5\n0.002 2 1.5\n";

    fn with_delim(d: &str) -> String {
        let mut s = format!("time_s{d}command_m{d}position_m\n");
        for row in ROWS.lines() {
            s.push_str(&row.split(' ').collect::<Vec<_>>().join(d));
            s.push('\n');
        }
        s
    }

    #[test]
    fn every_delimiter_is_detected_and_gives_same_values() {
        for d in [",", ";", "\t", "   ", ", "] {
            let r = read(&with_delim(d)).unwrap_or_else(|e| panic!("{d:?}: {e}"));
            assert_eq!(r.command(), &[0.0, 1.0, 2.0], "{d:?}");
            assert_eq!(r.position(), &[0.0, 0.5, 1.5], "{d:?}");
            assert!((r.rate_hz() - 1000.0).abs() < 1e-6);
        }
    }

    #[test]
    fn headerless_file_is_read_by_index() {
        let opts = ReadOptions {
            time: Some(ChannelRef::Index(1)),
            command: Some(ChannelRef::Index(2)),
            position: Some(ChannelRef::Index(3)),
            ..Default::default()
        };
        let r = read_with(ROWS, opts).unwrap();
        assert_eq!(r.len(), 3);
        // By name without header: a clear error.
        let e = read(ROWS).unwrap_err();
        assert!(e.to_string().contains("no header"), "{e}");
    }

    #[test]
    fn columns_by_index_override_defaults_and_extras_are_kept() {
        let text = "t,x,u,y\n0,9,0,0\n1,9,1,2\n2,9,2,3\n";
        let opts = ReadOptions {
            time: Some(ChannelRef::Index(1)),
            command: Some(ChannelRef::Name("U".into())),
            position: Some(ChannelRef::Index(4)),
            ..Default::default()
        };
        let r = read_with(text, opts).unwrap();
        assert_eq!(r.command(), &[0.0, 1.0, 2.0]);
        assert_eq!(r.position(), &[0.0, 2.0, 3.0]);
        assert_eq!(r.extra().len(), 1);
        assert_eq!(r.extra()[0].0, "x");
    }

    #[test]
    fn decimal_comma_is_reported_not_misread() {
        for text in [
            "time_s;command_m;position_m\n0;0;0\n0,001;1,5;0,5\n",
            "time_s\tcommand_m\tposition_m\n0,000\t0\t0\n0,001\t1\t0\n",
            "time_s command_m position_m\n0,000 0,5 0\n0,001 1 0\n",
            "0,000 0,5 0,1\n0,001 1,5 0,2\n",
        ] {
            let opts = ReadOptions {
                time: Some(ChannelRef::Index(1)),
                command: Some(ChannelRef::Index(2)),
                position: Some(ChannelRef::Index(3)),
                ..Default::default()
            };
            let e = if text.starts_with("time") {
                read(text)
            } else {
                read_with(text, opts)
            }
            .unwrap_err();
            match &e {
                Error::BadNumber { hint, .. } => assert_eq!(*hint, DECIMAL_COMMA_HINT, "{e}"),
                other => panic!("{text:?}: unexpected {other}"),
            }
        }
    }

    #[test]
    fn text_cell_reports_line_column_and_text() {
        let e = read("time_s,command_m,position_m\n0,0,0\n\n0.001,abc,0\n").unwrap_err();
        match e {
            Error::BadNumber {
                line,
                column,
                text,
                hint,
                ..
            } => {
                assert_eq!(
                    (line, column.as_str(), text.as_str(), hint),
                    (4, "command_m", "abc", "")
                );
            }
            other => panic!("unexpected {other}"),
        }
    }

    #[test]
    fn nan_is_refused_with_file_line_and_column() {
        let e = read("time_s,command_m,position_m\n0,0,0\n0.001,0,NaN\n0.002,0,0\n").unwrap_err();
        let msg = e.to_string();
        assert!(
            matches!(e.root(), Error::NonFinite { index: 1, .. }),
            "{msg}"
        );
        assert!(
            msg.starts_with("t.csv: line 3, column `position_m`"),
            "{msg}"
        );
    }

    #[test]
    fn decreasing_and_duplicate_time_name_line_and_values() {
        let e = read("time_s,command_m,position_m\n0,0,0\n0.002,0,0\n0.001,0,0\n").unwrap_err();
        let msg = e.to_string();
        assert!(
            matches!(e.root(), Error::NonMonotoneTime { index: 2, .. }),
            "{msg}"
        );
        assert!(
            msg.contains("line 4, column `time_s`")
                && msg.contains("0.002")
                && msg.contains("0.001"),
            "{msg}"
        );
        let e = read("time_s,command_m,position_m\n0,0,0\n0.001,0,0\n0.001,0,0\n").unwrap_err();
        assert!(
            matches!(e.root(), Error::NonMonotoneTime { index: 2, .. }),
            "{e}"
        );
    }

    #[test]
    fn jitter_beyond_tolerance_is_reported_with_line_and_tolerance_option_works() {
        let text =
            "time_s,command_m,position_m\n0,0,0\n0.001,0,0\n0.002,0,0\n0.0032,0,0\n0.0042,0,0\n";
        let e = read(text).unwrap_err();
        assert!(
            matches!(e.root(), Error::SamplingJitter { index: 3, .. }),
            "{e}"
        );
        assert!(e.to_string().contains("line 5"), "{e}");
        let opts = ReadOptions {
            jitter_tolerance: 0.25,
            ..Default::default()
        };
        let r = read_with(text, opts).unwrap();
        // nominal = mean interval 1.05 ms; worst interval 1.2 ms
        assert!((r.max_jitter() - 0.15 / 1.05).abs() < 1e-9);
    }

    #[test]
    fn ragged_row_is_malformed_with_line() {
        let e = read("time_s,command_m,position_m\n0,0,0\n0.001,0\n").unwrap_err();
        assert!(matches!(e, Error::Malformed { line: 3, .. }), "{e}");
    }

    #[test]
    fn empty_and_header_only_files_are_clear_errors() {
        let e = read("").unwrap_err();
        assert!(e.to_string().contains("empty"), "{e}");
        let e = read("\n# comment\n  \n").unwrap_err();
        assert!(e.to_string().contains("empty"), "{e}");
        let e = read("time_s,command_m,position_m\n").unwrap_err();
        assert!(
            matches!(e, Error::Malformed { line: 1, .. }) && e.to_string().contains("header only"),
            "{e}"
        );
        let e = read("time_s,command_m,position_m\n0,0,0\n").unwrap_err();
        assert!(
            matches!(e.root(), Error::TooFewSamples { actual: 1, .. }),
            "{e}"
        );
        assert!(e.to_string().starts_with("t.csv: "), "{e}");
    }

    #[test]
    fn invalid_utf8_is_malformed_with_line() {
        let bytes = b"time_s,command_m,position_m\n0,0,0\n0.001,\xff\xfe,0\n";
        let e =
            read_csv_from_bytes(bytes, Path::new("b.csv"), &ReadOptions::default()).unwrap_err();
        assert!(matches!(e, Error::Malformed { line: 3, .. }), "{e}");
    }

    #[test]
    fn missing_column_lists_available_ones() {
        let e = read("t,u,y\n0,0,0\n1,1,1\n").unwrap_err();
        match e {
            Error::MissingChannel {
                name, available, ..
            } => {
                assert_eq!(name, "time_s");
                assert_eq!(available, "t, u, y");
            }
            other => panic!("unexpected {other}"),
        }
    }

    #[test]
    fn encoder_counts_are_scaled_and_rate_synthesises_time() {
        let text = "command_m,position_m\n0,0\n100,90\n200,195\n";
        let opts = ReadOptions {
            rate_hz: Some(2000.0),
            scale: Some(1e-7),
            ..Default::default()
        };
        let r = read_with(text, opts).unwrap();
        assert!((r.command()[2] - 2e-5).abs() < 1e-18);
        assert!((r.position()[1] - 9e-6).abs() < 1e-18);
        assert_eq!(r.time(), &[0.0, 0.0005, 0.001]);
    }

    #[test]
    fn quoted_cells_crlf_bom_and_comments_are_accepted() {
        let text = "\u{feff}# exported\r\n\"time_s\",\"command_m\",\"position_m\"\r\n\"0\",\"0\",\"0\"\r\n\"0.001\",\"1\",\"1\"\r\n";
        let r = read(text).unwrap();
        assert_eq!(r.len(), 2);
        let e = read("time_s,command_m,position_m\n0,\"0,0\n").unwrap_err();
        assert!(matches!(e, Error::Malformed { line: 2, .. }), "{e}");
    }

    #[test]
    fn header_detection_ignores_text_columns_in_data() {
        // A text column in the data must not make row 1 a header.
        let text = "0,0,0,ok\n0.001,1,1,ok\n";
        let opts = ReadOptions {
            time: Some(ChannelRef::Index(1)),
            command: Some(ChannelRef::Index(2)),
            position: Some(ChannelRef::Index(3)),
            ..Default::default()
        };
        let r = read_with(text, opts).unwrap();
        assert_eq!(r.len(), 2);
        assert!(r.extra().is_empty());
    }
}
