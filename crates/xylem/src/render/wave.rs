//! A tile's pixel samples as waves of paths, for scenes whose every material is Lambertian, a
//! mirror or glass (the Cornell boxes; [`enabled`]). A path's state is a small record — a few
//! numbers and one of those small BSDFs — rather than a shading point holding a whole (wood)
//! BSDF, and each stage of a bounce (emission met, light samples, shadow rays, BSDF samples,
//! closest hits two rays at a time, shading points) is one loop over the wave's live paths;
//! paths that end leave the list. The stages run path by path inside the loops (a form with
//! the state in columns for SIMD lanes measured slower: notes/render.md, "Waves of paths").
//!
//! Every path makes the operations of [`integrator::radiance_frames`] on the same values in
//! the same order (the same functions: light sampling, the BSDF, MIS, roulette, ray offsets),
//! and the sums are added in sample order, so a wave renders the same bits as the per-path loop
//! (crates/xylem-cli/tests/simd_levels.rs compares them at every SIMD level).

use super::film::{Aov, FrameSums, PixelSum};
use super::frames::LightFrames;
use super::geometry::{Hit, Ray};
use super::integrator::{self, Columns, RayCount};
use super::sampler::{PathNumbers, PixelKeys};
use super::shading::{offset_length, offset_ray_origin};
use super::shadow::ShadowTest;
use super::Scene;
use crate::bsdf::{Bsdf, BsdfSample, Glass, Lambertian, Mirror};
use crate::material::Material;
use crate::math::Frame;
use glam::{UVec2, Vec2, Vec3};

/// Paths advanced together: enough that each stage's loop runs long, few enough that their
/// state stays in the L1 and L2 caches.
const WAVE: usize = 256;

/// Whether a one-frame render of `scene` with `lights` runs as waves: every material
/// Lambertian, a mirror or glass (each path's vertex then needs only its frame and a small
/// BSDF, [`LaneBsdf`]), and the environment variable `XYLEM_WAVES` not `off` (which keeps the
/// per-path loop, for tests and comparisons: the image is the same bits either way).
pub(super) fn enabled(scene: &Scene, lights: &LightFrames) -> bool {
    lights.len() == 1
        && scene.materials.iter().all(|m| LaneBsdf::of(m).is_some())
        && std::env::var("XYLEM_WAVES").as_deref() != Ok("off")
}

/// The BSDFs of the materials a wave shades: the [`crate::material::SurfaceBsdf`] variants
/// of the same name, whose functions it calls.
#[derive(Clone, Copy, Debug)]
enum LaneBsdf {
    Lambertian(Lambertian),
    Mirror(Mirror),
    Glass(Glass),
}

impl LaneBsdf {
    /// The BSDF of `material` (`None` for materials the waves leave to the per-path loop)
    /// and the albedo its AOV records, as `Material::shade` gives them.
    #[inline(always)]
    fn of(material: &Material) -> Option<(LaneBsdf, Vec3)> {
        match *material {
            Material::Lambertian { albedo } => {
                Some((LaneBsdf::Lambertian(Lambertian { albedo }), albedo))
            }
            Material::Mirror { reflectance } => {
                Some((LaneBsdf::Mirror(Mirror { reflectance }), reflectance))
            }
            Material::Glass { eta, tint } => Some((LaneBsdf::Glass(Glass { eta, tint }), tint)),
            _ => None,
        }
    }

    /// Whether every lobe is a delta lobe (no next-event estimation).
    #[inline(always)]
    fn is_delta(&self) -> bool {
        !matches!(self, LaneBsdf::Lambertian(_))
    }

    #[inline(always)]
    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
        match self {
            LaneBsdf::Lambertian(b) => b.sample(wo, uc, u),
            LaneBsdf::Mirror(b) => b.sample(wo, uc, u),
            LaneBsdf::Glass(b) => b.sample(wo, uc, u),
        }
    }
}

