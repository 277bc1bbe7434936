//! Writing results: never destroy what is not ours, never leave a partial
//! or mixed result.
//!
//! Where an output goes is decided by what its path names ([`destination`]):
//!
//! - **a regular file, or nothing yet** — written to a temporary file with a
//!   short name (`.fdPPPPNNNN.tmp`, so a legal 255-byte output name still
//!   works) in the same directory, flushed and `fsync`ed, then renamed over
//!   the target (an existing file keeps its permission bits). A symbolic link
//!   is followed: its final target is replaced, the link itself is kept.
//! - **a stream** — `-` (standard output), a FIFO, a character device
//!   (`/dev/null`, `/dev/full`, a terminal) or an open descriptor
//!   (`/dev/stdout`, `/dev/fd/N`, `/proc/self/fd/N`, e.g. `>(gzip > x.gz)`) —
//!   is opened and written directly (a descriptor path that is the
//!   process's own standard output is written through its descriptor, as
//!   `-`: appended where the shell appends, and the same output as `-`);
//!   it is never replaced, and what was sent
//!   into it cannot be taken back. A reader that closes it early (`| head`)
//!   ends that output quietly.
//! - a directory, a block device or a socket is refused.
//!
//! Several outputs of one command form an [`OutputSet`], committed together
//! or not at all: every regular file is first written completely to its
//! temporary file, then the streams are written, and only when all of that
//! succeeded are the temporary files renamed, in the order they were added
//! (commands add their summary last: a new summary on disk means every file
//! of its set is new too). On any error every temporary file is removed and
//! nothing is renamed. Renames of one set happen under an advisory lock of
//! each target directory (so two processes writing the same set at once
//! leave one whole set, never one's file beside the other's summary) and
//! under a process-wide lock
//! that [`abandon_pending_outputs`] (the binary's SIGINT/SIGTERM/SIGHUP
//! handler) also takes: a signal removes the temporary files and ends the
//! process either before the first rename or after the last one.
//!
//! A write that fails because the file-size limit was reached (`EFBIG`,
//! `ulimit -f`; the binary turns SIGXFSZ into this error) is reported as such.

use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Write};
use std::path::{Component, Path, PathBuf};
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Mutex, MutexGuard};

use crate::error::{Error, Result};

/// Most symbolic links followed to find an output's final target (as Linux's `ELOOP` limit).
const MAX_LINK_HOPS: usize = 40;

/// What an output path names.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Destination {
    /// A regular file (existing or not), replaced atomically; `target` is the
    /// final path after following symbolic links.
    File {
        /// The file that is created or replaced.
        target: PathBuf,
    },
    /// Standard output (`-`).
    Stdout,
    /// A FIFO, character device or open descriptor, written directly.
    Stream {
        /// The path to open for writing.
        path: PathBuf,
    },
}

impl Destination {
    /// Whether this output is written directly (cannot be made atomic).
    pub fn is_stream(&self) -> bool {
        !matches!(self, Destination::File { .. })
    }
}

/// Whether `path` names an open file descriptor (`/dev/stdout`, `/dev/fd/N`,
/// `/proc/<pid>/fd/N`): written directly, whatever it refers to.
fn is_descriptor_path(path: &Path) -> bool {
    let parts: Vec<Component<'_>> = path.components().collect();
    let name = |i: usize| parts.get(i).and_then(|c| c.as_os_str().to_str());
    matches!(
        (parts.first(), name(1), name(2), name(3)),
        (
            Some(Component::RootDir),
            Some("dev"),
            Some("stdout" | "stderr"),
            None
        ) | (Some(Component::RootDir), Some("dev"), Some("fd"), Some(_))
            | (Some(Component::RootDir), Some("proc"), Some(_), Some("fd"))
    )
}

