//! Streaming identification: push one line (or sample) at a time, get each
//! window's prediction of the next `H` samples as soon as it is due — before
//! the measurement it predicts has arrived.
//!
//! A [`Streamer`] visits **the same windows** as the batch engine
//! ([`crate::ident::engine`]) — window `j` is `[s_j, s_j + W)` with
//! `s_j = warm_up + estimator.warm_up() + j·hop` in absolute sample indices
//! counted from the first sample of the segment (see *Gaps*) — and makes
//! **the same estimator calls** (`reset` once, then `fit` and `predict` per
//! window, in order). Where it has the same data — the real command over each
//! horizon, i.e. a command lead ≥ `H` or [`CommandExtrapolation::Wait`] — its
//! predictions are those of [`crate::ident::engine::run`] on the same samples
//! (tested to ≤ 1e-12 of the position range; see *Horizon time stamps*).
//!
//! # Feeding the streamer
//!
//! * [`Streamer::push`]`(t, u, y)` — one input line. With
//!   [`StreamOptions::command_lead`] `N` the command `u` belongs to the
//!   sample `N` lines later (a CNC interpolator produces the set-point ahead
//!   of the measurement); the time `t` and position `y` belong to this line's
//!   sample. The positions of the first `N` lines have no command (it was
//!   sent before the stream began) and are not used: sample `j` is
//!   `(t, y)` of line `j + N` with `u` of line `j`.
//! * [`Streamer::push_command`]`(u)` ahead of [`Streamer::push_position`]`(t, y)`
//!   — commands and positions pair in order, at most
//!   [`StreamOptions::lookahead`] commands ahead.
//!
//! After each push call [`Streamer::poll`] until it returns `None`; at the
//! end of the input call [`Streamer::finish`] and poll again. (A binding's
//! `push(t, u, y)` → the predictions that became due is `push` + `poll`
//! until `None`; its `finish()` is `finish` + `poll`.)
//!
//! # When a prediction is due
//!
//! Window `j` is processed **at its end** — as soon as the position of sample
//! `s_j + W − 1` has arrived, before the first horizon sample's line is read —
//! unless the estimator reads the command over the horizon
//! ([`crate::ident::Estimator::uses_future_command`]: arx, rls, oe, auto, the
//! paper's `tf` mode) and the command has not arrived there yet. Then, by
//! [`StreamOptions::extrapolation`]:
//!
//! | command over the horizon ([`HorizonCommand`]) | when |
//! |---|---|
//! | not read (the paper's polynomial prediction) | at the window end |
//! | known: command lead `N ≥ H` | at the window end, with the real command |
//! | extrapolated ([`CommandExtrapolation`] hold, velocity, acceleration — the default) beyond the `N` samples received | at the window end |
//! | awaited ([`CommandExtrapolation::Wait`]) | once the command up to `s_j + W + H − 1` has arrived: `H − N − 1` samples late, a reconstruction |
//!
//! The extrapolated samples are overwritten by the real command when it
//! arrives; they are used by this one prediction only.
//! [`StreamStats::predicted_ahead`] and [`StreamStats::predicted_late`] count
//! the predicted samples made before and after their position arrived.
//!
//! # Gaps
//!
//! Each time stamp (a line's in [`Streamer::push`], a position's in
//! [`Streamer::push_position`]) is compared with the expected interval:
//! [`StreamOptions::dt`], else the mean interval of the current segment (the
//! first interval of a segment sets it). A time not after the previous one is
//! an error (nothing is stored; the caller skips the line). An interval off by
//! more than [`StreamOptions::jitter_tolerance`] is [`Interval::Irregular`]
//! and kept: the windows go on across it. An interval off by more than
//! [`StreamOptions::gap_deviation`] (50 %: one missing sample doubles it) is
//! an [`Interval::Gap`] — samples missing, a pause, a change of the sampling
//! — and the windows **restart**, not bridged: windows spanning a gap
//! would fit a model to samples that are not consecutive (an ARX regressor
//! would pair the wrong lags) and predict at the wrong times. A gap ends the
//! current *segment*: its windows still waiting for their command are
//! processed with the horizon cut at the last sample before the gap (polled
//! first), then the estimator is told of the gap
//! ([`crate::ident::Estimator::gap`]: `arx`, `rls`, `oe` and `auto` keep
//! their models unless the sample interval changed, `paper` starts afresh)
//! and a new segment starts with the sample after the gap, whose first
//! window ends `warm-up + W` samples later — as the batch engine does at a
//! recording's gaps.
//! Pushed lines also drop the commands received ahead of the positions (with
//! lines missing, their pairing by line count is lost; the next `N` positions
//! are unused again); [`Streamer::push_command`]'s commands are kept (they
//! pair in order). Scores and counters run over the whole stream; sample
//! indices keep counting.
//!
//! # Motion start
//!
//! The batch path uses the recording's motion start
//! ([`crate::Recording::motion_start_time`]: the time of the last sample
//! before the command first moves by more than 1 nm). The streamer finds the
//! same sample causally, per segment, when the first moving command arrives,
//! and its time once that sample is measured ([`Streamer::motion_start`];
//! before that, an estimator is given the time extrapolated like the horizon's,
//! which lies after every measured sample, so the paper method's rest-window
//! test decides as in batch). The paper method treats a window whose last
//! sample is at or before the motion start as a rest window (coefficients 0,
//! [`crate::ident::WindowOutcome::Fallback`], the last position held). One
//! exception: a recording whose command never moves has its first sample as
//! motion start in batch, while the streamer, which cannot know that the
//! command will never move, keeps `∞` (every paper window is a rest window).
//!
//! # Horizon time stamps and sampling interval
//!
//! A prediction made before its horizon samples have arrived needs their time
//! stamps: they are extrapolated as `t_last + m·dt`. `dt` ([`Streamer::dt`])
//! is [`StreamOptions::dt`] if given, else the running mean interval
//! `(t_last − t_first)/(n − 1)` of the segment (the batch path uses the mean
//! over the whole recording). On uniformly sampled data the predictions then
//! agree with the batch ones to rounding (≤ 1e-12 relative).
//!
//! # Buffers and cost
//!
//! All buffers are allocated in [`Streamer::new`], sized from the
//! configuration: the estimator may read `warm_up + W + hop` samples before a
//! window end (and the extrapolation 3) and `max(H, lookahead)` after it; the
//! linear buffers hold twice that and are compacted (a copy of the retained
//! samples to the front) when full, so the per-sample cost is O(1) amortised
//! and nothing is allocated per sample or per window (as long as the
//! estimator allocates nothing either).
//!
//! # Scores
//!
//! Each measured sample is scored against its latest prediction once no later
//! window can predict it, exactly as the batch engine keeps the most recent
//! prediction of a sample ([`StreamStats::scored`]); beside it, on the same
//! samples, the baseline of holding each window's last measured position
//! ([`StreamStats::hold`]).
//!
//! # Intervals and outliers
//!
//! The stream carries the batch engine's guard ([`crate::ident::engine::Guard`],
//! settings [`StreamOptions::guard`]): each prediction comes with its
//! interval ([`Prediction::lower`], [`Prediction::upper`]) from the
//! method's own scored errors, and an isolated wild sample is replaced by
//! its prediction in what the estimator sees (scored as measured; counted
//! in [`StreamStats::outliers`], the share inside the intervals in
//! [`StreamStats::interval_coverage_percent`]). A gap restarts the guard
//! with the windows.
//!
//! ```
//! use feedid::ident::stream::{StreamOptions, Streamer};
//! use feedid::ident::{EngineConfig, Method};
//! // the default method, with the command 10 lines ahead of the position
//! let method = Method::default();
//! let cfg = EngineConfig { window: method.default_window(), ..EngineConfig::default() };
//! let opts = StreamOptions { command_lead: 10, ..StreamOptions::default() };
//! let mut s = Streamer::with_options(method.build().unwrap(), cfg, opts).unwrap();
//! let dt = 2e-4;
//! let command = |k: usize| 1e-3 * (k as f64 * dt * 20.0).sin();
//! let mut position = vec![0.0; 2000];
//! for line in 0..2000 {
//!     if line > 0 {
//!         position[line] = 0.8 * position[line - 1] + 0.2 * command(line - 1);
//!     }
//!     // line `line` carries the command of sample line + 10
//!     s.push(line as f64 * dt, command(line + 10), position[line]).unwrap();
//!     while let Some(p) = s.poll().unwrap() {
//!         // made at the window end: sample `line` is the last one measured
//!         assert_eq!(p.horizon.start, line - 10 + 1);
//!         assert_eq!(p.already_measured, 0);
//!     }
//! }
//! s.finish();
//! while s.poll().unwrap().is_some() {}
//! let stats = s.stats();
//! assert_eq!((stats.samples, stats.unused_positions, stats.predicted_late), (1990, 10, 0));
//! assert!(stats.scored.samples > 1000);
//! ```

mod options;
mod streamer;
#[cfg(test)]
mod tests;
mod watch;

pub use options::{
    Arrival, CommandExtrapolation, HorizonCommand, Interval, Jump, StreamOptions, GAP_DEVIATION,
};
pub use streamer::{Prediction, StreamStats, Streamer};
pub use watch::{HoldLoss, HoldWatch, MIN_BLOCK};
