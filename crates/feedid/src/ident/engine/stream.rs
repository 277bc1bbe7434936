//! Streaming identification: push one sample at a time, get each window's
//! prediction of the next `H` samples as soon as it is due.
//!
//! A [`Streamer`] visits **the same windows** as the batch engine
//! ([`crate::ident::engine`]) — window `j` is `[s_j, s_j + W)` with
//! `s_j = warm_up + estimator.warm_up() + j·hop` in absolute sample indices
//! counted from the first pushed sample — and makes **the same estimator
//! calls** (`reset` once, then `fit` and `predict` per window, in order), so
//! its predictions are those of [`crate::ident::engine::run`] on the same data
//! (tested to ≤ 1e-12 relative; see *Horizon time stamps*).
//!
//! # When a prediction is due
//!
//! The command is the set-point, known ahead of the measured position (a CNC
//! interpolator produces it before the axis follows). An estimator that reads
//! the command over the horizon ([`Estimator::uses_future_command`], the
//! default) needs it before it can predict:
//!
//! | estimator                      | window `j` is processed once                                  |
//! |--------------------------------|---------------------------------------------------------------|
//! | `uses_future_command() == false` (paper, polynomial) | the position of sample `s_j + W − 1` (the window end) has arrived |
//! | `uses_future_command() == true`  | that position **and** the command up to `s_j + W + H − 1` have arrived |
//!
//! Two ways to feed the streamer:
//!
//! * [`Streamer::push`]`(t, u, y)` — one complete sample. A window-end
//!   estimator's prediction comes with the window's last sample; a
//!   future-command estimator's prediction comes `H − 1` samples later, with
//!   the sample that completes the command over its horizon (by then the
//!   horizon has been measured: such a prediction is a reconstruction, not a
//!   forecast). At most one prediction is due per `push`.
//! * [`Streamer::push_command`]`(t, u)` ahead of [`Streamer::push_position`]`(y)`
//!   — a CNC feeds its interpolator output up to `lookahead` samples
//!   ([`StreamOptions::lookahead`], default `H`) ahead of the measurement;
//!   positions are matched to commands in order. With a look-ahead of at least
//!   `H`, every estimator predicts at its window end. After these calls, call
//!   [`Streamer::poll`] until it returns `None`.
//!
//! At the end of the input call [`Streamer::finish`] and then
//! [`Streamer::poll`] until `None`: windows still waiting for the command are
//! processed with the horizon cut at the last measured sample, as the batch
//! engine cuts it at the end of the recording.
//!
//! # Motion start
//!
//! The batch path uses the recording's motion start
//! ([`crate::Recording::motion_start_time`]: the time of the last sample
//! before the command first moves by more than 1 nm). The streamer finds the
//! same value causally, when the first moving command sample arrives; until
//! then [`Signals::motion_start`] is `f64::INFINITY`. The paper method treats
//! a window whose last sample is at or before the motion start as a rest
//! window (coefficients 0, [`crate::ident::WindowOutcome::Fallback`], the last
//! position held), a decision that needs only the window, so batch and stream
//! agree. One exception: a recording whose command never moves has its first
//! sample as motion start in batch, while the streamer, which cannot know that
//! the command will never move, keeps `∞` (every paper window is a rest window).
//!
//! # Horizon time stamps and sampling interval
//!
//! A prediction made before its horizon samples have arrived needs their time
//! stamps: they are extrapolated as `t_last + m·dt`. Time stamps that have
//! arrived (with the command) are used as they are. `dt` ([`Signals::dt`]) is
//! [`StreamOptions::dt`] if given, else the running mean interval
//! `(t_last − t_first)/(n − 1)` (the batch path uses the mean over the whole
//! recording). On uniformly sampled data the predictions then agree with the
//! batch ones to rounding (≤ 1e-12 relative); with future-command emission
//! they are bit-identical.
//!
//! # Buffers and cost
//!
//! All buffers are allocated in [`Streamer::new`], sized from the
//! configuration: the estimator may read `warm_up + W + hop` samples before a
//! window end and `max(H, lookahead)` after it; the linear buffers hold twice
//! that and are compacted (a copy of the retained samples to the front) when
//! full, so the per-sample cost is O(1) amortised and nothing is allocated per
//! sample or per window (as long as the estimator allocates nothing either).
//!
//! Each measured sample is scored against its latest prediction once no later
//! window can predict it, exactly as the batch engine keeps the most recent
//! prediction of a sample ([`Streamer::stats`]).
//!
//! ```
//! use feedid::ident::{stream::Streamer, EngineConfig, PaperConfig};
//! let paper = PaperConfig::default().build().unwrap();
//! let mut s = Streamer::new(paper, EngineConfig::default()).unwrap();
//! let dt = 2e-4;
//! let mut predictions = 0;
//! for k in 0..200 {
//!     let t = k as f64 * dt;
//!     // a ramp starting after 2 ms and a position following it
//!     let u = 0.05 * (t - 2e-3).max(0.0);
//!     let y = 0.05 * (t - 2e-3).max(0.0).powi(2) / (t + 1e-3);
//!     if let Some(p) = s.push(t, u, y).unwrap() {
//!         assert_eq!(p.time.len(), 10);
//!         assert_eq!(p.horizon.start, k + 1); // due at the window end
//!         predictions += 1;
//!     }
//! }
//! assert_eq!(predictions, 19); // windows ending at samples 20, 30, …, 200
//! ```

