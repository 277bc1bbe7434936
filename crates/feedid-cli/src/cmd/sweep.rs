//! `feedid sweep`: prediction error of every window × horizon × method ×
//! order combination, in parallel, with a heat map and the best choice.

use std::fmt::Write as _;

use anyhow::{bail, Context, Result};
use feedid::ident::{sweep, SweepConfig, SweepResult};

use crate::args::SweepArgs;
use crate::cmd::method::{parse_orders, OrderOption};
use crate::cmd::progress::ProgressBar;
use crate::cmd::{check_distinct, recording, Outputs};

/// A comma-separated list of sample counts ≥ 1 (duplicates dropped, order kept).
fn parse_counts(flag: &str, s: &str) -> Result<Vec<usize>> {
    let mut out = Vec::new();
    for item in s.split(',').map(str::trim) {
        let v: usize = item.parse().map_err(|_| {
            anyhow::anyhow!(
                "invalid {flag} value `{item}` in `{s}`: expected whole numbers of samples, e.g. 10,20,40"
            )
        })?;
        if v == 0 {
            bail!("invalid {flag} value `0` in `{s}`: must be at least 1 sample");
        }
        if !out.contains(&v) {
            out.push(v);
        }
    }
    Ok(out)
}

/// The text table: one line per method/order/horizon, one column per window.
fn table(res: &SweepResult) -> String {
    let mut windows: Vec<usize> = res.rows.iter().map(|r| r.window).collect();
    windows.sort_unstable();
    windows.dedup();
    let mut keys: Vec<(String, usize)> = Vec::new();
    for r in &res.rows {
        let k = (r.model_label(), r.horizon);
        if !keys.contains(&k) {
            keys.push(k);
        }
    }
    let mut s = String::new();
    let _ = write!(s, "{:<20} {:>4}", "method", "H");
    for w in &windows {
        let _ = write!(s, " {:>10}", format!("W={w}"));
    }
    s.push('\n');
    for (m, h) in &keys {
        let _ = write!(s, "{m:<20} {h:>4}");
        for w in &windows {
            let cell = res
                .rows
                .iter()
                .find(|r| &r.model_label() == m && r.horizon == *h && r.window == *w)
                .filter(|r| r.ok())
                .map_or("–".to_string(), |r| {
                    format!("{:.3}", 1e6 * r.rms_common_m)
                });
            let _ = write!(s, " {cell:>10}");
        }
        s.push('\n');
    }
    s
}

/// Parse, sweep in parallel, write CSV (and SVG), print the table and the best choice.
pub fn run(a: &SweepArgs) -> Result<()> {
    if a.options.order_option()? == Some(OrderOption::Select) {
        bail!("--order auto is for `feedid identify`; sweep orders with --orders (na,nb,nk …)");
    }
    let methods = a
        .options
        .methods(a.methods.as_deref(), crate::args::SWEEP_METHODS)?;
    let windows = parse_counts("--windows", &a.windows)?;
    let horizons = parse_counts("--horizons", &a.horizons)?;
    let orders = a
        .orders
        .iter()
        .map(|o| parse_orders(o).context("--orders"))
        .collect::<Result<Vec<_>>>()?;
    if a.hop == Some(0) {
        bail!("invalid --hop 0: must be at least 1 sample");
    }
    let mut outs = vec![a.output.as_path()];
    outs.extend(a.plot.as_deref());
    check_distinct(&[a.input.as_path()], &outs)?;
    // dropped samples: every combination restarts after each gap (as `identify`)
    let rec = recording::load(&a.input, &a.recording)?;
    let cfg = SweepConfig {
        methods,
        windows,
        horizons,
        orders,
        hop: a.hop,
    };
    let bar = ProgressBar::new("sweep", "combinations");
    let res = sweep(&rec, &cfg, &|done, total| {
        bar.update(done as u64, total as u64);
    });
    bar.finish();
    let res = res?;
    if !res.rows.iter().any(|r| r.ok()) {
        let why = res
            .rows
            .iter()
            .find_map(|r| r.error.clone())
            .unwrap_or_else(|| "nothing predicted".into());
        bail!("{}: no combination could run ({why})", a.input.display());
    }
    let csv = res.to_csv();
    let svg = match &a.plot {
        Some(_) => Some(feedid_report::sweep_heat_map(&res).to_svg()?),
        None => None,
    };
    let mut outputs = Outputs::default();
    if let (Some(p), Some(svg)) = (&a.plot, svg) {
        outputs.add_text(p, svg)?;
    }
    outputs.add_text(&a.output, csv)?;
    outputs.commit()?;

    println!(
        "{}: {} samples at {:.2} Hz, {} combinations on {} threads",
        a.input.display(),
        res.samples,
        res.rate_hz,
        res.rows.len(),
        rayon::current_num_threads()
    );
    println!("rms prediction error [µm] over the common samples:");
    print!("{}", table(&res));
    print!("{}", res.summary_text());
    match &a.plot {
        Some(p) => println!("written {} and {}", a.output.display(), p.display()),
        None => println!("written {}", a.output.display()),
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use feedid::ident::ArxOrders;

    #[test]
    fn lists_are_parsed_and_bad_values_named() {
        assert_eq!(
            parse_counts("--windows", "10, 20,10,40").unwrap(),
            vec![10, 20, 40]
        );
        let e = parse_counts("--windows", "0,abc").unwrap_err().to_string();
        assert!(e.contains("`0`"), "{e}");
        let e = parse_counts("--windows", "10,abc").unwrap_err().to_string();
        assert!(e.contains("`abc`") && e.contains("--windows"), "{e}");
        assert!(parse_counts("--horizons", "").is_err());
        assert_eq!(parse_orders("4, 4,1").unwrap(), ArxOrders::new(4, 4, 1));
        assert!(parse_orders("4,4")
            .unwrap_err()
            .to_string()
            .contains("`4,4`"));
    }
}
