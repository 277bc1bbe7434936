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
use crate::ident::methods::{
    fit_arx, fit_arx_segments, fit_oe, fit_oe_measured, ArxConfig, ArxOrders, OeConfig,
};
use crate::ident::model::{LinearModel, NEGLIGIBLE_PAIR};
use crate::recording::Recording;
use crate::stats::{error_fit_percent, noise_level_of_run, ErrorStats};

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
    /// Samples of the recording fitted (measured ones).
    pub samples: usize,
    /// Samples dropped in the gaps of the fitted part (the model was
    /// simulated through them and not compared there); 0 without gaps.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub missing_samples: usize,
    /// Pole–zero pairs of the fit cancelled because they change nothing
    /// over the recording ([`LinearModel::without_negligible_pairs`]); 0
    /// when none.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub cancelled_pairs: usize,
    /// Sample time of the recording \[s\].
    pub sample_time_s: f64,
    /// Free-run simulation fit over the recording \[%\] (NRMSE).
    pub fit_percent: f64,
    /// RMS of the free-run simulation error \[m\].
    pub simulation_rms_m: f64,
    /// Share of the recording's following error `y − u` the free-run model
    /// explains, measurement noise excluded
    /// ([`crate::stats::error_fit_percent`]) \[%\]; what `feedid
    /// compensate` expects the model to leave without `--check`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error_fit_percent: Option<f64>,
    /// The recording's file, if known.
    #[serde(default)]
    pub source: Option<String>,
    /// With `auto`: every candidate tried, `"method orders: simulation rms"` or its error.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub candidates: Vec<String>,
}

/// Whether a count is zero (serde: written only when not).
fn is_zero(n: &usize) -> bool {
    *n == 0
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
/// A recording with gaps of dropped samples is fitted whole: ARX on the
/// rows of every segment between the gaps ([`fit_arx_segments`]: no row
/// pairs samples across a gap), output error and every free-run
/// simulation on the regular time grid through the gaps, the command
/// interpolated where samples were dropped, compared with the measured
/// samples only ([`fit_oe_measured`]); [`ModelProvenance::samples`] counts
/// the measured samples and [`ModelProvenance::missing_samples`] the
/// dropped ones.
///
/// Errors: those of [`fit_arx`] / [`fit_oe`] (too few samples, no
/// excitation, no stable model); with `auto`, the last candidate's error
/// when none succeeds.
///
/// With `auto` the three kinds are fitted in parallel (rayon's pool) and
/// compared in a fixed order, so the result does not depend on the threads.
pub fn fit_global_model<S: AsRef<[f64]>>(
    rec: &Recording<S>,
    kind: &GlobalModelKind,
) -> Result<ModelFile> {
    if rec.len() <= GLOBAL_FIT_SAMPLES {
        return fit_kind(rec, kind);
    }
    fit_kind(&rec.head(GLOBAL_FIT_SAMPLES)?, kind)
}

/// [`fit_global_model`] without the cap.
fn fit_kind<S: AsRef<[f64]>>(rec: &Recording<S>, kind: &GlobalModelKind) -> Result<ModelFile> {
    let d = Deviations::of(rec)?;
    fit_data(&d.data(rec), kind)
}

/// Command and position in deviations from the first command sample (and
/// their grid through any gaps): a global model is fitted and simulated
/// from rest there, so an offset of the recording (machine coordinates far
/// from 0) changes nothing — as for the sliding methods.
struct Deviations {
    command: Vec<f64>,
    position: Vec<f64>,
    grid: Option<Grid>,
}

impl Deviations {
    fn of<S: AsRef<[f64]>>(rec: &Recording<S>) -> Result<Self> {
        let r = rec.command().first().copied().unwrap_or(0.0);
        let shift = |v: &[f64]| v.iter().map(|x| x - r).collect::<Vec<f64>>();
        let grid = Grid::of(rec)?.map(|g| Grid {
            command: shift(&g.command),
            position: shift(&g.position),
            measured: g.measured,
        });
        Ok(Self {
            command: shift(rec.command()),
            position: shift(rec.position()),
            grid,
        })
    }

    fn data<'a, S: AsRef<[f64]>>(&'a self, rec: &Recording<S>) -> Data<'a> {
        Data {
            command: &self.command,
            position: &self.position,
            dt: rec.dt(),
            segments: rec.segments(),
            grid: self.grid.as_ref(),
        }
    }
}

