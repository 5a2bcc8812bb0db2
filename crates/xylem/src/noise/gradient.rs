//! Gradient noise: Perlin's improved noise (Perlin 2002, "Improving Noise", SIGGRAPH) in 1D and 3D
//! with its analytic gradient. Quintic fade `6t⁵ − 15t⁴ + 10t³` (Perlin 2002 §2) so the second
//! derivative is continuous across cells; Perlin's 12 cube-edge gradients mixed with the cube
//! diagonals for an isotropic second moment (see [`GRADS`]). The gradient of the trilinear blend
//! follows I. Quilez, "Gradient noise derivatives" (2017). A 4-lane SSE2 kernel
//! ([`gradient3_x4`]) evaluates four points at once — fBm uses it across octaves.

use super::hash::{mix32, saturating_i32};
#[cfg(target_arch = "x86_64")]
use super::hash::{KNUTH, PRIME_X, PRIME_Y, PRIME_Z};
#[cfg(target_arch = "x86_64")]
use super::lanes::Lanes;
use super::lattice::{corner_hashes, end_values, trilinear, trilinear_grad};
use crate::simd::{simd_wide, Simd};
use glam::Vec3;

/// Perlin 2002 quintic fade.
#[inline(always)]
pub fn fade(t: f32) -> f32 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

/// Derivative of [`fade`]: `30 t² (t − 1)²`.
#[inline(always)]
pub(crate) fn fade_d(t: f32) -> f32 {
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
    saturating_i32(x) - ((x.to_bits() >> 31) as i32)
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
    let h = corner_hashes(ix, iy, iz, s);
    let n000 = dot(grad(h[0]), x0, y0, z0);
    let n100 = dot(grad(h[1]), x1, y0, z0);
    let n010 = dot(grad(h[2]), x0, y1, z0);
    let n110 = dot(grad(h[3]), x1, y1, z0);
    let n001 = dot(grad(h[4]), x0, y0, z1);
    let n101 = dot(grad(h[5]), x1, y0, z1);
    let n011 = dot(grad(h[6]), x0, y1, z1);
    let n111 = dot(grad(h[7]), x1, y1, z1);
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

/// [`gradient3_grad`] with a scrambled seed. ∇n = blend of the corner gradients + fade′ times the
/// derivative of the blend of the corner values g·(p − corner).
#[inline(always)]
pub(crate) fn gradient3_grad_s(p: Vec3, s: u32) -> (f32, Vec3) {
    let (ix, iy, iz) = (cell_of(p.x), cell_of(p.y), cell_of(p.z));
    let f0 = Vec3::new(p.x - ix as f32, p.y - iy as f32, p.z - iz as f32);
    let h = corner_hashes(ix, iy, iz, s);
    let g: [Vec3; 8] = std::array::from_fn(|k| {
        let g = grad(h[k]);
        Vec3::new(g[0], g[1], g[2])
    });
    // Corner k's offset: f0 − 1 along the axes whose bit is set in k.
    let v: [f32; 8] = std::array::from_fn(|k| {
        let d = Vec3::new(
            f0.x - (k & 1) as f32,
            f0.y - ((k >> 1) & 1) as f32,
            f0.z - ((k >> 2) & 1) as f32,
        );
        g[k].dot(d)
    });
    let u = Vec3::new(fade(f0.x), fade(f0.y), fade(f0.z));
    let du = Vec3::new(fade_d(f0.x), fade_d(f0.y), fade_d(f0.z));
    let (value, dv) = trilinear_grad(&v, u, du);
    (value, trilinear(&g, u) + dv)
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
    let i = cell_of(x);
    let t = x - i as f32;
    let (g0, g1) = end_values(i, mix32(seed));
    let (a, b) = (g0 * t, g1 * (t - 1.0));
    let u = fade(t);
    (a + u * (b - a), g0 + u * (g1 - g0) + fade_d(t) * (b - a))
}

/// [`gradient3`] at every point of `points`, written to `out` (same length): the batch form for
/// callers with many points (image slices, benchmarks). Runs the lane kernel on 16 (AVX-512),
/// 8 (AVX2) or 4 (SSE2, the x86-64 baseline) points at once, whichever the CPU has (checked at
/// run time, [`Simd::best`]); the last `len % lanes` points and non-x86 targets use the scalar
/// kernel. Every path gives the values of [`gradient3`] (tested; a zero may differ in sign).
///
/// # Panics
/// If `points.len() != out.len()`.
pub fn gradient3_many(points: &[Vec3], seed: u32, out: &mut [f32]) {
    gradient3_many_with(Simd::best(), points, seed, out)
}

/// [`gradient3_many`] on the instruction set `simd`, or the best one the CPU has if it lacks it
/// (for comparing the paths; [`gradient3_many`] picks the best).
pub fn gradient3_many_with(simd: Simd, points: &[Vec3], seed: u32, out: &mut [f32]) {
    assert_eq!(
        points.len(),
        out.len(),
        "gradient3_many: {} points but {} outputs",
        points.len(),
        out.len()
    );
    let s = mix32(seed);
    let done = match simd.min(Simd::best()) {
        Simd::Scalar => 0,
        // SAFETY: each arm runs only where `Simd::best` detected its level's features.
        #[cfg(target_arch = "x86_64")]
        Simd::Sse2 => unsafe { many_sse2(points, s, out) },
        #[cfg(target_arch = "x86_64")]
        Simd::Avx2 => unsafe { many_avx2(points, s, out) },
        #[cfg(target_arch = "x86_64")]
        Simd::Avx512 => unsafe { many_avx512(points, s, out) },
        #[cfg(not(target_arch = "x86_64"))]
        _ => 0,
    };
    for (p, o) in points[done..].iter().zip(&mut out[done..]) {
        *o = gradient3_xyz(p.x, p.y, p.z, s);
    }
}

#[cfg(target_arch = "x86_64")]
unsafe fn many_sse2(points: &[Vec3], s: u32, out: &mut [f32]) -> usize {
    many::<std::arch::x86_64::__m128>(points, s, out)
}

simd_wide! {
    unsafe fn many_avx2 / many_avx512(points: &[Vec3], s: u32, out: &mut [f32]) -> usize
    where lanes = L
    {
        many::<L>(points, s, out)
    }
}

/// The lane kernel over whole groups of `L::N` points; returns how many points it wrote.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn many<L: Lanes>(points: &[Vec3], s: u32, out: &mut [f32]) -> usize {
    let s = L::splat_i(s);
    let groups = points.len() / L::N;
    for (p, o) in points.chunks_exact(L::N).zip(out.chunks_exact_mut(L::N)) {
        let (x, y, z) = L::load_xyz(p);
        kernel(x, y, z, s).store(o);
    }
    groups * L::N
}

