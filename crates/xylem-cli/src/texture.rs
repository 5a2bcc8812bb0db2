//! `xylem texture`: render a planar slice of a solid texture or noise to PNG (sRGB preview) or
//! EXR (linear 32-bit float RGB), chosen by the output's extension.
//!
//! The source of the colours is chosen in [`source`]; the slicing and output are shared, so
//! further sources (wood presets) only add a branch there and their own options.

use anyhow::{bail, Context};
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::process::ExitCode;
use xylem::picture::exr::{write_exr_layers_with, ExrCompression, ExrLayer};
use xylem::picture::png::write_png_linear;
use xylem::texture::{
    self, first_non_finite, Plane, Slice, SolidTexture, DEFAULT_SLICE_SAMPLES, MAX_SLICE_SAMPLES,
};

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
    /// Image side in pixels, 1 to 16384.
    #[arg(long, default_value_t = 256)]
    pub res: u32,
    /// Samples along each side of a pixel, 1 to 16: each pixel is the mean over a regular grid
    /// of SAMPLES² points (a box filter); 1 point-samples the pixel centre, which aliases where
    /// the texture has detail finer than a pixel (notes/picture.md).
    #[arg(long, default_value_t = DEFAULT_SLICE_SAMPLES)]
    pub samples: u32,
    /// Exposure of the PNG in stops, -30 to 30 (an EXR keeps the linear values).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = super::parse_exposure)]
    pub exposure: f32,
    /// Output file: `.png` (sRGB, exposure applied) or `.exr` (linear float RGB).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// List the textures and their parameters (default, range, meaning) and exit.
    #[arg(long)]
    pub list: bool,
    /// Slice a wood species preset instead of a texture (`xylem preset list`).
    #[arg(long, conflicts_with_all = ["name", "preset_file"])]
    pub preset: Option<String>,
    /// Slice a wood parameter file (TOML like scenes/presets/*.toml).
    #[arg(long, conflicts_with = "name")]
    pub preset_file: Option<PathBuf>,
    /// Wood: seed of the tree.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Wood: plain diffuse colour, without the fibre highlight seen along the plane's normal.
    #[arg(long)]
    pub flat: bool,
    /// Animate over this many seconds: write an animated PNG of `--frames` frames from time 0
    /// (textures with a `time` parameter: clouds, rust).
    #[arg(long, value_name = "SECONDS", conflicts_with_all = ["preset", "preset_file"])]
    pub animate: Option<f32>,
    /// Frames of an `--animate` sequence, 1 to 1000 (12 per second of the animation file).
    #[arg(long, default_value_t = 24)]
    pub frames: usize,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    if args.list {
        list();
        return Ok(ExitCode::SUCCESS);
    }
    let slice = slice(&args)?;
    let Some(out) = args.out.as_ref() else {
        bail!("--out FILE.png or FILE.exr is required");
    };
    let format = OutFormat::of(out)?;
    check_memory(&args, &slice, format)?;
    if let Some(seconds) = args.animate {
        animate(&args, &slice, out, seconds)?;
        return Ok(ExitCode::SUCCESS);
    }
    let source = source(&args)?;
    let pixels = slice.render_rows(&|p, o| source.eval_many(p, o));
    if let Some((x, y)) = first_non_finite(&pixels, slice.res) {
        bail!("the texture gave a non-finite colour at pixel ({x}, {y}); nothing written");
    }
    match format {
        OutFormat::Png => write_png_linear(out, slice.res, slice.res, &pixels, args.exposure),
        OutFormat::Exr => {
            let what = match (&args.preset, &args.preset_file, &args.name) {
                (Some(p), _, _) => format!("preset {p}"),
                (_, Some(f), _) => format!("preset file {}", f.display()),
                (_, _, n) => format!("texture {}", n.as_deref().unwrap_or("?")),
            };
            let meta = [
                ("source", what),
                ("params", args.params.join(" ")),
                ("seed", args.seed.to_string()),
                (
                    "slice",
                    format!(
                        "plane {} at {} mm, {} mm square",
                        slice.plane, slice.offset, slice.size
                    ),
                ),
            ];
            let layer = ExrLayer {
                name: "",
                channels: &["R", "G", "B"],
                data: pixels.iter().flat_map(|c| c.to_array()).collect(),
            };
            write_exr_layers_with(
                out,
                slice.res,
                slice.res,
                &[layer],
                ExrCompression::Zip,
                &meta,
            )
        }
    }
    .with_context(|| format!("writing {}", out.display()))?;
    println!(
        "wrote {} ({}×{} px, {} mm, plane {} at {} mm)",
        out.display(),
        slice.res,
        slice.res,
        slice.size,
        slice.plane,
        slice.offset
    );
    Ok(ExitCode::SUCCESS)
}

