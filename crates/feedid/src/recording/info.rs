//! A summary of a recording — what a user checks before identifying
//! (`feedid info`): size, sampling and its jitter, channel ranges, tracking
//! error and the motion segments of the command, with warnings.
//!
//! Definitions (`c` command, `x` position, `N` samples, `Δt` median interval):
//!
//! - jitter: `max_k |t_{k+1} − t_k − Δt|`, absolute \[s\] and relative to `Δt`;
//! - channel statistics: min, max, mean and `rms = sqrt(Σ v² / N)`;
//! - tracking error `e = c − x`: `rms(e)` and `max |e|`;
//! - motion segments ([`Recording::motion_segments`]): a step is moving when
//!   `|Δc| > max(1 nm, 1e-6 · (max c − min c))` ([`SEGMENT_STEP_RELATIVE`]);
//!   pauses shorter than [`SEGMENT_MIN_STANDSTILL_S`] = 0.1 s do not split a
//!   segment; each segment has its net distance, travel `Σ|Δc|` and peak speed.
//!
//! Warnings: those of [`crate::plausibility::check_recording`] (a command
//! that never moves, a frozen position, different units, implausible speed
//! or lag, a sign or offset mismatch, what the reader decided), and a
//! command that moves from the first sample (no rest phase).
//!
//! ```
//! use feedid::{io::recording_info, Recording};
//! let t: Vec<f64> = (0..400).map(|k| k as f64 * 1e-3).collect();
//! let c: Vec<f64> = t.iter().map(|&t| if t < 0.1 { 0.0 } else { (t - 0.1) * 1e-2 }).collect();
//! let rec = Recording::new(t, c.clone(), c).unwrap();
//! let info = recording_info(&rec);
//! assert_eq!(info.segments.len(), 1);
//! assert!(info.warnings.is_empty());
//! println!("{info}");
//! ```

use std::fmt;

use serde::Serialize;

use crate::error::Syntax;
use crate::recording::plausibility::check_recording;
use crate::recording::{Gap, MotionSegment, Recording, MOTION_THRESHOLD};

/// Motion threshold per step, relative to the command range.
pub const SEGMENT_STEP_RELATIVE: f64 = 1e-6;
/// Shortest standstill that separates two motion segments \[s\].
pub const SEGMENT_MIN_STANDSTILL_S: f64 = 0.1;

/// Statistics of one channel.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChannelStats {
    /// Channel name (`command`, `position`, or the extra channel's name).
    pub name: String,
    /// Unit (`m` for command and position, empty for extra channels).
    pub unit: String,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
    /// Mean value.
    pub mean: f64,
    /// Root mean square.
    pub rms: f64,
}

/// Summary of a recording (see the module doc for the definitions).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RecordingInfo {
    /// Number of samples.
    pub samples: usize,
    /// Time of the first sample \[s\].
    pub start_s: f64,
    /// Time from first to last sample \[s\].
    pub duration_s: f64,
    /// Nominal sampling rate \[Hz\].
    pub rate_hz: f64,
    /// Nominal (median) sampling interval \[s\].
    pub dt_s: f64,
    /// Largest interval deviation relative to the nominal interval.
    pub jitter_max_relative: f64,
    /// Largest interval deviation \[s\].
    pub jitter_max_abs_s: f64,
    /// Gaps of dropped samples (read with gaps allowed; empty otherwise):
    /// `feedid identify` and `feedid stream` restart their windows there.
    pub gaps: Vec<Gap>,
    /// Samples that look missing in those gaps.
    pub missing_samples: usize,
    /// Command, position, then the extra channels.
    pub channels: Vec<ChannelStats>,
    /// RMS of command − position \[m\].
    pub tracking_error_rms_m: f64,
    /// Largest |command − position| \[m\].
    pub tracking_error_max_m: f64,
    /// Time of the last sample before the command first moves \[s\] (the paper's time origin).
    pub motion_start_s: f64,
    /// Motion segments of the command.
    pub segments: Vec<MotionSegment>,
    /// Things to check before identifying.
    pub warnings: Vec<String>,
}

/// Summarise a recording (its warnings in [`Syntax::Library`]).
pub fn recording_info(rec: &Recording) -> RecordingInfo {
    recording_info_in(rec, Syntax::Library)
}

