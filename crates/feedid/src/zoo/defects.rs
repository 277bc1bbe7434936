//! Defects of real traces: isolated wild samples (glitches) in the measured
//! position, and dropped rows.
//!
//! * **Glitches** (members `i mod 12 = 5`): 1–3 rows, drawn uniformly after the
//!   first tenth of the recording and at least 20 rows apart, get an offset of
//!   random sign and a size log-uniform between 0.1 and 1000 times the
//!   command's amplitude (an encoder or bus error; up to a kilometre on a
//!   one-metre stroke). The truth column keeps the clean position.
//! * **Dropped rows** (the gapped members after the regular ones): 1–2 runs of
//!   1–3 rows are removed from a copy of a regular member, so the time column
//!   jumps there. The reader refuses such a file (it checks uniform
//!   sampling), so these members are kept apart, marked with `dropped_rows`
//!   (rows of the uniform recording) and `gap_source` (the member they copy);
//!   compare the two to see what a gap costs a method that accepts it.

use super::design::Draws;
use super::spec::Glitch;

/// Glitches for a recording of `n` rows and command amplitude `amplitude` \[m\].
pub(crate) fn glitches(d: &mut Draws, n: usize, amplitude: f64) -> Vec<Glitch> {
    let count = 1 + (d.uniform(0.0, 3.0) as usize).min(2);
    let mut out: Vec<Glitch> = Vec::with_capacity(count);
    let lo = n / 10;
    let mut attempts = 0;
    while out.len() < count && attempts < 100 && n > lo + 1 {
        attempts += 1;
        let index = lo + (d.uniform(0.0, (n - lo) as f64) as usize).min(n - lo - 1);
        if out.iter().any(|g| g.index.abs_diff(index) < 20) {
            continue;
        }
        let size = amplitude.max(1e-6) * d.log_uniform(0.1, 1000.0);
        out.push(Glitch {
            index,
            offset: d.sign() * size,
        });
    }
    out.sort_by_key(|g| g.index);
    out
}

/// Rows to drop from a recording of `n` rows (sorted, in the middle 60 %).
pub(crate) fn dropped_rows(d: &mut Draws, n: usize) -> Vec<usize> {
    let runs = 1 + (d.uniform(0.0, 2.0) as usize).min(1);
    let mut rows = Vec::new();
    for r in 0..runs {
        let len = 1 + (d.uniform(0.0, 3.0) as usize).min(2);
        // one run in each half of the middle 60 %
        let lo = n / 5 + r * (3 * n / 10);
        let start = lo + (d.uniform(0.0, (3 * n / 10 - len) as f64) as usize);
        rows.extend(start..start + len);
    }
    rows.sort_unstable();
    rows.dedup();
    rows
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glitches_are_isolated_and_inside_the_recording() {
        for i in 0..50 {
            let mut d = Draws::new(13, i, 210);
            let g = glitches(&mut d, 2000, 0.01);
            assert!((1..=3).contains(&g.len()));
            for w in g.windows(2) {
                assert!(w[1].index >= w[0].index + 20);
            }
            for x in &g {
                assert!(x.index >= 200 && x.index < 2000);
                assert!(x.offset.abs() >= 1e-3 && x.offset.abs() <= 10.0);
            }
        }
    }

    #[test]
    fn dropped_rows_are_short_runs_in_the_middle() {
        for i in 0..50 {
            let mut d = Draws::new(13, i, 210);
            let rows = dropped_rows(&mut d, 3000);
            assert!((1..=6).contains(&rows.len()), "{rows:?}");
            assert!(rows.iter().all(|&r| (600..2400).contains(&r)), "{rows:?}");
        }
    }
}
