//! `feedid identify`: sliding-window identification and prediction of a recording.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use feedid::drive::RigParams;
use feedid::ident::{
    fit_global_model, global_model_for, identify, select_order, ArxOrders, EngineConfig,
    GlobalModelKind, MethodKind, MethodSpec, OrderSearch, PaperConfig, SlidingResult,
    SHIFT_AMPLIFICATION_WARNING,
};
use feedid::io::{write_coefficients_csv, write_predictions_csv, CoefficientRow};
use rayon::prelude::*;

use crate::args::{IdentifyArgs, MethodArgs, WindowArgs};
use crate::cmd::{check_distinct, load_model_params, recording, Outputs};

/// The method named on the command line with its options.
pub fn method_spec(m: &MethodArgs) -> Result<MethodSpec> {
    let mut spec = MethodSpec::new(m.method.parse()?);
    spec.paper = PaperConfig {
        solver: m.solver.parse()?,
        time_origin: m.time_origin.parse()?,
        prediction: m.prediction.parse()?,
        ..spec.paper
    };
    if let Some(o) = m
        .order
        .as_deref()
        .filter(|o| !o.eq_ignore_ascii_case("auto"))
    {
        let orders = parse_orders(o)?;
        spec.arx.orders = orders;
        spec.rls.orders = orders;
    }
    if let Some(l) = m.lambda {
        spec.rls.lambda = l;
    }
    if let Some(t) = m.tolerance {
        spec.auto.tolerance = t * 1e-6;
    }
    Ok(spec)
}

/// `na,nb,nk` → orders.
fn parse_orders(s: &str) -> Result<ArxOrders> {
    let v: Vec<&str> = s.split(',').map(str::trim).collect();
    let parse = |x: &str| -> Result<usize> {
        x.parse()
            .map_err(|_| anyhow::anyhow!("invalid order `{s}`: expected na,nb,nk (e.g. 8,8,1)"))
    };
    if v.len() != 3 {
        anyhow::bail!("invalid order `{s}`: expected na,nb,nk (e.g. 8,8,1)");
    }
    Ok(ArxOrders {
        na: parse(v[0])?,
        nb: parse(v[1])?,
        nk: parse(v[2])?,
    })
}

/// Engine settings from the command line (window defaulting to the method's).
pub fn engine_config(w: &WindowArgs, spec: &MethodSpec) -> EngineConfig {
    EngineConfig {
        window: w.window.unwrap_or_else(|| spec.default_window()),
        horizon: w.horizon,
        hop: w.hop,
        warm_up: 0,
    }
}

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
            residual_rms_m: rec.fit.residual_rms,
            iterations: rec.fit.iterations,
            termination: rec.fit.termination.label(),
            coefficients: s.window_coefficients(i),
        })
}

/// Output paths of one recording.
struct OutputPaths {
    predictions: PathBuf,
    coefficients: Option<PathBuf>,
    summary: Option<PathBuf>,
}

