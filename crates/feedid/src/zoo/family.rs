//! The zoo itself: the standard family of generated recordings, random access
//! by index, parallel generation.

use std::ops::Range;

use rayon::prelude::*;

use super::axis::{self, class_ranges, AxisInputs};
use super::command::{self, CommandKind, Limits};
use super::defects;
use super::design::{log_lerp, plant_group, Dim, Draws};
use super::disturbance::{
    self, Disturbance, Disturbed, ENCODER_COUNTS, ENCODER_MAX_RATE, FRICTION_SHARE, PULSE_SHARE,
    PULSE_WIDTH,
};
use super::member::ZooMember;
use super::spec::{AxisClass, MemberSpec, PlantKind, ServoSetup};
use super::{plant, servo};
use crate::drive::ForcePulses;
use crate::error::{Error, Result};

/// Seed of the standard zoo.
pub const ZOO_SEED: u64 = 13;
/// Members of the standard zoo without dropped rows.
pub const STANDARD_REGULAR: usize = 210;
/// Members of the standard zoo with dropped rows (after the regular ones).
pub const STANDARD_GAPPED: usize = 10;
/// Disturbed members of the standard zoo (after those with dropped rows).
pub const STANDARD_DISTURBED: usize = 30;
/// Members of the small subset (the first regular members).
pub const SMALL_MEMBERS: usize = 20;
/// Most rows of a member's recording.
pub const MAX_ROWS: usize = 20_000;
/// Most samples a member's loop is simulated at (rows × decimation).
pub const MAX_LOOP_SAMPLES: usize = 60_000;
/// Highest position-loop rate \[Hz\].
pub const MAX_LOOP_RATE: f64 = 20_000.0;
/// Fewest rows of a member (unless its command is shorter).
pub const MIN_ROWS: usize = 1000;

/// A family of generated recordings (see the module doc of [`crate::zoo`]).
///
/// ```
/// use feedid::zoo::Zoo;
/// let zoo = Zoo::standard();
/// assert_eq!(zoo.len(), 250);
/// let m = zoo.member(3).unwrap();
/// assert_eq!(m, zoo.member(3).unwrap()); // the same bits every time
/// assert!(m.recording().is_ok());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Zoo {
    seed: u64,
    regular: usize,
    gapped: usize,
    disturbed: usize,
}

impl Zoo {
    /// The standard zoo: seed 13, 210 regular members, 10 with dropped rows
    /// and 30 disturbed.
    pub fn standard() -> Self {
        Self {
            seed: ZOO_SEED,
            regular: STANDARD_REGULAR,
            gapped: STANDARD_GAPPED,
            disturbed: STANDARD_DISTURBED,
        }
    }

    /// A zoo with another seed or size (member `i` depends on the seed, `i`
    /// and the number of regular members; gapped and disturbed members copy
    /// regular ones, so they need at least one).
    pub fn new(seed: u64, regular: usize, gapped: usize, disturbed: usize) -> Result<Self> {
        for (name, count) in [("gapped", gapped), ("disturbed", disturbed)] {
            if regular == 0 && count > 0 {
                return Err(Error::InvalidParameter {
                    name,
                    value: count as f64,
                    reason: "these members copy regular ones: needs at least one regular member",
                });
            }
        }
        Ok(Self {
            seed,
            regular,
            gapped,
            disturbed,
        })
    }

    /// Seed.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Number of members.
    pub fn len(&self) -> usize {
        self.regular + self.gapped + self.disturbed
    }

    /// True when the zoo has no member.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Indices of the members without dropped rows (every one readable).
    pub fn regular(&self) -> Range<usize> {
        0..self.regular
    }

    /// Indices of the members with dropped rows.
    pub fn gapped(&self) -> Range<usize> {
        self.regular..self.regular + self.gapped
    }

    /// Indices of the disturbed members (force pulses, strong friction, a
    /// coarse encoder at a low rate; every one readable).
    pub fn disturbed(&self) -> Range<usize> {
        self.regular + self.gapped..self.len()
    }

    /// Indices of every member the reader accepts: the regular members, then
    /// the disturbed ones.
    pub fn readable(&self) -> Vec<usize> {
        self.regular().chain(self.disturbed()).collect()
    }

