//! `auto`'s candidate predictors: hold, the command, and unit-gain ARX
//! models ([`super::model`]) fitted recursively (exponential forgetting) or
//! over a sliding window of samples, optionally with a constant term (bias).
//!
//! The column of the constant term is not 1 (that would give it a unit of
//! its own and make the relative ridge, or the recursive prior, depend on
//! the unit): it is the largest regressor or target of the candidate's
//! first informative window (`scale`), a length of the recording like every
//! other column, so the estimate of `c = θ_c·scale` scales with the unit
//! and the fit and prediction are unit-equivariant and offset-invariant.

// Negated comparisons are deliberate (they reject NaN).
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use std::fmt;
use std::ops::Range;

use super::model::{self, with_dims};
use crate::error::{Error, Result};
use crate::ident::engine::Signals;
use crate::ident::methods::regressor::ArxOrders;
use crate::ident::methods::rls::{fold_scale, has_avx2, rls_update};

/// Initial covariance `P₀ = p0·I` of the recursive candidates, in
/// coordinates scaled by the largest regressor of the first informative
/// window (and the bound on `tr P / n`): a weak prior, learnt over within a
/// few dozen samples.
const P0: f64 = 1e6;

/// One candidate predictor of `auto`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Candidate {
    /// The last measured position, held over the horizon.
    Hold,
    /// The command at the predicted instant (an axis with feed-forward
    /// follows it within its small following error).
    Command,
    /// The command, chosen only where it is still over the window and the
    /// horizon (an axis at rest on its set-point, where the command is the
    /// best prediction there is and every estimated model only adds the
    /// noise of its estimate), and never part of the candidates' median
    /// (it is not a model of the axis). Where the axis moves, its error is
    /// the following error, which grows through a move, so its score at a
    /// move's start says nothing about the move's end.
    CommandAtRest,
    /// Unit-gain ARX ([`super::model`]) by exponentially weighted recursive
    /// least squares with forgetting factor `lambda` (memory ≈ 1/(1 − λ)
    /// samples); a sample updates the estimate only if its regression row
    /// is not all zero (an exactly still axis carries no information).
    Recursive {
        /// Orders `na ≥ 1, nb ≥ 1, nk`.
        orders: ArxOrders,
        /// Forgetting factor λ ∈ (0, 1].
        lambda: f64,
        /// Whether the model has a constant term `c` added to every
        /// increment ([`super::model`]).
        bias: bool,
    },
    /// Unit-gain ARX by least squares over the last `window` samples,
    /// refitted at every window, with a ridge `ridge·‖Ψ‖²_F/n` relative to
    /// the regression (0 = none; rank-deficient columns are dropped).
    Windowed {
        /// Orders `na ≥ 1, nb ≥ 1, nk`.
        orders: ArxOrders,
        /// Rows fitted \[samples\].
        window: usize,
        /// Relative ridge ≥ 0.
        ridge: f64,
        /// Whether the model has a constant term `c` added to every
        /// increment ([`super::model`]).
        bias: bool,
    },
}

impl fmt::Display for Candidate {
    /// A short name: `hold`, `command`, `rls 2,2,0 λ=0.99`, `ls 2,2,0 W=100`
    /// (with the ridge if any: `ls 2,2,0 W=100 ρ=1e-6`; with a constant
    /// term: `rls 2,2,0+c λ=0.99`, `ls 2,2,0+c W=100`).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Candidate::Hold => f.write_str("hold"),
            Candidate::Command => f.write_str("command"),
            Candidate::CommandAtRest => f.write_str("command at rest"),
            Candidate::Recursive {
                orders: o,
                lambda,
                bias,
            } => {
                let c = if *bias { "+c" } else { "" };
                write!(f, "rls {},{},{}{c} λ={lambda}", o.na, o.nb, o.nk)
            }
            Candidate::Windowed {
                orders: o,
                window,
                ridge,
                bias,
            } => {
                let c = if *bias { "+c" } else { "" };
                write!(f, "ls {},{},{}{c} W={window}", o.na, o.nb, o.nk)?;
                if *ridge > 0.0 {
                    write!(f, " ρ={ridge:e}")?;
                }
                Ok(())
            }
        }
    }
}

impl Candidate {
    /// The orders of an identified candidate.
    pub fn orders(&self) -> Option<ArxOrders> {
        match self {
            Candidate::Hold | Candidate::Command | Candidate::CommandAtRest => None,
            Candidate::Recursive { orders, .. } | Candidate::Windowed { orders, .. } => {
                Some(*orders)
            }
        }
    }

    /// Whether the candidate may predict only where the command is still
    /// ([`Candidate::CommandAtRest`]).
    pub fn at_rest_only(&self) -> bool {
        matches!(self, Candidate::CommandAtRest)
    }

    /// Whether the candidate's predictions enter the pointwise median of
    /// the candidates (all but [`Candidate::CommandAtRest`]).
    pub(crate) fn in_median(&self) -> bool {
        !self.at_rest_only()
    }

    /// Whether the model has a constant term (bias).
    pub fn has_bias(&self) -> bool {
        matches!(
            self,
            Candidate::Recursive { bias: true, .. } | Candidate::Windowed { bias: true, .. }
        )
    }

    /// Number of estimated parameters (`na − 1 + nb`, plus one with a
    /// constant term; 0 for hold and command).
    pub(crate) fn n_params(&self) -> usize {
        self.orders()
            .map_or(0, |o| model::n_free(&o) + usize::from(self.has_bias()))
    }

