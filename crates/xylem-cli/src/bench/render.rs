//! `xylem bench render`: xylem against Mitsuba 3 on the Lambertian Cornell box
//! (scenes/cornell_box.toml: 256², path tracing to depth 8, box filter) in one run: xylem renders
//! it through the library (`render::render`), then `python -m validation.crosscheck --timing`
//! renders it in Mitsuba (depth 9 in Mitsuba's counting) and scores both images against one
//! high-spp Mitsuba reference. Both renders are timed after a first, untimed one (scene loading
//! and Mitsuba's JIT compilation excluded), `--repeats` times each, interleaved (xylem, Mitsuba,
//! xylem, …: Mitsuba's process stays up between its renders, `--serve`), so that a change of
//! machine load falls on both; medians and ranges are reported. samples/s = width · height ·
//! spp / seconds.

use anyhow::{bail, Context};
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};
use xylem::render::{image_io, render, RunOptions};
use xylem_lab::tradeoff::median_range;

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
    /// Timed renders of each renderer, 1 to 100, interleaved.
    #[arg(long, default_value_t = 5)]
    repeats: u32,
    /// Mitsuba's sampler for the timed renders: `independent` (its default) or one of its
    /// stratified ones (`multijitter`, `orthogonal`, `ldsampler`, `stratified`), to compare
    /// with xylem's Owen-scrambled Sobol samples like with like.
    #[arg(long, default_value = "independent", value_parser = ["independent", "multijitter", "orthogonal", "ldsampler", "stratified"])]
    mitsuba_sampler: String,
}

/// Mitsuba's timing process (`python -m validation.crosscheck --timing --serve`): one timed
/// render per request, the scores at the end.
struct Mitsuba {
    child: std::process::Child,
    stdin: std::process::ChildStdin,
    stdout: BufReader<std::process::ChildStdout>,
}

impl Mitsuba {
    fn start(mut cmd: Command) -> anyhow::Result<Mitsuba> {
        let mut child = cmd
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .context("cannot start Python")?;
        let (stdin, stdout) = (child.stdin.take(), child.stdout.take());
        let (Some(stdin), Some(stdout)) = (stdin, stdout) else {
            bail!("Python's pipes are missing");
        };
        let mut m = Mitsuba {
            child,
            stdin,
            stdout: BufReader::new(stdout),
        };
        let ready = m.line()?;
        if ready != "ready" {
            bail!("Mitsuba's timing process said `{ready}` instead of `ready`");
        }
        Ok(m)
    }

    /// The next line it prints; an error if it exited (its own error went to stderr).
    fn line(&mut self) -> anyhow::Result<String> {
        let mut l = String::new();
        if self.stdout.read_line(&mut l)? == 0 {
            let status = self.child.wait()?;
            bail!("Mitsuba's timing process exited ({status}); its error is above");
        }
        Ok(l.trim().to_string())
    }

    /// One timed Mitsuba render: its seconds.
    fn render(&mut self) -> anyhow::Result<f64> {
        writeln!(self.stdin, "render")?;
        self.stdin.flush()?;
        let l = self.line()?;
        l.parse()
            .with_context(|| format!("Mitsuba's timing process said `{l}`"))
    }

