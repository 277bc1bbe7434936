//! `feedid compensate --measured`: the next run's command learned from a
//! measured run of the program (iterative learning control with the
//! identified model, `feedid::compensate::learn`).

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{bail, Context, Result};
use feedid::compensate::{learn, LearnConfig, LearnStatus, Learning, LearningHistory, NoiseFilter};
use feedid::io::{read_recording, read_text_up_to, ChannelRef, ReadOptions};
use feedid::Recording;

use super::compensate::{config, micrometres, read_desired, write_command, Command};
use crate::args::CompensateArgs;
use crate::cmd::check_distinct;

/// Learn, write, verify, print.
pub fn run(a: &CompensateArgs) -> Result<()> {
    let Some(measured_path) = a.measured.as_deref() else {
        bail!("--measured run.csv is needed to learn");
    };
    let Some(model_path) = a.model.as_deref() else {
        bail!("learning from a run needs --model model.json (an identified model)");
    };
    let mut ins = vec![a.desired.as_path(), model_path, measured_path];
    ins.extend(a.sent.as_deref());
    let mut outs = vec![a.output.as_path()];
    outs.extend(a.verify_out.as_deref());
    outs.extend(a.summary.as_deref());
    outs.extend(a.history.as_deref());
    check_distinct(&ins, &outs)?;
    let noise_filter = match a.noise_filter.trim() {
        "auto" => NoiseFilter::Auto,
        s => NoiseFilter::Fixed(s.parse::<f64>().map_err(|_| {
            anyhow::anyhow!("invalid --noise-filter `{s}`: expected a time in seconds or auto")
        })?),
    };
    let cfg = LearnConfig {
        gain: a.learning_gain,
        noise_filter,
        compensate: config(a)?,
        ..LearnConfig::default()
    };
    cfg.validate()?;
    let verify_rig = super::compensate::verify_rig(a)?;

    let rec = read_desired(a)?;
    let desired = rec.position();
    let dt = rec.dt();
    let file = crate::cmd::load_model_file(model_path)?;
    let run = read_recording(measured_path, &ReadOptions::default())?;
    same_grid(&rec, &a.desired, &run, measured_path)?;
    let sent: Vec<f64> = match a.sent.as_deref() {
        Some(p) => {
            let opts = ReadOptions {
                command: Some(ChannelRef::parse("command_m")?),
                position: Some(ChannelRef::parse("command_m")?),
                ..ReadOptions::default()
            };
            let s = read_recording(p, &opts)?;
            same_grid(&rec, &a.desired, &s, p)?;
            s.command().to_vec()
        }
        None => run.command().to_vec(),
    };
    let history = match a.history.as_deref() {
        Some(p) => read_history(p)?,
        None => None,
    };
    let step = learn(
        &file.model,
        desired,
        &sent,
        run.position(),
        dt,
        &cfg,
        history.as_ref(),
    )
    .with_context(|| measured_path.display().to_string())?;

    let how = match &file.identified_by {
        Some(p) => format!("{} {} (fit {:.2} %)", p.method, p.orders, p.fit_percent),
        None => "model".to_string(),
    };
    let source = format!("{} [{how}]", model_path.display());
    let mut text = String::new();
    let _ = writeln!(
        text,
        "{}: run {} of {} ({} samples at {:.2} Hz); model {source}",
        measured_path.display(),
        step.run,
        a.desired.display(),
        rec.len(),
        rec.rate_hz()
    );
    describe(&mut text, &step, a);
    let sent = a.sent.as_deref().unwrap_or(measured_path);
    let command = Command {
        rec: &rec,
        command: &step.command,
        predicted: &step.predicted,
        summary: serde_json::to_value(&step)?,
        model: &source,
    };
    let extra = [
        ("measured_run", measured_path.display().to_string()),
        ("sent", sent.display().to_string()),
    ];
    let history = serde_json::to_string(&step.history)?;
    write_command(
        a,
        verify_rig.as_ref(),
        &mut text,
        command,
        &extra,
        |outputs| {
            if let Some(p) = &a.history {
                outputs.add_text(p, format!("{history}\n"))?;
            }
            Ok(())
        },
    )?;
    print!("{text}");
    warn(&step, a);
    Ok(())
}

