//! Closing the loop on the virtual rig: the compensated command and the plain
//! desired trajectory (as the command) are both run through the nonlinear
//! [`VirtualRig`], and the tracking errors `measured − desired` are compared.
//!
//! The rig starts at rest at position 0, which stands for the desired
//! trajectory's first value: both commands are run relative to `desired[0]`
//! and the positions referred back. Both runs use the same rig and seed (the
//! same noise sequence).
//!
//! ```
//! use feedid::compensate::{compensate_params, verify_on_rig, CompensateConfig};
//! use feedid::drive::{RigParams, VirtualRig};
//! use feedid::greybox::LoopModel;
//! use feedid::signal::Scenario;
//! let p = RigParams::default();
//! let desired = Scenario::Scurve.command(5000.0, 0.3, 0).unwrap();
//! let c = compensate_params(&p, LoopModel::Sampled, &desired, 2e-4, &CompensateConfig::default()).unwrap();
//! let v = verify_on_rig(&VirtualRig::new(p).with_seed(1), &desired, &c.command, 5000.0).unwrap();
//! assert!(v.improvement > 10.0);
//! ```

use serde::Serialize;

use crate::drive::VirtualRig;
use crate::error::{Error, Result};
use crate::stats::rms;

/// Tracking error of one run \[m\].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TrackingError {
    /// RMS of measured − desired.
    pub rms_m: f64,
    /// Largest |measured − desired|.
    pub max_abs_m: f64,
    /// RMS of true (noise-free) position − desired.
    pub rms_true_m: f64,
    /// Largest |true position − desired|.
    pub max_abs_true_m: f64,
    /// Peak motor current |i| \[A\].
    pub peak_current_a: f64,
}

/// Tracking before (desired as command) and after (compensated command).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Verification {
    /// With the desired trajectory as the command.
    pub uncompensated: TrackingError,
    /// With the compensated command.
    pub compensated: TrackingError,
    /// `uncompensated.rms_m / compensated.rms_m`.
    pub improvement: f64,
    /// Measured positions with the desired trajectory as the command \[m\].
    #[serde(skip)]
    pub position_uncompensated: Vec<f64>,
    /// Measured positions with the compensated command \[m\].
    #[serde(skip)]
    pub position_compensated: Vec<f64>,
}

fn run(
    rig: &VirtualRig,
    desired: &[f64],
    command: &[f64],
    rate_hz: f64,
) -> Result<(TrackingError, Vec<f64>)> {
    let y0 = desired[0];
    let shifted: Vec<f64> = command.iter().map(|u| u - y0).collect();
    let out = rig.simulate(&shifted, rate_hz)?;
    let e: Vec<f64> = out
        .position
        .iter()
        .zip(desired)
        .map(|(p, d)| p + y0 - d)
        .collect();
    let et: Vec<f64> = out
        .true_position
        .iter()
        .zip(desired)
        .map(|(p, d)| p + y0 - d)
        .collect();
    let max = |v: &[f64]| v.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    let position = out.position.iter().map(|p| p + y0).collect();
    Ok((
        TrackingError {
            rms_m: rms(&e),
            max_abs_m: max(&e),
            rms_true_m: rms(&et),
            max_abs_true_m: max(&et),
            peak_current_a: max(&out.motor_current),
        },
        position,
    ))
}

/// Run `command` and `desired` (as the command) through `rig` at `rate_hz`
/// \[Hz\] and compare the tracking errors.
///
/// Errors: [`Error::LengthMismatch`], [`Error::TooFewSamples`] for an empty
/// trajectory, and the rig's errors.
pub fn verify_on_rig(
    rig: &VirtualRig,
    desired: &[f64],
    command: &[f64],
    rate_hz: f64,
) -> Result<Verification> {
    if desired.len() != command.len() {
        return Err(Error::LengthMismatch {
            what: "desired trajectory and command",
            expected: desired.len(),
            actual: command.len(),
        });
    }
    if desired.is_empty() {
        return Err(Error::TooFewSamples {
            what: "a verification run",
            needed: 1,
            actual: 0,
        });
    }
    let (uncompensated, position_uncompensated) = run(rig, desired, desired, rate_hz)?;
    let (compensated, position_compensated) = run(rig, desired, command, rate_hz)?;
    let improvement = if compensated.rms_m > 0.0 {
        uncompensated.rms_m / compensated.rms_m
    } else {
        f64::MAX
    };
    Ok(Verification {
        uncompensated,
        compensated,
        improvement,
        position_uncompensated,
        position_compensated,
    })
}
