//! Compensation with models identified on zoo programs: the numerical
//! traps a real identification run sets (a pole–zero pair no recording can
//! tell apart, a high-order model sampled at tens of kHz).

use feedid::compensate::{compensate_model, CompensateConfig};
use feedid::ident::{fit_global_model, GlobalModelKind};
use feedid::zoo::Zoo;
use feedid::Recording;

/// The member's program, its first run (another noise seed) and the model
/// identified on that run.
fn identified(index: usize) -> (Vec<f64>, f64, feedid::ident::ModelFile) {
    let zoo = Zoo::standard();
    let member = zoo.member(index).unwrap();
    let spec = &member.spec;
    let run = spec
        .run_plant(&member.command, spec.noise_seed.wrapping_add(1))
        .unwrap();
    let rec = Recording::from_rate(spec.rate_hz, member.command.clone(), run.position).unwrap();
    let file = fit_global_model(&rec, &GlobalModelKind::Auto).unwrap();
    (member.command, 1.0 / spec.rate_hz, file)
}

fn unlimited() -> CompensateConfig {
    CompensateConfig {
        max_velocity: f64::INFINITY,
        max_acceleration: f64::INFINITY,
        ..CompensateConfig::default()
    }
}

#[test]
fn a_long_s_curve_gives_a_model_with_unit_gain_that_compensation_inverts() {
    // member 86: a 1 m S-curve at 806 Hz on a first-order loop; an
    // output-error fit returns a differentiator behind a pole at 1e-11 rad/s
    let (desired, dt, file) = identified(86);
    let g = file.model.dc_gain().unwrap();
    assert!((g - 1.0).abs() < 1e-3, "steady-state gain {g}");
    let c = compensate_model(&file.model, &desired, dt, &unlimited()).unwrap();
    assert!(c.fallback.is_none(), "{:?}", c.fallback);
    assert!(
        c.predicted_error.rms < 1e-3 * c.predicted_plain_error.rms,
        "{} vs {}",
        c.predicted_error.rms,
        c.predicted_plain_error.rms
    );
}

#[test]
fn a_seven_pole_model_sampled_at_13_khz_keeps_its_gain_in_compensation() {
    // member 147: a slow heavy axis at 13.2 kHz, oe 7,2; the inverse's
    // factors once said its DC gain was −0.05
    let (desired, dt, file) = identified(147);
    let own = file
        .model
        .discrete_state_space(Some(dt))
        .unwrap()
        .dc_gain()
        .unwrap();
    let c = compensate_model(&file.model, &desired, dt, &unlimited()).unwrap();
    assert!(
        (c.model_dc_gain - own).abs() < 1e-4 * own.abs(),
        "{} vs {own}",
        c.model_dc_gain
    );
    // the model's prediction of the plain program is the size of its
    // following error (hundreds of µm on a 20.9 mm ramp), not metres
    let plain = c.predicted_plain_error.rms;
    assert!(plain > 1e-4 && plain < 1e-2, "{plain}");
}
