//! The `nn` estimator: gathers the learning samples as the windows slide,
//! trains the network (module `train`) when it has enough, predicts by
//! running it forward over the horizon, and takes online steps if asked.

use std::ops::Range;

use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::config::{NnConfig, MIN_TRAIN_SAMPLES};
use super::net::{add_squared_error_gradient, forward, Adam, Scratch, Shape};
use super::train::{train, TrainReport, TrainSettings};
use crate::error::{Error, Result};
use crate::ident::engine::{rate_changed, Estimator, PredictStatus, Signals, WindowFit};
use crate::ident::methods::regressor::{first_non_finite, ArxOrders};
use crate::solve::Termination;

/// Samples per mini-batch of the batch training.
const BATCH: usize = 64;
/// Epochs without a better held-out error before a training stops.
const PATIENCE: usize = 5;
/// Share of the training samples (the last ones) held out for early stopping.
const HOLDOUT: f64 = 0.2;
/// Newest samples of a window an online step learns from (at most).
const ONLINE_SAMPLES: usize = 64;

/// The neural NARX predictor over sliding windows (see the module doc).
#[derive(Debug, Clone)]
pub struct NnEstimator {
    config: NnConfig,
    shape: Shape,
    lag: usize,
    /// Learning samples: raw inputs (metres, `f` per row) and targets.
    xs: Vec<f64>,
    ts: Vec<f64>,
    /// Learning samples at which the next batch training runs (`usize::MAX`: none).
    next_train: usize,
    /// Whether the network has been trained (it predicts only then).
    trained: bool,
    /// Parameters (layout of module `net`).
    p: Vec<f64>,
    /// Per-input scale `1/σ` and the target's scale `σ_t` of the last training.
    sx: Vec<f64>,
    st: f64,
    rng: ChaCha8Rng,
    scratch: Scratch,
    /// Buffers: one raw input, one scaled input, the gradient, the online batch.
    raw: Vec<f64>,
    z: Vec<f64>,
    grad: Vec<f64>,
    adam: Adam,
    online_x: Vec<f64>,
    online_t: Vec<f64>,
    /// Positions over a horizon: `na` measured, then the predicted ones.
    path: Vec<f64>,
    cursor: Option<usize>,
    /// Whether the command has moved (learning samples start there).
    moved: bool,
    dt: f64,
    last: Option<TrainReport>,
    updates: usize,
}

impl NnEstimator {
    /// A fresh estimator (untrained) with `config` (validated by [`NnConfig::build`]).
    pub(crate) fn new(config: NnConfig) -> Self {
        let o = config.orders;
        let shape = Shape {
            f: o.na - 1 + o.nb,
            h: config.hidden,
        };
        let n = shape.params();
        let seed = config.seed as u64;
        Self {
            lag: o.lag().max(1),
            shape,
            xs: Vec::new(),
            ts: Vec::new(),
            next_train: MIN_TRAIN_SAMPLES.min(config.train_samples),
            trained: false,
            p: vec![0.0; n],
            sx: vec![0.0; shape.f],
            st: 0.0,
            rng: ChaCha8Rng::seed_from_u64(seed),
            scratch: Scratch::new(shape),
            raw: vec![0.0; shape.f],
            z: vec![0.0; shape.f],
            grad: vec![0.0; n],
            adam: Adam::new(n),
            online_x: Vec::with_capacity(ONLINE_SAMPLES * shape.f),
            online_t: Vec::with_capacity(ONLINE_SAMPLES),
            path: Vec::new(),
            cursor: None,
            moved: false,
            dt: 0.0,
            last: None,
            updates: 0,
            config,
        }
    }

    /// The settings.
    pub fn config(&self) -> &NnConfig {
        &self.config
    }

    /// Whether the network has been trained (before that it does not predict).
    pub fn is_trained(&self) -> bool {
        self.trained
    }

    /// Learning samples gathered so far (at most [`NnConfig::train_samples`]).
    pub fn learning_samples(&self) -> usize {
        self.ts.len()
    }

