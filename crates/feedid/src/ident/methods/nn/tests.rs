use super::net::{add_squared_error_gradient, forward, Scratch, Shape};
use super::train::candle_gradient;
use super::*;
use crate::drive::{RigParams, VirtualRig};
use crate::error::Error;
use crate::ident::engine::{run, EngineConfig, Estimator, SlidingResult};
use crate::ident::{ArxOrders, Method};
use crate::signal::Scenario;
use crate::Recording;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The virtual rig (every effect on: friction makes it nonlinear) on a
/// scenario at 5 kHz.
fn rig(scenario: Scenario, seconds: f64) -> Recording {
    let rate = 5000.0;
    let command = scenario.command(rate, seconds, 1).unwrap();
    let out = VirtualRig::new(RigParams::default())
        .with_seed(3)
        .simulate(&command, rate)
        .unwrap();
    Recording::new(out.time, out.command, out.position).unwrap()
}

fn slide(config: &NnConfig, rec: &Recording) -> (SlidingResult, NnEstimator) {
    let mut est = config.build().unwrap();
    let cfg = EngineConfig {
        window: 100,
        horizon: 10,
        hop: None,
        warm_up: 0,
    };
    let r = run(&mut est, &rec.signals(), &cfg).unwrap();
    (r, est)
}

fn range(v: &[f64]) -> f64 {
    let (lo, hi) = v
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    hi - lo
}

#[test]
fn hand_written_gradient_equals_candles_automatic_differentiation() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for (f, h, n) in [(1, 1, 1), (5, 6, 20), (7, 16, 64)] {
        let shape = Shape { f, h };
        let p: Vec<f64> = (0..shape.params())
            .map(|_| rng.random_range(-0.8..0.8))
            .collect();
        let x: Vec<f64> = (0..n * f).map(|_| rng.random_range(-2.0..2.0)).collect();
        let t: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
        let reference = candle_gradient(shape, &p, &x, &t).unwrap();
        let mut grad = vec![0.0; shape.params()];
        let mut s = Scratch::new(shape);
        for (row, &ti) in x.chunks_exact(f).zip(&t) {
            add_squared_error_gradient(shape, &p, row, ti, 1.0 / n as f64, &mut s, &mut grad);
        }
        let scale = reference.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        for (k, (a, b)) in grad.iter().zip(&reference).enumerate() {
            assert!(
                (a - b).abs() <= 1e-12 * scale.max(1.0),
                "f {f} h {h}: parameter {k}: {a} vs candle {b}"
            );
        }
    }
}

#[test]
fn candle_and_the_plain_forward_pass_agree() {
    // the loss candle differentiates, through `train::mse` (plain forward)
    let shape = Shape { f: 3, h: 5 };
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let p: Vec<f64> = (0..shape.params())
        .map(|_| rng.random_range(-1.0..1.0))
        .collect();
    let x: Vec<f64> = (0..30).map(|_| rng.random_range(-1.0..1.0)).collect();
    let t = vec![0.0; 10];
    // with t = 0 the gradient of the bias b₃ is the mean of 2·f(z)
    let g = candle_gradient(shape, &p, &x, &t).unwrap();
    let b3 = shape.layout().b3;
    let mut s = Scratch::new(shape);
    let mean: f64 = x
        .chunks_exact(3)
        .map(|z| 2.0 * forward(shape, &p, z, &mut s))
        .sum::<f64>()
        / 10.0;
    assert!((g[b3] - mean).abs() < 1e-13, "{} vs {mean}", g[b3]);
}

#[test]
fn training_lowers_the_loss_on_a_known_system() {
    // the rig with friction: the least-squares linear start is not the
    // best one-step predictor, the network learns what it misses
    let rec = rig(Scenario::Prbs, 1.0);
    let (r, est) = slide(&NnConfig::default(), &rec);
    let r0 = est.last_training().unwrap();
    let (epochs, best, start_hold, hold) = (
        r0.epochs,
        r0.best_epoch,
        r0.start_holdout_mse,
        r0.holdout_mse,
    );
    let (start_train, train) = r0.train_mse;
    assert!(epochs >= 1 && best >= 1, "epochs {epochs}, kept {best}");
    assert!(
        train < 0.95 * start_train,
        "training mse {start_train} -> {train}"
    );
    assert!(hold < start_hold, "held-out mse {start_hold} -> {hold}");
    assert!(r.stats.samples > 9 * rec.len() / 10, "{}", r.stats.samples);
    assert!(
        r.stats.rms.is_finite() && r.stats.rms < 5e-6,
        "{}",
        r.stats.rms
    );
}

