//! 1D sparse convolution noise with one impulse per cell.

use super::*;

/// 1D sparse convolution noise with one impulse per cell, for the wood model's growth-rate variation
/// and interlocked-grain angle (Liu 2016 §6.1.3, §6.1.5; App. A.3: "Wyvill kernel, one band"):
/// n(x) = ½ Σ_j s_j K((x − x_j) / h), K the Wyvill kernel (eq. 4) of half-width h, impulse x_j
/// uniform in cell [j h, (j + 1) h), signs s_j = ±1 with equal probability, all from the cell hash.
///
/// One impulse per cell instead of a Poisson count (ours, notes/noise.md "Bounded 1D sparse
/// convolution noise"): at most three kernels reach a point, so |n| ≤ 1 and |n′| ≤
/// [`SparseConvolution1::MAX_SLOPE`] / h — bounds the wood model needs (a monotone growth time, a
/// largest helix angle). The signs are independent with mean zero, so the covariance is exactly
/// that of Poisson impulses of the same rate (density 2): stationary, no lattice.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SparseConvolution1 {
    inv_width: f32,
    offsets: [u32; 3],
}

impl SparseConvolution1 {
    /// sup |n′| · h = 48/(25√5) + 27/16 = 2.54615 (rounded up): half of max|K′| (own cell) plus
    /// twice |K′(½)|/2 (the neighbours) at the cell's midpoint (notes/noise.md).
    pub const MAX_SLOPE: f32 = 2.5462;
    /// Standard deviation of n, √(512/3003) (Campbell's theorem, notes/noise.md).
    pub const STD: f32 = 0.412_912;
    /// Standard deviation of n′ · h, √(2304/3465).
    pub const STD_SLOPE: f32 = 0.815_435;
    /// Mean distance between zero crossings of n, in kernel half-widths h (the Kac–Rice rate
    /// E[|n′| δ(n)] by Monte Carlo, 2.8·10⁷ samples, ±0.3 %: notes/noise.md).
    pub const ZERO_SPACING: f32 = 1.978;

    /// The noise with kernel half-width (and cell length) `width` > 0 for `seed`.
    pub fn new(width: f32, seed: u32) -> Self {
        SparseConvolution1 {
            inv_width: 1.0 / width,
            offsets: seed_offsets(seed),
        }
    }

    /// Value in [−1, 1] and derivative at `x`. No data-dependent branch, so a loop over many x
    /// vectorises.
    #[inline(always)]
    pub fn eval(&self, x: f32) -> (f32, f32) {
        let xc = x * self.inv_width;
        let base = floor_i32(xc);
        let f = xc - base as f32;
        let (mut value, mut deriv) = (0.0, 0.0);
        // An array, not `-1..=1`: an inclusive range is not unrolled, and the caller's loop then
        // does not vectorise.
        for o in [-1i32, 0, 1] {
            let h = cell3_offset(base.wrapping_add(o), 0, 0, &self.offsets);
            let half_sign = if h[1] >> 31 == 0 { 0.5 } else { -0.5 };
            let t = f - o as f32 - unit_f32(h[0]);
            // Clamped instead of `Kernel::eval_q`'s early return (the same values where the kernel
            // reaches, zeros beyond), so that loops over many x vectorise.
            let (k, dk) = wyvill((1.0 - t * t).max(0.0));
            value += half_sign * k;
            deriv += half_sign * 2.0 * dk * t;
        }
        (value, deriv * self.inv_width)
    }
}
