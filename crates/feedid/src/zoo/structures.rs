//! A generated family of drive structures whose truth is known: the
//! structure fit's estimates ([`crate::drive::DriveStructure::fit_with_restarts`])
//! are checked against it (`examples/structure_zoo.rs`, the tests).
//!
//! Axis `i` (seeded by its index; drawn again, deterministically, when its
//! loop — sampled or not — is unstable or its run leaves the program's own
//! size) is one of four structures in turn:
//!
//! | `i mod 4` | structure |
//! |---|---|
//! | 0 | P position loop around a P velocity loop (the EMPS cascade) |
//! | 1 | P around PI, velocity feed-forward 0.6–1 and acceleration feed-forward 0–0.8 |
//! | 2 | PID position loop commanding the force (ω = half the velocity bandwidth, ζ = 0.7) |
//! | 3 | the P/P cascade on two masses joined by the screw's stiffness, measured on the motor |
//!
//! | quantity | range |
//! |---|---|
//! | recording rate | 100 Hz … 20 kHz (log-uniform); the controller sampled at the recording's interval on every other axis recorded at ≥ 1 kHz, continuous otherwise |
//! | mass | 5 … 500 kg; drive gain 5 … 100 N per unit of output |
//! | loops | velocity loop 20 … 150 Hz (at most rate/15, rate/30 sampled), position loop a quarter of it |
//! | friction | viscous 0.5 … 3 s⁻¹ of the mass; Coulomb 3 … 15 % of the program's peak inertial force; a Stribeck dip (static level 1.2 … 1.6× Coulomb, 1 … 5 mm/s) on every third axis; a constant force (10 … 50 % of Coulomb) on every other |
//! | two-mass | motor side 20 … 40 % of the load, mode 3 … 8× the velocity loop (at most rate/4, rate/8 sampled), 5 % damped |
//! | program | `A·(sin ω₀t + 0.3·sin 6.3ω₀t + 0.1·sin 23.7ω₀t)`, A 2 … 20 mm, 1.5 periods of ω₀ over 2 … 8 s (at most 40 000 samples) |
//! | noise | Gaussian, 0.05 … 0.5 µm on the measured position |
//!
//! [`StructureAxis::estimate`] names what a fit estimates: mass, viscous and
//! Coulomb friction, and where the axis has them the constant force, the
//! static level, the motor mass and the stiffness.

use std::f64::consts::PI;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

use crate::drive::{
    Controller, Drive, DriveStructure, FeedForward, FrictionLaw, LoopGains, LoopKind, Measured,
    Mechanics, StructureParam, VelocityEstimate,
};
use crate::error::{Error, Result};

/// Draws tried for one axis before it is given up.
const MAX_DRAWS: u64 = 20;

/// One axis of the family.
#[derive(Debug, Clone)]
pub struct StructureAxis {
    /// Its index in the family.
    pub index: usize,
    /// What it is, in a line.
    pub label: String,
    /// The true structure.
    pub truth: DriveStructure,
    /// Recording rate \[Hz\].
    pub rate_hz: f64,
    /// The program \[m\].
    pub command: Vec<f64>,
    /// Standard deviation of the measurement noise \[m\].
    pub noise_std_m: f64,
    /// The parameters a fit estimates.
    pub estimate: Vec<StructureParam>,
    /// Seed of its draw (and of its noise).
    pub seed: u64,
    /// The true (noise-free) position \[m\].
    pub clean: Vec<f64>,
}

impl StructureAxis {
    /// Axis `i` of the family (module doc), with its noise-free run.
    pub fn new(i: usize) -> Result<Self> {
        for attempt in 0..MAX_DRAWS {
            let mut a = draw(i, attempt);
            if !a.truth.closed_loop()?.stable {
                continue;
            }
            let size = a.command.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            if let Ok(run) = a.truth.simulate(&a.command, a.rate_hz, 0.0) {
                let worst = run
                    .position
                    .iter()
                    .zip(&a.command)
                    .fold(0.0_f64, |m, (y, u)| m.max((y - u).abs()));
                if worst < size {
                    a.clean = run.position;
                    return Ok(a);
                }
            }
        }
        Err(Error::InvalidModel {
            reason: "no draw of this structure axis has a stable loop",
        })
    }

