//! Options shared by every recording reader: which columns or variables hold
//! time, command and position, and the units they are in.
//!
//! Conversions to SI (what [`crate::Recording`] holds):
//!
//! - position and command: `x[m] = factor · x[file]`, with `factor` the
//!   [`Unit`] factor (m = 1, mm = 1e-3, um = 1e-6, nm = 1e-9) or, for encoder
//!   counts, the explicit [`ReadOptions::scale`] (e.g. 1e-7 m/count);
//! - time: `t[s] = factor · t[file]` with the [`TimeUnit`] factor
//!   (s = 1, ms = 1e-3, us = 1e-6); or, without a time column,
//!   `t_k = k / rate_hz`, `k = 0, 1, …`.
//!
//! ```
//! use feedid::io::{ChannelRef, ReadOptions, Unit};
//! let opts = ReadOptions {
//!     command: Some("2".parse().unwrap()),
//!     position: Some(ChannelRef::Name("x_mm".into())),
//!     position_unit: "mm".parse().unwrap(),
//!     ..ReadOptions::default()
//! };
//! assert_eq!(opts.command, Some(ChannelRef::Index(2)));
//! assert_eq!(opts.position_unit, Unit::Mm);
//! ```

use std::fmt;
use std::str::FromStr;

use crate::error::{Error, Result};
use crate::recording::DEFAULT_JITTER_TOLERANCE;

/// Default name of the time column in text files.
pub const DEFAULT_TIME_COLUMN: &str = "time_s";
/// Default name of the command column in text files.
pub const DEFAULT_COMMAND_COLUMN: &str = "command_m";
/// Default name of the position column in text files.
pub const DEFAULT_POSITION_COLUMN: &str = "position_m";

/// A column (text files) or variable (MAT-files), by name or 1-based index.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ChannelRef {
    /// By header name (text) or variable name (MAT).
    Name(String),
    /// By 1-based column index (text files only).
    Index(usize),
}

impl ChannelRef {
    /// Parse a user string: all digits → [`ChannelRef::Index`], else [`ChannelRef::Name`].
    ///
    /// Fails on an empty string and on index `0` (indices are 1-based).
    pub fn parse(s: &str) -> Result<Self> {
        let t = s.trim();
        if t.is_empty() {
            return Err(Error::InvalidChoice {
                what: "column",
                value: s.to_string(),
                expected: "a column name or a 1-based column index",
            });
        }
        if t.bytes().all(|b| b.is_ascii_digit()) {
            return match t.parse::<usize>() {
                Ok(0) | Err(_) => Err(Error::InvalidChoice {
                    what: "column index",
                    value: s.to_string(),
                    expected: "1, 2, 3, ... (indices are 1-based)",
                }),
                Ok(i) => Ok(ChannelRef::Index(i)),
            };
        }
        Ok(ChannelRef::Name(t.to_string()))
    }
}

impl FromStr for ChannelRef {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        ChannelRef::parse(s)
    }
}

impl fmt::Display for ChannelRef {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ChannelRef::Name(n) => write!(f, "{n}"),
            ChannelRef::Index(i) => write!(f, "{i}"),
        }
    }
}

/// Length unit of position and command in the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Unit {
    /// Metres (default).
    #[default]
    M,
    /// Millimetres.
    Mm,
    /// Micrometres.
    Um,
    /// Nanometres.
    Nm,
}

impl Unit {
    /// Metres per file unit.
    pub fn factor(self) -> f64 {
        match self {
            Unit::M => 1.0,
            Unit::Mm => 1e-3,
            Unit::Um => 1e-6,
            Unit::Nm => 1e-9,
        }
    }

    /// Short name (`m`, `mm`, `um`, `nm`).
    pub fn as_str(self) -> &'static str {
        match self {
            Unit::M => "m",
            Unit::Mm => "mm",
            Unit::Um => "um",
            Unit::Nm => "nm",
        }
    }
}

