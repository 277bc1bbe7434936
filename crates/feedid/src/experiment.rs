//! The paper's two experiments end to end on the virtual rig (what
//! `feedid reproduce` runs): a ramp of 30 mm at 50 mm/s and a 1 mm step in
//! 0.2 ms, sampled at 5 kHz, identified with the paper's method (W = 20,
//! H = 10) and compared with the nominal simulation model — the counterparts
//! of the paper's figures 5–8 and its error figures.
//!
//! Paper's reported values (measured axis): ramp ≈ 40 µm error of the LSM
//! model vs ≈ 80 µm of the simulation model; step up to 0.15 mm (LSM) at the
//! start of motion.

use std::fmt::Write as _;

use crate::drive::{RigEffects, RigParams, VirtualRig};
use crate::error::Result;
use crate::ident::{EngineConfig, Method, PaperConfig, Solver};
use crate::pipeline::{Identification, Pipeline};
use crate::recording::Recording;
use crate::signal::Scenario;
use crate::stats::ErrorStats;

/// Settings of the paper experiments.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PaperExperimentConfig {
    /// Rig parameters (measured axis and nominal model alike); default: the default rig.
    pub params: RigParams,
    /// Nonlinear effects of the virtual rig; default: all on.
    pub effects: RigEffects,
    /// Noise seed; default 1.
    pub seed: u64,
    /// Sampling rate \[Hz\]; default 5000 (paper).
    pub rate_hz: f64,
    /// Window and horizon; default W = 20, H = 10 (paper).
    pub engine: EngineConfig,
    /// Solver used for the figures; default simplex (paper). Both are tabulated.
    pub solver: Solver,
    /// Zoom of the response figures after the motion start \[s\]; default 0.06 (paper).
    pub zoom: f64,
}

impl Default for PaperExperimentConfig {
    fn default() -> Self {
        Self {
            params: RigParams::default(),
            effects: RigEffects::default(),
            seed: 1,
            rate_hz: 5000.0,
            engine: EngineConfig::default(),
            solver: Solver::Simplex,
            zoom: 0.06,
        }
    }
}

/// Error statistics of one curve against the measurement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurveErrors {
    /// Over the whole recording (predicted samples).
    pub whole: ErrorStats,
    /// Over the zoom window after the motion start.
    pub zoom: ErrorStats,
    /// After the zoom window (the settled part of the move).
    pub after: ErrorStats,
}

/// One experiment (ramp or step).
#[derive(Debug, Clone)]
pub struct ExperimentResult {
    /// Scenario name.
    pub name: &'static str,
    /// The virtual rig's "measurement".
    pub recording: Recording,
    /// The identification with the figure solver (predictions and nominal simulation).
    pub identification: Identification,
    /// Errors of the paper method with QR.
    pub qr: CurveErrors,
    /// Errors of the paper method with the simplex.
    pub simplex: CurveErrors,
    /// Errors of the nominal simulation model.
    pub simulation: CurveErrors,
    /// Mean time per window with QR \[µs\].
    pub qr_us: f64,
    /// Mean time per window with the simplex \[µs\].
    pub simplex_us: f64,
    /// Motion start \[s\].
    pub motion_start: f64,
    /// Zoom length \[s\].
    pub zoom: f64,
    /// Solver of [`ExperimentResult::identification`].
    pub solver: Solver,
}

/// Duration of each experiment \[s\]: the ramp's full 30 mm move and settling, 0.1 s after the step.
fn duration(s: Scenario) -> f64 {
    match s {
        Scenario::Ramp => 0.7,
        _ => 0.1,
    }
}

/// Run one experiment (`Scenario::Ramp` or `Scenario::Step`, or any other scenario).
pub fn run_experiment(scenario: Scenario, cfg: &PaperExperimentConfig) -> Result<ExperimentResult> {
    let command = scenario.command(cfg.rate_hz, duration(scenario), cfg.seed)?;
    let rig = VirtualRig::new(cfg.params)
        .with_effects(cfg.effects)
        .with_seed(cfg.seed);
    let out = rig.simulate(&command, cfg.rate_hz)?;
    let recording = Recording::new(out.time, out.command, out.position)?;
    let motion_start = recording.motion_start_time();
    let in_zoom = |t: f64| t >= motion_start && t <= motion_start + cfg.zoom;

    let mut runs = Vec::with_capacity(2);
    for solver in [Solver::Qr, Solver::Simplex] {
        let method = Method::Paper(PaperConfig {
            solver,
            ..PaperConfig::default()
        });
        runs.push(
            Pipeline::new(method)
                .engine(cfg.engine)
                .method_global_model(false)
                .nominal(cfg.params)
                .run(&recording)?,
        );
    }
    let errors = |id: &Identification, curve: &dyn Fn(usize) -> Option<f64>| {
        let y = recording.position();
        let t = recording.time();
        let pairs = |keep: &dyn Fn(f64) -> bool| {
            (0..y.len())
                .filter(|&k| id.sliding.has_prediction[k] && keep(t[k]))
                .filter_map(|k| curve(k).map(|v| (y[k], v)))
                .collect::<Vec<_>>()
        };
        CurveErrors {
            whole: ErrorStats::from_pairs(pairs(&|_| true)),
            zoom: ErrorStats::from_pairs(pairs(&in_zoom)),
            after: ErrorStats::from_pairs(pairs(&|tk| tk > motion_start + cfg.zoom)),
        }
    };
    let qr = errors(&runs[0], &|k| runs[0].sliding.prediction(k));
    let simplex = errors(&runs[1], &|k| runs[1].sliding.prediction(k));
    let simulation = errors(&runs[0], &|k| {
        runs[0].simulated.as_ref().and_then(|s| s.get(k).copied())
    });
    let qr_us = runs[0].sliding.per_window_us();
    let simplex_us = runs[1].sliding.per_window_us();
    let identification = match cfg.solver {
        Solver::Qr => runs.swap_remove(0),
        Solver::Simplex => runs.swap_remove(1),
    };
    Ok(ExperimentResult {
        name: scenario.name(),
        recording,
        identification,
        qr,
        simplex,
        simulation,
        qr_us,
        simplex_us,
        motion_start,
        zoom: cfg.zoom,
        solver: cfg.solver,
    })
}

