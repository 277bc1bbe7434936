//! Tests of the rig's feed-forward, backlash and dead time, and of the
//! encoder range: against exact discretisations of the linear model with
//! feed-forward and against closed forms.

use nalgebra::{DMatrix, DVector};

use super::*;
use crate::drive::{closed_loop_coefficients, D1Variant};
use crate::signal::{Ramp, Scurve, Step};

const RATE: f64 = 5000.0;

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

fn ff_params(kvff: f64, kaff: f64) -> RigParams {
    let mut p = RigParams::default();
    p.control.kvff = kvff;
    p.control.kaff = kaff;
    p
}

fn linear_with(p: RigParams, position_loop: PositionLoop) -> VirtualRig {
    VirtualRig::linear(p).with_effects(RigEffects {
        position_loop,
        ..RigEffects::linear()
    })
}

fn ramp_cmd() -> Vec<f64> {
    Ramp::default().generate(RATE, 0.8).unwrap()
}

fn scurve_cmd() -> Vec<f64> {
    Scurve::default().generate(RATE, 0.4).unwrap()
}

/// The open-P-loop cascade written out independently: `ẋ = A x + b_v·v_c + b_i·i_ff`.
fn open_loop(p: &RigParams) -> (DMatrix<f64>, DVector<f64>, DVector<f64>) {
    let (r, k, j, m) = (p.r(), p.stiffness_k(), p.inertia_j(), p.table.mass);
    let c = p.control;
    let mo = p.motor;
    let (c1, c2) = (p.damping.c1, p.damping.c2);
    let l = mo.inductance;
    let mut a = DMatrix::zeros(7, 7);
    // z_v' = v_c − r ω;  z_i' = i_ref − i;  i_ref = Kp (v_c − r ω + Ki z_v) + i_ff
    a[(0, 4)] = -r;
    a[(1, 0)] = c.kp * c.ki;
    a[(1, 4)] = -c.kp * r;
    a[(1, 2)] = -1.0;
    // L i' = Kpi (i_ref − i + Kii z_i) − R i − Ke ω
    a[(2, 0)] = c.kpi * c.kp * c.ki / l;
    a[(2, 4)] = (-c.kpi * c.kp * r - mo.ke) / l;
    a[(2, 2)] = (-c.kpi - mo.resistance) / l;
    a[(2, 1)] = c.kpi * c.kii / l;
    a[(3, 4)] = 1.0;
    a[(4, 2)] = mo.kt / j;
    a[(4, 4)] = -c1 / j;
    a[(4, 3)] = -r * k * r / j;
    a[(4, 5)] = r * k / j;
    a[(5, 6)] = 1.0;
    a[(6, 3)] = k * r / m;
    a[(6, 5)] = -k / m;
    a[(6, 6)] = -c2 / m;
    let bv = DVector::from_vec(vec![1.0, c.kp, c.kpi * c.kp / l, 0.0, 0.0, 0.0, 0.0]);
    let bi = DVector::from_vec(vec![0.0, 1.0, c.kpi / l, 0.0, 0.0, 0.0, 0.0]);
    (a, bv, bi)
}

