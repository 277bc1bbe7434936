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
//! | `nn` | neural NARX predictor: a two-layer `tanh` network with a linear bypass on `auto`'s unit-gain regressor, trained on the first moving samples ([`NnConfig`]) | 100 | `na, nb, nk` (its lags) | — |
//!
//! `auto` takes orders for its long-memory recursive candidate (default
//! 8,8,0); its other candidates stay as they are. Setting
//! orders on a method without an ARX regressor is an error, not ignored.
//!
//! # Options
//!
//! Each option is described once, as an [`OptionSpec`] (key, Python
//! keyword, value type, range, unit, help) next to the method that has it;
//! a method lists its options ([`MethodOption`]) in its settings' `impl
//! MethodSettings`, which also reads and sets them. [`Method::options`]
//! gathers every option with the methods that have it and their defaults;
//! [`Method::set_option`] parses, range-checks and sets one. The CLI's
//! flags and help, Python's keywords, docstrings and stubs come from these
//! descriptions.
//!
//! # Adding a method
//!
//! 1. a module under `ident/methods/` with its settings (`Default`,
//!    `validate`, `build`), its [`Estimator`], the [`OptionSpec`] of each
//!    option of its own and `impl MethodSettings` for the settings;
//! 2. its `mod` and `pub use` lines in `ident/methods/mod.rs`;
//! 3. a variant of [`Method`] here, its entry in [`Method::all`] and
//!    [`METHOD_NAMES`]; the compiler then lists every `match` below that
//!    needs an arm.
//!
//! The pipeline, the CLI (`--method NAME` and one flag per option), the
//! streamer, sweeps, reports and the Python package take the method and its
//! options from here and need no change; the Python stubs' option lines are
//! regenerated (`FEEDID_UPDATE_STUBS=1 cargo test -p feedid-cli --test
//! options`).
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

use crate::error::{Error, Result, Syntax};
use crate::ident::engine::{Estimator, Span};
use crate::ident::global::GlobalModelKind;
use crate::ident::methods::{
    ArxConfig, ArxOrders, AutoConfig, NnConfig, OeConfig, PaperConfig, RlsConfig,
};
use crate::ident::option::{MethodOption, MethodSettings, OptionInfo, OptionUse};

/// Accepted method names, for messages.
pub const METHOD_NAMES: &str = "auto, paper, arx, rls, oe, nn";

/// The methods that take ARX orders, for messages.
pub const ORDER_METHODS: &str = "arx, rls, nn, auto";

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
    /// Neural NARX predictor.
    Nn(NnConfig),
}

impl Default for Method {
    /// `auto` with its default settings.
    fn default() -> Self {
        Method::Auto(AutoConfig::default())
    }
}

impl Method {
    /// Every method with its default settings, in the order of [`METHOD_NAMES`].
    pub fn all() -> [Method; 6] {
        [
            Method::Auto(AutoConfig::default()),
            Method::Paper(PaperConfig::default()),
            Method::Arx(ArxConfig::default()),
            Method::Rls(RlsConfig::default()),
            Method::Oe(OeConfig::default()),
            Method::Nn(NnConfig::default()),
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
            Method::Nn(_) => "nn",
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
            Method::Nn(c) => {
                let o = c.orders;
                format!("NN {},{},{} h={}", o.na, o.nb, o.nk, c.hidden)
            }
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
            Method::Nn(_) => 100,
        }
    }

