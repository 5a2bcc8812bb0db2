//! Gradient noise: Perlin's improved noise (Perlin 2002, "Improving Noise", SIGGRAPH) in 1D and 3D
//! with its analytic gradient. Quintic fade `6t⁵ − 15t⁴ + 10t³` (Perlin 2002 §2) so the second
//! derivative is continuous across cells; the 12 cube-edge gradients padded to 16 (Perlin 2002
//! §3). The gradient of the trilinear blend follows I. Quilez, "Gradient noise derivatives" (2017).

use super::hash::{floor_i32, lattice, mix32, signed_f32, PRIME_X, PRIME_Y, PRIME_Z};
use glam::Vec3;

/// Perlin 2002 quintic fade.
#[inline(always)]
pub fn fade(t: f32) -> f32 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

/// Derivative of [`fade`]: `30 t² (t − 1)²`.
#[inline(always)]
pub fn fade_d(t: f32) -> f32 {
    30.0 * t * t * (t * (t - 2.0) + 1.0)
}

/// Gradient set: Perlin 2002's 12 cube-edge midpoints, padded to 16 (a 4-bit index) with the 4
/// diagonals of a regular tetrahedron instead of Perlin's 4 repeated edges, so that the second
/// moment is exactly isotropic, E[g gᵀ] = ¾ I (Perlin's padding gives diag(10, 12, 10)/16, a 20 %
/// excess along y). Derivation in notes/noise.md. (w unused, for alignment.)
static GRADS: [[f32; 4]; 16] = [
    [1.0, 1.0, 0.0, 0.0],
    [-1.0, 1.0, 0.0, 0.0],
    [1.0, -1.0, 0.0, 0.0],
    [-1.0, -1.0, 0.0, 0.0],
    [1.0, 0.0, 1.0, 0.0],
    [-1.0, 0.0, 1.0, 0.0],
    [1.0, 0.0, -1.0, 0.0],
    [-1.0, 0.0, -1.0, 0.0],
    [0.0, 1.0, 1.0, 0.0],
    [0.0, -1.0, 1.0, 0.0],
    [0.0, 1.0, -1.0, 0.0],
    [0.0, -1.0, -1.0, 0.0],
    [1.0, 1.0, 1.0, 0.0],
    [-1.0, -1.0, 1.0, 0.0],
    [1.0, -1.0, -1.0, 0.0],
    [-1.0, 1.0, -1.0, 0.0],
];

#[inline(always)]
fn grad(h: u32) -> &'static [f32; 4] {
    &GRADS[(h >> 28) as usize]
}

#[inline(always)]
fn dot(g: &[f32; 4], x: f32, y: f32, z: f32) -> f32 {
    g[0] * x + g[1] * y + g[2] * z
}

/// Improved Perlin noise at `p` for `seed`. Zero at every lattice point; range within ±1.04
/// (measured, see tests) and mean 0.
#[inline]
pub fn gradient3(p: Vec3, seed: u32) -> f32 {
    let s = mix32(seed);
    let (ix, iy, iz) = (floor_i32(p.x), floor_i32(p.y), floor_i32(p.z));
    let (x0, y0, z0) = (p.x - ix as f32, p.y - iy as f32, p.z - iz as f32);
    let (x1, y1, z1) = (x0 - 1.0, y0 - 1.0, z0 - 1.0);
    let xa = (ix as u32).wrapping_mul(PRIME_X);
    let ya = (iy as u32).wrapping_mul(PRIME_Y);
    let za = (iz as u32).wrapping_mul(PRIME_Z);
    let (xb, yb, zb) = (
        xa.wrapping_add(PRIME_X),
        ya.wrapping_add(PRIME_Y),
        za.wrapping_add(PRIME_Z),
    );
    let n000 = dot(grad(lattice(xa, ya, za, s)), x0, y0, z0);
    let n100 = dot(grad(lattice(xb, ya, za, s)), x1, y0, z0);
    let n010 = dot(grad(lattice(xa, yb, za, s)), x0, y1, z0);
    let n110 = dot(grad(lattice(xb, yb, za, s)), x1, y1, z0);
    let n001 = dot(grad(lattice(xa, ya, zb, s)), x0, y0, z1);
    let n101 = dot(grad(lattice(xb, ya, zb, s)), x1, y0, z1);
    let n011 = dot(grad(lattice(xa, yb, zb, s)), x0, y1, z1);
    let n111 = dot(grad(lattice(xb, yb, zb, s)), x1, y1, z1);
    let (u, v, w) = (fade(x0), fade(y0), fade(z0));
    let a = n000 + u * (n100 - n000);
    let b = n010 + u * (n110 - n010);
    let c = n001 + u * (n101 - n001);
    let d = n011 + u * (n111 - n011);
    let e = a + v * (b - a);
    let f = c + v * (d - c);
    e + w * (f - e)
}

