//! `feedid greybox`: physical parameters from a recording (simulation error
//! of the physical model) or from identified N and D coefficients, with
//! standard errors, correlations and identifiability; optional tracking over
//! sliding windows.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{bail, Context, Result};
use feedid::drive::RigEffects;
use feedid::error::Syntax;
use feedid::greybox::{
    fit_coefficients, fit_greybox_with_progress, track_greybox_with_progress, Dynamics,
    GreyboxConfig, GreyboxFit, LoopModel, Measurements, PhysicalParameter, TrackConfig,
    TrackWindow,
};
use feedid::ident::LinearModel;
use feedid::io::cell;

use crate::args::GreyboxArgs;
use crate::cmd::progress::ProgressBar;
use crate::cmd::{check_distinct, load_effects, load_model_params, recording, Outputs};

/// Run the fit(s), write the outputs, print the report.
pub fn run(a: &GreyboxArgs) -> Result<()> {
    let mut ins: Vec<&Path> = a.input.iter().map(|p| p.as_path()).collect();
    ins.extend(a.validate.as_deref());
    ins.extend(a.from_model.as_deref());
    ins.extend(a.params.as_deref());
    ins.extend(a.effects.as_deref());
    let mut outs: Vec<&Path> = a.summary.iter().map(|p| p.as_path()).collect();
    outs.extend(a.params_out.as_deref());
    outs.extend(a.track_out.as_deref());
    check_distinct(&ins, &outs)?;
    if let Some(structure) = crate::cmd::load_structure(a.params.as_deref())? {
        return fit_structure(a, &structure);
    }
    let settings = settings(a)?;

    let mut text = String::new();
    let mut context = serde_json::Map::new();
    let (fit, track) = match (&a.from_model, &a.input) {
        (Some(path), _) => (from_model(path, &settings, &mut text, &mut context)?, None),
        (None, Some(input)) => from_recording(a, input, &settings, &mut text, &mut context)?,
        (None, None) => bail!("give a recording or --from-model model.json"),
    };

    report(&mut text, &fit);
    if let Some(rows) = &track {
        report_track(&mut text, &settings.estimate, rows);
    }
    if let Some(path) = &a.validate {
        let other = recording::load(path, &a.recording)?;
        let v = fit
            .validate_on(
                &settings.cfg,
                other.command(),
                other.position(),
                other.rate_hz(),
            )
            .with_context(|| path.display().to_string())?;
        let _ = writeln!(text, "{}", validation_line(path, &v));
        context.insert("validation".into(), serde_json::to_value(v)?);
    }
    write_outputs(a, &fit, track.as_deref(), &settings.estimate, context)?;
    print!("{text}");
    for w in fit.warnings_in(Syntax::Cli) {
        eprintln!("warning: {w}");
    }
    Ok(())
}

/// The printed line of a validation on the recording at `path`.
fn validation_line(path: &Path, v: &feedid::drive::StructureValidation) -> String {
    format!(
        "validation on {} ({} samples): rms error {:.3} µm, max {:.3} µm, fit {:.3} % (tracking error there {:.3} µm rms)",
        path.display(),
        v.samples,
        1e6 * v.rms,
        1e6 * v.max,
        v.fit_percent,
        1e6 * v.tracking_rms
    )
}

/// What to estimate, from where, with which model.
struct Settings {
    estimate: Vec<PhysicalParameter>,
    start: feedid::drive::RigParams,
    position_loop: LoopModel,
    cfg: GreyboxConfig,
}

/// The settings of a fit of the paper's rig from the arguments.
fn settings(a: &GreyboxArgs) -> Result<Settings> {
    let estimate = PhysicalParameter::parse_list(&a.estimate)?;
    let start = load_model_params(a.params.as_deref(), a.allow_unstable)?;
    let position_loop: LoopModel = a.position_loop.parse()?;
    let effects = match &a.effects {
        Some(p) => load_effects(p)?,
        None => RigEffects::default(),
    };
    let cfg = GreyboxConfig {
        dynamics: if a.friction {
            Dynamics::Nonlinear
        } else {
            Dynamics::Linear
        },
        position_loop,
        effects,
        max_iterations: a.max_iterations,
        refuse_unidentifiable: !a.allow_unidentifiable,
        restarts: a.restarts,
        ..GreyboxConfig::default()
    };
    if a.track_window.is_some() && a.track_out.is_none() {
        bail!("--track-window needs --track-out track.csv");
    }
    Ok(Settings {
        estimate,
        start,
        position_loop,
        cfg,
    })
}

