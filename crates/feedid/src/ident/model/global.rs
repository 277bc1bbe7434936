//! A global model of a whole recording — what `feedid identify --model-out`
//! writes and `feedid compensate --model` reads — with where it came from.
//!
//! Kinds, independent of the sliding-window method:
//!
//! * `arx` ([`fit_arx`]): discrete `B(q)/A(q)` at the recording's sample time
//!   by least squares (orders `na,nb,nk`, default 8,8,1);
//! * `oe` ([`fit_oe`]): continuous `N(s)/D(s)` by output-error
//!   Levenberg–Marquardt (orders `poles,zeros`, default 7,2 — the cascade's
//!   structure, so that `feedid greybox --from-model` can map it to physical
//!   parameters);
//! * `auto` (the default): arx 8,8,1, oe 7,2 and oe 5,1 are all fitted and
//!   the one with the smallest free-run simulation error over the recording
//!   is kept. Equation-error ARX is biased at low frequencies by noise, and
//!   the output-error fit can stop in a poor local minimum; comparing the
//!   free-run error catches both. On the virtual rig this picks oe 7,2 for a
//!   PRBS or ramp recording, arx for a chirp or S-curve, oe 5,1 for a
//!   multisine.
//!
//! The file is JSON: `{"model": <LinearModel>, "identified_by": {...}}` with
//! the method, orders, samples, sample time and the free-run simulation fit
//! (NRMSE %, and the rms error in m) over the recording. A bare
//! [`LinearModel`] JSON is read as well.
//!
//! ```
//! use feedid::ident::{fit_global_model, GlobalModelKind, ModelFile};
//! use feedid::lti::TransferFunction;
//! let g = TransferFunction::new(vec![2.0e4], vec![1.0, 300.0, 2.0e4]).unwrap();
//! let dt = 1e-3;
//! let u: Vec<f64> = (0..800).map(|k| if (k / 50) % 2 == 1 { 1e-3 } else { 0.0 }).collect();
//! let y = g.to_state_space().unwrap().discretize_zoh(dt).unwrap().simulate(&u, None).unwrap();
//! let rec = feedid::Recording::from_rate(1000.0, u, y).unwrap();
//! let file = fit_global_model(&rec, &GlobalModelKind::Oe { poles: 2, zeros: 0 }).unwrap();
//! let back = ModelFile::from_json(&file.to_json()).unwrap();
//! let (a, b) = (back.model.dc_gain().unwrap(), file.model.dc_gain().unwrap());
//! assert!((a - b).abs() < 1e-12);
//! assert!(file.identified_by.unwrap().fit_percent > 99.99);
//! ```

use std::path::Path;
use std::str::FromStr;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::ident::{fit_arx, fit_oe, ArxConfig, ArxOrders, LinearModel, OeConfig};
use crate::recording::Recording;
use crate::stats::ErrorStats;

/// Which global model to fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GlobalModelKind {
    /// The best of arx 8,8,1, oe 7,2 and oe 5,1 by free-run simulation error.
    Auto,
    /// Discrete ARX with these orders.
    Arx(ArxOrders),
    /// Continuous output error with `poles` poles and `zeros` zeros.
    Oe {
        /// Number of poles.
        poles: usize,
        /// Number of zeros (< poles).
        zeros: usize,
    },
}

impl GlobalModelKind {
    /// The kind named `auto`, `arx` (orders 8,8,1) or `oe` (orders 7,2).
    pub fn default_for(name: &str) -> Result<Self> {
        match name.trim().to_ascii_lowercase().as_str() {
            "auto" => Ok(GlobalModelKind::Auto),
            "arx" => Ok(GlobalModelKind::Arx(ArxOrders::default())),
            "oe" => Ok(GlobalModelKind::Oe { poles: 7, zeros: 2 }),
            _ => Err(Error::InvalidChoice {
                what: "model kind",
                value: name.to_string(),
                expected: "auto, arx, oe",
            }),
        }
    }