use std::ops::Range;

use crate::error::{Error, Result};
use crate::ident::engine::{fit_and_predict, EngineConfig};
use crate::ident::{Estimator, Signals, WindowOutcome};
use crate::recording::MOTION_THRESHOLD;
use crate::stats::{ErrorAccumulator, ErrorStats};

/// Largest buffer the streamer allocates \[samples per channel\].
const MAX_CAPACITY: usize = 1 << 26;

/// Options of a [`Streamer`] beyond the window configuration.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StreamOptions {
    /// Command look-ahead \[samples\]: the command of sample `k + lookahead`
    /// may be pushed before the position of sample `k`; `None` = the horizon
    /// `H` (default). [`Streamer::push`] needs 0.
    pub lookahead: Option<usize>,
    /// Nominal sample interval \[s\]; `None` = the running mean interval (default).
    pub dt: Option<f64>,
}

/// One window's prediction, borrowed from the streamer's buffers.
#[derive(Debug, Clone, PartialEq)]
pub struct Prediction<'a> {
    /// Samples fitted (absolute indices, 0 = first pushed sample).
    pub window: Range<usize>,
    /// Samples predicted (`H` samples; fewer only after [`Streamer::finish`]).
    pub horizon: Range<usize>,
    /// Time stamps of the horizon samples \[s\] (extrapolated where not yet pushed).
    pub time: &'a [f64],
    /// Predicted positions \[m\]; empty if the window failed.
    pub position: &'a [f64],
    /// The window's coefficients (zeros if the fit failed).
    pub coefficients: &'a [f64],
    /// RMS of the window's fit residual \[m\] (0 if the fit failed).
    pub residual_rms: f64,
    /// Solver iterations (0 if the fit or the prediction failed).
    pub iterations: usize,
    /// What became of the window.
    pub outcome: WindowOutcome,
}

impl Prediction<'_> {
    /// Whether the window produced a prediction.
    pub fn is_ok(&self) -> bool {
        self.outcome.predicted()
    }
}

/// Counters and scores of a stream so far.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StreamStats {
    /// Samples with a measured position.
    pub samples: usize,
    /// Command samples (≥ `samples`).
    pub commands: usize,
    /// Windows processed.
    pub windows: usize,
    /// Windows whose fit or prediction failed.
    pub failed_windows: usize,
    /// Windows whose prediction the method withheld (not validated; `auto`).
    pub withheld_windows: usize,
    /// Error of the latest prediction of each measured sample that no later window can predict.
    pub scored: ErrorStats,
}

/// Sliding-window identification fed one sample at a time (see the module doc).
///
/// Generic over the estimator; `Streamer<Box<dyn Estimator>>` (the default
/// type parameter) takes a method chosen at run time.
#[derive(Debug)]
pub struct Streamer<E: Estimator = Box<dyn Estimator>> {
    est: E,
    config: EngineConfig,
    hop: usize,
    /// Samples before a window end the estimator may read.
    back: usize,
    lookahead: usize,
    future: bool,
    dt_fixed: Option<f64>,
    cap: usize,
    /// Absolute index of element 0 of the buffers.
    off: usize,
    t: Vec<f64>,
    u: Vec<f64>,
    y: Vec<f64>,
    /// Latest prediction per sample, and whether there is one.
    p: Vec<f64>,
    has: Vec<bool>,
    /// Commands pushed / positions pushed (absolute counts).
    nc: usize,
    np: usize,
    /// Highest absolute index + 1 with a stored prediction.
    top: usize,
    t_first: f64,
    t_last: f64,
    c_first: f64,
    motion_start: f64,
    next_start: usize,
    scored: usize,
    finished: bool,
    coef: Vec<f64>,
    pred: Vec<f64>,
    windows: usize,
    failed: usize,
    withheld: usize,
    acc: ErrorAccumulator,
}

impl<E: Estimator> Streamer<E> {
    /// A streamer with the default [`StreamOptions`].
    pub fn new(estimator: E, config: EngineConfig) -> Result<Self> {
        Self::with_options(estimator, config, StreamOptions::default())
    }

