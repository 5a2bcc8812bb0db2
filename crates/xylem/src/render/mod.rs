//! The BVH path tracer: camera, lights, meshes on an obvhs BVH, integrator, film with AOVs,
//! EXR / PNG output and progress.
//!
//! [`render`] renders a [`Scene`] tile by tile on a rayon pool. Every pixel sample draws its
//! random numbers from streams keyed by (seed, pixel, sample) only, so the image is bit-identical
//! for any thread count.

mod adaptive;
pub mod camera;
pub mod film;
pub mod frames;
pub mod geometry;
pub mod image_io;
pub mod integrator;
pub mod light;
pub mod lod;
pub mod resources;
mod sampler;
pub mod shading;
pub mod shadow;
mod wave;
pub mod wide_bvh;

pub use camera::{Camera, CameraRays, Projection};
pub(crate) use film::FrameSums;
pub use film::{Aov, Filter, PixelSum, RenderedImage};
pub use frames::LightFrames;
pub use geometry::{Accel, Instance, Ray, Transform, TriMesh};
pub(crate) use integrator::path_numbers;
pub use integrator::{primary_sample, Integrator};
pub use light::{
    DistantLight, EnvMap, Environment, Light, PointLight, RectLight, SphereLight, SpotLight,
};
pub use shading::ShadingPoint;
use shadow::ShadowTest;

use crate::material::Material;
use crate::progress::{NoProgress, Progress};
use crate::simd::{simd_wide, Simd};
use glam::{UVec2, Vec3};
use integrator::{
    primary_sample_into, radiance_frames, FirstBounce, FramesScratch, KeptSample, PrimarySample,
    RayCount,
};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// Everything a render needs to know about the world.
pub struct Scene {
    /// The geometry: placed meshes in their BVHs.
    pub accel: Accel,
    /// Materials, indexed by [`Instance::material`].
    pub materials: Vec<Material>,
    /// The lights [`render`] renders with ([`render_frames`] takes each frame's lights from a
    /// [`LightFrames`] instead).
    pub lights: Vec<Light>,
    /// The camera: pose, projection and image size.
    pub camera: Camera,
    /// Pixel reconstruction filter.
    pub filter: Filter,
}

/// Sampling settings of one render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    /// Samples per pixel (1–1000000).
    pub spp: u32,
    /// Direct lighting only, or path tracing.
    pub integrator: Integrator,
    /// Random seed: the same seed gives the same image on any thread count.
    pub seed: u64,
    /// How [`render`] spreads the image's samples over its pixels.
    pub sampling: Sampling,
}

/// How [`render`] spreads an image's samples over its pixels (`[render] sampling`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Sampling {
    /// spp samples in every pixel.
    Uniform,
    /// A pilot of spp/4 samples in every pixel, then the cost of the uniform render's remaining
    /// samples spent where the pilot found the pixel's neighbours noisy and cheap, at most
    /// 16 spp a pixel (Neyman allocation with costs, unbiased: notes/render.md, "Adaptive
    /// sampling"). Uniform below 8 spp, and in [`render_frames`] (a sweep's frames share their
    /// samples).
    #[default]
    Adaptive,
}

impl Sampling {
    /// Both ways, in the order of [`Sampling::NAMES`].
    pub const ALL: [Sampling; 2] = [Sampling::Uniform, Sampling::Adaptive];
    /// The names a scene file or a command line gives.
    pub const NAMES: [&'static str; 2] = ["uniform", "adaptive"];

    /// The `--sampling` name (`adaptive`).
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }
}

impl std::str::FromStr for Sampling {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| {
                format!(
                    "`{s}` is not a sampling (allowed: {})",
                    Self::NAMES.join(", ")
                )
            })
    }
}

