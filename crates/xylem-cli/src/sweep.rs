//! `xylem sweep`: renders a light sweep (or a slice of one) and assembles its outputs.

use anyhow::Context;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use xylem::picture::exr::ExrCompression;
use xylem::scene::quality::Quality;
use xylem::sweep::batch::PrimaryMode;
use xylem::sweep::job::{run_job, SweepJob};
use xylem::sweep::parse_arc;
use xylem::sweep::sequence::{assemble, AssembleOptions};

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The scene file (TOML); its `[sweep]` table sets the defaults of the options below.
    #[arg(required_unless_present = "assemble")]
    pub scene: Option<PathBuf>,
    /// Number of frames along the arc, 1 to 100000.
    #[arg(long)]
    pub frames: Option<usize>,
    /// The arc of light angles from the zenith, FROM..TO in degrees (e.g. -60..60).
    #[arg(long, allow_hyphen_values = true)]
    pub arc: Option<String>,
    /// Output folder (default: out/<scene name>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Render only frames A..B (A to B-1) or A..=B, e.g. for a job array; assemble afterwards.
    #[arg(long)]
    pub frames_range: Option<String>,
    /// Samples per pixel, 1 to 1000000 (overrides the scene\'s render.spp).
    #[arg(long, value_parser = super::parse_spp)]
    pub spp: Option<u32>,
    /// Image size WxH, 1 to 16384 each (overrides render.width / render.height), e.g. 256x192.
    #[arg(long, value_parser = super::render::parse_res)]
    pub res: Option<(u32, u32)>,
    /// Speed/accuracy preset measured in validation/TRADEOFF.md (spp and wood-model knobs);
    /// `--spp` still overrides its sample count.
    #[arg(long, value_parser = crate::named::<Quality>(&Quality::NAMES))]
    pub quality: Option<Quality>,
    /// Render each frame from scratch, without the work frames share (to time or check the sharing).
    #[arg(long)]
    pub naive: bool,
    /// Worker threads (0 = all cores; at most 16 per core).
    #[arg(long, default_value_t = 0, value_parser = super::parse_threads)]
    pub threads: usize,
    /// Do not show the progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// Assemble contact sheet, animated PNG, CSV and viewer from the frames already in DIR.
    #[arg(long, value_name = "DIR", conflicts_with_all = ["scene", "frames", "arc", "frames_range", "spp", "res", "naive", "quality", "memory", "primaries", "emit_openjd"])]
    pub assemble: Option<PathBuf>,
    /// Compression of each frame's EXR: `rle` is fast, `zip` gives files ≈ 20 % smaller for
    /// ≈ 50 ms more CPU per 512×384 frame (notes/sweep.md), `none` writes raw floats.
    #[arg(long, default_value = "rle", value_parser = crate::named::<ExrCompression>(&ExrCompression::NAMES))]
    pub exr_compression: ExrCompression,
    /// Largest thumbnail width on the contact sheet, in pixels, 8 to 4096.
    #[arg(long, default_value_t = 240, value_parser = clap::value_parser!(u32).range(8..=4096))]
    pub thumb_width: u32,
    /// Render even when the memory or disk estimate exceeds what the machine has.
    #[arg(long)]
    pub ignore_limits: bool,
    /// Memory for the frames held at once, e.g. 512M or 4G: frames are rendered and written in
    /// batches that fit it, so a long sweep needs no more memory than a short one (default:
    /// batches of 17 frames with the primary samples kept or 54 without, whichever takes less
    /// memory, within a quarter of the memory available; notes/cluster.md).
    #[arg(long, value_name = "BYTES", value_parser = xylem::sweep::batch::parse_bytes)]
    pub memory: Option<u64>,
    /// Whether a sweep in several batches keeps each pixel sample's light-independent part from
    /// the first batch for the others (`keep`), computes it again per batch (`recompute`), or
    /// does what fits the memory and models faster (`auto`). Never changes a pixel.
    #[arg(long, default_value = "auto", value_parser = crate::named::<PrimaryMode>(&PrimaryMode::NAMES))]
    pub primaries: PrimaryMode,
    /// Render nothing: write DIR/template.json, an Open Job Description job template of this
    /// sweep (render tasks over chunks of frames, then the assembly) for `openjd run` or a farm.
    #[arg(long, value_name = "DIR", conflicts_with_all = ["frames_range", "naive"])]
    pub emit_openjd: Option<PathBuf>,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    if let Some(dir) = &args.assemble {
        return assemble_dir(dir, args.thumb_width);
    }
    let Some(scene) = &args.scene else {
        anyhow::bail!("give a scene file (or --assemble DIR)");
    };
    let mut loaded = xylem::scene::load_with(scene, args.ignore_limits)?;
    // The scene file's digest, recorded with every frame so that `--assemble` refuses slices
    // of different scene files (read as the load above read it: bounded, or the embedded copy
    // of a built-in scene).
    let scene_crc = crc32fast::hash(&xylem::scene::source(scene)?.0);
    for w in &loaded.warnings {
        eprintln!("warning: {w}");
    }
    xylem::scene::Overrides {
        quality: args.quality,
        spp: args.spp,
        res: args.res,
        ..Default::default()
    }
    .apply(&mut loaded)?;
    let arc = args
        .arc
        .as_deref()
        .map(parse_arc)
        .transpose()
        .context("--arc")?;
    if let Some(dir) = &args.emit_openjd {
        return emit_openjd(&args, &loaded, scene, dir, arc);
    }
    let bar = super::progress::Bar::new(!args.quiet);
    let job = SweepJob {
        frames: args.frames,
        arc,
        range: args.frames_range.clone(),
        out: args
            .out
            .clone()
            .unwrap_or_else(|| Path::new("out").join(&loaded.name)),
        naive: args.naive,
        run: xylem::render::RunOptions {
            threads: args.threads,
            progress: &bar,
        },
        exr: args.exr_compression,
        ignore_limits: args.ignore_limits,
        memory: args.memory,
        primaries: args.primaries,
        provenance: format!(
            "scene crc32 {scene_crc:08x}, quality {}",
            args.quality.map_or("none".to_string(), |q| q.to_string())
        ),
    };
    announce(&loaded, &job);
    let report = run_job(&loaded, &job).with_context(|| format!("sweep of {}", scene.display()))?;
    print_summary(&report, &job.out);
    Ok(ExitCode::SUCCESS)
}