/// The output's format, by its extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum OutFormat {
    Png,
    Exr,
}

impl OutFormat {
    fn of(path: &std::path::Path) -> anyhow::Result<Self> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("png") => Ok(OutFormat::Png),
            Some("exr") => Ok(OutFormat::Exr),
            _ => bail!(
                "--out {}: the extension must be .png (sRGB preview) or .exr (linear float)",
                path.display()
            ),
        }
    }
}

/// What to slice: a wood preset, or a named texture with its `--param`s.
/// The texture at times 0, T/n, …, (n−1)T/n as a looping APNG (12 frames/s).
fn animate(args: &Args, slice: &Slice, out: &std::path::Path, seconds: f32) -> anyhow::Result<()> {
    let Some(name) = args.name.as_deref() else {
        bail!("--animate needs a texture name");
    };
    if !texture::ANIMATED.contains(&name) {
        bail!(
            "texture `{name}` has no `time` parameter; animated textures: {}",
            texture::ANIMATED.join(", ")
        );
    }
    if !(seconds.is_finite() && seconds > 0.0) {
        bail!("--animate {seconds}: the duration must be a positive number of seconds");
    }
    if !(1..=1000).contains(&args.frames) {
        bail!("--frames {}: allowed 1 to 1000", args.frames);
    }
    let mut params = parse_params(&args.params)?;
    if params.contains_key("time") {
        bail!("--param time: set by --animate; give --animate SECONDS instead");
    }
    let bar = indicatif::ProgressBar::new(args.frames as u64);
    let mut frames = Vec::with_capacity(args.frames);
    for i in 0..args.frames {
        params.insert("time".into(), seconds * i as f32 / args.frames as f32);
        let tex = texture::by_name(name, &params)?;
        let pixels = slice.render_rows(&|p, o| tex.eval_many(p, o));
        if let Some((x, y)) = first_non_finite(&pixels, slice.res) {
            bail!("frame {i}: non-finite colour at pixel ({x}, {y}); nothing written");
        }
        frames.push(xylem::picture::Rgb8 {
            width: slice.res,
            height: slice.res,
            data: xylem::picture::srgb::to_srgb8(&pixels, args.exposure),
        });
        bar.inc(1);
    }
    bar.finish_and_clear();
    xylem::picture::png::write_apng(out, &frames, 12)
        .with_context(|| format!("writing {}", out.display()))?;
    println!(
        "wrote {} ({} frames over {seconds} s)",
        out.display(),
        args.frames
    );
    Ok(())
}

fn source(args: &Args) -> anyhow::Result<Box<dyn SolidTexture>> {
    if let Some(wood) = wood_source(args)? {
        return Ok(wood);
    }
    let Some(name) = args.name.as_deref() else {
        bail!("name a texture: {} (or --list)", texture::NAMES.join(", "));
    };
    let params = parse_params(&args.params)?;
    Ok(texture::by_name(name, &params)?)
}

