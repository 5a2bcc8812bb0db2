//! Gradient noise: Perlin's improved noise (Perlin 2002, "Improving Noise", SIGGRAPH) in 1D and 3D
//! with its analytic gradient. Quintic fade `6t⁵ − 15t⁴ + 10t³` (Perlin 2002 §2) so the second
//! derivative is continuous across cells; Perlin's 12 cube-edge gradients mixed with the cube
//! diagonals for an isotropic second moment (see [`GRADS`]). The gradient of the trilinear blend
//! follows I. Quilez, "Gradient noise derivatives" (2017). A 4-lane SSE2 kernel
//! ([`gradient3_x4`]) evaluates four points at once — fBm uses it across octaves.

use super::hash::{lattice, mix32, signed_f32, PRIME_X, PRIME_Y, PRIME_Z};
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

/// Gradient set, indexed by the top 5 hash bits `h >> 27`: bits 4, 3, 2 are the signs of x, y, z
/// and bits 1–0 pick the axis to zero (0 = x, 1 = y, 2 = z, 3 = none). So with probability ¾ the
/// gradient is one of Perlin 2002's 12 cube-edge vectors (±1, ±1, 0)… and with probability ¼
/// one of the 8 cube diagonals; the second moment is exactly isotropic, E[g gᵀ] = ¾ I
/// (Perlin's 16-entry padding with 4 repeated edges gives diag(10, 12, 10)/16, a 20 % excess
/// along y). The bit layout lets the SIMD kernel form g·d with sign flips and masks instead of a
/// table lookup; this table is the same set for the scalar path. Derivation in notes/noise.md.
static GRADS: [[f32; 4]; 32] = [
    [0.0, 1.0, 1.0, 0.0],
    [1.0, 0.0, 1.0, 0.0],
    [1.0, 1.0, 0.0, 0.0],
    [1.0, 1.0, 1.0, 0.0],
    [0.0, 1.0, -1.0, 0.0],
    [1.0, 0.0, -1.0, 0.0],
    [1.0, 1.0, 0.0, 0.0],
    [1.0, 1.0, -1.0, 0.0],
    [0.0, -1.0, 1.0, 0.0],
    [1.0, 0.0, 1.0, 0.0],
    [1.0, -1.0, 0.0, 0.0],
    [1.0, -1.0, 1.0, 0.0],
    [0.0, -1.0, -1.0, 0.0],
    [1.0, 0.0, -1.0, 0.0],
    [1.0, -1.0, 0.0, 0.0],
    [1.0, -1.0, -1.0, 0.0],
    [0.0, 1.0, 1.0, 0.0],
    [-1.0, 0.0, 1.0, 0.0],
    [-1.0, 1.0, 0.0, 0.0],
    [-1.0, 1.0, 1.0, 0.0],
    [0.0, 1.0, -1.0, 0.0],
    [-1.0, 0.0, -1.0, 0.0],
    [-1.0, 1.0, 0.0, 0.0],
    [-1.0, 1.0, -1.0, 0.0],
    [0.0, -1.0, 1.0, 0.0],
    [-1.0, 0.0, 1.0, 0.0],
    [-1.0, -1.0, 0.0, 0.0],
    [-1.0, -1.0, 1.0, 0.0],
    [0.0, -1.0, -1.0, 0.0],
    [-1.0, 0.0, -1.0, 0.0],
    [-1.0, -1.0, 0.0, 0.0],
    [-1.0, -1.0, -1.0, 0.0],
];

#[inline(always)]
fn grad(h: u32) -> &'static [f32; 4] {
    &GRADS[(h >> 27) as usize]
}

#[inline(always)]
fn dot(g: &[f32; 4], x: f32, y: f32, z: f32) -> f32 {
    (g[0] * x + g[1] * y) + g[2] * z
}

/// The lattice cell of a coordinate: truncation minus the sign bit. Equal to ⌊x⌋ except at
/// negative integers, where it picks the cell on the left with fraction 1 — the same point of a
/// continuous noise — and it needs no int→float round trip (the dominant cost of a branch-free
/// exact floor in this kernel).
#[inline(always)]
pub(crate) fn cell_of(x: f32) -> i32 {
    (x as i32) - ((x.to_bits() >> 31) as i32)
}

