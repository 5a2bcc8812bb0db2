//! The numbers of one pixel sample, drawn from (seed, pixel, sample) alone so that any frame,
//! tile or thread order gives the same bits: the camera's and the path's from scrambled Sobol
//! points.

/// The film and lens numbers of sample `sample` of pixel `pixel_index`: point `sample` of a 4D
/// Owen-scrambled Sobol sequence (Burley 2020, "Practical Hash-based Owen Scrambling", JCGT
/// 9(4), through the `sobol_burley` crate), scrambled and shuffled per (seed, pixel). A pixel's
/// first 2^m samples form a (0, m, 2)-net in the film's two dimensions (one sample in every
/// elementary interval of area 2^−m: a 4 × 4 grid at 16 spp), so the sub-pixel texture of the
/// wood averages out faster than independent samples do; pixels stay independent of each
/// other. The sequence holds 2^16 points: each further 2^16 samples take a fresh scramble.
#[inline(always)]
pub(crate) fn pixel_sample(seed: u64, pixel_index: u64, sample: u32) -> [f32; 4] {
    PixelKeys::new(seed, pixel_index, sample).film(sample)
}

/// What the samples of one pixel (and block of 2^16 samples) share: the film points' scramble
/// ([`pixel_sample`]) and the path numbers' key ([`PathNumbers`]), two SplitMix64 chains each,
/// worked out once for all of a pixel's samples where they are taken one after the other.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PixelKeys {
    pixel_index: u64,
    block: u32,
    film: SobolScramble,
    path: PathNumbers,
}

impl PixelKeys {
    /// The keys of sample `sample`'s block of pixel `pixel_index` under `seed`.
    #[inline(always)]
    pub(crate) fn new(seed: u64, pixel_index: u64, sample: u32) -> Self {
        let block = sample >> 16;
        let salted = |salt: u64| {
            splitmix64(seed ^ splitmix64(pixel_index ^ (u64::from(block) << 48) ^ salt))
        };
        PixelKeys {
            pixel_index,
            block,
            film: SobolScramble::new(salted(1 << 63) as u32),
            path: PathNumbers::keyed(salted(1 << 62)),
        }
    }

    /// Whether these are the keys of sample `sample` of pixel `pixel_index`.
    #[inline(always)]
    pub(crate) fn cover(&self, pixel_index: u64, sample: u32) -> bool {
        self.pixel_index == pixel_index && self.block == sample >> 16
    }

    /// The film and lens numbers of sample `sample` ([`pixel_sample`]).
    #[inline(always)]
    pub(crate) fn film(&self, sample: u32) -> [f32; 4] {
        self.film.point(sample & 0xFFFF)
    }

    /// The path numbers of sample `sample` ([`PathNumbers::new`]).
    #[inline(always)]
    pub(crate) fn path(&self, sample: u32) -> PathNumbers {
        PathNumbers {
            index: sample & 0xFFFF,
            ..self.path
        }
    }
}

/// Point `index` (below 2^16) of the 4D Owen-scrambled Sobol sequence under `seed`: the bits of
/// `sobol_burley::sample_4d(index, 0, seed)` (Burley 2020: the index shuffled by a nested
/// uniform scramble, the Sobol matrix product, each dimension Owen-scrambled under its own
/// hashed seed), computed faster: the matrix product as two lookups of byte tables
/// ([`SOBOL_BYTES`]) instead of the crate's loop over the index's bits (whose trip count the
/// branch predictor cannot guess), and the four dimensions' integer multiplies lane by lane
/// instead of the crate's SSE2 emulation of a four-lane multiply (x86-64's baseline has none).
/// 39 → 22 ns a point on the 2-core Xeon (notes/render.md); three points a camera sample.
#[inline]
fn sobol_4d(index: u32, seed: u32) -> [f32; 4] {
    sobol_4d_by(&SOBOL_BYTES, index, seed)
}

/// [`sobol_4d`] with the byte tables given (the test's control changes them).
#[inline(always)]
fn sobol_4d_by(bytes: &[[[u32; 4]; 256]; 2], index: u32, seed: u32) -> [f32; 4] {
    SobolScramble::new(seed).point_by(bytes, index)
}

