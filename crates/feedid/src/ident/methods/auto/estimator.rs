//! The `auto` estimator: every candidate learns from every sample and
//! predicts every horizon; each prediction is scored once measured, per
//! regime of the command, and the candidate with the best score in the
//! coming horizon's regime predicts.

use std::ops::Range;

use super::candidate::{Candidate, Predictor};
use super::config::AutoConfig;
use super::model;
use crate::error::{Error, Result};
use crate::ident::engine::{rate_changed, Estimator, PredictStatus, Signals, WindowFit};
use crate::solve::Termination;

/// Regimes of a horizon, scored apart: 0 = the command is still over the
/// window and the horizon, 1 = it moves at a constant speed over the
/// horizon and the `H` samples before it, 2 = its speed changes there.
pub const REGIMES: usize = 3;

/// Relative change of the command's speed below which it counts as constant.
const CONSTANT_SPEED: f64 = 1e-3;

/// Relative margin by which a candidate's score must beat the current
/// choice's to replace it (hysteresis). Scores of candidates that predict
/// alike cross often, and near a crossing the last bits of the data (a
/// recording read in mm instead of m) would decide between them: the
/// margin makes such switches rare, so the predictions do not depend on
/// the unit, and keeps the choice from chattering.
const TIE: f64 = 0.02;

/// Factor by which the two best-backtested candidates' mean squared errors
/// must both lie below those of holding, the median and the first choice
/// for the best of them to make the first prediction (see [`First`]): one
/// model far ahead may be luck on one horizon, two that found the dynamics
/// are not. Chosen on the drive zoo: 50 … 1000 make the same two
/// recordings better (by 1.1× and 50×) and none worse, 30 a third better
/// (by 4 %), 10 … 20 one worse (by 1.5×).
const SECONDED_FIRST: f64 = 100.0;

/// Whether score `a` beats score `b` (a scored candidate beats an
/// unscored one; scores within [`TIE`] are a tie, which `a` loses).
fn beats(a: Option<f64>, b: Option<f64>) -> bool {
    match (a, b) {
        (Some(_), None) => true,
        (Some(a), Some(b)) => a < b * (1.0 - TIE),
        _ => false,
    }
}

/// A candidate, its pending prediction and its scores.
#[derive(Debug, Clone)]
struct Member {
    predictor: Predictor,
    /// A second predictor of the same candidate for the backtest
    /// (allocated once, reset in place).
    trial_predictor: Predictor,
    /// The last prediction, not yet scored.
    pending: Vec<f64>,
    pending_start: usize,
    pending_len: usize,
    /// Regime of the pending prediction's horizon.
    pending_regime: usize,
    /// Exponentially weighted mean squared error per horizon \[m²\], per regime.
    score: [f64; REGIMES],
    scored: [usize; REGIMES],
    /// Whether the candidate can predict (fitted).
    ready: bool,
    /// Mean squared error of its backtest on the first window \[m²\]
    /// (decides only how the first prediction is made, [`First`]).
    trial: Option<f64>,
    /// The candidate whose factors this one is solved from
    /// ([`Predictor::fit_follower`]), if any.
    leader: Option<usize>,
    /// Whether the backtest's predictor could be fitted.
    trial_fitted: bool,
}

impl Member {
    fn new(c: Candidate) -> Self {
        Self {
            predictor: Predictor::new(c),
            trial_predictor: Predictor::new(c),
            pending: Vec::new(),
            pending_start: 0,
            pending_len: 0,
            pending_regime: 2,
            score: [0.0; REGIMES],
            scored: [0; REGIMES],
            ready: false,
            trial: None,
            leader: None,
            trial_fitted: false,
        }
    }

    /// Whether the candidate may predict a horizon of regime `r`
    /// ([`Candidate::at_rest_only`]: only where the command is still).
    fn eligible(&self, r: usize) -> bool {
        r == 0 || !self.predictor.spec().at_rest_only()
    }

    /// Whether its predictions enter the candidates' median.
    fn in_median(&self) -> bool {
        self.predictor.spec().in_median()
    }

    /// Whether its pending prediction of `h` samples enters the median.
    fn pending_in_median(&self, h: usize) -> bool {
        self.pending_len == h && self.in_median()
    }

    /// The score in regime `r`, else in the first scored regime, else none.
    fn score_in(&self, r: usize) -> Option<f64> {
        if self.scored[r] > 0 {
            Some(self.score[r])
        } else {
            (0..REGIMES)
                .find(|&q| self.scored[q] > 0)
                .map(|q| self.score[q])
        }
    }
}

