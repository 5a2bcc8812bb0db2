//! The render benchmark behind `xylem bench render`: xylem against Mitsuba 3 on one of
//! [`CASES`] (path tracing to depth 8, box filter: the Lambertian Cornell box of
//! scenes/cornell_box.toml, the box with a mirror and a glass sphere, or sweep_board's board
//! under a rect light, which Mitsuba shades through the `xylem_wood` plugin) in one run: `python
//! -m validation.crosscheck --timing --case …` writes the case as a xylem scene file and renders
//! it in Mitsuba (depth 9 in Mitsuba's counting), xylem renders that file through the library
//! (`render::render`), and Mitsuba's process scores both images against one high-spp Mitsuba
//! reference. Both renders are timed after a first, untimed one (scene loading and Mitsuba's JIT
//! compilation excluded), `repeats` times each, interleaved (xylem, Mitsuba, xylem, …: Mitsuba's
//! process stays up between its renders, `--serve`), so that a change of machine load falls on
//! both; medians and ranges are reported.
//! samples/s = width · height · spp / seconds.

use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use xylem::picture::ImageError;
use xylem::render::{image_io, render, RenderError, RunOptions};
use xylem::scene::SceneError;

/// What `xylem bench render` measures.
#[derive(Clone, Debug)]
pub struct RenderBench {
    /// The scene both renderers render: a case of `validation.crosscheck --timing`
    /// ([`CASES`]), written as a xylem scene file by Mitsuba's timing process.
    pub case: String,
    /// A scene (a file, or a built-in scene's name) to time xylem alone on, with `no_mitsuba`;
    /// `None`: the case's (scenes/cornell_box.toml for `cornell_box` without Mitsuba).
    pub scene: Option<PathBuf>,
    /// Samples per pixel of each timed render (both renderers), 1 to 1000000.
    pub spp: u32,
    /// Render threads (xylem) and Dr.Jit worker threads (Mitsuba), 1 to 256.
    pub threads: usize,
    /// Samples per pixel of the Mitsuba reference (made once, cached in target/crosscheck/timing).
    pub reference_spp: u32,
    /// Python with Mitsuba 3 (default: $XYLEM_PYTHON, else target/python-venv/bin/python).
    pub python: Option<PathBuf>,
    /// Only time xylem.
    pub no_mitsuba: bool,
    /// Timed renders of each renderer, 1 to 100, interleaved.
    pub repeats: u32,
    /// Mitsuba's sampler for the timed renders.
    pub mitsuba_sampler: String,
}

