//! A train of force pulses on the table: the disturbance of interrupted
//! cutting (a tool entering and leaving the work) and of impacts, which the
//! command does not announce.
//!
//! ```text
//! F_d(t) = (−1)ⁿ·F   for first + n·period ≤ t < first + n·period + width,  n = 0, 1, …
//! F_d(t) = 0         otherwise
//! ```
//!
//! The sign alternates from pulse to pulse (a push, then a pull), so the
//! train has no mean that the velocity loop's integral could learn. The
//! force is added to the table's equation of motion,
//! `M·dv_a/dt = F_s − C2·v_a − F_f(v_a) + F_d(t)`, held over each RK4 substep
//! at its value at the substep's start. `force = 0` (the default) is no
//! disturbance.

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// Force pulses on the table (module doc); `force = 0` is off.
///
/// ```
/// use feedid::drive::ForcePulses;
/// let p = ForcePulses { force: 20.0, width: 0.01, period: 0.5, first: 0.1 };
/// assert_eq!(p.at(0.05), 0.0);
/// assert_eq!(p.at(0.105), 20.0);
/// assert_eq!(p.at(0.605), -20.0);
/// assert_eq!(p.at(0.2), 0.0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ForcePulses {
    /// Height of each pulse \[N\] (its sign alternates); default 0 (off).
    pub force: f64,
    /// Length of each pulse \[s\]; default 0.01.
    pub width: f64,
    /// Time from one pulse's start to the next's \[s\]; default 0.5.
    pub period: f64,
    /// Start of the first pulse \[s\] after sample 0; default 0.1.
    pub first: f64,
}

impl Default for ForcePulses {
    fn default() -> Self {
        Self {
            force: 0.0,
            width: 0.01,
            period: 0.5,
            first: 0.1,
        }
    }
}

impl ForcePulses {
    /// True when the train acts (`force ≠ 0`).
    pub fn active(&self) -> bool {
        self.force != 0.0
    }

    /// The force at time `t` \[s\] after sample 0 \[N\].
    #[inline]
    pub fn at(&self, t: f64) -> f64 {
        if self.force == 0.0 || t < self.first {
            return 0.0;
        }
        let since = t - self.first;
        let n = (since / self.period).floor();
        if since - n * self.period < self.width {
            if n % 2.0 == 0.0 {
                self.force
            } else {
                -self.force
            }
        } else {
            0.0
        }
    }

    /// Check the values: finite, width and period > 0, width ≤ period, first ≥ 0.
    pub fn validate(&self) -> Result<()> {
        let check = |name: &'static str, value: f64, ok: bool, reason: &'static str| {
            if value.is_finite() && ok {
                Ok(())
            } else {
                Err(Error::InvalidParameter {
                    name,
                    value,
                    reason,
                })
            }
        };
        check("pulses.force", self.force, true, "must be finite")?;
        check(
            "pulses.width",
            self.width,
            self.width > 0.0,
            "must be finite and > 0",
        )?;
        check(
            "pulses.period",
            self.period,
            self.period >= self.width,
            "must be finite and at least the width",
        )?;
        check(
            "pulses.first",
            self.first,
            self.first >= 0.0,
            "must be finite and >= 0",
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_train_alternates_in_sign_and_is_zero_between_pulses() {
        let p = ForcePulses {
            force: 3.0,
            width: 0.002,
            period: 0.01,
            first: 0.005,
        };
        let dt = 1e-4;
        let f: Vec<f64> = (0..500).map(|k| p.at(k as f64 * dt + 0.5 * dt)).collect();
        // 20 samples per pulse, 100 per period, first at sample 50
        assert!(f[..50].iter().all(|&v| v == 0.0));
        assert!(f[50..70].iter().all(|&v| v == 3.0));
        assert!(f[70..150].iter().all(|&v| v == 0.0));
        assert!(f[150..170].iter().all(|&v| v == -3.0));
        assert!(f[250..270].iter().all(|&v| v == 3.0));
        // the mean over whole pairs of pulses is zero
        let mean: f64 = f[50..250].iter().sum::<f64>() / 200.0;
        assert!(mean.abs() < 1e-12, "{mean}");
    }

    #[test]
    fn off_by_default_and_invalid_values_are_named() {
        let p = ForcePulses::default();
        assert!(!p.active());
        assert_eq!(p.at(0.1), 0.0);
        assert!(p.validate().is_ok());
        let e = ForcePulses { width: 0.0, ..p }.validate().unwrap_err();
        assert!(e.to_string().contains("pulses.width"), "{e}");
        let e = ForcePulses { period: 0.001, ..p }.validate().unwrap_err();
        assert!(e.to_string().contains("pulses.period"), "{e}");
        assert!(ForcePulses {
            force: f64::NAN,
            ..p
        }
        .validate()
        .is_err());
    }
}