    /// A streamer; allocates every buffer it will use.
    pub fn with_options(
        estimator: E,
        config: EngineConfig,
        options: StreamOptions,
    ) -> Result<Self> {
        let hop = config.hop();
        for (name, v) in [
            ("window", config.window),
            ("horizon", config.horizon),
            ("hop", hop),
        ] {
            if v == 0 {
                return Err(Error::InvalidParameter {
                    name,
                    value: 0.0,
                    reason: "must be at least 1 sample",
                });
            }
        }
        let lookahead = options.lookahead.unwrap_or(config.horizon);
        if let Some(dt) = options.dt {
            if !(dt.is_finite() && dt > 0.0) {
                return Err(Error::InvalidParameter {
                    name: "dt",
                    value: dt,
                    reason: "must be finite and > 0",
                });
            }
        }
        // retained: `back` before a window end, up to H + look-ahead after it
        let back = estimator
            .warm_up()
            .checked_add(config.window)
            .and_then(|v| v.checked_add(hop));
        let span = back
            .and_then(|v| v.checked_add(config.horizon))
            .and_then(|v| v.checked_add(lookahead))
            .and_then(|v| v.checked_add(1))
            .filter(|&v| v <= MAX_CAPACITY / 2);
        let (Some(back), Some(span)) = (back, span) else {
            return Err(Error::InvalidParameter {
                name: "window + horizon + hop + look-ahead",
                value: f64::INFINITY,
                reason: "too large for a stream buffer",
            });
        };
        let cap = 2 * span;
        let nc = estimator.coefficient_names().len();
        let mut s = Self {
            future: estimator.uses_future_command(),
            est: estimator,
            config,
            hop,
            back,
            lookahead,
            dt_fixed: options.dt,
            cap,
            off: 0,
            t: vec![0.0; cap],
            u: vec![0.0; cap],
            y: vec![0.0; cap],
            p: vec![0.0; cap],
            has: vec![false; cap],
            nc: 0,
            np: 0,
            top: 0,
            t_first: 0.0,
            t_last: 0.0,
            c_first: 0.0,
            motion_start: f64::INFINITY,
            next_start: 0,
            scored: 0,
            finished: false,
            coef: vec![0.0; nc],
            pred: vec![0.0; config.horizon],
            windows: 0,
            failed: 0,
            withheld: 0,
            acc: ErrorAccumulator::default(),
        };
        s.reset();
        Ok(s)
    }

    /// Forget all samples and start a new stream (the estimator is reset too).
    pub fn reset(&mut self) {
        self.est.reset();
        self.off = 0;
        self.has.fill(false);
        self.nc = 0;
        self.np = 0;
        self.top = 0;
        self.motion_start = f64::INFINITY;
        self.next_start = self.config.warm_up.saturating_add(self.est.warm_up());
        self.scored = 0;
        self.finished = false;
        self.windows = 0;
        self.failed = 0;
        self.withheld = 0;
        self.acc = ErrorAccumulator::default();
    }

    /// The estimator.
    pub fn estimator(&self) -> &E {
        &self.est
    }

    /// The window configuration.
    pub fn config(&self) -> &EngineConfig {
        &self.config
    }

    /// Whether a window waits for the command over its horizon
    /// ([`Estimator::uses_future_command`]); if not, it is processed at its end.
    pub fn waits_for_future_command(&self) -> bool {
        self.future
    }

    /// Motion start found so far \[s\] (`f64::INFINITY` until the command moves).
    pub fn motion_start(&self) -> f64 {
        self.motion_start
    }

    /// Counters and the score so far.
    pub fn stats(&self) -> StreamStats {
        StreamStats {
            samples: self.np,
            commands: self.nc,
            windows: self.windows,
            failed_windows: self.failed,
            withheld_windows: self.withheld,
            scored: self.acc.finish(),
        }
    }

    /// The sampling interval used (`None` before two samples without [`StreamOptions::dt`]).
    pub fn dt(&self) -> Option<f64> {
        match self.dt_fixed {
            Some(dt) => Some(dt),
            None if self.nc >= 2 => Some((self.t_last - self.t_first) / (self.nc - 1) as f64),
            None => None,
        }
    }

