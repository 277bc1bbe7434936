//! Benchmark: the paper method per window (fit + prediction of H = 10
//! samples) at W = 20, QR and simplex, on windows of the virtual rig's ramp
//! (every effect on) in motion, consecutive windows (hop 10). Targets
//! QR ≤ 1 µs, simplex ≤ 50 µs per window; the simplex from the
//! paper's zeros (default) and from the previous window's coefficients.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use feedid::drive::{RigParams, VirtualRig};
use feedid::ident::{Estimator, PaperConfig, Signals, SimplexStart, Solver};
use feedid::signal::Scenario;
use feedid::Recording;

fn per_window(c: &mut Criterion) {
    let rate = 5000.0;
    let command = Scenario::Ramp
        .command(rate, 0.8, 1)
        .unwrap_or_else(|e| panic!("{e}"));
    let out = VirtualRig::new(RigParams::default())
        .with_seed(1)
        .simulate(&command, rate)
        .unwrap_or_else(|e| panic!("{e}"));
    let rec = Recording::new(out.time, out.command, out.position).unwrap_or_else(|e| panic!("{e}"));
    let signals: Signals<'_> = rec.signals();
    let (w, h) = (20, 10);
    // windows in motion, 10 ms … 780 ms, hop 10
    let starts: Vec<usize> = (50..rec.len() - w - h).step_by(10).collect();
    for (solver, start, name) in [
        (Solver::Qr, SimplexStart::Zeros, "qr"),
        (Solver::Simplex, SimplexStart::Zeros, "simplex"),
        (Solver::Simplex, SimplexStart::Previous, "simplex_previous"),
    ] {
        let mut m = PaperConfig {
            solver,
            simplex_start: start,
            ..PaperConfig::default()
        }
        .build()
        .unwrap_or_else(|e| panic!("{e}"));
        let mut coef = [0.0; 11];
        let mut pred = [0.0; 10];
        let mut i = 0;
        c.bench_function(&format!("paper_{name}_per_window_w20"), |b| {
            b.iter(|| {
                let s = starts[i % starts.len()];
                i += 1;
                let fit = m
                    .fit(&signals, s..s + w, &mut coef)
                    .unwrap_or_else(|e| panic!("{e}"));
                m.predict(&signals, s..s + w, s + w..s + w + h, &mut pred)
                    .unwrap_or_else(|e| panic!("{e}"));
                black_box((fit.residual_rms, pred[h - 1]))
            })
        });
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(20)
        .warm_up_time(std::time::Duration::from_secs(1))
        .measurement_time(std::time::Duration::from_secs(3));
    targets = per_window
}
criterion_main!(benches);
