//! Settings of the windowed ARX estimator.

// Negated comparisons are deliberate (they reject NaN).
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use super::estimator::ArxEstimator;
use crate::error::{Error, Result};
use crate::ident::methods::regressor::{ArxOrders, ORDER_OPTION, RIDGE_OPTION};
use crate::ident::option::{MethodOption, MethodSettings, OptionValue};

impl MethodSettings for ArxConfig {
    fn options(&self) -> &'static [MethodOption] {
        const OPTIONS: &[MethodOption] = &[
            MethodOption::new(&ORDER_OPTION),
            MethodOption::new(&RIDGE_OPTION),
        ];
        OPTIONS
    }

    fn option(&self, key: &str) -> Option<OptionValue> {
        match key {
            "order" => Some(OptionValue::Orders(self.orders)),
            "ridge" => Some(OptionValue::Float(self.ridge)),
            _ => None,
        }
    }

    fn set_option(&mut self, key: &str, value: &OptionValue) -> Result<()> {
        match (key, value) {
            ("order", OptionValue::Orders(o)) => {
                o.validate()?;
                self.orders = *o;
            }
            ("ridge", OptionValue::Float(r)) => self.ridge = *r,
            _ => {
                return Err(Error::UnknownOption {
                    key: key.to_string(),
                    known: "order, ridge".to_string(),
                })
            }
        }
        Ok(())
    }
}

/// Configuration of the windowed ARX estimator.
///
/// The defaults (orders 3,3,0 with the current command sample, engine
/// window W = 100, a small ridge, no DC-gain or excitation gate) were chosen
/// on the drive zoo ([`crate::zoo`], example
/// `zoo_sweep`), not on one rig: the command is a planned trajectory, so its
/// value at the predicted instant is known and nk = 0 uses it; a gate or a
/// gain bound withholds predictions on drives unlike the rig.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArxConfig {
    /// Model orders; default `na = 3, nb = 3, nk = 0`.
    pub orders: ArxOrders,
    /// Relative ridge `ρ` on the column-normalised coefficients; default 1e-10.
    pub ridge: f64,
    /// Poles must lie strictly inside this radius; default 1.0 (stable).
    /// `f64::INFINITY` disables the stability check.
    /// `f64::INFINITY` disables the stability check.
    pub max_pole_radius: f64,
    /// Accepted DC gain `B(1)/A(1)` interval (a position
    /// servo has gain 1); default `(−∞, ∞)`: no check.
    pub dc_gain_bounds: (f64, f64),
    /// Minimum standard deviation of the command over the window's rows \[m\];
    /// below it the window is a standstill and the last model is kept.
    /// Default 0 (every window is fitted; the ridge keeps standstills defined).
    pub min_excitation: f64,
    /// Largest condition estimate of the column-scaled regression; above it
    /// the window counts as rank deficient. Default ∞: with the ridge the
    /// solution stays defined on collinear data (on a constant-speed ramp
    /// the command columns span only `{1, k}`, condition ~1e15) and such
    /// windows predict well on the rig. Without ridge, a numerically rank
    /// deficient regression always counts as not informative.
    pub max_condition: f64,
    /// At most this many windows between two factorisations from scratch;
    /// default 64. (The sliding update rebuilds every `⌈W/hop⌉` windows
    /// anyway and has no drift to bound; 1 refactors every window.)
    pub refactor_every: usize,
    /// Use the exact sliding update when windows overlap (default true);
    /// `false` factors every window from scratch (same result to rounding, slower).
    pub sliding: bool,
    /// Estimate an offset `c` as well, `A·ỹ = B·ũ + c` (coefficient name `"c"`);
    /// default false (a position servo has unit DC gain and needs none). Use
    /// it for systems whose DC gain is not 1.
    pub offset: bool,
}

impl Default for ArxConfig {
    fn default() -> Self {
        Self {
            orders: ArxOrders::new(3, 3, 0),
            ridge: 1e-10,
            max_pole_radius: 1.0,
            dc_gain_bounds: (f64::NEG_INFINITY, f64::INFINITY),
            min_excitation: 0.0,
            max_condition: f64::INFINITY,
            refactor_every: 64,
            sliding: true,
            offset: false,
        }
    }
}

impl ArxConfig {
    /// Validate and build the estimator.
    pub fn build(self) -> Result<ArxEstimator> {
        self.validate()?;
        Ok(ArxEstimator::new(self))
    }

    /// Check every setting.
    pub fn validate(&self) -> Result<()> {
        self.orders.validate()?;
        for (name, v) in [
            ("ridge", self.ridge),
            ("min_excitation", self.min_excitation),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::InvalidParameter {
                    name,
                    value: v,
                    reason: "must be finite and >= 0",
                });
            }
        }
        if !(self.max_pole_radius > 0.0) {
            return Err(Error::InvalidParameter {
                name: "max_pole_radius",
                value: self.max_pole_radius,
                reason: "must be > 0",
            });
        }
        if !(self.max_condition > 1.0) {
            return Err(Error::InvalidParameter {
                name: "max_condition",
                value: self.max_condition,
                reason: "must be > 1",
            });
        }
        let (lo, hi) = self.dc_gain_bounds;
        if lo.is_nan() || hi.is_nan() || lo >= hi {
            return Err(Error::InvalidParameter {
                name: "dc_gain_bounds",
                value: lo,
                reason: "need lower < upper",
            });
        }
        if self.refactor_every == 0 {
            return Err(Error::InvalidParameter {
                name: "refactor_every",
                value: 0.0,
                reason: "must be at least 1",
            });
        }
        Ok(())
    }
}
