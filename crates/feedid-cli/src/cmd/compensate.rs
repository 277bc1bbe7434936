//! `feedid compensate`: the command that makes the predicted position follow
//! a desired trajectory (identified model or physical model), optionally
//! verified on the nonlinear virtual rig.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{Context, Result};
use feedid::compensate::{
    compensate_model, compensate_params, verify_on_rig, CompensateConfig, Compensation, Fallback,
    ModelErrorSource, ModelQuality, Smoothing, StartMode, Verification, ZeroHandling,
};
use feedid::drive::{RigEffects, VirtualRig};
use feedid::greybox::LoopModel;
use feedid::io::{cell, read_recording, ChannelRef, ReadOptions};

use crate::args::CompensateArgs;
use crate::cmd::{check_distinct, load_effects, load_model_params, Outputs};

/// The settings of the command from the arguments (validated).
pub(crate) fn config(a: &CompensateArgs) -> Result<CompensateConfig> {
    let smoothing = match a.smooth.trim() {
        "auto" => Smoothing::Auto,
        s => Smoothing::Fixed(s.parse::<f64>().map_err(|_| {
            anyhow::anyhow!("invalid --smooth `{s}`: expected a time in seconds or auto")
        })?),
    };
    let start: StartMode = a.start.parse()?;
    let cfg = CompensateConfig {
        smoothing,
        max_velocity: a.max_velocity,
        max_acceleration: a.max_acceleration,
        max_smoothing: a.max_smoothing,
        unit_dc_gain: !a.keep_dc_gain,
        start,
        min_benefit: a.min_benefit,
        min_fit_percent: a.min_fit,
        fallback: !a.no_fallback,
        ..CompensateConfig::default()
    };
    cfg.validate()?;
    Ok(cfg)
}

/// The desired trajectory: one position column against time.
pub(crate) fn read_desired(a: &CompensateArgs) -> Result<feedid::Recording> {
    let opts = ReadOptions {
        time: Some(ChannelRef::parse(&a.desired_time)?),
        command: Some(ChannelRef::parse(&a.desired_column)?),
        position: Some(ChannelRef::parse(&a.desired_column)?),
        ..ReadOptions::default()
    };
    Ok(read_recording(&a.desired, &opts)?)
}

/// A rig for `--verify`, if asked.
pub(crate) fn verify_rig(a: &CompensateArgs) -> Result<Option<VirtualRig>> {
    if !a.verify {
        return Ok(None);
    }
    let params = load_model_params(a.rig.as_deref(), a.allow_unstable)?;
    let effects = match &a.effects {
        Some(p) => load_effects(p)?,
        None => RigEffects::default(),
    };
    Ok(Some(
        VirtualRig::new(params)
            .with_effects(effects)
            .with_seed(a.seed),
    ))
}

/// Compute, write, verify, print.
pub fn run(a: &CompensateArgs) -> Result<()> {
    if a.measured.is_some() {
        return super::learn::run(a);
    }
    let mut ins = vec![a.desired.as_path()];
    ins.extend(a.model.as_deref());
    ins.extend(a.params.as_deref());
    ins.extend(a.rig.as_deref());
    ins.extend(a.effects.as_deref());
    ins.extend(a.check.iter().map(|p| p.as_path()));
    let mut outs = vec![a.output.as_path()];
    outs.extend(a.verify_out.as_deref());
    outs.extend(a.summary.as_deref());
    check_distinct(&ins, &outs)?;
    let mut cfg = config(a)?;
    let position_loop: LoopModel = a.position_loop.parse()?;
    let verify_rig = verify_rig(a)?;
    let rec = read_desired(a)?;
    let desired = rec.position();
    let dt = rec.dt();

    let mut text = String::new();
    let (source, comp) = match (&a.model, &a.params) {
        (Some(path), _) => from_model(a, path, desired, dt, &mut cfg)?,
        (None, Some(path)) => {
            let params = load_model_params(Some(path), a.allow_unstable)?;
            let comp = compensate_params(&params, position_loop, desired, dt, &cfg)
                .with_context(|| path.display().to_string())?;
            (
                format!(
                    "{} [physical model, {} position loop]",
                    path.display(),
                    position_loop.name()
                ),
                comp,
            )
        }
        (None, None) => anyhow::bail!("give --model model.json or --params rig.toml"),
    };
    refuse_runaway(a, &rec, &comp)?;
    let _ = writeln!(
        text,
        "{}: {} samples at {:.2} Hz; model {source}",
        a.desired.display(),
        rec.len(),
        rec.rate_hz()
    );
    describe(
        &mut text,
        &comp,
        &cfg.quality,
        a.check.len(),
        a.encoder_resolution.is_some(),
    );

    let command = Command {
        rec: &rec,
        command: &comp.command,
        predicted: &comp.predicted,
        summary: serde_json::to_value(&comp)?,
        model: &source,
    };
    write_command(a, verify_rig.as_ref(), &mut text, command, &[], |_| Ok(()))?;
    print!("{text}");
    warn(a, &comp, desired);
    Ok(())
}