/// Parameters from the coefficients of an identified continuous model.
fn from_model(
    path: &Path,
    st: &Settings,
    text: &mut String,
    context: &mut serde_json::Map<String, serde_json::Value>,
) -> Result<GreyboxFit> {
    let file = crate::cmd::load_model_file(path)?;
    let (num, den) = match &file.model {
        LinearModel::Continuous { num, den } if den.len() == 8 && num.len() <= 3 => {
            (num.clone(), den.clone())
        }
        _ => bail!(
            "{}: parameters from coefficients need a continuous model N(s)/D(s) with 7 poles and at most 2 zeros (identify with --model-out M --model-kind oe --model-order 7,2)",
            path.display()
        ),
    };
    let fit = fit_coefficients(&num, &den, &st.start, &st.estimate, &st.cfg)
        .with_context(|| path.display().to_string())?;
    let _ = writeln!(
        text,
        "{}: N2…N0, D7…D0 of the identified model, {} coefficient ratios",
        path.display(),
        fit.residuals
    );
    context.insert("from_model".into(), path.display().to_string().into());
    Ok(fit)
}

/// The recording's column `--current` names, if any.
fn current_column<'r>(
    rec: &'r feedid::Recording,
    a: &GreyboxArgs,
    input: &Path,
) -> Result<Option<&'r [f64]>> {
    let Some(name) = &a.current else {
        return Ok(None);
    };
    let column = rec
        .extra()
        .iter()
        .find(|(n, _)| n == name || n.eq_ignore_ascii_case(name))
        .map(|(_, v)| v.as_slice())
        .ok_or_else(|| {
            let names: Vec<&str> = rec.extra().iter().map(|(n, _)| n.as_str()).collect();
            anyhow::anyhow!(
                "{}: no current column `{name}`; numeric columns besides time, command and position: {}",
                input.display(),
                if names.is_empty() { "none".to_string() } else { names.join(", ") }
            )
        })?;
    Ok(Some(column))
}

/// Parameters from a recording by simulation error, and the tracking over
/// windows if asked.
fn from_recording(
    a: &GreyboxArgs,
    input: &Path,
    st: &Settings,
    text: &mut String,
    context: &mut serde_json::Map<String, serde_json::Value>,
) -> Result<(GreyboxFit, Option<Vec<TrackWindow>>)> {
    // dropped samples: the simulation runs through them on the
    // regular grid (the command interpolated there) and only the
    // measured samples are compared
    let (rec, warnings) = recording::load_checked(input, &a.recording)?;
    context.insert("warnings".into(), warnings.into());
    let current = current_column(&rec, a, input)?;
    let gapped = !rec.gaps().is_empty();
    let fill = |v: &[f64]| -> Result<Vec<f64>> {
        Ok(if gapped {
            rec.fill_gaps(v)?
        } else {
            Vec::new()
        })
    };
    let (command, position) = (fill(rec.command())?, fill(rec.position())?);
    let current_grid = current.map(fill).transpose()?;
    let measured = if gapped {
        rec.grid_indices()
    } else {
        Vec::new()
    };
    let mut data = if gapped {
        Measurements::new(&command, &position, rec.dt()).with_measured(&measured)
    } else {
        Measurements::new(rec.command(), rec.position(), rec.dt())
    };
    if let Some(c) = current {
        data = data.with_current(match &current_grid {
            Some(g) if gapped => g,
            _ => c,
        });
    }
    let bar = ProgressBar::new("greybox", "fits");
    let update = |done: u64, total: u64| bar.update(done, total);
    let fit = fit_greybox_with_progress(&data, &st.start, &st.estimate, &st.cfg, Some(&update));
    bar.finish();
    let fit = fit.with_context(|| input.display().to_string())?;
    describe_recording(
        a,
        input,
        &rec,
        st.position_loop,
        current.is_some(),
        text,
        context,
    );
    let track = match a.track_window {
        Some(w) => Some(track(a, input, &rec, &data, &fit, st, w)?),
        None => None,
    };
    Ok((fit, track))
}