impl std::fmt::Display for Sampling {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl RenderSettings {
    /// The EXR header attributes that say how an image of `scene` (its name and file) seen by
    /// `camera` was made: scene, file, spp, seed, integrator and camera (the software attribute
    /// carries xylem's version; [`crate::picture::exr::stage_exr_layers`]). Camera axes as [`Camera`] has
    /// them: right, up and view direction; lengths in mm.
    pub fn exr_meta(
        &self,
        scene: &str,
        file: &str,
        camera: &Camera,
    ) -> Vec<(&'static str, String)> {
        let v = |v: glam::Vec3| format!("({}, {}, {})", v.x, v.y, v.z);
        let f = &camera.frame;
        let projection = match camera.projection {
            camera::Projection::Perspective {
                fov_y,
                lens_radius,
                focus_distance,
            } => format!(
                "perspective, fov_y {} deg, lens radius {lens_radius} mm, focus {focus_distance} mm",
                fov_y.to_degrees()
            ),
            camera::Projection::Orthographic { width } => format!("orthographic, width {width} mm"),
        };
        vec![
            ("scene", scene.to_string()),
            ("scene_file", file.to_string()),
            ("spp", self.spp.to_string()),
            ("sampling", self.sampling.to_string()),
            ("seed", self.seed.to_string()),
            ("integrator", self.integrator.to_string()),
            (
                "camera",
                format!(
                    "eye {} right {} up {} view {}, {projection}, {}x{} px",
                    v(camera.eye),
                    v(f.s),
                    v(f.t),
                    v(f.n),
                    camera.width,
                    camera.height
                ),
            ),
        ]
    }
}

/// How to run a render (not part of the image: changing these never changes a pixel).
///
/// `RunOptions { threads: 2, ..Default::default() }` renders on two threads and reports no
/// progress.
#[derive(Clone, Copy, Debug)]
pub struct RunOptions<'a> {
    /// Worker threads; 0 = all cores.
    pub threads: usize,
    /// Told of every finished tile with the Mrays/s so far (the CLI draws a bar on stderr).
    pub progress: &'a dyn Progress,
}

impl Default for RunOptions<'_> {
    fn default() -> Self {
        RunOptions {
            threads: 0,
            progress: &NoProgress,
        }
    }
}

/// A finished render with its statistics.
#[derive(Clone, Debug)]
pub struct RenderOutput {
    /// The image with its AOV layers.
    pub image: RenderedImage,
    /// Wall time of the render.
    pub elapsed: Duration,
    /// Rays traced (camera, shadow and bounce rays).
    pub rays: u64,
    /// Whether the tiles ran as waves of paths (every material Lambertian, a mirror or glass,
    /// and `XYLEM_WAVES` not `off`; `render::wave`) rather than one path at a time: the same
    /// image either way.
    pub waves: bool,
}

/// Why a render could not start.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// The rayon thread pool could not be built.
    #[error("cannot start {threads} render threads: {message}")]
    Threads {
        /// The thread count asked for.
        threads: usize,
        /// rayon's message.
        message: String,
    },
    /// The caller asked the run to stop ([`crate::progress::Progress::stop`]).
    #[error("stopped before the render finished ({done} of {total} tiles)")]
    Stopped {
        /// Tiles finished.
        done: u64,
        /// Tiles in the render.
        total: u64,
    },
    /// An image with no pixels.
    #[error("image size {width}x{height} is empty")]
    EmptyImage {
        /// Image width in pixels.
        width: u32,
        /// Image height in pixels.
        height: u32,
    },
}

/// Side length of the square tiles handed to worker threads.
pub(crate) const TILE: u32 = 16;