/// The compensation from an identified model (`--model`), its quality on
/// `--check` or on its own identification recording set in `cfg`; the
/// model's description and the compensation.
fn from_model(
    a: &CompensateArgs,
    path: &Path,
    desired: &[f64],
    dt: f64,
    cfg: &mut CompensateConfig,
) -> Result<(String, Compensation)> {
    let file = crate::cmd::load_model_file(path)?;
    if let Some(q) = a.encoder_resolution {
        if !(q.is_finite() && q > 0.0) {
            anyhow::bail!(
                "--encoder-resolution {q}: the encoder's resolution must be a positive length [m]"
            );
        }
    }
    cfg.quality = match a.check.as_slice() {
        [check] => {
            // (dropped samples: the model runs through them)
            let opts = ReadOptions {
                allow_gaps: true,
                ..ReadOptions::default()
            };
            let r = read_recording(check, &opts)?;
            ModelQuality::from_recording(&file.model, &r)
                .with_context(|| check.display().to_string())?
        }
        [first, second] => {
            // two runs of the program: complete, the noise out by cross-products
            let opts = ReadOptions::default();
            let r1 = read_recording(first, &opts)?;
            let r2 = read_recording(second, &opts)?;
            ModelQuality::from_two_recordings(&file.model, &r1, &r2, a.encoder_resolution)
                .with_context(|| format!("{} and {}", first.display(), second.display()))?
        }
        [] => ModelQuality {
            // the fits on the model's own identification recording
            position_fit_percent: file.identified_by.as_ref().map(|p| p.fit_percent),
            error_fit_percent: file
                .identified_by
                .as_ref()
                .and_then(|p| p.error_fit_percent),
            noise_rms_m: None,
        },
        more => anyhow::bail!(
            "--check given {} times: one recording of the axis, or two runs of the same program",
            more.len()
        ),
    };
    let comp = compensate_model(&file.model, desired, dt, cfg)
        .with_context(|| path.display().to_string())?;
    let how = match &file.identified_by {
        Some(p) => format!("{} {} (fit {:.2} %)", p.method, p.orders, p.fit_percent),
        None => "model".to_string(),
    };
    Ok((format!("{} [{how}]", path.display()), comp))
}

/// An unstable model (allowed by --allow-unstable) can give a command that
/// runs away: refused, nothing written.
fn refuse_runaway(a: &CompensateArgs, rec: &feedid::Recording, comp: &Compensation) -> Result<()> {
    for (name, v) in [
        ("command", &comp.command),
        ("predicted position", &comp.predicted),
    ] {
        if let Some(k) = v.iter().position(|x| !feedid::recording::is_usable(*x)) {
            anyhow::bail!(
                "{}: the {name} runs away ({:e} at t = {} s): the model cannot be inverted here; nothing written",
                a.output.display(),
                v[k],
                rec.time()[k]
            );
        }
    }
    Ok(())
}