impl ExperimentResult {
    /// Indices of the samples in the zoom window after the motion start.
    pub fn zoom_indices(&self) -> Vec<usize> {
        let t = self.recording.time();
        (0..t.len())
            .filter(|&k| t[k] >= self.motion_start && t[k] <= self.motion_start + self.zoom)
            .collect()
    }
}

/// The error table of the experiments as Markdown, with the paper's values.
pub fn summary_markdown(results: &[ExperimentResult], cfg: &PaperExperimentConfig) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# feedid reproduce — the paper's experiments on the virtual rig\n"
    );
    let _ = writeln!(
        s,
        "Virtual rig: default rig of the design notes, every nonlinear effect {} \
         (friction, position-dependent stiffness, current/voltage limits, sampled \
         position loop, 0.1 µm encoder, 0.2 µm noise), seed {}. Sampling {} Hz, \
         window W = {} samples ({:.1} ms), horizon H = {} ({:.1} ms), hop {}.\n",
        if cfg.effects == RigEffects::default() {
            "on"
        } else {
            "as configured"
        },
        cfg.seed,
        cfg.rate_hz,
        cfg.engine.window,
        1e3 * cfg.engine.window as f64 / cfg.rate_hz,
        cfg.engine.horizon,
        1e3 * cfg.engine.horizon as f64 / cfg.rate_hz,
        cfg.engine.hop()
    );
    let _ = writeln!(
        s,
        "Errors are measurement − model over every predicted sample (whole move), \
         over the first {z:.0} ms after the motion start (the paper's figures) and \
         after them (the settled part).\n",
        z = 1e3 * cfg.zoom
    );
    let _ = writeln!(
        s,
        "| experiment | model | rms whole [µm] | max whole [µm] | rms first {z:.0} ms [µm] | max first {z:.0} ms [µm] | rms after {z:.0} ms [µm] | per window [µs] |",
        z = 1e3 * cfg.zoom
    );
    let _ = writeln!(s, "|---|---|---:|---:|---:|---:|---:|---:|");
    for r in results {
        for (label, e, us) in [
            ("paper LSM, QR", &r.qr, Some(r.qr_us)),
            ("paper LSM, simplex", &r.simplex, Some(r.simplex_us)),
            ("simulation model", &r.simulation, None),
        ] {
            let _ = writeln!(
                s,
                "| {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {} |",
                r.name,
                label,
                1e6 * e.whole.rms,
                1e6 * e.whole.max_abs,
                1e6 * e.zoom.rms,
                1e6 * e.zoom.max_abs,
                1e6 * e.after.rms,
                us.map_or("–".to_string(), |v| format!("{v:.2}"))
            );
        }
    }
    let _ = writeln!(
        s,
        "\nPaper (measured axis): ramp — LSM error about 40 µm, simulation model about \
         80 µm; step — LSM error up to 0.15 mm at the start of motion, decreasing with time."
    );
    let _ = writeln!(
        s,
        "\nFigures: `ramp_response.svg`, `ramp_error.svg` (paper figures 5, 6), \
         `step_response.svg`, `step_error.svg` (figures 7, 8)."
    );
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ramp_experiment_runs_and_prediction_beats_nothing() {
        let cfg = PaperExperimentConfig {
            solver: Solver::Qr,
            ..Default::default()
        };
        let r = run_experiment(Scenario::Ramp, &cfg).unwrap();
        assert!(r.qr.whole.samples > 3000);
        assert!(r.qr.whole.rms.is_finite());
        // the nominal model on the nonlinear rig is off by tens of µm at most
        assert!(r.simulation.whole.rms < 50e-6, "{:?}", r.simulation);
        let md = summary_markdown(&[r], &cfg);
        assert!(md.contains("| ramp | paper LSM, QR |"));
    }
}
