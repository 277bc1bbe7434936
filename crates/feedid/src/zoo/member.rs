//! A generated member: its description, the recording (time, command,
//! measured position) and the truth (the noise-free position).

use std::io::Write;

use super::spec::MemberSpec;
use crate::error::Result;
use crate::recording::{Recording, DEFAULT_JITTER_TOLERANCE};

/// One recording of the zoo.
#[derive(Debug, Clone, PartialEq)]
pub struct ZooMember {
    /// Everything drawn for the member.
    pub spec: MemberSpec,
    /// Time \[s\] (`k/rate`; jumps at dropped rows).
    pub time: Vec<f64>,
    /// Command \[m\].
    pub command: Vec<f64>,
    /// Measured position \[m\]: quantised, with noise and glitches.
    pub position: Vec<f64>,
    /// True position \[m\]: no quantisation, noise or glitch.
    pub truth: Vec<f64>,
}

impl ZooMember {
    /// Number of rows.
    pub fn len(&self) -> usize {
        self.time.len()
    }

    /// True when there are no rows (never for a generated member).
    pub fn is_empty(&self) -> bool {
        self.time.is_empty()
    }

    /// The member as a checked, uniformly sampled [`Recording`]; an error for
    /// members with dropped rows (see [`ZooMember::recording_with_gaps`]).
    pub fn recording(&self) -> Result<Recording> {
        Recording::new(
            self.time.clone(),
            self.command.clone(),
            self.position.clone(),
        )
    }

    /// The member as a checked [`Recording`] with its dropped rows as gaps
    /// ([`Recording::allowing_gaps`]), as `feedid identify` reads it; the
    /// same as [`ZooMember::recording`] for a member without dropped rows.
    pub fn recording_with_gaps(&self) -> Result<Recording> {
        Recording::allowing_gaps(
            self.time.clone(),
            self.command.clone(),
            self.position.clone(),
            DEFAULT_JITTER_TOLERANCE,
        )
    }

    /// Write `time_s,command_m,position_m,true_position_m` (a file
    /// `feedid identify` reads with no options; shortest round-trip numbers).
    pub fn write_csv<W: Write + ?Sized>(&self, w: &mut W) -> std::io::Result<()> {
        writeln!(w, "time_s,command_m,position_m,true_position_m")?;
        for k in 0..self.len() {
            writeln!(
                w,
                "{},{},{},{}",
                self.time[k], self.command[k], self.position[k], self.truth[k]
            )?;
        }
        Ok(())
    }
}