/// The warnings on standard error: a fallback to the plain trajectory
/// (which meets the limits: the library refuses one that does not),
/// approximated zeros, pre-actuation.
fn warn(a: &CompensateArgs, comp: &Compensation, desired: &[f64]) {
    if let Some(f) = &comp.fallback {
        eprintln!(
            "warning: the plain desired trajectory is sent as the command: {f}; {}",
            fallback_hint(f, a, comp, desired)
        );
    }
    if !comp.exact_inverse {
        eprintln!(
            "warning: the model has zeros on the unit circle; they were approximated (zero phase error), so even the model does not follow exactly"
        );
    }
    if comp.pre_actuation_m > 1e-3 * comp.predicted_error.rms.max(1e-9)
        && comp.pre_actuation_m > 1e-9
    {
        eprintln!(
            "warning: the command would have to start moving {:.3} µm before the first sample (pre-actuation of non-minimum-phase zeros); give the trajectory more rest at its start",
            1e6 * comp.pre_actuation_m
        );
    }
}

/// `command.csv`: `time_s,command_m,desired_m,predicted_m`.
pub(crate) fn add_command_csv<'a>(
    outputs: &mut Outputs<'a>,
    path: &Path,
    time: &'a [f64],
    command: &'a [f64],
    desired: &'a [f64],
    predicted: &'a [f64],
) -> Result<()> {
    outputs.add(path, move |w| {
        writeln!(w, "time_s,command_m,desired_m,predicted_m")?;
        for k in 0..time.len() {
            writeln!(
                w,
                "{},{},{},{}",
                cell(Some(time[k])),
                cell(Some(command[k])),
                cell(Some(desired[k])),
                cell(Some(predicted[k]))
            )?;
        }
        Ok(())
    })
}

/// `--verify-out`: `time_s,desired_m,position_uncompensated_m,position_compensated_m`.
pub(crate) fn add_verification_csv<'a>(
    outputs: &mut Outputs<'a>,
    path: &Path,
    time: &'a [f64],
    desired: &'a [f64],
    v: &'a Verification,
) -> Result<()> {
    outputs.add(path, move |w| {
        writeln!(
            w,
            "time_s,desired_m,position_uncompensated_m,position_compensated_m"
        )?;
        for k in 0..time.len() {
            writeln!(
                w,
                "{},{},{},{}",
                cell(Some(time[k])),
                cell(Some(desired[k])),
                cell(Some(v.position_uncompensated[k])),
                cell(Some(v.position_compensated[k]))
            )?;
        }
        Ok(())
    })
}

/// The summary's context: the files, samples, rate, limits and the
/// verification with its seed.
/// A command for the desired trajectory of `rec` and what goes with it.
pub(crate) struct Command<'a> {
    pub(crate) rec: &'a feedid::Recording,
    pub(crate) command: &'a [f64],
    pub(crate) predicted: &'a [f64],
    /// The summary's own keys.
    pub(crate) summary: serde_json::Value,
    /// What the model is, for the summary.
    pub(crate) model: &'a str,
}

