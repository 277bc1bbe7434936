//! Levenberg–Marquardt for nonlinear least squares `min_p ½‖r(p)‖²`,
//! `r: ℝⁿ → ℝᵐ`.
//!
//! Each iteration solves the damped linearised problem
//!
//! ```text
//!     min_δ ‖J·δ + r‖² + μ‖D·δ‖²   ⇔   [J; √μ·D]·δ ≈ [−r; 0]
//! ```
//!
//! by Householder QR (no normal equations): the QR `J·D_s⁻¹·P = Q·R` of the
//! Jacobian once per iteration ([`lstsq_in_place`]), then for every damping
//! tried the small `2n×n` problem `[R; √μ·D·D_s⁻¹·P]·z ≈ [Qᵀ(−r); 0]` (the
//! same step: `Q` is orthogonal on the first block; MINPACK's `lmpar`
//! works on `R` the same way), with Marquardt's diagonal scaling `D = diag(d_j)`,
//! `d_j = max(d_j, ‖J_j‖)` over the iterations (Moré 1978; a zero column
//! gets `d_j = 1`). A step is accepted if it decreases `‖r‖`; the damping is
//! updated from the gain ratio `ϱ = (‖r‖² − ‖r_new‖²)/(‖r‖² − ‖r + Jδ‖²)`
//! (Nielsen 1999): on success `μ ← μ·max(1/3, 1 − (2ϱ − 1)³)`, `ν ← 2`; on
//! failure `μ ← μ·ν`, `ν ← 2ν`. The initial damping is
//! `μ₀ = initial_damping` (relative, since `D` carries the column norms).
//!
//! The Jacobian (column-major `m×n`) comes from a user closure or from
//! forward differences with scaled steps `h_j = √ε_fd·|p_j|` (`√ε_fd` if
//! `p_j = 0`), as in MINPACK's `lmdif`.
//!
//! Convergence (MINPACK conventions), [`Termination::Converged`] when after an
//! accepted step
//! * `ftol`: both the actual and the predicted relative reduction of `‖r‖²` are ≤ `ftol`,
//! * `xtol`: `‖D·δ‖ ≤ xtol·‖D·p‖`,
//! * `gtol`: `max_j |J_jᵀ r| / (‖J_j‖·‖r‖) ≤ gtol` (checked before each step),
//! * or `‖r‖ = 0`; [`Termination::MaxIterations`] at the iteration cap.
//!
//! The report gives the final residual norm; the workspace keeps the
//! residuals and the Jacobian at the returned parameters
//! ([`LevenbergMarquardt::jacobian`]) for standard errors (unless
//! [`LmConfig::final_jacobian`] is off).
//!
//! References: K. Levenberg (1944), D.W. Marquardt (1963); J.J. Moré, "The
//! Levenberg–Marquardt algorithm: implementation and theory", LNM 630 (1978);
//! H.B. Nielsen, "Damping parameter in Marquardt's method", IMM-REP-1999-05.

use crate::error::{Error, Result};
use crate::solve::qr::{lstsq_in_place, LstsqOptions, QrWorkspace};
use crate::solve::Termination;

/// Tolerances and caps of Levenberg–Marquardt.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LmConfig {
    /// Relative reduction tolerance on `‖r‖²`. Default `1e-12`.
    pub ftol: f64,
    /// Relative step tolerance on `‖D·δ‖/‖D·p‖`. Default `1e-12`.
    pub xtol: f64,
    /// Gradient (cosine) tolerance. Default `1e-12`.
    pub gtol: f64,
    /// Iteration cap (Jacobian evaluations). Default 200.
    pub max_iterations: usize,
    /// Initial relative damping `μ₀`. Default `1e-3`.
    pub initial_damping: f64,
    /// Relative forward-difference step `√ε_fd`. Default `√ε ≈ 1.49e-8`.
    pub fd_step: f64,
    /// Evaluate the Jacobian at the returned parameters when the last
    /// accepted step moved them (for standard errors,
    /// [`LevenbergMarquardt::jacobian`]); default true. `false` saves `n`
    /// residual evaluations (forward differences) per run and leaves the
    /// Jacobian of the last iteration in the workspace.
    pub final_jacobian: bool,
}

