//! Integer hashes on lattice coordinates. Two kinds, both pure functions of their inputs:
//!
//! - [`pcg3d`]: the well-mixed 3D → 3D hash of Jarzynski & Olano 2020 ("Hash Functions for GPU
//!   Rendering", JCGT 9(3), §2 "pcg3d"). Used wherever a cell needs several good random numbers
//!   (sparse convolution impulses, Worley feature points).
//! - [`lattice`]: a one-multiply hash for the hot loop of gradient / value noise: the spatial hash of
//!   Teschner et al. 2003 ("Optimized Spatial Hashing for Collision Detection of Deformable
//!   Objects", VMV, xor of coordinates times large odd constants) followed by one Knuth
//!   multiplicative scramble (TAOCP vol. 3 §6.4) whose *top* bits are used. Both are integer
//!   only, so precision does not degrade far from the origin (unlike `fract(sin(x))`).

/// Jarzynski & Olano 2020, "pcg3d": three rounds of an LCG step plus cross-lane mixing.
#[inline(always)]
pub fn pcg3d(v: [u32; 3]) -> [u32; 3] {
    let mut x = v[0].wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
    let mut y = v[1].wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
    let mut z = v[2].wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
    x = x.wrapping_add(y.wrapping_mul(z));
    y = y.wrapping_add(z.wrapping_mul(x));
    z = z.wrapping_add(x.wrapping_mul(y));
    x ^= x >> 16;
    y ^= y >> 16;
    z ^= z >> 16;
    x = x.wrapping_add(y.wrapping_mul(z));
    y = y.wrapping_add(z.wrapping_mul(x));
    z = z.wrapping_add(x.wrapping_mul(y));
    [x, y, z]
}

/// A 32-bit integer finaliser ("lowbias32", C. Wellons 2018, *Prospecting for Hash Functions*):
/// xorshift–multiply rounds with measured low avalanche bias. Used to derive streams of numbers
/// from one cell hash and to scramble seeds.
#[inline(always)]
pub fn mix32(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    x
}

/// Hash of an integer cell `(ix, iy, iz)` and a seed: [`pcg3d`] of the cell translated by a
/// seed-dependent offset, so different seeds see unrelated hash values.
#[inline(always)]
pub(crate) fn cell3(ix: i32, iy: i32, iz: i32, seed: u32) -> [u32; 3] {
    cell3_offset(ix, iy, iz, &seed_offsets(seed))
}

/// [`cell3`] with the seed's [`seed_offsets`] computed once by the caller (hot loops).
#[inline(always)]
pub(crate) fn cell3_offset(ix: i32, iy: i32, iz: i32, s: &[u32; 3]) -> [u32; 3] {
    pcg3d([
        (ix as u32).wrapping_add(s[0]),
        (iy as u32).wrapping_add(s[1]),
        (iz as u32).wrapping_add(s[2]),
    ])
}

/// Three large pseudo-random lattice translations derived from a seed (see [`cell3`]).
#[inline(always)]
pub(crate) fn seed_offsets(seed: u32) -> [u32; 3] {
    let a = mix32(seed ^ 0x9e37_79b9);
    [a, mix32(a ^ 0x85eb_ca6b), mix32(a ^ 0xc2b2_ae35)]
}

/// Teschner et al. 2003 constants (large primes) for the per-axis multiply of [`lattice`].
pub(crate) const PRIME_X: u32 = 73_856_093;
/// Teschner et al. 2003's prime for y.
pub(crate) const PRIME_Y: u32 = 19_349_663;
/// Teschner et al. 2003's prime for z.
pub(crate) const PRIME_Z: u32 = 83_492_791;
/// Knuth's multiplicative-hash constant ⌊2^32/φ⌋ (odd).
pub(crate) const KNUTH: u32 = 0x9e37_79b1;

/// The cheap lattice hash: `((x·P1) ^ (y·P2) ^ (z·P3) ^ s) · K`, returning all 32 bits; callers use
/// the high bits. Callers pass the per-axis products (`x·P1` ...), so neighbouring corners cost one
/// add each. `s` is a seed already scrambled with [`mix32`].
#[inline(always)]
pub fn lattice(xp: u32, yp: u32, zp: u32, s: u32) -> u32 {
    let h = (xp ^ yp ^ zp ^ s).wrapping_mul(KNUTH);
    h ^ (h >> 15)
}

