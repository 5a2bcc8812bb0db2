//! The Lambertian BSDF f = ρ/π (Lambert 1760), sampled with a cosine-weighted hemisphere.

use super::{Bsdf, BsdfSample};
use crate::math::{cosine_hemisphere, cosine_hemisphere_pdf, INV_PI};
use glam::{Vec2, Vec3};

/// Ideal diffuse reflection with albedo `albedo` (each channel in [0, 1]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lambertian {
    /// Albedo per channel, linear RGB 0–1.
    pub albedo: Vec3,
}

impl Bsdf for Lambertian {
    #[inline]
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if wo.z > 0.0 && wi.z > 0.0 {
            self.albedo * INV_PI
        } else {
            Vec3::ZERO
        }
    }

    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z > 0.0 && wi.z > 0.0 {
            cosine_hemisphere_pdf(wi.z)
        } else {
            0.0
        }
    }

    fn sample(&self, wo: Vec3, _uc: f32, u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = cosine_hemisphere(u);
        let pdf = cosine_hemisphere_pdf(wi.z);
        if pdf <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi,
            f: self.albedo * INV_PI,
            pdf,
            is_delta: false,
            eta: 1.0,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sample_weight_is_albedo() {
        let b = Lambertian {
            albedo: Vec3::new(0.2, 0.5, 0.8),
        };
        let wo = Vec3::new(0.1, 0.2, 0.97).normalize();
        let s = b.sample(wo, 0.5, Vec2::new(0.3, 0.7)).unwrap();
        let w = s.f * s.wi.z / s.pdf;
        assert!((w - b.albedo).length() < 1e-5);
        assert_eq!(b.eval(wo, -s.wi), Vec3::ZERO);
    }
}
