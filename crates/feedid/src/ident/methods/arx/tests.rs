//! Tests of the ARX estimator and the batch fit.

// Index loops mirror the formulas.
#![allow(clippy::needless_range_loop, clippy::too_many_arguments)]

use std::ops::Range;

use super::config::*;
use super::factor::SlidingFactor;
use super::fit::*;
use crate::ident::engine::EngineConfig;
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
    let r = crate::ident::engine::run_as_made(
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

/// The rig's chirp (every effect on, seed 1) at 5 kHz: (time, command, position).
fn rig_chirp(seconds: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    use crate::drive::{RigParams, VirtualRig};
    use crate::signal::Scenario;
    let rate = 5000.0;
    let command = Scenario::Chirp.command(rate, seconds, 1).unwrap();
    let out = VirtualRig::new(RigParams::default())
        .with_seed(1)
        .simulate(&command, rate)
        .unwrap();
    (out.time, out.command, out.position)
}

/// Seeded random smooth input through a stable 8th-order ARX system with noise.
fn random_arx8(seed: u64, n: usize) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let normal = Normal::new(0.0, 1.0).unwrap();
    let mut u = vec![0.0; n];
    let mut level = 0.0;
    for k in 1..n {
        if rng.random_range(0.0..1.0) < 0.05 {
            level = 1e-3 * normal.sample(&mut rng);
        }
        u[k] = 0.9 * u[k - 1] + 0.1 * level;
    }
    // poles 0.5 … 0.9 (real), unit DC gain spread over the b's
    let mut a = vec![1.0];
    for i in 0..8 {
        let p = 0.5 + 0.05 * i as f64;
        let mut next = vec![0.0; a.len() + 1];
        for (j, &c) in a.iter().enumerate() {
            next[j] += c;
            next[j + 1] -= p * c;
        }
        a = next;
    }
    let gain: f64 = a.iter().sum();
    let b = vec![gain / 8.0; 8];
    let noise: Vec<f64> = (0..n).map(|_| 2e-8 * normal.sample(&mut rng)).collect();
    let y = simulate_arx(&a[1..], &b, 1, &u, &noise);
    (time(n, 2e-4), u, y)
}

/// The window's prediction from the reference fit (SVD of the stacked
/// ridge problem, [`reference_fit`]).
fn reference_prediction(
    orders: &ArxOrders,
    y: &[f64],
    u: &[f64],
    window: Range<usize>,
    h: usize,
    ridge: f64,
) -> (Vec<f64>, Vec<f64>) {
    let theta = reference_fit(orders, y, u, window.clone(), ridge);
    let mut past = vec![0.0; orders.na + h];
    let mut out = vec![0.0; h];
    let e = window.end;
    predict_k_step(orders, &theta, y, u, e, y[e - 1], 0.0, &mut past, &mut out);
    (theta, out)
}

#[test]
fn default_window_predictions_match_a_batch_svd_fit_on_rig_and_random_data() {
    // the estimator at orders 8,8,1, ridge 1e-8 (the two stacks and the
    // Hessenberg solve) against a from-scratch SVD fit of every window
    for (name, (t, u, y)) in [
        ("rig chirp", rig_chirp(0.6)),
        ("random ARX", random_arx8(21, 3000)),
    ] {
        let orders = ArxOrders::new(8, 8, 1);
        let s = Signals::new(&t, &u, &y, t[1] - t[0], 0.0);
        let mut est = ArxConfig {
            orders,
            ridge: 1e-8,
            ..ArxConfig::default()
        }
        .build()
        .unwrap();
        let range = y.iter().fold(f64::NEG_INFINITY, |a, &v| a.max(v))
            - y.iter().fold(f64::INFINITY, |a, &v| a.min(v));
        let (w, h, hop) = (200, 10, 10);
        let mut coef = vec![0.0; 16];
        let mut pred = vec![0.0; h];
        let (mut compared, mut slid, mut worst) = (0, 0, 0.0f64);
        let mut start = orders.lag();
        while start + w + h <= y.len() {
            let window = start..start + w;
            est.fit(&s, window.clone(), &mut coef).unwrap();
            est.predict(&s, window.clone(), window.end..window.end + h, &mut pred)
                .unwrap();
            let d = est.diagnostics().unwrap();
            slid += usize::from(d.slid);
            if d.accepted {
                let (theta, want) = reference_prediction(&orders, &y, &u, window, h, 1e-8);
                for j in 0..16 {
                    assert!(coef[j].is_finite() && theta[j].is_finite());
                }
                for (p, q) in pred.iter().zip(&want) {
                    worst = worst.max((p - q).abs() / range);
                }
                compared += 1;
            }
            start += hop;
        }
        assert!(compared > 100, "{name}: {compared} windows compared");
        assert!(
            slid > compared * 8 / 10,
            "{name}: {slid} of {compared} slid"
        );
        assert!(
            worst < 1e-9,
            "{name}: predictions differ by {worst:e} of the range"
        );
    }
}

