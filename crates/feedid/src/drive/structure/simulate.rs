//! The nonlinear simulation of a drive structure: the rigid mass (or the
//! motor and load of a two-mass axis) under the friction law and the saturated controller, integrated with the classical
//! RK4 method in substeps of at most `0.3/λ` (λ the fastest closed-loop pole
//! or friction knee) within each sample interval.
//!
//! A sampled controller (`[controller] sample_time` = the command's
//! interval) reads the position at each sample, estimates the velocity from
//! it, and holds its output over the interval; the command's velocity and
//! acceleration for the feed-forward are its differences, `(x_s[k+1] −
//! x_s[k])/Ts` and `(x_s[k+1] − 2x_s[k] + x_s[k−1])/Ts²`. A continuous
//! controller acts inside the integration on the command interpolated
//! linearly between samples.

use super::{DriveStructure, LoopKind, Measured, VelocityEstimate};
use crate::error::{Error, Result};

/// A command run on a drive structure, one value per sample.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct StructureRun {
    /// Time `k/rate` \[s\].
    pub time: Vec<f64>,
    /// Command \[m\].
    pub command: Vec<f64>,
    /// Position \[m\].
    pub position: Vec<f64>,
    /// Velocity \[m/s\].
    pub velocity: Vec<f64>,
    /// Controller output after saturation (sampled: held from this sample on).
    pub output: Vec<f64>,
}

/// Most RK4 steps of one simulation (substeps × samples).
const MAX_STEPS: f64 = 1e8;

/// State: load position and velocity, position-loop integral, velocity-loop
/// integral, motor position and velocity (rigid: the load's), winding
/// current and current-loop integral (0 for a force source).
type State = [f64; 8];

impl DriveStructure {
    /// Simulate the structure on `command` sampled at `rate_hz`, from rest at
    /// `initial_position` \[m\] (module doc of `simulate.rs`).
    ///
    /// ```
    /// use feedid::drive::DriveStructure;
    /// let s = DriveStructure::from_toml_str(
    ///     "[position]\nkp = 50.0\n[velocity]\nkp = 100.0\n\
    ///      [drive]\ngain = 10.0\n[mechanics]\nmass = 5.0\n[friction]\nviscous = 20.0\n",
    ///     None,
    /// )
    /// .unwrap();
    /// let cmd = vec![1e-3; 2000]; // a 1 mm step at 1 kHz
    /// let run = s.simulate(&cmd, 1000.0, 0.0).unwrap();
    /// assert!((run.position[1999] - 1e-3).abs() < 1e-9);
    /// ```
    pub fn simulate(
        &self,
        command: &[f64],
        rate_hz: f64,
        initial_position: f64,
    ) -> Result<StructureRun> {
        self.validate()?;
        crate::signal::check_rate(rate_hz)?;
        crate::signal::check_command(command, "a command for a drive structure", 2)?;
        if !initial_position.is_finite() {
            return Err(Error::InvalidParameter {
                name: "initial position",
                value: initial_position,
                reason: "must be finite",
            });
        }
        let dt = 1.0 / rate_hz;
        if let Some(ts) = self.controller.sample_time {
            if (ts - dt).abs() > 1e-6 * dt {
                return Err(Error::InvalidParameter {
                    name: "controller.sample_time",
                    value: ts,
                    reason: "must equal the command's sample interval (a sampled controller runs at the recording's rate)",
                });
            }
        }
        let substeps = self.substeps(dt);
        let h = dt / substeps as f64;
        let n = command.len();
        if (substeps as f64) * (n as f64) > MAX_STEPS {
            return Err(Error::InvalidParameter {
                name: "integration steps",
                value: substeps as f64 * n as f64,
                reason: "the structure's fastest pole or friction knee needs more than 1e8 steps on this command (a friction level far above the mass's scale, or a smoothing velocity far too small)",
            });
        }
        let mut run = StructureRun {
            time: (0..n).map(|k| k as f64 * dt).collect(),
            command: command.to_vec(),
            position: vec![0.0; n],
            velocity: vec![0.0; n],
            output: vec![0.0; n],
        };
        let mut x: State = [
            initial_position,
            0.0,
            0.0,
            0.0,
            initial_position,
            0.0,
            0.0,
            0.0,
        ];
        let (mut e_prev, mut history) = (command[0] - initial_position, [initial_position; 2]);
        for k in 0..n {
            let (xm, vm) = self.measured(&x);
            run.position[k] = xm;
            run.velocity[k] = vm;
            let next = command[(k + 1).min(n - 1)];
            let prev = command[k.saturating_sub(1)];
            let slope = (next - command[k]) / dt;
            let accel = (next - 2.0 * command[k] + prev) / (dt * dt);
            if self.controller.sample_time.is_some() {
                // the sampled controller: measure, estimate, hold
                let xv = self.velocity_side(&x).0;
                let v_hat = match self.controller.velocity_estimate {
                    VelocityEstimate::Central => (xv - history[1]) / (2.0 * dt),
                    VelocityEstimate::Backward => (xv - history[0]) / dt,
                };
                let e = command[k] - xm;
                let (kp, ki, kd) = self.position.terms();
                let vref = kp * (e + ki * x[2] + kd * (e - e_prev) / dt);
                e_prev = e;
                x[2] += e * dt;
                let raw = if self.velocity.kind == LoopKind::None {
                    vref
                } else {
                    let (kv, kvi, _) = self.velocity.terms();
                    let ev = vref + self.feed_forward.velocity * slope - v_hat;
                    let out = kv * (ev + kvi * x[3]);
                    x[3] += ev * dt;
                    out
                };
                let u = self.saturate(raw + self.acceleration_output(accel));
                run.output[k] = u;
                history = [xv, history[0]];
                if k + 1 < n {
                    for j in 0..substeps {
                        rk4(&mut x, j as f64 * h, h, |_, s| self.held(s, u));
                    }
                }
            } else {
                let ff = self.acceleration_output(accel);
                run.output[k] = self.continuous_output(&x, command[k], slope, ff);
                if k + 1 < n {
                    let start = command[k];
                    for j in 0..substeps {
                        rk4(&mut x, j as f64 * h, h, |t, s| {
                            self.continuous(s, start + slope * t, slope, ff)
                        });
                    }
                }
            }
            if x.iter().any(|v| !v.is_finite()) {
                return Err(Error::InvalidModel {
                    reason: "drive structure simulation diverged (non-finite state)",
                });
            }
        }
        Ok(run)
    }

