//! A measured (or simulated) recording: time, command and measured position,
//! checked on construction.
//!
//! Checks: equal lengths, every value finite and at most [`MAX_MAGNITUDE`]
//! in magnitude (so that squares and sums of squares over any recording stay
//! finite), time strictly increasing with a mean interval of at least
//! [`MIN_INTERVAL`] (so that the rate and finite differences stay finite), and
//! uniform sampling — every interval within `jitter_tolerance` (relative) of
//! the mean interval. Nothing is dropped or reordered.
//!
//! **Dropped samples.** A recording built with gaps allowed
//! ([`Recording::allowing_gaps`], [`RecordingRef::borrowed_allowing_gaps`];
//! the reader's [`crate::io::ReadOptions::allow_gaps`], which `feedid
//! identify` sets) accepts an interval that spans a whole number `m + 1 ≥ 2`
//! of typical (median) intervals, within a quarter of one: `m` samples
//! missing, dropped by the acquisition. The sample after it starts a new
//! *segment* ([`Recording::gaps`]); the sliding engine restarts its windows
//! there, as `feedid stream` does, instead of pairing samples that are not
//! consecutive. The nominal interval is then the mean of the intervals
//! within the segments, and every one of them must still lie within the
//! jitter tolerance of it. More than [`MAX_GAPS_ANY_LENGTH`] gaps in more
//! than [`MAX_GAP_SHARE`] of the intervals are not a few dropped samples
//! but irregular sampling or a change of the rate ([`Error::TooManyGaps`]).
//! Without gaps allowed, such an interval is a [`Error::SamplingJitter`]
//! that names the missing samples.
//!
//! ```
//! use feedid::Recording;
//! let t: Vec<f64> = (0..5).map(|k| k as f64 * 2e-4).collect();
//! let r = Recording::new(t, vec![0.0; 5], vec![0.0; 5]).unwrap();
//! assert!((r.rate_hz() - 5000.0).abs() < 1e-6);
//! ```
//!
//! A recording owns its signals (`Recording`, storage `Vec<f64>`) or borrows
//! them ([`RecordingRef`], storage `&[f64]`): the borrowed form runs the same
//! checks without copying, e.g. over arrays owned by Python or a memory map.

use serde::Serialize;

use crate::error::{Error, Result};

/// Default relative tolerance on sampling-interval deviation (1 %).
pub const DEFAULT_JITTER_TOLERANCE: f64 = 0.01;

/// Largest share of a recording's intervals that may be gaps of dropped
/// samples when gaps are allowed (1 %; [`MAX_GAPS_ANY_LENGTH`] gaps are
/// accepted whatever the length): a data acquisition drops a sample now
/// and then; a recording where more intervals span whole numbers of
/// intervals is sampled irregularly or changes its rate
/// ([`Error::TooManyGaps`]).
pub const MAX_GAP_SHARE: f64 = 0.01;

/// Gaps accepted in a recording of any length (see [`MAX_GAP_SHARE`]).
pub const MAX_GAPS_ANY_LENGTH: usize = 3;

/// Largest magnitude of any value of a recording (1e100): its square summed
/// over 1e9 samples is still finite.
pub const MAX_MAGNITUDE: f64 = 1e100;

/// Shortest mean sampling interval \[s\] (1e-12 s, a rate of 1 THz): with
/// values up to [`MAX_MAGNITUDE`] every finite difference stays finite.
pub const MIN_INTERVAL: f64 = 1e-12;

/// A checked recording of command and measured position, owning its signals
/// (`S = Vec<f64>`, the default) or borrowing them ([`RecordingRef`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Recording<S = Vec<f64>> {
    time: S,
    command: S,
    position: S,
    extra: Vec<(String, Vec<f64>)>,
    dt: f64,
    max_jitter: f64,
    notes: Vec<String>,
    gaps: Vec<Gap>,
    /// The jitter tolerance it was checked with (relative).
    tolerance: f64,
}

/// Samples missing before sample `index` of a recording (see the module
/// doc, *Dropped samples*).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Gap {
    /// Zero-based index of the first sample after the gap (it starts a new segment).
    pub index: usize,
    /// Whole samples that look missing (the interval spans `missing + 1` typical ones).
    pub missing: usize,
}

impl Recording {
    /// Build with the default checks (1 % jitter tolerance).
    pub fn new(time: Vec<f64>, command: Vec<f64>, position: Vec<f64>) -> Result<Self> {
        Self::with_tolerance(time, command, position, DEFAULT_JITTER_TOLERANCE)
    }

    /// Build from uniformly sampled signals at `rate_hz`, time starting at 0.
    pub fn from_rate(rate_hz: f64, command: Vec<f64>, position: Vec<f64>) -> Result<Self> {
        if !rate_hz.is_finite() || rate_hz <= 0.0 {
            return Err(Error::InvalidParameter {
                name: "rate",
                value: rate_hz,
                reason: "must be finite and > 0",
            });
        }
        let time = (0..command.len()).map(|k| k as f64 / rate_hz).collect();
        Self::new(time, command, position)
    }

