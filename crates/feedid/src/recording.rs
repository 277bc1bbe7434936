//! A measured (or simulated) recording: time, command and measured position,
//! checked on construction.
//!
//! Checks: equal lengths, every value finite, time strictly increasing, and
//! uniform sampling — every interval within `jitter_tolerance` (relative) of
//! the median interval. Nothing is dropped or reordered.
//!
//! ```
//! use feedid::Recording;
//! let t: Vec<f64> = (0..5).map(|k| k as f64 * 2e-4).collect();
//! let r = Recording::new(t, vec![0.0; 5], vec![0.0; 5]).unwrap();
//! assert!((r.rate_hz() - 5000.0).abs() < 1e-6);
//! ```

use crate::error::{Error, Result};
use crate::ident::Signals;

/// Default relative tolerance on sampling-interval deviation (1 %).
pub const DEFAULT_JITTER_TOLERANCE: f64 = 0.01;

/// A checked recording of command and measured position.
#[derive(Debug, Clone, PartialEq)]
pub struct Recording {
    time: Vec<f64>,
    command: Vec<f64>,
    position: Vec<f64>,
    extra: Vec<(String, Vec<f64>)>,
    dt: f64,
    max_jitter: f64,
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
        check_finite("time", &time)?;
        check_finite("command", &command)?;
        check_finite("position", &position)?;
        for k in 1..time.len() {
            if time[k] <= time[k - 1] {
                return Err(Error::NonMonotoneTime {
                    index: k,
                    previous: time[k - 1],
                    value: time[k],
                });
            }
        }
        let dt = median_interval(&time);
        let mut max_jitter = 0.0_f64;
        let mut worst = 0;
        for k in 1..time.len() {
            let rel = ((time[k] - time[k - 1]) - dt).abs() / dt;
            if rel > max_jitter {
                max_jitter = rel;
                worst = k;
            }
        }
        if max_jitter > jitter_tolerance {
            return Err(Error::SamplingJitter {
                index: worst,
                interval: time[worst] - time[worst - 1],
                nominal: dt,
                relative_percent: 100.0 * max_jitter,
                tolerance_percent: 100.0 * jitter_tolerance,
            });
        }
        Ok(Self {
            time,
            command,
            position,
            extra: Vec::new(),
            dt,
            max_jitter,
        })
    }

    /// Attach a further channel (e.g. motor current); checked for length and finiteness.
    pub fn with_channel(mut self, name: &str, values: Vec<f64>) -> Result<Self> {
        if values.len() != self.time.len() {
            return Err(Error::LengthMismatch {
                what: "extra channel vs time",
                expected: self.time.len(),
                actual: values.len(),
            });
        }
        check_finite(name, &values)?;
        self.extra.push((name.to_string(), values));
        Ok(self)
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.time.len()
    }

    /// Always false: a recording has at least two samples.
    pub fn is_empty(&self) -> bool {
        self.time.is_empty()
    }

    /// Time stamps \[s\].
    pub fn time(&self) -> &[f64] {
        &self.time
    }

    /// Command (set-point) position \[m\].
    pub fn command(&self) -> &[f64] {
        &self.command
    }

    /// Measured position \[m\].
    pub fn position(&self) -> &[f64] {
        &self.position
    }

    /// Further channels, by name.
    pub fn extra(&self) -> &[(String, Vec<f64>)] {
        &self.extra
    }

    /// Nominal (median) sample interval \[s\].
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
        self.time[self.time.len() - 1] - self.time[0]
    }

    /// Index of the last sample before the command first moves, or `None` if
    /// it never moves by more than `threshold` \[m\] from its first value.
    pub fn motion_start_index(&self, threshold: f64) -> Option<usize> {
        let c0 = self.command[0];
        self.command
            .iter()
            .position(|&c| (c - c0).abs() > threshold)
            .map(|k| k.saturating_sub(1))
    }

    /// The paper's time origin: the time of the last sample before the
    /// command moves (by more than 1 nm); the first sample's time if it never moves.
    pub fn motion_start_time(&self) -> f64 {
        self.motion_start_index(MOTION_THRESHOLD)
            .map_or(self.time[0], |k| self.time[k])
    }

    /// Whether the command moves at all (by more than 1 nm).
    pub fn command_moves(&self) -> bool {
        self.motion_start_index(MOTION_THRESHOLD).is_some()
    }

    /// The whole recording as an estimator view.
    pub fn signals(&self) -> Signals<'_> {
        Signals::new(
            &self.time,
            &self.command,
            &self.position,
            self.dt,
            self.motion_start_time(),
        )
    }
}

/// Command change that counts as motion \[m\] (1 nm).
pub const MOTION_THRESHOLD: f64 = 1e-9;

fn check_finite(channel: &str, v: &[f64]) -> Result<()> {
    match v.iter().position(|x| !x.is_finite()) {
        Some(index) => Err(Error::NonFinite {
            channel: channel.to_string(),
            index,
            value: v[index],
        }),
        None => Ok(()),
    }
}

/// Median of the intervals of a strictly increasing sequence (len ≥ 2).
fn median_interval(time: &[f64]) -> f64 {
    let mut d: Vec<f64> = time.windows(2).map(|w| w[1] - w[0]).collect();
    let mid = d.len() / 2;
    let (_, m, _) = d.select_nth_unstable_by(mid, f64::total_cmp);
    *m
}

#[cfg(test)]
mod tests {
    use super::*;

    fn t(n: usize) -> Vec<f64> {
        (0..n).map(|k| k as f64 * 1e-3).collect()
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
    fn motion_start_is_last_rest_sample() {
        let c = vec![0.0, 0.0, 0.0, 1e-6, 2e-6];
        let r = Recording::new(t(5), c, vec![0.0; 5]).unwrap();
        assert_eq!(r.motion_start_index(1e-9), Some(2));
        assert!((r.motion_start_time() - 2e-3).abs() < 1e-15);
    }

    #[test]
    fn standstill_has_no_motion_start() {
        let r = Recording::new(t(5), vec![1.0; 5], vec![0.0; 5]).unwrap();
        assert!(!r.command_moves());
        assert_eq!(r.motion_start_time(), 0.0);
    }
}
