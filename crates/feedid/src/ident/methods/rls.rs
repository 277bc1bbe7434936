//! Recursive least squares (RLS) on the ARX regressor, with exponential
//! forgetting or an exact finite window.
//!
//! Model and regressor as in [`crate::ident::ArxEstimator`]:
//! `ỹ[k] = ψ_kᵀθ + e[k]`, `ψ_k = [−ỹ[k−1] … −ỹ[k−na], ũ[k−nk] … ũ[k−nk−nb+1]]`,
//! with deviation coordinates `ỹ = (y − r₀)/s`, `ũ = (u − r₀)/s` (a frame
//! `r₀` and the scale `s` = [`RlsConfig::scale`], so that `P` is well scaled).
//!
//! # Exponential forgetting (default)
//!
//! ```text
//! g = P·ψ,   K = g/(λ + ψᵀg),   θ ← θ + K·(ỹ − ψᵀθ),   P ← (P − K·gᵀ)/λ
//! ```
//!
//! `P` is kept exactly symmetric by writing the downdate entry by entry as
//! `Pᵢⱼ ← (Pᵢⱼ − (gᵢ·gⱼ)/(λ + ψᵀg))/λ` (the product `gᵢ·gⱼ` is the same
//! for `Pⱼᵢ`, so `Pψ` can be accumulated from contiguous rows; no square
//! root on the critical path). The dot products are summed in four lanes
//! (short dependency chains). Memory
//! `≈ 1/(1 − λ)` samples. Two safeguards against covariance wind-up:
//! * **Excitation gate** (off by default, [`RlsConfig::min_excitation`] = 0): a sample updates `θ` and `P` (and is forgotten) only
//!   when the command moved over the regressor span, i.e. the range of
//!   `u[k−nk−nb] … u[k−nk]` exceeds [`RlsConfig::min_excitation`]. At
//!   standstill nothing is updated, so `P` cannot grow like `λ⁻ᵏ`.
//! * **Trace bound:** when `tr P` exceeds [`RlsConfig::max_trace`] (default
//!   the initial trace `n·P₀`), `P` is scaled back to it.
//!
//! # Exact finite window ([`RlsConfig::window`])
//!
//! With `window = Some(W)` and no forgetting, each sample `k` is added
//! (the update above with λ = 1) and sample `k − W` removed:
//!
//! ```text
//! g = P·ψ,   d = 1 − ψᵀg,   θ ← θ − g·(ỹ − ψᵀθ)/d,   P ← P + g·gᵀ/d
//! ```
//!
//! so `θ` is the least-squares fit of the last `W` (gated) samples with the
//! prior `θᵀP₀⁻¹θ` (tiny for large `P₀`). A failing removal (`d ≤ 0`
//! numerically) rebuilds `θ, P` from the last `W` samples.
//!
//! # Frame
//!
//! The frame `r₀` is the measured position at the first processed sample and
//! moves to the current position when that leaves `r₀ ± frame_span`
//! ([`RlsConfig::frame_span`]): the model has no offset term, so `θ` is kept
//! (exact for a unit-DC-gain system, as a position servo; the windowed
//! variant is rebuilt in the new frame, exactly).
//!
//! # Processing and prediction
//!
//! `fit` processes every sample from its internal cursor up to
//! `window.end` (the window range only tells where the data ends; hop and
//! window length only decide when predictions are made); `reset` rewinds.
//! Prediction is the k-step-ahead prediction of the ARX model from the
//! measured past, in deviations from the last measured position. A model
//! with a pole on or outside the unit circle (Schur–Cohn test) is never used
//! for a prediction: the last stable estimate predicts instead, and a
//! window gives none (`predict` fails with [`Error::InvalidModel`]) only
//! while there has been no stable estimate yet.
//!
//! References: L. Ljung, *System Identification*, 2nd ed., §11.2; S. Haykin,
//! *Adaptive Filter Theory*, ch. 10; `docs/METHODS.md` §6.
//!
//! ```
//! use feedid::ident::{engine, ArxOrders, EngineConfig, GuardConfig, RlsConfig, Signals};
//! let n = 600;
//! let dt = 1e-3;
//! let u: Vec<f64> = (0..n).map(|k| 1e-3 * (0.05 * k as f64).sin()).collect();
//! let mut y = vec![0.0; n];
//! for k in 1..n {
//!     y[k] = 0.6 * y[k - 1] + 0.4 * u[k - 1];
//! }
//! let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
//! let mut rls = RlsConfig { orders: ArxOrders::new(1, 1, 1), p0: 1e10, ..RlsConfig::default() }
//!     .build()
//!     .unwrap();
//! // the predictions as the method made them: the runaway guard off (early in
//! // a recording the motion seen so far may be less than the next horizon's)
//! let guard = GuardConfig { runaway: None, ..GuardConfig::default() };
//! let s = Signals::new(&t, &u, &y, dt, 0.0);
//! let res = engine::run_with(&mut rls, &s, &EngineConfig::default(), &guard, None).unwrap();
//! assert!(res.stats.rms < 1e-8, "{}", res.stats.rms); // amplitude 1e-3
//! ```

// Negated comparisons are deliberate (they reject NaN); index loops mirror the
// matrix formulas.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]

use std::ops::Range;

use crate::error::{Error, Result};
use crate::ident::engine::{rate_changed, Estimator, PredictStatus, Signals, WindowFit};
use crate::ident::methods::regressor::{poles_inside, predict_horizon, ArxOrders, ORDER_OPTION};
use crate::ident::option::{
    MethodOption, MethodSettings, OptionKind, OptionRange, OptionSpec, OptionValue,
};
use crate::solve::Termination;

