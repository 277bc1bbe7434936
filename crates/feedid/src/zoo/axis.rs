//! The recipe of a rig member: mechanics from the mass and the stroke, a motor
//! sized for the axis's acceleration, and a cascade tuned the way a
//! commissioning engineer would — current loop by pole–zero cancellation,
//! velocity loop from the rigid inertia, position loop below it, and every
//! bandwidth kept under the axial mode.
//!
//! For moving mass `M`, lead `ℓ` (`r = ℓ/2π`), stroke `±A`, axis acceleration
//! `a_cap` and speed `v_cap` (ranges per [`AxisClass`] in [`class_ranges`]):
//!
//! ```text
//! screw      L = 2A + 0.1 m, nut at A + 0.05 m (travel 0.05 … 2A + 0.05 m),
//!            d = max(12 mm·(M/5 kg)^¼, ℓ, L/40, 8 mm), root 0.82·d,
//!            K_bearing = 5.6e9·d, K_nut = 1e10·d  [N/m, d in m]   (the default rig's per metre of d)
//! inertia    J_m = (M·r² + J_screw)/λ,  λ ∈ [1, 5] (load-to-motor ratio), J_bearings = 0.1·J_m
//! axial mode ω_res² = K·(1/M + r²/J); a "placed" mode (20–300 Hz) softens the nut to
//!            K = ω²/(1/M + r²/J) (a soft coupling or column standing for the first structural mode)
//! motor      F_pk = 1.25·(J/r² + M)·a_cap·(1 + 1.6·f),  I_max ∈ [4, 40] A,  Kt = Ke = F_pk·r/I_max,
//!            U_max = max(24 V, Ke·v_cap/(0.6·r)),  R = 0.15·U_max/I_max,  L = R·τ_e, τ_e ∈ [1, 8] ms
//! loops      ω_v = ρ_v·Kv (ρ_v ∈ [2.5, 4]) and ω_v ≤ ω_res/1.8  (the default rig: 1.87),
//!            Kp = ω_v·(J + M·r²)/(Kt·r),  Ki = ω_v/ρ_i (ρ_i ∈ [3, 6]),
//!            ω_c = clamp(6·ω_v, 2π·400, 2π·5000) rad/s,  Kpi = L·ω_c,  Kii = R/L,
//!            Kv = ω_v/ρ_v (lowered with ω_v when the mode limits it)
//! damping    C2 = M·[5, 40] 1/s,  C1 = J·[1, 5] 1/s
//! friction   table only: F_c = f·F_pk/(1 + 1.6 f), breakaway 1.1–1.6·F_c, Stribeck 0.5–10 mm/s
//! ```
//!
//! The default rig follows the same rules (Kii = R/L, Kpi = L·2π·2 kHz,
//! ω_v = 2π·300 Hz ≈ 2.7·Kv, Ki = ω_v/4). The linear closed loop of every
//! member is checked (continuous poles at the rest position and both ends of
//! the travel, and the sampled position loop at the loop rate); a tuning that
//! fails (a real part ≥ 0, a damping ratio below 1e-4 or a spectral radius
//! ≥ 1) is detuned by 0.8 in ω_v and Kv until it passes. The rig has no
//! damping inside the screw, so an axial mode far above the loops keeps only
//! the light damping of the guides (damping ratios down to ~1e-3, as the
//! manifest's `min_damping` shows). The RK4 step is
//! `0.35/|λ_max|` of the fastest closed-loop pole (at most a loop sample), and
//! the friction regularisation `v_ε ≥ 4·F_s·h/M` keeps the friction knee
//! inside the integrator's stability region.

use nalgebra::Complex;

use super::design::{Dim, Draws};
use super::spec::{AxisClass, RigSetup, Stability};
use crate::drive::{
    closed_loop_state_space, closed_loop_state_space_with_stiffness, ForcePulses, Friction,
    PositionLoop, RigEffects, RigParams,
};
use crate::error::{Error, Result};
use crate::lti::{DiscreteStateSpace, StateSpace};

/// Ranges of an axis class (SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ClassRanges {
    /// Moving mass \[kg\].
    pub mass: (f64, f64),
    /// Position-loop gain \[1/s\] (before the mode limits it).
    pub kv: (f64, f64),
    /// Peak acceleration of the axis \[m/s²\].
    pub acceleration: (f64, f64),
    /// Top speed \[m/s\].
    pub velocity: (f64, f64),
    /// Screw lead \[m\].
    pub lead: (f64, f64),
    /// Largest stroke ±A \[m\].
    pub amplitude_max: f64,
}

