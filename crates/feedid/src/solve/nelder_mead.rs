//! The Nelder–Mead downhill simplex minimiser (derivative free).
//!
//! Minimises `f: ℝⁿ → ℝ` by moving a simplex of `n + 1` vertices
//! `x₀ … x_n`, kept sorted so that `f(x₀) ≤ … ≤ f(x_n)`. With the centroid
//! `c = (1/n)·Σ_{i<n} x_i` of all but the worst vertex, one iteration tries
//!
//! * reflection   `x_r = c + ρ·(c − x_n)`,                 `ρ = 1`
//! * expansion    `x_e = c + χ·(x_r − c)`  if `f_r < f₀`,  `χ = 2`
//! * outside contraction `x_c = c + γ·(x_r − c)` if `f_{n−1} ≤ f_r < f_n`, `γ = 0.5`
//! * inside contraction  `x_cc = c − γ·(c − x_n)` if `f_r ≥ f_n`
//! * shrink towards the best vertex `x_i ← x₀ + σ·(x_i − x₀)`, `σ = 0.5`,
//!   when a contraction fails,
//!
//! with the standard coefficients above (Nelder & Mead 1965; the variant and
//! acceptance rules of Lagarias et al. 1998 and of SciPy's `fmin`).
//!
//! The start simplex is `x₀` plus the vertices `x₀ + h_j·e_j` with caller
//! supplied per-coordinate steps `h_j ≠ 0`. It stops, like SciPy's
//! `fmin(xatol, fatol)`, when **both** the spread of `f` over the simplex
//! `max_i |f_i − f₀| ≤ ftol` (optionally `+ ftol_rel·|f₀| + ftol_root·√|f₀|`) and the simplex size
//! `max_i ‖x_i − x₀‖_∞ ≤ xtol` hold ([`Termination::Converged`]), or at the
//! iteration or evaluation cap ([`Termination::MaxIterations`]).
//! A NaN objective value is treated as `+∞` (the point is rejected).
//!
//! [`NelderMead`] is a workspace sized for `n` unknowns; after construction a
//! minimisation allocates nothing, so one workspace can be reused for every
//! window of a sliding identification.
//!
//! References: J.A. Nelder, R. Mead, "A simplex method for function
//! minimization", Computer J. 7 (1965) 308–313; J.C. Lagarias et al.,
//! "Convergence properties of the Nelder–Mead simplex method in low
//! dimensions", SIAM J. Optim. 9 (1998) 112–147.

use crate::error::{Error, Result};
use crate::solve::Termination;

const RHO: f64 = 1.0;
const CHI: f64 = 2.0;
const GAMMA: f64 = 0.5;
const SIGMA: f64 = 0.5;

/// Tolerances and caps of the Nelder–Mead minimiser.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NelderMeadConfig {
    /// Absolute tolerance on the simplex size `max_i ‖x_i − x₀‖_∞`
    /// (units of `x`). Default `1e-4` (SciPy's `xatol`).
    pub xtol: f64,
    /// Absolute tolerance on the spread `max_i |f_i − f₀|` of the objective
    /// over the simplex (units of `f`). Default `1e-4` (SciPy's `fatol`).
    pub ftol: f64,
    /// Relative tolerance on the spread: the test is
    /// `max_i |f_i − f₀| ≤ ftol + ftol_rel·|f₀|`, which can be met when the
    /// minimum value is large compared with its rounding error. Default 0
    /// (SciPy's absolute test).
    pub ftol_rel: f64,
    /// Tolerance on the spread proportional to `√|f₀|`: the test becomes
    /// `max_i |f_i − f₀| ≤ ftol + ftol_rel·|f₀| + ftol_root·√|f₀|`. Meant
    /// for sums of squares `f = ‖r‖²`, whose rounding error is
    /// `≈ 2‖r‖·δr`, i.e. proportional to `√f`. Default 0.
    pub ftol_root: f64,
    /// Iteration cap. Default 1000.
    pub max_iterations: usize,
    /// Objective-evaluation cap. Default 2000.
    pub max_evaluations: usize,
}

impl Default for NelderMeadConfig {
    fn default() -> Self {
        Self {
            xtol: 1e-4,
            ftol: 1e-4,
            ftol_rel: 0.0,
            ftol_root: 0.0,
            max_iterations: 1000,
            max_evaluations: 2000,
        }
    }
}

/// Outcome of a Nelder–Mead minimisation (the minimiser itself is written
/// into the caller's `x`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NelderMeadReport {
    /// Objective value at the returned point.
    pub f: f64,
    /// Iterations performed.
    pub iterations: usize,
    /// Objective evaluations performed.
    pub evaluations: usize,
    /// Why it stopped.
    pub termination: Termination,
}

