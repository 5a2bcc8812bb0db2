//! Lights: point, spot, distant, rectangular area, sphere, and a constant or lat-long (EXR)
//! environment. Lights are not in the BVH: rays are tested against them analytically, so a
//! light can move (a light sweep) without rebuilding anything, and lights never cast shadows.
//!
//! Units: lengths in mm; `intensity` in W/sr, `radiance` in W/(sr·mm²) and `irradiance` in W/mm²
//! (any consistent unit works; the film records radiance).

use super::geometry::Ray;
use crate::math::{uniform_sphere, Frame, PI, UNIFORM_SPHERE_PDF};
use glam::{Vec2, Vec3};
use std::sync::Arc;

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

/// Isotropic point light at `position` of radiant intensity `intensity` (W/sr, per channel).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLight {
    /// Position (mm).
    pub position: Vec3,
    /// Radiant intensity (W/sr).
    pub intensity: Vec3,
}

/// Point light limited to a cone about `direction` with a smoothstep falloff between
/// `cos_outer` and `cos_inner` (pbrt-v4 §12.2.2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpotLight {
    /// Position (mm).
    pub position: Vec3,
    /// Unit axis of the cone, pointing away from the light.
    pub direction: Vec3,
    /// Radiant intensity on the axis (W/sr).
    pub intensity: Vec3,
    /// Cosine of the half-angle inside which the intensity is full.
    pub cos_inner: f32,
    /// Cosine of the half-angle outside which there is no light.
    pub cos_outer: f32,
}

/// Light from one direction, irradiance `irradiance` on a surface facing it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DistantLight {
    /// Unit direction towards the light.
    pub direction: Vec3,
    /// Irradiance at normal incidence (W/mm²).
    pub irradiance: Vec3,
}

/// One-sided parallelogram `corner + a·edge_u + b·edge_v` (a, b in [0, 1]) emitting `radiance`
/// towards `edge_u × edge_v`. The edges are set once ([`RectLight::new`]), so the quantities
/// sampling and hit tests need from them alone are worked out there, not per ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RectLight {
    /// One corner (mm).
    pub corner: Vec3,
    /// First edge from the corner (mm).
    edge_u: Vec3,
    /// Second edge from the corner (mm).
    edge_v: Vec3,
    /// Emitted radiance (W/(sr·mm²)).
    pub radiance: Vec3,
    /// edge_u × edge_v (its length is the area).
    normal: Vec3,
    /// The area |edge_u × edge_v|.
    area: f32,
    /// Gram matrix of the edges (u·u, u·v, v·v) and its determinant, for the hit's (a, b).
    gram: [f32; 4],
}

impl RectLight {
    /// The parallelogram at `corner` spanned by `edge_u` and `edge_v`, emitting `radiance`.
    pub fn new(corner: Vec3, edge_u: Vec3, edge_v: Vec3, radiance: Vec3) -> Self {
        let normal = edge_u.cross(edge_v);
        let (uu, uv, vv) = (edge_u.dot(edge_u), edge_u.dot(edge_v), edge_v.dot(edge_v));
        RectLight {
            corner,
            edge_u,
            edge_v,
            radiance,
            normal,
            area: normal.length(),
            gram: [uu, uv, vv, uu * vv - uv * uv],
        }
    }

    /// First edge from the corner (mm).
    pub fn edge_u(&self) -> Vec3 {
        self.edge_u
    }

    /// Second edge from the corner (mm).
    pub fn edge_v(&self) -> Vec3 {
        self.edge_v
    }
}

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

/// A constant environment or a lat-long map (z up; u = φ/2π with φ = atan2(y, x), v = θ/π).
#[derive(Clone, Debug)]
pub struct Environment {
    /// Radiance (W/(sr·mm²), linear RGB) of the constant environment, or the factor the map's
    /// texels are scaled by.
    pub scale: Vec3,
    /// The lat-long map; `None` for a constant environment.
    pub map: Option<Arc<EnvMap>>,
}

/// A lat-long radiance map with its sampling distribution.
#[derive(Debug)]
pub struct EnvMap {
    /// Texels per row (φ from 0 to 2π).
    pub width: usize,
    /// Rows (θ from 0 at +z to π).
    pub height: usize,
    /// Radiance texels (linear RGB), row-major, top row = +z.
    pub texels: Vec<Vec3>,
    dist: Distribution2D,
    /// (cos, sin) of the map's rotation about z: a texel at azimuth φ is seen at φ + angle. Applied
    /// to the lookup direction, so any angle is exact (rounding the angle to whole texel columns
    /// moved a 4-column map by up to 45°).
    rotation: (f32, f32),
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

