//! Reading a live text stream line by line: each line is parsed as soon as
//! it has arrived, with the same options and rules as a text file
//! ([`crate::io::read_csv`]: columns by name or index, header detection,
//! delimiter, units, scale, time unit, sampling rate), and a line that cannot
//! be read is reported with its number and skipped — a live stream cannot be
//! refused as a whole.
//!
//! Differences from a file, all because the stream cannot wait:
//!
//! - the delimiter and the header are decided from the **first two** content
//!   lines (a file uses fifty);
//! - without a header, and with no column given, time, command and position
//!   are columns 1, 2 and 3 (command and position 1 and 2 with a sampling
//!   rate) — what `feedid simulate` writes, without its header;
//! - with a sampling rate, line `k` of the data (counting lines that were
//!   skipped: each was a sample) has `t = k / rate`;
//! - the values are not checked here (finite, time increasing, intervals):
//!   that is the streamer's part ([`crate::ident::stream::Streamer`]);
//! - lines are read as a file's are (`\n`, `\r\n` or `\r` endings, a byte-order
//!   mark, blank and `#` lines skipped), but a line over [`MAX_STREAM_LINE`]
//!   bytes, with a NUL byte, or not UTF-8 is skipped, not fatal: the rest of
//!   it is read without being held, so memory stays bounded; and there is no
//!   limit on the input's length (a file from a pipe has 256 MiB).
//!
//! Every line is parsed without allocating ([`StreamLine::Sample`]);
//! [`PredictionRows`] writes what a stream predicts.
//!
//! ```
//! use feedid::io::{ReadOptions, StreamLine, StreamReader, Unit};
//! let text = "time_s,command_m,position_m\n0,0,0\n0.001,1,0.5\n0.002,x,1\n";
//! let opts = ReadOptions { position_unit: Unit::Mm, ..ReadOptions::default() };
//! let mut r = StreamReader::new(text.as_bytes(), "stdin".as_ref(), &opts).unwrap();
//! assert!(matches!(r.next_line().unwrap(), Some(StreamLine::Header { line: 1 })));
//! assert!(matches!(r.next_line().unwrap(), Some(StreamLine::Sample { line: 2, .. })));
//! match r.next_line().unwrap() {
//!     Some(StreamLine::Sample { time, command, position, .. }) => {
//!         assert_eq!((time, command, position), (0.001, 1e-3, 0.5e-3));
//!     }
//!     other => panic!("{other:?}"),
//! }
//! assert!(matches!(r.next_line().unwrap(), Some(StreamLine::Skipped { line: 4, .. })));
//! assert!(r.next_line().unwrap().is_none());
//! ```

use std::collections::VecDeque;
use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::io::layout::{Headerless, TextLayout};
use crate::io::options::ReadOptions;
use crate::io::source::LineReader;
use crate::io::text::Line;

/// Longest line of a stream \[bytes\] (1 MiB, [`crate::io::MAX_LINE_BYTES`]);
/// a longer one is skipped.
pub const MAX_STREAM_LINE: usize = crate::io::source::MAX_LINE_BYTES;

/// What one content line of a stream was (blank and `#` lines are not reported).
#[derive(Debug)]
pub enum StreamLine {
    /// The header row.
    Header {
        /// 1-based line number.
        line: usize,
    },
    /// A sample, in SI units.
    Sample {
        /// 1-based line number.
        line: usize,
        /// Time \[s\].
        time: f64,
        /// Command \[m\].
        command: f64,
        /// Measured position \[m\].
        position: f64,
    },
    /// A line that could not be read (wrong field count, not a number, too
    /// long, not UTF-8, a NUL byte); the error names the line and column.
    Skipped {
        /// 1-based line number.
        line: usize,
        /// Why.
        error: Error,
    },
}

/// Reads a text stream line by line (see the module doc).
#[derive(Debug)]
pub struct StreamReader<R> {
    lines: LineReader<R>,
    path: PathBuf,
    opts: ReadOptions,
    layout: Option<TextLayout>,
    /// Data lines so far (samples and skipped lines after the header).
    data_rows: usize,
    /// Events of the first lines, decided together with the layout.
    queued: VecDeque<StreamLine>,
    done: bool,
}