/// The ranges of each class.
pub(crate) fn class_ranges(class: AxisClass) -> ClassRanges {
    match class {
        AxisClass::Heavy => ClassRanges {
            mass: (50.0, 500.0),
            kv: (10.0, 40.0),
            acceleration: (1.0, 4.0),
            velocity: (0.1, 0.5),
            lead: (0.010, 0.040),
            amplitude_max: 1.0,
        },
        AxisClass::Conventional => ClassRanges {
            mass: (10.0, 150.0),
            kv: (17.0, 170.0),
            acceleration: (2.0, 8.0),
            velocity: (0.2, 1.0),
            lead: (0.005, 0.025),
            amplitude_max: 0.5,
        },
        AxisClass::Stiff => ClassRanges {
            mass: (0.5, 30.0),
            kv: (100.0, 1000.0),
            acceleration: (5.0, 20.0),
            velocity: (0.1, 1.0),
            lead: (0.005, 0.020),
            amplitude_max: 0.2,
        },
    }
}

/// What the member's design fixed before the recipe.
#[derive(Debug, Clone, Copy)]
pub(crate) struct AxisInputs {
    /// Class.
    pub class: AxisClass,
    /// Position-loop gain asked for \[1/s\].
    pub kv: f64,
    /// Stroke ±A \[m\].
    pub stroke: f64,
    /// Feed-forward gains.
    pub kvff: f64,
    /// Acceleration feed-forward gain.
    pub kaff: f64,
    /// Coulomb friction share of the peak force.
    pub friction_share: f64,
    /// Backlash width \[m\] (0 = none).
    pub backlash: f64,
    /// Placed axial mode \[Hz\], if any.
    pub placed_mode_hz: Option<f64>,
    /// Encoder resolution \[m\].
    pub resolution: f64,
    /// Noise std \[m\].
    pub noise_std: f64,
    /// Dead time \[loop samples\].
    pub dead_time: usize,
    /// Loop sample interval \[s\].
    pub loop_dt: f64,
}

/// The rig of a member and what the recipe derived.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Axis {
    /// Parameters, effects and step.
    pub setup: RigSetup,
    /// Final position-loop gain \[1/s\].
    pub kv: f64,
    /// Velocity-loop bandwidth \[rad/s\].
    pub velocity_bandwidth: f64,
    /// Moving mass \[kg\].
    pub mass: f64,
    /// Axial mode at rest \[Hz\].
    pub axial_mode_hz: f64,
    /// The mode was placed.
    pub placed: bool,
    /// Peak acceleration the axis is built for \[m/s²\].
    pub acceleration: f64,
    /// Top speed \[m/s\].
    pub velocity: f64,
    /// Linear closed-loop checks.
    pub stability: Stability,
}