    /// Whether this candidate (windowed, with a constant term) can be solved
    /// from the factors of `leader` (the same windowed candidate without
    /// it, carrying the constant column: [`Predictor::carry_constant`]).
    pub(crate) fn follows(&self, leader: &Candidate) -> bool {
        match (*self, *leader) {
            (
                Candidate::Windowed {
                    orders: a,
                    window: wa,
                    bias: true,
                    ..
                },
                Candidate::Windowed {
                    orders: b,
                    window: wb,
                    bias: false,
                    ..
                },
            ) => a == b && wa == wb,
            _ => false,
        }
    }

    /// Samples needed before the first regression row.
    pub fn warm_up(&self) -> usize {
        self.orders().map_or(1, |o| model::lag(&o))
    }

    /// Check the settings (`na ≥ 1`, valid orders, λ ∈ (0, 1], window ≥ 2, ridge ≥ 0).
    pub fn validate(&self) -> Result<()> {
        if let Some(o) = self.orders() {
            o.validate()?;
            if o.na == 0 {
                return Err(Error::InvalidParameter {
                    name: "na",
                    value: 0.0,
                    reason: "auto's unit-gain models need na >= 1",
                });
            }
        }
        match *self {
            Candidate::Recursive { lambda, .. } if !(lambda > 0.0 && lambda <= 1.0) => {
                Err(Error::InvalidParameter {
                    name: "lambda",
                    value: lambda,
                    reason: "must be in (0, 1]",
                })
            }
            Candidate::Windowed { window, .. } if window < 2 => Err(Error::InvalidParameter {
                name: "window",
                value: window as f64,
                reason: "an auto candidate's window must be at least 2 samples",
            }),
            Candidate::Windowed { ridge, .. } if !(ridge.is_finite() && ridge >= 0.0) => {
                Err(Error::InvalidParameter {
                    name: "ridge",
                    value: ridge,
                    reason: "must be finite and >= 0",
                })
            }
            _ => Ok(()),
        }
    }
}

/// A candidate with its state.
#[derive(Debug, Clone)]
pub(crate) struct Predictor {
    spec: Candidate,
    /// Free parameters of the unit-gain model, then (with a bias) the
    /// coefficient of the constant column.
    theta: Vec<f64>,
    /// Number of free parameters of the unit-gain model (without the bias).
    n_model: usize,
    /// Whether the model has been fitted (hold and command: always).
    fitted: bool,
    state: State,
}

#[derive(Debug, Clone)]
enum State {
    Plain,
    Recursive(Box<Recursive>),
    Windowed(Box<Windowed>),
}

#[derive(Debug, Clone)]
struct Recursive {
    /// `P̃` of the covariance `P = κ·P̃` (see [`rls_update`]).
    p: Vec<f64>,
    /// `κ`.
    kappa: f64,
    psi: Vec<f64>,
    g: Vec<f64>,
    /// Next sample to process (absolute).
    cursor: Option<usize>,
    /// Scale of the regressors (0 until an informative window arrived).
    scale: f64,
    avx: bool,
}

/// With a bias, the value of the constant column (`scale`) and its
/// coefficient `θ_c` give `c = θ_c·scale`; 0 without a bias.
fn constant_of(theta: &[f64], n_model: usize, scale: f64) -> f64 {
    theta.get(n_model).map_or(0.0, |t| t * scale)
}

/// Least squares over the last `W/2 … W` samples without downdating: the
/// triangular factor of `[Ψ t]` over a completed block of `W/2` rows and
/// that of the rows since, grown by Givens rotations; at each fit the two
/// are merged (the newer one's rows rotated into a copy of the older) and
/// the merged factor solved. A block that reaches `W/2` rows becomes the
/// older one.
#[derive(Debug, Clone)]
struct Windowed {
    /// Row-major `(n+1)×(n+1)` upper-triangular factors: older, newer.
    factors: [Vec<f64>; 2],
    rows: [usize; 2],
    /// The factor of both blocks' rows (`rows[0] + rows[1]`), as of the
    /// last fit.
    merged: Vec<f64>,
    cursor: Option<usize>,
    psi: Vec<f64>,
    /// Scratch of one row `[ψ t]`.
    row: Vec<f64>,
    /// Up to [`GROUP`] rows waiting to be rotated into the newer factor.
    group: Vec<f64>,
    /// Scratch of the ridge solve: `[R z]` (`(n+1)×(n+1)`), the solution
    /// (`n`) and the ridge rows (`n×(n+1)`).
    small: Vec<f64>,
    rhs: Vec<f64>,
    ridge_rows: Vec<f64>,
    /// Value of the constant column (bias only): the largest regressor or
    /// target of the first informative window (0 until it arrived).
    scale: f64,
    /// A candidate without a constant term whose factors also carry the
    /// constant column, after the target (`[Ψ t c]`), so that the same
    /// candidate with a constant term can be solved from them
    /// ([`Predictor::fit_follower`]) instead of keeping factors of its own.
    carries: bool,
}

/// Rows rotated into a windowed candidate's factor together.
const GROUP: usize = 4;

impl Windowed {
    /// Rotate the first `count` rows of the group into the newer factor;
    /// it becomes the older one when it holds `half` rows.
    fn add_group(&mut self, count: usize, half: usize) {
        let m = self.row.len();
        givens_add_rows(&mut self.factors[1], &mut self.group[..count * m], m);
        self.rows[1] += count;
        if self.rows[1] >= half {
            let [a, b] = &mut self.factors;
            std::mem::swap(a, b);
            b.fill(0.0);
            self.rows = [self.rows[1], 0];
        }
    }
}

