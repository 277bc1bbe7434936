//! 2 ms-ahead prediction targets of the `arx` and `rls` estimators
//! on the virtual rig (all effects on, 0.2 µm noise, 0.1 µm quantisation,
//! 5 kHz, horizon H = 10 = 2 ms, hop = H) and on the EMPS benchmark (1 kHz,
//! H = 10).
//!
//! Settings: the settings tuned on the rig, the defaults before the drive
//! zoo chose the present ones (see the zoo benchmark in docs/RESULTS.md):
//! `arx` na = nb = 8, nk = 1, ridge 1e-8, DC gain in [0.5, 2], excitation
//! gate 0.1 µm, over windows of W = 200 samples; `rls` na = nb = 8, nk = 1,
//! λ = 0.999, p0 = 1e4, coordinates scaled by 1 mm, predictions every H
//! samples after the first 100. The EMPS check runs the defaults.
//! Targets: rms ≤ 0.5 µm and max ≤ 10 µm on the rig, rms ≤ 1 µm on EMPS,
//! reached by at least one of the two methods on every recording except the
//! paper step (1 mm in 0.2 ms, saturating the current limit), where the
//! windowed linear models reach about 4 µm rms / 9 µm max; that is asserted
//! as it stands.

mod common;

use feedid::drive::{RigParams, VirtualRig};
use feedid::ident::{engine, ArxConfig, ArxOrders, EngineConfig, Estimator, RlsConfig, Signals};
use feedid::signal::Scenario;
use feedid::stats::ErrorStats;

const RATE: f64 = 5000.0;

fn run(est: &mut dyn Estimator, s: &Signals<'_>, window: usize) -> ErrorStats {
    let cfg = EngineConfig {
        window,
        horizon: 10,
        hop: None,
        warm_up: 0,
    };
    let r = engine::run(est, s, &cfg).unwrap();
    assert!(r.stats.samples > 0);
    r.stats
}

/// The settings tuned on the rig (the defaults before the drive zoo).
fn both(s: &Signals<'_>) -> (ErrorStats, ErrorStats) {
    let mut arx = ArxConfig {
        orders: ArxOrders::new(8, 8, 1),
        ridge: 1e-8,
        dc_gain_bounds: (0.5, 2.0),
        min_excitation: 1e-7,
        ..ArxConfig::default()
    }
    .build()
    .unwrap();
    let mut rls = RlsConfig {
        orders: ArxOrders::new(8, 8, 1),
        p0: 1e4,
        scale: Some(1e-3),
        min_excitation: 1e-6,
        frame_span: 1.0,
        ..RlsConfig::default()
    }
    .build()
    .unwrap();
    (run(&mut arx, s, 200), run(&mut rls, s, 100))
}

/// The defaults (chosen on the drive zoo).
fn defaults(s: &Signals<'_>) -> (ErrorStats, ErrorStats) {
    let mut arx = ArxConfig::default().build().unwrap();
    let mut rls = RlsConfig::default().build().unwrap();
    (run(&mut arx, s, 100), run(&mut rls, s, 100))
}

#[test]
fn arx_and_rls_reach_the_prediction_targets_on_the_virtual_rig() {
    let um = 1e6;
    let mut report = String::new();
    for scenario in Scenario::ALL {
        let command = scenario
            .command(RATE, scenario.default_duration(), 1)
            .unwrap();
        let out = VirtualRig::new(RigParams::default())
            .with_seed(7)
            .simulate(&command, RATE)
            .unwrap();
        let s = Signals::new(&out.time, &out.command, &out.position, 1.0 / RATE, 0.0);
        let (a, r) = both(&s);
        report += &format!(
            "{:9} arx rms {:6.3} max {:6.3} | rls rms {:6.3} max {:6.3} µm\n",
            scenario.name(),
            a.rms * um,
            a.max_abs * um,
            r.rms * um,
            r.max_abs * um
        );
        let best_rms = a.rms.min(r.rms);
        match scenario {
            Scenario::Step => {
                assert!(a.rms <= 5e-6 && a.max_abs <= 10e-6, "{report}");
            }
            Scenario::Prbs => {
                assert!(best_rms <= 0.5e-6, "{report}");
                assert!(a.max_abs <= 10e-6 && r.max_abs <= 10e-6, "{report}");
            }
            _ => {
                assert!(a.rms <= 0.5e-6 && a.max_abs <= 10e-6, "{report}");
            }
        }
    }
    println!("{report}");
}

#[test]
fn rls_reaches_one_micrometre_on_emps() {
    let Some(rec) = common::emps_recording() else {
        return;
    };
    let (a, r) = defaults(&rec.signals());
    println!(
        "EMPS arx rms {:.3} max {:.3} | rls rms {:.3} max {:.3} µm",
        a.rms * 1e6,
        a.max_abs * 1e6,
        r.rms * 1e6,
        r.max_abs * 1e6
    );
    assert!(r.rms <= 1e-6, "rls rms {}", r.rms);
    assert!(r.max_abs <= 10e-6, "rls max {}", r.max_abs);
}
