//! Many recordings through one pipeline, one recording per task on all cores
//! (rayon). Each task runs the single-threaded identification of
//! [`Pipeline::run`], so the results equal those of a sequential loop (only
//! the measured [`SlidingResult::elapsed`](crate::ident::SlidingResult::elapsed)
//! differs); a recording that fails is reported in its place and the others
//! go on.

use rayon::prelude::*;

use crate::error::Result;
use crate::pipeline::{Identification, Pipeline};
use crate::recording::Recording;

impl Pipeline<'_> {
    /// Identify every recording, in parallel; the results in the order of
    /// `recordings`, each recording's own error in its place.
    ///
    /// ```
    /// use feedid::pipeline::Pipeline;
    /// use feedid::Recording;
    /// let t: Vec<f64> = (0..400).map(|k| k as f64 * 2e-4).collect();
    /// let u: Vec<f64> = t.iter().map(|&t| 0.05 * (t - 0.01).max(0.0)).collect();
    /// let y: Vec<f64> = (0..400).map(|k| if k >= 3 { u[k - 3] } else { 0.0 }).collect();
    /// let rec = Recording::new(t, u, y).unwrap();
    /// let short = Recording::new(vec![0.0, 1e-3], vec![0.0; 2], vec![0.0; 2]).unwrap();
    /// let runs = Pipeline::new("arx".parse().unwrap())
    ///     .window(100)
    ///     .run_many(&[rec.clone(), short, rec]);
    /// assert_eq!(runs.len(), 3);
    /// assert!(runs[0].is_ok() && runs[1].is_err() && runs[2].is_ok());
    /// ```
    pub fn run_many<S>(&self, recordings: &[Recording<S>]) -> Vec<Result<Identification>>
    where
        S: AsRef<[f64]> + Sync,
    {
        self.run_each(recordings, |pipeline, recording| pipeline.run(recording))
    }

    /// `each(self, input)` for every input, in parallel; the results in the
    /// order of `inputs`. For a caller that reads, identifies and writes a
    /// recording in one task (`feedid identify --out-dir`), so that one
    /// recording per core is in memory at a time; `each` reports its own
    /// failure in its result, and the other inputs go on.
    pub fn run_each<I, T, F>(&self, inputs: &[I], each: F) -> Vec<T>
    where
        I: Sync,
        T: Send,
        F: Fn(&Self, &I) -> T + Sync,
    {
        inputs.par_iter().map(|input| each(self, input)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{RigParams, VirtualRig};
    use crate::signal::Scenario;

    /// Seeded rig recordings of four commands, and one too short to identify.
    fn recordings() -> Vec<Recording> {
        let rate = 5000.0;
        let mut all: Vec<Recording> = [
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
        let first = &all[0];
        let short = Recording::new(
            first.time()[..10].to_vec(),
            first.command()[..10].to_vec(),
            first.position()[..10].to_vec(),
        )
        .unwrap();
        all.insert(2, short);
        all
    }

    /// The summary as JSON without the measured times.
    fn summary_json(run: &Identification) -> String {
        let mut s = run.summary();
        s.identification_seconds = 0.0;
        s.per_window_us = 0.0;
        serde_json::to_string(&s).unwrap()
    }

    #[test]
    fn run_many_equals_running_each_alone() {
        let all = recordings();
        for method in ["paper", "arx"] {
            let pipeline = Pipeline::new(method.parse().unwrap()).nominal(RigParams::default());
            let many = pipeline.run_many(&all);
            assert_eq!(many.len(), all.len());
            for (rec, m) in all.iter().zip(&many) {
                match (pipeline.run(rec), m) {
                    (Ok(a), Ok(m)) => {
                        assert!(!a.sliding.windows.is_empty());
                        assert_eq!(a.sliding.predicted, m.sliding.predicted);
                        assert_eq!(a.sliding.has_prediction, m.sliding.has_prediction);
                        assert_eq!(a.sliding.coefficients, m.sliding.coefficients);
                        assert_eq!(a.sliding.windows, m.sliding.windows);
                        assert_eq!(a.simulated, m.simulated);
                        assert_eq!(a.warnings, m.warnings);
                        assert_eq!(summary_json(&a), summary_json(m));
                    }
                    (Err(a), Err(m)) => assert_eq!(a.to_string(), m.to_string()),
                    (a, m) => panic!("alone {:?} vs many {:?}", a.is_ok(), m.is_ok()),
                }
            }
            // the too-short recording fails in its place, the others succeed
            let failed: Vec<usize> = (0..many.len()).filter(|&i| many[i].is_err()).collect();
            assert_eq!(failed, [2], "{method}");
        }
    }

    #[test]
    fn invalid_settings_fail_every_recording_on_its_own() {
        let all = recordings();
        let pipeline = Pipeline::new("arx".parse().unwrap()).horizon(0);
        let many = pipeline.run_many(&all[..2]);
        assert_eq!(many.len(), 2);
        assert!(many.iter().all(|r| r.is_err()));
    }

    #[test]
    fn run_each_keeps_the_order_of_the_inputs() {
        let pipeline = Pipeline::new("arx".parse().unwrap());
        let inputs: Vec<usize> = (0..64).collect();
        let out = pipeline.run_each(&inputs, |p, &i| (p.method().name(), i * i));
        assert_eq!(
            out,
            inputs.iter().map(|&i| ("arx", i * i)).collect::<Vec<_>>()
        );
    }
}
