//! `xylem bench render`: xylem against Mitsuba 3 on the Lambertian Cornell box
//! (scenes/cornell_box.toml: 256², path tracing to depth 8, box filter) in one run: xylem renders
//! it through the library (`render::render`), then `python -m validation.crosscheck --timing`
//! renders it in Mitsuba (depth 9 in Mitsuba's counting) and scores both images against one
//! high-spp Mitsuba reference. Both renders are timed after a first, untimed one (scene loading
//! and Mitsuba's JIT compilation excluded); samples/s = width · height · spp / seconds.

use anyhow::{bail, Context};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};
use xylem::render::{image_io, render, RunOptions};

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The scene (a file, or a built-in scene's name).
    #[arg(long, default_value = "scenes/cornell_box.toml")]
    scene: PathBuf,
    /// Samples per pixel of each timed render (both renderers).
    #[arg(long, default_value_t = 64)]
    spp: u32,
    /// Render threads (xylem) and Dr.Jit worker threads (Mitsuba).
    #[arg(long, default_value_t = 2)]
    threads: usize,
    /// Samples per pixel of the Mitsuba reference (made once, cached in target/crosscheck/timing).
    #[arg(long, default_value_t = 2048)]
    reference_spp: u32,
    /// Python with Mitsuba 3 (default: $XYLEM_PYTHON, else the test suite's
    /// target/python-venv/bin/python).
    #[arg(long)]
    python: Option<PathBuf>,
    /// Only time xylem.
    #[arg(long)]
    no_mitsuba: bool,
}

/// The repository (validation/crosscheck and the venv live there): the current folder if it
/// holds validation/crosscheck, else the source tree this binary was built from.
fn repository() -> Option<PathBuf> {
    let here = std::env::current_dir().ok()?;
    [
        here,
        PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")),
    ]
    .into_iter()
    .find(|d| d.join("validation/crosscheck/__main__.py").exists())
}

/// Debian's libLLVM 19 for Dr.Jit's LLVM backend, unless `$DRJIT_LIBLLVM_PATH` is set.
fn libllvm_19() -> Option<PathBuf> {
    ["libLLVM-19.so", "libLLVM.so.19.1"]
        .iter()
        .map(|n| Path::new("/usr/lib/x86_64-linux-gnu").join(n))
        .find(|p| p.exists())
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    if !(1..=1_000_000).contains(&args.spp) {
        bail!("--spp {}: allowed 1 to 1000000", args.spp);
    }
    if !(1..=256).contains(&args.threads) {
        bail!("--threads {}: allowed 1 to 256", args.threads);
    }
    let mut loaded = xylem::scene::load(&args.scene).map_err(|e| anyhow::anyhow!("{e}"))?;
    loaded.settings.spp = args.spp;
    let (w, h) = (loaded.scene.camera.width, loaded.scene.camera.height);
    let opts = RunOptions {
        threads: args.threads,
        ..Default::default()
    };
    render(&loaded.scene, &loaded.settings, &opts)?; // warm-up, untimed
    let out = render(&loaded.scene, &loaded.settings, &opts)?;
    let seconds = out.elapsed.as_secs_f64();
    let samples = w as f64 * h as f64 * args.spp as f64;
    println!(
        "xylem {}: {}x{}, {} spp, {}, {} threads: {:.3} s, {:.3} M samples/s",
        loaded.name,
        w,
        h,
        args.spp,
        loaded.settings.integrator,
        args.threads,
        seconds,
        samples / seconds / 1e6
    );
    if args.no_mitsuba {
        return Ok(ExitCode::SUCCESS);
    }
    let Some(repo) = repository() else {
        println!("Mitsuba skipped: validation/crosscheck/ not found (run from the repository)");
        return Ok(ExitCode::SUCCESS);
    };
    let python = args
        .python
        .or_else(|| std::env::var_os("XYLEM_PYTHON").map(PathBuf::from))
        .unwrap_or_else(|| repo.join("target/python-venv/bin/python"));
    if !python.exists() {
        println!(
            "Mitsuba skipped: {} not found (`cargo test --release --test python` makes the venv, or pass --python)",
            python.display()
        );
        return Ok(ExitCode::SUCCESS);
    }
    let work = repo.join("target/crosscheck/timing");
    std::fs::create_dir_all(&work).with_context(|| format!("cannot create {}", work.display()))?;
    let exr = work.join("xylem_bench_render.exr");
    image_io::write_image_exr(&exr, &out.image, &[])?;
    let mut cmd = Command::new(&python);
    cmd.args(["-m", "validation.crosscheck", "--timing"])
        .args(["--threads", &args.threads.to_string()])
        .args(["--spp", &args.spp.to_string()])
        .args(["--reference-spp", &args.reference_spp.to_string()])
        .arg("--xylem-image")
        .arg(&exr)
        .args(["--xylem-seconds", &format!("{seconds}")])
        .args(["--xylem-spp", &args.spp.to_string()])
        .current_dir(&repo);
    if std::env::var_os("DRJIT_LIBLLVM_PATH").is_none() {
        if let Some(p) = libllvm_19() {
            cmd.env("DRJIT_LIBLLVM_PATH", p);
        }
    }
    let run = cmd
        .output()
        .with_context(|| format!("cannot run {}", python.display()))?;
    if run.status.success() {
        print!("{}", String::from_utf8_lossy(&run.stdout));
    } else {
        let err = String::from_utf8_lossy(&run.stderr);
        let tail: Vec<&str> = err.lines().rev().take(3).collect();
        println!(
            "Mitsuba skipped: `{} -m validation.crosscheck --timing` failed ({}): {}",
            python.display(),
            run.status,
            tail.into_iter().rev().collect::<Vec<_>>().join(" | ")
        );
    }
    Ok(ExitCode::SUCCESS)
}