impl<R: BufRead> StreamReader<R> {
    /// A reader of `input`; `source` names it in errors (`stdin`). The
    /// options are checked here.
    pub fn new(input: R, source: &Path, opts: &ReadOptions) -> Result<Self> {
        opts.validate()?;
        Ok(Self {
            // a live stream has no byte limit: it may run for days
            lines: LineReader::new(input, source, None),
            path: source.to_path_buf(),
            opts: opts.clone(),
            layout: None,
            data_rows: 0,
            queued: VecDeque::new(),
            done: false,
        })
    }

    /// The next content line, `None` at the end of the input. An error is
    /// fatal: reading failed, or the first lines do not have the columns asked for.
    pub fn next_line(&mut self) -> Result<Option<StreamLine>> {
        if let Some(e) = self.queued.pop_front() {
            return Ok(Some(e));
        }
        if self.done {
            return Ok(None);
        }
        if self.layout.is_none() {
            self.start()?;
            return Ok(self.queued.pop_front());
        }
        let Self {
            lines,
            path,
            opts,
            layout,
            data_rows,
            ..
        } = self;
        let Some(layout) = layout.as_ref() else {
            return Ok(None);
        };
        let event = match lines.next_content_line_or_skip()? {
            None => {
                self.done = true;
                return Ok(None);
            }
            Some((line, Err(error))) => StreamLine::Skipped { line, error },
            Some((no, Ok(text))) => sample(layout, &Line { no, text }, path, opts, *data_rows),
        };
        *data_rows += 1;
        Ok(Some(event))
    }

    /// Read the first two usable lines, decide the layout from them and
    /// queue the events of every line read so far.
    fn start(&mut self) -> Result<()> {
        let mut read: Vec<(usize, std::result::Result<String, Error>)> = Vec::new();
        while read.iter().filter(|(_, r)| r.is_ok()).count() < 2 {
            match self.lines.next_content_line_or_skip()? {
                None => break,
                Some((no, r)) => read.push((no, r.map(str::to_string))),
            }
        }
        let usable = read.iter().any(|(_, r)| r.is_ok());
        if !usable {
            // nothing usable: report the bad lines, then the end
            for (line, r) in read {
                if let Err(error) = r {
                    self.queued.push_back(StreamLine::Skipped { line, error });
                }
            }
            self.done = true;
            return Ok(());
        }
        let (layout, header_line) = {
            let head: Vec<Line<'_>> = read
                .iter()
                .filter_map(|(no, r)| r.as_ref().ok().map(|text| Line { no: *no, text }))
                .collect();
            let layout = TextLayout::detect(&head, &self.opts, &self.path, Headerless::ByIndex)?;
            let header_line = layout.has_header().then(|| head[0].no);
            (layout, header_line)
        };
        for (line, r) in read {
            let event = match r {
                Err(error) => {
                    self.data_rows += 1;
                    StreamLine::Skipped { line, error }
                }
                Ok(_) if Some(line) == header_line => StreamLine::Header { line },
                Ok(text) => {
                    let l = Line {
                        no: line,
                        text: &text,
                    };
                    let e = sample(&layout, &l, &self.path, &self.opts, self.data_rows);
                    self.data_rows += 1;
                    e
                }
            };
            self.queued.push_back(event);
        }
        self.layout = Some(layout);
        Ok(())
    }
}

/// The sample of a data line (or why it is skipped); `row` is its index among the data lines.
fn sample(
    layout: &TextLayout,
    line: &Line<'_>,
    path: &Path,
    opts: &ReadOptions,
    row: usize,
) -> StreamLine {
    match layout.row(line, path) {
        Ok(r) => {
            let f = opts.position_factor();
            let time = match (r.time, opts.rate_hz) {
                (Some(t), _) => t * opts.time_unit.factor(),
                (None, Some(rate)) => row as f64 / rate,
                (None, None) => f64::NAN,
            };
            StreamLine::Sample {
                line: line.no,
                time,
                command: r.command * f,
                position: r.position * f,
            }
        }
        Err(error) => StreamLine::Skipped {
            line: line.no,
            error,
        },
    }
}

/// Columns of the rows a stream writes, in order: time, prediction and its
/// interval. Later columns are appended, never inserted: read them by name.
pub const PREDICTION_COLUMNS: [&str; 4] = ["time_s", "predicted_m", "lower_m", "upper_m"];

/// Writes streamed predictions as CSV rows, one per predicted sample
/// ([`PREDICTION_COLUMNS`]; shortest round-trip numbers), and flushes after
/// each prediction so that a reader has it at once. Writes nothing else; a
/// write error is returned as it is (the caller tells a closed pipe from a
/// full disk).
#[derive(Debug)]
pub struct PredictionRows<W: Write> {
    out: W,
    rows: usize,
}

