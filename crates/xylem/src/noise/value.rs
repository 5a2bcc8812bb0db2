//! Value noise: random values in [−1, 1) at the integer lattice, blended with Perlin's quintic fade
//! (Perlin 2002) — the "lattice value noise" of Ebert et al., *Texturing and Modeling* (3rd ed.)
//! ch. 2. The analytic gradient is the derivative of the faded trilinear blend (noise/lattice.rs).

use super::gradient::{fade, fade_d};
use super::hash::{floor_i32, mix32, signed_f32};
use super::lattice::{corner_hashes, end_values, trilinear_grad};
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
    let h = corner_hashes(ix, iy, iz, s);
    let v = h.map(signed_f32);
    let u = Vec3::new(fade(f.x), fade(f.y), fade(f.z));
    let du = Vec3::new(fade_d(f.x), fade_d(f.y), fade_d(f.z));
    trilinear_grad(&v, u, du)
}

/// 1D value noise; range [−1, 1).
#[inline]
pub fn value1(x: f32, seed: u32) -> f32 {
    value1_grad(x, seed).0
}

/// [`value1`] and its derivative.
#[inline]
pub fn value1_grad(x: f32, seed: u32) -> (f32, f32) {
    let i = floor_i32(x);
    let t = x - i as f32;
    let (v0, v1) = end_values(i, mix32(seed));
    (v0 + fade(t) * (v1 - v0), fade_d(t) * (v1 - v0))
}
