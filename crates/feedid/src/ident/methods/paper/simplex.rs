//! The paper's simplex: Nelder–Mead on the sum of squares of one window's
//! least-squares problem in the scaled basis, from zero coefficients or
//! from the previous window's fit ([`SimplexStart`](super::SimplexStart)).
//!
//! The sum of squares `‖G·z − b‖²` (`G` the `W×n` unit-norm basis) is
//! evaluated in its projected form `‖M·z − c‖² + ‖b⊥‖²` with `G = Q·M`
//! (`M` 8×n from the window's projection, `c = Qᵀb`, `b⊥ = b − Q·c`): the
//! same function (to rounding) at `8·n` instead of `W·n` multiply-adds per
//! evaluation.

use super::config::SimplexSettings;
use super::polynomials::NQ;
use crate::error::Result;
use crate::solve::{NelderMead, NelderMeadConfig, Termination};

/// A window's sum of squares in projected form.
#[derive(Debug, Clone, Copy)]
pub(super) struct Reduced<'a> {
    /// `M` (8×n, column-major).
    pub(super) m: &'a [f64],
    /// `c = Qᵀb` (8).
    pub(super) c: &'a [f64; NQ],
    /// `‖b⊥‖²`, the part no coefficient reaches.
    pub(super) rest2: f64,
    /// `‖b‖` (the data scale of the tolerances and the start steps).
    pub(super) bnorm: f64,
    /// Data rows `W` (the rounding level of the sum of squares grows with `√W`).
    pub(super) rows: usize,
    /// `M` is upper triangular (column `k` is zero below row `k`).
    pub(super) triangular: bool,
}

impl Reduced<'_> {
    /// `‖M·z − c‖` (without the constant part).
    fn distance(&self, z: &[f64]) -> f64 {
        let mut r = [0.0; NQ];
        self.residual(z, &mut r).sqrt()
    }

    /// `‖M·z − c‖²`, the residual in `r`.
    #[inline(always)]
    fn residual(&self, z: &[f64], r: &mut [f64; NQ]) -> f64 {
        for (ri, ci) in r.iter_mut().zip(self.c) {
            *ri = -ci;
        }
        for (k, zk) in z.iter().enumerate() {
            let rows = if self.triangular { k + 1 } else { NQ };
            let col = &self.m[k * NQ..k * NQ + rows];
            for (ri, mi) in r.iter_mut().zip(col) {
                *ri += mi * zk;
            }
        }
        r.iter().map(|v| v * v).sum()
    }
}

/// Minimise `‖G·z − b‖²` by the simplex from `z` (`warm`: the given start,
/// with start steps `step_rel·max(‖G·(z − z_LS,8)‖, 100·xtol_data·‖b‖)`, the
/// distance to the best polynomial of degree 7; otherwise from `z = 0` with
/// start steps `step_rel·‖b‖`, the paper's setting).
pub(super) fn simplex_fit(
    nm: &mut NelderMead,
    problem: &Reduced<'_>,
    z: &mut [f64],
    warm: bool,
    settings: &SimplexSettings,
    steps: &mut [f64],
) -> Result<(f64, usize, Termination)> {
    let bnorm = problem.bnorm;
    if !warm {
        z.fill(0.0);
    }
    if bnorm == 0.0 {
        z.fill(0.0);
        return Ok((0.0, 0, Termination::Converged));
    }
    let scale = if warm {
        problem.distance(z).max(100.0 * settings.xtol_data * bnorm)
    } else {
        bnorm
    };
    for s in steps.iter_mut() {
        *s = settings.step_rel * scale;
    }
    let cfg = NelderMeadConfig {
        xtol: settings.xtol_data * bnorm,
        ftol: settings.ftol_data * bnorm * bnorm,
        ftol_rel: 0.0,
        ftol_root: settings.noise_factor * f64::EPSILON * (problem.rows as f64).sqrt() * bnorm,
        max_iterations: settings.max_iterations,
        max_evaluations: settings.max_evaluations,
    };
    let rest2 = problem.rest2;
    let mut r = [0.0; NQ];
    let objective = |p: &[f64]| -> f64 { problem.residual(p, &mut r) + rest2 };
    let rep = nm.minimize(objective, z, steps, &cfg)?;
    Ok((rep.f, rep.iterations, rep.termination))
}