#[test]
fn the_same_seed_gives_the_same_predictions_and_another_seed_others() {
    let rec = rig(Scenario::Chirp, 0.4);
    let (a, _) = slide(&NnConfig::default(), &rec);
    let (b, _) = slide(&NnConfig::default(), &rec);
    let tol = 1e-12 * range(rec.position());
    assert_eq!(a.has_prediction, b.has_prediction);
    for (k, (x, y)) in a.predicted.iter().zip(&b.predicted).enumerate() {
        assert!((x - y).abs() <= tol, "sample {k}: {x} vs {y}");
    }
    let (c, _) = slide(
        &NnConfig {
            seed: 1,
            ..NnConfig::default()
        },
        &rec,
    );
    assert!(a.predicted.iter().zip(&c.predicted).any(|(x, y)| x != y));
}

#[test]
fn predictions_follow_a_change_of_unit_and_offset() {
    let rec = rig(Scenario::Scurve, 0.3);
    let (a, _) = slide(&NnConfig::default(), &rec);
    let (k, off) = (1e3, 250.0);
    let moved = Recording::new(
        rec.time().to_vec(),
        rec.command().iter().map(|v| k * v + off).collect(),
        rec.position().iter().map(|v| k * v + off).collect(),
    )
    .unwrap();
    let (b, _) = slide(&NnConfig::default(), &moved);
    assert_eq!(a.has_prediction, b.has_prediction);
    let tol = 1e-6 * range(rec.position());
    for (i, (x, y)) in a.predicted.iter().zip(&b.predicted).enumerate() {
        if a.has_prediction[i] {
            assert!(
                ((y - off) / k - x).abs() <= tol,
                "sample {i}: {x} vs {}",
                (y - off) / k
            );
        }
    }
}

/// A first-order servo `y[k] = y[k−1] + g·(u[k] − y[k−1])` whose gain `g`
/// jumps from 0.05 to 0.2 halfway, on a staircase command.
fn changing_drive() -> Recording {
    let n = 8000;
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let mut u = vec![0.0; n];
    let mut level = 0.0;
    for (k, v) in u.iter_mut().enumerate() {
        if k % 97 == 0 && k > 0 {
            level = rng.random_range(-1e-3..1e-3);
        }
        *v = level;
    }
    let mut y = vec![0.0; n];
    for k in 1..n {
        let g = if k < n / 2 { 0.05 } else { 0.2 };
        y[k] = y[k - 1] + g * (u[k] - y[k - 1]);
    }
    let t = (0..n).map(|k| k as f64 * 2e-4).collect();
    Recording::new(t, u, y).unwrap()
}

#[test]
fn online_steps_follow_a_drive_that_changes() {
    let rec = changing_drive();
    let fixed = NnConfig {
        train_samples: 2000,
        ..NnConfig::default()
    };
    let online = NnConfig {
        online_steps: 5,
        learning_rate: 3e-3,
        ..fixed.clone()
    };
    let (a, _) = slide(&fixed, &rec);
    let (b, est) = slide(&online, &rec);
    assert!(est.config().online_steps == 5);
    let late = |r: &SlidingResult| {
        let from = rec.len() * 3 / 4;
        let (mut s, mut n) = (0.0, 0);
        for k in from..rec.len() {
            if r.has_prediction[k] {
                s += (r.predicted[k] - rec.position()[k]).powi(2);
                n += 1;
            }
        }
        assert!(n > 1000);
        (s / n as f64).sqrt()
    };
    let (fixed_rms, online_rms) = (late(&a), late(&b));
    assert!(
        online_rms < 0.5 * fixed_rms,
        "after the change: fixed {fixed_rms:e}, online {online_rms:e}"
    );
}