/// The hashed seeds of one scramble of the Sobol sequence ([`sobol_4d`]): the index shuffle's
/// and each dimension's. A scramble whose points are drawn again and again (a pixel's film
/// points, a role's first-vertex points) hashes its seed once; each point then starts its
/// chain of multiplications without the hash's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SobolScramble {
    shuffle: u32,
    dims: [u32; 4],
}

impl SobolScramble {
    /// The scramble of `seed`, as `sobol_burley` hashes it (dimension set 0).
    #[inline(always)]
    fn new(seed: u32) -> Self {
        use sobol_burley::parts::hash;
        let dim_seed = seed.wrapping_mul(0x9c8f_2d3b);
        let salt = [0x912f_69ba, 0x174f_18ab, 0x691e_72ca, 0xb40c_c1b8];
        SobolScramble {
            shuffle: hash(seed ^ 0x79c6_8e4a),
            dims: salt.map(|s| hash(dim_seed ^ s)),
        }
    }

    /// Point `index` (below 2^16) under this scramble.
    #[inline(always)]
    fn point(&self, index: u32) -> [f32; 4] {
        self.point_by(&SOBOL_BYTES, index)
    }

    /// [`SobolScramble::point`] with the byte tables given.
    #[inline(always)]
    fn point_by(&self, bytes: &[[[u32; 4]; 256]; 2], index: u32) -> [f32; 4] {
        use sobol_burley::parts::{owen_scramble_rev, u32_to_f32_norm};
        let shuffled = owen_scramble_rev(index.reverse_bits(), self.shuffle);
        let hi = &bytes[0][(shuffled >> 24) as usize];
        let lo = &bytes[1][((shuffled >> 16) & 0xFF) as usize];
        std::array::from_fn(|d| {
            let sobol = hi[d] ^ lo[d];
            u32_to_f32_norm(owen_scramble_rev(sobol, self.dims[d]).reverse_bits())
        })
    }
}

/// The direction numbers of the first four Sobol dimensions (Joe and Kuo 2008, as the
/// `sobol_burley` crate tabulates them), bit-reversed: row k is what the Sobol matrix product
/// XORs in for bit 31 − k of a bit-reversed index (a test compares them with the crate's).
const SOBOL_DIRECTIONS: [[u32; 4]; 16] = [
    [0x0000_0001, 0x0000_0001, 0x0000_0001, 0x0000_0001],
    [0x0000_0002, 0x0000_0003, 0x0000_0003, 0x0000_0003],
    [0x0000_0004, 0x0000_0005, 0x0000_0006, 0x0000_0004],
    [0x0000_0008, 0x0000_000f, 0x0000_0009, 0x0000_000a],
    [0x0000_0010, 0x0000_0011, 0x0000_0017, 0x0000_001f],
    [0x0000_0020, 0x0000_0033, 0x0000_003a, 0x0000_002e],
    [0x0000_0040, 0x0000_0055, 0x0000_0071, 0x0000_0045],
    [0x0000_0080, 0x0000_00ff, 0x0000_00a3, 0x0000_00c9],
    [0x0000_0100, 0x0000_0101, 0x0000_0116, 0x0000_011b],
    [0x0000_0200, 0x0000_0303, 0x0000_0339, 0x0000_02a4],
    [0x0000_0400, 0x0000_0505, 0x0000_0677, 0x0000_079a],
    [0x0000_0800, 0x0000_0f0f, 0x0000_09aa, 0x0000_0b67],
    [0x0000_1000, 0x0000_1111, 0x0000_1601, 0x0000_101e],
    [0x0000_2000, 0x0000_3333, 0x0000_3903, 0x0000_302d],
    [0x0000_4000, 0x0000_5555, 0x0000_7706, 0x0000_4041],
    [0x0000_8000, 0x0000_ffff, 0x0000_aa09, 0x0000_a0c3],
];

/// The Sobol matrix product by bytes: `SOBOL_BYTES[h][b]` is the XOR of the direction numbers
/// of byte b's set bits, for the top byte (h = 0: bits 31–24, rows 0–7) and the next one
/// (h = 1: bits 23–16, rows 8–15) of a bit-reversed index below 2^16. 8 KiB.
static SOBOL_BYTES: [[[u32; 4]; 256]; 2] = [sobol_byte_table(0), sobol_byte_table(8)];

