//! Reading input files with bounded memory and time, whatever they hold.
//!
//! - **Lines** ([`LineReader`]) end at `\n`, `\r\n` or a lone `\r` (old Mac
//!   files); a line longer than [`MAX_LINE_BYTES`] is refused as soon as the
//!   limit is passed, without holding more of it; a NUL byte is refused at
//!   once (a binary file, `/dev/zero`); invalid UTF-8 is refused with its line.
//! - **Streams** — a FIFO, a character device, standard input — have no size
//!   to check beforehand: at most [`MAX_STREAM_BYTES`] are read from one,
//!   then it is refused (an endless source would otherwise fill the memory;
//!   a longer recording is read from a regular file).
//! - **Small files** (rig parameters, effects, models: [`read_small_text`])
//!   are refused beyond [`MAX_SMALL_FILE_BYTES`].
//!
//! So `feedid info /dev/zero` ends at its first byte, a 1 GB file of one
//! line after 1 MiB, and `yes 0,0,0 > fifo` at its second sample (the time
//! does not increase; see [`crate::io::read_csv`]).

use std::fs::File;
use std::io::{BufRead, Read};
use std::path::{Path, PathBuf};

use crate::error::{Error, InputKind, Result};

/// Longest line of a text file \[bytes\] (1 MiB).
pub const MAX_LINE_BYTES: usize = 1 << 20;

/// Most bytes read from a FIFO, character device or pipe (256 MiB, about
/// 20 minutes of three channels at 5 kHz as text): an endless source is
/// refused within seconds. A regular file has no such limit.
pub const MAX_STREAM_BYTES: u64 = 256 << 20;

/// Largest parameter, effects or model file \[bytes\] (16 MiB).
pub const MAX_SMALL_FILE_BYTES: u64 = 16 << 20;

fn io_error(path: &Path, source: std::io::Error) -> Error {
    Error::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// An opened input and the most bytes to read from it (`None`: a regular file, read to its end).
pub(crate) fn open_input(path: &Path) -> Result<(File, Option<u64>)> {
    let file = File::open(path).map_err(|e| io_error(path, e))?;
    let meta = file.metadata().map_err(|e| io_error(path, e))?;
    if meta.is_dir() {
        return Err(io_error(
            path,
            std::io::Error::other("is a directory, not a file"),
        ));
    }
    let limit = (!meta.is_file()).then_some(MAX_STREAM_BYTES);
    Ok((file, limit))
}

/// Read everything from `r`, refusing more than `limit` bytes
/// ([`Error::InputTooLarge`] of `kind`).
pub(crate) fn read_to_end_bounded<R: Read>(
    r: R,
    limit: Option<u64>,
    path: &Path,
    kind: InputKind,
) -> Result<Vec<u8>> {
    let mut bytes = Vec::new();
    match limit {
        None => {
            let mut r = r;
            r.read_to_end(&mut bytes).map_err(|e| io_error(path, e))?;
        }
        Some(limit) => {
            r.take(limit.saturating_add(1))
                .read_to_end(&mut bytes)
                .map_err(|e| io_error(path, e))?;
            if bytes.len() as u64 > limit {
                return Err(Error::InputTooLarge {
                    path: path.to_path_buf(),
                    limit,
                    kind,
                });
            }
        }
    }
    Ok(bytes)
}

/// Read a whole input file (a stream at most [`MAX_STREAM_BYTES`]).
pub(crate) fn read_file(path: &Path) -> Result<Vec<u8>> {
    let (file, limit) = open_input(path)?;
    read_to_end_bounded(file, limit, path, InputKind::Stream)
}

/// Read a small text file (rig parameters, effects, a model): at most
/// [`MAX_SMALL_FILE_BYTES`], UTF-8, no NUL byte.
pub fn read_small_text(path: &Path) -> Result<String> {
    read_text_up_to(path, MAX_SMALL_FILE_BYTES)
}

/// Read a text file of at most `limit` bytes (UTF-8, no NUL byte), e.g. a
/// learning history, which holds a command and an error per sample.
pub fn read_text_up_to(path: &Path, limit: u64) -> Result<String> {
    let (file, _) = open_input(path)?;
    let bytes = read_to_end_bounded(file, Some(limit), path, InputKind::TextFile)?;
    if let Some(i) = bytes.iter().position(|&b| b == 0) {
        return Err(Error::Malformed {
            path: path.to_path_buf(),
            line: 1 + bytes[..i].iter().filter(|&&b| b == b'\n').count(),
            reason: format!("NUL byte at byte {}: a binary file, not text", i + 1),
        });
    }
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let bytes = e.as_bytes();
        Error::Malformed {
            path: path.to_path_buf(),
            line: 1 + bytes[..at].iter().filter(|&&b| b == b'\n').count(),
            reason: "invalid UTF-8 (is this a text file?)".into(),
        }
    })
}

