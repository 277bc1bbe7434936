//! Running a member's plant — the rig with its effects or the servo, with its
//! dead time, encoder and noise — on a command: the member's own, or another
//! one (an identification excitation, a compensated command) for the same axis.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

use super::servo;
use super::spec::MemberSpec;
use crate::drive::{RigStepper, VirtualRig};
use crate::error::{Error, Result};
use crate::lti::DiscreteStateSpace;

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
        crate::signal::check_command(command, "a command for a zoo plant", 2)?;
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

/// A member's plant stepped one recorded sample at a time
/// ([`MemberSpec::stepper`]): the same axis, set-point interpolation, dead
/// time, encoder and noise sequence as [`MemberSpec::run_plant`], for a loop
/// in which each command is computed from the positions measured so far.
#[derive(Debug, Clone)]
pub struct PlantStepper {
    axis: Axis,
    /// Loop samples per recorded sample.
    m: usize,
    /// Command of the current recorded sample \[m\].
    last: f64,
    k: usize,
}

#[derive(Debug, Clone)]
enum Axis {
    Rig(Box<RigStepper>),
    Servo(Box<ServoStepper>),
}

/// A servo member at the loop rate: ZOH model, dead time, encoder, noise.
#[derive(Debug, Clone)]
struct ServoStepper {
    sys: DiscreteStateSpace,
    x: Vec<f64>,
    scratch: Vec<f64>,
    /// Loop commands, oldest first (the oldest is the one the axis acts on).
    history: Vec<f64>,
    resolution: f64,
    noise: Normal<f64>,
    rng: ChaCha8Rng,
    truth: f64,
    measured: f64,
}

impl ServoStepper {
    /// Output at the current loop sample, then one noise draw.
    fn measure(&mut self) {
        let u = self.history[0];
        self.truth = self.sys.output(&self.x, u);
        let q = self.resolution;
        self.measured = (self.truth / q).round() * q + self.noise.sample(&mut self.rng);
    }

    fn step(&mut self, command: f64) -> Result<()> {
        let acting = self.history[0];
        self.sys.advance(&mut self.x, acting, &mut self.scratch)?;
        self.history.rotate_left(1);
        if let Some(last) = self.history.last_mut() {
            *last = command;
        }
        self.measure();
        Ok(())
    }
}

impl MemberSpec {
    /// This member's plant at rest at 0, to be stepped one recorded sample at
    /// a time from the first command `first` (sample 0), with measurement
    /// noise from `noise_seed` (the sequence of [`MemberSpec::run_plant`]).
    ///
    /// ```
    /// use feedid::zoo::Zoo;
    /// let spec = Zoo::standard().spec(2).unwrap();
    /// let cmd: Vec<f64> = (0..400).map(|k| if k < 50 { 0.0 } else { 1e-4 }).collect();
    /// let run = spec.run_plant(&cmd, 1).unwrap();
    /// let mut axis = spec.stepper(cmd[0], 1).unwrap();
    /// for &u in &cmd[1..] {
    ///     axis.advance(u).unwrap();
    /// }
    /// assert_eq!(axis.position(), run.position[399]);
    /// ```
    pub fn stepper(&self, first: f64, noise_seed: u64) -> Result<PlantStepper> {
        if !first.is_finite() {
            return Err(Error::NonFinite {
                channel: "command".to_string(),
                index: 0,
                value: first,
            });
        }
        let m = self.decimation();
        let axis = if let Some(rig) = &self.rig {
            let stepper = VirtualRig::new(rig.params)
                .with_effects(rig.effects)
                .with_seed(noise_seed)
                .with_max_step(rig.max_step)
                .stepper(self.loop_rate_hz, first)?;
            Axis::Rig(Box::new(stepper))
        } else {
            let Some(s) = &self.servo else {
                return Err(Error::InvalidModel {
                    reason: "zoo member without a plant",
                });
            };
            let sys = servo::transfer_function(s)?
                .to_state_space()?
                .discretize_zoh(1.0 / self.loop_rate_hz)?;
            let n = sys.order();
            let noise =
                Normal::new(0.0, self.noise_std_m).map_err(|_| Error::InvalidParameter {
                    name: "noise_std",
                    value: self.noise_std_m,
                    reason: "must be finite and >= 0",
                })?;
            let mut st = ServoStepper {
                sys,
                x: vec![0.0; n],
                scratch: vec![0.0; n],
                history: vec![first; self.dead_time_samples * m + 1],
                resolution: self.resolution_m,
                noise,
                rng: ChaCha8Rng::seed_from_u64(noise_seed),
                truth: 0.0,
                measured: 0.0,
            };
            st.measure();
            Axis::Servo(Box::new(st))
        };
        Ok(PlantStepper {
            axis,
            m,
            last: first,
            k: 0,
        })
    }
}

