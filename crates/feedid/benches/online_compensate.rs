//! Benchmark: online compensation per sample — one second of the virtual
//! rig's S-curve at 5 kHz, the measured positions of a plain run fed to an
//! [`OnlineCompensator`] (default settings, 4 samples of preview) sample by
//! sample: model update, guard, correction and limits per sample (criterion
//! throughput "elements" = samples). At 5 kHz a sample arrives every 200 µs;
//! the target is ≤ 20 µs.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use feedid::compensate::{OnlineCompensator, OnlineConfig};
use feedid::drive::{RigParams, VirtualRig};
use feedid::signal::Scenario;

fn per_sample(c: &mut Criterion) {
    let rate = 5000.0;
    let desired = Scenario::Scurve
        .command(rate, 1.0, 1)
        .unwrap_or_else(|e| panic!("{e}"));
    let out = VirtualRig::new(RigParams::default())
        .with_seed(1)
        .simulate(&desired, rate)
        .unwrap_or_else(|e| panic!("{e}"));
    let cfg = OnlineConfig::default();
    let mut comp = OnlineCompensator::new(cfg, 1.0 / rate).unwrap_or_else(|e| panic!("{e}"));
    let n = desired.len();
    let mut g = c.benchmark_group("online_compensate");
    g.throughput(Throughput::Elements(n as u64));
    g.bench_function("online_compensate_1s_5khz", |b| {
        b.iter(|| {
            comp.reset();
            let mut fed = 0;
            while fed <= cfg.preview {
                comp.push_desired(desired[fed])
                    .unwrap_or_else(|e| panic!("{e}"));
                fed += 1;
            }
            let mut acc = comp.first_command().unwrap_or_else(|e| panic!("{e}"));
            for k in 0..n - 1 {
                if fed < n {
                    comp.push_desired(desired[fed])
                        .unwrap_or_else(|e| panic!("{e}"));
                    fed += 1;
                } else {
                    comp.finish_desired();
                }
                acc += comp.step(out.position[k]).unwrap_or_else(|e| panic!("{e}"));
            }
            black_box(acc)
        })
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(20)
        .warm_up_time(std::time::Duration::from_secs(1))
        .measurement_time(std::time::Duration::from_secs(3));
    targets = per_sample
}
criterion_main!(benches);