/// Configuration of the RLS estimator (defaults chosen on the drive zoo,
/// [`crate::zoo`]).
///
/// With these defaults the 10-sample-ahead rms error is 0.44 µm on EMPS
/// (1 kHz) and 0.35 … 0.80 µm 2 ms ahead on the rig's ramp, S-curve, chirp,
/// PRBS and multisine (`tests/arx_rls_targets.rs`, `--nocapture` prints
/// them). On slow sweeps of nearly noise-free axes the ARX(8,8)
/// coefficients are undetermined in the directions the motion does not
/// excite and can wind up there (`docs/RESULTS.md`, the zoo benchmark read in mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RlsConfig {
    /// Model orders; default `na = 8, nb = 8, nk = 0`.
    pub orders: ArxOrders,
    /// Forgetting factor λ ∈ (0, 1]; default 0.999 (memory ≈ 1000 samples,
    /// 0.2 s at 5 kHz). Ignored (λ = 1) with [`RlsConfig::window`].
    pub lambda: f64,
    /// Exact finite window of this many samples instead of forgetting; default `None`.
    pub window: Option<usize>,
    /// Initial covariance `P₀ = p0·I` (scaled coordinates); default 1e6.
    pub p0: f64,
    /// Bound on `tr P`; default `None` = the initial trace `n·p0`.
    pub max_trace: Option<f64>,
    /// Minimum command range over the regressor span for an update,
    /// relative to the scale `s`; default 0: the gate is off (every sample
    /// updates); a positive value, e.g. 1e-6, turns it on.
    pub min_excitation: f64,
    /// Scale `s` of the deviation coordinates \[m\]; default `None`: from
    /// the data, the larger of the ranges of command and position over the
    /// first window in which either moves (so that units and offsets do not
    /// change the estimates).
    pub scale: Option<f64>,
    /// Distance from the frame `r₀` that moves the frame, relative to the
    /// scale `s`; default 1 (`∞`: the frame never moves).
    pub frame_span: f64,
    /// Poles must lie strictly inside this radius for a prediction; default 1.0.
    pub max_pole_radius: f64,
}

impl Default for RlsConfig {
    fn default() -> Self {
        Self {
            orders: ArxOrders::new(8, 8, 0),
            lambda: 0.999,
            window: None,
            p0: 1e6,
            max_trace: None,
            min_excitation: 0.0,
            scale: None,
            frame_span: 1.0,
            max_pole_radius: 1.0,
        }
    }
}

/// Option `lambda` of `rls` ([`RlsConfig::lambda`]); `lambda_` in Python.
const LAMBDA_OPTION: OptionSpec = OptionSpec {
    key: "lambda",
    python: Some("lambda_"),
    value_name: "LAMBDA",
    kind: OptionKind::Float,
    range: Some(OptionRange {
        min: 0.0,
        min_open: true,
        max: 1.0,
        max_open: false,
    }),
    unit: None,
    help: "forgetting factor λ (memory ≈ 1/(1−λ) samples)",
    requires: None,
};

impl MethodSettings for RlsConfig {
    fn options(&self) -> &'static [MethodOption] {
        const OPTIONS: &[MethodOption] = &[
            MethodOption::new(&ORDER_OPTION),
            MethodOption::new(&LAMBDA_OPTION),
        ];
        OPTIONS
    }

    fn option(&self, key: &str) -> Option<OptionValue> {
        match key {
            "order" => Some(OptionValue::Orders(self.orders)),
            "lambda" => Some(OptionValue::Float(self.lambda)),
            _ => None,
        }
    }

    fn set_option(&mut self, key: &str, value: &OptionValue) -> Result<()> {
        match (key, value) {
            ("order", OptionValue::Orders(o)) => {
                o.validate()?;
                self.orders = *o;
            }
            ("lambda", OptionValue::Float(l)) => self.lambda = *l,
            _ => {
                return Err(Error::UnknownOption {
                    key: key.to_string(),
                    known: "order, lambda".to_string(),
                })
            }
        }
        Ok(())
    }
}

impl RlsConfig {
    /// Validate and build the estimator.
    pub fn build(self) -> Result<RlsEstimator> {
        self.validate()?;
        Ok(RlsEstimator::new(self))
    }

    /// Check the settings (orders, λ ∈ (0, 1], positive scales, a window of at least 1).
    pub fn validate(&self) -> Result<()> {
        self.orders.validate()?;
        if !(self.lambda > 0.0 && self.lambda <= 1.0) {
            return Err(Error::InvalidParameter {
                name: "lambda",
                value: self.lambda,
                reason: "must be in (0, 1]",
            });
        }
        for (name, v) in [("p0", self.p0), ("scale", self.scale.unwrap_or(1.0))] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::InvalidParameter {
                    name,
                    value: v,
                    reason: "must be finite and > 0",
                });
            }
        }
        if !(self.frame_span > 0.0) {
            return Err(Error::InvalidParameter {
                name: "frame_span",
                value: self.frame_span,
                reason: "must be > 0 (∞: the frame never moves)",
            });
        }
        if !(self.min_excitation >= 0.0 && self.min_excitation.is_finite()) {
            return Err(Error::InvalidParameter {
                name: "min_excitation",
                value: self.min_excitation,
                reason: "must be >= 0",
            });
        }
        if let Some(t) = self.max_trace {
            if !(t > 0.0) {
                return Err(Error::InvalidParameter {
                    name: "max_trace",
                    value: t,
                    reason: "must be > 0",
                });
            }
        }
        if self.window == Some(0) {
            return Err(Error::InvalidParameter {
                name: "window",
                value: 0.0,
                reason: "must be at least 1 sample",
            });
        }
        Ok(())
    }
}

/// Recursive least-squares estimator (method name `"rls"`); see the module doc.
#[derive(Debug, Clone)]
pub struct RlsEstimator {
    config: RlsConfig,
    n: usize,
    theta: Vec<f64>,
    /// Row-major `n×n`.
    p: Vec<f64>,
    psi: Vec<f64>,
    g: Vec<f64>,
    past: Vec<f64>,
    /// Scratch of the stability test (`na + 1`).
    schur: Vec<f64>,
    r0: f64,
    framed: bool,
    /// The last estimate whose poles passed the check (empty: none yet).
    stable: Vec<f64>,
    /// The scale `s` in use (0 until the data have moved).
    s: f64,
    cursor: Option<usize>,
    /// Absolute index of the first processed sample since the reset.
    start: Option<usize>,
    /// Sample interval the model was learnt at \[s\] (0 before the first fit).
    dt: f64,
    updates: usize,
    max_trace: f64,
    /// Whether the CPU has AVX2 (selects the vectorised update).
    avx: bool,
}

impl RlsEstimator {
    fn new(config: RlsConfig) -> Self {
        let n = config.orders.n_params();
        let mut s = Self {
            config,
            n,
            theta: vec![0.0; n],
            p: vec![0.0; n * n],
            psi: vec![0.0; n],
            g: vec![0.0; n],
            past: Vec::new(),
            schur: vec![0.0; n + 1],
            r0: 0.0,
            framed: false,
            stable: Vec::with_capacity(n),
            s: 0.0,
            cursor: None,
            start: None,
            dt: 0.0,
            updates: 0,
            max_trace: config.max_trace.unwrap_or(n as f64 * config.p0),
            avx: crate::solve::rows::avx2(),
        };
        s.reset();
        s
    }

