//! `feedid reproduce`: the paper's experiments on the virtual rig.

use std::path::PathBuf;

use anyhow::{Context, Result};
use feedid::experiment::{run_experiment, summary_markdown, PaperExperimentConfig};
use feedid::ident::Method;
use feedid::signal::Scenario;
use feedid_report::experiment::{error_chart, response_chart};
use feedid_report::paper_report;

use crate::args::ReproduceArgs;
use crate::cmd::progress::ProgressBar;
use crate::cmd::{check_distinct, load_model_params, Outputs};

/// Run ramp and step, write figures, summary.md and report.html, print the table.
pub fn run(a: &ReproduceArgs) -> Result<()> {
    let cfg = PaperExperimentConfig {
        params: load_model_params(a.params.as_deref(), a.allow_unstable)?,
        seed: a.seed,
        solver: a.solver.parse()?,
        axis: a.axis.parse()?,
        ..PaperExperimentConfig::default()
    };
    // three steps of about equal length: the two experiments, the report
    let bar = ProgressBar::new("reproduce", "steps");
    bar.update(0, 3);
    let mut results = Vec::new();
    for s in [Scenario::Ramp, Scenario::Step] {
        results.push(run_experiment(s, &cfg)?);
        bar.update(results.len() as u64, 3);
    }
    // an unstable rig (allowed by --allow-unstable) runs its simulation model
    // away: the comparison has nothing to compare then, and never prints inf
    for r in &results {
        let e = &r.simulation.whole;
        if !(e.rms.is_finite() && e.max_abs.is_finite() && e.max_abs < 1e100) {
            anyhow::bail!(
                "{}: the nominal simulation model diverged on the {} (unstable parameters); \
                 the paper's comparison needs a running model; nothing written",
                a.params
                    .as_deref()
                    .map_or_else(|| "the rig".to_string(), |p| p.display().to_string()),
                r.name
            );
        }
    }
    let mut files = Vec::new();
    for r in &results {
        files.push((
            format!("{}_response.svg", r.name),
            response_chart(r).to_svg()?,
        ));
        files.push((format!("{}_error.svg", r.name), error_chart(r).to_svg()?));
    }
    let md = summary_markdown(&results, &cfg);
    files.push(("summary.md".to_string(), md.clone()));
    let others = a
        .compare
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty() && *s != "none")
        .map(|s| Ok(s.parse::<Method>()?))
        .collect::<Result<Vec<_>>>()?;
    let page = paper_report(&results, &cfg, &others)?;
    bar.finish();
    files.push(("report.html".to_string(), page.to_html()));

    std::fs::create_dir_all(&a.out)
        .with_context(|| format!("{}: cannot create directory", a.out.display()))?;
    let paths: Vec<PathBuf> = files.iter().map(|(name, _)| a.out.join(name)).collect();
    check_distinct(
        &a.params.iter().map(|p| p.as_path()).collect::<Vec<_>>(),
        &paths.iter().map(|p| p.as_path()).collect::<Vec<_>>(),
    )?;
    let mut outputs = Outputs::default();
    // summary.md and report.html are the last two
    for (path, (_, text)) in paths.iter().zip(files) {
        outputs.add_text(path, text)?;
    }
    outputs.commit()?;
    println!("{md}");
    println!("written to {}", a.out.display());
    Ok(())
}