/// The free-run simulation error of `model` over the recording: simulated
/// from rest at the first command sample, on the regular time grid through
/// any gaps of dropped samples (the command interpolated there), and
/// compared with the measured samples only — as the global models are
/// scored ([`ModelProvenance::fit_percent`]).
///
/// ```
/// use feedid::ident::{simulation_error, LinearModel};
/// let m = LinearModel::discrete(vec![0.0, 0.2], vec![1.0, -0.8], 1e-3).unwrap();
/// let u: Vec<f64> = (0..500).map(|k| ((k / 50) % 2) as f64 * 1e-3).collect();
/// let y = m.simulate(&u).unwrap();
/// let rec = feedid::Recording::from_rate(1000.0, u, y).unwrap().dropping(&[120, 121]).unwrap();
/// let e = simulation_error(&m, &rec).unwrap();
/// assert_eq!(e.samples, 498);
/// assert!(e.rms < 1e-12);
/// ```
pub fn simulation_error<S: AsRef<[f64]>>(
    model: &LinearModel,
    rec: &Recording<S>,
) -> Result<ErrorStats> {
    let d = Deviations::of(rec)?;
    simulated(model, &d.data(rec))
}

/// The free-run simulation of `model` on the data's command (through the
/// gaps), compared with the measured position.
fn simulated(model: &LinearModel, data: &Data<'_>) -> Result<ErrorStats> {
    Ok(simulated_with_fit(model, data)?.0)
}

/// [`simulated`] and the share of the following error the model explains
/// (noise excluded, [`crate::stats::error_fit_percent`]).
fn simulated_with_fit(model: &LinearModel, data: &Data<'_>) -> Result<(ErrorStats, Option<f64>)> {
    let (y, u, dt) = (data.position, data.command, data.dt);
    let sim: Vec<f64> = match data.grid {
        None => model.simulate_at(u, dt)?,
        // through the gaps, compared where measured
        Some(g) => {
            let s = model.simulate_at(&g.command, dt)?;
            g.measured.iter().map(|&k| s[k]).collect()
        }
    };
    let stats = ErrorStats::from_pairs(y.iter().copied().zip(sim.iter().copied()));
    let residual: Vec<f64> = y.iter().zip(&sim).map(|(a, b)| a - b).collect();
    let following: Vec<f64> = y.iter().zip(u).map(|(a, b)| a - b).collect();
    let noise = noise_level_of_run(&residual, y);
    let fit = if stats.rms.is_finite() {
        error_fit_percent(&residual, &following, noise)
    } else {
        None
    };
    Ok((stats, fit))
}

/// A model with pairs cancelled: the model, how many pairs, its free-run
/// simulation and its error fit.
type Reduced = (LinearModel, usize, ErrorStats, Option<f64>);

/// Largest growth of the free-run rms that cancelling the pairs the
/// recording cannot resolve may cost.
const UNRESOLVED_PAIR_COST: f64 = 0.1;

/// `model` without the pole–zero pairs whose change of a unit-step response
/// over `span` seconds is below the free-run residual `rms` relative to the
/// command's travel (what the recording resolves), when its own free run is
/// within [`UNRESOLVED_PAIR_COST`] of `rms`: the model, the pairs cancelled,
/// its simulation and error fit; `None` when there is no such pair or the
/// free run disagrees. Such a pair (a slow pole beside a slow zero on the
/// other side of the origin) changes nothing within the recording but
/// rules the model's steady-state gain, which the compensation's unit-gain
/// scaling and inverse depend on.
fn unresolved_pairs(
    model: &LinearModel,
    data: &Data<'_>,
    span: f64,
    rms: f64,
) -> Result<Option<Reduced>> {
    let u0 = data.command.first().copied().unwrap_or(0.0);
    let travel = data
        .command
        .iter()
        .fold(0.0_f64, |m, v| m.max((v - u0).abs()));
    if !(travel > 0.0 && rms.is_finite()) {
        return Ok(None);
    }
    let tolerance = rms / travel;
    if tolerance <= NEGLIGIBLE_PAIR {
        return Ok(None);
    }
    let (reduced, n) = model.without_pairs_below(span, tolerance)?;
    if n == 0 {
        return Ok(None);
    }
    let (stats, error_fit) = simulated_with_fit(&reduced, data)?;
    if !(stats.rms.is_finite() && stats.rms <= (1.0 + UNRESOLVED_PAIR_COST) * rms) {
        return Ok(None);
    }
    Ok(Some((reduced, n, stats, error_fit)))
}