    /// Samples incident light at `p` with uniform numbers `u`.
    ///
    /// Same as `sample_at(p, &LightU::new(u))`; a caller that samples many placements of one
    /// light with the same numbers (a light sweep) makes the [`LightU`] once.
    pub fn sample(&self, p: Vec3, u: Vec2) -> Option<LightSample> {
        match self {
            Light::Point(PointLight {
                position,
                intensity,
            }) => delta_point(p, *position, *intensity),
            Light::Spot(SpotLight {
                position,
                direction,
                intensity,
                cos_inner,
                cos_outer,
            }) => {
                let mut s = delta_point(p, *position, *intensity)?;
                let cos = (-s.wi).dot(*direction);
                s.li *= smoothstep(*cos_outer, *cos_inner, cos);
                Some(s)
            }
            Light::Distant(DistantLight {
                direction,
                irradiance,
            }) => Some(LightSample {
                wi: *direction,
                dist: f32::INFINITY,
                li: *irradiance,
                pdf: 1.0,
                is_delta: true,
            }),
            Light::Rect(RectLight {
                corner,
                edge_u,
                edge_v,
                radiance,
                normal: n,
                area,
                ..
            }) => {
                let q = *corner + *edge_u * u.x + *edge_v * u.y;
                let to = q - p;
                let d2 = to.length_squared();
                let dist = d2.sqrt();
                let wi = to / dist;
                let cos_l = -wi.dot(*n / *area);
                if cos_l <= 0.0 || !(dist > 0.0) {
                    return None;
                }
                Some(LightSample {
                    wi,
                    dist,
                    li: *radiance,
                    pdf: d2 / (cos_l * area),
                    is_delta: false,
                })
            }
            Light::Sphere(SphereLight {
                center,
                radius,
                radiance,
            }) => sample_sphere(p, *center, *radius, *radiance, u.x, azimuth(u.y)),
            Light::Environment(env) => {
                let (wi, pdf) = match &env.map {
                    None => (uniform_sphere(u), UNIFORM_SPHERE_PDF),
                    Some(map) => map.sample(u)?,
                };
                Some(LightSample {
                    wi,
                    dist: f32::INFINITY,
                    li: env.radiance(wi),
                    pdf,
                    is_delta: false,
                })
            }
        }
    }

    /// [`Light::sample`] with the uniform numbers prepared: for a sphere light the azimuth's sine
    /// and cosine come from `u` (identical results; the trigonometry is done once per `u`).
    pub fn sample_at(&self, p: Vec3, u: &LightU) -> Option<LightSample> {
        match self {
            Light::Sphere(SphereLight {
                center,
                radius,
                radiance,
            }) => sample_sphere(p, *center, *radius, *radiance, u.u.x, u.azimuth),
            Light::Point(_)
            | Light::Spot(_)
            | Light::Distant(_)
            | Light::Rect(_)
            | Light::Environment(_) => self.sample(p, u.u),
        }
    }

