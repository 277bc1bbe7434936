//! Everything the report shows about one recording: the sliding
//! identification of every chosen method, the nominal simulation model,
//! residual analysis, global models fitted over the whole recording, and the
//! figures and tables built from them.
//!
//! Quantities (y measured, ŷ predicted, u command, all in metres):
//!
//! ```text
//! prediction error      e[k] = y[k] − ŷ[k]                (samples with a prediction)
//! error per horizon     rms of e over each window's horizon of H samples
//! normalised coefficient c_i(w) / median_w |c_i(w)|       (steady → flat line at ±1)
//! residual correlations r_ee(τ), r_ue(τ) with the 99 % band ±2.58/√N   (see ResidualAnalysis)
//! Bode                  |G(j2πf)| in dB and arg G in degrees; discrete models at z = e^{j2πfΔt}
//! ```
//!
//! Each method runs through the library's identification pipeline
//! ([`feedid::pipeline::Pipeline`]). Global models: ARX (orders of the
//! `arx`/`rls` method if chosen, else 8,8,1) and a continuous-time
//! output-error model (3 poles, 1 zero, or the `oe` method's orders), both by
//! the library's one global-model path ([`feedid::ident::fit_global_model`],
//! over at most the first [`feedid::ident::GLOBAL_FIT_SAMPLES`] samples);
//! their free-run simulation fit is tabulated. A fit that fails is reported
//! in the text, not as an error.
//!
//! ```
//! use feedid::ident::{EngineConfig, Method};
//! use feedid_report::{recording_report, RecordingAnalysis, ReportOptions};
//! use feedid::Recording;
//! let t: Vec<f64> = (0..400).map(|k| k as f64 * 2e-4).collect();
//! let u: Vec<f64> = t.iter().map(|&t| if t > 0.01 { 0.05 * (t - 0.01) } else { 0.0 }).collect();
//! let y: Vec<f64> = (0..400).map(|k| if k > 5 { u[k - 5] } else { 0.0 }).collect();
//! let rec = Recording::new(t, u, y).unwrap();
//! let opts = ReportOptions::new(vec![(
//!     "paper".parse::<Method>().unwrap(),
//!     EngineConfig::default(),
//! )]);
//! let a = RecordingAnalysis::run("ramp.csv", rec, &opts).unwrap();
//! let page = recording_report(&a).unwrap();
//! assert!(page.to_html().contains("id=\"rec-response-zoom\""));
//! ```

mod analysis;
mod diagnostics;
mod figures;
#[cfg(test)]
mod tests;

pub use analysis::{recording_report, GlobalModel, MethodRun, RecordingAnalysis, ReportOptions};
