//! The integrator: unidirectional path tracing with next-event estimation, multiple importance
//! sampling (power heuristic, Veach 1997 §9.2) and Russian roulette, for every frame of a
//! [`LightFrames`] at once; direct lighting is its one-bounce case.
//!
//! Per pixel sample the work is split in two:
//! - [`primary_sample`]: everything that does not depend on the lights — the camera ray, the first
//!   hit, its shading frame, `wo` and the evaluated material (a small `Copy` [`ShadingPoint`]);
//! - `radiance_frames`: the path from there, its light-dependent terms per frame.
//!
//! Each part draws its numbers from (seed, pixel, sample) alone — the camera from a scrambled
//! Sobol point (`sampler::pixel_sample`), the path from one per role (`sampler::PathNumbers`) —
//! so a frame rendered with others equals the frame rendered alone bit for bit.

use super::camera::CameraRays;
use super::film::Aov;
use super::frames::LightFrames;
use super::geometry::{Hit, Ray};
use super::light::{Light, LightHit, LightSample, LightSamples, LightU};
use super::sampler::{pixel_sample, PathNumbers};
use super::shading::{offset_length, offset_origin, offset_ray_origin, ShadingPoint};
use super::shadow::{shadow_t_max, Segments, ShadowTest};
use super::Scene;
use crate::bsdf::{Bsdf, BsdfSample};
use crate::material::{MaterialHit, SurfaceAtWo, SurfaceBsdf};
use crate::math::{is_zero, power_heuristic, Frame};
use glam::{Mat3, UVec2, Vec2, Vec3};

/// Which light transport to simulate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Integrator {
    /// Emission plus single-bounce direct lighting (NEE + one MIS'd BSDF sample): the path
    /// tracer with one bounce.
    Direct,
    /// Path tracing up to `max_depth` bounces, Russian roulette from bounce 3.
    Path {
        /// Bounces after the camera ray's first hit at most (1 = direct lighting).
        max_depth: u32,
    },
}

impl Integrator {
    /// The most bounces a path makes (direct lighting: 1).
    pub fn max_depth(&self) -> u32 {
        match *self {
            Integrator::Direct => 1,
            Integrator::Path { max_depth } => max_depth,
        }
    }
}

/// The scene file's names (`direct`, `path (max_depth 8)`), not the Rust variants.
impl std::fmt::Display for Integrator {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Integrator::Direct => f.write_str("direct"),
            Integrator::Path { max_depth } => write!(f, "path (max_depth {max_depth})"),
        }
    }
}

/// The light-independent part of one pixel sample.
#[derive(Clone, Copy, Debug)]
pub struct PrimarySample {
    /// The camera ray (world, unit direction).
    pub ray: Ray,
    /// Distance to the first surface (infinite on a miss).
    pub t_hit: f32,
    /// The first hit, ready to be lit; `None` on a miss.
    pub point: Option<ShadingPoint>,
    /// The first-hit AOVs of this sample (coverage 0 on a miss).
    pub aov: Aov,
    /// Footprint of the hits after a bounce, (per unit depth along the view axis, constant) mm:
    /// the camera's ([`CameraRays::depth_footprint`]) times this sample's `footprint_scale`.
    pub bounce_footprint: (f32, f32),
}

/// Counts of rays traced, for the rays/s report, and of the shading work done
/// ([`crate::material::Material::shading_cost`] summed), for adaptive sampling's costs.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct RayCount {
    pub rays: u64,
    pub shading: u64,
}

impl RayCount {
    /// Rays plus shading, in rays: what the samples so far cost.
    pub(crate) fn work(&self) -> u64 {
        self.rays + self.shading
    }
}

