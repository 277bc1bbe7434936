//! The [`Streamer`]: buffers, segments, when a window is due, and scoring
//! (the rules are in the module doc of [`crate::ident::stream`]).

use std::ops::Range;

use crate::error::{Error, Result};
use crate::ident::engine::sliding::range;
use crate::ident::engine::stream::options::{
    Arrival, CommandExtrapolation, HorizonCommand, Interval, Jump, StreamOptions,
};
use crate::ident::engine::{
    fit_and_predict, EngineConfig, Estimator, Guard, Regime, Signals, WindowOutcome,
};
use crate::recording::MOTION_THRESHOLD;
use crate::stats::{ErrorAccumulator, ErrorStats};

/// Largest buffer the streamer allocates \[samples per channel\].
const MAX_CAPACITY: usize = 1 << 26;

/// One window's prediction, borrowed from the streamer's buffers.
///
/// Per horizon sample: its time, predicted position and prediction interval
/// (the columns a consumer writes).
#[derive(Debug, Clone, PartialEq)]
pub struct Prediction<'a> {
    /// Samples fitted (absolute indices, 0 = the first sample of the stream).
    pub window: Range<usize>,
    /// Samples predicted (`H` samples; fewer only when the input ended or a
    /// gap came before the horizon's end and the window had waited for its command).
    pub horizon: Range<usize>,
    /// Time stamps of the horizon samples \[s\] (extrapolated `t_last + m·dt`
    /// where not yet measured).
    pub time: &'a [f64],
    /// Predicted positions \[m\]; empty unless [`Prediction::is_ok`].
    pub position: &'a [f64],
    /// Lower bounds of the prediction intervals \[m\] (as the batch
    /// engine's, [`crate::ident::GuardConfig`]); as long as `position`.
    pub lower: &'a [f64],
    /// Upper bounds of the prediction intervals \[m\]; as long as `position`.
    pub upper: &'a [f64],
    /// Horizon samples whose position had already arrived when this
    /// prediction was made (0: a forecast of the whole horizon).
    pub already_measured: usize,
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
    /// Lines pushed with [`Streamer::push`] (a gap's line included).
    pub lines: usize,
    /// Samples with a measured position.
    pub samples: usize,
    /// Command samples (≥ `samples`).
    pub commands: usize,
    /// Positions not used: the first `command_lead` lines of each segment,
    /// whose own command was sent before the segment began.
    pub unused_positions: usize,
    /// Windows processed.
    pub windows: usize,
    /// Windows whose fit or prediction failed.
    pub failed_windows: usize,
    /// Windows whose prediction was withheld (implausible, see
    /// [`GuardConfig::plausibility`](crate::ident::GuardConfig::plausibility)).
    pub withheld_windows: usize,
    /// Predicted samples whose prediction was made before their position arrived.
    pub predicted_ahead: usize,
    /// Predicted samples whose position had already arrived (a reconstruction).
    pub predicted_late: usize,
    /// Gaps (the windows restarted after each).
    pub gaps: usize,
    /// Irregular intervals (kept; the windows went on across them).
    pub irregular_intervals: usize,
    /// Error of the latest prediction of each measured sample that no later
    /// window can predict (as the batch engine keeps the latest).
    pub scored: ErrorStats,
    /// The baseline on the same samples: each window's last measured position held.
    pub hold: ErrorStats,
    /// Scored samples whose measured position lay inside the prediction interval.
    pub inside_interval: usize,
    /// Samples rejected as isolated outliers (not fitted; scored as measured).
    pub outliers: usize,
    /// Windows whose prediction was cut back as a runaway
    /// ([`GuardConfig::runaway`](crate::ident::GuardConfig::runaway)).
    pub runaway_windows: usize,
    /// Predicted samples cut back as runaways.
    pub runaway_samples: usize,
    /// Scored samples per command regime ([`Regime::ALL`] order).
    pub regime_samples: [usize; 5],
    /// Of which inside their prediction interval.
    pub regime_inside: [usize; 5],
}