/// Reusable Nelder–Mead workspace for `n` unknowns.
#[derive(Debug, Clone)]
pub struct NelderMead {
    n: usize,
    /// `(n+1)` vertices, row `i` = `simplex[i·n..(i+1)·n]`, objective `fvals[i]`.
    simplex: Vec<f64>,
    fvals: Vec<f64>,
    /// Vertex indices sorted by objective value (best first).
    order: Vec<usize>,
    centroid: Vec<f64>,
    xr: Vec<f64>,
    xe: Vec<f64>,
    row: Vec<f64>,
}

impl NelderMead {
    /// Workspace for `n ≥ 1` unknowns.
    pub fn new(n: usize) -> Self {
        Self {
            n,
            simplex: vec![0.0; (n + 1) * n],
            fvals: vec![0.0; n + 1],
            order: (0..=n).collect(),
            centroid: vec![0.0; n],
            xr: vec![0.0; n],
            xe: vec![0.0; n],
            row: vec![0.0; n],
        }
    }

    /// Number of unknowns.
    pub fn dim(&self) -> usize {
        self.n
    }

    /// Minimise `f` starting at `x` with per-coordinate start steps `steps`;
    /// the best point found is written back into `x`.
    ///
    /// Errors: [`Error::LengthMismatch`] if `x` or `steps` do not have length
    /// [`NelderMead::dim`], [`Error::InvalidParameter`] for a zero or
    /// non-finite step, non-finite start or non-positive caps,
    /// [`Error::NonFinite`] if `f(x₀)` is not finite.
    ///
    /// ```
    /// use feedid::solve::{NelderMead, NelderMeadConfig, Termination};
    /// let mut nm = NelderMead::new(2);
    /// let mut x = [0.0, 0.0];
    /// let cfg = NelderMeadConfig { xtol: 1e-8, ftol: 1e-12, ..Default::default() };
    /// let rep = nm
    ///     .minimize(|p: &[f64]| (p[0] - 1.0).powi(2) + 4.0 * (p[1] + 2.0).powi(2), &mut x, &[0.5, 0.5], &cfg)
    ///     .unwrap();
    /// assert_eq!(rep.termination, Termination::Converged);
    /// assert!((x[0] - 1.0).abs() < 1e-6 && (x[1] + 2.0).abs() < 1e-6);
    /// ```
    pub fn minimize<F: FnMut(&[f64]) -> f64>(
        &mut self,
        mut f: F,
        x: &mut [f64],
        steps: &[f64],
        config: &NelderMeadConfig,
    ) -> Result<NelderMeadReport> {
        let n = self.n;
        if x.len() != n {
            return Err(Error::LengthMismatch {
                what: "Nelder-Mead start point",
                expected: n,
                actual: x.len(),
            });
        }
        if steps.len() != n {
            return Err(Error::LengthMismatch {
                what: "Nelder-Mead steps",
                expected: n,
                actual: steps.len(),
            });
        }
        if n == 0 {
            return Err(Error::TooFewSamples {
                what: "Nelder-Mead unknowns",
                needed: 1,
                actual: 0,
            });
        }
        if let Some(&h) = steps.iter().find(|h| !(h.is_finite() && **h != 0.0)) {
            return Err(Error::InvalidParameter {
                name: "Nelder-Mead step",
                value: h,
                reason: "must be finite and non-zero",
            });
        }
        if let Some(&v) = x.iter().find(|v| !v.is_finite()) {
            return Err(Error::InvalidParameter {
                name: "Nelder-Mead start point",
                value: v,
                reason: "must be finite",
            });
        }
        if !(config.xtol >= 0.0
            && config.ftol >= 0.0
            && config.ftol_rel >= 0.0
            && config.ftol_root >= 0.0)
        {
            return Err(Error::InvalidParameter {
                name: "Nelder-Mead tolerance",
                value: config
                    .xtol
                    .min(config.ftol)
                    .min(config.ftol_rel)
                    .min(config.ftol_root),
                reason: "must be >= 0",
            });
        }
        if config.max_iterations == 0 || config.max_evaluations == 0 {
            return Err(Error::InvalidParameter {
                name: "Nelder-Mead iteration cap",
                value: config.max_iterations.min(config.max_evaluations) as f64,
                reason: "must be >= 1",
            });
        }
        let mut eval = |p: &[f64], count: &mut usize| -> f64 {
            *count += 1;
            let v = f(p);
            if v.is_nan() {
                f64::INFINITY
            } else {
                v
            }
        };

        let mut evaluations = 0;
        // start simplex (vertex rows in place; `order` sorts them by f)
        self.simplex[..n].copy_from_slice(x);
        self.fvals[0] = eval(x, &mut evaluations);
        if !self.fvals[0].is_finite() {
            return Err(Error::NonFinite {
                channel: "Nelder-Mead objective at the start point".to_string(),
                index: 0,
                value: self.fvals[0],
            });
        }
        for j in 0..n {
            let row = &mut self.simplex[(j + 1) * n..(j + 2) * n];
            row.copy_from_slice(x);
            row[j] += steps[j];
            self.fvals[j + 1] = eval(&self.simplex[(j + 1) * n..(j + 2) * n], &mut evaluations);
        }
        for (i, o) in self.order.iter_mut().enumerate() {
            *o = i;
        }
        self.sort();

        let mut iterations = 0;
        let termination = loop {
            if self.converged(config) {
                break Termination::Converged;
            }
            if iterations >= config.max_iterations || evaluations >= config.max_evaluations {
                break Termination::MaxIterations;
            }
            iterations += 1;

            // centroid of the n best vertices
            for v in self.centroid.iter_mut() {
                *v = 0.0;
            }
            for &i in &self.order[..n] {
                for (c, s) in self
                    .centroid
                    .iter_mut()
                    .zip(&self.simplex[i * n..(i + 1) * n])
                {
                    *c += s;
                }
            }
            let inv_n = 1.0 / n as f64;
            for c in self.centroid.iter_mut() {
                *c *= inv_n;
            }
            let iw = self.order[n];
            let worst = iw * n..(iw + 1) * n;
            for ((r, c), w) in self
                .xr
                .iter_mut()
                .zip(&self.centroid)
                .zip(&self.simplex[worst.clone()])
            {
                *r = c + RHO * (c - w);
            }
            let fr = eval(&self.xr, &mut evaluations);
            let f0 = self.fvals[self.order[0]];
            let fworst = self.fvals[iw];
            let fsecond = self.fvals[self.order[n - 1]];

            if fr < f0 {
                for ((e, c), r) in self.xe.iter_mut().zip(&self.centroid).zip(&self.xr) {
                    *e = c + CHI * (r - c);
                }
                let fe = eval(&self.xe, &mut evaluations);
                if fe < fr {
                    self.simplex[worst].copy_from_slice(&self.xe);
                    self.fvals[iw] = fe;
                } else {
                    self.simplex[worst].copy_from_slice(&self.xr);
                    self.fvals[iw] = fr;
                }
            } else if fr < fsecond {
                self.simplex[worst].copy_from_slice(&self.xr);
                self.fvals[iw] = fr;
            } else {
                let mut do_shrink = false;
                if fr < fworst {
                    // outside contraction
                    for ((e, c), r) in self.xe.iter_mut().zip(&self.centroid).zip(&self.xr) {
                        *e = c + GAMMA * (r - c);
                    }
                    let fc = eval(&self.xe, &mut evaluations);
                    if fc <= fr {
                        self.simplex[worst].copy_from_slice(&self.xe);
                        self.fvals[iw] = fc;
                    } else {
                        do_shrink = true;
                    }
                } else {
                    // inside contraction
                    for ((e, c), w) in self
                        .xe
                        .iter_mut()
                        .zip(&self.centroid)
                        .zip(&self.simplex[worst.clone()])
                    {
                        *e = c - GAMMA * (c - w);
                    }
                    let fcc = eval(&self.xe, &mut evaluations);
                    if fcc < fworst {
                        self.simplex[worst].copy_from_slice(&self.xe);
                        self.fvals[iw] = fcc;
                    } else {
                        do_shrink = true;
                    }
                }
                if do_shrink {
                    let ib = self.order[0];
                    self.row
                        .copy_from_slice(&self.simplex[ib * n..(ib + 1) * n]);
                    for i in 0..=n {
                        if i == ib {
                            continue;
                        }
                        for (v, b) in self.simplex[i * n..(i + 1) * n].iter_mut().zip(&self.row) {
                            *v = b + SIGMA * (*v - b);
                        }
                        self.fvals[i] = eval(&self.simplex[i * n..(i + 1) * n], &mut evaluations);
                    }
                    self.sort();
                    continue;
                }
            }
            // only the worst vertex changed: move it to its place (what the
            // full insertion sort would do, in O(n))
            self.insert_last();
        };
        let ib = self.order[0];
        x.copy_from_slice(&self.simplex[ib * n..(ib + 1) * n]);
        Ok(NelderMeadReport {
            f: self.fvals[ib],
            iterations,
            evaluations,
            termination,
        })
    }