/// Builds the shading point of a hit seen along `ray`. `aov` is given at the camera's first hit,
/// with the pixel footprint at the hit (times `footprint_scale`, [`footprint_scale`]), which
/// band-limits the textures. Written into `out`, where the caller keeps it: a shading point holds
/// a whole BSDF (484 bytes), and returning it by value cost a copy of all of them per vertex
/// (`memcpy`, 3–5 % of a Cornell-box render in `perf`); the BSDF itself is copied by its variant
/// ([`SurfaceBsdf::copied`]). Returns the material's shading cost
/// ([`crate::material::Material::shading_cost`]).
#[inline(always)]
pub(crate) fn shading_point(
    scene: &Scene,
    ray: &Ray,
    hit: &Hit,
    footprint: Footprint,
    out: &mut Option<ShadingPoint>,
) -> u32 {
    let s = scene.accel.surface(ray, hit);
    let inst = &scene.accel.instances[s.instance as usize];
    let material = &scene.materials[inst.material as usize];
    let mh = MaterialHit {
        p_object: s.p_object,
        p_world: s.p,
        n_object: s.n_object,
        ng: s.ng,
        ns: s.ns,
        tangent: s.tangent,
        object_to_world: Mat3::from(inst.transform.to_world.matrix3),
        normal_to_world: inst.transform.normal_to_world,
        placement: inst.placement,
        // The camera's first hit has its pixel's footprint, the ellipse it makes on the surface,
        // stretched by 1/cos, taken at its geometric mean; a hit after a bounce the camera's at
        // its depth (a lower bound, `depth_footprint`).
        footprint: match &footprint {
            Footprint::Pixel(_, pixel) => *pixel / s.ng.dot(ray.d).abs().max(0.05).sqrt(),
            Footprint::AtDepth((per_depth, constant)) => {
                let cam = &scene.camera;
                constant + per_depth * (s.p - cam.eye).dot(cam.frame.n).abs()
            }
        },
    };
    let shading = material.shade(&mh);
    let wo_world = -ray.d;
    let (ng, frame) = facing(
        s.ng,
        shading.frame,
        wo_world,
        shading.bsdf.is_transmissive(),
    );
    if let Footprint::Pixel(a, _) = footprint {
        *a = Aov {
            albedo: shading.aov.albedo,
            normal: frame.n,
            depth: hit.t,
            fiber: shading.aov.fiber,
            ray_mask: shading.aov.ray_mask,
            growth_time: shading.aov.growth_time,
            coverage: 1.0,
        };
    }
    // Field by field into the slot (a shading point built aside and moved in was a `memmove`
    // of all its bytes per vertex, 2.5 % of a Cornell-box render); an empty slot first gets a
    // placeholder (once per path at most).
    let sp = out.get_or_insert_with(ShadingPoint::placeholder);
    sp.p = s.p;
    sp.ng = ng;
    sp.frame = frame;
    sp.wo = frame.to_local(wo_world);
    shading.bsdf.copy_to(&mut sp.bsdf);
    sp.eps = offset_length(scene.accel.scale());
    material.shading_cost()
}

/// The geometric normal `ng` and shading frame of a hit seen from `wo_world`, turned to face
/// the viewer unless the surface transmits: opaque surfaces are two-sided.
#[inline(always)]
pub(crate) fn facing(ng: Vec3, frame: Frame, wo_world: Vec3, transmissive: bool) -> (Vec3, Frame) {
    if !transmissive && ng.dot(wo_world) < 0.0 {
        let flipped = Frame {
            s: frame.s,
            t: -frame.t,
            n: -frame.n,
        };
        (-ng, flipped)
    } else {
        (ng, frame)
    }
}

/// The share of the pixel footprint each of `spp` camera samples band-limits its first hit by:
/// max(1/8, 1/√spp), as pbrt-v4 scales its camera ray differentials (Pharr, Jakob, Humphreys,
/// "Physically Based Rendering", 4th ed., §5.1.5 and `RayIntegrator::EvaluatePixelSample`):
/// the samples of a pixel already average over it, so each one only needs to be band-limited to
/// the spacing between samples, ≈ 1/√spp pixel; filtering each by the whole pixel would blur the
/// converged image by a pixel-wide box on top of the reconstruction filter (on sweep_board at
/// 16 spp: relative MSE against the 256-spp point-sampled reference 3.86·10⁻³ with the whole
/// pixel, 3.60·10⁻³ unfiltered; notes/sweep.md "Footprint").
pub fn footprint_scale(spp: u32) -> f32 {
    (1.0 / (spp.max(1) as f32).sqrt()).max(0.125)
}

/// The footprint band-limiting a hit's textures ([`shading_point`]).
pub(crate) enum Footprint<'a> {
    /// The camera's first hit: its AOVs are written here, and its pixel's footprint (mm, times
    /// the sample's `footprint_scale`) along the ray.
    Pixel(&'a mut Aov, f32),
    /// A hit after a bounce: [`PrimarySample::bounce_footprint`] at the hit's depth.
    AtDepth((f32, f32)),
}

/// The light-independent part of sample `sample` of pixel `pixel`; first hits are band-limited
/// by `footprint_scale` of the pixel footprint ([`footprint_scale`]).
pub fn primary_sample(
    scene: &Scene,
    pixel: UVec2,
    sample: u32,
    seed: u64,
    footprint_scale: f32,
) -> PrimarySample {
    let mut out = PrimarySample::empty();
    primary_sample_into(
        scene,
        &scene.camera.rays(),
        pixel,
        sample,
        seed,
        footprint_scale,
        &mut out,
    );
    out
}

impl PrimarySample {
    /// A placeholder to write samples into ([`primary_sample_into`]): no ray, no hit.
    pub(crate) fn empty() -> PrimarySample {
        PrimarySample {
            ray: Ray {
                o: Vec3::ZERO,
                d: Vec3::ZERO,
            },
            t_hit: f32::INFINITY,
            point: None,
            aov: Aov::default(),
            bounce_footprint: (0.0, 0.0),
        }
    }
}

