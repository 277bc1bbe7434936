//! Method options (keyword arguments) → a library [`Method`], as the
//! command-line tool's option flags do, both derived from the library's
//! option descriptions ([`Method::options`]): one keyword per option (its
//! Python keyword, e.g. `lambda_`), set through [`Method::set_option`]; an
//! option the method does not have is an error naming the methods it
//! applies to.

use feedid::error::Syntax;
use feedid::ident::{Method, OptionKind, OptionValue};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::errors::{input, IntoPy};

/// The method options of `identify` and `Streamer`: the keyword arguments
/// given, by library key, as text.
#[derive(Debug, Default, Clone)]
pub struct MethodOptions {
    /// Key (`"lambda"`) and value as text, in the order of [`Method::options`].
    pub values: Vec<(&'static str, String)>,
}

/// What `order` asks for.
pub enum OrderOption {
    /// These orders (`na,nb,nk`).
    Orders,
    /// Choose them from the recording.
    Select,
}

impl MethodOptions {
    /// The method options among the keyword arguments `kwargs` (by their
    /// Python keywords; `None` values are not given); another keyword is a
    /// `TypeError`, as for any function.
    pub fn from_kwargs(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let mut values = Vec::new();
        let Some(kwargs) = kwargs else {
            return Ok(Self { values });
        };
        let options = Method::options();
        for k in kwargs.keys() {
            let k: String = k.extract()?;
            if !options.iter().any(|o| o.spec.python_keyword() == k) {
                return Err(PyTypeError::new_err(format!(
                    "got an unexpected keyword argument '{k}'"
                )));
            }
        }
        for o in &options {
            let kw = o.spec.python_keyword();
            let Some(v) = kwargs.get_item(kw)? else {
                continue;
            };
            if v.is_none() {
                continue;
            }
            let wrong =
                |what: &str| PyTypeError::new_err(format!("argument '{kw}': must be {what}"));
            let text = match o.spec.kind {
                OptionKind::Float => v
                    .extract::<f64>()
                    .map_err(|_| wrong("a real number"))?
                    .to_string(),
                OptionKind::Int => v
                    .extract::<usize>()
                    .map_err(|_| wrong("a whole number >= 0"))?
                    .to_string(),
                OptionKind::Choice(_) | OptionKind::Orders => {
                    v.extract::<String>().map_err(|_| wrong("a str"))?
                }
            };
            values.push((o.spec.key, text));
        }
        Ok(Self { values })
    }

    /// The value of option `key`, if given.
    fn get(&self, key: &str) -> Option<&str> {
        self.values
            .iter()
            .find(|(k, _)| *k == key)
            .map(|(_, v)| v.as_str())
    }

    /// `order`, parsed.
    pub fn order_option(&self) -> PyResult<Option<OrderOption>> {
        let Some(o) = self.get("order") else {
            return Ok(None);
        };
        if is_select(o) {
            return Ok(Some(OrderOption::Select));
        }
        let spec = Method::options()
            .into_iter()
            .find(|i| i.spec.key == "order")
            .map(|i| i.spec)
            .ok_or_else(|| input("no order option"))?;
        match spec.parse(o).py_err()? {
            OptionValue::Orders(_) => Ok(Some(OrderOption::Orders)),
            _ => Err(input(format!("invalid order `{o}`"))),
        }
    }