/// [`recording_info`] with the warnings' hints in a front end's syntax
/// ([`crate::plausibility::Warning::phrased`]).
pub fn recording_info_in(rec: &Recording, syntax: Syntax) -> RecordingInfo {
    let (c, x) = (rec.command(), rec.position());
    let mut channels = vec![stats("command", "m", c), stats("position", "m", x)];
    channels.extend(rec.extra().iter().map(|(n, v)| stats(n, "", v)));

    let n = rec.len() as f64;
    let (mut se, mut emax) = (0.0_f64, 0.0_f64);
    for (a, b) in c.iter().zip(x) {
        let e = a - b;
        se += e * e;
        emax = emax.max(e.abs());
    }
    let e_rms = (se / n).sqrt();

    let c_range = channels[0].max - channels[0].min;
    let step = MOTION_THRESHOLD.max(SEGMENT_STEP_RELATIVE * c_range);
    let segments = rec.motion_segments(step, SEGMENT_MIN_STANDSTILL_S);

    let mut warnings: Vec<String> = check_recording(rec)
        .into_iter()
        .map(|w| w.phrased(syntax))
        .collect();
    if c.len() >= 2 && (c[1] - c[0]).abs() > MOTION_THRESHOLD {
        warnings.push(
            "command moves from the first sample: no rest phase before the motion".to_string(),
        );
    }

    RecordingInfo {
        samples: rec.len(),
        start_s: rec.time()[0],
        duration_s: rec.duration(),
        rate_hz: rec.rate_hz(),
        dt_s: rec.dt(),
        jitter_max_relative: rec.max_jitter(),
        jitter_max_abs_s: rec.max_jitter() * rec.dt(),
        gaps: rec.gaps().to_vec(),
        missing_samples: rec.missing_samples(),
        channels,
        tracking_error_rms_m: e_rms,
        tracking_error_max_m: emax,
        motion_start_s: rec.motion_start_time(),
        segments,
        warnings,
    }
}

fn stats(name: &str, unit: &str, v: &[f64]) -> ChannelStats {
    let n = v.len().max(1) as f64;
    let (mut min, mut max, mut sum, mut sq) = (f64::INFINITY, f64::NEG_INFINITY, 0.0, 0.0);
    for &a in v {
        min = min.min(a);
        max = max.max(a);
        sum += a;
        sq += a * a;
    }
    ChannelStats {
        name: name.to_string(),
        unit: unit.to_string(),
        min,
        max,
        mean: sum / n,
        rms: (sq / n).sqrt(),
    }
}

/// A length in mm with µm resolution, e.g. `0.5800 mm`.
fn fmt_len(m: f64) -> String {
    format!("{:.4} mm", m * 1e3)
}

/// A number with about 6 significant digits, without needless exponents.
fn fmt_num(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || (1e-3..1e6).contains(&a) {
        let decimals = if a == 0.0 {
            0
        } else {
            (5 - a.log10().floor() as i32).clamp(0, 8) as usize
        };
        format!("{v:.decimals$}")
    } else {
        format!("{v:.5e}")
    }
}