/// [`primary_sample`] into `out`, with the camera's per-ray constants worked out by the caller
/// (`camera` = `scene.camera.rays()`, once per tile); the same bits. Written in place, since a
/// sample holds a whole BSDF ([`shading_point`]). Returns the first hit's shading cost (0 on a
/// miss).
#[inline(always)]
pub(crate) fn primary_sample_into(
    scene: &Scene,
    camera: &CameraRays,
    pixel: UVec2,
    sample: u32,
    seed: u64,
    footprint_scale: f32,
    out: &mut PrimarySample,
) -> u32 {
    let ray = camera_ray(scene, camera, pixel, sample, seed);
    out.ray = ray;
    out.aov = Aov::default();
    let (per_depth, constant) = camera.depth_footprint();
    out.bounce_footprint = (footprint_scale * per_depth, footprint_scale * constant);
    match scene.accel.intersect(&ray, f32::INFINITY) {
        Some(hit) => {
            let pixel = footprint_scale * camera.pixel_footprint(&ray, hit.t);
            out.t_hit = hit.t;
            shading_point(
                scene,
                &ray,
                &hit,
                Footprint::Pixel(&mut out.aov, pixel),
                &mut out.point,
            )
        }
        None => {
            out.t_hit = f32::INFINITY;
            out.point = None;
            0
        }
    }
}

/// The camera ray of sample `sample` of pixel `pixel`: its film point drawn from the filter and
/// its lens point, both from the pixel's Sobol point ([`pixel_sample`]).
#[inline(always)]
pub(crate) fn camera_ray(
    scene: &Scene,
    camera: &CameraRays,
    pixel: UVec2,
    sample: u32,
    seed: u64,
) -> Ray {
    film_ray(
        scene,
        camera,
        pixel,
        pixel_sample(seed, pixel_index(scene, pixel), sample),
    )
}

/// [`camera_ray`] of the pixel's Sobol point `u` (film, then lens).
#[inline(always)]
pub(crate) fn film_ray(scene: &Scene, camera: &CameraRays, pixel: UVec2, u: [f32; 4]) -> Ray {
    let film = pixel.as_vec2() + Vec2::splat(0.5) + scene.filter.sample(Vec2::new(u[0], u[1]));
    camera.ray(film, Vec2::new(u[2], u[3]))
}

/// The path numbers of a sample ([`PathNumbers`]).
pub(crate) fn path_numbers(scene: &Scene, pixel: UVec2, sample: u32, seed: u64) -> PathNumbers {
    PathNumbers::new(seed, pixel_index(scene, pixel), sample)
}

/// The index of `pixel` that keys its numbers ([`pixel_sample`], [`PathNumbers`]): row-major
/// over the whole image.
#[inline(always)]
pub(crate) fn pixel_index(scene: &Scene, pixel: UVec2) -> u64 {
    pixel.y as u64 * scene.camera.width as u64 + pixel.x as u64
}

/// The term of one light sample `ls` in next-event estimation: f · Li · |cos θi| · w / pdf when
/// the light is unoccluded, w the power heuristic against BSDF sampling (1 for delta lights);
/// zero when the sample failed, the BSDF vanishes or the light is occluded.
#[inline(always)]
pub(crate) fn light_term(
    shadow: &ShadowTest,
    sp: &ShadingPoint,
    bsdf: &SurfaceAtWo,
    ls: Option<LightSample>,
    rays: &mut RayCount,
) -> Vec3 {
    let Some(ls) = ls else {
        return Vec3::ZERO;
    };
    let eval = |wi: Vec3, with_pdf| bsdf.eval_pdf(wi, with_pdf);
    let Some((term, ray, t_max)) = unshadowed_term(&ls, sp.frame, (sp.p, sp.ng, sp.eps), eval)
    else {
        return Vec3::ZERO;
    };
    rays.rays += 1;
    if !shadow.unoccluded(&ray, t_max) {
        return Vec3::ZERO;
    }
    term
}

/// [`light_term`] before its shadow test: the MIS-weighted term of light sample `ls` at the
/// point `p` with geometric normal `ng` and shading `frame` (rays leave it offset by `eps`),
/// `eval` giving the BSDF's value and density at a local direction, and the shadow segment
/// (ray and its `t_max`) the term needs; `None` where there is no term (the sample failed or
/// the BSDF vanishes), so no shadow ray either.
#[inline(always)]
pub(crate) fn unshadowed_term(
    ls: &LightSample,
    frame: Frame,
    (p, ng, eps): (Vec3, Vec3, f32),
    eval: impl FnOnce(Vec3, bool) -> (Vec3, f32),
) -> Option<(Vec3, Ray, f32)> {
    if !(ls.pdf > 0.0) || ls.li == Vec3::ZERO {
        return None;
    }
    let wi = frame.to_local(ls.wi);
    let (f, bsdf_pdf) = eval(wi, !ls.is_delta);
    if f == Vec3::ZERO {
        return None;
    }
    let ray = Ray {
        o: offset_ray_origin(p, ng, eps, ls.wi),
        d: ls.wi,
    };
    let term = weighted_term(f, ls.li, wi.z, ls.pdf, bsdf_pdf, ls.is_delta);
    Some((term, ray, shadow_t_max(ls.dist)))
}

