//! The identification methods as one enum: each variant holds that method's
//! settings, and every question about a method — its name, label, default
//! window, global model, orders, validation, estimator — is answered here by
//! an exhaustive `match`, so the compiler lists every place a new method
//! must fill in.
//!
//! | name | estimator | default window | orders | global model |
//! |---|---|---|---|---|
//! | `auto` | online choice among windowed and recursive unit-gain ARX candidates, scale-free, always predicts ([`AutoConfig`]); the default | 50 | of its long-memory RLS candidate | best of arx 8,8,1, oe 7,2, oe 5,1 |
//! | `paper` | the paper's polynomial method ([`PaperConfig`]) | 20 | — | — |
//! | `arx` | windowed ARX with exact sliding update ([`ArxConfig`]) | 100 | `na, nb, nk` | ARX with its orders |
//! | `rls` | recursive least squares with forgetting ([`RlsConfig`]) | 100 | `na, nb, nk` | ARX with its orders |
//! | `oe` | continuous-time output error over sliding windows ([`OeConfig`]) | 200 | — (poles, zeros) | OE with its poles and zeros |
//!
//! `auto` takes orders for its long-memory recursive candidate (default
//! 8,8,0); its other candidates stay as they are. Setting
//! orders on a method without an ARX regressor is an error, not ignored.
//!
//! # Adding a method
//!
//! 1. a module under `ident/methods/` with its settings (`Default`,
//!    `validate`, `build`) and its [`Estimator`];
//! 2. its `mod` and `pub use` lines in `ident/methods/mod.rs` (and the
//!    `pub use` in `ident/mod.rs`);
//! 3. a variant of [`Method`] here and its name in [`Method::all`]; the
//!    compiler then lists every `match` below that needs an arm.
//!
//! The pipeline, the CLI (`--method NAME`), the streamer, sweeps and reports
//! take the method from here and need no change.
//!
//! ```
//! use feedid::ident::{ArxOrders, Method};
//! let mut m: Method = "arx".parse().unwrap();
//! assert_eq!((m.name(), m.default_window()), ("arx", 100));
//! m.set_orders(ArxOrders::new(4, 4, 1)).unwrap();
//! assert_eq!(m.label(), "ARX 4,4,1");
//! assert_eq!(m.build().unwrap().name(), "arx");
//! let mut p: Method = "paper".parse().unwrap();
//! assert!(p.set_orders(ArxOrders::new(4, 4, 1)).is_err()); // refused, not ignored
//! ```

use std::fmt;
use std::str::FromStr;

use crate::error::{Error, Result};
use crate::ident::{
    ArxConfig, ArxOrders, AutoConfig, Estimator, GlobalModelKind, OeConfig, PaperConfig, RlsConfig,
};

/// Accepted method names, for messages.
pub const METHOD_NAMES: &str = "auto, paper, arx, rls, oe";

/// The methods that take ARX orders, for messages.
const ORDER_METHODS: &str = "arx, rls, auto";

/// An identification method and its settings.
#[derive(Debug, Clone, PartialEq)]
pub enum Method {
    /// The paper's windowed polynomial least squares.
    Paper(PaperConfig),
    /// Windowed ARX.
    Arx(ArxConfig),
    /// Recursive least squares.
    Rls(RlsConfig),
    /// Continuous-time output error.
    Oe(OeConfig),
    /// Validated choice of model, order and memory from the data (the default).
    Auto(AutoConfig),
}

impl Default for Method {
    /// `auto` with its default settings.
    fn default() -> Self {
        Method::Auto(AutoConfig::default())
    }
}

impl Method {
    /// Every method with its default settings, in the order of [`METHOD_NAMES`].
    pub fn all() -> [Method; 5] {
        [
            Method::Auto(AutoConfig::default()),
            Method::Paper(PaperConfig::default()),
            Method::Arx(ArxConfig::default()),
            Method::Rls(RlsConfig::default()),
            Method::Oe(OeConfig::default()),
        ]
    }

