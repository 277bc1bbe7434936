//! `feedid reproduce`: the paper's experiments on the virtual rig.

use anyhow::{Context, Result};
use feedid::experiment::{run_experiment, summary_markdown, PaperExperimentConfig};
use feedid::ident::Method;
use feedid::io::write_string_atomic;
use feedid::signal::Scenario;
use feedid_report::experiment::{error_chart, response_chart};
use feedid_report::paper_report;

use crate::args::ReproduceArgs;
use crate::cmd::{load_params, Outputs};

/// Run ramp and step, write figures, summary.md and report.html, print the table.
pub fn run(a: &ReproduceArgs) -> Result<()> {
    let cfg = PaperExperimentConfig {
        params: load_params(a.params.as_deref())?,
        seed: a.seed,
        solver: a.solver.parse()?,
        ..PaperExperimentConfig::default()
    };
    let mut results = Vec::new();
    for s in [Scenario::Ramp, Scenario::Step] {
        results.push(run_experiment(s, &cfg)?);
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
    files.push(("report.html".to_string(), page.to_html()));

    std::fs::create_dir_all(&a.out)
        .with_context(|| format!("{}: cannot create directory", a.out.display()))?;
    let mut outputs = Outputs::default();
    for (name, text) in &files {
        outputs.write(&a.out.join(name), |p| write_string_atomic(p, text))?;
    }
    outputs.commit();
    println!("{md}");
    println!("written to {}", a.out.display());
    Ok(())
}
