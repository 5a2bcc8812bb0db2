//! Poisson impulse counts and impulse positions from cell hashes (Liu 2016 §4.1).

use super::*;

/// Poisson-distributed count with mean `m` from one 32-bit hash: inverse CDF walk in f64 (exact
/// enough that the top of the uniform never falls off the accumulated CDF).
#[inline]
pub(super) fn poisson(h: u32, m: f32) -> u32 {
    poisson_with(h, m as f64, (-(m as f64)).exp())
}

/// [`poisson`] with `exp(−m)` precomputed by the caller.
#[inline(always)]
pub(super) fn poisson_with(h: u32, m: f64, exp_neg_m: f64) -> u32 {
    let u = (h as f64 + 0.5) * (1.0 / 4_294_967_296.0);
    let mut term = exp_neg_m;
    let mut cdf = term;
    let mut k = 0;
    while u > cdf && k < MAX_DRAW {
        k += 1;
        term *= m * INV_K[k as usize];
        cdf += term;
    }
    k
}

/// Entries of [`PoissonTable`]: counts below this come from integer compares alone (a Poisson
/// count of mean 1.19, the distortion's, reaches 8 with probability 3.5·10⁻⁵).
pub(super) const TABLE: usize = 8;

/// The inverse-CDF walk of [`poisson_with`] turned into integer thresholds on the raw hash, built
/// once per band (per ring for cylindrical cells) instead of walking in f64 per cell. The walk
/// steps past k while u > CDF(k), u = (h + ½)/2³²; both sides are exact in f64 (a power-of-two
/// scale), so u > CDF(k) ⇔ h ≥ T_k with T_k = ⌊2³² CDF(k) − ½⌋ + 1, and the count is the number
/// of thresholds h reaches: the same count, bit for bit (test `poisson_table_matches_the_walk`).
#[derive(Clone, Copy, Debug)]
pub(super) struct PoissonTable {
    /// T_k for k < [`TABLE`], as u64 (2³² and beyond: never reached).
    pub(super) thresholds: [u64; TABLE],
    /// The same test in u32 for SIMD lanes: h ≥ T_k ⇔ h > T_k − 1 (saturated at u32::MAX, never
    /// true, for T_k > 2³²); T_k = 0 (always reached) is counted in `always` and stored as MAX.
    below: [u32; TABLE],
    always: u32,
    m: f64,
    exp_neg_m: f64,
}

impl PoissonTable {
    pub(super) fn new(m: f64) -> Self {
        let exp_neg_m = (-m).exp();
        let mut thresholds = [0u64; TABLE];
        let (mut term, mut cdf) = (exp_neg_m, exp_neg_m);
        for (k, t) in thresholds.iter_mut().enumerate() {
            if k > 0 {
                term *= m * INV_K[k];
                cdf += term;
            }
            // ⌊x⌋ + 1 for x = 2³² CDF − ½ ≥ −½ (truncation is the floor for x ≥ 0).
            let x = cdf * 4_294_967_296.0 - 0.5;
            // (x < 2³³, so the i64 conversion, one instruction, is exact after truncation.)
            *t = if x < 0.0 { 0 } else { (x as i64 + 1) as u64 };
        }
        let below = thresholds.map(|t| match t {
            0 => u32::MAX,
            t => (t - 1).min(u32::MAX as u64) as u32,
        });
        PoissonTable {
            thresholds,
            below,
            always: thresholds.iter().filter(|&&t| t == 0).count() as u32,
            m,
            exp_neg_m,
        }
    }

    /// The count for hash `h` if below [`TABLE`], else [`TABLE`]: u32 compares only, for lanes.
    #[inline(always)]
    pub(super) fn table_count(&self, h: u32) -> u32 {
        self.always + self.below.iter().map(|&b| (h > b) as u32).sum::<u32>()
    }

    /// The count for hash `h`: integer compares, the f64 walk only past the table (rare).
    #[inline(always)]
    pub(super) fn count(&self, h: u32) -> u32 {
        let h = h as u64;
        let t = &self.thresholds;
        // Empty cells (most, for sparse features) cost one compare.
        if h < t[0] {
            return 0;
        }
        // Three more compares cover counts below 4 (≈ 97 % of non-empty cells at mean 1.2).
        let c = 1 + (h >= t[1]) as u32 + (h >= t[2]) as u32 + (h >= t[3]) as u32;
        if c < 4 {
            c
        } else {
            poisson_with(h as u32, self.m, self.exp_neg_m)
        }
    }
}

/// 1/k for the Poisson walk (a multiply instead of a division per step).
static INV_K: [f64; MAX_DRAW as usize + 1] = {
    let mut t = [0.0; MAX_DRAW as usize + 1];
    let mut k = 1;
    while k <= MAX_DRAW as usize {
        t[k] = 1.0 / k as f64;
        k += 1;
    }
    t
};

/// Random numbers of impulse `k` of a cell: two 32-bit words, the cell's hash words `h1` and `h2`
/// advanced k + 1 Weyl steps (odd constants: the golden ratio's and MurmurHash3's), each through
/// the lowbias32 finaliser ([`mix32`]; the second chained on the first) and cut into four 16-bit
/// fields: the position in the cell (resolution 2⁻¹⁶ of a cell) and a weight uniform in [−1, 1).
/// Only 32-bit multiplies, so AVX2 lanes run it as well as AVX-512 ones (a 64-bit SplitMix stream
/// before, whose products AVX2 lacks: notes/noise.md).
#[inline(always)]
pub(super) fn impulse(h: [u32; 3], k: u32) -> (Vec3, f32) {
    impulse_numbers(impulse_stream(h[1], h[2], k))
}

/// The two words of impulse `k` of a cell with hash words `h1`, `h2` (see [`impulse`]).
#[inline(always)]
pub(super) fn impulse_stream(h1: u32, h2: u32, k: u32) -> (u32, u32) {
    let k1 = k.wrapping_add(1);
    (
        h1.wrapping_add(k1.wrapping_mul(0x9e37_79b9)),
        h2.wrapping_add(k1.wrapping_mul(0x85eb_ca6b)),
    )
}

/// The words of [`impulse_stream`] mixed and cut into the impulse's position in its cell and its
/// weight (see [`impulse`]).
#[inline(always)]
pub(super) fn impulse_numbers((a, b): (u32, u32)) -> (Vec3, f32) {
    let a = mix32(a);
    let b = mix32(b ^ a);
    // 16-bit fields: exact as i32 and as f32.
    let field = |v: u32, shift: u32| ((v >> shift) & 0xffff) as i32 as f32 * (1.0 / 65_536.0);
    (
        Vec3::new(field(a, 16), field(a, 0), field(b, 16)),
        2.0 * field(b, 0) - 1.0,
    )
}
