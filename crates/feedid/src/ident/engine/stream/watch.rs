//! Whether a stream's predictions lose to holding the last position, block
//! by block as the stream runs: a low sampling rate without a command lead
//! extrapolates the command over a horizon of many milliseconds (10 samples
//! at 100 Hz are 100 ms), and the predictions can then do worse than the
//! simplest baseline without any other sign.
//!
//! [`HoldWatch::check`] compares, over each block of scored samples (about
//! [`HoldWatch::block_seconds`], at least [`MIN_BLOCK`] samples), the sum of
//! squared errors of the predictions with that of holding each window's last
//! measured position on the same samples ([`StreamStats::hold`]), and
//! reports a block where the predictions lost ([`HoldLoss`]), with the cause
//! and the options that change it ([`HoldLoss::advice`]).

use crate::error::{Hint, Syntax};
use crate::ident::engine::stream::{HorizonCommand, StreamStats};

/// Fewest scored samples in a block.
pub const MIN_BLOCK: usize = 200;

/// A block of a stream in which the predictions lost to holding.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HoldLoss {
    /// Length of the block \[s\] (its samples times the sampling interval).
    pub seconds: f64,
    /// Scored samples in the block.
    pub samples: usize,
    /// RMS prediction error over the block \[m\].
    pub rms: f64,
    /// RMS error of holding the last position over the same samples \[m\].
    pub hold_rms: f64,
}

impl HoldLoss {
    /// What makes the predictions lose and what changes it, for a stream
    /// with `command` over a horizon of `horizon` samples at interval `dt`.
    /// The settings it suggests are in [`Syntax::Library`] (`horizon = 1`);
    /// [`HoldLoss::advice_in`] phrases them for a front end.
    pub fn advice(&self, command: HorizonCommand, horizon: usize, dt: f64) -> String {
        self.advice_in(command, horizon, dt, Syntax::Library)
    }

    /// [`HoldLoss::advice`] with the settings it suggests in a front end's
    /// syntax: the CLI names `--horizon 1`, Python `horizon=1`.
    pub fn advice_in(
        &self,
        command: HorizonCommand,
        horizon: usize,
        dt: f64,
        syntax: Syntax,
    ) -> String {
        let set = |key: &'static str, value: String| Hint::SetValue { key, value }.phrase(syntax);
        let ahead = format!(
            "a horizon of {horizon} samples is {:.3} ms at {:.4} Hz",
            1e3 * horizon as f64 * dt,
            1.0 / dt
        );
        // the paper's 2 ms, or one sample where that is shorter
        let paper = (2e-3 / dt).round();
        let shorter = if paper >= 1.0 && paper < horizon as f64 {
            format!("{}: {paper} samples here", set("horizon", "2ms".into()))
        } else {
            format!("{}: {:.3} ms here", set("horizon", "1".into()), 1e3 * dt)
        };
        let lead = Hint::Option {
            key: "command_lead",
        }
        .phrase(syntax);
        let auto = set("method", "auto".into());
        match command {
            HorizonCommand::Extrapolated { known, .. } => format!(
                "{ahead}, and the command over {} of them is extrapolated ({command}); \
                 give the command ahead ({lead} N, N ≥ {horizon}), a shorter horizon \
                 ({shorter}), or let each window wait for its command ({})",
                horizon - known.min(horizon),
                set("extrapolate", "wait".into())
            ),
            HorizonCommand::NotRead => format!(
                "{ahead}, predicted from the window alone (the method does not read the \
                 command); try a shorter horizon ({shorter}) or a method that reads the \
                 command ({auto})"
            ),
            HorizonCommand::Known { .. } | HorizonCommand::Awaited { .. } => format!(
                "{ahead}, with its command known: the method's model does not hold here; try \
                 a shorter horizon ({shorter}) or another method ({auto})"
            ),
        }
    }
}

/// Watches a stream's scores block by block (see the module doc).
#[derive(Debug, Clone)]
pub struct HoldWatch {
    block_seconds: f64,
    /// Scored samples, squared errors of the predictions and of the hold at
    /// the end of the last block.
    last: (usize, f64, f64),
    blocks: usize,
    lost: usize,
}

impl HoldWatch {
    /// A watch over blocks of about `block_seconds` (at least [`MIN_BLOCK`] samples).
    pub fn new(block_seconds: f64) -> Self {
        Self {
            block_seconds,
            last: (0, 0.0, 0.0),
            blocks: 0,
            lost: 0,
        }
    }

