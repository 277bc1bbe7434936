//! `auto`: a validated multiple-model predictor that picks the model, its
//! order and its memory from the data while it runs, and emits only the
//! predictions it can vouch for.
//!
//! # Candidates
//!
//! Every candidate sees every sample and predicts every horizon:
//!
//! | # | candidate | role |
//! |---|---|---|
//! | 0 | RLS, `na = nb = 8`, λ = 0.999 (memory ≈ 1000 samples) | the drive's closed loop, precise once learnt |
//! | 1 | RLS, `na = nb = 4`, λ = 0.99 (memory ≈ 100 samples) | low order, adapts ten times faster |
//! | 2 | hold (the last measured position) | standstill, and the baseline |
//!
//! # Selection by validated prediction error
//!
//! When a window is fitted, the samples of the previous horizon are known, so
//! every candidate's previous prediction is *scored*: its mean squared error
//! `e²` over the horizon updates an exponentially weighted score
//! `S ← (1 − α)·S + α·e²` ([`AutoConfig::memory`] = α). The candidate with
//! the lowest score predicts. This is cross-validation in time: each score is
//! computed on data the candidate had not seen when it predicted.
//!
//! # When nothing is emitted
//!
//! A prediction is *withheld* ([`PredictStatus::Withheld`], a window outcome,
//! not an error; no value, no NaN)
//! unless both hold:
//! * **validated**: the chosen candidate's rms error was within
//!   [`AutoConfig::tolerance`] on each of the last [`AutoConfig::min_scored`]
//!   horizons;
//! * **within experience**: the command's excursion over the horizon,
//!   `x = max |u[k] − u[end−1]|`, does not exceed
//!   `headroom·X + tolerance`, where `X` is the largest excursion of a past
//!   horizon that some candidate predicted within the tolerance.
//!
//! So the first horizons of a new kind of motion (the start of a ramp, a step
//! that saturates the current loop) are not predicted until a candidate has
//! shown that it follows them; afterwards they are. Coverage (the share of
//! samples predicted) is part of every summary.
//!
//! Cost: the two RLS updates, ≈ 0.3 µs per sample on one core.
//!
//! References: L. Ljung, *System Identification*, 2nd ed., §16.4 (model
//! validation) and §11.2 (RLS); R. Murray-Smith, T. A. Johansen, *Multiple
//! Model Approaches to Modelling and Control*, 1997 (model switching).
//!
//! ```
//! use feedid::ident::{engine, AutoConfig, EngineConfig, Signals};
//! let n = 3000;
//! let dt = 2e-4;
//! let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
//! let u: Vec<f64> = t.iter().map(|&t| 1e-4 * (2.0 * std::f64::consts::PI * 20.0 * t).sin()).collect();
//! let mut y = vec![0.0; n];
//! for k in 1..n {
//!     y[k] = 0.9 * y[k - 1] + 0.1 * u[k - 1];
//! }
//! let mut auto = AutoConfig::default().build().unwrap();
//! let cfg = EngineConfig { window: 50, ..EngineConfig::default() };
//! let res = engine::run(&mut auto, &Signals::new(&t, &u, &y, dt, 0.0), &cfg).unwrap();
//! assert!(res.stats.samples > n / 2);
//! assert!(res.stats.max_abs < 5e-6); // never beyond the tolerance
//! assert!(res.stats.rms < 1e-7); // amplitude 1e-4 m
//! ```

use std::ops::Range;

use crate::error::{Error, Result};
use crate::ident::{
    ArxOrders, Estimator, PredictStatus, RlsConfig, RlsEstimator, Samples, Signals, WindowFit,
};
use crate::solve::Termination;

/// Settings of the `auto` method.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AutoConfig {
    /// Largest recent rms prediction error of the chosen candidate for a
    /// prediction to be emitted \[m\]; default 5e-6 (5 µm).
    pub tolerance: f64,
    /// Weight α of the newest horizon in the score, in (0, 1]; default 0.5.
    pub memory: f64,
    /// Consecutive horizons the chosen candidate must have predicted within
    /// the tolerance (rms over each horizon) before its predictions are
    /// emitted; default 2.
    pub min_scored: usize,
    /// Factor on the largest validated command excursion; default 2.
    pub headroom: f64,
    /// The long-memory RLS candidate; default `na = nb = 8`, λ = 0.999,
    /// `p0 = 1e8` (a weak prior: the model is learnt from the data within
    /// a few dozen samples).
    pub long: RlsConfig,
    /// The short-memory RLS candidate; default `na = nb = 4`, λ = 0.99.
    pub short: RlsConfig,
    /// Combine the validated candidates whose score is within this factor of
    /// the best one, weighted by the inverse score; default 1 = the best one
    /// only (on the rig, blending was never better than choosing).
    pub blend: f64,
}

