//! Delta lights: point, spot and distant. No ray can hit them, so they have a `sample` and no
//! `hit`, and their samples take no MIS weight.

use super::LightSample;
use crate::math::smoothstep;
use glam::Vec3;

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

impl PointLight {
    /// The light arriving at `p`: irradiance at normal incidence I/d² (inverse-square law).
    #[inline]
    pub fn sample(&self, p: Vec3) -> Option<LightSample> {
        delta_point(p, self.position, self.intensity)
    }
}

impl SpotLight {
    /// The light arriving at `p`: a point light's I/d² times the cone's smoothstep falloff.
    #[inline]
    pub fn sample(&self, p: Vec3) -> Option<LightSample> {
        let mut s = delta_point(p, self.position, self.intensity)?;
        let cos = (-s.wi).dot(self.direction);
        s.li *= smoothstep(self.cos_outer, self.cos_inner, cos);
        Some(s)
    }
}

impl DistantLight {
    /// The light arriving anywhere: irradiance `irradiance` from `direction`.
    #[inline]
    pub fn sample(&self) -> LightSample {
        LightSample {
            wi: self.direction,
            dist: f32::INFINITY,
            li: self.irradiance,
            pdf: 1.0,
            is_delta: true,
        }
    }
}

#[inline]
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