/// Whether `path` is the file this process's standard output is open on
/// (the same device and inode; the same pipe or terminal).
#[cfg(unix)]
fn is_stdout(path: &Path) -> bool {
    use std::os::fd::AsFd;
    use std::os::unix::fs::MetadataExt;
    let Ok(fd) = std::io::stdout().as_fd().try_clone_to_owned() else {
        return false;
    };
    match (File::from(fd).metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn is_stdout(_path: &Path) -> bool {
    false
}

/// Decide where an output path goes (see the module doc). Errors:
/// [`Error::Io`] for a directory, a block device, a socket, a link loop or
/// an unreadable path.
pub fn destination(path: &Path) -> Result<Destination> {
    let refuse = |what: &str| Error::Io {
        path: path.to_path_buf(),
        source: std::io::Error::other(format!("{what}; refusing to write to it")),
    };
    if path.as_os_str() == "-" {
        return Ok(Destination::Stdout);
    }
    if path.as_os_str().is_empty() {
        return Err(refuse("an empty path"));
    }
    let stream = || Destination::Stream {
        path: path.to_path_buf(),
    };
    let mut p = path.to_path_buf();
    for _ in 0..=MAX_LINK_HOPS {
        if is_descriptor_path(&p) {
            // the process's own standard output under another name
            // (`/dev/stdout`, `/dev/fd/1`, `/proc/self/fd/1`) is written
            // through its descriptor, as `-` is: reopening it would start
            // at offset 0 of a file the shell opened for appending
            return Ok(if is_stdout(&p) {
                Destination::Stdout
            } else {
                stream()
            });
        }
        let meta = match std::fs::symlink_metadata(&p) {
            Ok(m) => m,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Ok(Destination::File { target: p });
            }
            Err(source) => {
                return Err(Error::Io {
                    path: path.to_path_buf(),
                    source,
                })
            }
        };
        let ft = meta.file_type();
        if ft.is_symlink() {
            let link = std::fs::read_link(&p).map_err(|source| Error::Io {
                path: path.to_path_buf(),
                source,
            })?;
            p = if link.is_absolute() {
                link
            } else {
                p.parent().unwrap_or_else(|| Path::new("")).join(link)
            };
            continue;
        }
        if ft.is_file() {
            return Ok(Destination::File { target: p });
        }
        if ft.is_dir() {
            return Err(refuse("a directory"));
        }
        #[cfg(unix)]
        {
            use std::os::unix::fs::FileTypeExt;
            if ft.is_block_device() {
                return Err(refuse(
                    "a block device (writing would destroy what it holds)",
                ));
            }
            if ft.is_socket() {
                return Err(refuse("a socket"));
            }
        }
        // FIFO, character device
        return Ok(stream());
    }
    Err(refuse("a chain of more than 40 symbolic links"))
}

// ------------------------------------------------------------ pending temps

/// Temporary files not yet renamed, and whether the process is ending.
struct Pending {
    files: Vec<PathBuf>,
    closed: bool,
}

static PENDING: Mutex<Pending> = Mutex::new(Pending {
    files: Vec::new(),
    closed: false,
});

static COUNTER: AtomicU32 = AtomicU32::new(0);

fn pending() -> MutexGuard<'static, Pending> {
    PENDING.lock().unwrap_or_else(|e| e.into_inner())
}

/// Remove every temporary output file of this process and keep new ones from
/// being created, then run `then` (e.g. end the process) while no set can be
/// half renamed: a set being renamed finishes first. For the binary's signal
/// handler; returns what `then` returns.
pub fn abandon_pending_outputs<R>(then: impl FnOnce(usize) -> R) -> R {
    let mut g = pending();
    g.closed = true;
    let n = g.files.len();
    for f in g.files.drain(..) {
        let _ = std::fs::remove_file(f);
    }
    let r = then(n);
    drop(g);
    r
}

/// Number of temporary output files of this process not yet renamed or removed.
pub fn pending_output_count() -> usize {
    pending().files.len()
}