    /// The last batch training: epochs run, the epoch kept, and the
    /// one-step errors before and after.
    pub fn last_training(&self) -> Option<TrainReport> {
        self.last
    }

    /// Whether sample `k` is one to learn from: every sample from the
    /// first one whose command moved within its regressor span on (a rest
    /// before the first motion would only teach the network to stand still).
    fn learning(&mut self, u: &[f64], k: usize) -> bool {
        if !self.moved {
            let o = self.config.orders;
            let hi = k - o.nk;
            let lo = hi.saturating_sub(o.nb);
            self.moved = u[lo..hi].iter().any(|&v| v != u[hi]);
        }
        self.moved
    }

    /// Scale the raw inputs `raw` into `z`.
    fn scale(sx: &[f64], raw: &[f64], z: &mut [f64]) {
        for ((z, &r), &s) in z.iter_mut().zip(raw).zip(sx) {
            *z = r * s;
        }
    }

    /// Train on the learning samples gathered so far: scales from them, the
    /// linear part by least squares, the hidden layers from the seed, then
    /// the batch training.
    fn train_now(&mut self) -> Result<TrainReport> {
        let f = self.shape.f;
        let n = self.ts.len();
        let mut sig = vec![0.0; f];
        for row in self.xs.chunks_exact(f) {
            for (s, &v) in sig.iter_mut().zip(row) {
                *s += v * v;
            }
        }
        for (sx, s) in self.sx.iter_mut().zip(&sig) {
            let rms = (s / n as f64).sqrt();
            *sx = if rms > 0.0 && rms.is_finite() {
                1.0 / rms
            } else {
                0.0
            };
        }
        let st = (self.ts.iter().map(|v| v * v).sum::<f64>() / n as f64).sqrt();
        if !(st > 0.0 && st.is_finite()) {
            return Err(Error::Singular {
                context: "nn (the axis has not moved in its learning samples)",
            });
        }
        self.st = st;
        let mut x = vec![0.0; n * f];
        for (row, raw) in x.chunks_exact_mut(f).zip(self.xs.chunks_exact(f)) {
            Self::scale(&self.sx, raw, row);
        }
        let t: Vec<f64> = self.ts.iter().map(|v| v / st).collect();
        self.init(&x, &t)?;
        let settings = TrainSettings {
            epochs: self.config.epochs,
            batch: BATCH,
            learning_rate: self.config.learning_rate,
            patience: PATIENCE,
            holdout: HOLDOUT,
        };
        let report = train(self.shape, &mut self.p, &x, &t, &settings, &mut self.rng)?;
        if !self.p.iter().all(|v| v.is_finite()) {
            return Err(Error::NonFinite {
                channel: "nn weights".to_string(),
                index: n,
                value: f64::NAN,
            });
        }
        self.adam.clear();
        self.trained = true;
        self.last = Some(report);
        Ok(report)
    }

    /// The starting network: the linear part and output bias by least
    /// squares (QR, then SVD of R) on the scaled samples, the hidden layers Glorot-uniform
    /// from the seed, the output weights zero (so it starts as the
    /// least-squares unit-gain ARX model).
    fn init(&mut self, x: &[f64], t: &[f64]) -> Result<()> {
        let (f, h) = (self.shape.f, self.shape.h);
        let n = t.len();
        let o = self.shape.layout();
        // QR of the (n × f+1) regressor, then the SVD of its small R:
        // rank-deficient inputs (a constant one) get the minimum-norm
        // solution, and no n × n or second n × (f+1) matrix is formed
        let a = DMatrix::from_fn(n, f + 1, |r, c| if c < f { x[r * f + c] } else { 1.0 });
        let mut b = DVector::from_column_slice(t);
        let qr = a.qr();
        qr.q_tr_mul(&mut b);
        let r = qr.r();
        let k = r.nrows();
        let svd = r.svd(true, true);
        let cut = 1e-12 * svd.singular_values.max();
        let theta = svd
            .solve(&b.rows(0, k).into_owned(), cut)
            .map_err(|_| Error::Singular {
                context: "nn (least-squares start of its linear part)",
            })?;
        let glorot = |fan_in: usize, fan_out: usize| (6.0 / (fan_in + fan_out) as f64).sqrt();
        let (g1, g2) = (glorot(f, h), glorot(h, h));
        for w in &mut self.p[o.w1..o.b1] {
            *w = self.rng.random_range(-g1..g1);
        }
        for w in &mut self.p[o.w2..o.b2] {
            *w = self.rng.random_range(-g2..g2);
        }
        self.p[o.b1..o.w2].fill(0.0);
        self.p[o.b2..o.w3].fill(0.0);
        self.p[o.w3..o.b3].fill(0.0);
        self.p[o.l..o.len].copy_from_slice(&theta.as_slice()[..f]);
        self.p[o.b3] = theta[f];
        Ok(())
    }

