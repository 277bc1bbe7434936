//! The method options are described once, in the library
//! ([`feedid::ident::Method::options`]): the CLI's flags and their help, and
//! the Python stubs (`python/feedid/_feedid.pyi`) must say what the
//! descriptions say. `FEEDID_UPDATE_STUBS=1 cargo test -p feedid-cli --test
//! options` rewrites the stubs' generated lines.

mod common;

use common::{feedid, stdout};
use feedid::error::Syntax;
use feedid::ident::{Method, OptionKind};

/// The first line of the stubs' generated block of method options.
const BEGIN: &str = "# method options: generated from the library's option descriptions";
/// Its last line.
const END: &str = "# end of method options";

/// The stub file of the native module.
fn pyi_path() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../python/feedid/_feedid.pyi")
}

/// The Python type of an option's value in the stubs.
fn python_type(kind: OptionKind) -> &'static str {
    match kind {
        OptionKind::Float => "float",
        OptionKind::Int => "int",
        OptionKind::Choice(_) | OptionKind::Orders => "str",
    }
}

/// The stubs' keyword lines of the method options, at `indent`.
fn stub_lines(indent: &str) -> Vec<String> {
    let mut lines = vec![format!(
        "{indent}{BEGIN} (FEEDID_UPDATE_STUBS=1 cargo test -p feedid-cli --test options)"
    )];
    for o in Method::options() {
        lines.push(format!(
            "{indent}{}: Optional[{}] = None,",
            o.spec.python_keyword(),
            python_type(o.spec.kind)
        ));
    }
    lines.push(format!("{indent}{END}"));
    lines
}

/// `text` with every generated block replaced by the one the descriptions give.
fn regenerate(text: &str) -> String {
    let mut out = Vec::new();
    let mut lines = text.lines();
    while let Some(line) = lines.next() {
        if line.trim_start().starts_with(BEGIN) {
            let indent = &line[..line.len() - line.trim_start().len()];
            out.extend(stub_lines(indent));
            for l in lines.by_ref() {
                if l.trim_start() == END {
                    break;
                }
            }
        } else {
            out.push(line.to_string());
        }
    }
    let mut s = out.join("\n");
    s.push('\n');
    s
}

#[test]
fn the_python_stubs_carry_every_method_option_with_its_type_and_default() {
    let path = pyi_path();
    let text = std::fs::read_to_string(&path).unwrap();
    let expected = regenerate(&text);
    if std::env::var_os("FEEDID_UPDATE_STUBS").is_some() {
        std::fs::write(&path, &expected).unwrap();
        return;
    }
    assert_eq!(
        text, expected,
        "python/feedid/_feedid.pyi differs from the option descriptions: run \
         FEEDID_UPDATE_STUBS=1 cargo test -p feedid-cli --test options"
    );
    // both native entry points that take a method: Streamer and identify
    assert_eq!(text.matches(BEGIN).count(), 2);
    for o in Method::options() {
        let line = format!(
            "{}: Optional[{}] = None,",
            o.spec.python_keyword(),
            python_type(o.spec.kind)
        );
        assert_eq!(text.matches(&line).count(), 2, "{line}");
    }
    // the keywords as the Python users know them
    let keywords: Vec<&str> = Method::options()
        .iter()
        .map(|o| o.spec.python_keyword())
        .collect();
    for k in [
        "order",
        "solver",
        "time_origin",
        "prediction",
        "simplex_start",
        "lambda_",
        "ridge",
    ] {
        assert!(keywords.contains(&k), "{k}");
    }
}

#[test]
fn every_command_that_takes_a_method_offers_every_option_with_its_help() {
    for command in ["identify", "stream", "report", "sweep"] {
        let help = stdout(&feedid(&[command, "--help"]));
        for o in Method::options() {
            let flag = format!("{} <{}>", o.spec.flag(), o.spec.value_name);
            assert!(help.contains(&flag), "{command}: {flag}");
            let text = o.help(Syntax::Cli);
            assert!(help.contains(&text), "{command} {flag}: {text}\n{help}");
            // the methods that have it and their defaults
            for u in &o.methods {
                assert!(
                    text.contains(u.method) && text.contains(&u.default),
                    "{text}"
                );
            }
        }
    }
}

#[test]
fn an_option_for_a_method_without_it_names_the_flag_and_the_methods_that_have_it() {
    for o in Method::options() {
        let Some(without) = Method::all()
            .into_iter()
            .find(|m| !m.has_option(o.spec.key))
        else {
            continue;
        };
        let value = o.methods[0].default.clone();
        let out = feedid(&[
            "identify",
            "no-such-file.csv",
            "--method",
            without.name(),
            &o.spec.flag(),
            &value,
            "-o",
            "unused.csv",
        ]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success());
        assert!(
            err.contains(&format!(
                "{} does not apply to --method {} (only to {})",
                o.spec.flag(),
                without.name(),
                o.applies_to(Syntax::Cli)
            )),
            "{err}"
        );
    }
}
