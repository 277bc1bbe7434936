//! Pseudo-random binary sequence (maximum-length LFSR), raw or smoothed.
//!
//! A Fibonacci linear-feedback shift register of `n` bits with a primitive
//! feedback polynomial produces a sequence of period `2ⁿ − 1` bits. Each new
//! bit is the XOR of the tapped bits, `b = ⊕ s_{n−t}` over the taps `t`; the
//! register shifts right and `b` enters at the top. The seed picks the initial
//! (non-zero) register state `s₀ = 1 + (seed mod (2ⁿ − 1))`, i.e. a cyclic shift.
//!
//! The output bit is held for `clock` samples. Levels are `0` (bit 0) and `A`
//! (bit 1), so the command starts from the rest position 0. With `smoothing = m > 0`
//! every level change becomes a raised-cosine transition over `m` samples
//! (`m ≤ clock`), which keeps the demanded acceleration finite; `m = 0` gives
//! the raw sequence. Its spectrum is flat within 3 dB up to about
//! `0.44·rate/clock`.
//!
//! Defaults: `A` = 0.03 mm (linear default rig: 8.3 A peak, inside the 10 A limit), `clock` = 10 samples (2 ms at 5 kHz), `n` = 9
//! (period 511 bits = 1.022 s at 5 kHz), `smoothing` = 5 samples, rest 0.010 s.
//! Supported register lengths 2 … 24. Reference: L. Ljung, *System
//! Identification*, 2nd ed., §13.3; tap table after Xilinx XAPP 052.

use serde::{Deserialize, Serialize};

use super::common::{check_finite, check_non_negative, check_rate, sample_count, taper};
use crate::error::{Error, Result};

/// Pseudo-random binary position sequence.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Prbs {
    /// Level of a 1 bit A \[m\] (a 0 bit is at 0); default 3e-5.
    pub amplitude: f64,
    /// Samples per bit (clock period); default 10.
    pub clock: usize,
    /// Register length n (2 … 24); default 9.
    pub register: u32,
    /// Raised-cosine transition length in samples (0 = raw, ≤ `clock`); default 5.
    pub smoothing: usize,
    /// Rest before the sequence starts \[s\]; default 0.010.
    pub rest: f64,
}

impl Default for Prbs {
    fn default() -> Self {
        Self {
            amplitude: 3e-5,
            clock: 10,
            register: 9,
            smoothing: 5,
            rest: 0.010,
        }
    }
}

/// Feedback taps (polynomial exponents) of a maximum-length Fibonacci LFSR, n = 2 … 24.
fn taps(n: u32) -> Option<&'static [u32]> {
    Some(match n {
        2 => &[2, 1],
        3 => &[3, 2],
        4 => &[4, 3],
        5 => &[5, 3],
        6 => &[6, 5],
        7 => &[7, 6],
        8 => &[8, 6, 5, 4],
        9 => &[9, 5],
        10 => &[10, 7],
        11 => &[11, 9],
        12 => &[12, 6, 4, 1],
        13 => &[13, 4, 3, 1],
        14 => &[14, 5, 3, 1],
        15 => &[15, 14],
        16 => &[16, 15, 13, 4],
        17 => &[17, 14],
        18 => &[18, 11],
        19 => &[19, 6, 2, 1],
        20 => &[20, 17],
        21 => &[21, 19],
        22 => &[22, 21],
        23 => &[23, 18],
        24 => &[24, 23, 22, 17],
        _ => return None,
    })
}

/// Maximum-length binary sequence generator (Fibonacci LFSR).
#[derive(Debug, Clone)]
pub struct Lfsr {
    state: u32,
    n: u32,
    taps: &'static [u32],
}

impl Lfsr {
    /// Register of length `n` (2 … 24) starting at state `1 + (seed mod (2ⁿ − 1))`.
    pub fn new(n: u32, seed: u64) -> Result<Self> {
        let taps = taps(n).ok_or(Error::InvalidParameter {
            name: "prbs.register",
            value: f64::from(n),
            reason: "must be between 2 and 24",
        })?;
        let period = (1u64 << n) - 1;
        let state = (1 + seed % period) as u32;
        Ok(Self { state, n, taps })
    }

    /// Sequence period `2ⁿ − 1` in bits.
    pub fn period(&self) -> u64 {
        (1u64 << self.n) - 1
    }

    /// Current register state (never 0).
    pub fn state(&self) -> u32 {
        self.state
    }

    /// Output the lowest bit and advance the register.
    pub fn next_bit(&mut self) -> bool {
        let out = self.state & 1 == 1;
        let mut b = 0u32;
        for &t in self.taps {
            b ^= self.state >> (self.n - t);
        }
        self.state = (self.state >> 1) | ((b & 1) << (self.n - 1));
        out
    }
}