/// Uniform in [0, 1) from the top 24 bits of a hash.
#[inline(always)]
pub(crate) fn unit_f32(h: u32) -> f32 {
    (h >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// Uniform in [-1, 1) from the top 24 bits of a hash.
#[inline(always)]
pub(crate) fn signed_f32(h: u32) -> f32 {
    (h >> 8) as f32 * (2.0 / 16_777_216.0) - 1.0
}

/// `x as i32` (truncation, saturating, NaN → 0) from an unchecked conversion and selects: the
/// same values, but a loop over many x vectorises (a plain `as` compiles to scalar code there).
#[inline(always)]
pub(crate) fn saturating_i32(x: f32) -> i32 {
    const LIMIT: f32 = 2_147_483_648.0; // 2³¹
    let inside = x.abs() < LIMIT;
    // SAFETY: the argument is finite and below 2³¹ in magnitude.
    let t = unsafe { (if inside { x } else { 0.0 }).to_int_unchecked::<i32>() };
    if inside {
        t
    } else if x >= LIMIT {
        i32::MAX
    } else if x <= -LIMIT {
        i32::MIN
    } else {
        0
    }
}

/// `⌊x⌋` as an integer without a libm call (`f32::floor` is not an instruction on baseline
/// x86-64). Exact for |x| < 2^31; vectorises (through [`saturating_i32`]).
#[inline(always)]
pub(crate) fn floor_i32(x: f32) -> i32 {
    let i = saturating_i32(x);
    i - ((x < i as f32) as i32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn saturating_i32_is_as() {
        let mut r = crate::math::Pcg32::new(11, 0);
        let check = |x: f32| assert_eq!(saturating_i32(x), x as i32, "{x}");
        for x in [
            0.0f32,
            -0.0,
            0.5,
            -0.5,
            -1.0,
            2_147_483_520.0,
            -2_147_483_648.0,
            2_147_483_648.0,
            -2_147_483_904.0,
            f32::MAX,
            f32::MIN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
        ] {
            check(x);
        }
        for _ in 0..100_000 {
            let x = (r.next_f32() * 2.0 - 1.0) * 10f32.powf(r.next_f32() * 12.0);
            check(x);
            check(x.round());
        }
    }

    #[test]
    fn floor_matches_std() {
        for x in [
            -2.5f32, -2.0, -0.0, 0.0, 0.3, 1.0, 1.9999, -1e-7, 12345.6, -98765.4,
        ] {
            assert_eq!(floor_i32(x), x.floor() as i32, "{x}");
        }
    }

    #[test]
    fn pcg3d_avalanche() {
        // Flipping one of the low 16 bits of an input lane (what differs between nearby cells and
        // impulse indices) should flip each output bit with probability 1/2. Over 2000 inputs ×
        // 48 flips × 96 output bits, σ of the fraction ≈ 1e-4; tolerance 0.01 (≫ 5σ). (pcg3d mixes
        // the top input bits less: measured 0.27 for bit 31 of z; we never rely on those alone.)
        let mut r = crate::math::Pcg32::new(3, 0);
        let (mut flipped, mut total) = (0u64, 0u64);
        for _ in 0..2000 {
            let v = [r.next_u32(), r.next_u32(), r.next_u32()];
            let h = pcg3d(v);
            for lane in 0..3 {
                for bit in 0..16 {
                    let mut w = v;
                    w[lane] ^= 1 << bit;
                    let g = pcg3d(w);
                    flipped += (0..3)
                        .map(|k| (h[k] ^ g[k]).count_ones() as u64)
                        .sum::<u64>();
                    total += 96;
                }
            }
        }
        let frac = flipped as f64 / total as f64;
        assert!((frac - 0.5).abs() < 0.01, "avalanche fraction {frac}");
    }

    #[test]
    fn seeds_change_cell_hashes() {
        let same = (0..1000)
            .filter(|&i| cell3(i, 2 * i, -i, 1) == cell3(i, 2 * i, -i, 2))
            .count();
        assert_eq!(same, 0);
    }
}