impl Default for AutoConfig {
    fn default() -> Self {
        Self {
            tolerance: 5e-6,
            memory: 0.5,
            min_scored: 2,
            headroom: 2.0,
            blend: 1.0,
            long: RlsConfig {
                p0: 1e8,
                ..RlsConfig::default()
            },
            short: RlsConfig {
                orders: ArxOrders::new(4, 4, 1),
                lambda: 0.99,
                ..RlsConfig::default()
            },
        }
    }
}

impl AutoConfig {
    /// Validate and build the estimator.
    pub fn build(self) -> Result<AutoEstimator> {
        self.validate()?;
        let long = self.long.build()?;
        let short = self.short.build()?;
        let long_names = long.coefficient_names().len();
        let short_names = short.coefficient_names().len();
        Ok(AutoEstimator {
            config: self,
            slots: [
                Slot::new(Candidate::Rls(Box::new(long)), long_names),
                Slot::new(Candidate::Rls(Box::new(short)), short_names),
                Slot::new(Candidate::Hold, 0),
            ],
            selected: None,
            seen_excursion: 0.0,
            pending_excursion: 0.0,
        })
    }

    /// Check the settings (tolerance, memory, blend, headroom and both RLS candidates).
    pub fn validate(&self) -> Result<()> {
        if !(self.tolerance.is_finite() && self.tolerance > 0.0) {
            return Err(Error::InvalidParameter {
                name: "tolerance",
                value: self.tolerance,
                reason: "must be finite and > 0",
            });
        }
        if !(self.memory > 0.0 && self.memory <= 1.0) {
            return Err(Error::InvalidParameter {
                name: "memory",
                value: self.memory,
                reason: "must be in (0, 1]",
            });
        }
        if !(self.blend.is_finite() && self.blend >= 1.0) {
            return Err(Error::InvalidParameter {
                name: "blend",
                value: self.blend,
                reason: "must be finite and >= 1",
            });
        }
        if !(self.headroom.is_finite() && self.headroom >= 1.0) {
            return Err(Error::InvalidParameter {
                name: "headroom",
                value: self.headroom,
                reason: "must be finite and >= 1",
            });
        }
        self.long.validate()?;
        self.short.validate()
    }
}

/// A new candidate replaces the previous choice only when its score is
/// below this fraction of the previous one's.
const HYSTERESIS: f64 = 0.8;

/// Names of the candidates, in the order of the `candidate` coefficient.
pub const AUTO_CANDIDATES: [&str; 3] = ["rls8", "rls4", "hold"];

#[derive(Debug, Clone)]
enum Candidate {
    Rls(Box<RlsEstimator>),
    Hold,
}

#[derive(Debug, Clone)]
struct Slot {
    candidate: Candidate,
    coef: Vec<f64>,
    /// The last prediction, not yet scored.
    pending: Vec<f64>,
    pending_start: usize,
    pending_len: usize,
    /// Exponentially weighted mean squared error \[m²\].
    score: f64,
    scored: usize,
    /// Consecutive scored horizons with an rms error within the tolerance.
    streak: usize,
    /// Whether the last fit succeeded.
    ok: bool,
}

impl Slot {
    fn new(candidate: Candidate, n_coef: usize) -> Self {
        Self {
            candidate,
            coef: vec![0.0; n_coef],
            pending: Vec::new(),
            pending_start: 0,
            pending_len: 0,
            score: 0.0,
            scored: 0,
            streak: 0,
            ok: false,
        }
    }

    fn reset(&mut self) {
        if let Candidate::Rls(r) = &mut self.candidate {
            r.reset();
        }
        self.pending_len = 0;
        self.score = 0.0;
        self.scored = 0;
        self.streak = 0;
        self.ok = false;
    }
}

/// The `auto` estimator (method name `"auto"`); see the module doc.
#[derive(Debug, Clone)]
pub struct AutoEstimator {
    config: AutoConfig,
    slots: [Slot; 3],
    selected: Option<usize>,
    /// Largest command excursion of a horizon predicted within the tolerance \[m\].
    seen_excursion: f64,
    /// Command excursion of the pending horizon \[m\].
    pending_excursion: f64,
}

