//! Continuous-time SISO transfer function N(s)/D(s).

use crate::error::{Error, Result};

/// A continuous-time SISO transfer function with coefficients in descending powers of s.
#[derive(Debug, Clone, PartialEq)]
pub struct TransferFunction {
    num: Vec<f64>,
    den: Vec<f64>,
}

/// Magnitude and phase of a frequency response at one frequency.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrequencyPoint {
    /// Frequency \[Hz\].
    pub freq_hz: f64,
    /// Magnitude (linear, not dB).
    pub magnitude: f64,
    /// Phase \[deg\], unwrapped along the requested frequencies.
    pub phase_deg: f64,
}

impl TransferFunction {
    /// Build from numerator and denominator in descending powers of s.
    ///
    /// Leading zeros are stripped; the denominator must be non-zero, all
    /// coefficients finite, and the system proper (deg N ≤ deg D).
    pub fn new(num: Vec<f64>, den: Vec<f64>) -> Result<Self> {
        let strip = |v: Vec<f64>| -> Vec<f64> {
            let first = v.iter().position(|&c| c != 0.0).unwrap_or(v.len());
            v[first..].to_vec()
        };
        if num.iter().chain(den.iter()).any(|c| !c.is_finite()) {
            return Err(Error::InvalidModel {
                reason: "non-finite transfer-function coefficient",
            });
        }
        let num = strip(num);
        let den = strip(den);
        if den.is_empty() {
            return Err(Error::InvalidModel {
                reason: "zero denominator",
            });
        }
        if num.len() > den.len() {
            return Err(Error::InvalidModel {
                reason: "improper transfer function (deg N > deg D)",
            });
        }
        let num = if num.is_empty() { vec![0.0] } else { num };
        Ok(Self { num, den })
    }

    /// Numerator coefficients, descending powers of s.
    pub fn num(&self) -> &[f64] {
        &self.num
    }

    /// Denominator coefficients, descending powers of s.
    pub fn den(&self) -> &[f64] {
        &self.den
    }

    /// Order of the denominator.
    pub fn order(&self) -> usize {
        self.den.len() - 1
    }
}
