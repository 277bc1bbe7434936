//! The CSV tables of `feedid identify`: predictions per sample and
//! coefficients per window, from plain columns.
//!
//! Numbers are written with Rust's shortest round-trip formatting, so a value
//! read back is bit-identical. A missing or non-finite value is an empty
//! cell: no `NaN` or `inf` is ever written.

use std::io::Write;

/// Format an optional value as a CSV cell (empty when missing or non-finite).
pub fn cell(v: Option<f64>) -> String {
    match v {
        Some(x) if x.is_finite() => format!("{x}"),
        _ => String::new(),
    }
}

/// The per-sample predictions of a run, as columns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PredictionColumns<'a> {
    /// Predicted position \[m\]; counts only where `has_prediction`.
    pub predicted: &'a [f64],
    /// Lower bound of the prediction interval \[m\].
    pub lower: &'a [f64],
    /// Upper bound of the prediction interval \[m\].
    pub upper: &'a [f64],
    /// Whether the sample was predicted.
    pub has_prediction: &'a [bool],
}

/// Write `time_s,command_m,measured_m,predicted_m,lower_m,upper_m,simulated_m`,
/// one row per sample of `time`; the prediction and its interval count only
/// where `has_prediction[k]`; empty cells where nothing was predicted or
/// simulated (or a value is not finite).
pub fn write_predictions_csv(
    w: &mut dyn Write,
    time: &[f64],
    command: &[f64],
    measured: &[f64],
    predictions: PredictionColumns<'_>,
    simulated: Option<&[f64]>,
) -> std::io::Result<()> {
    writeln!(
        w,
        "time_s,command_m,measured_m,predicted_m,lower_m,upper_m,simulated_m"
    )?;
    let at = |v: &[f64], k: usize| v.get(k).copied();
    // one row formatted into a reused buffer, then written whole (no
    // allocation per cell: 18 M rows for an hour at 5 kHz)
    let mut row = String::with_capacity(128);
    for (k, t) in time.iter().enumerate() {
        let has = predictions.has_prediction.get(k) == Some(&true);
        let pick = |v: &[f64]| if has { at(v, k) } else { None };
        row.clear();
        push_cell(&mut row, Some(*t));
        row.push(',');
        push_cell(&mut row, at(command, k));
        row.push(',');
        push_cell(&mut row, at(measured, k));
        row.push(',');
        push_cell(&mut row, pick(predictions.predicted));
        row.push(',');
        push_cell(&mut row, pick(predictions.lower));
        row.push(',');
        push_cell(&mut row, pick(predictions.upper));
        row.push(',');
        push_cell(&mut row, simulated.and_then(|s| at(s, k)));
        row.push('\n');
        w.write_all(row.as_bytes())?;
    }
    Ok(())
}

/// Append [`cell`]`(v)` to `out` without allocating.
fn push_cell(out: &mut String, v: Option<f64>) {
    use std::fmt::Write as _;
    if let Some(x) = v.filter(|x| x.is_finite()) {
        // writing to a String cannot fail
        let _ = write!(out, "{x}");
    }
}

/// One window's row of the coefficients table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoefficientRow<'a> {
    /// Time of the window's first sample \[s\].
    pub start_s: Option<f64>,
    /// Time of the window's last sample \[s\].
    pub end_s: Option<f64>,
    /// RMS of the fit residuals \[m\].
    pub residual_rms_m: f64,
    /// Solver iterations.
    pub iterations: usize,
    /// Why the solver stopped (`converged`, `fallback`, …).
    pub termination: &'a str,
    /// The coefficients, in the order of the names.
    pub coefficients: &'a [f64],
}

