//! Batch identification of many recordings at once, one recording per task
//! on all cores (rayon). Each task builds its own estimator and runs the
//! single-threaded engine ([`crate::ident::engine::run`]) on its recording,
//! so the results equal those of a sequential loop (only the measured
//! [`SlidingResult::elapsed`] differs).

use rayon::prelude::*;

use crate::error::Result;
use crate::ident::engine::{run, EngineConfig, SlidingResult};
use crate::ident::Estimator;
use crate::Recording;

/// Identify every recording with a fresh estimator from `make_estimator`,
/// in parallel; results in the order of `recordings`.
///
/// ```
/// use feedid::ident::{batch::identify_many, EngineConfig, PaperConfig};
/// use feedid::Recording;
/// let t: Vec<f64> = (0..100).map(|k| k as f64 * 2e-4).collect();
/// let u: Vec<f64> = t.iter().map(|&t| 0.05 * t).collect();
/// let y: Vec<f64> = t.iter().map(|&t| 1e3 * t.powi(5)).collect();
/// let rec = Recording::new(t, u, y).unwrap();
/// let results = identify_many(&[rec.clone(), rec], || PaperConfig::default().build(), &EngineConfig::default());
/// assert_eq!(results.len(), 2);
/// assert!(results.iter().all(|r| r.is_ok()));
/// ```
pub fn identify_many<E, F>(
    recordings: &[Recording],
    make_estimator: F,
    config: &EngineConfig,
) -> Vec<Result<SlidingResult>>
where
    E: Estimator,
    F: Fn() -> Result<E> + Sync,
{
    recordings
        .par_iter()
        .map(|rec| {
            let mut est = make_estimator()?;
            run(&mut est, &rec.signals(), config)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{RigParams, VirtualRig};
    use crate::ident::{PaperConfig, Solver};
    use crate::signal::Scenario;

    #[test]
    fn parallel_results_equal_sequential_results() {
        let rate = 5000.0;
        let recs: Vec<Recording> = [
            Scenario::Ramp,
            Scenario::Step,
            Scenario::Scurve,
            Scenario::Prbs,
        ]
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let c = s.command(rate, 0.1, 1).unwrap();
            let o = VirtualRig::new(RigParams::default())
                .with_seed(i as u64)
                .simulate(&c, rate)
                .unwrap();
            Recording::new(o.time, o.command, o.position).unwrap()
        })
        .collect();
        let mut short = recs[0].clone();
        short = Recording::new(
            short.time()[..10].to_vec(),
            short.command()[..10].to_vec(),
            short.position()[..10].to_vec(),
        )
        .unwrap();
        let mut all = recs;
        all.push(short);
        let cfg = EngineConfig::default();
        let make = || {
            PaperConfig {
                solver: Solver::Qr,
                ..PaperConfig::default()
            }
            .build()
        };
        let par = identify_many(&all, make, &cfg);
        assert_eq!(par.len(), all.len());
        for (rec, p) in all.iter().zip(&par) {
            match (run(&mut make().unwrap(), &rec.signals(), &cfg), p) {
                (Ok(s), Ok(p)) => {
                    assert!(!s.windows.is_empty());
                    assert_eq!(s.predicted, p.predicted);
                    assert_eq!(s.has_prediction, p.has_prediction);
                    assert_eq!(s.coefficients, p.coefficients);
                    assert_eq!(s.windows, p.windows);
                    assert_eq!(s.stats, p.stats);
                }
                (Err(s), Err(p)) => assert_eq!(s.to_string(), p.to_string()),
                (s, p) => panic!("sequential {:?} vs parallel {:?}", s.is_ok(), p.is_ok()),
            }
        }
        // the too-short recording fails on its own, the others succeed
        assert_eq!(par.iter().filter(|r| r.is_err()).count(), 1);
        // a failing estimator factory is reported per recording
        let bad = identify_many(
            &all[..2],
            || {
                PaperConfig {
                    simplex: crate::ident::SimplexSettings {
                        step_rel: -1.0,
                        ..Default::default()
                    },
                    ..PaperConfig::default()
                }
                .build()
            },
            &cfg,
        );
        assert!(bad.iter().all(|r| r.is_err()));
    }
}
