//! Batch training of the network in candle: mini-batch Adam on the
//! one-step squared error, every fifth block of 50 training samples held
//! out, and the parameters of the epoch with the lowest held-out error kept
//! (early stopping; epoch 0 — the starting network — included, so training
//! never returns a network worse on the held-out samples than the one it
//! started from).
//!
//! candle builds the graph of the loss, differentiates it and does the
//! matrix products of a batch; the network's layout and its plain forward
//! pass are in module `net`, which scores the held-out samples with the
//! same code that predicts.

use candle_core::{Device, Tensor, Var};
use rand::seq::SliceRandom;
use rand_chacha::ChaCha8Rng;

use super::net::{forward, Scratch, Shape, ADAM};
use crate::error::{Error, Result};
use crate::solve::Termination;

/// How a batch training runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct TrainSettings {
    /// Most passes over the training samples.
    pub epochs: usize,
    /// Samples per gradient step.
    pub batch: usize,
    /// Adam's step size.
    pub learning_rate: f64,
    /// Epochs without a better held-out error before stopping.
    pub patience: usize,
    /// Share of the samples (the last ones, in time order) held out.
    pub holdout: f64,
}

/// What a batch training of `nn` did ([`NnEstimator::last_training`](crate::ident::NnEstimator::last_training)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrainReport {
    /// Epochs run.
    pub epochs: usize,
    /// The epoch whose parameters were kept (0: the starting network).
    pub best_epoch: usize,
    /// Mean squared one-step error (scaled) on the held-out samples before training.
    pub start_holdout_mse: f64,
    /// Mean squared one-step error (scaled) on the held-out samples, kept parameters.
    pub holdout_mse: f64,
    /// Mean squared one-step error (scaled) on the training samples before and after.
    pub train_mse: (f64, f64),
    /// Stopped because the held-out error stopped improving (`Converged`)
    /// or at the epoch cap (`MaxIterations`).
    pub termination: Termination,
}

fn candle(e: candle_core::Error) -> Error {
    Error::Network {
        stage: "training",
        message: e.to_string(),
    }
}

/// Mean squared error of the network over `rows` of `x` (`f` per row) against `t`.
pub(crate) fn mse(shape: Shape, p: &[f64], x: &[f64], t: &[f64], rows: &[usize]) -> f64 {
    let f = shape.f;
    let mut s = Scratch::new(shape);
    let n = rows.len().max(1) as f64;
    rows.iter()
        .map(|&r| (forward(shape, p, &x[r * f..(r + 1) * f], &mut s) - t[r]).powi(2))
        .sum::<f64>()
        / n
}

/// The network's parameters as candle variables.
struct Vars {
    all: Vec<Var>,
}

impl Vars {
    fn new(shape: Shape, p: &[f64], dev: &Device) -> candle_core::Result<Self> {
        let (f, h) = (shape.f, shape.h);
        let o = shape.layout();
        let all = vec![
            Var::from_slice(&p[o.w1..o.b1], (f, h), dev)?,
            Var::from_slice(&p[o.b1..o.w2], h, dev)?,
            Var::from_slice(&p[o.w2..o.b2], (h, h), dev)?,
            Var::from_slice(&p[o.b2..o.w3], h, dev)?,
            Var::from_slice(&p[o.w3..o.b3], (h, 1), dev)?,
            Var::from_slice(&p[o.b3..o.l], 1, dev)?,
            Var::from_slice(&p[o.l..o.len], (f, 1), dev)?,
        ];
        Ok(Self { all })
    }

    /// Output of the network for the rows of `x` (`(batch, f)`), `(batch, 1)`.
    fn forward(&self, x: &Tensor) -> candle_core::Result<Tensor> {
        let v = |i: usize| self.all[i].as_tensor();
        let h1 = x.matmul(v(0))?.broadcast_add(v(1))?.tanh()?;
        let h2 = h1.matmul(v(2))?.broadcast_add(v(3))?.tanh()?;
        h2.matmul(v(4))?.broadcast_add(v(5))?.add(&x.matmul(v(6))?)
    }

    /// Copy the variables into the flat parameters (the layout of module `net`).
    fn write(&self, p: &mut [f64]) -> candle_core::Result<()> {
        let mut at = 0;
        for v in &self.all {
            let w = v.as_tensor().flatten_all()?.to_vec1::<f64>()?;
            p[at..at + w.len()].copy_from_slice(&w);
            at += w.len();
        }
        Ok(())
    }
}

/// Gradient of the mean squared error of the rows of `x` (`n × f`) against
/// `t`, computed by candle's automatic differentiation, in the flat layout
/// (the reference the hand-written gradient is tested against).
#[cfg(test)]
pub(crate) fn candle_gradient(shape: Shape, p: &[f64], x: &[f64], t: &[f64]) -> Result<Vec<f64>> {
    let run = || -> candle_core::Result<Vec<f64>> {
        let dev = Device::Cpu;
        let vars = Vars::new(shape, p, &dev)?;
        let n = t.len();
        let xb = Tensor::from_slice(x, (n, shape.f), &dev)?;
        let tb = Tensor::from_slice(t, (n, 1), &dev)?;
        let loss = vars.forward(&xb)?.sub(&tb)?.sqr()?.mean_all()?;
        let grads = loss.backward()?;
        let mut g = Vec::with_capacity(p.len());
        for v in &vars.all {
            let gi = grads
                .get(v.as_tensor())
                .expect("every variable is in the graph");
            g.extend(gi.flatten_all()?.to_vec1::<f64>()?);
        }
        Ok(g)
    };
    run().map_err(candle)
}