impl Predictor {
    /// A fresh predictor (the settings are validated by the caller).
    pub(crate) fn new(spec: Candidate) -> Self {
        let n = spec.n_params();
        let n_model = spec.orders().map_or(0, |o| model::n_free(&o));
        let state = match spec {
            Candidate::Hold | Candidate::Command | Candidate::CommandAtRest => State::Plain,
            Candidate::Recursive { .. } => State::Recursive(Box::new(Recursive {
                p: vec![0.0; n * stride(n)],
                kappa: 1.0,
                psi: vec![0.0; stride(n)],
                g: vec![0.0; stride(n)],
                cursor: None,
                scale: 0.0,
                avx: has_avx2(),
            })),
            Candidate::Windowed { .. } => State::Windowed(Box::new(Windowed {
                factors: [vec![0.0; (n + 1) * (n + 1)], vec![0.0; (n + 1) * (n + 1)]],
                rows: [0, 0],
                merged: vec![0.0; (n + 1) * (n + 1)],
                cursor: None,
                psi: vec![0.0; n],
                row: vec![0.0; n + 1],
                group: vec![0.0; GROUP * (n + 1)],
                small: vec![0.0; (n + 1) * (n + 1)],
                rhs: vec![0.0; n],
                ridge_rows: vec![0.0; n * (n + 1)],
                scale: 0.0,
                carries: false,
            })),
        };
        let mut p = Self {
            spec,
            theta: vec![0.0; n],
            n_model,
            fitted: false,
            state,
        };
        p.reset();
        p
    }

    /// The candidate.
    pub(crate) fn spec(&self) -> &Candidate {
        &self.spec
    }

    /// Free parameters of the unit-gain model (empty for hold and command;
    /// without the constant term).
    pub(crate) fn theta(&self) -> &[f64] {
        &self.theta[..self.n_model]
    }

    /// The constant `c` added to every increment, in the unit of the
    /// recording per sample (0 without a bias).
    pub(crate) fn constant(&self) -> f64 {
        match &self.state {
            State::Recursive(r) => constant_of(&self.theta, self.n_model, r.scale),
            State::Windowed(l) => constant_of(&self.theta, self.n_model, l.scale),
            State::Plain => 0.0,
        }
    }

    /// Let the factors of this windowed candidate without a constant term
    /// also carry the constant column, so that the same candidate with it
    /// can follow ([`Predictor::fit_follower`]); forgets all state. No
    /// effect on other candidates.
    pub(crate) fn carry_constant(&mut self) {
        let n = self.theta.len();
        if let (State::Windowed(l), Candidate::Windowed { bias: false, .. }) =
            (&mut self.state, self.spec)
        {
            let m = n + 2;
            l.carries = true;
            l.factors = [vec![0.0; m * m], vec![0.0; m * m]];
            l.merged = vec![0.0; m * m];
            l.row = vec![0.0; m];
            l.group = vec![0.0; GROUP * m];
        }
        self.reset();
    }

    /// Fit this windowed candidate with a constant term from the factors of
    /// `leader` (see [`Candidate::follows`]; its fit done up to the same
    /// sample) instead of from factors of its own: the leader's factor of
    /// `[Ψ t c]` with its last two columns swapped and one Givens rotation
    /// is the factor of `[Ψ c t]` over the same rows — the same least
    /// squares as its own factors would give, for half the work. Returns
    /// whether the model can predict. A follower that is restarted refits
    /// from the leader's rows at the next fit.
    pub(crate) fn fit_follower(&mut self, leader: &Predictor) -> bool {
        let n = self.theta.len();
        let (State::Windowed(l), State::Windowed(lead)) = (&mut self.state, &leader.state) else {
            return self.fitted;
        };
        let Candidate::Windowed { ridge, .. } = self.spec else {
            return self.fitted;
        };
        let m = n + 1;
        if !lead.carries || lead.row.len() != m || l.factors[0].len() != m * m {
            return self.fitted;
        }
        l.scale = lead.scale;
        l.cursor = lead.cursor;
        l.rows = lead.rows;
        if lead.rows[0] + lead.rows[1] < n || l.scale == 0.0 {
            return self.fitted;
        }
        // [Ψ t c] → [Ψ c t]: swap the last two columns …
        let (src, dst) = (&lead.merged, &mut l.factors[0]);
        let (nm, t, c) = (n - 1, n - 1, n);
        for i in 0..m {
            let row = &src[i * m..(i + 1) * m];
            let out = &mut dst[i * m..(i + 1) * m];
            out[..nm].copy_from_slice(&row[..nm]);
            out[t] = row[c];
            out[c] = row[t];
        }
        // … and rotate rows nm and nm + 1 to zero the entry below the diagonal
        if let Some((rho, cs, sn)) = rotation(dst[nm * m + nm], dst[(nm + 1) * m + nm]) {
            dst[nm * m + nm] = rho;
            dst[(nm + 1) * m + nm] = 0.0;
            let (a, b) = (dst[nm * m + c], dst[(nm + 1) * m + c]);
            dst[nm * m + c] = cs * a + sn * b;
            dst[(nm + 1) * m + c] = cs * b - sn * a;
        }
        if solve_ridge(
            &l.factors[0],
            m,
            n,
            ridge,
            &mut l.small,
            &mut l.ridge_rows,
            &mut l.rhs,
        ) && l.rhs.iter().all(|v| v.is_finite())
        {
            self.theta.copy_from_slice(&l.rhs);
            self.fitted = true;
        }
        self.fitted
    }

