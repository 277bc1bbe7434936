//! `feedid order`: model-order selection on a recording.

use anyhow::{bail, Result};
use feedid::ident::{select_order, OrderSearch, TermKind};

use crate::args::OrderArgs;
use crate::cmd::recording;

/// `lo..hi` or `n` → inclusive range.
fn range(name: &str, s: &str) -> Result<(usize, usize)> {
    let parse = |x: &str| -> Result<usize> {
        x.trim()
            .parse()
            .map_err(|_| anyhow::anyhow!("invalid --{name} `{s}`: expected LO..HI or N"))
    };
    let r = match s.split_once("..") {
        Some((a, b)) => (parse(a)?, parse(b.trim_start_matches('='))?),
        None => {
            let n = parse(s)?;
            (n, n)
        }
    };
    if r.0 > r.1 {
        bail!("invalid --{name} `{s}`: empty range");
    }
    Ok(r)
}

/// Print the order table, the FROLS terms and the choice.
pub fn run(a: &OrderArgs) -> Result<()> {
    // dropped samples: the orders are chosen on the stretch between them
    // where the command moves most (lagged regressors must not reach across
    // a gap, and a stretch at rest teaches nothing)
    let rec = recording::load(&a.input, &a.recording)?;
    let part = rec.moving_segment();
    let search = OrderSearch {
        na: range("na", &a.na)?,
        nb: range("nb", &a.nb)?,
        nk: range("nk", &a.nk)?,
        criterion: a.criterion.parse()?,
        validation_fraction: a.validation,
        ..OrderSearch::default()
    };
    let (u, y) = (&rec.command()[part.clone()], &rec.position()[part.clone()]);
    let stretch = if rec.gaps().is_empty() {
        None
    } else {
        Some(format!(
            "the stretch between dropped samples where the command moves most: samples {}..{} ({} of {}; {} gap(s), {} sample(s) missing)",
            part.start,
            part.end,
            part.len(),
            rec.len(),
            rec.gaps().len(),
            rec.missing_samples()
        ))
    };
    let sel = select_order(u, y, rec.dt(), &search).map_err(|e| match &stretch {
        Some(s) => anyhow::anyhow!("{}: on {s}: {e}", a.input.display()),
        None => anyhow::anyhow!("{}: {e}", a.input.display()),
    })?;
    if a.json {
        let mut v = serde_json::to_value(&sel)?;
        if let Some(obj) = v.as_object_mut() {
            obj.insert("first_sample".into(), part.start.into());
            obj.insert("samples_used".into(), part.len().into());
            obj.insert("samples".into(), rec.len().into());
            obj.insert("gaps".into(), rec.gaps().len().into());
        }
        println!("{}", serde_json::to_string_pretty(&v)?);
        return Ok(());
    }
    println!("{}", a.input.display());
    if let Some(s) = &stretch {
        println!("orders chosen on {s}");
    }
    println!("{}", sel.table);
    println!("FROLS terms in order of selection (error reduction ratio, cumulative):");
    let mut total = 0.0;
    for t in &sel.frols.terms {
        total += t.err;
        let name = match t.kind {
            TermKind::Output => format!("y[k-{}]", t.lag),
            TermKind::Input => format!("u[k-{}]", t.lag),
            TermKind::Constant => "constant".to_string(),
        };
        println!(
            "  {name:<10} ERR {:.3e}  1-ΣERR {:.3e}",
            t.err,
            (1.0 - total).max(0.0)
        );
    }
    println!(
        "choice by {:?}: na = {}, nb = {}, nk = {} (use with --method arx --order {},{},{})",
        sel.criterion,
        sel.chosen.na,
        sel.chosen.nb,
        sel.chosen.nk,
        sel.chosen.na,
        sel.chosen.nb,
        sel.chosen.nk
    );
    Ok(())
}
