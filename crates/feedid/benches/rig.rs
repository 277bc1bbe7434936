//! Benchmark: one second of the nonlinear virtual rig (every effect on) at
//! 5 kHz driven by the paper's ramp. Target: under 50 ms.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use feedid::drive::{RigOutput, RigParams, VirtualRig};
use feedid::signal::Ramp;

fn rig_one_second(c: &mut Criterion) {
    let rate = 5000.0;
    let command = Ramp::default()
        .generate(rate, 1.0)
        .unwrap_or_else(|e| panic!("ramp: {e}"));
    let rig = VirtualRig::new(RigParams::default()).with_seed(1);
    let mut out = RigOutput::default();
    c.bench_function("rig_nonlinear_ramp_1s_5khz", |b| {
        b.iter(|| {
            rig.simulate_into(black_box(&command), rate, &mut out)
                .unwrap_or_else(|e| panic!("simulate: {e}"));
            black_box(out.position[4999])
        })
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = rig_one_second
}
criterion_main!(benches);