/// Peak bytes per pixel of one texture image, from the buffers it allocates: the linear colours
/// (12), then for a PNG the 8-bit copy and its encoding (3 + 3, rounded up to 24 in all); for
/// an EXR the flat float copy, the per-channel samples and the encoding (12 each, 48 in all;
/// measured 38: a 4096² EXR peaked at 632 MB resident).
const PNG_BYTES_PER_PIXEL: u64 = 24;
const EXR_BYTES_PER_PIXEL: u64 = 48;

/// Refuses, before a pixel is computed, a texture whose buffers would not fit in the memory
/// available (`--res 16384` as EXR is about 12 GiB; an animation holds every 8-bit frame).
fn check_memory(args: &Args, slice: &Slice, format: OutFormat) -> anyhow::Result<()> {
    let px = slice.res as u64 * slice.res as u64;
    let (what, memory) = match (args.animate, format) {
        (Some(_), _) => (
            format!(
                "{} frames of a {}² texture animation",
                args.frames, slice.res
            ),
            px * (12 + 6 * args.frames.clamp(1, 1000) as u64),
        ),
        (None, OutFormat::Png) => (
            format!("a {}² texture PNG", slice.res),
            px * PNG_BYTES_PER_PIXEL,
        ),
        (None, OutFormat::Exr) => (
            format!("a {}² texture EXR", slice.res),
            px * EXR_BYTES_PER_PIXEL,
        ),
    };
    use xylem::resources::{available_memory, Bytes};
    match available_memory() {
        Some(have) if memory > have => bail!(
            "{what} needs about {} of memory but {} is available; lower --res (or --frames)",
            Bytes(memory),
            Bytes(have)
        ),
        _ => Ok(()),
    }
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
    if !(1..=MAX_SLICE_SAMPLES).contains(&args.samples) {
        bail!(
            "--samples {} must be in 1..={MAX_SLICE_SAMPLES} (per side of a pixel)",
            args.samples
        );
    }
    Ok(Slice {
        plane: args.plane,
        offset: args.offset,
        size: args.size,
        res: args.res,
        samples: args.samples,
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

/// A wood volume seen as a solid texture: its preview colour along the plane's normal.
struct WoodSlice {
    volume: xylem::wood::WoodVolume,
    view: glam::Vec3,
    shade: bool,
}

impl WoodSlice {
    /// Colour alone, or with the fibres when the preview shades their highlight.
    fn needs(&self) -> xylem::wood::Needs {
        if self.shade {
            xylem::wood::Needs::COLOR_FIBERS
        } else {
            xylem::wood::Needs::COLOR
        }
    }
}

impl SolidTexture for WoodSlice {
    fn eval(&self, p: glam::Vec3) -> glam::Vec3 {
        xylem::wood::preview_color(&self.volume.eval(p, self.needs()), self.view, self.shade)
    }

    /// A row at once through [`xylem::wood::WoodVolume::eval_many`] (the same texels).
    fn eval_many(&self, points: &[glam::Vec3], out: &mut [glam::Vec3]) {
        let mut texels = vec![xylem::wood::WoodTexel::default(); points.len()];
        self.volume.eval_many(points, self.needs(), &mut texels);
        for (o, t) in out.iter_mut().zip(&texels) {
            *o = xylem::wood::preview_color(t, self.view, self.shade);
        }
    }
}

/// The wood source of `--preset` / `--preset-file`, if one is given.
fn wood_source(args: &Args) -> anyhow::Result<Option<Box<dyn SolidTexture>>> {
    let params = match (&args.preset, &args.preset_file) {
        (Some(name), _) => xylem::wood::preset(name)?,
        (None, Some(file)) => xylem::scene::read_preset_file(file)?,
        (None, None) => return Ok(None),
    };
    let volume = xylem::wood::WoodVolume::new(params, args.seed)?;
    let view = match args.plane {
        Plane::Xy => glam::Vec3::Z,
        Plane::Xz => glam::Vec3::Y,
        Plane::Yz => glam::Vec3::X,
    };
    Ok(Some(Box::new(WoodSlice {
        volume,
        view,
        shade: !args.flat,
    })))
}
