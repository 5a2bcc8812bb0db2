//! The integer lattice shared by value and gradient noise: the hashes of a cell's corners and the
//! faded trilinear blend of corner values with its derivative (I. Quilez, "Gradient noise
//! derivatives", 2017: the blend expanded as `c₀ + k₁u + k₂v + k₃w + k₄uv + k₅vw + k₆wu + k₇uvw`).

use super::hash::{lattice, signed_f32, PRIME_X, PRIME_Y, PRIME_Z};
use glam::Vec3;
use std::ops::{Add, Mul, Sub};

/// Lattice hashes of the eight corners of cell `(ix, iy, iz)` for the scrambled seed `s`, in
/// Quilez's order 000, 100, 010, 110, 001, 101, 011, 111 (bit k of the index is the step along
/// axis k). The per-axis products are formed once, so each further corner costs one add.
#[inline(always)]
pub(crate) fn corner_hashes(ix: i32, iy: i32, iz: i32, s: u32) -> [u32; 8] {
    let xa = (ix as u32).wrapping_mul(PRIME_X);
    let ya = (iy as u32).wrapping_mul(PRIME_Y);
    let za = (iz as u32).wrapping_mul(PRIME_Z);
    let (xb, yb, zb) = (
        xa.wrapping_add(PRIME_X),
        ya.wrapping_add(PRIME_Y),
        za.wrapping_add(PRIME_Z),
    );
    [
        lattice(xa, ya, za, s),
        lattice(xb, ya, za, s),
        lattice(xa, yb, za, s),
        lattice(xb, yb, za, s),
        lattice(xa, ya, zb, s),
        lattice(xb, ya, zb, s),
        lattice(xa, yb, zb, s),
        lattice(xb, yb, zb, s),
    ]
}

/// The values in [−1, 1) at the two ends of 1D cell `i` (on the line y = z = 0 of the lattice).
#[inline(always)]
pub(crate) fn end_values(i: i32, s: u32) -> (f32, f32) {
    let xa = (i as u32).wrapping_mul(PRIME_X);
    (
        signed_f32(lattice(xa, 0, 0, s)),
        signed_f32(lattice(xa.wrapping_add(PRIME_X), 0, 0, s)),
    )
}

/// The k-coefficients `[k₁ … k₇]` of the trilinear blend of corner values `c` (order of
/// [`corner_hashes`]).
#[inline(always)]
fn coefficients<T>(c: &[T; 8]) -> [T; 7]
where
    T: Copy + Add<Output = T> + Sub<Output = T>,
{
    let [a, b, c_, d, e, f, g, h] = *c;
    [
        b - a,
        c_ - a,
        e - a,
        a - b - c_ + d,
        a - c_ - e + g,
        a - b - e + f,
        // −a + b + c − d + e − f − g + h, from b − a so no negation is needed.
        b - a + c_ - d + e - f - g + h,
    ]
}

/// Trilinear blend of the corner values (or vectors) `c` at weights `u`.
#[inline(always)]
pub(crate) fn trilinear<T>(c: &[T; 8], u: Vec3) -> T
where
    T: Copy + Add<Output = T> + Sub<Output = T> + Mul<f32, Output = T>,
{
    let k = coefficients(c);
    c[0] + k[0] * u.x
        + k[1] * u.y
        + k[2] * u.z
        + k[3] * (u.x * u.y)
        + k[4] * (u.y * u.z)
        + k[5] * (u.z * u.x)
        + k[6] * (u.x * u.y * u.z)
}

/// [`trilinear`] of scalar corner values and its gradient with respect to the point, for weights
/// `u = fade(t)` with derivatives `du = fade′(t)`: ∂/∂tᵢ = fade′(tᵢ) ∂blend/∂uᵢ.
#[inline(always)]
pub(crate) fn trilinear_grad(c: &[f32; 8], u: Vec3, du: Vec3) -> (f32, Vec3) {
    let [k1, k2, k3, k4, k5, k6, k7] = coefficients(c);
    let d = du
        * (Vec3::new(k1, k2, k3)
            + Vec3::new(u.y, u.z, u.x) * Vec3::new(k4, k5, k6)
            + Vec3::new(u.z, u.x, u.y) * Vec3::new(k6, k4, k5)
            + k7 * Vec3::new(u.y * u.z, u.z * u.x, u.x * u.y));
    (trilinear(c, u), d)
}
