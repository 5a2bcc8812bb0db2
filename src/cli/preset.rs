//! `xylem preset`: the built-in species presets.

use crate::wood;
use anyhow::Context;
use std::process::ExitCode;

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(subcommand)]
    what: What,
}

#[derive(clap::Subcommand, Debug)]
enum What {
    /// List the built-in presets and the features each one switches on.
    List,
    /// Print a preset's TOML (a starting point for `--preset-file`).
    Show { name: String },
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    match args.what {
        What::List => {
            for name in wood::PRESET_NAMES {
                let p = wood::preset(name).with_context(|| format!("preset {name}"))?;
                println!("{name:<24} {}", features(&p).join(", "));
            }
        }
        What::Show { name } => print!("{}", wood::preset_text(&name)?),
    }
    Ok(ExitCode::SUCCESS)
}

/// The model features a preset switches on, in words.
fn features(p: &wood::WoodParams) -> Vec<&'static str> {
    let d = &p.distortion;
    [
        (p.growth.is_some(), "growth variation"),
        (p.interlock.is_some(), "interlocked grain"),
        (d.radial.is_some(), "r-distortion"),
        (d.tangential.is_some(), "θ-distortion"),
        (d.longitudinal.is_some(), "z-distortion"),
        (
            p.pores.as_ref().is_some_and(|x| x.ring_porosity >= 0.75),
            "ring-porous",
        ),
        (
            p.pores
                .as_ref()
                .is_some_and(|x| x.ring_porosity > 0.25 && x.ring_porosity < 0.75),
            "semi-ring-porous",
        ),
        (
            p.pores.as_ref().is_some_and(|x| x.ring_porosity <= 0.25),
            "diffuse-porous",
        ),
        (p.rays.is_some(), "rays"),
        (p.knots.is_some(), "knots"),
    ]
    .into_iter()
    .filter_map(|(on, name)| on.then_some(name))
    .collect()
}