/// Improved Perlin noise at `p` for `seed`. Zero at every lattice point; range within ±1.04
/// (measured, see tests) and mean 0.
#[inline]
pub fn gradient3(p: Vec3, seed: u32) -> f32 {
    gradient3_s(p, mix32(seed))
}

/// [`gradient3`] with the seed already scrambled by [`mix32`] (fractal sums derive octave seeds
/// from one scrambled seed by an add).
#[inline(always)]
pub(crate) fn gradient3_s(p: Vec3, s: u32) -> f32 {
    gradient3_xyz(p.x, p.y, p.z, s)
}

/// The scalar kernel on separate coordinates (keeps the compiler from shuffling a `Vec3`).
#[inline(always)]
pub(crate) fn gradient3_xyz(x: f32, y: f32, z: f32, s: u32) -> f32 {
    let (ix, iy, iz) = (cell_of(x), cell_of(y), cell_of(z));
    let (x0, y0, z0) = (x - ix as f32, y - iy as f32, z - iz as f32);
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
    gradient3_grad_s(p, mix32(seed))
}

/// [`gradient3_grad`] with a scrambled seed.
#[inline(always)]
pub(crate) fn gradient3_grad_s(p: Vec3, s: u32) -> (f32, Vec3) {
    let (ix, iy, iz) = (cell_of(p.x), cell_of(p.y), cell_of(p.z));
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
    let i = cell_of(x);
    let t = x - i as f32;
    let xa = (i as u32).wrapping_mul(PRIME_X);
    let g0 = signed_f32(lattice(xa, 0, 0, s));
    let g1 = signed_f32(lattice(xa.wrapping_add(PRIME_X), 0, 0, s));
    let (a, b) = (g0 * t, g1 * (t - 1.0));
    let u = fade(t);
    (a + u * (b - a), g0 + u * (g1 - g0) + fade_d(t) * (b - a))
}