    /// The configuration.
    pub fn config(&self) -> &RlsConfig {
        &self.config
    }

    /// Current coefficients `[a…, b…]`.
    pub fn theta(&self) -> &[f64] {
        &self.theta
    }

    /// Number of samples that updated the estimate since the last reset.
    pub fn updates(&self) -> usize {
        self.updates
    }

    /// Current covariance matrix `P` (row-major `n×n`, scaled coordinates).
    pub fn covariance(&self) -> &[f64] {
        &self.p
    }

    fn reset_covariance(&mut self) {
        let n = self.n;
        self.theta.fill(0.0);
        self.p.fill(0.0);
        for i in 0..n {
            self.p[i * n + i] = self.config.p0;
        }
    }

    /// Whether sample `k` (local index) is exciting (command moved over the regressor span).
    fn exciting(&self, u: &[f64], k: usize) -> bool {
        let o = &self.config.orders;
        let hi = k - o.nk;
        let lo = hi.saturating_sub(o.nb);
        let (mut mn, mut mx) = (u[hi], u[hi]);
        for &v in &u[lo..hi] {
            mn = mn.min(v);
            mx = mx.max(v);
        }
        mx - mn > self.config.min_excitation * self.s || self.config.min_excitation == 0.0
    }

    /// Load the scaled regressor of sample `k` (local) into `psi`; returns the target.
    ///
    /// Same values as `arx::regressor` followed by the scaling, without bounds
    /// checks per element.
    fn load(&mut self, y: &[f64], u: &[f64], k: usize) -> f64 {
        let o = &self.config.orders;
        let (na, nb, nk) = (o.na, o.nb, o.nk);
        let r = self.r0;
        let s = 1.0 / self.s;
        let (pa, pb) = self.psi.split_at_mut(na);
        for (p, &v) in pa.iter_mut().zip(y[k - na..k].iter().rev()) {
            *p = -(v - r) * s;
        }
        let hi = k + 1 - nk;
        for (p, &v) in pb.iter_mut().zip(u[hi - nb..hi].iter().rev()) {
            *p = (v - r) * s;
        }
        (y[k] - r) * s
    }

    /// RLS update with forgetting `lambda`; returns the a-priori error (scaled).
    ///
    /// With `bound`, the trace bound is applied to the updated `P` in the
    /// same pass (as [`Self::bound_trace`] would after it). `P` stays exactly
    /// symmetric: the downdate is `Pᵢⱼ ← (Pᵢⱼ − (gᵢ·gⱼ)/(λ + ψᵀg))/λ`.
    fn add(&mut self, target: f64, lambda: f64, bound: bool) -> f64 {
        let max = if bound { self.max_trace } else { f64::INFINITY };
        let (p, psi, theta, g) = (&mut self.p, &self.psi, &mut self.theta, &mut self.g);
        #[cfg(target_arch = "x86_64")]
        let r = if self.avx {
            // SAFETY: `avx` is set only when the CPU reports AVX2 (`new`).
            unsafe {
                add_avx2::<false>(
                    self.n, self.n, p, psi, theta, g, target, lambda, max, &mut 1.0,
                )
            }
        } else {
            add_sized::<false>(
                self.n, self.n, p, psi, theta, g, target, lambda, max, &mut 1.0,
            )
        };
        #[cfg(not(target_arch = "x86_64"))]
        let r = {
            let _ = self.avx;
            add_sized::<false>(
                self.n, self.n, p, psi, theta, g, target, lambda, max, &mut 1.0,
            )
        };
        match r {
            Ok(e) => e,
            Err(e) => {
                if bound {
                    self.bound_trace();
                }
                e
            }
        }
    }

    /// Exact removal of a sample; false if it would lose definiteness.
    fn remove(&mut self, target: f64) -> bool {
        let n = self.n;
        sym_mul(&self.p, &self.psi, &mut self.g);
        let mut q = 0.0;
        let mut pred = 0.0;
        for ((&s, &gi), &t) in self.psi.iter().zip(&self.g).zip(&self.theta) {
            q += s * gi;
            pred += s * t;
        }
        let d = 1.0 - q;
        if !(d > 1e-12) {
            return false;
        }
        let e = target - pred;
        for (t, &gi) in self.theta.iter_mut().zip(&self.g) {
            *t -= gi * e / d;
        }
        let g = &self.g;
        for (row, &gi) in self.p.chunks_exact_mut(n).zip(g) {
            for (v, &gj) in row.iter_mut().zip(g) {
                *v += gi * gj / d;
            }
        }
        true
    }

    fn bound_trace(&mut self) {
        let n = self.n;
        let tr: f64 = self.p.iter().step_by(n + 1).sum();
        if tr > self.max_trace {
            let f = self.max_trace / tr;
            for v in &mut self.p {
                *v *= f;
            }
        }
    }

    /// Rebuild the windowed estimate from the samples `[k − W, k)` (local indices ≥ `first`).
    fn rebuild_window(&mut self, y: &[f64], u: &[f64], first: usize, k: usize, w: usize) {
        self.reset_covariance();
        for j in k.saturating_sub(w).max(first)..k {
            if self.exciting(u, j) {
                let t = self.load(y, u, j);
                self.add(t, 1.0, false);
            }
        }
    }
}

