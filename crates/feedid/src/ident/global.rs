//! One model over the whole recording (a *global* model), next to the sliding
//! windows: its free-run simulation gives `sim_fit_percent`, and it is the
//! model that `--model-out` writes and compensation or a Bode plot use.
//!
//! | method | global model |
//! |---|---|
//! | `arx`, `rls`, `auto` | ARX by least squares over every sample ([`fit_arx`]), the method's orders (`auto`: those of its long candidate) |
//! | `oe` | continuous-time output error ([`fit_oe`]) with the method's poles and zeros |
//! | `paper` | none: the paper's model only exists per window |
//!
//! The free-run fit is the NRMSE fit `100·(1 − ‖y − ŷ‖/‖y − ȳ‖)` of the
//! model simulated from rest on the measured command alone (no measured
//! output used), MATLAB's `compare` with `Inf` horizon.
//!
//! ```
//! use feedid::ident::{fit_global_model, MethodKind, MethodSpec};
//! use feedid::Recording;
//! let n = 2000;
//! let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
//! let u: Vec<f64> = (0..n).map(|k| 1e-3 * ((k / 100) % 2) as f64).collect();
//! let mut y = vec![0.0; n];
//! for k in 1..n {
//!     y[k] = 0.9 * y[k - 1] + 0.1 * u[k - 1];
//! }
//! let rec = Recording::new(t, u, y).unwrap();
//! let mut spec = MethodSpec::new(MethodKind::Arx);
//! spec.arx.orders = feedid::ident::ArxOrders::new(1, 1, 1);
//! let g = fit_global_model(&rec, &spec).unwrap().unwrap();
//! assert!(g.sim_fit_percent > 99.99);
//! ```

use crate::error::Result;
use crate::ident::{fit_arx, fit_oe, LinearModel, MethodKind, MethodSpec};
use crate::recording::Recording;
use crate::stats::ErrorStats;

/// A model fitted over a whole recording and its free-run simulation.
#[derive(Debug, Clone, PartialEq)]
pub struct GlobalModel {
    /// The model.
    pub model: LinearModel,
    /// Its structure in words, e.g. `"arx na=8 nb=8 nk=1"` or `"oe 3 poles 1 zero"`.
    pub structure: String,
    /// Free-run simulation on the recording's command \[m\].
    pub simulated: Vec<f64>,
    /// NRMSE fit of the free-run simulation \[%\] (`−∞ … 100`).
    pub sim_fit_percent: f64,
    /// Whether the model is stable.
    pub stable: bool,
}

/// Fit the global model of `spec`'s method over `rec` (`None` for `paper`).
///
/// Errors: the fit itself failed (too few samples, singular data). An
/// unstable or non-finite simulation is not an error: `stable` is false and
/// `sim_fit_percent` is `−∞`.
pub fn fit_global_model(rec: &Recording, spec: &MethodSpec) -> Result<Option<GlobalModel>> {
    let (u, y, dt) = (rec.command(), rec.position(), rec.dt());
    let (model, structure) = match spec.kind {
        MethodKind::Paper => return Ok(None),
        MethodKind::Arx | MethodKind::Rls | MethodKind::Auto => {
            let orders = match spec.kind {
                MethodKind::Rls => spec.rls.orders,
                MethodKind::Auto => spec.auto.long.orders,
                _ => spec.arx.orders,
            };
            let fit = fit_arx(u, y, dt, orders, &spec.arx)?;
            (
                fit.model,
                format!("arx na={} nb={} nk={}", orders.na, orders.nb, orders.nk),
            )
        }
        MethodKind::Oe => {
            let fit = fit_oe(u, y, dt, &spec.oe)?;
            (
                fit.model,
                format!(
                    "oe {} poles {} zeros (continuous time)",
                    spec.oe.poles, spec.oe.zeros
                ),
            )
        }
    };
    let stable = model.is_stable().unwrap_or(false);
    let simulated = if stable {
        model.simulate_at(u, dt).unwrap_or_default()
    } else {
        Vec::new()
    };
    let sim_fit_percent = if simulated.len() == y.len() && simulated.iter().all(|v| v.is_finite()) {
        ErrorStats::from_pairs(y.iter().copied().zip(simulated.iter().copied())).fit_percent
    } else {
        f64::NEG_INFINITY
    };
    Ok(Some(GlobalModel {
        model,
        structure,
        simulated,
        sim_fit_percent,
        stable,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{RigParams, VirtualRig};
    use crate::signal::Scenario;

    #[test]
    fn paper_has_no_global_model() {
        let t: Vec<f64> = (0..100).map(|k| k as f64 * 1e-3).collect();
        let rec = Recording::new(t.clone(), t.clone(), t).unwrap();
        assert!(fit_global_model(&rec, &MethodSpec::new(MethodKind::Paper))
            .unwrap()
            .is_none());
    }

    #[test]
    fn exact_second_order_arx_simulates_the_data_exactly() {
        let n = 1500;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let u: Vec<f64> = (0..n)
            .map(|k| 1e-3 * ((k as f64 * 0.013).sin() + (k as f64 * 0.041).sin()))
            .collect();
        let mut y = vec![0.0; n];
        for k in 2..n {
            y[k] = 1.5 * y[k - 1] - 0.7 * y[k - 2] + 0.1 * u[k - 1] + 0.1 * u[k - 2];
        }
        let rec = Recording::new(t, u, y.clone()).unwrap();
        let mut spec = MethodSpec::new(MethodKind::Arx);
        spec.arx.orders = crate::ident::ArxOrders::new(2, 2, 1);
        spec.arx.ridge = 0.0;
        let g = fit_global_model(&rec, &spec).unwrap().unwrap();
        assert!(g.stable);
        let err = g
            .simulated
            .iter()
            .zip(&y)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-12, "{err}");
        assert!(g.sim_fit_percent > 99.9999, "{}", g.sim_fit_percent);
        assert_eq!(g.structure, "arx na=2 nb=2 nk=1");
    }

    #[test]
    fn global_models_of_the_rig_chirp_simulate_well() {
        let rate = 5000.0;
        let cmd = Scenario::Chirp.command(rate, 1.0, 1).unwrap();
        let out = VirtualRig::new(RigParams::default())
            .with_seed(3)
            .simulate(&cmd, rate)
            .unwrap();
        let rec = Recording::new(out.time, out.command, out.position).unwrap();
        for kind in [MethodKind::Arx, MethodKind::Oe, MethodKind::Auto] {
            let g = fit_global_model(&rec, &MethodSpec::new(kind))
                .unwrap()
                .unwrap();
            assert!(g.stable, "{kind}");
            assert!(g.sim_fit_percent > 80.0, "{kind}: {}", g.sim_fit_percent);
        }
    }
}