    /// Both tolerances met.
    fn converged(&self, config: &NelderMeadConfig) -> bool {
        let n = self.n;
        let ib = self.order[0];
        let f0 = self.fvals[ib];
        let ftol = config.ftol + config.ftol_rel * f0.abs() + config.ftol_root * f0.abs().sqrt();
        let outside = |d: f64, tol: f64| d.is_nan() || d > tol;
        if self.fvals.iter().any(|&fi| outside((fi - f0).abs(), ftol)) {
            return false;
        }
        let best = &self.simplex[ib * n..(ib + 1) * n];
        for i in 0..=n {
            let row = &self.simplex[i * n..(i + 1) * n];
            if row
                .iter()
                .zip(best)
                .any(|(a, b)| outside((a - b).abs(), config.xtol))
            {
                return false;
            }
        }
        true
    }

    /// Re-sort after only the vertex `order[n]` changed (stable: the same
    /// order as [`Self::sort`]).
    fn insert_last(&mut self) {
        let mut k = self.n;
        let v = self.fvals[self.order[k]];
        while k > 0 && v < self.fvals[self.order[k - 1]] {
            self.order.swap(k, k - 1);
            k -= 1;
        }
    }

    /// Stable insertion sort of the vertex indices by objective value.
    fn sort(&mut self) {
        let n = self.n;
        for i in 1..=n {
            let mut k = i;
            while k > 0 && self.fvals[self.order[k]] < self.fvals[self.order[k - 1]] {
                self.order.swap(k, k - 1);
                k -= 1;
            }
        }
    }
}

