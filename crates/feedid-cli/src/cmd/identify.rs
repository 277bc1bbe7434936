//! `feedid identify`: sliding-window identification and prediction of a
//! recording — arguments, one library pipeline call per recording
//! ([`feedid::pipeline::Pipeline`]), the output files and the printed summary.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use feedid::error::Syntax;
use feedid::ident::{GlobalModelKind, GuardConfig, OrderSearch, SlidingResult};
use feedid::io::{
    write_coefficients_csv, write_predictions_csv, CoefficientRow, PredictionColumns,
};
use feedid::pipeline::Pipeline;

use crate::args::{IdentifyArgs, RecordingArgs};
use crate::cmd::method::OrderOption;
use crate::cmd::progress::ProgressBar;
use crate::cmd::{check_distinct, load_model_params, recording, Outputs};

/// The coefficients table's rows of a sliding run.
fn coefficient_rows<'a>(
    time: &'a [f64],
    s: &'a SlidingResult,
) -> impl Iterator<Item = CoefficientRow<'a>> + 'a {
    s.windows
        .iter()
        .enumerate()
        .map(move |(i, rec)| CoefficientRow {
            start_s: time.get(rec.window.start).copied(),
            end_s: time.get(rec.window.end.saturating_sub(1)).copied(),
            residual_rms_m: rec.residual_rms,
            iterations: rec.iterations,
            termination: rec.outcome.label(),
            coefficients: s.window_coefficients(i),
        })
}

/// A writer that shows the bytes written on the bar (every MiB).
struct Counting<'w, 'b> {
    inner: &'w mut dyn std::io::Write,
    bar: &'b ProgressBar,
    written: u64,
    shown: u64,
}

impl<'w, 'b> Counting<'w, 'b> {
    fn new(inner: &'w mut dyn std::io::Write, bar: &'b ProgressBar) -> Self {
        Self {
            inner,
            bar,
            written: 0,
            shown: 0,
        }
    }
}

impl std::io::Write for Counting<'_, '_> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.written += n as u64;
        if self.written - self.shown >= 1 << 20 {
            self.bar.set_bytes(self.written);
            self.shown = self.written;
        }
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}

/// Output paths of one recording.
struct OutputPaths {
    predictions: PathBuf,
    coefficients: Option<PathBuf>,
    summary: Option<PathBuf>,
    model: Option<PathBuf>,
}

/// Identify, write the outputs, print a short summary (one file, or a batch with --out-dir).
pub fn run(a: &IdentifyArgs) -> Result<()> {
    let method = a.options.method(&a.method)?;
    #[allow(clippy::neg_cmp_op_on_partial_ord)] // rejects NaN
    if !(a.interval > 0.0 && a.interval < 100.0) {
        bail!(
            "invalid --interval {}: the probability of the prediction intervals must be in (0, 100) % (e.g. 95)",
            a.interval
        );
    }
    let params = load_model_params(a.params.as_deref(), a.allow_unstable)?;
    let rig = a
        .params
        .as_deref()
        .map_or_else(|| "built-in".to_string(), |p| p.display().to_string());
    let mut pipeline = Pipeline::new(method)
        .spans(a.windows.window, a.windows.horizon, a.windows.hop)
        .guard(GuardConfig {
            interval: a.interval / 100.0,
            runaway: a.runaway.0,
            ..GuardConfig::default()
        })
        .nominal(params);
    if a.options.order_option()? == Some(OrderOption::Select) {
        pipeline = pipeline.select_orders(OrderSearch::default());
    }
    if a.model_out.is_some() {
        let name = a.model_kind.as_deref().unwrap_or("auto");
        let kind = match &a.model_order {
            Some(order) => GlobalModelKind::with_orders(name, order)?,
            None => GlobalModelKind::default_for(name)?,
        };
        pipeline = pipeline.extra_model(kind);
    }
    match (&a.out_dir, a.inputs.as_slice()) {
        (None, [input]) => {
            let paths = OutputPaths {
                predictions: a
                    .output
                    .clone()
                    .ok_or_else(|| anyhow::anyhow!("missing -o predictions.csv"))?,
                coefficients: a.coefficients.clone(),
                summary: a.summary.clone(),
                model: a.model_out.clone(),
            };
            let mut ins = vec![input.as_path()];
            ins.extend(a.params.as_deref());
            let mut outs = vec![paths.predictions.as_path()];
            outs.extend(paths.coefficients.as_deref());
            outs.extend(paths.summary.as_deref());
            outs.extend(paths.model.as_deref());
            check_distinct(&ins, &outs)?;
            // a bar on a terminal for a long run, through every slow phase
            // (an hour of 5 kHz text: reading 2 GB, identifying 18 M
            // samples, writing 1.5 GB)
            let bar = ProgressBar::new("reading", "bytes");
            let update = |done: u64, total: u64| {
                bar.update(done, total);
                if done == total {
                    bar.spin("identify: global model, residuals, summary", false);
                }
            };
            let pipeline = pipeline.progress(&update);
            let text = identify_file(input, &a.recording, &pipeline, &rig, &paths, &bar);
            bar.finish();
            let text = text?;
            print!("{text}");
            Ok(())
        }
        (None, _) => bail!("several inputs need --out-dir DIR (one set of outputs per input)"),
        (Some(dir), inputs) => {
            // two inputs with the same name would overwrite each other's outputs
            let mut seen = std::collections::HashMap::new();
            for input in inputs {
                let stem = output_stem(input);
                if let Some(first) = seen.insert(stem.clone(), input) {
                    bail!(
                        "{} and {} would both write {}: give the recordings different names",
                        first.display(),
                        input.display(),
                        dir.join(format!("{stem}.*")).display()
                    );
                }
            }
            std::fs::create_dir_all(dir)
                .with_context(|| format!("{}: cannot create directory", dir.display()))?;
            // no output may overwrite an input (`--out-dir .` beside a recording
            // named like another's output)
            let batch_outputs: Vec<PathBuf> = inputs
                .iter()
                .flat_map(|input| {
                    let stem = output_stem(input);
                    ["predictions.csv", "coefficients.csv", "summary.json"]
                        .map(|ext| dir.join(format!("{stem}.{ext}")))
                })
                .collect();
            let mut ins: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
            ins.extend(a.params.as_deref());
            let outs: Vec<&Path> = batch_outputs.iter().map(PathBuf::as_path).collect();
            check_distinct(&ins, &outs)?;
            // read, identify and write each recording in its own task
            let results: Vec<Result<String>> = pipeline.run_each(inputs, |pipeline, input| {
                let stem = output_stem(input);
                let paths = OutputPaths {
                    predictions: dir.join(format!("{stem}.predictions.csv")),
                    coefficients: Some(dir.join(format!("{stem}.coefficients.csv"))),
                    summary: Some(dir.join(format!("{stem}.summary.json"))),
                    model: None,
                };
                identify_file(
                    input,
                    &a.recording,
                    pipeline,
                    &rig,
                    &paths,
                    &ProgressBar::hidden(),
                )
            });
            let mut failed = 0;
            for r in &results {
                match r {
                    Ok(text) => print!("{text}"),
                    Err(e) => {
                        // the error names its file (see identify_file)
                        failed += 1;
                        eprintln!("error: {}", crate::one_line(e));
                    }
                }
            }
            if failed > 0 {
                bail!("{failed} of {} recordings failed", results.len());
            }
            Ok(())
        }
    }
}

