//! Settings of `nn` and the options they answer to.

use crate::error::{Error, Result};
use crate::ident::methods::regressor::{ArxOrders, ORDER_OPTION};
use crate::ident::option::{
    MethodOption, MethodSettings, OptionKind, OptionRange, OptionSpec, OptionValue,
};

use super::estimator::NnEstimator;

/// Most samples a network is trained on ([`NnConfig::train_samples`]): the
/// bound on the memory its training set takes (≤ 80 MB at the largest orders).
pub const MAX_TRAIN_SAMPLES: usize = 1_000_000;
/// Most neurons per hidden layer ([`NnConfig::hidden`]).
pub const MAX_HIDDEN: usize = 256;
/// Most epochs of a batch training ([`NnConfig::epochs`]).
pub const MAX_EPOCHS: usize = 10_000;
/// Most online gradient steps per window ([`NnConfig::online_steps`]).
pub const MAX_ONLINE_STEPS: usize = 100;
/// Fewest samples the first training needs ([`NnConfig::train_samples`] may not be lower).
pub const MIN_TRAIN_SAMPLES: usize = 100;

/// Settings of the neural NARX predictor (`--method nn`).
#[derive(Debug, Clone, PartialEq)]
pub struct NnConfig {
    /// Lags of the unit-gain regressor `na,nb,nk` (past positions, command
    /// terms, command delay in samples; as `auto`'s models). Default `8,8,0`
    /// (chosen on the drive zoo: 4,4,0 cannot hold a dead time with
    /// feed-forward, median error 1.33× the best fixed method's against 1.10×).
    pub orders: ArxOrders,
    /// Neurons in each of the two `tanh` hidden layers. Default 16.
    pub hidden: usize,
    /// Samples the network is trained on, counted from the command's first
    /// motion: it trains when it has 100, again at every doubling, last at
    /// this many, then predicts with what it learnt (plus the online
    /// steps). Default 20 000 (4 s at 5 kHz).
    pub train_samples: usize,
    /// Most passes over the training samples per training (early stopping
    /// on every fifth block of 50 samples, held out, usually ends it
    /// sooner). Default 30; 0
    /// keeps the starting network (the least-squares unit-gain ARX model of
    /// the training samples: the network's linear part, its hidden layers
    /// idle).
    pub epochs: usize,
    /// Adam's step size, for batch training and online steps. Default 3e-3
    /// (on the drive zoo: 90th percentile of the error ratio 3.70 against
    /// 4.16 at 1e-3).
    pub learning_rate: f64,
    /// Gradient steps per window on the window's newest samples once the
    /// network has trained (the online regime, to follow a drive that
    /// changes). Default 0: trained on the first part, then fixed.
    pub online_steps: usize,
    /// Seed of the initial weights and of the order of the mini-batches.
    /// Default 0.
    pub seed: usize,
}

impl Default for NnConfig {
    fn default() -> Self {
        Self {
            orders: ArxOrders::new(8, 8, 0),
            hidden: 16,
            train_samples: 20_000,
            epochs: 30,
            learning_rate: 3e-3,
            online_steps: 0,
            seed: 0,
        }
    }
}

const HIDDEN_OPTION: OptionSpec = OptionSpec {
    key: "hidden",
    python: None,
    value_name: "N",
    kind: OptionKind::Int,
    range: Some(OptionRange {
        min: 1.0,
        min_open: false,
        max: MAX_HIDDEN as f64,
        max_open: false,
    }),
    unit: None,
    help: "neurons in each of the network's two tanh hidden layers",
    requires: None,
};

const TRAIN_OPTION: OptionSpec = OptionSpec {
    key: "train_samples",
    python: None,
    value_name: "N",
    kind: OptionKind::Int,
    range: Some(OptionRange {
        min: MIN_TRAIN_SAMPLES as f64,
        min_open: false,
        max: MAX_TRAIN_SAMPLES as f64,
        max_open: false,
    }),
    unit: Some("samples"),
    help: "samples from the command's first motion on that the network is trained on (it \
           trains at 100, at every doubling, last at this many; then it predicts with what \
           it learnt)",
    requires: None,
};

const EPOCHS_OPTION: OptionSpec = OptionSpec {
    key: "epochs",
    python: None,
    value_name: "N",
    kind: OptionKind::Int,
    range: Some(OptionRange {
        min: 0.0,
        min_open: false,
        max: MAX_EPOCHS as f64,
        max_open: false,
    }),
    unit: None,
    help: "most passes over the training samples per training (early stopping on the \
           held-out fifth of the samples); 0 keeps the least-squares linear part alone",
    requires: None,
};

const LEARNING_RATE_OPTION: OptionSpec = OptionSpec {
    key: "learning_rate",
    python: None,
    value_name: "RATE",
    kind: OptionKind::Float,
    range: Some(OptionRange {
        min: 0.0,
        min_open: true,
        max: 1.0,
        max_open: false,
    }),
    unit: None,
    help: "Adam's step size (batch training and online steps)",
    requires: None,
};

