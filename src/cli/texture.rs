//! `xylem texture`: render a planar slice of a solid texture or noise to PNG.
//!
//! The source of the colours is chosen in [`source`]; the slicing and output are shared, so
//! further sources (wood presets) only add a branch there and their own options.

use crate::render::image_io::write_png_linear;
use crate::texture::{self, first_non_finite, Plane, Slice, SolidTexture};
use anyhow::{bail, Context};
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Texture or noise: marble, slab_marble, ring_wood, log_wood, stone, clouds, worley, value,
    /// gradient, fbm, warp, sparse_convolution (`--list` shows their parameters).
    pub name: Option<String>,
    /// A texture parameter, KEY=VALUE (repeatable), e.g. `--param scale=20`.
    #[arg(long = "param", value_name = "KEY=VALUE")]
    pub params: Vec<String>,
    /// Slicing plane: xy, xz or yz.
    #[arg(long, default_value = "xy")]
    pub plane: Plane,
    /// Position of the plane along its normal (mm).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub offset: f32,
    /// Side of the square window (mm), centred on the axis.
    #[arg(long, default_value_t = 100.0)]
    pub size: f32,
    /// Image side in pixels.
    #[arg(long, default_value_t = 256)]
    pub res: u32,
    /// Exposure of the PNG in stops.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,
    /// Output PNG.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// List the textures and their parameters (default, range, meaning) and exit.
    #[arg(long)]
    pub list: bool,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    if args.list {
        list();
        return Ok(ExitCode::SUCCESS);
    }
    let slice = slice(&args)?;
    let Some(out) = args.out.as_ref() else {
        bail!("--out FILE.png is required");
    };
    let source = source(&args)?;
    let pixels = slice.render(&|p| source.eval(p));
    if let Some((x, y)) = first_non_finite(&pixels, slice.res) {
        bail!("the texture gave a non-finite colour at pixel ({x}, {y}); nothing written");
    }
    write_png_linear(out, slice.res, slice.res, &pixels, args.exposure)
        .with_context(|| format!("writing {}", out.display()))?;
    println!(
        "wrote {} ({}×{} px, {} mm, plane {:?} at {} mm)",
        out.display(),
        slice.res,
        slice.res,
        slice.size,
        slice.plane,
        slice.offset
    );
    Ok(ExitCode::SUCCESS)
}

/// What to slice: a named texture with its `--param`s.
fn source(args: &Args) -> anyhow::Result<Box<dyn SolidTexture>> {
    let Some(name) = args.name.as_deref() else {
        bail!("name a texture: {} (or --list)", texture::NAMES.join(", "));
    };
    let params = parse_params(&args.params)?;
    Ok(texture::by_name(name, &params)?)
}

/// The slice geometry, checked.
fn slice(args: &Args) -> anyhow::Result<Slice> {
    if !(args.size.is_finite() && args.size > 0.0) {
        bail!("--size {} must be a positive length (mm)", args.size);
    }
    if !args.offset.is_finite() {
        bail!("--offset {} must be finite", args.offset);
    }
    if !(1..=16384).contains(&args.res) {
        bail!("--res {} must be in 1..=16384", args.res);
    }
    Ok(Slice {
        plane: args.plane,
        offset: args.offset,
        size: args.size,
        res: args.res,
    })
}

/// `KEY=VALUE` strings to a parameter map.
fn parse_params(items: &[String]) -> anyhow::Result<BTreeMap<String, f32>> {
    let mut map = BTreeMap::new();
    for item in items {
        let Some((k, v)) = item.split_once('=') else {
            bail!("--param `{item}`: expected KEY=VALUE");
        };
        let value: f32 = v
            .trim()
            .parse()
            .with_context(|| format!("--param `{item}`: `{v}` is not a number"))?;
        map.insert(k.trim().to_string(), value);
    }
    Ok(map)
}

fn list() {
    for name in texture::NAMES {
        println!("{name}");
        for p in texture::params(name).unwrap_or(&[]) {
            println!(
                "    {:<16} default {:<8} range [{}, {}]  {}",
                p.name, p.default, p.min, p.max, p.doc
            );
        }
    }
}