    /// The candidates of [`GlobalModelKind::Auto`].
    pub const AUTO_CANDIDATES: [GlobalModelKind; 3] = [
        GlobalModelKind::Arx(ArxOrders::new(8, 8, 1)),
        GlobalModelKind::Oe { poles: 7, zeros: 2 },
        GlobalModelKind::Oe { poles: 5, zeros: 1 },
    ];

    /// The kind a run's summary fits for its free-run figure
    /// ([`crate::pipeline::Pipeline::method_global_model`]): [`GlobalModelKind::Auto`]
    /// becomes its least-squares candidate arx 8,8,1, every other kind is
    /// kept. The output-error candidates of `auto` cost seconds per 25 000
    /// samples (about 400× the sliding identification of the default
    /// method on EMPS), the ARX fit milliseconds; the full comparison stays
    /// what `feedid identify --model-out` asks for.
    pub fn for_summary(self) -> Self {
        match self {
            GlobalModelKind::Auto => Self::AUTO_CANDIDATES[0],
            other => other,
        }
    }

    /// A kind with orders `na,nb,nk` (arx) or `poles,zeros` (oe).
    pub fn with_orders(name: &str, orders: &str) -> Result<Self> {
        let bad = || Error::InvalidChoice {
            what: "model order",
            value: orders.to_string(),
            expected: "na,nb,nk for arx (e.g. 8,8,1); poles,zeros for oe (e.g. 7,2)",
        };
        let v: Vec<usize> = orders
            .split(',')
            .map(|x| x.trim().parse::<usize>().map_err(|_| bad()))
            .collect::<Result<_>>()?;
        match (Self::default_for(name)?, v.as_slice()) {
            (GlobalModelKind::Arx(_), [na, nb, nk]) => {
                let o = ArxOrders::new(*na, *nb, *nk);
                o.validate()?;
                Ok(GlobalModelKind::Arx(o))
            }
            (GlobalModelKind::Oe { .. }, [p, z]) => Ok(GlobalModelKind::Oe {
                poles: *p,
                zeros: *z,
            }),
            (GlobalModelKind::Auto, _) => Err(Error::InvalidChoice {
                what: "model order for kind auto",
                value: orders.to_string(),
                expected:
                    "no order (auto tries arx 8,8,1, oe 7,2, oe 5,1); name arx or oe to give one",
            }),
            _ => Err(bad()),
        }
    }

    /// Method name (`"auto"`, `"arx"`, `"oe"`).
    pub fn name(&self) -> &'static str {
        match self {
            GlobalModelKind::Auto => "auto",
            GlobalModelKind::Arx(_) => "arx",
            GlobalModelKind::Oe { .. } => "oe",
        }
    }

    /// Orders as written on the command line.
    pub fn orders(&self) -> String {
        match self {
            GlobalModelKind::Auto => String::new(),
            GlobalModelKind::Arx(o) => format!("{},{},{}", o.na, o.nb, o.nk),
            GlobalModelKind::Oe { poles, zeros } => format!("{poles},{zeros}"),
        }
    }
}

impl FromStr for GlobalModelKind {
    type Err = Error;

    fn from_str(s: &str) -> Result<Self> {
        Self::default_for(s)
    }
}

/// Where a model came from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelProvenance {
    /// `"arx"` or `"oe"`.
    pub method: String,
    /// Orders (`na,nb,nk` or `poles,zeros`).
    pub orders: String,
    /// Samples of the recording.
    pub samples: usize,
    /// Sample time of the recording \[s\].
    pub sample_time_s: f64,
    /// Free-run simulation fit over the recording \[%\] (NRMSE).
    pub fit_percent: f64,
    /// RMS of the free-run simulation error \[m\].
    pub simulation_rms_m: f64,
    /// The recording's file, if known.
    #[serde(default)]
    pub source: Option<String>,
    /// With `auto`: every candidate tried, `"method orders: simulation rms"` or its error.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub candidates: Vec<String>,
}

/// A model file: the model and its provenance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelFile {
    /// The identified model.
    pub model: LinearModel,
    /// How it was identified (absent for a bare model).
    #[serde(default)]
    pub identified_by: Option<ModelProvenance>,
}

