//! `feedid report`: a self-contained HTML report of one recording.

use anyhow::{bail, Result};
use feedid::ident::EngineConfig;
use feedid_report::{recording_report, RecordingAnalysis, ReportOptions};

use crate::args::ReportArgs;
use crate::cmd::method::OrderOption;
use crate::cmd::progress::ProgressBar;
use crate::cmd::{check_distinct, load_model_params, params_error, recording, Outputs};

/// Identify with every method, build the page, write it atomically.
pub fn run(a: &ReportArgs) -> Result<()> {
    if a.options.order_option()? == Some(OrderOption::Select) {
        bail!("--order auto is for `feedid identify`; give the orders (na,nb,nk; `feedid order` chooses them)");
    }
    let methods = a
        .options
        .methods(a.methods.as_deref(), crate::args::REPORT_METHODS)?;
    if !(a.zoom.is_finite() && a.zoom > 0.0) {
        bail!(
            "invalid --zoom {}: must be a positive number of milliseconds",
            a.zoom
        );
    }
    let mut ins = vec![a.input.as_path()];
    ins.extend(a.params.as_deref());
    check_distinct(&ins, &[a.output.as_path()])?;
    let params = load_model_params(a.params.as_deref(), a.allow_unstable)?;
    // dropped samples: the methods restart after each gap (as `identify`)
    let (rec, warnings) = recording::load_checked(&a.input, &a.recording)?;
    let rate = rec.rate_hz();
    let methods = methods
        .into_iter()
        .map(|m| {
            let cfg = EngineConfig {
                window: m.window_for(a.windows.window, rate)?,
                horizon: a.windows.horizon.samples(rate, "horizon")?,
                hop: a.windows.hop.map(|h| h.samples(rate, "hop")).transpose()?,
                warm_up: 0,
            };
            Ok((m, cfg))
        })
        .collect::<Result<Vec<_>>>()?;
    let mut opts = ReportOptions::new(methods);
    opts.params = params;
    opts.params_source = match &a.params {
        Some(p) => format!("the rig parameters in {}", p.display()),
        None => "the built-in default rig".to_string(),
    };
    opts.zoom_s = a.zoom / 1e3;
    let name = a.input.file_name().map_or_else(
        || a.input.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    let bar = ProgressBar::new("report", "samples");
    let update = |done: u64, total: u64| bar.update(done, total);
    let analysis = RecordingAnalysis::run_with_progress(&name, rec, &opts, Some(&update));
    bar.finish();
    let mut analysis = analysis.map_err(|e| match e {
        // extreme but valid parameters can give no usable nominal model: say which file
        feedid_report::Error::Core(core)
            if matches!(core.root(), feedid::Error::InvalidModel { .. }) && a.params.is_some() =>
        {
            params_error(a.params.as_deref(), core)
        }
        other => other.into(),
    })?;
    analysis
        .comparison
        .notes
        .extend(warnings.iter().map(|w| format!("warning: {w}")));
    let page = recording_report(&analysis)?;
    let html = page.to_html();
    let mut outputs = Outputs::default();
    outputs.add(&a.output, |w| w.write_all(html.as_bytes()))?;
    outputs.commit()?;

    println!(
        "{}: {} samples at {:.2} Hz",
        a.input.display(),
        analysis.recording.len(),
        analysis.recording.rate_hz()
    );
    for m in &analysis.runs {
        let s = m.identification.summary();
        match (s.rms_error_m, s.max_abs_error_m, s.fit_percent) {
            (Some(rms), Some(max), Some(fit)) => println!(
                "  {:<32} rms {:>10.3} µm  max {:>10.3} µm  fit {:>7.2} %  coverage {:.1} %",
                m.label,
                1e6 * rms,
                1e6 * max,
                fit,
                s.coverage_percent
            ),
            _ => println!("  {:<32} no sample predicted (no error reported)", m.label),
        }
    }
    println!(
        "  {:<32} rms {:>10.3} µm  max {:>10.3} µm",
        "simulation model (nominal)",
        1e6 * analysis.simulation_stats.rms,
        1e6 * analysis.simulation_stats.max_abs
    );
    for n in &analysis.notes {
        println!("  note: {n}");
    }
    println!(
        "written {} ({} figures, {} kB)",
        a.output.display(),
        page.figure_ids().len(),
        html.len().div_ceil(1024)
    );
    Ok(())
}