    /// The measured position: the true one plus its noise (seeded).
    pub fn measured(&self) -> Vec<f64> {
        let mut rng = ChaCha8Rng::seed_from_u64(self.seed ^ 0xa5a5);
        match Normal::new(0.0, self.noise_std_m) {
            Ok(normal) => self
                .clean
                .iter()
                .map(|y| y + normal.sample(&mut rng))
                .collect(),
            Err(_) => self.clean.clone(),
        }
    }

    /// The truth with every estimated parameter moved by `share` (up and
    /// down in turn; a constant force from 0): a fit's start.
    pub fn start(&self, share: f64) -> DriveStructure {
        let mut start = self.truth.clone();
        for (j, &p) in self.estimate.iter().enumerate() {
            let t = p.get(&self.truth);
            let v = match p {
                StructureParam::Offset => 0.0,
                _ if j % 2 == 0 => (1.0 + share) * t,
                _ => t / (1.0 + share),
            };
            p.set(&mut start, v);
        }
        // a static level below the Coulomb level is no Stribeck law
        if let Some(s) = start.friction.r#static {
            start.friction.r#static = Some(s.max(1.05 * start.friction.coulomb));
        }
        start
    }
}

fn log_uniform(rng: &mut ChaCha8Rng, lo: f64, hi: f64) -> f64 {
    (lo.ln() + rng.random::<f64>() * (hi.ln() - lo.ln())).exp()
}

