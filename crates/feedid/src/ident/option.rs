//! Method options described once: each option's [`OptionSpec`] (key,
//! Python keyword, value type, range, unit, help) lives next to the method
//! that has it, and a method's settings list, read and set their options
//! through [`MethodSettings`]. Front ends derive their flags, keywords,
//! help texts and stubs from these descriptions; the registry
//! (`ident/method.rs`) gathers them per option ([`OptionInfo`]).

use std::fmt;

use crate::error::{Error, Result, Syntax};
use crate::ident::methods::regressor::ArxOrders;

/// The type of an option's value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OptionKind {
    /// A real number.
    Float,
    /// A whole number ≥ 0.
    Int,
    /// One of these names (aliases may be accepted too).
    Choice(&'static [&'static str]),
    /// ARX orders `na,nb,nk`.
    Orders,
}

/// The valid range of a numeric option (always finite values).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OptionRange {
    /// Lower bound.
    pub min: f64,
    /// Whether the lower bound itself is excluded.
    pub min_open: bool,
    /// Upper bound (`f64::INFINITY`: none).
    pub max: f64,
    /// Whether the upper bound itself is excluded.
    pub max_open: bool,
}

impl OptionRange {
    /// `[min, ∞)`: at least `min`.
    pub const fn at_least(min: f64) -> Self {
        Self {
            min,
            min_open: false,
            max: f64::INFINITY,
            max_open: true,
        }
    }

    /// Whether `v` lies in the range (NaN and infinities never do).
    pub fn contains(&self, v: f64) -> bool {
        let above = if self.min_open {
            v > self.min
        } else {
            v >= self.min
        };
        let below = if self.max_open {
            v < self.max
        } else {
            v <= self.max
        };
        v.is_finite() && above && below
    }
}

impl fmt::Display for OptionRange {
    /// `≥ 0`, `> 0` or `in (0, 1]`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let min = number_text(self.min);
        if self.max.is_infinite() {
            return write!(f, "{} {min}", if self.min_open { ">" } else { "≥" });
        }
        write!(
            f,
            "in {}{min}, {}{}",
            if self.min_open { "(" } else { "[" },
            number_text(self.max),
            if self.max_open { ")" } else { "]" }
        )
    }
}

/// A method option: everything a front end needs to offer it (flag,
/// keyword, type, range, unit, help). Defined once, next to the method(s)
/// that have it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OptionSpec {
    /// Key, snake_case (`"time_origin"`); the CLI flag is `--time-origin`.
    pub key: &'static str,
    /// The Python keyword when it differs from the key (`lambda_`).
    pub python: Option<&'static str>,
    /// Placeholder of the value in help texts (`"NAME"`, `"LAMBDA"`).
    pub value_name: &'static str,
    /// Type of the value.
    pub kind: OptionKind,
    /// Valid range of a numeric value.
    pub range: Option<OptionRange>,
    /// Unit of a numeric value (`"samples"`), if any.
    pub unit: Option<&'static str>,
    /// What it sets, without the methods and the default (`"forgetting factor λ"`).
    pub help: &'static str,
    /// Another option's value it works only with (`("solver", "simplex")`).
    pub requires: Option<(&'static str, &'static str)>,
}

impl OptionSpec {
    /// The command-line flag (`--time-origin`).
    pub fn flag(&self) -> String {
        format!("--{}", self.key.replace('_', "-"))
    }

    /// The Python keyword (`time_origin`, `lambda_`).
    pub fn python_keyword(&self) -> &'static str {
        self.python.unwrap_or(self.key)
    }

    /// Parse a value given as text, checked against the kind and range.
    pub fn parse(&self, value: &str) -> Result<OptionValue> {
        let invalid = |expected: String| Error::InvalidOption {
            key: self.key,
            value: value.to_string(),
            expected,
        };
        let in_range = |v: f64| match self.range {
            Some(r) if !r.contains(v) => Err(invalid(format!("expected a number {r}"))),
            _ => Ok(v),
        };
        match self.kind {
            OptionKind::Float => {
                let v: f64 = value
                    .trim()
                    .parse()
                    .map_err(|_| invalid("expected a number".into()))?;
                Ok(OptionValue::Float(in_range(v)?))
            }
            OptionKind::Int => {
                let v: usize = value
                    .trim()
                    .parse()
                    .map_err(|_| invalid("expected a whole number ≥ 0".into()))?;
                in_range(v as f64)?;
                Ok(OptionValue::Int(v))
            }
            OptionKind::Choice(_) => Ok(OptionValue::Choice(value.trim().to_string())),
            OptionKind::Orders => {
                let bad = || invalid("expected na,nb,nk (e.g. 8,8,1)".into());
                let v = value
                    .split(',')
                    .map(|x| x.trim().parse::<usize>().map_err(|_| bad()))
                    .collect::<Result<Vec<_>>>()?;
                match v.as_slice() {
                    [na, nb, nk] => Ok(OptionValue::Orders(ArxOrders::new(*na, *nb, *nk))),
                    _ => Err(bad()),
                }
            }
        }
    }
}