/// Convenience wrapper: minimise `f` from `x0` with a fresh workspace,
/// returning the minimiser and the report (allocates).
pub fn nelder_mead<F: FnMut(&[f64]) -> f64>(
    f: F,
    x0: &[f64],
    steps: &[f64],
    config: &NelderMeadConfig,
) -> Result<(Vec<f64>, NelderMeadReport)> {
    let mut x = x0.to_vec();
    let report = NelderMead::new(x0.len()).minimize(f, &mut x, steps, config)?;
    Ok((x, report))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rosenbrock(p: &[f64]) -> f64 {
        100.0 * (p[1] - p[0] * p[0]).powi(2) + (1.0 - p[0]).powi(2)
    }

    #[test]
    fn rosenbrock_minimum_is_found_from_classic_start() {
        let cfg = NelderMeadConfig {
            xtol: 1e-10,
            ftol: 1e-14,
            ftol_rel: 0.0,
            ftol_root: 0.0,
            max_iterations: 5000,
            max_evaluations: 10000,
        };
        let (x, rep) = nelder_mead(rosenbrock, &[-1.2, 1.0], &[0.1, 0.1], &cfg).unwrap();
        assert_eq!(rep.termination, Termination::Converged);
        assert!(
            (x[0] - 1.0).abs() < 1e-7 && (x[1] - 1.0).abs() < 1e-7,
            "{x:?}"
        );
        assert!(rep.f < 1e-14);
        assert!(rep.evaluations >= rep.iterations);
    }

    #[test]
    fn scipy_default_tolerances_reproduce_known_rosenbrock_accuracy() {
        // SciPy's fmin(rosen, [-1.2, 1]) with xatol = fatol = 1e-4 and the
        // 5 % start steps ends within ~1e-4 of (1, 1).
        let cfg = NelderMeadConfig::default();
        let (x, rep) = nelder_mead(rosenbrock, &[-1.2, 1.0], &[-0.06, 0.05], &cfg).unwrap();
        assert_eq!(rep.termination, Termination::Converged);
        assert!(
            (x[0] - 1.0).abs() < 1e-3 && (x[1] - 1.0).abs() < 1e-3,
            "{x:?}"
        );
    }

    #[test]
    fn anisotropic_quadratic_minimum_is_found_in_five_dimensions() {
        let centre = [1.0, -2.0, 3.0, 0.5, -0.25];
        let weights = [1.0, 10.0, 0.1, 3.0, 30.0];
        let f = |p: &[f64]| -> f64 {
            p.iter()
                .zip(&centre)
                .zip(&weights)
                .map(|((x, c), w)| w * (x - c) * (x - c))
                .sum::<f64>()
                + 0.5 * (p[0] - centre[0]) * (p[1] - centre[1])
        };
        let cfg = NelderMeadConfig {
            xtol: 1e-9,
            ftol: 1e-16,
            ftol_rel: 0.0,
            ftol_root: 0.0,
            max_iterations: 20000,
            max_evaluations: 40000,
        };
        let (x, rep) = nelder_mead(f, &[0.0; 5], &[0.5; 5], &cfg).unwrap();
        assert_eq!(rep.termination, Termination::Converged);
        for (xi, ci) in x.iter().zip(&centre) {
            assert!((xi - ci).abs() < 1e-7, "{x:?}");
        }
    }

    #[test]
    fn iteration_cap_stops_with_max_iterations() {
        let cfg = NelderMeadConfig {
            xtol: 1e-12,
            ftol: 1e-12,
            ftol_rel: 0.0,
            ftol_root: 0.0,
            max_iterations: 10,
            max_evaluations: 1000,
        };
        let (_, rep) = nelder_mead(rosenbrock, &[-1.2, 1.0], &[0.1, 0.1], &cfg).unwrap();
        assert_eq!(rep.termination, Termination::MaxIterations);
        assert_eq!(rep.iterations, 10);
        let cfg = NelderMeadConfig {
            max_iterations: 1000,
            max_evaluations: 20,
            ..cfg
        };
        let (_, rep) = nelder_mead(rosenbrock, &[-1.2, 1.0], &[0.1, 0.1], &cfg).unwrap();
        assert_eq!(rep.termination, Termination::MaxIterations);
        assert!(rep.evaluations >= 20 && rep.evaluations < 20 + 4);
    }

    #[test]
    fn result_never_worse_than_start_and_workspace_is_reusable() {
        let mut nm = NelderMead::new(2);
        let cfg = NelderMeadConfig::default();
        for start in [[-1.2, 1.0], [2.0, 2.0], [0.0, 0.0]] {
            let mut x = start;
            let rep = nm.minimize(rosenbrock, &mut x, &[0.1, 0.1], &cfg).unwrap();
            assert!(rep.f <= rosenbrock(&start));
            assert_eq!(rep.f, rosenbrock(&x));
        }
    }

    #[test]
    fn nan_objective_is_rejected_not_returned() {
        // NaN outside the unit disc; the minimum (0.3, 0.3) is inside
        let f = |p: &[f64]| {
            if p[0] * p[0] + p[1] * p[1] > 1.0 {
                f64::NAN
            } else {
                (p[0] - 0.3).powi(2) + (p[1] - 0.3).powi(2)
            }
        };
        let cfg = NelderMeadConfig {
            xtol: 1e-8,
            ftol: 1e-14,
            ..Default::default()
        };
        let (x, rep) = nelder_mead(f, &[0.0, 0.0], &[0.8, 0.8], &cfg).unwrap();
        assert!(rep.f.is_finite());
        assert!((x[0] - 0.3).abs() < 1e-6 && (x[1] - 0.3).abs() < 1e-6);
    }

    #[test]
    fn relative_function_tolerance_stops_at_a_large_minimum_value() {
        // minimum value 1e6: an absolute spread of 1e-12 is below its rounding
        let f = |p: &[f64]| 1e6 + (p[0] - 1.0).powi(2) + (p[1] - 2.0).powi(2);
        let strict = NelderMeadConfig {
            xtol: 1e-9,
            ftol: 1e-12,
            ftol_rel: 0.0,
            ftol_root: 0.0,
            max_iterations: 5000,
            max_evaluations: 10000,
        };
        let (_, rep) = nelder_mead(f, &[0.0, 0.0], &[0.5, 0.5], &strict).unwrap();
        let relative = NelderMeadConfig {
            ftol_rel: 1e-14,
            ..strict
        };
        let (x, rep_rel) = nelder_mead(f, &[0.0, 0.0], &[0.5, 0.5], &relative).unwrap();
        assert_eq!(rep_rel.termination, Termination::Converged);
        assert!(rep_rel.iterations <= rep.iterations);
        assert!(
            (x[0] - 1.0).abs() < 1e-4 && (x[1] - 2.0).abs() < 1e-4,
            "{x:?}"
        );
    }

    #[test]
    fn invalid_inputs_are_errors() {
        let cfg = NelderMeadConfig::default();
        assert!(matches!(
            nelder_mead(rosenbrock, &[0.0, 0.0], &[0.1, 0.0], &cfg),
            Err(Error::InvalidParameter { .. })
        ));
        assert!(matches!(
            nelder_mead(rosenbrock, &[0.0, 0.0], &[0.1], &cfg),
            Err(Error::LengthMismatch { .. })
        ));
        assert!(matches!(
            nelder_mead(|_: &[f64]| f64::INFINITY, &[0.0], &[0.1], &cfg),
            Err(Error::NonFinite { .. })
        ));
    }
}