    /// Forget the model but keep the position in the data (a model that
    /// predicted implausibly starts learning again from the next sample).
    pub(crate) fn restart(&mut self) {
        let cursor = match &self.state {
            State::Recursive(r) => r.cursor,
            State::Windowed(l) => l.cursor,
            State::Plain => None,
        };
        self.reset();
        match &mut self.state {
            State::Recursive(r) => r.cursor = cursor,
            State::Windowed(l) => l.cursor = cursor,
            State::Plain => {}
        }
    }

    /// Forget all state.
    pub(crate) fn reset(&mut self) {
        self.theta.fill(0.0);
        self.fitted = matches!(
            self.spec,
            Candidate::Hold | Candidate::Command | Candidate::CommandAtRest
        );
        match &mut self.state {
            State::Recursive(r) => {
                r.cursor = None;
                r.scale = 0.0;
                reset_covariance(&mut r.p, &mut r.kappa, self.theta.len());
            }
            State::Windowed(l) => {
                l.cursor = None;
                l.scale = 0.0;
                for f in &mut l.factors {
                    f.fill(0.0);
                }
                l.merged.fill(0.0);
                l.rows = [0, 0];
            }
            State::Plain => {}
        }
    }

    /// A gap of dropped samples: keep the model (and a recursive candidate
    /// its covariance), forget what pairs samples — the recursive cursor,
    /// the windowed factors of the rows before the gap.
    pub(crate) fn gap(&mut self) {
        match &mut self.state {
            State::Recursive(r) => r.cursor = None,
            State::Windowed(l) => {
                l.cursor = None;
                for f in &mut l.factors {
                    f.fill(0.0);
                }
                l.merged.fill(0.0);
                l.rows = [0, 0];
            }
            State::Plain => {}
        }
    }

    /// Learn from the samples up to `end` (exclusive); `start` is the first
    /// sample of the engine's first window (where a recursive candidate
    /// begins). Returns whether the model can predict.
    pub(crate) fn fit(&mut self, signals: &Signals<'_>, start: usize, end: usize) -> bool {
        let Some(o) = self.spec.orders() else {
            return true;
        };
        let lag = model::lag(&o);
        let first = signals.offset() + lag;
        let bias = self.spec.has_bias();
        let nm = self.n_model;
        match (&mut self.state, self.spec) {
            (State::Recursive(r), Candidate::Recursive { lambda, .. }) => {
                let mut cursor = r.cursor.unwrap_or(start.max(first));
                if cursor < first || cursor > end {
                    // the data moved under us (a new recording): start over
                    self.theta.fill(0.0);
                    self.fitted = false;
                    r.scale = 0.0;
                    reset_covariance(&mut r.p, &mut r.kappa, self.theta.len());
                    cursor = start.max(first).min(end);
                }
                let Ok(w) = signals.window(cursor..end, lag, "auto candidate") else {
                    return self.fitted;
                };
                let (y, u) = (w.position, w.command);
                let n = self.theta.len();
                let rows = lag..lag + (end - cursor);
                if r.scale == 0.0 {
                    r.scale = largest_row_entry(&o, y, u, rows.clone(), &mut r.psi[..nm]);
                }
                if r.scale > 0.0 {
                    let inv = 1.0 / r.scale;
                    let max_trace = n as f64 * P0;
                    let theta = &mut self.theta;
                    let rls = Rows {
                        y,
                        u,
                        inv,
                        bias,
                        nm,
                        lambda,
                        max_trace,
                    };
                    if with_dims!(o, update_rows(r, theta, rows, &rls)) {
                        self.fitted = true;
                    }
                    fold_scale(&mut r.p, &mut r.kappa);
                    if !self.theta.iter().all(|v| v.is_finite()) {
                        self.theta.fill(0.0);
                        reset_covariance(&mut r.p, &mut r.kappa, n);
                        self.fitted = false;
                    }
                }
                r.cursor = Some(end);
                self.fitted
            }
            (State::Windowed(l), Candidate::Windowed { window, ridge, .. }) => {
                let mut cursor = l.cursor.unwrap_or(start.max(first));
                if cursor < first || cursor > end {
                    self.theta.fill(0.0);
                    self.fitted = false;
                    for f in &mut l.factors {
                        f.fill(0.0);
                    }
                    l.merged.fill(0.0);
                    l.rows = [0, 0];
                    l.scale = 0.0;
                    cursor = start.max(first).min(end);
                }
                let Ok(w) = signals.window(cursor..end, lag, "auto candidate") else {
                    return self.fitted;
                };
                let (y, u) = (w.position, w.command);
                let n = self.theta.len();
                let half = (window / 2).max(1);
                let rows = lag..lag + (end - cursor);
                let constant = bias || l.carries;
                if constant && l.scale == 0.0 {
                    l.scale = largest_row_entry(&o, y, u, rows.clone(), &mut l.psi[..nm]);
                }
                // rows gathered in groups of up to GROUP and rotated in
                // together (the same result as one by one)
                let m = l.row.len();
                let mut pending = 0;
                for k in rows {
                    // built in place (a copy reloaded the fresh scalar
                    // stores as vectors: a stall)
                    let row = &mut l.group[pending * m..(pending + 1) * m];
                    let (t, informative) = model::row_scaled(o, y, u, k, 1.0, &mut row[..nm]);
                    if !informative {
                        continue;
                    }
                    // the column `scale` (no row before it is known): before
                    // the target with a bias, after it when carried
                    if constant && l.scale == 0.0 {
                        continue;
                    }
                    if bias {
                        row[nm] = l.scale;
                    }
                    row[n] = t;
                    if l.carries {
                        row[n + 1] = l.scale;
                    }
                    pending += 1;
                    if pending == GROUP || l.rows[1] + pending >= half {
                        l.add_group(pending, half);
                        pending = 0;
                    }
                }
                if pending > 0 {
                    l.add_group(pending, half);
                }
                l.cursor = Some(end);
                let stride = l.row.len();
                merge(&l.factors, l.rows, &mut l.merged, &mut l.row);
                if l.rows[0] + l.rows[1] >= n
                    && solve_ridge(
                        &l.merged,
                        stride,
                        n,
                        ridge,
                        &mut l.small,
                        &mut l.ridge_rows,
                        &mut l.rhs,
                    )
                    && l.rhs.iter().all(|v| v.is_finite())
                {
                    self.theta.copy_from_slice(&l.rhs);
                    self.fitted = true;
                }
                self.fitted
            }
            _ => self.fitted,
        }
    }