/// Build the rig of a member (see the module doc).
pub(crate) fn build(d: &mut Draws, inp: &AxisInputs) -> Result<Axis> {
    let ranges = class_ranges(inp.class);
    let two_pi = 2.0 * std::f64::consts::PI;
    let mass = d.log_in(Dim::Mass, ranges.mass);
    let lead = d.log_in(Dim::Lead, ranges.lead);
    let r = lead / two_pi;
    let a = inp.stroke;
    let mut p = RigParams::default();
    // mechanics
    let screw_length = 2.0 * a + 0.1;
    let diameter = (0.012 * (mass / 5.0).powf(0.25))
        .max(lead)
        .max(screw_length / 40.0)
        .max(0.008);
    p.geometry.lead = lead;
    p.geometry.screw_diameter = diameter;
    p.geometry.root_diameter = 0.82 * diameter;
    p.geometry.screw_length = screw_length;
    p.geometry.nut_position = a + 0.05;
    p.stiffness.bearing = 5.6e9 * diameter;
    p.stiffness.nut = 1e10 * diameter;
    p.table.mass = mass;
    let lambda = d.log_in(Dim::InertiaRatio, (1.0, 5.0));
    let j_load = mass * r * r + p.screw_inertia();
    p.inertia.motor = j_load / lambda;
    p.inertia.bearings = 0.1 * p.inertia.motor;
    let j = p.inertia_j();
    let mode = |k: f64| (k * (1.0 / mass + r * r / j)).sqrt();
    let mut omega_res = mode(p.stiffness_k());
    let mut placed = false;
    if let Some(f) = inp.placed_mode_hz {
        let target = two_pi * f;
        if target < 0.95 * omega_res {
            let k_target = target * target / (1.0 / mass + r * r / j);
            let rest =
                1.0 / k_target - 1.0 / p.screw_stiffness() - 1.0 / (2.0 * p.stiffness.bearing);
            if rest > 0.0 {
                p.stiffness.nut = 1.0 / rest;
                omega_res = mode(p.stiffness_k());
                placed = true;
            }
        }
    }
    // motor and drive
    let acceleration = d.log_in(Dim::Acceleration, ranges.acceleration);
    let velocity = d.log_in(Dim::Velocity, ranges.velocity);
    let rigid_mass = j / (r * r) + mass;
    let f = inp.friction_share;
    let peak_force = 1.25 * rigid_mass * acceleration * (1.0 + 1.6 * f);
    let current_limit = d.log_in(Dim::CurrentLimit, (4.0, 40.0));
    let kt = peak_force * r / current_limit;
    p.motor.kt = kt;
    p.motor.ke = kt;
    let voltage_limit = (kt * velocity / r / 0.6).max(24.0);
    p.motor.resistance = 0.15 * voltage_limit / current_limit;
    p.motor.inductance = p.motor.resistance * d.log_in(Dim::ElectricalTime, (1e-3, 8e-3));
    p.damping.c2 = mass * d.log_in(Dim::Damping, (5.0, 40.0));
    p.damping.c1 = j * d.uniform(1.0, 5.0);
    // loops
    let rho_v = d.lin_in(Dim::VelocityRatio, (2.5, 4.0));
    let rho_i = d.lin_in(Dim::ResetRatio, (3.0, 6.0));
    let mut omega_v = (rho_v * inp.kv).min(omega_res / 1.8);
    p.control.kvff = inp.kvff;
    p.control.kaff = inp.kaff;
    // friction and effects (the smoothing speed follows the step, below)
    let coulomb = f * peak_force / (1.0 + 1.6 * f);
    let breakaway = coulomb * d.uniform(1.1, 1.6);
    let stribeck = d.log_uniform(5e-4, 1e-2);
    let travel = [0.05, p.geometry.nut_position, 2.0 * a + 0.05];
    let variable = d.u(Dim::VariableStiffness) < 0.6;
    for _ in 0..40 {
        tune(&mut p, omega_v, rho_v, rho_i);
        let stiffnesses: Vec<f64> = if variable {
            travel.iter().map(|&l| p.stiffness_at(l)).collect()
        } else {
            vec![p.stiffness_k()]
        };
        let stability = check(&p, &stiffnesses, inp.loop_dt)?;
        if stability.max_real_part < 0.0
            && stability.min_damping >= 1e-4
            && stability.spectral_radius < 1.0
        {
            let h = (0.35 / stability.fastest_pole).min(inp.loop_dt);
            let table_friction = Friction {
                coulomb,
                breakaway,
                stribeck_velocity: stribeck,
                smoothing_velocity: (stribeck / 10.0).max(4.0 * breakaway * h / mass),
            };
            let effects = RigEffects {
                friction: f > 0.0,
                motor_friction: Friction {
                    coulomb: 0.0,
                    breakaway: 0.0,
                    ..Friction::motor_default()
                },
                table_friction,
                variable_stiffness: variable,
                limits: true,
                current_limit,
                voltage_limit,
                quantisation: true,
                resolution: inp.resolution,
                noise: inp.noise_std > 0.0,
                noise_std: inp.noise_std,
                position_loop: PositionLoop::Sampled,
                backlash: inp.backlash > 0.0,
                backlash_width: if inp.backlash > 0.0 {
                    inp.backlash
                } else {
                    RigEffects::default().backlash_width
                },
                dead_time: inp.dead_time,
                pulses: ForcePulses::default(),
            };
            p.validate()?;
            effects.validate()?;
            return Ok(Axis {
                setup: RigSetup {
                    params: p,
                    effects,
                    max_step: h,
                },
                kv: p.control.kv,
                velocity_bandwidth: omega_v,
                mass,
                axial_mode_hz: omega_res / two_pi,
                placed,
                acceleration,
                velocity,
                stability,
            });
        }
        omega_v *= 0.8;
    }
    Err(Error::InvalidModel {
        reason: "zoo: no stable tuning of the rig member",
    })
}

/// Set the loop gains for velocity bandwidth `omega_v` (module doc).
fn tune(p: &mut RigParams, omega_v: f64, rho_v: f64, rho_i: f64) {
    let r = p.r();
    let j_total = p.inertia_j() + p.table.mass * r * r;
    let two_pi = 2.0 * std::f64::consts::PI;
    let omega_c = (6.0 * omega_v).clamp(two_pi * 400.0, two_pi * 5000.0);
    p.control.kp = omega_v * j_total / (p.motor.kt * r);
    p.control.ki = omega_v / rho_i;
    p.control.kv = omega_v / rho_v;
    p.control.kpi = p.motor.inductance * omega_c;
    p.control.kii = p.motor.resistance / p.motor.inductance;
}

