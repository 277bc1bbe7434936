//! One module per subcommand.

mod identify;
mod info;
mod method;
mod model;
mod order;
mod progress;
mod recording;
mod reproduce;
pub(crate) mod simulate;

mod stream;
mod stream_compensate;

mod compensate;
mod greybox;
mod learn;
mod report;
mod sweep;
pub(crate) mod tune;
pub(crate) mod zoo;

use std::io::Write;

use anyhow::Context;
use std::path::{Path, PathBuf};

use crate::args::{Cli, Command};

/// Dispatch a parsed command line.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Identify(a) => identify::run(&a),
        Command::Info(a) => info::run(&a),
        Command::Model(a) => model::run(&a),
        Command::Order(a) => order::run(&a),
        Command::Reproduce(a) => reproduce::run(&a),
        Command::Simulate(a) => simulate::run(&a),
        Command::Stream(a) => stream::run(&a),
        Command::Report(a) => report::run(&a),
        Command::Sweep(a) => sweep::run(&a),
        Command::Greybox(a) => greybox::run(&a),
        Command::Compensate(a) => compensate::run(&a),
        Command::Zoo(a) => zoo::run(&a),
        Command::Tune(a) => tune::run(&a),
    }
}

/// The rig parameters from a TOML file, or the built-in default rig, with
/// the one validation every command makes (`feedid::drive::check_model`:
/// each value in range, the closed loop finite — `kv = 1e300` is refused
/// everywhere, not only by `feedid model`).
pub fn load_params(path: Option<&Path>) -> anyhow::Result<feedid::drive::RigParams> {
    let params = match path {
        // bounded: `--params /dev/zero` must not read forever
        Some(p) => {
            let text = feedid::io::read_small_text(p)?;
            if feedid::drive::DriveStructure::describes(&text) {
                anyhow::bail!(
                    "{}: a drive structure file ([drive], [mechanics]): `feedid model`, \
                     `feedid simulate`, `feedid greybox` and `feedid tune` read it; this command needs the paper's rig parameters",
                    p.display()
                );
            }
            feedid::drive::RigParams::from_toml_str(&text, Some(p))?
        }
        None => feedid::drive::RigParams::default(),
    };
    feedid::drive::check_model(&params).map_err(|e| params_error(path, e))?;
    Ok(params)
}

/// A drive structure file (`--params` with `[drive]`/`[mechanics]` tables),
/// or `None` for the paper's rig parameters (or none given).
pub fn load_structure(
    path: Option<&Path>,
) -> anyhow::Result<Option<feedid::drive::DriveStructure>> {
    let Some(p) = path else {
        return Ok(None);
    };
    let text = feedid::io::read_small_text(p)?;
    if !feedid::drive::DriveStructure::describes(&text) {
        return Ok(None);
    }
    Ok(Some(feedid::drive::DriveStructure::from_toml_str(
        &text,
        Some(p),
    )?))
}

/// [`load_params`] for a model that is simulated or inverted: an unstable
/// one is refused (exit 2, its unstable poles named) unless `allow_unstable`,
/// then only warned about.
pub fn load_model_params(
    path: Option<&Path>,
    allow_unstable: bool,
) -> anyhow::Result<feedid::drive::RigParams> {
    let params = load_params(path)?;
    let check = feedid::drive::check_model(&params)?;
    if !check.stable {
        let name = path.map_or_else(
            || "the built-in rig".to_string(),
            |p| p.display().to_string(),
        );
        let e = feedid::Error::UnstableModel {
            poles: check.describe_unstable(),
        };
        if !allow_unstable {
            anyhow::bail!("{name}: {e}; give --allow-unstable to use it anyway");
        }
        eprintln!("warning: {name}: {e}");
    }
    Ok(params)
}

/// An identified model file (`--model`, `--from-model`), read with a bound.
pub fn load_model_file(path: &Path) -> anyhow::Result<feedid::ident::ModelFile> {
    let text = feedid::io::read_small_text(path)?;
    Ok(feedid::ident::ModelFile::from_json_file(&text, path)?)
}

/// Rig effects from a TOML file (`--effects`): friction law, limits, noise.
pub fn load_effects(path: &Path) -> anyhow::Result<feedid::drive::RigEffects> {
    let text = feedid::io::read_small_text(path)?;
    let fx: feedid::drive::RigEffects = toml::from_str(&text)
        .map_err(|e| anyhow::anyhow!("{}: {}", path.display(), e.to_string().replace('\n', " ")))?;
    fx.validate().with_context(|| path.display().to_string())?;
    Ok(fx)
}

