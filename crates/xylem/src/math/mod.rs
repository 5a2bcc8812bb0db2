//! Small pure math shared by every module: orthonormal frames, safe inverse
//! trigonometry, sampling warps, a seedable random number generator, and `exp` / `sin_cos` that
//! vectorise (`elementary`).

pub mod elementary;
mod frame;
mod rng;
mod sampling;

pub use frame::Frame;
pub use glam::{Mat3, Vec2, Vec3};
pub use rng::Pcg32;
pub use sampling::*;

/// π.
pub const PI: f32 = std::f32::consts::PI;
/// 1/π.
pub(crate) const INV_PI: f32 = std::f32::consts::FRAC_1_PI;

/// `sqrt(max(x, 0))`: rounding can push a mathematically non-negative argument below 0.
#[inline]
pub fn safe_sqrt(x: f32) -> f32 {
    x.max(0.0).sqrt()
}

/// `asin` with its argument clamped to [-1, 1], so rounding never yields NaN.
#[inline]
pub fn safe_asin(x: f32) -> f32 {
    x.clamp(-1.0, 1.0).asin()
}

/// `acos` with its argument clamped to [-1, 1], so rounding never yields NaN.
#[inline]
pub(crate) fn safe_acos(x: f32) -> f32 {
    x.clamp(-1.0, 1.0).acos()
}

/// Whether every component of `v` is 0 (`v == Vec3::ZERO`), without branches.
#[inline(always)]
pub(crate) fn is_zero(v: Vec3) -> bool {
    (v.x == 0.0) & (v.y == 0.0) & (v.z == 0.0)
}

/// Hermite smoothstep (Ebert et al., *Texturing and Modeling*, ch. 2): 0 below `e0`, 1 above
/// `e1`, 3t² − 2t³ between; a step at `e1` when the edges coincide or cross (a spot light whose
/// inner and outer cones are one, a zero-width threshold), where t would be 0/0.
#[inline]
pub fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    if e0 >= e1 {
        return if x >= e1 { 1.0 } else { 0.0 };
    }
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Degrees to radians (files hold degrees, code works in radians).
#[inline]
pub fn radians(deg: f32) -> f32 {
    deg.to_radians()
}

/// Relative luminance of a linear-sRGB colour (ITU-R BT.709 weights).
#[inline]
pub fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// Reflect `v` about the normal `n` (both unit vectors; result points away from the surface when `v` does).
#[inline]
pub fn reflect(v: Vec3, n: Vec3) -> Vec3 {
    2.0 * v.dot(n) * n - v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn safe_functions_never_nan() {
        for x in [-1.000_001_f32, -1.0, 0.0, 1.0, 1.000_001, -0.0] {
            assert!(safe_asin(x).is_finite());
            assert!(safe_acos(x).is_finite());
            assert!(safe_sqrt(x - 1.0).is_finite());
        }
        assert_eq!(safe_sqrt(-1e-9), 0.0);
    }

    #[test]
    fn reflect_preserves_angle() {
        let n = Vec3::Z;
        let v = Vec3::new(0.3, -0.4, 0.866).normalize();
        let r = reflect(v, n);
        assert!((r.z - v.z).abs() < 1e-6 && (r.x + v.x).abs() < 1e-6);
    }
}
