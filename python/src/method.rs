//! Method options (keyword arguments) → a library [`Method`], as the
//! command-line tool's `--order`, `--solver`, `--time-origin`,
//! `--prediction`, `--lambda` and `--tolerance` do: an option the method does
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
    /// RLS forgetting factor.
    pub lambda: Option<f64>,
    /// Auto method: tolerance \[µm\].
    pub tolerance: Option<f64>,
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
        if let Some(t) = self.tolerance {
            match &mut m {
                Method::Auto(c) => c.tolerance = t * 1e-6,
                _ => return Err(refuse("tolerance", "auto", &m)),
            }
        }
        m.validate().py_err()?;
        Ok(m)
    }
}