/// A new temporary file beside `target`, registered for removal.
fn create_temp(target: &Path) -> std::io::Result<(PathBuf, File)> {
    let dir = directory_of(target);
    let pid = std::process::id();
    for _ in 0..1000 {
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let tmp = dir.join(format!(".fd{pid:x}{n:x}.tmp"));
        let mut g = pending();
        if g.closed {
            return Err(std::io::Error::new(
                std::io::ErrorKind::Interrupted,
                "interrupted: the process is ending",
            ));
        }
        match OpenOptions::new().write(true).create_new(true).open(&tmp) {
            Ok(f) => {
                g.files.push(tmp.clone());
                return Ok((tmp, f));
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e),
        }
    }
    Err(std::io::Error::other(
        "cannot find a free name for a temporary file",
    ))
}

/// Remove temporary files (after an error) and forget them.
fn discard(temps: &[PathBuf]) {
    let mut g = pending();
    for t in temps {
        let _ = std::fs::remove_file(t);
        g.files.retain(|f| f != t);
    }
}

/// A write error, named as a file-size limit when it is one.
fn output_error(path: &Path, e: std::io::Error) -> Error {
    // EFBIG is 27 on Linux and the BSDs
    let source = if cfg!(unix) && e.raw_os_error() == Some(27) {
        std::io::Error::new(
            e.kind(),
            "file too large: the file-size limit (ulimit -f) was reached",
        )
    } else {
        e
    };
    Error::Io {
        path: path.to_path_buf(),
        source,
    }
}

// ------------------------------------------------------------------- sets

/// What writes one output.
type Body<'a> = Box<dyn FnOnce(&mut dyn Write) -> std::io::Result<()> + 'a>;

/// One output of a set.
struct Item<'a> {
    /// As given (for messages).
    path: PathBuf,
    dest: Destination,
    body: Body<'a>,
}

/// The outputs of one command, committed together or not at all (see the
/// module doc).
///
/// ```
/// use std::io::Write;
/// use feedid::io::OutputSet;
/// let dir = std::env::temp_dir().join(format!("feedid-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// let rows = vec![1.0, 2.5];
/// let mut set = OutputSet::new();
/// set.add(&dir.join("data.csv"), |w| {
///     for r in &rows {
///         writeln!(w, "{r}")?;
///     }
///     Ok(())
/// })?;
/// set.add(&dir.join("summary.json"), |w| writeln!(w, "{{\"rows\": 2}}"))?; // last
/// set.commit()?;
/// assert_eq!(std::fs::read_to_string(dir.join("data.csv"))?, "1\n2.5\n");
/// # std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Default)]
pub struct OutputSet<'a> {
    items: Vec<Item<'a>>,
}

impl<'a> OutputSet<'a> {
    /// An empty set.
    pub fn new() -> Self {
        Self { items: Vec::new() }
    }

    /// Add an output: `body` writes its content when the set is committed.
    /// The path is resolved now ([`destination`]), so a directory or a block
    /// device is refused before anything is computed or written.
    pub fn add<F>(&mut self, path: &Path, body: F) -> Result<()>
    where
        F: FnOnce(&mut dyn Write) -> std::io::Result<()> + 'a,
    {
        let dest = destination(path)?;
        self.items.push(Item {
            path: path.to_path_buf(),
            dest,
            body: Box::new(body),
        });
        Ok(())
    }

    /// Number of outputs added.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// Whether no output was added.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// Whether one of the outputs is standard output.
    pub fn uses_stdout(&self) -> bool {
        self.items.iter().any(|i| i.dest == Destination::Stdout)
    }