/// Poles of the linear closed loop at each stiffness, and the sampled loop.
fn check(p: &RigParams, stiffnesses: &[f64], loop_dt: f64) -> Result<Stability> {
    let mut s = Stability {
        max_real_part: f64::NEG_INFINITY,
        min_damping: f64::INFINITY,
        spectral_radius: 0.0,
        fastest_pole: 0.0,
    };
    for &k in stiffnesses {
        let poles = closed_loop_state_space_with_stiffness(p, k)?.poles()?;
        merge_continuous(&mut s, &poles);
    }
    // the sampled position loop: x⁺ = Φx + Γ·Kv·(x_s − x_a)
    let mut open = *p;
    open.control.kvff = 0.0;
    open.control.kaff = 0.0;
    open.control.kv = 0.0;
    let a = closed_loop_state_space(&open)?;
    open.control.kv = 1.0;
    let bv = closed_loop_state_space(&open)?.b;
    let disc = StateSpace::new(a.a, bv, a.c, 0.0)?.discretize_zoh(loop_dt)?;
    let kv = p.control.kv;
    let closed = DiscreteStateSpace::from_parts(
        &disc.a - (&disc.b * &disc.c) * kv,
        &disc.b * kv,
        disc.c.clone(),
        0.0,
        loop_dt,
    )?;
    merge_sampled(&mut s, &closed.poles()?, loop_dt);
    Ok(s)
}

/// Fold continuous poles into the checks.
pub(crate) fn merge_continuous(s: &mut Stability, poles: &[Complex<f64>]) {
    for z in poles {
        s.max_real_part = s.max_real_part.max(z.re);
        s.fastest_pole = s.fastest_pole.max(z.norm());
        if z.norm() > 0.0 {
            s.min_damping = s.min_damping.min(-z.re / z.norm());
        }
    }
}

/// Fold sampled poles (their radius, and the damping of `ln z / Δt`) into the checks.
pub(crate) fn merge_sampled(s: &mut Stability, poles: &[Complex<f64>], dt: f64) {
    for z in poles {
        s.spectral_radius = s.spectral_radius.max(z.norm());
        if z.norm() > 0.0 {
            let sz = z.ln() / dt;
            if sz.norm() > 0.0 {
                s.min_damping = s.min_damping.min(-sz.re / sz.norm());
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_recipe_reproduces_the_default_rigs_current_loop_rules() {
        // the default rig: Kii = R/L, Kpi = L·ω_c with ω_c = 2π·2 kHz, Ki = ω_v/4
        let p = RigParams::default();
        let c = p.control;
        assert!((c.kii - p.motor.resistance / p.motor.inductance).abs() < 0.1);
        let omega_c = c.kpi / p.motor.inductance;
        assert!((omega_c / (2.0 * std::f64::consts::PI * 2000.0) - 1.0).abs() < 1e-3);
        let r = p.r();
        let omega_v = c.kp * p.motor.kt * r / (p.inertia_j() + p.table.mass * r * r);
        assert!((omega_v / c.ki - 4.0).abs() < 0.01, "{}", omega_v / c.ki);
        assert!((2.5..2.8).contains(&(omega_v / c.kv)), "{}", omega_v / c.kv);
        // and its velocity loop sits 1.87× under its axial mode (561 Hz)
        let ratio = 2.0 * std::f64::consts::PI * 561.0 / omega_v;
        assert!((1.8..1.95).contains(&ratio), "{ratio}");
    }

    #[test]
    fn the_default_rig_passes_the_stability_check() {
        let p = RigParams::default();
        let s = check(&p, &[p.stiffness_k()], 2e-4).unwrap();
        assert!(s.max_real_part < 0.0 && s.spectral_radius < 1.0, "{s:?}");
        assert!(s.min_damping > 0.1, "{s:?}");
        // fastest pole: 1430 Hz (docs/METHODS.md §2.5)
        let f = s.fastest_pole / (2.0 * std::f64::consts::PI);
        assert!((f - 1430.0).abs() < 10.0, "{f}");
    }

    #[test]
    fn the_check_catches_an_unstable_gain() {
        let mut p = RigParams::default();
        p.control.kv = 30_000.0;
        let s = check(&p, &[p.stiffness_k()], 2e-4).unwrap();
        assert!(s.max_real_part > 0.0 || s.spectral_radius >= 1.0, "{s:?}");
    }
}