impl AutoEstimator {
    /// The settings.
    pub fn config(&self) -> &AutoConfig {
        &self.config
    }

    /// Index into [`AUTO_CANDIDATES`] of the candidate chosen at the last fit.
    pub fn selected(&self) -> Option<usize> {
        self.selected
    }

    /// Score every pending prediction on the samples now known (`< end`).
    fn score_pending(&mut self, signals: &Signals<'_>, end: usize) {
        let alpha = self.config.memory;
        let tol2 = self.config.tolerance * self.config.tolerance;
        let mut best = f64::INFINITY;
        for slot in &mut self.slots {
            if slot.pending_len == 0 {
                continue;
            }
            let from = slot.pending_start.max(signals.offset());
            let to = (slot.pending_start + slot.pending_len).min(end);
            if let (true, Ok(w)) = (to > from, signals.window(from..to, 0, "auto scoring")) {
                let y = w.position;
                let p = &slot.pending[from - slot.pending_start..to - slot.pending_start];
                let mse = y.iter().zip(p).map(|(a, b)| (a - b) * (a - b)).sum::<f64>()
                    / (to - from) as f64;
                if mse.is_finite() {
                    slot.score = if slot.scored == 0 {
                        mse
                    } else {
                        (1.0 - alpha) * slot.score + alpha * mse
                    };
                    slot.scored += 1;
                    slot.streak = if mse <= tol2 { slot.streak + 1 } else { 0 };
                    best = best.min(mse);
                }
            }
            slot.pending_len = 0;
        }
        if best <= tol2 {
            self.seen_excursion = self.seen_excursion.max(self.pending_excursion);
        }
    }
}

/// The window's samples: non-empty and inside the available data.
fn window_samples<'a>(signals: &Signals<'a>, window: &Range<usize>) -> Result<Samples<'a>> {
    if window.is_empty() {
        return Err(Error::TooFewSamples {
            what: "auto window",
            needed: window.end.max(signals.offset() + 1),
            actual: signals.end(),
        });
    }
    signals.window(window.clone(), 0, "auto window")
}

