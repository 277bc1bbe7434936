//! Identifiability of a chosen parameter set from the Jacobian of the
//! residuals with respect to the log-parameters `θ_j = ln(p_j/p_j,start)`.
//!
//! With the thin QR factorisation `J = Q·R` and the SVD `R = U·Σ·Vᵀ`:
//!
//! ```text
//! condition number   κ = σ_max/σ_min
//! null direction     v_i (column of V) with σ_i ≤ rank_tolerance·σ_max
//! covariance         cov θ = s²·V·Σ⁻²·Vᵀ,   s² = ‖r‖²/(m − n)
//! std error          se(p_j) = p_j·√(cov θ)_jj       (delta method)
//! correlation        ρ_jk = (V·Σ⁻²·Vᵀ)_jk / √((V·Σ⁻²·Vᵀ)_jj·(V·Σ⁻²·Vᵀ)_kk)
//! ```
//!
//! A null direction `v` means the residuals do not change, to first order,
//! when every parameter is multiplied by `λ^{v_j}` (v scaled so that
//! `max |v_j| = 1`): only the combinations orthogonal to it are determined.
//! Two parameters that only appear as a product (`Kp·Kt` when `Ke = 0`) give
//! `v = (1, −1)`. Log-parameters make `J` dimensionless, so κ compares the
//! parameters' relative influence and does not depend on their units.
//!
//! Verdict per parameter: *not identifiable* if it takes part
//! (`|v_j| ≥ 0.05`) in a null direction or its relative standard error
//! exceeds 100 %; *poor* if its relative standard error exceeds
//! `poor_relative_std` (default 10 %); *identifiable* otherwise. On noise-free
//! data the standard errors are 0 and only the rank test speaks. The fit
//! ([`super::fit_greybox`]) then checks what this local analysis cannot see:
//! an estimate that moves far beyond its standard error when the fit is
//! started elsewhere becomes *not identifiable*, and every estimate of a fit
//! whose residuals are structured ([`super::whiteness`]) *unreliable*.
//!
//! Reference: E. Walter, L. Pronzato, *Identification of Parametric Models
//! from Experimental Data*, Springer 1997, ch. 2 (structural
//! identifiability) and §5.3 (local practical identifiability); L. Ljung,
//! *System Identification*, 2nd ed., §9.3 (asymptotic covariance).

use nalgebra::DMatrix;
use serde::Serialize;

use super::names::PhysicalParameter;
use crate::error::{Error, Result};

/// How well one parameter is determined by the data.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// Determined, with a relative standard error below the "poor" threshold.
    Identifiable,
    /// Determined, but with a large relative standard error.
    Poor,
    /// Not determined by the data (a null direction, a standard error above
    /// 100 %, or an estimate that moves far beyond its standard error when
    /// the fit starts elsewhere).
    NotIdentifiable,
    /// Determined by the data through this model, but the model leaves
    /// structure in the residuals (see [`super::whiteness`]): the standard
    /// error does not bound the error, the estimate may be biased.
    Unreliable,
}

impl Verdict {
    /// Lower-case label.
    pub fn label(self) -> &'static str {
        match self {
            Verdict::Identifiable => "identifiable",
            Verdict::Poor => "poor",
            Verdict::NotIdentifiable => "not identifiable",
            Verdict::Unreliable => "unreliable",
        }
    }
}

/// A direction in log-parameter space along which the residuals do not change.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NullDirection {
    /// The parameters that take part (`|v_j| ≥ 0.05`).
    pub parameters: Vec<&'static str>,
    /// Their exponents `v_j` (largest magnitude 1): scaling each by `λ^{v_j}` leaves the response unchanged.
    pub exponents: Vec<f64>,
    /// `σ_i/σ_max` of this direction.
    pub singular_value_ratio: f64,
}

impl NullDirection {
    /// Human-readable form, e.g. `Kp·λ^1.00, Kt·λ^-1.00`.
    pub fn describe(&self) -> String {
        self.parameters
            .iter()
            .zip(&self.exponents)
            .map(|(p, e)| format!("{p}·λ^{e:.2}"))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// Thresholds of the analysis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IdentifiabilityThresholds {
    /// `σ_i/σ_max` at or below which a direction is a null direction. Default 1e-6.
    pub rank_tolerance: f64,
    /// Relative standard error above which a parameter is "poor". Default 0.1.
    pub poor_relative_std: f64,
}

impl Default for IdentifiabilityThresholds {
    fn default() -> Self {
        Self {
            rank_tolerance: 1e-6,
            poor_relative_std: 0.1,
        }
    }
}

/// Result of the analysis of one Jacobian.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Identifiability {
    /// `σ_max/σ_min` of the log-parameter Jacobian (∞ → reported as `f64::MAX`).
    pub condition_number: f64,
    /// Null directions.
    pub null_directions: Vec<NullDirection>,
    /// Relative standard error of each parameter (`None` when undetermined).
    pub relative_std_errors: Vec<Option<f64>>,
    /// Correlation matrix of the estimates (row-major, n×n).
    pub correlation: Vec<Vec<f64>>,
    /// Verdict per parameter.
    pub verdicts: Vec<Verdict>,
}