    /// Build with an explicit relative jitter tolerance (e.g. 0.01 = 1 %).
    pub fn with_tolerance(
        time: Vec<f64>,
        command: Vec<f64>,
        position: Vec<f64>,
        jitter_tolerance: f64,
    ) -> Result<Self> {
        Self::checked(time, command, position, jitter_tolerance, false)
    }

    /// Build with the jitter tolerance `jitter_tolerance`, accepting dropped
    /// samples as gaps between segments (see the module doc).
    ///
    /// ```
    /// use feedid::Recording;
    /// // 1 kHz with sample 3 missing
    /// let t = vec![0.0, 1e-3, 2e-3, 4e-3, 5e-3, 6e-3];
    /// let r = Recording::allowing_gaps(t.clone(), vec![0.0; 6], vec![0.0; 6], 0.01).unwrap();
    /// assert_eq!(r.gaps()[0].index, 3);
    /// assert_eq!(r.gaps()[0].missing, 1);
    /// assert!((r.dt() - 1e-3).abs() < 1e-12);
    /// assert_eq!(r.segments(), vec![0..3, 3..6]);
    /// assert!(Recording::new(t, vec![0.0; 6], vec![0.0; 6]).is_err());
    /// ```
    pub fn allowing_gaps(
        time: Vec<f64>,
        command: Vec<f64>,
        position: Vec<f64>,
        jitter_tolerance: f64,
    ) -> Result<Self> {
        Self::checked(time, command, position, jitter_tolerance, true)
    }
}

/// A recording that borrows its signals: checked like an owned one, copied never.
pub type RecordingRef<'a> = Recording<&'a [f64]>;

impl<'a> Recording<&'a [f64]> {
    /// Check borrowed time \[s\], command \[m\] and position \[m\] with a
    /// relative jitter tolerance (e.g. [`DEFAULT_JITTER_TOLERANCE`]) and wrap
    /// them without copying; the checks and errors are those of
    /// [`Recording::with_tolerance`].
    ///
    /// ```
    /// use feedid::{RecordingRef, recording::DEFAULT_JITTER_TOLERANCE};
    /// let t: Vec<f64> = (0..5).map(|k| k as f64 * 1e-3).collect();
    /// let u = [0.0, 1e-6, 2e-6, 3e-6, 4e-6];
    /// let r = RecordingRef::borrowed(&t, &u, &u, DEFAULT_JITTER_TOLERANCE).unwrap();
    /// assert_eq!(r.command().as_ptr(), u.as_ptr());
    /// assert!((r.rate_hz() - 1000.0).abs() < 1e-9);
    /// ```
    pub fn borrowed(
        time: &'a [f64],
        command: &'a [f64],
        position: &'a [f64],
        jitter_tolerance: f64,
    ) -> Result<Self> {
        Self::checked(time, command, position, jitter_tolerance, false)
    }

    /// [`RecordingRef::borrowed`], accepting dropped samples as gaps
    /// (see [`Recording::allowing_gaps`]).
    pub fn borrowed_allowing_gaps(
        time: &'a [f64],
        command: &'a [f64],
        position: &'a [f64],
        jitter_tolerance: f64,
    ) -> Result<Self> {
        Self::checked(time, command, position, jitter_tolerance, true)
    }
}

impl<S: AsRef<[f64]>> Recording<S> {
    /// Check the signals (see the module docs) and wrap them, owned or borrowed.
    fn checked(
        time: S,
        command: S,
        position: S,
        jitter_tolerance: f64,
        allow_gaps: bool,
    ) -> Result<Self> {
        let (dt, max_jitter, gaps) = check(
            time.as_ref(),
            command.as_ref(),
            position.as_ref(),
            jitter_tolerance,
            allow_gaps,
        )?;
        Ok(Self {
            time,
            command,
            position,
            extra: Vec::new(),
            dt,
            max_jitter,
            notes: Vec::new(),
            gaps,
            tolerance: jitter_tolerance,
        })
    }

    /// Attach a further channel (e.g. motor current); checked for length and finiteness.
    pub fn with_channel(mut self, name: &str, values: Vec<f64>) -> Result<Self> {
        if values.len() != self.len() {
            return Err(Error::LengthMismatch {
                what: "extra channel vs time",
                expected: self.len(),
                actual: values.len(),
            });
        }
        check_finite(name, &values)?;
        self.extra.push((name.to_string(), values));
        Ok(self)
    }

    /// Attach a note about how the recording was read (e.g. renamed
    /// duplicate columns); shown with the plausibility warnings.
    pub fn with_note(mut self, note: String) -> Self {
        self.notes.push(note);
        self
    }

    /// Notes attached while reading.
    pub fn notes(&self) -> &[String] {
        &self.notes
    }

