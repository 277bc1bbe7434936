//! The read-only view of a recording that an estimator reads: time, command
//! and measured position in absolute sample indices, the nominal sample
//! interval and the motion start, with one checked accessor for a range of
//! samples ([`Signals::window`]).
//!
//! Indices are *absolute* sample indices of the whole recording; element 0
//! of the underlying slices is sample [`Signals::offset`]. Batch processing
//! uses offset 0 ([`Signals::new`], [`Recording::signals`]); the streaming
//! path passes a moving buffer with a growing offset
//! ([`Signals::with_offset`]).
//!
//! A recording with dropped samples ([`Recording::gaps`]) gives a view that
//! knows its gaps ([`Signals::gaps`], [`Signals::segments`]): the sliding
//! engine runs each segment between gaps on its own, and an estimator only
//! ever sees a view of one segment (no gaps).
//!
//! ```
//! use feedid::ident::Signals;
//! let t = [0.0, 1e-3, 2e-3, 3e-3];
//! let u = [0.0, 1.0, 2.0, 3.0];
//! let y = [0.0, 0.5, 1.5, 2.5];
//! let s = Signals::new(&t, &u, &y, 1e-3, 0.0);
//! let w = s.window(2..4, 1, "example").unwrap(); // samples 1..4: one before the window
//! assert_eq!(w.start, 1);
//! assert_eq!(w.position, &[0.5, 1.5, 2.5]);
//! assert!(s.window(1..4, 2, "example").is_err()); // no sample before 0
//! ```

use std::ops::Range;

use crate::error::{Error, Result};
use crate::recording::{segments, Gap, Recording, MOTION_THRESHOLD};

/// Read-only view of the signals an estimator may use (see the module doc).
#[derive(Debug, Clone, Copy)]
pub struct Signals<'a> {
    offset: usize,
    time: &'a [f64],
    command: &'a [f64],
    position: &'a [f64],
    dt: f64,
    motion_start: f64,
    gaps: &'a [Gap],
}

/// The samples of one checked range (from [`Signals::window`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Samples<'a> {
    /// Absolute index of element 0 of the slices.
    pub start: usize,
    /// Time stamps \[s\].
    pub time: &'a [f64],
    /// Command (set-point) position \[m\].
    pub command: &'a [f64],
    /// Measured position \[m\].
    pub position: &'a [f64],
}

impl<'a> Signals<'a> {
    /// A view of whole arrays (offset 0): time \[s\], command \[m\], measured
    /// position \[m\], nominal sample interval `dt` \[s\] and the time at
    /// which motion starts \[s\] (the paper's time origin). Samples beyond
    /// the shortest of the three slices are not visible.
    pub fn new(
        time: &'a [f64],
        command: &'a [f64],
        position: &'a [f64],
        dt: f64,
        motion_start: f64,
    ) -> Self {
        Self::with_offset(0, time, command, position, dt, motion_start)
    }

    /// A view whose element 0 is the absolute sample `offset` (a streaming buffer).
    pub fn with_offset(
        offset: usize,
        time: &'a [f64],
        command: &'a [f64],
        position: &'a [f64],
        dt: f64,
        motion_start: f64,
    ) -> Self {
        Self {
            offset,
            time,
            command,
            position,
            dt,
            motion_start,
            gaps: &[],
        }
    }

    /// This view with the gaps `gaps` (absolute indices of the samples
    /// after them, ascending; see the module doc).
    pub fn with_gaps(self, gaps: &'a [Gap]) -> Self {
        Self { gaps, ..self }
    }

    /// This view with the motion start `t` \[s\].
    pub fn with_motion_start(self, t: f64) -> Self {
        Self {
            motion_start: t,
            ..self
        }
    }

