//! The pipeline's settings (a builder) and the run itself.

use crate::drive::{simulate_nominal_recording, RigParams};
use crate::error::{Error, Result};
use crate::ident::engine::{range, run_with, Progress};
use crate::ident::{
    fit_global_model, prediction_residuals, select_order, EngineConfig, GlobalModelKind,
    GuardConfig, Method, ModelFile, OrderSearch, PredictionMode, Signals, SlidingResult, Span,
    TimeOrigin, RESIDUAL_LAGS, SHIFT_AMPLIFICATION_WARNING,
};
use crate::pipeline::{Identification, OrderChoice, Warning};
use crate::recording::plausibility::check_recording;
use crate::recording::{Recording, RecordingRef, DEFAULT_JITTER_TOLERANCE};
use crate::stats::ErrorStats;

/// One identification run's settings: the method, the windows, and what to
/// compute besides the predictions. Build with [`Pipeline::new`] and the
/// setters, then [`Pipeline::run`] on a recording (as often as you like).
///
/// Defaults: the method's own window ([`Method::default_window`]), horizon
/// 10, hop = horizon; no order selection; the method's global model
/// ([`Method::global_model`]) fitted for the summary; residual analysis up
/// to lag [`RESIDUAL_LAGS`]; no nominal simulation; no extra model; no
/// progress hook; 95 % prediction intervals and outlier rejection
/// ([`GuardConfig::default`]).
#[derive(Clone)]
pub struct Pipeline<'a> {
    method: Method,
    window: Option<Span>,
    horizon: Span,
    hop: Option<Span>,
    warm_up: usize,
    order_search: Option<OrderSearch>,
    method_global_model: bool,
    extra_model: Option<GlobalModelKind>,
    residual_lags: Option<usize>,
    nominal: Option<RigParams>,
    guard: GuardConfig,
    progress: Option<Progress<'a>>,
}

impl std::fmt::Debug for Pipeline<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Pipeline")
            .field("method", &self.method)
            .field("window", &self.window)
            .field("horizon", &self.horizon)
            .field("hop", &self.hop)
            .field("warm_up", &self.warm_up)
            .field("order_search", &self.order_search)
            .field("method_global_model", &self.method_global_model)
            .field("extra_model", &self.extra_model)
            .field("residual_lags", &self.residual_lags)
            .field("nominal", &self.nominal.is_some())
            .field("guard", &self.guard)
            .field("progress", &self.progress.is_some())
            .finish()
    }
}

impl<'a> Pipeline<'a> {
    /// A run of `method` with the defaults (see [`Pipeline`]).
    pub fn new(method: Method) -> Self {
        Self {
            method,
            window: None,
            horizon: Span::Samples(10),
            hop: None,
            warm_up: 0,
            order_search: None,
            method_global_model: true,
            extra_model: None,
            residual_lags: Some(RESIDUAL_LAGS),
            nominal: None,
            guard: GuardConfig::default(),
            progress: None,
        }
    }

    /// The method (with its settings).
    pub fn method(&self) -> &Method {
        &self.method
    }

    /// Window length W \[samples\]; default: the method's ([`Method::default_window`]).
    pub fn window(mut self, window: usize) -> Self {
        self.window = Some(Span::Samples(window));
        self
    }

    /// Window length, or `None` for the method's default.
    pub fn window_or_default(mut self, window: Option<usize>) -> Self {
        self.window = window.map(Span::Samples);
        self
    }

    /// Prediction horizon H \[samples\]; default 10.
    pub fn horizon(mut self, horizon: usize) -> Self {
        self.horizon = Span::Samples(horizon);
        self
    }

    /// Shift between windows \[samples\]; `None` (default) = the horizon.
    pub fn hop(mut self, hop: Option<usize>) -> Self {
        self.hop = hop.map(Span::Samples);
        self
    }

    /// Window (`None`: the method's), horizon and hop (`None`: the horizon)
    /// in samples or in time ([`Span`]: `"2ms"`), converted at the rate of
    /// each recording run.
    pub fn spans(mut self, window: Option<Span>, horizon: Span, hop: Option<Span>) -> Self {
        self.window = window;
        self.horizon = horizon;
        self.hop = hop;
        self
    }