    /// Indices of the small subset for fast tests: the first 20 regular
    /// members (every plant, command and feed-forward kind, two glitched).
    pub fn small(&self) -> Range<usize> {
        0..SMALL_MEMBERS.min(self.regular)
    }

    /// The description of member `index` (no simulation).
    pub fn spec(&self, index: usize) -> Result<MemberSpec> {
        Ok(self.plan(index)?.spec)
    }

    /// Generate member `index`.
    pub fn member(&self, index: usize) -> Result<ZooMember> {
        simulate(self.plan(index)?)
    }

    /// Generate several members in parallel (all cores), in the order given.
    pub fn members(&self, indices: &[usize]) -> Vec<Result<ZooMember>> {
        indices.par_iter().map(|&i| self.member(i)).collect()
    }

    /// Describe several members in parallel, in the order given.
    pub fn specs(&self, indices: &[usize]) -> Vec<Result<MemberSpec>> {
        indices.par_iter().map(|&i| self.spec(i)).collect()
    }

    /// The regular member a gapped member copies.
    fn gap_source(&self, g: usize) -> usize {
        (g * 23 + 4) % self.regular
    }

    fn plan(&self, index: usize) -> Result<Plan> {
        if index >= self.len() {
            return Err(Error::InvalidParameter {
                name: "member",
                value: index as f64,
                reason: "is past the last member of the zoo",
            });
        }
        if index < self.regular {
            return plan_regular(self.seed, self.regular, index, &Overrides::default());
        }
        if index >= self.regular + self.gapped {
            return self.plan_disturbed(index, index - self.regular - self.gapped);
        }
        let source = self.gap_source(index - self.regular);
        let mut plan = plan_regular(self.seed, self.regular, source, &Overrides::default())?;
        let mut d = Draws::new(self.seed, index, self.regular);
        let rows = defects::dropped_rows(&mut d, plan.rows);
        let s = &mut plan.spec;
        s.index = index;
        s.samples = plan.rows - rows.len();
        s.dropped_rows = rows;
        s.gap_source = Some(source);
        s.label = s.make_label();
        Ok(plan)
    }
}

impl Zoo {
    /// The regular member the `d`-th disturbed member copies: candidates of
    /// its kind (disturbance.rs), spread evenly.
    fn disturbed_source(&self, d: usize) -> Result<usize> {
        let kind = disturbance::kind_of(d);
        let is_rig = |i: usize| plant_group(i) <= 2;
        let reverses = |i: usize| {
            matches!(
                CommandKind::of(i),
                CommandKind::Sweep
                    | CommandKind::Square
                    | CommandKind::PointToPoint
                    | CommandKind::Contour
            )
        };
        // coarse encoders alternate between servo and rig axes (servo
        // actuators are where low rates and coarse counts are common)
        let servo_turn = (d / 3).is_multiple_of(2);
        let candidates: Vec<usize> = self
            .regular()
            .filter(|&i| match kind {
                0 => is_rig(i),
                1 => is_rig(i) && reverses(i),
                _ => is_rig(i) != servo_turn,
            })
            .collect();
        if candidates.is_empty() {
            return Err(Error::InvalidParameter {
                name: "disturbed",
                value: self.disturbed as f64,
                reason: "no regular member of the kind a disturbed member copies",
            });
        }
        // the golden-ratio sequence: well spread for any count, and irregular
        // enough not to follow the design's cycles (command, feed-forward)
        let golden = 0.5 * (5f64.sqrt() - 1.0);
        let u = (0.05 + 0.3 * kind as f64 + (d / 3) as f64 * golden).fract();
        let at = ((u * candidates.len() as f64) as usize).min(candidates.len() - 1);
        Ok(candidates[at])
    }