/// How many next-event samples light `light` takes at vertex `depth`, `glossy` saying whether
/// the vertex is glossy wood ([`glossy_wood`]): its [`Light::nee_samples`] at the camera's first
/// hit on glossy wood, whose sharp finish reflection and fibre highlight one light sample
/// resolves poorly (parquet floor, roughness 0.08, and teapot, 0.05: 2.3–2.7× less
/// high-frequency noise, notes/render.md), and one elsewhere. At later vertices splitting would
/// cost a path tracer's every bounce (the Cornell box, 8 bounces: +67 % CPU); on Lambertian
/// surfaces (the Cornell box: relative MSE 0.998× for +27 % CPU) and satin wood
/// (cornell_wood_marble, roughness 0.5: 0.989× for +12 %) it bought nothing.
#[inline]
fn splits_at(light: &Light, depth: u32, glossy: bool) -> u32 {
    if depth == 0 && glossy {
        light.nee_samples()
    } else {
        1
    }
}

/// Finish roughness below which wood counts as glossy for [`splits_at`]: between the measured
/// scenes that gained (≤ 0.08) and the one that did not (0.5).
const GLOSSY_ROUGHNESS: f32 = 0.25;

/// Whether `sp` is wood under a glossy finish (roughness below [`GLOSSY_ROUGHNESS`]), where
/// the first hit's rect-light samples are split ([`splits_at`]).
#[inline(always)]
fn glossy_wood(sp: &ShadingPoint) -> bool {
    matches!(&sp.bsdf, SurfaceBsdf::Wood(b) if b.params().roughness < GLOSSY_ROUGHNESS)
}

/// The next-event term of light `light` (index `j` among the lights) at `sp`: the sum of
/// [`light_term`] over its n = [`splits_at`] samples, each sample's density taken × n.
/// That is Veach's multi-sample MIS with n light samples and one BSDF sample (Veach 1997
/// §9.2.4, eq. 9.13 with counts: w_l = (n p_l)² / ((n p_l)² + p_b²), each sample weighted
/// w_l / (n p_l)); [`PathState::add_emission`] weighs a BSDF sample that meets the light with
/// the same n p_l. With n = 1 the plain term.
#[inline(always)]
fn split_light_term(
    shadow: &ShadowTest,
    sp: &ShadingPoint,
    bsdf: &SurfaceAtWo,
    light: &Light,
    (numbers, depth, j, glossy): (&PathNumbers, u32, usize, bool),
    rays: &mut RayCount,
) -> Vec3 {
    let n = splits_at(light, depth, glossy);
    let sample = |k| split_sample(light, sp.p, numbers, (depth, j, k, n));
    let mut sum = light_term(shadow, sp, bsdf, sample(0), rays);
    for k in 1..n {
        sum += light_term(shadow, sp, bsdf, sample(k), rays);
    }
    sum
}

/// Sample `k` of the `n` of light `light` (index `j`) at `p`, its density taken × n
/// ([`split_light_term`]). A function rather than a closure there so that it can be
/// `#[inline(always)]`: as a closure LLVM kept it out of line, compiled for the baseline rather
/// than the render tile's SIMD level (7 % of a Cornell-box render).
#[inline(always)]
fn split_sample(
    light: &Light,
    p: Vec3,
    numbers: &PathNumbers,
    (depth, j, k, n): (u32, usize, u32, u32),
) -> Option<LightSample> {
    // × n is exact for n = 1, and `light_split` with n = 1 is `light`: one sample unchanged.
    let u = Vec2::from(numbers.light_split(depth, j, k, n));
    light.sample(p, u).map(|mut ls| {
        ls.pdf *= n as f32;
        ls
    })
}

/// f · Li · |cos θi| · w / pdf of an unoccluded light sample, w the power heuristic (Veach 1997
/// eq. 9.13) of the light's density against the BSDF's (1 for delta lights).
#[inline(always)]
fn weighted_term(f: Vec3, li: Vec3, wi_z: f32, pdf: f32, bsdf_pdf: f32, is_delta: bool) -> Vec3 {
    f * li * mis_scale(wi_z, pdf, bsdf_pdf, is_delta)
}

/// |cos θi| · w / pdf, the factor of f · Li in [`weighted_term`].
#[inline(always)]
fn mis_scale(wi_z: f32, pdf: f32, bsdf_pdf: f32, is_delta: bool) -> f32 {
    let w = if is_delta {
        1.0
    } else {
        power_heuristic(pdf, bsdf_pdf)
    };
    wi_z.abs() * w / pdf
}

/// Per-frame `Vec3`s as three columns (x, y, z or r, g, b: structure of arrays, one lane per
/// frame), so that a loop over the frames runs in SIMD lanes.
pub(crate) type Columns = [Vec<f32>; 3];

/// Each column of `c` resized to `n` (new lanes 0).
fn resize_columns(c: &mut Columns, n: usize) {
    for c in c {
        c.resize(n, 0.0);
    }
}

/// Scratch columns of [`light_terms`], reused from call to call.
#[derive(Clone, Debug, Default)]
pub(crate) struct TermScratch {
    /// The samples' directions in the local shading frame.
    wi: Columns,
    /// The BSDF's values (by channel) and densities at them.
    f: Columns,
    bsdf_pdf: Vec<f32>,
    /// Whether each shadow segment surely misses every object (no BVH query needed).
    culled: Vec<bool>,
    segments: Segments,
    /// Whether each sample's term is nonzero unless its light is occluded (a shadow ray).
    shadowed: Vec<bool>,
}

