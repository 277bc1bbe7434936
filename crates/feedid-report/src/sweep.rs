//! The heat map of a window sweep ([`feedid::ident::sweep`]): rows
//! method/order, columns window, colour and number the rms error over the
//! common samples.

use feedid::ident::{SweepResult, PAPER_WINDOW};

use crate::plot::HeatMap;

/// Heat map: one row per method/order (and horizon when several), one
/// column per window, colour and number = common-sample rms in µm (log
/// scale); the best cell of each horizon outlined.
pub fn sweep_heat_map(res: &SweepResult) -> HeatMap {
    let windows = res.window_list();
    let groups = res.groups();
    let several_h = res.horizon_list().len() > 1;
    let dt_ms = if res.rate_hz > 0.0 {
        1e3 / res.rate_hz
    } else {
        0.0
    };
    let mut h = HeatMap::new(
        &format!(
            "Prediction rms error over the common samples (from {:.1} ms on{})",
            res.common_start as f64 * dt_ms,
            if res.gaps > 0 {
                " in each segment between dropped samples"
            } else {
                ""
            }
        ),
        "window W [samples]",
        "method",
        "rms error [µm] (log colour scale)",
    );
    h.columns = windows
        .iter()
        .map(|&w| {
            if w == PAPER_WINDOW {
                format!("{w} (paper)")
            } else {
                format!("{w}")
            }
        })
        .collect();
    h.rows = groups
        .iter()
        .map(|(m, hz)| {
            if several_h {
                format!("{m}, H={hz}")
            } else {
                m.clone()
            }
        })
        .collect();
    h.values = vec![f64::NAN; groups.len() * windows.len()];
    for r in &res.rows {
        let (Some(i), Some(j)) = (
            groups
                .iter()
                .position(|g| g.0 == r.model_label() && g.1 == r.horizon),
            windows.iter().position(|&w| w == r.window),
        ) else {
            continue;
        };
        if r.ok() {
            h.values[i * windows.len() + j] = 1e6 * r.rms_common_m;
        }
    }
    for hz in res.horizon_list() {
        if let Some(b) = res.best_for_horizon(hz) {
            let i = groups
                .iter()
                .position(|g| g.0 == b.model_label() && g.1 == b.horizon);
            let j = windows.iter().position(|&w| w == b.window);
            if let (Some(i), Some(j)) = (i, j) {
                h.marked.push((i, j));
            }
        }
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;
    use feedid::drive::{RigParams, VirtualRig};
    use feedid::ident::{sweep, ArxOrders, SweepConfig};
    use feedid::signal::Scenario;
    use feedid::Recording;

    fn ramp() -> Recording {
        let cmd = Scenario::Ramp.command(5000.0, 0.12, 1).unwrap();
        let out = VirtualRig::new(RigParams::default())
            .with_seed(1)
            .simulate(&cmd, 5000.0)
            .unwrap();
        Recording::new(out.time, out.command, out.position).unwrap()
    }

    fn cfg() -> SweepConfig {
        SweepConfig {
            methods: vec!["paper".parse().unwrap(), "arx".parse().unwrap()],
            windows: vec![20, 40, 80],
            horizons: vec![5, 10],
            orders: vec![ArxOrders::new(2, 2, 1), ArxOrders::new(4, 4, 1)],
            hop: None,
        }
    }

    #[test]
    fn heat_map_has_one_cell_per_combination() {
        let res = sweep(&ramp(), &cfg(), &|_, _| {}).unwrap();
        let h = sweep_heat_map(&res);
        // rows: paper×2 horizons + arx 2 orders × 2 horizons = 6; columns 3
        assert_eq!(h.rows.len(), 6);
        assert_eq!(h.columns, vec!["20 (paper)", "40", "80"]);
        assert_eq!(h.values.len(), res.rows.len());
        let svg = h.to_svg().unwrap();
        assert_eq!(svg.matches("class=\"cell\"").count(), res.rows.len());
        assert_eq!(h.marked.len(), 2, "best of each horizon");
    }
}
