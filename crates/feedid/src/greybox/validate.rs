//! A fitted physical model checked on a recording it was not fitted on
//! (`feedid greybox --validate`): its simulation against the measured
//! position, beside the tracking error it explains there.

use super::fit::{GreyboxConfig, GreyboxFit};
use super::model::PhysicalModel;
use crate::drive::StructureValidation;
use crate::error::{Error, Result};

impl GreyboxFit {
    /// Simulate the fitted model (its parameters and effects, with the
    /// dynamics and position loop of `cfg`, as fitted) on another
    /// recording's `command` sampled at `rate_hz` \[Hz\] and compare with its
    /// measured `position`, as [`crate::drive::DriveStructure::validate_on`]
    /// does for a drive structure.
    pub fn validate_on(
        &self,
        cfg: &GreyboxConfig,
        command: &[f64],
        position: &[f64],
        rate_hz: f64,
    ) -> Result<StructureValidation> {
        if !(rate_hz.is_finite() && rate_hz > 0.0) {
            return Err(Error::InvalidParameter {
                name: "rate",
                value: rate_hz,
                reason: "must be finite and > 0 (Hz)",
            });
        }
        let model = PhysicalModel {
            params: self.params,
            effects: self.effects,
            dynamics: cfg.dynamics,
            position_loop: cfg.position_loop,
        };
        let simulated = model.simulate(command, 1.0 / rate_hz)?;
        StructureValidation::compare(command, position, &simulated)
    }
}