/// A parsed option value.
#[derive(Debug, Clone, PartialEq)]
pub enum OptionValue {
    /// A real number.
    Float(f64),
    /// A whole number.
    Int(usize),
    /// A name (parsed further by the method: `"simplex"`).
    Choice(String),
    /// ARX orders.
    Orders(ArxOrders),
}

impl fmt::Display for OptionValue {
    /// As given on the command line (`0.999`, `1e-10`, `qr`, `8,8,0`).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            OptionValue::Float(v) => f.write_str(&number_text(*v)),
            OptionValue::Int(v) => write!(f, "{v}"),
            OptionValue::Choice(s) => f.write_str(s),
            OptionValue::Orders(o) => write!(f, "{},{},{}", o.na, o.nb, o.nk),
        }
    }
}

/// A number as a user writes it: `0.999`, `0`, `1e-10`.
fn number_text(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || !v.is_finite() || (1e-4..1e6).contains(&a) {
        v.to_string()
    } else {
        format!("{v:e}")
    }
}

/// One method's entry for an option it has.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MethodOption {
    /// The option.
    pub spec: &'static OptionSpec,
    /// What of the method it sets, when not the whole method (`"its long-memory candidate"`).
    pub note: Option<&'static str>,
}

impl MethodOption {
    /// The option, for the whole method.
    pub const fn new(spec: &'static OptionSpec) -> Self {
        Self { spec, note: None }
    }

    /// The option, for a part of the method (`"its windowed candidates"`).
    pub const fn of(spec: &'static OptionSpec, note: &'static str) -> Self {
        Self {
            spec,
            note: Some(note),
        }
    }
}

/// A method that has an option, and its default.
#[derive(Debug, Clone, PartialEq)]
pub struct OptionUse {
    /// Method name.
    pub method: &'static str,
    /// What of the method it sets ([`MethodOption::note`]).
    pub note: Option<&'static str>,
    /// The method's default value, as text.
    pub default: String,
}

/// An option with every method that has it ([`Method::options`]).
#[derive(Debug, Clone, PartialEq)]
pub struct OptionInfo {
    /// The option.
    pub spec: &'static OptionSpec,
    /// The methods that have it, with their defaults.
    pub methods: Vec<OptionUse>,
}

impl OptionInfo {
    /// The methods it applies to, for messages: `arx, rls, auto`, or
    /// `paper (with --solver simplex)` in the front end's syntax.
    pub fn applies_to(&self, syntax: Syntax) -> String {
        let names: Vec<&str> = self.methods.iter().map(|u| u.method).collect();
        let mut s = names.join(", ");
        if let Some((key, value)) = self.spec.requires {
            s += &format!(" (with {})", syntax.setting(key, value));
        }
        s
    }

    /// The defaults: `qr`, or `arx 3,3,0; rls 8,8,0` when several methods have it.
    pub fn defaults(&self) -> String {
        match self.methods.as_slice() {
            [one] => one.default.clone(),
            many => many
                .iter()
                .map(|u| format!("{} {}", u.method, u.default))
                .collect::<Vec<_>>()
                .join("; "),
        }
    }

    /// The help line: who has it, what it sets, the valid range, the
    /// defaults (`rls: forgetting factor λ … [default: 0.999]`).
    pub fn help(&self, syntax: Syntax) -> String {
        let who: Vec<String> = self
            .methods
            .iter()
            .map(|u| match u.note {
                Some(n) => format!("{} ({n})", u.method),
                None => u.method.to_string(),
            })
            .collect();
        let mut who = who.join(", ");
        if let Some((key, value)) = self.spec.requires {
            who += &format!(" (with {})", syntax.setting(key, value));
        }
        let mut help = format!("{who}: {}", self.spec.help);
        if let Some(r) = self.spec.range {
            help += &format!(", {r}");
        }
        if let Some(u) = self.spec.unit {
            help += &format!(" [{u}]");
        }
        format!("{help} [default: {}]", self.defaults())
    }
}

/// How a method's settings answer the option interface; each method's
/// settings implement it next to their option specs.
pub(crate) trait MethodSettings {
    /// The options the method has.
    fn options(&self) -> &'static [MethodOption] {
        &[]
    }

    /// The current value of one of its options.
    fn option(&self, _key: &str) -> Option<OptionValue> {
        None
    }

    /// Set one of its options (the value parsed by its spec).
    fn set_option(&mut self, key: &str, _value: &OptionValue) -> Result<()> {
        Err(Error::UnknownOption {
            key: key.to_string(),
            known: String::new(),
        })
    }
}
