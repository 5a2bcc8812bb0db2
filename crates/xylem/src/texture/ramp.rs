//! Colour helpers for the classic textures: piecewise-linear colour ramps in linear RGB and the
//! smooth threshold (Hermite smoothstep, Ebert et al., *Texturing and Modeling*, ch. 2).

use glam::Vec3;

pub use crate::math::smoothstep;

/// A multi-stop colour ramp: stops `(t, colour)` with increasing t; clamps outside.
#[derive(Clone, Debug, PartialEq)]
pub struct Ramp {
    /// `(t, colour)` stops, t increasing, colour linear RGB; at least one.
    pub stops: Vec<(f32, Vec3)>,
}

impl Ramp {
    /// A ramp through `stops`; they must be non-empty with increasing t.
    pub fn new(stops: &[(f32, Vec3)]) -> Self {
        Ramp {
            stops: stops.to_vec(),
        }
    }

    /// The colour at `t`: linear between the neighbouring stops, the end colours outside
    /// (non-finite t reads as 0).
    pub fn eval(&self, t: f32) -> Vec3 {
        let t = if t.is_finite() { t } else { 0.0 };
        let s = &self.stops;
        if t <= s[0].0 {
            return s[0].1;
        }
        for w in s.windows(2) {
            if t <= w[1].0 {
                let u = (t - w[0].0) / (w[1].0 - w[0].0);
                return w[0].1.lerp(w[1].1, u);
            }
        }
        s[s.len() - 1].1
    }
}

/// Grey of a value in [0, 1] (clamped), for the noise views.
#[inline]
pub fn grey(v: f32) -> Vec3 {
    Vec3::splat(if v.is_finite() {
        v.clamp(0.0, 1.0)
    } else {
        0.0
    })
}