/// Renders the scene with its own lights.
///
/// ```
/// use std::path::Path;
/// // A scene file (here a built-in one; `xylem::scene::load` reads any file), made small.
/// let mut loaded = xylem::scene::load(Path::new("scenes/sweep_board.toml"))?;
/// loaded.scene.camera = loaded.scene.camera.with_resolution(32, 24);
/// loaded.settings.spp = 2;
/// let out = xylem::render::render(&loaded.scene, &loaded.settings, &Default::default())?;
/// assert_eq!(out.image.beauty.len(), 32 * 24);
/// // Beauty with alpha, the AOV layers and the settings in the header:
/// let dir = std::env::temp_dir().join(format!("xylem-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// let meta = loaded.settings.exr_meta(&loaded.name, "scenes/sweep_board.toml", &loaded.scene.camera);
/// xylem::render::image_io::write_image_exr(&dir.join("board.exr"), &out.image, &meta)?;
/// # std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn render(
    scene: &Scene,
    settings: &RenderSettings,
    run: &RunOptions,
) -> Result<RenderOutput, RenderError> {
    let lights = LightFrames::fixed(&scene.lights);
    let mut frames = match (settings.sampling, adaptive::pilot_count(settings.spp)) {
        (Sampling::Adaptive, Some(pilot)) => render_adaptive(scene, &lights, settings, run, pilot)?,
        _ => render_frames(scene, &lights, settings, run)?,
    };
    let frame = frames.frames.swap_remove(0);
    Ok(RenderOutput {
        image: RenderedImage {
            width: frames.width,
            height: frames.height,
            beauty: frame.beauty,
            std_error: frame.std_error,
            aov: frames.aov,
            nonfinite: frame.nonfinite,
        },
        elapsed: frames.elapsed,
        rays: frames.rays,
        waves: wave::enabled(scene, &lights),
    })
}

/// One frame of a [`render_frames`] run: its radiance and per-pixel standard error (the AOVs,
/// the same in every frame, are kept once in [`Frames`]).
#[derive(Clone, Debug)]
pub struct FrameImage {
    /// Mean radiance per pixel (row-major, top row first).
    pub beauty: Vec<Vec3>,
    /// Standard error of each pixel's luminance.
    pub std_error: Vec<f32>,
    /// Samples that were not finite (counted, contributing zero).
    pub nonfinite: u64,
}

/// The frames of a [`render_frames`] run with the first-hit AOVs they share.
#[derive(Clone, Debug)]
pub struct Frames {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// The first-hit AOVs, shared by every frame.
    pub aov: Vec<Aov>,
    /// One image per frame of the [`LightFrames`], in order.
    pub frames: Vec<FrameImage>,
    /// Wall time of the render.
    pub elapsed: Duration,
    /// Rays traced (camera, shadow and bounce rays).
    pub rays: u64,
}

impl Frames {
    /// Frame `k` as a [`RenderedImage`] (for EXR output with the AOV layers).
    pub fn image(&self, k: usize) -> RenderedImage {
        let f = &self.frames[k];
        RenderedImage {
            width: self.width,
            height: self.height,
            beauty: f.beauty.clone(),
            std_error: f.std_error.clone(),
            aov: self.aov.clone(),
            nonfinite: f.nonfinite,
        }
    }
}

/// Every pixel sample's light-independent part of a render ([`primary_sample`] and the first
/// bounce's sampled continuation), tile by tile, kept so that a later pass over other frames of the same scene and settings (a sweep's next
/// batch) lights these samples again instead of tracing and shading them anew
/// ([`render_frames_reusing`]). [`Primaries::bytes`] each; a sample is the same value whether
/// computed or read here, so frames are the same bits either way.
#[derive(Clone, Debug, Default)]
pub struct Primaries {
    /// Per tile (in [`render_frames`]'s order), its pixels' samples, pixel-major.
    tiles: Vec<Vec<KeptSample>>,
}

impl Primaries {
    /// Bytes the primary samples of a `width × height` render at `spp` take.
    pub fn bytes(width: u32, height: u32, spp: u32) -> u64 {
        width as u64 * height as u64 * spp as u64 * size_of::<KeptSample>() as u64
    }

    /// True until a pass has filled it.
    pub fn is_empty(&self) -> bool {
        self.tiles.is_empty()
    }
}

/// Renders every frame of `lights` at once, tile by tile on a pool of `run.threads` threads.
///
/// Each pixel sample's light-independent part ([`primary_sample`]) and its path are computed
/// once and lit for every frame straight away (pixel → sample → frame), so nothing but the
/// tile's pixel sums is kept whatever the number of frames; each frame equals the render of
/// that frame alone, bit for bit, on any thread count.
pub fn render_frames(
    scene: &Scene,
    lights: &LightFrames,
    settings: &RenderSettings,
    run: &RunOptions,
) -> Result<Frames, RenderError> {
    render_frames_reusing(scene, lights, settings, run, None)
}

