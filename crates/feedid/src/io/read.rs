//! Reading a recording from any supported file: dispatch on content and
//! extension, unit conversion, and the checks of [`Recording`] with the
//! place in the file attached to their errors.
//!
//! Dispatch: a file whose first bytes are a MAT-file header (`MATLAB …` text
//! with the `IM`/`MI` endianness indicator at byte 126, or the HDF5 signature
//! of a v7.3 file at byte 0 or 512) or whose name ends in `.mat` is read by
//! [`crate::io::read_mat`]; everything else as text by [`crate::io::read_csv`].
//!
//! ```no_run
//! use feedid::io::{read_recording, ChannelRef, ReadOptions};
//! let opts = ReadOptions {
//!     time: Some(ChannelRef::Name("t".into())),
//!     command: Some(ChannelRef::Name("qg".into())),
//!     position: Some(ChannelRef::Name("qm".into())),
//!     ..ReadOptions::default()
//! };
//! let rec = read_recording("DATA_EMPS.mat".as_ref(), &opts)?;
//! println!("{} samples at {} Hz", rec.len(), rec.rate_hz());
//! # Ok::<(), feedid::Error>(())
//! ```

use std::io::{BufReader, Read};
use std::path::Path;

use crate::error::{Error, Result};
use crate::io::csv::{read_csv_from_bytes, read_csv_from_reader};
use crate::io::mat::{is_mat_bytes, read_mat_from_bytes};
use crate::io::options::ReadOptions;
use crate::io::source::{open_input, read_to_end_bounded};
use crate::recording::Recording;

/// Read a recording from a MAT-file or a text file (see the module doc for
/// the dispatch rule). Text is read line by line with bounded memory, a
/// MAT-file whole; from a pipe or device at most
/// [`crate::io::MAX_STREAM_BYTES`] (see [`crate::io::read_csv`]).
pub fn read_recording(path: &Path, opts: &ReadOptions) -> Result<Recording> {
    read_recording_with_progress(path, opts, None)
}

/// A progress hook of a read: `progress(bytes read, file size)`; the size
/// is 0 when unknown (a pipe or device).
pub type ReadProgress<'a> = &'a (dyn Fn(u64, u64) + Sync);

/// Bytes between two calls of a [`ReadProgress`] hook.
pub const READ_PROGRESS_BYTES: u64 = 1 << 22;

/// [`read_recording`], calling `progress(bytes read, file size)` every
/// [`READ_PROGRESS_BYTES`] bytes read (a bar for an hour of 5 kHz text,
/// 2 GB); the recording is the same.
pub fn read_recording_with_progress(
    path: &Path,
    opts: &ReadOptions,
    progress: Option<ReadProgress<'_>>,
) -> Result<Recording> {
    let mat_ext = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mat"));
    let (file, limit) = open_input(path)?;
    let total = file
        .metadata()
        .ok()
        .filter(|m| m.is_file())
        .map_or(0, |m| m.len());
    let counted = Counted {
        inner: file,
        read: 0,
        next_report: READ_PROGRESS_BYTES,
        total,
        progress,
    };
    let mut reader = BufReader::with_capacity(1 << 16, counted);
    // the first bytes decide (a MAT-file's signatures end at byte 520)
    let mut head = Vec::with_capacity(MAT_SIGNATURE_BYTES);
    (&mut reader)
        .take(MAT_SIGNATURE_BYTES as u64)
        .read_to_end(&mut head)
        .map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
    if mat_ext || is_mat_bytes(&head) {
        let rest = read_to_end_bounded(
            reader,
            limit.map(|l| l.saturating_sub(head.len() as u64)),
            path,
            crate::error::InputKind::Stream,
        )?;
        head.extend_from_slice(&rest);
        read_mat_from_bytes(&head, path, opts)
    } else {
        read_csv_from_reader(head.as_slice().chain(reader), path, opts, limit)
    }
}

/// A reader that reports the bytes read through a [`ReadProgress`] hook.
struct Counted<'p, R> {
    inner: R,
    read: u64,
    next_report: u64,
    total: u64,
    progress: Option<ReadProgress<'p>>,
}

impl<R: Read> Read for Counted<'_, R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.read += n as u64;
        if let Some(p) = self.progress {
            if self.read >= self.next_report {
                p(self.read, self.total);
                while self.next_report <= self.read {
                    self.next_report += READ_PROGRESS_BYTES;
                }
            }
        }
        Ok(n)
    }
}

/// Bytes that decide between a MAT-file and text (the HDF5 signature of a
/// v7.3 file may sit at byte 512).
const MAT_SIGNATURE_BYTES: usize = 520;

/// Like [`read_recording`] for file contents already in memory; `source` names them in errors.
pub fn read_recording_from_bytes(
    bytes: &[u8],
    source: &Path,
    opts: &ReadOptions,
) -> Result<Recording> {
    let mat_ext = source
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mat"));
    if mat_ext || is_mat_bytes(bytes) {
        read_mat_from_bytes(bytes, source, opts)
    } else {
        read_csv_from_bytes(bytes, source, opts)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::options::ChannelRef;

    #[test]
    fn progress_counts_the_bytes_read_and_the_recording_is_the_same() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("long.csv");
        let mut text = String::from("time_s,command_m,position_m,current_a\n");
        for k in 0..250_000 {
            text.push_str(&format!("{},{},{},1\n", k as f64 * 1e-3, k % 7, k % 5));
        }
        std::fs::write(&path, &text).unwrap();
        let size = text.len() as u64;
        let calls = std::sync::Mutex::new(Vec::new());
        let hook = |done: u64, total: u64| calls.lock().unwrap().push((done, total));
        let opts = ReadOptions::default();
        let with = read_recording_with_progress(&path, &opts, Some(&hook)).unwrap();
        let without = read_recording(&path, &opts).unwrap();
        assert_eq!(with.command(), without.command());
        assert_eq!(with.extra(), without.extra());
        let calls = calls.into_inner().unwrap();
        // one call per READ_PROGRESS_BYTES, increasing, of the file's size
        assert_eq!(calls.len() as u64, size / READ_PROGRESS_BYTES, "{calls:?}");
        assert!(calls.windows(2).all(|w| w[0].0 < w[1].0));
        assert!(calls
            .iter()
            .all(|&(d, t)| t == size && d <= size && d >= READ_PROGRESS_BYTES));
    }

    #[test]
    fn dispatch_reads_text_when_not_a_mat_file() {
        let text = b"time_s,command_m,position_m\n0,0,0\n0.001,1,1\n0.002,2,2\n";
        let r = read_recording_from_bytes(text, Path::new("a.csv"), &Default::default()).unwrap();
        assert_eq!(r.len(), 3);
        let opts = ReadOptions {
            command: Some(ChannelRef::Name("qg".into())),
            ..Default::default()
        };
        // A `.mat` name forces the MAT reader, which refuses text.
        let e = read_recording_from_bytes(text, Path::new("a.mat"), &opts).unwrap_err();
        assert!(matches!(e, Error::MatFile { .. }), "{e}");
    }
}