/// [`gradient3`] and its analytic gradient ∇n (Quilez 2017: derivative of the trilinear blend of
/// the eight corner planes `g·(p − corner)` under the quintic fade).
#[inline]
pub fn gradient3_grad(p: Vec3, seed: u32) -> (f32, Vec3) {
    let s = mix32(seed);
    let (ix, iy, iz) = (floor_i32(p.x), floor_i32(p.y), floor_i32(p.z));
    let f0 = Vec3::new(p.x - ix as f32, p.y - iy as f32, p.z - iz as f32);
    let f1 = f0 - Vec3::ONE;
    let xa = (ix as u32).wrapping_mul(PRIME_X);
    let ya = (iy as u32).wrapping_mul(PRIME_Y);
    let za = (iz as u32).wrapping_mul(PRIME_Z);
    let (xb, yb, zb) = (
        xa.wrapping_add(PRIME_X),
        ya.wrapping_add(PRIME_Y),
        za.wrapping_add(PRIME_Z),
    );
    let g = |h: u32| {
        let g = grad(h);
        Vec3::new(g[0], g[1], g[2])
    };
    // Corners a..h in Quilez's order: 000, 100, 010, 110, 001, 101, 011, 111.
    let ga = g(lattice(xa, ya, za, s));
    let gb = g(lattice(xb, ya, za, s));
    let gc = g(lattice(xa, yb, za, s));
    let gd = g(lattice(xb, yb, za, s));
    let ge = g(lattice(xa, ya, zb, s));
    let gf = g(lattice(xb, ya, zb, s));
    let gg = g(lattice(xa, yb, zb, s));
    let gh = g(lattice(xb, yb, zb, s));
    let va = ga.dot(f0);
    let vb = gb.dot(Vec3::new(f1.x, f0.y, f0.z));
    let vc = gc.dot(Vec3::new(f0.x, f1.y, f0.z));
    let vd = gd.dot(Vec3::new(f1.x, f1.y, f0.z));
    let ve = ge.dot(Vec3::new(f0.x, f0.y, f1.z));
    let vf = gf.dot(Vec3::new(f1.x, f0.y, f1.z));
    let vg = gg.dot(Vec3::new(f0.x, f1.y, f1.z));
    let vh = gh.dot(f1);
    let u = Vec3::new(fade(f0.x), fade(f0.y), fade(f0.z));
    let du = Vec3::new(fade_d(f0.x), fade_d(f0.y), fade_d(f0.z));
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
    let gradient = ga
        + u.x * (gb - ga)
        + u.y * (gc - ga)
        + u.z * (ge - ga)
        + u.x * u.y * (ga - gb - gc + gd)
        + u.y * u.z * (ga - gc - ge + gg)
        + u.z * u.x * (ga - gb - ge + gf)
        + u.x * u.y * u.z * (-ga + gb + gc - gd + ge - gf - gg + gh)
        + du * (Vec3::new(k1, k2, k3)
            + Vec3::new(u.y, u.z, u.x) * Vec3::new(k4, k5, k6)
            + Vec3::new(u.z, u.x, u.y) * Vec3::new(k6, k4, k5)
            + k7 * Vec3::new(u.y * u.z, u.z * u.x, u.x * u.y));
    (value, gradient)
}

/// 1D gradient noise: slopes uniform in [−1, 1) at the integers, quintic fade (Perlin 2002 in one
/// dimension). Range within ±0.5.
#[inline]
pub fn gradient1(x: f32, seed: u32) -> f32 {
    gradient1_grad(x, seed).0
}

/// [`gradient1`] and its derivative.
#[inline]
pub fn gradient1_grad(x: f32, seed: u32) -> (f32, f32) {
    let s = mix32(seed);
    let i = floor_i32(x);
    let t = x - i as f32;
    let xa = (i as u32).wrapping_mul(PRIME_X);
    let g0 = signed_f32(lattice(xa, 0, 0, s));
    let g1 = signed_f32(lattice(xa.wrapping_add(PRIME_X), 0, 0, s));
    let (a, b) = (g0 * t, g1 * (t - 1.0));
    let u = fade(t);
    (a + u * (b - a), g0 + u * (g1 - g0) + fade_d(t) * (b - a))
}
