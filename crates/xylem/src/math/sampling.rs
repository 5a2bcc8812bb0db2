//! Sampling warps from the unit square (Shirley & Chiu 1997; pbrt-v4 §A.5) with their densities.

use super::{INV_PI, PI};
use glam::{Vec2, Vec3};

/// Concentric map of the square onto the unit disk (Shirley & Chiu 1997), area-preserving.
pub(crate) fn concentric_disk(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return Vec2::ZERO;
    }
    let (r, theta) = if o.x.abs() > o.y.abs() {
        (o.x, (PI / 4.0) * (o.y / o.x))
    } else {
        (o.y, PI / 2.0 - (PI / 4.0) * (o.x / o.y))
    };
    r * Vec2::new(theta.cos(), theta.sin())
}

/// Cosine-weighted hemisphere about +z (Malley's method); density `cos θ / π`.
pub fn cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = concentric_disk(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
}

/// The density of [`cosine_hemisphere`] at a direction with cosine `cos_theta` (0 below the
/// horizon).
#[inline]
pub(crate) fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cos_theta.max(0.0) * INV_PI
}

/// Uniform direction on the unit sphere; density `1 / 4π`.
pub fn uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// The density of [`uniform_sphere`].
pub(crate) const UNIFORM_SPHERE_PDF: f32 = 1.0 / (4.0 * PI);

/// Power heuristic with β = 2 (Veach 1997, eq. 9.13) for multiple importance sampling.
#[inline]
pub(crate) fn power_heuristic(pdf_a: f32, pdf_b: f32) -> f32 {
    let a = pdf_a * pdf_a;
    let b = pdf_b * pdf_b;
    if a + b > 0.0 && (a + b).is_finite() {
        a / (a + b)
    } else if pdf_a.is_infinite() {
        1.0
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Pcg32;

    #[test]
    fn warps_stay_in_their_domains() {
        let mut r = Pcg32::new(3, 0);
        for _ in 0..10_000 {
            let u = r.next_vec2();
            assert!(concentric_disk(u).length() <= 1.0 + 1e-6);
            let c = cosine_hemisphere(u);
            assert!(c.z >= 0.0 && (c.length() - 1.0).abs() < 1e-5);
            assert!((uniform_sphere(u).length() - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn cosine_hemisphere_mean_cos_is_two_thirds() {
        // E[cos θ] under p = cos θ/π is ∫cos²θ/π dω = 2/3.
        let mut r = Pcg32::new(5, 0);
        let n = 100_000;
        let m: f64 = (0..n)
            .map(|_| cosine_hemisphere(r.next_vec2()).z as f64)
            .sum::<f64>()
            / n as f64;
        assert!((m - 2.0 / 3.0).abs() < 0.005);
    }
}