/// A path's vertex: what [`integrator::shading_point`] keeps of it.
#[derive(Clone, Copy, Debug)]
struct Vertex {
    p: Vec3,
    /// Geometric normal, facing the viewer unless the surface transmits.
    ng: Vec3,
    frame: Frame,
    /// Towards the viewer, local frame.
    wo: Vec3,
    bsdf: LaneBsdf,
    /// The albedo the first hit's AOV records.
    albedo: Vec3,
}

/// One path of the wave.
#[derive(Clone, Copy, Debug)]
struct Lane {
    /// The tile pixel the sample belongs to.
    pixel: u32,
    numbers: PathNumbers,
    beta: Vec3,
    eta_scale: f32,
    prev_pdf: f32,
    specular: bool,
    ray: Ray,
    t_hit: f32,
    depth: u32,
    /// The vertex the ray reached (none after a miss or the last bounce).
    vertex: Option<Vertex>,
    radiance: Vec3,
    cost: RayCount,
}

/// Scratch of [`tile_waves`], reused from wave to wave.
#[derive(Default)]
pub(super) struct WaveScratch {
    lanes: Vec<Lane>,
    aov: Vec<Aov>,
    active: Vec<u32>,
    next: Vec<u32>,
    hits: Vec<Option<Hit>>,
    /// Per active lane and light: the unoccluded term and its shadow ray (`None`: no term).
    terms: Vec<Option<(Vec3, Ray, f32)>>,
    radiance: Columns,
}