    /// The first `n` samples (all of them if `n` is larger) as a recording
    /// of its own, without the further channels; the sampling was checked
    /// when this recording was built, so no jitter tolerance applies again.
    /// Its gaps before sample `n` are kept. Errors: `n < 2`.
    pub fn head(&self, n: usize) -> Result<Recording> {
        let n = n.min(self.len());
        let mut head = Recording::with_tolerance(
            self.time()[..n].to_vec(),
            self.command()[..n].to_vec(),
            self.position()[..n].to_vec(),
            f64::INFINITY,
        )?;
        head.gaps = self.gaps.iter().copied().filter(|g| g.index < n).collect();
        head.tolerance = self.tolerance;
        if !head.gaps.is_empty() {
            head.dt = self.dt;
            head.max_jitter = self.max_jitter;
        }
        Ok(head)
    }

    /// The recording without the samples `dropped` (indices, any order),
    /// read with its gaps ([`Recording::allowing_gaps`], this recording's
    /// jitter tolerance) as from an acquisition that lost them; without the
    /// further channels. Errors: as [`Recording::allowing_gaps`] (e.g. more
    /// gaps than a few dropped samples make).
    ///
    /// ```
    /// use feedid::Recording;
    /// let t: Vec<f64> = (0..100).map(|k| k as f64 * 1e-3).collect();
    /// let rec = Recording::new(t.clone(), t.clone(), t).unwrap();
    /// let lost = rec.dropping(&[40, 41]).unwrap();
    /// assert_eq!((lost.len(), lost.gaps()[0].index, lost.gaps()[0].missing), (98, 40, 2));
    /// ```
    pub fn dropping(&self, dropped: &[usize]) -> Result<Recording> {
        let keep = |v: &[f64]| -> Vec<f64> {
            v.iter()
                .enumerate()
                .filter(|(k, _)| !dropped.contains(k))
                .map(|(_, &x)| x)
                .collect()
        };
        Recording::allowing_gaps(
            keep(self.time()),
            keep(self.command()),
            keep(self.position()),
            self.tolerance,
        )
    }

    /// Samples `range` (clamped to the recording) as a recording of its own,
    /// without the further channels, with the nominal interval of this one
    /// (one segment between gaps is a regular recording). Errors: fewer than
    /// 2 samples.
    pub fn slice(&self, range: std::ops::Range<usize>) -> Result<Recording> {
        let end = range.end.min(self.len());
        let start = range.start.min(end);
        let mut part = Recording::with_tolerance(
            self.time()[start..end].to_vec(),
            self.command()[start..end].to_vec(),
            self.position()[start..end].to_vec(),
            f64::INFINITY,
        )?;
        part.gaps = self
            .gaps
            .iter()
            .filter(|g| g.index > start && g.index < end)
            .map(|g| Gap {
                index: g.index - start,
                missing: g.missing,
            })
            .collect();
        if !part.gaps.is_empty() {
            part.dt = self.dt;
        }
        part.tolerance = self.tolerance;
        Ok(part)
    }

    /// An error unless the recording is uniformly sampled (no gaps): the
    /// [`Error::SamplingJitter`] its first gap would have raised without
    /// gaps allowed, for the computations that need one time grid (free-run
    /// simulation of a model, a check of a model against the recording).
    pub fn require_uniform(&self) -> Result<()> {
        match self.gaps.first() {
            None => Ok(()),
            Some(g) => {
                let t = self.time();
                let interval = t[g.index] - t[g.index - 1];
                Err(Error::SamplingJitter {
                    index: g.index,
                    interval,
                    nominal: self.dt,
                    relative_percent: 100.0 * (interval - self.dt).abs() / self.dt,
                    tolerance_percent: 100.0 * self.tolerance,
                    missing: g.missing,
                })
            }
        }
    }

    /// The gaps (dropped samples) between segments, ascending; empty for a
    /// regular recording (see the module doc).
    pub fn gaps(&self) -> &[Gap] {
        &self.gaps
    }