impl Identifiability {
    /// The parameters whose verdict is [`Verdict::NotIdentifiable`].
    pub fn not_identifiable(&self, names: &[PhysicalParameter]) -> Vec<&'static str> {
        names
            .iter()
            .zip(&self.verdicts)
            .filter(|(_, v)| **v == Verdict::NotIdentifiable)
            .map(|(p, _)| p.name())
            .collect()
    }

    /// An [`Error::NotIdentifiable`] naming the parameters of the null
    /// directions, or `None` when there is none.
    pub fn refusal(&self) -> Option<Error> {
        let first = self.null_directions.first()?;
        let mut names: Vec<&str> = Vec::new();
        for d in &self.null_directions {
            for p in &d.parameters {
                if !names.contains(p) {
                    names.push(p);
                }
            }
        }
        Some(Error::NotIdentifiable {
            parameters: names.join(", "),
            direction: first.describe(),
        })
    }
}

/// Analyse the column-major `m×n` Jacobian `jac` of the residuals with respect
/// to the log-parameters; `residual_ss` is `‖r‖²` at the estimate.
pub fn analyse(
    jac: &[f64],
    m: usize,
    names: &[PhysicalParameter],
    residual_ss: f64,
    thresholds: &IdentifiabilityThresholds,
) -> Result<Identifiability> {
    let n = names.len();
    if n == 0 || m < n || jac.len() != m * n {
        return Err(Error::LengthMismatch {
            what: "grey-box Jacobian",
            expected: m * n,
            actual: jac.len(),
        });
    }
    if let Some(i) = jac.iter().position(|v| !v.is_finite()) {
        return Err(Error::NonFinite {
            channel: "grey-box Jacobian".to_string(),
            index: i,
            value: jac[i],
        });
    }
    let j = DMatrix::from_column_slice(m, n, jac);
    let r = j.qr().r();
    let svd = r.svd(false, true);
    let vt = svd.v_t.ok_or(Error::Singular {
        context: "SVD of the grey-box Jacobian",
    })?;
    let s = &svd.singular_values;
    let smax = s.iter().fold(0.0_f64, |a, &b| a.max(b));
    let smin = s.iter().fold(f64::INFINITY, |a, &b| a.min(b));
    let condition_number = if smin > 0.0 { smax / smin } else { f64::MAX };

    let mut null_directions = Vec::new();
    let mut in_null = vec![false; n];
    for (i, &si) in s.iter().enumerate() {
        let ratio = if smax > 0.0 { si / smax } else { 0.0 };
        if ratio > thresholds.rank_tolerance {
            continue;
        }
        let v: Vec<f64> = (0..n).map(|k| vt[(i, k)]).collect();
        let big = v.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
        if big == 0.0 {
            continue;
        }
        // sign convention: the first participating exponent is positive
        let sign = v
            .iter()
            .find(|x| x.abs() >= 0.05 * big)
            .map_or(1.0, |x| x.signum());
        let mut parameters = Vec::new();
        let mut exponents = Vec::new();
        for (k, &x) in v.iter().enumerate() {
            if x.abs() >= 0.05 * big {
                in_null[k] = true;
                parameters.push(names[k].name());
                exponents.push(sign * x / big);
            }
        }
        null_directions.push(NullDirection {
            parameters,
            exponents,
            singular_value_ratio: ratio,
        });
    }

    // (JᵀJ)⁻¹ = V Σ⁻² Vᵀ over the determined directions (a pseudo-inverse
    // when there are null directions: the other parameters keep their errors)
    let cut = (smax * f64::EPSILON * (m.max(n) as f64)).max(thresholds.rank_tolerance * smax);
    let mut inv = DMatrix::<f64>::zeros(n, n);
    for (i, &si) in s.iter().enumerate() {
        if si > cut {
            let w = 1.0 / (si * si);
            for a in 0..n {
                for b in 0..n {
                    inv[(a, b)] += w * vt[(i, a)] * vt[(i, b)];
                }
            }
        }
    }
    let dof = (m - n).max(1) as f64;
    let s2 = (residual_ss / dof).max(0.0);
    let relative_std_errors: Vec<Option<f64>> = (0..n)
        .map(|k| {
            let v = (s2 * inv[(k, k)]).sqrt();
            (smax > 0.0 && !in_null[k] && v.is_finite()).then_some(v)
        })
        .collect();
    let correlation: Vec<Vec<f64>> = (0..n)
        .map(|a| {
            (0..n)
                .map(|b| {
                    let d = (inv[(a, a)] * inv[(b, b)]).sqrt();
                    let c = if a == b {
                        1.0
                    } else if d > 0.0 {
                        (inv[(a, b)] / d).clamp(-1.0, 1.0)
                    } else {
                        0.0
                    };
                    if c.is_finite() {
                        c
                    } else {
                        0.0
                    }
                })
                .collect()
        })
        .collect();
    let verdicts = (0..n)
        .map(|k| match (in_null[k], relative_std_errors[k]) {
            (true, _) | (false, None) => Verdict::NotIdentifiable,
            (false, Some(e)) if e > 1.0 => Verdict::NotIdentifiable,
            (false, Some(e)) if e > thresholds.poor_relative_std => Verdict::Poor,
            _ => Verdict::Identifiable,
        })
        .collect();
    Ok(Identifiability {
        condition_number,
        null_directions,
        relative_std_errors,
        correlation,
        verdicts,
    })
}