/// The samples `samples` (tile pixel index, pixel, sample number, in the order their sums are
/// added) of a one-frame render whose waves are [`enabled`], as waves of [`WAVE`] paths;
/// adds each sample's radiance and AOVs to `sums` and `aov_sums` and its cost to `work` and
/// `rays`, as the per-path loop of `tile_frames` does.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn tile_waves(
    scene: &Scene,
    lights: &LightFrames,
    shadow: &ShadowTest,
    (seed, max_depth): (u64, u32),
    samples: &[(u32, UVec2, u32)],
    scratch: &mut WaveScratch,
    (sums, aov_sums, work): (&mut FrameSums, &mut [PixelSum], &mut [u64]),
    rays: &mut RayCount,
) {
    let camera = scene.camera.rays();
    let eps = offset_length(scene.accel.scale());
    let mut memo = FrameMemo::default();
    // A pixel's samples come one after the other: their keys are worked out once.
    let mut keys = PixelKeys::new(seed, 0, 0);
    let lights_all = lights.first();
    for chunk in samples.chunks(WAVE) {
        let WaveScratch {
            lanes,
            aov,
            active,
            next,
            hits,
            terms,
            radiance,
        } = scratch;
        // Camera rays and their closest hits, as `primary_sample_into`.
        lanes.clear();
        aov.clear();
        for &(i, pixel, s) in chunk {
            let index = integrator::pixel_index(scene, pixel);
            if !keys.cover(index, s) {
                keys = PixelKeys::new(seed, index, s);
            }
            lanes.push(Lane {
                pixel: i,
                numbers: keys.path(s),
                beta: Vec3::ONE,
                eta_scale: 1.0,
                prev_pdf: 0.0,
                specular: true,
                ray: integrator::film_ray(scene, &camera, pixel, keys.film(s)),
                t_hit: f32::INFINITY,
                depth: 0,
                vertex: None,
                radiance: Vec3::ZERO,
                cost: RayCount {
                    rays: 1,
                    shading: 0,
                },
            });
            aov.push(Aov::default());
        }
        hits.clear();
        for pair in lanes.chunks(2) {
            match pair {
                [a, b] => hits.extend(scene.accel.intersect_pair([&a.ray, &b.ray], f32::INFINITY)),
                _ => hits.push(scene.accel.intersect(&pair[0].ray, f32::INFINITY)),
            }
        }
        for ((lane, hit), aov) in lanes.iter_mut().zip(hits.iter()).zip(aov.iter_mut()) {
            let Some(hit) = hit else { continue };
            lane.t_hit = hit.t;
            let v = vertex(scene, &lane.ray, hit, &mut memo);
            *aov = Aov {
                albedo: v.albedo,
                normal: v.frame.n,
                depth: hit.t,
                coverage: 1.0,
                ..Aov::default()
            };
            lane.vertex = Some(v);
            lane.cost.shading += 1;
        }
        active.clear();
        active.extend(0..lanes.len() as u32);
        while !active.is_empty() {
            // Emission the rays meet before their hits (a path ends where it meets a light),
            // and the paths that end at their vertex.
            next.clear();
            for &l in active.iter() {
                let lane = &mut lanes[l as usize];
                let met = add_emission(lights_all, lane);
                if !met && lane.vertex.is_some() && lane.depth < max_depth {
                    next.push(l);
                }
            }
            std::mem::swap(active, next);
            // Next-event estimation: each light's sample and unoccluded term, then the shadow
            // rays, then the sums in the lights' order.
            terms.clear();
            for &l in active.iter() {
                let lane = &mut lanes[l as usize];
                let v = lane.vertex.as_ref().expect("active lanes have a vertex");
                // Delta BSDFs take no light samples (`radiance_frames`): no terms.
                let LaneBsdf::Lambertian(lambertian) = v.bsdf else {
                    terms.extend(lights_all.iter().map(|_| None));
                    continue;
                };
                for (j, light) in lights_all.iter().enumerate() {
                    let u = Vec2::from(lane.numbers.light_split(lane.depth, j, 0, 1));
                    let eval = |wi, with_pdf| lambertian.eval_pdf(v.wo, wi, with_pdf);
                    terms.push(light.sample(v.p, u).and_then(|ls| {
                        integrator::unshadowed_term(&ls, v.frame, (v.p, v.ng, eps), eval)
                    }));
                }
            }
            for (term, ray, t_max) in terms.iter_mut().flatten() {
                if !shadow.unoccluded(ray, *t_max) {
                    *term = Vec3::ZERO;
                }
            }
            let n_lights = lights_all.len();
            for (k, &l) in active.iter().enumerate() {
                let lane = &mut lanes[l as usize];
                if lane.vertex.is_some_and(|v| v.bsdf.is_delta()) {
                    continue;
                }
                let mut nee = Vec3::ZERO;
                for t in &terms[k * n_lights..(k + 1) * n_lights] {
                    nee += match t {
                        Some((term, _, _)) => {
                            lane.cost.rays += 1;
                            *term
                        }
                        None => Vec3::ZERO,
                    };
                }
                // Channel by channel, as `add_next_event` adds them.
                lane.radiance = Vec3::from_array(std::array::from_fn(|c| {
                    lane.radiance[c] + lane.beta[c] * nee[c]
                }));
            }
            // The BSDF samples and roulette; the paths that go on trace their rays.
            next.clear();
            for &l in active.iter() {
                let lane = &mut lanes[l as usize];
                let last = lane.depth + 1 >= max_depth;
                if last && !lights.hittable() {
                    continue;
                }
                let u = lane.numbers.bounce(lane.depth);
                lane.depth += 1;
                if scatter(lane, u, eps) {
                    lane.cost.rays += 1;
                    next.push(l);
                }
            }
            std::mem::swap(active, next);
            hits.clear();
            for pair in active.chunks(2) {
                let ray = |i: usize| &lanes[pair[i] as usize].ray;
                match pair.len() {
                    2 => hits.extend(scene.accel.intersect_pair([ray(0), ray(1)], f32::INFINITY)),
                    _ => hits.push(scene.accel.intersect(ray(0), f32::INFINITY)),
                }
            }
            for (&l, hit) in active.iter().zip(hits.iter()) {
                let lane = &mut lanes[l as usize];
                lane.t_hit = hit.map_or(f32::INFINITY, |h| h.t);
                let last = lane.depth >= max_depth;
                lane.vertex = match hit {
                    Some(h) if !last => {
                        lane.cost.shading += 1;
                        Some(vertex(scene, &lane.ray, h, &mut memo))
                    }
                    _ => None,
                };
            }
        }
        // The sums in sample order, as the per-path loop adds them.
        for c in radiance.iter_mut() {
            c.resize(1, 0.0);
        }
        for (lane, aov) in lanes.iter().zip(aov.iter()) {
            let i = lane.pixel as usize;
            [radiance[0][0], radiance[1][0], radiance[2][0]] = lane.radiance.to_array();
            sums.add(i, radiance);
            aov_sums[i].add(Vec3::ZERO, aov);
            work[i] += lane.cost.work();
            rays.rays += lane.cost.rays;
            rays.shading += lane.cost.shading;
        }
    }
}

