//! `xylem render`: render a scene file to `DIR/<scene>.exr` (beauty + AOV layers) and
//! `DIR/<scene>.png` (sRGB preview).

use anyhow::Context;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use xylem::scene::quality::Quality;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Scene file (TOML, see scenes/README.md).
    scene: PathBuf,
    /// Samples per pixel, 1 to 1000000 (overrides the scene\'s render.spp).
    #[arg(long, value_parser = super::parse_spp)]
    spp: Option<u32>,
    /// Image size WxH (overrides render.width / render.height), e.g. 512x512.
    #[arg(long, value_parser = parse_res)]
    res: Option<(u32, u32)>,
    /// Output folder.
    #[arg(long, default_value = "out")]
    out: PathBuf,
    /// Worker threads (0 = all cores; at most 16 per core).
    #[arg(long, default_value_t = 0, value_parser = super::parse_threads)]
    threads: usize,
    /// Speed/accuracy preset measured in validation/TRADEOFF.md (spp and wood-model knobs, as
    /// `sweep --quality`); `--spp` and `--footprint-filter` still override it.
    #[arg(long, value_parser = crate::named::<Quality>(&Quality::NAMES))]
    quality: Option<Quality>,
    /// Band-limit wood by the pixel footprint, `on` or `off` (overrides render.footprint_filter,
    /// default on).
    #[arg(long, value_name = "on|off", value_parser = super::parse_on_off)]
    footprint_filter: Option<bool>,
    /// Random seed (overrides render.seed).
    #[arg(long)]
    seed: Option<u64>,
    /// How the samples are spread over the pixels (overrides render.sampling, default
    /// adaptive): `adaptive` takes a pilot of spp/4 in every pixel, then spends what the rest of
    /// a uniform render would cost on the pixels whose neighbours came out noisy (for cheap
    /// pixels more samples); `uniform` takes spp in every pixel.
    #[arg(long, value_parser = crate::named::<xylem::render::Sampling>(&xylem::render::Sampling::NAMES))]
    sampling: Option<xylem::render::Sampling>,
    /// Before rendering, print which wood features the scene skips and why: per wood material,
    /// the smallest pixel footprint its objects get from the camera and each fine feature (pores,
    /// rays, cell texture) kept, fading or skipped (faded to its mean in every pixel).
    #[arg(long)]
    explain: bool,
    /// Do not show the progress bar.
    #[arg(long)]
    quiet: bool,
    /// Render even when the memory or disk estimate exceeds what the machine has.
    #[arg(long)]
    ignore_limits: bool,
    /// Also write a JSON summary of the run to FILE (`-`: print it on stdout instead of the
    /// text lines): scene, settings, camera, time, rays, outputs, image statistics.
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
}

/// The `--explain` text: what [`xylem::render::lod::plan`] finds for every wood material.
pub(crate) fn explain(scene: &xylem::render::Scene, spp: u32) -> String {
    use xylem::render::lod::{plan, Detail};
    let plans = plan(scene, spp);
    if plans.is_empty() {
        return "explain: no procedural wood in view, nothing to skip\n".into();
    }
    let mut s = String::new();
    for p in plans {
        let fp = if p.footprint.is_infinite() {
            "no object in view".to_string()
        } else if p.footprint == 0.0 {
            "footprint filter off or an object at the eye: every feature kept".to_string()
        } else {
            format!("smallest pixel footprint {:.3} mm of wood", p.footprint)
        };
        s += &format!(
            "explain: material #{} ({} object{}): {fp}\n",
            p.material,
            p.objects,
            if p.objects == 1 { "" } else { "s" }
        );
        for f in &p.features {
            let why = match f.detail {
                Detail::Skipped => format!(
                    "skipped: {:.3} mm, under half of every footprint (faded to its mean, not \
                     evaluated)",
                    f.size
                ),
                Detail::Fading => format!(
                    "fading: {:.3} mm, under every footprint, over half of the smallest (part faded)",
                    f.size
                ),
                Detail::Kept => format!("kept: {:.3} mm, shown where the footprint is smaller", f.size),
            };
            s += &format!("explain:   {:<18}{why}\n", f.name);
        }
    }
    s
}

