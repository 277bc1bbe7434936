//! Estimators for the engine's tests (batch and stream alike): a hold
//! that predicts wildly once (`Wild`), a straight line through the last two
//! samples (`Linear`) and a command follower that fails now and then
//! (`Follow`).

use std::ops::Range;

use crate::error::{Error, Result};
use crate::ident::engine::{Estimator, PredictStatus, Signals, WindowFit};
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

/// Straight line through the last two window samples (window-end estimator).
pub(crate) struct Linear;

impl Estimator for Linear {
    fn name(&self) -> &'static str {
        "linear"
    }
    fn coefficient_names(&self) -> Vec<String> {
        vec!["last".into(), "slope".into()]
    }
    fn uses_future_command(&self) -> bool {
        false
    }
    fn fit(&mut self, s: &Signals<'_>, w: Range<usize>, c: &mut [f64]) -> Result<WindowFit> {
        let y = s.window(w.end - 2..w.end, 0, "test").unwrap().position;
        c[0] = y[1];
        c[1] = y[1] - y[0];
        Ok(WindowFit::identified(0.0, 0, Termination::Exact))
    }
    fn predict(
        &mut self,
        s: &Signals<'_>,
        w: Range<usize>,
        _: Range<usize>,
        out: &mut [f64],
    ) -> Result<PredictStatus> {
        let y = s.window(w.end - 2..w.end, 0, "test").unwrap().position;
        for (j, o) in out.iter_mut().enumerate() {
            *o = y[1] + (j as f64 + 1.0) * (y[1] - y[0]);
        }
        Ok(PredictStatus::Predicted)
    }
}

/// Last position plus the command change over the horizon; reads one
/// sample before the window (warm-up 1) and fails on every `fail`-th window
/// (never if 0).
pub(crate) struct Follow {
    k: usize,
    fail: usize,
}

/// `Follow` failing on every 7th window.
pub(crate) fn follow7() -> Follow {
    Follow { k: 0, fail: 7 }
}

/// `Follow` that never fails.
pub(crate) fn follow() -> Follow {
    Follow { k: 0, fail: 0 }
}

impl Estimator for Follow {
    fn name(&self) -> &'static str {
        "follow"
    }
    fn coefficient_names(&self) -> Vec<String> {
        vec!["gain".into()]
    }
    fn warm_up(&self) -> usize {
        1
    }
    fn reset(&mut self) {
        self.k = 0;
    }
    fn fit(&mut self, s: &Signals<'_>, w: Range<usize>, c: &mut [f64]) -> Result<WindowFit> {
        self.k += 1;
        if self.fail > 0 && self.k.is_multiple_of(self.fail) {
            return Err(Error::Singular { context: "test" });
        }
        let u = s.window(w.start - 1..w.end, 0, "test").unwrap().command;
        let y = s.window(w.start - 1..w.end, 0, "test").unwrap().position;
        let du = u[u.len() - 1] - u[0];
        c[0] = if du != 0.0 {
            (y[y.len() - 1] - y[0]) / du
        } else {
            1.0
        };
        Ok(WindowFit::identified(0.0, 0, Termination::Exact))
    }
    fn predict(
        &mut self,
        s: &Signals<'_>,
        w: Range<usize>,
        h: Range<usize>,
        out: &mut [f64],
    ) -> Result<PredictStatus> {
        let y0 = s.window(w.end - 1..w.end, 0, "test").unwrap().position[0];
        let u0 = s.window(w.end - 1..w.end, 0, "test").unwrap().command[0];
        for (o, &u) in out.iter_mut().zip(s.window(h, 0, "test").unwrap().command) {
            *o = y0 + (u - u0);
        }
        Ok(PredictStatus::Predicted)
    }
}
