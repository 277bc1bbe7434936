//! `nn`: a neural NARX predictor of the feed drive — the comparison the
//! paper's outlook asks for ("other techniques such as neural networks …
//! compared with the current method").
//!
//! # Model
//!
//! The network predicts the next position increment from the same
//! *unit-gain regressor written from the last measured position* that makes
//! `auto` free of units and offsets (docs/METHODS.md, `auto`):
//!
//! ```text
//! x_k = [y[k−2] − y[k−1], …, y[k−na] − y[k−1],  u[k−nk] − y[k−1], …, u[k−nk−nb+1] − y[k−1]],
//! y[k] − y[k−1] = σ_t · f(x_k ⊘ σ_x),
//! f(z) = w₃ᵀ tanh(W₂ᵀ tanh(W₁ᵀz + b₁) + b₂) + b₃ + lᵀz,
//! ```
//!
//! a multilayer perceptron with two `tanh` hidden layers of
//! [`NnConfig::hidden`] neurons and a *linear bypass* `lᵀz` (as MATLAB's
//! `idnlarx` networks and SysIdentPy's neural NARX keep a linear term).
//! `σ_x` (per input) and `σ_t` are the rms values of the inputs and the
//! target over the training samples: a change of unit scales them alike,
//! an offset cancels in the differences, so the predictions do not depend
//! on either. Over a horizon the network runs forward on its own predicted
//! positions and the known command (the command is the set-point, known
//! ahead), from the last measured position.
//!
//! # Training (first regime)
//!
//! The network learns from every sample from the command's first motion
//! on (a rest before it would only teach it to stand still). It trains
//! when 100 such samples have arrived, again at every doubling, and last at
//! [`NnConfig::train_samples`] (default 20 000); then it predicts with what
//! it learnt. Before its first training it gives no prediction (the
//! windows fail: "not trained yet", counted like every failed window). Each
//! training starts from
//!
//! - the linear part `l, b₃` by least squares (SVD) on the scaled samples
//!   and the output weights `w₃ = 0`: the starting network *is* the
//!   least-squares unit-gain ARX model of the training samples;
//! - the hidden layers Glorot-uniform from [`NnConfig::seed`] (ChaCha8),
//!
//! then runs Adam (Kingma & Ba, 2015; step size
//! [`NnConfig::learning_rate`]) on mini-batches of 64 in an order drawn from
//! the same seed, in candle (automatic differentiation, `f64` on the CPU),
//! for at most [`NnConfig::epochs`] epochs, holding out every fifth block
//! of 50 consecutive training samples and keeping the epoch with the
//! lowest held-out one-step error, epoch 0 included — so a training never
//! returns a network worse on the held-out samples than the linear model it
//! started from, and it stops after 5 epochs without improvement.
//!
//! # Online steps (second regime)
//!
//! With [`NnConfig::online_steps`] = `n > 0`, every window after the first
//! training takes `n` Adam steps on the mean squared one-step error of its
//! newest 64 samples, with the gradient written out by hand (module `net`,
//! checked against candle's automatic differentiation and against finite
//! differences), allocating nothing — so the network follows a drive that
//! changes.
//!
//! # Engine
//!
//! `nn` is an [`Estimator`](crate::ident::Estimator) like every other
//! method: the sliding engine, its runaway guard and calibrated intervals,
//! the pipeline, the streamer, reports, sweeps and the Python package take
//! it without a special case. A guard's restart keeps the network (it is
//! not relearnt from a few samples); a gap keeps it; a change of the sample
//! interval starts afresh. The same seed gives the same predictions.

mod config;
mod estimator;
mod net;
mod train;

pub use config::NnConfig;
pub use estimator::NnEstimator;
pub use train::TrainReport as NnTraining;

#[cfg(test)]
mod tests;