/// The report's line on the recording and its context in the summary.
fn describe_recording(
    a: &GreyboxArgs,
    input: &Path,
    rec: &feedid::Recording,
    position_loop: LoopModel,
    with_current: bool,
    text: &mut String,
    context: &mut serde_json::Map<String, serde_json::Value>,
) {
    let gapped = !rec.gaps().is_empty();
    let _ = writeln!(
        text,
        "{}: {} samples at {:.2} Hz; {} model, {} position loop; outputs: position{}",
        input.display(),
        rec.len(),
        rec.rate_hz(),
        if a.friction {
            "nonlinear (friction)"
        } else {
            "linear"
        },
        position_loop.name(),
        if with_current { ", current" } else { "" }
    );
    if gapped {
        let _ = writeln!(
            text,
            "{} gap(s) of dropped samples ({} missing): the model runs through them on the command interpolated there; only the {} measured samples are compared",
            rec.gaps().len(),
            rec.missing_samples(),
            rec.len()
        );
    }
    context.insert("input".into(), input.display().to_string().into());
    context.insert("samples".into(), rec.len().into());
    context.insert("gaps".into(), rec.gaps().len().into());
    context.insert("missing_samples".into(), rec.missing_samples().into());
    context.insert("rate_hz".into(), rec.rate_hz().into());
    context.insert(
        "dynamics".into(),
        (if a.friction { "nonlinear" } else { "linear" }).into(),
    );
    context.insert("position_loop".into(), position_loop.name().into());
    if let Some(c) = &a.current {
        context.insert("current".into(), c.clone().into());
    }
}

/// The parameters tracked over windows of `window_s` seconds, from the
/// whole recording's fit.
fn track(
    a: &GreyboxArgs,
    input: &Path,
    rec: &feedid::Recording,
    data: &Measurements<'_>,
    fit: &GreyboxFit,
    st: &Settings,
    window_s: f64,
) -> Result<Vec<TrackWindow>> {
    let samples = |s: f64, what: &str| -> Result<usize> {
        let n = (s * rec.rate_hz()).round();
        if !(n.is_finite() && n >= 1.0) {
            bail!("invalid {what} {s} s: must be at least one sample");
        }
        Ok(n as usize)
    };
    let window = samples(window_s, "--track-window")?;
    let hop = match a.track_hop {
        Some(h) => samples(h, "--track-hop")?,
        None => (window / 2).max(1),
    };
    let tc = TrackConfig {
        window,
        hop,
        ..TrackConfig::default()
    };
    let start_track = fit.params;
    let bar = ProgressBar::new("tracking", "windows");
    let update = |done: u64, total: u64| bar.update(done, total);
    let rows = track_greybox_with_progress(
        data,
        &start_track,
        &st.estimate,
        &st.cfg,
        &tc,
        Some(&update),
    );
    bar.finish();
    rows.map_err(|e| anyhow::anyhow!("{}: tracking: {e}", input.display()))
}

/// The parameter file, the track table and the summary, written together.
fn write_outputs(
    a: &GreyboxArgs,
    fit: &GreyboxFit,
    track: Option<&[TrackWindow]>,
    estimate: &[PhysicalParameter],
    context: serde_json::Map<String, serde_json::Value>,
) -> Result<()> {
    let mut outputs = Outputs::default();
    if let Some(p) = &a.params_out {
        outputs.add_text(p, fit.params.to_toml_string())?;
    }
    if let (Some(p), Some(rows)) = (&a.track_out, track) {
        outputs.add(p, |w| write_track_csv(w, estimate, rows))?;
    }
    if let Some(p) = &a.summary {
        let mut v = serde_json::to_value(fit)?;
        if let Some(obj) = v.as_object_mut() {
            for (k, val) in context {
                obj.insert(k, val);
            }
            if let Some(rows) = track {
                obj.insert("track".into(), serde_json::to_value(rows)?);
            }
        }
        let json = serde_json::to_string_pretty(&v)?;
        outputs.add_text(p, format!("{json}\n"))?;
    }
    outputs.commit()?;
    Ok(())
}