    /// Sends xylem's image and times, and returns the table it prints.
    fn score(mut self, score: serde_json::Value) -> anyhow::Result<String> {
        writeln!(self.stdin, "score {score}")?;
        drop(self.stdin);
        let mut table = String::new();
        std::io::Read::read_to_string(&mut self.stdout, &mut table)?;
        let status = self.child.wait()?;
        anyhow::ensure!(
            status.success(),
            "Mitsuba's timing process failed ({status})"
        );
        Ok(table)
    }
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
    if !args.no_mitsuba && loaded.name != "cornell_box" {
        // The Mitsuba side (validation/crosscheck --timing) builds the Cornell box only: timing
        // it against another scene would compare different images.
        bail!(
            "--scene {}: the Mitsuba 3 side of this benchmark renders only the Cornell box \
             (validation/crosscheck --timing); pass --no-mitsuba to time xylem alone",
            args.scene.display()
        );
    }
    loaded.settings.spp = args.spp;
    let (w, h) = (loaded.scene.camera.width, loaded.scene.camera.height);
    let opts = RunOptions {
        threads: args.threads,
        ..Default::default()
    };
    if !(1..=100).contains(&args.repeats) {
        bail!("--repeats {}: allowed 1 to 100", args.repeats);
    }
    let samples = w as f64 * h as f64 * args.spp as f64;
    let mut mitsuba = if args.no_mitsuba {
        None
    } else {
        mitsuba_process(&args)?
    };
    render(&loaded.scene, &loaded.settings, &opts)?; // warm-up, untimed
    let (mut xylem_s, mut mitsuba_s) = (Vec::new(), Vec::new());
    let mut last = None;
    for _ in 0..args.repeats {
        let out = render(&loaded.scene, &loaded.settings, &opts)?;
        xylem_s.push(out.elapsed.as_secs_f64());
        last = Some(out);
        if let Some(m) = &mut mitsuba {
            mitsuba_s.push(m.render()?);
        }
    }
    let (median, lo, hi) = median_range(&xylem_s);
    println!(
        "xylem {}: {}x{}, {} spp, {}, {} threads: {:.3} s (median of {}, {:.3}-{:.3}), {:.3} M samples/s",
        loaded.name,
        w,
        h,
        args.spp,
        loaded.settings.integrator,
        args.threads,
        median,
        args.repeats,
        lo,
        hi,
        samples / median / 1e6
    );
    let (Some(m), Some(out)) = (mitsuba, last) else {
        return Ok(ExitCode::SUCCESS);
    };
    let (m_median, m_lo, m_hi) = median_range(&mitsuba_s);
    println!(
        "Mitsuba: {m_median:.3} s (median of {}, {m_lo:.3}-{m_hi:.3}), interleaved with xylem's",
        args.repeats
    );
    let work = repository()
        .map(|r| r.join("target/crosscheck/timing"))
        .context("the repository")?;
    let exr = work.join("xylem_bench_render.exr");
    image_io::write_image_exr(&exr, &out.image, &[])?;
    let score = serde_json::json!({
        "image": exr, "spp": args.spp, "seconds": xylem_s,
    });
    print!("{}", m.score(score)?);
    Ok(ExitCode::SUCCESS)
}

/// Mitsuba's timing process, started and past its untimed first render, or None (with the
/// reason printed) where the repository, its venv or Mitsuba is missing.
fn mitsuba_process(args: &Args) -> anyhow::Result<Option<Mitsuba>> {
    let Some(repo) = repository() else {
        println!("Mitsuba skipped: validation/crosscheck/ not found (run from the repository)");
        return Ok(None);
    };
    let python = args
        .python
        .clone()
        .or_else(|| std::env::var_os("XYLEM_PYTHON").map(PathBuf::from))
        .unwrap_or_else(|| repo.join("target/python-venv/bin/python"));
    if !python.exists() {
        println!(
            "Mitsuba skipped: {} not found (`cargo test --release --test python` makes the venv, or pass --python)",
            python.display()
        );
        return Ok(None);
    }
    let work = repo.join("target/crosscheck/timing");
    std::fs::create_dir_all(&work).with_context(|| format!("cannot create {}", work.display()))?;
    let mut cmd = Command::new(&python);
    cmd.args(["-m", "validation.crosscheck", "--timing", "--serve"])
        .args(["--threads", &args.threads.to_string()])
        .args(["--spp", &args.spp.to_string()])
        .args(["--reference-spp", &args.reference_spp.to_string()])
        .args(["--sampler", &args.mitsuba_sampler])
        .current_dir(&repo);
    if std::env::var_os("DRJIT_LIBLLVM_PATH").is_none() {
        if let Some(p) = libllvm_19() {
            cmd.env("DRJIT_LIBLLVM_PATH", p);
        }
    }
    match Mitsuba::start(cmd) {
        Ok(m) => Ok(Some(m)),
        Err(e) => {
            println!(
                "Mitsuba skipped: `{} -m validation.crosscheck --timing` failed: {e:#}",
                python.display()
            );
            Ok(None)
        }
    }
}
