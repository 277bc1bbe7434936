//! Settings of `auto`.

// Negated comparisons are deliberate (they reject NaN).
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use super::candidate::Candidate;
use super::estimator::AutoEstimator;
use crate::error::{Error, Result};
use crate::ident::methods::regressor::{ArxOrders, ORDER_OPTION, RIDGE_OPTION};
use crate::ident::option::{MethodOption, MethodSettings, OptionValue};

impl MethodSettings for AutoConfig {
    fn options(&self) -> &'static [MethodOption] {
        const OPTIONS: &[MethodOption] = &[
            MethodOption::of(&ORDER_OPTION, "its long-memory candidate"),
            MethodOption::of(&RIDGE_OPTION, "its windowed candidates"),
        ];
        OPTIONS
    }

    fn option(&self, key: &str) -> Option<OptionValue> {
        match key {
            "order" => self.orders().map(OptionValue::Orders),
            "ridge" => self.candidates.iter().find_map(|c| match c {
                Candidate::Windowed { ridge, .. } => Some(OptionValue::Float(*ridge)),
                _ => None,
            }),
            _ => None,
        }
    }

    fn set_option(&mut self, key: &str, value: &OptionValue) -> Result<()> {
        match (key, value) {
            ("order", OptionValue::Orders(o)) => {
                o.validate()?;
                self.set_orders(*o)
            }
            ("ridge", OptionValue::Float(r)) => {
                self.set_ridge(*r);
                Ok(())
            }
            _ => Err(Error::UnknownOption {
                key: key.to_string(),
                known: "order, ridge".to_string(),
            }),
        }
    }
}

/// Settings of the `auto` method.
#[derive(Debug, Clone, PartialEq)]
pub struct AutoConfig {
    /// The candidate predictors; default [`AutoConfig::default_candidates`].
    pub candidates: Vec<Candidate>,
    /// Weight α of the newest horizon in a candidate's score (per regime),
    /// in (0, 1]; default 0.1 (chosen on the drive zoo).
    pub memory: f64,
    /// A candidate's prediction is discarded when it leaves the last
    /// measured position by more than this factor times the experienced
    /// motion (the largest range of the measured position over `H + 1`
    /// consecutive samples so far), ≥ 1; default 4. Until the axis has
    /// moved, only predictions that stay where it is pass.
    pub plausibility: f64,
    /// A candidate whose prediction departs from the candidates' consensus
    /// — at some step of the horizon more than half of their predictions
    /// lie on one side of it by more than this factor times its own recent
    /// rms error (odd count: its distance from their median exceeds that),
    /// and no other candidate stays within that distance of it —
    /// does not predict that horizon (a model thrown off by a motion it has not seen, such as a
    /// jerk of the command); > 0, `∞` disables; default 20 (chosen on the
    /// drive zoo: 5 … 30 give the same losses, but 5 and 30 make single
    /// recordings far worse).
    pub consensus: f64,
}

impl Default for AutoConfig {
    fn default() -> Self {
        Self {
            candidates: Self::default_candidates(),
            memory: 0.1,
            plausibility: 4.0,
            consensus: 20.0,
        }
    }
}

impl AutoConfig {
    /// The default candidates (see the module doc of `auto`).
    pub fn default_candidates() -> Vec<Candidate> {
        let rls = |na, nb, lambda| Candidate::Recursive {
            orders: ArxOrders::new(na, nb, 0),
            lambda,
            bias: false,
        };
        let ls = |bias| Candidate::Windowed {
            orders: ArxOrders::new(2, 2, 0),
            window: 100,
            ridge: 0.0,
            bias,
        };
        vec![
            ls(false),
            ls(true),
            Candidate::Recursive {
                orders: ArxOrders::new(3, 3, 0),
                lambda: 0.99,
                bias: true,
            },
            rls(3, 3, 0.995),
            rls(4, 4, 0.999),
            rls(6, 6, 0.999),
            rls(8, 8, 0.9995),
            Candidate::CommandAtRest,
        ]
    }