    /// Gradient steps on the window's newest samples (the online regime).
    fn online(&mut self, y: &[f64], u: &[f64], from: usize, to: usize) -> usize {
        let f = self.shape.f;
        let from = from.max(to.saturating_sub(ONLINE_SAMPLES));
        self.online_x.clear();
        self.online_t.clear();
        for k in from..to {
            let t = inputs(self.config.orders, y, u, k, &mut self.raw);
            let start = self.online_x.len();
            self.online_x.resize(start + f, 0.0);
            Self::scale(&self.sx, &self.raw, &mut self.online_x[start..]);
            self.online_t.push(t / self.st);
        }
        let m = self.online_t.len();
        if m == 0 {
            return 0;
        }
        for _ in 0..self.config.online_steps {
            self.grad.fill(0.0);
            for (row, &t) in self.online_x.chunks_exact(f).zip(&self.online_t) {
                add_squared_error_gradient(
                    self.shape,
                    &self.p,
                    row,
                    t,
                    1.0 / m as f64,
                    &mut self.scratch,
                    &mut self.grad,
                );
            }
            self.adam
                .step(&mut self.p, &self.grad, self.config.learning_rate);
        }
        self.config.online_steps
    }

    /// One-step rms error of the network over the samples `from..to` (local) \[m\].
    fn one_step_rms(&mut self, y: &[f64], u: &[f64], from: usize, to: usize) -> f64 {
        let mut sse = 0.0;
        for k in from..to {
            let t = inputs(self.config.orders, y, u, k, &mut self.raw);
            Self::scale(&self.sx, &self.raw, &mut self.z);
            let e = self.st * forward(self.shape, &self.p, &self.z, &mut self.scratch) - t;
            sse += e * e;
        }
        if to > from {
            (sse / (to - from) as f64).sqrt()
        } else {
            0.0
        }
    }
}

/// Raw inputs of sample `k` (local index into `y`, `u`, `k ≥ lag`) into
/// `raw` for lags `o`; returns the target `y[k] − y[k−1]`.
fn inputs(o: ArxOrders, y: &[f64], u: &[f64], k: usize, raw: &mut [f64]) -> f64 {
    let r = y[k - 1];
    for i in 2..=o.na {
        raw[i - 2] = y[k - i] - r;
    }
    for j in 0..o.nb {
        raw[o.na - 1 + j] = u[k - o.nk - j] - r;
    }
    y[k] - r
}