/// Draw `attempt` of axis `i` (module doc).
fn draw(i: usize, attempt: u64) -> StructureAxis {
    let seed = 0x5eed_0000 + i as u64 + 1_000_000 * attempt;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let kind = i % 4;
    let rate = log_uniform(&mut rng, 100.0, 20_000.0);
    let mass = log_uniform(&mut rng, 5.0, 500.0);
    let gain = log_uniform(&mut rng, 5.0, 100.0);
    // a sampled controller (its velocity estimate a sample and a half
    // late) keeps its loops and the mode further below the rate
    let sampled = i % 2 == 1 && rate >= 1000.0;
    let f_v = log_uniform(&mut rng, 20.0, 150.0).min(rate / if sampled { 30.0 } else { 15.0 });
    let w_v = 2.0 * PI * f_v;
    // the program
    let duration = (40_000.0 / rate).clamp(2.0, 8.0);
    let n = (duration * rate) as usize;
    let amplitude = log_uniform(&mut rng, 2e-3, 20e-3);
    let w0 = 2.0 * PI * 1.5 / duration;
    let command: Vec<f64> = (0..n)
        .map(|k| {
            let t = k as f64 / rate;
            amplitude * ((w0 * t).sin() + 0.3 * (6.3 * w0 * t).sin() + 0.1 * (23.7 * w0 * t).sin())
        })
        .collect();
    let a_peak = amplitude * w0 * w0 * (1.0 + 0.3 * 6.3 * 6.3 + 0.1 * 23.7 * 23.7);
    // friction
    let viscous = mass * log_uniform(&mut rng, 0.5, 3.0);
    let coulomb = mass * a_peak * log_uniform(&mut rng, 0.03, 0.15);
    let stribeck = i.is_multiple_of(3);
    let (r#static, stribeck_velocity) = if stribeck {
        (
            Some(coulomb * (1.2 + 0.4 * rng.random::<f64>())),
            Some(log_uniform(&mut rng, 1e-3, 5e-3)),
        )
    } else {
        (None, None)
    };
    let offset = if i.is_multiple_of(2) {
        let sign = if rng.random::<bool>() { 1.0 } else { -1.0 };
        sign * coulomb * (0.1 + 0.4 * rng.random::<f64>())
    } else {
        0.0
    };
    let friction = FrictionLaw {
        viscous,
        coulomb,
        coulomb_negative: None,
        r#static,
        stribeck_velocity,
        offset,
        smoothing_velocity: None,
    };
    let controller = Controller {
        sample_time: sampled.then_some(1.0 / rate),
        velocity_estimate: VelocityEstimate::Central,
        velocity_feedback: None,
    };
    let p = |kp: f64| LoopGains {
        kind: LoopKind::P,
        kp,
        ki: 0.0,
        kd: 0.0,
    };
    let none = LoopGains {
        kind: LoopKind::None,
        kp: 0.0,
        ki: 0.0,
        kd: 0.0,
    };
    let rigid = |mass: f64| Mechanics {
        mass,
        motor_mass: None,
        stiffness: None,
        damping: 0.0,
        measured: Measured::Load,
        motor_viscous: 0.0,
    };
    let drive = Drive { gain, limit: None };
    let no_ff = FeedForward::default();
    let (name, truth) = match kind {
        0 => (
            "P/P",
            DriveStructure {
                source: None,
                controller,
                position: p(w_v / 4.0),
                velocity: p(w_v * mass / gain),
                drive,
                current: None,
                mechanics: rigid(mass),
                friction,
                feed_forward: no_ff,
            },
        ),
        1 => (
            "P/PI vff+aff",
            DriveStructure {
                source: None,
                controller,
                position: p(w_v / 4.0),
                velocity: LoopGains {
                    kind: LoopKind::PI,
                    kp: w_v * mass / gain,
                    ki: w_v / 6.0,
                    kd: 0.0,
                },
                drive,
                current: None,
                mechanics: rigid(mass),
                friction,
                feed_forward: FeedForward {
                    velocity: 0.6 + 0.4 * rng.random::<f64>(),
                    acceleration: 0.8 * rng.random::<f64>(),
                },
            },
        ),
        2 => {
            // M·s² + g·kp·kd·s + g·kp: ω = w_v/2, ζ = 0.7
            let w = w_v / 2.0;
            (
                "PID force",
                DriveStructure {
                    source: None,
                    controller,
                    position: LoopGains {
                        kind: LoopKind::PID,
                        kp: w * w * mass / gain,
                        ki: w / 8.0,
                        kd: 1.4 / w,
                    },
                    velocity: none,
                    drive,
                    current: None,
                    mechanics: rigid(mass),
                    friction,
                    feed_forward: no_ff,
                },
            )
        }
        _ => {
            // the load and a motor side of 20–40 % of it, the mode 3–8× the
            // velocity loop's bandwidth (below a quarter of the rate)
            let motor = mass * (0.2 + 0.2 * rng.random::<f64>());
            let f_m = (f_v * (3.0 + 5.0 * rng.random::<f64>()))
                .min(rate / if sampled { 8.0 } else { 4.0 });
            let reduced = mass * motor / (mass + motor);
            let stiffness = (2.0 * PI * f_m).powi(2) * reduced;
            let damping = 2.0 * 0.05 * (stiffness * reduced).sqrt();
            (
                "P/P two-mass",
                DriveStructure {
                    source: None,
                    controller,
                    position: p(w_v / 4.0),
                    velocity: p(w_v * (mass + motor) / gain),
                    drive,
                    current: None,
                    mechanics: Mechanics {
                        mass,
                        motor_mass: Some(motor),
                        stiffness: Some(stiffness),
                        damping,
                        measured: Measured::Motor,
                        motor_viscous: 0.0,
                    },
                    friction,
                    feed_forward: no_ff,
                },
            )
        }
    };
    let mut estimate = vec![
        StructureParam::Mass,
        StructureParam::Viscous,
        StructureParam::Coulomb,
    ];
    if offset != 0.0 {
        estimate.push(StructureParam::Offset);
    }
    if stribeck {
        estimate.push(StructureParam::Static);
    }
    if kind == 3 {
        estimate.extend([StructureParam::MotorMass, StructureParam::Stiffness]);
    }
    let noise = log_uniform(&mut rng, 5e-8, 5e-7);
    let label = format!(
        "{name} @ {:.0} Hz{}, {mass:.1} kg, f_v {f_v:.1} Hz, Fc {coulomb:.1} N{}{}",
        rate,
        if sampled { " sampled" } else { "" },
        if stribeck { ", Stribeck" } else { "" },
        if offset != 0.0 { ", offset" } else { "" },
    );
    StructureAxis {
        index: i,
        label,
        truth,
        rate_hz: rate,
        command,
        noise_std_m: noise,
        estimate,
        seed,
        clean: Vec::new(),
    }
}