    /// The index of the first sample of every segment after the first
    /// (the gaps' `index`), ascending.
    pub fn gap_starts(&self) -> impl Iterator<Item = usize> + '_ {
        self.gaps.iter().map(|g| g.index)
    }

    /// Samples that look missing in all gaps.
    pub fn missing_samples(&self) -> usize {
        self.gaps.iter().map(|g| g.missing).sum()
    }

    /// The segments between gaps as sample ranges (one range, the whole
    /// recording, without gaps).
    pub fn segments(&self) -> Vec<std::ops::Range<usize>> {
        segments(self.len(), self.gap_starts())
    }

    /// The index of every sample on the regular time grid through the gaps
    /// (`k` itself without gaps; the samples after a gap of `m` dropped ones
    /// move `m` on): the grid has `len() + missing_samples()` samples.
    pub fn grid_indices(&self) -> Vec<usize> {
        let mut out = Vec::with_capacity(self.len());
        let mut shift = 0;
        let mut gaps = self.gaps.iter().peekable();
        for k in 0..self.len() {
            if let Some(g) = gaps.next_if(|g| g.index == k) {
                shift += g.missing;
            }
            out.push(k + shift);
        }
        out
    }

    /// `values` (one per sample of the recording: a channel) on the regular
    /// time grid through the gaps ([`Recording::grid_indices`]), the dropped
    /// samples interpolated linearly between their neighbours (for a planned
    /// command, what it was there). [`Error::LengthMismatch`] if `values`
    /// has not one value per sample.
    pub fn fill_gaps(&self, values: &[f64]) -> Result<Vec<f64>> {
        if values.len() != self.len() {
            return Err(Error::LengthMismatch {
                what: "channel to place on the regular grid",
                expected: self.len(),
                actual: values.len(),
            });
        }
        let mut grid = Vec::with_capacity(values.len() + self.missing_samples());
        let mut gaps = self.gaps.iter().peekable();
        for (k, &v) in values.iter().enumerate() {
            if let Some(g) = gaps.next_if(|g| g.index == k) {
                let before = values[k - 1];
                for i in 1..=g.missing {
                    let f = i as f64 / (g.missing + 1) as f64;
                    grid.push(before + f * (v - before));
                }
            }
            grid.push(v);
        }
        Ok(grid)
    }

    /// The longest segment (the first of equal ones).
    pub fn longest_segment(&self) -> std::ops::Range<usize> {
        self.segments()
            .into_iter()
            .reduce(|a, b| if b.len() > a.len() { b } else { a })
            .unwrap_or(0..0)
    }

    /// The segment in which the command moves the most (the largest range
    /// of the command; of equal ranges the longest, then the first): the
    /// stretch without gaps that order selection and the global models use
    /// (the whole recording without gaps). A log that moves, loses a sample
    /// and then dwells has its longest stretch at rest, where a model learns
    /// nothing.
    pub fn moving_segment(&self) -> std::ops::Range<usize> {
        let c = self.command();
        let range = |r: &std::ops::Range<usize>| {
            let (lo, hi) = c[r.clone()]
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                    (a.min(v), b.max(v))
                });
            if hi >= lo {
                hi - lo
            } else {
                0.0
            }
        };
        let mut best: Option<(std::ops::Range<usize>, f64)> = None;
        for s in self.segments() {
            let r = range(&s);
            let better = best
                .as_ref()
                .is_none_or(|(b, br)| r > *br || (r == *br && s.len() > b.len()));
            if better {
                best = Some((s, r));
            }
        }
        best.map_or(0..0, |(s, _)| s)
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.time().len()
    }

    /// Always false: a recording has at least two samples.
    pub fn is_empty(&self) -> bool {
        self.time().is_empty()
    }

    /// Time stamps \[s\].
    pub fn time(&self) -> &[f64] {
        self.time.as_ref()
    }

    /// Command (set-point) position \[m\].
    pub fn command(&self) -> &[f64] {
        self.command.as_ref()
    }

    /// Measured position \[m\].
    pub fn position(&self) -> &[f64] {
        self.position.as_ref()
    }

    /// Further channels, by name.
    pub fn extra(&self) -> &[(String, Vec<f64>)] {
        &self.extra
    }

    /// Nominal (mean) sample interval \[s\].
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// Nominal sampling rate \[Hz\].
    pub fn rate_hz(&self) -> f64 {
        1.0 / self.dt
    }

    /// Largest relative deviation of an interval from the nominal one.
    pub fn max_jitter(&self) -> f64 {
        self.max_jitter
    }

    /// Duration from first to last sample \[s\].
    pub fn duration(&self) -> f64 {
        let t = self.time();
        t[t.len() - 1] - t[0]
    }

    /// Index of the last sample before the command first moves, or `None` if
    /// it never moves by more than `threshold` \[m\] from its first value.
    pub fn motion_start_index(&self, threshold: f64) -> Option<usize> {
        let c = self.command();
        let c0 = c[0];
        c.iter()
            .position(|&c| (c - c0).abs() > threshold)
            .map(|k| k.saturating_sub(1))
    }

    /// The paper's time origin: the time of the last sample before the
    /// command moves (by more than 1 nm); the first sample's time if it never moves.
    pub fn motion_start_time(&self) -> f64 {
        self.motion_start_index(MOTION_THRESHOLD)
            .map_or(self.time()[0], |k| self.time()[k])
    }

    /// Whether the command moves at all (by more than 1 nm).
    pub fn command_moves(&self) -> bool {
        self.motion_start_index(MOTION_THRESHOLD).is_some()
    }

    /// Stretches where the command moves (see [`MotionSegment`]).
    ///
    /// A step `k → k+1` is moving when `|c[k+1] − c[k]| > step_threshold` \[m\];
    /// runs of moving steps separated by a standstill shorter than
    /// `min_standstill_s` \[s\] are merged into one segment. A segment runs
    /// from the last rest sample before its first moving step to the sample
    /// after its last moving step. Empty when the command never moves.
    pub fn motion_segments(
        &self,
        step_threshold: f64,
        min_standstill_s: f64,
    ) -> Vec<MotionSegment> {
        let (t, c) = (self.time(), self.command());
        // Runs of moving steps as (first step, last step).
        let mut runs: Vec<(usize, usize)> = Vec::new();
        for k in 0..c.len().saturating_sub(1) {
            if (c[k + 1] - c[k]).abs() <= step_threshold {
                continue;
            }
            match runs.last_mut() {
                Some((_, last)) if *last + 1 == k || t[k] - t[*last + 1] < min_standstill_s => {
                    *last = k
                }
                _ => runs.push((k, k)),
            }
        }
        runs.into_iter()
            .map(|(a, b)| {
                let (mut peak, mut travel) = (0.0_f64, 0.0);
                for k in a..=b {
                    let d = (c[k + 1] - c[k]).abs();
                    travel += d;
                    peak = peak.max(d / (t[k + 1] - t[k]));
                }
                MotionSegment {
                    start_s: t[a],
                    end_s: t[b + 1],
                    distance_m: c[b + 1] - c[a],
                    travel_m: travel,
                    peak_speed_m_per_s: peak,
                }
            })
            .collect()
    }
}

