//! Tests of the ARX estimator and the batch fit.

// Index loops mirror the formulas.
#![allow(clippy::needless_range_loop, clippy::too_many_arguments)]

use std::ops::Range;

use super::config::*;
use super::fit::*;
use crate::ident::engine::{run, EngineConfig};
use crate::ident::methods::regressor::*;
use crate::ident::{Estimator, FitStatus, Signals};
use crate::lti::poly_roots;
use crate::solve::Termination;
use nalgebra::DMatrix;
use nalgebra::DVector;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// Simulate `A y = B u + e` from rest.
pub(crate) fn simulate_arx(a: &[f64], b: &[f64], nk: usize, u: &[f64], noise: &[f64]) -> Vec<f64> {
    let n = u.len();
    let mut y = vec![0.0; n];
    for k in 0..n {
        let mut v = noise[k];
        for (i, ai) in a.iter().enumerate() {
            if k > i {
                v -= ai * y[k - i - 1];
            }
        }
        for (j, bj) in b.iter().enumerate() {
            if k >= nk + j {
                v += bj * u[k - nk - j];
            }
        }
        y[k] = v;
    }
    y
}

fn random_input(rng: &mut ChaCha8Rng, n: usize) -> Vec<f64> {
    (0..n).map(|_| rng.random_range(-1.0..1.0)).collect()
}

fn time(n: usize, dt: f64) -> Vec<f64> {
    (0..n).map(|k| k as f64 * dt).collect()
}

/// Reference: windowed ridge LS on the deviation rows by nalgebra SVD.
fn reference_fit(
    orders: &ArxOrders,
    y: &[f64],
    u: &[f64],
    window: Range<usize>,
    ridge: f64,
) -> Vec<f64> {
    let n = orders.n_params();
    let m = window.len();
    let r = y[window.end - 1];
    let mut psi = vec![0.0; n];
    let mut a = DMatrix::zeros(m, n);
    let mut b = DVector::zeros(m);
    for (i, k) in window.clone().enumerate() {
        b[i] = regressor(orders, y, u, k, r, &mut psi);
        for j in 0..n {
            a[(i, j)] = psi[j];
        }
    }
    let d: Vec<f64> = (0..n).map(|j| a.column(j).norm()).collect();
    let mut aa = DMatrix::zeros(m + n, n);
    let mut bb = DVector::zeros(m + n);
    for j in 0..n {
        for i in 0..m {
            aa[(i, j)] = a[(i, j)] / d[j];
        }
        aa[(m + j, j)] = ridge.sqrt();
    }
    bb.rows_mut(0, m).copy_from(&b);
    let z = aa.svd(true, true).solve(&bb, 1e-300).unwrap();
    (0..n).map(|j| z[j] / d[j]).collect()
}

#[test]
fn schur_cohn_agrees_with_polynomial_roots() {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut scratch = vec![0.0; 8];
    for _ in 0..500 {
        let n = rng.random_range(1..7);
        let a: Vec<f64> = (0..n).map(|_| rng.random_range(-1.5..1.5)).collect();
        let mut poly = vec![1.0];
        poly.extend_from_slice(&a);
        let roots = poly_roots(&poly).unwrap();
        let rho = roots.iter().map(|z| z.norm()).fold(0.0, f64::max);
        if (rho - 1.0).abs() < 1e-6 || (rho - 0.9).abs() < 1e-6 {
            continue;
        }
        assert_eq!(
            poles_inside(&a, 1.0, &mut scratch),
            rho < 1.0,
            "{a:?} rho {rho}"
        );
        assert_eq!(
            poles_inside(&a, 0.9, &mut scratch),
            rho < 0.9,
            "{a:?} rho {rho}"
        );
    }
}

#[test]
fn noise_free_arx_parameters_are_recovered_to_1e_8_per_window() {
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let n = 600;
    let u = random_input(&mut rng, n);
    let (a, b) = ([-1.5, 0.7], [0.3, 0.2]);
    let y = simulate_arx(&a, &b, 2, &u, &vec![0.0; n]);
    let t = time(n, 1e-3);
    let s = Signals::new(&t, &u, &y, 1e-3, 0.0);
    let mut est = ArxConfig {
        orders: ArxOrders::new(2, 2, 2),
        ridge: 0.0,
        dc_gain_bounds: (f64::NEG_INFINITY, f64::INFINITY),
        offset: true,
        ..ArxConfig::default()
    }
    .build()
    .unwrap();
    let mut coef = [0.0; 5];
    for start in [3, 100, 400] {
        est.fit(&s, start..start + 60, &mut coef).unwrap();
        let want = [a[0], a[1], b[0], b[1]];
        for j in 0..4 {
            assert!((coef[j] - want[j]).abs() < 1e-8, "{start} {j}: {coef:?}");
        }
    }
    assert_eq!(est.coefficient_names(), vec!["a1", "a2", "b2", "b3", "c"]);
}