    /// Write every output: regular files to temporary files first, then the
    /// streams, then rename the temporary files in the order they were added.
    /// On error nothing is renamed and every temporary file is removed.
    pub fn commit(self) -> Result<()> {
        let mut temps: Vec<(PathBuf, PathBuf)> = Vec::new(); // (temp, target)
        let mut streams = Vec::new();
        for item in self.items {
            match &item.dest {
                Destination::File { target } => match write_temp(target, item.body) {
                    Ok(tmp) => temps.push((tmp, target.clone())),
                    Err((tmp, e)) => {
                        let mut all: Vec<PathBuf> = temps.into_iter().map(|t| t.0).collect();
                        all.extend(tmp);
                        discard(&all);
                        return Err(output_error(&item.path, e));
                    }
                },
                _ => streams.push(item),
            }
        }
        for item in streams {
            if let Err(e) = write_stream(&item.dest, item.body) {
                discard(&temps.iter().map(|t| t.0.clone()).collect::<Vec<_>>());
                return Err(output_error(&item.path, e));
            }
        }
        // another process committing into the same directories waits here:
        // two runs writing one set at once leave one run's whole set
        let _locks = lock_directories(&temps);
        let mut g = pending();
        let mut dirs: Vec<PathBuf> = Vec::new();
        for (i, (tmp, target)) in temps.iter().enumerate() {
            if let Err(e) = std::fs::rename(tmp, target) {
                // cannot happen in practice (same directory as a file we created)
                for (t, _) in &temps[i..] {
                    let _ = std::fs::remove_file(t);
                    g.files.retain(|f| f != t);
                }
                for (t, _) in &temps[..i] {
                    g.files.retain(|f| f != t);
                }
                return Err(output_error(target, e));
            }
            g.files.retain(|f| f != tmp);
            let dir = directory_of(target).to_path_buf();
            if !dirs.contains(&dir) {
                dirs.push(dir);
            }
        }
        drop(g);
        // make the renames durable (best effort: not every file system allows it)
        for d in dirs {
            if let Ok(f) = File::open(&d) {
                let _ = f.sync_all();
            }
        }
        Ok(())
    }
}

/// The directory a target is renamed into (`.` for a bare file name).
fn directory_of(target: &Path) -> &Path {
    target
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or_else(|| Path::new("."))
}

/// Exclusive advisory locks (`flock`) on the directories of `temps`'
/// targets, taken in one order (canonical paths, sorted) by every process
/// so that none waits on another in a cycle; released when dropped. Best
/// effort: a directory that cannot be opened or locked (a file system
/// without locks) is renamed into unlocked, as before.
fn lock_directories(temps: &[(PathBuf, PathBuf)]) -> Vec<File> {
    let mut dirs: Vec<PathBuf> = temps
        .iter()
        .map(|(_, target)| {
            let d = directory_of(target);
            std::fs::canonicalize(d).unwrap_or_else(|_| d.to_path_buf())
        })
        .collect();
    dirs.sort();
    dirs.dedup();
    dirs.into_iter()
        .filter_map(|d| {
            let f = File::open(&d).ok()?;
            f.lock().ok()?;
            Some(f)
        })
        .collect()
}

/// Write `body` into a new temporary file beside `target`, flush and fsync it.
/// On error returns the temporary file's path (if one was made) to remove.
fn write_temp(
    target: &Path,
    body: Body<'_>,
) -> std::result::Result<PathBuf, (Option<PathBuf>, std::io::Error)> {
    let (tmp, file) = create_temp(target).map_err(|e| (None, e))?;
    let res = (|| {
        let mut w = BufWriter::with_capacity(1 << 16, file);
        body(&mut w)?;
        w.flush()?;
        let file = w.into_inner().map_err(|e| e.into_error())?;
        // keep the permission bits of the file replaced
        if let Ok(meta) = std::fs::metadata(target) {
            file.set_permissions(meta.permissions())?;
        }
        file.sync_all()
    })();
    match res {
        Ok(()) => Ok(tmp),
        Err(e) => Err((Some(tmp), e)),
    }
}

/// Write `body` directly into a stream. A reader that goes away early
/// (`feedid … -o - | head`) ends the writing quietly: it wanted no more.
fn write_stream(dest: &Destination, body: Body<'_>) -> std::io::Result<()> {
    match write_stream_raw(dest, body) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        r => r,
    }
}