fn report(t: &mut String, fit: &GreyboxFit) {
    let unit = if fit.source == "recording" {
        format!("{:.4} µm", 1e6 * fit.residual_rms)
    } else {
        format!("{:.3e} (relative)", fit.residual_rms)
    };
    let _ = write!(
        t,
        "  Levenberg–Marquardt: {} after {} iterations ({} evaluations); rms residual {unit}",
        fit.termination.label(),
        fit.iterations,
        fit.evaluations
    );
    if let Some(i) = fit.current_residual_rms {
        let _ = write!(t, ", current {:.4} A", i);
    }
    if let Some(f) = fit.fit_percent {
        let _ = write!(t, ", fit {f:.3} %");
    }
    let _ = writeln!(t);
    let _ = writeln!(
        t,
        "  {:<4} {:>14} {:>14} {:>12} {:>9}  {:<10} verdict",
        "name", "estimate", "start", "std error", "rel. %", "unit"
    );
    for e in &fit.estimates {
        let _ = writeln!(
            t,
            "  {:<4} {:>14.6e} {:>14.6e} {:>12} {:>9}  {:<10} {}",
            e.name,
            e.value,
            e.start,
            e.std_error.map_or("-".to_string(), |s| format!("{s:.3e}")),
            e.relative_std_error
                .map_or("-".to_string(), |r| format!("{:.3}", 100.0 * r)),
            e.unit,
            e.verdict.label()
        );
    }
    if fit.estimates.len() > 1 {
        let _ = writeln!(t, "  correlation:");
        let _ = write!(t, "  {:<4}", "");
        for e in &fit.estimates {
            let _ = write!(t, " {:>7}", e.name);
        }
        let _ = writeln!(t);
        for (e, row) in fit.estimates.iter().zip(&fit.correlation) {
            let _ = write!(t, "  {:<4}", e.name);
            for c in row {
                let _ = write!(t, " {c:>7.3}");
            }
            let _ = writeln!(t);
        }
    }
    let _ = writeln!(
        t,
        "  condition number of the log-parameter Jacobian: {:.3e}",
        fit.condition_number
    );
    if !fit.residual_structure.is_empty() {
        let parts: Vec<String> = fit
            .residual_structure
            .iter()
            .map(|s| {
                format!(
                    "{} {:.1} % predictable from its past ({})",
                    s.output,
                    100.0 * s.predictable_share,
                    if s.structured { "structured" } else { "white" }
                )
            })
            .collect();
        let _ = writeln!(t, "  residuals: {}", parts.join(", "));
    }
    if let Some(f) = fit.missing_feed_forward {
        let _ = writeln!(
            t,
            "  feed-forward test: Kvff, Kaff would explain {:.1} % of the position residual ({})",
            100.0 * f.explained_share,
            if f.likely {
                "feed-forward probably missing"
            } else {
                "none missing"
            }
        );
    }
    if fit.restarts > 0 {
        let _ = writeln!(
            t,
            "  restarts: {} fits started ±22 % from the estimate",
            fit.restarts
        );
    }
}

fn report_track(t: &mut String, estimate: &[PhysicalParameter], rows: &[TrackWindow]) {
    let skipped = rows.iter().filter(|r| !r.excited).count();
    let _ = writeln!(
        t,
        "  tracking: {} windows ({skipped} without excitation of a parameter: no estimate, the previous one kept)",
        rows.len()
    );
    let _ = write!(t, "  {:>9} {:>10}", "time s", "nut m");
    for p in estimate {
        let _ = write!(t, " {:>12} {:>10}", p.name(), "std");
    }
    let _ = writeln!(t);
    let step = (rows.len() / 10).max(1);
    for (i, r) in rows.iter().enumerate() {
        if i % step != 0 && i + 1 != rows.len() {
            continue;
        }
        let _ = write!(t, "  {:>9.4} {:>10.5}", r.time_s, r.nut_position_m);
        for (v, s) in r.values.iter().zip(&r.std_errors) {
            let v = if !r.excited {
                "-".to_string()
            } else {
                format!("{v:.5e}")
            };
            let _ = write!(
                t,
                " {:>12} {:>10}",
                v,
                s.map_or("-".to_string(), |s| format!("{s:.2e}"))
            );
        }
        if !r.excited {
            let _ = write!(t, "  not excited");
        }
        let _ = writeln!(t);
    }
}

fn write_track_csv(
    w: &mut dyn std::io::Write,
    estimate: &[PhysicalParameter],
    rows: &[TrackWindow],
) -> std::io::Result<()> {
    write!(w, "time_s,nut_position_m,mean_position_m")?;
    for p in estimate {
        write!(w, ",{0},{0}_std_error,{0}_verdict", p.name())?;
    }
    writeln!(w, ",residual_rms_m,termination")?;
    for r in rows {
        write!(
            w,
            "{},{},{}",
            cell(Some(r.time_s)),
            cell(Some(r.nut_position_m)),
            cell(Some(r.mean_position_m))
        )?;
        for ((v, s), verdict) in r.values.iter().zip(&r.std_errors).zip(&r.verdicts) {
            // a window that does not determine the parameter has no estimate of it
            let v = (r.excited).then_some(*v);
            write!(w, ",{},{},{}", cell(v), cell(*s), verdict.label())?;
        }
        writeln!(
            w,
            ",{},{}",
            cell(Some(r.residual_rms_m)),
            // a window that does not excite a parameter has no estimate
            if r.excited {
                r.termination.label()
            } else {
                "not_excited"
            }
        )?;
    }
    Ok(())
}

