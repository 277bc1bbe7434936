//! The figures of the paper's experiments ([`feedid::experiment`]): the
//! counterparts of the paper's figures 5–8 (response and error over the
//! first milliseconds of the motion).

use feedid::experiment::ExperimentResult;

use crate::plot::{LineChart, Series};

/// Measurement, simulation model and identified model over the zoom window
/// (paper figures 5 and 7), in ms and µm.
pub fn response_chart(r: &ExperimentResult) -> LineChart {
    let idx = r.zoom_indices();
    let t = r.recording.time();
    let ms: Vec<f64> = idx.iter().map(|&k| 1e3 * (t[k] - r.motion_start)).collect();
    let um = |f: &dyn Fn(usize) -> Option<f64>| -> Vec<f64> {
        idx.iter()
            .map(|&k| f(k).map_or(f64::NAN, |v| 1e6 * v))
            .collect()
    };
    let id = &r.identification;
    let mut c = LineChart::new(
        &format!(
            "{}: measurement, simulation model and identified model (first {:.0} ms)",
            r.name,
            1e3 * r.zoom
        ),
        "time since motion start [ms]",
        "table position [µm]",
    );
    c.push(
        Series::new(
            "command",
            ms.clone(),
            um(&|k| Some(r.recording.command()[k])),
        )
        .dashed()
        .with_color(5),
    );
    c.push(
        Series::new(
            "measurement (virtual rig)",
            ms.clone(),
            um(&|k| Some(r.recording.position()[k])),
        )
        .with_color(0),
    );
    c.push(
        Series::new(
            "simulation model",
            ms.clone(),
            um(&|k| id.simulated.as_ref().and_then(|s| s.get(k).copied())),
        )
        .with_color(1),
    );
    c.push(
        Series::new(
            &format!("identified model (paper LSM, {})", r.solver.label()),
            ms,
            um(&|k| id.sliding.prediction(k)),
        )
        .with_color(2),
    );
    c
}

/// Error of the identified and of the simulation model against the
/// measurement over the zoom window (paper figures 6 and 8), in µm.
pub fn error_chart(r: &ExperimentResult) -> LineChart {
    let idx = r.zoom_indices();
    let t = r.recording.time();
    let y = r.recording.position();
    let ms: Vec<f64> = idx.iter().map(|&k| 1e3 * (t[k] - r.motion_start)).collect();
    let id = &r.identification;
    let err = |f: &dyn Fn(usize) -> Option<f64>| -> Vec<f64> {
        idx.iter()
            .map(|&k| f(k).map_or(f64::NAN, |v| 1e6 * (y[k] - v)))
            .collect()
    };
    let mut c = LineChart::new(
        &format!(
            "{}: model error against measurement (first {:.0} ms)",
            r.name,
            1e3 * r.zoom
        ),
        "time since motion start [ms]",
        "measurement − model [µm]",
    );
    c.push(
        Series::new(
            "simulation model error",
            ms.clone(),
            err(&|k| id.simulated.as_ref().and_then(|s| s.get(k).copied())),
        )
        .with_color(1),
    );
    c.push(
        Series::new(
            "identified model (LSM) error",
            ms,
            err(&|k| id.sliding.prediction(k)),
        )
        .with_color(2),
    );
    c
}

#[cfg(test)]
mod tests {
    use super::*;
    use feedid::experiment::{run_experiment, PaperExperimentConfig};
    use feedid::ident::Solver;
    use feedid::signal::Scenario;

    #[test]
    fn ramp_figures_show_the_three_curves() {
        let cfg = PaperExperimentConfig {
            solver: Solver::Qr,
            ..Default::default()
        };
        let r = run_experiment(Scenario::Ramp, &cfg).unwrap();
        let svg = response_chart(&r).to_svg().unwrap();
        assert!(svg.contains("identified model"));
        assert!(svg.contains("simulation model") && svg.contains("measurement"));
        let svg = error_chart(&r).to_svg().unwrap();
        assert!(svg.contains("simulation model error"));
    }
}