/// The name of a recording's outputs in batch mode (`DIR/STEM.predictions.csv`, …).
fn output_stem(input: &Path) -> String {
    input
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "recording".to_string())
}

/// Read, identify and write one recording; returns the human-readable summary.
/// Every error names the file once: reading errors carry it from the
/// library, later ones get it here.
fn identify_file(
    input: &Path,
    read: &RecordingArgs,
    pipeline: &Pipeline<'_>,
    rig: &str,
    paths: &OutputPaths,
    bar: &ProgressBar,
) -> Result<String> {
    // the three signals only (no extra columns: 24 bytes per sample); the
    // recording's plausibility warnings come back among the run's
    let rec = recording::read_signals(input, read, &|done, total| bar.update(done, total))?;
    bar.phase("identify", "samples");
    let run = pipeline
        .run(&rec)
        .with_context(|| input.display().to_string())?;
    for w in &run.warnings {
        eprintln!("warning: {}: {}", input.display(), w.phrased(Syntax::Cli));
    }
    let mut summary = run.summary_in(Syntax::Cli);
    summary.nominal_rig = Some(rig.to_string());

    let mut model_line = None;
    let mut model_json = None;
    if let (Some(p), Some(model)) = (&paths.model, &run.model) {
        let mut file = model.clone();
        if let Some(prov) = file.identified_by.as_mut() {
            prov.source = Some(input.display().to_string());
            model_line = Some(format!(
                "  global model: {} {}, free-run fit {:.3} % (rms {:.3} µm) -> {}\n",
                prov.method,
                prov.orders,
                prov.fit_percent,
                1e6 * prov.simulation_rms_m,
                p.display()
            ));
        }
        model_json = Some((p, format!("{}\n", file.to_json())));
    }

    // every output written together or not at all, the summary last
    let mut outputs = Outputs::default();
    let s = &run.sliding;
    outputs.add(&paths.predictions, |w| {
        bar.spin("writing", true);
        write_predictions_csv(
            &mut Counting::new(w, bar),
            rec.time(),
            rec.command(),
            rec.position(),
            PredictionColumns {
                predicted: &s.predicted,
                lower: &s.lower,
                upper: &s.upper,
                has_prediction: &s.has_prediction,
            },
            run.simulated.as_deref(),
        )
    })?;
    if let Some(p) = &paths.coefficients {
        outputs.add(p, |w| {
            write_coefficients_csv(w, &s.coefficient_names, coefficient_rows(rec.time(), s))
        })?;
    }
    if let Some((p, json)) = model_json {
        outputs.add_text(p, json)?;
    }
    if let Some(p) = &paths.summary {
        let json = serde_json::to_string_pretty(&summary)?;
        outputs.add_text(p, format!("{json}\n"))?;
    }
    outputs.commit()?;
    Ok(format!(
        "{}: {summary}{}",
        input.display(),
        model_line.unwrap_or_default()
    ))
}
