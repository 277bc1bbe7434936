//! Writing results without leaving partial files behind.
//!
//! Every output is written to a temporary file in the target directory and
//! renamed into place only when complete; on error the temporary file is
//! removed, so a failed command leaves no output file.
//!
//! Numbers are written with Rust's shortest round-trip formatting, so a value
//! read back is bit-identical. A missing value is an empty cell.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::ident::SlidingResult;

/// Write a file atomically: `body` writes into a buffered temporary file that
/// is renamed to `path` only if `body` and the flush succeed.
pub fn write_atomic<F>(path: &Path, body: F) -> Result<()>
where
    F: FnOnce(&mut dyn Write) -> std::io::Result<()>,
{
    let io_err = |source| Error::Io {
        path: path.to_path_buf(),
        source,
    };
    let tmp = temp_path(path);
    let file = File::create(&tmp).map_err(io_err)?;
    let mut w = BufWriter::new(file);
    let res = body(&mut w).and_then(|()| w.flush());
    drop(w);
    match res {
        Ok(()) => std::fs::rename(&tmp, path).map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            io_err(e)
        }),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(io_err(e))
        }
    }
}

/// Write a whole string atomically.
pub fn write_string_atomic(path: &Path, text: &str) -> Result<()> {
    write_atomic(path, |w| w.write_all(text.as_bytes()))
}

fn temp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "output".to_string());
    path.with_file_name(format!(".{name}.part-{}", std::process::id()))
}

/// Format an optional value as a CSV cell (empty when missing or non-finite).
pub fn cell(v: Option<f64>) -> String {
    match v {
        Some(x) if x.is_finite() => format!("{x}"),
        _ => String::new(),
    }
}

/// Write `time_s,command_m,measured_m,predicted_m,simulated_m`, one row per
/// sample; empty cells where nothing was predicted or simulated.
pub fn write_predictions_csv(
    path: &Path,
    time: &[f64],
    command: &[f64],
    measured: &[f64],
    result: &SlidingResult,
    simulated: Option<&[f64]>,
) -> Result<()> {
    write_atomic(path, |w| {
        writeln!(w, "time_s,command_m,measured_m,predicted_m,simulated_m")?;
        for k in 0..time.len() {
            writeln!(
                w,
                "{},{},{},{},{}",
                time[k],
                command[k],
                measured[k],
                cell(result.prediction(k)),
                cell(simulated.and_then(|s| s.get(k).copied())),
            )?;
        }
        Ok(())
    })
}

/// Write per-window coefficients: `window,start_s,end_s,residual_rms_m,iterations,termination,<names…>`.
pub fn write_coefficients_csv(path: &Path, time: &[f64], result: &SlidingResult) -> Result<()> {
    write_atomic(path, |w| {
        write!(
            w,
            "window,start_s,end_s,residual_rms_m,iterations,termination"
        )?;
        for n in &result.coefficient_names {
            write!(w, ",{n}")?;
        }
        writeln!(w)?;
        for (i, rec) in result.windows.iter().enumerate() {
            let start = time.get(rec.window.start).copied();
            let end = time.get(rec.window.end.saturating_sub(1)).copied();
            write!(
                w,
                "{},{},{},{},{},{}",
                i,
                cell(start),
                cell(end),
                cell(Some(rec.residual_rms)),
                rec.iterations,
                rec.outcome.label()
            )?;
            for c in result.window_coefficients(i) {
                write!(w, ",{}", cell(Some(*c)))?;
            }
            writeln!(w)?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failed_body_leaves_no_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("out.csv");
        let e = write_atomic(&p, |w| {
            w.write_all(b"partial")?;
            Err(std::io::Error::other("boom"))
        });
        assert!(e.is_err());
        assert!(!p.exists());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }

    #[test]
    fn successful_body_creates_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("out.txt");
        write_string_atomic(&p, "hello").unwrap();
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "hello");
    }

    #[test]
    fn unwritable_directory_is_an_io_error_naming_the_path() {
        let p = Path::new("/nonexistent-dir-feedid/out.csv");
        let e = write_string_atomic(p, "x").unwrap_err();
        assert!(
            e.to_string().contains("/nonexistent-dir-feedid/out.csv"),
            "{e}"
        );
    }

    #[test]
    fn cells_are_empty_for_missing_or_nonfinite() {
        assert_eq!(cell(None), "");
        assert_eq!(cell(Some(f64::NAN)), "");
        assert_eq!(cell(Some(0.1)), "0.1");
    }
}