/// Why the render benchmark could not run.
#[derive(Debug, thiserror::Error)]
pub enum RenderBenchError {
    /// An argument out of range or not benchmarkable, as the command line spells it.
    #[error("{0}")]
    Argument(String),
    /// The scene could not be loaded.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// xylem's render failed.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// xylem's image could not be written for Mitsuba's scoring.
    #[error(transparent)]
    Image(#[from] ImageError),
    /// Mitsuba's timing process failed after it started.
    #[error("{0}")]
    Mitsuba(String),
    /// Talking to Mitsuba's timing process failed.
    #[error(transparent)]
    Io(#[from] std::io::Error),
}

/// The benchmark's figures.
#[derive(Clone, Debug)]
pub struct RenderTimes {
    /// The scene's name.
    pub name: String,
    /// Image size.
    pub width: u32,
    /// Image size.
    pub height: u32,
    /// The integrator, as the scene names it.
    pub integrator: String,
    /// xylem's timed renders, seconds.
    pub xylem_s: Vec<f64>,
    /// Why Mitsuba was not timed, when it was asked for and could not start.
    pub mitsuba_skipped: Option<String>,
    /// Mitsuba's timed renders, seconds (empty when it was not timed).
    pub mitsuba_s: Vec<f64>,
    /// The table Mitsuba's timing process prints (both images against its reference).
    pub mitsuba_table: Option<String>,
}

/// The cases `validation.crosscheck --timing --case` renders: the Lambertian Cornell box
/// (scenes/cornell_box.toml's scene), the same walls with a mirror and a glass sphere, and
/// sweep_board's mahogany board under a rect light (Mitsuba through the `xylem_wood` plugin).
pub const CASES: [&str; 3] = ["cornell_box", "cornell_spheres", "wood_board"];

/// Mitsuba's timing process (`python -m validation.crosscheck --timing --serve`): one timed
/// render per request, the scores at the end.
struct Mitsuba {
    child: std::process::Child,
    stdin: std::process::ChildStdin,
    stdout: BufReader<std::process::ChildStdout>,
    /// The case as a xylem scene file, written by the process (its `ready` line).
    scene: PathBuf,
}

impl Mitsuba {
    fn start(mut cmd: Command) -> Result<Mitsuba, RenderBenchError> {
        let mut child = cmd
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .map_err(|e| RenderBenchError::Mitsuba(format!("cannot start Python: {e}")))?;
        let (stdin, stdout) = (child.stdin.take(), child.stdout.take());
        let (Some(stdin), Some(stdout)) = (stdin, stdout) else {
            return Err(RenderBenchError::Mitsuba(
                "Python's pipes are missing".into(),
            ));
        };
        let mut m = Mitsuba {
            child,
            stdin,
            stdout: BufReader::new(stdout),
            scene: PathBuf::new(),
        };
        let ready = m.line()?;
        match ready.strip_prefix("ready ") {
            Some(scene) => m.scene = PathBuf::from(scene),
            None => {
                return Err(RenderBenchError::Mitsuba(format!(
                    "Mitsuba's timing process said `{ready}` instead of `ready SCENE`"
                )))
            }
        }
        Ok(m)
    }

    /// The next line it prints; an error if it exited (its own error went to stderr).
    fn line(&mut self) -> Result<String, RenderBenchError> {
        let mut l = String::new();
        if self.stdout.read_line(&mut l)? == 0 {
            let status = self.child.wait()?;
            return Err(RenderBenchError::Mitsuba(format!(
                "Mitsuba's timing process exited ({status}); its error is above"
            )));
        }
        Ok(l.trim().to_string())
    }

    /// One timed Mitsuba render: its seconds.
    fn render(&mut self) -> Result<f64, RenderBenchError> {
        writeln!(self.stdin, "render")?;
        self.stdin.flush()?;
        let l = self.line()?;
        l.parse().map_err(|e| {
            RenderBenchError::Mitsuba(format!("Mitsuba's timing process said `{l}`: {e}"))
        })
    }

    /// Sends xylem's image and times, and returns the table it prints.
    fn score(mut self, score: serde_json::Value) -> Result<String, RenderBenchError> {
        writeln!(self.stdin, "score {score}")?;
        drop(self.stdin);
        let mut table = String::new();
        std::io::Read::read_to_string(&mut self.stdout, &mut table)?;
        let status = self.child.wait()?;
        if !status.success() {
            return Err(RenderBenchError::Mitsuba(format!(
                "Mitsuba's timing process failed ({status})"
            )));
        }
        Ok(table)
    }
}

/// The repository (validation/crosscheck and the venv live there): the current folder if it
/// holds validation/crosscheck, else the source tree this crate was built from.
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

/// Runs the benchmark: xylem's renders, interleaved with Mitsuba's where it is asked for and
/// starts, and Mitsuba's scores of both.
pub fn run(b: &RenderBench) -> Result<RenderTimes, RenderBenchError> {
    let bad = |s: String| Err(RenderBenchError::Argument(s));
    if !(1..=1_000_000).contains(&b.spp) {
        return bad(format!("--spp {}: allowed 1 to 1000000", b.spp));
    }
    if !(1..=256).contains(&b.threads) {
        return bad(format!("--threads {}: allowed 1 to 256", b.threads));
    }
    if !(1..=1_000_000).contains(&b.reference_spp) {
        return bad(format!(
            "--reference-spp {}: allowed 1 to 1000000",
            b.reference_spp
        ));
    }
    if !CASES.contains(&b.case.as_str()) {
        return bad(format!("--case {}: allowed {}", b.case, CASES.join(", ")));
    }
    if let (Some(scene), false) = (&b.scene, b.no_mitsuba) {
        // Mitsuba renders the case's scene: timing it against another would compare different
        // images.
        return bad(format!(
            "--scene {}: the Mitsuba 3 side of this benchmark renders its own case (--case); \
             pass --no-mitsuba to time xylem alone on another scene",
            scene.display()
        ));
    }
    if !(1..=100).contains(&b.repeats) {
        return bad(format!("--repeats {}: allowed 1 to 100", b.repeats));
    }
    let (mut mitsuba, mitsuba_skipped) = if b.no_mitsuba {
        (None, None)
    } else {
        match mitsuba_process(b)? {
            Ok(m) => (Some(m), None),
            Err(why) => (None, Some(why)),
        }
    };
    let scene = match (&mitsuba, &b.scene) {
        (Some(m), _) => m.scene.clone(),
        (None, Some(scene)) => scene.clone(),
        (None, None) if b.case == "cornell_box" => PathBuf::from("scenes/cornell_box.toml"),
        (None, None) => {
            return bad(format!(
                "--case {}: its scene file is written by Mitsuba's timing process, which did \
                 not start ({}); pass --scene FILE --no-mitsuba to time xylem alone",
                b.case,
                mitsuba_skipped.as_deref().unwrap_or("--no-mitsuba")
            ))
        }
    };
    let mut loaded = xylem::scene::load(&scene)?;
    loaded.settings.spp = b.spp;
    // spp in every pixel, as Mitsuba samples: samples/s and RMSE per sample compare like with
    // like (adaptive sampling, `render`'s default, spreads a pixel's samples unevenly).
    loaded.settings.sampling = xylem::render::Sampling::Uniform;
    let (w, h) = (loaded.scene.camera.width, loaded.scene.camera.height);
    let opts = RunOptions {
        threads: b.threads,
        ..Default::default()
    };
    render(&loaded.scene, &loaded.settings, &opts)?; // warm-up, untimed
    let (mut xylem_s, mut mitsuba_s) = (Vec::new(), Vec::new());
    let mut last = None;
    for _ in 0..b.repeats {
        let out = render(&loaded.scene, &loaded.settings, &opts)?;
        xylem_s.push(out.elapsed.as_secs_f64());
        last = Some(out);
        if let Some(m) = &mut mitsuba {
            mitsuba_s.push(m.render()?);
        }
    }
    let mut times = RenderTimes {
        name: loaded.name.clone(),
        width: w,
        height: h,
        integrator: loaded.settings.integrator.to_string(),
        xylem_s,
        mitsuba_skipped,
        mitsuba_s,
        mitsuba_table: None,
    };
    let (Some(m), Some(out)) = (mitsuba, last) else {
        return Ok(times);
    };
    let work = repository()
        .map(|r| r.join("target/crosscheck/timing"))
        .ok_or_else(|| RenderBenchError::Mitsuba("the repository".into()))?;
    let exr = work.join(format!("xylem_bench_render_{}.exr", b.case));
    image_io::write_image_exr(&exr, &out.image, &[])?;
    let score = serde_json::json!({
        "image": exr, "spp": b.spp, "seconds": times.xylem_s,
    });
    times.mitsuba_table = Some(m.score(score)?);
    Ok(times)
}

/// Mitsuba's timing process, started and past its untimed first render, or why it is skipped
/// (the repository, its venv or Mitsuba is missing, or the process failed to start).
type Started = Result<Mitsuba, String>;

/// [`Started`]; an error where its work folder cannot be made.
fn mitsuba_process(b: &RenderBench) -> Result<Started, RenderBenchError> {
    let Some(repo) = repository() else {
        return Ok(Err(
            "validation/crosscheck/ not found (run from the repository)".into(),
        ));
    };
    let python = b
        .python
        .clone()
        .or_else(|| std::env::var_os("XYLEM_PYTHON").map(PathBuf::from))
        .unwrap_or_else(|| repo.join("target/python-venv/bin/python"));
    if !python.exists() {
        return Ok(Err(format!(
            "{} not found (`cargo test --release --test python` makes the venv, or pass --python)",
            python.display()
        )));
    }
    let work = repo.join("target/crosscheck/timing");
    std::fs::create_dir_all(&work)
        .map_err(|e| RenderBenchError::Mitsuba(format!("cannot create {}: {e}", work.display())))?;
    let mut cmd = Command::new(&python);
    cmd.args(["-m", "validation.crosscheck", "--timing", "--serve"])
        .args(["--case", &b.case])
        .args(["--threads", &b.threads.to_string()])
        .args(["--spp", &b.spp.to_string()])
        .args(["--reference-spp", &b.reference_spp.to_string()])
        .args(["--sampler", &b.mitsuba_sampler])
        .current_dir(&repo);
    // The xylem package for the wood case's plugin: `$PYTHONPATH`'s first, then the one the
    // test suite stages (tests/python.rs), then an installed one.
    let staged = repo.join("target/python-test/site");
    if staged.is_dir() {
        let mut paths: Vec<PathBuf> = std::env::var_os("PYTHONPATH")
            .map(|p| std::env::split_paths(&p).collect())
            .unwrap_or_default();
        paths.push(staged);
        if let Ok(joined) = std::env::join_paths(paths) {
            cmd.env("PYTHONPATH", joined);
        }
    }
    if std::env::var_os("DRJIT_LIBLLVM_PATH").is_none() {
        if let Some(p) = libllvm_19() {
            cmd.env("DRJIT_LIBLLVM_PATH", p);
        }
    }
    Ok(Mitsuba::start(cmd).map_err(|e| {
        format!(
            "`{} -m validation.crosscheck --timing` failed: {e}",
            python.display()
        )
    }))
}