/// The samples of one training: the rows trained on and those held out.
struct Data<'a> {
    x: &'a [f64],
    t: &'a [f64],
    fit: Vec<usize>,
    held: Vec<usize>,
}

/// The best held-out error so far, its epoch and its parameters.
struct Best {
    mse: f64,
    epoch: usize,
    p: Vec<f64>,
}

/// Consecutive samples held out or trained on together.
pub(crate) const HOLDOUT_BLOCK: usize = 50;

/// Split rows `0..n` into blocks of [`HOLDOUT_BLOCK`] and hold out every
/// `round(1/share)`-th block (the last of each group): held-out samples
/// from every part of the recording, each block long enough that its
/// samples are not the neighbours of trained ones but at its ends.
fn split(n: usize, share: f64) -> (Vec<usize>, Vec<usize>) {
    let every = (1.0 / share).round().max(2.0) as usize;
    let (mut fit, mut held) = (Vec::with_capacity(n), Vec::new());
    for r in 0..n {
        if (r / HOLDOUT_BLOCK) % every == every - 1 {
            held.push(r);
        } else {
            fit.push(r);
        }
    }
    if held.is_empty() {
        // fewer samples than a group: hold out the last block's worth
        let k = (n / every).max(1).min(n.saturating_sub(1));
        held = fit.split_off(n - k);
    }
    (fit, held)
}

/// Train the network `p` (flat, layout of module `net`) on the rows of `x`
/// (`f` scaled inputs per row) and targets `t`, in place; the parameters
/// left in `p` are those of the best epoch on the held-out samples.
pub(crate) fn train(
    shape: Shape,
    p: &mut [f64],
    x: &[f64],
    t: &[f64],
    settings: &TrainSettings,
    rng: &mut ChaCha8Rng,
) -> Result<TrainReport> {
    let n = t.len();
    debug_assert_eq!(x.len(), n * shape.f);
    let (fit, held) = split(n, settings.holdout);
    let data = Data { x, t, fit, held };
    let start_holdout = mse(shape, p, x, t, &data.held);
    let start_train = mse(shape, p, x, t, &data.fit);
    let mut best = Best {
        mse: start_holdout,
        epoch: 0,
        p: p.to_vec(),
    };
    let epochs = run_epochs(shape, p, &data, settings, rng, &mut best).map_err(candle)?;
    p.copy_from_slice(&best.p);
    Ok(TrainReport {
        epochs,
        best_epoch: best.epoch,
        start_holdout_mse: start_holdout,
        holdout_mse: best.mse,
        train_mse: (start_train, mse(shape, p, x, t, &data.fit)),
        termination: if best.epoch < epochs {
            Termination::Converged
        } else {
            Termination::MaxIterations
        },
    })
}

/// The epochs of [`train`] in candle; returns how many ran.
fn run_epochs(
    shape: Shape,
    p: &mut [f64],
    data: &Data<'_>,
    settings: &TrainSettings,
    rng: &mut ChaCha8Rng,
    best: &mut Best,
) -> candle_core::Result<usize> {
    let f = shape.f;
    let dev = Device::Cpu;
    let vars = Vars::new(shape, p, &dev)?;
    let mut m: Vec<Tensor> = vars
        .all
        .iter()
        .map(|v| v.as_tensor().zeros_like())
        .collect::<candle_core::Result<_>>()?;
    let mut v2 = m.clone();
    let (b1, b2, eps) = ADAM;
    let batch = settings.batch.max(1);
    let mut order = data.fit.clone();
    let mut xb = Vec::with_capacity(batch * f);
    let mut tb = Vec::with_capacity(batch);
    let mut step = 0i32;
    let mut epochs = 0;
    for epoch in 1..=settings.epochs {
        order.shuffle(rng);
        for chunk in order.chunks(batch) {
            xb.clear();
            tb.clear();
            for &r in chunk {
                xb.extend_from_slice(&data.x[r * f..(r + 1) * f]);
                tb.push(data.t[r]);
            }
            let xt = Tensor::from_slice(&xb, (chunk.len(), f), &dev)?;
            let tt = Tensor::from_slice(&tb, (chunk.len(), 1), &dev)?;
            let loss = vars.forward(&xt)?.sub(&tt)?.sqr()?.mean_all()?;
            let grads = loss.backward()?;
            step = step.saturating_add(1);
            let c1 = 1.0 - b1.powi(step);
            let c2 = 1.0 - b2.powi(step);
            for (i, var) in vars.all.iter().enumerate() {
                let Some(g) = grads.get(var.as_tensor()) else {
                    continue;
                };
                // the moments carry no graph (a gradient computed from the
                // variables would otherwise chain every step to the last)
                let g = g.detach();
                m[i] = (m[i].affine(b1, 0.0)? + g.affine(1.0 - b1, 0.0)?)?.detach();
                v2[i] = (v2[i].affine(b2, 0.0)? + g.sqr()?.affine(1.0 - b2, 0.0)?)?.detach();
                let denom = v2[i].affine(1.0 / c2, 0.0)?.sqrt()?.affine(1.0, eps)?;
                let delta = m[i].affine(settings.learning_rate / c1, 0.0)?.div(&denom)?;
                var.set(&var.as_tensor().detach().sub(&delta)?)?;
            }
        }
        epochs = epoch;
        vars.write(p)?;
        let e = mse(shape, p, data.x, data.t, &data.held);
        if e.is_finite() && e < best.mse {
            best.mse = e;
            best.epoch = epoch;
            best.p.copy_from_slice(p);
        } else if epoch - best.epoch >= settings.patience {
            break;
        }
    }
    Ok(epochs)
}