impl ModelFile {
    /// Pretty JSON.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_default()
    }

    /// Parse `{"model": …, "identified_by": …}` or a bare model; the
    /// coefficients are checked.
    pub fn from_json(text: &str) -> Result<Self> {
        let value: serde_json::Value =
            serde_json::from_str(text).map_err(|e| Error::ParamsFile {
                path: None,
                message: format!("model JSON: {e}"),
            })?;
        let file: ModelFile = if value.get("model").is_some() {
            serde_json::from_value(value).map_err(|e| Error::ParamsFile {
                path: None,
                message: format!("model JSON: {e}"),
            })?
        } else {
            ModelFile {
                model: LinearModel::from_json(text)?,
                identified_by: None,
            }
        };
        let model =
            LinearModel::from_json(&serde_json::to_string(&file.model).unwrap_or_default())?;
        Ok(ModelFile { model, ..file })
    }

    /// Read a model file; errors name the file.
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_json_file(&text, path)
    }

    /// [`ModelFile::from_json`] of the text of the file `path`; errors name the file.
    pub fn from_json_file(text: &str, path: &Path) -> Result<Self> {
        Self::from_json(text).map_err(|e| match e {
            Error::ParamsFile { message, .. } => Error::ParamsFile {
                path: Some(path.to_path_buf()),
                message,
            },
            other => Error::InFile {
                path: path.to_path_buf(),
                location: String::new(),
                source: Box::new(other),
            },
        })
    }
}

/// Samples a global model is fitted on at most: the first 200 000 (40 s at
/// 5 kHz, 200 s at 1 kHz). The one cap of every global fit (the summary's
/// free-run fit, `--model-out`, the report's Bode figure): the output-error
/// fits of a whole hour at 5 kHz would take minutes. The free-run fit is
/// reported over the same samples, and [`ModelProvenance::samples`] says
/// how many.
pub const GLOBAL_FIT_SAMPLES: usize = 200_000;

/// Fit a global model of `kind` to the recording (its first
/// [`GLOBAL_FIT_SAMPLES`] samples at most): the one path of every global
/// model.
///
/// Errors: a recording with gaps of dropped samples (a free-run fit needs
/// uniform sampling: fit one segment, [`Recording::slice`]); those of
/// [`fit_arx`] / [`fit_oe`] (too few samples, no excitation, no stable
/// model); with `auto`, the last candidate's error when none succeeds.
///
/// With `auto` the three kinds are fitted in parallel (rayon's pool) and
/// compared in a fixed order, so the result does not depend on the threads.
pub fn fit_global_model<S: AsRef<[f64]>>(
    rec: &Recording<S>,
    kind: &GlobalModelKind,
) -> Result<ModelFile> {
    rec.require_uniform()?;
    if rec.len() <= GLOBAL_FIT_SAMPLES {
        return fit_kind(rec, kind);
    }
    fit_kind(&rec.head(GLOBAL_FIT_SAMPLES)?, kind)
}

/// [`fit_global_model`] without the cap.
fn fit_kind<S: AsRef<[f64]>>(rec: &Recording<S>, kind: &GlobalModelKind) -> Result<ModelFile> {
    fit_data((rec.command(), rec.position(), rec.dt()), kind)
}

/// Command, position \[m\] and sample time \[s\] of the fitted samples.
type Data<'a> = (&'a [f64], &'a [f64], f64);

