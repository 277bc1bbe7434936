//! A length of the engine's windows, horizons and hops, in samples or in
//! time: `10` is ten samples, `2ms` two milliseconds — the paper's horizon,
//! 10 samples at 5 kHz, 2 at 1 kHz. A time becomes samples at the
//! recording's rate, rounded to the nearest whole sample.
//!
//! ```
//! use feedid::ident::Span;
//! let h: Span = "2ms".parse().unwrap();
//! assert_eq!(h.samples(5000.0, "horizon").unwrap(), 10);
//! assert_eq!(h.samples(1000.0, "horizon").unwrap(), 2);
//! assert_eq!("10".parse::<Span>().unwrap().samples(100.0, "horizon").unwrap(), 10);
//! ```

use std::fmt;
use std::str::FromStr;

use crate::error::{Error, Result};

/// A length in samples or in seconds (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Span {
    /// A number of samples.
    Samples(usize),
    /// A duration \[s\].
    Seconds(f64),
}

impl Span {
    /// The length in samples at `rate_hz` (a time rounded to the nearest
    /// sample). Errors name the parameter `name` (`"horizon"`, …): a time
    /// shorter than half a sample, or a rate that is not finite and > 0.
    pub fn samples(&self, rate_hz: f64, name: &'static str) -> Result<usize> {
        match *self {
            Span::Samples(n) => Ok(n),
            Span::Seconds(t) => {
                #[allow(clippy::neg_cmp_op_on_partial_ord)] // rejects NaN
                if !(rate_hz.is_finite() && rate_hz > 0.0) {
                    return Err(Error::InvalidParameter {
                        name,
                        value: t,
                        reason: "is a time, and the sampling rate is not known",
                    });
                }
                let n = (t * rate_hz).round();
                #[allow(clippy::neg_cmp_op_on_partial_ord)] // rejects NaN
                if !(n >= 1.0) {
                    return Err(Error::InvalidParameter {
                        name,
                        value: t,
                        reason: "is shorter than one sample at the recording's rate [s]",
                    });
                }
                if n > usize::MAX as f64 / 2.0 {
                    return Err(Error::InvalidParameter {
                        name,
                        value: t,
                        reason: "is too long [s]",
                    });
                }
                Ok(n as usize)
            }
        }
    }
}

impl Default for Span {
    /// The paper's horizon in samples: 10 (2 ms at 5 kHz).
    fn default() -> Self {
        Span::Samples(10)
    }
}

impl From<usize> for Span {
    fn from(n: usize) -> Self {
        Span::Samples(n)
    }
}

impl fmt::Display for Span {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Span::Samples(n) => write!(f, "{n}"),
            Span::Seconds(t) if t < 1e-3 => write!(f, "{}us", t * 1e6),
            Span::Seconds(t) if t < 1.0 => write!(f, "{}ms", t * 1e3),
            Span::Seconds(t) => write!(f, "{t}s"),
        }
    }
}

/// Why a text is not a [`Span`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SpanParseError(String);

impl fmt::Display for SpanParseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{:?}: expected a number of samples (10) or a time with its unit (2ms, 0.5s, 300us)",
            self.0
        )
    }
}

impl std::error::Error for SpanParseError {}

impl FromStr for Span {
    type Err = SpanParseError;

    fn from_str(s: &str) -> std::result::Result<Self, Self::Err> {
        let text = s.trim();
        let err = || SpanParseError(s.to_string());
        if let Ok(n) = text.parse::<usize>() {
            return Ok(Span::Samples(n));
        }
        let (number, scale) = [("ms", 1e-3), ("us", 1e-6), ("µs", 1e-6), ("s", 1.0)]
            .iter()
            .find_map(|(unit, scale)| text.strip_suffix(unit).map(|n| (n, *scale)))
            .ok_or_else(err)?;
        let v: f64 = number.trim().parse().map_err(|_| err())?;
        #[allow(clippy::neg_cmp_op_on_partial_ord)] // rejects NaN
        if !(v.is_finite() && v > 0.0) {
            return Err(err());
        }
        Ok(Span::Seconds(v * scale))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_and_times_are_read_and_converted_at_the_rate() {
        assert_eq!("25".parse::<Span>().unwrap(), Span::Samples(25));
        assert_eq!(" 2 ms".parse::<Span>().unwrap(), Span::Seconds(2e-3));
        assert_eq!("0.5s".parse::<Span>().unwrap(), Span::Seconds(0.5));
        assert_eq!("300us".parse::<Span>().unwrap(), Span::Seconds(300e-6));
        assert_eq!("300µs".parse::<Span>().unwrap(), Span::Seconds(300e-6));
        let h = Span::Seconds(2e-3);
        assert_eq!(h.samples(5000.0, "horizon").unwrap(), 10);
        assert_eq!(h.samples(16323.5, "horizon").unwrap(), 33);
        assert_eq!(h.samples(100.0, "horizon").ok(), None);
        assert_eq!(Span::Seconds(0.1).samples(100.0, "horizon").unwrap(), 10);
        assert!(h.samples(f64::NAN, "horizon").is_err());
        assert_eq!(Span::Samples(7).samples(f64::NAN, "horizon").unwrap(), 7);
    }

    #[test]
    fn text_that_is_not_a_length_is_refused_with_the_forms_accepted() {
        for bad in [
            "", "ms", "-2ms", "2 m", "two", "nanms", "infs", "0s", "1e400s",
        ] {
            let e = bad.parse::<Span>().unwrap_err();
            assert!(e.to_string().contains("2ms"), "{bad}: {e}");
        }
    }

    #[test]
    fn display_reads_back() {
        for s in [
            Span::Samples(10),
            Span::Seconds(2e-3),
            Span::Seconds(3.0),
            Span::Seconds(5e-5),
        ] {
            let back: Span = s.to_string().parse().unwrap();
            match (s, back) {
                (Span::Seconds(a), Span::Seconds(b)) => assert!((a - b).abs() < 1e-15 * a),
                (a, b) => assert_eq!(a, b),
            }
        }
    }
}