/// [`render_frames`], keeping or reusing the primary samples: with `Some` empty [`Primaries`]
/// the pass computes them and keeps them there; with `Some` filled ones (from a pass over the
/// same scene and settings) it reads them instead of computing them; the same frames, bit for
/// bit, in every case.
///
/// # Panics
/// If filled `primaries` do not have this render's tiles and samples.
pub fn render_frames_reusing(
    scene: &Scene,
    lights: &LightFrames,
    settings: &RenderSettings,
    run: &RunOptions,
    primaries: Option<&mut Primaries>,
) -> Result<Frames, RenderError> {
    let (w, h, tiles) = image_tiles(scene)?;
    let keep = primaries.as_ref().is_some_and(|p| p.is_empty());
    let reuse = primaries.as_deref().filter(|p| !p.is_empty());
    if let Some(p) = reuse {
        assert_eq!(p.tiles.len(), tiles.len(), "primaries of another render");
    }
    let shadow = ShadowTest::culled(&scene.accel);
    let start = Instant::now();
    let mut pass = TilePass::new(run, tiles.len() as u64, 1, &progress_unit(lights.len()))?;
    let results = pass.run(tiles.iter().map(|&o| (o, ())).collect(), |t, origin, ()| {
        let primary = match reuse {
            Some(p) => Primary::Reuse(&p.tiles[t]),
            None if keep => Primary::Keep,
            None => Primary::Compute,
        };
        let job = TileJob {
            origin,
            primary,
            span: Span::All(settings.spp),
            carry: None,
        };
        let tile = render_tile(scene, lights, &shadow, settings, job).finish();
        (tile.rays, tile)
    })?;
    let rays = pass.finish();
    let mut results: Vec<(UVec2, TileFrames)> = tiles.into_iter().zip(results).collect();
    if keep {
        if let Some(p) = primaries {
            p.tiles = results
                .iter_mut()
                .map(|(_, t)| std::mem::take(&mut t.kept))
                .collect();
        }
    }
    Ok(place_tiles(w, h, lights.len(), results, start, rays))
}

/// [`render_frames`] of one frame with [`Sampling::Adaptive`]: every pixel's first `pilot`
/// samples, then the cost of the rest of a uniform render's samples spread by
/// [`adaptive::allocate`] over the pilot's variances and costs, each pixel continuing its own
/// sample sequence where the pilot left it (so a pixel's samples are those of a uniform render
/// with more spp, in order).
fn render_adaptive(
    scene: &Scene,
    lights: &LightFrames,
    settings: &RenderSettings,
    run: &RunOptions,
    pilot: u32,
) -> Result<Frames, RenderError> {
    let (w, h, tiles) = image_tiles(scene)?;
    let shadow = ShadowTest::culled(&scene.accel);
    let start = Instant::now();
    let mut pass = TilePass::new(run, tiles.len() as u64, 2, "tiles (pilot, then the rest)")?;
    let pilots = pass.run(tiles.iter().map(|&o| (o, ())).collect(), |_, origin, ()| {
        let job = TileJob {
            origin,
            primary: Primary::Compute,
            span: Span::All(pilot),
            carry: None,
        };
        let tile = render_tile(scene, lights, &shadow, settings, job);
        (tile.rays, tile)
    })?;
    let mut measured = vec![adaptive::Pilot::default(); (w * h) as usize];
    for (&origin, tile) in tiles.iter().zip(&pilots) {
        for (i, sum) in tile.sums.frame(0).enumerate() {
            measured[tile_pixel(w, origin, i)] = adaptive::Pilot {
                var: sum.luminance_variance(),
                cost: tile.work[i] as f64 / pilot as f64,
            };
        }
    }
    let cap = adaptive::MAX_FACTOR * settings.spp - pilot;
    let m = settings.spp - pilot;
    let extra = adaptive::allocate(w, h, &measured, m, cap, settings.seed);
    let carried = tiles.iter().copied().zip(pilots).collect();
    let results = pass.run(carried, |_, origin, carry| {
        let tw = TILE.min(w - origin.x) as usize;
        let th = TILE.min(h - origin.y) as usize;
        let counts: Vec<u32> = (0..tw * th)
            .map(|i| extra[tile_pixel(w, origin, i)])
            .collect();
        let job = TileJob {
            origin,
            primary: Primary::Compute,
            span: Span::After {
                first: pilot,
                extra: &counts,
            },
            carry: Some(carry),
        };
        let tile = render_tile(scene, lights, &shadow, settings, job).finish();
        (tile.rays, tile)
    })?;
    let rays = pass.finish();
    let results: Vec<(UVec2, TileFrames)> = tiles.into_iter().zip(results).collect();
    Ok(place_tiles(w, h, lights.len(), results, start, rays))
}

