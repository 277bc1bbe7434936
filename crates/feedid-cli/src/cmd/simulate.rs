//! `feedid simulate`: a scenario on the virtual rig, written as a recording.

use anyhow::Result;
use feedid::drive::{RigEffects, VirtualRig};
use feedid::io::{read_recording, ChannelRef, ReadOptions};
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
        .chain(&a.command)
        .map(|p| p.as_path())
        .collect();
    check_distinct(&inputs, &[a.output.as_path()])?;
    if let Some(structure) = crate::cmd::load_structure(a.params.as_deref())? {
        return simulate_structure(a, &structure);
    }
    let params = load_model_params(a.params.as_deref(), a.allow_unstable)?;
    let effects = if a.linear {
        RigEffects::linear()
    } else if let Some(p) = &a.effects {
        load_effects(p)?
    } else {
        RigEffects::default()
    };
    // the command: a scenario, or a file's command run from rest at its
    // first value (the rig starts at 0, which stands for that value)
    let (what, rate, command, offset) = command_of(a)?;
    let duration = command.len() as f64 / rate;
    let rig = VirtualRig::new(params)
        .with_effects(effects)
        .with_seed(a.seed);
    simulate_rig(a, rig, what, rate, command, offset, duration)
}

/// The command to simulate: `(what, rate, command from 0, offset)`.
fn command_of(a: &SimulateArgs) -> Result<(String, f64, Vec<f64>, f64)> {
    Ok(match (&a.command, &a.scenario) {
        (Some(path), _) => {
            let opts = ReadOptions {
                time: a
                    .time_column
                    .as_deref()
                    .map(ChannelRef::parse)
                    .transpose()?,
                command: Some(ChannelRef::parse(&a.command_column)?),
                position: Some(ChannelRef::parse(&a.command_column)?),
                ..ReadOptions::default()
            };
            let rec = read_recording(path, &opts)?;
            let c0 = rec.command()[0];
            let rel: Vec<f64> = rec.command().iter().map(|c| c - c0).collect();
            (format!("{} as", path.display()), rec.rate_hz(), rel, c0)
        }
        (None, Some(name)) => {
            let scenario: Scenario = name.parse()?;
            let duration = a.duration.unwrap_or_else(|| scenario.default_duration());
            let command = scenario.command(a.rate, duration, a.seed)?;
            (scenario.name().to_string(), a.rate, command, 0.0)
        }
        (None, None) => anyhow::bail!("give --scenario NAME or --command cmd.csv"),
    })
}

/// Run the paper's rig and write its recording.
#[allow(clippy::too_many_arguments)]
fn simulate_rig(
    a: &SimulateArgs,
    rig: VirtualRig,
    what: String,
    rate: f64,
    command: Vec<f64>,
    offset: f64,
    duration: f64,
) -> Result<()> {
    let bar = ProgressBar::new("simulate", "samples");
    let update = |done: u64, total: u64| bar.update(done, total);
    let out = rig.simulate_with_progress(&command, rate, &update);
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
                out.command[k] + offset,
                out.position[k] + offset,
                out.true_position[k] + offset,
                out.motor_current[k],
                out.velocity[k]
            )?;
        }
        Ok(())
    })?;
    outputs.commit()?;
    let peak = command
        .iter()
        .fold(0.0_f64, |m, c| m.max((c + offset).abs()));
    println!(
        "{}: {} samples at {} Hz ({:.3} s), {} command, peak {:.4} mm, effects {}",
        a.output.display(),
        out.len(),
        rate,
        duration,
        what,
        1e3 * peak,
        if a.linear { "off (linear)" } else { "on" }
    );
    Ok(())
}

/// `feedid simulate --params structure.toml`: a command run on a drive
/// structure, written as `time_s,command_m,position_m,velocity_m_per_s,output`.
fn simulate_structure(a: &SimulateArgs, s: &feedid::drive::DriveStructure) -> Result<()> {
    if a.effects.is_some() || a.linear {
        anyhow::bail!(
            "{}: a drive structure has its own friction law and limits; --effects and --linear are for the paper's rig",
            a.params.as_deref().map_or_else(String::new, |p| p.display().to_string())
        );
    }
    let (what, rate, command, offset) = command_of(a)?;
    let run = s
        .simulate(&command, rate, 0.0)
        .map_err(|e| params_error(a.params.as_deref(), e))?;
    for (name, v) in [
        ("position_m", &run.position),
        ("velocity_m_per_s", &run.velocity),
    ] {
        if let Some(k) = v.iter().position(|x| !feedid::recording::is_usable(*x)) {
            anyhow::bail!(
                "{}: the simulation diverged: {name} reaches {:e} at t = {} s; nothing written",
                a.output.display(),
                v[k],
                run.time[k]
            );
        }
    }
    let mut outputs = Outputs::default();
    outputs.add(&a.output, |w| {
        writeln!(w, "time_s,command_m,position_m,velocity_m_per_s,output")?;
        for k in 0..run.time.len() {
            writeln!(
                w,
                "{},{},{},{},{}",
                run.time[k],
                run.command[k] + offset,
                run.position[k] + offset,
                run.velocity[k],
                run.output[k]
            )?;
        }
        Ok(())
    })?;
    outputs.commit()?;
    println!(
        "{}: {} samples at {} Hz ({:.3} s), {} command on the drive structure {}",
        a.output.display(),
        run.time.len(),
        rate,
        command.len() as f64 / rate,
        what,
        a.params
            .as_deref()
            .map_or_else(String::new, |p| p.display().to_string())
    );
    Ok(())
}
