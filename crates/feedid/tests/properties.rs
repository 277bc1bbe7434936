//! Property tests (proptest) of invariants that must hold for any data:
//!
//! - the exact sliding ARX update equals a fresh fit of every window;
//! - the streaming path ([`Streamer`]) equals the batch engine ([`run`]);
//! - the ZOH discretisation of a stable continuous system is stable.
//!
//! Compensation of an exact model being exact is not here: the compensation
//! command is written on another branch (add the property with it).
//!
//! Case counts are small (the estimators are exercised on hundreds of
//! windows per case) so that the file runs in a few seconds.

use feedid::ident::engine::{run, EngineConfig};
use feedid::ident::{ArxConfig, ArxOrders, Estimator, Method, Signals, StreamOptions, Streamer};
use feedid::lti::{poly_from_roots, Complex, TransferFunction};
use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A random smooth input and the response of a random stable ARX system with noise.
fn arx_data(seed: u64, n: usize) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    // input: random steps (every 5 samples on average), smoothed: exciting from the start
    let mut u = vec![0.0; n];
    let mut level = 1e-3;
    for k in 0..n {
        if rng.random_range(0.0..1.0) < 0.2 {
            level = rng.random_range(-1e-3..1e-3);
        }
        u[k] = if k > 0 {
            0.7 * u[k - 1] + 0.3 * level
        } else {
            0.0
        };
    }
    // system: two real poles in (0.3, 0.95), unit DC gain
    let p1: f64 = rng.random_range(0.3..0.95);
    let p2: f64 = rng.random_range(0.3..0.95);
    let (a1, a2) = (-(p1 + p2), p1 * p2);
    let b = 1.0 + a1 + a2;
    let mut y = vec![0.0; n];
    for k in 2..n {
        let e = rng.random_range(-1e-7..1e-7);
        y[k] = -a1 * y[k - 1] - a2 * y[k - 2] + b * u[k - 1] + e;
    }
    let t = (0..n).map(|k| k as f64 * 1e-3).collect();
    (t, u, y)
}