/// Exact discretisation of the sampled loop with held velocity reference and
/// current feed-forward: `x⁺ = Φx + Γ_v·v_c[k] + Γ_i·i_ff[k]`, with
/// `v_c = Kv(x_s[k] − x_a[k]) + kvff·(x_s[k+1] − x_s[k])/Δt` and
/// `i_ff = c_a·(x_s[k+1] − 2x_s[k] + x_s[k−1])/Δt²` (x_s[−1] = x_s[0]).
fn exact_sampled_loop_with_ff(p: &RigParams, cmd: &[f64], dt: f64) -> Vec<f64> {
    let (a, bv, bi) = open_loop(p);
    let mut aug = DMatrix::zeros(9, 9);
    aug.view_mut((0, 0), (7, 7)).copy_from(&a);
    aug.view_mut((0, 7), (7, 1)).copy_from(&bv);
    aug.view_mut((0, 8), (7, 1)).copy_from(&bi);
    let e = (aug * dt).exp();
    let phi = e.view((0, 0), (7, 7)).into_owned();
    let gv = e.view((0, 7), (7, 1)).into_owned();
    let gi = e.view((0, 8), (7, 1)).into_owned();
    let r = p.r();
    let ca = p.control.kaff * (p.inertia_j() + p.table.mass * r * r) / (r * p.motor.kt);
    let mut x = DVector::zeros(7);
    let mut y = Vec::with_capacity(cmd.len());
    for k in 0..cmd.len() {
        y.push(x[5]);
        if k + 1 == cmd.len() {
            break;
        }
        let prev = cmd[k.saturating_sub(1)];
        let vff = p.control.kvff * (cmd[k + 1] - cmd[k]) / dt;
        let acc = (cmd[k + 1] - 2.0 * cmd[k] + prev) / (dt * dt);
        let vc = p.control.kv * (cmd[k] - x[5]) + vff;
        x = &phi * &x + &gv * vc + &gi * (ca * acc);
    }
    y
}

/// Exact sampled response of the transfer function `N(s)/D(s)` of
/// [`closed_loop_coefficients`] (a companion realisation, independent of the
/// rig and of the state-space model) to the command held (`foh = false`) or
/// interpolated linearly (`foh = true`) between samples.
fn exact_transfer_function_response(p: &RigParams, cmd: &[f64], dt: f64, foh: bool) -> Vec<f64> {
    let tf = closed_loop_coefficients(p, D1Variant::Corrected)
        .transfer_function()
        .unwrap();
    let ss = tf.to_state_space().unwrap();
    let n = ss.order();
    let mut aug = DMatrix::zeros(n + 2, n + 2);
    aug.view_mut((0, 0), (n, n)).copy_from(&ss.a);
    aug.view_mut((0, n), (n, 1)).copy_from(&ss.b);
    aug[(n, n + 1)] = 1.0;
    let e = (aug * dt).exp();
    let phi = e.view((0, 0), (n, n)).into_owned();
    let g0 = e.view((0, n), (n, 1)).into_owned();
    let g1 = e.view((0, n + 1), (n, 1)).into_owned();
    let mut x = DVector::zeros(n);
    let mut y = Vec::with_capacity(cmd.len());
    for k in 0..cmd.len() {
        y.push((&ss.c * &x)[0] + ss.d * cmd[k]);
        let slope = if foh && k + 1 < cmd.len() {
            (cmd[k + 1] - cmd[k]) / dt
        } else {
            0.0
        };
        x = &phi * &x + &g0 * cmd[k] + &g1 * slope;
    }
    y
}

const FF_CASES: [(f64, f64); 3] = [(0.9, 0.0), (0.0, 0.8), (1.0, 1.0)];

#[test]
fn feed_forward_rig_with_held_command_is_the_exact_zoh_discretisation_of_the_new_tf() {
    for (kvff, kaff) in FF_CASES {
        let p = ff_params(kvff, kaff);
        for cmd in [ramp_cmd(), scurve_cmd()] {
            let out = linear_with(p, PositionLoop::Continuous)
                .simulate(&cmd, RATE)
                .unwrap();
            let exact = exact_transfer_function_response(&p, &cmd, 1.0 / RATE, false);
            let d = max_abs_diff(&out.true_position, &exact);
            assert!(d < 1e-10, "kvff {kvff} kaff {kaff}: max diff {d}");
        }
    }
}

#[test]
fn feed_forward_rig_with_interpolated_command_is_the_exact_foh_discretisation_of_the_new_tf() {
    for (kvff, kaff) in FF_CASES {
        let p = ff_params(kvff, kaff);
        for cmd in [ramp_cmd(), scurve_cmd()] {
            let out = linear_with(p, PositionLoop::Interpolated)
                .simulate(&cmd, RATE)
                .unwrap();
            let exact = exact_transfer_function_response(&p, &cmd, 1.0 / RATE, true);
            let d = max_abs_diff(&out.true_position, &exact);
            assert!(d < 1e-10, "kvff {kvff} kaff {kaff}: max diff {d}");
        }
    }
}