/// The fitted samples.
struct Data<'a> {
    /// Command \[m\], one per sample.
    command: &'a [f64],
    /// Measured position \[m\], one per sample.
    position: &'a [f64],
    /// Sample time \[s\].
    dt: f64,
    /// The segments between gaps (one without gaps).
    segments: Vec<std::ops::Range<usize>>,
    /// With gaps: the signals on the regular grid through them.
    grid: Option<&'a Grid>,
}

/// A recording with gaps on the regular time grid through them.
struct Grid {
    /// Command, the dropped samples interpolated \[m\].
    command: Vec<f64>,
    /// Position, the dropped samples interpolated (only the output-error
    /// fit's initial estimate sees them) \[m\].
    position: Vec<f64>,
    /// Grid index of every measured sample.
    measured: Vec<usize>,
}

impl Grid {
    /// The recording on its regular grid, `None` without gaps.
    fn of<S: AsRef<[f64]>>(rec: &Recording<S>) -> Result<Option<Self>> {
        if rec.gaps().is_empty() {
            return Ok(None);
        }
        Ok(Some(Grid {
            command: rec.fill_gaps(rec.command())?,
            position: rec.fill_gaps(rec.position())?,
            measured: rec.grid_indices(),
        }))
    }
}

/// [`fit_kind`] on the fitted samples.
fn fit_data(data: &Data<'_>, kind: &GlobalModelKind) -> Result<ModelFile> {
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

/// One kind fitted to the samples, and its free-run simulation compared
/// with the measured position.
fn fit_one(data: &Data<'_>, kind: &GlobalModelKind) -> Result<ModelFile> {
    let (u, y, dt) = (data.command, data.position, data.dt);
    let model = match (kind, data.grid) {
        (GlobalModelKind::Arx(orders), None) => {
            fit_arx(u, y, dt, *orders, &ArxConfig::default())?.model
        }
        (GlobalModelKind::Arx(orders), Some(_)) => {
            fit_arx_segments(u, y, dt, *orders, &ArxConfig::default(), &data.segments)?.model
        }
        (GlobalModelKind::Oe { poles, zeros }, grid) => {
            let cfg = OeConfig {
                poles: *poles,
                zeros: *zeros,
                ..OeConfig::default()
            };
            match grid {
                None => fit_oe(u, y, dt, &cfg)?.model,
                Some(g) => fit_oe_measured(&g.command, &g.position, dt, &g.measured, &cfg)?.model,
            }
        }
        (GlobalModelKind::Auto, _) => return fit_data(data, kind),
    };
    // a pair the recording cannot tell apart (a differentiator behind a
    // pole at 1e-11 rad/s) would leave a model of zero steady-state gain
    let span = dt * data.grid.map_or(u.len(), |g| g.command.len()) as f64;
    let (model, cancelled_pairs) = model.without_negligible_pairs(span)?;
    let (stats, error_fit) = simulated_with_fit(&model, data)?;
    if !(stats.rms.is_finite()) {
        return Err(Error::InvalidModel {
            reason: "the global model's simulation is not finite",
        });
    }
    // and a pair whose mode the recording cannot resolve: its change of the
    // response within the recording below the fit's own residual (relative
    // to the command's travel), kept out when the free run agrees
    let (model, cancelled_pairs, stats, error_fit) =
        match unresolved_pairs(&model, data, span, stats.rms)? {
            Some((m, n, st, ef)) => (m, cancelled_pairs + n, st, ef),
            None => (model, cancelled_pairs, stats, error_fit),
        };
    Ok(ModelFile {
        model,
        identified_by: Some(ModelProvenance {
            method: kind.name().to_string(),
            orders: kind.orders(),
            samples: u.len(),
            missing_samples: data.grid.map_or(0, |g| g.command.len() - u.len()),
            cancelled_pairs,
            sample_time_s: dt,
            fit_percent: stats.fit_percent,
            simulation_rms_m: stats.rms,
            error_fit_percent: error_fit,
            source: None,
            candidates: Vec::new(),
        }),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{simulate_nominal, RigParams};
    use crate::lti::TransferFunction;
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
    fn an_offset_of_the_recording_changes_no_global_fit() {
        // machine coordinates: the same motion 1000 m (and 1e6 m) from the origin
        let u = Scenario::Ramp.command(5000.0, 0.4, 1).unwrap();
        let y = simulate_nominal(&RigParams::default(), &u, 2e-4).unwrap();
        let fit = |off: f64| {
            let rec = Recording::from_rate(
                5000.0,
                u.iter().map(|v| v + off).collect(),
                y.iter().map(|v| v + off).collect(),
            )
            .unwrap();
            let mut out = Vec::new();
            for kind in [
                GlobalModelKind::default_for("arx").unwrap(),
                GlobalModelKind::Oe { poles: 3, zeros: 1 },
            ] {
                let f = fit_global_model(&rec, &kind).unwrap();
                out.push(f.identified_by.unwrap().fit_percent);
                out.push(simulation_error(&f.model, &rec).unwrap().fit_percent);
            }
            out
        };
        let base = fit(0.0);
        assert!(base[0] > 99.0, "{base:?}");
        for off in [1000.0, 1e6] {
            for (a, b) in base.iter().zip(fit(off)) {
                assert!((a - b).abs() < 0.05, "offset {off}: {a} vs {b}");
            }
        }
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
        let head = fit_kind(&h, &kind).unwrap();
        assert_eq!(capped, head);
        assert_eq!(capped.identified_by.unwrap().samples, GLOBAL_FIT_SAMPLES);
    }

    /// A second-order axis (ω = 141 rad/s, ζ ≈ 1.06) at 1 kHz under a
    /// square-wave command, exact (no noise).
    fn exact_second_order() -> (TransferFunction, Recording) {
        let g = TransferFunction::new(vec![2.0e4], vec![1.0, 300.0, 2.0e4]).unwrap();
        let u: Vec<f64> = (0..1200)
            .map(|k| if (k / 60) % 2 == 1 { 1e-3 } else { 0.0 })
            .collect();
        let y = g
            .to_state_space()
            .unwrap()
            .discretize_zoh(1e-3)
            .unwrap()
            .simulate(&u, None)
            .unwrap();
        (g, Recording::from_rate(1000.0, u, y).unwrap())
    }

    /// `g·(s − z)/(s − p)`: the second-order axis with a pole–zero pair.
    fn with_pair(g: &TransferFunction, z: f64, p: f64) -> LinearModel {
        let mul = |a: &[f64], b: &[f64]| {
            let mut c = vec![0.0; a.len() + b.len() - 1];
            for (i, x) in a.iter().enumerate() {
                for (j, y) in b.iter().enumerate() {
                    c[i + j] += x * y;
                }
            }
            c
        };
        let tf = TransferFunction::new(mul(g.num(), &[1.0, -z]), mul(g.den(), &[1.0, -p])).unwrap();
        LinearModel::continuous(&tf)
    }

    #[test]
    fn a_pair_the_recording_cannot_resolve_is_cancelled_and_one_it_can_is_kept() {
        use rand::SeedableRng;
        use rand_distr::{Distribution, Normal};
        let (g, exact) = exact_second_order();
        // 1 µm of noise on a 1 mm square wave: the recording resolves 1e-3
        // of a step
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let noise = Normal::new(0.0, 1e-6).unwrap();
        let y: Vec<f64> = exact
            .position()
            .iter()
            .map(|v| v + noise.sample(&mut rng))
            .collect();
        let rec = Recording::from_rate(1000.0, exact.command().to_vec(), y).unwrap();
        let d = Deviations::of(&rec).unwrap();
        let data = d.data(&rec);
        let span = 1.2;
        // an output-error fit's slow pair: a zero at +2e-4 rad/s beside a pole
        // at −4e-5 rad/s changes a step by 3e-4 within the 1.2 s, but makes
        // the steady-state gain −5
        let slow = with_pair(&g, 2e-4, -4e-5);
        assert!((slow.dc_gain().unwrap() + 5.0).abs() < 1e-6);
        assert_eq!(slow.without_negligible_pairs(span).unwrap().1, 0);
        let rms = simulated(&slow, &data).unwrap().rms;
        let (reduced, n, stats, _) = unresolved_pairs(&slow, &data, span, rms)
            .unwrap()
            .expect("the slow pair is cancelled");
        assert_eq!(n, 1);
        assert!((reduced.dc_gain().unwrap() - 1.0).abs() < 1e-9);
        assert!(stats.rms <= (1.0 + UNRESOLVED_PAIR_COST) * rms);
        // a pair that changes the response within the recording stays
        let felt = with_pair(&g, 0.5, -4e-5);
        let rms = simulated(&felt, &data).unwrap().rms;
        assert!(unresolved_pairs(&felt, &data, span, rms).unwrap().is_none());
        // and so does the slow pair on the noise-free recording, whose only
        // residual is the pair's own
        let d = Deviations::of(&exact).unwrap();
        let data = d.data(&exact);
        let rms = simulated(&slow, &data).unwrap().rms;
        assert!(unresolved_pairs(&slow, &data, span, rms).unwrap().is_none());
    }

    #[test]
    fn a_recording_with_dropped_samples_is_fitted_through_its_gaps() {
        let (g, full) = exact_second_order();
        // (none at an edge of the square wave: there the interpolated
        // command would not be the one the axis saw)
        let rec = full.dropping(&[200, 201, 202, 650, 905]).unwrap();
        assert_eq!(rec.gaps().len(), 3);
        // output error: the true model, from the measured samples only
        let oe = fit_global_model(&rec, &GlobalModelKind::Oe { poles: 2, zeros: 0 }).unwrap();
        let tf = match &oe.model {
            LinearModel::Continuous { num, den } => (num.clone(), den.clone()),
            other => panic!("{other:?}"),
        };
        for (a, b) in tf.1.iter().zip(g.den()) {
            assert!((a / b - 1.0).abs() < 1e-6, "{:?} vs {:?}", tf.1, g.den());
        }
        let p = oe.identified_by.as_ref().unwrap();
        assert_eq!((p.samples, p.missing_samples), (1195, 5));
        assert!(p.fit_percent > 99.999, "{}", p.fit_percent);
        // ARX: the exact discrete model has 2 poles and 2 zeros (ZOH), so
        // ARX 2,2,1 on the rows of the segments fits it to rounding, and
        // its free run through the gaps matches the measured samples
        let arx = fit_global_model(&rec, &GlobalModelKind::Arx(ArxOrders::new(2, 2, 1))).unwrap();
        let p = arx.identified_by.as_ref().unwrap();
        assert!(p.fit_percent > 99.999, "{}", p.fit_percent);
        let e = simulation_error(&arx.model, &rec).unwrap();
        assert_eq!(e.samples, 1195);
        assert!((e.fit_percent - p.fit_percent).abs() < 1e-9);
        // without the gaps: the same models to rounding
        let whole = fit_global_model(&full, &GlobalModelKind::Oe { poles: 2, zeros: 0 }).unwrap();
        assert!(
            (whole.model.dc_gain().unwrap() - oe.model.dc_gain().unwrap()).abs() < 1e-9,
            "{:?} vs {:?}",
            whole.model,
            oe.model
        );
        // the written file says what was missing; an old file without the
        // field still reads
        let json = oe.to_json();
        assert!(json.contains("\"missing_samples\": 5"), "{json}");
        assert!(!whole.to_json().contains("missing_samples"));
    }

    #[test]
    fn the_gap_paths_on_a_recording_without_gaps_are_the_plain_fits() {
        let (_, rec) = exact_second_order();
        let (u, y, dt) = (rec.command(), rec.position(), rec.dt());
        let o = ArxOrders::new(3, 2, 1);
        let cfg = ArxConfig::default();
        assert_eq!(
            fit_arx_segments(u, y, dt, o, &cfg, std::slice::from_ref(&(0..u.len()))).unwrap(),
            fit_arx(u, y, dt, o, &cfg).unwrap()
        );
        let oe = OeConfig {
            poles: 2,
            zeros: 0,
            ..OeConfig::default()
        };
        let all: Vec<usize> = (0..u.len()).collect();
        let a = fit_oe_measured(u, y, dt, &all, &oe).unwrap();
        let b = fit_oe(u, y, dt, &oe).unwrap();
        assert_eq!((a.num, a.den, a.report), (b.num, b.den, b.report));
        // bad indices are refused, not indexed
        for bad in [vec![0, 5, 5], vec![3, 1], vec![0, u.len()]] {
            let e = fit_oe_measured(u, y, dt, &bad, &oe)
                .unwrap_err()
                .to_string();
            assert!(e.contains("measured"), "{e}");
        }
        // a segment beyond the data, or a command of another length, is refused
        let e = fit_arx_segments(u, y, dt, o, &cfg, std::slice::from_ref(&(0..u.len() + 1)))
            .unwrap_err()
            .to_string();
        assert!(e.contains("segments"), "{e}");
        let e = fit_arx_segments(&u[1..], y, dt, o, &cfg, std::slice::from_ref(&(0..y.len())))
            .unwrap_err()
            .to_string();
        assert!(e.contains("command"), "{e}");
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