/// Says on stderr what is about to be rendered: scene, size, spp, integrator, one pass or not.
fn announce(loaded: &xylem::scene::LoadedScene, job: &SweepJob) {
    let cam = &loaded.scene.camera;
    eprintln!(
        "{}: {}x{}, {} spp, {}, {}",
        loaded.name,
        cam.width,
        cam.height,
        loaded.settings.spp,
        loaded.settings.integrator,
        if job.naive {
            "each frame alone (--naive)"
        } else {
            "frames in one pass"
        }
    );
}

/// Prints which frames were rendered, how fast, and what the folder holds now.
fn print_summary(report: &xylem::sweep::job::JobReport, out: &Path) {
    let n = report.rendered.len();
    println!(
        "rendered frames {}..{} of {} in {:.2} s ({:.3} s per frame; {} batch{} of up to {}{}) into {}",
        report.rendered.start,
        report.rendered.end,
        report.total,
        report.render_time.as_secs_f64(),
        report.render_time.as_secs_f64() / n.max(1) as f64,
        report.batches,
        if report.batches == 1 { "" } else { "es" },
        report.batch,
        if report.kept_primaries {
            ", primary samples kept"
        } else {
            ""
        },
        out.display()
    );
    match &report.assembled {
        Some(a) => {
            for f in &a.files {
                println!("  {}", f.display());
            }
        }
        // A slice: the folder may be complete now (this was the last slice) or not yet.
        None if xylem::sweep::sequence::read_records(out).is_ok() => println!(
            "every frame is in {} now; assemble them: xylem sweep --assemble {}",
            out.display(),
            out.display()
        ),
        None => println!(
            "not every frame is in {} yet; when all are: xylem sweep --assemble {}",
            out.display(),
            out.display()
        ),
    }
}

/// Writes the sweep's Open Job Description template: every render task gets the options that
/// decide the frames, so its slice matches the others.
fn emit_openjd(
    args: &Args,
    loaded: &xylem::scene::LoadedScene,
    scene: &Path,
    dir: &Path,
    arc: Option<(f32, f32)>,
) -> anyhow::Result<ExitCode> {
    use xylem::sweep::openjd::{default_chunk, write_template, OpenJdSweep};
    let (path, _) = xylem::sweep::SweepPath::from_scene(loaded, args.frames, arc)?;
    let frames = path.frames();
    let absolute = |p: &Path| {
        std::path::absolute(p).with_context(|| format!("making {} absolute", p.display()))
    };
    let mut render_args = vec!["--frames".to_string(), frames.to_string()];
    let mut add = |flag: &str, value: Option<String>| {
        if let Some(v) = value {
            render_args.extend([flag.to_string(), v]);
        }
    };
    add("--arc", args.arc.clone());
    add("--spp", args.spp.map(|n| n.to_string()));
    add("--res", args.res.map(|(w, h)| format!("{w}x{h}")));
    add("--quality", args.quality.map(|q| q.to_string()));
    add("--memory", args.memory.map(|m| m.to_string()));
    add(
        "--threads",
        (args.threads != 0).then(|| args.threads.to_string()),
    );
    add(
        "--exr-compression",
        Some(args.exr_compression.name().to_string()),
    );
    if args.ignore_limits {
        render_args.push("--ignore-limits".into());
    }
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| Path::new("out").join(&loaded.name));
    let sweep = OpenJdSweep {
        name: loaded.name.clone(),
        xylem: std::env::current_exe().context("finding the xylem binary")?,
        scene: absolute(scene)?,
        out: absolute(&out)?,
        frames,
        chunk: default_chunk(frames),
        render_args,
        assemble_args: vec!["--thumb-width".into(), args.thumb_width.to_string()],
    };
    let file = write_template(dir, &sweep)
        .with_context(|| format!("writing the job template into {}", dir.display()))?;
    println!(
        "wrote {} ({frames} frames in chunks of {}, then the assembly); run it with `openjd run {}` or submit {} as a job bundle",
        file.display(),
        sweep.chunk,
        file.display(),
        dir.display()
    );
    Ok(ExitCode::SUCCESS)
}

/// Assembles a folder of frames and reports what it wrote.
fn assemble_dir(dir: &Path, thumb_width: u32) -> anyhow::Result<ExitCode> {
    let opts = AssembleOptions {
        thumb_width,
        ..Default::default()
    };
    let done = xylem::output::FolderLock::try_new(dir, xylem::output::LockMode::Exclusive)
        .map_err(anyhow::Error::from)
        .and_then(|_lock| assemble(dir, &opts).map_err(anyhow::Error::from))
        .with_context(|| format!("assembling the sweep in {}", dir.display()))?;
    println!("assembled {} frames:", done.frames);
    for f in &done.files {
        println!("  {}", f.display());
    }
    Ok(ExitCode::SUCCESS)
}