/// [`light_term`] of every sample of `ls` (one light at many places: a light sweep's frames)
/// where `active[k]`, into the columns `out` at k (others left as they are), stage by stage over
/// all samples in structure-of-arrays columns — local directions, BSDF values and densities,
/// culled shadow segments, then the MIS-weighted terms in one loop — so each stage is a loop in
/// SIMD lanes without dependencies from one sample to the next. The same functions as
/// [`light_term`] on the same values, so the same bits (tested by the sweep's equality test).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(crate) fn light_terms(
    shadow: &ShadowTest,
    sp: &ShadingPoint,
    bsdf: &SurfaceAtWo,
    ls: &LightSamples,
    active: &[bool],
    scratch: &mut TermScratch,
    out: &mut Columns,
    rays: &mut RayCount,
) {
    let n = ls.len();
    let TermScratch {
        wi,
        f,
        bsdf_pdf,
        culled,
        segments,
        shadowed,
    } = scratch;
    resize_columns(wi, n);
    resize_columns(f, n);
    bsdf_pdf.resize(n, 0.0);
    shadowed.resize(n, false);
    let [wx, wy, wz] = &ls.wi;
    let (wx, wy, wz) = (&wx[..n], &wy[..n], &wz[..n]);
    let [lx, ly, lz] = wi;
    let (lx, ly, lz) = (&mut lx[..n], &mut ly[..n], &mut lz[..n]);
    for k in 0..n {
        let l = sp.frame.to_local(Vec3::new(wx[k], wy[k], wz[k]));
        [lx[k], ly[k], lz[k]] = l.to_array();
    }
    let [fr, fg, fb] = f;
    let (fr, fg, fb) = (&mut fr[..n], &mut fg[..n], &mut fb[..n]);
    let bsdf_pdf = &mut bsdf_pdf[..n];
    bsdf.eval_pdf_lanes([lx, ly, lz], !ls.is_delta, [fr, fg, fb], bsdf_pdf);
    shadow.culled_many(sp, ls, segments, culled);
    let (active, pdf, dist, shadowed) = (
        &active[..n],
        &ls.pdf[..n],
        &ls.dist[..n],
        &mut shadowed[..n],
    );
    let [lr, lg, lb] = &ls.li;
    let (lr, lg, lb) = (&lr[..n], &lg[..n], &lb[..n]);
    let [or, og, ob] = out;
    let (or, og, ob) = (&mut or[..n], &mut og[..n], &mut ob[..n]);
    // The unoccluded terms of all samples (a loop in lanes), then the few shadow segments the
    // boxes did not cull traced one by one; inactive samples keep what `out` held.
    for k in 0..n {
        let li = Vec3::new(lr[k], lg[k], lb[k]);
        let keep = active[k] & (pdf[k] > 0.0) & !is_zero(li);
        let f = if keep {
            Vec3::new(fr[k], fg[k], fb[k])
        } else {
            Vec3::ZERO
        };
        let scale = mis_scale(lz[k], pdf[k], bsdf_pdf[k], ls.is_delta);
        // A zero f stays zero whatever the scale (which may be infinite where pdf = 0).
        let lit = !is_zero(f);
        let term = if lit { f * li * scale } else { Vec3::ZERO };
        shadowed[k] = lit;
        let term = if active[k] {
            term
        } else {
            Vec3::new(or[k], og[k], ob[k])
        };
        [or[k], og[k], ob[k]] = term.to_array();
    }
    rays.rays += shadowed.iter().map(|&s| s as u64).sum::<u64>();
    let culled = &culled[..n];
    for k in 0..n {
        if !shadowed[k] | culled[k] {
            continue;
        }
        let d = Vec3::new(wx[k], wy[k], wz[k]);
        if !shadow.accel.unoccluded(
            &Ray {
                o: offset_origin(sp, d),
                d,
            },
            shadow_t_max(dist[k]),
        ) {
            [or[k], og[k], ob[k]] = [0.0; 3];
        }
    }
}

/// Russian roulette's survival probability for a path of throughput `beta` that has crossed
/// refractive boundaries whose η'² multiply to `eta_scale`: min(1, max(β) · η'²). Refraction
/// scales radiance by 1/η'² (Veach 1997 §5.2), a factor a path inside glass undoes when it
/// leaves, so counting it would kill paths whose weight comes back; pbrt-v4 §13.4 (`etaScale`)
/// and Mitsuba 3's path integrator take it out the same way (notes/render.md).
pub(crate) fn survival(beta: Vec3, eta_scale: f32) -> f32 {
    (beta.max_element() * eta_scale).min(1.0)
}