/// Whether the CPU has AVX2 (selects the vectorised RLS update).
pub(crate) fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// One exponentially weighted RLS update of `auto`'s recursive candidates
/// (the update of [`RlsEstimator`] on a scaled covariance) of the
/// `n = θ.len()` parameters: the covariance is `P = κ·P̃`, `p` holding `P̃`
/// row-major `n×s` with the stride `s = ψ.len() ≥ n` (the rows padded to
/// `s` columns, for whole vectors: the pads of `p` and `ψ` must be zero,
/// and they stay zero) and exactly symmetric in its `n×n` part, `kappa`
/// holding `κ`; `g` a scratch of length `s`, trace bound `max` on `tr P`
/// (∞ = none), `avx` from [`has_avx2`]. With `g̃ = P̃ψ` and
/// `d = λ + κ·ψᵀg̃`:
///
/// ```text
/// θ ← θ + g̃·(κ/d)·(ỹ − ψᵀθ),   P̃ᵢⱼ ← P̃ᵢⱼ − (g̃ᵢ·g̃ⱼ)·(κ/d),   κ ← κ/λ
/// ```
///
/// — the forgetting and the trace bound act on `κ` alone (two
/// multiplications per entry instead of three). Keep `κ` within a few
/// hundred binary orders of 1 by folding it into `p` now and then
/// ([`fold_scale`]). Returns the a-priori error, or `Err(e)` if `d` is not
/// positive (nothing updated). The padding changes no result
/// (bit-identical to `s = n`).
#[allow(clippy::too_many_arguments)]
pub(crate) fn rls_update(
    avx: bool,
    p: &mut [f64],
    kappa: &mut f64,
    psi: &[f64],
    theta: &mut [f64],
    g: &mut [f64],
    target: f64,
    lambda: f64,
    max: f64,
) -> std::result::Result<f64, f64> {
    let (s, n) = (psi.len(), theta.len().min(psi.len()));
    #[cfg(target_arch = "x86_64")]
    if avx {
        // SAFETY: callers pass `avx` from `has_avx2`.
        return unsafe { add_avx2::<true>(s, n, p, psi, theta, g, target, lambda, max, kappa) };
    }
    let _ = avx;
    add_sized::<true>(s, n, p, psi, theta, g, target, lambda, max, kappa)
}

/// Fold the scale `κ` of a covariance `P = κ·P̃` (see [`rls_update`]) into
/// `p` when it has left `[2⁻¹⁰⁰, 2¹⁰⁰]`, so that `P̃` neither underflows
/// nor overflows; `P` is unchanged (to rounding).
pub(crate) fn fold_scale(p: &mut [f64], kappa: &mut f64) {
    const WIDE: f64 = 1.2676506002282294e30; // 2¹⁰⁰
    if !(1.0 / WIDE..=WIDE).contains(kappa) {
        for v in p.iter_mut() {
            *v *= *kappa;
        }
        *kappa = 1.0;
    }
}

/// [`add_kernel`] with the strides up to 16 as constants (unrolled, vectorised).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn add_sized<const SCALED: bool>(
    s: usize,
    n: usize,
    p: &mut [f64],
    psi: &[f64],
    theta: &mut [f64],
    g: &mut [f64],
    target: f64,
    lambda: f64,
    max: f64,
    kappa: &mut f64,
) -> std::result::Result<f64, f64> {
    // each arm inlines the kernel with a constant size (unrolled loops)
    macro_rules! sized {
        ($($k:literal)*) => {
            match s {
                $($k => add_kernel::<SCALED>($k, n, p, psi, theta, g, target, lambda, max, kappa),)*
                _ => add_kernel::<SCALED>(s, n, p, psi, theta, g, target, lambda, max, kappa),
            }
        };
    }
    sized!(2 3 4 5 6 7 8 9 10 11 12 13 14 15 16)
}

/// [`add_sized`] compiled for AVX2 (4-wide vectors). No FMA contraction
/// happens in Rust, so the results are bit-identical to the portable path.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[allow(clippy::too_many_arguments)]
fn add_avx2<const SCALED: bool>(
    s: usize,
    n: usize,
    p: &mut [f64],
    psi: &[f64],
    theta: &mut [f64],
    g: &mut [f64],
    target: f64,
    lambda: f64,
    max: f64,
    kappa: &mut f64,
) -> std::result::Result<f64, f64> {
    add_sized::<SCALED>(s, n, p, psi, theta, g, target, lambda, max, kappa)
}

/// The update of [`RlsEstimator::add`] on `n` parameters stored with the
/// stride `s ≥ n` (see [`rls_update`]) with the trace bound `max` (∞ =
/// none); `Err(e)` if `λ + ψᵀg` is not positive (nothing updated, the
/// trace bound not applied). `SCALED`: `p` holds `P̃` of `P = κ·P̃`
/// (`kappa`, see [`rls_update`]); otherwise `p` holds `P` and `kappa` is
/// not used.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn add_kernel<const SCALED: bool>(
    s: usize,
    n: usize,
    p: &mut [f64],
    psi: &[f64],
    theta: &mut [f64],
    g: &mut [f64],
    target: f64,
    lambda: f64,
    max: f64,
    kappa: &mut f64,
) -> std::result::Result<f64, f64> {
    let (p, psi, theta, g) = (&mut p[..n * s], &psi[..s], &mut theta[..n], &mut g[..s]);
    let k = if SCALED { *kappa } else { 1.0 };
    // the trace of P̃ before the update (off the critical path)
    let mut diag = 0.0;
    if max < f64::INFINITY {
        for i in 0..n {
            diag += p[i * (s + 1)];
        }
    }
    let pred = dot4(&psi[..n], theta);
    sym_mul(p, psi, g);
    let den = if SCALED {
        lambda + k * dot4(psi, g)
    } else {
        lambda + dot4(psi, g)
    };
    let e = target - pred;
    if !(den > 0.0) || !den.is_finite() {
        return Err(e);
    }
    let inv = 1.0 / den;
    // κ/d (SCALED) or 1/d
    let c = if SCALED { k * inv } else { inv };
    for (t, &gi) in theta.iter_mut().zip(g.iter()) {
        *t += gi * c * e;
    }
    let il = 1.0 / lambda;
    let g = &*g;
    // trace of the updated P: κ·tr(P̃ − g̃·g̃ᵀ·κ/d)/λ
    let tr = if max < f64::INFINITY {
        (diag - dot4(&g[..n], &g[..n]) * c) * k * il
    } else {
        0.0
    };
    let f = if tr > max { max / tr } else { 1.0 };
    if SCALED {
        // (g̃ᵢ·g̃ⱼ)·c keeps P̃ exactly symmetric; forgetting and the bound
        // act on κ
        for (row, &gi) in p.chunks_exact_mut(s).zip(g) {
            for (v, &gj) in row.iter_mut().zip(g) {
                *v -= gi * gj * c;
            }
        }
        *kappa = k * il * f;
    } else if f == 1.0 {
        // (gᵢ·gⱼ)·(1/d) keeps P exactly symmetric without a square root
        for (row, &gi) in p.chunks_exact_mut(s).zip(g) {
            for (v, &gj) in row.iter_mut().zip(g) {
                *v = (*v - gi * gj * c) * il;
            }
        }
    } else {
        for (row, &gi) in p.chunks_exact_mut(s).zip(g) {
            for (v, &gj) in row.iter_mut().zip(g) {
                *v = (*v - gi * gj * c) * il * f;
            }
        }
    }
    Ok(e)
}

