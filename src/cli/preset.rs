//! `xylem preset`: the built-in species presets.

use crate::render::image_io::write_png_linear;
use crate::texture::{Plane, Slice};
use crate::wood;
use crate::wood::{preview_color, Needs};
use anyhow::Context;
use std::path::{Path, PathBuf};
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
    /// Write each preset's three cuts (transverse xy, radial xz, tangential yz) as PNGs, plus a
    /// contact sheet of all of them.
    Cuts {
        /// Output folder.
        #[arg(long, default_value = "out/presets")]
        out: PathBuf,
        /// Image side in pixels.
        #[arg(long, default_value_t = 192)]
        res: u32,
        /// Side of each cut in mm.
        #[arg(long, default_value_t = 100.0)]
        size: f32,
        /// Only these presets (default: all).
        #[arg(long)]
        only: Vec<String>,
        /// Plain diffuse colour instead of shading by fibre direction.
        #[arg(long)]
        flat: bool,
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
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
        What::Cuts {
            out,
            res,
            size,
            only,
            flat,
            seed,
        } => cuts(&out, res, size, &only, !flat, seed)?,
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

/// The three cuts of each preset (transverse at z = 0, radial through the pith, tangential `size`
/// mm from the pith), one PNG per cut, and `sheet.png` (rows: presets; columns: xy, xz, yz).
fn cuts(
    out: &Path,
    res: u32,
    size: f32,
    only: &[String],
    shade: bool,
    seed: u64,
) -> anyhow::Result<()> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let names: Vec<&str> = if only.is_empty() {
        wood::PRESET_NAMES.to_vec()
    } else {
        only.iter().map(String::as_str).collect()
    };
    let bar = indicatif::ProgressBar::new(3 * names.len() as u64);
    let mut sheet = vec![glam::Vec3::ZERO; (3 * res * res) as usize * names.len()];
    for (row, name) in names.iter().enumerate() {
        let volume = wood::WoodVolume::new(wood::preset(name)?, seed)?;
        let cuts = [
            (Plane::Xy, "xy", 0.0, glam::Vec3::Z),
            (Plane::Xz, "xz", 0.0, glam::Vec3::Y),
            (Plane::Yz, "yz", size, glam::Vec3::X),
        ];
        for (col, (plane, tag, offset, view)) in cuts.into_iter().enumerate() {
            let slice = Slice {
                plane,
                offset,
                size,
                res,
            };
            let needs = if shade {
                Needs::COLOR_FIBERS
            } else {
                Needs::COLOR
            };
            let px = slice.render_rows(&|p, o| {
                let mut texels = vec![crate::wood::WoodTexel::default(); p.len()];
                volume.eval_many(p, needs, &mut texels);
                for (o, t) in o.iter_mut().zip(&texels) {
                    *o = preview_color(t, view, shade);
                }
            });
            let path = out.join(format!("{name}_{tag}.png"));
            write_png_linear(&path, res, res, &px, 0.0)
                .with_context(|| format!("writing {}", path.display()))?;
            for j in 0..res {
                let dst = ((row as u32 * res + j) * 3 * res + col as u32 * res) as usize;
                let src = (j * res) as usize;
                sheet[dst..dst + res as usize].copy_from_slice(&px[src..src + res as usize]);
            }
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    let path = out.join("sheet.png");
    write_png_linear(&path, 3 * res, res * names.len() as u32, &sheet, 0.0)
        .with_context(|| format!("writing {}", path.display()))?;
    println!("wrote {} cuts and {}", 3 * names.len(), path.display());
    Ok(())
}