#[test]
fn nothing_is_predicted_before_the_first_training_nor_learnt_before_the_first_motion() {
    // 300 samples at rest, then a ramp
    let n = 1500;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * 2e-4).collect();
    let u: Vec<f64> = (0..n)
        .map(|k: usize| k.saturating_sub(300) as f64 * 1e-6)
        .collect();
    let mut y = vec![0.0; n];
    for k in 1..n {
        y[k] = y[k - 1] + 0.1 * (u[k] - y[k - 1]);
    }
    let rec = Recording::new(t, u, y).unwrap();
    let mut est = NnConfig::default().build().unwrap();
    let s = rec.signals();
    let mut coef = vec![0.0; est.coefficient_names().len()];
    // the rest teaches nothing: no training, every window refused with a reason
    let e = est.fit(&s, 100..300, &mut coef).unwrap_err();
    assert!(
        matches!(e, Error::Singular { context } if context.contains("not trained")),
        "{e}"
    );
    assert_eq!(est.learning_samples(), 0);
    // 100 samples after the first motion it has trained and predicts
    assert!(est.fit(&s, 250..380, &mut coef).is_err());
    est.fit(&s, 300..402, &mut coef).unwrap();
    assert!(est.is_trained());
    let mut out = [0.0; 10];
    est.predict(&s, 300..402, 402..412, &mut out).unwrap();
    assert!(out.iter().all(|v| v.is_finite()));
    let err = out
        .iter()
        .zip(&rec.position()[402..412])
        .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(err < 1e-6, "{err:e}");
}

#[test]
fn settings_outside_their_bounds_are_refused_with_the_value() {
    let cases: [(&str, NnConfig); 6] = [
        (
            "hidden",
            NnConfig {
                hidden: 0,
                ..NnConfig::default()
            },
        ),
        (
            "hidden",
            NnConfig {
                hidden: 257,
                ..NnConfig::default()
            },
        ),
        (
            "train_samples",
            NnConfig {
                train_samples: 99,
                ..NnConfig::default()
            },
        ),
        (
            "epochs",
            NnConfig {
                epochs: 10_001,
                ..NnConfig::default()
            },
        ),
        (
            "online_steps",
            NnConfig {
                online_steps: 101,
                ..NnConfig::default()
            },
        ),
        (
            "learning_rate",
            NnConfig {
                learning_rate: 0.0,
                ..NnConfig::default()
            },
        ),
    ];
    for (key, c) in cases {
        let e = c.validate().unwrap_err();
        assert!(
            matches!(e, Error::InvalidParameter { name, .. } if name == key),
            "{key}: {e}"
        );
    }
    let c = NnConfig {
        orders: ArxOrders::new(0, 3, 0),
        ..NnConfig::default()
    };
    assert!(c.validate().is_err());
    // through the option interface: parsed, bounded, refused with the limit
    let mut m: Method = "nn".parse().unwrap();
    m.set_option("hidden", "8").unwrap();
    m.set_option("online_steps", "3").unwrap();
    assert_eq!(m.label(), "NN 8,8,0 h=8");
    let e = m.set_option("train_samples", "5000000").unwrap_err();
    assert!(e.to_string().contains("[100, 1e6]"), "{e}");
    assert!(m.set_option("order", "0,2,0").is_err());
    assert_eq!(m.option("online_steps").as_deref(), Some("3"));
}

#[test]
fn a_linear_drive_is_predicted_about_as_well_as_by_windowed_arx() {
    let rate = 5000.0;
    let command = Scenario::Prbs.command(rate, 1.0, 1).unwrap();
    let out = VirtualRig::linear(RigParams::default())
        .simulate(&command, rate)
        .unwrap();
    let rec = Recording::new(out.time, out.command, out.position).unwrap();
    let (nn, _) = slide(&NnConfig::default(), &rec);
    let arx: Method = "arx".parse().unwrap();
    let mut est = arx.build().unwrap();
    let cfg = EngineConfig {
        window: 100,
        horizon: 10,
        hop: None,
        warm_up: 0,
    };
    let a = run(&mut est, &rec.signals(), &cfg).unwrap();
    // on the samples both predict
    let (mut sn, mut sa, mut n) = (0.0, 0.0, 0);
    for k in 0..rec.len() {
        if nn.has_prediction[k] && a.has_prediction[k] {
            sn += (nn.predicted[k] - rec.position()[k]).powi(2);
            sa += (a.predicted[k] - rec.position()[k]).powi(2);
            n += 1;
        }
    }
    assert!(n > 4000);
    assert!(sn <= 2.0 * sa.max(1e-30), "nn {sn:e} vs arx {sa:e}");
}