    /// The global model that goes with the method (fitted over the whole
    /// recording for the summary's free-run fit): ARX with the method's
    /// orders for `arx` and `rls`, OE with its poles and zeros for `oe`,
    /// [`GlobalModelKind::Auto`] for `auto`, none for `paper` (its model
    /// only exists per window).
    pub fn global_model(&self) -> Option<GlobalModelKind> {
        match self {
            Method::Paper(_) | Method::Nn(_) => None,
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
            Method::Nn(c) => Some(c.orders),
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
            Method::Nn(c) => {
                let mut changed = c.clone();
                changed.orders = orders;
                changed.validate()?;
                *c = changed;
            }
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
            Method::Nn(c) => c.validate(),
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
            Method::Nn(c) => Box::new(c.build()?),
        })
    }

    /// The window in samples: `window` converted at `rate_hz` (a time needs
    /// the rate), or the method's [`Method::default_window`] when `None` —
    /// the one place every front end takes its default window from.
    ///
    /// ```
    /// use feedid::ident::{Method, Span};
    /// let m = Method::default();
    /// assert_eq!(m.window_for(None, f64::NAN).unwrap(), 50);
    /// assert_eq!(m.window_for(Some(Span::Seconds(0.01)), 5000.0).unwrap(), 50);
    /// ```
    pub fn window_for(&self, window: Option<Span>, rate_hz: f64) -> Result<usize> {
        match window {
            Some(w) => w.samples(rate_hz, "window"),
            None => Ok(self.default_window()),
        }
    }

    /// One line on what the method does, for help texts.
    pub fn help(&self) -> &'static str {
        match self {
            Method::Paper(_) => "the paper's windowed polynomial least squares",
            Method::Arx(_) => "windowed ARX with exact sliding update",
            Method::Rls(_) => "recursive least squares with forgetting",
            Method::Oe(_) => "continuous-time output error over sliding windows",
            Method::Auto(_) => "validated choice of model, order and memory (the default)",
            Method::Nn(_) => "neural NARX predictor (a tanh network on auto's unit-gain regressor)",
        }
    }

    /// The method's description: name, label, help, default window, options.
    pub fn describe(&self) -> MethodInfo {
        MethodInfo {
            name: self.name(),
            label: self.label(),
            help: self.help(),
            default_window: self.default_window(),
            takes_orders: self.orders().is_some(),
            options: self.settings().options(),
        }
    }

    /// The method's settings as the option interface.
    fn settings(&self) -> &dyn MethodSettings {
        match self {
            Method::Paper(c) => c,
            Method::Arx(c) => c,
            Method::Rls(c) => c,
            Method::Oe(c) => c,
            Method::Auto(c) => c,
            Method::Nn(c) => c,
        }
    }

    /// The method's settings as the option interface, to change.
    fn settings_mut(&mut self) -> &mut dyn MethodSettings {
        match self {
            Method::Paper(c) => c,
            Method::Arx(c) => c,
            Method::Rls(c) => c,
            Method::Oe(c) => c,
            Method::Auto(c) => c,
            Method::Nn(c) => c,
        }
    }

    /// Whether the method has the option `key`.
    pub fn has_option(&self, key: &str) -> bool {
        self.settings().options().iter().any(|o| o.spec.key == key)
    }

    /// The current value of option `key`, as text (`None`: the method has no such option).
    pub fn option(&self, key: &str) -> Option<String> {
        self.has_option(key)
            .then(|| self.settings().option(key))
            .flatten()
            .map(|v| v.to_string())
    }

    /// Set option `key` (e.g. `"lambda"`) from its text `value`: parsed and
    /// range-checked against its [`OptionSpec`].
    ///
    /// Errors: [`Error::UnknownOption`] for a key no method has;
    /// [`Error::OptionNotApplicable`] for an option of other methods (it is
    /// refused, never ignored); [`Error::InvalidOption`] or
    /// [`Error::InvalidChoice`] for a value that does not parse or lies
    /// outside the range; the method's own checks (e.g. invalid orders).
    /// Nothing changes on error.
    ///
    /// ```
    /// use feedid::ident::Method;
    /// let mut m: Method = "rls".parse().unwrap();
    /// m.set_option("lambda", "0.99").unwrap();
    /// assert_eq!(m.option("lambda").as_deref(), Some("0.99"));
    /// assert!(m.set_option("lambda", "2").is_err()); // outside (0, 1]
    /// assert!(m.set_option("solver", "qr").is_err()); // paper's
    /// ```
    pub fn set_option(&mut self, key: &str, value: &str) -> Result<()> {
        let Some(info) = Method::options().into_iter().find(|o| o.spec.key == key) else {
            return Err(Error::UnknownOption {
                key: key.to_string(),
                known: Method::options()
                    .iter()
                    .map(|o| o.spec.key)
                    .collect::<Vec<_>>()
                    .join(", "),
            });
        };
        if !self.has_option(key) {
            return Err(Error::OptionNotApplicable {
                key: info.spec.key,
                method: self.name(),
                applies_to: info.applies_to(Syntax::Library),
            });
        }
        let v = info.spec.parse(value)?;
        let mut changed = self.clone();
        changed.settings_mut().set_option(info.spec.key, &v)?;
        *self = changed;
        Ok(())
    }

    /// Every method option, each once, with the methods that have it and
    /// their defaults (in the order of [`Method::by_specificity`]).
    pub fn options() -> Vec<OptionInfo> {
        let mut out: Vec<OptionInfo> = Vec::new();
        for m in Method::by_specificity() {
            for o in m.settings().options() {
                let default = m
                    .settings()
                    .option(o.spec.key)
                    .map(|v| v.to_string())
                    .unwrap_or_default();
                let used = OptionUse {
                    method: m.name(),
                    note: o.note,
                    default,
                };
                match out.iter_mut().find(|i| i.spec.key == o.spec.key) {
                    Some(i) => i.methods.push(used),
                    None => out.push(OptionInfo {
                        spec: o.spec,
                        methods: vec![used],
                    }),
                }
            }
        }
        out
    }

    /// Every method with its default settings, `auto` last (it combines the
    /// others, and its options go to its candidates): the order in which
    /// option help lists the methods.
    pub fn by_specificity() -> Vec<Method> {
        let mut all = Method::all().to_vec();
        all.sort_by_key(|m| matches!(m, Method::Auto(_)));
        all
    }
}