/// One table of [`SOBOL_BYTES`]: bit j of the byte (bit 31 − `first` − (7 − j) of the
/// index) takes row `first` + 7 − j.
const fn sobol_byte_table(first: usize) -> [[u32; 4]; 256] {
    let mut table = [[0u32; 4]; 256];
    let mut b = 0;
    while b < 256 {
        let mut j = 0;
        while j < 8 {
            if b & (1 << j) != 0 {
                let row = SOBOL_DIRECTIONS[first + 7 - j];
                let mut d = 0;
                while d < 4 {
                    table[b][d] ^= row[d];
                    d += 1;
                }
            }
            j += 1;
        }
        b += 1;
    }
    table
}

/// The numbers a pixel sample's path draws after its camera ray, each found by its role — the
/// vertex's depth and what it samples — rather than by its place in a stream: pbrt-v4's
/// padded Sobol sampler (Pharr, Jakob, Humphreys 2023, §8.7.4). Every role takes point
/// `sample` of the same 4D Owen-scrambled Sobol sequence as [`pixel_sample`], under a scramble
/// (and index shuffle) of its own, so each role's first 2^m samples in a pixel are stratified
/// like the film's while different roles stay independent of one another. Keyed by role, a
/// vertex gets the same numbers whichever lights, frames or earlier branches a render has.
///
/// Only the first [`STRATIFIED_DEPTH`] vertices take Sobol points (about 220 instructions
/// each); deeper ones take independent numbers hashed from the same key and role (a few
/// SplitMix64 steps), where stratification gains little — a path that far has already
/// scattered its strata over several dimensions — and the Sobol points cost 15 % of a
/// Cornell box render's instructions.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PathNumbers {
    /// The (seed, pixel, sample block) part of every role's scramble.
    key: u64,
    /// The point's index in the sequence.
    index: u32,
    /// The first vertex's scrambles of light 0 and of the bounce (roles 0 and 1), which
    /// nearly every path draws: [`PathNumbers::scramble`] of them, hashed once a pixel.
    first: [SobolScramble; 2],
}

impl PathNumbers {
    pub(crate) fn new(seed: u64, pixel_index: u64, sample: u32) -> Self {
        PixelKeys::new(seed, pixel_index, sample).path(sample)
    }

    /// The numbers of key `key` (point index 0).
    #[inline(always)]
    fn keyed(key: u64) -> Self {
        let scramble = |role| SobolScramble::new(Self::scramble(key, 0, role, 0));
        PathNumbers {
            key,
            index: 0,
            first: [scramble(0), scramble(1)],
        }
    }

    /// The Sobol scramble of role `role` at vertex `depth` (below [`STRATIFIED_DEPTH`]) for
    /// the points of block `block` (indices `block` · 2^16 on).
    #[inline(always)]
    fn scramble(key: u64, depth: u32, role: u64, block: u32) -> u32 {
        let scramble = splitmix64(key ^ role_hash(depth, role));
        match block {
            0 => scramble as u32,
            _ => splitmix64(scramble ^ u64::from(block)) as u32,
        }
    }

    /// The point of role `role` (a small integer, unique per role) at vertex `depth`.
    #[inline]
    fn point(&self, depth: u32, role: u64) -> [f32; 4] {
        self.point_at(depth, role, self.index)
    }

    /// [`PathNumbers::point`] at sequence index `index` (a split role's points sit at
    /// consecutive indices, [`PathNumbers::light_split`]). The Sobol points take indices below
    /// 2^16; each further block of 2^16 is scrambled on its own, as the samples' blocks are.
    #[inline(always)]
    fn point_at(&self, depth: u32, role: u64, index: u32) -> [f32; 4] {
        if depth < STRATIFIED_DEPTH {
            let block = index >> 16;
            if let (0, 0 | 1, 0) = (depth, role, block) {
                return self.first[role as usize].point(index);
            }
            return sobol_4d(index & 0xFFFF, Self::scramble(self.key, depth, role, block));
        }
        let scramble = splitmix64(self.key ^ role_hash(depth, role));
        let a = splitmix64(scramble ^ u64::from(index));
        let b = splitmix64(a);
        // The top 24 bits of each 32-bit half: uniform on [0, 1) in steps of 2^−24.
        let u = |x: u64| (x >> 40) as f32 * (1.0 / (1u64 << 24) as f32);
        [u(a), u(a << 32), u(b), u(b << 32)]
    }