/// The scalar `lattice` hash on lanes: `(x ^ y ^ z ^ s)·K`, then `h ^ (h >> 15)`.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn hash<L: Lanes>(x: L::I, y: L::I, z: L::I, s: L::I) -> L::I {
    let h = L::mul_lo(L::xor_i(L::xor_i(x, y), L::xor_i(z, s)), L::splat_i(KNUTH));
    L::xor_i(h, L::shr(h, 15))
}

/// g·d for the gradient picked by the top 5 bits of `h` (layout of [`GRADS`]): sign flips by xor
/// into the float sign bit, the dropped axis masked to +0; summed in the scalar `dot`'s order.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn gdot<L: Lanes>(h: L::I, dx: L, dy: L, dz: L) -> L {
    let axis = L::and_i(L::shr(h, 27), L::splat_i(3));
    let tx = dx.flip_sign(h, 31).zero_where_eq(axis, 0);
    let ty = dy.flip_sign(h, 30).zero_where_eq(axis, 1);
    let tz = dz.flip_sign(h, 29).zero_where_eq(axis, 2);
    tx.add(ty).add(tz)
}

/// [`fade`] on lanes, in the same operation order.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn fade_lanes<L: Lanes>(t: L) -> L {
    let inner = t
        .mul(t.mul(L::splat(6.0)).sub(L::splat(15.0)))
        .add(L::splat(10.0));
    t.mul(t).mul(t).mul(inner)
}

#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn lerp<L: Lanes>(a: L, b: L, t: L) -> L {
    a.add(t.mul(b.sub(a)))
}