/// Parses `WxH` with both in 1..=[`MAX_RESOLUTION`](xylem::scene::MAX_RESOLUTION).
pub(crate) fn parse_res(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("`{s}`: expected WxH, e.g. 512x512"))?;
    let p = |v: &str| -> Result<u32, String> {
        let n: u32 = v
            .trim()
            .parse()
            .map_err(|_| format!("`{s}`: `{v}` is not a whole number"))?;
        let max = xylem::scene::MAX_RESOLUTION;
        if (1..=max).contains(&n) {
            Ok(n)
        } else {
            Err(format!("`{s}`: {n} is out of range (allowed 1 to {max})"))
        }
    };
    Ok((p(w)?, p(h)?))
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let mut loaded = xylem::scene::load_with(&args.scene, args.ignore_limits)?;
    for w in &loaded.warnings {
        eprintln!("warning: {w}");
    }
    xylem::scene::Overrides {
        quality: args.quality,
        spp: args.spp,
        res: args.res,
        seed: args.seed,
        footprint_filter: args.footprint_filter,
        sampling: args.sampling,
    }
    .apply(&mut loaded)?;
    let bar = super::progress::Bar::new(!args.quiet);
    let run = xylem::render::RunOptions {
        threads: args.threads,
        progress: &bar,
    };
    let cam = &loaded.scene.camera;
    eprintln!(
        "{}: {}x{}, {} spp ({}), {}, {} triangles (BVH built in {:.1} ms)",
        loaded.name,
        cam.width,
        cam.height,
        loaded.settings.spp,
        loaded.settings.sampling,
        loaded.settings.integrator,
        loaded.scene.accel.triangle_count(),
        loaded.scene.accel.build_time.as_secs_f64() * 1e3
    );
    if args.explain {
        eprint!("{}", explain(&loaded.scene, loaded.settings.spp));
    }
    xylem::render::resources::Resources::render(cam.width, cam.height)
        .check(&args.out, args.ignore_limits)?;
    // The output folder is made (and so checked) before the render, not after it.
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create output folder {}", args.out.display()))?;
    xylem::output::Staged::new(&args.out.join(format!("{}.exr", loaded.name)))
        .with_context(|| format!("cannot write into output folder {}", args.out.display()))?;
    let out = xylem::render::render(&loaded.scene, &loaded.settings, &run)?;
    let exr = args.out.join(format!("{}.exr", loaded.name));
    let png = args.out.join(format!("{}.png", loaded.name));
    let meta = meta_pairs(&loaded, &args.scene);
    write_outputs(&out.image, &exr, &png, loaded.exposure, &meta)?;
    let secs = out.elapsed.as_secs_f64();
    let to_stdout = args.json.as_deref() == Some(Path::new("-"));
    if !to_stdout {
        println!(
            "rendered {} in {:.2} s: {:.2} Mrays/s ({} rays)",
            loaded.name,
            secs,
            out.rays as f64 / secs.max(1e-9) / 1e6,
            out.rays
        );
    }
    if out.image.nonfinite > 0 {
        eprintln!(
            "warning: {} non-finite samples were dropped (counted as zero)",
            out.image.nonfinite
        );
    }
    if let Some(file) = &args.json {
        let summary = summary(&loaded, &args.scene, &out, &meta, [&exr, &png]);
        let text = serde_json::to_string_pretty(&summary)? + "\n";
        if to_stdout {
            print!("{text}");
            return Ok(ExitCode::SUCCESS);
        }
        xylem::output::write_atomic(file, text.as_bytes())
            .with_context(|| format!("cannot write the JSON summary {}", file.display()))?;
        println!("wrote {}", file.display());
    }
    println!("wrote {} and {}", exr.display(), png.display());
    Ok(ExitCode::SUCCESS)
}

/// The EXR header's description of the render (scene, file, spp, seed, integrator, camera).
fn meta_pairs(loaded: &xylem::scene::LoadedScene, scene: &Path) -> Vec<(&'static str, String)> {
    loaded.settings.exr_meta(
        &loaded.name,
        &scene.display().to_string(),
        &loaded.scene.camera,
    )
}

/// `render --json`: what was rendered, how, how long it took, what was written and the image's
/// mean and peak (linear RGB) and its dropped samples.
fn summary(
    loaded: &xylem::scene::LoadedScene,
    scene: &Path,
    out: &xylem::render::RenderOutput,
    meta: &[(&'static str, String)],
    files: [&Path; 2],
) -> serde_json::Value {
    let img = &out.image;
    let n = img.beauty.len().max(1) as f64;
    let mean = img
        .beauty
        .iter()
        .fold([0f64; 3], |a, c| {
            [a[0] + c.x as f64, a[1] + c.y as f64, a[2] + c.z as f64]
        })
        .map(|x| x / n);
    let peak = img.beauty.iter().fold(0f32, |m, c| m.max(c.max_element()));
    let secs = out.elapsed.as_secs_f64();
    let cam = &loaded.scene.camera;
    serde_json::json!({
        "xylem": env!("CARGO_PKG_VERSION"),
        "scene": loaded.name,
        "scene_file": scene.display().to_string(),
        "width": cam.width,
        "height": cam.height,
        "spp": loaded.settings.spp,
        "seed": loaded.settings.seed,
        "sampling": loaded.settings.sampling.to_string(),
        "integrator": loaded.settings.integrator.to_string(),
        "camera": meta.iter().find(|m| m.0 == "camera").map(|m| m.1.clone()),
        "lights": loaded.scene.lights.len(),
        "triangles": loaded.scene.accel.triangle_count(),
        "seconds": secs,
        "rays": out.rays,
        "schedule": if out.waves { "waves" } else { "paths" },
        "mrays_per_s": out.rays as f64 / secs.max(1e-9) / 1e6,
        "nonfinite_samples": img.nonfinite,
        "mean_rgb": mean,
        "peak": peak,
        "outputs": files.iter().map(|f| f.display().to_string()).collect::<Vec<_>>(),
    })
}

/// Writes the EXR and the PNG as one pair: both are encoded to temporary files first, then, under
/// the folder's lock (so two renders into one folder never leave one's EXR beside the other's
/// PNG), the old PNG is removed, the EXR renamed into place and the PNG last. The PNG therefore
/// marks a complete pair even when the run is killed between the renames.
fn write_outputs(
    image: &xylem::render::RenderedImage,
    exr: &Path,
    png: &Path,
    exposure: f32,
    meta: xylem::picture::exr::ExrMeta,
) -> anyhow::Result<()> {
    use xylem::picture::file::commit;
    use xylem::picture::png::stage_png_linear;
    use xylem::render::image_io::stage_image_exr;
    let (staged_exr, staged_png) = rayon::join(
        || stage_image_exr(exr, image, meta),
        || stage_png_linear(png, image.width, image.height, &image.beauty, exposure),
    );
    let (staged_exr, staged_png) = (staged_exr?, staged_png?);
    let folder = png.parent().unwrap_or(Path::new("."));
    let _lock = xylem::output::FolderLock::wait_exclusive(folder)?;
    xylem::output::remove_if_present(png)
        .with_context(|| format!("cannot replace {}", png.display()))?;
    commit(staged_exr)?;
    commit(staged_png)?;
    Ok(())
}