    /// The two numbers that sample light `light` once at vertex `depth` (the renderer takes
    /// them through [`PathNumbers::light_split`], which gives these with n = 1; the tests
    /// compare against this form).
    #[cfg(test)]
    pub(crate) fn light(&self, depth: u32, light: usize) -> [f32; 2] {
        let p = self.point(depth, (light as u64) << 1);
        [p[0], p[1]]
    }

    /// The two numbers of the `k`-th of `n` samples of light `light` at vertex `depth`: the
    /// sequence's points n·i + k for pixel sample i, so a pixel's n · spp samples of the light
    /// are one Owen-scrambled Sobol sequence (each sample's n a stratified block of it, the
    /// whole a (0, m, 2)-net where n · spp = 2^m). With n = 1, [`PathNumbers::light`].
    #[inline(always)]
    pub(crate) fn light_split(&self, depth: u32, light: usize, k: u32, n: u32) -> [f32; 2] {
        let p = self.point_at(depth, (light as u64) << 1, self.index * n + k);
        [p[0], p[1]]
    }

    /// The numbers of the continuation from vertex `depth`: the direction's two (the first
    /// two Sobol dimensions, the pair stratified as a (0, m, 2)-net), the lobe choice and the
    /// Russian roulette test of the path it starts (each stratified on its own).
    #[inline(always)]
    pub(crate) fn bounce(&self, depth: u32) -> [f32; 4] {
        self.point(depth, 1)
    }
}

/// The vertices whose path numbers are Sobol points ([`PathNumbers`]): the camera's first hit
/// (its direct lighting and the first bounce's direction). With the next vertex too the
/// Cornell box's error fell a little further but the small Mitsuba cross-check flagged one
/// pixel at its fixed seeds (no bias: 64 seeds each put it within 1.7σ; notes/render.md).
const STRATIFIED_DEPTH: u32 = 1;

/// SplitMix64 of role `role` at vertex `depth` (part of every point's scramble), from a table
/// for the depths and roles most points have: one load instead of a chain of two
/// multiplications on each point's critical path.
#[inline(always)]
fn role_hash(depth: u32, role: u64) -> u64 {
    const TABLE: [[u64; ROLES]; DEPTHS] = {
        let mut t = [[0; ROLES]; DEPTHS];
        let mut d = 0;
        while d < DEPTHS {
            let mut r = 0;
            while r < ROLES {
                t[d][r] = role_key(d as u32, r as u64);
                r += 1;
            }
            d += 1;
        }
        t
    };
    match TABLE
        .get(depth as usize)
        .and_then(|row| row.get(role as usize))
    {
        Some(&hash) => hash,
        None => role_key(depth, role),
    }
}

/// SplitMix64 of role `role` at vertex `depth`: what [`role_hash`] tabulates.
const fn role_key(depth: u32, role: u64) -> u64 {
    splitmix64(((depth as u64) << 33) | role)
}

/// The vertex depths and roles [`role_hash`] keeps in its table (the bounce and four lights).
const DEPTHS: usize = 16;
const ROLES: usize = 8;

