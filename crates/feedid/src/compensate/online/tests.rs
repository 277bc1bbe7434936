use super::*;

/// The loop `y[k] = a·y[k−1] + (1 − a)·u[k−1]` closed through a compensator:
/// commands, positions (noise-free), and the compensator.
fn run_lag(
    cfg: OnlineConfig,
    a: f64,
    desired: &[f64],
    noise: &[f64],
) -> (Vec<f64>, Vec<f64>, OnlineCompensator) {
    let mut comp = OnlineCompensator::new(cfg, 1e-3).unwrap();
    let n = desired.len();
    let mut fed = 0;
    while fed <= cfg.preview {
        comp.push_desired(desired[fed]).unwrap();
        fed += 1;
    }
    let mut u = vec![comp.first_command().unwrap()];
    let mut y = vec![desired[0]];
    for k in 0..n - 1 {
        if fed < n {
            comp.push_desired(desired[fed]).unwrap();
            fed += 1;
        } else {
            comp.finish_desired();
        }
        let next = comp.step(y[k] + noise[k]).unwrap();
        y.push(a * y[k] + (1.0 - a) * u[k]);
        u.push(next);
    }
    (u, y, comp)
}

fn plain_lag(a: f64, desired: &[f64]) -> Vec<f64> {
    let mut y = vec![desired[0]];
    for k in 0..desired.len() - 1 {
        y.push(a * y[k] + (1.0 - a) * desired[k]);
    }
    y
}

fn sine(n: usize) -> Vec<f64> {
    (0..n).map(|k| 1e-3 * (k as f64 * 3e-3).sin()).collect()
}

/// Largest |y − r| from sample `from` to 100 samples before the end (the
/// sine stops abruptly there).
fn max_error(y: &[f64], r: &[f64], from: usize) -> f64 {
    let to = r.len() - 100;
    y[from..to]
        .iter()
        .zip(&r[from..to])
        .map(|(p, q)| (p - q).abs())
        .fold(0.0, f64::max)
}

#[test]
fn the_lag_of_a_first_order_loop_is_identified_and_removed() {
    // y = (1 − a)·q⁻¹/(1 − a·q⁻¹)·u: lag α₁ = dt·(1/(1 − a) − ½ + ½) = dt/(1 − a)
    let a = 0.8;
    let r = sine(4000);
    let (_, y, comp) = run_lag(OnlineConfig::default(), a, &r, &vec![0.0; r.len()]);
    assert_eq!(comp.state(), OnlineState::Active);
    let [a1, _, _] = comp.following_error_model();
    // the sampled lag: mean delay of the impulse response, Σk·h[k] = 1/(1 − a)
    let lag = 1e-3 / (1.0 - a);
    assert!((a1 - lag).abs() < 0.02 * lag, "{a1} vs {lag}");
    let plain = max_error(&plain_lag(a, &r), &r, 3000);
    let comp_err = max_error(&y, &r, 3000);

    assert!(plain > 1e-5, "{plain}");
    assert!(comp_err < 2e-3 * plain, "{comp_err} vs {plain}");
}

#[test]
fn the_correction_is_the_inverse_series_of_the_identified_model() {
    let r = sine(4000);
    for terms in 1..=3 {
        let cfg = OnlineConfig {
            terms,
            ..OnlineConfig::default()
        };
        // the compensator stepped to sample k (its model then is the one
        // the command of sample k + 1 was made with)
        let mut comp = OnlineCompensator::new(cfg, 1e-3).unwrap();
        let k = 3000;
        for &v in &r[..=cfg.preview] {
            comp.push_desired(v).unwrap();
        }
        let mut u = vec![comp.first_command().unwrap()];
        let mut y = vec![0.0];
        for i in 0..k {
            comp.push_desired(r[i + 1 + cfg.preview]).unwrap();
            let next = comp.step(y[i]).unwrap();
            y.push(0.8 * y[i] + 0.2 * u[i]);
            u.push(next);
        }
        let [a1, a2, a3] = comp.following_error_model();
        let series = [a1, a2 + a1 * a1, a3 + 2.0 * a1 * a2 + a1.powi(3)];
        let t = comp.time_constants();
        for i in 0..3 {
            let expected = if i < terms { series[i] } else { 0.0 };
            assert!(
                (t[i] - expected).abs() <= 1e-12 * expected.abs().max(a1.abs().powi(i as i32 + 1)),
                "terms {terms}, T{}: {} vs {expected}",
                i + 1,
                t[i]
            );
            if i >= terms {
                assert_eq!(
                    [a1, a2, a3][i],
                    0.0,
                    "terms {terms}: α{} not identified",
                    i + 1
                );
            }
        }
        // the last command: r + T·derivatives of r (weight 1, no limit)
        let at = |i: usize| r[i];
        let dt = 1e-3;
        let d1 = (at(k + 1) - at(k - 1)) / (2.0 * dt);
        let d2 = (at(k + 1) - 2.0 * at(k) + at(k - 1)) / (dt * dt);
        let d3 = (at(k + 2) - 2.0 * at(k + 1) + 2.0 * at(k - 1) - at(k - 2)) / (2.0 * dt * dt * dt);
        let expected = r[k] + t[0] * d1 + t[1] * d2 + t[2] * d3;
        assert!(
            (u[k] - expected).abs() < 1e-12,
            "terms {terms}: {} vs {expected}",
            u[k]
        );
    }
}

