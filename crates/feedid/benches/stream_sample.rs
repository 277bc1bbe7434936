//! Benchmark: the streaming path per sample (paper method, QR, W = 20,
//! H = hop = 10): one second of the virtual rig's ramp at 5 kHz pushed sample
//! by sample, reported per sample (criterion throughput "elements" = samples).
//! At 5 kHz a sample arrives every 200 µs.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use feedid::drive::{RigParams, VirtualRig};
use feedid::ident::stream::Streamer;
use feedid::ident::{EngineConfig, PaperConfig};
use feedid::signal::Scenario;

fn per_sample(c: &mut Criterion) {
    let rate = 5000.0;
    let command = Scenario::Ramp
        .command(rate, 1.0, 1)
        .unwrap_or_else(|e| panic!("{e}"));
    let out = VirtualRig::new(RigParams::default())
        .with_seed(1)
        .simulate(&command, rate)
        .unwrap_or_else(|e| panic!("{e}"));
    let paper = PaperConfig::default()
        .build()
        .unwrap_or_else(|e| panic!("{e}"));
    let mut s = Streamer::new(paper, EngineConfig::default()).unwrap_or_else(|e| panic!("{e}"));
    let n = out.time.len();
    let mut g = c.benchmark_group("stream");
    g.throughput(Throughput::Elements(n as u64));
    g.bench_function("stream_paper_qr_1s_5khz", |b| {
        b.iter(|| {
            s.reset();
            let mut acc = 0.0;
            for k in 0..n {
                s.push(out.time[k], out.command[k], out.position[k])
                    .unwrap_or_else(|e| panic!("{e}"));
                while let Some(p) = s.poll().unwrap_or_else(|e| panic!("{e}")) {
                    acc += p.position[0];
                }
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
