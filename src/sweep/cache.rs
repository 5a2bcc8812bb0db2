//! Rendering a sweep with a per-sweep cache: the camera and geometry do not move, so what does
//! not depend on the light — camera rays, first hits, shading frames, texels and BSDFs, i.e. the
//! renderer's [`PrimarySample`]s — is computed once per pixel sample and reused by every frame;
//! only the light-dependent part (`direct_radiance`, or path tracing from the cached first hit)
//! runs per frame.
//!
//! Work is tile-major and, within a tile, pixel → sample → frame: each primary sample is lit for
//! every frame as soon as it is computed, so the "cache" is one sample held in registers rather
//! than a buffer, whatever the image size. For direct lighting the BSDF-sampled ray is
//! light-independent too and is traced once per sample (see `direct_for_frames`). Every sample draws from the renderer's per-(seed, pixel, sample) streams and sums in the
//! same order as [`crate::render::render_with_lights`], so each frame is bit-identical to the
//! naive render of that frame.

use super::path::{ArcPlane, LightArc, PathError};
use crate::bsdf::Bsdf;
use crate::math::{power_heuristic, Pcg32};
use crate::render::integrator::{
    self, light_rng, primary_sample, BsdfAtWo, PrimarySample, RayCount, ShadowTest, TermScratch,
};
use crate::render::light::{LightSamples, LightU};
use crate::render::{
    Aov, Image, Integrator, Light, PixelSum, Ray, RenderError, RenderSettings, RunOptions, Scene,
    TILE,
};
use crate::scene::LoadedScene;
use crate::scene::MAX_ARCS;
use glam::{UVec2, Vec3, Vec3A};
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use std::ops::Range;
use std::time::{Duration, Instant};

/// Where the moving light goes: the arc's angles, its plane, and for lights with a position the
/// pivot and distance. The light runs the arc once per azimuth (`azimuths[..arcs]`, degrees
/// about the zenith from `plane`): frame k is angle `k % arc.frames` of arc `k / arc.frames`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SweepPath {
    pub arc: LightArc,
    pub plane: ArcPlane,
    pub pivot: Vec3,
    pub radius: f32,
    pub azimuths: [f32; MAX_ARCS],
    pub arcs: usize,
}

/// Why a scene's sweep cannot be set up; each names the scene and the `[sweep]` field.
#[derive(Debug, thiserror::Error)]
pub enum SetupError {
    #[error(
        "scene `{scene}` has no [sweep] table (it needs at least `light`, `arc_deg` and `radius`)"
    )]
    NoTable { scene: String },
    #[error(
        "scene `{scene}`: [sweep] light = \"{light}\" names no light; lights with names: {names}"
    )]
    NoLight {
        scene: String,
        light: String,
        names: String,
    },
    #[error("scene `{scene}`: [sweep] light = \"{light}\" is an area or environment light; a sweep moves a point, spot, sphere or distant light")]
    Immovable { scene: String, light: String },
    #[error("scene `{scene}`: [sweep] {field}: {message}")]
    Field {
        scene: String,
        field: &'static str,
        message: String,
    },
    #[error("scene `{scene}`: {source}")]
    Path { scene: String, source: PathError },
}

