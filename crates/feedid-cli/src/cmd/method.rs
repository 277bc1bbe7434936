//! The one place where command-line method options become library
//! [`Method`]s: `--method NAME` (identify, stream) or `--methods LIST`
//! (report, sweep) with the shared [`MethodOptions`].

use anyhow::{bail, Context, Result};
use feedid::error::{Hint, Syntax};
use feedid::ident::{ArxOrders, Method};

use crate::args::MethodOptions;

/// What `--order` asks for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OrderOption {
    /// These orders.
    Orders(ArxOrders),
    /// Choose them from the recording (`--order auto`).
    Select,
}

impl MethodOptions {
    /// These options, each given as `(key, value)` (as the flags would give them).
    #[cfg(test)]
    pub fn given(values: &[(&'static str, &str)]) -> Self {
        Self {
            values: values.iter().map(|&(k, v)| (k, v.to_string())).collect(),
        }
    }

    /// `--order`, parsed.
    pub fn order_option(&self) -> Result<Option<OrderOption>> {
        let Some((_, o)) = self.values.iter().find(|(k, _)| *k == "order") else {
            return Ok(None);
        };
        if is_select(o) {
            return Ok(Some(OrderOption::Select));
        }
        Ok(Some(OrderOption::Orders(parse_orders(o)?)))
    }

    /// Set every given option that `method` has; returns the flags of the
    /// given options it does not have (`--order auto` is left to the
    /// caller: see [`MethodOptions::order_option`]).
    pub fn apply(&self, method: &mut Method) -> Result<Vec<String>> {
        let mut missing = Vec::new();
        for (key, value) in &self.values {
            let flag = || Hint::Option { key }.phrase(Syntax::Cli);
            if *key == "order" && is_select(value) {
                if !method.has_option(key) {
                    missing.push(flag());
                }
                continue;
            }
            match method.set_option(key, value) {
                Ok(()) => {}
                Err(feedid::Error::OptionNotApplicable { .. }) => missing.push(flag()),
                Err(
                    e @ (feedid::Error::InvalidOption { .. } | feedid::Error::InvalidChoice { .. }),
                ) => return Err(e.into()),
                Err(e) => return Err(e).with_context(|| format!("{} {value}", flag())),
            }
        }
        Ok(missing)
    }

    /// The method named by `--method` with these options; an option the
    /// method does not have is an error.
    pub fn method(&self, name: &str) -> Result<Method> {
        let mut m: Method = name.parse()?;
        let missing = self.apply(&mut m)?;
        if let Some(flag) = missing.first() {
            bail!(
                "{flag} does not apply to --method {} (only to {})",
                m.name(),
                applies_to(flag)
            );
        }
        m.validate()?;
        Ok(m)
    }

    /// The methods of `--methods LIST` (or `default`), each option applied
    /// to the methods that have it; an option that none of them has is an
    /// error.
    pub fn methods(&self, list: Option<&str>, default: &str) -> Result<Vec<Method>> {
        let list = list.unwrap_or(default);
        let mut out = Vec::new();
        let mut missing_everywhere: Option<Vec<String>> = None;
        for name in list.split(',').map(str::trim) {
            if name.is_empty() {
                bail!("invalid --methods `{list}`: empty method name");
            }
            let mut m: Method = name.parse()?;
            let missing = self.apply(&mut m)?;
            missing_everywhere = Some(match missing_everywhere {
                None => missing,
                Some(before) => before.into_iter().filter(|f| missing.contains(f)).collect(),
            });
            m.validate()?;
            out.push(m);
        }
        if let Some(flag) = missing_everywhere.unwrap_or_default().first() {
            bail!(
                "{flag} does not apply to any of --methods {list} (only to {})",
                applies_to(flag)
            );
        }
        Ok(out)
    }
}

/// `--order auto`: choose the orders from the recording.
fn is_select(value: &str) -> bool {
    value.trim().eq_ignore_ascii_case("auto")
}

/// The methods the option of `flag` applies to, for messages (from the
/// library's option descriptions).
fn applies_to(flag: &str) -> String {
    Method::options()
        .into_iter()
        .find(|o| o.spec.flag() == flag)
        .map_or_else(|| "some methods".to_string(), |o| o.applies_to(Syntax::Cli))
}

/// `na,nb,nk` → orders.
pub fn parse_orders(s: &str) -> Result<ArxOrders> {
    let bad = || anyhow::anyhow!("invalid order `{s}`: expected na,nb,nk (e.g. 8,8,1)");
    let v: Vec<usize> = s
        .split(',')
        .map(|x| x.trim().parse().map_err(|_| bad()))
        .collect::<Result<_>>()?;
    match v.as_slice() {
        [na, nb, nk] => Ok(ArxOrders::new(*na, *nb, *nk)),
        _ => Err(bad()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_go_to_the_methods_that_have_them_and_are_refused_elsewhere() {
        let o = MethodOptions::given(&[("order", "2,2,1")]);
        for name in ["arx", "rls", "auto"] {
            let m = o.method(name).unwrap();
            assert_eq!(m.orders(), Some(ArxOrders::new(2, 2, 1)), "{name}");
        }
        for name in ["paper", "oe"] {
            let e = o.method(name).unwrap_err().to_string();
            assert!(e.contains("--order") && e.contains(name), "{e}");
        }
        let o = MethodOptions::given(&[("solver", "simplex")]);
        assert!(o.method("arx").is_err());
        let Method::Paper(c) = o.method("paper").unwrap() else {
            unreachable!()
        };
        assert_eq!(c.solver, feedid::ident::Solver::Simplex);
        // a list: each option to the methods that have it
        let ms = o.methods(Some("paper,arx"), "").unwrap();
        assert_eq!(ms.len(), 2);
        let e = o.methods(Some("arx,rls"), "").unwrap_err().to_string();
        assert!(e.contains("--solver") && e.contains("arx,rls"), "{e}");
        // the simplex start: with the simplex only
        let o = MethodOptions::given(&[("solver", "simplex"), ("simplex_start", "previous")]);
        let Method::Paper(c) = o.method("paper").unwrap() else {
            unreachable!()
        };
        assert_eq!(c.simplex_start, feedid::ident::SimplexStart::Previous);
        let o = MethodOptions::given(&[("simplex_start", "previous")]);
        let e = format!("{:#}", o.method("paper").unwrap_err());
        assert!(e.contains("simplex"), "{e}");
        assert!(o.method("arx").is_err());
        let o = MethodOptions::given(&[("solver", "simplex"), ("simplex_start", "last")]);
        assert!(o.method("paper").unwrap_err().to_string().contains("last"));
        // bad values are named
        let o = MethodOptions::given(&[("order", "2,2")]);
        assert!(o.method("arx").unwrap_err().to_string().contains("`2,2`"));
        let o = MethodOptions::given(&[("ridge", "0")]);
        let Method::Arx(c) = o.method("arx").unwrap() else {
            unreachable!()
        };
        assert_eq!(c.ridge, 0.0);
        let Method::Auto(c) = o.method("auto").unwrap() else {
            unreachable!()
        };
        assert!(c.candidates.iter().all(|c| match c {
            feedid::ident::Candidate::Windowed { ridge, .. } => *ridge == 0.0,
            _ => true,
        }));
        assert!(o.method("rls").unwrap_err().to_string().contains("--ridge"));
        let o = MethodOptions::given(&[("ridge", "-1")]);
        assert!(o.method("arx").is_err() && o.method("auto").is_err());
    }
}