    /// Push one complete sample: time \[s\], command \[m\], measured position
    /// \[m\]; returns the prediction that became due, if any. On error (a
    /// non-finite value, time not increasing) nothing is stored.
    pub fn push(&mut self, t: f64, command: f64, position: f64) -> Result<Option<Prediction<'_>>> {
        self.check_command(t, command)?;
        self.check_position(position)?;
        self.store_command(t, command)?;
        self.store_position(position);
        self.poll()
    }

    /// Push the command (set-point) of the next sample ahead of its position
    /// (at most `lookahead` ahead). Then call [`Streamer::poll`] until `None`.
    pub fn push_command(&mut self, t: f64, command: f64) -> Result<()> {
        self.check_command(t, command)?;
        self.store_command(t, command)
    }

    /// Push the measured position \[m\] of the oldest sample whose command has
    /// been pushed. Then call [`Streamer::poll`] until `None`.
    pub fn push_position(&mut self, position: f64) -> Result<()> {
        if self.np >= self.nc {
            return Err(Error::InvalidParameter {
                name: "position",
                value: position,
                reason: "no command pushed for this sample (push_command first)",
            });
        }
        self.check_position(position)?;
        self.store_position(position);
        Ok(())
    }

    /// End of input: windows waiting for the command are processed with the
    /// horizon cut at the last measured sample. Call [`Streamer::poll`] until `None`.
    pub fn finish(&mut self) {
        self.finished = true;
        self.advance_score();
    }

    /// Process the next window if it is due and return its prediction.
    pub fn poll(&mut self) -> Result<Option<Prediction<'_>>> {
        let (w, h) = (self.config.window, self.config.horizon);
        let s = self.next_start;
        let we = s.saturating_add(w);
        let he = if self.finished {
            if we >= self.np {
                return Ok(None);
            }
            we.saturating_add(h).min(self.np)
        } else {
            let he = we.saturating_add(h);
            if self.np < we || (self.future && self.nc < he) {
                return Ok(None);
            }
            he
        };
        let Some(dt) = self.dt() else {
            return Ok(None);
        };
        let end = self.nc.max(he);
        self.ensure_room(end)?;
        let Self {
            est,
            off,
            t,
            u,
            y,
            p,
            has,
            nc,
            np,
            coef,
            pred,
            t_last,
            motion_start,
            ..
        } = self;
        let (off, nc, np) = (*off, *nc, *np);
        // not yet pushed: extrapolated times, unknown (NaN) command and position
        for (m, ti) in t[nc - off..end - off].iter_mut().enumerate() {
            *ti = *t_last + (m + 1) as f64 * dt;
        }
        u[nc - off..end - off].fill(f64::NAN);
        y[np - off..end - off].fill(f64::NAN);
        let signals = Signals::with_offset(
            off,
            &t[..end - off],
            &u[..end - off],
            &y[..end - off],
            dt,
            *motion_start,
        );
        let out = &mut pred[..he - we];
        coef.fill(0.0);
        let record = fit_and_predict(est, &signals, s..we, we..he, coef, out);
        let ok = record.outcome.predicted();
        if ok {
            p[we - off..he - off].copy_from_slice(out);
            has[we - off..he - off].fill(true);
        }
        self.windows += 1;
        if ok {
            self.top = self.top.max(he);
        } else if record.outcome == WindowOutcome::Withheld {
            self.withheld += 1;
        } else {
            self.failed += 1;
        }
        self.next_start = s.saturating_add(self.hop);
        self.advance_score();
        let off = self.off;
        Ok(Some(Prediction {
            window: s..we,
            horizon: we..he,
            time: &self.t[we - off..he - off],
            position: if ok { &self.pred[..he - we] } else { &[] },
            coefficients: &self.coef,
            residual_rms: record.residual_rms,
            iterations: record.iterations,
            outcome: record.outcome,
        }))
    }

    fn check_command(&self, t: f64, command: f64) -> Result<()> {
        if self.finished {
            return Err(Error::InvalidParameter {
                name: "stream",
                value: self.nc as f64,
                reason: "finished: reset it before pushing more samples",
            });
        }
        for (channel, v) in [("time", t), ("command", command)] {
            check_value(channel, self.nc, v)?;
        }
        if self.nc > 0 && t <= self.t_last {
            return Err(Error::NonMonotoneTime {
                index: self.nc,
                previous: self.t_last,
                value: t,
            });
        }
        if self.nc - self.np > self.lookahead {
            return Err(Error::InvalidParameter {
                name: "command look-ahead",
                value: (self.nc - self.np + 1) as f64,
                reason: "more commands ahead of the positions than the streamer's look-ahead",
            });
        }
        Ok(())
    }

    fn check_position(&self, position: f64) -> Result<()> {
        check_value("position", self.np, position)
    }

    fn store_command(&mut self, t: f64, command: f64) -> Result<()> {
        self.ensure_room(self.nc + 1)?;
        let i = self.nc - self.off;
        self.t[i] = t;
        self.u[i] = command;
        self.y[i] = f64::NAN;
        if self.nc == 0 {
            self.t_first = t;
            self.c_first = command;
        } else if self.motion_start == f64::INFINITY
            && (command - self.c_first).abs() > MOTION_THRESHOLD
        {
            self.motion_start = self.t_last;
        }
        self.t_last = t;
        self.nc += 1;
        Ok(())
    }

    /// Store the position of sample `np` (its command is in the buffer).
    fn store_position(&mut self, position: f64) {
        if self.np >= self.nc {
            return;
        }
        self.y[self.np - self.off] = position;
        self.np += 1;
        self.advance_score();
    }

    /// Score the samples whose latest prediction is final.
    fn advance_score(&mut self) {
        let next_we = self.next_start.saturating_add(self.config.window);
        let limit = self.np.min(next_we);
        while self.scored < limit {
            let i = self.scored - self.off;
            if self.has[i] {
                self.acc.push(self.y[i], self.p[i]);
            }
            self.scored += 1;
        }
    }

    /// Make absolute indices `..end` addressable, compacting if needed.
    fn ensure_room(&mut self, end: usize) -> Result<()> {
        if end - self.off <= self.cap {
            return Ok(());
        }
        let next_we = self.next_start.saturating_add(self.config.window);
        let keep = self
            .nc
            .min(next_we.saturating_sub(self.back))
            .min(self.scored)
            .max(self.off);
        let hi = self.nc.max(self.top).max(keep);
        let (a, b) = (keep - self.off, hi - self.off);
        for v in [&mut self.t, &mut self.u, &mut self.y, &mut self.p] {
            v.copy_within(a..b, 0);
        }
        self.has.copy_within(a..b, 0);
        self.has[b - a..].fill(false);
        self.off = keep;
        if end - self.off <= self.cap {
            Ok(())
        } else {
            Err(Error::InvalidParameter {
                name: "stream buffer",
                value: (end - self.off) as f64,
                reason: "samples exceed the buffer: poll the due predictions until None",
            })
        }
    }
}

