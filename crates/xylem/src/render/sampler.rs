//! The numbers of one pixel sample, drawn from (seed, pixel, sample) alone so that any frame,
//! tile or thread order gives the same bits: the camera's from a scrambled Sobol point, the
//! lighting's from a random stream.

use crate::math::Pcg32;

/// The film and lens numbers of sample `sample` of pixel `pixel_index`: point `sample` of a 4D
/// Owen-scrambled Sobol sequence (Burley 2020, "Practical Hash-based Owen Scrambling", JCGT
/// 9(4), through the `sobol_burley` crate), scrambled and shuffled per (seed, pixel). A pixel's
/// first 2^m samples form a (0, m, 2)-net in the film's two dimensions (one sample in every
/// elementary interval of area 2^−m: a 4 × 4 grid at 16 spp), so the sub-pixel texture of the
/// wood averages out faster than independent samples do; pixels stay independent of each
/// other. The sequence holds 2^16 points: each further 2^16 samples take a fresh scramble.
pub(crate) fn pixel_sample(seed: u64, pixel_index: u64, sample: u32) -> [f32; 4] {
    let block = u64::from(sample >> 16);
    let scramble = splitmix64(seed ^ splitmix64(pixel_index ^ (block << 48) ^ (1 << 63)));
    sobol_burley::sample_4d(sample & 0xFFFF, 0, scramble as u32)
}

/// The lighting random stream of sample `sample` of pixel `pixel_index`: a PCG32 stream keyed by
/// a SplitMix64 hash (Steele et al. 2014) of (seed, sample) with the pixel index as stream
/// selector.
#[inline]
pub(crate) fn sample_rng(seed: u64, pixel_index: u64, sample: u32) -> Pcg32 {
    let key = splitmix64(seed ^ splitmix64(((sample as u64) << 2) | 1));
    Pcg32::new(key, pixel_index)
}

/// SplitMix64 finaliser (Steele, Lea, Flood 2014): a bijective 64-bit mix.
fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One cell of a `n` × `n` grid over the unit square.
    fn cell(x: f32, y: f32, n: usize) -> usize {
        let c = |v: f32| ((v * n as f32) as usize).min(n - 1);
        c(y) * n + c(x)
    }

    /// A pixel's first 16 film points fill every cell of a 4 × 4 grid (and its first 64 an
    /// 8 × 8 one), in every pixel; independent points (the control) almost never do.
    #[test]
    fn a_pixels_film_points_are_stratified() {
        for (n, spp) in [(4, 16u32), (8, 64)] {
            for pixel in 0..50u64 {
                let mut seen = vec![false; n * n];
                for s in 0..spp {
                    let u = pixel_sample(7, pixel, s);
                    seen[cell(u[0], u[1], n)] = true;
                }
                assert!(seen.iter().all(|&c| c), "pixel {pixel}, {spp} spp");
            }
        }
        let mut full = 0;
        for pixel in 0..50u64 {
            let mut rng = sample_rng(7, pixel, 0);
            let mut seen = [false; 16];
            for _ in 0..16 {
                let u = rng.next_vec2();
                seen[cell(u.x, u.y, 4)] = true;
            }
            full += seen.iter().all(|&c| c) as usize;
        }
        assert!(
            full <= 1,
            "independent points filled the grid in {full} of 50 pixels"
        );
    }

    /// Pixels and seeds get different scrambles: the same sample's points differ.
    #[test]
    fn pixels_and_seeds_are_scrambled_apart() {
        let a = pixel_sample(7, 3, 0);
        assert_ne!(a, pixel_sample(7, 4, 0));
        assert_ne!(a, pixel_sample(8, 3, 0));
        assert_ne!(pixel_sample(7, 3, 5), pixel_sample(7, 3, 5 + (1 << 16)));
    }
}
