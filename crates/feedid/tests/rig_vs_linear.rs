//! The virtual rig with every effect off against the linear closed-loop model
//! (issue: "with all of them off it matches the linear model to within 1e-3 of
//! the move amplitude").

use feedid::drive::{simulate_nominal, RigParams, VirtualRig};
use feedid::signal::Scenario;

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

#[test]
fn linear_rig_matches_linear_model_on_every_scenario() {
    let params = RigParams::default();
    let rate = 5000.0;
    for scenario in [
        Scenario::Ramp,
        Scenario::Step,
        Scenario::Scurve,
        Scenario::Chirp,
        Scenario::Prbs,
        Scenario::Multisine,
    ] {
        let duration = scenario.default_duration().min(0.4);
        let command = scenario.command(rate, duration, 1).unwrap();
        let rig = VirtualRig::linear(params).simulate(&command, rate).unwrap();
        let model = simulate_nominal(&params, &command, 1.0 / rate).unwrap();
        let amplitude = command.iter().fold(0.0_f64, |m, c| m.max(c.abs()));
        let diff = max_abs_diff(&rig.position, &model);
        assert!(
            diff <= 1e-3 * amplitude,
            "{scenario:?}: max diff {diff} m vs amplitude {amplitude} m"
        );
        // far tighter in fact: both are exact discretisations of the same ODE
        assert!(diff <= 1e-9 + 1e-7 * amplitude, "{scenario:?}: {diff}");
    }
}

#[test]
fn linear_rig_ramp_following_error_is_v_over_kv_plus_half_sample() {
    // ZOH-held command lags the continuous ramp by half a sample (rig docs).
    let params = RigParams::default();
    let rate = 5000.0;
    let command = Scenario::Ramp.command(rate, 0.5, 0).unwrap();
    let out = VirtualRig::linear(params).simulate(&command, rate).unwrap();
    let k = 2000; // 0.4 s, well inside the constant-velocity phase
    let e = out.command[k] - out.true_position[k];
    let want = 0.05 / 700.0 + 0.05 / (2.0 * rate);
    assert!((e - want).abs() < 0.05e-6, "{e} vs {want}");
}
