//! The fields of a delimited text recording, shared by the file reader
//! (`csv.rs`), the layout detection (`layout.rs`) and the live stream
//! (`stream.rs`): lines, delimiter detection, splitting and quoting,
//! numbers, the decimal-comma hint and resolving a column by name or index.

use std::path::Path;

use crate::error::{Error, Result};
use crate::io::columns::short_list;
use crate::io::options::ChannelRef;

/// Hint appended to [`Error::BadNumber`] when a cell looks like a decimal comma.
pub const DECIMAL_COMMA_HINT: &str = "; decimal comma is not supported; convert to a decimal point";

/// Number of rows looked at to detect the delimiter.
pub(super) const DETECT_ROWS: usize = 50;

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

/// Find a column by name (exact, else case-insensitive) or 1-based index.
/// A name that several columns carry is refused (never the first taken
/// silently); `role` (`time`, `command`, `position`) names the choice.
pub(super) fn resolve_column(
    r: &ChannelRef,
    header: Option<&[String]>,
    ncols: usize,
    path: &Path,
    role: &str,
    header_line: usize,
) -> Result<usize> {
    let missing = |available: String| Error::MissingChannel {
        path: path.to_path_buf(),
        kind: "column",
        name: r.to_string(),
        available,
    };
    let by_index = || format!("columns 1 to {ncols} by index (the file has no header row)");
    let ambiguous = |n: &str, cols: &[usize]| {
        Error::Malformed {
        path: path.to_path_buf(),
        line: header_line,
        reason: format!(
            "the {role} column `{n}` is ambiguous: columns {} of the header are all named so; select one by its number",
            short_list(cols.iter().map(|c| (c + 1).to_string()))
        ),
    }
    };
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
        (ChannelRef::Name(n), Some(h)) => {
            let exact: Vec<usize> = (0..h.len()).filter(|&i| h[i] == *n).collect();
            let matches = if exact.is_empty() {
                (0..h.len())
                    .filter(|&i| h[i].eq_ignore_ascii_case(n))
                    .collect()
            } else {
                exact
            };
            match matches.as_slice() {
                [] => Err(missing(short_list(h))),
                [i] => Ok(*i),
                many => Err(ambiguous(n, many)),
            }
        }
        (ChannelRef::Name(_), None) => Err(missing(by_index())),
    }
}
