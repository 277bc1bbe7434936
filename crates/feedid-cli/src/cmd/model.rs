//! `feedid model`: the nominal model in numbers.

use anyhow::Result;
use feedid::drive::{D1Variant, ModelSummary};

use crate::args::{D1Arg, ModelArgs};
use crate::cmd::{check_distinct, load_params, params_error, Outputs};

/// Print the model summary as text or JSON.
pub fn run(a: &ModelArgs) -> Result<()> {
    if let Some(p) = &a.save_params {
        check_distinct(
            &a.params.iter().map(|p| p.as_path()).collect::<Vec<_>>(),
            &[p],
        )?;
    }
    if let Some(structure) = crate::cmd::load_structure(a.params.as_deref())? {
        return print_structure(a, &structure);
    }
    let params = load_params(a.params.as_deref())?;
    let variant = match a.d1 {
        D1Arg::Corrected => D1Variant::Corrected,
        D1Arg::Paper => D1Variant::PaperPrinted,
    };
    let summary =
        ModelSummary::new(&params, variant).map_err(|e| params_error(a.params.as_deref(), e))?;
    if let Some(p) = &a.save_params {
        let mut outputs = Outputs::default();
        outputs.add_text(p, params.to_toml_string())?;
        outputs.commit()?;
    }
    if a.json {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        println!("{summary}");
    }
    Ok(())
}

/// `feedid model --params structure.toml`: the closed loop of a drive structure.
fn print_structure(a: &ModelArgs, s: &feedid::drive::DriveStructure) -> Result<()> {
    let name = a.params.as_deref();
    let summary = s.closed_loop().map_err(|e| params_error(name, e))?;
    if let Some(p) = &a.save_params {
        let mut outputs = Outputs::default();
        outputs.add_text(p, s.to_toml_string())?;
        outputs.commit()?;
    }
    if a.json {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        if let Some(src) = &s.source {
            println!("source: {src}");
        }
        println!("{summary}");
    }
    Ok(())
}
