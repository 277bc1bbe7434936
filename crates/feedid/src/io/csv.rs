//! Reading recordings from CSV and other delimited text files.
//!
//! Format rules:
//!
//! - **Lines**: `\n`, `\r\n` or `\r` endings; a UTF-8 byte-order mark is
//!   ignored; blank lines and lines starting with `#` are skipped (line
//!   numbers in errors are those of the file, 1-based). A line over 1 MiB, a
//!   NUL byte or invalid UTF-8 is refused where it occurs, and so is more
//!   than 256 MiB from a pipe or device ([`crate::io::MAX_STREAM_BYTES`]):
//!   memory stays bounded whatever the input.
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
//!   index; defaults `time_s`, `command_m`, `position_m`. A name that
//!   several columns carry is refused for time, command and position
//!   ("ambiguous: select one by its number"), never resolved silently. Without a time column,
//!   [`ReadOptions::rate_hz`] gives `t_k = k / rate`.
//! - **Numbers** are parsed strictly (Rust `f64` syntax: `-1.5e-3`, `.5`;
//!   `NaN`/`inf` are read and then refused as non-finite). A cell like `1,25`
//!   is reported as a decimal comma, which is not supported — never misread.
//!   Every row must have as many fields as the header (or the first row).
//! - **Extra columns**: every other column whose cells are all finite numbers
//!   is attached to the recording as an extra channel, unscaled, named by its
//!   header (or `col<N>` without header; `NAME@N` when several columns are
//!   named `NAME`, with a note on the recording); other columns are ignored.
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

use std::io::{BufRead, BufReader};
use std::path::Path;

use crate::error::{Error, Result};
use crate::io::columns::{build_recording, failing_sample, in_file, short_list, Role};
use crate::io::layout::{Headerless, TextLayout};
use crate::io::options::ReadOptions;
use crate::io::source::{open_input, LineReader};
use crate::io::text::{parse_number, split_checked, Line, DETECT_ROWS};
use crate::recording::Recording;

/// An owned [`Line`] (the first rows, kept for the detection).
struct OwnedLine {
    no: usize,
    text: String,
}

impl OwnedLine {
    fn view(&self) -> Line<'_> {
        Line {
            no: self.no,
            text: &self.text,
        }
    }
}

/// Read a recording from a delimited text file (see the module doc for the format).
///
/// The file is read line by line with bounded memory
/// ([`crate::io::source`]): a line beyond 1 MiB, a NUL byte, invalid UTF-8
/// and, from a pipe or device, more than 256 MiB are refused where they occur;
/// so are a ragged row, a cell that is not a number and a time that does not
/// increase, without reading further.
pub fn read_csv(path: &Path, opts: &ReadOptions) -> Result<Recording> {
    opts.validate()?;
    let (file, limit) = open_input(path)?;
    let mut lines = LineReader::new(BufReader::with_capacity(1 << 16, file), path, limit);
    parse_text(&mut lines, path, opts)
}

/// Read a recording from text coming from `reader` (at most `limit` bytes).
pub(crate) fn read_csv_from_reader<R: std::io::Read>(
    reader: R,
    path: &Path,
    opts: &ReadOptions,
    limit: Option<u64>,
) -> Result<Recording> {
    opts.validate()?;
    let mut lines = LineReader::new(BufReader::with_capacity(1 << 16, reader), path, limit);
    parse_text(&mut lines, path, opts)
}

/// Read a recording from text in memory; `source` names it in errors.
pub fn read_csv_from_str(text: &str, source: &Path, opts: &ReadOptions) -> Result<Recording> {
    read_csv_from_bytes(text.as_bytes(), source, opts)
}

/// Read a recording from bytes in memory (checked to be UTF-8 line by line); `source` names them in errors.
pub fn read_csv_from_bytes(bytes: &[u8], source: &Path, opts: &ReadOptions) -> Result<Recording> {
    opts.validate()?;
    let mut lines = LineReader::new(bytes, source, None);
    parse_text(&mut lines, source, opts)
}

