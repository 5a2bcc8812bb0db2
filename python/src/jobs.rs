//! `render`, `sweep` and `fit`: whole jobs into numpy arrays, interruptible with Ctrl-C.

use crate::*;

/// A `quality=` keyword (`draft`, `default` or `final`, as `--quality`).
pub(crate) fn parse_quality(
    quality: Option<&str>,
) -> PyResult<Option<xylem::scene::quality::Quality>> {
    parse_named("quality", quality)
}

/// A keyword argument given by name (`quality`, `sampling`), parsed; its error names it.
fn parse_named<T: std::str::FromStr>(field: &str, value: Option<&str>) -> PyResult<Option<T>>
where
    T::Err: std::fmt::Display,
{
    value
        .map(|v| v.parse().map_err(|e| value_error(format!("{field}: {e}"))))
        .transpose()
}

/// `threads`: 0 (all cores) up to 16 per core, as `--threads`.
pub(crate) fn check_threads(threads: usize) -> PyResult<()> {
    use xylem::resources::{check_threads, ResourceError};
    check_threads(threads).map_err(|e| match e {
        ResourceError::Threads { max, .. } => value_error(format!(
            "threads = {threads}: out of range (allowed 0 = all cores, up to {max})"
        )),
        other => value_error(other),
    })
}

/// Reshapes a row-major image of 3-vectors to (H, W, 3).
pub(crate) fn image3<'py>(
    py: Python<'py>,
    w: u32,
    h: u32,
    v: &[Vec3],
) -> PyResult<Bound<'py, PyAny>> {
    vec3_out(py, v, &[h as usize, w as usize])
}

pub(crate) fn image1<'py>(
    py: Python<'py>,
    w: u32,
    h: u32,
    v: Vec<f32>,
) -> PyResult<Bound<'py, PyAny>> {
    out(py, v, &[h as usize, w as usize])
}

/// A render's [`xylem::progress::Progress`] that asks it to stop once `flag` is set.
pub(crate) struct StopFlag<'a>(&'a std::sync::atomic::AtomicBool);

impl xylem::progress::Progress for StopFlag<'_> {
    fn update(&self, _done: u64, _total: u64, _message: &str) {}
    fn stop(&self) -> bool {
        self.0.load(std::sync::atomic::Ordering::Relaxed)
    }
}

/// Runs `f` with the GIL released on a helper thread while this (the main) thread checks
/// Python's signals every 50 ms, since only the main thread can raise KeyboardInterrupt: on
/// Ctrl-C the run is asked to stop ([`StopFlag`]), ends at its next tile, and the signal's
/// exception is raised. A panic in the run becomes a RuntimeError, never a PanicException.
pub(crate) fn interruptible<T: Send>(
    py: Python<'_>,
    f: impl FnOnce(&StopFlag) -> T + Send,
) -> PyResult<T> {
    let flag = std::sync::atomic::AtomicBool::new(false);
    let stop = StopFlag(&flag);
    std::thread::scope(|scope| {
        let run = scope.spawn(|| f(&stop));
        let mut interrupted = None;
        while !run.is_finished() {
            py.allow_threads(|| std::thread::sleep(std::time::Duration::from_millis(50)));
            if let Err(e) = py.check_signals() {
                flag.store(true, std::sync::atomic::Ordering::Relaxed);
                interrupted = Some(e);
                break;
            }
        }
        let out = py.allow_threads(|| run.join());
        match (interrupted, out) {
            (Some(e), _) => Err(e),
            (None, Ok(v)) => Ok(v),
            (None, Err(_)) => Err(pyo3::exceptions::PyRuntimeError::new_err(
                "the render panicked (a bug: please report it with the scene)",
            )),
        }
    })
}

/// `render(scene, spp=None, res=None, seed=None, threads=0, quality=None, footprint_filter=None,
/// sampling=None)`:
/// renders a scene (a file path, a built-in scene name, a dict as `load_dict` takes, or a
/// `Scene`) as `xylem render` does — `quality` is `--quality` (`draft`, `default`, `final`: spp
/// and wood-model knobs, validation/TRADEOFF.md), `spp` and `footprint_filter` override it;
/// `sampling` is `--sampling` (`adaptive`, the default, or `uniform`) — and returns a dict of
/// (H, W[, 3]) float32 arrays, top row first: `beauty`
/// (linear RGB), `std_error` (of each pixel's luminance), and the first-hit AOVs `albedo`,
/// `normal`, `depth`, `fiber`, `ray_mask`, `growth_time`; plus `nonfinite` (samples dropped) and
/// `seconds`. The GIL is released while rendering; Ctrl-C stops it within a tile and raises
/// KeyboardInterrupt.
#[pyfunction]
#[pyo3(signature = (scene, spp=None, res=None, seed=None, threads=0, quality=None, footprint_filter=None, sampling=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn render<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    spp: Option<u32>,
    res: Option<(u32, u32)>,
    seed: Option<u64>,
    threads: usize,
    quality: Option<&str>,
    footprint_filter: Option<bool>,
    sampling: Option<&str>,
) -> PyResult<Bound<'py, PyDict>> {
    check_threads(threads)?;
    let o = Overrides {
        quality: parse_quality(quality)?,
        spp,
        res,
        seed,
        footprint_filter,
        sampling: parse_named("sampling", sampling)?,
    };
    let out = with_scene(py, scene, &o, |loaded| {
        interruptible(py, |stop| {
            let run = xylem::render::RunOptions {
                threads,
                progress: stop,
            };
            xylem::render::render(&loaded.scene, &loaded.settings, &run)
        })
    })?
    .map_err(value_error)?;
    let img = &out.image;
    let (w, h) = (img.width, img.height);
    let d = PyDict::new(py);
    d.set_item("beauty", image3(py, w, h, &img.beauty)?)?;
    d.set_item("std_error", image1(py, w, h, img.std_error.clone())?)?;
    let aov3 =
        |f: fn(&xylem::render::Aov) -> Vec3| -> Vec<Vec3> { img.aov.iter().map(f).collect() };
    let aov1 = |f: fn(&xylem::render::Aov) -> f32| -> Vec<f32> { img.aov.iter().map(f).collect() };
    d.set_item("albedo", image3(py, w, h, &aov3(|a| a.albedo))?)?;
    d.set_item("normal", image3(py, w, h, &aov3(|a| a.normal))?)?;
    d.set_item("fiber", image3(py, w, h, &aov3(|a| a.fiber))?)?;
    d.set_item("depth", image1(py, w, h, aov1(|a| a.depth))?)?;
    d.set_item("ray_mask", image1(py, w, h, aov1(|a| a.ray_mask))?)?;
    d.set_item("growth_time", image1(py, w, h, aov1(|a| a.growth_time))?)?;
    d.set_item("nonfinite", img.nonfinite)?;
    d.set_item("seconds", out.elapsed.as_secs_f64())?;
    Ok(d)
}