impl FromStr for Unit {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "m" => Ok(Unit::M),
            "mm" => Ok(Unit::Mm),
            "um" | "µm" | "μm" => Ok(Unit::Um),
            "nm" => Ok(Unit::Nm),
            _ => Err(Error::InvalidChoice {
                what: "position unit",
                value: s.to_string(),
                expected: "m, mm, um, nm (for encoder counts use a scale factor instead)",
            }),
        }
    }
}

impl fmt::Display for Unit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Unit of the time column in the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TimeUnit {
    /// Seconds (default).
    #[default]
    S,
    /// Milliseconds.
    Ms,
    /// Microseconds.
    Us,
}

impl TimeUnit {
    /// Seconds per file unit.
    pub fn factor(self) -> f64 {
        match self {
            TimeUnit::S => 1.0,
            TimeUnit::Ms => 1e-3,
            TimeUnit::Us => 1e-6,
        }
    }

    /// Short name (`s`, `ms`, `us`).
    pub fn as_str(self) -> &'static str {
        match self {
            TimeUnit::S => "s",
            TimeUnit::Ms => "ms",
            TimeUnit::Us => "us",
        }
    }
}

impl FromStr for TimeUnit {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "s" => Ok(TimeUnit::S),
            "ms" => Ok(TimeUnit::Ms),
            "us" | "µs" | "μs" => Ok(TimeUnit::Us),
            _ => Err(Error::InvalidChoice {
                what: "time unit",
                value: s.to_string(),
                expected: "s, ms, us",
            }),
        }
    }
}

impl fmt::Display for TimeUnit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// How to read a recording file.
#[derive(Debug, Clone, PartialEq)]
pub struct ReadOptions {
    /// Time column/variable. Default (text): column `time_s`; MAT: none, so
    /// either this or `rate_hz` must be given. Must be `None` when `rate_hz` is set.
    pub time: Option<ChannelRef>,
    /// Command column/variable. Default (text): `command_m`; MAT: required.
    pub command: Option<ChannelRef>,
    /// Position column/variable. Default (text): `position_m`; MAT: required.
    pub position: Option<ChannelRef>,
    /// Sampling rate \[Hz\] when the file has no time column: `t_k = k / rate_hz`. Default: none.
    pub rate_hz: Option<f64>,
    /// Text delimiter byte; `None` (default) detects `\t`, `;`, `,` or runs of
    /// whitespace (`b' '` also means runs of whitespace).
    pub delimiter: Option<u8>,
    /// Whether the first row is a header; `None` (default) detects it.
    pub header: Option<bool>,
    /// Unit of position and command in the file. Default: m.
    pub position_unit: Unit,
    /// Factor \[m per file unit\] applied to position and command (e.g.
    /// encoder counts → m); cannot be combined with a unit other than m. Default: none.
    pub scale: Option<f64>,
    /// Unit of the time column. Default: s.
    pub time_unit: TimeUnit,
    /// Allowed relative deviation of a sampling interval from the mean one. Default: 0.01.
    pub jitter_tolerance: f64,
    /// Read only the time, command and position columns (variables), the
    /// columnar read of `feedid identify`: no extra channels
    /// ([`crate::Recording::extra`] stays empty), so a recording holds three
    /// `f64` per sample whatever the file's width. Default: false (every
    /// other all-numeric column or vector is kept as an extra channel).
    pub signals_only: bool,
    /// Accept dropped samples — an interval of a whole number (≥ 2) of
    /// typical intervals — as gaps between segments
    /// ([`crate::Recording::gaps`]; the sliding engine restarts its windows
    /// after each), as `feedid identify` does. Default: false (such an
    /// interval is a sampling-jitter error naming the missing samples).
    pub allow_gaps: bool,
}