    /// Lowercase name (`"paper"`, `"arx"`, …), as on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            Method::Paper(_) => "paper",
            Method::Arx(_) => "arx",
            Method::Rls(_) => "rls",
            Method::Oe(_) => "oe",
            Method::Auto(_) => "auto",
        }
    }

    /// A label for legends and tables: the method and its main settings
    /// (`"paper LSM, qr"`, `"ARX 8,8,1"`, `"RLS 8,8,1 λ=0.999"`, `"OE 3p/1z"`, `"auto"`).
    pub fn label(&self) -> String {
        match self {
            Method::Paper(c) => match (c.solver, c.simplex_start) {
                (crate::ident::Solver::Simplex, crate::ident::SimplexStart::Previous) => {
                    "paper LSM, simplex from the previous window".to_string()
                }
                _ => format!("paper LSM, {}", c.solver.label()),
            },
            Method::Arx(c) => {
                let o = c.orders;
                format!("ARX {},{},{}", o.na, o.nb, o.nk)
            }
            Method::Rls(c) => {
                let o = c.orders;
                format!("RLS {},{},{} λ={}", o.na, o.nb, o.nk, c.lambda)
            }
            Method::Oe(c) => format!("OE {}p/{}z", c.poles, c.zeros),
            Method::Auto(_) => "auto".to_string(),
        }
    }

    /// The window a method works best with at kHz rates \[samples\]: paper
    /// 20 (4 ms at 5 kHz, the paper's), arx 200, oe 200, auto 50, rls 100
    /// (for rls it decides only when the first prediction is made; rls
    /// remembers ≈ 1/(1 − λ) samples).
    pub fn default_window(&self) -> usize {
        match self {
            Method::Paper(_) => 20,
            Method::Arx(_) => 100,
            Method::Rls(_) => 100,
            Method::Oe(_) => 200,
            Method::Auto(_) => 50,
        }
    }

    /// The global model that goes with the method (fitted over the whole
    /// recording for the summary's free-run fit): ARX with the method's
    /// orders for `arx` and `rls`, OE with its poles and zeros for `oe`,
    /// [`GlobalModelKind::Auto`] for `auto`, none for `paper` (its model
    /// only exists per window).
    pub fn global_model(&self) -> Option<GlobalModelKind> {
        match self {
            Method::Paper(_) => None,
            Method::Arx(c) => Some(GlobalModelKind::Arx(c.orders)),
            Method::Rls(c) => Some(GlobalModelKind::Arx(c.orders)),
            Method::Oe(c) => Some(GlobalModelKind::Oe {
                poles: c.poles,
                zeros: c.zeros,
            }),
            Method::Auto(_) => Some(GlobalModelKind::Auto),
        }
    }

    /// The ARX orders the method uses (`auto`: those of its long-memory
    /// candidate); `None` for methods without an ARX regressor.
    pub fn orders(&self) -> Option<ArxOrders> {
        match self {
            Method::Paper(_) | Method::Oe(_) => None,
            Method::Arx(c) => Some(c.orders),
            Method::Rls(c) => Some(c.orders),
            Method::Auto(c) => c.orders(),
        }
    }

    /// Set the ARX orders (`auto`: of its long-memory RLS candidate).
    ///
    /// Errors: [`Error::NotApplicable`] for a method without an ARX
    /// regressor (`paper`, `oe`) — the orders are refused, never ignored;
    /// invalid orders.
    pub fn set_orders(&mut self, orders: ArxOrders) -> Result<()> {
        orders.validate()?;
        match self {
            Method::Paper(_) | Method::Oe(_) => {
                return Err(Error::NotApplicable {
                    setting: "ARX orders (na,nb,nk)",
                    method: self.name(),
                    applies_to: ORDER_METHODS,
                })
            }
            Method::Arx(c) => c.orders = orders,
            Method::Rls(c) => c.orders = orders,
            Method::Auto(c) => c.set_orders(orders)?,
        }
        Ok(())
    }

    /// Check the settings.
    pub fn validate(&self) -> Result<()> {
        match self {
            Method::Paper(c) => c.validate(),
            Method::Arx(c) => c.validate(),
            Method::Rls(c) => c.validate(),
            Method::Oe(c) => c.validate(),
            Method::Auto(c) => c.validate(),
        }
    }

    /// Validate the settings and build the estimator.
    pub fn build(&self) -> Result<Box<dyn Estimator + Send>> {
        Ok(match self {
            Method::Paper(c) => Box::new(c.build()?),
            Method::Arx(c) => Box::new(c.build()?),
            Method::Rls(c) => Box::new(c.build()?),
            Method::Oe(c) => Box::new(c.clone().build()?),
            Method::Auto(c) => Box::new(c.build()?),
        })
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Method {
    type Err = Error;

    /// A method by name (case-insensitive; `lsm` is `paper`), with its default settings.
    fn from_str(s: &str) -> Result<Self> {
        let name = s.trim().to_ascii_lowercase();
        let name = if name == "lsm" { "paper" } else { &name };
        Method::all()
            .into_iter()
            .find(|m| m.name() == name)
            .ok_or_else(|| Error::InvalidChoice {
                what: "method",
                value: s.to_string(),
                expected: METHOD_NAMES,
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_name_builds_its_estimator() {
        for name in ["paper", "arx", "rls", "oe", "auto"] {
            let m: Method = name.parse().unwrap();
            assert_eq!(m.name(), name);
            assert_eq!(m.build().unwrap().name(), name);
            assert!(m.validate().is_ok());
        }
        assert_eq!(Method::all().len(), METHOD_NAMES.split(", ").count());
        for (m, name) in Method::all().iter().zip(METHOD_NAMES.split(", ")) {
            assert_eq!(m.name(), name);
        }
        assert_eq!("LSM".parse::<Method>().unwrap().name(), "paper");
    }

    #[test]
    fn unknown_name_lists_the_choices() {
        let e = "magic".parse::<Method>().unwrap_err();
        assert!(e.to_string().contains("auto, paper, arx, rls, oe"), "{e}");
    }

    #[test]
    fn orders_apply_to_regressor_methods_and_are_refused_elsewhere() {
        let o = ArxOrders::new(2, 3, 0);
        for name in ["arx", "rls", "auto"] {
            let mut m: Method = name.parse().unwrap();
            m.set_orders(o).unwrap();
            assert_eq!(m.orders(), Some(o), "{name}");
        }
        // auto: the long candidate only
        let Method::Auto(c) = ({
            let mut m = Method::default();
            m.set_orders(o).unwrap();
            m
        }) else {
            unreachable!()
        };
        // only the reported (largest) candidate takes them
        let d = AutoConfig::default();
        let r = d.reported().unwrap();
        for (i, (a, b)) in c.candidates.iter().zip(&d.candidates).enumerate() {
            if i == r {
                assert_eq!(a.orders(), Some(o));
            } else {
                assert_eq!(a, b);
            }
        }
        for name in ["paper", "oe"] {
            let mut m: Method = name.parse().unwrap();
            let before = m.clone();
            let e = m.set_orders(o).unwrap_err();
            assert!(
                matches!(e, Error::NotApplicable { method, .. } if method == name),
                "{e}"
            );
            assert!(e.to_string().contains("arx, rls, auto"), "{e}");
            assert_eq!(m, before);
            assert_eq!(m.orders(), None);
        }
        // invalid orders are refused before anything changes
        let mut m: Method = "arx".parse().unwrap();
        assert!(m.set_orders(ArxOrders::new(2, 0, 1)).is_err());
        assert_eq!(m.orders(), Some(ArxConfig::default().orders));
    }

    #[test]
    fn labels_windows_and_global_models_follow_the_settings() {
        let labels: Vec<String> = Method::all().iter().map(Method::label).collect();
        assert_eq!(
            labels,
            [
                "auto",
                "paper LSM, qr",
                "ARX 3,3,0",
                "RLS 8,8,0 λ=0.999",
                "OE 3p/1z"
            ]
        );
        let windows: Vec<usize> = Method::all().iter().map(Method::default_window).collect();
        assert_eq!(windows, [50, 20, 100, 100, 200]);
        let mut rls: Method = "rls".parse().unwrap();
        rls.set_orders(ArxOrders::new(4, 4, 1)).unwrap();
        assert_eq!(
            rls.global_model(),
            Some(GlobalModelKind::Arx(ArxOrders::new(4, 4, 1)))
        );
        assert_eq!("paper".parse::<Method>().unwrap().global_model(), None);
        assert_eq!(
            Method::default().global_model(),
            Some(GlobalModelKind::Auto)
        );
    }
}