/// SplitMix64 finaliser (Steele, Lea, Flood 2014): a bijective 64-bit mix.
pub(super) const fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The table-driven Sobol points are the `sobol_burley` crate's bit for bit: every index of
    /// the sequence under 64 seeds (and the direction numbers are the crate's). The control: a
    /// table built with one direction number changed gives other points.
    #[test]
    fn sobol_points_are_the_crates() {
        for (k, row) in SOBOL_DIRECTIONS.iter().enumerate() {
            for (d, &v) in row.iter().enumerate() {
                assert_eq!(v, sobol_burley::parts::sobol_rev(1 << (31 - k), d as u32));
            }
        }
        for s in 0..64u32 {
            let seed = splitmix64(u64::from(s)) as u32;
            for index in 0..1u32 << 16 {
                assert_eq!(
                    sobol_4d(index, seed),
                    sobol_burley::sample_4d(index, 0, seed),
                    "index {index}, seed {seed:#x}"
                );
            }
        }
        // Row 9's dimension 2 off by one bit: about half the points move.
        let mut wrong = SOBOL_BYTES;
        for (b, entry) in wrong[1].iter_mut().enumerate() {
            if b & (1 << 6) != 0 {
                entry[2] ^= 1 << 3;
            }
        }
        let moved = (0..4096u32)
            .filter(|&i| sobol_4d_by(&wrong, i, 7) != sobol_burley::sample_4d(i, 0, 7))
            .count();
        assert!(moved > 1000, "{moved} of 4096 points moved");
    }

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
            let mut rng = crate::math::Pcg32::new(7, pixel);
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

    /// Each role of the path is stratified in a pixel like the film (every 4 × 4 cell at 16
    /// spp) and independent of the other roles: over 4096 pixels the correlation of a light's
    /// numbers with the bounce's, another light's and the film's stays within 4 standard
    /// errors of 0 (σ = 1/√4096); the control — the film's own numbers — correlates fully.
    #[test]
    fn path_roles_are_stratified_and_independent() {
        for pixel in 0..50u64 {
            for role in 0..5 {
                let mut seen = [false; 16];
                for s in 0..16u32 {
                    let n = PathNumbers::new(7, pixel, s);
                    let strata = |u: f32| ((u * 16.0) as usize).min(15);
                    let k = match role {
                        0 => n.light(0, 0),
                        1 => n.light(0, 3),
                        2 => [n.bounce(0)[0], n.bounce(0)[1]],
                        // The lobe choice and the roulette: 16 strata of [0, 1) each.
                        3 => [n.bounce(0)[2], -1.0],
                        _ => [n.bounce(0)[3], -1.0],
                    };
                    let k = match k {
                        [u, v] if v >= 0.0 => cell(u, v, 4),
                        [u, _] => strata(u),
                    };
                    seen[k] = true;
                }
                assert!(seen.iter().all(|&c| c), "pixel {pixel}, role {role}");
            }
        }
        let corr = |f: &dyn Fn(u64) -> (f32, f32)| {
            let (n, mut sxy) = (4096, 0.0f64);
            for p in 0..n {
                let (a, b) = f(p);
                sxy += (f64::from(a) - 0.5) * (f64::from(b) - 0.5);
            }
            sxy / n as f64 * 12.0
        };
        let sample = 5;
        let light = |p| PathNumbers::new(3, p, sample).light(0, 0)[0];
        let limit = 4.0 / 64.0;
        for (what, c) in [
            (
                "bounce",
                corr(&|p| (light(p), PathNumbers::new(3, p, sample).bounce(0)[1])),
            ),
            (
                "light 1",
                corr(&|p| (light(p), PathNumbers::new(3, p, sample).light(0, 1)[0])),
            ),
            (
                "depth 1",
                corr(&|p| (light(p), PathNumbers::new(3, p, sample).light(1, 0)[0])),
            ),
            ("film", corr(&|p| (light(p), pixel_sample(3, p, sample)[0]))),
            (
                "deep",
                corr(&|p| (light(p), PathNumbers::new(3, p, sample).light(4, 0)[1])),
            ),
            (
                "deep bounce",
                corr(&|p| {
                    (
                        PathNumbers::new(3, p, sample).bounce(5)[0],
                        PathNumbers::new(3, p, sample).bounce(5)[3],
                    )
                }),
            ),
        ] {
            assert!(c.abs() < limit, "{what}: correlation {c}");
        }
        // The hashed numbers of deep vertices are uniform on [0, 1): mean within 4σ of ½.
        let deep: Vec<f32> = (0..4096u64)
            .flat_map(|p| PathNumbers::new(3, p, sample).bounce(6))
            .collect();
        assert!(deep.iter().all(|u| (0.0..1.0).contains(u)));
        let mean = deep.iter().map(|&u| f64::from(u)).sum::<f64>() / deep.len() as f64;
        let sigma = (1.0 / (12.0 * deep.len() as f64)).sqrt();
        assert!((mean - 0.5).abs() < 4.0 * sigma, "deep mean {mean}");
        let control = corr(&|p| (pixel_sample(3, p, sample)[0], pixel_sample(3, p, sample)[0]));
        assert!(control > 0.9, "control correlation {control}");
    }

    /// Pixels and seeds get different scrambles: the same sample's points differ.
    #[test]
    fn pixels_and_seeds_are_scrambled_apart() {
        let a = pixel_sample(7, 3, 0);
        assert_ne!(a, pixel_sample(7, 4, 0));
        assert_ne!(a, pixel_sample(8, 3, 0));
        assert_ne!(pixel_sample(7, 3, 5), pixel_sample(7, 3, 5 + (1 << 16)));
    }

    /// A light's split samples (`light_split`): with n = 1 the unsplit numbers bit for bit; with
    /// n = 4 a pixel's 4 × 16 samples fill every cell of an 8 × 8 grid, and each pixel sample's
    /// 4 one cell of a 2 × 2 grid each. Control: 4 samples drawn as the unsplit numbers of
    /// other lights (independent scrambles) fill the 8 × 8 grid in almost no pixel.
    #[test]
    fn split_light_numbers_are_one_stratified_sequence() {
        let mut controls = 0;
        for pixel in 0..50u64 {
            let (mut seen, mut control) = ([false; 64], [false; 64]);
            for s in 0..16u32 {
                let n = PathNumbers::new(7, pixel, s);
                assert_eq!(n.light_split(0, 2, 0, 1), n.light(0, 2));
                assert_eq!(n.light_split(2, 2, 0, 1), n.light(2, 2));
                let mut quads = [false; 4];
                for k in 0..4 {
                    let u = n.light_split(0, 2, k, 4);
                    seen[cell(u[0], u[1], 8)] = true;
                    quads[cell(u[0], u[1], 2)] = true;
                    let c = n.light(0, 2 + 8 * k as usize);
                    control[cell(c[0], c[1], 8)] = true;
                }
                assert!(quads.iter().all(|&q| q), "pixel {pixel}, sample {s}");
            }
            assert!(seen.iter().all(|&c| c), "pixel {pixel}");
            controls += control.iter().all(|&c| c) as usize;
        }
        assert!(
            controls <= 1,
            "independent lights filled the grid in {controls} of 50 pixels"
        );
    }

    /// The keys a wave keeps for a pixel's samples give each sample the numbers it gets alone,
    /// across the 2^16-sample block boundary, and the role table holds SplitMix64's values (in
    /// it and past it). Control: keys kept past the block boundary give other numbers.
    #[test]
    fn kept_pixel_keys_give_each_sample_its_own_numbers() {
        for depth in 0..2 * DEPTHS as u32 {
            for role in 0..2 * ROLES as u64 {
                let expected = splitmix64((u64::from(depth) << 33) | role);
                assert_eq!(
                    role_hash(depth, role),
                    expected,
                    "depth {depth}, role {role}"
                );
            }
        }
        for pixel in [0u64, 5, 1 << 20] {
            let mut keys = PixelKeys::new(7, pixel, 0);
            for s in (0..40u32).chain(65530..65545) {
                if !keys.cover(pixel, s) {
                    keys = PixelKeys::new(7, pixel, s);
                }
                assert_eq!(keys.film(s), pixel_sample(7, pixel, s));
                let (kept, alone) = (keys.path(s), PathNumbers::new(7, pixel, s));
                assert_eq!(kept.bounce(0), alone.bounce(0), "pixel {pixel}, sample {s}");
                assert_eq!(
                    kept.light(3, 1),
                    alone.light(3, 1),
                    "pixel {pixel}, sample {s}"
                );
            }
        }
        for sample in [0, 3, 1 << 16] {
            let n = PathNumbers::new(9, 11, sample);
            for role in 0..2 {
                let formula = SobolScramble::new(PathNumbers::scramble(n.key, 0, role, 0));
                assert_eq!(
                    n.first[role as usize], formula,
                    "sample {sample}, role {role}"
                );
            }
        }
        let stale = PixelKeys::new(7, 5, 0);
        assert!(!stale.cover(5, 1 << 16) && !stale.cover(6, 0));
        assert_ne!(stale.film(1 << 16), pixel_sample(7, 5, 1 << 16));
        assert_ne!(
            stale.path(1 << 16).bounce(0),
            PathNumbers::new(7, 5, 1 << 16).bounce(0)
        );
    }
}