/// The image index of pixel `i` (row-major within its tile) of the tile at `origin` in a
/// `w`-wide image.
fn tile_pixel(w: u32, origin: UVec2, i: usize) -> usize {
    let tw = TILE.min(w - origin.x);
    let (x, y) = (origin.x + i as u32 % tw, origin.y + i as u32 / tw);
    (y * w + x) as usize
}

/// Passes over an image's tiles on a pool of `run.threads` threads, with progress over all
/// the passes, the rays counted and a stop asked for by [`Progress::stop`] honoured.
struct TilePass<'a> {
    pool: rayon::ThreadPool,
    run: &'a RunOptions<'a>,
    total: u64,
    done: AtomicU64,
    rays: AtomicU64,
    start: Instant,
}

impl<'a> TilePass<'a> {
    fn new(
        run: &'a RunOptions<'a>,
        tiles: u64,
        passes: u64,
        unit: &str,
    ) -> Result<Self, RenderError> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(run.threads)
            .build()
            .map_err(|e| RenderError::Threads {
                threads: run.threads,
                message: e.to_string(),
            })?;
        let total = tiles * passes;
        run.progress.start(total, unit);
        Ok(TilePass {
            pool,
            run,
            total,
            done: AtomicU64::new(0),
            rays: AtomicU64::new(0),
            start: Instant::now(),
        })
    }

    /// `tile(index, origin, input)` for every (tile origin, input) of `jobs`, in their order;
    /// each gives its result and the rays it traced.
    fn run<I: Send, T: Send>(
        &mut self,
        jobs: Vec<(UVec2, I)>,
        tile: impl Fn(usize, UVec2, I) -> (u64, T) + Sync + Send,
    ) -> Result<Vec<T>, RenderError> {
        let stopped = std::sync::atomic::AtomicBool::new(false);
        let this = &*self;
        let results: Vec<Option<T>> = self.pool.install(|| {
            // Every tile its own job to steal: adaptive sampling's second pass gives a few
            // tiles (a highlight's) many times the mean work, and rayon's default splitting
            // left one thread running a long sequential run of tiles with them while the other
            // waited (sweep_board, 2 threads: that pass 1.54x faster than on one thread; each
            // tile stolen alone: 1.88x).
            jobs.into_par_iter()
                .with_max_len(1)
                .enumerate()
                .map(|(t, (origin, input))| {
                    if stopped.load(Ordering::Relaxed) || this.run.progress.stop() {
                        stopped.store(true, Ordering::Relaxed);
                        return None;
                    }
                    let (rays, out) = tile(t, origin, input);
                    let total = this.rays.fetch_add(rays, Ordering::Relaxed) + rays;
                    let secs = this.start.elapsed().as_secs_f64().max(1e-9);
                    let done = this.done.fetch_add(1, Ordering::Relaxed) + 1;
                    let rate = format!("{:.2} Mrays/s", total as f64 / secs / 1e6);
                    this.run.progress.update(done, this.total, &rate);
                    Some(out)
                })
                .collect()
        });
        if stopped.into_inner() {
            self.run.progress.finish();
            return Err(RenderError::Stopped {
                done: self.done.load(Ordering::Relaxed),
                total: self.total,
            });
        }
        Ok(results.into_iter().flatten().collect())
    }

    /// Ends the progress report; the rays traced over all passes.
    fn finish(self) -> u64 {
        self.run.progress.finish();
        self.rays.into_inner()
    }
}

