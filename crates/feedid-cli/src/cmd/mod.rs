//! One module per subcommand.

mod info;
mod model;
mod recording;
mod stream;

use crate::args::{Cli, Command};

/// Dispatch a parsed command line.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Info(a) => info::run(&a),
        Command::Model(a) => model::run(&a),
        Command::Stream(a) => stream::run(&a),
    }
}

/// The rig parameters from a TOML file, or the built-in default rig.
pub fn load_params(path: Option<&std::path::Path>) -> anyhow::Result<feedid::drive::RigParams> {
    Ok(match path {
        Some(p) => feedid::drive::RigParams::load(p)?,
        None => feedid::drive::RigParams::default(),
    })
}