#[test]
fn feed_forward_rig_with_sampled_loop_is_the_exact_discretisation_with_held_references() {
    for (kvff, kaff) in FF_CASES {
        let p = ff_params(kvff, kaff);
        for cmd in [ramp_cmd(), scurve_cmd()] {
            let out = linear_with(p, PositionLoop::Sampled)
                .simulate(&cmd, RATE)
                .unwrap();
            let exact = exact_sampled_loop_with_ff(&p, &cmd, 1.0 / RATE);
            let d = max_abs_diff(&out.true_position, &exact);
            assert!(d < 1e-10, "kvff {kvff} kaff {kaff}: max diff {d}");
        }
    }
}

#[test]
fn ramp_following_error_is_one_minus_kvff_times_v_over_kv() {
    let cmd = ramp_cmd();
    let v = 0.05;
    for (kvff, kaff) in [(0.5, 0.0), (0.9, 0.6), (1.0, 1.0)] {
        let p = ff_params(kvff, kaff);
        let expected = (1.0 - kvff) * v / p.control.kv;
        // the coefficients say so too: (D1 − N1 − F1)/D0 = (1 − kvff)/Kv
        let c = closed_loop_coefficients(&p, D1Variant::Corrected);
        let per_v = c.following_error_per_velocity();
        assert!(
            (per_v - (1.0 - kvff) / p.control.kv).abs() < 1e-12 / p.control.kv,
            "{per_v}"
        );
        for pl in [PositionLoop::Sampled, PositionLoop::Interpolated] {
            let out = linear_with(p, pl).simulate(&cmd, RATE).unwrap();
            // steady part of the ramp: 0.3 s … 0.6 s
            for (k, (c, x)) in cmd
                .iter()
                .zip(&out.true_position)
                .enumerate()
                .take(3000)
                .skip(1500)
            {
                let e = c - x;
                assert!(
                    (e - expected).abs() < 1e-8,
                    "kvff {kvff} {pl:?} k={k}: {e} vs {expected}"
                );
            }
        }
    }
}

#[test]
fn acceleration_feed_forward_reduces_the_error_of_a_jerk_limited_move() {
    // with kvff = 1 the remaining error is inertial: kaff = 1 removes most of it
    let cmd = scurve_cmd();
    let peak = |p: RigParams| {
        let out = linear_with(p, PositionLoop::Sampled)
            .simulate(&cmd, RATE)
            .unwrap();
        max_abs_diff(&cmd, &out.true_position)
    };
    let none = peak(ff_params(0.0, 0.0));
    let velocity = peak(ff_params(1.0, 0.0));
    let both = peak(ff_params(1.0, 1.0));
    assert!(velocity < 0.2 * none, "{none} {velocity}");
    assert!(both < 0.2 * velocity, "{velocity} {both}");
}

#[test]
fn zero_feed_forward_and_effects_switched_on_with_zero_values_change_no_bit() {
    let cmd = Step::default().generate(RATE, 0.05).unwrap();
    let base = VirtualRig::new(RigParams::default()).with_seed(3);
    let a = base.simulate(&cmd, RATE).unwrap();
    let fx = RigEffects {
        backlash: true,
        backlash_width: 0.0,
        dead_time: 0,
        ..RigEffects::default()
    };
    let b = base.clone().with_effects(fx).simulate(&cmd, RATE).unwrap();
    assert_eq!(a, b);
}

#[test]
fn dead_time_delays_the_response_by_whole_samples() {
    let cmd = scurve_cmd();
    for pl in [
        PositionLoop::Sampled,
        PositionLoop::Continuous,
        PositionLoop::Interpolated,
    ] {
        for p in [RigParams::default(), ff_params(1.0, 1.0)] {
            let fx = RigEffects {
                position_loop: pl,
                friction: true,
                ..RigEffects::linear()
            };
            let rig = VirtualRig::new(p).with_effects(fx);
            let a = rig.simulate(&cmd, RATE).unwrap();
            for d in 1..=3 {
                let b = rig
                    .clone()
                    .with_effects(RigEffects { dead_time: d, ..fx })
                    .simulate(&cmd, RATE)
                    .unwrap();
                assert_eq!(b.command, cmd);
                // the command rests 50 samples at 0: the delayed run is the
                // same run shifted by d samples, bit for bit
                assert_eq!(&b.true_position[d..], &a.true_position[..cmd.len() - d]);
                assert!(b.true_position[..d].iter().all(|&v| v == 0.0));
            }
        }
    }
}