impl Default for LmConfig {
    fn default() -> Self {
        Self {
            ftol: 1e-12,
            xtol: 1e-12,
            gtol: 1e-12,
            max_iterations: 200,
            initial_damping: 1e-3,
            fd_step: f64::EPSILON.sqrt(),
            final_jacobian: true,
        }
    }
}

/// Outcome of a Levenberg–Marquardt run (the parameters are written into the caller's `p`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LmReport {
    /// Final residual norm `‖r(p)‖₂`.
    pub residual_norm: f64,
    /// Iterations (Jacobian evaluations) performed.
    pub iterations: usize,
    /// Residual evaluations performed (including those for finite differences).
    pub evaluations: usize,
    /// Why it stopped.
    pub termination: Termination,
}

/// Reusable Levenberg–Marquardt workspace for `m` residuals and `n` parameters.
#[derive(Debug, Clone)]
pub struct LevenbergMarquardt {
    m: usize,
    n: usize,
    r: Vec<f64>,
    r_new: Vec<f64>,
    r_tmp: Vec<f64>,
    jac: Vec<f64>,
    jac_at_p: bool,
    /// The QR of the Jacobian (`m×n`) and `Qᵀ(−r)` (`m`).
    jqr: Vec<f64>,
    jrhs: Vec<f64>,
    /// The damped `2n×n` problem of a step and its right-hand side.
    aug: Vec<f64>,
    rhs: Vec<f64>,
    delta: Vec<f64>,
    p_new: Vec<f64>,
    diag: Vec<f64>,
    qr: QrWorkspace,
    qr_small: QrWorkspace,
}

impl LevenbergMarquardt {
    /// Workspace for `m` residuals and `n` parameters.
    pub fn new(m: usize, n: usize) -> Self {
        Self {
            m,
            n,
            r: vec![0.0; m],
            r_new: vec![0.0; m],
            r_tmp: vec![0.0; m],
            jac: vec![0.0; m * n],
            jac_at_p: false,
            jqr: vec![0.0; m * n],
            jrhs: vec![0.0; m],
            aug: vec![0.0; 2 * n * n],
            rhs: vec![0.0; 2 * n],
            delta: vec![0.0; n],
            p_new: vec![0.0; n],
            diag: vec![0.0; n],
            qr: QrWorkspace::new(n),
            qr_small: QrWorkspace::new(n),
        }
    }

    /// Jacobian (column-major `m×n`) at the parameters returned by the last run.
    pub fn jacobian(&self) -> &[f64] {
        &self.jac
    }

    /// Residuals at the parameters returned by the last run.
    pub fn residuals(&self) -> &[f64] {
        &self.r
    }

    /// Minimise `‖r(p)‖²` from `p` with a forward-difference Jacobian.
    ///
    /// `residual(p, r)` writes the `m` residuals. See [`Self::minimize_with_jacobian`].
    pub fn minimize<R>(&mut self, residual: R, p: &mut [f64], config: &LmConfig) -> Result<LmReport>
    where
        R: FnMut(&[f64], &mut [f64]),
    {
        self.run(residual, None::<fn(&[f64], &mut [f64])>, p, config)
    }