#[test]
fn units_do_not_change_the_commands() {
    let r = sine(3000);
    let noise: Vec<f64> = (0..r.len())
        .map(|k| 1e-7 * ((k * 7919) % 13) as f64 / 13.0)
        .collect();
    let (u, _, _) = run_lag(OnlineConfig::default(), 0.7, &r, &noise);
    let scaled: Vec<f64> = r.iter().map(|v| v * 1e3).collect();
    let noise_mm: Vec<f64> = noise.iter().map(|v| v * 1e3).collect();
    let cfg = OnlineConfig {
        max_velocity: 1e3,
        max_acceleration: 3e4,
        ..OnlineConfig::default()
    };
    let (u_mm, _, _) = run_lag(cfg, 0.7, &scaled, &noise_mm);
    for (a, b) in u.iter().zip(&u_mm) {
        assert!((a * 1e3 - b).abs() <= 1e-9 * b.abs().max(1.0), "{a} {b}");
    }
}

#[test]
fn every_command_meets_the_limits_or_the_plain_trajectorys_own_values() {
    let r = sine(4000);
    let cfg = OnlineConfig {
        max_velocity: 3.05e-3,
        max_acceleration: 9.5e-3,
        ..OnlineConfig::default()
    };
    let (u, _, comp) = run_lag(cfg, 0.8, &r, &vec![0.0; r.len()]);
    assert!(comp.stats().limited > 0);
    let dt = 1e-3;
    for k in 2..u.len() {
        let v = (u[k] - u[k - 1]).abs() / dt;
        let a = (u[k] - 2.0 * u[k - 1] + u[k - 2]).abs() / (dt * dt);
        let vr = (r[k] - r[k - 1]).abs() / dt;
        let ar = (r[k] - 2.0 * r[k - 1] + r[k - 2]).abs() / (dt * dt);
        let tol = 1.0 + 1e-9;
        assert!(a <= cfg.max_acceleration.max(ar) * tol, "{k}: {a}");
        assert!(v <= cfg.max_velocity.max(vr) * tol, "{k}: {v}");
    }
}

#[test]
fn a_model_that_explains_nothing_sends_the_plain_command() {
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};
    let r = sine(4000);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let nd = Normal::new(0.0, 1e-3).unwrap();
    // the position measured: noise far above the following error
    let noise: Vec<f64> = (0..r.len()).map(|_| nd.sample(&mut rng)).collect();
    let (u, _, comp) = run_lag(OnlineConfig::default(), 0.8, &r, &noise);
    assert_eq!(comp.state(), OnlineState::Unexplained);
    assert_eq!(comp.stats().compensated, 0);
    for (a, b) in u.iter().zip(&r) {
        assert_eq!(a, b);
    }
}

#[test]
fn at_rest_nothing_is_learnt_and_the_command_rests() {
    let r = vec![2e-3; 500];
    let (u, _, comp) = run_lag(OnlineConfig::default(), 0.8, &r, &vec![1e-7; r.len()]);
    assert_eq!(comp.stats().model_updates, 0);
    assert_eq!(comp.state(), OnlineState::Learning);
    assert!(u.iter().all(|v| *v == 2e-3));
}

#[test]
fn bad_settings_and_samples_are_refused() {
    let bad = [
        OnlineConfig {
            preview: 33,
            ..OnlineConfig::default()
        },
        OnlineConfig {
            preview: 1,
            ..OnlineConfig::default()
        },
        OnlineConfig {
            lambda: 1.0,
            ..OnlineConfig::default()
        },
        OnlineConfig {
            max_velocity: f64::NAN,
            ..OnlineConfig::default()
        },
        OnlineConfig {
            max_unexplained_share: 0.0,
            ..OnlineConfig::default()
        },
        OnlineConfig {
            blend_samples: 0,
            ..OnlineConfig::default()
        },
    ];
    for cfg in bad {
        assert!(OnlineCompensator::new(cfg, 1e-3).is_err(), "{cfg:?}");
    }
    assert!(OnlineCompensator::new(OnlineConfig::default(), 0.0).is_err());
    let mut c = OnlineCompensator::new(OnlineConfig::default(), 1e-3).unwrap();
    assert!(c.first_command().is_err(), "no desired sample yet");
    assert!(c.push_desired(f64::NAN).is_err());
    c.push_desired(0.0).unwrap();
    c.first_command().unwrap();
    assert!(c.first_command().is_err(), "only once");
    // not enough preview for the next command
    let e = c.step(0.0).unwrap_err();
    assert!(e.to_string().contains("preview"), "{e}");
    for _ in 0..5 {
        c.push_desired(0.0).unwrap();
    }
    assert!(c.step(f64::INFINITY).is_err());
    assert_eq!(c.step(0.0).unwrap(), 0.0);
    // too far ahead
    let mut c = OnlineCompensator::new(OnlineConfig::default(), 1e-3).unwrap();
    for _ in 0..64 {
        c.push_desired(0.0).unwrap();
    }
    assert!(c.push_desired(0.0).is_err());
}