/// A stretch of the recording where the command moves.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MotionSegment {
    /// Time of the last rest sample before the motion \[s\].
    pub start_s: f64,
    /// Time of the first sample after the last moving step \[s\].
    pub end_s: f64,
    /// Net command displacement over the segment, signed \[m\].
    pub distance_m: f64,
    /// Path length of the command over the segment, `Σ|Δc|` \[m\].
    pub travel_m: f64,
    /// Largest command speed `|Δc|/Δt` in the segment \[m/s\].
    pub peak_speed_m_per_s: f64,
}

/// Command change that counts as motion \[m\] (1 nm).
pub const MOTION_THRESHOLD: f64 = 1e-9;

/// The checks of a recording (see the module docs); returns the nominal
/// interval \[s\], the largest relative interval deviation and, with
/// `allow_gaps`, the gaps (dropped samples).
fn check(
    time: &[f64],
    command: &[f64],
    position: &[f64],
    jitter_tolerance: f64,
    allow_gaps: bool,
) -> Result<(f64, f64, Vec<Gap>)> {
    if command.len() != time.len() {
        return Err(Error::LengthMismatch {
            what: "command vs time",
            expected: time.len(),
            actual: command.len(),
        });
    }
    if position.len() != time.len() {
        return Err(Error::LengthMismatch {
            what: "position vs time",
            expected: time.len(),
            actual: position.len(),
        });
    }
    if time.len() < 2 {
        return Err(Error::TooFewSamples {
            what: "a recording",
            needed: 2,
            actual: time.len(),
        });
    }
    check_finite("time", time)?;
    check_finite("command", command)?;
    check_finite("position", position)?;
    for k in 1..time.len() {
        if time[k] <= time[k - 1] {
            return Err(Error::NonMonotoneTime {
                index: k,
                previous: time[k - 1],
                value: time[k],
            });
        }
    }
    let dt = mean_interval(time);
    if dt < MIN_INTERVAL {
        return Err(Error::SamplingInterval {
            interval: dt,
            min: MIN_INTERVAL,
            max_rate: 1.0 / MIN_INTERVAL,
        });
    }
    let (worst, max_jitter) = largest_deviation(time, dt, &[]);
    if max_jitter <= jitter_tolerance {
        return Ok((dt, max_jitter, Vec::new()));
    }
    // a whole number of typical (median) intervals, within a quarter:
    // samples dropped (the mean is stretched by the gaps themselves)
    let mut steps: Vec<f64> = time.windows(2).map(|w| w[1] - w[0]).collect();
    let mid = steps.len() / 2;
    let (_, median, _) = steps.select_nth_unstable_by(mid, f64::total_cmp);
    let median = *median;
    let missing_at = |k: usize| {
        let ratio = (time[k] - time[k - 1]) / median;
        let whole = ratio.round();
        if whole >= 2.0 && (ratio - whole).abs() <= 0.25 {
            whole as usize - 1
        } else {
            0
        }
    };
    let jitter_error = |worst: usize, dt: f64, max_jitter: f64| Error::SamplingJitter {
        index: worst,
        interval: time[worst] - time[worst - 1],
        nominal: dt,
        relative_percent: 100.0 * max_jitter,
        tolerance_percent: 100.0 * jitter_tolerance,
        missing: missing_at(worst),
    };
    if !allow_gaps {
        return Err(jitter_error(worst, dt, max_jitter));
    }
    let gaps: Vec<Gap> = (1..time.len())
        .filter_map(|k| {
            let missing = missing_at(k);
            (missing > 0).then_some(Gap { index: k, missing })
        })
        .collect();
    let intervals = time.len() - 1;
    if gaps.len() > MAX_GAPS_ANY_LENGTH && gaps.len() as f64 > MAX_GAP_SHARE * intervals as f64 {
        return Err(Error::TooManyGaps {
            index: gaps[0].index,
            gaps: gaps.len(),
            intervals,
            max_percent: 100.0 * MAX_GAP_SHARE,
        });
    }
    // the nominal interval within the segments (each is uniformly sampled)
    let (mut span, mut intervals) = (0.0, 0usize);
    for r in segments(time.len(), gaps.iter().map(|g| g.index)) {
        if r.len() >= 2 {
            span += time[r.end - 1] - time[r.start];
            intervals += r.len() - 1;
        }
    }
    if intervals == 0 {
        return Err(jitter_error(worst, dt, max_jitter));
    }
    let dt = span / intervals as f64;
    let (worst, max_jitter) = largest_deviation(time, dt, &gaps);
    if max_jitter > jitter_tolerance {
        return Err(jitter_error(worst, dt, max_jitter));
    }
    Ok((dt, max_jitter, gaps))
}