/// Four gradient-noise evaluations at once (points `x[i], y[i], z[i]`, scrambled seeds `s[i]`),
/// bit-identical to four calls of the scalar kernel. SSE2 (baseline on x86-64): lanes are the
/// points, so every instruction is vertical; g·d is formed from the hash bits by sign flips and
/// masks (see [`GRADS`]). Elsewhere it falls back to the scalar kernel.
#[allow(dead_code)]
#[inline(always)]
pub(crate) fn gradient3_x4(x: [f32; 4], y: [f32; 4], z: [f32; 4], s: [u32; 4]) -> [f32; 4] {
    #[cfg(target_arch = "x86_64")]
    {
        // SAFETY: SSE2 is part of the x86-64 baseline; the intrinsics only touch registers.
        unsafe {
            use std::arch::x86_64::_mm_loadu_ps as load;
            sse2::kernel(load(x.as_ptr()), load(y.as_ptr()), load(z.as_ptr()), s)
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        std::array::from_fn(|i| gradient3_xyz(x[i], y[i], z[i], s[i]))
    }
}

/// [`gradient3_x4`] at the four points `p · f[i] + shift[·][i]` (the octaves of a fractal sum),
/// formed in the same order as the scalar `p * f + shift`.
#[inline(always)]
pub(crate) fn gradient3_x4_affine(
    p: Vec3,
    f: [f32; 4],
    shift: [[f32; 4]; 3],
    s: [u32; 4],
) -> [f32; 4] {
    #[cfg(target_arch = "x86_64")]
    {
        // SAFETY: SSE2 is part of the x86-64 baseline; the intrinsics only touch registers.
        unsafe {
            use std::arch::x86_64::*;
            let f = _mm_loadu_ps(f.as_ptr());
            let axis = |c: f32, sh: &[f32; 4]| {
                _mm_add_ps(_mm_mul_ps(_mm_set1_ps(c), f), _mm_loadu_ps(sh.as_ptr()))
            };
            sse2::kernel(
                axis(p.x, &shift[0]),
                axis(p.y, &shift[1]),
                axis(p.z, &shift[2]),
                s,
            )
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        std::array::from_fn(|i| {
            let q = p * f[i] + Vec3::new(shift[0][i], shift[1][i], shift[2][i]);
            gradient3_xyz(q.x, q.y, q.z, s[i])
        })
    }
}

#[cfg(target_arch = "x86_64")]
mod sse2 {
    use super::super::hash::{KNUTH, PRIME_X, PRIME_Y, PRIME_Z};
    use std::arch::x86_64::*;

    /// Low 32 bits of a lane-wise u32 product (SSE2 has only the 32×32→64 `pmuludq`).
    #[inline(always)]
    unsafe fn mul_lo(a: __m128i, k: __m128i) -> __m128i {
        let even = _mm_mul_epu32(a, k);
        let odd = _mm_mul_epu32(_mm_srli_epi64(a, 32), _mm_srli_epi64(k, 32));
        _mm_unpacklo_epi32(
            _mm_shuffle_epi32(even, 0b10_00_10_00),
            _mm_shuffle_epi32(odd, 0b10_00_10_00),
        )
    }

    /// The scalar `lattice` hash on four lanes: `(x ^ y ^ z ^ s)·K`, then `h ^ (h >> 15)`.
    #[inline(always)]
    unsafe fn hash(x: __m128i, y: __m128i, z: __m128i, s: __m128i) -> __m128i {
        let h = mul_lo(
            _mm_xor_si128(_mm_xor_si128(x, y), _mm_xor_si128(z, s)),
            _mm_set1_epi32(KNUTH as i32),
        );
        _mm_xor_si128(h, _mm_srli_epi32(h, 15))
    }

    /// g·d for the gradient picked by the top 5 bits of `h` (layout of `GRADS`): sign flips by
    /// xor into the float sign bit, the dropped axis masked to +0.
    #[inline(always)]
    unsafe fn gdot(h: __m128i, dx: __m128, dy: __m128, dz: __m128) -> __m128 {
        let sign = _mm_set1_epi32(i32::MIN);
        let sx = _mm_and_si128(h, sign);
        let sy = _mm_and_si128(_mm_slli_epi32(h, 1), sign);
        let sz = _mm_and_si128(_mm_slli_epi32(h, 2), sign);
        let b = _mm_and_si128(_mm_srli_epi32(h, 27), _mm_set1_epi32(3));
        let kx = _mm_cmpeq_epi32(b, _mm_setzero_si128());
        let ky = _mm_cmpeq_epi32(b, _mm_set1_epi32(1));
        let kz = _mm_cmpeq_epi32(b, _mm_set1_epi32(2));
        let tx = _mm_andnot_si128(kx, _mm_xor_si128(_mm_castps_si128(dx), sx));
        let ty = _mm_andnot_si128(ky, _mm_xor_si128(_mm_castps_si128(dy), sy));
        let tz = _mm_andnot_si128(kz, _mm_xor_si128(_mm_castps_si128(dz), sz));
        _mm_add_ps(
            _mm_add_ps(_mm_castsi128_ps(tx), _mm_castsi128_ps(ty)),
            _mm_castsi128_ps(tz),
        )
    }

    #[inline(always)]
    unsafe fn fade(t: __m128) -> __m128 {
        let inner = _mm_add_ps(
            _mm_mul_ps(
                t,
                _mm_sub_ps(_mm_mul_ps(t, _mm_set1_ps(6.0)), _mm_set1_ps(15.0)),
            ),
            _mm_set1_ps(10.0),
        );
        _mm_mul_ps(_mm_mul_ps(_mm_mul_ps(t, t), t), inner)
    }

    #[inline(always)]
    unsafe fn lerp(a: __m128, b: __m128, t: __m128) -> __m128 {
        _mm_add_ps(a, _mm_mul_ps(t, _mm_sub_ps(b, a)))
    }

    /// Cell index (truncation minus sign bit, as `cell_of`) and the fraction.
    #[inline(always)]
    unsafe fn cell(p: __m128) -> (__m128i, __m128) {
        let i = _mm_add_epi32(_mm_cvttps_epi32(p), _mm_srai_epi32(_mm_castps_si128(p), 31));
        (i, _mm_sub_ps(p, _mm_cvtepi32_ps(i)))
    }

    #[inline(always)]
    pub(super) unsafe fn kernel(x: __m128, y: __m128, z: __m128, s: [u32; 4]) -> [f32; 4] {
        let (ix, x0) = cell(x);
        let (iy, y0) = cell(y);
        let (iz, z0) = cell(z);
        let one = _mm_set1_ps(1.0);
        let (x1, y1, z1) = (
            _mm_sub_ps(x0, one),
            _mm_sub_ps(y0, one),
            _mm_sub_ps(z0, one),
        );
        let (px, py, pz) = (
            _mm_set1_epi32(PRIME_X as i32),
            _mm_set1_epi32(PRIME_Y as i32),
            _mm_set1_epi32(PRIME_Z as i32),
        );
        let xa = mul_lo(ix, px);
        let ya = mul_lo(iy, py);
        let za = mul_lo(iz, pz);
        let (xb, yb, zb) = (
            _mm_add_epi32(xa, px),
            _mm_add_epi32(ya, py),
            _mm_add_epi32(za, pz),
        );
        let s = _mm_loadu_si128(s.as_ptr() as *const __m128i);
        let n000 = gdot(hash(xa, ya, za, s), x0, y0, z0);
        let n100 = gdot(hash(xb, ya, za, s), x1, y0, z0);
        let n010 = gdot(hash(xa, yb, za, s), x0, y1, z0);
        let n110 = gdot(hash(xb, yb, za, s), x1, y1, z0);
        let n001 = gdot(hash(xa, ya, zb, s), x0, y0, z1);
        let n101 = gdot(hash(xb, ya, zb, s), x1, y0, z1);
        let n011 = gdot(hash(xa, yb, zb, s), x0, y1, z1);
        let n111 = gdot(hash(xb, yb, zb, s), x1, y1, z1);
        let (u, v, w) = (fade(x0), fade(y0), fade(z0));
        let a = lerp(n000, n100, u);
        let b = lerp(n010, n110, u);
        let c = lerp(n001, n101, u);
        let d = lerp(n011, n111, u);
        let e = lerp(a, b, v);
        let f = lerp(c, d, v);
        let mut out = [0.0f32; 4];
        _mm_storeu_ps(out.as_mut_ptr(), lerp(e, f, w));
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Pcg32;

    #[test]
    fn four_lane_kernel_equals_scalar() {
        let mut r = Pcg32::new(1, 0);
        for _ in 0..20_000 {
            let mut c = [[0.0f32; 4]; 3];
            for axis in c.iter_mut() {
                for v in axis.iter_mut() {
                    *v = (r.next_f32() - 0.5) * 2000.0;
                }
            }
            let s = [r.next_u32(), r.next_u32(), r.next_u32(), r.next_u32()];
            let v = gradient3_x4(c[0], c[1], c[2], s);
            for k in 0..4 {
                // Equal as numbers (a zero's sign may differ: the kernel masks to +0).
                assert_eq!(v[k], gradient3_xyz(c[0][k], c[1][k], c[2][k], s[k]));
            }
        }
    }

    #[test]
    fn gradient_table_matches_bit_layout() {
        // E[g gᵀ] = ¾ I exactly over the 32 entries.
        let mut m = [[0.0f32; 3]; 3];
        for g in GRADS.iter() {
            for i in 0..3 {
                for j in 0..3 {
                    m[i][j] += g[i] * g[j] / 32.0;
                }
            }
        }
        for (i, row) in m.iter().enumerate() {
            for (j, &v) in row.iter().enumerate() {
                assert_eq!(v, if i == j { 0.75 } else { 0.0 });
            }
        }
    }
}
