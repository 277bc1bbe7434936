//! Physical parameters from identified closed-loop coefficients `N2 … N0`,
//! `D7 … D0` (the paper's suggestion: "if the parameters in the control
//! system, like Kv, Kp and Ki, can be calculated through the identified
//! coefficients Ni and Di …").
//!
//! The coefficients are known functions of the parameters
//! ([`closed_loop_coefficients`]); identified ones carry an arbitrary common
//! scale, so both sides are divided by `D0` and compared relatively:
//!
//! ```text
//! r_i(θ) = (c_i(p)/D0(p)) / (ĉ_i/D̂0) − 1,    c ∈ {N2, N1, N0, D7, …, D1}
//! ```
//!
//! (10 residuals), minimised over the log-parameters of the chosen set by
//! Levenberg–Marquardt, the others fixed at their starting values. The map is
//! invertible for the chosen set when the Jacobian has full rank; a rank
//! defect (more unknowns than independent coefficient ratios, or parameters
//! that enter only in a fixed combination) is reported — and by default
//! refused — by name, exactly as for a recording ([`super::identifiability`]).
//! Exact coefficients of a rig give its parameters back to the LM tolerance.
//! The standard errors use the spread of the relative coefficient residuals,
//! so they only mean something when the coefficients are noisy but
//! consistent.
//!
//! ```
//! use feedid::drive::{closed_loop_coefficients, D1Variant, RigParams};
//! use feedid::greybox::{fit_coefficients, GreyboxConfig, PhysicalParameter};
//! let c = closed_loop_coefficients(&RigParams::default(), D1Variant::Corrected);
//! let mut start = RigParams::default();
//! start.control.kv = 500.0;
//! start.control.ki = 300.0;
//! let set = PhysicalParameter::parse_list("Kv,Ki").unwrap();
//! let fit = fit_coefficients(&c.num, &c.den, &start, &set, &GreyboxConfig::default()).unwrap();
//! assert!((fit.estimates[0].value - 700.0).abs() < 1e-6);
//! assert!((fit.estimates[1].value - 471.2).abs() < 1e-6);
//! ```

use super::fit::{apply, central_jacobian, check_set, estimates, GreyboxConfig, GreyboxFit};
use super::identifiability::analyse;
use super::names::PhysicalParameter;
use crate::drive::{closed_loop_coefficients, D1Variant, RigParams};
use crate::error::{Error, Result};
use crate::solve::{LevenbergMarquardt, LmConfig};

/// Number of compared coefficient ratios (N2, N1, N0, D7 … D1 over D0).
const RATIOS: usize = 10;

/// `[N2, N1, N0, D7, …, D1]` divided by `D0`.
fn ratios(num: &[f64; 3], den: &[f64; 8]) -> [f64; RATIOS] {
    let d0 = den[7];
    let mut r = [0.0; RATIOS];
    for (slot, c) in r.iter_mut().zip(num.iter().chain(&den[..7])) {
        *slot = c / d0;
    }
    r
}

