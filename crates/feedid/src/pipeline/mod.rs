//! One identification of a recording, end to end — what `feedid identify`
//! does, as a library call: choose the orders from the data if asked, slide
//! the method's estimator over the recording and predict, simulate the
//! nominal physical model next to it (the paper's third curve), fit the
//! method's global model, analyse the residuals, and summarise.
//!
//! ```
//! use feedid::pipeline::Pipeline;
//! use feedid::drive::RigParams;
//! use feedid::Recording;
//! let t: Vec<f64> = (0..400).map(|k| k as f64 * 2e-4).collect();
//! let u: Vec<f64> = t.iter().map(|&t| 0.05 * (t - 0.01).max(0.0)).collect();
//! let y: Vec<f64> = (0..400).map(|k| if k >= 3 { u[k - 3] } else { 0.0 }).collect();
//! let rec = Recording::new(t, u, y).unwrap();
//! let run = Pipeline::new("arx".parse().unwrap())
//!     .window(100)
//!     .nominal(RigParams::default())
//!     .run(&rec)
//!     .unwrap();
//! let s = run.summary();
//! assert_eq!((s.method.as_str(), s.window), ("arx", 100));
//! assert!(s.samples_predicted > 0);
//! assert!(s.to_string().contains("samples at 5000.00 Hz, method arx"));
//! assert!(serde_json::to_string(&s).unwrap().contains("\"rms_error_m\""));
//! ```
//!
//! Every method on one recording, compared on the same samples:
//! [`Comparison::run`] (what `feedid report` draws).
//!
//! Many recordings: [`Pipeline::run_many`] (or [`Pipeline::run_each`] for a
//! caller that reads and writes each in the same task) on all cores, results
//! in input order, one failure per recording.
//!
//! Everything here is `Send` and free of command-line types; a binding can
//! call [`Pipeline::run_slices`] with three `&[f64]`. Prediction intervals
//! (per-sample lower and upper bounds) belong next to the predictions in
//! [`crate::ident::SlidingResult`] and their coverage in
//! [`IdentifySummary`]; warnings found on the way are in
//! [`Identification::warnings`].

mod builder;
mod compare;
mod many;
mod run;
mod summary;
mod warning;

pub use builder::{Pipeline, DIVERGED_SPAN};
pub use compare::{CompareOptions, Comparison, GlobalModel, MethodRun, MIN_ZOOM_SAMPLES};
pub use run::{Identification, OrderChoice};
pub use summary::{IdentifySummary, RegimeInterval};
pub use warning::Warning;
