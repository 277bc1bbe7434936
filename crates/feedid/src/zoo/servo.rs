//! Simple servo plants: the position loop around an ideal (first-order) or a
//! first-order-lag (second-order) velocity loop, as linear-motor axes and
//! small actuators with fast inner loops behave.
//!
//! ```text
//! first order:   ẋ = Kv·(x_s − x) + kvff·ẋ_s                   X/X_s = (kvff·s + Kv)/(s + Kv)
//! second order:  v̇ = ω_v·(Kv·(x_s − x) + kvff·ẋ_s − v), ẋ = v   X/X_s = ω_v·(kvff·s + Kv)/(s² + ω_v·s + ω_v·Kv)
//! ```
//!
//! with `ω_v = 4ζ²·Kv` for the damping ratio ζ ∈ [0.35, 1.2]. Both follow a
//! ramp with the error `(1 − kvff)·v/Kv`. They are simulated exactly: the
//! zero-order-hold discretisation of the transfer function at the loop rate,
//! from rest. Quantisation, noise, dead time and glitches are added by the zoo
//! as for the rig (the loop closes on the true position).

use super::axis::{merge_continuous, merge_sampled};
use super::spec::{ServoSetup, Stability};
use crate::error::Result;
use crate::lti::TransferFunction;

/// The transfer function of a servo member.
pub(crate) fn transfer_function(s: &ServoSetup) -> Result<TransferFunction> {
    match s.velocity_bandwidth {
        None => TransferFunction::new(vec![s.kvff, s.kv], vec![1.0, s.kv]),
        Some(wv) => TransferFunction::new(vec![wv * s.kvff, wv * s.kv], vec![1.0, wv, wv * s.kv]),
    }
}

/// Poles of the servo and of its ZOH image at `loop_dt`.
pub(crate) fn check(s: &ServoSetup, loop_dt: f64) -> Result<Stability> {
    let tf = transfer_function(s)?;
    let mut st = Stability {
        max_real_part: f64::NEG_INFINITY,
        min_damping: f64::INFINITY,
        spectral_radius: 0.0,
        fastest_pole: 0.0,
    };
    merge_continuous(&mut st, &tf.poles()?);
    let disc = tf.to_state_space()?.discretize_zoh(loop_dt)?;
    merge_sampled(&mut st, &disc.poles()?, loop_dt);
    Ok(st)
}

/// Response of the servo to `command` sampled every `loop_dt` \[s\] (ZOH), from rest.
pub(crate) fn simulate(s: &ServoSetup, command: &[f64], loop_dt: f64) -> Result<Vec<f64>> {
    transfer_function(s)?
        .to_state_space()?
        .simulate(command, loop_dt, None)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_order_servo_step_is_the_exponential_and_ramp_error_closed_form() {
        let s = ServoSetup {
            kv: 50.0,
            velocity_bandwidth: None,
            kvff: 0.0,
        };
        let dt = 1e-3;
        let y = simulate(&s, &[1.0; 200], dt).unwrap();
        for (k, v) in y.iter().enumerate() {
            let want = 1.0 - (-50.0 * k as f64 * dt).exp();
            assert!((v - want).abs() < 1e-12, "k {k}");
        }
        // ramp: steady error (1 − kvff)·v/Kv (sampled at the instants of a
        // held command: plus half a sample of lag)
        for kvff in [0.0, 0.6] {
            let s = ServoSetup { kvff, ..s };
            let cmd: Vec<f64> = (0..2000).map(|k| 0.1 * k as f64 * dt).collect();
            let y = simulate(&s, &cmd, dt).unwrap();
            let e = cmd[1999] - y[1999];
            // ZOH of kvff + (1 − kvff)·Kv/(s + Kv) on a sampled ramp: the lag
            // of the discrete pole q = e^{−Kv·dt} is v·dt/(1 − q) ≈ v/Kv + v·dt/2
            let q = (-50.0 * dt).exp();
            let want = (1.0 - kvff) * 0.1 * dt / (1.0 - q);
            assert!((e - want).abs() < 1e-12, "kvff {kvff}: {e} vs {want}");
            assert!((e - (1.0 - kvff) * 0.1 / 50.0).abs() < 0.1 * dt, "{e}");
        }
    }

    #[test]
    fn second_order_servo_has_the_drawn_damping_and_is_stable() {
        let kv = 100.0;
        for zeta in [0.35, 0.7, 1.2] {
            let s = ServoSetup {
                kv,
                velocity_bandwidth: Some(4.0 * zeta * zeta * kv),
                kvff: 0.9,
            };
            let st = check(&s, 1e-3).unwrap();
            assert!(st.max_real_part < 0.0 && st.spectral_radius < 1.0);
            if zeta < 1.0 {
                assert!((st.min_damping - zeta).abs() < 1e-6, "{st:?}");
            }
            assert!((transfer_function(&s).unwrap().dc_gain() - 1.0).abs() < 1e-15);
        }
    }
}
