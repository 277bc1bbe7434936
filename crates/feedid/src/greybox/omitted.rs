//! Is feed-forward missing from the model? A score test for the omitted
//! feed-forward gains of a grey-box fit.
//!
//! Most CNC axes run velocity feed-forward (docs/METHODS.md §2.4); a model
//! without it explains the small following error only by an absurd
//! position-loop gain and leaves a structured residual. When neither `Kvff`
//! nor `Kaff` is estimated and the starting rig has none, the residual `e`
//! of the fit is regressed on the Jacobian `J` of the estimated parameters
//! and on the two feed-forward directions
//!
//! ```text
//! d_v = ŷ(kvff = 1) − ŷ(kvff = 0),   d_a = ŷ(kaff = 1) − ŷ(kaff = 0)
//! ```
//!
//! (the response of the linear cascade is *linear* in `kvff` and `kaff`:
//! they only enter the numerator, so these differences are exact
//! directions, not linearisations). The share of the residual that the
//! feed-forward explains beyond what the estimated parameters can,
//!
//! ```text
//! share = 1 − ‖e − P_[J, d_v, d_a]·e‖² / ‖e − P_J·e‖²
//! ```
//!
//! is the Lagrange-multiplier (score) statistic of the omitted parameters
//! over the residual sum of squares (Ljung, *System Identification*, 2nd
//! ed., §16.4, model structure tests). Above [`FEED_FORWARD_LIMIT`] the fit
//! says that feed-forward is probably missing and which gains to estimate.

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use super::model::PhysicalModel;
use crate::error::Result;

/// Share of the residual explained by the feed-forward directions above
/// which feed-forward counts as missing (0.5).
pub const FEED_FORWARD_LIMIT: f64 = 0.5;

/// What feed-forward would add to a fit that has none.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MissingFeedForward {
    /// Share of the position residual (after the estimated parameters)
    /// explained by velocity and acceleration feed-forward (0 … 1).
    pub explained_share: f64,
    /// Share explained by velocity feed-forward alone (0 … 1).
    pub velocity_share: f64,
    /// Whether `explained_share` exceeds [`FEED_FORWARD_LIMIT`].
    pub likely: bool,
}

/// Residual sum of squares of `e` after least squares on the columns of `a`
/// (SVD, rank-revealing: dependent columns are dropped).
fn residual_ss(a: &DMatrix<f64>, e: &DVector<f64>) -> f64 {
    if a.ncols() == 0 {
        return e.norm_squared();
    }
    // scale the columns so that the rank tolerance is relative
    let mut a = a.clone();
    for mut c in a.column_iter_mut() {
        let n = c.norm();
        if n > 0.0 {
            c /= n;
        }
    }
    let svd = a.clone().svd(true, true);
    let tol = 1e-10 * svd.singular_values.max().max(f64::MIN_POSITIVE);
    match svd.solve(e, tol) {
        Ok(x) => (e - &a * x).norm_squared(),
        Err(_) => e.norm_squared(),
    }
}

/// The score test of the module doc for a fit of `model` (with the estimates
/// in place and no feed-forward) to `command` sampled every `dt` \[s\]:
/// `residual` the position residual (simulated − measured, any common
/// weight) at the samples `rows` (the measured ones), `jacobian` its
/// derivatives by the estimated (log-)parameters, column-major,
/// `residual.len()` rows. `None` when the residual is zero.
pub(crate) fn missing_feed_forward(
    model: &PhysicalModel,
    command: &[f64],
    dt: f64,
    rows: &[usize],
    residual: &[f64],
    jacobian: &[f64],
    weight: f64,
) -> Result<Option<MissingFeedForward>> {
    let m = residual.len();
    let n = jacobian.len() / m.max(1);
    let e = DVector::from_column_slice(residual);
    if m == 0 || e.norm_squared() <= 0.0 {
        return Ok(None);
    }
    let base = model.simulate(command, dt)?;
    let direction = |set: fn(&mut PhysicalModel)| -> Result<Vec<f64>> {
        let mut with = *model;
        set(&mut with);
        let y = with.simulate(command, dt)?;
        Ok(rows.iter().map(|&k| weight * (y[k] - base[k])).collect())
    };
    let dv = direction(|p| p.params.control.kvff = 1.0)?;
    let da = direction(|p| p.params.control.kaff = 1.0)?;
    let mut a = DMatrix::<f64>::zeros(m, n + 2);
    a.view_mut((0, 0), (m, n))
        .copy_from(&DMatrix::from_column_slice(m, n, jacobian));
    a.set_column(n, &DVector::from_vec(dv));
    a.set_column(n + 1, &DVector::from_vec(da));
    let alone = residual_ss(&a.columns(0, n).into_owned(), &e);
    if alone <= 0.0 {
        return Ok(None);
    }
    let velocity = residual_ss(&a.columns(0, n + 1).into_owned(), &e);
    let both = residual_ss(&a, &e);
    let share = (1.0 - both / alone).clamp(0.0, 1.0);
    Ok(Some(MissingFeedForward {
        explained_share: share,
        velocity_share: (1.0 - velocity / alone).clamp(0.0, 1.0),
        likely: share > FEED_FORWARD_LIMIT,
    }))
}