/// Estimate `estimate` from identified coefficients `num = [N2, N1, N0]`
/// (shorter is padded with leading zeros) and `den = [D7, …, D0]`, starting
/// from (and fixing the others at) `start`.
///
/// Errors: [`Error::InvalidModel`] for other orders or zero/non-finite
/// coefficients, [`Error::InvalidChoice`] for friction levels,
/// [`Error::InvalidParameter`] for a start value ≤ 0,
/// [`Error::NotIdentifiable`] when the map is not invertible for the set
/// (and `cfg.refuse_unidentifiable`).
pub fn fit_coefficients(
    num: &[f64],
    den: &[f64],
    start: &RigParams,
    estimate: &[PhysicalParameter],
    cfg: &GreyboxConfig,
) -> Result<GreyboxFit> {
    let base = check_set(estimate, start, &cfg.effects, false)?;
    let n = estimate.len();
    if den.len() != 8 || num.len() > 3 || num.is_empty() {
        return Err(Error::InvalidModel {
            reason: "parameters from coefficients need the cascade's structure: N2 … N0 and D7 … D0 (7 poles, at most 2 zeros)",
        });
    }
    let mut nn = [0.0; 3];
    nn[3 - num.len()..].copy_from_slice(num);
    let mut dd = [0.0; 8];
    dd.copy_from_slice(den);
    if nn.iter().chain(&dd).any(|v| !v.is_finite()) || dd[7] == 0.0 {
        return Err(Error::InvalidModel {
            reason: "identified coefficients must be finite with D0 != 0",
        });
    }
    let target = ratios(&nn, &dd);
    if target.contains(&0.0) {
        return Err(Error::InvalidModel {
            reason: "an identified coefficient is zero; the cascade has none",
        });
    }
    if n > RATIOS {
        return Err(Error::TooFewSamples {
            what: "coefficient ratios for the chosen parameters",
            needed: n,
            actual: RATIOS,
        });
    }
    let mut params = *start;
    let mut effects = cfg.effects;
    let mut residual = |theta: &[f64], r: &mut [f64]| {
        apply(estimate, &base, theta, &mut params, &mut effects);
        let c = closed_loop_coefficients(&params, D1Variant::Corrected);
        let model = ratios(&c.num, &c.den);
        for ((ri, m), t) in r.iter_mut().zip(&model).zip(&target) {
            let v = m / t - 1.0;
            *ri = if v.is_finite() { v } else { 1e6 };
        }
    };

    let mut theta = vec![0.0; n];
    let mut jac = vec![0.0; RATIOS * n];
    let mut scratch = vec![0.0; RATIOS];
    central_jacobian(&mut residual, &theta, RATIOS, &mut scratch, &mut jac);
    residual(&theta, &mut scratch);
    let ss0: f64 = scratch.iter().map(|v| v * v).sum();
    if cfg.refuse_unidentifiable {
        if let Some(e) = analyse(&jac, RATIOS, estimate, ss0, &cfg.thresholds)?.refusal() {
            return Err(e);
        }
    }
    let mut lm = LevenbergMarquardt::new(RATIOS, n);
    let lm_cfg = LmConfig {
        ftol: cfg.tolerance,
        xtol: cfg.tolerance,
        gtol: cfg.tolerance,
        max_iterations: cfg.max_iterations.max(1),
        ..LmConfig::default()
    };
    let report = lm.minimize(&mut residual, &mut theta, &lm_cfg)?;
    central_jacobian(&mut residual, &theta, RATIOS, &mut scratch, &mut jac);
    residual(&theta, &mut scratch);
    let ss: f64 = scratch.iter().map(|v| v * v).sum();
    let analysis = analyse(&jac, RATIOS, estimate, ss, &cfg.thresholds)?;
    let mut params = *start;
    let mut effects = cfg.effects;
    apply(estimate, &base, &theta, &mut params, &mut effects);
    Ok(GreyboxFit {
        source: "coefficients",
        estimates: estimates(estimate, &base, &theta, &analysis),
        correlation: analysis.correlation.clone(),
        condition_number: analysis.condition_number,
        null_directions: analysis.null_directions.clone(),
        termination: report.termination,
        iterations: report.iterations,
        evaluations: report.evaluations + 4 * n + 2,
        residual_rms: (ss / RATIOS as f64).sqrt(),
        current_residual_rms: None,
        fit_percent: None,
        residuals: RATIOS,
        residual_structure: Vec::new(),
        restarts: 0,
        missing_feed_forward: None,
        params,
        effects,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::RigEffects;
    use crate::greybox::Verdict;
    use PhysicalParameter::*;

    #[test]
    fn exact_coefficients_give_the_parameters_back() {
        let mut truth = RigParams::default();
        truth.control.kv = 612.0;
        truth.table.mass = 4.1;
        truth.damping.c2 = 180.0;
        let c = closed_loop_coefficients(&truth, D1Variant::Corrected);
        // an arbitrary common scale (identified models are monic, say)
        let s = 1.0 / c.den[0];
        let num: Vec<f64> = c.num.iter().map(|v| v * s).collect();
        let den: Vec<f64> = c.den.iter().map(|v| v * s).collect();
        let set = [Kv, Kp, Ki, C2, M, K];
        let fit = fit_coefficients(
            &num,
            &den,
            &RigParams::default(),
            &set,
            &GreyboxConfig::default(),
        )
        .unwrap();
        let fx = RigEffects::default();
        for (e, p) in fit.estimates.iter().zip(set) {
            let want = p.get(&truth, &fx);
            assert!(
                (e.value / want - 1.0).abs() < 1e-6,
                "{}: {} vs {want}",
                e.name,
                e.value
            );
            assert_eq!(e.verdict, Verdict::Identifiable);
        }
    }

    #[test]
    fn a_non_invertible_set_is_refused_by_name() {
        let c = closed_loop_coefficients(&RigParams::default(), D1Variant::Corrected);
        // Kpi, R, L, Ke scale together (a voltage unit): only their ratios matter
        let set = [Kv, Kpi, R, L, Ke];
        let e = fit_coefficients(
            &c.num,
            &c.den,
            &RigParams::default(),
            &set,
            &GreyboxConfig::default(),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("Kpi, R, L, Ke"), "{e}");
        assert!(!e.contains("Kv,"), "{e}");
    }

    #[test]
    fn other_model_orders_are_rejected() {
        let e = fit_coefficients(
            &[1.0],
            &[1.0, 2.0, 3.0],
            &RigParams::default(),
            &[Kv],
            &GreyboxConfig::default(),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("7 poles"), "{e}");
    }
}
