//! Benchmark: the neural predictor (`--method nn`) per window once trained,
//! on the virtual rig's chirp (every effect on, 5 kHz, 1 s): the network is
//! trained on the first 2000 samples from the first motion, then each
//! window of the last 2000 samples (W = 100, H = 10, hop 10) is a fit (the
//! new samples' one-step residual) and a 10-step prediction; and the
//! prediction alone. Target: ≤ 50 µs per window.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use feedid::drive::{RigParams, VirtualRig};
use feedid::ident::engine::run;
use feedid::ident::{EngineConfig, Estimator, NnConfig};
use feedid::signal::Scenario;
use feedid::Recording;

fn recording() -> Recording {
    let rate = 5000.0;
    let command = Scenario::Chirp
        .command(rate, 1.0, 1)
        .unwrap_or_else(|e| panic!("{e}"));
    let out = VirtualRig::new(RigParams::default())
        .with_seed(1)
        .simulate(&command, rate)
        .unwrap_or_else(|e| panic!("{e}"));
    Recording::new(out.time, out.command, out.position).unwrap_or_else(|e| panic!("{e}"))
}

fn nn(c: &mut Criterion) {
    let rec = recording();
    let s = rec.signals();
    let config = NnConfig {
        train_samples: 2000,
        ..NnConfig::default()
    };
    let mut est = config.build().unwrap_or_else(|e| panic!("{e}"));
    let cfg = EngineConfig {
        window: 100,
        horizon: 10,
        hop: None,
        warm_up: 0,
    };
    // train (the run leaves the estimator trained)
    run(&mut est, &s, &cfg).unwrap_or_else(|e| panic!("{e}"));
    assert!(est.is_trained());
    let n = rec.len();
    let ends: Vec<usize> = (n - 2000..n - 10).step_by(10).collect();
    let mut coef = vec![0.0; est.coefficient_names().len()];
    let mut out = [0.0; 10];
    let mut group = c.benchmark_group("nn");
    group.throughput(Throughput::Elements(ends.len() as u64));
    group.bench_function("fit_and_predict_per_window", |b| {
        b.iter(|| {
            for &e in &ends {
                est.fit(&s, e - 100..e, &mut coef)
                    .unwrap_or_else(|e| panic!("{e}"));
                est.predict(&s, e - 100..e, e..e + 10, &mut out)
                    .unwrap_or_else(|e| panic!("{e}"));
            }
            black_box(out[9])
        })
    });
    group.bench_function("predict_per_window", |b| {
        b.iter(|| {
            for &e in &ends {
                est.predict(&s, e - 100..e, e..e + 10, &mut out)
                    .unwrap_or_else(|e| panic!("{e}"));
            }
            black_box(out[9])
        })
    });
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(10)
        .warm_up_time(std::time::Duration::from_secs(1))
        .measurement_time(std::time::Duration::from_secs(3));
    targets = nn
}
criterion_main!(benches);
