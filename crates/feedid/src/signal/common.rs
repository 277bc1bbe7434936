//! Helpers shared by the command generators: argument checks, sample counts and
//! the raised-cosine taper `w(τ) = (1 − cos(π·τ))/2`, `τ ∈ [0, 1]`.

use crate::error::{Error, Result};

/// Default acquisition rate of every command \[Hz\]: 5 kHz, as in the paper.
pub const DEFAULT_RATE_HZ: f64 = 5000.0;

/// Default rest before motion starts \[s\]: 10 ms, so "start of motion" is visible.
pub const DEFAULT_REST: f64 = 0.010;

/// Check that `rate_hz` is finite and positive.
pub(crate) fn check_rate(rate_hz: f64) -> Result<()> {
    if !rate_hz.is_finite() || rate_hz <= 0.0 {
        return Err(Error::InvalidParameter {
            name: "rate",
            value: rate_hz,
            reason: "must be finite and > 0",
        });
    }
    Ok(())
}

/// Check that `value` is finite and strictly positive.
pub(crate) fn check_positive(name: &'static str, value: f64) -> Result<()> {
    if !value.is_finite() || value <= 0.0 {
        return Err(Error::InvalidParameter {
            name,
            value,
            reason: "must be finite and > 0",
        });
    }
    Ok(())
}

/// Check that `value` is finite and not negative.
pub(crate) fn check_non_negative(name: &'static str, value: f64) -> Result<()> {
    if !value.is_finite() || value < 0.0 {
        return Err(Error::InvalidParameter {
            name,
            value,
            reason: "must be finite and >= 0",
        });
    }
    Ok(())
}

/// Check a command given to a simulation: at least `needed` samples
/// (`what` names it in the error), every one finite (the first that is not
/// is named by its index).
pub(crate) fn check_command(command: &[f64], what: &'static str, needed: usize) -> Result<()> {
    if command.len() < needed {
        return Err(Error::TooFewSamples {
            what,
            needed,
            actual: command.len(),
        });
    }
    if let Some((index, &value)) = command.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(Error::NonFinite {
            channel: "command".to_string(),
            index,
            value,
        });
    }
    Ok(())
}

/// Check that `value` is finite (any sign).
pub(crate) fn check_finite(name: &'static str, value: f64) -> Result<()> {
    if !value.is_finite() {
        return Err(Error::InvalidParameter {
            name,
            value,
            reason: "must be finite",
        });
    }
    Ok(())
}

/// Most samples of a command: 1e8 (5.5 h at 5 kHz). A simulation keeps about
/// ten signals of this length in memory (8 GB at the limit).
pub const MAX_SAMPLES: usize = 100_000_000;

/// Number of samples `n = round(duration·rate)` of a command (times `k/rate`,
/// `k = 0 … n−1`); at least 2, at most [`MAX_SAMPLES`].
pub fn sample_count(rate_hz: f64, duration: f64) -> Result<usize> {
    check_rate(rate_hz)?;
    check_positive("duration", duration)?;
    let n = (duration * rate_hz).round();
    if n > MAX_SAMPLES as f64 {
        return Err(Error::InvalidParameter {
            name: "duration",
            value: duration,
            reason: "gives more than 1e8 samples at this rate",
        });
    }
    let n = n as usize;
    if n < 2 {
        return Err(Error::TooFewSamples {
            what: "a command (duration·rate)",
            needed: 2,
            actual: n,
        });
    }
    Ok(n)
}

/// Raised-cosine taper: 0 for `τ ≤ 0`, `(1 − cos(π·τ))/2` on `[0, 1]`, 1 for `τ ≥ 1`.
pub(crate) fn taper(tau: f64) -> f64 {
    if tau <= 0.0 {
        0.0
    } else if tau >= 1.0 {
        1.0
    } else {
        0.5 * (1.0 - (std::f64::consts::PI * tau).cos())
    }
}