/// Fit every window of `arx_data(seed)` with the sliding update and from
/// scratch; `Err` names the first coefficient that differs by more than
/// rounding amplified by the window's condition estimate.
fn sliding_vs_fresh(
    seed: u64,
    orders: ArxOrders,
    window: usize,
    hop: usize,
    ridge: f64,
) -> Result<(), String> {
    let n = 600;
    let (t, u, y) = arx_data(seed, n);
    let s = Signals::new(&t, &u, &y, 1e-3, 0.0);
    let base = ArxConfig {
        orders,
        ridge,
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
    let nc = sliding.coefficient_names().len();
    let (mut c1, mut c2) = (vec![0.0; nc], vec![0.0; nc]);
    let mut start = orders.lag();
    while start + window < n {
        let r1 = sliding.fit(&s, start..start + window, &mut c1);
        let r2 = fresh.fit(&s, start..start + window, &mut c2);
        if r1.is_ok() != r2.is_ok() {
            return Err(format!("window at {start}: {r1:?} vs {r2:?}"));
        }
        let cond = fresh.diagnostics().unwrap().condition;
        let tol = 1e-9 + 1e-11 * cond;
        let scale = c2.iter().fold(1e-3f64, |m, v| m.max(v.abs()));
        for j in 0..nc {
            if (c1[j] - c2[j]).abs() > tol * scale {
                return Err(format!(
                    "window at {start}, coefficient {j}: {} vs {} (condition {cond:e})",
                    c1[j], c2[j]
                ));
            }
        }
        start += hop;
    }
    Ok(())
}

/// Cases the property found before the frame check and the downdate bound
/// were tightened (the sliding coefficients drifted by up to 2e-5 relative).
#[test]
fn sliding_arx_regressions_found_by_the_property() {
    for (seed, na, nb, nk, window, hop, ridge) in [
        (374443, 1, 4, 1, 30, 2, 0.0),
        (960358, 4, 4, 2, 31, 5, 0.0),
        (282358, 3, 1, 2, 31, 1, 0.0),
        (616293, 2, 1, 0, 30, 4, 0.0),
        (409619, 1, 2, 0, 30, 1, 1e-8),
        (145067, 4, 1, 2, 35, 1, 1e-8),
        (101477, 4, 1, 2, 37, 5, 1e-8),
        (288661, 4, 1, 2, 45, 4, 1e-8),
    ] {
        let r = sliding_vs_fresh(seed, ArxOrders::new(na, nb, nk), window, hop, ridge);
        assert!(r.is_ok(), "seed {seed}: {}", r.unwrap_err());
    }
}

/// 24 cases from a fixed seed (reproducible in CI); `PROPTEST_CASES=500` and
/// `PROPTEST_RNG_SEED=random` explore further.
fn config() -> ProptestConfig {
    let env = |k: &str| std::env::var(k).ok();
    ProptestConfig {
        cases: env("PROPTEST_CASES")
            .and_then(|s| s.parse().ok())
            .unwrap_or(24),
        rng_seed: match env("PROPTEST_RNG_SEED").as_deref() {
            Some("random") => RngSeed::Random,
            _ => RngSeed::Fixed(20261121),
        },
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn sliding_arx_update_equals_a_fresh_fit(
        seed in 0u64..1_000_000,
        na in 1usize..5,
        nb in 1usize..5,
        nk in 0usize..3,
        window in 30usize..120,
        hop in 1usize..9,
        ridge in prop::sample::select(vec![0.0, 1e-8]),
    ) {
        let r = sliding_vs_fresh(seed, ArxOrders::new(na, nb, nk), window, hop, ridge);
        prop_assert!(r.is_ok(), "{}", r.unwrap_err());
    }

    #[test]
    fn streaming_equals_the_batch_engine(
        seed in 0u64..1_000_000,
        method in 0usize..3,
        window in 20usize..80,
        horizon in 1usize..15,
        hop in 1usize..20,
    ) {
        let mut spec: Method = ["paper", "arx", "rls"][method].parse().unwrap();
        if spec.orders().is_some() {
            spec.set_orders(ArxOrders::new(2, 2, 1)).unwrap();
        }
        let n = 400;
        let (t, u, y) = arx_data(seed, n);
        let cfg = EngineConfig { window, horizon, hop: Some(hop), warm_up: 0 };
        let rec = feedid::Recording::new(t, u, y).unwrap();
        let mut est = spec.build().unwrap();
        let batch = run(est.as_mut(), &rec.signals(), &cfg).unwrap();
        // the stream with the recording's interval (its default is the running mean)
        // (waiting for the real command over each horizon, as batch has it)
        let opts = StreamOptions {
            dt: Some(rec.dt()),
            extrapolation: feedid::ident::stream::CommandExtrapolation::Wait,
            ..StreamOptions::default()
        };
        let mut s = Streamer::with_options(spec.build().unwrap(), cfg, opts).unwrap();
        let mut streamed = vec![None; n];
        let mut take = |p: feedid::ident::Prediction<'_>| {
            for (k, &v) in p.horizon.clone().zip(p.position) {
                if k < n {
                    streamed[k] = Some(v); // later windows supersede earlier ones
                }
            }
        };
        for k in 0..n {
            s.push(rec.time()[k], rec.command()[k], rec.position()[k]).unwrap();
            while let Some(p) = s.poll().unwrap() {
                take(p);
            }
        }
        s.finish();
        while let Some(p) = s.poll().unwrap() {
            take(p);
        }
        for (k, &c) in streamed.iter().enumerate() {
            match (batch.prediction(k), c) {
                (None, None) => {}
                (Some(b), Some(c)) => prop_assert!(
                    (b - c).abs() <= 1e-9 * b.abs().max(1e-6),
                    "{} sample {}: batch {} vs stream {}", spec.name(), k, b, c
                ),
                (b, c) => prop_assert!(false, "{} sample {}: batch {:?} vs stream {:?}", spec.name(), k, b, c),
            }
        }
    }

    #[test]
    fn zoh_of_a_stable_system_is_stable(
        seed in 0u64..1_000_000,
        real in 0usize..4,
        pairs in 0usize..3,
        log_dt in -6.0f64..-1.0,
    ) {
        prop_assume!(real + 2 * pairs > 0);
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut roots = Vec::new();
        for _ in 0..real {
            roots.push(Complex::new(-10f64.powf(rng.random_range(0.0..4.0)), 0.0));
        }
        for _ in 0..pairs {
            let w = 10f64.powf(rng.random_range(0.0..4.0));
            let zeta: f64 = rng.random_range(0.01..1.0);
            let (re, im) = (-zeta * w, w * (1.0 - zeta * zeta).sqrt());
            roots.push(Complex::new(re, im));
            roots.push(Complex::new(re, -im));
        }
        let den = poly_from_roots(&roots);
        let dc = den.last().copied().unwrap();
        let g = TransferFunction::new(vec![dc], den).unwrap();
        prop_assert!(g.is_stable().unwrap());
        let dt = 10f64.powf(log_dt);
        let d = g.to_state_space().unwrap().discretize_zoh(dt).unwrap();
        prop_assert!(d.is_stable().unwrap(), "dt {}: poles {:?}", dt, d.poles().unwrap());
        // and every discrete pole is exp(p·dt) of a continuous one, inside the unit circle
        for z in d.poles().unwrap() {
            prop_assert!(z.norm() < 1.0, "pole {} at dt {}", z, dt);
        }
        let dcd = d.dc_gain().unwrap();
        prop_assert!((dcd - 1.0).abs() < 1e-6, "DC gain {}", dcd);
    }
}
