//! The problem of one sliding window of the output-error method: the
//! residual `ŷ(θ) − y` of the continuous model discretised at the window's
//! sample interval, with the initial state eliminated by least squares
//! (variable projection), and its Jacobian (forward differences, the
//! default, or Kaufman's projected form). The solver (Levenberg–Marquardt) and the loop
//! over windows live in `estimator.rs`.

use super::companion::{is_hurwitz, simulate_from, window_responses, Companion, MAX_ORDER};
use super::estimator::Structure;
use crate::error::{Error, Result};
use crate::solve::{lstsq_in_place, LstsqOptions, QrWorkspace};

/// Buffers of one window fit (variable projection over the initial state).
#[derive(Debug, Clone)]
pub(super) struct WindowWork {
    pub(super) comp: Companion,
    /// Forced response from the zero state.
    pub(super) forced: Vec<f64>,
    /// Observability matrix `C·A_dᵏ`, `W×n` column-major.
    pub(super) obs: Vec<f64>,
    /// Copy of `obs` factorised by the least-squares solve.
    obs_qr: Vec<f64>,
    rhs: Vec<f64>,
    pub(super) x0: Vec<f64>,
    pub(super) x: Vec<f64>,
    qr: QrWorkspace,
    /// The parameters of the last successful [`WindowWork::residual`]
    /// (whose discretisation, `x0` and `obs` are in place).
    theta_eval: Vec<f64>,
    eval_valid: bool,
    /// Scratch of [`WindowWork::jacobian`]: base and perturbed outputs, the
    /// states (`W×n`), an orthonormal basis of the columns of `obs` (`W×n`).
    y_base: Vec<f64>,
    y_pert: Vec<f64>,
    states: Vec<f64>,
    q: Vec<f64>,
}

impl WindowWork {
    pub(super) fn new(n: usize, p: usize) -> Self {
        Self {
            comp: Companion::new(n),
            forced: Vec::new(),
            obs: Vec::new(),
            obs_qr: Vec::new(),
            rhs: Vec::new(),
            x0: vec![0.0; n],
            x: vec![0.0; n],
            qr: QrWorkspace::new(n),
            theta_eval: vec![0.0; p],
            eval_valid: false,
            y_base: Vec::new(),
            y_pert: Vec::new(),
            states: Vec::new(),
            q: Vec::new(),
        }
    }

    pub(super) fn ensure(&mut self, w: usize) {
        let n = self.x.len();
        if self.forced.len() != w {
            self.forced.resize(w, 0.0);
            self.obs.resize(w * n, 0.0);
            self.obs_qr.resize(w * n, 0.0);
            self.rhs.resize(w, 0.0);
            self.y_base.resize(w, 0.0);
            self.y_pert.resize(w, 0.0);
            self.states.resize(w * n, 0.0);
            self.q.resize(w * n, 0.0);
        }
    }

    /// Residual `ŷ − y` over the window with the least-squares initial state;
    /// leaves `x0` and the discretisation of `theta` in place.
    pub(super) fn residual(
        &mut self,
        st: &Structure,
        theta: &[f64],
        h: f64,
        u: &[f64],
        y: &[f64],
        r: &mut [f64],
    ) -> Result<()> {
        let n = st.n;
        let w = u.len();
        self.eval_valid = false;
        self.comp.discretize(&theta[..n], h)?;
        let beta = &theta[n..];
        // forced response, observability rows C·A_dᵏ, y − forced
        window_responses(
            &self.comp,
            beta,
            u,
            y,
            &mut self.forced,
            &mut self.obs,
            &mut self.rhs,
        );
        self.obs_qr.copy_from_slice(&self.obs);
        if lstsq_in_place(
            w,
            n,
            &mut self.obs_qr,
            &mut self.rhs,
            &mut self.x0,
            &mut self.qr,
            &LstsqOptions::default(),
        )
        .is_err()
        {
            self.x0.fill(0.0);
        }
        for k in 0..w {
            let free: f64 = (0..n).map(|j| self.obs[k + j * w] * self.x0[j]).sum();
            r[k] = self.forced[k] + free - y[k];
        }
        if r.iter().any(|v| !v.is_finite()) {
            return Err(Error::InvalidModel {
                reason: "non-finite output-error window simulation",
            });
        }
        self.theta_eval.copy_from_slice(theta);
        self.eval_valid = true;
        Ok(())
    }

