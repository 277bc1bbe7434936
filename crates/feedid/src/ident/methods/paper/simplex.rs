//! The paper's simplex: Nelder–Mead on the sum of squares of one window's
//! least-squares problem in the scaled basis, from zero coefficients.

use super::config::SimplexSettings;
use crate::error::Result;
use crate::solve::{NelderMead, NelderMeadConfig, Termination};

/// Minimise `‖G·z − b‖²` (G column-major `m×n`, unit-norm columns) by the simplex from `z = 0`.
#[allow(clippy::too_many_arguments)]
pub(super) fn simplex_fit(
    nm: &mut NelderMead,
    g: &[f64],
    b: &[f64],
    resid: &mut [f64],
    z: &mut [f64],
    settings: &SimplexSettings,
    steps: &mut [f64],
) -> Result<(f64, usize, Termination)> {
    let m = b.len();
    let n = z.len();
    let bnorm = b.iter().map(|v| v * v).sum::<f64>().sqrt();
    for v in z.iter_mut() {
        *v = 0.0;
    }
    if bnorm == 0.0 {
        return Ok((0.0, 0, Termination::Converged));
    }
    for s in steps.iter_mut() {
        *s = settings.step_rel * bnorm;
    }
    let cfg = NelderMeadConfig {
        xtol: settings.xtol_data * bnorm,
        ftol: settings.ftol_data * bnorm * bnorm,
        ftol_rel: 0.0,
        ftol_root: settings.noise_factor * f64::EPSILON * (m as f64).sqrt() * bnorm,
        max_iterations: settings.max_iterations,
        max_evaluations: settings.max_evaluations,
    };
    let objective = |p: &[f64]| -> f64 {
        for (r, bi) in resid.iter_mut().zip(b) {
            *r = -bi;
        }
        for (k, pk) in p.iter().enumerate() {
            let col = &g[k * m..(k + 1) * m];
            for (r, gi) in resid.iter_mut().zip(col) {
                *r += gi * pk;
            }
        }
        resid.iter().map(|r| r * r).sum()
    };
    let rep = nm.minimize(objective, z, &steps[..n], &cfg)?;
    Ok((rep.f, rep.iterations, rep.termination))
}