/// A sample value is accepted as in a [`crate::Recording`]: finite and at
/// most [`crate::recording::MAX_MAGNITUDE`] in magnitude.
fn check_value(channel: &str, index: usize, v: f64) -> Result<()> {
    if !v.is_finite() {
        return Err(Error::NonFinite {
            channel: channel.to_string(),
            index,
            value: v,
        });
    }
    if !crate::recording::is_usable(v) {
        return Err(Error::OutOfRange {
            channel: channel.to_string(),
            index,
            value: v,
            limit: crate::recording::MAX_MAGNITUDE,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{RigParams, VirtualRig};
    use crate::ident::engine::{run, SlidingResult};
    use crate::ident::{PaperConfig, PaperMethod, PredictStatus, Solver, WindowFit};
    use crate::signal::Scenario;
    use crate::solve::Termination;
    use crate::Recording;

    /// Straight line through the last two window samples (window-end estimator).
    struct Linear;

    impl Estimator for Linear {
        fn name(&self) -> &'static str {
            "linear"
        }
        fn coefficient_names(&self) -> Vec<String> {
            vec!["last".into(), "slope".into()]
        }
        fn uses_future_command(&self) -> bool {
            false
        }
        fn fit(&mut self, s: &Signals<'_>, w: Range<usize>, c: &mut [f64]) -> Result<WindowFit> {
            let y = s.window(w.end - 2..w.end, 0, "test").unwrap().position;
            c[0] = y[1];
            c[1] = y[1] - y[0];
            Ok(WindowFit::identified(0.0, 0, Termination::Exact))
        }
        fn predict(
            &mut self,
            s: &Signals<'_>,
            w: Range<usize>,
            _: Range<usize>,
            out: &mut [f64],
        ) -> Result<PredictStatus> {
            let y = s.window(w.end - 2..w.end, 0, "test").unwrap().position;
            for (j, o) in out.iter_mut().enumerate() {
                *o = y[1] + (j as f64 + 1.0) * (y[1] - y[0]);
            }
            Ok(PredictStatus::Predicted)
        }
    }

    /// Last position plus the command change over the horizon; reads one
    /// sample before the window (warm-up 1) and fails on every 7th window.
    struct Follow {
        k: usize,
    }

    impl Estimator for Follow {
        fn name(&self) -> &'static str {
            "follow"
        }
        fn coefficient_names(&self) -> Vec<String> {
            vec!["gain".into()]
        }
        fn warm_up(&self) -> usize {
            1
        }
        fn reset(&mut self) {
            self.k = 0;
        }
        fn fit(&mut self, s: &Signals<'_>, w: Range<usize>, c: &mut [f64]) -> Result<WindowFit> {
            self.k += 1;
            if self.k % 7 == 0 {
                return Err(Error::Singular { context: "test" });
            }
            let u = s.window(w.start - 1..w.end, 0, "test").unwrap().command;
            let y = s.window(w.start - 1..w.end, 0, "test").unwrap().position;
            let du = u[u.len() - 1] - u[0];
            c[0] = if du != 0.0 {
                (y[y.len() - 1] - y[0]) / du
            } else {
                1.0
            };
            Ok(WindowFit::identified(0.0, 0, Termination::Exact))
        }
        fn predict(
            &mut self,
            s: &Signals<'_>,
            w: Range<usize>,
            h: Range<usize>,
            out: &mut [f64],
        ) -> Result<PredictStatus> {
            let y0 = s.window(w.end - 1..w.end, 0, "test").unwrap().position[0];
            let u0 = s.window(w.end - 1..w.end, 0, "test").unwrap().command[0];
            for (o, &u) in out.iter_mut().zip(s.window(h, 0, "test").unwrap().command) {
                *o = y0 + (u - u0);
            }
            Ok(PredictStatus::Predicted)
        }
    }

    /// How samples are fed.
    #[derive(Debug, Clone, Copy)]
    enum Feed {
        Push,
        Ahead(usize),
    }

    /// Window, horizon, outcome and coefficients of one processed window.
    type WindowSummary = (Range<usize>, Range<usize>, WindowOutcome, Vec<f64>);

    /// What a stream produced, in the batch engine's layout.
    struct Collected {
        windows: Vec<WindowSummary>,
        predicted: Vec<f64>,
        has: Vec<bool>,
        /// (sample index at which the prediction arrived, horizon start)
        arrivals: Vec<(usize, usize)>,
        stats: StreamStats,
    }

    fn collect_from(out: &mut Collected, p: Option<Prediction<'_>>, arrived_at: usize, t: &[f64]) {
        let Some(p) = p else { return };
        assert_eq!(p.time.len(), p.horizon.len());
        if p.is_ok() {
            assert_eq!(p.position.len(), p.horizon.len());
            for (j, k) in p.horizon.clone().enumerate() {
                if k < out.predicted.len() {
                    out.predicted[k] = p.position[j];
                    out.has[k] = true;
                    // time stamps: actual or extrapolated to rounding
                    assert!((p.time[j] - t[k]).abs() < 1e-12 * t[k].abs().max(1.0));
                }
            }
        }
        out.arrivals.push((arrived_at, p.horizon.start));
        out.windows.push((
            p.window.clone(),
            p.horizon.clone(),
            p.outcome,
            p.coefficients.to_vec(),
        ));
    }

    fn stream<E: Estimator>(est: E, cfg: EngineConfig, rec: &Recording, feed: Feed) -> Collected {
        let (t, u, y) = (rec.time(), rec.command(), rec.position());
        let n = t.len();
        let mut out = Collected {
            windows: Vec::new(),
            predicted: vec![0.0; n],
            has: vec![false; n],
            arrivals: Vec::new(),
            stats: StreamStats {
                samples: 0,
                commands: 0,
                windows: 0,
                failed_windows: 0,
                withheld_windows: 0,
                scored: ErrorStats::from_pairs([]),
            },
        };
        let opts = StreamOptions {
            lookahead: match feed {
                Feed::Push => None,
                Feed::Ahead(l) => Some(l),
            },
            dt: None,
        };
        let mut s = Streamer::with_options(est, cfg, opts).unwrap();
        match feed {
            Feed::Push => {
                for k in 0..n {
                    let p = s.push(t[k], u[k], y[k]).unwrap();
                    collect_from(&mut out, p, k, t);
                    assert!(s.poll().unwrap().is_none(), "two predictions due at {k}");
                }
            }
            Feed::Ahead(l) => {
                for k in 0..n + l {
                    if k < n {
                        s.push_command(t[k], u[k]).unwrap();
                        while let Some(p) = s.poll().unwrap() {
                            collect_from(&mut out, Some(p), k, t);
                        }
                    }
                    if k >= l {
                        s.push_position(y[k - l]).unwrap();
                        while let Some(p) = s.poll().unwrap() {
                            collect_from(&mut out, Some(p), k - l, t);
                        }
                    }
                }
            }
        }
        s.finish();
        while let Some(p) = s.poll().unwrap() {
            collect_from(&mut out, Some(p), n, t);
        }
        out.stats = s.stats();
        out
    }

    /// Stream and batch give the same windows, coefficients and predictions.
    fn assert_same(c: &Collected, b: &SlidingResult, rel: f64, what: &str) {
        let n = b.predicted.len();
        // a window-end estimator may also process the window ending at the
        // last sample, which has nothing left to predict in batch
        let ws: Vec<_> = c.windows.iter().filter(|w| w.0.end < n).collect();
        assert_eq!(ws.len(), b.windows.len(), "{what}: window count");
        for (i, (w, bw)) in ws.iter().zip(&b.windows).enumerate() {
            assert_eq!(w.0, bw.window, "{what}: window {i}");
            assert_eq!(w.1.start, bw.horizon.start, "{what}: window {i}");
            assert_eq!(w.1.end.min(n), bw.horizon.end, "{what}: window {i}");
            assert_eq!(w.2, bw.outcome, "{what}: window {i}");
            assert_eq!(&w.3[..], b.window_coefficients(i), "{what}: window {i}");
        }
        let scale = b.predicted.iter().fold(1e-300_f64, |m, v| m.max(v.abs()));
        for k in 0..n {
            assert_eq!(c.has[k], b.has_prediction[k], "{what}: sample {k}");
            if c.has[k] {
                let (a, e) = (c.predicted[k], b.predicted[k]);
                assert!(
                    (a - e).abs() <= rel * scale,
                    "{what}: sample {k}: {a:e} vs {e:e}"
                );
            }
        }
        assert_eq!(c.stats.scored.samples, b.stats.samples, "{what}");
        assert!(
            (c.stats.scored.rms - b.stats.rms).abs() <= 1e-9 * b.stats.rms + rel * scale,
            "{what}: rms {} vs {}",
            c.stats.scored.rms,
            b.stats.rms
        );
        assert_eq!(c.stats.samples, n);
        assert_eq!(
            c.stats.failed_windows,
            c.windows
                .iter()
                .filter(|w| w.2 == WindowOutcome::Failed)
                .count()
        );
    }

    fn rig_recording(scenario: Scenario, duration: f64) -> Recording {
        let rate = 5000.0;
        let command = scenario.command(rate, duration, 1).unwrap();
        let out = VirtualRig::new(RigParams::default())
            .with_seed(7)
            .simulate(&command, rate)
            .unwrap();
        Recording::new(out.time, out.command, out.position).unwrap()
    }

    fn configs() -> [EngineConfig; 4] {
        [
            EngineConfig::default(),
            EngineConfig {
                window: 9,
                horizon: 3,
                hop: Some(1),
                warm_up: 5,
            },
            EngineConfig {
                window: 12,
                horizon: 6,
                hop: Some(4),
                warm_up: 0,
            },
            EngineConfig {
                window: 5,
                horizon: 8,
                hop: Some(13),
                warm_up: 2,
            },
        ]
    }

    const FEEDS: [Feed; 4] = [Feed::Push, Feed::Ahead(1), Feed::Ahead(3), Feed::Ahead(12)];

    #[test]
    fn trivial_estimators_stream_exactly_as_the_batch_engine() {
        let rec = rig_recording(Scenario::Ramp, 0.08);
        for cfg in configs() {
            for feed in FEEDS {
                let what = format!("{cfg:?} {feed:?}");
                let b = run(&mut Linear, &rec.signals(), &cfg).unwrap();
                let c = stream(Linear, cfg, &rec, feed);
                // extrapolated time stamps are not used by these estimators
                assert_same(&c, &b, 0.0, &format!("linear {what}"));
                let b = run(&mut Follow { k: 0 }, &rec.signals(), &cfg).unwrap();
                assert!(b.failed_windows() > 0);
                let c = stream(Follow { k: 0 }, cfg, &rec, feed);
                assert_same(&c, &b, 0.0, &format!("follow {what}"));
            }
        }
    }

    fn paper(solver: Solver) -> PaperMethod {
        PaperConfig {
            solver,
            ..PaperConfig::default()
        }
        .build()
        .unwrap()
    }

    #[test]
    fn paper_method_streams_as_the_batch_engine_with_qr_and_simplex() {
        // 10 ms of rest then the ramp: rest windows, the motion start and moving windows
        let rec = rig_recording(Scenario::Ramp, 0.1);
        let cases = [
            (Solver::Qr, EngineConfig::default(), Feed::Push),
            (Solver::Qr, configs()[1], Feed::Push),
            (Solver::Qr, configs()[2], Feed::Ahead(3)),
            (Solver::Simplex, EngineConfig::default(), Feed::Push),
        ];
        for (solver, cfg, feed) in cases {
            let what = format!("{solver:?} {cfg:?} {feed:?}");
            let b = run(&mut paper(solver), &rec.signals(), &cfg).unwrap();
            let rest = b
                .windows
                .iter()
                .filter(|w| w.outcome == WindowOutcome::Fallback)
                .count();
            assert!(rest > 0 && rest < b.windows.len() / 2, "{what}: {rest}");
            assert_eq!(b.failed_windows(), 0);
            let c = stream(paper(solver), cfg, &rec, feed);
            // extrapolated horizon time stamps: equal to rounding
            assert_same(&c, &b, 1e-12, &what);
            // window-end emission: each prediction arrives with the window's last sample
            for &(at, h) in &c.arrivals {
                assert!(at + 1 == h || at == rec.len(), "{what}: {at} {h}");
            }
        }
    }

    #[test]
    fn motion_start_is_found_causally_with_the_batch_value() {
        let rec = rig_recording(Scenario::Ramp, 0.03);
        let mut s = Streamer::new(Linear, EngineConfig::default()).unwrap();
        let k0 = rec.motion_start_index(MOTION_THRESHOLD).unwrap();
        for k in 0..rec.len() {
            s.push(rec.time()[k], rec.command()[k], rec.position()[k])
                .unwrap();
            if k <= k0 {
                assert_eq!(s.motion_start(), f64::INFINITY, "{k}");
            } else {
                assert_eq!(s.motion_start(), rec.motion_start_time());
            }
        }
    }

    #[test]
    fn future_command_predictions_wait_for_the_command_over_the_horizon() {
        let rec = rig_recording(Scenario::Ramp, 0.05);
        let cfg = EngineConfig::default();
        let c = stream(Follow { k: 0 }, cfg, &rec, Feed::Push);
        assert!(!c.arrivals.is_empty());
        for &(at, h) in &c.arrivals {
            // H − 1 samples after the window end, or at the end of input
            assert!(at == h + cfg.horizon - 1 || at == rec.len(), "{at} {h}");
        }
        // with a look-ahead of H, at the window end
        let c = stream(Follow { k: 0 }, cfg, &rec, Feed::Ahead(cfg.horizon));
        for &(at, h) in &c.arrivals {
            assert!(at + 1 == h || at == rec.len(), "{at} {h}");
        }
        assert!(Streamer::new(Follow { k: 0 }, cfg)
            .unwrap()
            .waits_for_future_command());
        assert!(!Streamer::new(Linear, cfg)
            .unwrap()
            .waits_for_future_command());
    }

    #[test]
    fn finish_cuts_the_last_horizons_at_the_last_sample() {
        let rec = rig_recording(Scenario::Ramp, 0.02); // 100 samples
        let c = stream(Follow { k: 0 }, EngineConfig::default(), &rec, Feed::Push);
        let last = c.windows.last().unwrap();
        // windows at 1, 11, …, 71 (warm-up 1); the last one ends at 91 and its horizon is cut
        assert_eq!(last.0, 71..91);
        assert_eq!(last.1, 91..100);
    }

    #[test]
    fn rejected_samples_leave_the_stream_unchanged() {
        let rec = rig_recording(Scenario::Ramp, 0.04);
        let (t, u, y) = (rec.time(), rec.command(), rec.position());
        let mut s = Streamer::new(paper(Solver::Qr), EngineConfig::default()).unwrap();
        let mut got = Vec::new();
        for k in 0..rec.len() {
            if k == 37 {
                assert!(matches!(
                    s.push(t[k - 1], u[k], y[k]),
                    Err(Error::NonMonotoneTime { index: 37, .. })
                ));
                assert!(matches!(
                    s.push(t[k], f64::NAN, y[k]),
                    Err(Error::NonFinite { index: 37, .. })
                ));
                assert!(matches!(
                    s.push(t[k], u[k], f64::INFINITY),
                    Err(Error::NonFinite { index: 37, .. })
                ));
            }
            if let Some(p) = s.push(t[k], u[k], y[k]).unwrap() {
                got.push(p.position.to_vec());
            }
        }
        let mut clean = Streamer::new(paper(Solver::Qr), EngineConfig::default()).unwrap();
        let mut want = Vec::new();
        for k in 0..rec.len() {
            if let Some(p) = clean.push(t[k], u[k], y[k]).unwrap() {
                want.push(p.position.to_vec());
            }
        }
        assert_eq!(got, want);
        assert_eq!(s.stats(), clean.stats());
    }

    #[test]
    fn values_a_recording_refuses_are_refused_per_sample() {
        let mut s = Streamer::new(Linear, EngineConfig::default()).unwrap();
        s.push(0.0, 0.0, 0.0).unwrap();
        for (t, u, y) in [(1e-3, 1e101, 0.0), (1e-3, 0.0, -1e300), (1e200, 0.0, 0.0)] {
            let e = s.push(t, u, y).unwrap_err();
            assert!(matches!(e, Error::OutOfRange { index: 1, .. }), "{e}");
        }
        assert_eq!(s.stats().samples, 1);
        s.push(1e-3, 1e100, 0.0).unwrap();
    }

    #[test]
    fn misuse_is_reported() {
        let cfg = EngineConfig::default();
        let mut s = Streamer::new(Linear, cfg).unwrap();
        assert!(s.push_position(0.0).is_err());
        for k in 0..=cfg.horizon {
            s.push_command(k as f64, 0.0).unwrap();
        }
        assert!(matches!(
            s.push_command(99.0, 0.0),
            Err(Error::InvalidParameter {
                name: "command look-ahead",
                ..
            })
        ));
        s.finish();
        assert!(s.push(100.0, 0.0, 0.0).is_err());
        s.reset();
        assert!(s.push(0.0, 0.0, 0.0).unwrap().is_none());
        // unpolled predictions eventually overflow the buffer instead of growing it
        let mut s = Streamer::with_options(
            Linear,
            EngineConfig {
                hop: Some(1),
                ..cfg
            },
            StreamOptions {
                lookahead: Some(0),
                dt: Some(1.0),
            },
        )
        .unwrap();
        let r: Result<()> = (0..10_000).try_for_each(|k| {
            s.push_command(k as f64, 0.0)?;
            s.push_position(0.0)
        });
        assert!(matches!(
            r,
            Err(Error::InvalidParameter {
                name: "stream buffer",
                ..
            })
        ));
        let zero = EngineConfig { window: 0, ..cfg };
        assert!(Streamer::new(Linear, zero).is_err());
        let bad_dt = StreamOptions {
            dt: Some(0.0),
            ..StreamOptions::default()
        };
        assert!(Streamer::with_options(Linear, cfg, bad_dt).is_err());
    }

    #[test]
    fn boxed_estimators_stream_like_concrete_ones() {
        let rec = rig_recording(Scenario::Ramp, 0.04);
        let boxed: Box<dyn Estimator> = Box::new(paper(Solver::Qr));
        let a = stream(boxed, EngineConfig::default(), &rec, Feed::Push);
        let b = stream(paper(Solver::Qr), EngineConfig::default(), &rec, Feed::Push);
        assert_eq!(a.predicted, b.predicted);
        assert_eq!(a.stats, b.stats);
    }
}