    /// Predict `out` over `horizon` (starting at `window_end`) from the last fit.
    pub(crate) fn predict(
        &self,
        signals: &Signals<'_>,
        horizon: Range<usize>,
        past: &mut Vec<f64>,
        out: &mut [f64],
    ) -> Result<()> {
        let e = horizon.start;
        match self.spec {
            Candidate::Hold => {
                let w = signals.window(e..e, 1, "auto hold")?;
                out.fill(w.position[0]);
            }
            Candidate::Command | Candidate::CommandAtRest => {
                let w = signals.window(horizon.clone(), 0, "auto command")?;
                out.copy_from_slice(w.command);
            }
            Candidate::Recursive { orders, .. } | Candidate::Windowed { orders, .. } => {
                let c = self.constant();
                if !self.fitted {
                    return Err(Error::Singular {
                        context: "auto candidate (not fitted yet)",
                    });
                }
                let lag = model::lag(&orders);
                let w = signals.window(horizon.clone(), lag, "auto candidate prediction")?;
                let need = orders.na.max(1) + out.len();
                if past.len() < need {
                    past.resize(need, 0.0);
                }
                let theta = &self.theta[..self.n_model];
                let (y, u) = (w.position, w.command);
                model::predict(orders, theta, c, y, u, lag, past, out);
            }
        }
        if out.iter().all(|v| v.is_finite()) {
            Ok(())
        } else {
            Err(Error::NonFinite {
                channel: "auto candidate prediction".to_string(),
                index: e,
                value: f64::NAN,
            })
        }
    }
}

/// The factor of the rows of both `factors` (holding `rows` rows each)
/// into `merged`: the newer one's rows rotated into a copy of the older
/// (a copy when either is empty); `row` is scratch of one row.
fn merge(factors: &[Vec<f64>; 2], rows: [usize; 2], merged: &mut [f64], row: &mut [f64]) {
    let [old, new] = factors;
    if rows[0] == 0 {
        merged.copy_from_slice(new);
        return;
    }
    merged.copy_from_slice(old);
    if rows[1] == 0 {
        return;
    }
    let m = row.len();
    // (every row: with fewer rows than columns, a zero regressor can leave
    // a leading row of the triangle empty and fill a later one)
    for (i, r) in new.chunks_exact(m).enumerate() {
        // row i of a triangle is zero before column i
        row[..i].fill(0.0);
        row[i..].copy_from_slice(&r[i..]);
        givens_add(merged, row);
    }
}

/// The Givens rotation `(ρ, c, s)` that zeroes `x` against the diagonal
/// `d` (`None` when `x` is 0 or `ρ` is not positive: nothing to do).
#[inline(always)]
fn rotation(d: f64, x: f64) -> Option<(f64, f64, f64)> {
    if x == 0.0 {
        return None;
    }
    let rho = (d * d + x * x).sqrt();
    if !(rho > 0.0) {
        return None;
    }
    let inv = 1.0 / rho;
    Some((rho, d * inv, x * inv))
}

/// [`givens_add`] of the rows of `rows` (each of `m` entries) in turn, as
/// a wavefront: row `q` is rotated at column `c` in step `c + q`, after the
/// rows before it have passed that column, so that the rows' chains of
/// dependent square roots and divisions overlap. Bit-identical to adding
/// them one by one.
#[inline(always)]
fn givens_add_rows(r: &mut [f64], rows: &mut [f64], m: usize) {
    givens_add_rows_upto(r, rows, m, m);
}

/// [`givens_add_rows`] eliminating the rows' first `cols ≤ m` columns only
/// (the later ones are rotated along, not eliminated).
#[inline(always)]
fn givens_add_rows_upto(r: &mut [f64], rows: &mut [f64], m: usize, cols: usize) {
    let g = rows.len() / m;
    for step in 0..cols + g.saturating_sub(1) {
        for q in 0..g.min(step + 1) {
            let i = step - q;
            if i >= cols {
                continue;
            }
            let row = &mut rows[q * m..(q + 1) * m];
            let Some((rho, c, s)) = rotation(r[i * m + i], row[i]) else {
                continue;
            };
            r[i * m + i] = rho;
            for j in i + 1..m {
                let a = r[i * m + j];
                let b = row[j];
                r[i * m + j] = c * a + s * b;
                row[j] = c * b - s * a;
            }
        }
    }
}

/// Rotate the row `row` (length `m`) into the row-major `m×m` upper-triangular
/// factor `r` (Givens rotations; `row` is destroyed).
#[inline(always)]
fn givens_add(r: &mut [f64], row: &mut [f64]) {
    let m = row.len();
    givens_add_rows_upto(r, row, m, m);
}