impl fmt::Display for RecordingInfo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "samples     {}", self.samples)?;
        writeln!(
            f,
            "duration    {} s (from {} s)",
            fmt_num(self.duration_s),
            fmt_num(self.start_s)
        )?;
        writeln!(
            f,
            "sampling    {} Hz, dt {} ms, jitter max {:.4} % ({} µs)",
            fmt_num(self.rate_hz),
            fmt_num(self.dt_s * 1e3),
            100.0 * self.jitter_max_relative,
            fmt_num(self.jitter_max_abs_s * 1e6)
        )?;
        if let Some(g) = self.gaps.first() {
            writeln!(
                f,
                "gaps        {} ({} sample(s) missing; the first before sample {}): identify \
                 and stream restart their windows after each",
                self.gaps.len(),
                self.missing_samples,
                g.index
            )?;
        }
        writeln!(
            f,
            "{:<12} {:>14} {:>14} {:>14} {:>14}",
            "channel", "min", "max", "mean", "rms"
        )?;
        for c in &self.channels {
            let (scale, label) = if c.unit == "m" {
                (1e3, format!("{} [mm]", c.name))
            } else {
                (1.0, c.name.clone())
            };
            writeln!(
                f,
                "{:<12} {:>14} {:>14} {:>14} {:>14}",
                label,
                fmt_num(c.min * scale),
                fmt_num(c.max * scale),
                fmt_num(c.mean * scale),
                fmt_num(c.rms * scale)
            )?;
        }
        writeln!(
            f,
            "tracking error (command − position): rms {}, max {}",
            fmt_len(self.tracking_error_rms_m),
            fmt_len(self.tracking_error_max_m)
        )?;
        writeln!(f, "motion starts at {} s", fmt_num(self.motion_start_s))?;
        writeln!(f, "motion segments: {}", self.segments.len())?;
        if !self.segments.is_empty() {
            writeln!(
                f,
                "  {:>4} {:>12} {:>12} {:>14} {:>14} {:>14}",
                "#", "start [s]", "end [s]", "distance [mm]", "travel [mm]", "peak [mm/s]"
            )?;
            for (i, s) in self.segments.iter().enumerate() {
                writeln!(
                    f,
                    "  {:>4} {:>12} {:>12} {:>14} {:>14} {:>14}",
                    i + 1,
                    fmt_num(s.start_s),
                    fmt_num(s.end_s),
                    fmt_num(s.distance_m * 1e3),
                    fmt_num(s.travel_m * 1e3),
                    fmt_num(s.peak_speed_m_per_s * 1e3)
                )?;
            }
        }
        for w in &self.warnings {
            writeln!(f, "warning: {w}")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rec(c: Vec<f64>, x: Vec<f64>) -> Recording {
        let t = (0..c.len()).map(|k| k as f64 * 1e-3).collect();
        Recording::new(t, c, x).unwrap()
    }

    #[test]
    fn statistics_match_hand_computed_values() {
        let r = rec(vec![0.0, 0.0, 1e-3, 2e-3], vec![0.0, 0.0, 0.5e-3, 1.5e-3]);
        let i = recording_info(&r);
        assert_eq!(i.samples, 4);
        assert!((i.duration_s - 3e-3).abs() < 1e-15);
        assert!((i.rate_hz - 1000.0).abs() < 1e-6);
        let c = &i.channels[0];
        assert_eq!((c.min, c.max), (0.0, 2e-3));
        assert!((c.mean - 0.75e-3).abs() < 1e-15);
        assert!((c.rms - (5e-6_f64 / 4.0).sqrt()).abs() < 1e-15);
        // e = [0, 0, 0.5, 0.5] mm
        assert!((i.tracking_error_rms_m - (0.5e-6_f64 / 4.0).sqrt()).abs() < 1e-15);
        assert!((i.tracking_error_max_m - 0.5e-3).abs() < 1e-15);
        assert!((i.motion_start_s - 1e-3).abs() < 1e-15);
        assert_eq!(i.segments.len(), 1);
        assert!((i.segments[0].distance_m - 2e-3).abs() < 1e-15);
        assert!((i.segments[0].peak_speed_m_per_s - 1.0).abs() < 1e-9);
        assert!((i.segments[0].travel_m - 2e-3).abs() < 1e-15);
        assert!(i.warnings.is_empty(), "{:?}", i.warnings);
    }

    #[test]
    fn standstill_command_is_a_warning_not_an_error() {
        let i = recording_info(&rec(vec![0.1; 5], vec![0.1; 5]));
        assert!(i.segments.is_empty());
        assert!(i.warnings.iter().any(|w| w.contains("command never moves")));
        let text = i.to_string();
        assert!(text.contains("warning: command never moves"), "{text}");
    }

    #[test]
    fn unit_mismatch_and_no_rest_are_warned() {
        let c: Vec<f64> = (0..10).map(|k| k as f64 * 1e-6).collect();
        let x: Vec<f64> = c.iter().map(|v| v * 1e3).collect();
        let i = recording_info(&rec(c, x));
        assert!(
            i.warnings.iter().any(|w| w.contains("different units")),
            "{:?}",
            i.warnings
        );
        assert!(
            i.warnings.iter().any(|w| w.contains("first sample")),
            "{:?}",
            i.warnings
        );
    }

    #[test]
    fn display_is_a_compact_table_and_json_serialises() {
        let r = rec(vec![0.0, 0.0, 1e-3, 2e-3], vec![0.0, 0.0, 0.5e-3, 1.5e-3])
            .with_channel("u", vec![1.0, 2.0, 3.0, 4.0])
            .unwrap();
        let i = recording_info(&r);
        let text = i.to_string();
        assert!(text.contains("samples     4"), "{text}");
        assert!(
            text.contains("command [mm]") && text.contains("u "),
            "{text}"
        );
        assert!(text.contains("motion segments: 1"), "{text}");
        assert!(text.lines().count() < 20, "{text}");
        let json = serde_json::to_string(&i).unwrap();
        assert!(json.contains("\"segments\"") && json.contains("\"tracking_error_rms_m\""));
    }

    #[test]
    fn number_format_is_readable() {
        assert_eq!(fmt_num(1000.0), "1000.00");
        assert_eq!(fmt_num(0.001), "0.00100000");
        assert_eq!(fmt_num(0.0), "0");
        assert_eq!(fmt_num(24.84), "24.8400");
        assert_eq!(fmt_num(2.5e-7), "2.50000e-7");
    }
}