/// Lines of a text input with bounded memory (see the module doc).
#[derive(Debug)]
pub(crate) struct LineReader<R> {
    inner: R,
    path: PathBuf,
    buf: Vec<u8>,
    /// 1-based number of the last line returned.
    line: usize,
    /// A `\r` ended the last line: a `\n` right after it belongs to it.
    after_cr: bool,
    /// Bytes consumed so far.
    total: u64,
    limit: Option<u64>,
    done: bool,
}

impl<R: BufRead> LineReader<R> {
    /// Lines of `inner`; at most `limit` bytes are read (`None`: no limit).
    pub(crate) fn new(inner: R, path: &Path, limit: Option<u64>) -> Self {
        Self {
            inner,
            path: path.to_path_buf(),
            buf: Vec::new(),
            line: 0,
            after_cr: false,
            total: 0,
            limit,
            done: false,
        }
    }

    fn malformed(&self, line: usize, reason: String) -> Error {
        Error::Malformed {
            path: self.path.clone(),
            line,
            reason,
        }
    }

    fn consume(&mut self, n: usize) -> Result<()> {
        self.inner.consume(n);
        self.total += n as u64;
        match self.limit {
            Some(limit) if self.total > limit => Err(Error::InputTooLarge {
                path: self.path.clone(),
                limit,
                kind: InputKind::Stream,
            }),
            _ => Ok(()),
        }
    }

    /// The next line (without its ending) and its 1-based number, or `None` at the end.
    #[cfg(test)]
    pub(crate) fn next_line(&mut self) -> Result<Option<(usize, &str)>> {
        match self.read_raw()? {
            None => Ok(None),
            Some(no) => Ok(Some((no, self.checked_text(no)?))),
        }
    }

    /// The next line that is neither blank nor a comment (`#`), as
    /// [`LineReader::next_line`]; a UTF-8 byte-order mark opening the first
    /// line is dropped.
    pub(crate) fn next_content_line(&mut self) -> Result<Option<(usize, &str)>> {
        loop {
            let Some(no) = self.read_raw()? else {
                return Ok(None);
            };
            let t = self.checked_text(no)?.trim();
            let t = if no == 1 {
                t.strip_prefix('\u{feff}').unwrap_or(t).trim()
            } else {
                t
            };
            if t.is_empty() || t.starts_with('#') {
                continue;
            }
            let text = self.checked_text(no)?;
            let text = if no == 1 {
                text.strip_prefix('\u{feff}').unwrap_or(text)
            } else {
                text
            };
            return Ok(Some((no, text)));
        }
    }

    /// For a live stream, where one bad line must not end the input: the
    /// next line that is neither blank nor a comment, as
    /// [`LineReader::next_content_line`], or the error of an unusable line
    /// (longer than [`MAX_LINE_BYTES`], a NUL byte, invalid UTF-8) once the
    /// rest of it has been skipped. The outer error (reading failed, the byte
    /// limit) is fatal.
    pub(crate) fn next_content_line_or_skip(
        &mut self,
    ) -> Result<Option<(usize, std::result::Result<&str, Error>)>> {
        loop {
            let no = self.line + 1;
            match self.read_raw() {
                Ok(None) => return Ok(None),
                Ok(Some(no)) => {
                    let usable = match self.checked_text(no) {
                        Err(e) => return Ok(Some((no, Err(e)))),
                        Ok(t) => {
                            let t = t.trim();
                            let t = if no == 1 {
                                t.strip_prefix('\u{feff}').unwrap_or(t).trim()
                            } else {
                                t
                            };
                            !(t.is_empty() || t.starts_with('#'))
                        }
                    };
                    if usable {
                        let text = self.checked_text(no)?;
                        let text = if no == 1 {
                            text.strip_prefix('\u{feff}').unwrap_or(text)
                        } else {
                            text
                        };
                        return Ok(Some((no, Ok(text))));
                    }
                }
                Err(e @ Error::Malformed { .. }) => {
                    self.skip_rest_of_line()?;
                    self.line = no;
                    return Ok(Some((no, Err(e))));
                }
                Err(e) => return Err(e),
            }
        }
    }

