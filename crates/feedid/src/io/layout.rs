//! The layout of a delimited text recording — its delimiter, whether its
//! first row is a header, which columns hold time, command and position —
//! found from its first lines by the rules of [`crate::io::read_csv`], and
//! the parse of one row with it ([`TextLayout::row`], which allocates
//! nothing). The file reader decides the layout from the first fifty lines,
//! the line-by-line reader of a live stream ([`crate::io::StreamReader`])
//! from the first two (it cannot wait for fifty); both parse every row with
//! [`TextLayout::row`].

use std::path::Path;

use crate::error::{Error, Result};
use crate::io::columns::short_text;
use crate::io::options::{
    ChannelRef, ReadOptions, DEFAULT_COMMAND_COLUMN, DEFAULT_POSITION_COLUMN, DEFAULT_TIME_COLUMN,
};
use crate::io::text::{
    decimal_comma_hint, detect_delimiter, for_each_field, number_like, parse_number,
    resolve_column, split_checked, Delim, Line,
};

/// Which columns hold time, command and position when the options name none
/// and the text has no header.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Headerless {
    /// The default names (`time_s`, `command_m`, `position_m`) need a header
    /// (the file reader's rule).
    ByName,
    /// Time, command, position are columns 1, 2, 3 (command and position 1
    /// and 2 with a sampling rate), as `feedid simulate` writes them.
    ByIndex,
}

/// Delimiter, header and columns of a text recording.
#[derive(Debug, Clone)]
pub(crate) struct TextLayout {
    pub(super) delim: Delim,
    /// Fields in every row.
    pub(super) ncols: usize,
    /// The header's cells, if the first line is a header.
    pub(super) header: Option<Vec<String>>,
    /// The first line: the header, or the row whose field count every row must have.
    pub(super) first_line: usize,
    /// Columns (0-based) of time (`None` with a sampling rate), command and position.
    pub(super) time_col: Option<usize>,
    pub(super) cmd_col: usize,
    pub(super) pos_col: usize,
}

/// One row's time (`None` with a sampling rate), command and position, in
/// the file's units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RawRow {
    pub(crate) time: Option<f64>,
    pub(crate) command: f64,
    pub(crate) position: f64,
}

