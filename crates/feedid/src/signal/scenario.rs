//! Named test scenarios: the default command of each generator family.
//!
//! | name        | command                                              | default duration |
//! |-------------|------------------------------------------------------|------------------|
//! | `ramp`      | 30 mm at 50 mm/s (paper)                             | 0.8 s            |
//! | `step`      | 1 mm in 0.2 ms (paper)                               | 0.05 s           |
//! | `scurve`    | 20 mm, 100 mm/s, 2 m/s², 200 m/s³                    | 0.4 s            |
//! | `chirp`     | 0.03 mm, 1 → 200 Hz logarithmic                      | 2.0 s            |
//! | `prbs`      | 0.03 mm, 10-sample clock, 9-bit register, smoothed  | 1.1 s            |
//! | `multisine` | 0.03 mm peak, 1 … 200 Hz, Schroeder phases          | 1.1 s            |
//!
//! Every command rests 10 ms at 0 before it moves; the default rate is 5 kHz
//! ([`DEFAULT_RATE_HZ`]). The excitation amplitudes (chirp, PRBS, multisine)
//! keep the default rig inside its 10 A current limit; the paper step
//! deliberately does not (its linear response would need 256 A).

use std::fmt;
use std::str::FromStr;

use super::chirp::Chirp;
use super::common::{sample_count, DEFAULT_RATE_HZ};
use super::multisine::Multisine;
use super::prbs::Prbs;
use super::ramp::Ramp;
use super::scurve::Scurve;
use super::step::Step;
use crate::error::{Error, Result};

/// A named default command.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Scenario {
    /// Paper ramp: 30 mm at 50 mm/s.
    Ramp,
    /// Paper step: 1 mm in 0.2 ms.
    Step,
    /// Jerk-limited point-to-point move.
    Scurve,
    /// Logarithmic sine sweep.
    Chirp,
    /// Smoothed pseudo-random binary sequence.
    Prbs,
    /// Schroeder-phase multisine.
    Multisine,
}

const NAMES: &str = "ramp, step, scurve, chirp, prbs, multisine";

impl Scenario {
    /// All scenarios in documentation order.
    pub const ALL: [Scenario; 6] = [
        Scenario::Ramp,
        Scenario::Step,
        Scenario::Scurve,
        Scenario::Chirp,
        Scenario::Prbs,
        Scenario::Multisine,
    ];

    /// Lower-case name as accepted by [`FromStr`].
    pub fn name(self) -> &'static str {
        match self {
            Scenario::Ramp => "ramp",
            Scenario::Step => "step",
            Scenario::Scurve => "scurve",
            Scenario::Chirp => "chirp",
            Scenario::Prbs => "prbs",
            Scenario::Multisine => "multisine",
        }
    }

    /// Default duration \[s\] (see the module table).
    pub fn default_duration(self) -> f64 {
        match self {
            Scenario::Ramp => 0.8,
            Scenario::Step => 0.05,
            Scenario::Scurve => 0.4,
            Scenario::Chirp => 2.0,
            Scenario::Prbs | Scenario::Multisine => 1.1,
        }
    }

    /// Default acquisition rate \[Hz\]: 5000.
    pub fn default_rate(self) -> f64 {
        DEFAULT_RATE_HZ
    }

    /// The default command of this scenario, `round(duration·rate_hz)` samples
    /// at `rate_hz` \[Hz\] for `duration` \[s\]; `seed` drives the PRBS (ignored otherwise).
    ///
    /// ```
    /// use feedid::signal::Scenario;
    /// let s: Scenario = "ramp".parse().unwrap();
    /// let x = s.command(5000.0, s.default_duration(), 0).unwrap();
    /// assert_eq!(x.len(), 4000);
    /// ```
    pub fn command(self, rate_hz: f64, duration: f64, seed: u64) -> Result<Vec<f64>> {
        let mut out = vec![0.0; sample_count(rate_hz, duration)?];
        self.fill(rate_hz, seed, &mut out)?;
        Ok(out)
    }

    /// Write the default command of this scenario at `rate_hz` into `out`.
    pub fn fill(self, rate_hz: f64, seed: u64, out: &mut [f64]) -> Result<()> {
        match self {
            Scenario::Ramp => Ramp::default().fill(rate_hz, out),
            Scenario::Step => Step::default().fill(rate_hz, out),
            Scenario::Scurve => Scurve::default().fill(rate_hz, out),
            Scenario::Chirp => Chirp::default().fill(rate_hz, out),
            Scenario::Prbs => Prbs::default().fill(rate_hz, seed, out),
            Scenario::Multisine => Multisine::default().fill(rate_hz, out),
        }
    }
}

impl FromStr for Scenario {
    type Err = Error;

    fn from_str(s: &str) -> Result<Self> {
        let lower = s.trim().to_ascii_lowercase();
        Scenario::ALL
            .into_iter()
            .find(|sc| sc.name() == lower)
            .ok_or_else(|| Error::InvalidChoice {
                what: "scenario",
                value: s.to_string(),
                expected: NAMES,
            })
    }
}

impl fmt::Display for Scenario {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_name_parses_back_to_its_scenario() {
        for s in Scenario::ALL {
            assert_eq!(s.name().parse::<Scenario>().unwrap(), s);
            assert_eq!(s.to_string(), s.name());
        }
        assert_eq!("  Ramp ".parse::<Scenario>().unwrap(), Scenario::Ramp);
    }

    #[test]
    fn unknown_name_lists_the_choices() {
        let e = "sine".parse::<Scenario>().unwrap_err();
        assert!(e.to_string().contains("multisine"), "{e}");
    }

    #[test]
    fn every_default_command_is_finite_starts_at_rest_and_has_default_length() {
        for s in Scenario::ALL {
            let x = s.command(5000.0, s.default_duration(), 1).unwrap();
            assert_eq!(x.len(), (s.default_duration() * 5000.0).round() as usize);
            assert!(x.iter().all(|v| v.is_finite()), "{s}");
            assert!(x[..50].iter().all(|&v| v == 0.0), "{s}");
            assert!(x.iter().any(|&v| v != 0.0), "{s}");
        }
    }

    #[test]
    fn ramp_scenario_ends_at_thirty_mm() {
        let x = Scenario::Ramp.command(5000.0, 0.8, 0).unwrap();
        assert!((x[x.len() - 1] - 0.03).abs() < 1e-15);
    }
}