impl SweepPath {
    /// The sweep of a loaded scene's `[sweep]` table, with `frames` and `arc` (degrees) overriding
    /// the table's; returns the path and the index of the light that moves.
    pub fn from_scene(
        loaded: &LoadedScene,
        frames: Option<usize>,
        arc: Option<(f32, f32)>,
    ) -> Result<(SweepPath, usize), SetupError> {
        let scene = loaded.name.clone();
        let t = loaded.sweep.as_ref().ok_or_else(|| SetupError::NoTable {
            scene: scene.clone(),
        })?;
        let moving = loaded
            .light_names
            .iter()
            .position(|n| n.as_deref() == Some(t.light.as_str()))
            .ok_or_else(|| SetupError::NoLight {
                scene: scene.clone(),
                light: t.light.clone(),
                names: loaded
                    .light_names
                    .iter()
                    .flatten()
                    .map(|n| format!("\"{n}\""))
                    .collect::<Vec<_>>()
                    .join(", "),
            })?;
        if matches!(
            loaded.scene.lights[moving],
            Light::Rect { .. } | Light::Environment(_)
        ) {
            return Err(SetupError::Immovable {
                scene,
                light: t.light.clone(),
            });
        }
        let field = |field, message: &str| SetupError::Field {
            scene: scene.clone(),
            field,
            message: message.to_string(),
        };
        let radius = t.radius;
        if !(radius.is_finite() && radius > 0.0) {
            return Err(field(
                "radius",
                &format!("{radius} must be a positive distance (mm)"),
            ));
        }
        let pivot = Vec3::from_array(t.pivot);
        if !pivot.is_finite() {
            return Err(field("pivot", "every component must be finite"));
        }
        let plane = ArcPlane::from_axis(Vec3::Z, Vec3::from_array(t.axis)).ok_or_else(|| {
            field(
                "axis",
                "must be a non-zero direction not parallel to +z (the zenith)",
            )
        })?;
        let (from, to) = arc.unwrap_or((t.arc_deg[0], t.arc_deg[1]));
        let arc =
            LightArc::new(from, to, frames.unwrap_or(t.frames as usize)).map_err(|source| {
                SetupError::Path {
                    scene: scene.clone(),
                    source,
                }
            })?;
        let arcs = t.azimuths_deg.len();
        if arcs == 0 || arcs > MAX_ARCS {
            return Err(field(
                "azimuths_deg",
                &format!("{arcs} azimuths (allowed 1 to {MAX_ARCS})"),
            ));
        }
        if arc.frames * arcs > super::path::MAX_FRAMES {
            return Err(SetupError::Path {
                scene,
                source: PathError::Frames(arc.frames * arcs),
            });
        }
        let path = SweepPath::with_arcs(arc, plane, pivot, radius, &t.azimuths_deg);
        Ok((path, moving))
    }

    /// A path of one arc per entry of `azimuths_deg` (at most [`MAX_ARCS`]; extra ones are
    /// dropped).
    pub fn with_arcs(
        arc: LightArc,
        plane: ArcPlane,
        pivot: Vec3,
        radius: f32,
        azimuths_deg: &[f32],
    ) -> SweepPath {
        let given = azimuths_deg.len().min(MAX_ARCS);
        let mut azimuths = [0.0; MAX_ARCS];
        azimuths[..given].copy_from_slice(&azimuths_deg[..given]);
        let arcs = given.max(1);
        SweepPath {
            arc,
            plane,
            pivot,
            radius,
            azimuths,
            arcs,
        }
    }

    /// Frames of the whole sweep: every arc's.
    pub fn frames(&self) -> usize {
        self.arc.frames * self.arcs
    }

    /// The light angle (degrees from the zenith along its arc) of frame `frame`.
    pub fn light_deg(&self, frame: usize) -> f32 {
        self.arc.angle_deg(frame % self.arc.frames)
    }

    /// The azimuth (degrees about the zenith) of the arc frame `frame` lies on.
    pub fn azimuth_deg(&self, frame: usize) -> f32 {
        self.azimuths[(frame / self.arc.frames).min(self.arcs - 1)]
    }

    /// The plane of the arc frame `frame` lies on: `plane` turned about its zenith by the arc's
    /// azimuth (Rodrigues' rotation of `toward`, which is perpendicular to the zenith).
    pub fn frame_plane(&self, frame: usize) -> ArcPlane {
        let (s, c) = self.azimuth_deg(frame).to_radians().sin_cos();
        let (z, a) = (self.plane.zenith, self.plane.toward);
        ArcPlane {
            zenith: z,
            toward: (c * a + s * z.cross(a)).normalize(),
        }
    }

    /// The unit direction from the pivot towards the light of frame `frame`.
    pub fn direction(&self, frame: usize) -> Vec3 {
        self.frame_plane(frame).direction(self.light_deg(frame))
    }