/// A library error caused by the values of a parameter file, prefixed by the
/// file (`rig.toml: these parameters give no usable model: …`).
pub fn params_error(path: Option<&Path>, e: feedid::Error) -> anyhow::Error {
    match path {
        Some(p) => anyhow::anyhow!(
            "{}: these parameters give no usable model: {e}",
            p.display()
        ),
        None => e.into(),
    }
}

/// What a path names, for collision checks: the file it reaches (device and
/// inode, through symbolic and hard links) when it exists, else its final
/// path; character devices (`/dev/null`) may be named any number of times.
#[derive(Debug, Clone, PartialEq, Eq)]
enum PathKey {
    Stdout,
    Device,
    Inode(u64, u64),
    Path(PathBuf),
}

#[cfg(unix)]
fn inode_key(meta: &std::fs::Metadata) -> PathKey {
    use std::os::unix::fs::{FileTypeExt, MetadataExt};
    if meta.file_type().is_char_device() {
        PathKey::Device
    } else {
        PathKey::Inode(meta.dev(), meta.ino())
    }
}

#[cfg(not(unix))]
fn inode_key(_meta: &std::fs::Metadata) -> PathKey {
    PathKey::Device
}

/// The key of a path that may not exist yet: its canonical directory and name.
fn new_path_key(p: &Path) -> Option<PathKey> {
    let dir = match p.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    Some(PathKey::Path(
        std::fs::canonicalize(dir).ok()?.join(p.file_name()?),
    ))
}

fn input_key(p: &Path) -> Option<PathKey> {
    match std::fs::metadata(p) {
        Ok(m) => Some(inode_key(&m)),
        Err(_) => new_path_key(p),
    }
}

fn output_key(p: &Path) -> Option<PathKey> {
    match feedid::io::destination(p).ok()? {
        feedid::io::Destination::Stdout => Some(PathKey::Stdout),
        feedid::io::Destination::File { target } => match std::fs::metadata(&target) {
            Ok(m) => Some(inode_key(&m)),
            Err(_) => new_path_key(&target),
        },
        feedid::io::Destination::Stream { path } => {
            std::fs::metadata(&path).ok().map(|m| inode_key(&m))
        }
    }
}

/// Refuse a command line whose outputs would overwrite one of its inputs or
/// each other (`identify rec.csv -o rec.csv` would destroy the recording),
/// also through other paths, symbolic or hard links. An output `-` sends the
/// command's own printed text to standard error.
pub fn check_distinct(inputs: &[&Path], outputs: &[&Path]) -> anyhow::Result<()> {
    let outs: Vec<Option<PathKey>> = outputs.iter().map(|p| output_key(p)).collect();
    let ins: Vec<Option<PathKey>> = inputs.iter().map(|p| input_key(p)).collect();
    for (i, (out, k)) in outputs.iter().zip(&outs).enumerate() {
        let Some(k) = k else { continue };
        if *k == PathKey::Device {
            continue;
        }
        for (input, ik) in inputs.iter().zip(&ins) {
            if ik.as_ref() == Some(k) {
                anyhow::bail!(
                    "{}: the output would overwrite the input {}",
                    out.display(),
                    input.display()
                );
            }
        }
        for (other, ok) in outputs[..i].iter().zip(&outs) {
            if ok.as_ref() == Some(k) {
                anyhow::bail!(
                    "{}: given for two outputs ({} too)",
                    out.display(),
                    other.display()
                );
            }
        }
    }
    if outs.contains(&Some(PathKey::Stdout)) {
        crate::stdout_taken_by_output();
    }
    Ok(())
}

/// The output files of one command, committed together or not at all
/// (`feedid::io::OutputSet`: temporary files first, then streams, then the
/// renames in the order added — commands add their summary last).
#[derive(Default)]
pub struct Outputs<'a> {
    set: feedid::io::OutputSet<'a>,
}

impl<'a> Outputs<'a> {
    /// Add an output written by `body` at commit time.
    pub fn add<F>(&mut self, path: &Path, body: F) -> anyhow::Result<()>
    where
        F: FnOnce(&mut dyn Write) -> std::io::Result<()> + 'a,
    {
        Ok(self.set.add(path, body)?)
    }

    /// Add an output holding `text`.
    pub fn add_text(&mut self, path: &Path, text: String) -> anyhow::Result<()> {
        self.add(path, move |w| w.write_all(text.as_bytes()))
    }

    /// Write everything, or nothing.
    pub fn commit(self) -> anyhow::Result<()> {
        if self.set.uses_stdout() {
            crate::stdout_taken_by_output();
        }
        Ok(self.set.commit()?)
    }
}