/// How far (in standard errors) a restarted fit may end from the estimate
/// before the parameter is not identifiable.
pub const RESTART_TOLERANCE_SE: f64 = 3.0;

/// The spread of the restarts per parameter in log-parameters (`None`
/// without restarts); a parameter that moved beyond its standard error is
/// not identifiable, and with structured residuals the others unreliable.
pub(crate) fn restart_verdicts(
    analysis: &mut Identifiability,
    ends: &[Vec<f64>],
    theta: &[f64],
    structured: bool,
) -> Vec<Option<f64>> {
    let spread: Vec<Option<f64>> = (0..theta.len())
        .map(|j| {
            (!ends.is_empty()).then(|| {
                ends.iter()
                    .map(|t| (t[j] - theta[j]).abs())
                    .fold(0.0_f64, f64::max)
                    .exp_m1()
            })
        })
        .collect();
    for (j, v) in analysis.verdicts.iter_mut().enumerate() {
        let moved = match (spread[j], analysis.relative_std_errors[j]) {
            // beyond the standard error, and beyond what the LM tolerance leaves
            (Some(s), Some(se)) => s > RESTART_TOLERANCE_SE * se && s > 1e-4,
            (Some(s), None) => s > 1e-4,
            _ => false,
        };
        if moved {
            *v = Verdict::NotIdentifiable;
        } else if structured && *v != Verdict::NotIdentifiable {
            *v = Verdict::Unreliable;
        }
    }
    spread
}

/// A verdict of a fit whose simulated position fits the measured one by
/// `fit_percent`: a model that explains none of it (worse than its mean: a
/// dead encoder, the wrong column) determines nothing, however small the
/// standard errors of its parameters look.
pub(crate) fn verdict_at_fit(verdict: Verdict, fit_percent: f64) -> Verdict {
    if fit_percent.is_nan() || fit_percent <= 0.0 {
        Verdict::NotIdentifiable
    } else {
        verdict
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use PhysicalParameter::{Kp, Kt, Kv};

    #[test]
    fn product_of_two_parameters_gives_the_null_direction_one_minus_one() {
        // r_i = t_i·(θ_Kp + θ_Kt) + 2·t_i²·θ_Kv: Kp and Kt only as a product
        let m = 20;
        let mut jac = vec![0.0; 3 * m];
        for i in 0..m {
            let t = i as f64 / m as f64;
            jac[i] = t;
            jac[m + i] = t;
            jac[2 * m + i] = 2.0 * t * t + 0.1;
        }
        let a = analyse(&jac, m, &[Kp, Kt, Kv], 1e-6, &Default::default()).unwrap();
        assert_eq!(a.null_directions.len(), 1);
        let d = &a.null_directions[0];
        assert_eq!(d.parameters, vec!["Kp", "Kt"]);
        assert!((d.exponents[0] - 1.0).abs() < 1e-12 && (d.exponents[1] + 1.0).abs() < 1e-12);
        assert_eq!(a.verdicts[0], Verdict::NotIdentifiable);
        assert_eq!(a.verdicts[1], Verdict::NotIdentifiable);
        assert_eq!(a.verdicts[2], Verdict::Identifiable);
        let e = a.refusal().unwrap().to_string();
        assert!(e.contains("Kp, Kt"), "{e}");
    }

    #[test]
    fn standard_errors_match_the_closed_form_of_a_linear_regression() {
        // J = [1, t]: cov = s²·(JᵀJ)⁻¹ in closed form
        let t: Vec<f64> = (0..5).map(|i| i as f64).collect();
        let mut jac = vec![1.0; 10];
        jac[5..].copy_from_slice(&t);
        let ss = 3.0; // residual sum of squares, dof 3 → s² = 1
        let a = analyse(&jac, 5, &[Kv, Kp], ss, &Default::default()).unwrap();
        // JᵀJ = [[5, 10], [10, 30]], inverse = [[0.6, −0.2], [−0.2, 0.1]]
        assert!((a.relative_std_errors[0].unwrap() - 0.6_f64.sqrt()).abs() < 1e-12);
        assert!((a.relative_std_errors[1].unwrap() - 0.1_f64.sqrt()).abs() < 1e-12);
        let rho = -0.2 / (0.6_f64 * 0.1).sqrt();
        assert!((a.correlation[0][1] - rho).abs() < 1e-12);
        assert_eq!(a.verdicts[0], Verdict::Poor); // 77 %
        assert_eq!(a.verdicts[1], Verdict::Poor); // 32 %
    }
}
