//! The BVH path tracer: camera, lights, meshes on an obvhs BVH, integrator, film with AOVs,
//! EXR / PNG output and progress.
//!
//! [`render`] renders a [`Scene`] tile by tile on a rayon pool. Every pixel sample draws its
//! random numbers from streams keyed by (seed, pixel, sample) only, so the image is bit-identical
//! for any thread count.

pub mod bench;
pub mod camera;
#[cfg(feature = "embree-anchor")]
pub mod embree;
pub mod film;
pub mod geometry;
pub mod image_io;
pub mod integrator;
pub mod light;
pub mod resources;
pub mod wide_bvh;

pub use camera::{Camera, Projection};
pub use film::{Aov, Filter, Image, PixelSum};
pub use geometry::{Accel, Instance, Ray, Transform, TriMesh};
pub use integrator::{
    direct_radiance, light_rng, primary_sample, sample_rngs, shade_direct, Integrator,
    PrimarySample, ShadingPoint,
};
pub use light::{EnvMap, Environment, Light};

use crate::material::Material;
use glam::UVec2;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// Everything a render needs to know about the world.
pub struct Scene {
    pub accel: Accel,
    pub materials: Vec<Material>,
    pub lights: Vec<Light>,
    pub camera: Camera,
    pub filter: Filter,
}

/// Sampling settings of one render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    pub spp: u32,
    pub integrator: Integrator,
    pub seed: u64,
}

impl RenderSettings {
    /// The EXR header attributes that say how an image of `scene` (its name and file) seen by
    /// `camera` was made: scene, file, spp, seed, integrator and camera (the software attribute
    /// carries xylem's version; [`image_io::stage_exr_layers`]). Camera axes as [`Camera`] has
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
#[derive(Clone, Copy, Debug, Default)]
pub struct RunOptions {
    /// Worker threads; 0 = all cores.
    pub threads: usize,
    /// Show an indicatif progress bar on stderr.
    pub progress: bool,
}

/// A finished render with its statistics.
#[derive(Clone, Debug)]
pub struct RenderOutput {
    pub image: Image,
    pub elapsed: Duration,
    /// Rays traced (camera, shadow and bounce rays).
    pub rays: u64,
}

#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error("cannot start {threads} render threads: {message}")]
    Threads { threads: usize, message: String },
    #[error("image size {width}x{height} is empty")]
    EmptyImage { width: u32, height: u32 },
}

/// Side length of the square tiles handed to worker threads.
pub const TILE: u32 = 16;

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
/// let dir = tempfile::tempdir()?;
/// let meta = loaded.settings.exr_meta(&loaded.name, "scenes/sweep_board.toml", &loaded.scene.camera);
/// xylem::render::image_io::write_image_exr(&dir.path().join("board.exr"), &out.image, &meta)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn render(
    scene: &Scene,
    settings: &RenderSettings,
    run: &RunOptions,
) -> Result<RenderOutput, RenderError> {
    render_with_lights(scene, &scene.lights, settings, run)
}

/// What every tiled render starts with: the image size checked, a pool of `run.threads`
/// threads, and the origins of the TILE×TILE tiles covering the image (row-major).
pub fn tiled_job(
    scene: &Scene,
    run: &RunOptions,
) -> Result<(rayon::ThreadPool, Vec<UVec2>), RenderError> {
    let (w, h) = (scene.camera.width, scene.camera.height);
    if w == 0 || h == 0 {
        return Err(RenderError::EmptyImage {
            width: w,
            height: h,
        });
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(run.threads)
        .build()
        .map_err(|e| RenderError::Threads {
            threads: run.threads,
            message: e.to_string(),
        })?;
    let tiles: Vec<UVec2> = (0..h.div_ceil(TILE))
        .flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| UVec2::new(tx, ty) * TILE))
        .collect();
    Ok((pool, tiles))
}

/// Renders the scene lit by `lights` instead of its own.
pub fn render_with_lights(
    scene: &Scene,
    lights: &[Light],
    settings: &RenderSettings,
    run: &RunOptions,
) -> Result<RenderOutput, RenderError> {
    let (w, h) = (scene.camera.width, scene.camera.height);
    let (pool, tiles) = tiled_job(scene, run)?;
    let bar = if run.progress {
        let b = ProgressBar::new(tiles.len() as u64);
        b.set_style(
            ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {wide_bar} {pos}/{len} tiles, eta {eta} {msg}",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        b
    } else {
        ProgressBar::hidden()
    };
    let total_rays = AtomicU64::new(0);
    let start = Instant::now();
    let results: Vec<(UVec2, Vec<PixelSum>)> = pool.install(|| {
        tiles
            .par_iter()
            .map(|&origin| {
                let (sums, rays) = render_tile(scene, lights, settings, origin);
                let total = total_rays.fetch_add(rays, Ordering::Relaxed) + rays;
                let secs = start.elapsed().as_secs_f64().max(1e-9);
                bar.set_message(format!("{:.2} Mrays/s", total as f64 / secs / 1e6));
                bar.inc(1);
                (origin, sums)
            })
            .collect()
    });
    bar.finish_and_clear();
    let mut sums = vec![PixelSum::default(); (w * h) as usize];
    for (origin, tile) in results {
        let tw = TILE.min(w - origin.x);
        for (i, s) in tile.into_iter().enumerate() {
            let (x, y) = (origin.x + i as u32 % tw, origin.y + i as u32 / tw);
            sums[(y * w + x) as usize] = s;
        }
    }
    Ok(RenderOutput {
        image: Image::from_sums(w, h, &sums),
        elapsed: start.elapsed(),
        rays: total_rays.into_inner(),
    })
}

/// Renders one tile; returns its pixel sums (row-major within the tile) and the rays traced.
fn render_tile(
    scene: &Scene,
    lights: &[Light],
    settings: &RenderSettings,
    origin: UVec2,
) -> (Vec<PixelSum>, u64) {
    let (w, h) = (scene.camera.width, scene.camera.height);
    let (tw, th) = (TILE.min(w - origin.x), TILE.min(h - origin.y));
    let mut rays = integrator::RayCount::default();
    let mut out = Vec::with_capacity((tw * th) as usize);
    for y in origin.y..origin.y + th {
        for x in origin.x..origin.x + tw {
            let pixel = UVec2::new(x, y);
            let mut sum = PixelSum::default();
            for s in 0..settings.spp {
                let ps = primary_sample(scene, pixel, s, settings.seed);
                rays.0 += 1;
                let mut rng = light_rng(scene, pixel, s, settings.seed);
                let l = match settings.integrator {
                    Integrator::Direct => {
                        integrator::direct_radiance_counted(scene, &ps, lights, &mut rng, &mut rays)
                    }
                    Integrator::Path { max_depth } => integrator::path_radiance(
                        scene, &ps, lights, &mut rng, max_depth, &mut rays,
                    ),
                };
                sum.add(l, &ps.aov);
            }
            out.push(sum);
        }
    }
    (out, rays.0)
}