    fn plan_disturbed(&self, index: usize, d: usize) -> Result<Plan> {
        let source = self.disturbed_source(d)?;
        let mut draws = Draws::new(self.seed, index, self.regular);
        let kind = disturbance::kind_of(d);
        let overrides = match kind {
            1 => Overrides {
                friction_share: Some(draws.uniform(FRICTION_SHARE.0, FRICTION_SHARE.1)),
                ..Overrides::default()
            },
            2 => Overrides {
                max_rate: ENCODER_MAX_RATE,
                ..Overrides::default()
            },
            _ => Overrides::default(),
        };
        let mut plan = plan_regular(self.seed, self.regular, source, &overrides)?;
        let s = &mut plan.spec;
        let disturbance = match kind {
            0 => {
                let Some(rig) = s.rig.as_mut() else {
                    return Err(Error::InvalidModel {
                        reason: "zoo: force pulses need a rig member",
                    });
                };
                let p = &rig.params;
                let peak_force = p.motor.kt * rig.effects.current_limit / p.r();
                let share = draws.uniform(PULSE_SHARE.0, PULSE_SHARE.1);
                let width = draws
                    .log_uniform(PULSE_WIDTH.0, PULSE_WIDTH.1)
                    .max(2.0 / s.loop_rate_hz);
                let period = (s.duration_s / draws.uniform(3.0, 8.0)).max(2.0 * width);
                let first = s.duration_s * draws.uniform(0.05, 0.3);
                let pulses = ForcePulses {
                    force: draws.sign() * share * peak_force,
                    width,
                    period,
                    first,
                };
                rig.effects.pulses = pulses;
                Disturbance::Pulses { pulses, share }
            }
            1 => Disturbance::Friction {
                share: s.friction_share,
            },
            _ => {
                let counts = draws.log_uniform(ENCODER_COUNTS.0, ENCODER_COUNTS.1);
                let q = s.amplitude_m / counts;
                s.resolution_m = q;
                s.noise_std_m = 0.0;
                if let Some(rig) = s.rig.as_mut() {
                    rig.effects.quantisation = true;
                    rig.effects.resolution = q;
                    rig.effects.noise = false;
                    rig.effects.noise_std = 0.0;
                }
                Disturbance::Encoder { counts }
            }
        };
        s.index = index;
        s.disturbed = Some(Disturbed {
            source,
            disturbance,
        });
        s.label = s.make_label();
        Ok(plan)
    }
}

/// Changes to the design of a regular member (disturbed members).
#[derive(Debug, Clone, Copy)]
struct Overrides {
    /// Coulomb friction share in place of the design's (rig members).
    friction_share: Option<f64>,
    /// Highest recording rate \[Hz\] (the rate quantile maps onto the range up to it).
    max_rate: f64,
}

impl Default for Overrides {
    fn default() -> Self {
        Self {
            friction_share: None,
            max_rate: MAX_LOOP_RATE,
        }
    }
}

/// A member before simulation.
struct Plan {
    spec: MemberSpec,
    /// Command at the loop rate, `(rows − 1)·decimation + 1` samples.
    command: Vec<f64>,
    /// Loop samples per recorded row.
    decimation: usize,
    /// Rows of the uniform recording.
    rows: usize,
}

/// Plant of member `i` (design.rs).
fn plant_of(i: usize) -> PlantKind {
    match plant_group(i) {
        0 => PlantKind::Rig(AxisClass::Heavy),
        1 => PlantKind::Rig(AxisClass::Conventional),
        2 => PlantKind::Rig(AxisClass::Stiff),
        3 => PlantKind::FirstOrder,
        _ => PlantKind::SecondOrder,
    }
}

/// Range of Kv \[1/s\] of the servo members.
const SERVO_KV: (f64, f64) = (10.0, 3000.0);

/// What a member's design fixes before its rate is final.
struct Fixed {
    i: usize,
    plant: PlantKind,
    kind: CommandKind,
    kv_asked: f64,
    amplitude: f64,
    resolution: f64,
    noise_std: f64,
    dead_time: usize,
    kvff: f64,
    kaff: f64,
    wanted: f64,
    friction_share: f64,
    backlash: f64,
    placed_mode_hz: Option<f64>,
    zeta: f64,
}

