//! The pipeline's settings (a builder) and the run itself.

use crate::drive::{simulate_nominal, RigParams};
use crate::error::{Error, Result};
use crate::ident::engine::{run_with_progress, Progress};
use crate::ident::{
    fit_global_model, prediction_residuals, select_order, EngineConfig, GlobalModelKind, Method,
    OrderSearch, RESIDUAL_LAGS, SHIFT_AMPLIFICATION_WARNING,
};
use crate::pipeline::{Identification, OrderChoice, Warning};
use crate::recording::Recording;
use crate::stats::ErrorStats;

/// One identification run's settings: the method, the windows, and what to
/// compute besides the predictions. Build with [`Pipeline::new`] and the
/// setters, then [`Pipeline::run`] on a recording (as often as you like).
///
/// Defaults: the method's own window ([`Method::default_window`]), horizon
/// 10, hop = horizon; no order selection; the method's global model
/// ([`Method::global_model`]) fitted for the summary; residual analysis up
/// to lag [`RESIDUAL_LAGS`]; no nominal simulation; no extra model; no
/// progress hook.
#[derive(Clone)]
pub struct Pipeline<'a> {
    method: Method,
    window: Option<usize>,
    horizon: usize,
    hop: Option<usize>,
    warm_up: usize,
    order_search: Option<OrderSearch>,
    method_global_model: bool,
    extra_model: Option<GlobalModelKind>,
    residual_lags: Option<usize>,
    nominal: Option<RigParams>,
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
            horizon: 10,
            hop: None,
            warm_up: 0,
            order_search: None,
            method_global_model: true,
            extra_model: None,
            residual_lags: Some(RESIDUAL_LAGS),
            nominal: None,
            progress: None,
        }
    }

    /// The method (with its settings).
    pub fn method(&self) -> &Method {
        &self.method
    }

    /// Window length W \[samples\]; default: the method's ([`Method::default_window`]).
    pub fn window(mut self, window: usize) -> Self {
        self.window = Some(window);
        self
    }

    /// Window length, or `None` for the method's default.
    pub fn window_or_default(mut self, window: Option<usize>) -> Self {
        self.window = window;
        self
    }

    /// Prediction horizon H \[samples\]; default 10.
    pub fn horizon(mut self, horizon: usize) -> Self {
        self.horizon = horizon;
        self
    }

    /// Shift between windows \[samples\]; `None` (default) = the horizon.
    pub fn hop(mut self, hop: Option<usize>) -> Self {
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

    /// Fit the method's global model ([`Method::global_model`]) for the
    /// summary's free-run fit; default true. A model that cannot be fitted
    /// is a note in the summary, not an error.
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

    /// Report progress of the sliding identification as `(done, total)`
    /// samples (about 500 calls per run; the global-model fits after it are
    /// not counted). Called from the thread that runs the pipeline.
    pub fn progress(mut self, progress: Progress<'a>) -> Self {
        self.progress = Some(progress);
        self
    }

    /// The engine settings this pipeline uses with `method`.
    fn engine_config(&self, method: &Method) -> EngineConfig {
        EngineConfig {
            window: self.window.unwrap_or_else(|| method.default_window()),
            horizon: self.horizon,
            hop: self.hop,
            warm_up: self.warm_up,
        }
    }

    /// Identify time \[s\], command \[m\] and measured position \[m\]
    /// (copied into a checked [`Recording`]).
    pub fn run_slices(
        &self,
        time: &[f64],
        command: &[f64],
        position: &[f64],
    ) -> Result<Identification> {
        let rec = Recording::new(time.to_vec(), command.to_vec(), position.to_vec())?;
        self.run(&rec)
    }

    /// Identify `recording`.
    ///
    /// Errors: invalid settings; orders asked of a method without them
    /// ([`Error::NotApplicable`]); a failed order selection, simulation or
    /// extra model ([`Error::Stage`], with the reason); a recording too
    /// short for the windows.
    pub fn run(&self, recording: &Recording) -> Result<Identification> {
        let mut method = self.method.clone();
        method.validate()?;
        let order_choice = match &self.order_search {
            None => None,
            Some(search) => {
                if method.orders().is_none() {
                    return Err(Error::NotApplicable {
                        setting: "order selection",
                        method: method.name(),
                        applies_to: "arx, rls, auto",
                    });
                }
                let sel = select_order(
                    recording.command(),
                    recording.position(),
                    recording.dt(),
                    search,
                )
                .map_err(|e| Error::Stage {
                    stage: "order selection",
                    source: Box::new(e),
                })?;
                method.set_orders(sel.chosen)?;
                Some(OrderChoice {
                    orders: sel.chosen,
                    criterion: sel.criterion,
                })
            }
        };
        let config = self.engine_config(&method);
        let signals = recording.signals();
        let mut warnings = Vec::new();
        if let Method::Paper(paper) = &method {
            let g = paper.worst_shift_amplification(&signals, &config);
            if g > SHIFT_AMPLIFICATION_WARNING {
                warnings.push(Warning::PaperCoefficientAccuracy { amplification: g });
            }
        }

        let mut estimator = method.build()?;
        let sliding = run_with_progress(estimator.as_mut(), &signals, &config, self.progress)?;

        let simulated = match &self.nominal {
            Some(p) => Some(
                simulate_nominal(p, recording.command(), recording.dt()).map_err(|e| {
                    Error::Stage {
                        stage: "nominal simulation",
                        source: Box::new(e),
                    }
                })?,
            ),
            None => None,
        };
        // over the predicted samples (all samples if nothing was predicted)
        let simulation_stats = simulated.as_ref().map(|sim| {
            let y = recording.position();
            let any = sliding.stats.samples > 0;
            ErrorStats::from_pairs(
                (0..y.len())
                    .filter(|&k| !any || sliding.has_prediction[k])
                    .map(|k| (y[k], sim[k])),
            )
        });
        let residuals = self.residual_lags.and_then(|lags| {
            prediction_residuals(&sliding, recording.command(), recording.position(), lags)
        });

        let method_kind = method.global_model().filter(|_| self.method_global_model);
        let (global, global_note) = match &method_kind {
            None => (None, None),
            Some(kind) => match fit_global_model(recording, kind) {
                Ok(g) => (Some(g), None),
                Err(e) => (None, Some(format!("not fitted ({e})"))),
            },
        };
        let model = match &self.extra_model {
            None => None,
            Some(kind) if Some(kind) == method_kind.as_ref() && global.is_some() => global.clone(),
            Some(kind) => Some(fit_global_model(recording, kind).map_err(|e| Error::Stage {
                stage: "global model",
                source: Box::new(e),
            })?),
        };
        Ok(Identification {
            method,
            config,
            samples: recording.len(),
            rate_hz: recording.rate_hz(),
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
