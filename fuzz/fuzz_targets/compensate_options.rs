//! Compensation with arbitrary options and desired trajectories: never
//! panic, never allocate without bound; an accepted command is finite and
//! meets the velocity and acceleration limits it was given (the plain one
//! sent instead too).
#![no_main]

use feedid::compensate::{compensate_model, CompensateConfig, Smoothing, StartMode};
use feedid::ident::LinearModel;
use libfuzzer_sys::fuzz_target;

/// The next `f64` of `data` (8 bytes), if any.
fn take(data: &mut &[u8]) -> Option<f64> {
    let (head, rest) = data.split_first_chunk::<8>()?;
    *data = rest;
    Some(f64::from_le_bytes(*head))
}

fuzz_target!(|data: &[u8]| {
    let mut d = data;
    let Some(flags) = d.first().copied() else {
        return;
    };
    d = &d[1..];
    let (Some(smooth), Some(max_smoothing), Some(vmax), Some(amax), Some(min_benefit)) =
        (take(&mut d), take(&mut d), take(&mut d), take(&mut d), take(&mut d))
    else {
        return;
    };
    let cfg = CompensateConfig {
        smoothing: if flags & 1 == 0 {
            Smoothing::Auto
        } else {
            Smoothing::Fixed(smooth)
        },
        max_smoothing,
        max_velocity: vmax,
        max_acceleration: amax,
        min_benefit,
        start: if flags & 2 == 0 {
            StartMode::Rest
        } else {
            StartMode::Moving
        },
        ..CompensateConfig::default()
    };
    // the desired trajectory: at most 2000 samples at 1 kHz
    let mut desired = Vec::new();
    while let Some(v) = take(&mut d) {
        if desired.len() == 2000 {
            break;
        }
        desired.push(v);
    }
    let Ok(model) = LinearModel::discrete(vec![0.0, 0.2], vec![1.0, -0.8], 1e-3) else {
        return;
    };
    if let Ok(c) = compensate_model(&model, &desired, 1e-3, &cfg) {
        assert!(c.command.iter().all(|v| v.is_finite()));
        assert!(c.peak_velocity <= vmax * (1.0 + 1e-6), "{} > {vmax}", c.peak_velocity);
        assert!(
            c.peak_acceleration <= amax * (1.0 + 1e-6),
            "{} > {amax}",
            c.peak_acceleration
        );
    }
});