/// The `auto` estimator (method name `"auto"`); see the module doc.
#[derive(Debug, Clone)]
pub struct AutoEstimator {
    config: AutoConfig,
    members: Vec<Member>,
    selected: Option<usize>,
    /// The candidate whose coefficients are reported.
    reported: Option<usize>,
    /// First sample of the first window since the reset.
    start: Option<usize>,
    past: Vec<f64>,
    arx: Vec<f64>,
    /// Regime of the next horizon (decided at the fit).
    regime: usize,
    /// Horizon length of the last prediction (10 before the first).
    horizon: usize,
    /// Largest range of the measured position over `H + 1` consecutive
    /// samples seen so far \[m\] (the experienced motion over a horizon).
    experience: f64,
    /// Samples below this index are in `experience`.
    experienced_to: usize,
    /// How the next prediction is made: decided by the backtest for the
    /// first one after a reset, [`First::Chosen`] for every other.
    first: First,
    /// Scratch for the pointwise median of the predictions.
    sorted: Vec<f64>,
    /// Sample interval the candidates learnt at \[s\] (0 before the first fit).
    dt: f64,
}

/// The first prediction after a reset: the best-backtested candidate when
/// a second one backtested almost as well and both far better than the
/// rest ([`SECONDED_FIRST`]), else whichever of the three backtested best
/// on the first window's last horizon (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum First {
    /// Hold the last measured position.
    Hold,
    /// The pointwise median of the candidates' predictions and holding.
    Median,
    /// The chosen candidate's prediction (at the first, the settings' first
    /// ready one; every later prediction).
    Chosen,
}

impl AutoEstimator {
    pub(super) fn new(config: AutoConfig) -> Self {
        let mut members: Vec<Member> = config.candidates.iter().map(|&c| Member::new(c)).collect();
        // a windowed candidate with a constant term is solved from the
        // factors of the same candidate without it, if there is one
        let n = members.len();
        for (m, c) in members.iter_mut().zip(&config.candidates) {
            m.leader = config.candidates.iter().position(|l| c.follows(l));
        }
        for j in 0..n {
            if members.iter().any(|m| m.leader == Some(j)) {
                members[j].predictor.carry_constant();
                members[j].trial_predictor.carry_constant();
            }
        }
        let reported = config.reported();
        let n_arx = reported
            .and_then(|r| config.candidates[r].orders())
            .map_or(0, |o| o.n_params());
        Self {
            config,
            members,
            selected: None,
            reported,
            start: None,
            past: Vec::new(),
            arx: vec![0.0; n_arx],
            regime: 2,
            horizon: 10,
            experience: 0.0,
            experienced_to: 0,
            first: First::Chosen,
            sorted: Vec::new(),
            dt: 0.0,
        }
    }

    /// The settings.
    pub fn config(&self) -> &AutoConfig {
        &self.config
    }

    /// Index into [`AutoConfig::candidates`] of the candidate chosen at the last fit.
    pub fn selected(&self) -> Option<usize> {
        self.selected
    }

    /// Regime of the horizon after the last fit (see [`REGIMES`]).
    pub fn regime(&self) -> usize {
        self.regime
    }