/// The camera's image size and its tiles ([`tile_origins`]); an error for an empty image.
fn image_tiles(scene: &Scene) -> Result<(u32, u32, Vec<UVec2>), RenderError> {
    let (w, h) = (scene.camera.width, scene.camera.height);
    if w == 0 || h == 0 {
        return Err(RenderError::EmptyImage {
            width: w,
            height: h,
        });
    }
    Ok((w, h, tile_origins(w, h)))
}

/// The top-left corners of the `TILE × TILE` tiles covering a `w × h` image, row by row.
fn tile_origins(w: u32, h: u32) -> Vec<UVec2> {
    (0..h.div_ceil(TILE))
        .flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| UVec2::new(tx, ty) * TILE))
        .collect()
}

/// The finished tiles put together into a `w × h` run of `n_frames` frames with their AOVs,
/// timed from `start`, `rays` traced.
fn place_tiles(
    w: u32,
    h: u32,
    n_frames: usize,
    results: Vec<(UVec2, TileFrames)>,
    start: Instant,
    rays: u64,
) -> Frames {
    let n = (w * h) as usize;
    let mut frames: Vec<FrameImage> = (0..n_frames)
        .map(|_| FrameImage {
            beauty: vec![Vec3::ZERO; n],
            std_error: vec![0.0; n],
            nonfinite: 0,
        })
        .collect();
    let mut aov = vec![Aov::default(); n];
    for (origin, tile) in results {
        let place = |i: usize| tile_pixel(w, origin, i);
        for (i, a) in tile.aov.iter().enumerate() {
            aov[place(i)] = *a;
        }
        for (f, img) in frames.iter_mut().zip(tile.frames) {
            for i in 0..img.beauty.len() {
                f.beauty[place(i)] = img.beauty[i];
                f.std_error[place(i)] = img.std_error[i];
            }
            f.nonfinite += img.nonfinite;
        }
    }
    Frames {
        width: w,
        height: h,
        aov,
        frames,
        elapsed: start.elapsed(),
        rays,
    }
}

/// What a render's progress counts: `tiles`, or `tiles × 48 frames` for a sweep.
fn progress_unit(frames: usize) -> String {
    if frames > 1 {
        format!("tiles × {frames} frames")
    } else {
        "tiles".to_string()
    }
}

/// One tile's frames (per frame the averaged pixels, a [`RenderedImage`] the size of the tile without
/// AOVs), its AOVs once, the rays traced and, when asked to keep them, its primary samples.
struct TileFrames {
    aov: Vec<Aov>,
    frames: Vec<RenderedImage>,
    rays: u64,
    kept: Vec<KeptSample>,
}

/// A tile's sums so far (its pixels' radiance in every frame and AOVs, pixel-major), the rays
/// its pass traced and, when asked to keep them, its primary samples.
struct TileSums {
    width: u32,
    height: u32,
    sums: FrameSums,
    aov_sums: Vec<PixelSum>,
    rays: u64,
    /// Per pixel, what its samples cost in rays ([`RayCount::work`]).
    work: Vec<u64>,
    kept: Vec<KeptSample>,
}

impl TileSums {
    /// The tile's averaged frames and AOVs.
    fn finish(self) -> TileFrames {
        let (tw, th) = (self.width, self.height);
        let aov = RenderedImage::from_sums(tw, th, &self.aov_sums).aov;
        let frames = (0..self.sums.frames())
            .map(|k| RenderedImage::from_radiance(tw, th, self.sums.frame(k)))
            .collect();
        TileFrames {
            aov,
            frames,
            rays: self.rays,
            kept: self.kept,
        }
    }
}

/// One tile's work in a pass: where it is, where its primary samples come from, which samples
/// it takes and the sums of an earlier pass it continues.
struct TileJob<'a> {
    origin: UVec2,
    primary: Primary<'a>,
    span: Span<'a>,
    carry: Option<TileSums>,
}

