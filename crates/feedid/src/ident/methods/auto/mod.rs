//! `auto`: a multiple-model predictor that picks the model, its order and
//! its memory from the data while it runs, and always predicts.
//!
//! # Candidates
//!
//! Every candidate ([`Candidate`], default [`AutoConfig::default_candidates`])
//! but the command at rest is a *unit-gain ARX model written in increments
//! from the last measured position* (module `model`): with `A(1) = B(1)` (a position servo follows its
//! set-point with unit gain),
//!
//! ```text
//! y[k] − y[k−1] = −Σ_{i=2..na} a_i·(y[k−i] − y[k−1]) + Σ_{j=0..nb−1} b_j·(u[k−nk−j] − y[k−1]),
//! ```
//!
//! a regression whose regressors and target are all differences of
//! positions. An offset of the recording cancels exactly and a change of
//! unit scales every row alike, so the estimates `θ` do not depend on
//! units or offsets, and nothing in `auto` is an absolute length: the
//! recursive candidates scale their coordinates by the largest regressor of
//! their first informative window, the windowed ones use a ridge relative
//! to `‖Ψ‖²_F/n`, the plausibility check below is relative to the motion the
//! recording has shown. `θ = 0` is the hold predictor. The defaults are
//!
//! - `ls 2,2,0 W=100` and `ls 2,2,0+c W=100`: least squares over the last
//!   100 samples, refitted at every window (short memory, quick after a
//!   change), without and with a constant term, no ridge (a ridge of 1e-6
//!   cost up to 11× on recordings sampled at 7–18 kHz, where the
//!   regressors of 100 samples are nearly collinear);
//! - `rls 3,3,0+c λ=0.99`: recursive least squares (memory ≈ 100 samples)
//!   of the model plus a constant increment `c` (a constant disturbance:
//!   friction during a one-directional move, gravity, a following-error
//!   bias; see module `model`);
//! - `rls 3,3,0 λ=0.995`, `rls 4,4,0 λ=0.999`, `rls 6,6,0 λ=0.999`,
//!   `rls 8,8,0 λ=0.9995`: exponentially weighted recursive least squares
//!   (memories of 200 to 2000 samples, low to high orders);
//! - `command at rest` ([`Candidate::CommandAtRest`]): the command itself,
//!   eligible only for a horizon whose command is still over the window and
//!   the horizon (regime *still* below), and never part of the candidates'
//!   median. An axis that rests on its set-point (feed-forward, a stiff
//!   loop) is predicted best by the command, and every estimated model
//!   there only adds the noise of its estimate (`1 + p/N` in mean square);
//!   where the axis moves, the command's error is the following error,
//!   which grows through a move, so its score at a ramp's start (when the
//!   axis has barely fallen behind) would wrongly recommend it for the
//!   ramp's end (member 182 of the zoo: 31 % worse), and in the median it
//!   pulls the first prediction towards a set-point the axis lags (members
//!   84, 92 and 168: 5–9 % worse).
//!
//! All models use `nk = 0`, the command at the predicted instant: the command is a
//! planned trajectory, known ahead, and at low sampling rates it is what
//! matters. They were chosen on the drive zoo ([`crate::zoo`], example
//! `zoo_sweep`), not on one recording. `--order` sets the orders of the
//! long-memory recursive candidate (the one whose coefficients are
//! reported, [`AutoConfig::reported`]); `--ridge` the ridge of the windowed
//! ones.
//!
//! # Choice
//!
//! Every candidate learns from every sample and predicts every horizon
//! `H` samples ahead, running its equation forward from the last measured
//! position on the known command. Once a horizon is measured, each
//! candidate's prediction is scored by its mean squared error `e²` over
//! the horizon, and its score in the horizon's *regime* of the command —
//! still, constant speed, or changing speed ([`AutoEstimator::regime`]) — becomes
//! `s ← (1 − α)·s + α·e²` (α = [`AutoConfig::memory`], default 0.1). At
//! each window the ready candidate with the lowest score in the coming
//! horizon's regime predicts (an unscored regime borrows the candidate's
//! first scored one). Scores are compared with one another only, so they
//! carry no threshold and no unit.
//!
//! The first window is not chosen blind: before its prediction every
//! candidate is backtested once, out of sample — a second instance of it
//! learns the window without its last `H` samples and predicts them — and
//! so are holding the last position and the pointwise *median* of the
//! candidates' predictions and holding. The first horizon is predicted by
//! whichever of holding, the median and the first choice (the settings'
//! first ready candidate) backtested best, ties going to holding, then to
//! the median. Models learnt from a few dozen samples often predict wildly
//! and a single backtested horizon is a poor guide to which of them will
//! (choosing the best-backtested candidate instead made three recordings of
//! the zoo up to 2.5× worse); the median of all of them is robust to a few
//! wild ones. Only when the two best-backtested candidates *both* did
//! better than holding, the median and the first choice by a factor of 100
//! in mean square does the best of them predict the first horizon: two
//! models that found the dynamics of the first move are evidence, one is
//! not (a first-order axis learnt exactly by the high orders from its first
//! move, member 134 of the zoo: 50× better over the recording). The
//! backtest scores decide nothing after the first horizon.
//!
//! A candidate whose prediction departs from the *consensus* does not
//! predict that horizon; the best-scored candidate that agrees does. It
//! departs when, at some step of the horizon, more than half of the
//! candidates' predictions lie on one side of it by more than
//! [`AutoConfig::consensus`] (default 20) times its own recent rms error —
//! with an odd count of predictions: its distance from their median exceeds
//! that (fewer than three predictions make no consensus) — unless another
//! candidate's prediction stays within that distance of it at every step
//! (it is *seconded*). A model well scored on a smooth motion can be thrown
//! off by a motion it has not seen (a jerk of the command excites directions
//! its nearly collinear regressors never determined): its prediction then
//! leaves the others by far more than it ever erred, and alone. But when a
//! few candidates have found the exact model and the rest have not (a
//! first-order axis learnt by the ARX(4,4), (6,6) and (8,8) candidates to
//! 1e-9 of the move while the low orders err by microns), the precise ones
//! are outvoted by the imprecise majority; two models that agree to within
//! one's own small error are evidence the majority lacks. The factor is
//! relative to the candidate's own errors, so it carries no unit. When
//! *every* plausible candidate departs (each far from the others for its
//! own small error — at the stop of a long, smooth ramp sampled at 16–20 kHz,
//! where every model has erred by nanometres and each extrapolates the
//! unseen stop its own way), none is trusted alone and the pointwise median
//! of their predictions and holding predicts, as at the first horizon
//! (holding instead, while the axis still moved at 8 µm per sample, made
//! two recordings of the zoo 8× and 125× worse).
//!
//! A candidate's prediction is *implausible* when it leaves the last
//! measured position by more than [`AutoConfig::plausibility`] times the
//! largest motion of the position over `H + 1` samples so far: the
//! candidate is then restarted (a wound-up or noise-fitted model learns
//! again) and the best-scored plausible candidate predicts instead. If none
//! is plausible, `auto` holds the last position. So every window after the
//! first gets a prediction: `auto` never withholds.
//!
//! How far to trust a prediction is the engine's prediction interval
//! ([`crate::ident::engine::Guard`]): the quantile of the method's own
//! recent scored errors at each step ahead. Isolated wild samples
//! (glitches) are rejected there before `auto` or any other method fits
//! them.

mod candidate;
mod config;
mod estimator;
mod model;

pub use candidate::Candidate;
pub use config::AutoConfig;
pub use estimator::AutoEstimator;
