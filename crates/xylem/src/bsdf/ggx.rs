//! The isotropic GGX / Trowbridge–Reitz microfacet distribution (Trowbridge & Reitz 1975;
//! Walter et al. 2007, eqs. 33–34) with Smith masking (Heitz 2014, "Understanding the
//! masking-shadowing function", eqs. 72, 99) and visible-normal sampling (Heitz 2018,
//! "Sampling the GGX distribution of visible normals", JCGT 7(4)), in the shading frame.

use crate::math::{safe_sqrt, PI};
use glam::{Vec2, Vec3};

/// GGX distribution with width α (α → 0 is a mirror).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ggx {
    /// Width α (the GGX roughness, 0 = mirror).
    pub alpha: f32,
}

impl Ggx {
    /// D(h) = α² / (π (cos²θh (α² − 1) + 1)²) (Walter et al. 2007, eq. 33).
    #[inline]
    pub fn d(&self, h: Vec3) -> f32 {
        if h.z <= 0.0 {
            return 0.0;
        }
        let a2 = self.alpha * self.alpha;
        let t = h.z * h.z * (a2 - 1.0) + 1.0;
        a2 / (PI * t * t)
    }

    /// Smith Λ(ω) = (−1 + √(1 + α² tan²θ)) / 2 (Heitz 2014, eq. 72).
    #[inline]
    pub fn lambda(&self, w: Vec3) -> f32 {
        let c2 = w.z * w.z;
        if c2 <= 0.0 {
            return f32::INFINITY;
        }
        let tan2 = (1.0 - c2).max(0.0) / c2;
        0.5 * (-1.0 + (1.0 + self.alpha * self.alpha * tan2).sqrt())
    }

    /// G1(ω) = 1 / (1 + Λ(ω)).
    #[inline]
    pub(crate) fn g1(&self, w: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// Height-correlated masking-shadowing G2 = 1 / (1 + Λ(ωo) + Λ(ωi)) (Heitz 2014, eq. 99);
    /// symmetric in its arguments, so the reflection lobe stays reciprocal.
    #[inline]
    pub(crate) fn g2(&self, wo: Vec3, wi: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(wo) + self.lambda(wi))
    }

    /// Samples a visible microfacet normal for `wo` (z > 0) (Heitz 2018, Listing 1): stretch,
    /// sample the projected hemisphere, unstretch. Density `g1(wo) max(0, wo·h) d(h) / wo.z`.
    pub(crate) fn sample_visible_normal(&self, wo: Vec3, u: Vec2) -> Vec3 {
        let vh = Vec3::new(self.alpha * wo.x, self.alpha * wo.y, wo.z).normalize();
        let len2 = vh.x * vh.x + vh.y * vh.y;
        let t1 = if len2 > 0.0 {
            Vec3::new(-vh.y, vh.x, 0.0) / len2.sqrt()
        } else {
            Vec3::X
        };
        let t2 = vh.cross(t1);
        let r = u.x.sqrt();
        let phi = 2.0 * PI * u.y;
        let p1 = r * phi.cos();
        let s = 0.5 * (1.0 + vh.z);
        let p2 = (1.0 - s) * safe_sqrt(1.0 - p1 * p1) + s * r * phi.sin();
        let nh = p1 * t1 + p2 * t2 + safe_sqrt(1.0 - p1 * p1 - p2 * p2) * vh;
        Vec3::new(self.alpha * nh.x, self.alpha * nh.y, nh.z.max(1e-7)).normalize()
    }

    /// Density per solid angle of the reflected direction `wi = reflect(wo, h)` when h is drawn by
    /// [`Ggx::sample_visible_normal`]: D_vis(h) / (4 wo·h) = G1(wo) D(h) / (4 wo.z).
    #[inline]
    pub(crate) fn reflection_pdf(&self, wo: Vec3, h: Vec3) -> f32 {
        if wo.z <= 0.0 || wo.dot(h) <= 0.0 {
            return 0.0;
        }
        self.g1(wo) * self.d(h) / (4.0 * wo.z)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{uniform_sphere, Pcg32};

    #[test]
    fn projected_area_of_microfacets_is_one() {
        // ∫ D(h) cos θh dh = 1 (Walter et al. 2007, eq. 4), by uniform-sphere Monte Carlo.
        for alpha in [0.1f32, 0.5, 1.0] {
            let g = Ggx { alpha };
            let mut r = Pcg32::new(9, 0);
            let n = 400_000;
            let mut s = 0.0f64;
            for _ in 0..n {
                let h = uniform_sphere(r.next_vec2());
                s += (g.d(h) * h.z.max(0.0) * 4.0 * PI) as f64;
            }
            let m = s / n as f64;
            let tol = if alpha < 0.2 { 0.08 } else { 0.02 };
            assert!((m - 1.0).abs() < tol, "alpha {alpha}: {m}");
        }
    }

    #[test]
    fn visible_normals_face_the_viewer() {
        let g = Ggx { alpha: 0.6 };
        let mut r = Pcg32::new(1, 2);
        let wo = Vec3::new(0.7, 0.1, 0.3).normalize();
        for _ in 0..10_000 {
            let h = g.sample_visible_normal(wo, r.next_vec2());
            assert!(h.z > 0.0 && wo.dot(h) >= -1e-5 && (h.length() - 1.0).abs() < 1e-5);
        }
    }
}