    /// `light` moved to frame `frame`: point and sphere lights move to the arc point, spot
    /// lights move there and aim at the pivot, distant lights shine from the arc direction.
    /// Other lights (area, environment) have no position on an arc and are returned unchanged.
    pub fn place(&self, light: &Light, frame: usize) -> Light {
        let dir = self.direction(frame);
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
        lights
            .iter()
            .enumerate()
            .map(|(i, l)| {
                if i == moving {
                    self.place(l, frame)
                } else {
                    l.clone()
                }
            })
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
    let (pool, tiles) = crate::render::tiled_job(scene, run)?;
    let lights = SweepLights::new(scene, path, moving, frames.clone());
    let bar = progress_bar(run.progress, tiles.len() as u64, lights.frames.len());
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
            light_deg: path.light_deg(index),
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

/// One tile for every frame. Each pixel sample's primary part is computed once and lit for every
/// frame straight away (pixel → sample → frame), so nothing but the tile's pixel sums is kept;
/// each (pixel, frame) sums its samples in the naive renderer's order. The AOVs, the same in
/// every frame, are summed once.
fn sweep_tile(
    scene: &Scene,
    sweep: &SweepLights,
    settings: &RenderSettings,
    origin: UVec2,
) -> TileFrames {
    let (w, h) = (scene.camera.width, scene.camera.height);
    let (tw, th) = (TILE.min(w - origin.x), TILE.min(h - origin.y));
    let n = (tw * th) as usize;
    let lights = &sweep.frames;
    let frames = lights.len();
    // Pixel-major (pixel i, frame k at i·frames + k): a pixel's samples update one contiguous
    // run of sums instead of one cache line in each of `frames` arrays.
    let mut sums = vec![PixelSum::default(); n * frames];
    let mut aov_sums = vec![PixelSum::default(); n];
    let mut radiance = vec![Vec3::ZERO; lights.len()];
    let mut scratch = FrameScratch::default();
    let mut rays = RayCount::default();
    for (i, pixel) in (origin.y..origin.y + th)
        .flat_map(|y| (origin.x..origin.x + tw).map(move |x| UVec2::new(x, y)))
        .enumerate()
    {
        for s in 0..settings.spp {
            let ps = primary_sample(scene, pixel, s, settings.seed);
            let rng = light_rng(scene, pixel, s, settings.seed);
            match settings.integrator {
                Integrator::Direct => {
                    direct_for_frames(scene, sweep, &ps, &rng, &mut scratch, &mut radiance)
                }
                Integrator::Path { max_depth } => {
                    for (l, frame_lights) in radiance.iter_mut().zip(lights) {
                        let mut r = rng.clone();
                        *l = integrator::path_radiance(
                            scene,
                            &ps,
                            frame_lights,
                            &mut r,
                            max_depth,
                            &mut rays,
                        );
                    }
                }
            }
            for (sum, l) in sums[i * frames..(i + 1) * frames].iter_mut().zip(&radiance) {
                sum.add_radiance(*l);
            }
            aov_sums[i].add(Vec3::ZERO, &ps.aov);
        }
    }
    let aov = Image::from_sums(tw, th, &aov_sums).aov;
    let frames = (0..frames)
        .map(|k| {
            let frame_sums: Vec<PixelSum> = sums.iter().skip(k).step_by(frames).copied().collect();
            let mut img = Image::from_sums(tw, th, &frame_sums);
            img.aov = Vec::new();
            img
        })
        .collect();
    TileFrames { aov, frames }
}

/// Per-sample buffers of `direct_for_frames`, reused across samples.
#[derive(Default)]
struct FrameScratch {
    /// Whether each frame's sample is shaded at the first hit (not a light seen in front).
    shaded: Vec<bool>,
    /// The light-sample numbers of each light (the same in every frame).
    us: Vec<LightU>,
    /// Each light's next-event term; those of the lights that do not move hold for every frame.
    terms: Vec<Vec3>,
    /// The moving light's samples, next-event terms and their scratch columns, every frame.
    samples: LightSamples,
    moving_terms: Vec<Vec3>,
    term_scratch: TermScratch,
}

/// [`integrator::direct_radiance`] of one primary sample for every frame's lights, into `out`;
/// light `moving` is the only one whose place differs between frames.
///
/// The lighting stream `rng` draws two numbers per light for next-event estimation whatever the
/// lights' positions, so the numbers — and hence the next-event terms of the lights that do not
/// move — are the same in every frame and are computed once; only the moving light's term differs
/// per frame, and it is computed for all frames at once, frames in SIMD lanes
/// ([`LightSamples`], [`integrator::light_terms`]), with the BSDF prepared for this `wo` once
/// ([`BsdfAtWo`]). The BSDF-sampled direction
/// that follows, and the scene hit along it, are also the same in every frame: traced once, and
/// per frame only the light it may meet is tested. Sums run in the renderer's order
/// (`sample_lights`, `shade_direct`), so each frame equals the naive render.
fn direct_for_frames(
    scene: &Scene,
    sweep: &SweepLights,
    ps: &PrimarySample,
    rng: &Pcg32,
    scratch: &mut FrameScratch,
    out: &mut [Vec3],
) {
    let (lights, moving, shadow) = (&sweep.frames, sweep.moving, &sweep.shadow);
    let mut rays = RayCount::default();
    let FrameScratch {
        shaded,
        us,
        terms,
        samples,
        moving_terms,
        term_scratch,
    } = scratch;
    shaded.clear();
    shaded.resize(out.len(), false);
    sweep.nearest_per_frame(&ps.ray, ps.t_hit, |k, hit| {
        // A light seen directly in front of the first hit (or on a miss) is the sample's value.
        if let Some((_, t, le, _)) = hit {
            if t < ps.t_hit || ps.point.is_none() {
                out[k] = le;
                return;
            }
        }
        shaded[k] = ps.point.is_some();
        if !shaded[k] {
            out[k] = Vec3::ZERO;
        }
    });
    let (Some(sp), Some(first)) = (&ps.point, shaded.iter().position(|&s| s)) else {
        return;
    };
    // Next-event estimation, as `sample_lights` does it in each frame.
    let mut r = rng.clone();
    if sp.bsdf.is_delta() {
        for (l, _) in out.iter_mut().zip(shaded.iter()).filter(|(_, &s)| s) {
            *l = Vec3::ZERO;
        }
    } else {
        let bsdf = BsdfAtWo::new(sp);
        us.clear();
        terms.clear();
        for (j, light) in lights[first].iter().enumerate() {
            let u = LightU::new(r.next_vec2());
            us.push(u);
            terms.push(if j == moving {
                Vec3::ZERO
            } else {
                integrator::light_term(shadow, sp, &bsdf, light.sample_at(sp.p, &u), &mut rays)
            });
        }
        // The moving light's term in every frame at once (`light_terms`), then each frame's sum
        // in the lights' order.
        let u = &us[moving];
        match &sweep.sphere {
            Some(s) => samples.sample_sphere(sp.p, &s.centers, s.radius, s.radiance, u),
            None => samples.sample_each(sp.p, lights.iter().map(|fl| &fl[moving]), u),
        }
        moving_terms.resize(out.len(), Vec3::ZERO);
        integrator::light_terms(
            shadow,
            sp,
            &bsdf,
            samples,
            shaded,
            term_scratch,
            moving_terms,
            &mut rays,
        );
        for k in (0..out.len()).filter(|&k| shaded[k]) {
            let mut l = Vec3::ZERO;
            for (j, t) in terms.iter().enumerate() {
                l += if j == moving { moving_terms[k] } else { *t };
            }
            out[k] = l;
        }
    }
    let uc = r.next_f32();
    let u = r.next_vec2();
    if lights[first].iter().all(Light::is_delta) {
        return;
    }
    let Some(bs) = sp.bsdf.sample(sp.wo, uc, u) else {
        return;
    };
    if !(bs.pdf > 0.0) {
        return;
    }
    let d = sp.frame.to_world(bs.wi);
    let ray = Ray {
        o: integrator::offset_origin(sp, d),
        d,
    };
    let t_scene = scene
        .accel
        .intersect(&ray, f32::INFINITY)
        .map_or(f32::INFINITY, |h| h.t);
    sweep.nearest_per_frame(&ray, t_scene, |k, hit| {
        if let (true, Some((_, _, le, light_pdf))) = (shaded[k], hit) {
            let w = if bs.is_delta {
                1.0
            } else {
                power_heuristic(bs.pdf, light_pdf)
            };
            out[k] += bs.f * le * (bs.wi.z.abs() * w / bs.pdf);
        }
    });
}

/// The lights of every frame of a sweep, and what lets a frame skip work: the lights that do not
/// move, the box the moving light stays in over all frames, and the culled shadow test.
struct SweepLights<'a> {
    /// Each frame's lights (the scene's, light `moving` placed on the arc).
    frames: Vec<Vec<Light>>,
    moving: usize,
    /// The scene's lights without the moving one, in their order.
    fixed: Vec<Light>,
    /// A box holding the moving light in every frame, widened by a margin far above the rounding
    /// of a ray–sphere test; `None` when rays cannot meet the light at all (a delta light).
    swept: Option<(Vec3A, Vec3A)>,
    shadow: ShadowTest<'a>,
    /// The moving light's centre in every frame (by component), radius and radiance, when it
    /// is a sphere: sampled for all frames at once ([`LightSamples::sample_sphere`]).
    sphere: Option<MovingSphere>,
}

/// A sphere light's places over the frames of a sweep.
struct MovingSphere {
    centers: [Vec<f32>; 3],
    radius: f32,
    radiance: Vec3,
}

impl MovingSphere {
    /// The moving light of `frames` (each frame's lights) if it is a sphere in every frame.
    fn new(frames: &[Vec<Light>], moving: usize) -> Option<Self> {
        let mut m = MovingSphere {
            centers: Default::default(),
            radius: 0.0,
            radiance: Vec3::ZERO,
        };
        for fl in frames {
            let Light::Sphere {
                center,
                radius,
                radiance,
            } = fl[moving]
            else {
                return None;
            };
            if !m.centers[0].is_empty() && (radius, radiance) != (m.radius, m.radiance) {
                return None;
            }
            for (c, v) in m.centers.iter_mut().zip(center.to_array()) {
                c.push(v);
            }
            (m.radius, m.radiance) = (radius, radiance);
        }
        Some(m)
    }
}

impl<'a> SweepLights<'a> {
    fn new(scene: &'a Scene, path: &SweepPath, moving: usize, frames: Range<usize>) -> Self {
        let frames: Vec<Vec<Light>> = frames
            .map(|f| path.frame_lights(&scene.lights, moving, f))
            .collect();
        let swept = frames
            .iter()
            .try_fold(None, |acc: Option<(Vec3, Vec3)>, fl| {
                let Light::Sphere { center, radius, .. } = fl[moving] else {
                    return if fl[moving].is_delta() {
                        Some(None)
                    } else {
                        None
                    };
                };
                // Rounding of `intersect_sphere` is ~1e-7 of the coordinates; 1e-3 of them is safe.
                let r = Vec3::splat(radius + 1e-3 * (center.abs().max_element() + radius));
                let (lo, hi) = acc.unwrap_or((center, center));
                Some(Some((lo.min(center - r), hi.max(center + r))))
            });
        let swept = match swept {
            Some(Some((lo, hi))) => Some((lo.into(), hi.into())),
            // Every frame's light is delta: no ray meets it.
            Some(None) => None,
            // An unexpected kind of moving light: a box that every ray "may hit".
            None => Some((Vec3A::NEG_INFINITY, Vec3A::INFINITY)),
        };
        let fixed = scene
            .lights
            .iter()
            .enumerate()
            .filter(|&(i, _)| i != moving)
            .map(|(_, l)| l.clone())
            .collect();
        SweepLights {
            sphere: MovingSphere::new(&frames, moving),
            frames,
            moving,
            fixed,
            swept,
            shadow: ShadowTest::culled(&scene.accel),
        }
    }