fn plan_regular(seed: u64, regular: usize, i: usize, over: &Overrides) -> Result<Plan> {
    let d = Draws::new(seed, i, regular);
    let plant = plant_of(i);
    let (kv_range, amplitude_max) = match plant {
        PlantKind::Rig(c) => {
            let r = class_ranges(c);
            (r.kv, r.amplitude_max)
        }
        _ => (SERVO_KV, 1.0),
    };
    let kv_asked = d.log_in(Dim::Kv, kv_range);
    // recording rate: a loop of Kv·Δt ≤ 0.15 within 20 samples per row
    let rate_lo = (kv_asked / (0.15 * 20.0)).max(100.0);
    let mut rate = d.log_in(Dim::Rate, (rate_lo, over.max_rate.max(rate_lo)));
    let resolution = d.log_in(Dim::Resolution, (1e-9, 2e-5));
    let u_noise = d.u(Dim::Noise);
    let ff_mode = (i / 7) % 3;
    let is_rig = matches!(plant, PlantKind::Rig(_));
    let fixed = Fixed {
        i,
        plant,
        kind: CommandKind::of(i),
        kv_asked,
        amplitude: d.log_in(Dim::Amplitude, (1e-4, amplitude_max)),
        resolution,
        noise_std: if u_noise < 0.1 {
            0.0
        } else {
            resolution * log_lerp(0.05, 3.0, (u_noise - 0.1) / 0.9)
        },
        dead_time: ((d.u(Dim::DeadTime) * 4.0) as usize).min(3),
        kvff: if ff_mode > 0 {
            d.lin_in(Dim::Kvff, (0.8, 1.0))
        } else {
            0.0
        },
        kaff: if ff_mode == 2 && is_rig {
            d.lin_in(Dim::Kaff, (0.5, 1.0))
        } else {
            0.0
        },
        wanted: d.log_in(Dim::Duration, (1.0, 5.0)),
        friction_share: match (is_rig, over.friction_share) {
            (false, _) => 0.0,
            (true, Some(f)) => f,
            (true, None) => d.lin_in(Dim::Friction, (0.0, 0.1)),
        },
        backlash: if is_rig && d.u(Dim::Backlash) < 0.35 {
            d.lin_in(Dim::BacklashWidth, (1e-6, 2e-5))
        } else {
            0.0
        },
        placed_mode_hz: (is_rig && d.u(Dim::Resonance) < 0.3)
            .then(|| d.log_in(Dim::ResonanceFrequency, (20.0, 300.0))),
        zeta: d.lin_in(Dim::ServoDamping, (0.35, 1.2)),
    };
    // a move too long for the row cap is recorded at a lower rate (a trace
    // buffer of fixed size), down to the lowest rate the loop allows; each
    // attempt starts from the same draws, so the member is the single pass at
    // the final rate
    for _ in 0..4 {
        let mut dd = d.clone();
        let (plan, needed, max_duration) = attempt(&fixed, rate, &mut dd)?;
        if needed <= max_duration * (1.0 + 1e-9) || rate <= rate_lo * (1.0 + 1e-9) {
            return Ok(plan);
        }
        rate = (rate * max_duration / needed * 0.999).max(rate_lo);
    }
    let mut dd = d.clone();
    Ok(attempt(&fixed, rate, &mut dd)?.0)
}

