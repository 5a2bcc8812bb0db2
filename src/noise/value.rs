//! Value noise: random values in [−1, 1) at the integer lattice, blended with Perlin's quintic fade
//! (Perlin 2002) — the "lattice value noise" of Ebert et al., *Texturing and Modeling* (3rd ed.)
//! ch. 2. The analytic gradient is the derivative of the faded trilinear blend.

use super::gradient::{fade, fade_d};
use super::hash::{floor_i32, lattice, mix32, signed_f32, PRIME_X, PRIME_Y, PRIME_Z};
use glam::Vec3;

/// 3D value noise; range [−1, 1), mean 0.
#[inline]
pub fn value3(p: Vec3, seed: u32) -> f32 {
    value3_grad(p, seed).0
}

/// [`value3`] and its analytic gradient.
#[inline]
pub fn value3_grad(p: Vec3, seed: u32) -> (f32, Vec3) {
    value3_grad_s(p, mix32(seed))
}

/// [`value3_grad`] with a scrambled seed.
#[inline(always)]
pub(crate) fn value3_grad_s(p: Vec3, s: u32) -> (f32, Vec3) {
    let (ix, iy, iz) = (floor_i32(p.x), floor_i32(p.y), floor_i32(p.z));
    let f = Vec3::new(p.x - ix as f32, p.y - iy as f32, p.z - iz as f32);
    let xa = (ix as u32).wrapping_mul(PRIME_X);
    let ya = (iy as u32).wrapping_mul(PRIME_Y);
    let za = (iz as u32).wrapping_mul(PRIME_Z);
    let (xb, yb, zb) = (
        xa.wrapping_add(PRIME_X),
        ya.wrapping_add(PRIME_Y),
        za.wrapping_add(PRIME_Z),
    );
    let v = |x, y, z| signed_f32(lattice(x, y, z, s));
    let (va, vb, vc, vd) = (v(xa, ya, za), v(xb, ya, za), v(xa, yb, za), v(xb, yb, za));
    let (ve, vf, vg, vh) = (v(xa, ya, zb), v(xb, ya, zb), v(xa, yb, zb), v(xb, yb, zb));
    let u = Vec3::new(fade(f.x), fade(f.y), fade(f.z));
    let du = Vec3::new(fade_d(f.x), fade_d(f.y), fade_d(f.z));
    let k1 = vb - va;
    let k2 = vc - va;
    let k3 = ve - va;
    let k4 = va - vb - vc + vd;
    let k5 = va - vc - ve + vg;
    let k6 = va - vb - ve + vf;
    let k7 = -va + vb + vc - vd + ve - vf - vg + vh;
    let value = va
        + u.x * k1
        + u.y * k2
        + u.z * k3
        + u.x * u.y * k4
        + u.y * u.z * k5
        + u.z * u.x * k6
        + u.x * u.y * u.z * k7;
    let gradient = du
        * (Vec3::new(k1, k2, k3)
            + Vec3::new(u.y, u.z, u.x) * Vec3::new(k4, k5, k6)
            + Vec3::new(u.z, u.x, u.y) * Vec3::new(k6, k4, k5)
            + k7 * Vec3::new(u.y * u.z, u.z * u.x, u.x * u.y));
    (value, gradient)
}

/// 1D value noise; range [−1, 1).
#[inline]
pub fn value1(x: f32, seed: u32) -> f32 {
    value1_grad(x, seed).0
}

/// [`value1`] and its derivative.
#[inline]
pub fn value1_grad(x: f32, seed: u32) -> (f32, f32) {
    let s = mix32(seed);
    let i = floor_i32(x);
    let t = x - i as f32;
    let xa = (i as u32).wrapping_mul(PRIME_X);
    let v0 = signed_f32(lattice(xa, 0, 0, s));
    let v1 = signed_f32(lattice(xa.wrapping_add(PRIME_X), 0, 0, s));
    (v0 + fade(t) * (v1 - v0), fade_d(t) * (v1 - v0))
}