    /// Where a ray first meets this light, what it emits towards the ray's origin, and the
    /// solid-angle density `sample` would have chosen that direction with from `ray.o`.
    pub fn hit(&self, ray: &Ray) -> Option<LightHit> {
        match self {
            Light::Rect(RectLight {
                corner,
                edge_u,
                edge_v,
                radiance,
                normal: n,
                area,
                gram: [uu, uv, vv, det],
            }) => {
                let denom = ray.d.dot(*n);
                if denom >= 0.0 {
                    return None; // one-sided: seen only from the front
                }
                let t = (*corner - ray.o).dot(*n) / denom;
                if !(t > 0.0) || !t.is_finite() {
                    return None;
                }
                let rel = ray.at(t) - *corner;
                // Coordinates in the (possibly non-orthogonal) edge basis.
                let (ru, rv) = (rel.dot(*edge_u), rel.dot(*edge_v));
                let a = (ru * vv - rv * uv) / det;
                let b = (rv * uu - ru * uv) / det;
                if !(0.0..=1.0).contains(&a) || !(0.0..=1.0).contains(&b) {
                    return None;
                }
                let cos_l = -denom / area;
                Some(LightHit {
                    distance: t,
                    radiance: *radiance,
                    pdf: t * t / (cos_l * area),
                })
            }
            Light::Sphere(SphereLight {
                center,
                radius,
                radiance,
            }) => {
                let t = intersect_sphere(ray, *center, *radius)?;
                let d2 = (*center - ray.o).length_squared();
                let r2 = radius * radius;
                if d2 <= r2 {
                    return None;
                }
                Some(LightHit {
                    distance: t,
                    radiance: *radiance,
                    pdf: 1.0 / (2.0 * PI * one_minus_cos_cone(r2 / d2)),
                })
            }
            Light::Environment(env) => {
                let pdf = match &env.map {
                    None => UNIFORM_SPHERE_PDF,
                    Some(map) => map.pdf(ray.d),
                };
                Some(LightHit {
                    distance: f32::INFINITY,
                    radiance: env.radiance(ray.d),
                    pdf,
                })
            }
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
struct ConeSample {
    wi: [f32; 3],
    dist: f32,
    pdf: f32,
    /// False when the point lies inside the sphere (then the other fields are meaningless).
    valid: bool,
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
    fn new(to: Vec3, r2: f32, ux: f32, (sin_phi, cos_phi): (f32, f32)) -> Self {
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

/// Samples of one light from one point at many places of the light (the frames of a light
/// sweep) with the same numbers, as columns (structure of arrays), for the batch next-event
/// terms of `render::integrator::light_terms`. A sphere light is sampled by one loop over
/// the frames' centres ([`LightSamples::sample_sphere`]): no frame depends on another, so the
/// loop runs in SIMD lanes instead of one latency-bound chain of square roots and divisions per
/// frame. Values bit-identical to [`Light::sample_at`] (tested).
#[derive(Clone, Debug, Default)]
pub struct LightSamples {
    /// Unit directions towards the light (world), by component.
    pub wi: [Vec<f32>; 3],
    /// Distance to each light sample (infinite for distant and environment lights).
    pub dist: Vec<f32>,
    /// Solid-angle density (1 for delta lights); 0 where there is no sample.
    pub pdf: Vec<f32>,
    /// Incident radiance of each sample (irradiance at normal incidence for delta lights), by
    /// channel.
    pub li: [Vec<f32>; 3],
    /// Whether the light is a delta light (the same in every place).
    pub is_delta: bool,
}

impl LightSamples {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.pdf.len()
    }

    /// True when there are no samples.
    pub fn is_empty(&self) -> bool {
        self.pdf.is_empty()
    }

    fn resize(&mut self, n: usize) {
        for c in self.wi.iter_mut().chain(&mut self.li) {
            c.resize(n, 0.0);
        }
        self.dist.resize(n, 0.0);
        self.pdf.resize(n, 0.0);
    }

    /// Samples the sphere of radius `radius` and radiance `radiance` centred at `centers[k]` (by
    /// component) from `p`, for every k, with numbers `u`.
    #[inline(always)]
    pub fn sample_sphere(
        &mut self,
        p: Vec3,
        centers: &[Vec<f32>; 3],
        radius: f32,
        radiance: Vec3,
        u: &LightU,
    ) {
        let n = centers[0].len();
        self.resize(n);
        self.is_delta = false;
        for (c, v) in self.li.iter_mut().zip(radiance.to_array()) {
            c.fill(v);
        }
        let [cx, cy, cz] = centers;
        let (cx, cy, cz) = (&cx[..n], &cy[..n], &cz[..n]);
        let [wx, wy, wz] = &mut self.wi;
        let (wx, wy, wz) = (&mut wx[..n], &mut wy[..n], &mut wz[..n]);
        let (dist, pdf) = (&mut self.dist[..n], &mut self.pdf[..n]);
        let r2 = radius * radius;
        for k in 0..n {
            let to = Vec3::new(cx[k], cy[k], cz[k]) - p;
            let c = ConeSample::new(to, r2, u.u.x, u.azimuth);
            [wx[k], wy[k], wz[k]] = c.wi;
            dist[k] = c.dist;
            pdf[k] = if c.valid { c.pdf } else { 0.0 };
        }
    }

    /// Samples from `p` of `lights` — one light's place in each frame, any kind of light — one
    /// at a time ([`Light::sample_at`]); a failed sample is stored with density 0.
    pub(crate) fn sample_each<'a>(
        &mut self,
        p: Vec3,
        lights: impl ExactSizeIterator<Item = &'a Light>,
        u: &LightU,
    ) {
        self.resize(lights.len());
        self.is_delta = false;
        for (k, light) in lights.enumerate() {
            self.is_delta = light.is_delta();
            let s = light.sample_at(p, u);
            let s = s.unwrap_or(LightSample {
                wi: Vec3::ZERO,
                dist: 0.0,
                li: Vec3::ZERO,
                pdf: 0.0,
                is_delta: self.is_delta,
            });
            for (c, v) in self.wi.iter_mut().zip(s.wi.to_array()) {
                c[k] = v;
            }
            for (c, v) in self.li.iter_mut().zip(s.li.to_array()) {
                c[k] = v;
            }
            (self.dist[k], self.pdf[k]) = (s.dist, s.pdf);
        }
    }

    /// Place `k`'s sample as [`Light::sample_at`] returns it (`None` where it returns `None`).
    #[inline]
    pub fn get(&self, k: usize) -> Option<LightSample> {
        (self.pdf[k] != 0.0).then(|| LightSample {
            wi: Vec3::new(self.wi[0][k], self.wi[1][k], self.wi[2][k]),
            dist: self.dist[k],
            li: Vec3::new(self.li[0][k], self.li[1][k], self.li[2][k]),
            pdf: self.pdf[k],
            is_delta: self.is_delta,
        })
    }
}

fn delta_point(p: Vec3, position: Vec3, intensity: Vec3) -> Option<LightSample> {
    let to = position - p;
    let d2 = to.length_squared();
    if !(d2 > 0.0) {
        return None;
    }
    let dist = d2.sqrt();
    // Inverse-square law: irradiance at normal incidence E = I / d².
    Some(LightSample {
        wi: to / dist,
        dist,
        li: intensity / d2,
        pdf: 1.0,
        is_delta: true,
    })
}

/// Hermite smoothstep, 0 below `a`, 1 above `b`.
fn smoothstep(a: f32, b: f32, x: f32) -> f32 {
    if a >= b {
        return if x >= b { 1.0 } else { 0.0 };
    }
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
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
pub fn intersect_sphere(ray: &Ray, center: Vec3, radius: f32) -> Option<f32> {
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

impl Environment {
    /// Radiance arriving from direction `-d`, i.e. seen looking along `d`.
    pub fn radiance(&self, d: Vec3) -> Vec3 {
        match &self.map {
            None => self.scale,
            Some(m) => self.scale * m.lookup(d),
        }
    }
}

impl EnvMap {
    /// A map from row-major texels (top row = +z); sampling is proportional to luminance·sin θ.
    pub fn new(width: usize, height: usize, texels: Vec<Vec3>) -> Self {
        let weights: Vec<f32> = (0..height)
            .flat_map(|y| {
                let sin = ((y as f32 + 0.5) / height as f32 * PI).sin();
                let texels = &texels;
                (0..width).map(move |x| {
                    let c = texels[y * width + x];
                    (crate::math::luminance(c).max(0.0) * sin).max(1e-8)
                })
            })
            .collect();
        EnvMap {
            width,
            height,
            dist: Distribution2D::new(&weights, width, height),
            texels,
            rotation: (1.0, 0.0),
        }
    }

    /// The map turned by `degrees` about z (positive: counter-clockwise seen from +z).
    pub fn rotated(mut self, degrees: f32) -> Self {
        let (s, c) = degrees.to_radians().sin_cos();
        self.rotation = (c, s);
        self
    }

    /// `d` turned by the map's rotation, backwards (`inverse`: world → map) or forwards.
    fn turn(&self, d: Vec3, inverse: bool) -> Vec3 {
        let (c, s) = self.rotation;
        if s == 0.0 && c == 1.0 {
            return d;
        }
        let s = if inverse { -s } else { s };
        Vec3::new(c * d.x - s * d.y, s * d.x + c * d.y, d.z)
    }

    fn uv(d: Vec3) -> Vec2 {
        let phi = d.y.atan2(d.x);
        let phi = if phi < 0.0 { phi + 2.0 * PI } else { phi };
        Vec2::new(phi / (2.0 * PI), crate::math::safe_acos(d.z) / PI)
    }

    fn dir(uv: Vec2) -> Vec3 {
        let (phi, theta) = (uv.x * 2.0 * PI, uv.y * PI);
        Vec3::new(
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        )
    }

    /// The texel (nearest, no filtering) seen looking along the world direction `d`, the map's
    /// rotation applied.
    pub fn lookup(&self, d: Vec3) -> Vec3 {
        let uv = Self::uv(self.turn(d, true));
        let x = ((uv.x * self.width as f32) as usize).min(self.width - 1);
        let y = ((uv.y * self.height as f32) as usize).min(self.height - 1);
        self.texels[y * self.width + x]
    }

    /// Direction and solid-angle pdf: p(ω) = p(u, v) / (2π² sin θ) (pbrt-v4 §12.5.2).
    fn sample(&self, u: Vec2) -> Option<(Vec3, f32)> {
        let (uv, pdf_uv) = self.dist.sample(u);
        let sin = (uv.y * PI).sin();
        if sin <= 0.0 || pdf_uv <= 0.0 {
            return None;
        }
        Some((
            self.turn(Self::dir(uv), false),
            pdf_uv / (2.0 * PI * PI * sin),
        ))
    }

    fn pdf(&self, d: Vec3) -> f32 {
        let uv = Self::uv(self.turn(d, true));
        let sin = (uv.y * PI).sin();
        if sin <= 0.0 {
            return 0.0;
        }
        self.dist.pdf(uv) / (2.0 * PI * PI * sin)
    }
}

/// Piecewise-constant 1D density on [0, 1) (pbrt-v4 §A.4.1).
#[derive(Debug, Clone)]
struct Distribution1D {
    func: Vec<f32>,
    cdf: Vec<f32>,
    integral: f32,
}

impl Distribution1D {
    fn new(func: &[f32]) -> Self {
        let n = func.len();
        let mut cdf = vec![0.0f32; n + 1];
        for i in 0..n {
            cdf[i + 1] = cdf[i] + func[i] / n as f32;
        }
        let integral = cdf[n];
        for c in &mut cdf[1..] {
            *c /= integral;
        }
        Distribution1D {
            func: func.to_vec(),
            cdf,
            integral,
        }
    }

    /// Continuous sample in [0, 1), its density and its cell.
    fn sample(&self, u: f32) -> (f32, f32, usize) {
        let n = self.func.len();
        let i = (self.cdf.partition_point(|&c| c <= u).max(1) - 1).min(n - 1);
        let width = self.cdf[i + 1] - self.cdf[i];
        let du = if width > 0.0 {
            (u - self.cdf[i]) / width
        } else {
            0.5
        };
        let x = ((i as f32 + du.clamp(0.0, 1.0)) / n as f32).min(1.0 - f32::EPSILON);
        (x, self.func[i] / self.integral, i)
    }

    fn pdf_cell(&self, i: usize) -> f32 {
        self.func[i] / self.integral
    }
}

/// Piecewise-constant 2D density: a marginal over rows and a conditional per row.
#[derive(Debug, Clone)]
struct Distribution2D {
    rows: Vec<Distribution1D>,
    marginal: Distribution1D,
    width: usize,
    height: usize,
}

impl Distribution2D {
    fn new(f: &[f32], width: usize, height: usize) -> Self {
        let rows: Vec<Distribution1D> = (0..height)
            .map(|y| Distribution1D::new(&f[y * width..(y + 1) * width]))
            .collect();
        let marg: Vec<f32> = rows.iter().map(|r| r.integral).collect();
        Distribution2D {
            marginal: Distribution1D::new(&marg),
            rows,
            width,
            height,
        }
    }

    fn sample(&self, u: Vec2) -> (Vec2, f32) {
        let (v, pv, row) = self.marginal.sample(u.y);
        let (x, px, _) = self.rows[row].sample(u.x);
        (Vec2::new(x, v), pv * px)
    }

    fn pdf(&self, uv: Vec2) -> f32 {
        let x = ((uv.x * self.width as f32) as usize).min(self.width - 1);
        let y = ((uv.y * self.height as f32) as usize).min(self.height - 1);
        self.marginal.pdf_cell(y) * self.rows[y].pdf_cell(x)
    }
}

/// The nearest light a ray meets before `t_max`: its index in `lights` and where it is met.
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