/// Which samples of its pixels a tile pass takes.
#[derive(Clone, Copy)]
enum Span<'a> {
    /// Samples 0..n of every pixel.
    All(u32),
    /// Samples first..first + extra[i] of the tile's pixel i.
    After { first: u32, extra: &'a [u32] },
}

impl Span<'_> {
    /// The samples of the tile's pixel `i`.
    fn of(&self, i: usize) -> std::ops::Range<u32> {
        match *self {
            Span::All(n) => 0..n,
            Span::After { first, extra } => first..first + extra[i],
        }
    }
}

/// Where a tile's primary samples come from: computed, computed and kept, or read from an
/// earlier pass (the tile's samples, pixel-major).
#[derive(Clone, Copy)]
enum Primary<'a> {
    Compute,
    Keep,
    Reuse(&'a [KeptSample]),
}

/// One tile for every frame: each (pixel, frame) sums its samples in sample order; the AOVs,
/// the same in every frame, are summed once.
fn render_tile(
    scene: &Scene,
    lights: &LightFrames,
    shadow: &ShadowTest,
    settings: &RenderSettings,
    job: TileJob,
) -> TileSums {
    #[cfg(target_arch = "x86_64")]
    match Simd::best() {
        // SAFETY: `Simd::best` detected the level's features on this CPU.
        Simd::Avx512 => return unsafe { render_tile_avx512(scene, lights, shadow, settings, job) },
        Simd::Avx2 => return unsafe { render_tile_avx2(scene, lights, shadow, settings, job) },
        Simd::Sse2 | Simd::Scalar => {}
    }
    render_tile_in(scene, lights, shadow, settings, job)
}

simd_wide! {
    unsafe fn render_tile_avx2 / render_tile_avx512(
        scene: &Scene,
        lights: &LightFrames,
        shadow: &ShadowTest,
        settings: &RenderSettings,
        job: TileJob,
    ) -> TileSums {
        render_tile_in(scene, lights, shadow, settings, job)
    }
}

/// The body of [`render_tile`], compiled once per SIMD level (`simd_level!`): the per-frame
/// loops it inlines (light samples, next-event terms, BSDF batches, sums) run in that level's
/// lanes. The path loop's steps are `#[inline(always)]` so that each level's copy holds them
/// too (shading points, `Material::shade`, light sampling, hits and terms, shadow tests, BSDF
/// sampling, camera rays, Sobol points, closest hits): in VEX's three-operand forms the scalar
/// chains lose their register copies, 14 % of a Cornell-box render on the AVX-512 Xeon
/// (notes/render.md). The same IEEE operations at every level, so the same bits
/// (crates/xylem-cli/tests/simd_levels.rs).
#[inline(always)]
fn render_tile_in(
    scene: &Scene,
    lights: &LightFrames,
    shadow: &ShadowTest,
    settings: &RenderSettings,
    job: TileJob,
) -> TileSums {
    // One frame (a plain render): the frame loops of constant length (`radiance_frames`).
    match lights.len() {
        1 => tile_frames::<true>(scene, lights, shadow, settings, job),
        _ => tile_frames::<false>(scene, lights, shadow, settings, job),
    }
}

