//! Running a member's plant — the rig with its effects or the servo, with its
//! dead time, encoder and noise — on a command: the member's own, or another
//! one (an identification excitation, a compensated command) for the same axis.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

use super::servo;
use super::spec::MemberSpec;
use crate::drive::VirtualRig;
use crate::error::{Error, Result};

/// A command run on a member's plant, at the member's recording rate.
#[derive(Debug, Clone, PartialEq)]
pub struct PlantRun {
    /// Time \[s\] (`k/rate`).
    pub time: Vec<f64>,
    /// Command \[m\] (as given).
    pub command: Vec<f64>,
    /// Measured position \[m\] (quantised, with noise; no glitches).
    pub position: Vec<f64>,
    /// True position \[m\].
    pub truth: Vec<f64>,
}

impl MemberSpec {
    /// Loop samples per recorded row (`loop_rate_hz / rate_hz`).
    pub fn decimation(&self) -> usize {
        (self.loop_rate_hz / self.rate_hz).round().max(1.0) as usize
    }

    /// Run this member's axis on `command` sampled at the member's recording
    /// rate, with measurement noise from `noise_seed`: the command is
    /// interpolated linearly to the loop rate (the set-point generator), the
    /// axis simulated there and the result kept every
    /// [`MemberSpec::decimation`]-th sample. Glitches and dropped rows are not
    /// applied (they belong to the member's recording). Starts at rest at 0.
    ///
    /// ```
    /// use feedid::zoo::Zoo;
    /// let spec = Zoo::standard().spec(2).unwrap();
    /// let cmd: Vec<f64> = (0..400).map(|k| if k < 50 { 0.0 } else { 1e-4 }).collect();
    /// let run = spec.run_plant(&cmd, 1).unwrap();
    /// assert_eq!(run.truth.len(), 400);
    /// ```
    pub fn run_plant(&self, command: &[f64], noise_seed: u64) -> Result<PlantRun> {
        if command.len() < 2 {
            return Err(Error::TooFewSamples {
                what: "a command for a zoo plant",
                needed: 2,
                actual: command.len(),
            });
        }
        if let Some((index, &value)) = command.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(Error::NonFinite {
                channel: "command".to_string(),
                index,
                value,
            });
        }
        let m = self.decimation();
        let fine: Vec<f64> = (0..(command.len() - 1) * m + 1)
            .map(|j| {
                let (k, r) = (j / m, j % m);
                if r == 0 {
                    command[k]
                } else {
                    let f = r as f64 / m as f64;
                    command[k] + f * (command[k + 1] - command[k])
                }
            })
            .collect();
        let (measured, truth) = run_loop(self, &fine, noise_seed)?;
        let n = command.len();
        Ok(PlantRun {
            time: (0..n).map(|k| k as f64 / self.rate_hz).collect(),
            command: command.to_vec(),
            position: (0..n).map(|k| measured[k * m]).collect(),
            truth: (0..n).map(|k| truth[k * m]).collect(),
        })
    }
}

/// Measured and true position of the member's plant driven by `command` at
/// the loop rate.
pub(crate) fn run_loop(
    spec: &MemberSpec,
    command: &[f64],
    noise_seed: u64,
) -> Result<(Vec<f64>, Vec<f64>)> {
    if let Some(rig) = &spec.rig {
        let out = VirtualRig::new(rig.params)
            .with_effects(rig.effects)
            .with_seed(noise_seed)
            .with_max_step(rig.max_step)
            .simulate(command, spec.loop_rate_hz)?;
        return Ok((out.position, out.true_position));
    }
    let Some(s) = &spec.servo else {
        return Err(Error::InvalidModel {
            reason: "zoo member without a plant",
        });
    };
    let delay = spec.dead_time_samples * spec.decimation();
    let delayed: Vec<f64> = (0..command.len())
        .map(|k| command[k.saturating_sub(delay)])
        .collect();
    let truth = servo::simulate(s, &delayed, 1.0 / spec.loop_rate_hz)?;
    let q = spec.resolution_m;
    let noise = Normal::new(0.0, spec.noise_std_m).map_err(|_| Error::InvalidParameter {
        name: "noise_std",
        value: spec.noise_std_m,
        reason: "must be finite and >= 0",
    })?;
    let mut rng = ChaCha8Rng::seed_from_u64(noise_seed);
    let measured = truth
        .iter()
        .map(|&x| (x / q).round() * q + noise.sample(&mut rng))
        .collect();
    Ok((measured, truth))
}