/// The interval (by the index of the sample ending it) that deviates most
/// from `dt`, and its relative deviation; the intervals ending at a gap's
/// sample are skipped.
fn largest_deviation(time: &[f64], dt: f64, gaps: &[Gap]) -> (usize, f64) {
    let mut next_gap = gaps.iter().map(|g| g.index).peekable();
    let (mut worst, mut max_jitter) = (1, 0.0_f64);
    for k in 1..time.len() {
        if next_gap.peek() == Some(&k) {
            next_gap.next();
            continue;
        }
        let rel = ((time[k] - time[k - 1]) - dt).abs() / dt;
        if rel > max_jitter {
            max_jitter = rel;
            worst = k;
        }
    }
    (worst, max_jitter)
}

/// The segments of `n` samples split before each of `starts` (ascending
/// indices in `1..n`; others are ignored): `0..s₁, s₁..s₂, …, sₘ..n`.
pub fn segments(n: usize, starts: impl Iterator<Item = usize>) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    let mut from = 0;
    for s in starts {
        if s > from && s < n {
            out.push(from..s);
            from = s;
        }
    }
    if from < n {
        out.push(from..n);
    }
    out
}

fn check_finite(channel: &str, v: &[f64]) -> Result<()> {
    match v.iter().position(|x| !is_usable(*x)) {
        Some(index) if !v[index].is_finite() => Err(Error::NonFinite {
            channel: channel.to_string(),
            index,
            value: v[index],
        }),
        Some(index) => Err(Error::OutOfRange {
            channel: channel.to_string(),
            index,
            value: v[index],
            limit: MAX_MAGNITUDE,
        }),
        None => Ok(()),
    }
}

/// Whether a value is accepted in a recording: finite and at most [`MAX_MAGNITUDE`] in magnitude.
pub fn is_usable(x: f64) -> bool {
    x.abs() <= MAX_MAGNITUDE
}