/// Write `window,start_s,end_s,residual_rms_m,iterations,termination,<names…>`,
/// one row per window.
pub fn write_coefficients_csv<'a, I>(
    w: &mut dyn Write,
    names: &[String],
    rows: I,
) -> std::io::Result<()>
where
    I: IntoIterator<Item = CoefficientRow<'a>>,
{
    write!(
        w,
        "window,start_s,end_s,residual_rms_m,iterations,termination"
    )?;
    for n in names {
        write!(w, ",{n}")?;
    }
    writeln!(w)?;
    for (i, r) in rows.into_iter().enumerate() {
        write!(
            w,
            "{},{},{},{},{},{}",
            i,
            cell(r.start_s),
            cell(r.end_s),
            cell(Some(r.residual_rms_m)),
            r.iterations,
            r.termination
        )?;
        for c in r.coefficients {
            write!(w, ",{}", cell(Some(*c)))?;
        }
        writeln!(w)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_are_empty_for_missing_or_nonfinite() {
        assert_eq!(cell(None), "");
        assert_eq!(cell(Some(f64::NAN)), "");
        assert_eq!(cell(Some(f64::INFINITY)), "");
        assert_eq!(cell(Some(0.1)), "0.1");
    }

    #[test]
    fn predictions_leave_unpredicted_and_nonfinite_cells_empty() {
        let mut out = Vec::new();
        write_predictions_csv(
            &mut out,
            &[0.0, 0.5, 1.0],
            &[1.0, 2.0, 3.0],
            &[1.0, 2.0, 3.0],
            PredictionColumns {
                predicted: &[9.0, 2.5, f64::NAN],
                lower: &[8.0, 2.25, 1.0],
                upper: &[10.0, 2.75, 2.0],
                has_prediction: &[false, true, true],
            },
            Some(&[1.0, f64::INFINITY, 3.0]),
        )
        .unwrap();
        assert_eq!(
            String::from_utf8(out).unwrap(),
            "time_s,command_m,measured_m,predicted_m,lower_m,upper_m,simulated_m\n\
             0,1,1,,,,1\n0.5,2,2,2.5,2.25,2.75,\n1,3,3,,1,2,3\n"
        );
    }

    #[test]
    fn predictions_rows_are_the_cells_of_the_row_by_row_format() {
        // the buffered writer gives exactly `cell` joined by commas
        let vals = [0.1, -2.5e-7, 1e300, 3.0, f64::NAN, 1.0 / 3.0, -0.0, 5e-324];
        let n = vals.len();
        let rot = |s: usize| -> Vec<f64> { (0..n).map(|k| vals[(k + s) % n]).collect() };
        let (t, u, y, p, sim) = (rot(0), rot(1), rot(2), rot(3), rot(4));
        let (lo, hi) = (rot(5), rot(6));
        let has: Vec<bool> = (0..n).map(|k| k % 3 != 0).collect();
        let mut out = Vec::new();
        let cols = PredictionColumns {
            predicted: &p,
            lower: &lo,
            upper: &hi,
            has_prediction: &has,
        };
        write_predictions_csv(&mut out, &t, &u, &y, cols, Some(&sim)).unwrap();
        let mut expect =
            String::from("time_s,command_m,measured_m,predicted_m,lower_m,upper_m,simulated_m\n");
        for k in 0..n {
            let pick = |v: &[f64]| if has[k] { Some(v[k]) } else { None };
            expect.push_str(&format!(
                "{},{},{},{},{},{},{}\n",
                cell(Some(t[k])),
                cell(Some(u[k])),
                cell(Some(y[k])),
                cell(pick(&p)),
                cell(pick(&lo)),
                cell(pick(&hi)),
                cell(Some(sim[k]))
            ));
        }
        assert_eq!(String::from_utf8(out).unwrap(), expect);
    }

    #[test]
    fn coefficients_have_one_row_per_window() {
        let mut out = Vec::new();
        let names = vec!["a1".to_string(), "b1".to_string()];
        let rows = [
            CoefficientRow {
                start_s: Some(0.0),
                end_s: Some(0.1),
                residual_rms_m: 1e-6,
                iterations: 3,
                termination: "converged",
                coefficients: &[0.5, f64::NAN],
            },
            CoefficientRow {
                start_s: None,
                end_s: None,
                residual_rms_m: 0.0,
                iterations: 0,
                termination: "failed",
                coefficients: &[1.0, 2.0],
            },
        ];
        write_coefficients_csv(&mut out, &names, rows).unwrap();
        assert_eq!(
            String::from_utf8(out).unwrap(),
            "window,start_s,end_s,residual_rms_m,iterations,termination,a1,b1\n\
             0,0,0.1,0.000001,3,converged,0.5,\n1,,,0,0,failed,1,2\n"
        );
    }
}