/// [`fit_kind`] on the fitted samples.
fn fit_data(data: Data<'_>, kind: &GlobalModelKind) -> Result<ModelFile> {
    if *kind != GlobalModelKind::Auto {
        return fit_one(data, kind);
    }
    let mut best: Option<ModelFile> = None;
    let mut notes = Vec::new();
    let mut last_err = None;
    // independent fits, in parallel; compared in order (the sequential result)
    let fits: Vec<Result<ModelFile>> = GlobalModelKind::AUTO_CANDIDATES
        .par_iter()
        .map(|cand| fit_one(data, cand))
        .collect();
    for (cand, fit) in GlobalModelKind::AUTO_CANDIDATES.into_iter().zip(fits) {
        match fit {
            Ok(f) => {
                let rms = f
                    .identified_by
                    .as_ref()
                    .map_or(f64::INFINITY, |p| p.simulation_rms_m);
                notes.push(format!(
                    "{} {}: simulation rms {:.4e} m",
                    cand.name(),
                    cand.orders(),
                    rms
                ));
                let better = match best.as_ref() {
                    None => true,
                    Some(b) => {
                        rms < b
                            .identified_by
                            .as_ref()
                            .map_or(f64::INFINITY, |p| p.simulation_rms_m)
                    }
                };
                if rms.is_finite() && better {
                    best = Some(f);
                }
            }
            Err(e) => {
                notes.push(format!("{} {}: {e}", cand.name(), cand.orders()));
                last_err = Some(e);
            }
        }
    }
    match best {
        Some(mut f) => {
            if let Some(p) = f.identified_by.as_mut() {
                p.candidates = notes;
            }
            Ok(f)
        }
        None => Err(last_err.unwrap_or(Error::InvalidModel {
            reason: "no global model could be fitted",
        })),
    }
}