/// `sweep(scene, frames=None, arc=None, spp=None, res=None, seed=None, threads=0, quality=None,
/// footprint_filter=None)`: renders the
/// light sweep of a scene's (a path, a name, a dict or a `Scene`, as `render` takes) `[sweep]` table (frames sharing their light-independent work, as `xylem sweep` does)
/// without writing files; `arc` = (from_deg, to_deg). Returns a dict: `frames` (F, H, W, 3),
/// `std_error` (F, H, W), `light_deg` (F,), `seconds`. The GIL is released while rendering;
/// Ctrl-C stops it within a tile and raises KeyboardInterrupt.
#[pyfunction]
#[pyo3(signature = (scene, frames=None, arc=None, spp=None, res=None, seed=None, threads=0, quality=None, footprint_filter=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn sweep<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    frames: Option<usize>,
    arc: Option<(f32, f32)>,
    spp: Option<u32>,
    res: Option<(u32, u32)>,
    seed: Option<u64>,
    threads: usize,
    quality: Option<&str>,
    footprint_filter: Option<bool>,
) -> PyResult<Bound<'py, PyDict>> {
    check_threads(threads)?;
    let o = Overrides {
        quality: parse_quality(quality)?,
        spp,
        res,
        seed,
        footprint_filter,
        sampling: None,
    };
    let (r, deg) = with_scene(py, scene, &o, |loaded| {
        let (path, moving) =
            xylem::sweep::SweepPath::from_scene(loaded, frames, arc).map_err(value_error)?;
        let total = path.arc.frames;
        let r = interruptible(py, |stop| {
            let run = xylem::render::RunOptions {
                threads,
                progress: stop,
            };
            xylem::sweep::render_sweep(
                &loaded.scene,
                &loaded.settings,
                &path,
                moving,
                0..total,
                &run,
            )
        })?
        .map_err(value_error)?;
        let deg: Vec<f32> = (0..r.frames.len()).map(|k| path.light_deg(k)).collect();
        Ok((r, deg))
    })?;
    let (w, h, f) = (r.width as usize, r.height as usize, r.frames.len());
    let beauty: Vec<f32> = r
        .frames
        .iter()
        .flat_map(|fr| fr.beauty.iter().flat_map(|c| c.to_array()))
        .collect();
    let err: Vec<f32> = r
        .frames
        .iter()
        .flat_map(|fr| fr.std_error.clone())
        .collect();
    let d = PyDict::new(py);
    d.set_item(
        "frames",
        PyArray1::from_vec(py, beauty).reshape([f, h, w, 3])?,
    )?;
    d.set_item("std_error", PyArray1::from_vec(py, err).reshape([f, h, w])?)?;
    d.set_item("light_deg", PyArray1::from_vec(py, deg))?;
    d.set_item("seconds", r.elapsed.as_secs_f64())?;
    Ok(d)
}

/// Fits the capture in the folder `capture` (a sweep's `manifest.json` and frames) and writes
/// its maps and report into `out`, as `xylem fit` does; returns the report as JSON text
/// (`xylem.fit` parses it). One board per call, the GIL released, so a Ray or Dask pool of
/// processes can fit many boards at once.
#[pyfunction]
#[pyo3(signature = (capture, out, texels=None, threads=0))]
pub(crate) fn fit(
    py: Python<'_>,
    capture: PathBuf,
    out: PathBuf,
    texels: Option<(usize, usize)>,
    threads: usize,
) -> PyResult<String> {
    check_threads(threads)?;
    let report = py
        .allow_threads(|| {
            let opts = xylem::fit::FitOptions {
                texels,
                threads,
                ..Default::default()
            };
            xylem::fit::fit_folder(&capture, &out, &opts)
        })
        .map_err(|e| match e {
            xylem::fit::FolderError::Fit(f) => value_error(f),
            other => PyOSError::new_err(other.to_string()),
        })?;
    Ok(report.to_string())
}
