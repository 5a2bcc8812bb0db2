//! Lights: point, spot, distant, rectangular area, sphere, and a constant or lat-long (EXR)
//! environment. Lights are not in the BVH: rays are tested against them analytically, so a
//! light can move (a light sweep) without rebuilding anything, and lights never cast shadows.
//!
//! Units: lengths in mm; `intensity` in W/sr, `radiance` in W/(sr·mm²) and `irradiance` in W/mm²
//! (any consistent unit works; the film records radiance).

mod delta;
mod environment;
mod rect;
mod samples;
mod sphere;

pub use delta::{DistantLight, PointLight, SpotLight};
pub use environment::{EnvMap, Environment};
pub use rect::RectLight;
pub use samples::LightSamples;
pub(crate) use sphere::sphere_line_misses;
pub use sphere::SphereLight;

use super::geometry::Ray;
use crate::math::PI;
use glam::{Vec2, Vec3};

/// Next-event samples of a rect light at the camera's first hit on glossy wood
/// ([`Light::nee_samples`]).
pub const RECT_LIGHT_SAMPLES: u32 = 4;

/// One light of the scene. Each kind is a struct of its own, and every `match` on lights names
/// every kind (no wildcard arm), so a new kind fails to compile wherever it is not handled.
#[derive(Clone, Debug)]
pub enum Light {
    /// Isotropic point light.
    Point(PointLight),
    /// Point light limited to a cone.
    Spot(SpotLight),
    /// Light from one direction.
    Distant(DistantLight),
    /// One-sided parallelogram area light.
    Rect(RectLight),
    /// Sphere area light.
    Sphere(SphereLight),
    /// Light from infinitely far away in every direction.
    Environment(Environment),
}

/// A sample of incident light at a point.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Unit direction towards the light (world).
    pub wi: Vec3,
    /// Distance to the light sample (infinite for distant and environment lights).
    pub dist: f32,
    /// Incident radiance (or, for delta lights, irradiance at normal incidence: I/d², E).
    pub li: Vec3,
    /// Solid-angle density; 1 for delta lights.
    pub pdf: f32,
    /// True for a delta light (point, spot, distant): a BSDF-sampled ray can never hit it, so
    /// the sample takes no MIS weight.
    pub is_delta: bool,
}

impl Light {
    /// True for lights that a BSDF-sampled ray can never hit (point, spot, distant).
    pub fn is_delta(&self) -> bool {
        match self {
            Light::Point(_) | Light::Spot(_) | Light::Distant(_) => true,
            Light::Rect(_) | Light::Sphere(_) | Light::Environment(_) => false,
        }
    }

    /// How many samples next-event estimation takes of this light at the camera's first hit
    /// on glossy wood (one elsewhere, `integrator::splits_at`): 4 for a rect light, 1 for every other
    /// kind. Splitting a light's samples (pbrt-v3's per-light
    /// `nSamples` in `UniformSampleAllLights`, Pharr, Jakob, Humphreys 2016 §14.3.1; Mitsuba 3's
    /// `emitter_samples`) is unbiased. A large area light near glossy wood dominated the
    /// parquet floor's noise (a point light in its place had a tenth of the high-frequency
    /// energy), and the shading point's wood, not the light sample, is what costs: 4 samples
    /// of its window took the parquet's energy 2.3× lower for 25 % more CPU time
    /// (notes/render.md, "Light-sample splitting").
    #[inline]
    pub fn nee_samples(&self) -> u32 {
        match self {
            Light::Rect(_) => RECT_LIGHT_SAMPLES,
            Light::Point(_)
            | Light::Spot(_)
            | Light::Distant(_)
            | Light::Sphere(_)
            | Light::Environment(_) => 1,
        }
    }

    /// Samples incident light at `p` with uniform numbers `u`.
    ///
    /// Same as `sample_at(p, &LightU::new(u))`; a caller that samples many placements of one
    /// light with the same numbers (a light sweep) makes the [`LightU`] once.
    #[inline(always)]
    pub fn sample(&self, p: Vec3, u: Vec2) -> Option<LightSample> {
        match self {
            Light::Point(l) => l.sample(p),
            Light::Spot(l) => l.sample(p),
            Light::Distant(l) => Some(l.sample()),
            Light::Rect(l) => l.sample(p, u),
            Light::Sphere(l) => l.sample(p, u.x, azimuth(u.y)),
            Light::Environment(env) => env.sample(u),
        }
    }

    /// [`Light::sample`] with the uniform numbers prepared: for a sphere light the azimuth's sine
    /// and cosine come from `u` (identical results; the trigonometry is done once per `u`).
    #[inline(always)]
    pub fn sample_at(&self, p: Vec3, u: &LightU) -> Option<LightSample> {
        match self {
            Light::Sphere(l) => l.sample(p, u.u.x, u.azimuth),
            Light::Point(_)
            | Light::Spot(_)
            | Light::Distant(_)
            | Light::Rect(_)
            | Light::Environment(_) => self.sample(p, u.u),
        }
    }

    /// Where a ray first meets this light, what it emits towards the ray's origin, and the
    /// solid-angle density `sample` would have chosen that direction with from `ray.o`.
    #[inline(always)]
    pub fn hit(&self, ray: &Ray) -> Option<LightHit> {
        match self {
            Light::Rect(l) => l.hit(ray),
            Light::Sphere(l) => l.hit(ray),
            Light::Environment(env) => Some(env.hit(ray)),
            // Delta lights: no ray meets them.
            Light::Point(_) | Light::Spot(_) | Light::Distant(_) => None,
        }
    }
}

/// Where a ray meets a light ([`Light::hit`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightHit {
    /// Distance along the ray (∞ for an environment light).
    pub distance: f32,
    /// Radiance the light emits towards the ray's origin.
    pub radiance: Vec3,
    /// Solid-angle density with which `Light::sample` from the ray's origin picks this direction.
    pub pdf: f32,
}

/// A light sample's two uniform numbers with what [`Light::sample`] derives from them alone: the
/// (sin, cos) of the azimuth φ = 2π u.y of a sphere light's cone sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightU {
    /// The two uniform numbers in [0, 1)².
    pub u: Vec2,
    azimuth: (f32, f32),
}

impl LightU {
    /// The light-sample numbers `u` with the azimuth they give worked out.
    pub fn new(u: Vec2) -> Self {
        LightU {
            u,
            azimuth: azimuth(u.y),
        }
    }
}

/// (sin φ, cos φ) of the azimuth φ = 2π·v.
#[inline]
fn azimuth(v: f32) -> (f32, f32) {
    (2.0 * PI * v).sin_cos()
}

/// The nearest light a ray meets before `t_max`: its index in `lights` and where it is met.
#[inline(always)]
pub fn nearest_light(lights: &[Light], ray: &Ray, t_max: f32) -> Option<(usize, LightHit)> {
    let mut best: Option<(usize, LightHit)> = None;
    for (i, l) in lights.iter().enumerate() {
        if let Some(hit) = l.hit(ray) {
            let t = hit.distance;
            let limit = best.map_or(t_max, |b| b.1.distance);
            // Environment lights (t = ∞) count only when nothing else was hit.
            if t < limit || (t.is_infinite() && t_max.is_infinite() && best.is_none()) {
                best = Some((i, hit));
            }
        }
    }
    best
}

#[cfg(test)]
mod tests;