/// A path's throughput `beta` and η'² product `eta_scale` after the BSDF sample `bs` (of
/// positive density) at bounce `depth`: β takes f · |cos θi| / pdf and, from bounce 3, Russian
/// roulette with the number `u_roulette` ([`survival`]). False where the path ends (roulette,
/// or a throughput that is zero or not finite).
#[inline(always)]
pub(crate) fn carry_on(
    beta: &mut Vec3,
    eta_scale: &mut f32,
    bs: &BsdfSample,
    depth: u32,
    u_roulette: f32,
) -> bool {
    *beta *= bs.f * (bs.wi.z.abs() / bs.pdf);
    *eta_scale *= bs.eta * bs.eta;
    if depth >= 3 {
        let q = survival(*beta, *eta_scale);
        if u_roulette >= q {
            return false;
        }
        *beta /= q;
    }
    beta.is_finite() && *beta != Vec3::ZERO
}

/// The light-independent rest of a path's first bounce: the state [`radiance_frames`] reaches
/// after sampling the BSDF at the first vertex and tracing the ray it gives (throughput, MIS
/// state, the ray, what it hit, and the lighting stream after the draws), `None` in a
/// [`FirstBounce`] where the path ended there. Kept with the primary sample, it lets a later
/// pass over other lights skip that sampling and tracing.
#[derive(Clone, Debug)]
pub(crate) struct Continuation {
    path: PathState,
    hit: Option<Hit>,
}

/// A path between two vertices: its throughput β, the product of η'² over its refractions
/// ([`survival`]), the density of the BSDF sample that made its ray and whether that sample
/// was a delta lobe (for the MIS weight of the emission the ray meets), the ray and the
/// distance to what it hit (∞ for nothing).
#[derive(Clone, Copy, Debug)]
struct PathState {
    beta: Vec3,
    eta_scale: f32,
    prev_pdf: f32,
    specular: bool,
    /// Whether the vertex the ray left is glossy wood ([`splits_at`]).
    prev_glossy: bool,
    ray: Ray,
    t_hit: f32,
}

impl PathState {
    /// Continues the path from `sp` by sampling its BSDF with the bounce's numbers
    /// (`PathNumbers::bounce`: direction, lobe, roulette): the throughput takes
    /// f · |cos θi| / pdf and, from bounce 3 (`depth` counts this one), Russian roulette
    /// ([`survival`]); the ray leaves `sp` along the sample. False where the path ends.
    #[inline(always)]
    fn scatter(
        &mut self,
        sp: &ShadingPoint,
        [u0, u1, uc, u_roulette]: [f32; 4],
        depth: u32,
    ) -> bool {
        let Some(bs) = sp.bsdf.sample(sp.wo, uc, Vec2::new(u0, u1)) else {
            return false;
        };
        if !(bs.pdf > 0.0) {
            return false;
        }
        self.specular = bs.is_delta;
        self.prev_pdf = bs.pdf;
        self.prev_glossy = glossy_wood(sp);
        if !carry_on(&mut self.beta, &mut self.eta_scale, &bs, depth, u_roulette) {
            return false;
        }
        let d = sp.frame.to_world(bs.wi);
        self.ray = Ray {
            o: offset_origin(sp, d),
            d,
        };
        true
    }

    /// Adds to `out` the emission the ray meets before its hit — a light in front of the
    /// surface, or the environment — in every live frame, weighted by β and the power heuristic
    /// against light sampling (1 after a delta lobe), and ends those frames' paths.
    #[inline(always)]
    fn add_emission(
        &self,
        lights: &LightFrames,
        depth: u32,
        alive: &mut [bool],
        out: &mut Columns,
    ) {
        lights.nearest_per_frame(&self.ray, self.t_hit, |k, (i, hit)| {
            if !alive[k] {
                return;
            }
            // Against the light's n next-event samples, as `split_light_term` weighs them. The
            // ray left the vertex before this one (depth − 1; the camera ray, depth 0, is
            // `specular`), glossy wood or not (`prev_glossy`).
            let splits = splits_at(
                &lights.first()[i],
                depth.saturating_sub(1),
                self.prev_glossy,
            );
            let mis = (self.specular, self.prev_pdf, splits);
            if let Some(add) = emission_met(&hit, self.t_hit, self.beta, mis) {
                for (c, a) in out.iter_mut().zip(add.to_array()) {
                    c[k] += a;
                }
                alive[k] = false;
            }
        });
    }
}

/// The emission a path of throughput `beta` gains from light hit `hit` on a ray whose closest
/// surface lies at `t_hit` (∞ for none): `None` when the light lies behind that surface, else
/// β · Le weighted by the power heuristic against the light's `splits` next-event samples
/// (Veach 1997 eq. 9.13; 1 after a `specular` BSDF sample), the BSDF having sampled the ray
/// with density `prev_pdf`.
#[inline(always)]
pub(crate) fn emission_met(
    hit: &LightHit,
    t_hit: f32,
    beta: Vec3,
    (specular, prev_pdf, splits): (bool, f32, u32),
) -> Option<Vec3> {
    let in_front = hit.distance < t_hit || !t_hit.is_finite();
    if !in_front {
        return None;
    }
    let w = if specular {
        1.0
    } else {
        power_heuristic(prev_pdf, splits as f32 * hit.pdf)
    };
    Some(beta * hit.radiance * w)
}

