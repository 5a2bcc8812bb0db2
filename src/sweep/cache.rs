//! Rendering a sweep with a per-sweep cache: the camera and geometry do not move, so what does
//! not depend on the light — camera rays, first hits, shading frames, texels and BSDFs, i.e. the
//! renderer's [`PrimarySample`]s — is computed once per pixel sample and reused by every frame;
//! only the light-dependent part ([`direct_radiance`], or path tracing from the cached first hit)
//! runs per frame.
//!
//! Work is tile-major: a worker computes one tile's primary samples (a few hundred kB) and shades
//! them for every frame before moving on, so the cache stays small and hot whatever the image
//! size. Every sample draws from the renderer's per-(seed, pixel, sample) streams and sums in the
//! same order as [`crate::render::render_with_lights`], so each frame is bit-identical to the
//! naive render of that frame.

use super::path::{ArcPlane, LightArc};
use crate::render::integrator::{self, light_rng, primary_sample, PrimarySample, RayCount};
use crate::render::{
    Aov, Image, Integrator, Light, PixelSum, RenderError, RenderSettings, RunOptions, Scene, TILE,
};
use glam::{UVec2, Vec3};
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use std::ops::Range;
use std::time::{Duration, Instant};

/// Where the moving light goes: the arc's angles, its plane, and for lights with a position the
/// pivot and distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SweepPath {
    pub arc: LightArc,
    pub plane: ArcPlane,
    pub pivot: Vec3,
    pub radius: f32,
}

impl SweepPath {
    /// `light` moved to light angle `angle_deg`: point and sphere lights move to the arc point,
    /// spot lights move there and aim at the pivot, distant lights shine from the arc direction.
    /// Other lights (area, environment) have no position on an arc and are returned unchanged.
    pub fn place(&self, light: &Light, angle_deg: f32) -> Light {
        let dir = self.plane.direction(angle_deg);
        let at = self.pivot + self.radius * dir;
        match light.clone() {
            Light::Point { intensity, .. } => Light::Point {
                position: at,
                intensity,
            },
            Light::Spot {
                intensity,
                cos_inner,
                cos_outer,
                ..
            } => Light::Spot {
                position: at,
                direction: -dir,
                intensity,
                cos_inner,
                cos_outer,
            },
            Light::Sphere {
                radius, radiance, ..
            } => Light::Sphere {
                center: at,
                radius,
                radiance,
            },
            Light::Distant { irradiance, .. } => Light::Distant {
                direction: dir,
                irradiance,
            },
            other => other,
        }
    }

    /// The scene's lights for frame `frame`, the light at index `moving` placed on the arc.
    pub fn frame_lights(&self, lights: &[Light], moving: usize, frame: usize) -> Vec<Light> {
        let angle = self.arc.angle_deg(frame);
        lights
            .iter()
            .enumerate()
            .map(|(i, l)| if i == moving { self.place(l, angle) } else { l.clone() })
            .collect()
    }
}

/// One rendered frame: its light angle and radiance (the AOVs are shared by all frames).
#[derive(Clone, Debug)]
pub struct SweepFrame {
    pub index: usize,
    pub light_deg: f32,
    pub beauty: Vec<Vec3>,
    pub std_error: Vec<f32>,
    pub nonfinite: u64,
}

/// The frames of a sweep (or of a slice of one) with the first-hit AOVs they share.
#[derive(Clone, Debug)]
pub struct SweepRender {
    pub width: u32,
    pub height: u32,
    pub aov: Vec<Aov>,
    pub frames: Vec<SweepFrame>,
    pub elapsed: Duration,
}

impl SweepRender {
    /// Frame `k` of this render as a renderer [`Image`] (for EXR output with AOV layers).
    pub fn image(&self, k: usize) -> Image {
        let f = &self.frames[k];
        Image {
            width: self.width,
            height: self.height,
            beauty: f.beauty.clone(),
            std_error: f.std_error.clone(),
            aov: self.aov.clone(),
            nonfinite: f.nonfinite,
        }
    }
}