// ------------------------------------------------------------ descriptions

/// A method's description, for help texts and bindings ([`Method::describe`]).
#[derive(Debug, Clone, PartialEq)]
pub struct MethodInfo {
    /// Name as on the command line (`"arx"`).
    pub name: &'static str,
    /// Label with the default settings (`"ARX 3,3,0"`).
    pub label: String,
    /// One line on what it does.
    pub help: &'static str,
    /// Default window \[samples\].
    pub default_window: usize,
    /// Whether it takes ARX orders (`order`).
    pub takes_orders: bool,
    /// Its options.
    pub options: &'static [MethodOption],
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
        for name in ["paper", "arx", "rls", "oe", "auto", "nn"] {
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
        assert!(
            e.to_string().contains("auto, paper, arx, rls, oe, nn"),
            "{e}"
        );
    }

    #[test]
    fn orders_apply_to_regressor_methods_and_are_refused_elsewhere() {
        let o = ArxOrders::new(2, 3, 0);
        for name in ["arx", "rls", "nn", "auto"] {
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
            assert!(e.to_string().contains("arx, rls, nn, auto"), "{e}");
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
                "OE 3p/1z",
                "NN 8,8,0 h=16"
            ]
        );
        let windows: Vec<usize> = Method::all().iter().map(Method::default_window).collect();
        assert_eq!(windows, [50, 20, 100, 100, 200, 100]);
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