    /// Each candidate's score in the current regime: its exponentially
    /// weighted mean squared error per horizon \[m²\], `None` before its
    /// first scored horizon.
    pub fn scores(&self) -> impl Iterator<Item = Option<f64>> + '_ {
        let r = self.regime;
        self.members.iter().map(move |m| m.score_in(r))
    }

    /// Score every pending prediction on the samples now known (`< end`).
    fn score_pending(&mut self, signals: &Signals<'_>, end: usize) {
        let alpha = self.config.memory;
        for m in &mut self.members {
            if m.pending_len == 0 {
                continue;
            }
            let from = m.pending_start.max(signals.offset());
            let to = (m.pending_start + m.pending_len).min(end);
            if let (true, Ok(w)) = (to > from, signals.window(from..to, 0, "auto scoring")) {
                let p = &m.pending[from - m.pending_start..to - m.pending_start];
                let r = m.pending_regime;
                if let Some(mse) = mean_square_error(w.position, p.iter().copied()) {
                    m.score[r] = if m.scored[r] == 0 {
                        mse
                    } else {
                        (1.0 - alpha) * m.score[r] + alpha * mse
                    };
                    m.scored[r] += 1;
                }
            }
            m.pending_len = 0;
        }
    }

    /// Extend the experienced motion over the samples measured up to `end`.
    fn learn_experience(&mut self, signals: &Signals<'_>, end: usize) {
        let h = self.horizon;
        let from = self.experienced_to.max(signals.offset() + h).min(end);
        if let Ok(w) = signals.window(from..end, h, "auto experience") {
            let y = w.position;
            // (plain comparisons: the positions are finite, and f64::min/max
            // cost their NaN handling on every sample)
            for k in h..y.len() {
                let (mut lo, mut hi) = (y[k], y[k]);
                for &v in &y[k - h..k] {
                    if v < lo {
                        lo = v;
                    }
                    if v > hi {
                        hi = v;
                    }
                }
                if hi - lo > self.experience {
                    self.experience = hi - lo;
                }
            }
        }
        self.experienced_to = end.max(self.experienced_to);
    }

    /// Score every candidate once before the first prediction, out of
    /// sample: fitted on `start..end − H`, predicting `end − H..end`
    /// (measured), so that the first choice is not blind. Needs `2·H`
    /// samples in the first window; without them nothing is scored yet.
    /// Returns the mean squared errors there of holding the last position
    /// and of the pointwise median of the candidates' predictions and
    /// holding.
    fn backtest(&mut self, signals: &Signals<'_>, start: usize, end: usize) -> Option<(f64, f64)> {
        let h = self.horizon;
        if end < start + 2 * h {
            return None;
        }
        let split = end - h;
        let measured = signals
            .window(split..end, 0, "auto backtest")
            .ok()?
            .position;
        let last = last_position(signals, start..split).ok()?;
        let hold = mean_square_error(measured, std::iter::repeat(last))?;
        // a predictor of its own: the candidate proper learns the first
        // window in one piece (its coordinates' scale is set by the first
        // rows it sees); followers after their leaders
        for m in self.members.iter_mut().filter(|m| m.leader.is_none()) {
            m.trial_predictor.reset();
            m.trial_fitted = m.trial_predictor.fit(signals, start, split);
        }
        for i in 0..self.members.len() {
            if let Some((m, leader)) = follower_and_leader(&mut self.members, i) {
                m.trial_predictor.reset();
                m.trial_fitted = m.trial_predictor.fit_follower(&leader.trial_predictor);
            }
        }
        for m in &mut self.members {
            m.pending_len = 0;
            m.trial = None;
            if !m.trial_fitted {
                continue;
            }
            if m.pending.len() < h {
                m.pending.resize(h, 0.0);
            }
            let buf = &mut m.pending[..h];
            if m.trial_predictor
                .predict(signals, split..end, &mut self.past, buf)
                .is_ok()
            {
                m.trial = mean_square_error(measured, buf.iter().copied());
            }
        }
        let (members, sorted) = (&self.members, &mut self.sorted);
        let median = (0..h).map(|j| {
            median_at(
                members,
                |m| m.trial.is_some() && m.in_median(),
                last,
                j,
                sorted,
            )
        });
        Some((hold, mean_square_error(measured, median)?))
    }

    /// Whether candidate `i`'s pending prediction (of `h` samples)
    /// departs from the candidates' consensus: at some step, more than half
    /// of the pending predictions (its own included) lie on one side of it
    /// by more than [`AutoConfig::consensus`] times its recent rms error (at
    /// least `1e-9` of the experienced motion, so that exact models of
    /// noise-free data agree) — with an odd count, its distance from their
    /// median exceeds that — and no other candidate's prediction stays
    /// within that distance of it over the whole horizon (two models that
    /// agree outweigh a majority of less precise ones). Never with fewer
    /// than three pending predictions, nor for an unscored candidate.
    fn dissents(&self, i: usize, h: usize) -> bool {
        let k = self.config.consensus;
        let me = &self.members[i];
        let Some(score) = me.score_in(self.regime) else {
            return false;
        };
        let pending = self.members.iter().filter(|m| m.pending_len == h);
        let count = pending.clone().count();
        if count < 3 || !k.is_finite() || me.pending_len != h {
            return false;
        }
        let limit = k * score.sqrt().max(1e-9 * self.experience);
        let outvoted = me.pending[..h].iter().enumerate().any(|(j, &p)| {
            if !p.is_finite() {
                return true;
            }
            let (mut above, mut below) = (0, 0);
            for m in pending.clone() {
                let q = m.pending[j];
                if q > p + limit {
                    above += 1;
                } else if q < p - limit {
                    below += 1;
                }
            }
            2 * above > count || 2 * below > count
        });
        let seconded = || {
            self.members.iter().enumerate().any(|(o, m)| {
                o != i
                    && m.pending_len == h
                    && m.pending[..h]
                        .iter()
                        .zip(&me.pending[..h])
                        .all(|(q, p)| (q - p).abs() <= limit)
            })
        };
        outvoted && !seconded()
    }

    /// The best-backtested ready candidate when it and the second best
    /// both backtested [`SECONDED_FIRST`] times better (in mean square)
    /// than `rest`, the best of holding, the median and the first choice.
    fn seconded_first(&self, rest: f64) -> Option<usize> {
        let mut best: Option<(f64, usize)> = None;
        let mut second: Option<f64> = None;
        for (i, m) in self.members.iter().enumerate().filter(|(_, m)| m.ready) {
            let Some(t) = m.trial else { continue };
            match best {
                Some((b, _)) if t >= b => second = Some(second.map_or(t, |s| s.min(t))),
                _ => {
                    second = best.map(|(b, _)| b);
                    best = Some((t, i));
                }
            }
        }
        match (best, second) {
            (Some((_, i)), Some(s)) if s * SECONDED_FIRST < rest => Some(i),
            _ => None,
        }
    }

    /// The ready candidate eligible in the current regime
    /// ([`Candidate::at_rest_only`]) with the lowest score there
    /// (unscored candidates last); ties ([`TIE`]) keep the previous choice,
    /// else the first in the order of the settings.
    fn choose(&self) -> Option<usize> {
        let r = self.regime;
        let mut choice: Option<(usize, Option<f64>)> = self
            .selected
            .filter(|&i| self.members[i].ready && self.members[i].eligible(r))
            .map(|i| (i, self.members[i].score_in(r)));
        for (i, m) in self.members.iter().enumerate() {
            if !m.ready || !m.eligible(r) || choice.is_some_and(|(c, _)| c == i) {
                continue;
            }
            let s = m.score_in(r);
            if choice.is_none_or(|(_, b)| beats(s, b)) {
                choice = Some((i, s));
            }
        }
        choice.map(|(i, _)| i)
    }
}