/// Mean interval `(t_last − t_first)/(n − 1)` of a strictly increasing
/// sequence (len ≥ 2): exact for alternating time-stamp jitter such as the
/// EMPS file's 1.000024 / 0.999984 ms, where the median would be biased.
fn mean_interval(time: &[f64]) -> f64 {
    (time[time.len() - 1] - time[0]) / (time.len() - 1) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    fn t(n: usize) -> Vec<f64> {
        (0..n).map(|k| k as f64 * 1e-3).collect()
    }

    #[test]
    fn borrowed_recording_checks_alike_and_does_not_copy() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(17);
        for case in 0..60 {
            let n = rng.random_range(0..12);
            let mut time: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
            let mut command: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
            let mut position = command.clone();
            // spoil one thing (or nothing) at random
            match (rng.random_range(0..6), n > 2) {
                (0, true) => time[n / 2] = time[n / 2 - 1],
                (1, true) => time[n / 2] += 4e-4,
                (2, true) => position[n - 1] = f64::NAN,
                (3, true) => command[1] = 1e200,
                (4, _) => {
                    position.pop();
                }
                _ => {}
            }
            let tol = DEFAULT_JITTER_TOLERANCE;
            let owned =
                Recording::with_tolerance(time.clone(), command.clone(), position.clone(), tol);
            let borrowed = RecordingRef::borrowed(&time, &command, &position, tol);
            match (owned, borrowed) {
                (Ok(o), Ok(b)) => {
                    assert_eq!(b.time().as_ptr(), time.as_ptr(), "case {case}");
                    assert_eq!(b.command().as_ptr(), command.as_ptr());
                    assert_eq!(b.position().as_ptr(), position.as_ptr());
                    assert_eq!((o.dt(), o.max_jitter()), (b.dt(), b.max_jitter()));
                    assert_eq!(o.motion_start_time(), b.motion_start_time());
                    assert_eq!(o.head(3).unwrap(), b.head(3).unwrap());
                }
                (Err(o), Err(b)) => assert_eq!(o.to_string(), b.to_string(), "case {case}"),
                (o, b) => panic!("case {case}: owned {o:?} but borrowed {b:?}"),
            }
        }
    }

    #[test]
    fn rejects_mismatched_lengths() {
        let e = Recording::new(t(4), vec![0.0; 3], vec![0.0; 4]).unwrap_err();
        assert!(matches!(
            e,
            Error::LengthMismatch {
                expected: 4,
                actual: 3,
                ..
            }
        ));
    }

    #[test]
    fn rejects_nan_with_index() {
        let mut y = vec![0.0; 4];
        y[2] = f64::NAN;
        let e = Recording::new(t(4), vec![0.0; 4], y).unwrap_err();
        assert!(matches!(e, Error::NonFinite { index: 2, .. }), "{e}");
    }

    #[test]
    fn rejects_decreasing_and_duplicate_time() {
        let mut tt = t(5);
        tt[3] = tt[2];
        let e = Recording::new(tt, vec![0.0; 5], vec![0.0; 5]).unwrap_err();
        assert!(matches!(e, Error::NonMonotoneTime { index: 3, .. }), "{e}");
    }

    #[test]
    fn rejects_jitter_beyond_tolerance_and_reports_size() {
        let mut tt = t(10);
        tt[5] += 1e-4; // 10 % of the interval
        let e = Recording::new(tt, vec![0.0; 10], vec![0.0; 10]).unwrap_err();
        match e {
            Error::SamplingJitter {
                relative_percent, ..
            } => {
                assert!((relative_percent - 10.0).abs() < 1e-6)
            }
            other => panic!("unexpected {other}"),
        }
    }

    #[test]
    fn dropped_samples_are_named_in_the_jitter_error() {
        // 40 samples at 1 ms with `drop` consecutive ones missing after sample 20
        for (drop, missing) in [(1, 1), (3, 3), (0, 0)] {
            let mut tt: Vec<f64> = (0..40)
                .filter(|&k| !(21..21 + drop).contains(&k))
                .map(|k| k as f64 * 1e-3)
                .collect();
            if drop == 0 {
                tt[21] += 0.4e-3; // 40 % jitter: not a whole interval
            }
            let n = tt.len();
            let e = Recording::new(tt, vec![0.0; n], vec![0.0; n]).unwrap_err();
            match &e {
                Error::SamplingJitter {
                    index, missing: m, ..
                } => {
                    assert_eq!(*m, missing, "{e}");
                    // (the jittered sample makes two intervals 40 % off)
                    assert!(*index == 21 || drop == 0, "{e}");
                }
                other => panic!("unexpected {other}"),
            }
            let text = e.to_string();
            assert_eq!(text.contains("`stream` restart"), missing > 0, "{text}");
            if missing == 1 {
                assert!(text.contains("1 sample looks missing"), "{text}");
            }
        }
    }

    #[test]
    fn dropped_samples_are_gaps_between_segments_when_allowed() {
        // 60 samples at 1 ms from t = 5 s; sample 21 and samples 40..43 missing
        let tt: Vec<f64> = (0..60)
            .filter(|&k| k != 21 && !(40..43).contains(&k))
            .map(|k| 5.0 + k as f64 * 1e-3)
            .collect();
        let n = tt.len();
        let u: Vec<f64> = (0..n).map(|k| k as f64 * 1e-6).collect();
        let r = Recording::allowing_gaps(tt.clone(), u.clone(), u.clone(), 0.01).unwrap();
        let g: Vec<(usize, usize)> = r.gaps().iter().map(|g| (g.index, g.missing)).collect();
        assert_eq!(g, [(21, 1), (39, 3)]);
        assert_eq!(r.missing_samples(), 4);
        assert_eq!(r.segments(), vec![0..21, 21..39, 39..n]);
        assert_eq!(r.longest_segment(), 0..21);
        // a ramp moves most in its longest segment
        assert_eq!(r.moving_segment(), 0..21);
        let still = Recording::allowing_gaps(tt.clone(), vec![0.0; n], u.clone(), 0.01).unwrap();
        assert_eq!(still.moving_segment(), 0..21, "no motion: the longest");
        let mut step = vec![0.0; n];
        for v in &mut step[21..25] {
            *v = 1e-3;
        }
        let moved = Recording::allowing_gaps(tt.clone(), step, u.clone(), 0.01).unwrap();
        assert_eq!(
            moved.moving_segment(),
            21..39,
            "the short stretch that moves"
        );
        // the nominal interval is that of the segments, not stretched by the gaps
        assert!((r.dt() - 1e-3).abs() < 1e-12, "{}", r.dt());
        assert!(r.max_jitter() < 1e-9);
        // borrowed alike; head and slice keep the gaps they contain
        let b = RecordingRef::borrowed_allowing_gaps(&tt, &u, &u, 0.01).unwrap();
        assert_eq!((b.gaps(), b.dt()), (r.gaps(), r.dt()));
        assert_eq!(r.head(30).unwrap().gaps(), &r.gaps()[..1]);
        let s = r.slice(10..45).unwrap();
        let g: Vec<(usize, usize)> = s.gaps().iter().map(|g| (g.index, g.missing)).collect();
        assert_eq!(g, [(11, 1), (29, 3)]);
        assert_eq!(r.slice(21..39).unwrap().gaps(), &[]);
        // the regular grid through the gaps: each sample where its time puts
        // it, a channel linear across the gaps (the time itself, here)
        let grid = r.grid_indices();
        assert_eq!(grid.len(), n);
        for (k, &i) in grid.iter().enumerate() {
            assert!((tt[k] - (5.0 + i as f64 * 1e-3)).abs() < 1e-9, "{k} {i}");
        }
        let full = r.fill_gaps(&tt).unwrap();
        assert_eq!(full.len(), 60);
        for (i, &t) in full.iter().enumerate() {
            assert!((t - (5.0 + i as f64 * 1e-3)).abs() < 1e-9, "{i}");
        }
        assert!(r.fill_gaps(&tt[1..]).is_err());
        assert_eq!(
            r.slice(0..21).unwrap().grid_indices(),
            (0..21).collect::<Vec<_>>()
        );
        // without gaps allowed: the jitter error names the missing sample
        let e = Recording::new(tt.clone(), u.clone(), u.clone()).unwrap_err();
        assert!(
            matches!(e, Error::SamplingJitter { missing: 1 | 3, .. }),
            "{e}"
        );
        // and says which commands read it anyway
        let m = e.to_string();
        assert!(
            m.contains("`feedid identify`, `report`, `sweep` and `stream` restart"),
            "{m}"
        );
        assert!(m.contains("`greybox` simulates through it"), "{m}");
        // an interval that is not a whole number of intervals stays an error,
        // and so does jitter within a segment
        for (k, dt) in [(30, 0.5e-3), (10, 0.05e-3)] {
            let mut bad = tt.clone();
            for v in &mut bad[k..] {
                *v += dt;
            }
            let e = Recording::allowing_gaps(bad, u.clone(), u.clone(), 0.01).unwrap_err();
            assert!(
                matches!(e, Error::SamplingJitter { index, missing: 0, .. } if index == k),
                "{e}"
            );
        }
        // what needs one time grid refuses the gaps, naming the first
        let e = Recording::allowing_gaps(tt.clone(), u.clone(), u.clone(), 0.01)
            .unwrap()
            .require_uniform()
            .unwrap_err();
        assert!(
            matches!(
                e,
                Error::SamplingJitter {
                    index: 21,
                    missing: 1,
                    ..
                }
            ),
            "{e}"
        );
        // a change of the rate halfway is not a few dropped samples
        let halved: Vec<f64> = (0..60)
            .map(|k| if k < 40 { k as f64 } else { 40.0 + 2.0 * (k - 40) as f64 } * 1e-3)
            .collect();
        let e = Recording::allowing_gaps(halved, vec![0.0; 60], vec![0.0; 60], 0.01).unwrap_err();
        assert!(
            matches!(
                e,
                Error::TooManyGaps {
                    index: 41,
                    gaps: 19,
                    intervals: 59,
                    ..
                }
            ),
            "{e}"
        );
        // a regular recording has one segment and no gaps
        let r = Recording::allowing_gaps(t(10), vec![0.0; 10], vec![0.0; 10], 0.01).unwrap();
        assert!(r.gaps().is_empty() && r.require_uniform().is_ok());
        assert_eq!(r.segments(), vec![0..10]);
    }

    #[test]
    fn motion_start_is_last_rest_sample() {
        let c = vec![0.0, 0.0, 0.0, 1e-6, 2e-6];
        let r = Recording::new(t(5), c, vec![0.0; 5]).unwrap();
        assert_eq!(r.motion_start_index(1e-9), Some(2));
        assert!((r.motion_start_time() - 2e-3).abs() < 1e-15);
    }

    #[test]
    fn motion_segments_merge_short_pauses_and_split_long_ones() {
        // 1 kHz: rest 10, ramp +1 mm/s for 10 steps, pause 5 (short), ramp 5,
        // pause 200 (long), ramp back -2 mm/s for 10 steps, rest.
        let mut c = vec![0.0; 10];
        let mut x = 0.0;
        let mut push = |steps: usize, dx: f64, c: &mut Vec<f64>| {
            for _ in 0..steps {
                x += dx;
                c.push(x);
            }
        };
        push(10, 1e-6, &mut c);
        push(5, 0.0, &mut c);
        push(5, 1e-6, &mut c);
        push(200, 0.0, &mut c);
        push(10, -2e-6, &mut c);
        push(10, 0.0, &mut c);
        let n = c.len();
        let r = Recording::new(t(n), c, vec![0.0; n]).unwrap();
        let s = r.motion_segments(1e-9, 0.05);
        assert_eq!(s.len(), 2, "{s:?}");
        assert!((s[0].start_s - 0.009).abs() < 1e-12 && (s[0].end_s - 0.029).abs() < 1e-12);
        assert!((s[0].distance_m - 15e-6).abs() < 1e-15);
        assert!((s[0].peak_speed_m_per_s - 1e-3).abs() < 1e-9);
        assert!((s[1].distance_m + 20e-6).abs() < 1e-15);
        assert!((s[1].travel_m - 20e-6).abs() < 1e-15);
        assert!((s[1].peak_speed_m_per_s - 2e-3).abs() < 1e-9);
        // A long minimum standstill merges everything into one segment.
        assert_eq!(r.motion_segments(1e-9, 1.0).len(), 1);
        // A short one splits the first segment at the 5-sample pause.
        assert_eq!(r.motion_segments(1e-9, 0.001).len(), 3);
    }

    #[test]
    fn standstill_has_no_motion_start() {
        let r = Recording::new(t(5), vec![1.0; 5], vec![0.0; 5]).unwrap();
        assert!(!r.command_moves());
        assert_eq!(r.motion_start_time(), 0.0);
    }
}
