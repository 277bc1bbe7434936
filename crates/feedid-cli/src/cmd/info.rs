//! `feedid info`: what a user checks before identifying.

use anyhow::Result;
use feedid::error::Syntax;
use feedid::io::recording_info_in;

use crate::args::InfoArgs;
use crate::cmd::recording;

/// Print samples, duration, rate and jitter, channel ranges and motion segments.
pub fn run(a: &InfoArgs) -> Result<()> {
    // the gaps of dropped samples are described, not refused
    let rec = recording::load(&a.input, &a.recording)?;
    let info = recording_info_in(&rec, Syntax::Cli);
    if a.json {
        println!("{}", serde_json::to_string_pretty(&info)?);
    } else {
        println!("{}", a.input.display());
        println!("{info}");
    }
    Ok(())
}