#[test]
fn backlash_is_a_dead_band_of_the_screw_force() {
    let p = RigParams::default();
    let width = 1e-5;
    let fx = RigEffects {
        backlash: true,
        backlash_width: width,
        ..RigEffects::linear()
    };
    let plant = Plant::new(&p, &fx);
    let r = p.r();
    let k = p.stiffness_k();
    let m = p.table.mass;
    let input = Input::Held { vc: 0.0, iff: 0.0 };
    let table_acceleration = |stretch: f64| {
        let x = [0.0, 0.0, 0.0, stretch / r, 0.0, 0.0, 0.0];
        plant.deriv(&x, input, 0.0, 0.0)[6]
    };
    for s in [-0.49 * width, -0.2 * width, 0.0, 0.3 * width, 0.5 * width] {
        assert_eq!(table_acceleration(s), 0.0, "stretch {s}");
    }
    for extra in [1e-7, 1e-6, 3e-6] {
        let a = table_acceleration(0.5 * width + extra);
        assert!((a - k * extra / m).abs() < 1e-9 * k * extra / m, "{a}");
        let a = table_acceleration(-0.5 * width - extra);
        assert!((a + k * extra / m).abs() < 1e-9 * k * extra / m, "{a}");
    }
}

#[test]
fn backlash_adds_lost_motion_at_reversals_only() {
    // a slow sine (reversals) with friction: backlash shows as extra error
    // near the reversals, bounded by the play, and nowhere on the steady move
    let rate = 2000.0;
    let n = 4000;
    let cmd: Vec<f64> = (0..n)
        .map(|k| {
            let t = k as f64 / rate;
            if t < 0.01 {
                0.0
            } else {
                1e-3 * (1.0 - (2.0 * std::f64::consts::PI * (t - 0.01)).cos())
            }
        })
        .collect();
    let base = RigEffects {
        friction: true,
        position_loop: PositionLoop::Sampled,
        ..RigEffects::linear()
    };
    let width = 2e-5;
    let run = |fx: RigEffects| {
        VirtualRig::new(RigParams::default())
            .with_effects(fx)
            .simulate(&cmd, rate)
            .unwrap()
            .true_position
    };
    let plain = run(base);
    let with = run(RigEffects {
        backlash: true,
        backlash_width: width,
        ..base
    });
    let d = max_abs_diff(&plain, &with);
    assert!(d > 0.05 * width && d < 2.0 * width, "difference {d}");
    // the largest difference comes within 100 ms after a reversal (t = 0.51, 1.01, 1.51 s)
    let worst = plain
        .iter()
        .zip(&with)
        .map(|(a, b)| (a - b).abs())
        .enumerate()
        .fold((0, 0.0), |acc, (k, e)| if e > acc.1 { (k, e) } else { acc });
    let t = worst.0 as f64 / rate;
    let since = (t - 0.01) % 1.0;
    assert!(
        (0.5..0.6).contains(&since) || since < 0.1,
        "worst at t = {t} s"
    );
}

#[test]
fn encoder_resolution_from_one_nanometre_to_twenty_micrometres() {
    let cmd = scurve_cmd();
    for q in [1e-9, 1e-8, 1e-6, 2e-5] {
        let fx = RigEffects {
            noise: false,
            resolution: q,
            ..RigEffects::default()
        };
        let out = VirtualRig::new(RigParams::default())
            .with_effects(fx)
            .simulate(&cmd, RATE)
            .unwrap();
        assert!(out.position.iter().all(|v| v.is_finite()));
        for (&m, &t) in out.position.iter().zip(&out.true_position) {
            let units = m / q;
            assert!((units - units.round()).abs() < 1e-6, "q {q}: {m}");
            assert!((m - t).abs() <= 0.5 * q * (1.0 + 1e-9), "q {q}");
        }
        // the loop follows to within a few counts (plus the dynamics) at rest
        let last = *out.true_position.last().unwrap();
        assert!((last - 0.02).abs() < 3.0 * q + 2e-7, "q {q}: {last}");
    }
}