/// Renders frames `frames` of a sweep in which light `moving` of the scene follows `path`,
/// caching each pixel sample's light-independent part across all frames.
pub fn render_sweep(
    scene: &Scene,
    settings: &RenderSettings,
    path: &SweepPath,
    moving: usize,
    frames: Range<usize>,
    run: &RunOptions,
) -> Result<SweepRender, RenderError> {
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
    let lights: Vec<Vec<Light>> = frames
        .clone()
        .map(|f| path.frame_lights(&scene.lights, moving, f))
        .collect();
    let tiles: Vec<UVec2> = (0..h.div_ceil(TILE))
        .flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| UVec2::new(tx, ty) * TILE))
        .collect();
    let bar = progress_bar(run.progress, tiles.len() as u64, lights.len());
    let start = Instant::now();
    let results: Vec<(UVec2, TileFrames)> = pool.install(|| {
        tiles
            .par_iter()
            .map(|&origin| {
                let r = (origin, sweep_tile(scene, &lights, settings, origin));
                bar.inc(1);
                r
            })
            .collect()
    });
    bar.finish_and_clear();
    let n = (w * h) as usize;
    let mut out: Vec<SweepFrame> = frames
        .map(|index| SweepFrame {
            index,
            light_deg: path.arc.angle_deg(index),
            beauty: vec![Vec3::ZERO; n],
            std_error: vec![0.0; n],
            nonfinite: 0,
        })
        .collect();
    let mut aov = vec![Aov::default(); n];
    for (origin, tile) in results {
        let tw = TILE.min(w - origin.x);
        let place = |i: usize| {
            let (x, y) = (origin.x + i as u32 % tw, origin.y + i as u32 / tw);
            (y * w + x) as usize
        };
        for (i, a) in tile.aov.iter().enumerate() {
            aov[place(i)] = *a;
        }
        for (f, img) in out.iter_mut().zip(tile.frames) {
            for i in 0..img.beauty.len() {
                f.beauty[place(i)] = img.beauty[i];
                f.std_error[place(i)] = img.std_error[i];
            }
            f.nonfinite += img.nonfinite;
        }
    }
    Ok(SweepRender {
        width: w,
        height: h,
        aov,
        frames: out,
        elapsed: start.elapsed(),
    })
}

fn progress_bar(show: bool, tiles: u64, frames: usize) -> ProgressBar {
    if !show {
        return ProgressBar::hidden();
    }
    let b = ProgressBar::new(tiles);
    b.set_style(
        ProgressStyle::with_template(&format!(
            "{{spinner}} [{{elapsed_precise}}] {{wide_bar}} {{pos}}/{{len}} tiles × {frames} frames, eta {{eta}}"
        ))
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    b
}

/// One tile's frames: per frame the averaged pixels (an [`Image`] the size of the tile, its own
/// AOVs dropped), and the AOVs once.
struct TileFrames {
    aov: Vec<Aov>,
    frames: Vec<Image>,
}

/// One tile for every frame: its primary samples once, then the light-dependent part per frame,
/// summed exactly as the naive renderer sums them.
fn sweep_tile(
    scene: &Scene,
    lights: &[Vec<Light>],
    settings: &RenderSettings,
    origin: UVec2,
) -> TileFrames {
    let (w, h) = (scene.camera.width, scene.camera.height);
    let (tw, th) = (TILE.min(w - origin.x), TILE.min(h - origin.y));
    let spp = settings.spp as usize;
    let pixels: Vec<UVec2> = (origin.y..origin.y + th)
        .flat_map(|y| (origin.x..origin.x + tw).map(move |x| UVec2::new(x, y)))
        .collect();
    let cache: Vec<PrimarySample> = pixels
        .iter()
        .flat_map(|&p| (0..settings.spp).map(move |s| primary_sample(scene, p, s, settings.seed)))
        .collect();
    let mut rays = RayCount::default();
    let mut aov = Vec::new();
    let frames = lights
        .iter()
        .map(|frame_lights| {
            let sums: Vec<PixelSum> = pixels
                .iter()
                .enumerate()
                .map(|(i, &pixel)| {
                    let mut sum = PixelSum::default();
                    for (s, ps) in cache[i * spp..(i + 1) * spp].iter().enumerate() {
                        let mut rng = light_rng(scene, pixel, s as u32, settings.seed);
                        let l = match settings.integrator {
                            Integrator::Direct => {
                                integrator::direct_radiance(scene, ps, frame_lights, &mut rng)
                            }
                            Integrator::Path { max_depth } => integrator::path_radiance(
                                scene,
                                ps,
                                frame_lights,
                                &mut rng,
                                max_depth,
                                &mut rays,
                            ),
                        };
                        sum.add(l, &ps.aov);
                    }
                    sum
                })
                .collect();
            let mut img = Image::from_sums(tw, th, &sums);
            if aov.is_empty() {
                aov = std::mem::take(&mut img.aov);
            } else {
                img.aov = Vec::new();
            }
            img
        })
        .collect();
    TileFrames { aov, frames }
}
