//! Cylindrical coordinates about the pith (the z axis) and their frame field (Liu et al. 2016 §6.1.1:
//! "the gradients of the coordinates produce three orthogonal vector fields").

use crate::math::Frame;
use glam::Vec3;

/// Below this distance from the pith (mm) θ and r̂ are undefined; a fixed fallback frame is used.
pub const PITH_EPSILON: f32 = 1e-6;

/// Cylindrical coordinates of a tree-space point: radius r (mm), angle θ in (−π, π], height z (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cylindrical {
    /// Distance from the pith (mm).
    pub r: f32,
    /// Angle about the pith (radians, in (−π, π]).
    pub theta: f32,
    /// Height along the pith (mm).
    pub z: f32,
}

impl Cylindrical {
    /// Coordinates of `p`; at the pith θ = 0.
    #[inline]
    pub(crate) fn from_point(p: Vec3) -> Self {
        let r = (p.x * p.x + p.y * p.y).sqrt();
        let theta = if r > PITH_EPSILON {
            p.y.atan2(p.x)
        } else {
            0.0
        };
        Cylindrical { r, theta, z: p.z }
    }
}

/// The frame (r̂, θ̂, ẑ) at `p` as a [`Frame`] with `s = r̂`, `t = θ̂`, `n = ẑ` (right-handed:
/// r̂ × θ̂ = ẑ). On the pith (r < [`PITH_EPSILON`]) the frame is (x̂, ŷ, ẑ), so it is never NaN.
#[inline]
pub fn cylinder_frame(p: Vec3) -> Frame {
    let (c, s) = cylinder_cos_sin(p.x, p.y);
    cylinder_frame_from(c, s)
}

/// (cos θ, sin θ) of the point (x, y, ·): r̂'s components, (1, 0) on the pith.
#[inline(always)]
pub(crate) fn cylinder_cos_sin(x: f32, y: f32) -> (f32, f32) {
    let r2 = x * x + y * y;
    let inv = 1.0 / r2.sqrt();
    if r2 > PITH_EPSILON * PITH_EPSILON {
        (x * inv, y * inv)
    } else {
        (1.0, 0.0)
    }
}

/// The frame (r̂, θ̂, ẑ) from r̂ = (c, s, 0).
#[inline(always)]
pub(crate) fn cylinder_frame_from(c: f32, s: f32) -> Frame {
    Frame {
        s: Vec3::new(c, s, 0.0),
        t: Vec3::new(-s, c, 0.0),
        n: Vec3::Z,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_is_the_gradient_of_the_coordinates() {
        // r̂ = ∇r and θ̂ = r ∇θ, checked by central differences away from the pith.
        let p = Vec3::new(3.0, -4.0, 7.0);
        let f = cylinder_frame(p);
        let h = 1e-3;
        let d = |g: &dyn Fn(Vec3) -> f32, e: Vec3| (g(p + e * h) - g(p - e * h)) / (2.0 * h);
        let r = |q: Vec3| Cylindrical::from_point(q).r;
        let th = |q: Vec3| Cylindrical::from_point(q).theta;
        let grad_r = Vec3::new(d(&r, Vec3::X), d(&r, Vec3::Y), d(&r, Vec3::Z));
        let grad_t = Vec3::new(d(&th, Vec3::X), d(&th, Vec3::Y), d(&th, Vec3::Z)) * 5.0;
        assert!((grad_r - f.s).length() < 1e-3, "{grad_r} vs {}", f.s);
        assert!((grad_t - f.t).length() < 1e-3, "{grad_t} vs {}", f.t);
    }

    #[test]
    fn pith_is_finite() {
        let c = Cylindrical::from_point(Vec3::new(0.0, 0.0, 2.0));
        assert_eq!((c.r, c.theta), (0.0, 0.0));
        let f = cylinder_frame(Vec3::new(0.0, -0.0, 5.0));
        assert_eq!((f.s, f.t, f.n), (Vec3::X, Vec3::Y, Vec3::Z));
    }
}
