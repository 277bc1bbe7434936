//! The streaming path allocates nothing per sample or per window once
//! running (issue: "No allocation per sample or per window after
//! construction"): the paper method (QR on its cached projection, the
//! simplex from zeros and from the previous window), auto, rls, arx (the
//! two-stack sliding factor and the Hessenberg solve) and oe (both
//! Jacobians). Counted with a global allocator that counts the
//! allocations made by the test's own thread.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use feedid::drive::{RigParams, VirtualRig};
use feedid::ident::stream::{CommandExtrapolation, StreamOptions, Streamer};
use feedid::ident::{
    EngineConfig, Method, OeConfig, OeJacobian, PaperConfig, SimplexStart, Solver, WindowOutcome,
};
use feedid::signal::Scenario;

struct Counting;

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
    // per thread: tests run in parallel and each counts only its own
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn note() {
    if COUNTING.try_with(|c| c.get()).unwrap_or(false) {
        let _ = ALLOCATIONS.try_with(|a| a.set(a.get() + 1));
    }
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note();
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        note();
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations made by `f` on this thread.
fn allocations_in(f: impl FnOnce()) -> usize {
    let before = ALLOCATIONS.with(Cell::get);
    COUNTING.with(|c| c.set(true));
    f();
    COUNTING.with(|c| c.set(false));
    ALLOCATIONS.with(Cell::get) - before
}

#[test]
fn steady_state_pushes_allocate_nothing_for_the_paper_method() {
    let rate = 5000.0;
    let command = Scenario::Ramp.command(rate, 0.4, 1).unwrap();
    let rig = VirtualRig::new(RigParams::default())
        .with_seed(3)
        .simulate(&command, rate)
        .unwrap();
    // the counter itself works
    assert!(allocations_in(|| drop(std::hint::black_box(vec![1u8; 16]))) >= 1);
    for (solver, hop, start) in [
        (Solver::Qr, None, SimplexStart::Zeros),
        (Solver::Qr, Some(1), SimplexStart::Zeros),
        (Solver::Simplex, None, SimplexStart::Zeros),
        (Solver::Simplex, None, SimplexStart::Previous),
    ] {
        let paper = PaperConfig {
            solver,
            simplex_start: start,
            ..PaperConfig::default()
        }
        .build()
        .unwrap();
        let cfg = EngineConfig {
            hop,
            ..EngineConfig::default()
        };
        let mut s = Streamer::new(paper, cfg).unwrap();
        let warm = 200; // rest, motion start and the first moving windows
        for k in 0..warm {
            s.push(rig.time[k], rig.command[k], rig.position[k])
                .unwrap();
            while s.poll().unwrap().is_some() {}
        }
        let mut predictions = 0;
        let mut sum = 0.0;
        let n = allocations_in(|| {
            for k in warm..rig.time.len() {
                s.push(rig.time[k], rig.command[k], rig.position[k])
                    .unwrap();
                while let Some(p) = s.poll().unwrap() {
                    predictions += 1;
                    sum += p.position.iter().sum::<f64>();
                }
            }
        });
        assert!(sum.is_finite());
        // the buffers were compacted many times over 1800 samples
        assert!(predictions >= 180, "{predictions}");
        assert_eq!(
            n, 0,
            "{solver:?} hop {hop:?}: {n} allocations in steady state"
        );
        assert_eq!(s.stats().failed_windows, 0);
    }
}

#[test]
fn steady_state_pushes_allocate_nothing_for_the_default_and_linear_methods() {
    let rate = 5000.0;
    let command = Scenario::Chirp.command(rate, 0.5, 1).unwrap();
    let rig = VirtualRig::new(RigParams::default())
        .with_seed(3)
        .simulate(&command, rate)
        .unwrap();
    let n = rig.time.len();
    // extrapolating the command (the default), waiting for it, with a command
    // lead, and across gaps (a 1 ms pause every 500 lines)
    let feeds = [
        (CommandExtrapolation::default(), 0, false),
        (CommandExtrapolation::Acceleration, 0, true),
        (CommandExtrapolation::Wait, 0, false),
        (CommandExtrapolation::default(), 10, true),
    ];
    let projected = Method::Oe(OeConfig {
        jacobian: OeJacobian::Projected,
        ..OeConfig::default()
    });
    let methods: [(&str, Method); 5] = [
        ("auto", "auto".parse().unwrap()),
        ("rls", "rls".parse().unwrap()),
        ("arx", "arx".parse().unwrap()),
        ("oe", "oe".parse().unwrap()),
        ("oe (projected Jacobian)", projected),
    ];
    for (name, spec) in &methods {
        for (extrapolation, lead, gaps) in feeds {
            let what = format!("{name} {extrapolation:?} lead {lead} gaps {gaps}");
            let spec = spec.clone();
            let cfg = EngineConfig {
                window: spec.default_window(),
                ..EngineConfig::default()
            };
            let opts = StreamOptions {
                command_lead: lead,
                extrapolation,
                ..StreamOptions::default()
            };
            let mut s = Streamer::with_options(spec.build().unwrap(), cfg, opts).unwrap();
            let time = |k: usize| rig.time[k] + if gaps { (k / 500) as f64 * 1e-3 } else { 0.0 };
            // (predictions, windows withheld as implausible)
            let push = |s: &mut Streamer<_>, k: usize, counts: &mut (usize, usize)| {
                s.push(time(k), rig.command[(k + lead).min(n - 1)], rig.position[k])
                    .unwrap();
                while let Some(p) = s.poll().unwrap() {
                    if p.is_ok() {
                        counts.0 += 1;
                    }
                    if p.outcome == WindowOutcome::Withheld {
                        counts.1 += 1;
                    }
                }
            };
            let warm = 400;
            let mut counts = (0, 0);
            for k in 0..warm {
                push(&mut s, k, &mut counts);
            }
            counts = (0, 0);
            // oe starts every segment with a fresh initial estimate (SRIVC
            // and a full fit, a warm-up that allocates): after a gap, only
            // the push completing the segment's first window may allocate;
            // so may the push fitting the first window after a prediction
            // withheld as implausible (oe then starts again from SRIVC)
            let oe = matches!(spec, Method::Oe(_));
            let mut allocated = 0;
            let mut restarting = false;
            for k in warm..n {
                let (windows, withheld) = (s.stats().windows, counts.1);
                let a = allocations_in(|| push(&mut s, k, &mut counts));
                let windowed = s.stats().windows > windows;
                // samples of the segment so far, this one included
                let j = k % 500 + 1;
                let first_window = cfg.window + lead;
                let restart =
                    (gaps && oe && (first_window..=first_window + cfg.horizon).contains(&j))
                        || (restarting && windowed);
                if !restart {
                    allocated += a;
                }
                if counts.1 > withheld {
                    restarting = true;
                } else if windowed {
                    restarting = false;
                }
            }
            let predictions = counts.0;
            assert!(predictions >= 100, "{what}: {predictions}");
            assert!(counts.1 <= 2, "{what}: {} predictions withheld", counts.1);
            assert_eq!(
                allocated, 0,
                "{what}: {allocated} allocations in steady state"
            );
            assert_eq!(
                s.stats().gaps,
                if gaps { (n - 1) / 500 } else { 0 },
                "{what}"
            );
        }
    }
}