    /// Substeps per sample: the fastest closed-loop pole and friction knee
    /// resolved (`h·λ ≤ 0.3`), at least one.
    fn substeps(&self, dt: f64) -> usize {
        let mech = &self.mechanics;
        let f = &self.friction;
        let level = f
            .r#static
            .unwrap_or(0.0)
            .max(f.coulomb)
            .max(f.coulomb_negative.unwrap_or(0.0));
        // the friction acts on the load (rigid: on everything)
        let m = if mech.two_mass() {
            mech.mass
        } else {
            mech.total_mass()
        };
        let knee = (level / f.smoothing_velocity.unwrap_or(1e-4) + f.viscous + mech.damping) / m;
        let poles = self
            .closed_loop()
            .map(|s| {
                s.poles
                    .iter()
                    .fold(0.0f64, |a, p| a.max((p.re * p.re + p.im * p.im).sqrt()))
            })
            .unwrap_or(0.0);
        let rate = knee.max(poles).max(1.0 / dt);
        ((dt * rate / 0.3).ceil() as usize).clamp(1, 100_000)
    }

    fn saturate(&self, u: f64) -> f64 {
        match self.drive.limit {
            Some(l) => u.clamp(-l, l),
            None => u,
        }
    }

    /// `kaff·M/g·ẍ_s`: the output that accelerates every moving mass with the command.
    fn acceleration_output(&self, accel: f64) -> f64 {
        self.feed_forward.acceleration * self.mechanics.total_mass() / self.drive.gain * accel
    }

    /// The measured position and velocity in state `s`.
    fn measured(&self, s: &State) -> (f64, f64) {
        if self.mechanics.two_mass() && self.mechanics.measured == Measured::Motor {
            (s[4], s[5])
        } else {
            (s[0], s[1])
        }
    }