/// The regime (see [`REGIMES`]) of the horizon `end..end + h` after a
/// window starting at `from`, from the command (cut at the end of the data).
fn regime(signals: &Signals<'_>, from: usize, end: usize, h: usize) -> usize {
    let to = (end + h).min(signals.end());
    let Ok(w) = signals.window(from..to, 0, "auto regime") else {
        return 2;
    };
    let u = w.command;
    let Some(&u0) = u.first() else {
        return 2;
    };
    if u.iter().all(|&v| v == u0) {
        return 0;
    }
    // the speed over the horizon and the h samples before it
    let tail = &u[u.len().saturating_sub(2 * h + 1)..];
    let (mut d1, mut d2) = (0.0f64, 0.0f64);
    for p in tail.windows(3) {
        d1 = d1.max((p[2] - p[1]).abs());
        d2 = d2.max((p[2] - 2.0 * p[1] + p[0]).abs());
    }
    if d2 <= CONSTANT_SPEED * d1 {
        1
    } else {
        2
    }
}

/// The median of `last` and the `j`-th pending prediction of every member
/// that `include`s (`sorted`: scratch, allocated once).
fn median_at(
    members: &[Member],
    include: impl Fn(&Member) -> bool,
    last: f64,
    j: usize,
    sorted: &mut Vec<f64>,
) -> f64 {
    sorted.clear();
    sorted.push(last);
    sorted.extend(members.iter().filter(|m| include(m)).map(|m| m.pending[j]));
    sorted.sort_unstable_by(f64::total_cmp);
    let n = sorted.len();
    if n % 2 == 1 {
        sorted[n / 2]
    } else {
        0.5 * (sorted[n / 2 - 1] + sorted[n / 2])
    }
}

/// Member `i` (mutable) and its leader, if it follows one.
fn follower_and_leader(members: &mut [Member], i: usize) -> Option<(&mut Member, &Member)> {
    let j = members[i].leader.filter(|&j| j != i)?;
    if i < j {
        let (a, b) = members.split_at_mut(j);
        Some((&mut a[i], &b[0]))
    } else {
        let (a, b) = members.split_at_mut(i);
        Some((&mut b[0], &a[j]))
    }
}

/// Mean squared difference of `measured` and `predicted` (as many as
/// `measured`), if finite.
fn mean_square_error(measured: &[f64], predicted: impl Iterator<Item = f64>) -> Option<f64> {
    let sse: f64 = measured
        .iter()
        .zip(predicted)
        .map(|(a, b)| (a - b) * (a - b))
        .sum();
    Some(sse / measured.len().max(1) as f64).filter(|v| v.is_finite())
}

/// The last measured position of the window.
fn last_position(signals: &Signals<'_>, window: Range<usize>) -> Result<f64> {
    let w = signals.window(window.end..window.end, 1, "auto window")?;
    Ok(w.position[0])
}