    /// The gaps between segments (empty for a regular recording).
    pub fn gaps(&self) -> &'a [Gap] {
        self.gaps
    }

    /// The segments between gaps as absolute sample ranges (one range, all
    /// visible samples, without gaps).
    pub fn segments(&self) -> Vec<Range<usize>> {
        segments(
            self.len(),
            self.gaps.iter().map(|g| g.index - self.offset.min(g.index)),
        )
        .into_iter()
        .map(|r| r.start + self.offset..r.end + self.offset)
        .collect()
    }

    /// The view of the samples `range` (absolute, within the visible data),
    /// without gaps: one segment as the estimators see it.
    pub fn part(&self, range: Range<usize>) -> Self {
        let end = range.end.clamp(self.offset, self.end());
        let start = range.start.clamp(self.offset, end);
        let (a, b) = (start - self.offset, end - self.offset);
        Self {
            offset: start,
            time: &self.time[a..b],
            command: &self.command[a..b],
            position: &self.position[a..b],
            dt: self.dt,
            motion_start: self.motion_start,
            gaps: &[],
        }
    }

    /// [`Signals::part`] for one segment between gaps, as a recording of
    /// its own: its motion start is the last sample of the segment before
    /// its command first moves (by more than 1 nm), else its first sample.
    pub fn segment(&self, range: Range<usize>) -> Self {
        let part = self.part(range);
        let (t, c) = (part.time, part.command);
        let motion_start = match (c.first(), t.first()) {
            (Some(&c0), Some(&t0)) => c
                .iter()
                .position(|&v| (v - c0).abs() > MOTION_THRESHOLD)
                .map_or(t0, |k| t[k.saturating_sub(1)]),
            _ => part.motion_start,
        };
        Self {
            motion_start,
            ..part
        }
    }

    /// Absolute index of the first visible sample.
    pub fn offset(&self) -> usize {
        self.offset
    }

    /// Number of visible samples (the shortest of the three slices).
    pub fn len(&self) -> usize {
        self.time
            .len()
            .min(self.command.len())
            .min(self.position.len())
    }

    /// Whether no sample is visible.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// First absolute index past the visible data.
    pub fn end(&self) -> usize {
        self.offset + self.len()
    }

    /// Nominal sample interval \[s\].
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// Time at which motion starts \[s\] (the paper's time origin;
    /// `f64::INFINITY` while streaming until the command moves).
    pub fn motion_start(&self) -> f64 {
        self.motion_start
    }

    /// An error unless the three slices have the same length.
    pub fn check_lengths(&self) -> Result<()> {
        let n = self.time.len();
        if self.command.len() != n || self.position.len() != n {
            return Err(Error::LengthMismatch {
                what: "signals",
                expected: n,
                actual: self.command.len().min(self.position.len()),
            });
        }
        Ok(())
    }

    /// Every visible sample.
    pub fn all(&self) -> Samples<'a> {
        let n = self.len();
        Samples {
            start: self.offset,
            time: &self.time[..n],
            command: &self.command[..n],
            position: &self.position[..n],
        }
    }

    /// The samples `range` (absolute indices) preceded by `past` samples:
    /// `range.start − past .. range.end`, checked to lie in the visible
    /// data. The one place where estimators' windows and horizons are
    /// checked; `what` names the range in the error
    /// ([`Error::TooFewSamples`]).
    pub fn window(
        &self,
        range: Range<usize>,
        past: usize,
        what: &'static str,
    ) -> Result<Samples<'a>> {
        let first = self.offset.saturating_add(past);
        if range.start > range.end || range.start < first || range.end > self.end() {
            return Err(Error::TooFewSamples {
                what,
                needed: range
                    .end
                    .max(first.saturating_add(range.end.saturating_sub(range.start))),
                actual: self.end(),
            });
        }
        let (a, b) = (range.start - past - self.offset, range.end - self.offset);
        Ok(Samples {
            start: range.start - past,
            time: &self.time[a..b],
            command: &self.command[a..b],
            position: &self.position[a..b],
        })
    }
}

impl<S: AsRef<[f64]>> Recording<S> {
    /// The whole recording as an estimator view (offset 0, its mean sample
    /// interval and its motion start).
    pub fn signals(&self) -> Signals<'_> {
        Signals::new(
            self.time(),
            self.command(),
            self.position(),
            self.dt(),
            self.motion_start_time(),
        )
        .with_gaps(self.gaps())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn window_checks_its_range_and_the_past_samples() {
        let t = [0.0, 1.0, 2.0, 3.0, 4.0];
        let u = [10.0, 11.0, 12.0, 13.0, 14.0];
        let y = [20.0, 21.0, 22.0, 23.0];
        let s = Signals::with_offset(100, &t, &u, &y, 1.0, 0.0);
        assert_eq!(s.len(), 4, "the shortest slice");
        assert_eq!(s.end(), 104);
        assert!(s.check_lengths().is_err());
        let w = s.window(102..104, 2, "w").unwrap();
        assert_eq!((w.start, w.time, w.command), (100, &t[..4], &u[..4]));
        #[allow(clippy::reversed_empty_ranges)]
        let inverted = 103..102;
        for (r, past) in [(101..104, 2), (102..105, 0), (99..101, 0), (inverted, 0)] {
            let e = s.window(r.clone(), past, "w").unwrap_err();
            assert!(
                matches!(
                    e,
                    Error::TooFewSamples {
                        what: "w",
                        actual: 104,
                        ..
                    }
                ),
                "{r:?}: {e}"
            );
        }
        // an empty range inside the data is fine
        assert!(s.window(103..103, 0, "w").unwrap().time.is_empty());
        // huge past or range ends do not overflow
        assert!(s.window(102..104, usize::MAX, "w").is_err());
        assert!(s.window(usize::MAX - 1..usize::MAX, 0, "w").is_err());
        assert_eq!(s.all().position, &y);
    }
}
