//! `feedid zoo`: list the drive zoo or write its members as recordings that
//! `feedid identify` reads with no options, with a manifest of every
//! parameter drawn.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::Args;
use feedid::zoo::{MemberSpec, Zoo};
use rayon::prelude::*;

use crate::cmd::Outputs;

/// `feedid zoo`.
#[derive(Debug, Args)]
pub struct ZooArgs {
    /// Print a table of the members and the ranges they span.
    #[arg(long)]
    pub list: bool,
    /// Write each member as DIR/zoo-NNN.csv (time_s,command_m,position_m,true_position_m),
    /// with DIR/manifest.csv and DIR/manifest.json (every parameter drawn).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Members: all, regular, gapped (dropped rows), disturbed (force
    /// pulses, strong friction, coarse encoders), small (the first 20), a
    /// range A..B or A..=B, or a list 1,5,9.
    #[arg(long, value_name = "SET", default_value = "all")]
    pub members: String,
}

/// Run `feedid zoo`.
pub fn run(a: &ZooArgs) -> Result<()> {
    if !a.list && a.out.is_none() {
        bail!("nothing to do: give --list, --out DIR or both");
    }
    let zoo = Zoo::standard();
    let indices = parse_members(&a.members, &zoo)?;
    let specs: Vec<MemberSpec> = zoo
        .specs(&indices)
        .into_iter()
        .collect::<feedid::Result<_>>()?;
    if a.list {
        print!("{}", table(&specs));
    }
    if let Some(dir) = &a.out {
        write_members(&zoo, &specs, dir)?;
    }
    Ok(())
}

/// Parse `--members`.
fn parse_members(s: &str, zoo: &Zoo) -> Result<Vec<usize>> {
    let t = s.trim();
    let n = zoo.len();
    let bad = || {
        anyhow::anyhow!(
            "invalid --members `{s}`: expected all, regular, gapped, disturbed, small, A..B, A..=B or a list 1,5,9 (members 0 … {})",
            n - 1
        )
    };
    let list: Vec<usize> = match t {
        "all" => (0..n).collect(),
        "regular" => zoo.regular().collect(),
        "gapped" => zoo.gapped().collect(),
        "disturbed" => zoo.disturbed().collect(),
        "small" => zoo.small().collect(),
        _ if t.contains("..") => {
            let (lo, hi) = t.split_once("..").ok_or_else(bad)?;
            let lo: usize = lo.trim().parse().map_err(|_| bad())?;
            let hi = match hi.strip_prefix('=') {
                Some(h) => h.trim().parse::<usize>().map_err(|_| bad())?.checked_add(1),
                None => hi.trim().parse::<usize>().ok(),
            }
            .ok_or_else(bad)?;
            if lo >= hi {
                bail!("invalid --members `{s}`: the range is empty");
            }
            (lo..hi).collect()
        }
        _ => t
            .split(',')
            .map(|x| x.trim().parse::<usize>().map_err(|_| bad()))
            .collect::<Result<_>>()?,
    };
    if let Some(&i) = list.iter().find(|&&i| i >= n) {
        bail!(
            "invalid --members `{s}`: member {i} does not exist (the zoo has members 0 … {})",
            n - 1
        );
    }
    Ok(list)
}

/// The member table and the ranges the listed members span.
fn table(specs: &[MemberSpec]) -> String {
    let mut s = format!(
        "{:>5} {:<16} {:<7} {:>9} {:>6} {:>8} {:<7} {:>11}  label\n",
        "index", "plant", "command", "rate_hz", "rows", "kv", "ff", "amplitude_m"
    );
    for m in specs {
        s += &format!(
            "{:>5} {:<16} {:<7} {:>9.1} {:>6} {:>8.1} {:<7} {:>11.4e}  {}\n",
            m.index,
            m.plant.name(),
            m.command.name(),
            m.rate_hz,
            m.samples,
            m.kv,
            m.feed_forward(),
            m.amplitude_m,
            m.label
        );
    }
    let span = |name: &str, unit: &str, v: Vec<f64>| -> String {
        if v.is_empty() {
            return String::new();
        }
        let (lo, hi) = v
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                (a.min(x), b.max(x))
            });
        format!(
            "  {name:<22} {lo:.3e} … {hi:.3e} {unit} ({} members)\n",
            v.len()
        )
    };
    s += &format!("{} members span:\n", specs.len());
    s += &span(
        "recording rate",
        "Hz",
        specs.iter().map(|m| m.rate_hz).collect(),
    );
    s += &span("Kv", "1/s", specs.iter().map(|m| m.kv).collect());
    s += &span(
        "moving mass (rig)",
        "kg",
        specs.iter().filter_map(|m| m.mass_kg).collect(),
    );
    s += &span(
        "friction share (rig)",
        "",
        specs
            .iter()
            .filter(|m| m.rig.is_some())
            .map(|m| m.friction_share)
            .collect(),
    );
    s += &span(
        "backlash",
        "m",
        specs
            .iter()
            .map(|m| m.backlash_m)
            .filter(|&b| b > 0.0)
            .collect(),
    );
    s += &span(
        "placed axial mode",
        "Hz",
        specs
            .iter()
            .filter(|m| m.resonance_placed)
            .filter_map(|m| m.axial_mode_hz)
            .collect(),
    );
    s += &span(
        "dead time",
        "samples",
        specs.iter().map(|m| m.dead_time_samples as f64).collect(),
    );
    s += &span(
        "encoder resolution",
        "m",
        specs.iter().map(|m| m.resolution_m).collect(),
    );
    s += &span(
        "noise std",
        "m",
        specs.iter().map(|m| m.noise_std_m).collect(),
    );
    s += &span(
        "amplitude",
        "m",
        specs.iter().map(|m| m.amplitude_m).collect(),
    );
    let count = |f: &dyn Fn(&MemberSpec) -> bool| specs.iter().filter(|m| f(m)).count();
    s += &format!(
        "  feed-forward           none {}, vff {}, vff+aff {}\n",
        count(&|m| m.feed_forward() == "none"),
        count(&|m| m.feed_forward() == "vff"),
        count(&|m| m.feed_forward() == "vff+aff")
    );
    s += &format!(
        "  defects                glitches on {}, dropped rows on {} (identify reads them segment by segment)\n",
        count(&|m| !m.glitches.is_empty()),
        count(&|m| m.has_gaps())
    );
    let kind = |k: &'static str| count(&|m| m.disturbed.is_some_and(|d| d.disturbance.name() == k));
    s += &format!(
        "  disturbances           force pulses on {}, strong friction on {}, coarse encoder on {}\n",
        kind("pulses"),
        kind("friction"),
        kind("encoder")
    );
    s
}