#[test]
fn window_fit_matches_svd_reference_with_ridge_and_offset() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let n = 400;
    let u: Vec<f64> = random_input(&mut rng, n)
        .iter()
        .map(|v| 0.25 + 1e-3 * v)
        .collect();
    let noise: Vec<f64> = (0..n).map(|_| 1e-6 * rng.random_range(-1.0..1.0)).collect();
    let y0 = simulate_arx(&[-0.8], &[0.1, 0.1], 1, &u, &noise);
    let y: Vec<f64> = y0.to_vec();
    let t = time(n, 1e-3);
    let s = Signals::new(&t, &u, &y, 1e-3, 0.0);
    for ridge in [0.0, 1e-6, 1e-2] {
        let orders = ArxOrders::new(2, 3, 0);
        let mut est = ArxConfig {
            orders,
            ridge,
            max_pole_radius: f64::INFINITY,
            dc_gain_bounds: (f64::NEG_INFINITY, f64::INFINITY),
            ..ArxConfig::default()
        }
        .build()
        .unwrap();
        let mut coef = [0.0; 5];
        est.fit(&s, 150..250, &mut coef).unwrap();
        let want = reference_fit(&orders, &y, &u, 150..250, ridge);
        for j in 0..5 {
            assert!(
                (coef[j] - want[j]).abs() <= 1e-9 * want[j].abs().max(1e-3),
                "ridge {ridge} j {j}: {} vs {}",
                coef[j],
                want[j]
            );
        }
    }
}

#[test]
fn sliding_update_equals_fresh_fit_on_random_data() {
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let n = 3000;
    let normal = Normal::new(0.0, 1.0).unwrap();
    let u: Vec<f64> = (0..n)
        .map(|k| 0.1 * (k as f64 * 0.01).sin() + 0.01 * normal.sample(&mut rng))
        .collect();
    let noise: Vec<f64> = (0..n).map(|_| 1e-4 * normal.sample(&mut rng)).collect();
    let y = simulate_arx(&[-1.6, 0.8, -0.1], &[0.1, 0.15, 0.05], 1, &u, &noise);
    let t = time(n, 1e-3);
    let s = Signals::new(&t, &u, &y, 1e-3, 0.0);
    let base = ArxConfig {
        orders: ArxOrders::new(3, 3, 1),
        ridge: 1e-6,
        max_pole_radius: f64::INFINITY,
        dc_gain_bounds: (f64::NEG_INFINITY, f64::INFINITY),
        refactor_every: 1000,
        ..ArxConfig::default()
    };
    let mut sliding = base.build().unwrap();
    let mut fresh = ArxConfig {
        sliding: false,
        ..base
    }
    .build()
    .unwrap();
    let (mut c1, mut c2) = ([0.0; 6], [0.0; 6]);
    let mut slid = 0;
    let mut worst: f64 = 0.0;
    for (w, hop) in [(80usize, 1usize), (120, 7), (50, 3)] {
        sliding.reset();
        let mut start = 10;
        while start + w < n {
            sliding.fit(&s, start..start + w, &mut c1).unwrap();
            fresh.fit(&s, start..start + w, &mut c2).unwrap();
            if sliding.diagnostics().unwrap().slid {
                slid += 1;
            }
            let scale = c2.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for j in 0..6 {
                worst = worst.max((c1[j] - c2[j]).abs() / scale);
            }
            start += hop;
        }
    }
    assert!(slid > 2000, "sliding used {slid} times");
    assert!(worst < 1e-9, "worst relative difference {worst}");
}

#[test]
fn standstill_keeps_last_model_and_reports_fallback() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let n = 400;
    let mut u = random_input(&mut rng, n);
    for v in &mut u[200..] {
        *v = 0.0;
    }
    let y = simulate_arx(&[-0.5], &[0.5], 1, &u, &vec![0.0; n]);
    let t = time(n, 1e-3);
    let s = Signals::new(&t, &u, &y, 1e-3, 0.0);
    let mut est = ArxConfig {
        orders: ArxOrders::new(1, 1, 1),
        min_excitation: 1e-9,
        ridge: 0.0,
        ..ArxConfig::default()
    }
    .build()
    .unwrap();
    let mut coef = [0.0; 2];
    // no model yet and a standstill window: error
    let zeros = vec![0.0; 100];
    let still = Signals::new(&t[..100], &zeros, &zeros, 1e-3, 0.0);
    assert!(est.fit(&still, 10..60, &mut coef).is_err());
    let f = est.fit(&s, 100..160, &mut coef).unwrap();
    assert_eq!(f.status, FitStatus::Identified(Termination::Exact));
    let f = est.fit(&s, 300..360, &mut coef).unwrap();
    assert_eq!(f.status, FitStatus::Fallback);
    assert!((coef[0] + 0.5).abs() < 1e-9 && (coef[1] - 0.5).abs() < 1e-9);
    assert_eq!(
        est.diagnostics().unwrap().reason,
        "standstill (command not exciting)"
    );
}

