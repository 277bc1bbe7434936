//! `feedid simulate`: a scenario on the virtual rig, written as a recording.

use anyhow::Result;
use feedid::drive::{RigEffects, VirtualRig};
use feedid::signal::Scenario;

use crate::args::SimulateArgs;
use crate::cmd::progress::ProgressBar;
use crate::cmd::{check_distinct, load_effects, load_model_params, params_error, Outputs};

/// Simulate and write `time_s,command_m,position_m,…`.
pub fn run(a: &SimulateArgs) -> Result<()> {
    let inputs: Vec<&std::path::Path> = a
        .params
        .iter()
        .chain(&a.effects)
        .map(|p| p.as_path())
        .collect();
    check_distinct(&inputs, &[a.output.as_path()])?;
    let scenario: Scenario = a.scenario.parse()?;
    let params = load_model_params(a.params.as_deref(), a.allow_unstable)?;
    let effects = if a.linear {
        RigEffects::linear()
    } else if let Some(p) = &a.effects {
        load_effects(p)?
    } else {
        RigEffects::default()
    };
    let duration = a.duration.unwrap_or_else(|| scenario.default_duration());
    let command = scenario.command(a.rate, duration, a.seed)?;
    let rig = VirtualRig::new(params)
        .with_effects(effects)
        .with_seed(a.seed);
    let bar = ProgressBar::new("simulate", "samples");
    let update = |done: u64, total: u64| bar.update(done, total);
    let out = rig.simulate_with_progress(&command, a.rate, &update);
    bar.finish();
    let out = out.map_err(|e| params_error(a.params.as_deref().or(a.effects.as_deref()), e))?;
    // an unstable rig (allowed by --allow-unstable) may run away: never write
    // what cannot be read back as a recording
    let channels = [
        ("position_m", &out.position),
        ("true_position_m", &out.true_position),
        ("current_a", &out.motor_current),
        ("velocity_m_per_s", &out.velocity),
    ];
    for (name, v) in channels {
        if let Some(k) = v.iter().position(|x| !feedid::recording::is_usable(*x)) {
            anyhow::bail!(
                "{}: the simulation diverged: {name} reaches {:e} at t = {} s (beyond ±1e100 or not finite); nothing written",
                a.output.display(),
                v[k],
                out.time[k]
            );
        }
    }
    let mut outputs = Outputs::default();
    outputs.add(&a.output, |w| {
        writeln!(
            w,
            "time_s,command_m,position_m,true_position_m,current_a,velocity_m_per_s"
        )?;
        for k in 0..out.len() {
            writeln!(
                w,
                "{},{},{},{},{},{}",
                out.time[k],
                out.command[k],
                out.position[k],
                out.true_position[k],
                out.motor_current[k],
                out.velocity[k]
            )?;
        }
        Ok(())
    })?;
    outputs.commit()?;
    let peak = command.iter().fold(0.0_f64, |m, c| m.max(c.abs()));
    println!(
        "{}: {} samples at {} Hz ({:.3} s), {} command, peak {:.4} mm, effects {}",
        a.output.display(),
        out.len(),
        a.rate,
        duration,
        scenario.name(),
        1e3 * peak,
        if a.linear { "off (linear)" } else { "on" }
    );
    Ok(())
}