impl TextLayout {
    /// The layout from the first content lines `head` (at least one; the
    /// delimiter is detected from all of them, the header from the first
    /// two).
    pub(crate) fn detect(
        head: &[Line<'_>],
        opts: &ReadOptions,
        path: &Path,
        headerless: Headerless,
    ) -> Result<Self> {
        let Some(first) = head.first() else {
            return Err(Error::Malformed {
                path: path.to_path_buf(),
                line: 1,
                reason: "the file is empty (no header, no data rows)".into(),
            });
        };
        let delim = match opts.delimiter {
            None => detect_delimiter(head),
            Some(b' ') => Delim::Whitespace,
            Some(b) => Delim::Byte(b),
        };
        let mut fields: Vec<&str> = Vec::new();
        let mut below: Vec<&str> = Vec::new();
        split_checked(first, delim, path, &mut fields)?;
        let has_header = match opts.header {
            Some(h) => h,
            None => match head.get(1) {
                Some(second) => {
                    split_checked(second, delim, path, &mut below)?;
                    fields.iter().enumerate().any(|(i, c)| {
                        !number_like(c) && below.get(i).is_some_and(|b| number_like(b))
                    })
                }
                None => fields.iter().any(|c| !number_like(c)),
            },
        };
        let header: Option<Vec<String>> =
            has_header.then(|| fields.iter().map(|s| s.to_string()).collect());
        let ncols = fields.len();
        let names = header.as_deref();
        let resolve =
            |r: &ChannelRef, role: &str| resolve_column(r, names, ncols, path, role, first.no);
        let default = |o: &Option<ChannelRef>, name: &str, index: usize| {
            o.clone().unwrap_or_else(|| {
                if names.is_none() && headerless == Headerless::ByIndex {
                    ChannelRef::Index(index)
                } else {
                    ChannelRef::Name(name.to_string())
                }
            })
        };
        let rate = opts.rate_hz.is_some();
        let first_value = if rate { 1 } else { 2 };
        let time_col = match (&opts.time, rate) {
            (None, true) => None,
            (t, _) => Some(resolve(&default(t, DEFAULT_TIME_COLUMN, 1), "time")?),
        };
        let cmd_col = resolve(
            &default(&opts.command, DEFAULT_COMMAND_COLUMN, first_value),
            "command",
        )?;
        let pos_col = resolve(
            &default(&opts.position, DEFAULT_POSITION_COLUMN, first_value + 1),
            "position",
        )?;
        Ok(Self {
            delim,
            ncols,
            header,
            first_line: first.no,
            time_col,
            cmd_col,
            pos_col,
        })
    }

    /// Whether the first line is a header.
    pub(crate) fn has_header(&self) -> bool {
        self.header.is_some()
    }

    /// Column `i` (0-based) by its header name, else its 1-based number.
    pub(crate) fn col_name(&self, i: usize) -> String {
        match self.header.as_deref().and_then(|n| n.get(i)) {
            Some(n) if !n.is_empty() => n.clone(),
            _ => (i + 1).to_string(),
        }
    }

    /// Split one data row and read its time, command and position:
    /// [`Error::Malformed`] for a wrong number of fields or a bad quote,
    /// [`Error::BadNumber`] naming the column for a cell that is not a number.
    pub(crate) fn row(&self, line: &Line<'_>, path: &Path) -> Result<RawRow> {
        let want = [self.time_col, Some(self.cmd_col), Some(self.pos_col)];
        let mut cells = [""; 3];
        let mut n = 0usize;
        for_each_field(line.text, self.delim, |f| {
            for (cell, col) in cells.iter_mut().zip(want) {
                if col == Some(n) {
                    *cell = f;
                }
            }
            n += 1;
        })
        .map_err(|reason| Error::Malformed {
            path: path.to_path_buf(),
            line: line.no,
            reason: reason.to_string(),
        })?;
        if n != self.ncols {
            let hint = if self.delim == Delim::Byte(b',') && n > self.ncols {
                "; if the file uses decimal commas, convert them to decimal points"
            } else {
                ""
            };
            return Err(Error::Malformed {
                path: path.to_path_buf(),
                line: line.no,
                reason: format!(
                    "{n} fields, expected {} as in line {}{hint}",
                    self.ncols, self.first_line
                ),
            });
        }
        let cell = |i: usize| -> Result<f64> {
            let text = cells[i];
            parse_number(text).ok_or_else(|| Error::BadNumber {
                path: path.to_path_buf(),
                line: line.no,
                column: want[i].map_or_else(String::new, |c| self.col_name(c)),
                text: short_text(text),
                hint: decimal_comma_hint(text, self.delim),
            })
        };
        Ok(RawRow {
            time: match self.time_col {
                Some(_) => Some(cell(0)?),
                None => None,
            },
            command: cell(1)?,
            position: cell(2)?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lines<'a>(text: &'a [&'a str]) -> Vec<Line<'a>> {
        text.iter()
            .enumerate()
            .map(|(i, t)| Line { no: i + 1, text: t })
            .collect()
    }

    #[test]
    fn simulate_output_is_read_by_name_and_headerless_rows_by_index() {
        let p = Path::new("stdin");
        let head = [
            "time_s,command_m,position_m,true_position_m,current_a,velocity_m_per_s",
            "0.0002,1e-6,2e-6,0,0,0",
        ];
        let l = TextLayout::detect(
            &lines(&head),
            &ReadOptions::default(),
            p,
            Headerless::ByIndex,
        )
        .unwrap();
        assert!(l.has_header());
        let r = l.row(&lines(&head)[1], p).unwrap();
        assert_eq!((r.time, r.command, r.position), (Some(2e-4), 1e-6, 2e-6));
        // no header: columns 1, 2, 3 (by name: an error naming the columns)
        let head = ["0 1 2", "1 2 3"];
        let l = TextLayout::detect(
            &lines(&head),
            &ReadOptions::default(),
            p,
            Headerless::ByIndex,
        )
        .unwrap();
        assert!(!l.has_header());
        let r = l.row(&lines(&head)[1], p).unwrap();
        assert_eq!((r.time, r.command, r.position), (Some(1.0), 2.0, 3.0));
        let e = TextLayout::detect(
            &lines(&head),
            &ReadOptions::default(),
            p,
            Headerless::ByName,
        )
        .unwrap_err();
        assert!(e.to_string().contains("no header"), "{e}");
        // with a rate: command and position are columns 1 and 2
        let opts = ReadOptions {
            rate_hz: Some(100.0),
            ..ReadOptions::default()
        };
        let head = ["5;6", "7;8"];
        let l = TextLayout::detect(&lines(&head), &opts, p, Headerless::ByIndex).unwrap();
        let r = l.row(&lines(&head)[0], p).unwrap();
        assert_eq!((r.time, r.command, r.position), (None, 5.0, 6.0));
    }

    #[test]
    fn rows_are_checked_as_the_file_reader_checks_them() {
        let p = Path::new("stdin");
        let head = ["t\tu\ty\textra", "0\t1\t2\tx"];
        let opts = ReadOptions {
            time: Some(ChannelRef::Name("t".into())),
            command: Some(ChannelRef::Index(2)),
            position: Some(ChannelRef::Name("Y".into())),
            ..ReadOptions::default()
        };
        let l = TextLayout::detect(&lines(&head), &opts, p, Headerless::ByIndex).unwrap();
        let row = |t: &str| l.row(&Line { no: 7, text: t }, p);
        assert_eq!(row("1\t2\t3\tz").unwrap().position, 3.0);
        let e = row("1\t2\t3").unwrap_err();
        assert!(
            matches!(e, Error::Malformed { line: 7, .. })
                && e.to_string().contains("3 fields, expected 4 as in line 1"),
            "{e}"
        );
        match row("1\tabc\t3\tz").unwrap_err() {
            Error::BadNumber { line, column, .. } => assert_eq!((line, column.as_str()), (7, "u")),
            e => panic!("{e}"),
        }
        match row("1\t2\t0,5\tz").unwrap_err() {
            Error::BadNumber { hint, .. } => assert!(hint.contains("decimal comma")),
            e => panic!("{e}"),
        }
        let e = TextLayout::detect(
            &lines(&head),
            &ReadOptions::default(),
            p,
            Headerless::ByIndex,
        )
        .unwrap_err();
        assert!(e.to_string().contains("time_s"), "{e}");
    }
}