/// out += β · nee over the first `n` frames where `alive`, a channel at a time in lanes.
#[inline(always)]
fn add_next_event(out: &mut Columns, nee: &Columns, alive: &[bool], beta: Vec3, n: usize) {
    let alive = &alive[..n];
    for ((o, e), b) in out.iter_mut().zip(nee).zip(beta.to_array()) {
        let (o, e) = (&mut o[..n], &e[..n]);
        for k in 0..n {
            let sum = o[k] + b * e[k];
            o[k] = if alive[k] { sum } else { o[k] };
        }
    }
}

/// One pixel sample kept for later passes: its primary sample and its first bounce's
/// continuation ([`Continuation`]).
#[derive(Clone, Debug)]
pub(crate) struct KeptSample {
    pub(crate) primary: PrimarySample,
    pub(crate) next: Option<Continuation>,
}

/// What [`radiance_frames`] does at the first bounce: trace it, trace it and keep its
/// continuation, or take a kept one.
pub(crate) enum FirstBounce<'a> {
    Trace,
    Keep(&'a mut Option<Continuation>),
    Reuse(&'a Option<Continuation>),
}

/// Scratch of [`radiance_frames`], reused from sample to sample.
#[derive(Clone, Debug, Default)]
pub(crate) struct FramesScratch {
    /// Whether each frame's path still runs (it stops where a ray meets a light).
    alive: Vec<bool>,
    /// Each frame's next-event estimate at the current vertex.
    nee: Columns,
    /// Each light's next-event term; those of the lights that do not move hold for every frame.
    terms: Vec<Vec3>,
    /// The moving light's samples and terms in every frame, and their scratch columns.
    samples: LightSamples,
    moving_terms: Columns,
    /// The moving light's terms of its second and later split samples
    /// ([`Light::nee_samples`]).
    split_terms: Columns,
    term_scratch: TermScratch,
}

/// The radiance of one primary sample in every frame of `lights`, into `out` (one per frame):
/// unidirectional path tracing (pbrt-v4 §13.4 structure) with next-event estimation at every
/// non-delta vertex, the BSDF-sampled continuation MIS-weighted (power heuristic, Veach 1997
/// eq. 9.13) where it meets a light, and Russian roulette from bounce 3 ([`survival`]). Direct
/// lighting is the path of one bounce.
///
/// The frames share everything but the lights, so the path — its rays, hits, BSDF samples and
/// roulette, all drawn from `numbers` by role whatever the lights — is traced once; per frame
/// only the emission a ray meets (which also ends that frame's path) and the next-event terms
/// are worked out: the fixed lights' terms once, the moving light's for all frames at once,
/// frames in SIMD lanes ([`light_terms`]). Each frame sums its terms in the lights' order, so
/// it equals the render of that frame alone bit for bit.
///
/// `first` keeps the first bounce's light-independent part or takes a kept one
/// ([`FirstBounce`]): the same values either way, so the same bits. Keeping traces the bounce
/// even where no frame needs it (every camera ray met a light, or nothing is hittable), since
/// other frames may.
///
/// `ONE` says that `lights` has one frame (a plain render): the frame loops then have the
/// constant length 1, which the compiler folds into straight code (the per-frame columns cost
/// ≈ 9 % of a Cornell-box render's instructions otherwise); the same operations, so the same
/// bits.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(crate) fn radiance_frames<const ONE: bool>(
    scene: &Scene,
    lights: &LightFrames,
    shadow: &ShadowTest,
    ps: &PrimarySample,
    numbers: &PathNumbers,
    max_depth: u32,
    scratch: &mut FramesScratch,
    out: &mut Columns,
    rays: &mut RayCount,
    mut first: FirstBounce,
) {
    debug_assert!(!ONE || lights.len() == 1);
    let n = if ONE { 1 } else { lights.len() };
    resize_columns(out, n);
    for c in out.iter_mut() {
        c.fill(0.0);
    }
    scratch.alive.clear();
    scratch.alive.resize(n, true);
    let mut path = PathState {
        beta: Vec3::ONE,
        eta_scale: 1.0,
        prev_pdf: 0.0,
        specular: true,
        prev_glossy: false,
        ray: ps.ray,
        t_hit: ps.t_hit,
    };
    // The first vertex is read where it lies (`ps.point`), the later ones from `bounce`: a
    // shading point holds a whole BSDF (hundreds of bytes), so it is not copied from one to
    // the other.
    let mut bounce: Option<ShadingPoint> = None;
    let mut at_first = true;
    let mut depth = 0u32;
    let footprint = || Footprint::AtDepth(ps.bounce_footprint);
    loop {
        path.add_emission(lights, depth, &mut scratch.alive, out);
        let vertex = if at_first { &ps.point } else { &bounce };
        let Some(sp) = vertex else { break };
        let keeping = at_first && matches!(first, FirstBounce::Keep(_));
        if depth >= max_depth || (!keeping && !scratch.alive[..n].contains(&true)) {
            break;
        }
        if !sp.bsdf.is_delta() {
            next_event_frames::<ONE>(lights, shadow, sp, numbers, depth, scratch, rays);
            add_next_event(out, &scratch.nee, &scratch.alive, path.beta, n);
        }
        let last = depth + 1 >= max_depth;
        if let (true, FirstBounce::Reuse(kept)) = (at_first, &first) {
            // The continuation this sample's first bounce had when it was kept.
            if last && !lights.hittable() {
                break;
            }
            let Some(c) = kept else { break };
            (path, depth, at_first) = (c.path, 1, false);
            match c.hit {
                Some(h) if !last => {
                    rays.shading +=
                        shading_point(scene, &path.ray, &h, footprint(), &mut bounce) as u64
                }
                _ => bounce = None,
            }
            continue;
        }
        let u = numbers.bounce(depth);
        if last && !lights.hittable() && !keeping {
            // The continuation could only collect emission, and no ray meets a delta light.
            break;
        }
        depth += 1;
        if !path.scatter(sp, u, depth) {
            break;
        }
        rays.rays += 1;
        at_first = false;
        let hit = scene.accel.intersect(&path.ray, f32::INFINITY);
        path.t_hit = hit.map_or(f32::INFINITY, |h| h.t);
        // Kept once, at the first bounce (then the path goes on as a traced one).
        if let FirstBounce::Keep(kept) = std::mem::replace(&mut first, FirstBounce::Trace) {
            *kept = Some(Continuation { path, hit });
            if last && !lights.hittable() {
                break;
            }
        }
        match hit {
            // The last vertex only needs its distance (emission in front of it), not shading.
            Some(h) if !last => {
                rays.shading += shading_point(scene, &path.ray, &h, footprint(), &mut bounce) as u64
            }
            _ => bounce = None,
        }
    }
}