impl PlantStepper {
    /// Index of the current recorded sample.
    pub fn sample(&self) -> usize {
        self.k
    }

    /// Measured position at the current sample (quantised, with noise) \[m\].
    pub fn position(&self) -> f64 {
        match &self.axis {
            Axis::Rig(r) => r.position(),
            Axis::Servo(s) => s.measured,
        }
    }

    /// True position at the current sample \[m\].
    pub fn true_position(&self) -> f64 {
        match &self.axis {
            Axis::Rig(r) => r.true_position(),
            Axis::Servo(s) => s.truth,
        }
    }

    /// Give the command of recorded sample `k + 1` (interpolated linearly to
    /// the loop rate) and run the axis to it; returns its measured position \[m\].
    pub fn advance(&mut self, next: f64) -> Result<f64> {
        if !next.is_finite() {
            return Err(Error::NonFinite {
                channel: "command".to_string(),
                index: self.k + 1,
                value: next,
            });
        }
        let m = self.m;
        for r in 1..=m {
            let u = if r == m {
                next
            } else {
                self.last + (r as f64 / m as f64) * (next - self.last)
            };
            match &mut self.axis {
                Axis::Rig(s) => {
                    s.advance(u)?;
                }
                Axis::Servo(s) => s.step(u)?,
            }
        }
        self.last = next;
        self.k += 1;
        Ok(self.position())
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

#[cfg(test)]
mod tests {
    use crate::zoo::{PlantKind, Zoo};

    /// A command with rest, a move and a reversal at the member's rate.
    fn command(n: usize) -> Vec<f64> {
        (0..n)
            .map(|k| {
                let t = k as f64 / n as f64;
                if t < 0.1 {
                    0.0
                } else {
                    2e-4 * (1.0 - (6.0 * (t - 0.1)).cos())
                }
            })
            .collect()
    }

    #[test]
    fn stepping_a_member_reproduces_its_batch_run_bit_for_bit() {
        let zoo = Zoo::standard();
        let (mut rigs, mut servos) = (0, 0);
        for i in zoo.regular().take(12) {
            let spec = zoo.spec(i).unwrap();
            match spec.plant {
                PlantKind::Rig(_) => rigs += 1,
                _ => servos += 1,
            }
            let cmd = command(300);
            let run = spec.run_plant(&cmd, 7).unwrap();
            let mut axis = spec.stepper(cmd[0], 7).unwrap();
            assert_eq!(axis.position(), run.position[0], "member {i}");
            for (k, &c) in cmd.iter().enumerate().skip(1) {
                let y = axis.advance(c).unwrap();
                assert_eq!(y, run.position[k], "member {i} sample {k}");
                assert_eq!(axis.true_position(), run.truth[k], "member {i} sample {k}");
            }
            assert_eq!(axis.sample(), cmd.len() - 1);
        }
        // both kinds of plant were stepped
        assert!(rigs > 0 && servos > 0, "{rigs} rigs, {servos} servos");
    }

    #[test]
    fn a_non_finite_command_is_refused_with_its_index() {
        let spec = Zoo::standard().spec(1).unwrap();
        let mut axis = spec.stepper(0.0, 1).unwrap();
        axis.advance(1e-6).unwrap();
        let e = axis.advance(f64::NAN).unwrap_err();
        assert!(e.to_string().contains('2'), "{e}");
        assert!(spec.stepper(f64::INFINITY, 1).is_err());
    }
}
