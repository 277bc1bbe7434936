//! The layers of ARCHITECTURE.md, checked on the source: a module imports
//! nothing from a layer above it (test modules aside, which may use the
//! virtual rig as a reference), inside `ident` and `io` a sub-layer imports
//! only from itself and the ones below (paths `crate::ident::…`,
//! `crate::io::…` — names of a `mod.rs` re-export resolved to the module
//! that defines them — and `super::…`), and `rls`/`oe` use the shared ARX
//! regressor, not the `arx` method's internals.

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

/// The code of a file before its test module (whole files named `tests.rs`
/// and files under a `tests/` folder are tests).
fn code(p: &Path) -> String {
    // the folders between `src/` and the file
    let folders: Vec<_> = p
        .components()
        .rev()
        .skip(1)
        .take_while(|c| c.as_os_str() != "src")
        .collect();
    if p.file_name().is_some_and(|n| n == "tests.rs")
        || folders.iter().any(|c| c.as_os_str() == "tests")
    {
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
        &["recording"],
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

/// The sub-layers of `ident`, lowest first: paths under `src/ident`, a
/// folder or a file. A module may import from its own sub-layer and the
/// ones below.
const IDENT_LAYERS: &[&[&str]] = &[
    // the linear model type
    &["model"],
    // signals, the estimator trait, the sliding engine, the streamer
    &["engine"],
    // the ARX regressor the methods and order selection share, and the
    // description of method options (an option's value may be ARX orders)
    &["methods/regressor.rs", "option.rs"],
    &[
        "methods/paper",
        "methods/arx",
        "methods/oe",
        "methods/rls.rs",
        "methods/nn",
    ],
    // auto runs rls updates
    &["methods/auto"],
    // global models of a whole recording (fit_arx, fit_oe)
    &["global.rs"],
    // the registry: every method by name, its global model
    &["method.rs"],
    &["select", "analysis"],
];

/// The sub-layers of `recording`, lowest first: the plausibility checks
/// sit on the checked recording, the summary on both.
const RECORDING_LAYERS: &[&[&str]] = &[&["checked.rs"], &["plausibility.rs"], &["info.rs"]];

/// The sub-layers of `io`, lowest first (paths under `src/io`).
const IO_LAYERS: &[&[&str]] = &[
    &["options.rs", "source.rs", "output.rs", "table.rs"],
    // columns → checked recording, the file context of errors, messages
    &["columns.rs"],
    // fields of a delimited text line
    &["text.rs"],
    // delimiter, header and columns of a text recording
    &["layout.rs"],
    &["csv.rs", "mat.rs"],
    // dispatch on the file's content; the live stream
    &["read.rs", "stream.rs"],
];

/// The path trees after `prefix` in `code`: `a::b::{c, d::{e}}` gives
/// `[a, b, c]` and `[a, b, d, e]`; `x as y` counts as `x`.
fn paths_after(code: &str, prefix: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let mut from = 0;
    while let Some(i) = code[from..].find(prefix) {
        let start = from + i;
        // `crate::io::` must not match inside `foo_crate::io::`
        let before = code[..start].chars().next_back();
        from = start + prefix.len();
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
            continue;
        }
        let mut pos = from;
        tree(code.as_bytes(), &mut pos, Vec::new(), &mut out);
    }
    out
}

/// Parse one path tree at `pos`, appending complete paths to `out`.
fn tree(b: &[u8], pos: &mut usize, mut path: Vec<String>, out: &mut Vec<Vec<String>>) {
    loop {
        while *pos < b.len() && b[*pos].is_ascii_whitespace() {
            *pos += 1;
        }
        if *pos < b.len() && b[*pos] == b'{' {
            *pos += 1;
            loop {
                tree(b, pos, path.clone(), out);
                // skip `as name` and anything else to the next `,` or `}`
                while *pos < b.len() && b[*pos] != b',' && b[*pos] != b'}' {
                    *pos += 1;
                }
                if *pos >= b.len() {
                    return;
                }
                let c = b[*pos];
                *pos += 1;
                if c == b'}' {
                    return;
                }
            }
        }
        let start = *pos;
        while *pos < b.len() && (b[*pos].is_ascii_alphanumeric() || b[*pos] == b'_') {
            *pos += 1;
        }
        if *pos == start {
            if !path.is_empty() {
                out.push(path);
            }
            return;
        }
        path.push(String::from_utf8_lossy(&b[start..*pos]).into_owned());
        if b[*pos..].starts_with(b"::") {
            *pos += 2;
        } else {
            out.push(path);
            return;
        }
    }
}

/// The child module of folder `dir` whose items `dir/mod.rs` re-exports as `name`.
fn reexported_from(dir: &Path, name: &str) -> Option<String> {
    let m = code(&dir.join("mod.rs"));
    let uses = paths_after(&m, "use ");
    uses.into_iter()
        .map(|p| p.into_iter().filter(|s| s != "self").collect::<Vec<_>>())
        .find(|p| p.len() > 1 && p.last().is_some_and(|l| l == name))
        .map(|p| p[0].clone())
}

/// The file or folder (relative to `root`) that the path `segs` from the
/// module folder `dir` names: modules are followed as far as they go, a
/// name re-exported by a `mod.rs` to the child that defines it.
fn resolve(root: &Path, mut dir: PathBuf, segs: &[String]) -> Option<PathBuf> {
    for s in segs {
        if dir.join(s).is_dir() {
            dir = dir.join(s);
        } else if dir.join(format!("{s}.rs")).is_file() {
            return Some(dir.join(format!("{s}.rs")));
        } else if let Some(child) = reexported_from(&dir, s) {
            return resolve(root, dir, &[child, s.clone()]);
        } else {
            break;
        }
    }
    dir.strip_prefix(root).ok().map(Path::to_path_buf)?;
    Some(dir)
}

/// The sub-layer of `rel` (a path under the module's folder): the entry it
/// lies in; a folder above several entries counts as the highest of them.
fn layer_of(rel: &Path, table: &[&[&str]]) -> Option<usize> {
    let inside = table
        .iter()
        .position(|l| l.iter().any(|e| rel.starts_with(e)));
    inside.or_else(|| {
        table
            .iter()
            .rposition(|l| l.iter().any(|e| Path::new(e).starts_with(rel)))
    })
}

/// Every import in `src/<module>` that runs upward through `table`, and
/// every file of the module the table does not place (its `mod.rs` files
/// aside, which hold only `mod` and `pub use`).
fn layer_violations(src: &Path, module: &str, table: &[&[&str]]) -> Vec<String> {
    let root = src.join(module);
    let mut found = Vec::new();
    for file in sources(&root) {
        let rel = file.strip_prefix(&root).unwrap().to_path_buf();
        if file.file_name().is_some_and(|n| n == "mod.rs") {
            continue;
        }
        let code = code(&file);
        if code.is_empty() {
            continue;
        }
        let Some(own) = layer_of(&rel, table) else {
            found.push(format!("{module}/{} is in no sub-layer", rel.display()));
            continue;
        };
        // `crate::module::…` from the module's folder, `super::…` from the file's parent module
        let mut targets: Vec<PathBuf> = Vec::new();
        for p in paths_after(&code, &format!("crate::{module}::")) {
            targets.extend(resolve(&root, root.clone(), &p));
        }
        let own_module = if file.file_name().is_some_and(|n| n == "mod.rs") {
            file.parent().unwrap().to_path_buf()
        } else {
            file.with_extension("")
        };
        for p in paths_after(&code, "super::") {
            let mut base = own_module.parent().unwrap().to_path_buf();
            let mut rest = p.as_slice();
            while rest.first().is_some_and(|s| s == "super") {
                base = base.parent().unwrap().to_path_buf();
                rest = &rest[1..];
            }
            if base.starts_with(&root) {
                targets.extend(resolve(&root, base, rest));
            }
        }
        for t in targets {
            let Ok(t) = t.strip_prefix(&root) else {
                continue;
            };
            if let Some(l) = layer_of(t, table) {
                if l > own {
                    found.push(format!(
                        "{module}/{} (sub-layer {own}) imports {module}/{} (sub-layer {l})",
                        rel.display(),
                        t.display()
                    ));
                }
            }
        }
    }
    found
}

fn crate_src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

#[test]
fn ident_sub_layers_import_only_from_lower_ones() {
    let found = layer_violations(&crate_src(), "ident", IDENT_LAYERS);
    assert!(found.is_empty(), "{found:#?}");
}

#[test]
fn recording_sub_layers_import_only_from_lower_ones() {
    let found = layer_violations(&crate_src(), "recording", RECORDING_LAYERS);
    assert!(found.is_empty(), "{found:#?}");
}

#[test]
fn io_sub_layers_import_only_from_lower_ones() {
    let found = layer_violations(&crate_src(), "io", IO_LAYERS);
    assert!(found.is_empty(), "{found:#?}");
}

/// Write `files` (path, text) under a fresh `src/` folder.
fn fixture(files: &[(&str, &str)]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for (path, text) in files {
        let p = dir.path().join("src").join(path);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, text).unwrap();
    }
    dir
}