/// Solve `min ‖R·θ − z‖² + λ‖θ‖²` from the upper-triangular factor of
/// `[Ψ t …]` (row-major, rows of `stride ≥ n + 1` entries; `R` its leading
/// `n×n` block, `z` its column `n` above the diagonal; columns after it are
/// ignored), `λ = max(ridge, 1e-12)·‖R‖²_F/n` (the relative ridge; 1e-12
/// keeps a rank-deficient window defined); the solution goes to `theta`.
fn solve_ridge(
    f: &[f64],
    m: usize,
    n: usize,
    ridge: f64,
    small: &mut [f64],
    ridge_rows: &mut [f64],
    theta: &mut [f64],
) -> bool {
    // [R z] into `small` ((n+1)×(n+1), the last row unused)
    let w = n + 1;
    let mut frob = 0.0;
    small.fill(0.0);
    for i in 0..n {
        for j in i..n {
            small[i * w + j] = f[i * m + j];
            frob += f[i * m + j] * f[i * m + j];
        }
        small[i * w + n] = f[i * m + n];
    }
    if !(frob > 0.0 && frob.is_finite()) {
        return false;
    }
    let lambda = ridge.max(1e-12) * frob / n as f64;
    // fold the rows [√λ·e_k 0] into the triangle (together, as a wavefront:
    // the same as one after the other)
    ridge_rows.fill(0.0);
    let root = lambda.sqrt();
    for k in 0..n {
        ridge_rows[k * w + k] = root;
    }
    givens_add_rows_upto(small, &mut ridge_rows[..n * w], w, n);
    // back substitution
    for i in (0..n).rev() {
        let mut v = small[i * w + n];
        for j in i + 1..n {
            v -= small[i * w + j] * theta[j];
        }
        let d = small[i * w + i];
        if !(d.abs() > 0.0) {
            return false;
        }
        theta[i] = v / d;
    }
    true
}

/// Row stride of a recursive candidate's covariance for `n` parameters:
/// one more when that makes whole 4-wide vectors (7 → 8, 11 → 12, 15 → 16;
/// the pad stays zero, the results are bit-identical, see [`rls_update`];
/// padding further cost more than it saved).
fn stride(n: usize) -> usize {
    if n % 4 == 3 {
        n + 1
    } else {
        n
    }
}

fn reset_covariance(p: &mut [f64], kappa: &mut f64, n: usize) {
    *kappa = 1.0;
    p.fill(0.0);
    let s = stride(n);
    for i in 0..n {
        p[i * s + i] = P0;
    }
}

/// Largest magnitude of a regressor or target over the rows (0 if all zero or not finite).
/// What a recursive candidate's rows are built from and how they are fed.
struct Rows<'a> {
    /// Positions and commands of the window (local indices).
    y: &'a [f64],
    u: &'a [f64],
    /// Scale of the coordinates (1 / the largest regressor of the first window).
    inv: f64,
    /// Whether the model has a constant term (column `nm`).
    bias: bool,
    /// Free parameters of the unit-gain model.
    nm: usize,
    lambda: f64,
    /// Trace bound of the covariance.
    max_trace: f64,
}

/// Feed the rows `rows` (local indices) of orders `o` to the recursive
/// least squares of `r` and `theta`; uninformative rows are skipped.
/// Returns whether any row was used.
#[inline(always)]
fn update_rows<D: model::Dims>(
    o: D,
    r: &mut Recursive,
    theta: &mut [f64],
    rows: Range<usize>,
    a: &Rows<'_>,
) -> bool {
    let (y, u, inv, bias, nm) = (a.y, a.u, a.inv, a.bias, a.nm);
    let (lambda, max_trace) = (a.lambda, a.max_trace);
    let mut used = false;
    for k in rows {
        // scaled as it is built (a separate pass reloaded the fresh scalar
        // stores as vectors: a stall)
        let (t, informative) = model::row_scaled(o, y, u, k, inv, &mut r.psi[..nm]);
        if !informative {
            continue;
        }
        if bias {
            // the column `scale`, in scaled coordinates
            r.psi[nm] = 1.0;
        }
        let _ = rls_update(
            r.avx,
            &mut r.p,
            &mut r.kappa,
            &r.psi,
            theta,
            &mut r.g,
            t,
            lambda,
            max_trace,
        );
        used = true;
    }
    used
}

