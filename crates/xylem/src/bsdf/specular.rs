//! Ideal specular BSDFs the scenes need: a mirror and a smooth dielectric (glass). Both are
//! pure delta lobes: `eval` and `pdf` are 0, `sample` returns `is_delta` samples.

use super::fresnel::{fresnel_dielectric, refract};
use super::{Bsdf, BsdfSample};
use glam::{Vec2, Vec3};

/// A perfect mirror with reflectance `reflectance` per channel (two-sided).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mirror {
    /// Reflectance per channel, linear RGB 0–1.
    pub reflectance: Vec3,
}

impl Bsdf for Mirror {
    fn eval(&self, _wo: Vec3, _wi: Vec3) -> Vec3 {
        Vec3::ZERO
    }

    fn pdf(&self, _wo: Vec3, _wi: Vec3) -> f32 {
        0.0
    }

    /// wi = reflect(wo, z) with weight `reflectance` (f = R/|cos θi|, pdf = 1).
    fn sample(&self, wo: Vec3, _uc: f32, _u: Vec2) -> Option<BsdfSample> {
        if wo.z == 0.0 || !wo.is_finite() {
            return None;
        }
        Some(BsdfSample {
            wi: Vec3::new(-wo.x, -wo.y, wo.z),
            f: self.reflectance / wo.z.abs(),
            pdf: 1.0,
            is_delta: true,
            eta: 1.0,
        })
    }
}

/// A smooth dielectric boundary (glass) of index `eta` inside (the +z side is outside), with a
/// transmission `tint`. Reflection or refraction is chosen with probability F and 1 − F
/// (Fresnel, Born & Wolf §1.5.2), so the weight is the tint times the radiance scaling 1/η'²
/// of refraction (Veach 1997, §5.2; pbrt-v4 §9.5.2, radiance transport).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Glass {
    /// Refractive index inside (relative to outside).
    pub eta: f32,
    /// Transmission tint per channel, linear RGB 0–1.
    pub tint: Vec3,
}

impl Glass {
    /// Clear glass of index `eta` (tint 1).
    pub fn new(eta: f32) -> Self {
        Glass {
            eta,
            tint: Vec3::ONE,
        }
    }
}

impl Bsdf for Glass {
    fn eval(&self, _wo: Vec3, _wi: Vec3) -> Vec3 {
        Vec3::ZERO
    }

    fn pdf(&self, _wo: Vec3, _wi: Vec3) -> f32 {
        0.0
    }

    fn sample(&self, wo: Vec3, uc: f32, _u: Vec2) -> Option<BsdfSample> {
        if wo.z == 0.0 || !wo.is_finite() || !(self.eta > 0.0) {
            return None;
        }
        let entering = wo.z > 0.0;
        let (eta, n) = if entering {
            (self.eta, Vec3::Z)
        } else {
            (1.0 / self.eta, -Vec3::Z)
        };
        let cos_o = wo.z.abs();
        let f = fresnel_dielectric(cos_o, eta);
        if uc < f {
            return Some(BsdfSample {
                wi: Vec3::new(-wo.x, -wo.y, wo.z),
                f: Vec3::splat(f / cos_o),
                pdf: f,
                is_delta: true,
                eta: 1.0,
            });
        }
        let wi = refract(wo, n, eta)?;
        let t = 1.0 - f;
        let cos_i = wi.z.abs();
        if !(cos_i > 0.0) {
            return None;
        }
        Some(BsdfSample {
            wi,
            f: self.tint * (t / (cos_i * eta * eta)),
            pdf: t,
            is_delta: true,
            eta,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mirror_reflects_with_its_reflectance() {
        let m = Mirror {
            reflectance: Vec3::new(0.9, 0.8, 0.7),
        };
        let wo = Vec3::new(0.3, -0.2, 0.93).normalize();
        let s = m.sample(wo, 0.5, Vec2::ZERO).unwrap();
        assert!(s.is_delta);
        assert!((s.wi - Vec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-6);
        assert!((s.f * s.wi.z.abs() / s.pdf - m.reflectance).length() < 1e-5);
        assert_eq!(m.eval(wo, s.wi), Vec3::ZERO);
        assert!(m.sample(Vec3::X, 0.5, Vec2::ZERO).is_none());
    }

    #[test]
    fn glass_splits_by_fresnel_and_obeys_snell() {
        let g = Glass::new(1.5);
        let wo = Vec3::new(0.5, 0.0, 0.866_025_4);
        let f = fresnel_dielectric(wo.z, 1.5);
        // Reflection branch: weight 1 (F/F).
        let r = g.sample(wo, 0.5 * f, Vec2::ZERO).unwrap();
        assert!(r.wi.z > 0.0 && (r.f * r.wi.z.abs() / r.pdf - Vec3::ONE).length() < 1e-5);
        // Refraction branch: sin θt = sin θo / η, weight 1/η².
        let t = g.sample(wo, 0.99, Vec2::ZERO).unwrap();
        assert!(t.wi.z < 0.0);
        assert!(((1.0 - t.wi.z * t.wi.z).sqrt() - 0.5 / 1.5).abs() < 1e-5);
        let w = t.f * t.wi.z.abs() / t.pdf;
        assert!((w - Vec3::splat(1.0 / 2.25)).length() < 1e-5);
        // Leaving the glass beyond the critical angle: always reflected.
        let inside = Vec3::new(0.8, 0.0, -0.6);
        let s = g.sample(inside, 0.999, Vec2::ZERO).unwrap();
        assert!(s.wi.z < 0.0 && (s.pdf - 1.0).abs() < 1e-6);
        // Leaving below the critical angle: sin θt = η sin θo, weight η² (radiance scaling).
        let out = Vec3::new(0.3, 0.0, -(1.0f32 - 0.09).sqrt());
        let e = g.sample(out, 0.999, Vec2::ZERO).unwrap();
        assert!(e.wi.z > 0.0 && ((1.0 - e.wi.z * e.wi.z).sqrt() - 0.45).abs() < 1e-5);
        assert!((e.f * e.wi.z.abs() / e.pdf - Vec3::splat(2.25)).length() < 1e-4);
    }
}