    /// Calls `f(k, integrator::nearest_light(frame k's lights, ray, t_max))` for every frame k.
    /// When the ray surely misses the moving light's box, the answer is that of the fixed lights
    /// alone (the moving one would have returned no hit in any frame), found once.
    fn nearest_per_frame(
        &self,
        ray: &Ray,
        t_max: f32,
        mut f: impl FnMut(usize, Option<(usize, f32, Vec3, f32)>),
    ) {
        let misses = self.swept.is_none_or(|(lo, hi)| {
            let inv = Vec3A::ONE / Vec3A::from(ray.d);
            integrator::segment_misses_box(ray.o.into(), inv, f32::INFINITY, lo, hi)
        });
        if misses {
            let hit = integrator::nearest_light(&self.fixed, ray, t_max);
            for k in 0..self.frames.len() {
                f(k, hit);
            }
        } else {
            for (k, lights) in self.frames.iter().enumerate() {
                f(k, integrator::nearest_light(lights, ray, t_max));
            }
        }
    }
}

/// The same frames rendered naively, one whole render per frame (nothing cached): the reference
/// the cache is tested against and timed against.
pub fn render_naive(
    scene: &Scene,
    settings: &RenderSettings,
    path: &SweepPath,
    moving: usize,
    frames: Range<usize>,
    run: &RunOptions,
) -> Result<SweepRender, RenderError> {
    let start = Instant::now();
    let (mut aov, mut out) = (Vec::new(), Vec::new());
    for index in frames {
        let lights = path.frame_lights(&scene.lights, moving, index);
        let img = crate::render::render_with_lights(scene, &lights, settings, run)?.image;
        aov = img.aov;
        out.push(SweepFrame {
            index,
            light_deg: path.light_deg(index),
            beauty: img.beauty,
            std_error: img.std_error,
            nonfinite: img.nonfinite,
        });
    }
    Ok(SweepRender {
        width: scene.camera.width,
        height: scene.camera.height,
        aov,
        frames: out,
        elapsed: start.elapsed(),
    })
}