impl Default for ReadOptions {
    fn default() -> Self {
        Self {
            time: None,
            command: None,
            position: None,
            rate_hz: None,
            delimiter: None,
            header: None,
            position_unit: Unit::M,
            scale: None,
            time_unit: TimeUnit::S,
            jitter_tolerance: DEFAULT_JITTER_TOLERANCE,
            signals_only: false,
            allow_gaps: false,
        }
    }
}

impl ReadOptions {
    /// Check the options for consistency (before any file is read).
    pub fn validate(&self) -> Result<()> {
        if let Some(rate) = self.rate_hz {
            if !rate.is_finite() || rate <= 0.0 {
                return Err(Error::InvalidParameter {
                    name: "rate",
                    value: rate,
                    reason: "must be finite and > 0",
                });
            }
            if self.time.is_some() {
                return Err(Error::InvalidParameter {
                    name: "rate",
                    value: rate,
                    reason: "give either a sampling rate or a time column, not both",
                });
            }
        }
        if let Some(scale) = self.scale {
            if !scale.is_finite() || scale == 0.0 {
                return Err(Error::InvalidParameter {
                    name: "scale",
                    value: scale,
                    reason: "must be finite and non-zero",
                });
            }
            if self.position_unit != Unit::M {
                return Err(Error::InvalidParameter {
                    name: "scale",
                    value: scale,
                    reason: "cannot be combined with a position unit other than m",
                });
            }
        }
        if !self.jitter_tolerance.is_finite() || self.jitter_tolerance < 0.0 {
            return Err(Error::InvalidParameter {
                name: "jitter tolerance",
                value: self.jitter_tolerance,
                reason: "must be finite and >= 0",
            });
        }
        Ok(())
    }

    /// Metres per file unit of position and command (`scale`, else the unit factor).
    pub fn position_factor(&self) -> f64 {
        self.scale.unwrap_or_else(|| self.position_unit.factor())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn channel_ref_digits_are_one_based_indices_else_names() {
        assert_eq!(ChannelRef::parse("3").unwrap(), ChannelRef::Index(3));
        assert_eq!(
            ChannelRef::parse(" qm ").unwrap(),
            ChannelRef::Name("qm".into())
        );
        assert_eq!(
            ChannelRef::parse("x3").unwrap(),
            ChannelRef::Name("x3".into())
        );
        assert!(ChannelRef::parse("0").is_err());
        assert!(ChannelRef::parse("").is_err());
    }

    #[test]
    fn units_parse_and_convert_to_si() {
        assert_eq!("mm".parse::<Unit>().unwrap().factor(), 1e-3);
        assert_eq!("µm".parse::<Unit>().unwrap(), Unit::Um);
        assert_eq!("NM".parse::<Unit>().unwrap().factor(), 1e-9);
        assert_eq!("ms".parse::<TimeUnit>().unwrap().factor(), 1e-3);
        let e = "inch".parse::<Unit>().unwrap_err().to_string();
        assert!(e.contains("inch") && e.contains("m, mm, um, nm"), "{e}");
        let e = "min".parse::<TimeUnit>().unwrap_err().to_string();
        assert!(e.contains("s, ms, us"), "{e}");
    }

    #[test]
    fn scale_and_non_metre_unit_are_exclusive() {
        let o = ReadOptions {
            scale: Some(1e-7),
            position_unit: Unit::Mm,
            ..Default::default()
        };
        assert!(matches!(
            o.validate(),
            Err(Error::InvalidParameter { name: "scale", .. })
        ));
        let o = ReadOptions {
            scale: Some(1e-7),
            ..Default::default()
        };
        o.validate().unwrap();
        assert_eq!(o.position_factor(), 1e-7);
    }

    #[test]
    fn rate_and_time_column_are_exclusive() {
        let o = ReadOptions {
            rate_hz: Some(1000.0),
            time: Some(ChannelRef::Index(1)),
            ..Default::default()
        };
        assert!(o.validate().is_err());
        let o = ReadOptions {
            rate_hz: Some(-1.0),
            ..Default::default()
        };
        assert!(o.validate().is_err());
    }
}
