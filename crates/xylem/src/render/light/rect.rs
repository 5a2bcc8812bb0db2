//! The one-sided parallelogram area light: uniform area sampling converted to solid angle, and
//! the analytic ray hit.

use super::{LightHit, LightSample};
use crate::render::geometry::Ray;
use glam::{Vec2, Vec3};

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

    /// Samples the point `corner + u.x·edge_u + u.y·edge_v` uniformly by area; the solid-angle
    /// density is d² / (cos θ_l · area) (pbrt-v4 §12.5.1). `None` behind the light.
    #[inline]
    pub fn sample(&self, p: Vec3, u: Vec2) -> Option<LightSample> {
        let q = self.corner + self.edge_u * u.x + self.edge_v * u.y;
        let to = q - p;
        let d2 = to.length_squared();
        let dist = d2.sqrt();
        let wi = to / dist;
        let cos_l = -wi.dot(self.normal / self.area);
        if cos_l <= 0.0 || !(dist > 0.0) {
            return None;
        }
        Some(LightSample {
            wi,
            dist,
            li: self.radiance,
            pdf: d2 / (cos_l * self.area),
            is_delta: false,
        })
    }

    /// Where `ray` meets the front of the parallelogram, with the density [`RectLight::sample`]
    /// gives that direction.
    #[inline(always)]
    pub fn hit(&self, ray: &Ray) -> Option<LightHit> {
        let [uu, uv, vv, det] = self.gram;
        let (n, area) = (self.normal, self.area);
        let denom = ray.d.dot(n);
        if denom >= 0.0 {
            return None; // one-sided: seen only from the front
        }
        let t = (self.corner - ray.o).dot(n) / denom;
        if !(t > 0.0) || !t.is_finite() {
            return None;
        }
        let rel = ray.at(t) - self.corner;
        // Coordinates in the (possibly non-orthogonal) edge basis.
        let (ru, rv) = (rel.dot(self.edge_u), rel.dot(self.edge_v));
        let a = (ru * vv - rv * uv) / det;
        let b = (rv * uu - ru * uv) / det;
        if !(0.0..=1.0).contains(&a) || !(0.0..=1.0).contains(&b) {
            return None;
        }
        let cos_l = -denom / area;
        Some(LightHit {
            distance: t,
            radiance: self.radiance,
            pdf: t * t / (cos_l * area),
        })
    }
}