    #[test]
    fn every_option_is_described_once_and_reads_back_its_default() {
        let infos = Method::options();
        let keys: Vec<&str> = infos.iter().map(|o| o.spec.key).collect();
        assert_eq!(
            keys,
            [
                "solver",
                "time_origin",
                "prediction",
                "simplex_start",
                "order",
                "ridge",
                "lambda",
                "hidden",
                "train_samples",
                "epochs",
                "learning_rate",
                "online_steps",
                "nn_seed"
            ]
        );
        let who = |key: &str| {
            let o = infos.iter().find(|o| o.spec.key == key).unwrap();
            o.applies_to(Syntax::Library)
        };
        assert_eq!(who("order"), "arx, rls, nn, auto");
        assert_eq!(who("hidden"), "nn");
        assert_eq!(who("ridge"), "arx, auto");
        assert_eq!(who("lambda"), "rls");
        assert_eq!(who("simplex_start"), "paper (with solver = simplex)");
        for o in &infos {
            assert!(o
                .spec
                .key
                .chars()
                .all(|c| c.is_ascii_lowercase() || c == '_'));
            assert!(!o.spec.help.is_empty() && !o.methods.is_empty());
            for u in &o.methods {
                // the default reads back and sets to itself
                let mut m: Method = u.method.parse().unwrap();
                let before = m.clone();
                assert_eq!(m.option(o.spec.key).as_deref(), Some(u.default.as_str()));
                m.set_option(o.spec.key, &u.default).unwrap();
                assert_eq!(m, before, "{} {}", u.method, o.spec.key);
            }
        }
        assert_eq!(
            infos[4].help(Syntax::Cli),
            "arx, rls, nn, auto (its long-memory candidate): ARX orders `na,nb,nk` (poles, \
             input terms, input delay in samples), or `auto` (chosen from the recording by BIC; \
             identify only) [default: arx 3,3,0; rls 8,8,0; nn 8,8,0; auto 8,8,0]"
        );
        let d = Method::default().describe();
        assert_eq!(
            (d.name, d.default_window, d.takes_orders),
            ("auto", 50, true)
        );
        assert_eq!(d.options.len(), 2);
        assert!(!"oe".parse::<Method>().unwrap().describe().takes_orders);
    }

    #[test]
    fn set_option_parses_checks_and_refuses_with_typed_errors() {
        let mut m: Method = "rls".parse().unwrap();
        m.set_option("lambda", "0.99").unwrap();
        m.set_option("order", " 4, 4, 1 ").unwrap();
        assert_eq!(m.label(), "RLS 4,4,1 λ=0.99");
        let before = m.clone();
        for (key, value) in [
            ("lambda", "1.5"),
            ("lambda", "0"),
            ("lambda", "x"),
            ("order", "2,2"),
        ] {
            let e = m.set_option(key, value).unwrap_err();
            assert!(
                matches!(&e, Error::InvalidOption { key: k, value: v, .. } if *k == key && v == value),
                "{e}"
            );
            assert!(e.to_string().contains(&format!("`{value}`")), "{e}");
        }
        let e = m.set_option("lambda", "NaN").unwrap_err();
        assert!(e.to_string().contains("in (0, 1]"), "{e}");
        // invalid orders: the method's own check
        assert!(m.set_option("order", "2,0,1").is_err());
        let e = m.set_option("ridge", "0").unwrap_err();
        assert!(
            matches!(&e, Error::OptionNotApplicable { key: "ridge", method: "rls", applies_to } if applies_to == "arx, auto"),
            "{e}"
        );
        let e = m.set_option("magic", "1").unwrap_err();
        assert!(matches!(e, Error::UnknownOption { .. }), "{e}");
        assert!(e.to_string().contains("lambda"), "{e}");
        assert_eq!(m, before);
        // choices: the method's names and aliases
        let mut p: Method = "paper".parse().unwrap();
        p.set_option("solver", "Nelder-Mead").unwrap();
        p.set_option("simplex_start", "previous").unwrap();
        assert_eq!(p.option("solver").as_deref(), Some("simplex"));
        assert!(p.set_option("prediction", "cubic").is_err());
        let mut a = Method::default();
        a.set_option("ridge", "1e-6").unwrap();
        assert_eq!(a.option("ridge").as_deref(), Some("1e-6"));
        assert!(a.set_option("ridge", "-1").is_err());
    }

    #[test]
    fn the_window_is_the_given_one_or_the_methods() {
        for m in Method::all() {
            assert_eq!(m.window_for(None, f64::NAN).unwrap(), m.default_window());
            assert_eq!(m.window_for(Some(Span::Samples(7)), f64::NAN).unwrap(), 7);
            assert_eq!(m.window_for(Some(Span::Seconds(2e-3)), 5000.0).unwrap(), 10);
            assert!(m.window_for(Some(Span::Seconds(2e-3)), f64::NAN).is_err());
        }
    }
}
