//! `feedid tune`: position- and velocity-loop gains retuned from a drive
//! structure's model for a bandwidth and damping asked for, both gain sets'
//! closed loops, and a program run through both in the nonlinear simulation.

use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;
use feedid::drive::{RunFigures, TuneTarget};
use feedid::signal::Scenario;

use crate::cmd::{check_distinct, load_structure, params_error, Outputs};

/// `feedid tune`.
#[derive(Debug, Args)]
pub struct TuneArgs {
    /// The drive structure (its current gains, mass, friction): e.g.
    /// examples/emps.toml or the output of `feedid greybox --params-out`.
    #[arg(long, value_name = "structure.toml")]
    pub params: PathBuf,
    /// −3 dB bandwidth of the closed loop asked for [Hz].
    #[arg(long, value_name = "HZ")]
    pub bandwidth: f64,
    /// Damping ratio of the closed-loop poles.
    #[arg(long, default_value_t = std::f64::consts::FRAC_1_SQRT_2, value_name = "ZETA")]
    pub damping: f64,
    /// Run this scenario (ramp, step, scurve, chirp, prbs, multisine) through the
    /// nonlinear simulation with both gain sets.
    #[arg(long, value_name = "NAME")]
    pub verify: Option<String>,
    /// Sampling rate of the verification [Hz]; default: the controller's, else 1000.
    #[arg(long, value_name = "HZ", requires = "verify")]
    pub rate: Option<f64>,
    /// Write the structure with the new gains (TOML).
    #[arg(long, value_name = "tuned.toml")]
    pub params_out: Option<PathBuf>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Run `feedid tune`.
pub fn run(a: &TuneArgs) -> Result<()> {
    if let Some(out) = &a.params_out {
        check_distinct(&[a.params.as_path()], &[out.as_path()])?;
    }
    let Some(structure) = load_structure(Some(&a.params))? else {
        bail!(
            "{}: not a drive structure file ([drive], [mechanics]); `feedid tune` retunes a drive structure",
            a.params.display()
        );
    };
    let tuned = structure
        .tune(&TuneTarget {
            bandwidth_hz: a.bandwidth,
            damping: a.damping,
        })
        .map_err(|e| params_error(Some(&a.params), e))?;
    let verified: Option<(String, RunFigures, RunFigures)> = match &a.verify {
        Some(name) => {
            let scenario: Scenario = name.parse()?;
            let rate = a
                .rate
                .or(structure.controller.sample_time.map(|t| 1.0 / t))
                .unwrap_or(1000.0);
            let command = scenario.command(rate, scenario.default_duration(), 0)?;
            let before = structure.run_figures(&command, rate)?;
            let after = tuned.structure.run_figures(&command, rate)?;
            Some((scenario.name().to_string(), before, after))
        }
        None => None,
    };
    if let Some(out) = &a.params_out {
        let mut outputs = Outputs::default();
        outputs.add_text(out, tuned.structure.to_toml_string())?;
        outputs.commit()?;
    }
    if a.json {
        let mut v = serde_json::to_value(&tuned)?;
        if let (Some(o), Some((name, b, f))) = (v.as_object_mut(), &verified) {
            o.insert(
                "verify".into(),
                serde_json::json!({ "scenario": name, "before": b, "after": f }),
            );
        }
        println!("{}", serde_json::to_string_pretty(&v)?);
        return Ok(());
    }
    let bw = |v: Option<f64>| v.map_or("none".to_string(), |b| format!("{b:.3} Hz"));
    let damping = |s: &feedid::drive::StructureSummary| {
        s.poles.iter().fold(f64::INFINITY, |m, p| m.min(p.damping))
    };
    let fe = |s: &feedid::drive::StructureSummary| {
        s.following_error_per_velocity
            .map_or("unbounded".to_string(), |e| {
                format!("{:.4} µm per mm/s", 1e3 * e)
            })
    };
    println!(
        "{}: bandwidth {:.3} Hz, damping {:.4} asked",
        a.params.display(),
        a.bandwidth,
        a.damping
    );
    println!("{:<28} {:>20} {:>20}", "", "now", "proposed");
    println!(
        "{:<28} {:>20.4} {:>20.4}",
        "position kp [1/s]", tuned.position_kp.0, tuned.position_kp.1
    );
    println!(
        "{:<28} {:>20.4} {:>20.4}",
        "velocity kp", tuned.velocity_kp.0, tuned.velocity_kp.1
    );
    for (name, (before, after)) in [
        ("velocity ki [1/s]", tuned.velocity_ki),
        ("position ki [1/s]", tuned.position_ki),
        ("position kd [s]", tuned.position_kd),
    ] {
        if before != 0.0 || after != 0.0 {
            println!("{name:<28} {before:>20.6} {after:>20.6}");
        }
    }
    println!(
        "{:<28} {:>20} {:>20}",
        "bandwidth",
        bw(tuned.before.bandwidth_hz),
        bw(tuned.after.bandwidth_hz)
    );
    println!(
        "{:<28} {:>20.4} {:>20.4}",
        "smallest damping",
        damping(&tuned.before),
        damping(&tuned.after)
    );
    println!(
        "{:<28} {:>20} {:>20}",
        "stable (linear)", tuned.before.stable, tuned.after.stable
    );
    println!(
        "{:<28} {:>20.3} {:>20.3}",
        "step overshoot [%]", tuned.overshoot_percent.0, tuned.overshoot_percent.1
    );
    println!(
        "{:<28} {:>20} {:>20}",
        "following error",
        fe(&tuned.before),
        fe(&tuned.after)
    );
    if let Some((name, b, f)) = &verified {
        println!("nonlinear simulation, {name} (friction, limits, the controller as in the file):");
        println!(
            "{:<28} {:>20.3} {:>20.3}",
            "  rms following error [µm]",
            1e6 * b.rms_error,
            1e6 * f.rms_error
        );
        println!(
            "{:<28} {:>20.3} {:>20.3}",
            "  max following error [µm]",
            1e6 * b.max_error,
            1e6 * f.max_error
        );
        println!(
            "{:<28} {:>20.3} {:>20.3}",
            "  overshoot [%]", b.overshoot_percent, f.overshoot_percent
        );
        println!(
            "{:<28} {:>20.4} {:>20.4}",
            "  peak output", b.peak_output, f.peak_output
        );
        println!(
            "{:<28} {:>20.2} {:>20.2}",
            "  at the output limit [%]", b.saturated_percent, f.saturated_percent
        );
    }
    Ok(())
}