/// Plan a member at recording rate `rate`; also the length its command
/// needs and the longest allowed \[s\].
fn attempt(f: &Fixed, rate: f64, d: &mut Draws) -> Result<(Plan, f64, f64)> {
    let loop_min = (f.kv_asked / 0.15).max(250.0);
    let mut decimation = ((loop_min / rate) * (1.0 - 1e-12)).ceil().max(1.0) as usize;
    while decimation > 1 && rate * decimation as f64 > MAX_LOOP_RATE * (1.0 + 1e-12) {
        decimation -= 1;
    }
    let decimation = decimation.min(20);
    let loop_rate = rate * decimation as f64;
    let max_rows = MAX_ROWS.min(MAX_LOOP_SAMPLES / decimation);
    let rows0 = ((f.wanted * rate).round() as usize).clamp(MIN_ROWS, max_rows);
    let loop_dt = 1.0 / loop_rate;
    let (kv, velocity_bandwidth, velocity, acceleration, rig, servo_setup, mass, mode, placed);
    let stability;
    match f.plant {
        PlantKind::Rig(class) => {
            let a = axis::build(
                d,
                &AxisInputs {
                    class,
                    kv: f.kv_asked,
                    stroke: f.amplitude,
                    kvff: f.kvff,
                    kaff: f.kaff,
                    friction_share: f.friction_share,
                    backlash: f.backlash,
                    placed_mode_hz: f.placed_mode_hz,
                    resolution: f.resolution,
                    noise_std: f.noise_std,
                    dead_time: f.dead_time * decimation,
                    loop_dt,
                },
            )?;
            kv = a.kv;
            velocity_bandwidth = Some(a.velocity_bandwidth);
            velocity = a.velocity;
            acceleration = a.acceleration;
            rig = Some(a.setup);
            servo_setup = None;
            mass = Some(a.mass);
            mode = Some(a.axial_mode_hz);
            placed = a.placed;
            stability = a.stability;
        }
        PlantKind::FirstOrder | PlantKind::SecondOrder => {
            let s = ServoSetup {
                kv: f.kv_asked,
                velocity_bandwidth: (f.plant == PlantKind::SecondOrder)
                    .then_some(4.0 * f.zeta * f.zeta * f.kv_asked),
                kvff: f.kvff,
            };
            kv = f.kv_asked;
            velocity_bandwidth = s.velocity_bandwidth;
            velocity = d.log_in(Dim::Velocity, (0.05, 2.0));
            acceleration = d.log_in(Dim::Acceleration, (2.0, 50.0));
            stability = servo::check(&s, loop_dt)?;
            rig = None;
            servo_setup = Some(s);
            mass = None;
            mode = None;
            placed = false;
        }
    }
    let max_duration = max_rows as f64 / rate;
    let limits = Limits {
        amplitude: f.amplitude,
        velocity,
        acceleration,
        kv,
        rate,
        loop_rate,
        duration: rows0 as f64 / rate,
        max_duration,
    };
    let planned = command::plan(f.kind, &limits, d);
    let rows = ((planned.duration * rate).round() as usize).clamp(2, max_rows);
    let command = command::sample(&planned.spec, loop_rate, (rows - 1) * decimation + 1)?;
    let amplitude_m = command
        .iter()
        .step_by(decimation)
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let glitches = if f.i % 12 == 5 {
        defects::glitches(d, rows, amplitude_m)
    } else {
        Vec::new()
    };
    let noise_seed = d.seed();
    let two_pi = 2.0 * std::f64::consts::PI;
    let mut spec = MemberSpec {
        index: f.i,
        label: String::new(),
        plant: f.plant,
        rate_hz: rate,
        loop_rate_hz: loop_rate,
        samples: rows,
        duration_s: rows as f64 / rate,
        kv,
        velocity_bandwidth_hz: velocity_bandwidth.map(|w| w / two_pi),
        kvff: f.kvff,
        kaff: f.kaff,
        mass_kg: mass,
        axial_mode_hz: mode,
        resonance_placed: placed,
        friction_share: f.friction_share,
        backlash_m: f.backlash,
        dead_time_samples: f.dead_time,
        resolution_m: f.resolution,
        noise_std_m: f.noise_std,
        amplitude_m,
        command: planned.spec,
        glitches,
        dropped_rows: Vec::new(),
        gap_source: None,
        disturbed: None,
        noise_seed,
        stability,
        rig,
        servo: servo_setup,
    };
    spec.label = spec.make_label();
    Ok((
        Plan {
            spec,
            command,
            decimation,
            rows,
        },
        planned.needed,
        max_duration,
    ))
}

/// Simulate a planned member.
fn simulate(plan: Plan) -> Result<ZooMember> {
    let Plan {
        spec,
        command,
        decimation: m,
        rows,
    } = plan;
    let (measured, truth) = plant::run_loop(&spec, &command, spec.noise_seed)?;
    let keep = |k: usize| spec.dropped_rows.binary_search(&k).is_err();
    let pick =
        |v: &[f64]| -> Vec<f64> { (0..rows).filter(|&k| keep(k)).map(|k| v[k * m]).collect() };
    let time: Vec<f64> = (0..rows)
        .filter(|&k| keep(k))
        .map(|k| k as f64 / spec.rate_hz)
        .collect();
    let mut position: Vec<f64> = (0..rows).map(|k| measured[k * m]).collect();
    for g in &spec.glitches {
        position[g.index] += g.offset;
    }
    let position = (0..rows)
        .filter(|&k| keep(k))
        .map(|k| position[k])
        .collect();
    Ok(ZooMember {
        time,
        command: pick(&command),
        position,
        truth: pick(&truth),
        spec,
    })
}