impl Estimator for AutoEstimator {
    fn name(&self) -> &'static str {
        "auto"
    }

    /// `candidate` (index into [`AUTO_CANDIDATES`]), `expected_error_m` (its
    /// recent rms 2 ms-ahead error), then the long RLS candidate's coefficients.
    fn coefficient_names(&self) -> Vec<String> {
        let mut names = vec!["candidate".to_string(), "expected_error_m".to_string()];
        if let Candidate::Rls(r) = &self.slots[0].candidate {
            names.extend(r.coefficient_names());
        }
        names
    }

    fn warm_up(&self) -> usize {
        self.slots
            .iter()
            .map(|s| match &s.candidate {
                Candidate::Rls(r) => r.warm_up(),
                Candidate::Hold => 0,
            })
            .max()
            .unwrap_or(0)
    }

    fn reset(&mut self) {
        for s in &mut self.slots {
            s.reset();
        }
        self.selected = None;
        self.seen_excursion = 0.0;
        self.pending_excursion = 0.0;
    }

    fn fit(
        &mut self,
        signals: &Signals<'_>,
        window: Range<usize>,
        coef: &mut [f64],
    ) -> Result<WindowFit> {
        window_samples(signals, &window)?;
        self.score_pending(signals, window.end);
        let mut residual = [0.0; 3];
        for (i, slot) in self.slots.iter_mut().enumerate() {
            slot.ok = match &mut slot.candidate {
                Candidate::Rls(r) => match r.fit(signals, window.clone(), &mut slot.coef) {
                    Ok(f) => {
                        residual[i] = f.residual_rms;
                        true
                    }
                    Err(_) => false,
                },
                Candidate::Hold => true,
            };
        }
        // lowest score among the scored candidates; else the first usable one
        let previous = self.selected;
        let mut choice: Option<usize> = None;
        for (i, slot) in self.slots.iter().enumerate() {
            if !slot.ok {
                continue;
            }
            choice = match choice {
                None => Some(i),
                Some(c) => {
                    let sc = &self.slots[c];
                    let better = match (slot.scored > 0, sc.scored > 0) {
                        (true, false) => true,
                        (true, true) => {
                            // keep the previous choice unless clearly beaten
                            let keep =
                                |j: usize| if Some(j) == previous { HYSTERESIS } else { 1.0 };
                            slot.score * keep(i) < sc.score * keep(c)
                        }
                        _ => false,
                    };
                    Some(if better { i } else { c })
                }
            };
        }
        self.selected = choice;
        let Some(c) = choice else {
            return Err(Error::Singular {
                context: "auto (no candidate could be fitted)",
            });
        };
        if let Some(x) = coef.get_mut(0) {
            *x = c as f64;
        }
        if let Some(x) = coef.get_mut(1) {
            let s = &self.slots[c];
            *x = if s.scored > 0 { s.score.sqrt() } else { 0.0 };
        }
        if let Some(rest) = coef.get_mut(2..) {
            let src = &self.slots[0].coef;
            let n = rest.len().min(src.len());
            rest[..n].copy_from_slice(&src[..n]);
        }
        Ok(WindowFit::identified(residual[c], 0, Termination::Exact))
    }

    fn predict(
        &mut self,
        signals: &Signals<'_>,
        window: Range<usize>,
        horizon: Range<usize>,
        out: &mut [f64],
    ) -> Result<PredictStatus> {
        let w = window_samples(signals, &window)?;
        let h = out.len();
        let (last, u_last) = (
            w.position[w.position.len() - 1],
            w.command[w.command.len() - 1],
        );
        for slot in &mut self.slots {
            slot.pending_len = 0;
            if !slot.ok {
                continue;
            }
            if slot.pending.len() < h {
                slot.pending.resize(h, 0.0);
            }
            let buf = &mut slot.pending[..h];
            let good = match &mut slot.candidate {
                Candidate::Rls(r) => r
                    .predict(signals, window.clone(), horizon.clone(), buf)
                    .is_ok(),
                Candidate::Hold => {
                    buf.fill(last);
                    true
                }
            };
            if good && buf.iter().all(|v| v.is_finite()) {
                slot.pending_start = horizon.start;
                slot.pending_len = h;
            }
        }
        // command excursion over the horizon
        let hu = horizon.end.min(signals.end());
        let excursion = match signals.window(horizon.start..hu, 0, "auto horizon") {
            Ok(hz) => hz
                .command
                .iter()
                .map(|u| (u - u_last).abs())
                .fold(0.0, f64::max),
            Err(_) => 0.0,
        };
        self.pending_excursion = if excursion.is_finite() {
            excursion
        } else {
            f64::INFINITY
        };

        let Some(c) = self.selected else {
            return Ok(PredictStatus::Withheld {
                reason: "no candidate model",
            });
        };
        let slot = &self.slots[c];
        if slot.pending_len != h {
            return Ok(PredictStatus::Withheld {
                reason: "the chosen model could not predict",
            });
        }
        let tol = self.config.tolerance;
        if slot.streak < self.config.min_scored {
            return Ok(PredictStatus::Withheld {
                reason: "not yet validated",
            });
        }
        let within = self.pending_excursion <= self.config.headroom * self.seen_excursion + tol;
        if !within {
            return Ok(PredictStatus::Withheld {
                reason: "the command leaves the validated range",
            });
        }
        let best = slot.score;
        let limit = self.config.blend * best;
        let mut wsum = 0.0;
        out.fill(0.0);
        for s in &self.slots {
            if s.pending_len == h && s.scored >= self.config.min_scored && s.score <= limit {
                let w = 1.0 / s.score.max(1e-30);
                wsum += w;
                for (o, p) in out.iter_mut().zip(&s.pending[..h]) {
                    *o += w * p;
                }
            }
        }
        if wsum > 0.0 && wsum.is_finite() {
            for o in out.iter_mut() {
                *o /= wsum;
            }
        } else {
            out.copy_from_slice(&slot.pending[..h]);
        }
        Ok(PredictStatus::Predicted)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ident::engine::{run, EngineConfig};
    use crate::ident::WindowOutcome;

    fn first_order(n: usize, u: impl Fn(usize) -> f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let u: Vec<f64> = (0..n).map(u).collect();
        let mut y = vec![0.0; n];
        for k in 1..n {
            y[k] = 0.8 * y[k - 1] + 0.2 * u[k - 1];
        }
        (t, u, y)
    }

    #[test]
    fn auto_is_as_good_as_its_best_candidate_on_an_exact_system() {
        // a rich input (10 sines) into a known first-order ARX system
        let (t, u, y) = first_order(2000, |k| {
            (1..=10)
                .map(|m| 1e-5 * ((k as f64) * 0.037 * m as f64 + m as f64).sin())
                .sum()
        });
        let s = Signals::new(&t, &u, &y, 1e-3, 0.0);
        let cfg = EngineConfig {
            window: 50,
            ..EngineConfig::default()
        };
        let mut est = AutoConfig::default().build().unwrap();
        let r = run(&mut est, &s, &cfg).unwrap();
        assert!(r.stats.samples > 1800, "{}", r.stats.samples);
        // each candidate alone, scored on the samples auto predicted
        let best = [AutoConfig::default().long, AutoConfig::default().short]
            .into_iter()
            .map(|c| {
                let mut e = c.build().unwrap();
                let rc = run(&mut e, &s, &cfg).unwrap();
                let (mut se, mut m) = (0.0, 0);
                for (k, yk) in y.iter().enumerate() {
                    if let (Some(_), Some(p)) = (r.prediction(k), rc.prediction(k)) {
                        se += (p - yk) * (p - yk);
                        m += 1;
                    }
                }
                (se / m as f64).sqrt()
            })
            .fold(f64::INFINITY, f64::min);
        assert!(r.stats.rms <= 2.0 * best, "{} vs {best}", r.stats.rms);
        // amplitude ≈ 3e-5 m: relative error below 1e-3
        assert!(r.stats.rms < 3e-8, "{}", r.stats.rms);
    }

    #[test]
    fn step_into_the_unknown_is_withheld_not_mispredicted() {
        // at rest, then a 1 mm command step: the horizon containing the step
        // has never been validated, so it must not be predicted
        let (t, u, y) = first_order(600, |k| if k >= 300 { 1e-3 } else { 0.0 });
        let mut est = AutoConfig::default().build().unwrap();
        let cfg = EngineConfig {
            window: 50,
            ..EngineConfig::default()
        };
        let r = run(&mut est, &Signals::new(&t, &u, &y, 1e-3, 0.0), &cfg).unwrap();
        let withheld = r
            .windows
            .iter()
            .filter(|w| w.outcome == WindowOutcome::Withheld)
            .count();
        assert!(withheld > 0);
        // the samples right after the step (300..310) are not predicted
        assert!((300..310).all(|k| r.prediction(k).is_none()));
        // every emitted prediction is within the tolerance
        assert!(r.stats.max_abs <= 5e-6, "{}", r.stats.max_abs);
        // and rest before the step is predicted (hold is exact at rest)
        assert!(r.prediction(200).is_some());
    }

    #[test]
    fn selection_prefers_the_candidate_with_the_lower_score() {
        // a pure constant: all candidates exact; then a sine: hold is poor
        let (t, u, y) = first_order(3000, |k| 2e-4 * ((k as f64) * 0.05).sin());
        let mut est = AutoConfig::default().build().unwrap();
        let cfg = EngineConfig {
            window: 50,
            ..EngineConfig::default()
        };
        let r = run(&mut est, &Signals::new(&t, &u, &y, 1e-3, 0.0), &cfg).unwrap();
        let last = r.windows.len() - 1;
        let cand = r.window_coefficients(last)[0];
        assert!(cand < 2.0, "hold chosen on a moving signal");
    }

    #[test]
    fn invalid_settings_are_rejected_by_name() {
        for (cfg, name) in [
            (
                AutoConfig {
                    tolerance: 0.0,
                    ..AutoConfig::default()
                },
                "tolerance",
            ),
            (
                AutoConfig {
                    memory: 1.5,
                    ..AutoConfig::default()
                },
                "memory",
            ),
            (
                AutoConfig {
                    headroom: 0.5,
                    ..AutoConfig::default()
                },
                "headroom",
            ),
        ] {
            let e = cfg.build().unwrap_err().to_string();
            assert!(e.contains(name), "{e}");
        }
    }

    #[test]
    fn predictions_are_always_finite_on_noise_and_standstill() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let n = 2000;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let u: Vec<f64> = (0..n).map(|_| rng.random::<f64>() * 1e-6).collect();
        let y: Vec<f64> = (0..n).map(|_| rng.random::<f64>() * 1e-6).collect();
        let mut est = AutoConfig::default().build().unwrap();
        let r = run(
            &mut est,
            &Signals::new(&t, &u, &y, 1e-3, 0.0),
            &EngineConfig::default(),
        )
        .unwrap();
        assert!(r.predicted.iter().all(|v| v.is_finite()));
        let zero = vec![0.0; n];
        let r = run(
            &mut est,
            &Signals::new(&t, &zero, &zero, 1e-3, 0.0),
            &EngineConfig::default(),
        )
        .unwrap();
        assert!(r.predicted.iter().all(|v| v.is_finite()));
    }
}