fn largest_row_entry(
    o: &ArxOrders,
    y: &[f64],
    u: &[f64],
    rows: Range<usize>,
    psi: &mut [f64],
) -> f64 {
    let mut m = 0.0f64;
    for k in rows {
        let t = model::row(o, y, u, k, psi);
        m = psi.iter().fold(m.max(t.abs()), |m, v| m.max(v.abs()));
    }
    if m.is_finite() {
        m
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `y[k] = 1.5 y[k−1] − 0.6 y[k−2] + 0.05 u[k] + 0.05 u[k−1] + d` (unit DC
    /// gain, a constant disturbance `d` per sample), in `unit`s, `offset` away.
    fn system(n: usize, d: f64, offset: f64, unit: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let u0: Vec<f64> = (0..n)
            .map(|k| {
                let k = k as f64;
                1e-3 * ((k * 0.07).sin() + (k * 0.011).cos() + 0.3 * (k * 1.3).sin())
            })
            .collect();
        let mut y0 = vec![0.0; n];
        for k in 2..n {
            y0[k] = 1.5 * y0[k - 1] - 0.6 * y0[k - 2] + 0.05 * u0[k] + 0.05 * u0[k - 1] + d;
        }
        let map = |v: &f64| (v + offset) * unit;
        (
            t,
            u0.iter().map(map).collect(),
            y0.iter().map(map).collect(),
        )
    }

    fn windowed(bias: bool) -> Candidate {
        Candidate::Windowed {
            orders: ArxOrders::new(2, 2, 0),
            window: 100,
            ridge: 0.0,
            bias,
        }
    }

    /// Fit on samples `10..end`, predict `end..end + 10`.
    fn fit_predict(
        c: Candidate,
        data: &(Vec<f64>, Vec<f64>, Vec<f64>),
        end: usize,
    ) -> (Predictor, [f64; 10]) {
        let (t, u, y) = data;
        let s = Signals::new(t, u, y, 1e-3, 0.0);
        let mut p = Predictor::new(c);
        assert!(p.fit(&s, 10, end));
        let mut out = [0.0; 10];
        p.predict(&s, end..end + 10, &mut Vec::new(), &mut out)
            .unwrap();
        (p, out)
    }

    #[test]
    fn a_follower_solved_from_its_leaders_factor_equals_the_candidate_fitted_alone() {
        // noise added so that the fit is not exact; fitted in pieces of 10
        // samples (as auto does), past several swaps of the two factors
        let (t, u, mut y) = system(700, 2e-6, 0.3, 1.0);
        for (k, v) in y.iter_mut().enumerate() {
            *v += 1e-7 * ((k * 7919 % 13) as f64 - 6.0);
        }
        let s = Signals::new(&t, &u, &y, 1e-3, 0.0);
        let mut plain = Predictor::new(windowed(false));
        let mut leader = Predictor::new(windowed(false));
        leader.carry_constant();
        let mut alone = Predictor::new(windowed(true));
        let mut follower = Predictor::new(windowed(true));
        assert!(windowed(true).follows(&windowed(false)));
        assert!(!windowed(false).follows(&windowed(true)));
        let (mut past, mut a, mut b) = (Vec::new(), [0.0; 10], [0.0; 10]);
        let mut end = 40;
        while end + 10 <= 700 {
            let fitted = plain.fit(&s, 10, end);
            assert_eq!(leader.fit(&s, 10, end), fitted);
            assert_eq!(alone.fit(&s, 10, end), follower.fit_follower(&leader));
            // carrying the constant column changes nothing of the leader's own fit
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(plain.theta()), bits(leader.theta()), "end {end}");
            if alone.fitted {
                for (x, z) in alone.theta.iter().zip(&follower.theta) {
                    assert!(
                        (x - z).abs() <= 1e-8 * x.abs().max(1e-3),
                        "end {end}: {x} vs {z}"
                    );
                }
                alone.predict(&s, end..end + 10, &mut past, &mut a).unwrap();
                follower
                    .predict(&s, end..end + 10, &mut past, &mut b)
                    .unwrap();
                for (x, z) in a.iter().zip(&b) {
                    assert!((x - z).abs() <= 1e-12, "end {end}: {x} vs {z}");
                }
            }
            end += 10;
        }
        assert!(follower.fitted && (follower.constant() - 2e-6).abs() < 1e-7);
    }

    /// The textbook row update, column by column (the reference).
    fn givens_add_one_by_one(r: &mut [f64], row: &mut [f64]) {
        let m = row.len();
        for i in 0..m {
            let x = row[i];
            if x == 0.0 {
                continue;
            }
            let d = r[i * m + i];
            let rho = (d * d + x * x).sqrt();
            let inv = 1.0 / rho;
            let (c, s) = (d * inv, x * inv);
            r[i * m + i] = rho;
            for j in i + 1..m {
                let (a, b) = (r[i * m + j], row[j]);
                r[i * m + j] = c * a + s * b;
                row[j] = c * b - s * a;
            }
        }
    }

    #[test]
    fn rows_rotated_in_as_a_wavefront_equal_rows_rotated_in_one_by_one_bit_for_bit() {
        use rand::{Rng, SeedableRng};
        use rand_chacha::ChaCha8Rng;
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for (m, g) in [(5, 1), (5, 4), (6, 3), (4, 4), (6, 7)] {
            let (mut a, mut b) = (vec![0.0; m * m], vec![0.0; m * m]);
            for round in 0..20 {
                // some zero entries (skipped rotations), leading ones included
                let mut rows: Vec<f64> = (0..g * m)
                    .map(|i| {
                        if (i + round) % 6 == 0 {
                            0.0
                        } else {
                            rng.random_range(-1.0..1.0)
                        }
                    })
                    .collect();
                for row in rows.clone().chunks_exact(m) {
                    givens_add_one_by_one(&mut a, &mut row.to_vec());
                }
                givens_add_rows(&mut b, &mut rows, m);
            }
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&a), bits(&b), "m {m}, group {g}");
        }
        // eliminating fewer columns than the rows hold: the ridge rows of
        // `solve_ridge`, the last column rotated along
        let w = 4;
        let mut r: Vec<f64> = (0..w * w)
            .map(|i| if i / w <= i % w { 1.0 + i as f64 } else { 0.0 })
            .collect();
        let mut r1 = r.clone();
        let mut rows = vec![0.0; 3 * w];
        for k in 0..3 {
            rows[k * w + k] = 0.5;
        }
        for row in rows.clone().chunks_exact(w) {
            let mut row = row.to_vec();
            for i in 0..3 {
                let x = row[i];
                if x == 0.0 {
                    continue;
                }
                let d = r1[i * w + i];
                let rho = (d * d + x * x).sqrt();
                let (c, s) = (d / rho, x / rho);
                r1[i * w + i] = rho;
                for j in i + 1..w {
                    let (p, q) = (r1[i * w + j], row[j]);
                    r1[i * w + j] = c * p + s * q;
                    row[j] = c * q - s * p;
                }
            }
        }
        givens_add_rows_upto(&mut r, &mut rows, w, 3);
        for (x, y) in r.iter().zip(&r1) {
            assert!((x - y).abs() <= 1e-15 * y.abs().max(1.0), "{x} vs {y}");
        }
        assert_eq!(r[3 * w + 3], 16.0, "the last row is not touched");
    }

    #[test]
    fn merging_two_factors_gives_the_factor_of_all_their_rows() {
        use rand::{Rng, SeedableRng};
        use rand_chacha::ChaCha8Rng;
        // seeded rows, some with zeros (skipped rotations); the newer block
        // with fewer rows than columns, its first row without a lead entry
        let m = 5;
        let mut rng = ChaCha8Rng::seed_from_u64(12);
        for (n_old, n_new) in [(0, 3), (7, 0), (50, 2), (50, 49), (6, 1)] {
            let mut row_of = |k: usize| -> Vec<f64> {
                (0..m)
                    .map(|j| {
                        if (k + j).is_multiple_of(7) {
                            0.0
                        } else {
                            rng.random_range(-0.5..0.5)
                        }
                    })
                    .collect()
            };
            let rows: Vec<Vec<f64>> = (0..n_old + n_new).map(&mut row_of).collect();
            let (mut old, mut new, mut all) =
                (vec![0.0; m * m], vec![0.0; m * m], vec![0.0; m * m]);
            for (k, r) in rows.iter().enumerate() {
                let target = if k < n_old { &mut old } else { &mut new };
                givens_add(target, &mut r.clone());
                givens_add(&mut all, &mut r.clone());
            }
            let (mut merged, mut scratch) = (vec![0.0; m * m], vec![0.0; m]);
            merge(&[old, new], [n_old, n_new], &mut merged, &mut scratch);
            // the factor is unique: positive diagonals (Givens) on both sides
            for (i, (a, b)) in merged.iter().zip(&all).enumerate() {
                assert!(
                    (a - b).abs() <= 1e-12,
                    "{n_old}+{n_new} rows, entry {i}: {a} vs {b}"
                );
            }
        }
    }

    #[test]
    fn a_constant_disturbance_is_fitted_and_predicted_exactly() {
        let d = 2e-6;
        let data = system(400, d, 0.0, 1.0);
        let (p, out) = fit_predict(windowed(true), &data, 300);
        let theta = p.theta();
        for (a, b) in theta.iter().zip([0.6, 0.05, 0.05]) {
            assert!((a - b).abs() < 1e-8, "θ {theta:?}");
        }
        assert!((p.constant() - d).abs() < 1e-12, "c {}", p.constant());
        for (h, v) in out.iter().enumerate() {
            assert!((v - data.2[300 + h]).abs() < 1e-12, "step {h}");
        }
        // without the constant the same model is not exact
        let (_, plain) = fit_predict(windowed(false), &data, 300);
        let worst = plain
            .iter()
            .enumerate()
            .map(|(h, v)| (v - data.2[300 + h]).abs())
            .fold(0.0, f64::max);
        assert!(worst > 1e-8, "{worst}");
    }

    #[test]
    fn the_recursive_candidate_with_a_constant_learns_the_disturbance() {
        let d = 2e-6;
        let data = system(2000, d, 0.0, 1.0);
        let c = Candidate::Recursive {
            orders: ArxOrders::new(2, 2, 0),
            lambda: 1.0,
            bias: true,
        };
        let (p, out) = fit_predict(c, &data, 1900);
        assert!((p.constant() - d).abs() < 1e-3 * d, "c {}", p.constant());
        for (h, v) in out.iter().enumerate() {
            assert!((v - data.2[1900 + h]).abs() < 1e-9, "step {h}");
        }
    }

    #[test]
    fn an_offset_changes_nothing_and_a_unit_scales_the_constant() {
        let d = 2e-6;
        for c in [
            windowed(true),
            Candidate::Windowed {
                orders: ArxOrders::new(3, 3, 0),
                window: 60,
                ridge: 1e-3,
                bias: true,
            },
            Candidate::Recursive {
                orders: ArxOrders::new(3, 3, 0),
                lambda: 0.99,
                bias: true,
            },
        ] {
            let base = system(400, d, 0.0, 1.0);
            let (p0, out0) = fit_predict(c, &base, 300);
            let shift = 1.0;
            let (p1, out1) = fit_predict(c, &system(400, d, shift, 1.0), 300);
            assert!((p0.constant() - p1.constant()).abs() < 1e-4 * d, "{c}");
            for (a, b) in out0.iter().zip(&out1) {
                assert!((a + shift - b).abs() < 1e-9, "{c}: {a} {b}");
            }
            let unit = 1e6; // µm
            let (p2, out2) = fit_predict(c, &system(400, d, 0.0, unit), 300);
            assert!(
                (p0.constant() * unit - p2.constant()).abs() < 1e-9 * unit,
                "{c}"
            );
            for (a, b) in out0.iter().zip(&out2) {
                assert!((a * unit - b).abs() < 1e-9 * unit, "{c}: {a} {b}");
            }
        }
    }
}