#[cfg(test)]
mod tests {
    use crate::drive::{PositionLoop, RigEffects, RigParams, VirtualRig};
    use crate::greybox::{
        fit_greybox, GreyboxConfig, Measurements, PhysicalParameter, Verdict, FEED_FORWARD_START,
    };
    use crate::signal::Scenario;

    const RATE: f64 = 5000.0;

    /// A slow axis with velocity feed-forward (docs/METHODS.md §2.4): Kv 30 1/s,
    /// kvff 0.97, measured by the linear rig with a sampled loop, 0.2 µm noise.
    fn ff_axis() -> RigParams {
        let mut p = RigParams::default();
        p.control.kv = 30.0;
        p.control.kvff = 0.97;
        p
    }

    fn record(p: RigParams, scenario: Scenario, duration: f64) -> (Vec<f64>, Vec<f64>) {
        let u = scenario.command(RATE, duration, 1).unwrap();
        let fx = RigEffects {
            position_loop: PositionLoop::Sampled,
            noise: true,
            ..RigEffects::linear()
        };
        let out = VirtualRig::new(p)
            .with_effects(fx)
            .with_seed(7)
            .simulate(&u, RATE)
            .unwrap();
        (u, out.position)
    }

    #[test]
    fn kv_and_kvff_of_a_feed_forward_axis_are_recovered_from_a_start_without_feed_forward() {
        let truth = ff_axis();
        for scenario in [Scenario::Scurve, Scenario::Prbs] {
            let (u, y) = record(truth, scenario, 0.4);
            let data = Measurements::new(&u, &y, 1.0 / RATE);
            // the built-in rig: Kv 700 1/s, no feed-forward
            let start = RigParams::default();
            let set = PhysicalParameter::parse_list("Kv,Kvff").unwrap();
            let fit = fit_greybox(&data, &start, &set, &GreyboxConfig::default()).unwrap();
            let (kv, kvff) = (&fit.estimates[0], &fit.estimates[1]);
            assert_eq!(kvff.start, FEED_FORWARD_START);
            assert!((kv.value / 30.0 - 1.0).abs() < 0.05, "{scenario}: {fit:?}");
            assert!(
                (kvff.value / 0.97 - 1.0).abs() < 0.01,
                "{scenario}: {fit:?}"
            );
            for e in &fit.estimates {
                assert_eq!(e.verdict, Verdict::Identifiable, "{scenario}: {e:?}");
                // the truth within 4 standard errors
                let truth = if e.name == "Kv" { 30.0 } else { 0.97 };
                let se = e.std_error.unwrap();
                assert!((e.value - truth).abs() < 4.0 * se, "{scenario}: {e:?}");
            }
            // the noise floor: 0.2 µm rms
            assert!(fit.residual_rms < 0.25e-6, "{}", fit.residual_rms);
            assert!(fit.missing_feed_forward.is_none());
            assert!(fit.warnings().is_empty(), "{:?}", fit.warnings());
        }
    }

    #[test]
    fn kv_alone_on_a_feed_forward_axis_is_unreliable_and_says_feed_forward_is_missing() {
        let (u, y) = record(ff_axis(), Scenario::Scurve, 0.4);
        let data = Measurements::new(&u, &y, 1.0 / RATE);
        let set = PhysicalParameter::parse_list("Kv").unwrap();
        let fit = fit_greybox(
            &data,
            &RigParams::default(),
            &set,
            &GreyboxConfig::default(),
        )
        .unwrap();
        // Kv runs far from 30 1/s to mimic the small following error
        assert!(fit.estimates[0].value > 300.0, "{fit:?}");
        assert_ne!(fit.estimates[0].verdict, Verdict::Identifiable);
        let m = fit.missing_feed_forward.unwrap();
        assert!(m.likely && m.explained_share > 0.6, "{m:?}");
        assert!(!fit.warnings().join("\n").contains("--"), "{fit:?}");
        let w = fit.warnings_in(crate::error::Syntax::Cli).join("\n");
        assert!(
            w.contains("feed-forward may be missing") && w.contains("--estimate Kv,Kvff,Kaff"),
            "{w}"
        );
        assert!(!w.contains("friction?"), "{w}");
    }

    #[test]
    fn an_axis_without_feed_forward_is_not_said_to_lack_it() {
        // Kv off its start on an axis without feed-forward: the fit is
        // exact up to the noise, nothing is missing
        let mut truth = RigParams::default();
        truth.control.kv = 450.0;
        let (u, y) = record(truth, Scenario::Scurve, 0.4);
        let data = Measurements::new(&u, &y, 1.0 / RATE);
        let set = PhysicalParameter::parse_list("Kv").unwrap();
        let fit = fit_greybox(
            &data,
            &RigParams::default(),
            &set,
            &GreyboxConfig::default(),
        )
        .unwrap();
        assert!(
            (fit.estimates[0].value / 450.0 - 1.0).abs() < 0.01,
            "{fit:?}"
        );
        let m = fit.missing_feed_forward.unwrap();
        assert!(!m.likely && m.explained_share < 0.1, "{m:?}");
        assert!(!fit.warnings().join(" ").contains("feed-forward"));
    }
}