impl Default for StreamStats {
    /// A stream before its first line: every count 0, nothing scored.
    fn default() -> Self {
        let none = ErrorStats::from_pairs([]);
        Self {
            lines: 0,
            samples: 0,
            commands: 0,
            unused_positions: 0,
            windows: 0,
            failed_windows: 0,
            withheld_windows: 0,
            predicted_ahead: 0,
            predicted_late: 0,
            gaps: 0,
            irregular_intervals: 0,
            scored: none,
            hold: none,
            inside_interval: 0,
            outliers: 0,
            runaway_windows: 0,
            runaway_samples: 0,
            regime_samples: [0; 5],
            regime_inside: [0; 5],
        }
    }
}

impl StreamStats {
    /// Share of the scored samples inside their prediction interval \[%\];
    /// `None` before any sample is scored.
    pub fn interval_coverage_percent(&self) -> Option<f64> {
        (self.scored.samples > 0)
            .then(|| 100.0 * self.inside_interval as f64 / self.scored.samples as f64)
    }
}

/// A line or position that revealed a gap, stored once the predictions due
/// before the gap have been polled.
#[derive(Debug, Clone, Copy)]
enum Pending {
    Line { t: f64, u: f64, y: f64 },
    Position { t: f64, y: f64 },
}

/// Sliding-window identification fed one sample at a time (see the module doc).
///
/// Generic over the estimator; `Streamer<Box<dyn Estimator>>` (the default
/// type parameter) takes a method chosen at run time.
#[derive(Debug)]
pub struct Streamer<E: Estimator = Box<dyn Estimator>> {
    est: E,
    config: EngineConfig,
    options: StreamOptions,
    hop: usize,
    /// Samples before a window end the estimator (or the extrapolation) may read.
    back: usize,
    lookahead: usize,
    future: bool,
    cap: usize,
    /// Absolute index of element 0 of the buffers.
    off: usize,
    t: Vec<f64>,
    u: Vec<f64>,
    /// Position as the estimator sees it (outliers replaced by their prediction).
    y: Vec<f64>,
    /// Position as measured (scored).
    raw: Vec<f64>,
    /// Latest prediction per sample, its interval, its hold baseline, and
    /// whether there is one.
    p: Vec<f64>,
    lo: Vec<f64>,
    hi: Vec<f64>,
    base: Vec<f64>,
    /// The regime of each latest prediction.
    rg: Vec<Regime>,
    has: Vec<bool>,
    /// Prediction intervals and outlier rejection, as in the batch engine.
    guard: Guard,
    /// Commands / positions stored (absolute counts).
    nc: usize,
    np: usize,
    /// Highest absolute index + 1 with a stored prediction.
    top: usize,
    /// Absolute index of the current segment's first sample.
    seg: usize,
    /// Lines pushed in the current segment (for the command lead).
    seg_lines: usize,
    /// Time of the segment's first sample (position).
    seg_t0: f64,
    /// Time of the segment's first checked time stamp, and intervals checked since.
    seg_clock: Option<f64>,
    seg_intervals: usize,
    /// Last checked time stamp (a line's, or a position's).
    last_time: Option<f64>,
    /// Time of the last sample (position).
    t_last: f64,
    /// The previous segment's interval.
    dt_prev: Option<f64>,
    c_first: f64,
    /// Last sample before the command first moves (absolute), and its time once measured.
    motion_idx: Option<usize>,
    motion_time: f64,
    next_start: usize,
    scored: usize,
    finished: bool,
    /// A gap ends the segment: the windows still due are processed first.
    ending: bool,
    pending: Option<Pending>,
    coef: Vec<f64>,
    pred: Vec<f64>,
    pred_lo: Vec<f64>,
    pred_hi: Vec<f64>,
    pred_rg: Vec<Regime>,
    inside: usize,
    runaway_windows: usize,
    runaway_samples: usize,
    regime_samples: [usize; 5],
    regime_inside: [usize; 5],
    lines: usize,
    unused: usize,
    windows: usize,
    failed: usize,
    withheld: usize,
    ahead: usize,
    late: usize,
    gaps: usize,
    irregular: usize,
    acc: ErrorAccumulator,
    acc_hold: ErrorAccumulator,
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
        options.validate()?;
        let lookahead = options
            .lookahead
            .unwrap_or(config.horizon.max(options.command_lead));
        // retained: `back` before a window end (warm-up, window, hop and the
        // extrapolation's history), up to H + look-ahead after it
        let history = CommandExtrapolation::Acceleration.history();
        let back = estimator
            .warm_up()
            .checked_add(config.window)
            .and_then(|v| v.checked_add(hop))
            .and_then(|v| v.checked_add(history));
        let span = back
            .and_then(|v| v.checked_add(config.horizon))
            .and_then(|v| v.checked_add(lookahead))
            .and_then(|v| v.checked_add(1))
            .filter(|&v| v <= MAX_CAPACITY / 2);
        let (Some(back), Some(span)) = (back, span) else {
            return Err(Error::StreamBufferTooLarge {
                window: config.window,
                hop,
                horizon: config.horizon,
                lookahead,
                max: MAX_CAPACITY / 2 - (estimator.warm_up() + history + 1).min(MAX_CAPACITY / 2),
            });
        };
        let cap = 2 * span;
        let ncoef = estimator.coefficient_names().len();
        let basis = options.command_basis(estimator.uses_future_command(), config.horizon);
        let guard = Guard::new(options.guard, config.horizon, hop)?.with_command_basis(basis);
        let mut s = Self {
            future: estimator.uses_future_command(),
            est: estimator,
            config,
            options,
            hop,
            back,
            lookahead,
            cap,
            off: 0,
            t: vec![0.0; cap],
            u: vec![0.0; cap],
            y: vec![0.0; cap],
            raw: vec![0.0; cap],
            p: vec![0.0; cap],
            lo: vec![0.0; cap],
            hi: vec![0.0; cap],
            base: vec![0.0; cap],
            rg: vec![Regime::Rest; cap],
            has: vec![false; cap],
            guard,
            nc: 0,
            np: 0,
            top: 0,
            seg: 0,
            seg_lines: 0,
            seg_t0: 0.0,
            seg_clock: None,
            seg_intervals: 0,
            last_time: None,
            t_last: 0.0,
            dt_prev: None,
            c_first: 0.0,
            motion_idx: None,
            motion_time: f64::INFINITY,
            next_start: 0,
            scored: 0,
            finished: false,
            ending: false,
            pending: None,
            coef: vec![0.0; ncoef],
            pred: vec![0.0; config.horizon],
            pred_lo: vec![0.0; config.horizon],
            pred_hi: vec![0.0; config.horizon],
            pred_rg: vec![Regime::Rest; config.horizon],
            inside: 0,
            runaway_windows: 0,
            runaway_samples: 0,
            regime_samples: [0; 5],
            regime_inside: [0; 5],
            lines: 0,
            unused: 0,
            windows: 0,
            failed: 0,
            withheld: 0,
            ahead: 0,
            late: 0,
            gaps: 0,
            irregular: 0,
            acc: ErrorAccumulator::default(),
            acc_hold: ErrorAccumulator::default(),
        };
        s.reset();
        Ok(s)
    }

    /// Forget all samples and counters and start a new stream (the estimator is reset too).
    pub fn reset(&mut self) {
        self.off = 0;
        self.nc = 0;
        self.np = 0;
        self.last_time = None;
        self.dt_prev = None;
        self.finished = false;
        self.pending = None;
        self.lines = 0;
        self.unused = 0;
        self.windows = 0;
        self.failed = 0;
        self.withheld = 0;
        self.ahead = 0;
        self.late = 0;
        self.gaps = 0;
        self.irregular = 0;
        self.acc = ErrorAccumulator::default();
        self.acc_hold = ErrorAccumulator::default();
        self.inside = 0;
        self.runaway_windows = 0;
        self.runaway_samples = 0;
        self.regime_samples = [0; 5];
        self.regime_inside = [0; 5];
        self.est.reset();
        self.begin_segment();
        self.guard.reset();
    }

    /// Start a segment at sample `np` (commands already stored from there on
    /// are kept; see [`Streamer::restart_segment`]).
    fn begin_segment(&mut self) {
        // (after a gap the estimator keeps what does not pair samples)
        self.est.gap();
        self.guard.reset_segment();
        self.has.fill(false);
        self.top = self.np;
        self.scored = self.np;
        self.seg = self.np;
        self.seg_lines = 0;
        self.seg_clock = None;
        self.seg_intervals = 0;
        self.next_start = self
            .np
            .saturating_add(self.config.warm_up)
            .saturating_add(self.est.warm_up());
        self.ending = false;
        self.motion_idx = None;
        self.motion_time = f64::INFINITY;
        if self.nc > self.np {
            // commands kept across a gap: the new segment's first command and motion start
            let (a, b) = (self.np - self.off, self.nc - self.off);
            self.c_first = self.u[a];
            self.motion_idx = self.u[a + 1..b]
                .iter()
                .position(|&v| (v - self.c_first).abs() > MOTION_THRESHOLD)
                .map(|i| self.np + i);
        }
    }

    /// The estimator.
    pub fn estimator(&self) -> &E {
        &self.est
    }

    /// The window configuration.
    pub fn config(&self) -> &EngineConfig {
        &self.config
    }

    /// The stream options.
    pub fn options(&self) -> &StreamOptions {
        &self.options
    }

    /// Whether the estimator reads the command over the horizon
    /// ([`Estimator::uses_future_command`]).
    pub fn uses_future_command(&self) -> bool {
        self.future
    }

    /// Where the command over each horizon comes from with lines pushed by
    /// [`Streamer::push`] (with [`Streamer::push_command`], the look-ahead
    /// the caller keeps plays the part of the command lead).
    pub fn horizon_command(&self) -> HorizonCommand {
        let lead = self.options.command_lead;
        if !self.future {
            HorizonCommand::NotRead
        } else if lead >= self.config.horizon {
            HorizonCommand::Known { lead }
        } else if self.options.extrapolation == CommandExtrapolation::Wait {
            HorizonCommand::Awaited { lead }
        } else {
            HorizonCommand::Extrapolated {
                extrapolation: self.options.extrapolation,
                known: lead,
            }
        }
    }

    /// Motion start of the current segment \[s\]: the time of the last
    /// sample before the command first moves, `f64::INFINITY` until that
    /// sample has been measured.
    pub fn motion_start(&self) -> f64 {
        self.motion_time
    }

    /// Counters and scores so far.
    pub fn stats(&self) -> StreamStats {
        StreamStats {
            lines: self.lines,
            samples: self.np,
            commands: self.nc,
            unused_positions: self.unused,
            windows: self.windows,
            failed_windows: self.failed,
            withheld_windows: self.withheld,
            predicted_ahead: self.ahead,
            predicted_late: self.late,
            gaps: self.gaps,
            irregular_intervals: self.irregular,
            scored: self.acc.finish(),
            hold: self.acc_hold.finish(),
            inside_interval: self.inside,
            outliers: self.guard.outliers(),
            runaway_windows: self.runaway_windows,
            runaway_samples: self.runaway_samples,
            regime_samples: self.regime_samples,
            regime_inside: self.regime_inside,
        }
    }

    /// The sampling interval used \[s\]: [`StreamOptions::dt`], else the mean
    /// interval of the current segment's samples (of its time stamps while it
    /// has fewer than two samples, else the previous segment's); `None`
    /// before any interval is known.
    pub fn dt(&self) -> Option<f64> {
        if let Some(dt) = self.options.dt {
            return Some(dt);
        }
        let n = self.np - self.seg;
        if n >= 2 {
            Some((self.t_last - self.seg_t0) / (n - 1) as f64)
        } else if let (Some(t0), Some(t1), true) =
            (self.seg_clock, self.last_time, self.seg_intervals > 0)
        {
            Some((t1 - t0) / self.seg_intervals as f64)
        } else {
            self.dt_prev
        }
    }

    /// Push one input line: time \[s\], command \[m\], measured position
    /// \[m\]. With [`StreamOptions::command_lead`] `N`, the command belongs to
    /// the sample `N` lines later and the position to this line's sample;
    /// the positions of a segment's first `N` lines are not used (their
    /// commands came before it). Then call [`Streamer::poll`] until `None`.
    ///
    /// On error (a non-finite or out-of-range value, a time not after the
    /// previous one) nothing is stored. After a gap the line starts a new
    /// segment (see the module doc).
    pub fn push(&mut self, t: f64, command: f64, position: f64) -> Result<Arrival> {
        self.check_open()?;
        check_value("time", self.np, t)?;
        check_value("command", self.nc, command)?;
        check_value("position", self.np, position)?;
        let interval = self.check_time(t)?;
        let lead = self.options.command_lead;
        if let Interval::Gap(_) = interval {
            // the line becomes sample `np` of the new segment (unless a lead leaves it unused)
            let sample = (lead == 0).then_some(self.np);
            self.lines += 1;
            self.gaps += 1;
            self.pending = Some(Pending::Line {
                t,
                u: command,
                y: position,
            });
            self.ending = true;
            self.settle()?;
            return Ok(Arrival { sample, interval });
        }
        self.ensure_room(self.nc + 1)?;
        self.lines += 1;
        self.note(interval, t);
        let sample = self.accept_line(t, command, position);
        Ok(Arrival { sample, interval })
    }

    /// Store a checked line (room for one command ensured).
    fn accept_line(&mut self, t: f64, command: f64, position: f64) -> Option<usize> {
        self.store_command(command);
        self.seg_lines += 1;
        if self.seg_lines > self.options.command_lead {
            self.store_position(t, position);
            Some(self.np - 1)
        } else {
            self.unused += 1;
            None
        }
    }

    /// Push the command (set-point) \[m\] of the next sample ahead of its
    /// position, at most [`StreamOptions::lookahead`] samples ahead. Then
    /// call [`Streamer::poll`] until `None`. Do not mix with [`Streamer::push`].
    pub fn push_command(&mut self, command: f64) -> Result<()> {
        self.check_open()?;
        check_value("command", self.nc, command)?;
        if self.nc - self.np > self.lookahead {
            return Err(Error::InvalidParameter {
                name: "command look-ahead",
                value: (self.nc - self.np + 1) as f64,
                reason: "more commands ahead of the positions than the streamer's look-ahead",
            });
        }
        self.ensure_room(self.nc + 1)?;
        self.store_command(command);
        Ok(())
    }

    /// Push the time \[s\] and measured position \[m\] of the oldest sample
    /// whose command has been pushed. Then call [`Streamer::poll`] until
    /// `None`. After a gap the sample starts a new segment; the commands
    /// pushed ahead are kept (positions and commands pair in order).
    pub fn push_position(&mut self, t: f64, position: f64) -> Result<Arrival> {
        self.check_open()?;
        if self.np >= self.nc {
            return Err(Error::InvalidParameter {
                name: "position",
                value: position,
                reason: "no command pushed for this sample (push_command first)",
            });
        }
        check_value("time", self.np, t)?;
        check_value("position", self.np, position)?;
        let interval = self.check_time(t)?;
        let sample = Some(self.np);
        if let Interval::Gap(_) = interval {
            self.gaps += 1;
            self.pending = Some(Pending::Position { t, y: position });
            self.ending = true;
            self.settle()?;
        } else {
            self.note(interval, t);
            self.store_position(t, position);
        }
        Ok(Arrival { sample, interval })
    }

    /// End of input: windows still waiting for their command are processed
    /// with the horizon cut at the last measured sample, as the batch engine
    /// cuts it at the end of the recording. Call [`Streamer::poll`] until `None`.
    pub fn finish(&mut self) {
        self.finished = true;
        self.advance_score();
    }

    /// Process the next window if it is due and return its prediction.
    pub fn poll(&mut self) -> Result<Option<Prediction<'_>>> {
        loop {
            if let Some(w) = self.due() {
                return self.process(w).map(Some);
            }
            if !self.ending {
                return Ok(None);
            }
            self.settle()?;
        }
    }

    /// The next window `(start, end, horizon end)` if it can be processed now.
    fn due(&self) -> Option<(usize, usize, usize)> {
        let (w, h) = (self.config.window, self.config.horizon);
        let s = self.next_start;
        let we = s.saturating_add(w);
        let he = if self.finished || self.ending {
            if we >= self.np {
                return None;
            }
            we.saturating_add(h).min(self.np)
        } else {
            let he = we.saturating_add(h);
            let waits = self.future && self.options.extrapolation == CommandExtrapolation::Wait;
            if self.np < we || (waits && self.nc < he) {
                return None;
            }
            he
        };
        self.dt()?;
        Some((s, we, he))
    }

    /// Fit window `s..we`, predict `we..he`, store and count.
    fn process(&mut self, (s, we, he): (usize, usize, usize)) -> Result<Prediction<'_>> {
        let dt = self.dt().unwrap_or(f64::NAN);
        let end = self.nc.max(he);
        self.ensure_room(end)?;
        let (off, nc, np) = (self.off, self.nc, self.np);
        // not yet measured: extrapolated times and unknown (NaN) positions
        let t_last = self.t_last;
        for (m, ti) in self.t[np - off..end - off].iter_mut().enumerate() {
            *ti = t_last + (m + 1) as f64 * dt;
        }
        self.y[np - off..end - off].fill(f64::NAN);
        // not yet received: the command extrapolated (or NaN, never read when waiting)
        if end > nc {
            let first = self.seg.max(off).max(nc.saturating_sub(3));
            let (past, future) = self.u[first - off..end - off].split_at_mut(nc - first);
            if self.future && self.options.extrapolation != CommandExtrapolation::Wait {
                self.options.extrapolation.fill(past, future);
            } else {
                future.fill(f64::NAN);
            }
        }
        // isolated wild samples measured since the last window: replaced by
        // their prediction in what the estimator sees (as the batch engine)
        {
            let (raw, y, seg) = (&self.raw, &mut self.y, self.seg);
            self.guard
                .observe(seg.max(off), we, |k| raw[k - off], |k, v| y[k - off] = v);
        }
        let motion_start = match self.motion_idx {
            Some(i) if i < np => self.motion_time,
            Some(i) => t_last + (i + 1 - np) as f64 * dt,
            None => f64::INFINITY,
        };
        let signals = Signals::with_offset(
            off,
            &self.t[..end - off],
            &self.u[..end - off],
            &self.y[..end - off],
            dt,
            motion_start,
        );
        let out = &mut self.pred[..he - we];
        self.coef.fill(0.0);
        let mut record =
            fit_and_predict(&mut self.est, &signals, s..we, we..he, &mut self.coef, out);
        let spread = range(&self.y[s - off..we - off]);
        let last = self.y[we - 1 - off];
        if record.outcome.predicted()
            && self.est.checks_plausibility()
            && !self
                .guard
                .plausible(out, last, spread, range(&self.u[s - off..he - off]))
        {
            record.outcome = WindowOutcome::Withheld;
            self.est.restart();
        }
        let ok = record.outcome.predicted();
        let already = np.clamp(we, he) - we;
        let (lo, hi) = (&mut self.pred_lo[..he - we], &mut self.pred_hi[..he - we]);
        let rg = &mut self.pred_rg[..he - we];
        if ok {
            let command = &self.u[s - off..he - off];
            let cut = self
                .guard
                .predicted(we, out, last, spread, command, self.future, lo, hi, rg);
            if cut > 0 {
                self.runaway_windows += 1;
                self.runaway_samples += cut;
            }
            self.p[we - off..he - off].copy_from_slice(out);
            self.lo[we - off..he - off].copy_from_slice(lo);
            self.hi[we - off..he - off].copy_from_slice(hi);
            self.rg[we - off..he - off].copy_from_slice(rg);
            self.has[we - off..he - off].fill(true);
            let hold = self.y[we - 1 - off];
            self.base[we - off..he - off].fill(hold);
            self.top = self.top.max(he);
            self.late += already;
            self.ahead += he - we - already;
        } else if record.outcome == WindowOutcome::Withheld {
            self.withheld += 1;
        } else {
            self.failed += 1;
        }
        self.windows += 1;
        self.next_start = s.saturating_add(self.hop);
        self.advance_score();
        let off = self.off;
        Ok(Prediction {
            window: s..we,
            horizon: we..he,
            time: &self.t[we - off..he - off],
            position: if ok { &self.pred[..he - we] } else { &[] },
            lower: if ok { &self.pred_lo[..he - we] } else { &[] },
            upper: if ok { &self.pred_hi[..he - we] } else { &[] },
            already_measured: already,
            coefficients: &self.coef,
            residual_rms: record.residual_rms,
            iterations: record.iterations,
            outcome: record.outcome,
        })
    }

    /// Refuse a push after [`Streamer::finish`] or while a gap waits for the
    /// predictions due before it to be polled.
    fn check_open(&self) -> Result<()> {
        if self.finished {
            return Err(Error::InvalidParameter {
                name: "stream",
                value: self.nc as f64,
                reason: "finished: reset it before pushing more samples",
            });
        }
        if self.pending.is_some() {
            return Err(Error::InvalidParameter {
                name: "stream",
                value: self.np as f64,
                reason:
                    "predictions due before a gap were not polled: poll until None after every push",
            });
        }
        Ok(())
    }

    /// Classify the interval from the last time stamp to `t` (an error if `t` is not after it).
    fn check_time(&self, t: f64) -> Result<Interval> {
        let Some(prev) = self.last_time else {
            return Ok(Interval::Regular);
        };
        if t <= prev {
            return Err(Error::NonMonotoneTime {
                index: self.np,
                previous: prev,
                value: t,
            });
        }
        let expected = match (self.options.dt, self.seg_clock) {
            (Some(dt), _) => dt,
            (None, Some(t0)) if self.seg_intervals > 0 => (prev - t0) / self.seg_intervals as f64,
            _ => return Ok(Interval::Regular),
        };
        let jump = Jump {
            previous_time: prev,
            time: t,
            expected,
        };
        let deviation = ((t - prev) / expected - 1.0).abs();
        Ok(
            if deviation.is_nan() || deviation > self.options.gap_deviation() {
                Interval::Gap(jump)
            } else if deviation > self.options.jitter_tolerance {
                Interval::Irregular(jump)
            } else {
                Interval::Regular
            },
        )
    }

    /// Take the time stamp `t` (already checked) into the segment's clock.
    fn note(&mut self, interval: Interval, t: f64) {
        if let Interval::Irregular(_) = interval {
            self.irregular += 1;
        }
        if self.seg_clock.is_some() {
            self.seg_intervals += 1;
        } else {
            self.seg_clock = Some(t);
        }
        self.last_time = Some(t);
    }

    /// If a gap ended the segment and nothing is due in it any more: start
    /// the new segment and store the line or position that revealed the gap.
    fn settle(&mut self) -> Result<()> {
        if !self.ending || self.due().is_some() {
            return Ok(());
        }
        let Some(pending) = self.pending else {
            self.ending = false;
            return Ok(());
        };
        self.restart_segment(matches!(pending, Pending::Line { .. }))?;
        self.pending = None;
        match pending {
            Pending::Line { t, u, y } => {
                self.ensure_room(self.nc + 1)?;
                self.note(Interval::Regular, t);
                self.accept_line(t, u, y);
            }
            Pending::Position { t, y } => {
                self.note(Interval::Regular, t);
                self.store_position(t, y);
            }
        }
        if self.finished {
            self.advance_score();
        }
        Ok(())
    }

    /// End the segment at the last sample and begin a new one there. Lines
    /// (`discard_ahead`) drop the commands received ahead of the positions:
    /// their pairing by line does not survive missing lines.
    fn restart_segment(&mut self, discard_ahead: bool) -> Result<()> {
        self.advance_score();
        self.dt_prev = self.dt();
        if discard_ahead {
            self.nc = self.np;
        }
        // keep only the commands ahead of the last position
        let (a, b) = (self.np - self.off, self.nc - self.off);
        for v in [&mut self.t, &mut self.u, &mut self.y, &mut self.raw] {
            v.copy_within(a..b, 0);
        }
        self.off = self.np;
        self.begin_segment();
        Ok(())
    }

    /// Store the command of sample `nc` (room ensured).
    fn store_command(&mut self, command: f64) {
        let i = self.nc - self.off;
        self.u[i] = command;
        self.t[i] = f64::NAN;
        self.y[i] = f64::NAN;
        self.raw[i] = f64::NAN;
        if self.nc == self.seg {
            self.c_first = command;
        } else if self.motion_idx.is_none() && (command - self.c_first).abs() > MOTION_THRESHOLD {
            let k = self.nc - 1;
            self.motion_idx = Some(k);
            if k < self.np {
                // k = np − 1: the last sample measured
                self.motion_time = self.t_last;
            }
        }
        self.nc += 1;
    }

    /// Store time and position of sample `np` (its command is in the buffer).
    fn store_position(&mut self, t: f64, position: f64) {
        let i = self.np - self.off;
        self.t[i] = t;
        self.y[i] = position;
        self.raw[i] = position;
        if self.np == self.seg {
            self.seg_t0 = t;
        }
        if self.motion_idx == Some(self.np) {
            self.motion_time = t;
        }
        self.t_last = t;
        self.np += 1;
        self.advance_score();
    }

    /// Score the samples whose latest prediction is final.
    fn advance_score(&mut self) {
        // windows still due (after a gap, at the end) advance `next_start`
        // past the last sample before they stop being due
        let next_we = self.next_start.saturating_add(self.config.window);
        let limit = self.np.min(next_we);
        while self.scored < limit {
            let i = self.scored - self.off;
            if self.has[i] {
                let y = self.raw[i];
                self.acc.push(y, self.p[i]);
                self.acc_hold.push(y, self.base[i]);
                let inside = usize::from(self.lo[i] <= y && y <= self.hi[i]);
                self.inside += inside;
                let r = self.rg[i].index();
                self.regime_samples[r] += 1;
                self.regime_inside[r] += inside;
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
        for v in [
            &mut self.t,
            &mut self.u,
            &mut self.y,
            &mut self.raw,
            &mut self.p,
            &mut self.lo,
            &mut self.hi,
            &mut self.base,
        ] {
            v.copy_within(a..b, 0);
        }
        self.rg.copy_within(a..b, 0);
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