/// The next line that is neither blank nor a comment.
fn next_content<'r, R: BufRead>(lines: &'r mut LineReader<R>) -> Result<Option<Line<'r>>> {
    Ok(lines
        .next_content_line()?
        .map(|(no, text)| Line { no, text }))
}

/// Parse the lines of a text recording (see the module doc for the format).
fn parse_text<R: BufRead>(
    lines: &mut LineReader<R>,
    path: &Path,
    opts: &ReadOptions,
) -> Result<Recording> {
    // the first rows, for the delimiter and the header
    let mut head: Vec<OwnedLine> = Vec::new();
    while head.len() < DETECT_ROWS {
        match next_content(lines)? {
            Some(l) => head.push(OwnedLine {
                no: l.no,
                text: l.text.to_string(),
            }),
            None => break,
        }
    }
    let head_lines: Vec<Line<'_>> = head.iter().map(OwnedLine::view).collect();
    let layout = TextLayout::detect(&head_lines, opts, path, Headerless::ByName)?;
    let header_line = layout.first_line;
    let data_head = if layout.has_header() {
        head_lines.get(1..).unwrap_or_default()
    } else {
        &head_lines[..]
    };
    if data_head.is_empty() {
        return Err(Error::Malformed {
            path: path.to_path_buf(),
            line: header_line,
            reason: "header only, no data rows".into(),
        });
    }
    let (ncols, time_col, cmd_col, pos_col) = (
        layout.ncols,
        layout.time_col,
        layout.cmd_col,
        layout.pos_col,
    );
    let names = layout.header.as_deref();
    let col_name = |i: usize| layout.col_name(i);

    // Parse the rows as they are read.
    let mut rows = Rows {
        path,
        layout: &layout,
        time_factor: opts.time_unit.factor(),
        time: time_col.map(|_| Vec::new()),
        command: Vec::new(),
        position: Vec::new(),
        extras: (0..ncols)
            .map(|c| {
                let used = Some(c) == time_col || c == cmd_col || c == pos_col;
                (!used && !opts.signals_only).then(Vec::new)
            })
            .collect(),
        dropped: Vec::new(),
        row_lines: RowLines::default(),
    };
    for line in data_head {
        rows.push(line)?;
    }
    drop(head_lines);
    drop(head);
    while let Some(line) = next_content(lines)? {
        rows.push(&line)?;
    }
    let Rows {
        time,
        command,
        position,
        extras,
        dropped,
        row_lines,
        ..
    } = rows;

    let mut rec = build_recording(time, command, position, opts).map_err(|e| {
        let location = match failing_sample(&e) {
            Some((k, role)) => {
                let line = row_lines.line(k).unwrap_or(0);
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
    // extra channels; a name given to several columns gets `@column` on each
    let name_of = |c: usize| match names.and_then(|n| n.get(c)) {
        Some(n) if !n.is_empty() => n.clone(),
        _ => format!("col{}", c + 1),
    };
    let kept: Vec<bool> = extras.iter().map(Option::is_some).collect();
    // the columns of each header name, gathered once (a file may have
    // 100 000 columns: no comparison of every column with every other)
    let mut by_name: std::collections::HashMap<String, Vec<usize>> =
        std::collections::HashMap::new();
    if names.is_some() {
        for i in 0..ncols {
            by_name.entry(name_of(i)).or_default().push(i);
        }
    }
    for (c, slot) in extras.into_iter().enumerate() {
        let Some(v) = slot else { continue };
        let name = name_of(c);
        let same: &[usize] = by_name.get(&name).map_or(&[], Vec::as_slice);
        if same.len() > 1 {
            rec = rec.with_channel(&format!("{name}@{}", c + 1), v)?;
            if same.iter().find(|&&i| kept[i]) == Some(&c) {
                rec = rec.with_note(format!(
                    "columns {} of the header are all named `{name}`: the extra channels are called {}",
                    short_list(same.iter().map(|i| (i + 1).to_string())),
                    short_list(
                        same.iter()
                            .filter(|&&i| kept[i])
                            .map(|i| format!("{name}@{}", i + 1))
                    )
                ));
            }
        } else {
            rec = rec.with_channel(&name, v)?;
        }
    }
    // an extra column left out says so (`info` lists it among the warnings)
    for (c, line, cell) in dropped {
        rec = rec.with_note(format!(
            "column {} (`{}`) is not kept as a channel: line {line} holds `{cell}`, not a finite number",
            c + 1,
            name_of(c)
        ));
    }
    Ok(rec)
}

/// The columns being collected, row by row.
struct Rows<'p, 'l> {
    path: &'p Path,
    layout: &'l TextLayout,
    time_factor: f64,
    time: Option<Vec<f64>>,
    command: Vec<f64>,
    position: Vec<f64>,
    extras: Vec<Option<Vec<f64>>>,
    /// Extra columns left out: `(column, line, the cell)` of the first
    /// cell that is not a finite number.
    dropped: Vec<(usize, usize, String)>,
    row_lines: RowLines,
}

/// The file line (1-based) of each data row, kept as the rows where the
/// numbering jumps (after a header, blank or comment line): `(row, line)`
/// pairs. A file without blank lines costs one pair instead of a `usize`
/// per row, which matters for an hour at 5 kHz (18 M rows).
#[derive(Debug, Default, Clone, PartialEq)]
struct RowLines {
    rows: usize,
    jumps: Vec<(usize, usize)>,
}

impl RowLines {
    /// Record that the next row is on file line `line`.
    fn push(&mut self, line: usize) {
        let continues = self
            .jumps
            .last()
            .is_some_and(|&(r, l)| l + (self.rows - r) == line);
        if !continues {
            self.jumps.push((self.rows, line));
        }
        self.rows += 1;
    }

    /// The file line of data row `row` (0-based), if there is such a row.
    fn line(&self, row: usize) -> Option<usize> {
        if row >= self.rows {
            return None;
        }
        let i = self.jumps.partition_point(|&(r, _)| r <= row);
        let (r, l) = *self.jumps.get(i.checked_sub(1)?)?;
        Some(l + (row - r))
    }
}

impl Rows<'_, '_> {
    /// Parse one data row ([`TextLayout::row`]: field count, numbers) and
    /// check that the time increases (here, so that a bad stream stops at
    /// once; the other checks of [`Recording`] run once everything is read);
    /// the extra columns are kept while all their cells are numbers.
    fn push(&mut self, line: &Line<'_>) -> Result<()> {
        let path = self.path;
        let row = self.layout.row(line, path)?;
        if let (Some(t), Some(v), Some(c)) = (self.time.as_mut(), row.time, self.layout.time_col) {
            if let Some(&prev) = t.last() {
                if v.is_finite() && prev.is_finite() && v <= prev {
                    return Err(in_file(
                        path,
                        format!("line {}, column `{}`", line.no, self.layout.col_name(c)),
                        Error::NonMonotoneTime {
                            index: t.len(),
                            previous: prev * self.time_factor,
                            value: v * self.time_factor,
                        },
                    ));
                }
            }
            t.push(v);
        }
        self.command.push(row.command);
        self.position.push(row.position);
        if self.extras.iter().any(Option::is_some) {
            let mut fields: Vec<&str> = Vec::with_capacity(self.layout.ncols);
            split_checked(line, self.layout.delim, path, &mut fields)?;
            for (c, slot) in self.extras.iter_mut().enumerate() {
                if let Some(v) = slot {
                    match fields.get(c).and_then(|s| parse_number(s)) {
                        Some(x) if crate::recording::is_usable(x) => v.push(x),
                        _ => {
                            let cell: String = fields
                                .get(c)
                                .map_or("", |s| s.trim())
                                .chars()
                                .take(40)
                                .collect();
                            self.dropped.push((c, line.no, cell));
                            *slot = None;
                        }
                    }
                }
            }
        }
        self.row_lines.push(line.no);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::options::ChannelRef;
    use crate::io::text::DECIMAL_COMMA_HINT;

    fn read(text: &str) -> Result<Recording> {
        read_csv_from_str(text, Path::new("t.csv"), &ReadOptions::default())
    }

    #[test]
    fn a_file_of_twenty_thousand_columns_names_its_channels_and_repeated_names() {
        // the columns sharing a name are gathered once (comparing every
        // column with every other took minutes at 100 000 columns)
        let n = 20_000;
        let mut names: Vec<String> = (0..n).map(|i| format!("c{i}")).collect();
        names[n - 1] = "c7".to_string();
        let mut text = format!("time_s,command_m,position_m,{}\n", names.join(","));
        let ones = vec!["1"; n].join(",");
        for k in 0..20 {
            text += &format!("{},{},{},{ones}\n", k as f64 * 1e-3, k as f64 * 1e-6, 0.0);
        }
        let r = read(&text).unwrap();
        assert_eq!(r.extra().len(), n);
        assert_eq!(r.extra()[7].0, "c7@11");
        assert_eq!(r.extra()[n - 1].0, format!("c7@{}", n + 3));
        assert_eq!(r.notes().len(), 1, "{:?}", r.notes());
        assert!(
            r.notes()[0].contains(&format!("columns 11, {}", n + 3)),
            "{:?}",
            r.notes()
        );
    }

    #[test]
    fn an_extra_column_left_out_says_where_and_why() {
        let r = read(
            "time_s,command_m,position_m,extra,ok\n0,0,0,1,1\n0.001,0,0,nan,2\n0.002,0,0,3,3\n",
        )
        .unwrap();
        let names: Vec<&str> = r.extra().iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["ok"]);
        assert_eq!(r.notes().len(), 1, "{:?}", r.notes());
        let n = &r.notes()[0];
        assert!(
            n.contains("column 4 (`extra`)") && n.contains("line 3") && n.contains("`nan`"),
            "{n}"
        );
    }

    fn read_with(text: &str, opts: ReadOptions) -> Result<Recording> {
        read_csv_from_str(text, Path::new("t.csv"), &opts)
    }

    const ROWS: &str = "0 0 0\n0.001 1 0.5\n0.002 2 1.5\n";

    #[test]
    fn row_lines_give_the_line_of_every_row_as_a_plain_list_would() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(19);
        for case in 0..200 {
            // increasing line numbers with random gaps (blank and comment lines)
            let n = rng.random_range(0..300);
            let mut line = rng.random_range(1..4);
            let mut plain = Vec::new();
            let mut map = RowLines::default();
            for _ in 0..n {
                if rng.random_bool(if case % 2 == 0 { 0.05 } else { 0.5 }) {
                    line += rng.random_range(1..5);
                }
                plain.push(line);
                map.push(line);
                line += 1;
            }
            for k in 0..n + 2 {
                assert_eq!(map.line(k), plain.get(k).copied(), "case {case} row {k}");
            }
        }
        // a file without gaps costs one pair
        let mut map = RowLines::default();
        (2..100_002).for_each(|l| map.push(l));
        assert_eq!(map.jumps, vec![(0, 2)]);
        assert_eq!(map.line(99_999), Some(100_001));
    }

    #[test]
    fn signals_only_reads_the_same_signals_without_the_extra_columns() {
        let text = "# export\ntime_s,command_m,position_m,current_a,note\n0,0,0,1.5,a\n\n0.001,1e-6,2e-7,2.5,b\n0.002,2e-6,9e-7,3.5,c\n";
        let all = read(text).unwrap();
        assert_eq!(all.extra().len(), 1);
        let opts = ReadOptions {
            signals_only: true,
            ..Default::default()
        };
        let only = read_with(text, opts.clone()).unwrap();
        assert!(only.extra().is_empty());
        assert_eq!(only.time(), all.time());
        assert_eq!(only.command(), all.command());
        assert_eq!(only.position(), all.position());
        // errors still name the file's line after a blank one
        let bad = "time_s,command_m,position_m,current_a\n0,0,0,1\n\n0.001,0,NaN,2\n";
        let e = read_with(bad, opts).unwrap_err().to_string();
        assert!(e.starts_with("t.csv: line 4, column `position_m`"), "{e}");
    }

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
    fn cr_only_line_endings_are_read_like_newlines() {
        let text = "time_s,command_m,position_m\r0,0,0\r0.001,1,0.5\r0.002,2,1.5\r";
        let r = read(text).unwrap();
        assert_eq!(r.command(), &[0.0, 1.0, 2.0]);
        let e = read("time_s,command_m,position_m\r0,0,0\r0.001,x,0\r").unwrap_err();
        assert!(matches!(e, Error::BadNumber { line: 3, .. }), "{e}");
    }

    #[test]
    fn nul_bytes_are_named_with_line_and_byte() {
        let bytes = b"time_s,command_m,position_m\n0,0,0\n0.001,\x001,0\n";
        let e =
            read_csv_from_bytes(bytes, Path::new("b.csv"), &ReadOptions::default()).unwrap_err();
        assert!(matches!(e, Error::Malformed { line: 3, .. }), "{e}");
        assert!(e.to_string().contains("NUL byte at byte 7"), "{e}");
    }

    #[test]
    fn a_used_column_named_twice_is_refused_and_others_are_renamed() {
        let text = "time_s,command_m,position_m,position_m\n0,0,0,9\n0.001,1,1,9\n";
        let e = read(text).unwrap_err();
        let msg = e.to_string();
        assert!(
            matches!(e, Error::Malformed { line: 1, .. })
                && msg.contains("position column `position_m` is ambiguous")
                && msg.contains("columns 3, 4"),
            "{msg}"
        );
        // by index it is read, and the unused duplicate is named
        let opts = ReadOptions {
            position: Some(ChannelRef::Index(3)),
            ..Default::default()
        };
        let r = read_with(text, opts).unwrap();
        assert_eq!(r.position(), &[0.0, 1.0]);
        assert_eq!(r.extra()[0].0, "position_m@4");
        assert!(
            r.notes()[0].contains("called position_m@4"),
            "{:?}",
            r.notes()
        );
        // two unused columns of one name: both kept, renamed, and a note says so
        let text = "time_s,command_m,position_m,i,i\n0,0,0,1,2\n0.001,1,1,3,4\n";
        let r = read(text).unwrap();
        let names: Vec<&str> = r.extra().iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, vec!["i@4", "i@5"]);
        assert_eq!(r.notes().len(), 1, "{:?}", r.notes());
        assert!(r.notes()[0].contains("columns 4, 5"), "{:?}", r.notes());
        // case-insensitive twins are ambiguous too
        let e = read("time_s,Command_M,COMMAND_M,position_m\n0,0,0,0\n1,1,1,1\n").unwrap_err();
        assert!(e.to_string().contains("ambiguous"), "{e}");
    }

    #[test]
    fn an_endless_stream_stops_at_its_first_bad_row_or_at_the_limit() {
        // `yes 0,0,0`: the time does not increase at the second row
        struct Yes(&'static [u8], usize);
        impl std::io::Read for Yes {
            fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
                let mut n = 0;
                while n < buf.len() {
                    buf[n] = self.0[self.1 % self.0.len()];
                    self.1 += 1;
                    n += 1;
                }
                Ok(n)
            }
        }
        let e = read_csv_from_reader(
            Yes(b"0,0,0\n", 0),
            Path::new("fifo"),
            &ReadOptions {
                time: Some(ChannelRef::Index(1)),
                command: Some(ChannelRef::Index(2)),
                position: Some(ChannelRef::Index(3)),
                ..Default::default()
            },
            Some(1 << 30),
        )
        .unwrap_err();
        assert!(
            matches!(e.root(), Error::NonMonotoneTime { index: 1, .. })
                && e.to_string().contains("line 2"),
            "{e}"
        );
        // increasing time forever: refused at the limit
        struct Counter(u64, Vec<u8>);
        impl std::io::Read for Counter {
            fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
                if self.1.is_empty() {
                    self.0 += 1;
                    self.1 = format!("{},0,0\n", self.0).into_bytes();
                }
                let n = buf.len().min(self.1.len());
                buf[..n].copy_from_slice(&self.1[..n]);
                self.1.drain(..n);
                Ok(n)
            }
        }
        let e = read_csv_from_reader(
            Counter(0, b"time_s,command_m,position_m\n".to_vec()),
            Path::new("fifo"),
            &ReadOptions::default(),
            Some(100_000),
        )
        .unwrap_err();
        assert!(matches!(e, Error::InputTooLarge { .. }), "{e}");
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
