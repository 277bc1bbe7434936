//! Benchmark: the identifying methods on the virtual rig's chirp (every
//! effect on), through the sliding engine as the CLI runs them:
//! `arx` and `oe` per window (W = 200, H = 10, hop 10; each window is a fit
//! plus a 10-step prediction, the ARX fit using the exact sliding update),
//! (`oe_projected`: `OeJacobian::Projected`), and `rls` per sample (it
//! updates on every sample; hop 10, window 100).
//! Target: RLS ≤ 200 ns per sample.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use feedid::drive::{RigParams, VirtualRig};
use feedid::ident::engine::run;
use feedid::ident::{EngineConfig, Method, OeConfig, OeJacobian};
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

fn methods(c: &mut Criterion) {
    let rec = recording();
    let signals = rec.signals();
    let mut group = c.benchmark_group("methods");
    let projected = Method::Oe(OeConfig {
        jacobian: OeJacobian::Projected,
        ..OeConfig::default()
    });
    for (name, spec) in [
        ("arx", None),
        ("oe", None),
        ("oe_projected", Some(projected)),
        ("rls", None),
        ("auto", None),
    ] {
        let spec: Method = match spec {
            Some(s) => s,
            None => name.parse().unwrap_or_else(|e| panic!("{e}")),
        };
        let cfg = EngineConfig {
            window: spec.default_window(),
            ..EngineConfig::default()
        };
        let windows = cfg.windows(rec.len(), 0).count() as u64;
        let mut est = spec.build().unwrap_or_else(|e| panic!("{e}"));
        // per window for arx/oe, per sample for rls and auto (sample-driven)
        let (label, n) = if matches!(spec, Method::Rls(_) | Method::Auto(_)) {
            ("per_sample", rec.len() as u64)
        } else {
            ("per_window", windows)
        };
        group.throughput(Throughput::Elements(n));
        group.bench_function(format!("{name}_{label}"), |b| {
            b.iter(|| {
                let r = run(est.as_mut(), &signals, &cfg).unwrap_or_else(|e| panic!("{e}"));
                black_box(r.stats.rms)
            })
        });
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(10)
        .warm_up_time(std::time::Duration::from_secs(1))
        .measurement_time(std::time::Duration::from_secs(4));
    targets = methods
}
criterion_main!(benches);