const ONLINE_OPTION: OptionSpec = OptionSpec {
    key: "online_steps",
    python: None,
    value_name: "N",
    kind: OptionKind::Int,
    range: Some(OptionRange {
        min: 0.0,
        min_open: false,
        max: MAX_ONLINE_STEPS as f64,
        max_open: false,
    }),
    unit: None,
    help: "gradient steps per window on its newest samples once trained (online \
           learning, to follow a drive that changes); 0: fixed after training",
    requires: None,
};

const SEED_OPTION: OptionSpec = OptionSpec {
    key: "nn_seed",
    python: None,
    value_name: "N",
    kind: OptionKind::Int,
    range: None,
    unit: None,
    help: "seed of the network's initial weights and mini-batch order (the same seed \
           gives the same predictions)",
    requires: None,
};

impl MethodSettings for NnConfig {
    fn options(&self) -> &'static [MethodOption] {
        const OPTIONS: &[MethodOption] = &[
            MethodOption::new(&ORDER_OPTION),
            MethodOption::new(&HIDDEN_OPTION),
            MethodOption::new(&TRAIN_OPTION),
            MethodOption::new(&EPOCHS_OPTION),
            MethodOption::new(&LEARNING_RATE_OPTION),
            MethodOption::new(&ONLINE_OPTION),
            MethodOption::new(&SEED_OPTION),
        ];
        OPTIONS
    }

    fn option(&self, key: &str) -> Option<OptionValue> {
        Some(match key {
            "order" => OptionValue::Orders(self.orders),
            "hidden" => OptionValue::Int(self.hidden),
            "train_samples" => OptionValue::Int(self.train_samples),
            "epochs" => OptionValue::Int(self.epochs),
            "learning_rate" => OptionValue::Float(self.learning_rate),
            "online_steps" => OptionValue::Int(self.online_steps),
            "nn_seed" => OptionValue::Int(self.seed),
            _ => return None,
        })
    }

    fn set_option(&mut self, key: &str, value: &OptionValue) -> Result<()> {
        match (key, value) {
            ("order", OptionValue::Orders(o)) => {
                let mut c = self.clone();
                c.orders = *o;
                c.validate()?;
                self.orders = *o;
            }
            ("hidden", OptionValue::Int(v)) => self.hidden = *v,
            ("train_samples", OptionValue::Int(v)) => self.train_samples = *v,
            ("epochs", OptionValue::Int(v)) => self.epochs = *v,
            ("learning_rate", OptionValue::Float(v)) => self.learning_rate = *v,
            ("online_steps", OptionValue::Int(v)) => self.online_steps = *v,
            ("nn_seed", OptionValue::Int(v)) => self.seed = *v,
            _ => {
                return Err(Error::UnknownOption {
                    key: key.to_string(),
                    known: "order, hidden, train_samples, epochs, learning_rate, online_steps, \
                            nn_seed"
                        .to_string(),
                })
            }
        }
        Ok(())
    }
}

impl NnConfig {
    /// Check the settings: orders with `na ≥ 1` (the regressor is written
    /// from the last measured position), every size within its bound.
    pub fn validate(&self) -> Result<()> {
        self.orders.validate()?;
        if self.orders.na == 0 {
            return Err(Error::InvalidParameter {
                name: "na",
                value: 0.0,
                reason:
                    "must be at least 1 for nn (its inputs are positions relative to the last one)",
            });
        }
        let bound = |name: &'static str, v: usize, lo: usize, hi: usize, reason: &'static str| {
            if v < lo || v > hi {
                Err(Error::InvalidParameter {
                    name,
                    value: v as f64,
                    reason,
                })
            } else {
                Ok(())
            }
        };
        bound("hidden", self.hidden, 1, MAX_HIDDEN, "must be in [1, 256]")?;
        bound(
            "train_samples",
            self.train_samples,
            MIN_TRAIN_SAMPLES,
            MAX_TRAIN_SAMPLES,
            "must be in [100, 1000000]",
        )?;
        bound(
            "epochs",
            self.epochs,
            0,
            MAX_EPOCHS,
            "must be in [0, 10000]",
        )?;
        bound(
            "online_steps",
            self.online_steps,
            0,
            MAX_ONLINE_STEPS,
            "must be in [0, 100]",
        )?;
        if !(self.learning_rate > 0.0 && self.learning_rate <= 1.0) {
            return Err(Error::InvalidParameter {
                name: "learning_rate",
                value: self.learning_rate,
                reason: "must be in (0, 1]",
            });
        }
        Ok(())
    }

    /// Validate and build the estimator.
    pub fn build(&self) -> Result<NnEstimator> {
        self.validate()?;
        Ok(NnEstimator::new(self.clone()))
    }
}
