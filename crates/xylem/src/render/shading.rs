//! The shading point: a hit ready to be lit, and where rays leaving it start. Below both the
//! integrator and the shadow test, which read it.

use crate::material::SurfaceBsdf;
use crate::math::Frame;
use glam::Vec3;

/// A first hit ready to be lit: position, geometric normal, shading frame, outgoing direction in
/// the local frame and the material's BSDF. `Copy`, so sweeps can cache one per pixel sample.
#[derive(Clone, Copy, Debug)]
pub struct ShadingPoint {
    /// Hit point (world, mm).
    pub p: Vec3,
    /// Geometric normal (world), on the side of `wo` unless the BSDF transmits.
    pub ng: Vec3,
    /// World shading frame (z = shading normal).
    pub frame: Frame,
    /// Direction towards the viewer, in the local frame.
    pub wo: Vec3,
    /// The material's BSDF at the hit, in the local shading frame.
    pub bsdf: SurfaceBsdf,
    /// Ray-origin offset length for rays leaving this point (mm).
    pub eps: f32,
}

impl ShadingPoint {
    /// A shading point to overwrite ([`shading_point`](super::integrator::shading_point)): black Lambertian at the origin.
    #[cold]
    pub(super) fn placeholder() -> ShadingPoint {
        ShadingPoint {
            p: Vec3::ZERO,
            ng: Vec3::Z,
            frame: Frame::from_normal_tangent(Vec3::Z, Vec3::X),
            wo: Vec3::Z,
            bsdf: SurfaceBsdf::Lambertian(crate::bsdf::Lambertian { albedo: Vec3::ZERO }),
            eps: 0.0,
        }
    }
}

/// How far a ray leaving a surface starts from it ([`ShadingPoint::eps`]) in a scene of extent
/// `scale` ([`crate::render::geometry::Accel::scale`]): 2·10⁻⁵ of it, above the rounding error
/// of hit points across the scene.
#[inline(always)]
pub(crate) fn offset_length(scale: f32) -> f32 {
    2e-5 * scale
}

/// Origin of a ray leaving `sp` along `dir`: the hit point moved `eps` along the geometric
/// normal, to the side `dir` points to, so the ray does not hit the surface it starts on.
#[inline(always)]
pub(crate) fn offset_origin(sp: &ShadingPoint, dir: Vec3) -> Vec3 {
    offset_ray_origin(sp.p, sp.ng, sp.eps, dir)
}

/// [`offset_origin`] from the point `p` with geometric normal `ng` and offset length `eps`.
#[inline(always)]
pub(crate) fn offset_ray_origin(p: Vec3, ng: Vec3, eps: f32, dir: Vec3) -> Vec3 {
    let side = if ng.dot(dir) >= 0.0 { 1.0 } else { -1.0 };
    p + ng * (side * eps)
}