impl<W: Write> PredictionRows<W> {
    /// A writer to `out`; nothing is written yet.
    pub fn new(out: W) -> Self {
        Self { out, rows: 0 }
    }

    /// Write the header line and flush.
    pub fn header(&mut self) -> std::io::Result<()> {
        writeln!(self.out, "{}", PREDICTION_COLUMNS.join(","))?;
        self.out.flush()
    }

    /// Write one prediction — time stamps \[s\], predicted positions \[m\]
    /// and the bounds of their intervals \[m\] of its horizon samples
    /// (equal lengths) — and flush.
    pub fn write(
        &mut self,
        time: &[f64],
        position: &[f64],
        lower: &[f64],
        upper: &[f64],
    ) -> std::io::Result<()> {
        for (((t, y), lo), hi) in time.iter().zip(position).zip(lower).zip(upper) {
            writeln!(self.out, "{t},{y},{lo},{hi}")?;
            self.rows += 1;
        }
        self.out.flush()
    }

    /// Rows written so far.
    pub fn rows(&self) -> usize {
        self.rows
    }
}

/// Columns of the rows of an online compensation (`feedid stream
/// --compensate`), in order: the time of the sample the command is for, its
/// desired position and the command to send.
pub const COMMAND_COLUMNS: [&str; 3] = ["time_s", "desired_m", "command_m"];

/// Writes the commands of an online compensation as CSV rows
/// ([`COMMAND_COLUMNS`]; shortest round-trip numbers), flushing after each
/// so that the drive has it at once. Writes nothing else.
#[derive(Debug)]
pub struct CommandRows<W: Write> {
    out: W,
    rows: usize,
}

impl<W: Write> CommandRows<W> {
    /// A writer to `out`; nothing is written yet.
    pub fn new(out: W) -> Self {
        Self { out, rows: 0 }
    }

    /// Write the header line and flush.
    pub fn header(&mut self) -> std::io::Result<()> {
        writeln!(self.out, "{}", COMMAND_COLUMNS.join(","))?;
        self.out.flush()
    }

    /// Write one command — its sample's time \[s\], desired position \[m\]
    /// and the command \[m\] — and flush.
    pub fn write(&mut self, time: f64, desired: f64, command: f64) -> std::io::Result<()> {
        writeln!(self.out, "{time},{desired},{command}")?;
        self.rows += 1;
        self.out.flush()
    }

