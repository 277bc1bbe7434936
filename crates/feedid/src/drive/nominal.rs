//! The nominal linear model driven by a measured command: the paper's
//! "simulation model", its third curve next to measurement and identified
//! model.
//!
//! The 7-state cascade (at the default nut position) is discretised exactly
//! (zero-order hold on the command) at the recording's sample interval and
//! started at rest at the first command value: with unit DC gain the
//! equilibrium output equals the command, so the deviation from `x_s[0]` is
//! simulated from the zero state.

use crate::drive::{closed_loop_state_space, RigParams};
use crate::error::{Error, Result};
use crate::recording::Recording;

/// [`simulate_nominal`] driven by a recording's command, at its samples.
/// Across a gap of dropped samples ([`Recording::gaps`]) the loop runs on:
/// the command at the missing samples is interpolated linearly (a planned
/// trajectory), and only the measured samples are returned.
pub fn simulate_nominal_recording<S: AsRef<[f64]>>(
    params: &RigParams,
    rec: &Recording<S>,
) -> Result<Vec<f64>> {
    let c = rec.command();
    if rec.gaps().is_empty() {
        return simulate_nominal(params, c, rec.dt());
    }
    let sim = simulate_nominal(params, &rec.fill_gaps(c)?, rec.dt())?;
    Ok(rec.grid_indices().into_iter().map(|i| sim[i]).collect())
}

/// Simulate the nominal linear closed loop on a sampled `command` \[m\] with
/// sample interval `dt` \[s\]; returns the table position \[m\] per sample.
pub fn simulate_nominal(params: &RigParams, command: &[f64], dt: f64) -> Result<Vec<f64>> {
    if !dt.is_finite() || dt <= 0.0 {
        return Err(Error::InvalidParameter {
            name: "dt",
            value: dt,
            reason: "must be finite and > 0",
        });
    }
    let Some(&u0) = command.first() else {
        return Ok(Vec::new());
    };
    let sys = closed_loop_state_space(params)?.discretize_zoh(dt)?;
    let du: Vec<f64> = command.iter().map(|&u| u - u0).collect();
    let mut y = sys.simulate(&du, None)?;
    for v in &mut y {
        *v += u0;
    }
    Ok(y)
}
