//! The virtual rig one sample at a time: the same integration as
//! [`VirtualRig::simulate`] (bit for bit, same noise sequence), for a loop in
//! which the next command is computed from the positions measured so far
//! (a compensator, a controller under test).

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

use super::{positive, ForcePulses, Input, Plant, PositionLoop, VirtualRig};
use crate::error::{Error, Result};

/// The virtual rig stepped one sample at a time ([`VirtualRig::stepper`]).
///
/// Sample `k`'s measured position is available before the command of
/// sample `k + 1` is given ([`RigStepper::advance`]): the sampled position
/// loop acts on command `k` over the interval `k → k + 1` and, with
/// feed-forward, on the set-point generator's velocity `u[k+1] − u[k]`.
#[derive(Debug, Clone)]
pub struct RigStepper {
    plant: Plant,
    position_loop: PositionLoop,
    rate_hz: f64,
    substeps: usize,
    noise: Option<Normal<f64>>,
    rng: ChaCha8Rng,
    /// Commands `u[k − delay − 1] … u[k + 1 − delay]` and newer (ring, oldest first).
    history: Vec<f64>,
    delay: usize,
    /// Force pulses on the table.
    pulses: ForcePulses,
    k: usize,
    x: [f64; 7],
    measured: f64,
}

impl VirtualRig {
    /// A rig at rest at 0 stepped one sample at a time at `rate_hz`, its
    /// first command `first` (sample 0); its measured position at sample 0 is
    /// ready ([`RigStepper::position`]).
    pub fn stepper(&self, rate_hz: f64, first: f64) -> Result<RigStepper> {
        if !rate_hz.is_finite() || rate_hz <= 0.0 {
            return Err(Error::InvalidParameter {
                name: "rate",
                value: rate_hz,
                reason: "must be finite and > 0",
            });
        }
        positive("max_step", self.max_step)?;
        if !first.is_finite() {
            return Err(Error::NonFinite {
                channel: "command".to_string(),
                index: 0,
                value: first,
            });
        }
        self.params.validate()?;
        self.effects.validate()?;
        let fx = &self.effects;
        let noise = Normal::new(0.0, fx.noise_std).map_err(|_| Error::InvalidParameter {
            name: "noise_std",
            value: fx.noise_std,
            reason: "must be finite and >= 0",
        })?;
        let delay = fx.dead_time;
        let mut s = RigStepper {
            plant: Plant::new(&self.params, fx),
            position_loop: fx.position_loop,
            rate_hz,
            substeps: self.substeps(rate_hz),
            noise: fx.noise.then_some(noise),
            rng: ChaCha8Rng::seed_from_u64(self.seed),
            history: vec![first; delay + 3],
            delay,
            pulses: fx.pulses,
            k: 0,
            x: [0.0; 7],
            measured: 0.0,
        };
        s.measure();
        Ok(s)
    }
}

impl RigStepper {
    /// Index of the current sample.
    pub fn sample(&self) -> usize {
        self.k
    }

    /// Measured table position at the current sample (quantised, with noise) \[m\].
    pub fn position(&self) -> f64 {
        self.measured
    }

    /// True table position x_a at the current sample \[m\].
    pub fn true_position(&self) -> f64 {
        self.x[5]
    }

    /// Armature current i at the current sample \[A\].
    pub fn motor_current(&self) -> f64 {
        self.x[2]
    }

    /// True table speed v_a at the current sample \[m/s\].
    pub fn velocity(&self) -> f64 {
        self.x[6]
    }

    /// Give the command of sample `k + 1` and integrate the interval
    /// `k → k + 1`; returns the measured position at `k + 1` \[m\].
    pub fn advance(&mut self, next: f64) -> Result<f64> {
        if !next.is_finite() {
            return Err(Error::NonFinite {
                channel: "command".to_string(),
                index: self.k + 1,
                value: next,
            });
        }
        self.history.rotate_left(1);
        if let Some(last) = self.history.last_mut() {
            *last = next;
        }
        // the command the loop acts on: delayed by the dead time, the first
        // command before the first sample
        let at = |back: usize| self.history[self.history.len() - 1 - back];
        let (prev, xl, next) = (at(self.delay + 2), at(self.delay + 1), at(self.delay));
        let rate = self.rate_hz;
        let ff = self.plant.feed_forward;
        let kv = self.plant.kv;
        let measured = self.quantised();
        let input = match self.position_loop {
            PositionLoop::Sampled if ff.active => {
                // the set-point generator's velocity over the coming interval
                // and the change of velocity from the previous one, held
                let v = (next - xl) * rate;
                let a = (next - 2.0 * xl + prev) * rate * rate;
                Input::Held {
                    vc: kv * (xl - measured) + ff.kvff * v,
                    iff: ff.current_gain * a,
                }
            }
            PositionLoop::Sampled => Input::Held {
                vc: kv * (xl - measured),
                iff: 0.0,
            },
            PositionLoop::Continuous => {
                if ff.active {
                    // ẋ_s, ẍ_s of the held command are impulses at t_k:
                    // the exact state jump (A·b₂ + b₁)·Δx_s
                    ff.jump(&mut self.x, &ff.ramp_jump, xl - prev);
                }
                Input::Command {
                    start: xl,
                    slope: 0.0,
                    vff: 0.0,
                }
            }
            PositionLoop::Interpolated => {
                let slope = (next - xl) * rate;
                if ff.active {
                    // ẍ_s of the interpolated command is an impulse at t_k:
                    // the exact state jump b₂·Δẋ_s
                    let prev_slope = (xl - prev) * rate;
                    ff.jump(&mut self.x, &ff.slope_jump, slope - prev_slope);
                }
                Input::Command {
                    start: xl,
                    slope,
                    vff: ff.kvff * slope,
                }
            }
        };
        let h = 1.0 / rate / self.substeps as f64;
        let t0 = self.k as f64 / rate;
        for j in 0..self.substeps {
            let tau = j as f64 * h;
            let force = self.pulses.at(t0 + tau);
            self.plant.rk4(&mut self.x, input, tau, h, force);
        }
        self.k += 1;
        if self.x.iter().any(|v| !v.is_finite()) {
            return Err(Error::InvalidModel {
                reason: "virtual rig simulation diverged (non-finite state)",
            });
        }
        self.measure();
        Ok(self.measured)
    }

    /// The true position as the encoder reads it (quantised, no noise).
    fn quantised(&self) -> f64 {
        let x = self.x[5];
        if self.plant.quantisation {
            (x / self.plant.resolution).round() * self.plant.resolution
        } else {
            x
        }
    }

    /// Read the encoder at the current sample (one noise draw).
    fn measure(&mut self) {
        let q = self.quantised();
        self.measured = match &self.noise {
            Some(n) => q + n.sample(&mut self.rng),
            None => q,
        };
    }
}