    /// Rows written so far.
    pub fn rows(&self) -> usize {
        self.rows
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn all(text: &[u8], opts: &ReadOptions) -> Result<Vec<StreamLine>> {
        let mut r = StreamReader::new(text, Path::new("stdin"), opts)?;
        let mut out = Vec::new();
        while let Some(l) = r.next_line()? {
            out.push(l);
        }
        Ok(out)
    }

    fn samples(lines: &[StreamLine]) -> Vec<(usize, f64, f64, f64)> {
        lines
            .iter()
            .filter_map(|l| match l {
                StreamLine::Sample {
                    line,
                    time,
                    command,
                    position,
                } => Some((*line, *time, *command, *position)),
                _ => None,
            })
            .collect()
    }

    fn skipped(lines: &[StreamLine]) -> Vec<(usize, String)> {
        lines
            .iter()
            .filter_map(|l| match l {
                StreamLine::Skipped { line, error } => Some((*line, error.to_string())),
                _ => None,
            })
            .collect()
    }

    #[test]
    fn the_same_text_gives_the_same_samples_as_the_file_reader() {
        let text = "# exported\r\ntime_ms;x_mm;cmd_mm\r\n0;0;0\r\n\r\n1;0.5;1\r\n2;1.5;2\r\n";
        let opts = ReadOptions {
            time: Some("time_ms".parse().unwrap()),
            command: Some("3".parse().unwrap()),
            position: Some("x_mm".parse().unwrap()),
            position_unit: "mm".parse().unwrap(),
            time_unit: "ms".parse().unwrap(),
            ..ReadOptions::default()
        };
        let lines = all(text.as_bytes(), &opts).unwrap();
        assert!(matches!(lines[0], StreamLine::Header { line: 2 }));
        let rec = crate::io::read_csv_from_str(text, Path::new("f.csv"), &opts).unwrap();
        let s = samples(&lines);
        assert_eq!(s.iter().map(|r| r.0).collect::<Vec<_>>(), [3, 5, 6]);
        for (k, (_, t, u, y)) in s.iter().enumerate() {
            assert_eq!(
                (*t, *u, *y),
                (rec.time()[k], rec.command()[k], rec.position()[k])
            );
        }
    }

    #[test]
    fn bad_lines_are_skipped_with_their_number_and_the_stream_goes_on() {
        let mut text = b"time_s,command_m,position_m\n0,0,0\n".to_vec();
        text.extend_from_slice(b"1,abc,0\n1,2\n\xff\xfe,0,0\nx\0y\n");
        text.extend(std::iter::repeat_n(b'7', MAX_STREAM_LINE + 10));
        text.extend_from_slice(b"\n2,2,2\n3,3,3");
        let lines = all(&text, &ReadOptions::default()).unwrap();
        let s = skipped(&lines);
        let numbers: Vec<usize> = s.iter().map(|e| e.0).collect();
        assert_eq!(numbers, [3, 4, 5, 6, 7], "{s:?}");
        assert!(s[0].1.contains("column `command_m`"), "{}", s[0].1);
        assert!(s[1].1.contains("2 fields, expected 3"), "{}", s[1].1);
        assert!(s[2].1.contains("UTF-8"), "{}", s[2].1);
        assert!(s[3].1.contains("NUL"), "{}", s[3].1);
        assert!(s[4].1.contains("longer than"), "{}", s[4].1);
        let got: Vec<usize> = samples(&lines).iter().map(|r| r.0).collect();
        assert_eq!(got, [2, 8, 9]);
    }

    #[test]
    fn a_rate_counts_every_data_line_as_a_sample_slot() {
        let opts = ReadOptions {
            rate_hz: Some(1000.0),
            ..ReadOptions::default()
        };
        let lines = all(b"1 2\n3 4\nbad\n5 6\n", &opts).unwrap();
        let t: Vec<f64> = samples(&lines).iter().map(|r| r.1).collect();
        assert_eq!(t, [0.0, 0.001, 0.003]);
        assert_eq!(skipped(&lines).len(), 1);
    }

    #[test]
    fn bad_first_lines_are_reported_and_do_not_decide_the_layout() {
        let lines = all(
            b"\xff\ntime_s,command_m,position_m\n0,1,2\n",
            &ReadOptions::default(),
        )
        .unwrap();
        assert_eq!(skipped(&lines).len(), 1);
        assert!(matches!(lines[1], StreamLine::Header { line: 2 }));
        assert_eq!(samples(&lines), [(3, 0.0, 1.0, 2.0)]);
        // nothing but bad lines, or nothing at all: no sample, no error
        assert_eq!(
            all(b"\xff\n\0\n", &ReadOptions::default()).unwrap().len(),
            2
        );
        assert!(all(b"", &ReadOptions::default()).unwrap().is_empty());
        assert!(all(b"\n# only a comment\n", &ReadOptions::default())
            .unwrap()
            .is_empty());
        // columns that are not there: fatal
        let e = all(b"a,b\n1,2\n", &ReadOptions::default()).unwrap_err();
        assert!(e.to_string().contains("time_s"), "{e}");
        let e = all(b"1,2\n3,4\n", &ReadOptions::default()).unwrap_err();
        assert!(
            e.to_string().contains("no column `3`") || e.to_string().contains("`3`"),
            "{e}"
        );
    }

    proptest::proptest! {
        #[test]
        fn any_bytes_end_without_panic_and_every_line_is_reported_once(
            body in proptest::collection::vec(proptest::prelude::any::<u8>(), 0..400),
            sel in 0u8..8,
        ) {
            let opts = ReadOptions {
                rate_hz: (sel & 1 != 0).then_some(100.0),
                header: [None, Some(true), Some(false), None][(sel >> 1) as usize],
                ..ReadOptions::default()
            };
            if let Ok(lines) = all(&body, &opts) {
                let numbers: Vec<usize> = lines
                    .iter()
                    .map(|l| match l {
                        StreamLine::Header { line }
                        | StreamLine::Sample { line, .. }
                        | StreamLine::Skipped { line, .. } => *line,
                    })
                    .collect();
                proptest::prop_assert!(numbers.windows(2).all(|w| w[0] < w[1]), "{:?}", numbers);
                proptest::prop_assert!(numbers.len() <= body.len() + 1);
            }
        }
    }
}
