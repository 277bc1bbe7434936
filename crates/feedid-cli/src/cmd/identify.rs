//! `feedid identify`: sliding-window identification and prediction of a recording.

use anyhow::Result;
use feedid::ident::{identify, ArxOrders, EngineConfig, MethodSpec, PaperConfig};
use feedid::io::{write_coefficients_csv, write_predictions_csv, write_string_atomic};

use crate::args::{IdentifyArgs, MethodArgs, WindowArgs};
use crate::cmd::{load_params, recording, Outputs};

/// The method named on the command line with its options.
pub fn method_spec(m: &MethodArgs) -> Result<MethodSpec> {
    let mut spec = MethodSpec::new(m.method.parse()?);
    spec.paper = PaperConfig {
        solver: m.solver.parse()?,
        time_origin: m.time_origin.parse()?,
        prediction: m.prediction.parse()?,
        ..spec.paper
    };
    if let Some(o) = &m.order {
        let orders = parse_orders(o)?;
        spec.arx.orders = orders;
        spec.rls.orders = orders;
    }
    if let Some(l) = m.lambda {
        spec.rls.lambda = l;
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

/// Identify, write the outputs, print a short summary.
pub fn run(a: &IdentifyArgs) -> Result<()> {
    let spec = method_spec(&a.method)?;
    let mut est = spec.build()?;
    let cfg = engine_config(&a.windows, &spec);
    let params = load_params(a.params.as_deref())?;
    let rec = recording::load(&a.input, &a.recording)?;
    let run = identify(&rec, est.as_mut(), &cfg, Some(&params))?;
    let summary = run.summary();

    let mut outputs = Outputs::default();
    outputs.write(&a.output, |p| {
        write_predictions_csv(
            p,
            rec.time(),
            rec.command(),
            rec.position(),
            &run.sliding,
            run.simulated.as_deref(),
        )
    })?;
    if let Some(p) = &a.coefficients {
        outputs.write(p, |p| write_coefficients_csv(p, rec.time(), &run.sliding))?;
    }
    if let Some(p) = &a.summary {
        let json = serde_json::to_string_pretty(&summary)?;
        outputs.write(p, |p| write_string_atomic(p, &format!("{json}\n")))?;
    }
    outputs.commit();

    println!(
        "{}: {} samples at {:.2} Hz, method {}, window {}, horizon {}, hop {}",
        a.input.display(),
        summary.samples,
        summary.rate_hz,
        summary.method,
        summary.window,
        summary.horizon,
        summary.hop
    );
    println!(
        "  {} windows ({} failed, {} fallback), {} samples predicted",
        summary.windows,
        summary.failed_windows,
        summary.fallback_windows,
        summary.samples_predicted
    );
    println!(
        "  prediction error: rms {:.3} µm, max {:.3} µm, fit {:.3} %",
        1e6 * summary.rms_error_m,
        1e6 * summary.max_abs_error_m,
        summary.fit_percent
    );
    if let (Some(r), Some(m)) = (summary.sim_rms_error_m, summary.sim_max_abs_error_m) {
        println!(
            "  simulation model:  rms {:.3} µm, max {:.3} µm",
            1e6 * r,
            1e6 * m
        );
    }
    println!(
        "  time: {:.3} ms identification and prediction, {:.2} µs per window",
        1e3 * summary.identification_seconds,
        summary.per_window_us
    );
    Ok(())
}