    /// The block length asked for \[s\].
    pub fn block_seconds(&self) -> f64 {
        self.block_seconds
    }

    /// Blocks compared so far, and of them the ones lost to holding.
    pub fn blocks(&self) -> (usize, usize) {
        (self.blocks, self.lost)
    }

    /// After new samples were scored (`stats` of the stream, `dt` its
    /// sampling interval if known): a block that ended and was lost.
    pub fn check(&mut self, stats: &StreamStats, dt: Option<f64>) -> Option<HoldLoss> {
        let n = stats.scored.samples;
        if n < self.last.0 {
            // a reset stream
            self.last = (0, 0.0, 0.0);
        }
        let dt = dt.filter(|d| d.is_finite() && *d > 0.0)?;
        let block = ((self.block_seconds / dt).round() as usize).max(MIN_BLOCK);
        let m = n - self.last.0;
        if m < block {
            return None;
        }
        let sse = stats.scored.rms.powi(2) * n as f64;
        let hold = stats.hold.rms.powi(2) * stats.hold.samples as f64;
        let (d, dh) = (sse - self.last.1, hold - self.last.2);
        self.last = (n, sse, hold);
        self.blocks += 1;
        (d.is_finite() && dh.is_finite() && d > dh).then(|| {
            self.lost += 1;
            HoldLoss {
                seconds: m as f64 * dt,
                samples: m,
                rms: (d.max(0.0) / m as f64).sqrt(),
                hold_rms: (dh.max(0.0) / m as f64).sqrt(),
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stats(n: usize, rms: f64, hold: f64) -> StreamStats {
        let mut s = StreamStats {
            lines: n,
            samples: n,
            commands: n,
            ..StreamStats::default()
        };
        s.scored.samples = n;
        s.scored.rms = rms;
        s.hold.samples = n;
        s.hold.rms = hold;
        s
    }

    #[test]
    fn a_block_lost_to_holding_is_reported_with_its_own_figures() {
        // 100 Hz, blocks of 2 s = 200 samples: the first block wins (rms 1
        // against 2), the second loses (cumulative rms chosen so that the
        // second block alone has rms 3 against the hold's 1)
        let mut w = HoldWatch::new(2.0);
        assert_eq!(w.check(&stats(150, 1.0, 2.0), Some(0.01)), None);
        assert_eq!(w.check(&stats(200, 1.0, 2.0), Some(0.01)), None);
        let rms = ((200.0 * 1.0 + 200.0 * 9.0) / 400.0f64).sqrt();
        let hold = ((200.0 * 4.0 + 200.0 * 1.0) / 400.0f64).sqrt();
        let loss = w.check(&stats(400, rms, hold), Some(0.01)).unwrap();
        assert_eq!(loss.samples, 200);
        assert!((loss.seconds - 2.0).abs() < 1e-12);
        assert!((loss.rms - 3.0).abs() < 1e-12 && (loss.hold_rms - 1.0).abs() < 1e-12);
        assert_eq!(w.blocks(), (2, 1));
        let command = HorizonCommand::Extrapolated {
            extrapolation: crate::ident::engine::stream::CommandExtrapolation::Acceleration,
            known: 0,
        };
        let library = loss.advice(command, 10, 0.01);
        assert!(!library.contains("--"), "{library}");
        assert!(library.contains("horizon = 1: 10.000 ms"), "{library}");
        let py = loss.advice_in(command, 10, 0.01, Syntax::Python);
        assert!(
            py.contains("horizon=1: 10.000 ms") && !py.contains("--"),
            "{py}"
        );
        let text = loss.advice_in(command, 10, 0.01, Syntax::Cli);
        assert!(
            text.contains("100.000 ms") && text.contains("--command-lead"),
            "{text}"
        );
        // 2 ms is less than a sample at 100 Hz: the advice is one sample
        assert!(text.contains("--horizon 1: 10.000 ms"), "{text}");
    }

    #[test]
    fn without_a_known_interval_nothing_is_judged() {
        let mut w = HoldWatch::new(2.0);
        assert_eq!(w.check(&stats(10_000, 5.0, 1.0), None), None);
        assert_eq!(w.blocks(), (0, 0));
    }
}
