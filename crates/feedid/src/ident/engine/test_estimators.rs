//! Estimators for the engine's tests (batch and stream alike).

use std::ops::Range;

use crate::error::Result;
use crate::ident::{Estimator, PredictStatus, Signals, WindowFit};
use crate::solve::Termination;

/// Holds the last position, except on window `wild` (counted from 1 after
/// the last reset), where it predicts `jump` away; counts its restarts.
pub(crate) struct Wild {
    k: usize,
    wild: usize,
    jump: f64,
    /// Calls of [`Estimator::restart`].
    pub(crate) restarts: usize,
}

impl Wild {
    pub(crate) fn new(wild: usize, jump: f64) -> Self {
        Self {
            k: 0,
            wild,
            jump,
            restarts: 0,
        }
    }
}

impl Estimator for Wild {
    fn name(&self) -> &'static str {
        "wild"
    }
    fn coefficient_names(&self) -> Vec<String> {
        vec![]
    }
    fn reset(&mut self) {
        self.k = 0;
    }
    fn restart(&mut self) {
        self.restarts += 1;
    }
    fn fit(&mut self, _: &Signals<'_>, _: Range<usize>, _: &mut [f64]) -> Result<WindowFit> {
        self.k += 1;
        Ok(WindowFit::identified(0.0, 0, Termination::Exact))
    }
    fn predict(
        &mut self,
        s: &Signals<'_>,
        w: Range<usize>,
        _: Range<usize>,
        out: &mut [f64],
    ) -> Result<PredictStatus> {
        let last = s.window(w.end - 1..w.end, 0, "test")?.position[0];
        let jump = if self.k == self.wild { self.jump } else { 0.0 };
        out.fill(last + jump);
        Ok(PredictStatus::Predicted)
    }
}