/// `Σ aᵢbᵢ` (equal lengths) in four lanes (entry `i` into lane `i mod 4`,
/// then `(l₀ + l₁) + (l₂ + l₃)`): short dependency chains, and trailing
/// zeros (padding) change no bit.
#[inline(always)]
fn dot4(a: &[f64], b: &[f64]) -> f64 {
    // index loops: iterator adapters are not inlined into the large kernel
    let n = a.len();
    let b = &b[..n];
    let mut d = [0.0f64; 4];
    let mut i = 0;
    while i + 4 <= n {
        d[0] += a[i] * b[i];
        d[1] += a[i + 1] * b[i + 1];
        d[2] += a[i + 2] * b[i + 2];
        d[3] += a[i + 3] * b[i + 3];
        i += 4;
    }
    let mut l = 0;
    while i < n {
        d[l] += a[i] * b[i];
        i += 1;
        l += 1;
    }
    (d[0] + d[1]) + (d[2] + d[3])
}

/// `g = P·ψ` for an exactly symmetric row-major `P` (rows of `g.len()`
/// entries, as many rows as it holds), accumulated as the ψ-weighted sum of
/// its rows (contiguous, vectorisable).
#[inline(always)]
fn sym_mul(p: &[f64], psi: &[f64], g: &mut [f64]) {
    if let Ok(g) = <&mut [f64; 16]>::try_from(&mut *g) {
        // accumulate in registers for the default orders
        let mut acc = [0.0; 16];
        for (row, &s) in p.chunks_exact(16).zip(psi) {
            for (a, &v) in acc.iter_mut().zip(row) {
                *a += v * s;
            }
        }
        *g = acc;
        return;
    }
    let n = psi.len();
    g.fill(0.0);
    for (row, &s) in p.chunks_exact(n).zip(psi) {
        for (gi, &a) in g.iter_mut().zip(row) {
            *gi += a * s;
        }
    }
}