#[test]
fn two_stack_update_equals_a_fresh_factor_for_irregular_window_sequences() {
    let (t, u, y) = random_arx8(22, 4000);
    let s = Signals::new(&t, &u, &y, 2e-4, 0.0);
    let base = ArxConfig {
        orders: ArxOrders::new(4, 4, 1),
        max_pole_radius: f64::INFINITY,
        dc_gain_bounds: (f64::NEG_INFINITY, f64::INFINITY),
        min_excitation: 0.0,
        ..ArxConfig::default()
    };
    let mut sliding = base.build().unwrap();
    let mut fresh = ArxConfig {
        sliding: false,
        ..base
    }
    .build()
    .unwrap();
    // regular hops, a hop that does not divide W, hop 1, a jump back, the
    // same window twice, a hop ≥ W, a change of hop
    let mut starts = vec![];
    let mut k = 10;
    for hop in [10usize, 10, 10, 7, 7, 7, 1, 1, 1, 3] {
        for _ in 0..30 {
            starts.push(k);
            k += hop;
        }
    }
    starts.extend([500, 500, 400, 410, 420, 1000, 1300, 1301, 1302]);
    let (mut c1, mut c2) = ([0.0; 8], [0.0; 8]);
    let mut slid = 0;
    for &st in &starts {
        let window = st..st + 120;
        sliding.fit(&s, window.clone(), &mut c1).unwrap();
        fresh.fit(&s, window, &mut c2).unwrap();
        slid += usize::from(sliding.diagnostics().unwrap().slid);
        let cond = fresh.diagnostics().unwrap().condition;
        let scale = c2.iter().fold(1e-3f64, |m, v| m.max(v.abs()));
        for j in 0..8 {
            assert!(
                (c1[j] - c2[j]).abs() <= (1e-9 + 1e-11 * cond) * scale,
                "window at {st}, coefficient {j}: {} vs {} (condition {cond:e})",
                c1[j],
                c2[j]
            );
        }
    }
    assert!(slid > 200, "{slid} windows slid");
}

#[test]
fn sliding_factor_equals_the_factor_from_scratch_with_few_aggregates() {
    // R from the two stacks (front aggregates capped at 1, 2 and 3: rebuilds
    // every 1, 2, 3 windows) against R of each window from scratch, on
    // white-noise input (R is unique and well determined); the data sit at
    // an offset of 0.2 so that the frames matter
    let mut rng = ChaCha8Rng::seed_from_u64(23);
    let du = random_input(&mut rng, 2000);
    let noise: Vec<f64> = (0..2000)
        .map(|_| 0.01 * rng.random_range(-1.0..1.0))
        .collect();
    let dy = simulate_arx(&[-1.2, 0.5, -0.1], &[0.1, 0.05, 0.05], 1, &du, &noise);
    let u: Vec<f64> = du.iter().map(|v| 0.2 + 1e-3 * v).collect();
    let y: Vec<f64> = dy.iter().map(|v| 0.2 + 1e-3 * v).collect();
    let orders = ArxOrders::new(3, 3, 1);
    let lag = orders.lag();
    for cap in [1usize, 2, 3, 1000] {
        let mut f = SlidingFactor::new(&orders);
        f.max_aggregates = cap;
        let mut g = SlidingFactor::new(&orders);
        let mut slid = 0;
        for start in (lag..1500).step_by(6) {
            let rows = start..start + 60;
            let reference = y[rows.end - 1];
            slid += usize::from(f.update(&orders, &y, &u, 0, rows.clone(), reference, true, 64));
            g.update(&orders, &y, &u, 0, rows, reference, false, 64);
            // compare R·S (unscaled; the two may use different scales)
            let norm = (0..f.p)
                .map(|j| (0..=j).map(|i| g.rs(i, j).powi(2)).sum::<f64>())
                .sum::<f64>()
                .sqrt();
            for i in 0..f.p {
                for j in i..f.p {
                    assert!(
                        (f.rs(i, j) - g.rs(i, j)).abs() <= 1e-12 * norm,
                        "cap {cap}, window at {start}: R[{i}][{j}] {} vs {}",
                        f.rs(i, j),
                        g.rs(i, j)
                    );
                }
            }
        }
        if cap > 1 {
            assert!(slid > 100, "cap {cap}: {slid} windows slid");
        }
    }
}