/// A file on the desired trajectory's samples: as many rows, the same interval.
fn same_grid(
    desired: &Recording,
    desired_path: &Path,
    other: &Recording,
    path: &Path,
) -> Result<()> {
    if other.len() != desired.len() {
        bail!(
            "{}: {} samples, but the desired trajectory {} has {}: a run must be recorded on the program's samples",
            path.display(),
            other.len(),
            desired_path.display(),
            desired.len()
        );
    }
    if (other.dt() - desired.dt()).abs() > 1e-6 * desired.dt() {
        bail!(
            "{}: sample interval {} s, but the desired trajectory {} has {} s",
            path.display(),
            other.dt(),
            desired_path.display(),
            desired.dt()
        );
    }
    Ok(())
}

/// The history at `path`: `None` when there is no file yet.
fn read_history(path: &Path) -> Result<Option<LearningHistory>> {
    match std::fs::symlink_metadata(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(e).with_context(|| format!("{}", path.display())),
        Ok(m) if !m.is_file() => bail!(
            "{}: not a regular file; a learning history is a JSON file that feedid writes",
            path.display()
        ),
        Ok(_) => {}
    }
    let text = read_text_up_to(path, feedid::io::MAX_STREAM_BYTES)?;
    let h: LearningHistory = serde_json::from_str(&text).map_err(|e| {
        anyhow::anyhow!(
            "{}: not a feedid learning history ({e}); give a new file name to start one",
            path.display()
        )
    })?;
    Ok(Some(h))
}