    /// Consume the input up to and including the next line end (after a
    /// line that was refused part way).
    fn skip_rest_of_line(&mut self) -> Result<()> {
        loop {
            let chunk = match self.inner.fill_buf() {
                Ok(c) => c,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(io_error(&self.path, e)),
            };
            if chunk.is_empty() {
                self.done = true;
                return Ok(());
            }
            match chunk.iter().position(|&b| b == b'\n' || b == b'\r') {
                Some(i) => {
                    self.after_cr = chunk[i] == b'\r';
                    return self.consume(i + 1);
                }
                None => {
                    let n = chunk.len();
                    self.consume(n)?;
                }
            }
        }
    }

    /// The line in the buffer as text, or an error naming line `no`.
    fn checked_text(&self, no: usize) -> Result<&str> {
        std::str::from_utf8(&self.buf).map_err(|e| {
            self.malformed(
                no,
                format!(
                    "invalid UTF-8 at byte {} of the line (is this a text file?)",
                    e.valid_up_to() + 1
                ),
            )
        })
    }

    /// Read the next line into the buffer; its number, or `None` at the end.
    fn read_raw(&mut self) -> Result<Option<usize>> {
        if self.done {
            return Ok(None);
        }
        self.buf.clear();
        let no = self.line + 1;
        loop {
            let chunk = match self.inner.fill_buf() {
                Ok(c) => c,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(io_error(&self.path, e)),
            };
            if chunk.is_empty() {
                self.done = true;
                if self.buf.is_empty() {
                    return Ok(None);
                }
                break;
            }
            if self.after_cr {
                self.after_cr = false;
                if chunk[0] == b'\n' {
                    self.consume(1)?;
                    continue;
                }
            }
            let end = chunk
                .iter()
                .position(|&b| b == b'\n' || b == b'\r' || b == 0);
            let take = end.unwrap_or(chunk.len());
            if self.buf.len() + take > MAX_LINE_BYTES {
                return Err(self.malformed(
                    no,
                    format!(
                        "longer than {MAX_LINE_BYTES} bytes (1 MiB) without a line end: not a text recording"
                    ),
                ));
            }
            self.buf.extend_from_slice(&chunk[..take]);
            match end.map(|i| chunk[i]) {
                None => self.consume(take)?,
                Some(0) => {
                    return Err(self.malformed(
                        no,
                        format!(
                            "NUL byte at byte {} of the line: a binary file, not text{}",
                            self.buf.len() + 1,
                            " (a MAT-file needs the .mat extension or its 128-byte header)"
                        ),
                    ))
                }
                Some(b) => {
                    self.after_cr = b == b'\r';
                    self.consume(take + 1)?;
                    break;
                }
            }
        }
        self.line = no;
        Ok(Some(no))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lines(bytes: &[u8]) -> Result<Vec<(usize, String)>> {
        let p = Path::new("t.csv");
        let mut r = LineReader::new(bytes, p, None);
        let mut out = Vec::new();
        while let Some((no, t)) = r.next_line()? {
            out.push((no, t.to_string()));
        }
        Ok(out)
    }

    #[test]
    fn every_line_ending_is_read_and_numbered() {
        let want = vec![(1, "a".into()), (2, "b".into()), (3, "c".into())];
        for text in [
            &b"a\nb\nc\n"[..],
            b"a\r\nb\r\nc\r\n",
            b"a\rb\rc\r",
            b"a\rb\nc",
        ] {
            assert_eq!(lines(text).unwrap(), want, "{text:?}");
        }
        assert_eq!(
            lines(b"a\n\nb").unwrap(),
            vec![(1, "a".into()), (2, "".into()), (3, "b".into())]
        );
        assert!(lines(b"").unwrap().is_empty());
    }

    #[test]
    fn crlf_split_across_buffer_refills_is_one_ending() {
        // a BufReader of 3 bytes splits `\r` and `\n` into two reads
        let data = b"ab\r\ncd\r\nef";
        let r = std::io::BufReader::with_capacity(3, &data[..]);
        let mut lr = LineReader::new(r, Path::new("x"), None);
        let mut got = Vec::new();
        while let Some((no, t)) = lr.next_line().unwrap() {
            got.push((no, t.to_string()));
        }
        assert_eq!(
            got,
            vec![(1, "ab".into()), (2, "cd".into()), (3, "ef".into())]
        );
    }

    #[test]
    fn nul_bytes_and_invalid_utf8_are_named_with_their_line() {
        let e = lines(b"ok\nx\0y\n").unwrap_err();
        assert!(matches!(e, Error::Malformed { line: 2, .. }), "{e}");
        assert!(e.to_string().contains("NUL byte at byte 2"), "{e}");
        let e = lines(b"ok\n\xff\n").unwrap_err();
        assert!(matches!(e, Error::Malformed { line: 2, .. }), "{e}");
    }

    #[test]
    fn an_endless_line_is_refused_after_the_limit_without_reading_on() {
        // an endless reader of 'x': refused once the limit is passed
        let endless = std::io::repeat(b'x');
        let r = std::io::BufReader::new(endless);
        let mut lr = LineReader::new(r, Path::new("zero"), None);
        let e = lr.next_line().unwrap_err();
        assert!(e.to_string().contains("longer than 1048576 bytes"), "{e}");
        assert!(lr.total <= (MAX_LINE_BYTES as u64) + 8192, "{}", lr.total);
        // /dev/zero: the first byte
        let r = std::io::BufReader::new(std::io::repeat(0));
        let e = LineReader::new(r, Path::new("zero"), None)
            .next_line()
            .unwrap_err();
        assert!(e.to_string().contains("NUL byte at byte 1"), "{e}");
    }

    #[test]
    fn a_live_stream_skips_unusable_lines_and_goes_on() {
        let mut data = b"a\n\x00b\n\xff\r\n# c\n\n".to_vec();
        data.extend(std::iter::repeat_n(b'x', MAX_LINE_BYTES + 5000));
        data.extend_from_slice(b"\r\nd\re");
        let r = std::io::BufReader::with_capacity(4096, &data[..]);
        let mut lr = LineReader::new(r, Path::new("stdin"), None);
        let mut got = Vec::new();
        while let Some((no, l)) = lr.next_content_line_or_skip().unwrap() {
            got.push((no, l.map(str::to_string).map_err(|e| e.to_string())));
        }
        let numbers: Vec<usize> = got.iter().map(|g| g.0).collect();
        assert_eq!(numbers, [1, 2, 3, 6, 7, 8], "{got:?}");
        assert_eq!(got[0].1, Ok("a".to_string()));
        assert!(got[1].1.as_ref().unwrap_err().contains("NUL"), "{got:?}");
        assert!(got[2].1.as_ref().unwrap_err().contains("UTF-8"), "{got:?}");
        assert!(
            got[3].1.as_ref().unwrap_err().contains("longer than"),
            "{got:?}"
        );
        assert_eq!(got[4].1, Ok("d".to_string()));
        assert_eq!(got[5].1, Ok("e".to_string()));
    }

    #[test]
    fn a_stream_beyond_its_limit_is_refused() {
        let endless = std::io::BufReader::new(std::io::repeat(b'\n'));
        let mut lr = LineReader::new(endless, Path::new("fifo"), Some(1000));
        let e = loop {
            match lr.next_line() {
                Ok(Some(_)) => continue,
                Ok(None) => panic!("an endless stream ended"),
                Err(e) => break e,
            }
        };
        assert!(matches!(e, Error::InputTooLarge { limit: 1000, .. }), "{e}");
        let e = read_to_end_bounded(
            std::io::repeat(1),
            Some(10),
            Path::new("d"),
            InputKind::Stream,
        )
        .unwrap_err();
        assert!(matches!(e, Error::InputTooLarge { .. }), "{e}");
        assert_eq!(
            read_to_end_bounded(&b"abc"[..], Some(3), Path::new("d"), InputKind::Stream).unwrap(),
            b"abc"
        );
    }

    #[test]
    fn small_text_files_refuse_binary_content() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("rig.toml");
        std::fs::write(&p, b"[a]\nb = 1\0\n").unwrap();
        let e = read_small_text(&p).unwrap_err();
        assert!(matches!(e, Error::Malformed { line: 2, .. }), "{e}");
        std::fs::write(&p, "[a]\nb = 1\n").unwrap();
        assert_eq!(read_small_text(&p).unwrap(), "[a]\nb = 1\n");
        let e = read_small_text(dir.path()).unwrap_err();
        assert!(e.to_string().contains("directory"), "{e}");
        if Path::new("/dev/zero").exists() {
            let e = read_small_text(Path::new("/dev/zero")).unwrap_err();
            assert!(matches!(e, Error::InputTooLarge { .. }), "{e}");
        }
    }
}
