//! Method options (keyword arguments) → a library [`Method`], as the
//! command-line tool's `--order`, `--solver`, `--time-origin`,
//! `--prediction`, `--simplex-start`, `--lambda` and `--ridge` do: an option the method does
//! not have is an error naming the methods it applies to.

use feedid::ident::{ArxOrders, Method};
use pyo3::prelude::*;

use crate::errors::{input, IntoPy};

/// The method options of `identify` and `Streamer`.
#[derive(Debug, Default, Clone)]
pub struct MethodOptions {
    /// `na,nb,nk` or `auto` (identify only).
    pub order: Option<String>,
    /// Paper method: solver name.
    pub solver: Option<String>,
    /// Paper method: time origin name.
    pub time_origin: Option<String>,
    /// Paper method: prediction mode name.
    pub prediction: Option<String>,
    /// Paper method: simplex start name.
    pub simplex_start: Option<String>,
    /// RLS forgetting factor.
    pub lambda: Option<f64>,
    /// ARX and auto: ridge of the least squares.
    pub ridge: Option<f64>,
}

/// What `order` asks for.
pub enum OrderOption {
    /// These orders.
    Orders(ArxOrders),
    /// Choose them from the recording.
    Select,
}

impl MethodOptions {
    /// `order`, parsed.
    pub fn order_option(&self) -> PyResult<Option<OrderOption>> {
        let Some(o) = self.order.as_deref() else {
            return Ok(None);
        };
        if o.trim().eq_ignore_ascii_case("auto") {
            return Ok(Some(OrderOption::Select));
        }
        let bad = || {
            input(format!(
                "invalid order `{o}`: expected na,nb,nk (e.g. 8,8,1)"
            ))
        };
        let v: Vec<usize> = o
            .split(',')
            .map(|x| x.trim().parse().map_err(|_| bad()))
            .collect::<PyResult<_>>()?;
        match v.as_slice() {
            [na, nb, nk] => Ok(Some(OrderOption::Orders(ArxOrders::new(*na, *nb, *nk)))),
            _ => Err(bad()),
        }
    }

    /// The method `name` with these options.
    pub fn method(&self, name: &str) -> PyResult<Method> {
        let mut m: Method = name.parse().py_err()?;
        let refuse = |option: &str, applies_to: &str, m: &Method| {
            input(format!(
                "{option} does not apply to method {} (only to {applies_to})",
                m.name()
            ))
        };
        if let Some(s) = &self.solver {
            let v = s.parse().py_err()?;
            match &mut m {
                Method::Paper(c) => c.solver = v,
                _ => return Err(refuse("solver", "paper", &m)),
            }
        }
        if let Some(s) = &self.time_origin {
            let v = s.parse().py_err()?;
            match &mut m {
                Method::Paper(c) => c.time_origin = v,
                _ => return Err(refuse("time_origin", "paper", &m)),
            }
        }
        if let Some(s) = &self.prediction {
            let v = s.parse().py_err()?;
            match &mut m {
                Method::Paper(c) => c.prediction = v,
                _ => return Err(refuse("prediction", "paper", &m)),
            }
        }
        if let Some(s) = &self.simplex_start {
            let v = s.parse().py_err()?;
            match &mut m {
                Method::Paper(c) => c.simplex_start = v,
                _ => return Err(refuse("simplex_start", "paper", &m)),
            }
        }
        match self.order_option()? {
            Some(OrderOption::Orders(o)) => match m.set_orders(o) {
                Ok(()) => {}
                Err(feedid::Error::NotApplicable { .. }) => {
                    return Err(refuse("order", "arx, rls, auto", &m))
                }
                Err(e) => {
                    return Err(input(format!(
                        "order {}: {e}",
                        self.order.as_deref().unwrap_or_default()
                    )))
                }
            },
            Some(OrderOption::Select) if m.orders().is_none() => {
                return Err(refuse("order", "arx, rls, auto", &m))
            }
            _ => {}
        }
        if let Some(l) = self.lambda {
            match &mut m {
                Method::Rls(c) => c.lambda = l,
                _ => return Err(refuse("lambda", "rls", &m)),
            }
        }
        if let Some(r) = self.ridge {
            match &mut m {
                Method::Arx(c) => c.ridge = r,
                Method::Auto(c) => c.set_ridge(r),
                _ => return Err(refuse("ridge", "arx, auto", &m)),
            }
        }
        m.validate().py_err()?;
        Ok(m)
    }
}

/// The runaway factor (`--runaway`): ≥ 1, or `None` (off).
pub fn runaway(factor: Option<f64>) -> PyResult<Option<f64>> {
    match factor {
        #[allow(clippy::neg_cmp_op_on_partial_ord)] // rejects NaN
        Some(k) if !(k.is_finite() && k >= 1.0) => Err(input(format!(
            "invalid runaway {k}: a factor ≥ 1 (default 1.5), or None to keep every prediction as the method made it"
        ))),
        k => Ok(k),
    }
}

/// The probability of the prediction intervals \[%\] → a fraction, checked
/// as `--interval` is.
pub fn interval(percent: f64) -> PyResult<f64> {
    #[allow(clippy::neg_cmp_op_on_partial_ord)] // rejects NaN
    if !(percent > 0.0 && percent < 100.0) {
        return Err(input(format!(
            "invalid interval {percent}: the probability of the prediction intervals must be in (0, 100) % (e.g. 95)"
        )));
    }
    Ok(percent / 100.0)
}