#[test]
fn new_effects_read_from_toml_and_bad_values_are_rejected() {
    let fx: RigEffects =
        toml::from_str("backlash = true\nbacklash_width = 1e-5\ndead_time = 2\n").unwrap();
    assert!(fx.backlash && fx.backlash_width == 1e-5 && fx.dead_time == 2);
    assert!(fx.friction, "missing keys keep their defaults");
    fx.validate().unwrap();
    let bad = RigEffects {
        backlash_width: -1e-6,
        ..RigEffects::default()
    };
    assert!(bad
        .validate()
        .unwrap_err()
        .to_string()
        .contains("backlash_width"));
    assert!(toml::from_str::<RigEffects>("dead_time = -1").is_err());
    let p = RigParams::from_toml_str("[control]\nkvff = 0.95\nkaff = 0.5\n", None).unwrap();
    assert_eq!((p.control.kvff, p.control.kaff), (0.95, 0.5));
    let e = RigParams::from_toml_str("[control]\nkvff = -0.1\n", None).unwrap_err();
    assert!(e.to_string().contains("control.kvff"), "{e}");
    let e = RigParams::from_toml_str("[control]\nkaff = 3\n", None).unwrap_err();
    assert!(e.to_string().contains("control.kaff"), "{e}");
}

#[test]
fn force_pulses_push_the_table_only_while_they_act_and_the_loop_recovers() {
    let cmd = ramp_cmd();
    let pulses = ForcePulses {
        force: 50.0,
        width: 0.01,
        period: 0.2,
        first: 0.3,
    };
    let fx = RigEffects {
        noise: false,
        quantisation: false,
        ..RigEffects::default()
    };
    let plain = VirtualRig::new(RigParams::default())
        .with_effects(fx)
        .simulate(&cmd, RATE)
        .unwrap();
    let pushed = VirtualRig::new(RigParams::default())
        .with_effects(RigEffects { pulses, ..fx })
        .simulate(&cmd, RATE)
        .unwrap();
    let first = (0.3 * RATE).round() as usize;
    // nothing changes before the first pulse, bit for bit
    assert_eq!(
        plain.true_position[..=first],
        pushed.true_position[..=first]
    );
    let dev: Vec<f64> = plain
        .true_position
        .iter()
        .zip(&pushed.true_position)
        .map(|(a, b)| b - a)
        .collect();
    // the push (+50 N) moves the table forward, the pull at 0.5 s back
    let during = |t0: f64| -> f64 {
        let k0 = (t0 * RATE) as usize;
        dev[k0..k0 + (0.02 * RATE) as usize]
            .iter()
            .copied()
            .fold(0.0, |m: f64, v| if v.abs() > m.abs() { v } else { m })
    };
    let (push, pull) = (during(0.3), during(0.5));
    assert!(push > 1e-7, "{push}");
    assert!(pull < -1e-7, "{pull}");
    // the velocity loop's integral rejects the force: gone before the next pulse
    let before_next = dev[(0.49 * RATE) as usize].abs();
    assert!(before_next < 0.1 * push.abs(), "{before_next} vs {push}");
    // read from TOML like every effect
    let fx: RigEffects = toml::from_str("[pulses]\nforce = 20.0\nwidth = 0.002\n").unwrap();
    assert_eq!(fx.pulses.force, 20.0);
    assert_eq!(fx.pulses.period, ForcePulses::default().period);
    let e = toml::from_str::<RigEffects>("[pulses]\nforce = 1.0\nwidth = 1.0\nperiod = 0.5\n")
        .unwrap()
        .validate()
        .unwrap_err();
    assert!(e.to_string().contains("pulses.period"), "{e}");
}
