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
    // a loop far too slow for the command (a gain of 1e-6): the axis
    // barely moves, which no table shows at a glance
    let span = |v: &[f64]| {
        v.iter().fold(f64::NEG_INFINITY, |m, &x| m.max(x))
            - v.iter().fold(f64::INFINITY, |m, &x| m.min(x))
    };
    let (moved, asked) = (span(&out.true_position), span(&out.command));
    if asked > 0.0 && moved < 0.01 * asked {
        eprintln!(
            "warning: the axis covers {moved:.3e} m of the command's {} m ({:.2} %): the closed \
             loop is far too slow for this command (see `feedid model` for its following error; a \
             gain too small?)",
            feedid::error::short_number(asked),
            100.0 * moved / asked
        );
    }
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

/// A TOML value as the help shows it: plain decimals, exponents for the
/// very small and very large (`1e-7`, not `0.0000001`).
fn toml_number(v: f64) -> String {
    if v != 0.0 && (v.abs() < 1e-3 || v.abs() >= 1e6) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// The long help of `--effects`: every table and key of the effects file
/// with its unit and its default, the defaults read from
/// [`RigEffects::default`] (the effect structs of `feedid::drive`).
pub fn effects_long_help() -> String {
    let d = RigEffects::default();
    let on = |b: bool| if b { "true" } else { "false" };
    let position_loop = serde_json::to_string(&d.position_loop).unwrap_or_default();
    let friction = |f: &feedid::drive::Friction, force: &str, speed: &str| {
        [
            (
                "coulomb",
                toml_number(f.coulomb),
                format!("Coulomb level [{force}]"),
            ),
            (
                "breakaway",
                toml_number(f.breakaway),
                format!("breakaway (static) level at zero speed, ≥ coulomb [{force}]"),
            ),
            (
                "stribeck_velocity",
                toml_number(f.stribeck_velocity),
                format!("Stribeck speed, > 0 [{speed}]"),
            ),
            (
                "smoothing_velocity",
                toml_number(f.smoothing_velocity),
                format!("regularisation speed of the tanh, > 0 [{speed}]"),
            ),
        ]
    };
    let mut rows: Vec<(String, String)> = Vec::new();
    let mut key =
        |k: &str, v: String, what: &str| rows.push((format!("{k} = {v}"), what.to_string()));
    key(
        "friction",
        on(d.friction).into(),
        "Coulomb + Stribeck friction at motor and table (the two tables below)",
    );
    key(
        "variable_stiffness",
        on(d.variable_stiffness).into(),
        "screw stiffness depending on the nut position",
    );
    key(
        "limits",
        on(d.limits).into(),
        "current and voltage limits with anti-windup",
    );
    key(
        "current_limit",
        toml_number(d.current_limit),
        "current limit [A]",
    );
    key(
        "voltage_limit",
        toml_number(d.voltage_limit),
        "voltage limit [V]",
    );
    key(
        "quantisation",
        on(d.quantisation).into(),
        "linear-encoder quantisation",
    );
    key(
        "resolution",
        toml_number(d.resolution),
        "encoder resolution [m]",
    );
    key(
        "noise",
        on(d.noise).into(),
        "Gaussian noise on the recorded position",
    );
    key(
        "noise_std",
        toml_number(d.noise_std),
        "noise standard deviation [m]",
    );
    key(
        "position_loop",
        position_loop,
        "the P position loop: \"sampled\" (at the sample rate), \"continuous\" (command held between samples) or \"interpolated\" (command interpolated)",
    );
    key(
        "backlash",
        on(d.backlash).into(),
        "dead band in the screw–table connection",
    );
    key(
        "backlash_width",
        toml_number(d.backlash_width),
        "total play of the backlash [m]",
    );
    key(
        "dead_time",
        d.dead_time.to_string(),
        "dead time between the recorded set-point and the drive [samples]",
    );
    // (table, what it is, its keys)
    type KeyRows = Vec<(String, String)>;
    let mut tables: Vec<(&str, &str, KeyRows)> = Vec::new();
    for (name, what, f, force, speed) in [
        (
            "motor_friction",
            "motor friction law",
            &d.motor_friction,
            "N·m",
            "rad/s",
        ),
        (
            "table_friction",
            "table friction law",
            &d.table_friction,
            "N",
            "m/s",
        ),
    ] {
        tables.push((
            name,
            what,
            friction(f, force, speed)
                .into_iter()
                .map(|(k, v, w)| (format!("{k} = {v}"), w))
                .collect(),
        ));
    }
    let p = &d.pulses;
    tables.push((
        "pulses",
        "force pulses on the table (cutting, impacts); off while force = 0",
        vec![
            (
                format!("force = {}", toml_number(p.force)),
                "height of each pulse, its sign alternating [N]".into(),
            ),
            (
                format!("width = {}", toml_number(p.width)),
                "length of each pulse [s]".into(),
            ),
            (
                format!("period = {}", toml_number(p.period)),
                "from one pulse's start to the next's [s]".into(),
            ),
            (
                format!("first = {}", toml_number(p.first)),
                "start of the first pulse after sample 0 [s]".into(),
            ),
        ],
    ));
    // the explanations in one column: keys indented by 2, table keys by 4
    let column = rows
        .iter()
        .map(|(k, _)| 2 + k.chars().count())
        .chain(
            tables
                .iter()
                .flat_map(|t| t.2.iter())
                .map(|(k, _)| 4 + k.chars().count()),
        )
        .max()
        .unwrap_or(0)
        + 2;
    let mut o = String::from(
        "Nonlinear effects of the virtual rig: a TOML file of any of the keys below \
         (shown with their defaults; a missing key keeps its default, but a friction table present in the file needs \
         all four of its keys; an unknown key is an error; the plain keys come before the [tables]). Default: all on but backlash, \
         dead time and pulses; --linear switches every effect off.\n\n",
    );
    for (k, w) in &rows {
        o += &format!("  {k:<width$}{w}\n", width = column - 2);
    }
    for (name, what, keys) in &tables {
        o += &format!("  [{name}]  {what}\n");
        for (k, w) in keys {
            o += &format!("    {k:<width$}{w}\n", width = column - 4);
        }
    }
    o.trim_end().to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_effects_help_lists_every_key_with_its_default_and_parses_as_toml() {
        let help = effects_long_help();
        let d = serde_json::to_value(RigEffects::default()).unwrap();
        for (k, v) in d.as_object().unwrap() {
            match v.as_object() {
                Some(table) => {
                    assert!(help.contains(&format!("[{k}]")), "[{k}] in\n{help}");
                    for sub in table.keys() {
                        assert!(
                            help.contains(&format!("    {sub} = ")),
                            "{k}.{sub} in\n{help}"
                        );
                    }
                }
                None => assert!(help.contains(&format!("  {k} = ")), "{k} in\n{help}"),
            }
        }
        assert!(
            help.contains("resolution = 1e-7") && help.contains("[m]"),
            "{help}"
        );
        assert!(help.contains("stribeck_velocity = 0.5"), "{help}");
        assert!(!help.contains("simulate --help"), "{help}");
        // the keys with their defaults, as listed, make a valid effects file
        // equal to the defaults
        let mut toml = String::new();
        for line in help.lines() {
            let t = line.trim_start();
            if let Some(end) = t
                .find("  ")
                .filter(|_| t.contains(" = ") || t.starts_with('['))
            {
                toml += &t[..end];
                toml.push('\n');
            }
        }
        let parsed: RigEffects = toml::from_str(&toml).unwrap_or_else(|e| panic!("{e}\n{toml}"));
        assert_eq!(parsed, RigEffects::default(), "{toml}");
    }
}