/// [`Frame::from_normal_tangent`] of the last normal and tangent it was given, kept: paths
/// one after the other in a wave often hit the same flat triangle (a pixel's camera rays
/// nearly always), whose normal and tangent are the same numbers, so the frame is too.
#[derive(Default)]
struct FrameMemo {
    last: Option<(Vec3, Vec3, Frame)>,
}

impl FrameMemo {
    #[inline(always)]
    fn frame(&mut self, n: Vec3, tangent: Vec3) -> Frame {
        let same =
            |a: Vec3, b: Vec3| a.to_array().map(f32::to_bits) == b.to_array().map(f32::to_bits);
        match self.last {
            Some((ln, lt, frame)) if same(ln, n) && same(lt, tangent) => frame,
            _ => {
                let frame = Frame::from_normal_tangent(n, tangent);
                self.last = Some((n, tangent, frame));
                frame
            }
        }
    }
}

/// The vertex at `hit` along `ray`: [`integrator::shading_point`]'s values.
#[inline(always)]
fn vertex(scene: &Scene, ray: &Ray, hit: &Hit, memo: &mut FrameMemo) -> Vertex {
    let s = scene.accel.surface(ray, hit);
    let inst = &scene.accel.instances[s.instance as usize];
    let Some((bsdf, albedo)) = LaneBsdf::of(&scene.materials[inst.material as usize]) else {
        unreachable!("waves are enabled for their materials only")
    };
    let wo_world = -ray.d;
    let transmissive = matches!(bsdf, LaneBsdf::Glass(_));
    let (ng, frame) = integrator::facing(s.ng, memo.frame(s.ns, s.tangent), wo_world, transmissive);
    Vertex {
        p: s.p,
        ng,
        frame,
        wo: frame.to_local(wo_world),
        bsdf,
        albedo,
    }
}

/// [`integrator::PathState::add_emission`] for one frame: the light the ray meets before its
/// hit, weighted ([`integrator::emission_met`]; one next-event sample a light at these
/// vertices); true where the path met one (and ends).
#[inline(always)]
fn add_emission(lights: &[super::light::Light], lane: &mut Lane) -> bool {
    let Some((_, hit)) = super::light::nearest_light(lights, &lane.ray, lane.t_hit) else {
        return false;
    };
    let mis = (lane.specular, lane.prev_pdf, 1);
    let Some(add) = integrator::emission_met(&hit, lane.t_hit, lane.beta, mis) else {
        return false;
    };
    lane.radiance += add;
    true
}

/// [`integrator::PathState::scatter`] on a Lambertian vertex.
#[inline(always)]
fn scatter(lane: &mut Lane, [u0, u1, uc, u_roulette]: [f32; 4], eps: f32) -> bool {
    let v = lane
        .vertex
        .as_ref()
        .expect("scattering lanes have a vertex");
    let Some(bs) = v.bsdf.sample(v.wo, uc, Vec2::new(u0, u1)) else {
        return false;
    };
    if !(bs.pdf > 0.0) {
        return false;
    }
    lane.specular = bs.is_delta;
    lane.prev_pdf = bs.pdf;
    let depth = lane.depth;
    if !integrator::carry_on(&mut lane.beta, &mut lane.eta_scale, &bs, depth, u_roulette) {
        return false;
    }
    let d = v.frame.to_world(bs.wi);
    lane.ray = Ray {
        o: offset_ray_origin(v.p, v.ng, eps, d),
        d,
    };
    true
}
