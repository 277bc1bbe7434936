//! The one place where command-line method options become library
//! [`Method`]s: `--method NAME` (identify, stream) or `--methods LIST`
//! (report, sweep) with the shared [`MethodOptions`].

use anyhow::{bail, Context, Result};
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
    /// `--order`, parsed.
    pub fn order_option(&self) -> Result<Option<OrderOption>> {
        let Some(o) = self.order.as_deref() else {
            return Ok(None);
        };
        if o.trim().eq_ignore_ascii_case("auto") {
            return Ok(Some(OrderOption::Select));
        }
        Ok(Some(OrderOption::Orders(parse_orders(o)?)))
    }

    /// Set every given option that `method` has; returns the flags of the
    /// given options it does not have (`--order auto` is left to the
    /// caller: see [`MethodOptions::order_option`]).
    pub fn apply(&self, method: &mut Method) -> Result<Vec<&'static str>> {
        let mut missing = Vec::new();
        if let Some(s) = &self.solver {
            let v = s.parse()?;
            match method {
                Method::Paper(c) => c.solver = v,
                _ => missing.push("--solver"),
            }
        }
        if let Some(s) = &self.time_origin {
            let v = s.parse()?;
            match method {
                Method::Paper(c) => c.time_origin = v,
                _ => missing.push("--time-origin"),
            }
        }
        if let Some(s) = &self.prediction {
            let v = s.parse()?;
            match method {
                Method::Paper(c) => c.prediction = v,
                _ => missing.push("--prediction"),
            }
        }
        if let Some(s) = &self.simplex_start {
            let v = s.parse()?;
            match method {
                Method::Paper(c) => c.simplex_start = v,
                _ => missing.push("--simplex-start"),
            }
        }
        match self.order_option()? {
            Some(OrderOption::Orders(o)) => match method.set_orders(o) {
                Ok(()) => {}
                Err(feedid::Error::NotApplicable { .. }) => missing.push("--order"),
                Err(e) => {
                    return Err(e).with_context(|| {
                        format!("--order {}", self.order.as_deref().unwrap_or_default())
                    })
                }
            },
            Some(OrderOption::Select) if method.orders().is_none() => missing.push("--order"),
            _ => {}
        }
        if let Some(l) = self.lambda {
            match method {
                Method::Rls(c) => c.lambda = l,
                _ => missing.push("--lambda"),
            }
        }
        if let Some(r) = self.ridge {
            match method {
                Method::Arx(c) => c.ridge = r,
                Method::Auto(c) => c.set_ridge(r),
                _ => missing.push("--ridge"),
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
        let mut missing_everywhere: Option<Vec<&'static str>> = None;
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

/// The methods an option applies to, for messages.
fn applies_to(flag: &str) -> &'static str {
    match flag {
        "--solver" | "--time-origin" | "--prediction" => "paper",
        "--simplex-start" => "paper (with --solver simplex)",
        "--order" => "arx, rls, auto",
        "--lambda" => "rls",
        "--ridge" => "arx, auto",
        _ => "some methods",
    }
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

    fn options() -> MethodOptions {
        MethodOptions {
            solver: None,
            time_origin: None,
            prediction: None,
            simplex_start: None,
            order: None,
            lambda: None,
            ridge: None,
        }
    }

    #[test]
    fn options_go_to_the_methods_that_have_them_and_are_refused_elsewhere() {
        let o = MethodOptions {
            order: Some("2,2,1".into()),
            ..options()
        };
        for name in ["arx", "rls", "auto"] {
            let m = o.method(name).unwrap();
            assert_eq!(m.orders(), Some(ArxOrders::new(2, 2, 1)), "{name}");
        }
        for name in ["paper", "oe"] {
            let e = o.method(name).unwrap_err().to_string();
            assert!(e.contains("--order") && e.contains(name), "{e}");
        }
        let o = MethodOptions {
            solver: Some("simplex".into()),
            ..options()
        };
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
        let o = MethodOptions {
            solver: Some("simplex".into()),
            simplex_start: Some("previous".into()),
            ..options()
        };
        let Method::Paper(c) = o.method("paper").unwrap() else {
            unreachable!()
        };
        assert_eq!(c.simplex_start, feedid::ident::SimplexStart::Previous);
        let o = MethodOptions {
            simplex_start: Some("previous".into()),
            ..options()
        };
        let e = format!("{:#}", o.method("paper").unwrap_err());
        assert!(e.contains("simplex"), "{e}");
        assert!(o.method("arx").is_err());
        let o = MethodOptions {
            solver: Some("simplex".into()),
            simplex_start: Some("last".into()),
            ..options()
        };
        assert!(o.method("paper").unwrap_err().to_string().contains("last"));
        // bad values are named
        let o = MethodOptions {
            order: Some("2,2".into()),
            ..options()
        };
        assert!(o.method("arx").unwrap_err().to_string().contains("`2,2`"));
        let o = MethodOptions {
            ridge: Some(0.0),
            ..options()
        };
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
        let o = MethodOptions {
            ridge: Some(-1.0),
            ..options()
        };
        assert!(o.method("arx").is_err() && o.method("auto").is_err());
    }
}