impl Estimator for NnEstimator {
    fn name(&self) -> &'static str {
        "nn"
    }

    fn coefficient_names(&self) -> Vec<String> {
        vec![
            "learning_samples".to_string(),
            "holdout_rms_m".to_string(),
            "online_steps".to_string(),
        ]
    }

    fn warm_up(&self) -> usize {
        self.lag
    }

    fn reset(&mut self) {
        *self = NnEstimator::new(self.config.clone());
    }

    /// The network is kept (a network is not relearnt from a few samples;
    /// the guard's safe prediction stands in for the implausible one); the
    /// online steps start their moments afresh.
    fn restart(&mut self) {
        self.adam.clear();
    }

    /// The network and its learning samples are kept; the samples are
    /// taken up again after the gap (no input pairs samples across it),
    /// unless the sample interval changed (then it starts afresh).
    fn gap(&mut self) {
        self.cursor = None;
    }

    fn fit(
        &mut self,
        signals: &Signals<'_>,
        window: Range<usize>,
        coef: &mut [f64],
    ) -> Result<WindowFit> {
        if rate_changed(self.dt, signals.dt()) {
            self.reset();
        }
        self.dt = signals.dt();
        let lag = self.lag;
        let first = signals.offset() + lag;
        let mut cursor = self.cursor.unwrap_or(window.start.max(first));
        if cursor > window.end || cursor < first {
            cursor = window.start.max(first);
        }
        let base = cursor.min(window.start.max(first)) - lag;
        let w = signals.window(
            base + lag..window.end,
            lag,
            "nn window (past samples + window)",
        )?;
        let (y, u) = (w.position, w.command);
        first_non_finite(y, base, "position")?;
        first_non_finite(u, base, "command")?;
        // gather the new learning samples
        let cap = self.config.train_samples;
        for k in (cursor - base)..(window.end - base) {
            if self.ts.len() >= cap {
                break;
            }
            if self.learning(u, k) {
                let t = inputs(self.config.orders, y, u, k, &mut self.raw);
                self.xs.extend_from_slice(&self.raw);
                self.ts.push(t);
            }
        }
        self.cursor = Some(window.end);
        let mut status = None;
        if self.ts.len() >= self.next_train {
            let report = self.train_now();
            self.next_train = if self.ts.len() >= cap {
                usize::MAX
            } else {
                (2 * self.ts.len()).min(cap)
            };
            let report = report?;
            status = Some((report.epochs, report.termination));
        }
        if !self.trained {
            coef.fill(0.0);
            coef[0] = self.ts.len() as f64;
            return Err(Error::Singular {
                context: "nn (not trained yet: fewer samples since the first motion than its first training needs)",
            });
        }
        let from = window.start.max(first) - base;
        let to = window.end - base;
        if status.is_none() && self.config.online_steps > 0 {
            let steps = self.online(y, u, from, to);
            self.updates += steps;
            status = Some((steps, Termination::MaxIterations));
        }
        // the one-step residual over the samples new since the last window
        // (the whole window at the first one)
        let rms = self.one_step_rms(y, u, (cursor - base).max(from), to);
        coef[0] = self.ts.len() as f64;
        coef[1] = self.last.map_or(0.0, |r| r.holdout_mse.sqrt() * self.st);
        coef[2] = self.updates as f64;
        Ok(match status {
            Some((iterations, t)) => WindowFit::identified(rms, iterations, t),
            None => WindowFit::fallback(rms, 0),
        })
    }

    fn predict(
        &mut self,
        signals: &Signals<'_>,
        window: Range<usize>,
        horizon: Range<usize>,
        out: &mut [f64],
    ) -> Result<PredictStatus> {
        if !self.trained {
            return Err(Error::Singular {
                context: "nn (not trained yet)",
            });
        }
        let o = self.config.orders;
        let lag = self.lag;
        let end = window.end;
        let s = signals.window(end..horizon.end, lag, "nn horizon (past samples + horizon)")?;
        let base = end - lag;
        let h = horizon.len();
        self.path.resize(o.na + h, 0.0);
        // the measured positions before the horizon (never those in it)
        self.path[..o.na].copy_from_slice(&s.position[end - o.na - base..end - base]);
        let u = s.command;
        for q in 0..h {
            let k = end + q;
            let r = self.path[o.na + q - 1];
            for i in 2..=o.na {
                self.raw[i - 2] = self.path[o.na + q - i] - r;
            }
            for j in 0..o.nb {
                self.raw[o.na - 1 + j] = u[k - o.nk - j - base] - r;
            }
            Self::scale(&self.sx, &self.raw, &mut self.z);
            let step = self.st * forward(self.shape, &self.p, &self.z, &mut self.scratch);
            self.path[o.na + q] = r + step;
        }
        out[..h].copy_from_slice(&self.path[o.na..o.na + h]);
        Ok(PredictStatus::Predicted)
    }
}
