//! The sphere area light: uniform cone sampling (pbrt-v4 §6.2.4) and the ray–sphere hit.

use super::{LightHit, LightSample};
use crate::math::{Frame, PI};
use crate::render::geometry::Ray;
use glam::Vec3;

/// Sphere emitting `radiance` outwards.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereLight {
    /// Centre (mm).
    pub center: Vec3,
    /// Radius (mm).
    pub radius: f32,
    /// Emitted radiance (W/(sr·mm²)).
    pub radiance: Vec3,
}

impl SphereLight {
    /// Samples the cone the sphere subtends from `p` with numbers `ux` and the azimuth
    /// `(sin φ, cos φ)` (pbrt-v4 §6.2.4; `sample_sphere`).
    #[inline]
    pub fn sample(&self, p: Vec3, ux: f32, azimuth: (f32, f32)) -> Option<LightSample> {
        sample_sphere(p, self.center, self.radius, self.radiance, ux, azimuth)
    }

    /// Where `ray` meets the sphere, with the cone density of [`SphereLight::sample`]; `None`
    /// from inside.
    #[inline]
    pub fn hit(&self, ray: &Ray) -> Option<LightHit> {
        let t = intersect_sphere(ray, self.center, self.radius)?;
        let d2 = (self.center - ray.o).length_squared();
        let r2 = self.radius * self.radius;
        if d2 <= r2 {
            return None;
        }
        Some(LightHit {
            distance: t,
            radiance: self.radiance,
            pdf: 1.0 / (2.0 * PI * one_minus_cos_cone(r2 / d2)),
        })
    }
}

/// Uniform sampling of the cone of directions a sphere (centre at distance d, radius r)
/// subtends from `p` (pbrt-v4 §6.2.4, `Sphere::Sample`): cos θ uniform in [cos θmax, 1] with
/// sin²θmax = r²/d², azimuth given as `(sin φ, cos φ)`, solid-angle density
/// 1 / (2π (1 − cos θmax)). The distance to the sphere along the sampled direction ω is the
/// nearer root of |tω − (c − p)|² = r², i.e. t² − 2t d cos θ + d² − r² = 0:
/// t = d cos θ − √(r² − d² sin²θ) (as pbrt-v4 computes it), no ray–sphere intersection needed.
#[inline]
fn sample_sphere(
    p: Vec3,
    center: Vec3,
    radius: f32,
    radiance: Vec3,
    ux: f32,
    azimuth: (f32, f32),
) -> Option<LightSample> {
    let c = ConeSample::new(center - p, radius * radius, ux, azimuth);
    c.valid.then_some(LightSample {
        wi: Vec3::from_array(c.wi),
        dist: c.dist,
        li: radiance,
        pdf: c.pdf,
        is_delta: false,
    })
}

/// One cone sample of [`sample_sphere`] in plain `f32`s, computed whether or not it is valid, so
/// that a loop of them over many sphere centres ([`LightSamples::sample_sphere`]) vectorises; the
/// scalar sampler calls the same function, so both give the same bits.
#[derive(Clone, Copy, Debug)]
pub(super) struct ConeSample {
    pub(super) wi: [f32; 3],
    pub(super) dist: f32,
    pub(super) pdf: f32,
    /// False when the point lies inside the sphere (then the other fields are meaningless).
    pub(super) valid: bool,
}

/// 1 − cos θ_max of the cone a sphere subtends, from sin²θ_max = r²/d²: written
/// sin²θ / (1 + √(1 − sin²θ)), which equals 1 − √(1 − sin²θ) without its cancellation (in f32,
/// 1 − √(1 − s) is 0 for s < 6e-8, a sphere light of radius ≤ 0.01 mm at 50 mm went black, and
/// 11 % off at 0.1 mm); the same identity behind pbrt-v4's small-angle branch (§6.2.4).
#[inline(always)]
pub(crate) fn one_minus_cos_cone(sin2_max: f32) -> f32 {
    let s = sin2_max.clamp(0.0, 1.0);
    s / (1.0 + (1.0 - s).sqrt())
}

impl ConeSample {
    /// The sample for the centre at `to` (centre − point), squared radius `r2` and numbers
    /// `ux`, `(sin φ, cos φ)` (pbrt-v4 §6.2.4, see [`sample_sphere`]); the frame about the
    /// centre's direction is Duff et al. 2017 ([`Frame::from_normal`], branch-free).
    #[inline(always)]
    pub(super) fn new(to: Vec3, r2: f32, ux: f32, (sin_phi, cos_phi): (f32, f32)) -> Self {
        let d2 = to.length_squared();
        let one_minus_cos_max = one_minus_cos_cone(r2 / d2);
        let d = d2.sqrt();
        let frame = Frame::from_normal(to / d);
        // 1 − cos θ and sin²θ = (1 − cos θ)(1 + cos θ) from 1 − cos θ directly, without the
        // cancellation of 1 − cos²θ near the cone's axis.
        let one_minus_cos_t = ux * one_minus_cos_max;
        let cos_t = 1.0 - one_minus_cos_t;
        let sin2_t = (one_minus_cos_t * (2.0 - one_minus_cos_t)).max(0.0);
        let sin_t = sin2_t.sqrt();
        let wi = frame.to_world(Vec3::new(sin_t * cos_phi, sin_t * sin_phi, cos_t));
        ConeSample {
            wi: wi.to_array(),
            dist: d * cos_t - (r2 - d2 * sin2_t).max(0.0).sqrt(),
            pdf: 1.0 / (2.0 * PI * one_minus_cos_max),
            valid: d2 > r2,
        }
    }
}

/// The discriminant of the ray–sphere quadratic in the numerically stable form of Haines et
/// al. (Ray Tracing Gems ch. 7): r² minus the squared distance of the centre to the ray's line
/// (`oc` = origin − centre, `b` = oc·d).
#[inline(always)]
fn sphere_discriminant(oc: Vec3, b: f32, d: Vec3, radius: f32) -> f32 {
    let perp = oc - d * b;
    radius * radius - perp.length_squared()
}

/// True when the line of `ray` surely misses the sphere (negative discriminant): the first test
/// of [`intersect_sphere`], branch-free so that a loop of it over many spheres vectorises.
#[inline(always)]
pub(crate) fn sphere_line_misses(ray: &Ray, center: Vec3, radius: f32) -> bool {
    let oc = ray.o - center;
    sphere_discriminant(oc, oc.dot(ray.d), ray.d, radius) < 0.0
}

/// Nearest positive distance at which `ray` (unit direction) meets a sphere.
pub(crate) fn intersect_sphere(ray: &Ray, center: Vec3, radius: f32) -> Option<f32> {
    let oc = ray.o - center;
    let b = oc.dot(ray.d);
    // The test of `sphere_line_misses`, on the same values.
    let disc = sphere_discriminant(oc, b, ray.d, radius);
    if disc < 0.0 {
        return None;
    }
    let c = oc.length_squared() - radius * radius;
    let q = -b - b.signum() * disc.sqrt();
    let (t0, t1) = if q != 0.0 { (c / q, q) } else { (-b, -b) };
    let (t0, t1) = (t0.min(t1), t0.max(t1));
    if t0 > 0.0 {
        Some(t0)
    } else if t1 > 0.0 {
        Some(t1)
    } else {
        None
    }
}
