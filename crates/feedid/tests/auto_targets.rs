//! Prediction targets of the default method `auto` (issue 5) on the virtual
//! rig (all effects on, 0.2 µm noise, 0.1 µm quantisation, 5 kHz, horizon
//! H = 10 = 2 ms, hop = H, window 50) and on the EMPS benchmark (1 kHz, H = 10).
//!
//! Targets: rms ≤ 0.5 µm and max ≤ 10 µm over the predicted samples on every
//! scenario; rms ≤ 1 µm on EMPS. `auto` withholds the predictions it cannot
//! vouch for, so coverage (the share of samples predicted) is checked too:
//! above 95 % on every scenario except the paper step, where the ~25 ms of
//! current-saturated transient after the step are not predicted (no
//! linear model predicts them within 10 µm) and coverage is ≈ 25 % of the
//! 50 ms recording.

mod common;

use feedid::drive::{RigParams, VirtualRig};
use feedid::ident::{engine, AutoConfig, EngineConfig, Signals};
use feedid::signal::Scenario;
use feedid::stats::ErrorStats;

fn run_auto(s: &Signals<'_>) -> (ErrorStats, f64) {
    let mut est = AutoConfig::default().build().unwrap();
    let cfg = EngineConfig {
        window: 50,
        horizon: 10,
        hop: None,
        warm_up: 0,
    };
    let r = engine::run(&mut est, s, &cfg).unwrap();
    assert!(r.predicted.iter().all(|v| v.is_finite()));
    let coverage = r.stats.samples as f64 / s.len() as f64;
    (r.stats, coverage)
}

#[test]
fn auto_reaches_the_prediction_targets_on_every_rig_scenario() {
    let mut report = String::new();
    let mut failures = Vec::new();
    for scenario in Scenario::ALL {
        let rate = 5000.0;
        let command = scenario
            .command(rate, scenario.default_duration(), 1)
            .unwrap();
        let out = VirtualRig::new(RigParams::default())
            .with_seed(7)
            .simulate(&command, rate)
            .unwrap();
        let s = Signals::new(&out.time, &out.command, &out.position, 1.0 / rate, 0.0);
        let (st, cov) = run_auto(&s);
        report += &format!(
            "{:9} rms {:6.3} max {:6.3} µm coverage {:5.1} %\n",
            scenario.name(),
            st.rms * 1e6,
            st.max_abs * 1e6,
            cov * 100.0
        );
        let min_cov = if scenario == Scenario::Step {
            0.2
        } else {
            0.95
        };
        if !(st.rms <= 0.5e-6 && st.max_abs <= 10e-6 && cov >= min_cov) {
            failures.push(scenario.name());
        }
    }
    println!("{report}");
    assert!(failures.is_empty(), "missed on {failures:?}\n{report}");
}

#[test]
fn auto_reaches_one_micrometre_on_emps() {
    let Some(rec) = common::emps_recording() else {
        return;
    };
    let (st, cov) = run_auto(&rec.signals());
    println!(
        "EMPS auto rms {:.3} max {:.3} µm coverage {:.1} %",
        st.rms * 1e6,
        st.max_abs * 1e6,
        cov * 100.0
    );
    assert!(st.rms <= 1e-6, "rms {}", st.rms);
    assert!(st.max_abs <= 10e-6, "max {}", st.max_abs);
    assert!(cov >= 0.95, "coverage {cov}");
}
