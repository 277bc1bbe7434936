//! Rig parameters and effects from a TOML file or a JSON text (a Python
//! dictionary), checked as the command-line tool checks them: every value in
//! range, the closed loop finite, an unstable loop refused unless allowed.

use std::path::Path;

use feedid::drive::{check_model, RigEffects, RigParams};
use pyo3::prelude::*;

use crate::errors::{input, to_py, IntoPy};

/// Where parameters come from: a TOML file, a JSON text (from a dict), or
/// the built-in rig.
pub fn load(path: Option<&str>, json: Option<&str>, allow_unstable: bool) -> PyResult<RigParams> {
    let (params, name) = match (path, json) {
        (Some(p), _) => {
            let p = Path::new(p);
            let text = feedid::io::read_small_text(p).py_err()?;
            (
                RigParams::from_toml_str(&text, Some(p)).py_err()?,
                p.display().to_string(),
            )
        }
        (None, Some(j)) => {
            let params: RigParams =
                serde_json::from_str(j).map_err(|e| input(format!("params: {e}")))?;
            params
                .validate()
                .map_err(|e| input(format!("params: {e}")))?;
            (params, "params".to_string())
        }
        (None, None) => (RigParams::default(), "the built-in rig".to_string()),
    };
    let check = check_model(&params).map_err(|e| {
        input(format!(
            "{name}: these parameters give no usable model: {e}"
        ))
    })?;
    if !check.stable && !allow_unstable {
        let e = feedid::Error::UnstableModel {
            poles: check.describe_unstable(),
        };
        return Err(input(format!(
            "{name}: {e}; give allow_unstable=True to use it anyway"
        )));
    }
    Ok(params)
}

/// Rig effects from a TOML file (`feedid simulate --effects`).
pub fn effects(path: &str) -> PyResult<RigEffects> {
    let p = Path::new(path);
    let text = feedid::io::read_small_text(p).map_err(to_py)?;
    let fx: RigEffects = toml::from_str(&text).map_err(|e| {
        input(format!(
            "{}: {}",
            p.display(),
            e.to_string().replace('\n', " ")
        ))
    })?;
    fx.validate()
        .map_err(|e| input(format!("{}: {e}", p.display())))?;
    Ok(fx)
}