/// File name of member `i`.
fn file_name(i: usize) -> String {
    format!("zoo-{i:03}.csv")
}

/// Write the members and the manifests as one output set: the members are
/// simulated in parallel into memory (the whole zoo is about 140 MB of text),
/// then written together or not at all, the manifests last.
fn write_members(zoo: &Zoo, specs: &[MemberSpec], dir: &Path) -> Result<()> {
    if dir.exists() && !dir.is_dir() {
        bail!("{}: exists and is not a directory", dir.display());
    }
    std::fs::create_dir_all(dir)
        .with_context(|| format!("{}: cannot create directory", dir.display()))?;
    let members: Vec<(PathBuf, Vec<u8>)> = specs
        .par_iter()
        .map(|s| {
            let m = zoo.member(s.index)?;
            let mut text = Vec::new();
            m.write_csv(&mut text)?;
            Ok((dir.join(file_name(s.index)), text))
        })
        .collect::<Result<_>>()?;
    let mut outputs = Outputs::default();
    for (path, text) in members {
        outputs.add(&path, move |w| w.write_all(&text))?;
    }
    // every spec with `file` (its CSV, relative to the manifest) and
    // `readable` (false for dropped rows: not uniformly sampled; read with
    // their gaps, see docs/METHODS.md, "The drive zoo")
    let entries = specs
        .iter()
        .map(|s| {
            let mut v = serde_json::to_value(s)?;
            if let Some(o) = v.as_object_mut() {
                o.insert("file".into(), file_name(s.index).into());
                o.insert("readable".into(), (!s.has_gaps()).into());
            }
            Ok(v)
        })
        .collect::<Result<Vec<_>>>()?;
    let json = serde_json::to_string_pretty(&entries)?;
    outputs.add(&dir.join("manifest.csv"), |w| manifest_csv(specs, w))?;
    outputs.add_text(&dir.join("manifest.json"), format!("{json}\n"))?;
    outputs.commit()?;
    println!(
        "{}: {} members written (zoo-NNN.csv), manifest.csv, manifest.json",
        dir.display(),
        specs.len()
    );
    Ok(())
}

/// The flat manifest: one row per member.
fn manifest_csv(specs: &[MemberSpec], w: &mut dyn Write) -> std::io::Result<()> {
    writeln!(
        w,
        "index,file,readable,plant,command,rate_hz,loop_rate_hz,samples,duration_s,kv,\
         velocity_bandwidth_hz,kvff,kaff,mass_kg,axial_mode_hz,resonance_placed,friction_share,\
         backlash_m,dead_time_samples,resolution_m,noise_std_m,amplitude_m,glitch_rows,\
         dropped_rows,gap_source,disturbance,disturbed_source,max_real_part,min_damping,\
         spectral_radius,label"
    )?;
    let opt = |v: Option<f64>| v.map(|x| x.to_string()).unwrap_or_default();
    let rows = |v: &[usize]| {
        v.iter()
            .map(|k| k.to_string())
            .collect::<Vec<_>>()
            .join(";")
    };
    for s in specs {
        let glitches: Vec<usize> = s.glitches.iter().map(|g| g.index).collect();
        writeln!(
            w,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},\"{}\"",
            s.index,
            file_name(s.index),
            !s.has_gaps(),
            s.plant.name(),
            s.command.name(),
            s.rate_hz,
            s.loop_rate_hz,
            s.samples,
            s.duration_s,
            s.kv,
            opt(s.velocity_bandwidth_hz),
            s.kvff,
            s.kaff,
            opt(s.mass_kg),
            opt(s.axial_mode_hz),
            s.resonance_placed,
            s.friction_share,
            s.backlash_m,
            s.dead_time_samples,
            s.resolution_m,
            s.noise_std_m,
            s.amplitude_m,
            rows(&glitches),
            rows(&s.dropped_rows),
            s.gap_source.map(|g| g.to_string()).unwrap_or_default(),
            s.disturbed.map(|d| d.disturbance.name()).unwrap_or_default(),
            s.disturbed
                .map(|d| d.source.to_string())
                .unwrap_or_default(),
            s.stability.max_real_part,
            s.stability.min_damping,
            s.stability.spectral_radius,
            s.label.replace('"', "\"\"")
        )?;
    }
    Ok(())
}