/// [`render_tile_in`] for one frame (`ONE`) or any number.
#[inline(always)]
fn tile_frames<const ONE: bool>(
    scene: &Scene,
    lights: &LightFrames,
    shadow: &ShadowTest,
    settings: &RenderSettings,
    job: TileJob,
) -> TileSums {
    let TileJob {
        origin,
        primary,
        span,
        carry,
    } = job;
    let (w, h) = (scene.camera.width, scene.camera.height);
    let (tw, th) = (TILE.min(w - origin.x), TILE.min(h - origin.y));
    let n = (tw * th) as usize;
    let frames = lights.len();
    let max_depth = settings.integrator.max_depth();
    // Pixel-major (pixel i, frame k at i·frames + k): a pixel's samples update one contiguous
    // run of sums instead of one cache line in each of `frames` arrays.
    let (mut sums, mut aov_sums, mut work) = match carry {
        Some(c) => (c.sums, c.aov_sums, c.work),
        None => (
            FrameSums::new(n, frames),
            vec![PixelSum::default(); n],
            vec![0; n],
        ),
    };
    let mut rays = RayCount::default();
    let spp = settings.spp as usize;
    let mut kept = Vec::new();
    if let Primary::Keep = primary {
        kept.reserve_exact(n * spp);
    }
    if let Primary::Reuse(p) = primary {
        assert_eq!(p.len(), n * spp, "primaries of another render");
    }
    let pixels = (origin.y..origin.y + th)
        .flat_map(|y| (origin.x..origin.x + tw).map(move |x| UVec2::new(x, y)));
    if ONE && matches!(primary, Primary::Compute) && wave::enabled(scene, lights) {
        let mut samples = Vec::new();
        for (i, pixel) in pixels.enumerate() {
            samples.extend(span.of(i).map(|s| (i as u32, pixel, s)));
        }
        wave::tile_waves(
            scene,
            lights,
            shadow,
            (settings.seed, max_depth),
            &samples,
            &mut wave::WaveScratch::default(),
            (&mut sums, &mut aov_sums, &mut work),
            &mut rays,
        );
    } else {
        tile_paths::<ONE>(
            scene,
            (lights, shadow),
            settings,
            (pixels, primary, span),
            &mut kept,
            (&mut sums, &mut aov_sums, &mut work),
            &mut rays,
        );
    }
    TileSums {
        width: tw,
        height: th,
        sums,
        aov_sums,
        rays: rays.rays,
        work,
        kept,
    }
}

/// The per-path loop of [`tile_frames`]: each pixel's samples one path at a time, for every
/// frame; sums into `sums`, `aov_sums` and `work`, kept samples into `kept`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn tile_paths<const ONE: bool>(
    scene: &Scene,
    (lights, shadow): (&LightFrames, &ShadowTest),
    settings: &RenderSettings,
    (pixels, primary, span): (impl Iterator<Item = UVec2>, Primary, Span),
    kept: &mut Vec<KeptSample>,
    (sums, aov_sums, work): (&mut FrameSums, &mut [PixelSum], &mut [u64]),
    rays: &mut RayCount,
) {
    let max_depth = settings.integrator.max_depth();
    // Each frame's radiance of the sample at hand, by channel ([`integrator::Columns`]).
    let mut radiance = integrator::Columns::default();
    let mut scratch = FramesScratch::default();
    let fp_scale = integrator::footprint_scale(settings.spp);
    let camera = scene.camera.rays();
    // The primary sample of the pixel sample at hand, written in place ([`primary_sample_into`]).
    let mut computed = PrimarySample::empty();
    let spp = settings.spp as usize;
    for (i, pixel) in pixels.enumerate() {
        let samples = span.of(i);
        let before = rays.work();
        for s in samples {
            let (ps, reused) = match primary {
                Primary::Reuse(p) => {
                    let k = &p[i * spp + s as usize];
                    (&k.primary, Some(&k.next))
                }
                Primary::Compute | Primary::Keep => {
                    rays.rays += 1;
                    rays.shading += primary_sample_into(
                        scene,
                        &camera,
                        pixel,
                        s,
                        settings.seed,
                        fp_scale,
                        &mut computed,
                    ) as u64;
                    (&computed, None)
                }
            };
            let mut next = None;
            let first = match (primary, reused) {
                (_, Some(next)) => FirstBounce::Reuse(next),
                (Primary::Keep, _) => FirstBounce::Keep(&mut next),
                _ => FirstBounce::Trace,
            };
            let numbers = path_numbers(scene, pixel, s, settings.seed);
            radiance_frames::<ONE>(
                scene,
                lights,
                shadow,
                ps,
                &numbers,
                max_depth,
                &mut scratch,
                &mut radiance,
                rays,
                first,
            );
            if let Primary::Keep = primary {
                kept.push(KeptSample { primary: *ps, next });
            }
            sums.add(i, &radiance);
            aov_sums[i].add(Vec3::ZERO, &ps.aov);
        }
        work[i] += rays.work() - before;
    }
}