    /// The Jacobian of the window's residual (`W` data rows and the `p` prior
    /// rows `ρ·(θ − θ_prev)/max(|θ_prev|, 1)`, column-major `(W+p)×p`) at
    /// `theta`, in Kaufman's form of the variable-projection derivative:
    /// `J = P⊥·∂ŷ/∂θ` at the least-squares initial state `x0`, `P⊥` the
    /// projection off the columns of the observability matrix. The columns
    /// of `β` are exact (`∂ŷ_k/∂β_j = x_k[j]`, the simulated states); those
    /// of `α` are forward differences of the simulated output at the fixed
    /// `x0` (one discretisation and one simulation each, no least squares).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn jacobian(
        &mut self,
        st: &Structure,
        theta: &[f64],
        h: f64,
        u: &[f64],
        y: &[f64],
        rho: f64,
        prev: &[f64],
        fd_step: f64,
        jac: &mut [f64],
    ) -> Result<()> {
        let n = st.n;
        let p = st.p();
        let w = u.len();
        let rows = w + p;
        if !(self.eval_valid && self.theta_eval == theta) {
            let mut r = std::mem::take(&mut self.y_pert);
            let res = self.residual(st, theta, h, u, y, &mut r[..w]);
            self.y_pert = r;
            res?;
        }
        let beta = &theta[n..];
        let mb = beta.len();
        // the base trajectory from x0 (the discretisation of `theta` is in place)
        simulate_from(
            &self.comp,
            beta,
            &self.x0,
            u,
            &mut self.y_base,
            Some(&mut self.states),
        );
        jac.fill(0.0);
        for kk in 0..mb {
            let col = &mut jac[(n + kk) * rows..(n + kk) * rows + w];
            col.copy_from_slice(&self.states[(mb - 1 - kk) * w..(mb - kk) * w]);
        }
        let mut alpha = [0.0; MAX_ORDER];
        alpha[..n].copy_from_slice(&theta[..n]);
        for i in 0..n {
            let a = alpha[i];
            let step = if a == 0.0 { fd_step } else { fd_step * a.abs() };
            alpha[i] = a + step;
            let step = alpha[i] - a; // exactly representable
            let col = &mut jac[i * rows..i * rows + w];
            if is_hurwitz(&alpha[..n]) && self.comp.discretize(&alpha[..n], h).is_ok() {
                simulate_from(&self.comp, beta, &self.x0, u, &mut self.y_pert, None);
                for ((c, yp), yb) in col.iter_mut().zip(&self.y_pert).zip(&self.y_base) {
                    *c = (yp - yb) / step;
                }
            }
            alpha[i] = a;
        }
        // the discretisation in place is no longer that of `theta`
        self.eval_valid = false;
        // P⊥: an orthonormal basis of the columns of obs (classical
        // Gram–Schmidt twice, unit-norm columns first; dependent columns dropped)
        let mut rank = 0;
        for j in 0..n {
            let (qs, rest) = self.q.split_at_mut(rank * w);
            let v = &mut rest[..w];
            v.copy_from_slice(&self.obs[j * w..(j + 1) * w]);
            let norm0 = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            if !(norm0 > 0.0 && norm0.is_finite()) {
                continue;
            }
            v.iter_mut().for_each(|x| *x /= norm0);
            for _ in 0..2 {
                for qi in qs.chunks_exact(w) {
                    let d: f64 = qi.iter().zip(v.iter()).map(|(a, b)| a * b).sum();
                    v.iter_mut().zip(qi).for_each(|(x, a)| *x -= d * a);
                }
            }
            let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            if norm > w as f64 * f64::EPSILON {
                v.iter_mut().for_each(|x| *x /= norm);
                rank += 1;
            }
        }
        let q = &self.q[..rank * w];
        for l in 0..p {
            let col = &mut jac[l * rows..l * rows + w];
            for qi in q.chunks_exact(w) {
                let d: f64 = qi.iter().zip(col.iter()).map(|(a, b)| a * b).sum();
                col.iter_mut().zip(qi).for_each(|(x, a)| *x -= d * a);
            }
            jac[l * rows + w + l] = rho / prev[l].abs().max(1.0);
        }
        if jac.iter().any(|v| !v.is_finite()) {
            return Err(Error::InvalidModel {
                reason: "non-finite output-error window Jacobian",
            });
        }
        Ok(())
    }
}