/// Identify, write the outputs, print a short summary (one file, or a batch with --out-dir).
pub fn run(a: &IdentifyArgs) -> Result<()> {
    let spec = method_spec(&a.method)?;
    let cfg = engine_config(&a.windows, &spec);
    let params = load_model_params(a.params.as_deref(), a.allow_unstable)?;
    match (&a.out_dir, a.inputs.as_slice()) {
        (None, [input]) => {
            let paths = OutputPaths {
                predictions: a
                    .output
                    .clone()
                    .ok_or_else(|| anyhow::anyhow!("missing -o predictions.csv"))?,
                coefficients: a.coefficients.clone(),
                summary: a.summary.clone(),
            };
            let mut ins = vec![input.as_path()];
            ins.extend(a.params.as_deref());
            let mut outs = vec![paths.predictions.as_path()];
            outs.extend(paths.coefficients.as_deref());
            outs.extend(paths.summary.as_deref());
            outs.extend(a.model_out.as_deref());
            check_distinct(&ins, &outs)?;
            let text = identify_file(input, a, &spec, &cfg, &params, &paths)?;
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
            let results: Vec<(PathBuf, Result<String>)> = inputs
                .par_iter()
                .map(|input| {
                    let stem = output_stem(input);
                    let paths = OutputPaths {
                        predictions: dir.join(format!("{stem}.predictions.csv")),
                        coefficients: Some(dir.join(format!("{stem}.coefficients.csv"))),
                        summary: Some(dir.join(format!("{stem}.summary.json"))),
                    };
                    let r = identify_file(input, a, &spec, &cfg, &params, &paths);
                    (input.clone(), r)
                })
                .collect();
            let mut failed = 0;
            for (input, r) in &results {
                match r {
                    Ok(text) => print!("{text}"),
                    Err(e) => {
                        failed += 1;
                        eprintln!(
                            "error: {}: {}",
                            input.display(),
                            e.to_string().replace('\n', " ")
                        );
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
fn identify_file(
    input: &Path,
    a: &IdentifyArgs,
    spec: &MethodSpec,
    cfg: &EngineConfig,
    params: &RigParams,
    paths: &OutputPaths,
) -> Result<String> {
    let global_kind = match (&a.model_out, &a.model_kind, &a.model_order) {
        (None, _, _) => None,
        (Some(_), kind, Some(order)) => Some(GlobalModelKind::with_orders(
            kind.as_deref().unwrap_or("auto"),
            order,
        )?),
        (Some(_), kind, None) => Some(GlobalModelKind::default_for(
            kind.as_deref().unwrap_or("auto"),
        )?),
    };
    let (rec, warnings) = recording::load_checked(input, &a.recording)?;
    let mut spec = spec.clone();
    let mut chosen_order = None;
    if a.method
        .order
        .as_deref()
        .is_some_and(|o| o.eq_ignore_ascii_case("auto"))
    {
        let sel = select_order(
            rec.command(),
            rec.position(),
            rec.dt(),
            &OrderSearch::default(),
        )
        .with_context(|| format!("{}: order selection", input.display()))?;
        spec.arx.orders = sel.chosen;
        spec.rls.orders = sel.chosen;
        spec.auto.long.orders = sel.chosen;
        chosen_order = Some((sel.chosen, sel.criterion));
    }
    if spec.kind == MethodKind::Paper {
        let g = spec.paper.worst_shift_amplification(&rec.signals(), cfg);
        if g > SHIFT_AMPLIFICATION_WARNING {
            eprintln!(
                "warning: {}: paper method: windows lie far from the time origin; the \
                 coefficients N, D lose about {:.0} of their 16 digits (amplification {g:.1e}); \
                 predictions are not affected (--time-origin window keeps the coefficients accurate)",
                input.display(),
                g.log10().min(16.0)
            );
        }
    }
    let mut est = spec.build()?;
    let mut run = identify(&rec, est.as_mut(), cfg, Some(params))?;
    let mut global_note = None;
    match global_model_for(&rec, &spec) {
        Ok(g) => run.global = g,
        Err(e) => global_note = Some(format!("  global model: not fitted ({e})")),
    }
    let summary = run.summary();

    let mut global_line = None;
    let mut model_json = None;
    if let (Some(p), Some(kind)) = (&a.model_out, &global_kind) {
        let mut file = fit_global_model(&rec, kind)
            .map_err(|e| anyhow::anyhow!("{}: global model: {e}", input.display()))?;
        if let Some(prov) = file.identified_by.as_mut() {
            prov.source = Some(input.display().to_string());
            global_line = Some(format!(
                "  global model: {} {}, free-run fit {:.3} % (rms {:.3} µm) -> {}",
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
        write_predictions_csv(
            w,
            rec.time(),
            rec.command(),
            rec.position(),
            &s.predicted,
            &s.has_prediction,
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
        let mut v = serde_json::to_value(&summary)?;
        if let Some(obj) = v.as_object_mut() {
            obj.insert("warnings".into(), warnings.clone().into());
        }
        let json = serde_json::to_string_pretty(&v)?;
        outputs.add_text(p, format!("{json}\n"))?;
    }
    outputs.commit()?;

    let mut t = String::new();
    let _ = writeln!(
        t,
        "{}: {} samples at {:.2} Hz, method {}, window {}, horizon {}, hop {}",
        input.display(),
        summary.samples,
        summary.rate_hz,
        summary.method,
        summary.window,
        summary.horizon,
        summary.hop
    );
    if let Some((o, c)) = chosen_order {
        let _ = writeln!(
            t,
            "  order auto ({}): na {}, nb {}, nk {}",
            c.label(),
            o.na,
            o.nb,
            o.nk
        );
    }
    let _ = writeln!(
        t,
        "  {} windows ({} failed, {} fallback, {} withheld), {} samples predicted ({:.1} %)",
        summary.windows,
        summary.failed_windows,
        summary.fallback_windows,
        summary.withheld_windows,
        summary.samples_predicted,
        summary.coverage_percent
    );
    if summary.samples_predicted == 0 {
        // no figure over nothing
        let _ = writeln!(
            t,
            "  prediction error: none (no sample was predicted; see --tolerance, --window and the warnings)"
        );
    } else {
        let _ = writeln!(
            t,
            "  prediction error: rms {:.3} µm, max {:.3} µm, fit {:.3} %{}",
            1e6 * summary.rms_error_m,
            1e6 * summary.max_abs_error_m,
            summary.fit_percent,
            if warnings.is_empty() {
                ""
            } else {
                " (the recording has warnings: see above)"
            }
        );
    }
    if let Some(p) = run.global.as_ref().and_then(|g| g.identified_by.as_ref()) {
        let _ = writeln!(
            t,
            "  global model of the method ({} {}): free-run fit {:.3} %",
            p.method, p.orders, p.fit_percent
        );
    }
    if let Some(n) = global_note {
        let _ = writeln!(t, "{n}");
    }
    match (summary.sim_rms_error_m, summary.sim_max_abs_error_m) {
        (Some(r), Some(m)) if r.is_finite() && m.is_finite() => {
            let _ = writeln!(
                t,
                "  simulation model:  rms {:.3} µm, max {:.3} µm",
                1e6 * r,
                1e6 * m
            );
        }
        (Some(_), _) => {
            let _ = writeln!(t, "  simulation model:  diverged (unstable parameters)");
        }
        _ => {}
    }
    let _ = writeln!(
        t,
        "  time: {:.3} ms identification and prediction, {:.2} µs per window",
        1e3 * summary.identification_seconds,
        summary.per_window_us
    );
    if let Some(line) = global_line {
        let _ = writeln!(t, "{line}");
    }
    Ok(t)
}