/// Next-event estimation at `sp` in every live frame into `scratch.nee` (by channel; what it
/// holds for frames no longer alive is not read): one sample of every
/// light (its two numbers from `numbers`, whatever the light's place), each weighted against BSDF
/// sampling by the power heuristic (delta lights take weight 1), summed in the lights' order.
/// `ONE`: one frame, as in [`radiance_frames`].
#[inline(always)]
fn next_event_frames<const ONE: bool>(
    lights: &LightFrames,
    shadow: &ShadowTest,
    sp: &ShadingPoint,
    numbers: &PathNumbers,
    depth: u32,
    scratch: &mut FramesScratch,
    rays: &mut RayCount,
) {
    let n = if ONE { 1 } else { lights.len() };
    let FramesScratch {
        alive,
        nee,
        terms,
        samples,
        moving_terms,
        split_terms,
        term_scratch,
    } = scratch;
    let bsdf = sp.bsdf.at_wo(sp.wo);
    let glossy = glossy_wood(sp);
    let moving = lights.moving_index();
    terms.clear();
    for (j, light) in lights.first().iter().enumerate() {
        terms.push(if Some(j) == moving {
            Vec3::ZERO
        } else {
            split_light_term(shadow, sp, &bsdf, light, (numbers, depth, j, glossy), rays)
        });
    }
    resize_columns(nee, n);
    let Some(m) = moving else {
        let sum = terms.iter().fold(Vec3::ZERO, |l, t| l + *t);
        for (c, v) in nee.iter_mut().zip(sum.to_array()) {
            c.fill(v);
        }
        return;
    };
    // The moving light's split samples as `split_light_term` takes them, in every frame:
    // the k-th sample's terms into `split_terms`, added to the first's in the same order.
    let splits = splits_at(&lights.first()[m], depth, glossy);
    resize_columns(moving_terms, n);
    for k in 0..splits {
        let u = LightU::new(Vec2::from(numbers.light_split(depth, m, k, splits)));
        match lights.sphere() {
            Some(s) => samples.sample_sphere(sp.p, &s.centers, s.radius, s.radiance, &u),
            None => samples.sample_each(sp.p, lights.moving_places(m), &u),
        }
        if splits > 1 {
            for pdf in samples.pdf.iter_mut() {
                *pdf *= splits as f32;
            }
        }
        let out = if k == 0 {
            &mut *moving_terms
        } else {
            resize_columns(split_terms, n);
            &mut *split_terms
        };
        light_terms(shadow, sp, &bsdf, samples, alive, term_scratch, out, rays);
        if k > 0 {
            for (t, s) in moving_terms.iter_mut().zip(split_terms.iter()) {
                for (t, s) in t[..n].iter_mut().zip(&s[..n]) {
                    *t += *s;
                }
            }
        }
    }
    // Σ_j terms[j] in the lights' order with the moving light's term at j = m: the sum of the
    // terms before it is the same in every frame, so it is formed once; the same additions in
    // the same order as summing each frame from scratch, hence the same bits.
    // Each channel is summed on its own (as `Vec3` addition does), one light at a time over
    // the frames in lanes. Frames no longer alive get a sum too, which nothing reads.
    let before = terms[..m].iter().fold(Vec3::ZERO, |l, t| l + *t);
    let after = &terms[m + 1..];
    for (c, (e, t)) in nee.iter_mut().zip(moving_terms.iter()).enumerate() {
        let (e, t) = (&mut e[..n], &t[..n]);
        for k in 0..n {
            e[k] = before[c] + t[k];
        }
        for a in after {
            for e in e.iter_mut() {
                *e += a[c];
            }
        }
    }
}