impl Prbs {
    /// Check the parameters.
    pub fn validate(&self) -> Result<()> {
        check_finite("prbs.amplitude", self.amplitude)?;
        check_non_negative("prbs.rest", self.rest)?;
        if self.clock == 0 {
            return Err(Error::InvalidParameter {
                name: "prbs.clock",
                value: 0.0,
                reason: "must be at least 1 sample",
            });
        }
        if self.smoothing > self.clock {
            return Err(Error::InvalidParameter {
                name: "prbs.smoothing",
                value: self.smoothing as f64,
                reason: "must not exceed prbs.clock",
            });
        }
        if taps(self.register).is_none() {
            return Err(Error::InvalidParameter {
                name: "prbs.register",
                value: f64::from(self.register),
                reason: "must be between 2 and 24",
            });
        }
        Ok(())
    }

    /// Write the sequence sampled at `rate_hz` into `out` (seeded).
    pub fn fill(&self, rate_hz: f64, seed: u64, out: &mut [f64]) -> Result<()> {
        check_rate(rate_hz)?;
        self.validate()?;
        let mut lfsr = Lfsr::new(self.register, seed)?;
        let start = (self.rest * rate_hz).ceil() as usize;
        let (mut level, mut previous) = (0.0, 0.0);
        for (k, x) in out.iter_mut().enumerate() {
            if k < start {
                *x = 0.0;
                continue;
            }
            let j = k - start;
            let phase = j % self.clock;
            if phase == 0 {
                previous = level;
                level = if lfsr.next_bit() { self.amplitude } else { 0.0 };
            }
            *x = if self.smoothing == 0 {
                level
            } else {
                previous + (level - previous) * taper(phase as f64 / self.smoothing as f64)
            };
        }
        Ok(())
    }

    /// Allocate and return `round(duration·rate_hz)` samples.
    pub fn generate(&self, rate_hz: f64, duration: f64, seed: u64) -> Result<Vec<f64>> {
        let mut out = vec![0.0; sample_count(rate_hz, duration)?];
        self.fill(rate_hz, seed, &mut out)?;
        Ok(out)
    }
}

/// The default PRBS (0.03 mm, 10-sample clock, 9-bit register, smoothed) at `rate_hz`.
///
/// ```
/// let x = feedid::signal::prbs(5000.0, 1.1, 7).unwrap();
/// assert!(x.iter().all(|&v| (0.0..=3e-5).contains(&v)));
/// ```
pub fn prbs(rate_hz: f64, duration: f64, seed: u64) -> Result<Vec<f64>> {
    Prbs::default().generate(rate_hz, duration, seed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_register_length_gives_a_maximum_length_sequence() {
        for n in 2..=24 {
            let mut l = Lfsr::new(n, 0).unwrap();
            let s0 = l.state();
            let mut ones = 0u64;
            let mut period = 0u64;
            loop {
                ones += u64::from(l.next_bit());
                period += 1;
                if l.state() == s0 {
                    break;
                }
                assert!(period <= l.period(), "n={n}");
            }
            assert_eq!(period, l.period(), "n={n}");
            // an m-sequence has 2^(n−1) ones per period
            assert_eq!(ones, 1u64 << (n - 1), "n={n}");
        }
    }

    #[test]
    fn raw_prbs_holds_each_bit_for_one_clock_period() {
        let p = Prbs {
            smoothing: 0,
            rest: 0.0,
            clock: 4,
            ..Prbs::default()
        };
        let x = p.generate(1000.0, 0.4, 3).unwrap();
        for chunk in x.chunks(4) {
            assert!(chunk.iter().all(|&v| v == chunk[0]));
            assert!(chunk[0] == 0.0 || chunk[0] == p.amplitude);
        }
    }

    #[test]
    fn smoothed_prbs_changes_level_by_raised_cosine_and_starts_at_zero() {
        let x = prbs(5000.0, 1.1, 1).unwrap();
        assert!(x[..=50].iter().all(|&v| v == 0.0));
        // largest sample-to-sample change: raised cosine over 5 samples
        let max_step = x
            .windows(2)
            .map(|w| (w[1] - w[0]).abs())
            .fold(0.0, f64::max);
        let expected = 3e-5 * (std::f64::consts::PI / 5.0 * 3.0).cos().mul_add(-0.5, 0.5)
            - 3e-5 * (std::f64::consts::PI / 5.0 * 2.0).cos().mul_add(-0.5, 0.5);
        assert!((max_step - expected).abs() < 1e-15, "{max_step} {expected}");
    }

    #[test]
    fn same_seed_same_sequence_different_seed_differs() {
        let a = prbs(5000.0, 0.5, 11).unwrap();
        let b = prbs(5000.0, 0.5, 11).unwrap();
        let c = prbs(5000.0, 0.5, 12).unwrap();
        assert_eq!(a, b);
        assert_ne!(a, c);
    }

    #[test]
    fn bad_register_or_clock_is_rejected() {
        let p = Prbs {
            register: 40,
            ..Prbs::default()
        };
        assert!(p.generate(5000.0, 1.0, 0).is_err());
        let p = Prbs {
            clock: 0,
            ..Prbs::default()
        };
        assert!(p.generate(5000.0, 1.0, 0).is_err());
    }
}