impl Estimator for RlsEstimator {
    fn name(&self) -> &'static str {
        "rls"
    }

    fn coefficient_names(&self) -> Vec<String> {
        self.config.orders.coefficient_names()
    }

    fn warm_up(&self) -> usize {
        self.config.orders.lag()
    }

    fn reset(&mut self) {
        self.reset_covariance();
        self.framed = false;
        self.stable.clear();
        self.s = self.config.scale.unwrap_or(0.0);
        self.cursor = None;
        self.start = None;
        self.updates = 0;
        self.dt = 0.0;
    }

    /// The estimate and its covariance are kept; the samples are taken up
    /// again from the first window after the gap (no regressor pairs
    /// samples across it).
    fn gap(&mut self) {
        self.cursor = None;
        self.start = None;
    }

    fn fit(
        &mut self,
        signals: &Signals<'_>,
        window: Range<usize>,
        coef: &mut [f64],
    ) -> Result<WindowFit> {
        if rate_changed(self.dt, signals.dt()) {
            self.reset();
        }
        self.dt = signals.dt();
        let lag = self.config.orders.lag().max(1);
        signals.window(window.clone(), lag, "ARX window (past samples + window)")?;
        let first = signals.offset() + lag;
        let mut cursor = self.cursor.unwrap_or(window.start.max(first));
        if cursor > window.end || cursor < first {
            self.reset();
            cursor = window.start.max(first);
        }
        // the finite window needs the samples it removes: reach back W samples
        let reach = self.config.window.unwrap_or(0);
        let base = cursor.saturating_sub(reach + lag).max(signals.offset());
        let w = signals.window(base..window.end, 0, "ARX window (past samples + window)")?;
        let (y, u) = (w.position, w.command);
        if let Some(i) = y.iter().chain(u).position(|v| !v.is_finite()) {
            let ch = if i < y.len() { "position" } else { "command" };
            return Err(Error::NonFinite {
                channel: ch.to_string(),
                index: base + i % y.len(),
                value: f64::NAN,
            });
        }
        let start = *self.start.get_or_insert(cursor);
        let local_first = start.max(base + lag) - base;
        let mut sse = 0.0;
        let mut count = 0usize;
        if self.s == 0.0 {
            // the scale from the first data that move (units and offsets cancel)
            let range = |v: &[f64]| {
                let (lo, hi) = v
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                        (a.min(x), b.max(x))
                    });
                hi - lo
            };
            let from = cursor - base - lag;
            let s = range(&y[from..]).max(range(&u[from..]));
            if s > 0.0 && s.is_finite() {
                self.s = s;
            } else {
                // nothing moves yet: nothing to learn
                self.cursor = Some(window.end);
                coef.fill(0.0);
                return Err(Error::Singular {
                    context: "rls (no exciting sample yet)",
                });
            }
        }
        for k in (cursor - base)..(window.end - base) {
            if !self.framed {
                self.r0 = y[k - 1];
                self.framed = true;
            } else if (y[k - 1] - self.r0).abs() > self.config.frame_span * self.s {
                self.r0 = y[k - 1];
                if let Some(w) = self.config.window {
                    self.rebuild_window(y, u, local_first, k, w);
                }
            }
            if !self.exciting(u, k) {
                continue;
            }
            let t = self.load(y, u, k);
            match self.config.window {
                None => {
                    let e = self.add(t, self.config.lambda, true);
                    sse += e * e;
                }
                Some(w) => {
                    let e = self.add(t, 1.0, false);
                    sse += e * e;
                    if k >= w + local_first && self.exciting(u, k - w) {
                        let t_old = self.load(y, u, k - w);
                        if !self.remove(t_old) {
                            self.rebuild_window(y, u, local_first, k + 1, w);
                        }
                    }
                }
            }
            count += 1;
            self.updates += 1;
        }
        self.cursor = Some(window.end);
        if !self.theta.iter().all(|v| v.is_finite()) {
            self.reset();
            return Err(Error::NonFinite {
                channel: "rls coefficients".to_string(),
                index: window.end,
                value: f64::NAN,
            });
        }
        if self.updates == 0 {
            coef.fill(0.0);
            return Err(Error::Singular {
                context: "rls (no exciting sample yet)",
            });
        }
        let nc = coef.len().min(self.n);
        coef[..nc].copy_from_slice(&self.theta[..nc]);
        let rms = if count > 0 {
            (sse / count as f64).sqrt() * self.s
        } else {
            0.0
        };
        Ok(if count > 0 {
            WindowFit::identified(rms, count, Termination::Exact)
        } else {
            WindowFit::fallback(rms, count)
        })
    }

    fn predict(
        &mut self,
        signals: &Signals<'_>,
        window: Range<usize>,
        horizon: Range<usize>,
        out: &mut [f64],
    ) -> Result<PredictStatus> {
        let orders = self.config.orders;
        if self.updates == 0 {
            return Err(Error::Singular {
                context: "rls prediction (no model)",
            });
        }
        if poles_inside(
            &self.theta[..orders.na],
            self.config.max_pole_radius,
            &mut self.schur,
        ) {
            self.stable.clear();
            self.stable.extend_from_slice(&self.theta);
        } else if self.stable.is_empty() {
            return Err(Error::InvalidModel {
                reason: "RLS estimate has unstable poles",
            });
        }
        // the current estimate if it passed the check, else the last one that did
        predict_horizon(
            &orders,
            &self.stable,
            0.0,
            signals,
            window,
            horizon,
            &mut self.past,
            out,
            "RLS",
        )?;
        Ok(PredictStatus::Predicted)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ident::engine::FitStatus;
    use crate::ident::methods::regressor::regressor;
    use nalgebra::{DMatrix, DVector};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, Normal};

    fn simulate_arx(a: &[f64], b: &[f64], nk: usize, u: &[f64], noise: &[f64]) -> Vec<f64> {
        let n = u.len();
        let mut y = vec![0.0; n];
        for k in 0..n {
            let mut v = noise[k];
            for (i, ai) in a.iter().enumerate() {
                if k > i {
                    v -= ai * y[k - i - 1];
                }
            }
            for (j, bj) in b.iter().enumerate() {
                if k >= nk + j {
                    v += bj * u[k - nk - j];
                }
            }
            y[k] = v;
        }
        y
    }

    /// Batch ridge LS `min Σ(t − ψθ)²/s² + θᵀθ/p0` over samples `rows` in frame `r0`.
    fn batch(
        orders: &ArxOrders,
        y: &[f64],
        u: &[f64],
        rows: Range<usize>,
        r0: f64,
        s: f64,
        p0: f64,
    ) -> Vec<f64> {
        let n = orders.n_params();
        let m = rows.len();
        let mut psi = vec![0.0; n];
        let mut a = DMatrix::zeros(m + n, n);
        let mut b = DVector::zeros(m + n);
        for (i, k) in rows.enumerate() {
            b[i] = regressor(orders, y, u, k, r0, &mut psi) / s;
            for j in 0..n {
                a[(i, j)] = psi[j] / s;
            }
        }
        for j in 0..n {
            a[(m + j, j)] = 1.0 / p0.sqrt();
        }
        a.svd(true, true)
            .solve(&b, 1e-300)
            .unwrap()
            .as_slice()
            .to_vec()
    }

    fn data(seed: u64, n: usize, noise: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let normal = Normal::new(0.0, 1.0).unwrap();
        let u: Vec<f64> = (0..n).map(|_| 1e-4 * rng.random_range(-1.0..1.0)).collect();
        let e: Vec<f64> = (0..n)
            .map(|k| {
                if k == 0 {
                    0.0
                } else {
                    noise * normal.sample(&mut rng)
                }
            })
            .collect();
        let y = simulate_arx(&[-1.2, 0.5], &[0.2, 0.1], 1, &u, &e);
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        (t, u, y)
    }

    fn max_rel(a: &[f64], b: &[f64]) -> f64 {
        let s = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
            / s
    }

    #[test]
    fn unstable_estimate_is_never_used_for_a_prediction_the_last_stable_one_is() {
        // data from an unstable system: y[k] = 1.05 y[k-1] + u[k-1]
        let mut rng = ChaCha8Rng::seed_from_u64(6);
        let n = 100;
        let u: Vec<f64> = (0..n).map(|_| rng.random_range(-1e-3..1e-3)).collect();
        let y = simulate_arx(&[-1.05], &[1.0], 1, &u, &vec![0.0; n]);
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let s = Signals::new(&t, &u, &y, 1e-3, 0.0);
        let mut rls = RlsConfig {
            orders: ArxOrders::new(1, 1, 1),
            lambda: 1.0,
            p0: 1e10,
            min_excitation: 0.0,
            max_pole_radius: 1.0,
            ..RlsConfig::default()
        }
        .build()
        .unwrap();
        let mut coef = [0.0; 2];
        rls.fit(&s, 2..60, &mut coef).unwrap();
        assert!(coef[0] < -1.0, "a pole outside the unit circle: {coef:?}");
        let mut out = [0.0; 5];
        let e = rls.predict(&s, 2..60, 60..65, &mut out).unwrap_err();
        assert!(matches!(e, Error::InvalidModel { .. }), "{e}");
        // window by window: a prediction once an estimate was stable (from
        // the last stable estimate), none before
        let mut rls = rls.config().build().unwrap();
        let (mut unstable, mut last_stable) = (0, None);
        for end in (25..95).step_by(5) {
            rls.fit(&s, end - 20..end, &mut coef).unwrap();
            let stable = poles_inside(&rls.theta()[..1], 1.0, &mut [0.0; 2]);
            if stable {
                last_stable = Some(rls.theta().to_vec());
            }
            let r = rls.predict(&s, end - 20..end, end..end + 5, &mut out);
            assert_eq!(
                r.is_ok(),
                last_stable.is_some(),
                "window ending at {end}: {coef:?}"
            );
            assert!(r.is_err() || out.iter().all(|v| v.is_finite()));
            unstable += usize::from(!stable);
        }
        assert!(unstable > 0);
    }

    #[test]
    fn lambda_one_equals_batch_least_squares() {
        let (t, u, y) = data(1, 800, 1e-6);
        let s = Signals::new(&t, &u, &y, 1e-3, 0.0);
        let orders = ArxOrders::new(2, 2, 1);
        let cfg = RlsConfig {
            orders,
            lambda: 1.0,
            p0: 1e10,
            max_trace: Some(f64::INFINITY),
            frame_span: f64::INFINITY,
            scale: Some(1e-3),
            min_excitation: 0.0,
            ..RlsConfig::default()
        };
        let mut rls = cfg.build().unwrap();
        let mut coef = [0.0; 4];
        rls.fit(&s, 2..800, &mut coef).unwrap();
        // exact: ridge 1/p0 in scaled coordinates
        let want = batch(&orders, &y, &u, 2..800, y[1], 1e-3, 1e10);
        assert!(max_rel(&coef, &want) < 1e-8, "{coef:?} vs {want:?}");
        // and plain least squares to the ridge's effect
        let plain = batch(&orders, &y, &u, 2..800, y[1], 1e-3, 1e300);
        assert!(max_rel(&coef, &plain) < 1e-6, "{coef:?} vs {plain:?}");
    }

    #[test]
    fn processing_in_pieces_equals_one_pass() {
        let (t, u, y) = data(2, 600, 1e-6);
        let s = Signals::new(&t, &u, &y, 1e-3, 0.0);
        let mut a = RlsConfig::default().build().unwrap();
        let mut b = RlsConfig::default().build().unwrap();
        let mut ca = vec![0.0; 16];
        let mut cb = vec![0.0; 16];
        a.fit(&s, 8..600, &mut ca).unwrap();
        b.fit(&s, 8..100, &mut cb).unwrap();
        for end in (150..=600).step_by(50) {
            b.fit(&s, end - 50..end, &mut cb).unwrap();
        }
        assert_eq!(ca, cb);
        b.reset();
        b.fit(&s, 8..600, &mut cb).unwrap();
        assert_eq!(ca, cb);
    }

    #[test]
    fn avx2_update_gives_the_portable_estimates_bit_for_bit() {
        // the update's kernel is chosen at run time: both give exactly the
        // same estimates (on a CPU without AVX2 both are the portable one)
        let (t, u, y) = data(4, 1500, 1e-6);
        let s = Signals::new(&t, &u, &y, 1e-3, 0.0);
        for cfg in [
            RlsConfig::default(),
            RlsConfig {
                orders: ArxOrders::new(2, 2, 1),
                window: Some(120),
                ..RlsConfig::default()
            },
        ] {
            let run = || {
                let mut rls = cfg.build().unwrap();
                assert_eq!(rls.avx, crate::solve::rows::avx2());
                let mut coef = vec![0.0; cfg.orders.n_params()];
                let mut bits = Vec::new();
                for end in (200..=1500).step_by(10) {
                    rls.fit(&s, end - 100..end, &mut coef).unwrap();
                    bits.extend(coef.iter().map(|v| v.to_bits()));
                }
                bits
            };
            let fast = run();
            assert_eq!(fast, crate::solve::rows::portable(run));
        }
    }

    /// An RLS state of `n` parameters twice, unpadded and with the stride
    /// `s`: covariances `p0·I`, zero parameters, gain scratch —
    /// `[p, p_padded, θ, θ_padded, g, g_padded]`.
    fn two_states(n: usize, s: usize, p0: f64) -> [Vec<f64>; 6] {
        let (mut p1, mut p2) = (vec![0.0; n * n], vec![0.0; n * s]);
        for i in 0..n {
            p1[i * n + i] = p0;
            p2[i * s + i] = p0;
        }
        [
            p1,
            p2,
            vec![0.0; n],
            vec![0.0; n],
            vec![0.0; n],
            vec![0.0; s],
        ]
    }

    #[test]
    fn padded_rows_give_the_unpadded_updates_bit_for_bit() {
        // rls_update on P stored with rows padded to whole 4-wide vectors
        // (auto's candidates) against the unpadded storage, for every size
        // the default candidates use and more, with and without the trace
        // bound, on seeded regressors (some exactly zero)
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let mut next = || rng.random_range(-0.5..0.5);
        let avx = has_avx2();
        for n in 2..=15usize {
            let s = n.div_ceil(4usize) * 4;
            for max in [f64::INFINITY, 50.0 * n as f64] {
                let [mut p1, mut p2, mut th1, mut th2, mut g1, mut g2] = two_states(n, s, 100.0);
                let (mut k1, mut k2) = (1.0, 1.0);
                let mut psi2 = vec![0.0; s];
                for k in 0..300 {
                    let psi1: Vec<f64> = (0..n)
                        .map(|j| if (k + j) % 9 == 0 { 0.0 } else { next() })
                        .collect();
                    psi2[..n].copy_from_slice(&psi1);
                    let target = next();
                    let a = rls_update(
                        avx, &mut p1, &mut k1, &psi1, &mut th1, &mut g1, target, 0.99, max,
                    );
                    let b = rls_update(
                        avx, &mut p2, &mut k2, &psi2, &mut th2, &mut g2, target, 0.99, max,
                    );
                    assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits), "n {n} k {k}");
                    assert_eq!(k1.to_bits(), k2.to_bits(), "n {n} k {k}");
                }
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&th1), bits(&th2), "n {n}");
                for i in 0..n {
                    assert_eq!(
                        bits(&p1[i * n..(i + 1) * n]),
                        bits(&p2[i * s..i * s + n]),
                        "n {n}"
                    );
                    assert!(
                        p2[i * s + n..(i + 1) * s].iter().all(|&v| v == 0.0),
                        "pads stay zero"
                    );
                }
                assert!(th1.iter().any(|&v| v != 0.0));
            }
        }
    }

    #[test]
    fn the_scaled_covariance_update_equals_the_plain_update() {
        // auto's update on P = κ·P̃ against the RlsEstimator's on P, with
        // and without the trace bound (which binds: a weak prior, rows
        // that stop exciting half the parameters), through κ being folded
        // back into P̃ (unbounded)
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let avx = has_avx2();
        for n in [5usize, 6, 7, 11, 15] {
            let s = if n % 4 == 3 { n + 1 } else { n };
            for max in [f64::INFINITY, 2.0 * n as f64] {
                let [mut p1, mut p2, mut th1, mut th2, mut g1, mut g2] = two_states(n, s, 1.0);
                let mut kappa = 1.0;
                let (mut psi1, mut psi2) = (vec![0.0; n], vec![0.0; s]);
                let truth: Vec<f64> = (0..n).map(|j| 0.3 - 0.05 * j as f64).collect();
                let mut folds = 0;
                for k in 0..3000 {
                    for (j, v) in psi1.iter_mut().enumerate() {
                        *v = if k > 1500 && j % 2 == 1 {
                            0.0
                        } else {
                            rng.random_range(-1.0..1.0)
                        };
                    }
                    psi2[..n].copy_from_slice(&psi1);
                    let t = psi1.iter().zip(&truth).map(|(a, b)| a * b).sum::<f64>()
                        + 1e-3 * rng.random_range(-1.0..1.0);
                    let _ = add_sized::<false>(
                        n, n, &mut p1, &psi1, &mut th1, &mut g1, t, 0.95, max, &mut 1.0,
                    );
                    let _ = rls_update(
                        avx, &mut p2, &mut kappa, &psi2, &mut th2, &mut g2, t, 0.95, max,
                    );
                    let before = kappa;
                    fold_scale(&mut p2, &mut kappa);
                    folds += usize::from(kappa != before);
                }
                let scale = p1.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                for i in 0..n {
                    for j in 0..n {
                        let (a, b) = (p1[i * n + j], kappa * p2[i * s + j]);
                        assert!(
                            (a - b).abs() <= 1e-9 * scale,
                            "n {n} max {max}: P[{i},{j}] {a} vs {b}"
                        );
                    }
                }
                for (a, b) in th1.iter().zip(&th2) {
                    assert!((a - b).abs() <= 1e-9, "n {n} max {max}: θ {a} vs {b}");
                }
                if max.is_infinite() {
                    // without the bound κ grows by 1/0.95 per update: folded
                    assert!(folds > 0, "n {n}: κ was never folded");
                }
            }
        }
    }

    #[test]
    fn finite_window_equals_windowed_batch_fit() {
        let (t, u, y) = data(3, 1500, 1e-6);
        let s = Signals::new(&t, &u, &y, 1e-3, 0.0);
        let orders = ArxOrders::new(2, 2, 1);
        let w = 120;
        let mut rls = RlsConfig {
            orders,
            window: Some(w),
            p0: 1e8,
            frame_span: f64::INFINITY,
            scale: Some(1e-3),
            min_excitation: 0.0,
            ..RlsConfig::default()
        }
        .build()
        .unwrap();
        let mut coef = [0.0; 4];
        rls.fit(&s, 2..290, &mut coef).unwrap();
        for end in [300, 301, 700, 1500] {
            rls.fit(&s, end - 10..end, &mut coef).unwrap();
            let want = batch(&orders, &y, &u, end - w..end, y[1], 1e-3, 1e8);
            assert!(
                max_rel(&coef, &want) < 1e-8,
                "end {end}: {coef:?} vs {want:?}"
            );
        }
    }

    #[test]
    fn noise_free_known_arx_parameters_are_recovered() {
        let (t, u, y) = data(4, 2000, 0.0);
        let s = Signals::new(&t, &u, &y, 1e-3, 0.0);
        for window in [None, Some(300)] {
            let mut rls = RlsConfig {
                orders: ArxOrders::new(2, 2, 1),
                lambda: 0.99,
                window,
                p0: 1e12,
                max_trace: Some(f64::INFINITY),
                frame_span: f64::INFINITY,
                scale: Some(1e-3),
                ..RlsConfig::default()
            }
            .build()
            .unwrap();
            let mut coef = [0.0; 4];
            rls.fit(&s, 1000..2000, &mut coef).unwrap();
            let want = [-1.2, 0.5, 0.2, 0.1];
            assert!(max_rel(&coef, &want) < 1e-8, "{window:?}: {coef:?}");
        }
    }

    #[test]
    fn standstill_does_not_wind_up_the_covariance() {
        let (t, mut u, y0) = data(5, 3000, 1e-7);
        for v in &mut u[1000..] {
            *v = 0.0;
        }
        let e: Vec<f64> = (0..3000)
            .map(|k| 1e-7 * ((k * 37 % 11) as f64 - 5.0))
            .collect();
        let y = simulate_arx(&[-1.2, 0.5], &[0.2, 0.1], 1, &u, &e);
        let _ = y0;
        let s = Signals::new(&t, &u, &y, 1e-3, 0.0);
        let mut rls = RlsConfig {
            orders: ArxOrders::new(2, 2, 1),
            lambda: 0.95,
            max_trace: Some(f64::INFINITY),
            min_excitation: 1e-6,
            ..RlsConfig::default()
        }
        .build()
        .unwrap();
        let mut coef = [0.0; 4];
        rls.fit(&s, 900..1010, &mut coef).unwrap();
        let tr0: f64 = (0..4).map(|i| rls.covariance()[i * 5]).sum();
        let f = rls.fit(&s, 1100..3000, &mut coef).unwrap();
        assert_eq!(f.status, FitStatus::Fallback);
        let tr1: f64 = (0..4).map(|i| rls.covariance()[i * 5]).sum();
        assert_eq!(tr0, tr1);
        // without the gate the trace grows like λ^−k
        let mut open = RlsConfig {
            orders: ArxOrders::new(2, 2, 1),
            lambda: 0.95,
            min_excitation: 0.0,
            max_trace: Some(f64::INFINITY),
            ..RlsConfig::default()
        }
        .build()
        .unwrap();
        open.fit(&s, 900..1010, &mut coef).unwrap();
        open.fit(&s, 1100..3000, &mut coef).unwrap();
        let tr2: f64 = (0..4).map(|i| open.covariance()[i * 5]).sum();
        assert!(tr2 > 1e3 * tr1, "{tr2} vs {tr1}");
    }

    #[test]
    fn trace_bound_holds() {
        let (t, u, y) = data(6, 1000, 1e-6);
        let s = Signals::new(&t, &u, &y, 1e-3, 0.0);
        let mut rls = RlsConfig {
            orders: ArxOrders::new(2, 2, 1),
            lambda: 0.9,
            max_trace: Some(10.0),
            ..RlsConfig::default()
        }
        .build()
        .unwrap();
        let mut coef = [0.0; 4];
        rls.fit(&s, 2..1000, &mut coef).unwrap();
        let tr: f64 = (0..4).map(|i| rls.covariance()[i * 5]).sum();
        assert!(tr <= 10.0 * (1.0 + 1e-12));
    }

    #[test]
    fn bad_configurations_are_rejected() {
        assert!(RlsConfig {
            lambda: 0.0,
            ..Default::default()
        }
        .build()
        .is_err());
        assert!(RlsConfig {
            lambda: 1.5,
            ..Default::default()
        }
        .build()
        .is_err());
        assert!(RlsConfig {
            p0: -1.0,
            ..Default::default()
        }
        .build()
        .is_err());
        assert!(RlsConfig {
            window: Some(0),
            ..Default::default()
        }
        .build()
        .is_err());
    }
}