fn write_stream_raw(dest: &Destination, body: Body<'_>) -> std::io::Result<()> {
    match dest {
        Destination::Stdout => {
            let out = std::io::stdout();
            let mut w = BufWriter::with_capacity(1 << 16, out.lock());
            body(&mut w)?;
            w.flush()
        }
        Destination::Stream { path } => {
            let f = OpenOptions::new().write(true).open(path)?;
            let mut w = BufWriter::with_capacity(1 << 16, f);
            body(&mut w)?;
            w.flush()
        }
        Destination::File { .. } => Err(std::io::Error::other("not a stream")),
    }
}

/// Write one output (a set of one): `body` writes into a buffered temporary
/// file renamed to `path` only if `body`, the flush and the fsync succeed;
/// a stream is written directly (see the module doc).
pub fn write_atomic<F>(path: &Path, body: F) -> Result<()>
where
    F: FnOnce(&mut dyn Write) -> std::io::Result<()>,
{
    let mut set = OutputSet::new();
    set.add(path, body)?;
    set.commit()
}

/// Write a whole string as one output ([`write_atomic`]).
pub fn write_string_atomic(path: &Path, text: &str) -> Result<()> {
    write_atomic(path, |w| w.write_all(text.as_bytes()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

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
        assert_eq!(names(dir.path()), vec!["out.txt"]);
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
    fn a_set_with_a_failing_member_renames_nothing_and_keeps_the_old_files() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.csv");
        let b = dir.path().join("b.csv");
        let s = dir.path().join("summary.json");
        std::fs::write(&a, "old a").unwrap();
        std::fs::write(&s, "old s").unwrap();
        let mut set = OutputSet::new();
        set.add(&a, |w| w.write_all(b"new a")).unwrap();
        set.add(&b, |w| {
            w.write_all(b"half")?;
            Err(std::io::Error::other("disk gone"))
        })
        .unwrap();
        set.add(&s, |w| w.write_all(b"new s")).unwrap();
        let e = set.commit().unwrap_err().to_string();
        assert!(e.contains("b.csv") && e.contains("disk gone"), "{e}");
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old a");
        assert_eq!(std::fs::read_to_string(&s).unwrap(), "old s");
        assert_eq!(names(dir.path()), vec!["a.csv", "summary.json"]);
        assert_eq!(pending_output_count(), 0);
    }

    #[test]
    fn a_committed_set_replaces_every_file() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.csv");
        std::fs::write(&a, "old").unwrap();
        let mut set = OutputSet::new();
        set.add(&a, |w| w.write_all(b"new a")).unwrap();
        set.add(&dir.path().join("s.json"), |w| w.write_all(b"{}"))
            .unwrap();
        assert_eq!(set.len(), 2);
        set.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "new a");
        assert_eq!(names(dir.path()), vec!["a.csv", "s.json"]);
    }

    #[test]
    fn a_255_byte_output_name_works() {
        let dir = tempfile::tempdir().unwrap();
        let name = format!("{}.csv", "n".repeat(251));
        assert_eq!(name.len(), 255);
        let p = dir.path().join(&name);
        write_string_atomic(&p, "x").unwrap();
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "x");
    }

    #[cfg(unix)]
    #[test]
    fn a_symlink_is_followed_and_kept() {
        let dir = tempfile::tempdir().unwrap();
        let real = dir.path().join("real.csv");
        std::fs::write(&real, "old").unwrap();
        let sub = dir.path().join("sub");
        std::fs::create_dir(&sub).unwrap();
        let link = sub.join("link.csv");
        std::os::unix::fs::symlink("../real.csv", &link).unwrap();
        // and a link to that link
        let link2 = dir.path().join("link2.csv");
        std::os::unix::fs::symlink(&link, &link2).unwrap();
        write_string_atomic(&link2, "new").unwrap();
        assert_eq!(std::fs::read_to_string(&real).unwrap(), "new");
        assert!(std::fs::symlink_metadata(&link).unwrap().is_symlink());
        assert!(std::fs::symlink_metadata(&link2).unwrap().is_symlink());
        assert_eq!(names(&sub), vec!["link.csv"]);
        // a dangling link creates its target
        let dangling = dir.path().join("dangling.csv");
        std::os::unix::fs::symlink("made.csv", &dangling).unwrap();
        write_string_atomic(&dangling, "made").unwrap();
        assert_eq!(
            std::fs::read_to_string(dir.path().join("made.csv")).unwrap(),
            "made"
        );
        assert!(std::fs::symlink_metadata(&dangling).unwrap().is_symlink());
    }

    #[cfg(unix)]
    #[test]
    fn a_link_loop_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a");
        let b = dir.path().join("b");
        std::os::unix::fs::symlink(&b, &a).unwrap();
        std::os::unix::fs::symlink(&a, &b).unwrap();
        let e = write_string_atomic(&a, "x").unwrap_err().to_string();
        assert!(e.contains("symbolic links"), "{e}");
    }

    #[cfg(unix)]
    #[test]
    fn permissions_of_a_replaced_file_are_kept() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("x.csv");
        std::fs::write(&p, "old").unwrap();
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o640)).unwrap();
        write_string_atomic(&p, "new").unwrap();
        let mode = std::fs::metadata(&p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o640);
    }

    #[test]
    fn destinations_are_classified() {
        assert_eq!(destination(Path::new("-")).unwrap(), Destination::Stdout);
        let dir = tempfile::tempdir().unwrap();
        let e = destination(dir.path()).unwrap_err().to_string();
        assert!(e.contains("a directory"), "{e}");
        let new = dir.path().join("new.csv");
        assert_eq!(
            destination(&new).unwrap(),
            Destination::File {
                target: new.clone()
            }
        );
        for p in ["/dev/stdout", "/dev/fd/63", "/proc/self/fd/1"] {
            assert!(destination(Path::new(p)).unwrap().is_stream(), "{p}");
        }
        if Path::new("/dev/null").exists() {
            assert!(destination(Path::new("/dev/null")).unwrap().is_stream());
            write_string_atomic(Path::new("/dev/null"), "gone").unwrap();
            assert!(!std::fs::metadata("/dev/null")
                .unwrap()
                .file_type()
                .is_file());
        }
    }

    #[cfg(unix)]
    #[test]
    fn a_block_device_is_refused_before_anything_is_written() {
        // classification only: nothing is ever opened for writing here
        use std::os::unix::fs::FileTypeExt;
        let dev = std::fs::read_dir("/dev")
            .ok()
            .into_iter()
            .flatten()
            .filter_map(|e| e.ok())
            .find(|e| e.file_type().is_ok_and(|t| t.is_block_device()));
        let Some(dev) = dev else { return };
        let e = destination(&dev.path()).unwrap_err().to_string();
        assert!(e.contains("block device"), "{e}");
        let mut set = OutputSet::new();
        assert!(set.add(&dev.path(), |_| Ok(())).is_err());
        assert!(set.is_empty());
    }

    #[cfg(unix)]
    #[test]
    fn a_full_device_is_an_error_and_leaves_the_device() {
        let full = Path::new("/dev/full");
        if !full.exists() {
            return;
        }
        let e = write_string_atomic(full, &"x".repeat(100_000)).unwrap_err();
        assert!(e.to_string().contains("/dev/full"), "{e}");
        use std::os::unix::fs::FileTypeExt;
        assert!(std::fs::metadata(full)
            .unwrap()
            .file_type()
            .is_char_device());
    }

    #[test]
    fn a_file_size_error_is_named() {
        let e = output_error(Path::new("o.csv"), std::io::Error::from_raw_os_error(27));
        if cfg!(unix) {
            assert!(e.to_string().contains("ulimit -f"), "{e}");
        }
    }
}