/// One kind (not `Auto`) fitted to command `u`, position `y` \[m\] at the
/// sample time `dt` \[s\].
fn fit_one(data: Data<'_>, kind: &GlobalModelKind) -> Result<ModelFile> {
    let (u, y, dt) = data;
    let model = match kind {
        GlobalModelKind::Arx(orders) => fit_arx(u, y, dt, *orders, &ArxConfig::default())?.model,
        GlobalModelKind::Oe { poles, zeros } => {
            let cfg = OeConfig {
                poles: *poles,
                zeros: *zeros,
                ..OeConfig::default()
            };
            fit_oe(u, y, dt, &cfg)?.model
        }
        GlobalModelKind::Auto => return fit_data(data, kind),
    };
    let sim = model.simulate_at(u, dt)?;
    let stats = ErrorStats::from_pairs(y.iter().copied().zip(sim.iter().copied()));
    if !(stats.rms.is_finite()) {
        return Err(Error::InvalidModel {
            reason: "the global model's simulation is not finite",
        });
    }
    Ok(ModelFile {
        model,
        identified_by: Some(ModelProvenance {
            method: kind.name().to_string(),
            orders: kind.orders(),
            samples: u.len(),
            sample_time_s: dt,
            fit_percent: stats.fit_percent,
            simulation_rms_m: stats.rms,
            source: None,
            candidates: Vec::new(),
        }),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{simulate_nominal, RigParams};
    use crate::signal::Scenario;

    #[test]
    fn arx_of_the_linear_rig_simulates_it_closely() {
        let u = Scenario::Prbs.command(5000.0, 1.1, 1).unwrap();
        let y = simulate_nominal(&RigParams::default(), &u, 2e-4).unwrap();
        let rec = Recording::from_rate(5000.0, u, y).unwrap();
        let f = fit_global_model(&rec, &GlobalModelKind::default_for("arx").unwrap()).unwrap();
        let p = f.identified_by.as_ref().unwrap();
        assert_eq!(p.method, "arx");
        assert_eq!(p.orders, "8,8,1");
        assert!(p.fit_percent > 99.9, "{}", p.fit_percent);
        assert_eq!(f.model.dt(), Some(2e-4));
    }

    #[test]
    fn auto_keeps_the_candidate_with_the_smallest_simulation_error() {
        let u = Scenario::Prbs.command(5000.0, 0.6, 1).unwrap();
        let y = simulate_nominal(&RigParams::default(), &u, 2e-4).unwrap();
        let rec = Recording::from_rate(5000.0, u, y).unwrap();
        let f = fit_global_model(&rec, &GlobalModelKind::Auto).unwrap();
        let p = f.identified_by.unwrap();
        assert_eq!(p.candidates.len(), 3);
        for cand in GlobalModelKind::AUTO_CANDIDATES {
            if let Ok(c) = fit_global_model(&rec, &cand) {
                assert!(p.simulation_rms_m <= c.identified_by.unwrap().simulation_rms_m);
            }
        }
    }

    #[test]
    fn the_summary_fits_the_least_squares_candidate_of_auto_and_keeps_other_kinds() {
        assert_eq!(
            GlobalModelKind::Auto.for_summary(),
            GlobalModelKind::Arx(ArxOrders::new(8, 8, 1))
        );
        for k in [
            GlobalModelKind::Arx(ArxOrders::new(3, 2, 0)),
            GlobalModelKind::Oe { poles: 5, zeros: 1 },
        ] {
            assert_eq!(k.for_summary(), k);
        }
    }

    #[test]
    fn the_fit_covers_the_first_samples_only_and_says_how_many() {
        let u = Scenario::Prbs.command(5000.0, 0.2, 1).unwrap();
        let y = simulate_nominal(&RigParams::default(), &u, 2e-4).unwrap();
        let rec = Recording::from_rate(5000.0, u, y).unwrap();
        let kind = GlobalModelKind::Arx(ArxOrders::new(4, 4, 1));
        let whole = fit_global_model(&rec, &kind).unwrap();
        assert_eq!(whole.identified_by.as_ref().unwrap().samples, rec.len());
        // deterministic: the same recording gives the same model
        assert_eq!(fit_global_model(&rec, &kind).unwrap(), whole);
        // the cap is the head of the recording: a longer one fitted past
        // GLOBAL_FIT_SAMPLES is the fit of its first GLOBAL_FIT_SAMPLES
        let n = GLOBAL_FIT_SAMPLES + 1000;
        let u: Vec<f64> = (0..n).map(|k| rec.command()[k % rec.len()]).collect();
        let y: Vec<f64> = (0..n).map(|k| rec.position()[k % rec.len()]).collect();
        let long = Recording::from_rate(5000.0, u, y).unwrap();
        let capped = fit_global_model(&long, &kind).unwrap();
        let h = long.head(GLOBAL_FIT_SAMPLES).unwrap();
        let head = fit_one((h.command(), h.position(), h.dt()), &kind).unwrap();
        assert_eq!(capped, head);
        assert_eq!(capped.identified_by.unwrap().samples, GLOBAL_FIT_SAMPLES);
    }

    #[test]
    fn orders_parse_per_kind_and_bad_ones_are_named() {
        assert_eq!(
            GlobalModelKind::with_orders("oe", "5,1").unwrap(),
            GlobalModelKind::Oe { poles: 5, zeros: 1 }
        );
        assert_eq!(
            GlobalModelKind::with_orders("arx", "4,4,1").unwrap(),
            GlobalModelKind::Arx(ArxOrders::new(4, 4, 1))
        );
        let e = GlobalModelKind::with_orders("oe", "5,1,1")
            .unwrap_err()
            .to_string();
        assert!(e.contains("5,1,1"), "{e}");
        let e = GlobalModelKind::default_for("narx")
            .unwrap_err()
            .to_string();
        assert!(e.contains("narx") && e.contains("auto, arx, oe"), "{e}");
        assert!(GlobalModelKind::with_orders("auto", "7,2").is_err());
    }

    #[test]
    fn bare_models_and_wrapped_ones_are_read_and_bad_json_is_refused() {
        let m = LinearModel::discrete(vec![0.0, 0.5], vec![1.0, -0.5], 2e-4).unwrap();
        let bare = ModelFile::from_json(&m.to_json()).unwrap();
        assert_eq!(bare.model, m);
        assert!(bare.identified_by.is_none());
        let e = ModelFile::from_json("{\"model\": {\"kind\": \"discrete\", \"b\": [1.0]}}")
            .unwrap_err()
            .to_string();
        assert!(e.contains("model JSON"), "{e}");
        let e = ModelFile::from_json(
            "{\"model\": {\"kind\": \"discrete\", \"b\": [1.0], \"a\": [0.0], \"dt\": 1e-3}}",
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("a[0]"), "{e}");
    }
}