    /// The method `name` with these options.
    pub fn method(&self, name: &str) -> PyResult<Method> {
        let mut m: Method = name.parse().py_err()?;
        for (key, value) in &self.values {
            if *key == "order" && is_select(value) {
                if !m.has_option(key) {
                    return Err(refuse(key, &m));
                }
                continue;
            }
            match m.set_option(key, value) {
                Ok(()) => {}
                Err(feedid::Error::OptionNotApplicable { .. }) => return Err(refuse(key, &m)),
                Err(
                    e @ (feedid::Error::InvalidOption { .. } | feedid::Error::InvalidChoice { .. }),
                ) => return Err(crate::errors::to_py(e)),
                Err(e) => return Err(input(format!("{key} {value}: {e}"))),
            }
        }
        m.validate().py_err()?;
        Ok(m)
    }
}

/// `order="auto"`: choose the orders from the recording.
fn is_select(value: &str) -> bool {
    value.trim().eq_ignore_ascii_case("auto")
}

/// The error for option `key` given to method `m`, which does not have it.
fn refuse(key: &str, m: &Method) -> PyErr {
    let applies = Method::options()
        .into_iter()
        .find(|o| o.spec.key == key)
        .map_or_else(String::new, |o| o.applies_to(Syntax::Python));
    input(format!(
        "{key} does not apply to method {} (only to {applies})",
        m.name()
    ))
}

/// The library's description of every method option, for the Python
/// package (its keyword checks, docstrings and stubs): a list of dicts with
/// `key`, `python` (the keyword), `flag`, `kind` (`float`, `int`, `choice`,
/// `orders`), `choices`, `value_name`, `range` (`min`, `min_open`, `max`,
/// `max_open`, `text`) or None, `unit`, `help` (with the methods and
/// defaults), `text` (what it sets), `requires` (key, value) or None,
/// `applies_to`, `defaults` and `methods` (a list of `method`, `note`,
/// `default`).
#[pyfunction]
pub fn method_options(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    let out = PyList::empty(py);
    for o in Method::options() {
        let s = o.spec;
        let d = PyDict::new(py);
        d.set_item("key", s.key)?;
        d.set_item("python", s.python_keyword())?;
        d.set_item("flag", s.flag())?;
        let (kind, choices): (&str, &[&str]) = match s.kind {
            OptionKind::Float => ("float", &[]),
            OptionKind::Int => ("int", &[]),
            OptionKind::Choice(c) => ("choice", c),
            OptionKind::Orders => ("orders", &[]),
        };
        d.set_item("kind", kind)?;
        d.set_item("choices", choices.to_vec())?;
        d.set_item("value_name", s.value_name)?;
        match s.range {
            Some(r) => {
                let rd = PyDict::new(py);
                rd.set_item("min", r.min)?;
                rd.set_item("min_open", r.min_open)?;
                rd.set_item("max", r.max)?;
                rd.set_item("max_open", r.max_open)?;
                rd.set_item("text", r.to_string())?;
                d.set_item("range", rd)?;
            }
            None => d.set_item("range", py.None())?,
        }
        d.set_item("unit", s.unit)?;
        d.set_item("help", o.help(Syntax::Python))?;
        d.set_item("text", s.help)?;
        d.set_item("requires", s.requires)?;
        d.set_item("applies_to", o.applies_to(Syntax::Python))?;
        d.set_item("defaults", o.defaults())?;
        let methods = PyList::empty(py);
        for u in &o.methods {
            let md = PyDict::new(py);
            md.set_item("method", u.method)?;
            md.set_item("note", u.note)?;
            md.set_item("default", &u.default)?;
            methods.append(md)?;
        }
        d.set_item("methods", methods)?;
        out.append(d)?;
    }
    Ok(out)
}

/// The library's description of every method: a list of dicts with
/// `name`, `label`, `help`, `default_window` [samples], `takes_orders` and
/// `options` (their keys).
#[pyfunction]
pub fn methods(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    let out = PyList::empty(py);
    for m in Method::all() {
        let info = m.describe();
        let d = PyDict::new(py);
        d.set_item("name", info.name)?;
        d.set_item("label", info.label)?;
        d.set_item("help", info.help)?;
        d.set_item("default_window", info.default_window)?;
        d.set_item("takes_orders", info.takes_orders)?;
        let keys: Vec<&str> = info.options.iter().map(|o| o.spec.key).collect();
        d.set_item("options", keys)?;
        out.append(d)?;
    }
    Ok(out)
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