/// The command run on the rig when `--verify` asks (its figures appended to
/// `text`), and the output set written together: the command CSV, the
/// verification CSV, the summary (with `extra` keys) and what `more` adds.
pub(crate) fn write_command(
    a: &CompensateArgs,
    rig: Option<&VirtualRig>,
    text: &mut String,
    c: Command<'_>,
    extra: &[(&'static str, String)],
    more: impl FnOnce(&mut Outputs<'_>) -> Result<()>,
) -> Result<()> {
    let (rec, desired) = (c.rec, c.rec.position());
    let verification = match rig {
        Some(rig) => Some(verify_on_rig(rig, desired, c.command, rec.rate_hz())?),
        None => None,
    };
    if let Some(v) = &verification {
        describe_verification(text, v, a.seed);
    }
    let mut outputs = Outputs::default();
    add_command_csv(
        &mut outputs,
        &a.output,
        rec.time(),
        c.command,
        desired,
        c.predicted,
    )?;
    if let (Some(p), Some(v)) = (&a.verify_out, &verification) {
        add_verification_csv(&mut outputs, p, rec.time(), desired, v)?;
    }
    if let Some(p) = &a.summary {
        let mut v = c.summary;
        if let Some(obj) = v.as_object_mut() {
            add_summary_context(obj, a, c.model, rec, verification.as_ref())?;
            for (k, value) in extra {
                obj.insert((*k).into(), value.clone().into());
            }
        }
        outputs.add_text(p, format!("{}\n", serde_json::to_string_pretty(&v)?))?;
    }
    more(&mut outputs)?;
    outputs.commit()
}

pub(crate) fn add_summary_context(
    obj: &mut serde_json::Map<String, serde_json::Value>,
    a: &CompensateArgs,
    model: &str,
    rec: &feedid::Recording,
    verification: Option<&Verification>,
) -> Result<()> {
    obj.insert("desired".into(), a.desired.display().to_string().into());
    obj.insert("model".into(), model.into());
    obj.insert("samples".into(), rec.len().into());
    obj.insert("rate_hz".into(), rec.rate_hz().into());
    obj.insert("max_velocity_limit".into(), json_limit(a.max_velocity));
    obj.insert(
        "max_acceleration_limit".into(),
        json_limit(a.max_acceleration),
    );
    if let Some(ver) = verification {
        let mut vv = serde_json::to_value(ver)?;
        if let Some(o) = vv.as_object_mut() {
            o.insert("seed".into(), a.seed.into());
        }
        obj.insert("verification".into(), vv);
    }
    Ok(())
}

/// A length in µm, in scientific notation when below 1 nm.
pub(crate) fn micrometres(m: f64) -> String {
    if m != 0.0 && m.abs() < 1e-9 {
        format!("{:.3e} µm", 1e6 * m)
    } else {
        format!("{:.4} µm", 1e6 * m)
    }
}

/// A limit for JSON (∞ as null).
fn json_limit(v: f64) -> serde_json::Value {
    if v.is_finite() {
        v.into()
    } else {
        serde_json::Value::Null
    }
}

fn describe(t: &mut String, c: &Compensation, q: &ModelQuality, checks: usize, encoder: bool) {
    let count = |h: ZeroHandling| c.zeros.iter().filter(|z| z.handling == h).count();
    let _ = writeln!(
        t,
        "  sampled model: delay {} sample(s), DC gain {:.6}{}; zeros: {} inside (causal), {} outside (anti-causal), {} on the unit circle (zero-phase approximation)",
        c.delay_samples,
        c.model_dc_gain,
        if (c.model_dc_gain - 1.0).abs() > 1e-12 { " (rescaled to 1)" } else { "" },
        count(ZeroHandling::Causal),
        count(ZeroHandling::AntiCausal),
        count(ZeroHandling::ZeroPhase)
    );
    let fit = |v: Option<f64>| v.map_or("unknown".to_string(), |f| format!("{f:.2} %"));
    let _ = writeln!(
        t,
        "  start: {}; end velocity {:.6} m/s held after the last sample; model fit: position {}, following error {}",
        match c.start {
            StartMode::Rest => "at rest",
            StartMode::Moving => "moving",
        },
        c.end_velocity,
        fit(q.position_fit_percent),
        fit(q.error_fit_percent)
    );
    match &c.fallback {
        None => {
            let _ = writeln!(
                t,
                "  model's prediction: plain command rms {}, compensated rms {}; the model's own error here {} ({}): expected rms {}, benefit {:.2}×",
                micrometres(c.benefit.predicted_plain_rms_m),
                micrometres(c.benefit.predicted_compensated_rms_m),
                micrometres(c.benefit.model_error_rms_m),
                match c.benefit.model_error_from {
                    ModelErrorSource::ErrorFit => match checks {
                        0 => "the share of the following error it does not explain on its identification recording; --check run.csv measures it on this program",
                        1 => "the share of the following error it does not explain on --check; two runs of the program (--check a.csv --check b.csv) take the noise out exactly",
                        _ if encoder => "the share of the following error it does not explain on the two --check runs, without their noise (cross-products) and the encoder's rounding they share",
                        _ => "the share of the following error it does not explain on the two --check runs, without their noise (cross-products)",
                    },
                    ModelErrorSource::PositionFit => "its free-run fit scaled to this motion; --check run.csv measures it on the axis",
                    ModelErrorSource::Unknown => "unknown: the model file has no fit; give --check run.csv",
                },
                micrometres(c.benefit.expected_compensated_rms_m),
                c.benefit.expected_benefit
            );
            let _ = writeln!(
                t,
                "  command sent: compensated; smoothing σ up to {:.3} ms on {:.1} % of the samples{}{}; peak velocity {:.4} m/s at t = {:.4} s, peak acceleration {:.3} m/s² at t = {:.4} s",
                1e3 * c.smoothing_s,
                100.0 * c.smoothed_share,
                if c.start_ease_s > 0.0 {
                    format!(", start eased in (mean lag {:.3} ms)", 1e3 * c.start_ease_s)
                } else {
                    String::new()
                },
                if c.held_back_share > 0.0 && c.slewed {
                    format!(
                        "; the command slewed at the limits on {:.1} % of the samples (off the compensated one until it has caught up), where no smoothing up to --max-smoothing meets them",
                        100.0 * c.held_back_share
                    )
                } else if c.held_back_share > 0.0 {
                    format!(
                        "; the correction held back on {:.1} % of the samples, where no smoothing up to --max-smoothing meets the limits",
                        100.0 * c.held_back_share
                    )
                } else {
                    String::new()
                },
                c.peak_velocity,
                c.peak_velocity_time_s,
                c.peak_acceleration,
                c.peak_acceleration_time_s
            );
        }
        Some(f) => {
            let _ = writeln!(
                t,
                "  model's prediction: plain command rms {}",
                micrometres(c.benefit.predicted_plain_rms_m),
            );
            let _ = writeln!(
                t,
                "  command sent: the plain desired trajectory, because {f}; peak velocity {:.4} m/s, peak acceleration {:.3} m/s²",
                c.peak_velocity, c.peak_acceleration
            );
        }
    }
    let _ = writeln!(
        t,
        "  predicted − desired: rms {}, max {}",
        micrometres(c.predicted_error.rms),
        micrometres(c.predicted_error.max_abs)
    );
}

/// What would change a fall-back, in the command line's words.
fn fallback_hint(f: &Fallback, a: &CompensateArgs, c: &Compensation, desired: &[f64]) -> String {
    let moving_at_start = c.start == StartMode::Rest
        && desired.len() > 2
        && (desired[1] - desired[0]).abs()
            > 1e-9
                * desired
                    .iter()
                    .fold(0.0_f64, |m, v| m.max((v - desired[0]).abs()));
    let start = if moving_at_start {
        " The trajectory moves at its first sample: if it is cut from a longer program, --start moving compensates it as such."
    } else {
        ""
    };
    let text = match *f {
        Fallback::PoorFit { .. } => format!(
            "identify the model again on a run that excites the axis more (a chirp or PRBS, `feedid identify --model-out`), or measure its fit on this axis with --check run.csv; --min-fit (now {} %) lowers the threshold",
            a.min_fit
        ),
        Fallback::SmallBenefit { .. } => format!(
            "the model's own error leaves little to gain: a better model (--check run.csv shows how much of the following error it explains) or learning from a measured run (--measured run.csv) can; --min-benefit (now {}) lowers the threshold",
            a.min_benefit
        ),
        Fallback::Limits { quantity, .. } => format!(
            "raise --max-{quantity} (now {}) or allow more smoothing with --max-smoothing (now {} s)",
            if quantity == "velocity" { a.max_velocity } else { a.max_acceleration },
            a.max_smoothing
        ),
    };
    format!("{text}.{start}")
}

pub(crate) fn describe_verification(t: &mut String, v: &Verification, seed: u64) {
    let _ = writeln!(t, "  virtual rig (seed {seed}), measured − desired:");
    for (name, e) in [
        ("uncompensated", &v.uncompensated),
        ("compensated", &v.compensated),
    ] {
        let _ = writeln!(
            t,
            "    {name:<13}  rms {:>9.4} µm  max {:>9.4} µm  (true position: rms {:.4} µm)  peak current {:.2} A",
            1e6 * e.rms_m,
            1e6 * e.max_abs_m,
            1e6 * e.rms_true_m,
            e.peak_current_a
        );
    }
    let _ = writeln!(t, "    rms reduced {:.1}-fold", v.improvement);
}