    /// The position and velocity the velocity loop feeds back in state `s`.
    fn velocity_side(&self, s: &State) -> (f64, f64) {
        match self.controller.velocity_feedback {
            Some(Measured::Motor) if self.mechanics.two_mass() => (s[4], s[5]),
            Some(Measured::Load) => (s[0], s[1]),
            _ => self.measured(s),
        }
    }

    /// Accelerations of the load and the motor under the drive's `force`.
    fn accelerations(&self, s: &State, force: f64) -> (f64, f64) {
        let mech = &self.mechanics;
        match (mech.stiffness, mech.motor_mass) {
            (Some(k), Some(mm)) => {
                let spring = k * (s[4] - s[0]) + mech.damping * (s[5] - s[1]);
                let load = (spring - self.friction.force(s[1])) / mech.mass;
                (load, (force - spring - mech.motor_viscous * s[5]) / mm)
            }
            _ => {
                let a = (force - self.friction.force(s[1]) - mech.motor_viscous * s[1])
                    / mech.total_mass();
                (a, a)
            }
        }
    }

    /// The drive under the controller's output `u`: the force, and the
    /// rates of the winding current and the current loop's integral (0 for
    /// a force source).
    fn drive(&self, s: &State, u: f64) -> (f64, f64, f64) {
        match &self.current {
            Some(c) => {
                let volts = c.kp * (u - s[6]) + c.kp * c.ki * s[7];
                let di = (volts - c.resistance * s[6] - c.back_emf * s[5]) / c.inductance;
                (self.drive.gain * s[6], di, u - s[6])
            }
            None => (self.drive.gain * u, 0.0, 0.0),
        }
    }

    /// The mechanics and the current loop under a held output `u` (the
    /// sampled controller's integrals change only at the samples).
    fn held(&self, s: &State, u: f64) -> State {
        let (force, di, dz) = self.drive(s, u);
        let (al, am) = self.accelerations(s, force);
        [s[1], al, 0.0, 0.0, s[5], am, di, dz]
    }

    /// The continuous controller in state `s` at command `xs` moving at
    /// `slope`, plus the feed-forward output `ff`: its output (saturated)
    /// and the velocity loop's error.
    fn continuous_law(&self, s: &State, xs: f64, slope: f64, ff: f64) -> (f64, f64) {
        let (x, v) = self.measured(s);
        let e = xs - x;
        let (kp, ki, kd) = self.position.terms();
        let cp = kp * (e + ki * s[2] + kd * (slope - v));
        if self.velocity.kind == LoopKind::None {
            return (self.saturate(cp + ff), 0.0);
        }
        let (kv, kvi, _) = self.velocity.terms();
        let ev = cp + self.feed_forward.velocity * slope - self.velocity_side(s).1;
        (self.saturate(kv * (ev + kvi * s[3]) + ff), ev)
    }

    /// The continuous controller's output.
    fn continuous_output(&self, s: &State, xs: f64, slope: f64, ff: f64) -> f64 {
        self.continuous_law(s, xs, slope, ff).0
    }

    /// The right-hand side with the continuous controller.
    fn continuous(&self, s: &State, xs: f64, slope: f64, ff: f64) -> State {
        let (u, ev) = self.continuous_law(s, xs, slope, ff);
        let (force, di, dz) = self.drive(s, u);
        let (al, am) = self.accelerations(s, force);
        [s[1], al, xs - self.measured(s).0, ev, s[5], am, di, dz]
    }
}

/// One classical Runge–Kutta step of length `h` from time `t` (within the
/// sample interval) of `ẋ = f(t, x)`.
fn rk4(x: &mut State, t: f64, h: f64, f: impl Fn(f64, &State) -> State) {
    let at = |a: &State, s: f64, b: &State| -> State { std::array::from_fn(|j| a[j] + s * b[j]) };
    let k1 = f(t, x);
    let k2 = f(t + 0.5 * h, &at(x, 0.5 * h, &k1));
    let k3 = f(t + 0.5 * h, &at(x, 0.5 * h, &k2));
    let k4 = f(t + h, &at(x, h, &k3));
    for j in 0..x.len() {
        x[j] += h / 6.0 * (k1[j] + 2.0 * (k2[j] + k3[j]) + k4[j]);
    }
}