    /// Minimise `‖r(p)‖²` from `p` with an analytic Jacobian; the result is
    /// written into `p`.
    ///
    /// `residual(p, r)` writes the `m` residuals, `jacobian(p, j)` the
    /// column-major `m×n` Jacobian `∂r_i/∂p_j` at `j[i + j·m]`.
    ///
    /// Errors: [`Error::LengthMismatch`] for a wrong `p` length,
    /// [`Error::NonFinite`] for a non-finite start residual or Jacobian.
    ///
    /// ```
    /// use feedid::solve::{LevenbergMarquardt, LmConfig, Termination};
    /// // fit y = a·exp(−k·t) through noise-free data
    /// let t: Vec<f64> = (0..10).map(|i| i as f64 * 0.2).collect();
    /// let y: Vec<f64> = t.iter().map(|t| 2.0 * (-1.5 * t).exp()).collect();
    /// let mut lm = LevenbergMarquardt::new(10, 2);
    /// let mut p = [1.0, 1.0];
    /// let rep = lm
    ///     .minimize(
    ///         |p: &[f64], r: &mut [f64]| {
    ///             for i in 0..10 {
    ///                 r[i] = p[0] * (-p[1] * t[i]).exp() - y[i];
    ///             }
    ///         },
    ///         &mut p,
    ///         &LmConfig::default(),
    ///     )
    ///     .unwrap();
    /// assert_eq!(rep.termination, Termination::Converged);
    /// assert!((p[0] - 2.0).abs() < 1e-9 && (p[1] - 1.5).abs() < 1e-9);
    /// ```
    pub fn minimize_with_jacobian<R, J>(
        &mut self,
        residual: R,
        jacobian: J,
        p: &mut [f64],
        config: &LmConfig,
    ) -> Result<LmReport>
    where
        R: FnMut(&[f64], &mut [f64]),
        J: FnMut(&[f64], &mut [f64]),
    {
        self.run(residual, Some(jacobian), p, config)
    }

    fn run<R, J>(
        &mut self,
        mut residual: R,
        mut jacobian: Option<J>,
        p: &mut [f64],
        config: &LmConfig,
    ) -> Result<LmReport>
    where
        R: FnMut(&[f64], &mut [f64]),
        J: FnMut(&[f64], &mut [f64]),
    {
        let (m, n) = (self.m, self.n);
        if p.len() != n {
            return Err(Error::LengthMismatch {
                what: "Levenberg-Marquardt parameters",
                expected: n,
                actual: p.len(),
            });
        }
        if n == 0 || m == 0 {
            return Err(Error::TooFewSamples {
                what: "Levenberg-Marquardt residuals and parameters",
                needed: 1,
                actual: 0,
            });
        }
        if !(config.initial_damping > 0.0 && config.fd_step > 0.0) {
            return Err(Error::InvalidParameter {
                name: "initial_damping / fd_step",
                value: config.initial_damping.min(config.fd_step),
                reason: "must be > 0",
            });
        }
        let mut evaluations = 0;
        residual(p, &mut self.r);
        evaluations += 1;
        if let Some((i, &v)) = self.r.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(Error::NonFinite {
                channel: "Levenberg-Marquardt residual at the start point".to_string(),
                index: i,
                value: v,
            });
        }
        let mut cost = sumsq(&self.r);
        let mut mu = config.initial_damping;
        let mut nu = 2.0;
        for d in self.diag.iter_mut() {
            *d = 0.0;
        }
        self.jac_at_p = false;
        let mut iterations = 0;