#[test]
fn unstable_window_model_is_rejected() {
    // data from an unstable system: y[k] = 1.05 y[k-1] + u[k-1]
    let mut rng = ChaCha8Rng::seed_from_u64(6);
    let n = 100;
    let u = random_input(&mut rng, n);
    let y = simulate_arx(&[-1.05], &[1.0], 1, &u, &vec![0.0; n]);
    let t = time(n, 1e-3);
    let s = Signals::new(&t, &u, &y, 1e-3, 0.0);
    let mut est = ArxConfig {
        orders: ArxOrders::new(1, 1, 1),
        dc_gain_bounds: (f64::NEG_INFINITY, f64::INFINITY),
        max_pole_radius: 1.0,
        offset: true,
        ..ArxConfig::default()
    }
    .build()
    .unwrap();
    let mut coef = [0.0; 3];
    assert!(est.fit(&s, 5..60, &mut coef).is_err());
    assert_eq!(est.diagnostics().unwrap().reason, "unstable poles");
}

#[test]
fn k_step_prediction_is_exact_for_noise_free_data_far_from_zero() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let n = 500;
    let du = random_input(&mut rng, n);
    // unit DC gain system, offset 0.25 m: the deviation frame is exact
    let a = [-1.2, 0.4];
    let b = [0.1, 0.1];
    let dy = simulate_arx(&a, &b, 1, &du, &vec![0.0; n]);
    let u: Vec<f64> = du.iter().map(|v| 0.25 + 1e-3 * v).collect();
    let y: Vec<f64> = dy.iter().map(|v| 0.25 + 1e-3 * v).collect();
    let t = time(n, 1e-3);
    let s = Signals::new(&t, &u, &y, 1e-3, 0.0);
    let mut est = ArxConfig {
        orders: ArxOrders::new(2, 2, 1),
        ridge: 0.0,
        ..ArxConfig::default()
    }
    .build()
    .unwrap();
    let r = run(
        &mut est,
        &s,
        &EngineConfig {
            window: 40,
            horizon: 10,
            hop: Some(5),
            warm_up: 0,
        },
    )
    .unwrap();
    assert!(r.stats.rms < 1e-13, "{}", r.stats.rms);
    assert_eq!(r.failed_windows(), 0);
}

#[test]
fn batch_fit_standard_errors_cover_the_true_parameters() {
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    let n = 5000;
    let mut u = random_input(&mut rng, n);
    u[0] = 0.0;
    let normal = Normal::new(0.0, 0.05).unwrap();
    let mut e: Vec<f64> = (0..n).map(|_| normal.sample(&mut rng)).collect();
    e[0] = 0.0; // start at rest: the frame r = y[0] = 0 is exact
    let truth = [-1.5, 0.7, 1.0, 0.5];
    let y = simulate_arx(&truth[..2], &truth[2..], 1, &u, &e);
    let fit = fit_arx(
        &u,
        &y,
        1e-3,
        ArxOrders::new(2, 2, 1),
        &ArxConfig {
            ridge: 0.0,
            ..Default::default()
        },
    )
    .unwrap();
    for j in 0..4 {
        let z = (fit.theta[j] - truth[j]) / fit.std_errors[j];
        assert!(z.abs() < 4.0, "j {j}: z = {z}");
        assert!(fit.std_errors[j] < 0.01);
    }
    assert!((fit.loss.sqrt() - 0.05).abs() < 0.005);
    assert_eq!(fit.n, n - 2);
    // the model simulates like the data without noise
    let sim = fit.model.simulate(&u).unwrap();
    let clean = simulate_arx(&truth[..2], &truth[2..], 1, &u, &vec![0.0; n]);
    let err = sim
        .iter()
        .zip(&clean)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    let amp = clean.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(err < 0.02 * amp, "{err} vs amplitude {amp}");
}

#[test]
fn bad_configurations_are_rejected() {
    assert!(ArxConfig {
        orders: ArxOrders::new(2, 0, 1),
        ..Default::default()
    }
    .build()
    .is_err());
    assert!(ArxConfig {
        ridge: -1.0,
        ..Default::default()
    }
    .build()
    .is_err());
    assert!(ArxConfig {
        dc_gain_bounds: (2.0, 1.0),
        ..Default::default()
    }
    .build()
    .is_err());
    assert!(ArxConfig {
        refactor_every: 0,
        ..Default::default()
    }
    .build()
    .is_err());
}