    /// Window, horizon, hop and warm-up from an engine configuration.
    pub fn engine(mut self, config: EngineConfig) -> Self {
        self.warm_up = config.warm_up;
        self.window(config.window)
            .horizon(config.horizon)
            .hop(config.hop)
    }

    /// Choose the method's ARX orders from the recording first
    /// ([`select_order`], e.g. `OrderSearch::default()`: BIC over
    /// na 1…8, nb 1…8, nk 0…2). Refused for a method without orders.
    pub fn select_orders(mut self, search: OrderSearch) -> Self {
        self.order_search = Some(search);
        self
    }

    /// Fit the method's global model ([`Method::global_model`], with `auto`
    /// its least-squares candidate arx 8,8,1: [`GlobalModelKind::for_summary`])
    /// on the first [`crate::ident::GLOBAL_FIT_SAMPLES`] samples at most, for
    /// the summary's free-run fit; default true. A model that cannot be
    /// fitted is a note in the summary, not an error.
    pub fn method_global_model(mut self, fit: bool) -> Self {
        self.method_global_model = fit;
        self
    }

    /// Also fit a global model of this kind (`feedid identify --model-out`);
    /// a failure is an error of the run. The method's own global model is
    /// reused when it is the same kind.
    pub fn extra_model(mut self, kind: GlobalModelKind) -> Self {
        self.extra_model = Some(kind);
        self
    }

    /// Residual analysis up to this lag (`None`: none); default
    /// [`RESIDUAL_LAGS`].
    pub fn residuals(mut self, max_lag: Option<usize>) -> Self {
        self.residual_lags = max_lag;
        self
    }

    /// Simulate the nominal physical model of these rig parameters driven
    /// by the measured command (the paper's simulation model); default none.
    pub fn nominal(mut self, params: RigParams) -> Self {
        self.nominal = Some(params);
        self
    }

    /// Prediction intervals and outlier rejection of the engine; default
    /// [`GuardConfig::default`] (95 % intervals, outliers beyond 8 error
    /// scales rejected).
    pub fn guard(mut self, guard: GuardConfig) -> Self {
        self.guard = guard;
        self
    }

    /// Probability `P` of the prediction intervals, in (0, 1); default 0.95
    /// (the rest of [`Pipeline::guard`] unchanged).
    pub fn interval(mut self, probability: f64) -> Self {
        self.guard.interval = probability;
        self
    }

    /// Report progress of the sliding identification as `(done, total)`
    /// samples (about 500 calls per run; the global-model fits after it are
    /// not counted). Called from the thread that runs the pipeline.
    pub fn progress(mut self, progress: Progress<'a>) -> Self {
        self.progress = Some(progress);
        self
    }

    /// The engine settings this pipeline uses with `method` on a recording
    /// sampled at `rate_hz` (times converted to samples).
    pub fn engine_config(&self, method: &Method, rate_hz: f64) -> Result<EngineConfig> {
        Ok(EngineConfig {
            window: method.window_for(self.window, rate_hz)?,
            horizon: self.horizon.samples(rate_hz, "horizon")?,
            hop: self.hop.map(|h| h.samples(rate_hz, "hop")).transpose()?,
            warm_up: self.warm_up,
        })
    }

    /// Identify time \[s\], command \[m\] and measured position \[m\],
    /// checked as a [`Recording`] (1 % jitter tolerance) but not copied.
    pub fn run_slices(
        &self,
        time: &[f64],
        command: &[f64],
        position: &[f64],
    ) -> Result<Identification> {
        let rec = RecordingRef::borrowed(time, command, position, DEFAULT_JITTER_TOLERANCE)?;
        self.run(&rec)
    }