fn describe(t: &mut String, s: &Learning, a: &CompensateArgs) {
    let _ = writeln!(
        t,
        "  measured − desired: rms {}, max {} (noise {}{})",
        micrometres(s.measured.rms),
        micrometres(s.measured.max_abs),
        micrometres(s.noise_m),
        if s.wild_samples > 0 {
            format!("; {} wild sample(s) held", s.wild_samples)
        } else {
            String::new()
        }
    );
    if let Some(p) = s.previous_rms_m {
        let change = if s.measured.rms <= p {
            format!("shrank {:.2}×", p / s.measured.rms.max(1e-300))
        } else {
            format!("grew {:.2}×", s.measured.rms / p.max(1e-300))
        };
        let _ = writeln!(t, "  run {}: rms {} — {change}", s.run - 1, micrometres(p));
    }
    let status = match s.status {
        LearnStatus::First => "first run of this history: a step from it".to_string(),
        LearnStatus::Improving => "no worse than the best run: a step from it".to_string(),
        LearnStatus::AtNoise => {
            "at the noise of the measurement (rms within 1.25× the noise): nothing left to learn, the same command again".to_string()
        }
        LearnStatus::Damped {
            best_run,
            best_rms_m,
        } => format!(
            "worse than run {best_run} (rms {}) or not shrinking as predicted: the step is taken again from run {best_run} with half the gain",
            micrometres(best_rms_m)
        ),
        LearnStatus::Stopped {
            best_run,
            best_rms_m,
        } => format!(
            "stopped: run {best_run}'s command (rms {}) is sent again",
            micrometres(best_rms_m)
        ),
        LearnStatus::Settled {
            best_run,
            best_rms_m,
            achieved_share,
        } => match achieved_share {
            Some(share) => format!(
                "settled: the last step achieved {:.0} % of the reduction the model predicted for it (less than a tenth), and the model did not predict the axis's answer in any band; run {best_run}'s command (rms {}) is sent again",
                100.0 * share,
                micrometres(best_rms_m)
            ),
            None => format!(
                "settled: the model expects a further step to lower the rms by less than a tenth{}; run {best_run}'s command (rms {}) is sent again",
                if s.held_back_share > 0.5 {
                    format!(
                        " (the limits hold it back on {:.1} % of the samples: --max-velocity {} m/s, --max-acceleration {} m/s²)",
                        100.0 * s.held_back_share,
                        a.max_velocity,
                        a.max_acceleration
                    )
                } else {
                    String::new()
                },
                micrometres(best_rms_m)
            ),
        },
    };
    let _ = writeln!(t, "  learning: {status}");
    let share = if s.explained_share > 0.0 {
        format!(
            "explains {:.1} % of the run's error",
            100.0 * s.explained_share
        )
    } else {
        "explains none of the run's error (its own error on the run is larger)".to_string()
    };
    let _ = writeln!(
        t,
        "  model: {share}{}",
        if s.gain > 0.0 && s.explained_share < 1.0 && s.response_ratio.is_none() {
            "; the step's gain is scaled by it (at least ½)"
        } else {
            ""
        }
    );
    if let Some(r) = s.response_ratio {
        let _ = writeln!(
            t,
            "  the axis answered the last step {:.2}× as strongly as the model predicted{}",
            r,
            if s.gain > 0.0 {
                " (this step is scaled by its inverse, ½…2)"
            } else {
                ""
            }
        );
    }
    if s.unanswered_share > 0.0 && s.gain > 0.0 {
        let _ = writeln!(
            t,
            "  the axis did not answer the last step as the model predicted on {:.1} % of the samples: little or nothing of their error is learned again",
            100.0 * s.unanswered_share
        );
    }
    if s.gain > 0.0 {
        let _ = writeln!(
            t,
            "  step: gain {:.3}{}, noise filter σ {:.3} ms{}, step smoothing σ {:.3} ms{}",
            s.gain,
            if s.gain_limited {
                " (halved to keep the command within its limits)"
            } else {
                ""
            },
            1e3 * s.noise_filter_s,
            if s.robustness_filter_s >= a.max_smoothing * (1.0 - 1e-9) {
                " (at least --max-smoothing: the axis answered the last step as the model predicted in no narrower band)".to_string()
            } else if s.robustness_filter_s > 0.0 {
                format!(
                    " (at least {:.3} ms: the band in which the axis answered the last step as the model predicted)",
                    1e3 * s.robustness_filter_s
                )
            } else {
                String::new()
            },
            1e3 * s.step_smoothing_s,
            if s.held_back_share > 0.0 {
                format!(
                    ", held back on {:.1} % of the samples (limits)",
                    100.0 * s.held_back_share
                )
            } else {
                String::new()
            }
        );
    } else if s.gain_limited {
        let _ = writeln!(
            t,
            "  step: none — no step keeps the command within --max-velocity {} m/s and --max-acceleration {} m/s² (raise them, or --max-smoothing {} s); the same command again",
            a.max_velocity, a.max_acceleration, a.max_smoothing
        );
    }
    let _ = writeln!(
        t,
        "  next run, as the model predicts it: rms {} (measured with the noise: about {})",
        micrometres(s.predicted_next_rms_m),
        micrometres(s.predicted_next_measured_rms_m)
    );
    let _ = writeln!(
        t,
        "  command: peak velocity {:.4} m/s at t = {:.4} s, peak acceleration {:.3} m/s² at t = {:.4} s",
        s.peaks.velocity,
        s.peaks.velocity_time_s,
        s.peaks.acceleration,
        s.peaks.acceleration_time_s
    );
}

fn warn(s: &Learning, a: &CompensateArgs) {
    if a.history.is_none() {
        eprintln!(
            "note: without --history the runs are not numbered and nothing checks that the error shrinks; give --history FILE to keep them"
        );
    }
    match s.status {
        LearnStatus::Damped { best_run, .. } => eprintln!(
            "warning: run {} was worse than run {best_run} or did not shrink as the model predicted; the gain is halved to {} — if this repeats, identify the model again on a richer run",
            s.run, s.gain
        ),
        LearnStatus::Settled { best_run, .. } => eprintln!(
            "note: the learning has settled: what is left of the error is not what the model can correct; run {best_run}'s command is written again. A model identified on a run of the compensated command, or one of richer structure, may lower it further (start a new history)"
        ),
        LearnStatus::Stopped { best_run, .. } => eprintln!(
            "warning: the learning has stopped: the error kept growing with the gain halved; run {best_run}'s command is written again. The model is wrong where the error lives: identify it again (a richer run, or on this program's own recording) and start a new history"
        ),
        _ => {}
    }
}