/// [`gradient3_xyz`] on `L::N` points at once (lanes are points, every instruction vertical),
/// scrambled seeds `s` per lane. Same operations in the same order as the scalar kernel.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) unsafe fn kernel<L: Lanes>(x: L, y: L, z: L, s: L::I) -> L {
    let (ix, x0) = x.cell();
    let (iy, y0) = y.cell();
    let (iz, z0) = z.cell();
    let one = L::splat(1.0);
    let (x1, y1, z1) = (x0.sub(one), y0.sub(one), z0.sub(one));
    let (px, py, pz) = (
        L::splat_i(PRIME_X),
        L::splat_i(PRIME_Y),
        L::splat_i(PRIME_Z),
    );
    let (xa, ya, za) = (L::mul_lo(ix, px), L::mul_lo(iy, py), L::mul_lo(iz, pz));
    let (xb, yb, zb) = (L::add_i(xa, px), L::add_i(ya, py), L::add_i(za, pz));
    let n000 = gdot(hash::<L>(xa, ya, za, s), x0, y0, z0);
    let n100 = gdot(hash::<L>(xb, ya, za, s), x1, y0, z0);
    let n010 = gdot(hash::<L>(xa, yb, za, s), x0, y1, z0);
    let n110 = gdot(hash::<L>(xb, yb, za, s), x1, y1, z0);
    let n001 = gdot(hash::<L>(xa, ya, zb, s), x0, y0, z1);
    let n101 = gdot(hash::<L>(xb, ya, zb, s), x1, y0, z1);
    let n011 = gdot(hash::<L>(xa, yb, zb, s), x0, y1, z1);
    let n111 = gdot(hash::<L>(xb, yb, zb, s), x1, y1, z1);
    let (u, v, w) = (fade_lanes(x0), fade_lanes(y0), fade_lanes(z0));
    let a = lerp(n000, n100, u);
    let b = lerp(n010, n110, u);
    let c = lerp(n001, n101, u);
    let d = lerp(n011, n111, u);
    let e = lerp(a, b, v);
    let f = lerp(c, d, v);
    lerp(e, f, w)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Pcg32;

    /// Test points: random over ±1000 (every sign and many cells) plus values where the cell
    /// rule matters: integers, negative integers, ±0, values just below an integer.
    fn awkward_points(n: usize, seed: u64) -> Vec<Vec3> {
        let mut r = Pcg32::new(seed, 0);
        let special = [
            0.0f32,
            -0.0,
            1.0,
            -1.0,
            -3.0,
            2.5,
            -2.5,
            0.999_999_9,
            -1e-7,
            1e-30,
        ];
        (0..n)
            .map(|i| {
                let mut c = [0.0f32; 3];
                for v in c.iter_mut() {
                    *v = if r.next_u32().is_multiple_of(4) {
                        special[(r.next_u32() % special.len() as u32) as usize]
                    } else {
                        (r.next_f32() - 0.5) * 2000.0 * if i % 2 == 0 { 1.0 } else { 1e-3 }
                    };
                }
                Vec3::from(c)
            })
            .collect()
    }

    #[test]
    fn every_simd_path_equals_scalar() {
        // Same operations in the same order, so the same numbers (a zero's sign may differ: the
        // lane kernel masks a dropped axis to +0 where the scalar one multiplies by 0). Lengths
        // that are not multiples of the lane count exercise the scalar tail.
        for simd in Simd::ALL {
            if simd > Simd::best() {
                eprintln!("{simd:?} not on this CPU: not tested here");
                continue;
            }
            for (len, seed) in [(0usize, 1u32), (1, 2), (15, 3), (33, 4), (20_003, 5)] {
                let pts = awkward_points(len, seed as u64);
                let mut out = vec![f32::NAN; len];
                gradient3_many_with(simd, &pts, seed, &mut out);
                for (p, &v) in pts.iter().zip(&out) {
                    assert_eq!(v, gradient3(*p, seed), "{simd:?} at {p}");
                }
            }
        }
    }

    #[test]
    #[should_panic(expected = "3 points but 2 outputs")]
    fn batch_lengths_must_match() {
        gradient3_many(&[Vec3::ZERO; 3], 1, &mut [0.0; 2]);
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