#[test]
fn non_finite_new_samples_are_reported_and_the_next_windows_recover() {
    let (t, u, mut y) = random_arx8(24, 1500);
    y[700] = f64::NAN;
    let s = Signals::new(&t, &u, &y, 2e-4, 0.0);
    let mut est = ArxConfig::default().build().unwrap();
    let mut coef = vec![0.0; 16];
    let mut errors = vec![];
    for start in (8..1200).step_by(10) {
        if let Err(e) = est.fit(&s, start..start + 200, &mut coef) {
            errors.push((start, e.to_string()));
        }
    }
    // every window that holds sample 700 (rows or lags) fails and names it
    assert!(!errors.is_empty());
    for (start, msg) in &errors {
        assert!(*start + 200 > 700 && *start <= 700 + 8, "{start}: {msg}");
        assert!(msg.contains("700"), "{msg}");
    }
    // the windows after it fit again
    est.fit(&s, 1000..1200, &mut coef).unwrap();
    assert!(est.diagnostics().unwrap().accepted);
}

#[test]
fn condition_estimate_on_request_is_close_to_the_pivoted_one() {
    let (t, u, y) = rig_chirp(0.4);
    let s = Signals::new(&t, &u, &y, 2e-4, 0.0);
    let mut fast = ArxConfig::default().build().unwrap();
    // a finite condition limit takes the pivoted path (same problem)
    let mut pivoted = ArxConfig {
        max_condition: 1e300,
        ..ArxConfig::default()
    }
    .build()
    .unwrap();
    let (mut c1, mut c2) = (vec![0.0; 16], vec![0.0; 16]);
    let mut compared = 0;
    for start in (8..1700).step_by(10) {
        let window = start..start + 200;
        fast.fit(&s, window.clone(), &mut c1).unwrap();
        pivoted.fit(&s, window, &mut c2).unwrap();
        let (a, b) = (fast.diagnostics().unwrap(), pivoted.diagnostics().unwrap());
        assert_eq!(a.accepted, b.accepted);
        if a.reason.is_empty() {
            // 1-norm estimate vs |R00|/|Rnn| of the pivoted QR: both within a
            // small factor of the 2-norm condition number (16 columns)
            let ratio = a.condition / b.condition;
            assert!(
                a.condition >= 1.0 && (1e-2..=1e3).contains(&ratio),
                "window at {start}: {} vs {}",
                a.condition,
                b.condition
            );
            compared += 1;
        } else {
            assert_eq!(a.condition, f64::INFINITY, "{}", a.reason);
        }
    }
    assert!(compared > 50);
}

#[test]
fn avx2_kernels_give_the_portable_windows_bit_for_bit() {
    // the sliding factor's and the Hessenberg solve's kernels are chosen at
    // run time: an estimator built with the portable ones gives exactly the
    // same coefficients and predictions (on a CPU without AVX2 both are
    // portable); orders 8,8 (row stride 20) and 3,2 (the general kernel, 8)
    for (orders, (t, u, y)) in [
        (ArxOrders::default(), random_arx8(22, 2500)),
        (ArxOrders::new(3, 2, 1), rig_chirp(0.4)),
        (ArxOrders::new(5, 5, 2), random_arx8(23, 1500)),
    ] {
        let s = Signals::new(&t, &u, &y, t[1] - t[0], 0.0);
        let run = || {
            let mut est = ArxConfig {
                orders,
                ..ArxConfig::default()
            }
            .build()
            .unwrap();
            let p = orders.n_params();
            let (w, h, hop) = (200, 10, 10);
            let (mut coef, mut pred) = (vec![0.0; p], vec![0.0; h]);
            let mut bits = Vec::new();
            let mut start = orders.lag();
            while start + w + h <= y.len() {
                let window = start..start + w;
                est.fit(&s, window.clone(), &mut coef).unwrap();
                let ok = est
                    .predict(&s, window.clone(), window.end..window.end + h, &mut pred)
                    .is_ok();
                bits.push(u64::from(ok));
                bits.extend(coef.iter().chain(&pred).map(|v| v.to_bits()));
                start += hop;
            }
            bits
        };
        let fast = run();
        assert!(fast.len() > 1000);
        assert_eq!(fast, crate::solve::rows::portable(run), "{orders:?}");
    }
}
