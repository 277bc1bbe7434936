//! One module per subcommand.

mod identify;
mod info;
mod method;
mod model;
mod order;
mod recording;
mod reproduce;
mod simulate;

mod stream;

mod compensate;
mod greybox;
mod report;
mod sweep;
pub(crate) mod zoo;

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
    }
}

/// The rig parameters from a TOML file, or the built-in default rig.
pub fn load_params(path: Option<&Path>) -> anyhow::Result<feedid::drive::RigParams> {
    Ok(match path {
        Some(p) => feedid::drive::RigParams::load(p)?,
        None => feedid::drive::RigParams::default(),
    })
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

/// Refuse a command line whose outputs would overwrite one of its inputs or
/// each other (`identify rec.csv -o rec.csv` would destroy the recording).
pub fn check_distinct(inputs: &[&Path], outputs: &[&Path]) -> anyhow::Result<()> {
    // an output may not exist yet: compare its canonical directory and name
    let key = |p: &Path| -> Option<PathBuf> {
        let dir = match p.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        Some(std::fs::canonicalize(dir).ok()?.join(p.file_name()?))
    };
    for (i, out) in outputs.iter().enumerate() {
        let Some(k) = key(out) else { continue };
        for input in inputs {
            if key(input).as_ref() == Some(&k) {
                anyhow::bail!(
                    "{}: the output would overwrite the input {}",
                    out.display(),
                    input.display()
                );
            }
        }
        for other in &outputs[..i] {
            if key(other).as_ref() == Some(&k) {
                anyhow::bail!(
                    "{}: given for two outputs ({} too)",
                    out.display(),
                    other.display()
                );
            }
        }
    }
    Ok(())
}

/// Output files of one command: each is written atomically; if a later one
/// fails, the ones already written are removed, so a failed command leaves
/// no output behind.
#[derive(Default)]
pub struct Outputs {
    written: Vec<PathBuf>,
}

impl Outputs {
    /// Write one file with `f`; on failure remove what this command wrote so far.
    pub fn write<F>(&mut self, path: &Path, f: F) -> anyhow::Result<()>
    where
        F: FnOnce(&Path) -> feedid::Result<()>,
    {
        match f(path) {
            Ok(()) => {
                self.written.push(path.to_path_buf());
                Ok(())
            }
            Err(e) => {
                self.rollback();
                Err(e.into())
            }
        }
    }

    /// Keep everything written.
    pub fn commit(mut self) {
        self.written.clear();
    }

    fn rollback(&mut self) {
        for p in self.written.drain(..) {
            let _ = std::fs::remove_file(p);
        }
    }
}

impl Drop for Outputs {
    fn drop(&mut self) {
        self.rollback();
    }
}