        let termination = 'outer: loop {
            if cost == 0.0 {
                break Termination::Converged;
            }
            if iterations >= config.max_iterations {
                break Termination::MaxIterations;
            }
            iterations += 1;
            // Jacobian at p
            match jacobian.as_mut() {
                Some(jf) => jf(p, &mut self.jac),
                None => {
                    for j in 0..n {
                        let pj = p[j];
                        let h = if pj == 0.0 {
                            config.fd_step
                        } else {
                            config.fd_step * pj.abs()
                        };
                        p[j] = pj + h;
                        let h = p[j] - pj; // exactly representable step
                        residual(p, &mut self.r_tmp);
                        evaluations += 1;
                        p[j] = pj;
                        for i in 0..m {
                            self.jac[i + j * m] = (self.r_tmp[i] - self.r[i]) / h;
                        }
                    }
                }
            }
            self.jac_at_p = true;
            if let Some((i, &v)) = self.jac.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                return Err(Error::NonFinite {
                    channel: "Levenberg-Marquardt Jacobian".to_string(),
                    index: i,
                    value: v,
                });
            }
            // scaling and gradient test
            let rnorm = cost.sqrt();
            let mut gmax: f64 = 0.0;
            for j in 0..n {
                let col = &self.jac[j * m..(j + 1) * m];
                let cn = col.iter().map(|v| v * v).sum::<f64>().sqrt();
                self.diag[j] = self.diag[j].max(if cn > 0.0 { cn } else { 1.0 });
                if cn > 0.0 {
                    let g: f64 = col.iter().zip(&self.r).map(|(a, b)| a * b).sum();
                    gmax = gmax.max(g.abs() / (cn * rnorm));
                }
            }
            if gmax <= config.gtol {
                break Termination::Converged;
            }
            // QR of J once: J·D_s⁻¹·P = Q·R, c = Qᵀ(−r); ‖J·δ + r‖² = ‖R·z − c₁‖² + ‖c₂‖²
            self.jqr.copy_from_slice(&self.jac);
            for (c, r) in self.jrhs.iter_mut().zip(&self.r) {
                *c = -r;
            }
            lstsq_in_place(
                m,
                n,
                &mut self.jqr,
                &mut self.jrhs,
                &mut self.delta,
                &mut self.qr,
                &LstsqOptions::default(),
            )?;
            let kmax = m.min(n);
            let rest2: f64 = self.jrhs[kmax..].iter().map(|v| v * v).sum();
            // inner loop: find an acceptable step
            loop {
                // [R; √μ·D·D_s⁻¹·P] z ≈ [c₁; 0], δ = D_s⁻¹·P·z
                let rows = 2 * n;
                let perm = self.qr.permutation(n);
                let scale = self.qr.scales(n);
                self.aug.fill(0.0);
                for j in 0..n {
                    let col = &mut self.aug[j * rows..(j + 1) * rows];
                    // the upper triangle of R (kmax ≥ 1 rows)
                    let top = (j + 1).min(kmax);
                    col[..top].copy_from_slice(&self.jqr[j * m..j * m + top]);
                    let pj = perm[j];
                    col[n + j] = mu.sqrt() * self.diag[pj] / scale[pj];
                }
                self.rhs.fill(0.0);
                self.rhs[..kmax].copy_from_slice(&self.jrhs[..kmax]);
                let mut z = [0.0f64; 64];
                let z = if n <= z.len() {
                    &mut z[..n]
                } else {
                    &mut self.p_new[..n]
                };
                lstsq_in_place(
                    rows,
                    n,
                    &mut self.aug,
                    &mut self.rhs,
                    z,
                    &mut self.qr_small,
                    &LstsqOptions::default(),
                )?;
                // predicted ‖r + Jδ‖²
                let mut pred_cost = rest2;
                for i in 0..kmax {
                    let mut v = -self.jrhs[i];
                    for (j, zj) in z.iter().enumerate().skip(i) {
                        v += self.jqr[i + j * m] * zj;
                    }
                    pred_cost += v * v;
                }
                for k in 0..n {
                    let pj = perm[k];
                    self.delta[pj] = z[k] / scale[pj];
                }
                let dx_norm = self
                    .delta
                    .iter()
                    .zip(&self.diag)
                    .map(|(d, s)| (d * s) * (d * s))
                    .sum::<f64>()
                    .sqrt();
                let x_norm = p
                    .iter()
                    .zip(&self.diag)
                    .map(|(d, s)| (d * s) * (d * s))
                    .sum::<f64>()
                    .sqrt();
                for ((pn, pj), dj) in self.p_new.iter_mut().zip(p.iter()).zip(&self.delta) {
                    *pn = pj + dj;
                }
                residual(&self.p_new, &mut self.r_new);
                evaluations += 1;
                let new_cost = if self.r_new.iter().all(|v| v.is_finite()) {
                    sumsq(&self.r_new)
                } else {
                    f64::INFINITY
                };
                let actual = cost - new_cost;
                let predicted = cost - pred_cost;
                if new_cost < cost {
                    let rho = if predicted > 0.0 {
                        actual / predicted
                    } else {
                        1.0
                    };
                    mu *= (1.0 - (2.0 * rho - 1.0).powi(3)).max(1.0 / 3.0);
                    nu = 2.0;
                    p.copy_from_slice(&self.p_new);
                    std::mem::swap(&mut self.r, &mut self.r_new);
                    cost = new_cost;
                    self.jac_at_p = false;
                    let f_conv = actual <= config.ftol * (cost + actual)
                        && predicted.abs() <= config.ftol * (cost + actual);
                    let x_conv = dx_norm <= config.xtol * x_norm;
                    if f_conv || x_conv || cost == 0.0 {
                        break 'outer Termination::Converged;
                    }
                    continue 'outer;
                }
                // rejected
                mu *= nu;
                nu *= 2.0;
                if dx_norm <= config.xtol * x_norm || !mu.is_finite() || mu > 1e300 {
                    // no progress possible at this resolution
                    break 'outer Termination::Converged;
                }
            }
        };
        if !self.jac_at_p && config.final_jacobian {
            // refresh the Jacobian at the returned parameters
            match jacobian.as_mut() {
                Some(jf) => jf(p, &mut self.jac),
                None => {
                    for j in 0..n {
                        let pj = p[j];
                        let h = if pj == 0.0 {
                            config.fd_step
                        } else {
                            config.fd_step * pj.abs()
                        };
                        p[j] = pj + h;
                        let h = p[j] - pj;
                        residual(p, &mut self.r_tmp);
                        evaluations += 1;
                        p[j] = pj;
                        for i in 0..m {
                            self.jac[i + j * m] = (self.r_tmp[i] - self.r[i]) / h;
                        }
                    }
                }
            }
            self.jac_at_p = true;
        }
        Ok(LmReport {
            residual_norm: cost.sqrt(),
            iterations,
            evaluations,
            termination,
        })
    }
}