#[test]
fn the_sub_layer_check_reports_upward_imports() {
    const TABLE: &[&[&str]] = &[&["low"], &["mid.rs"], &["high"]];
    let files = [
        (
            "m/mod.rs",
            "mod high;\nmod low;\nmod mid;\npub use high::Top;\npub use low::Base;\n",
        ),
        ("m/low/mod.rs", "mod a;\nmod b;\npub use a::Base;\n"),
        ("m/low/a.rs", "pub struct Base;\n"),
        ("m/low/b.rs", "use super::a::Base;\n"),
        ("m/mid.rs", "use crate::m::Base;\npub struct Middle;\n"),
        ("m/high/mod.rs", "mod top;\npub use top::Top;\n"),
        (
            "m/high/top.rs",
            "use crate::m::{mid::Middle, low::Base};\npub struct Top;\n",
        ),
    ];
    let clean = fixture(&files);
    let found = layer_violations(&clean.path().join("src"), "m", TABLE);
    assert!(found.is_empty(), "{found:#?}");

    // a direct upward path, one through the façade, one through `super::`,
    // one in a group, and a file no sub-layer holds
    let mut bad = files.to_vec();
    bad[3] = ("m/low/b.rs", "use crate::m::mid::Middle;\n");
    bad[4] = ("m/mid.rs", "use crate::m::Top;\npub struct Middle;\n");
    bad.push((
        "m/low/c.rs",
        "use super::super::{mid::Middle, high::Top as T};\n",
    ));
    bad.push(("m/stray.rs", "pub struct Stray;\n"));
    let dirty = fixture(&bad);
    let found = layer_violations(&dirty.path().join("src"), "m", TABLE);
    let expect = [
        "m/low/b.rs (sub-layer 0) imports m/mid.rs (sub-layer 1)",
        "m/mid.rs (sub-layer 1) imports m/high/top.rs (sub-layer 2)",
        "m/low/c.rs (sub-layer 0) imports m/mid.rs (sub-layer 1)",
        "m/low/c.rs (sub-layer 0) imports m/high/top.rs (sub-layer 2)",
        "m/stray.rs is in no sub-layer",
    ];
    for e in expect {
        assert!(found.iter().any(|f| f == e), "missing {e:?} in {found:#?}");
    }
    assert_eq!(found.len(), expect.len(), "{found:#?}");
}
