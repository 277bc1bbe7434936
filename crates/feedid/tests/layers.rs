//! The layers of ARCHITECTURE.md, checked on the source: a module imports
//! nothing from a layer above it (test modules aside, which may use the
//! virtual rig as a reference), and `rls`/`oe` use the shared ARX regressor,
//! not the `arx` method's internals.

use std::path::{Path, PathBuf};

/// Every `.rs` file under `dir` (or `dir` itself if it is a file).
fn sources(dir: &Path) -> Vec<PathBuf> {
    if dir.is_file() {
        return vec![dir.to_path_buf()];
    }
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            out.extend(sources(&p));
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
    out
}

/// The code of a file before its test module (whole files named `tests.rs` are tests).
fn code(p: &Path) -> String {
    if p.file_name().is_some_and(|n| n == "tests.rs") {
        return String::new();
    }
    let text = std::fs::read_to_string(p).unwrap();
    let end = text.find("#[cfg(test)]").unwrap_or(text.len());
    text[..end]
        .lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// Modules of `layer` (paths under `src/`) must not name any of `above`.
fn assert_below(layer: &[&str], above: &[&str]) {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    for part in layer {
        for file in sources(&src.join(part)) {
            let code = code(&file);
            for higher in above {
                let needle = format!("crate::{higher}");
                assert!(
                    !code.contains(&needle),
                    "{} uses {needle}",
                    file.strip_prefix(&src).unwrap().display()
                );
            }
        }
    }
}

#[test]
fn low_layers_import_nothing_from_higher_ones() {
    let everything_above = [
        "recording",
        "drive",
        "zoo",
        "ident",
        "pipeline",
        "io",
        "greybox",
        "compensate",
        "experiment",
    ];
    for low in ["lti", "solve", "signal", "stats.rs", "error.rs"] {
        let above: Vec<&str> = everything_above
            .iter()
            .copied()
            .filter(|m| !low.starts_with(m))
            .collect();
        assert_below(&[low], &above);
    }
    assert_below(
        &["recording.rs"],
        &[
            "drive",
            "zoo",
            "ident",
            "pipeline",
            "io",
            "greybox",
            "compensate",
            "experiment",
        ],
    );
    // the plausibility checks sit on the recording: nothing else
    assert_below(
        &["plausibility.rs"],
        &[
            "drive",
            "ident",
            "pipeline",
            "io",
            "greybox",
            "compensate",
            "experiment",
        ],
    );
    // io writes plain columns: it knows nothing of identification
    assert_below(
        &["io"],
        &[
            "drive",
            "ident",
            "pipeline",
            "greybox",
            "compensate",
            "experiment",
        ],
    );
    assert_below(
        &["drive"],
        &[
            "zoo",
            "ident",
            "pipeline",
            "io",
            "greybox",
            "compensate",
            "experiment",
        ],
    );
    assert_below(
        &["zoo"],
        &[
            "ident",
            "pipeline",
            "io",
            "greybox",
            "compensate",
            "experiment",
        ],
    );
    assert_below(
        &["ident"],
        &[
            "drive",
            "zoo",
            "pipeline",
            "io",
            "greybox",
            "compensate",
            "experiment",
        ],
    );
}

#[test]
fn rls_and_oe_use_the_shared_regressor_not_arx_internals() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/ident/methods");
    for f in ["rls.rs", "oe", "auto"] {
        for file in sources(&src.join(f)) {
            let code = code(&file);
            assert!(
                !code.contains("methods::arx") && !code.contains("super::arx"),
                "{} reaches into the arx method",
                file.display()
            );
        }
    }
}