fn sumsq(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, Normal};

    fn decay_data(noise: f64) -> (Vec<f64>, Vec<f64>) {
        let mut rng = ChaCha8Rng::seed_from_u64(42);
        let normal = Normal::new(0.0, 1.0).unwrap();
        let t: Vec<f64> = (0..40).map(|i| i as f64 * 0.1).collect();
        let y = t
            .iter()
            .map(|&t| 3.0 * (-0.8 * t).exp() + 0.5 + noise * normal.sample(&mut rng))
            .collect();
        (t, y)
    }

    #[test]
    fn noise_free_exponential_decay_is_recovered_to_1e_10() {
        let (t, y) = decay_data(0.0);
        let mut lm = LevenbergMarquardt::new(t.len(), 3);
        let mut p = [1.0, 0.3, 0.0];
        let rep = lm
            .minimize(
                |p: &[f64], r: &mut [f64]| {
                    for i in 0..t.len() {
                        r[i] = p[0] * (-p[1] * t[i]).exp() + p[2] - y[i];
                    }
                },
                &mut p,
                &LmConfig::default(),
            )
            .unwrap();
        assert_eq!(rep.termination, Termination::Converged);
        assert!(
            (p[0] - 3.0).abs() < 1e-10 && (p[1] - 0.8).abs() < 1e-10 && (p[2] - 0.5).abs() < 1e-10,
            "{p:?}"
        );
        assert!(rep.residual_norm < 1e-10);
    }

    #[test]
    fn noisy_decay_fit_has_zero_gradient_and_matches_analytic_jacobian_run() {
        let (t, y) = decay_data(0.01);
        let m = t.len();
        let res = |p: &[f64], r: &mut [f64]| {
            for i in 0..m {
                r[i] = p[0] * (-p[1] * t[i]).exp() + p[2] - y[i];
            }
        };
        let jac = |p: &[f64], j: &mut [f64]| {
            for i in 0..m {
                let e = (-p[1] * t[i]).exp();
                j[i] = e;
                j[i + m] = -p[0] * t[i] * e;
                j[i + 2 * m] = 1.0;
            }
        };
        let mut lm = LevenbergMarquardt::new(m, 3);
        let mut p_fd = [1.0, 0.3, 0.0];
        lm.minimize(res, &mut p_fd, &LmConfig::default()).unwrap();
        let mut p_an = [1.0, 0.3, 0.0];
        let rep = lm
            .minimize_with_jacobian(res, jac, &mut p_an, &LmConfig::default())
            .unwrap();
        assert_eq!(rep.termination, Termination::Converged);
        for k in 0..3 {
            assert!((p_fd[k] - p_an[k]).abs() < 1e-7, "{p_fd:?} {p_an:?}");
        }
        // near the truth (noise 1 %)
        assert!((p_an[0] - 3.0).abs() < 0.05 && (p_an[1] - 0.8).abs() < 0.05);
        // first-order optimality: Jᵀr = 0, using the stored Jacobian
        let j = lm.jacobian();
        let r = lm.residuals();
        for k in 0..3 {
            let g: f64 = (0..m).map(|i| j[i + k * m] * r[i]).sum();
            assert!(g.abs() < 1e-9, "gradient {k}: {g}");
        }
        // stored Jacobian is the one at the solution
        let mut jref = vec![0.0; 3 * m];
        jac(&p_an, &mut jref);
        assert!(j.iter().zip(&jref).all(|(a, b)| (a - b).abs() < 1e-12));
        let rnorm = r.iter().map(|v| v * v).sum::<f64>().sqrt();
        assert!((rep.residual_norm - rnorm).abs() < 1e-15);
    }

    #[test]
    fn rosenbrock_as_least_squares_converges_to_one_one() {
        let mut lm = LevenbergMarquardt::new(2, 2);
        let mut p = [-1.2, 1.0];
        let rep = lm
            .minimize(
                |p: &[f64], r: &mut [f64]| {
                    r[0] = 10.0 * (p[1] - p[0] * p[0]);
                    r[1] = 1.0 - p[0];
                },
                &mut p,
                &LmConfig::default(),
            )
            .unwrap();
        assert_eq!(rep.termination, Termination::Converged);
        assert!(
            (p[0] - 1.0).abs() < 1e-10 && (p[1] - 1.0).abs() < 1e-10,
            "{p:?}"
        );
    }

    #[test]
    fn iteration_cap_is_reported() {
        let mut lm = LevenbergMarquardt::new(2, 2);
        let mut p = [-1.2, 1.0];
        let cfg = LmConfig {
            max_iterations: 2,
            ..LmConfig::default()
        };
        let rep = lm
            .minimize(
                |p: &[f64], r: &mut [f64]| {
                    r[0] = 10.0 * (p[1] - p[0] * p[0]);
                    r[1] = 1.0 - p[0];
                },
                &mut p,
                &cfg,
            )
            .unwrap();
        assert_eq!(rep.termination, Termination::MaxIterations);
        assert_eq!(rep.iterations, 2);
    }

    #[test]
    fn badly_scaled_parameters_are_handled_by_diagonal_scaling() {
        // y = a·t⁵ + b·exp(−c·t) with a ~ 1e10 and t in ms-range seconds
        let t: Vec<f64> = (1..30).map(|i| i as f64 * 2e-4).collect();
        let truth = [3e10, 1e-3, 500.0];
        let y: Vec<f64> = t
            .iter()
            .map(|&t| truth[0] * t.powi(5) + truth[1] * (-truth[2] * t).exp())
            .collect();
        let mut lm = LevenbergMarquardt::new(t.len(), 3);
        let mut p = [1e10, 2e-3, 300.0];
        let rep = lm
            .minimize(
                |p: &[f64], r: &mut [f64]| {
                    for i in 0..t.len() {
                        r[i] = p[0] * t[i].powi(5) + p[1] * (-p[2] * t[i]).exp() - y[i];
                    }
                },
                &mut p,
                &LmConfig::default(),
            )
            .unwrap();
        assert_eq!(rep.termination, Termination::Converged);
        for k in 0..3 {
            assert!((p[k] - truth[k]).abs() < 1e-7 * truth[k], "{p:?}");
        }
    }

    #[test]
    fn non_finite_start_is_an_error() {
        let mut lm = LevenbergMarquardt::new(1, 1);
        let mut p = [0.0];
        assert!(matches!(
            lm.minimize(
                |_: &[f64], r: &mut [f64]| r[0] = f64::NAN,
                &mut p,
                &LmConfig::default()
            ),
            Err(Error::NonFinite { .. })
        ));
    }
}