    /// Identify `recording`.
    ///
    /// Errors: invalid settings; orders asked of a method without them
    /// ([`Error::NotApplicable`]); a failed order selection, simulation or
    /// extra model ([`Error::Stage`], with the reason); a recording too
    /// short for the windows.
    pub fn run<S: AsRef<[f64]>>(&self, recording: &Recording<S>) -> Result<Identification> {
        let mut method = self.method.clone();
        method.validate()?;
        self.guard.validate()?;
        let order_choice = self.choose_orders(&mut method, recording)?;
        let config = self.engine_config(&method, recording.rate_hz())?;
        let signals = recording.signals();
        let mut warnings = setup_warnings(&method, recording, &signals, &config);
        let sliding = self.slide(&method, &signals, &config, &mut warnings)?;
        self.sliding_warnings(recording, &sliding, &mut warnings);
        let (simulated, simulation_stats, diverged) = self.simulate(recording, &sliding)?;
        if let Some(from_s) = diverged {
            warnings.push(Warning::NominalDiverged { from_s });
        }
        let residuals = self.residual_lags.and_then(|lags| {
            prediction_residuals(
                &sliding,
                recording.command(),
                recording.position(),
                lags,
                config.horizon,
            )
        });
        let (global, global_note, model) = self.global_models(&method, recording)?;
        Ok(Identification {
            method,
            config,
            samples: recording.len(),
            rate_hz: recording.rate_hz(),
            gaps: recording.gaps().len(),
            missing_samples: recording.missing_samples(),
            order_choice,
            sliding,
            simulated,
            simulation_stats,
            residuals,
            global,
            global_note,
            model,
            warnings,
        })
    }
}

/// The nominal simulation, its error figures, and the time from which it
/// ran away (see [`DIVERGED_SPAN`]).
type NominalRun = (Option<Vec<f64>>, Option<ErrorStats>, Option<f64>);

/// How far the nominal simulation may leave the measured position, in
/// multiples of the motion the recording spans (the larger of the
/// position's and the command's range), before it counts as run away
/// ([`Warning::NominalDiverged`]).
pub const DIVERGED_SPAN: f64 = 1e3;

/// The recording's plausibility warnings and the paper method's warnings
/// about its coefficients, known before the run.
fn setup_warnings<S: AsRef<[f64]>>(
    method: &Method,
    recording: &Recording<S>,
    signals: &Signals<'_>,
    config: &EngineConfig,
) -> Vec<Warning> {
    let mut warnings: Vec<Warning> = check_recording(recording)
        .into_iter()
        .map(Warning::Recording)
        .collect();
    if let Method::Paper(paper) = method {
        let g = paper.worst_shift_amplification(signals, config);
        if g > SHIFT_AMPLIFICATION_WARNING {
            warnings.push(Warning::PaperCoefficientAccuracy { amplification: g });
        }
        if paper.time_origin == TimeOrigin::Window {
            warnings.push(Warning::PaperWindowOrigin);
        }
    }
    warnings
}