impl Estimator for AutoEstimator {
    fn name(&self) -> &'static str {
        "auto"
    }

    /// `candidate` (index into [`AutoConfig::candidates`]; −1 while none
    /// is fitted and the last position is held),
    /// `expected_error_m` (its recent rms error over a horizon of the
    /// coming regime), then the ARX coefficients `a1 …, b_nk …` of the
    /// reported candidate ([`AutoConfig::reported`], the one `--order` sets).
    fn coefficient_names(&self) -> Vec<String> {
        let mut names = vec!["candidate".to_string(), "expected_error_m".to_string()];
        if let Some(o) = self
            .reported
            .and_then(|r| self.config.candidates[r].orders())
        {
            names.extend(o.coefficient_names());
        }
        names
    }

    fn warm_up(&self) -> usize {
        self.config
            .candidates
            .iter()
            .map(Candidate::warm_up)
            .max()
            .unwrap_or(1)
    }

    fn reset(&mut self) {
        // in place: a stream resets at every gap and allocates nothing after warm-up
        for m in &mut self.members {
            m.predictor.reset();
            m.pending_len = 0;
            m.pending_start = 0;
            m.pending_regime = 2;
            m.score = [0.0; REGIMES];
            m.scored = [0; REGIMES];
            m.ready = false;
            m.trial = None;
            m.trial_fitted = false;
        }
        self.selected = None;
        self.start = None;
        self.regime = 2;
        // (a stream's last horizon before a gap may have been cut short)
        self.horizon = 10;
        self.experience = 0.0;
        self.experienced_to = 0;
        self.first = First::Chosen;
        self.dt = 0.0;
    }

    /// The candidates keep their models and their scores (the drive is the
    /// same) and forget what pairs samples; the chosen one predicts the
    /// first horizon after the gap (no backtest: the scores are known). A
    /// changed sample interval resets everything at the next fit.
    fn gap(&mut self) {
        for m in &mut self.members {
            m.predictor.gap();
            m.trial_predictor.gap();
            m.pending_len = 0;
        }
        // (the last horizon before the gap may have been cut short)
        self.horizon = 10;
        self.first = First::Chosen;
    }

    fn fit(
        &mut self,
        signals: &Signals<'_>,
        window: Range<usize>,
        coef: &mut [f64],
    ) -> Result<WindowFit> {
        if window.is_empty() || window.end > signals.end() {
            return Err(Error::TooFewSamples {
                what: "auto window",
                needed: window.end.max(signals.offset() + 1),
                actual: signals.end(),
            });
        }
        if rate_changed(self.dt, signals.dt()) {
            // (a stream's gap that changed the rate: discrete models do not carry over)
            self.reset();
        }
        self.dt = signals.dt();
        self.score_pending(signals, window.end);
        self.learn_experience(signals, window.end);
        self.regime = regime(signals, window.start, window.end, self.horizon);
        let first_fit = self.start.is_none();
        let start = *self.start.get_or_insert(window.start);
        let backtest = if first_fit {
            self.backtest(signals, start, window.end)
        } else {
            None
        };
        for m in self.members.iter_mut().filter(|m| m.leader.is_none()) {
            m.ready = m.predictor.fit(signals, start, window.end);
        }
        for i in 0..self.members.len() {
            if let Some((m, leader)) = follower_and_leader(&mut self.members, i) {
                m.ready = m.predictor.fit_follower(&leader.predictor);
            }
        }
        self.selected = self.choose();
        // the first prediction: the best-backtested candidate if another
        // seconds it far ahead of the rest, else holding, the median or the
        // first choice, whichever backtested best (ties to the former)
        self.first = match backtest {
            Some((hold, median)) if first_fit => {
                let chosen = self
                    .selected
                    .and_then(|c| self.members[c].trial)
                    .unwrap_or(f64::INFINITY);
                if let Some(best) = self.seconded_first(hold.min(median).min(chosen)) {
                    self.selected = Some(best);
                    First::Chosen
                } else if hold <= median && hold <= chosen {
                    First::Hold
                } else if median <= chosen {
                    First::Median
                } else {
                    First::Chosen
                }
            }
            _ => First::Chosen,
        };
        coef.fill(0.0);
        if let Some(x) = coef.get_mut(0) {
            *x = self.selected.map_or(-1.0, |c| c as f64);
        }
        if let (Some(x), Some(c)) = (coef.get_mut(1), self.selected) {
            *x = self.members[c].score_in(self.regime).map_or(0.0, f64::sqrt);
        }
        if let Some(r) = self.reported {
            let p = &self.members[r].predictor;
            if let (Some(o), Some(rest)) = (p.spec().orders(), coef.get_mut(2..)) {
                let n = o.n_params().min(rest.len()).min(self.arx.len());
                model::arx_coefficients(&o, p.theta(), &mut self.arx);
                rest[..n].copy_from_slice(&self.arx[..n]);
            }
        }
        Ok(WindowFit::identified(0.0, 0, Termination::Exact))
    }

    /// The chosen candidate's prediction; if it cannot predict (or its
    /// prediction is implausible or departs from the candidates'
    /// consensus), the best-scored candidate that can.
    fn predict(
        &mut self,
        signals: &Signals<'_>,
        window: Range<usize>,
        horizon: Range<usize>,
        out: &mut [f64],
    ) -> Result<PredictStatus> {
        let h = out.len();
        self.horizon = h.max(1);
        let last = last_position(signals, window)?;
        let limit = self.config.plausibility * self.experience;
        for m in &mut self.members {
            m.pending_len = 0;
            if !m.ready {
                continue;
            }
            if m.pending.len() < h {
                m.pending.resize(h, 0.0);
            }
            let buf = &mut m.pending[..h];
            let ok = m
                .predictor
                .predict(signals, horizon.clone(), &mut self.past, buf)
                .is_ok();
            if ok && buf.iter().all(|p| (p - last).abs() <= limit) {
                m.pending_start = horizon.start;
                m.pending_len = h;
                m.pending_regime = self.regime;
            } else if ok && self.experience > 0.0 {
                // an implausible model (wound up, or fitted on noise) learns again
                m.predictor.restart();
                m.ready = false;
            }
        }
        match std::mem::replace(&mut self.first, First::Chosen) {
            First::Hold => {
                out.fill(last);
                return Ok(PredictStatus::Predicted);
            }
            First::Median => {
                let (members, sorted) = (&self.members, &mut self.sorted);
                for (j, o) in out.iter_mut().enumerate() {
                    *o = median_at(members, |m| m.pending_in_median(h), last, j, sorted);
                }
                return Ok(PredictStatus::Predicted);
            }
            First::Chosen => {}
        }
        let usable = |i: usize| {
            let m = &self.members[i];
            m.pending_len == h && m.eligible(self.regime) && !self.dissents(i, h)
        };
        let chosen = match self.selected {
            Some(c) if usable(c) => Some(c),
            _ => {
                let r = self.regime;
                let mut best: Option<(usize, Option<f64>)> = None;
                for (i, m) in self.members.iter().enumerate().filter(|&(i, _)| usable(i)) {
                    let s = m.score_in(r);
                    if best.is_none_or(|(_, b)| beats(s, b)) {
                        best = Some((i, s));
                    }
                }
                best.map(|(i, _)| i)
            }
        };
        match chosen {
            Some(c) => {
                out.copy_from_slice(&self.members[c].pending[..h]);
                Ok(PredictStatus::Predicted)
            }
            // every plausible candidate departs from the consensus: none is
            // trusted alone, their median with holding is; none plausible or
            // fitted: hold the last position
            None => {
                let (members, sorted) = (&self.members, &mut self.sorted);
                if members.iter().any(|m| m.pending_len == h) {
                    for (j, o) in out.iter_mut().enumerate() {
                        *o = median_at(members, |m| m.pending_in_median(h), last, j, sorted);
                    }
                } else {
                    out.fill(last);
                }
                Ok(PredictStatus::Predicted)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ident::engine::EngineConfig;

    /// 1 kHz, a slow 1 µm sine of the position; the command `offset` away.
    fn signals_data(offset: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let n = 200;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let y: Vec<f64> = (0..n).map(|k| 1e-6 * (0.05 * k as f64).sin()).collect();
        let u: Vec<f64> = y.iter().map(|v| v + offset).collect();
        (t, u, y)
    }

    /// `auto` with `config` over time `t` (1 kHz), command `u` and
    /// position `y` (window 50, H = hop = 10).
    fn run_on(
        config: AutoConfig,
        t: &[f64],
        u: &[f64],
        y: &[f64],
    ) -> crate::ident::engine::SlidingResult {
        let mut est = config.build().unwrap();
        let s = Signals::new(t, u, y, 1e-3, 0.0);
        let cfg = EngineConfig {
            window: 50,
            horizon: 10,
            hop: None,
            warm_up: 0,
        };
        crate::ident::engine::run_as_made(&mut est, &s, &cfg).unwrap()
    }

    /// `auto` with these candidates over [`signals_data`].
    fn run_candidates(
        candidates: Vec<Candidate>,
        offset: f64,
    ) -> (Vec<f64>, Vec<f64>, crate::ident::engine::SlidingResult) {
        let (t, u, y) = signals_data(offset);
        let config = AutoConfig {
            candidates,
            plausibility: 100.0,
            ..AutoConfig::default()
        };
        let r = run_on(config, &t, &u, &y);
        (u, y, r)
    }

    /// `auto` with the command as its only candidate, so that the first
    /// prediction is either the command or the held position.
    fn run_command_only(offset: f64) -> (Vec<f64>, Vec<f64>, crate::ident::engine::SlidingResult) {
        run_candidates(vec![Candidate::Command], offset)
    }

    #[test]
    fn the_first_prediction_holds_when_holding_backtests_better_than_every_candidate() {
        // the command is 1.5 µm beside the position: over the first window's
        // last horizon holding (error < 0.5 µm) beats it
        let (u, y, r) = run_command_only(1.5e-6);
        let first = r.windows[0].horizon.clone();
        let second = r.windows[1].horizon.clone();
        let last = y[first.start - 1];
        for k in first {
            assert_eq!(r.predicted[k], last, "sample {k}: the last position, held");
        }
        // from the second window on, the scored candidate predicts
        for k in second {
            assert_eq!(r.predicted[k], u[k], "sample {k}");
        }
    }

    #[test]
    fn the_first_prediction_is_the_median_when_it_backtests_better_than_holding_and_the_choice() {
        // the command leads the position by half a horizon of its motion:
        // holding lags, the command leads, their mean (the median of the
        // command and holding) is closest
        let (_, y0, _) = run_command_only(0.0);
        let lead = y0[55] - y0[50];
        let (u, y, r) = run_command_only(lead);
        let first = r.windows[0].horizon.clone();
        let last = y[first.start - 1];
        for k in first {
            assert_eq!(r.predicted[k], 0.5 * (last + u[k]), "sample {k}");
        }
    }

    #[test]
    fn two_candidates_far_ahead_in_the_backtest_make_the_first_prediction() {
        // holding first: the first choice backtests as holding, the median
        // of holding (twice) and the command (twice) better; the two
        // command candidates backtest exactly (the position is the command)
        use Candidate::{Command, Hold};
        let (u, _, r) = run_candidates(vec![Hold, Command, Command], 0.0);
        for k in r.windows[0].horizon.clone() {
            assert_eq!(r.predicted[k], u[k], "sample {k}: the command candidate's");
        }
        // one exact candidate is not enough: then holding (the median of
        // holding twice and the command is holding)
        let (_, y, r) = run_candidates(vec![Hold, Command], 0.0);
        let first = r.windows[0].horizon.clone();
        let last = y[first.start - 1];
        for k in first {
            assert_eq!(r.predicted[k], last, "sample {k}: held");
        }
    }

    #[test]
    fn the_command_at_rest_predicts_only_where_the_command_is_still() {
        // still for 100 samples, a ramp of 1 mm over 100, still again; the
        // axis follows 3 samples behind, 0.1 µm off the command at rest
        let n: usize = 400;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let u: Vec<f64> = (0..n)
            .map(|k| 1e-5 * (k.clamp(100, 200) - 100) as f64)
            .collect();
        let y: Vec<f64> = (0..n)
            .map(|k| u[k.saturating_sub(3)] + 1e-7 * ((k % 3) as f64 - 1.0))
            .collect();
        let config = AutoConfig {
            candidates: vec![Candidate::CommandAtRest],
            ..AutoConfig::default()
        };
        let r = run_on(config, &t, &u, &y);
        let (mut at_rest, mut moving) = (0, 0);
        for w in &r.windows[1..] {
            let still = u[w.window.start..w.horizon.end]
                .iter()
                .all(|&v| v == u[w.window.start]);
            for k in w.horizon.clone() {
                if still {
                    // the only candidate, eligible
                    assert_eq!(r.predicted[k], u[k], "sample {k}");
                    at_rest += 1;
                } else {
                    // not eligible, and not in the median: the last position, held
                    assert_eq!(r.predicted[k], y[w.window.end - 1], "sample {k}");
                    moving += 1;
                }
            }
        }
        assert!(at_rest > 100 && moving > 100, "{at_rest} {moving}");
    }

    #[test]
    fn the_command_at_rest_is_not_part_of_the_median() {
        // as the median test above: the median of holding and the command
        // backtests best; the command at rest beside it would make the
        // median the command
        let (_, y0, _) = run_command_only(0.0);
        let lead = y0[55] - y0[50];
        let (u, y, r) = run_candidates(vec![Candidate::Command, Candidate::CommandAtRest], lead);
        let first = r.windows[0].horizon.clone();
        let last = y[first.start - 1];
        for k in first {
            assert_eq!(r.predicted[k], 0.5 * (last + u[k]), "sample {k}");
        }
    }

    #[test]
    fn the_first_prediction_is_the_candidates_when_it_backtests_better_than_holding() {
        // the position follows the command exactly: the command backtests with error 0
        let (u, _, r) = run_command_only(0.0);
        for k in r.windows[0].horizon.clone() {
            assert_eq!(r.predicted[k], u[k], "sample {k}");
        }
    }
}

#[cfg(test)]
mod consensus_tests {
    use super::*;

    /// An `auto` with `n` plain candidates whose pending predictions over a
    /// horizon of 10 are the constants `values`, scored with rms errors `rms`
    /// (`None`: unscored).
    fn with_pending(values: &[f64], rms: &[Option<f64>], consensus: f64) -> AutoEstimator {
        let config = AutoConfig {
            candidates: vec![Candidate::Hold; values.len()],
            consensus,
            ..AutoConfig::default()
        };
        let mut est = config.build().unwrap();
        est.experience = 1.0;
        est.regime = 1;
        for ((m, &v), &e) in est.members.iter_mut().zip(values).zip(rms) {
            m.pending = vec![v; 10];
            m.pending_len = 10;
            if let Some(e) = e {
                m.score[1] = e * e;
                m.scored[1] = 1;
            }
        }
        est
    }

    fn dissenters(est: &AutoEstimator) -> Vec<usize> {
        (0..est.members.len())
            .filter(|&i| est.dissents(i, 10))
            .collect()
    }

    #[test]
    fn a_prediction_beyond_most_others_by_more_than_its_own_error_dissents() {
        // limit 20 × 0.01 = 0.2: three of four predictions lie below 5.0 − 0.2,
        // at most one beyond any other: only the 5.0 dissents
        let rms = [Some(0.01); 4];
        let est = with_pending(&[1.0, 1.01, 1.02, 5.0], &rms, 20.0);
        assert_eq!(dissenters(&est), vec![3]);
        // the same prediction by a candidate whose errors are that large agrees
        let est = with_pending(
            &[1.0, 1.01, 1.02, 5.0],
            &[Some(0.01), Some(0.01), Some(0.01), Some(0.5)],
            20.0,
        );
        assert!(dissenters(&est).is_empty());
        // an unscored candidate is never held against the consensus
        let est = with_pending(
            &[1.0, 1.01, 1.02, 5.0],
            &[Some(0.01), Some(0.01), Some(0.01), None],
            20.0,
        );
        assert!(dissenters(&est).is_empty());
    }

    #[test]
    fn two_precise_predictions_that_agree_outweigh_a_majority_of_less_precise_ones() {
        // three candidates with errors of 0.5 predict 1.0; two with errors
        // of 0.01 predict 5.0 and 5.05 (within 20 × 0.01 of each other):
        // the majority lies 4 below them, yet neither dissents
        let rms = [Some(0.5), Some(0.5), Some(0.5), Some(0.01), Some(0.01)];
        let est = with_pending(&[1.0, 1.0, 1.0, 5.0, 5.05], &rms, 20.0);
        assert!(dissenters(&est).is_empty());
        // apart by more than their limit, each is alone: both dissent
        let est = with_pending(&[1.0, 1.0, 1.0, 5.0, 5.3], &rms, 20.0);
        assert_eq!(dissenters(&est), vec![3, 4]);
        // seconded at one step of the horizon only is not seconded
        let mut est = with_pending(&[1.0, 1.0, 1.0, 5.0, 5.05], &rms, 20.0);
        est.members[4].pending[7] = 9.0;
        assert_eq!(dissenters(&est), vec![3, 4]);
    }

    #[test]
    fn no_consensus_with_fewer_than_three_predictions_or_when_disabled() {
        let est = with_pending(&[1.0, 5.0], &[Some(0.01); 2], 20.0);
        assert!(dissenters(&est).is_empty());
        let est = with_pending(&[1.0, 1.01, 1.02, 5.0], &[Some(0.01); 4], f64::INFINITY);
        assert!(dissenters(&est).is_empty());
        // one candidate that is not pending leaves two: no consensus
        let mut est = with_pending(&[1.0, 1.01, 5.0], &[Some(0.01); 3], 20.0);
        est.members[0].pending_len = 0;
        assert!(dissenters(&est).is_empty());
    }

    #[test]
    fn a_non_positive_consensus_factor_is_refused() {
        for c in [0.0, -1.0, f64::NAN] {
            let config = AutoConfig {
                consensus: c,
                ..AutoConfig::default()
            };
            assert!(config.validate().is_err(), "{c}");
        }
    }
}