    /// Index of the candidate whose orders `--order` sets and whose
    /// coefficients are reported: the recursive candidate with the longest
    /// memory (largest λ; the first of equals), else the windowed one with
    /// the longest window; `None` without an identified candidate.
    pub fn reported(&self) -> Option<usize> {
        let memory = |c: &Candidate| match *c {
            Candidate::Recursive { lambda, .. } => Some((1, lambda)),
            Candidate::Windowed { window, .. } => Some((0, window as f64)),
            Candidate::Hold | Candidate::Command | Candidate::CommandAtRest => None,
        };
        let mut best: Option<(usize, (i32, f64))> = None;
        for (i, c) in self.candidates.iter().enumerate() {
            if let Some(m) = memory(c) {
                if best.is_none_or(|(_, b)| m.0 > b.0 || (m.0 == b.0 && m.1 > b.1)) {
                    best = Some((i, m));
                }
            }
        }
        best.map(|(i, _)| i)
    }

    /// The orders of the reported candidate ([`AutoConfig::reported`]).
    pub fn orders(&self) -> Option<ArxOrders> {
        self.reported().and_then(|i| self.candidates[i].orders())
    }

    /// Set the orders of the reported candidate ([`AutoConfig::reported`]);
    /// an error without an identified candidate or for invalid orders.
    pub fn set_orders(&mut self, orders: ArxOrders) -> Result<()> {
        let i = self.reported().ok_or(Error::InvalidParameter {
            name: "orders",
            value: 0.0,
            reason: "auto has no identified candidate to take them",
        })?;
        let mut c = self.candidates[i];
        match &mut c {
            Candidate::Recursive { orders: o, .. } | Candidate::Windowed { orders: o, .. } => {
                *o = orders
            }
            Candidate::Hold | Candidate::Command | Candidate::CommandAtRest => {}
        }
        c.validate()?;
        self.candidates[i] = c;
        Ok(())
    }

    /// Set the ridge of every windowed candidate (relative, ≥ 0; checked
    /// by [`AutoConfig::validate`]).
    pub fn set_ridge(&mut self, ridge: f64) {
        for c in &mut self.candidates {
            if let Candidate::Windowed { ridge: r, .. } = c {
                *r = ridge;
            }
        }
    }

    /// Validate and build the estimator.
    pub fn build(&self) -> Result<AutoEstimator> {
        self.validate()?;
        Ok(AutoEstimator::new(self.clone()))
    }

    /// Check the settings (at least one candidate, each valid; memory in
    /// (0, 1], plausibility ≥ 1, consensus > 0).
    pub fn validate(&self) -> Result<()> {
        if self.candidates.is_empty() {
            return Err(Error::InvalidParameter {
                name: "candidates",
                value: 0.0,
                reason: "auto needs at least one candidate",
            });
        }
        for c in &self.candidates {
            c.validate()?;
        }
        if !(self.memory > 0.0 && self.memory <= 1.0) {
            return Err(Error::InvalidParameter {
                name: "memory",
                value: self.memory,
                reason: "must be in (0, 1]",
            });
        }
        if !(self.plausibility.is_finite() && self.plausibility >= 1.0) {
            return Err(Error::InvalidParameter {
                name: "plausibility",
                value: self.plausibility,
                reason: "must be finite and >= 1",
            });
        }
        if !(self.consensus > 0.0) {
            return Err(Error::InvalidParameter {
                name: "consensus",
                value: self.consensus,
                reason: "must be > 0 (infinity disables it)",
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The order docs/METHODS.md gives for the `candidate` column of `coef.csv`
    /// (an index into this list).
    #[test]
    fn the_default_candidates_are_in_the_order_the_methods_doc_numbers_them() {
        let names: Vec<String> = AutoConfig::default_candidates()
            .iter()
            .map(|c| c.to_string())
            .collect();
        assert_eq!(
            names,
            [
                "ls 2,2,0 W=100",
                "ls 2,2,0+c W=100",
                "rls 3,3,0+c λ=0.99",
                "rls 3,3,0 λ=0.995",
                "rls 4,4,0 λ=0.999",
                "rls 6,6,0 λ=0.999",
                "rls 8,8,0 λ=0.9995",
                "command at rest",
            ]
        );
        // the reported (long-memory) candidate is the last recursive one
        assert_eq!(AutoConfig::default().reported(), Some(6));
    }
}