/// The steps of [`Pipeline::run`]: orders, the sliding run and what it
/// warns of, the nominal simulation, the global models.
impl Pipeline<'_> {
    /// The orders chosen from the data, set on `method` (if asked).
    fn choose_orders<S: AsRef<[f64]>>(
        &self,
        method: &mut Method,
        recording: &Recording<S>,
    ) -> Result<Option<OrderChoice>> {
        let Some(search) = &self.order_search else {
            return Ok(None);
        };
        if method.orders().is_none() {
            return Err(Error::NotApplicable {
                setting: "order selection",
                method: method.name(),
                applies_to: crate::ident::ORDER_METHODS,
            });
        }
        // on the stretch without dropped samples where the command moves most
        let part = recording.moving_segment();
        let sel = select_order(
            &recording.command()[part.clone()],
            &recording.position()[part],
            recording.dt(),
            search,
        )
        .map_err(|e| Error::Stage {
            stage: "order selection",
            source: Box::new(e),
        })?;
        method.set_orders(sel.chosen)?;
        Ok(Some(OrderChoice {
            orders: sel.chosen,
            criterion: sel.criterion,
        }))
    }

    /// The sliding identification and prediction of the method.
    fn slide(
        &self,
        method: &Method,
        signals: &Signals<'_>,
        config: &EngineConfig,
        warnings: &mut Vec<Warning>,
    ) -> Result<SlidingResult> {
        Ok(match method {
            // the paper's tf prediction may fall back per window: count it
            Method::Paper(paper) if paper.prediction == PredictionMode::TransferFunction => {
                let mut estimator = (*paper).build()?;
                let sliding =
                    run_with(&mut estimator, signals, config, &self.guard, self.progress)?;
                let fallbacks = estimator.tf_fallbacks();
                if fallbacks > 0 {
                    warnings.push(Warning::PaperTfFallback {
                        fallbacks,
                        windows: sliding.windows.len(),
                    });
                }
                sliding
            }
            _ => {
                let mut estimator = method.build()?;
                run_with(
                    estimator.as_mut(),
                    signals,
                    config,
                    &self.guard,
                    self.progress,
                )?
            }
        })
    }

    /// Warnings of the sliding run: dropped samples, nothing predicted,
    /// withheld windows.
    fn sliding_warnings<S: AsRef<[f64]>>(
        &self,
        recording: &Recording<S>,
        sliding: &SlidingResult,
        warnings: &mut Vec<Warning>,
    ) {
        if let Some(g) = recording.gaps().first() {
            let segments = recording.segments();
            let unpredicted = segments
                .iter()
                .skip(1)
                .map(|r| {
                    r.clone()
                        .take_while(|&k| !sliding.has_prediction[k])
                        .count()
                })
                .sum();
            warnings.push(Warning::DroppedSamples {
                gaps: recording.gaps().len(),
                missing: recording.missing_samples(),
                first: g.index,
                first_time_s: recording.time()[g.index],
                unpredicted,
                stretch: recording.moving_segment().len(),
            });
        }
        if sliding.stats.samples == 0 {
            warnings.push(Warning::NothingPredicted {
                windows: sliding.windows.len(),
                failed: sliding.failed_windows(),
                withheld: sliding.withheld_windows(),
            });
        } else if sliding.withheld_windows() > 0 {
            warnings.push(Warning::ImplausibleWithheld {
                withheld: sliding.withheld_windows(),
                windows: sliding.windows.len(),
                factor: self.guard.plausibility.unwrap_or(f64::INFINITY),
            });
        }
    }

    /// The nominal simulation (if asked) and its errors over the predicted
    /// samples (all samples if nothing was predicted).
    fn simulate<S: AsRef<[f64]>>(
        &self,
        recording: &Recording<S>,
        sliding: &SlidingResult,
    ) -> Result<NominalRun> {
        let simulated = match &self.nominal {
            Some(p) => {
                Some(
                    simulate_nominal_recording(p, recording).map_err(|e| Error::Stage {
                        stage: "nominal simulation",
                        source: Box::new(e),
                    })?,
                )
            }
            None => None,
        };
        let mut simulated = simulated;
        let mut diverged = None;
        if let Some(sim) = simulated.as_mut() {
            // a run-away simulation (unstable parameters allowed) is left out
            // from where it leaves the recording's scale: no 1e189 in a file
            let (y, u) = (recording.position(), recording.command());
            let span = range(y).max(range(u));
            let bound = DIVERGED_SPAN * if span > 0.0 { span } else { 1.0 };
            if let Some(k) = (0..y.len())
                .find(|&k| (sim[k] - y[k]).abs().is_nan() || (sim[k] - y[k]).abs() > bound)
            {
                sim[k..].fill(f64::NAN);
                diverged = Some(recording.time()[k]);
            }
        }
        let simulation_stats = simulated.as_ref().map(|sim| {
            if diverged.is_some() {
                return ErrorStats {
                    samples: 0,
                    rms: f64::NAN,
                    max_abs: f64::NAN,
                    fit_percent: f64::NAN,
                };
            }
            let y = recording.position();
            let any = sliding.stats.samples > 0;
            ErrorStats::from_pairs(
                (0..y.len())
                    .filter(|&k| !any || sliding.has_prediction[k])
                    .map(|k| (y[k], sim[k])),
            )
        });
        Ok((simulated, simulation_stats, diverged))
    }

    /// Global models of the whole recording (through any gaps): the
    /// method's (or why it is missing) and the extra model.
    fn global_models<S: AsRef<[f64]>>(
        &self,
        method: &Method,
        recording: &Recording<S>,
    ) -> Result<(Option<ModelFile>, Option<String>, Option<ModelFile>)> {
        let method_kind = method
            .global_model()
            .map(GlobalModelKind::for_summary)
            .filter(|_| self.method_global_model);
        let fit_global = |kind: &GlobalModelKind| fit_global_model(recording, kind);
        let (global, global_note) = match &method_kind {
            None => (None, None),
            Some(kind) => match fit_global(kind) {
                Ok(g) => (Some(g), None),
                Err(e) => (None, Some(format!("not fitted ({e})"))),
            },
        };
        let model = match &self.extra_model {
            None => None,
            Some(kind) if Some(kind) == method_kind.as_ref() && global.is_some() => global.clone(),
            Some(kind) => Some(fit_global(kind).map_err(|e| Error::Stage {
                stage: "global model",
                source: Box::new(e),
            })?),
        };
        Ok((global, global_note, model))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::VirtualRig;
    use crate::ident::engine;
    use crate::signal::Scenario;

    fn ramp() -> Recording {
        let cmd = Scenario::Ramp.command(5000.0, 0.15, 1).unwrap();
        let out = VirtualRig::new(RigParams::default())
            .with_seed(3)
            .simulate(&cmd, 5000.0)
            .unwrap();
        Recording::new(out.time, out.command, out.position).unwrap()
    }

    #[test]
    fn borrowed_slices_identify_exactly_as_an_owned_recording() {
        let rec = ramp();
        for name in ["arx", "auto"] {
            let pipeline = Pipeline::new(name.parse().unwrap()).nominal(RigParams::default());
            let owned = pipeline.run(&rec).unwrap();
            let borrowed = pipeline
                .run_slices(rec.time(), rec.command(), rec.position())
                .unwrap();
            assert_eq!(
                owned.sliding.predicted, borrowed.sliding.predicted,
                "{name}"
            );
            assert_eq!(owned.sliding.lower, borrowed.sliding.lower, "{name}");
            assert_eq!(owned.sliding.coefficients, borrowed.sliding.coefficients);
            assert_eq!(owned.simulated, borrowed.simulated, "{name}");
            assert_eq!(owned.global, borrowed.global, "{name}");
            let (mut a, mut b) = (owned.summary(), borrowed.summary());
            // timing differs from run to run
            (a.identification_seconds, a.per_window_us) = (0.0, 0.0);
            (b.identification_seconds, b.per_window_us) = (0.0, 0.0);
            assert_eq!(a, b, "{name}");
        }
        // the checks of a recording apply to the slices too
        let mut t = rec.time().to_vec();
        t[7] = t[6];
        let e = Pipeline::new(Method::default())
            .run_slices(&t, rec.command(), rec.position())
            .unwrap_err();
        assert!(matches!(e, Error::NonMonotoneTime { index: 7, .. }), "{e}");
    }

    #[test]
    fn pipeline_and_its_results_can_cross_threads() {
        fn send<T: Send>() {}
        send::<Pipeline<'static>>();
        send::<Identification>();
        send::<Method>();
        send::<crate::pipeline::IdentifySummary>();
    }

    #[test]
    fn predictions_are_those_of_the_engine_and_the_summary_counts_them() {
        let rec = ramp();
        for name in ["paper", "arx", "auto"] {
            let method: Method = name.parse().unwrap();
            let run = Pipeline::new(method.clone())
                .method_global_model(false)
                .run(&rec)
                .unwrap();
            let cfg = EngineConfig {
                window: method.default_window(),
                ..EngineConfig::default()
            };
            let alone =
                engine::run(method.build().unwrap().as_mut(), &rec.signals(), &cfg).unwrap();
            assert_eq!(run.sliding.predicted, alone.predicted, "{name}");
            assert_eq!(run.sliding.has_prediction, alone.has_prediction, "{name}");
            assert_eq!(run.sliding.coefficients, alone.coefficients, "{name}");
            let s = run.summary();
            assert_eq!(s.samples_predicted, alone.stats.samples);
            assert_eq!(s.rms_error_m, Some(alone.stats.rms));
            assert_eq!(s.window, method.default_window());
            assert!(s.global_model.is_none() && s.sim_rms_error_m.is_none());
            let json = serde_json::to_value(&s).unwrap();
            assert!(json.get("global_model").is_none(), "absent, not null");
            assert!(s.to_string().starts_with(&format!(
                "{} samples at 5000.00 Hz, method {name}, window {}",
                rec.len(),
                method.default_window()
            )));
        }
    }

    #[test]
    fn slices_progress_nominal_model_and_extra_model_are_what_they_say() {
        let rec = ramp();
        let calls = std::sync::Mutex::new(Vec::new());
        let hook = |d: u64, n: u64| calls.lock().unwrap().push((d, n));
        let p = Pipeline::new("arx".parse().unwrap())
            .nominal(RigParams::default())
            .extra_model(GlobalModelKind::Arx(
                crate::ident::ArxConfig::default().orders,
            ))
            .progress(&hook);
        let a = p.run(&rec).unwrap();
        let b = p
            .run_slices(rec.time(), rec.command(), rec.position())
            .unwrap();
        assert_eq!(a.sliding.predicted, b.sliding.predicted);
        let calls = calls.into_inner().unwrap();
        assert_eq!(calls.last(), Some(&(rec.len() as u64, rec.len() as u64)));
        // the nominal model over the predicted samples
        let sim = a.simulated.as_ref().unwrap();
        let expect = ErrorStats::from_pairs(
            (0..rec.len())
                .filter(|&k| a.sliding.has_prediction[k])
                .map(|k| (rec.position()[k], sim[k])),
        );
        assert_eq!(a.simulation_stats, Some(expect));
        // the extra model of the method's own kind is the method's global model
        assert!(a.global.is_some());
        assert_eq!(a.model, a.global);
        let s = a.summary();
        assert_eq!(s.global_model.as_deref(), Some("arx 3,3,0"));
        assert!(s
            .to_string()
            .contains("global model of the method (arx 3,3,0)"));
    }

    #[test]
    fn dropped_samples_restart_the_windows_and_the_rig_runs_through_the_gaps() {
        let full = ramp();
        let rec = full.dropping(&[300, 301, 302, 520]).unwrap();
        let p = Pipeline::new("arx".parse().unwrap()).nominal(RigParams::default());
        let a = p.run(&rec).unwrap();
        // the engine's segments, the summary and the warning
        let b = engine::run(
            &mut Method::Arx(Default::default()).build().unwrap(),
            &rec.signals(),
            &a.config,
        )
        .unwrap();
        assert_eq!(a.sliding.predicted, b.predicted);
        assert!(!a.sliding.has_prediction[300..310].iter().any(|&h| h));
        let s = a.summary();
        assert_eq!((s.gaps, s.missing_samples), (2, 4));
        assert!(s
            .to_string()
            .contains("2 gap(s) of dropped samples (4 missing)"));
        assert!(
            s.to_string().contains(
                "on 746 measured samples (simulated through the 2 gap(s), compared where measured)"
            ),
            "{s}"
        );
        assert!(a.warnings.iter().any(|w| matches!(
            w,
            Warning::DroppedSamples {
                gaps: 2,
                missing: 4,
                first: 300,
                ..
            }
        )));
        // the nominal rig simulated on the full grid (the ramp's command is
        // linear in time, so interpolating it at the missing samples is exact)
        let sim = a.simulated.as_ref().unwrap();
        let whole =
            crate::drive::simulate_nominal(&RigParams::default(), full.command(), full.dt())
                .unwrap();
        for (i, &k) in rec.grid_indices().iter().enumerate() {
            assert!(
                (sim[i] - whole[k]).abs() <= 1e-12,
                "{k}: {} vs {}",
                sim[i],
                whole[k]
            );
        }
        // the global model: fitted on every measured sample, simulated
        // through the gaps (its fit is the free run's over the measured ones)
        assert_eq!(s.global_model_samples, Some(rec.len()));
        let g = a.global.as_ref().unwrap();
        let e = crate::ident::simulation_error(&g.model, &rec).unwrap();
        assert_eq!(e.samples, rec.len());
        let p = g.identified_by.as_ref().unwrap();
        assert_eq!((p.samples, p.missing_samples), (746, 4));
        assert!((p.fit_percent - e.fit_percent).abs() < 1e-9);
        assert!(p.fit_percent > 99.0, "{}", p.fit_percent);
    }

    #[test]
    fn the_summary_of_auto_fits_arx_on_a_stated_share_and_extra_auto_compares_all() {
        let rec = ramp();
        let run = Pipeline::new(Method::default())
            .extra_model(GlobalModelKind::Auto)
            .run(&rec)
            .unwrap();
        let s = run.summary();
        assert_eq!(s.global_model.as_deref(), Some("arx 8,8,1"));
        assert_eq!(s.global_model_samples, Some(rec.len()));
        let text = s.to_string();
        assert!(
            text.contains(&format!(
                "global model of the method (arx 8,8,1): free-run fit {:.3} % on all {} samples",
                s.global_fit_percent.unwrap(),
                rec.len()
            )),
            "{text}"
        );
        let json = serde_json::to_value(&s).unwrap();
        assert_eq!(json["global_model_samples"], rec.len());
        // the summary's model is the one fit_global_model gives for arx 8,8,1
        let arx = fit_global_model(&rec, &GlobalModelKind::Auto.for_summary()).unwrap();
        assert_eq!(run.global.as_ref(), Some(&arx));
        // --model-out auto still compares the three candidates
        let prov = run.model.as_ref().unwrap().identified_by.as_ref().unwrap();
        assert_eq!(prov.candidates.len(), 3, "{:?}", prov.candidates);
        // a share below 100 % is printed as such
        let mut part = s.clone();
        (part.samples, part.global_model_samples) = (1000, Some(250));
        assert!(
            part.to_string()
                .contains("on the first 250 samples (25.0 %)"),
            "{part}"
        );
    }

    #[test]
    fn orders_are_chosen_for_regressor_methods_and_refused_for_the_others() {
        let rec = ramp();
        let search = OrderSearch::default();
        let sel = select_order(rec.command(), rec.position(), rec.dt(), &search).unwrap();
        let run = Pipeline::new("rls".parse().unwrap())
            .select_orders(search)
            .method_global_model(false)
            .run(&rec)
            .unwrap();
        assert_eq!(run.method.orders(), Some(sel.chosen));
        assert!(run
            .summary()
            .to_string()
            .contains("  order auto (bic): na "));
        let e = Pipeline::new("paper".parse().unwrap())
            .select_orders(search)
            .run(&rec)
            .unwrap_err();
        assert!(
            matches!(
                e,
                Error::NotApplicable {
                    method: "paper",
                    ..
                }
            ),
            "{e}"
        );
        // a failed selection says why, under its stage
        let flat = Recording::from_rate(1000.0, vec![1e-3; 300], vec![1e-3; 300]).unwrap();
        let e = Pipeline::new("arx".parse().unwrap())
            .select_orders(OrderSearch::default())
            .run(&flat)
            .unwrap_err();
        assert!(
            matches!(
                e,
                Error::Stage {
                    stage: "order selection",
                    ..
                }
            ),
            "{e}"
        );
        assert!(e.to_string().len() > "order selection: ".len() + 5, "{e}");
        assert!(!matches!(e.root(), Error::Stage { .. }));
    }

    #[test]
    fn paper_tf_prediction_reports_the_windows_that_fell_back_to_the_polynomial() {
        use crate::drive::{RigParams, VirtualRig};
        use crate::ident::{Estimator, PaperConfig, PredictionMode};
        let rate = 5000.0;
        let command = Scenario::Ramp.command(rate, 0.3, 1).unwrap();
        let out = VirtualRig::new(RigParams::default())
            .with_seed(1)
            .simulate(&command, rate)
            .unwrap();
        let rec = Recording::new(out.time, out.command, out.position).unwrap();
        let paper = |prediction| {
            Method::Paper(PaperConfig {
                prediction,
                ..PaperConfig::default()
            })
        };
        let fallback_warnings = |run: &Identification| -> Vec<Warning> {
            run.warnings
                .iter()
                .filter(|w| matches!(w, Warning::PaperTfFallback { .. }))
                .cloned()
                .collect()
        };
        let poly = Pipeline::new(paper(PredictionMode::Polynomial))
            .run(&rec)
            .unwrap();
        assert!(fallback_warnings(&poly).is_empty());
        let tf = Pipeline::new(paper(PredictionMode::TransferFunction))
            .run(&rec)
            .unwrap();
        let warned = fallback_warnings(&tf);
        // reference: the windows whose two predictions are identical, by an
        // estimator of each mode fed the same windows
        let cfg = tf.config;
        let signals = rec.signals();
        let mut a = PaperConfig::default().build().unwrap();
        let mut b = PaperConfig {
            prediction: PredictionMode::TransferFunction,
            ..PaperConfig::default()
        }
        .build()
        .unwrap();
        let (mut coef, mut pa, mut pb) =
            ([0.0; 11], vec![0.0; cfg.horizon], vec![0.0; cfg.horizon]);
        let (mut windows, mut same, mut differ) = (0, 0, 0);
        for (window, horizon) in cfg.windows(rec.len(), a.warm_up()) {
            windows += 1;
            a.fit(&signals, window.clone(), &mut coef).unwrap();
            b.fit(&signals, window.clone(), &mut coef).unwrap();
            a.predict(&signals, window.clone(), horizon.clone(), &mut pa)
                .unwrap();
            b.predict(&signals, window, horizon, &mut pb).unwrap();
            let fell_back = b.diagnostics().is_some_and(|d| d.tf_fallback);
            if fell_back {
                assert_eq!(pa, pb);
                same += 1;
            } else if pa != pb {
                differ += 1;
            }
        }
        assert_eq!(b.tf_fallbacks(), same);
        assert_eq!(tf.sliding.windows.len(), windows);
        if same == 0 {
            assert!(warned.is_empty(), "{warned:?}");
        } else {
            assert!(
                matches!(
                    warned.as_slice(),
                    [Warning::PaperTfFallback { fallbacks, windows: w }] if *fallbacks == same && *w == windows
                ),
                "{warned:?} ({same} of {windows})"
            );
            assert!(warned[0]
                .to_string()
                .contains(&format!("{same} of {windows}")));
        }
        // the rig's ramp: the identified D(s) is almost never Hurwitz
        assert!(same * 10 > windows * 9, "{same} of {windows}");
        eprintln!("tf: {same} of {windows} windows fell back, {differ} predicted differently");
    }

    #[test]
    fn paper_windows_far_from_the_time_origin_warn() {
        // the motion starts at 0 and the recording lasts 25 s: windows far from it
        let n = 2000;
        let t: Vec<f64> = (0..n).map(|k| 25.0 + k as f64 * 1e-3).collect();
        let u: Vec<f64> = (0..n).map(|k| 1e-3 * (k as f64 * 0.01).sin()).collect();
        let rec = Recording::new(t, u.clone(), u).unwrap();
        let run = Pipeline::new("paper".parse().unwrap()).run(&rec).unwrap();
        assert!(matches!(
            run.warnings.as_slice(),
            [Warning::PaperCoefficientAccuracy { .. }]
        ));
        assert!(run.warnings[0].to_string().contains("lose about"));
        let run = Pipeline::new("arx".parse().unwrap()).run(&rec).unwrap();
        assert!(run.warnings.is_empty());
    }

    #[test]
    fn paper_window_time_origin_warns_that_it_cannot_predict_a_moving_axis() {
        // a ramp away from 0: the window-local output model starts at rest at 0
        let n = 400;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 2e-4).collect();
        let u: Vec<f64> = t.iter().map(|&t| 0.01 + 0.05 * t).collect();
        let rec = Recording::new(t, u.clone(), u).unwrap();
        let mut method: Method = "paper".parse().unwrap();
        if let Method::Paper(c) = &mut method {
            c.time_origin = TimeOrigin::Window;
        }
        let run = Pipeline::new(method).run(&rec).unwrap();
        assert!(
            run.warnings
                .iter()
                .any(|w| matches!(w, Warning::PaperWindowOrigin)),
            "{:?}",
            run.warnings
        );
        let run = Pipeline::new("paper".parse().unwrap()).run(&rec).unwrap();
        assert!(!run
            .warnings
            .iter()
            .any(|w| matches!(w, Warning::PaperWindowOrigin)));
    }
}