/// `feedid greybox rec --params structure.toml --estimate M,Fv,…`: a drive
/// structure's parameters from command and position (output error).
fn fit_structure(a: &GreyboxArgs, structure: &feedid::drive::DriveStructure) -> Result<()> {
    let Some(input) = &a.input else {
        bail!(
            "--from-model is for the paper's rig; a drive structure is estimated from a recording"
        );
    };
    if a.friction || a.effects.is_some() || a.track_window.is_some() {
        bail!(
            "--friction, --effects and --track-window are for the paper's rig; \
             a drive structure simulates its own friction law"
        );
    }
    let estimate = a
        .estimate
        .split(',')
        .filter(|t| !t.trim().is_empty())
        .map(|t| t.parse::<feedid::drive::StructureParam>())
        .collect::<feedid::Result<Vec<_>>>()?;
    let rec = recording::load(input, &a.recording)?;
    if !rec.gaps().is_empty() {
        bail!(
            "{}: {} dropped-sample gap(s); a drive structure is fitted on a uniformly sampled recording (cut it at the gap)",
            input.display(),
            rec.gaps().len()
        );
    }
    let fit = structure
        .fit_with_restarts(
            rec.command(),
            rec.position(),
            rec.rate_hz(),
            &estimate,
            a.restarts,
        )
        .with_context(|| input.display().to_string())?;
    // the controller output beside the position: the inverse-dynamics cross-check
    let idim = match &a.current {
        Some(name) => {
            let output = rec
                .extra()
                .iter()
                .find(|(n, _)| n == name || n.eq_ignore_ascii_case(name))
                .map(|(_, v)| v.as_slice())
                .ok_or_else(|| {
                    let names: Vec<&str> = rec.extra().iter().map(|(n, _)| n.as_str()).collect();
                    anyhow::anyhow!(
                        "{}: no controller-output column `{name}`; numeric columns besides time, command and position: {}",
                        input.display(),
                        if names.is_empty() { "none".to_string() } else { names.join(", ") }
                    )
                })?;
            let force: Vec<f64> = output.iter().map(|u| structure.drive.gain * u).collect();
            Some(
                feedid::drive::inverse_dynamics(
                    rec.position(),
                    &force,
                    rec.rate_hz(),
                    &feedid::drive::IdimConfig::default(),
                )
                .with_context(|| input.display().to_string())?,
            )
        }
        None => None,
    };
    let validation = match &a.validate {
        Some(path) => {
            let other = recording::load(path, &a.recording)?;
            let v = fit
                .structure
                .validate_on(other.command(), other.position(), other.rate_hz())
                .with_context(|| path.display().to_string())?;
            Some((path, v))
        }
        None => None,
    };
    let mut outputs = Outputs::default();
    if let Some(p) = &a.params_out {
        outputs.add_text(p, fit.structure.to_toml_string())?;
    }
    if let Some(p) = &a.summary {
        let mut v = serde_json::to_value(&fit)?;
        if let (Some(o), Some(i)) = (v.as_object_mut(), &idim) {
            o.insert("inverse_dynamics".into(), serde_json::to_value(i)?);
        }
        if let (Some(o), Some((_, val))) = (v.as_object_mut(), &validation) {
            o.insert("validation".into(), serde_json::to_value(val)?);
        }
        outputs.add_text(p, format!("{}\n", serde_json::to_string_pretty(&v)?))?;
    }
    outputs.commit()?;
    println!(
        "{}: {} samples at {} Hz, drive structure {}",
        input.display(),
        rec.len(),
        rec.rate_hz(),
        a.params
            .as_deref()
            .map_or_else(String::new, |p| p.display().to_string())
    );
    print!("{fit}");
    if let Some((path, v)) = &validation {
        println!("{}", validation_line(path, v));
    }
    if let Some(i) = idim {
        println!(
            "inverse dynamics (IDIM-LS, force = gain × {}; {} rows): M {:.4} ± {:.2e} kg, Fv {:.4} ± {:.2e} N·s/m, Fc {:.4} ± {:.2e} N, offset {:.4} ± {:.2e} N",
            a.current.as_deref().unwrap_or(""),
            i.rows,
            i.mass.0,
            i.mass.1,
            i.viscous.0,
            i.viscous.1,
            i.coulomb.0,
            i.coulomb.1,
            i.offset.0,
            i.offset.1
        );
    }
    Ok(())
}
