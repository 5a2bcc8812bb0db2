//! Sparse convolution noise as Liu, Dong, Hašan & Marschner 2016 ("Simulating the structure and
//! texture of solid wood", §4) build wood from: a Poisson process of impulses, generated per grid
//! cell from a hash (§4.1, their Fig. 6), convolved with a compact kernel (§4.3), summed over bands
//! (§4.4), with anisotropic kernels oriented by a frame field and shrunk by the bounding-box fit of
//! their eq. 9–12 (§4.5), on Cartesian or equal-volume cylindrical cells (§4.2), with the analytic
//! gradient of their eq. 13 (terms in ∇R, ∇Sₑ omitted, as in the paper).
//!
//! Derivations that are ours (impulses per cell, the search window, the Campbell-theorem moments
//! the tests check) are in notes/noise.md.

use super::hash::{cell3, cell3_offset, floor_i32, mix32, pcg3d, seed_offsets, unit_f32};
use crate::math::Frame;
use crate::simd::{simd_wide, Simd};
use glam::Vec3;
use serde::{Deserialize, Serialize};
use std::f32::consts::PI;

/// The kernel K(r) of one impulse, a function of the normalised distance r ∈ [0, 1), zero beyond.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Kernel {
    /// Wyvill kernel `(1 − r²)³` (Liu 2016 eq. 4, after Wyvill et al. 1986): C² at r = 1, for
    /// "continuous" noise.
    Wyvill,
    /// Bump kernel `exp(−s r² / (1 − r²))` (Liu 2016 eq. 6): a box as s → 0, a bump for s ≈ 1, a
    /// spike as s → ∞; for discrete features (pores, rays).
    Bump {
        /// Sharpness s ≥ 0.
        sharpness: f32,
    },
}

impl Kernel {
    /// `(K, dK/dq)` at `q = r²`; `(0, 0)` for `q ≥ 1`.
    #[inline(always)]
    pub(crate) fn eval_q(self, q: f32) -> (f32, f32) {
        if q >= 1.0 {
            return (0.0, 0.0);
        }
        let a = 1.0 - q;
        match self {
            Kernel::Wyvill => wyvill(a),
            Kernel::Bump { sharpness } => {
                let k = (-sharpness * q / a).exp();
                (k, -sharpness * k / (a * a))
            }
        }
    }
}

/// The Wyvill kernel (Liu 2016 eq. 4) as `(K, dK/dq)` at `a = 1 − q`, `q = r²`: `(a³, −3a²)`.
#[inline(always)]
fn wyvill(a: f32) -> (f32, f32) {
    (a * a * a, -3.0 * a * a)
}

/// How the impulses are weighted.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Weights {
    /// Every impulse has weight 1 (Liu 2016 eq. 7): a non-negative "density" of kernels, for masks
    /// of discrete features.
    Unit,
    /// Weights uniform in [−1, 1) (Lewis 1989, "Algorithms for solid noise synthesis"): zero-mean
    /// noise, for distortions.
    Signed,
}

/// The grid the impulses live in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Cells {
    /// Axis-aligned boxes of size `cell` (x, y, z).
    Cartesian,
    /// Liu 2016 §4.2: concentric bands about the z axis (the pith), `cell.x` wide radially; band j
    /// holds `max(1, round(2π r_mid / cell.y))` cells (so each is ≈ `cell.y` long in arc and all
    /// have ≈ equal volume); `cell.z` tall. Points are in pith coordinates.
    Cylindrical,
}

/// Parameters of a (multiband, possibly anisotropic and oriented) sparse convolution noise.
/// Lengths in the units of the points (millimetres in the wood model).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SparseConvolution {
    /// Kernel shape: Wyvill (continuous noise) or bump (discrete features).
    pub kernel: Kernel,
    /// Mean number of kernels overlapping a point (Liu 2016 §6.1.2), for the nominal envelope.
    pub density: f32,
    /// Kernel semi-axes Sₑ along the kernel frame's (s, t, n) axes; for Cartesian cells without a
    /// frame these are x, y, z; for cylindrical cells without a frame, (r̂, θ̂, ẑ).
    pub envelope: Vec3,
    /// Cell size S_c (x, y, z for Cartesian cells; radial width, arc length, height for
    /// cylindrical). Kernels are shrunk to fit one cell's half-extent per axis (eq. 11), so cells
    /// at least as large as the envelope keep kernels at their nominal size.
    pub cell: Vec3,
    /// Magnitude α of the base band (eq. 7).
    pub magnitude: f32,
    /// Unit (non-negative, masks) or signed (zero-mean, distortions) impulse weights.
    pub weights: Weights,
    /// Cartesian or cylindrical (about the pith) cell lattice.
    pub cells: Cells,
    /// Number of bands (≥ 1).
    pub bands: u32,
    /// Size factor β from one band to the next (eq. 8), in (0, 1]; typically ½.
    pub size_factor: f32,
    /// Power-law magnitude dropoff γ: band i has magnitude α β^(γ i) (eq. 8); typically 1–2.
    pub dropoff: f32,
}

impl Default for SparseConvolution {
    fn default() -> Self {
        SparseConvolution {
            kernel: Kernel::Wyvill,
            density: 4.0,
            envelope: Vec3::ONE,
            cell: Vec3::ONE,
            magnitude: 1.0,
            weights: Weights::Unit,
            cells: Cells::Cartesian,
            bands: 1,
            size_factor: 0.5,
            dropoff: 1.0,
        }
    }
}

/// Invalid noise parameters, naming the field and the allowed range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NoiseError {
    /// A parameter is not finite or outside its range.
    #[error("noise parameter `{field}` = {value} is outside the allowed range {range}")]
    OutOfRange {
        /// The parameter, e.g. `size_factor`.
        field: &'static str,
        /// The value given.
        value: f32,
        /// The allowed range.
        range: &'static str,
    },
}

fn check(field: &'static str, value: f32, ok: bool, range: &'static str) -> Result<(), NoiseError> {
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(NoiseError::OutOfRange {
            field,
            value,
            range,
        })
    }
}

/// Upper bound on the mean impulse count per cell (keeps the Poisson walk short and exact in f64).
pub const MAX_IMPULSES_PER_CELL: f32 = 64.0;
/// Hard cap on the impulses drawn in one cell (never reached in practice: P < 1e-40 at the mean bound).
const MAX_DRAW: u32 = 256;

impl SparseConvolution {
    /// Checks every field; the error names the field and its allowed range.
    pub fn validate(&self) -> Result<(), NoiseError> {
        check("density", self.density, self.density > 0.0, "(0, ∞)")?;
        for (f, v) in [
            ("envelope.x", self.envelope.x),
            ("envelope.y", self.envelope.y),
            ("envelope.z", self.envelope.z),
            ("cell.x", self.cell.x),
            ("cell.y", self.cell.y),
            ("cell.z", self.cell.z),
        ] {
            check(f, v, v > 0.0, "(0, ∞)")?;
        }
        check("magnitude", self.magnitude, true, "finite")?;
        let b = self.bands as f32;
        check("bands", b, (1.0..=16.0).contains(&b), "1..=16")?;
        let sf = self.size_factor;
        check("size_factor", sf, sf > 0.0 && sf <= 1.0, "(0, 1]")?;
        check("dropoff", self.dropoff, true, "finite")?;
        if let Kernel::Bump { sharpness } = self.kernel {
            check("kernel.sharpness", sharpness, sharpness >= 0.0, "[0, ∞)")?;
        }
        let m = self.impulses_per_cell();
        check(
            "density (as impulses per cell)",
            m,
            m <= MAX_IMPULSES_PER_CELL,
            "≤ 64 impulses per cell: lower the density or the cell size",
        )
    }

    /// Poisson intensity λ (impulses per unit volume) so that on average `density` nominal
    /// kernels (ellipsoids of volume 4/3 π eₓ e_y e_z) overlap a point: λ = density / V_kernel.
    pub fn intensity(&self) -> f32 {
        self.density / (4.0 / 3.0 * PI * self.envelope.x * self.envelope.y * self.envelope.z)
    }

    /// Mean impulse count of one (Cartesian, or average cylindrical) cell of the base band:
    /// λ · V_cell. Bands scale cells and kernels together, so it is the same in every band.
    pub fn impulses_per_cell(&self) -> f32 {
        self.intensity() * self.cell.x * self.cell.y * self.cell.z
    }

    /// Noise value at `p` with kernels aligned to the cells (Cartesian: x, y, z; cylindrical:
    /// r̂, θ̂, ẑ at `p`).
    #[inline]
    pub fn eval(&self, p: Vec3, seed: u32) -> f32 {
        self.sum::<false>(p, None, seed).0
    }

    /// Value and analytic gradient (Liu 2016 eq. 13) with kernels aligned to the cells.
    #[inline]
    pub fn eval_grad(&self, p: Vec3, seed: u32) -> (f32, Vec3) {
        self.sum::<true>(p, None, seed)
    }

    /// Value with every kernel oriented by `frame` (its s, t, n carry the envelope's x, y, z), the
    /// frame field queried at the evaluation point as Liu 2016 §4.5 does; kernels are shrunk by
    /// the bounding-box fit (eq. 9–12) so none leaves the searched cells.
    #[inline]
    pub fn eval_oriented(&self, p: Vec3, frame: &Frame, seed: u32) -> f32 {
        self.sum::<false>(p, Some(frame), seed).0
    }

    /// Value and gradient of [`SparseConvolution::eval_oriented`]: eq. 13 with the terms in ∇R,
    /// ∇Sₑ and ∇s_b omitted (eq. 14; exact where the frame and the fit are constant).
    #[inline]
    pub fn eval_oriented_grad(&self, p: Vec3, frame: &Frame, seed: u32) -> (f32, Vec3) {
        self.sum::<true>(p, Some(frame), seed)
    }

    /// The bounding-box shrink factor s_b (eq. 9–11) of a kernel with semi-axes `env` rotated to
    /// the columns of `frame`, against cell half-extents `cell` (both in the same axes):
    /// `min(1, min_i cell_i / ext_i)` with `ext_i` the 2-norm of row i of R·Sₑ (eq. 9). We clamp at
    /// 1 so kernels are only ever shrunk, never grown.
    pub fn fit_scale(env: Vec3, frame: &Frame, cell: Vec3) -> f32 {
        let ext = bbox_half_extent(env, frame);
        (cell.x / ext.x)
            .min(cell.y / ext.y)
            .min(cell.z / ext.z)
            .min(1.0)
    }

    fn sum<const GRAD: bool>(&self, p: Vec3, frame: Option<&Frame>, seed: u32) -> (f32, Vec3) {
        let bands = (0..self.bands.max(1)).map(|index| self.band(index, seed));
        sum_bands::<GRAD, _>(bands, self.cells, p, frame, 1.0)
    }

    /// Band `index` for `seed`: magnitude α β^(γ i) and the band with every length scaled by βⁱ
    /// (eq. 8). βⁱ is built by repeated multiplication, band 0 skips the libm call (1^γ = 1).
    fn band(&self, index: u32, seed: u32) -> (f32, Band) {
        let mut scale = 1.0f32;
        for _ in 0..index {
            scale *= self.size_factor;
        }
        let amp = self.magnitude
            * if index == 0 {
                1.0
            } else {
                scale.powf(self.dropoff)
            };
        let bseed = mix32(seed ^ mix32(index.wrapping_add(0x5bd1_e995)));
        let (env, cell) = (self.envelope * scale, self.cell * scale);
        let intensity = self.intensity() / (scale * scale * scale);
        let signed = self.weights == Weights::Signed;
        let band = Band::new(self.kernel, env, cell, intensity, signed, bseed);
        (amp, band)
    }

    /// Number of impulses the base band holds in Cartesian cell `(ix, iy, iz)` for `seed`
    /// (exposed so that tests and tools can check the Poisson process).
    pub fn cell_impulse_count(&self, cell: [i32; 3], seed: u32) -> u32 {
        let bseed = mix32(seed ^ mix32(0x5bd1_e995));
        let h = cell3(cell[0], cell[1], cell[2], bseed);
        poisson(h[0], self.impulses_per_cell())
    }
}

/// Σ amplitude × band (eq. 7–8) over `bands`, in order.
#[inline(always)]
fn sum_bands<const GRAD: bool, B: std::borrow::Borrow<(f32, Band)>>(
    bands: impl Iterator<Item = B>,
    cells: Cells,
    p: Vec3,
    frame: Option<&Frame>,
    kernel_scale: f32,
) -> (f32, Vec3) {
    let mut value = 0.0;
    let mut gradient = Vec3::ZERO;
    for b in bands {
        let (amp, band) = b.borrow();
        let (v, g) = match cells {
            Cells::Cartesian => band.cartesian::<GRAD>(p, frame, kernel_scale),
            Cells::Cylindrical => band.cylindrical::<GRAD>(p, frame, kernel_scale),
        };
        value += amp * v;
        if GRAD {
            gradient += amp * g;
        }
    }
    (value, gradient)
}

/// A [`SparseConvolution`] bound to a seed, with what does not depend on the query point — each
/// band's magnitude, scaled lengths, lattice offsets and Poisson thresholds — computed once.
/// Evaluates exactly as the `SparseConvolution` methods with that seed, for callers that query
/// one noise many times (the wood features).
#[derive(Clone, Debug)]
pub struct SeededSparse {
    noise: SparseConvolution,
    bands: Vec<(f32, Band)>,
}

impl SeededSparse {
    /// Binds `noise` to `seed`, precomputing each band once.
    pub fn new(noise: SparseConvolution, seed: u32) -> Self {
        let bands = (0..noise.bands.max(1))
            .map(|index| noise.band(index, seed))
            .collect();
        SeededSparse { noise, bands }
    }

    /// The parameters.
    pub fn noise(&self) -> &SparseConvolution {
        &self.noise
    }

    /// [`SparseConvolution::eval`].
    #[inline]
    pub fn eval(&self, p: Vec3) -> f32 {
        self.sum::<false>(p, None, self.bands.len()).0
    }

    /// [`SparseConvolution::eval_oriented`] (with its gradient when `GRAD`) over the first
    /// `bands` bands (all: the same value), every kernel shrunk about its own centre by
    /// `kernel_scale` ∈ (0, 1]: the same impulses, smaller kernels K(M(p − k) / kernel_scale), for
    /// features whose size varies with the point such as ring-porous pores (Liu et al. 2016
    /// §6.1.6). A scale of 1 gives exactly the unscaled noise.
    #[inline]
    pub fn eval_oriented_with<const GRAD: bool>(
        &self,
        p: Vec3,
        frame: &Frame,
        bands: usize,
        kernel_scale: f32,
    ) -> (f32, Vec3) {
        let bands = self.bands[..bands.min(self.bands.len())].iter();
        let scale = kernel_scale.clamp(f32::MIN_POSITIVE, 1.0);
        sum_bands::<GRAD, _>(bands, self.noise.cells, p, Some(frame), scale)
    }

    /// [`SeededSparse::eval_oriented_with`]'s value at `N` points, each with its frame and kernel
    /// scale: every band's query set-up (eq. 9–12) in SIMD lanes, the cell search point by
    /// point. The same values, bit for bit (tests).
    #[inline(always)]
    pub fn eval_oriented_many<const N: usize>(
        &self,
        p: &[Vec3; N],
        frames: &[Frame; N],
        bands: usize,
        kernel_scale: &[f32; N],
    ) -> [f32; N] {
        let scale = kernel_scale.map(|k| k.clamp(f32::MIN_POSITIVE, 1.0));
        let mut value = [0.0f32; N];
        for (amp, band) in &self.bands[..bands.min(self.bands.len())] {
            match self.noise.cells {
                Cells::Cartesian => {
                    let queries = band.cartesian_queries(p, frames, &scale);
                    for (value, q) in value.iter_mut().zip(&queries) {
                        *value += amp * band.cartesian_search::<false>(q).0;
                    }
                }
                Cells::Cylindrical => {
                    for i in 0..N {
                        let v = band
                            .cylindrical::<false>(p[i], Some(&frames[i]), scale[i])
                            .0;
                        value[i] += amp * v;
                    }
                }
            }
        }
        value
    }

    #[inline]
    fn sum<const GRAD: bool>(&self, p: Vec3, frame: Option<&Frame>, bands: usize) -> (f32, Vec3) {
        let bands = self.bands[..bands.min(self.bands.len())].iter();
        sum_bands::<GRAD, _>(bands, self.noise.cells, p, frame, 1.0)
    }
}

/// Eq. 9: half-extents of the axis-aligned bounding box of the unit sphere scaled by `env` and
/// rotated into `frame` — the 2-norms of the rows of R·Sₑ.
#[inline]
fn bbox_half_extent(env: Vec3, f: &Frame) -> Vec3 {
    let (a, b, c) = (f.s * env.x, f.t * env.y, f.n * env.z);
    Vec3::new(
        (a.x * a.x + b.x * b.x + c.x * c.x).sqrt(),
        (a.y * a.y + b.y * b.y + c.y * c.y).sqrt(),
        (a.z * a.z + b.z * b.z + c.z * c.z).sqrt(),
    )
}

/// Poisson-distributed count with mean `m` from one 32-bit hash: inverse CDF walk in f64 (exact
/// enough that the top of the uniform never falls off the accumulated CDF).
#[inline]
fn poisson(h: u32, m: f32) -> u32 {
    poisson_with(h, m as f64, (-(m as f64)).exp())
}

/// [`poisson`] with `exp(−m)` precomputed by the caller.
#[inline(always)]
fn poisson_with(h: u32, m: f64, exp_neg_m: f64) -> u32 {
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
const TABLE: usize = 8;

/// The inverse-CDF walk of [`poisson_with`] turned into integer thresholds on the raw hash, built
/// once per band (per ring for cylindrical cells) instead of walking in f64 per cell. The walk
/// steps past k while u > CDF(k), u = (h + ½)/2³²; both sides are exact in f64 (a power-of-two
/// scale), so u > CDF(k) ⇔ h ≥ T_k with T_k = ⌊2³² CDF(k) − ½⌋ + 1, and the count is the number
/// of thresholds h reaches: the same count, bit for bit (test `poisson_table_matches_the_walk`).
#[derive(Clone, Copy, Debug)]
struct PoissonTable {
    /// T_k for k < [`TABLE`], as u64 (2³² and beyond: never reached).
    thresholds: [u64; TABLE],
    /// The same test in u32 for SIMD lanes: h ≥ T_k ⇔ h > T_k − 1 (saturated at u32::MAX, never
    /// true, for T_k > 2³²); T_k = 0 (always reached) is counted in `always` and stored as MAX.
    below: [u32; TABLE],
    always: u32,
    m: f64,
    exp_neg_m: f64,
}

impl PoissonTable {
    fn new(m: f64) -> Self {
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
    fn table_count(&self, h: u32) -> u32 {
        self.always + self.below.iter().map(|&b| (h > b) as u32).sum::<u32>()
    }

    /// The count for hash `h`: integer compares, the f64 walk only past the table (rare).
    #[inline(always)]
    fn count(&self, h: u32) -> u32 {
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
fn impulse(h: [u32; 3], k: u32) -> (Vec3, f32) {
    impulse_numbers(impulse_stream(h[1], h[2], k))
}

/// The two words of impulse `k` of a cell with hash words `h1`, `h2` (see [`impulse`]).
#[inline(always)]
fn impulse_stream(h1: u32, h2: u32, k: u32) -> (u32, u32) {
    let k1 = k.wrapping_add(1);
    (
        h1.wrapping_add(k1.wrapping_mul(0x9e37_79b9)),
        h2.wrapping_add(k1.wrapping_mul(0x85eb_ca6b)),
    )
}

/// The words of [`impulse_stream`] mixed and cut into the impulse's position in its cell and its
/// weight (see [`impulse`]).
#[inline(always)]
fn impulse_numbers((a, b): (u32, u32)) -> (Vec3, f32) {
    let a = mix32(a);
    let b = mix32(b ^ a);
    // 16-bit fields: exact as i32 and as f32.
    let field = |v: u32, shift: u32| ((v >> shift) & 0xffff) as i32 as f32 * (1.0 / 65_536.0);
    (
        Vec3::new(field(a, 16), field(a, 0), field(b, 16)),
        2.0 * field(b, 0) - 1.0,
    )
}

/// One band, all lengths already scaled.
#[derive(Clone, Debug)]
struct Band {
    kernel: Kernel,
    env: Vec3,
    cell: Vec3,
    intensity: f32,
    signed: bool,
    /// The band's seed, as the lattice translations of [`seed_offsets`].
    offsets: [u32; 3],
    /// Counts of a Cartesian cell (mean `intensity` × cell volume).
    cell_counts: PoissonTable,
}

/// The kernel's inverse map M = s_b⁻¹ Sₑ⁻¹ Rᵀ of eq. 12, kept as axes and inverse lengths.
#[derive(Clone, Copy)]
struct KernelMap {
    axes: Option<Frame>,
    inv: Vec3,
}

impl KernelMap {
    /// Adds the kernel at offset `d = p − k` with weight `w` to `(value, gradient)`.
    #[inline(always)]
    fn add<const GRAD: bool>(&self, kernel: Kernel, d: Vec3, w: f32, acc: &mut (f32, Vec3)) {
        let local = match &self.axes {
            None => d,
            Some(f) => f.to_local(d),
        };
        let u = local * self.inv;
        let q = u.length_squared();
        if q < 1.0 {
            let (k, dk) = kernel.eval_q(q);
            acc.0 += w * k;
            if GRAD {
                // ∇_p K(|M d|²) = 2 K'(q) Mᵀ M d (eq. 13).
                let g = 2.0 * dk * w * u * self.inv;
                acc.1 += match &self.axes {
                    None => g,
                    Some(f) => f.to_world(g),
                };
            }
        }
    }
}

/// Everything a Cartesian query needs besides the band: the kernel map after the fit, the
/// point's cell `base` and its place `f` in it, the window `lo..=hi` (cell offsets per axis), the
/// per-axis gap scale of the axis-aligned cell test (0 for oriented kernels) and the counts.
#[derive(Clone, Copy)]
struct CartesianQuery {
    map: KernelMap,
    reach: Vec3,
    base: [i32; 3],
    f: Vec3,
    gap_scale: Vec3,
}

impl CartesianQuery {
    /// The window: offsets ⌊f − reach⌋ ..= ⌊f + reach⌋ per axis (≤ 3 cells, 4 if rounding).
    #[inline(always)]
    fn window(&self) -> ([i32; 3], [i32; 3]) {
        let (lo, hi) = (self.f - self.reach, self.f + self.reach);
        (
            [floor_i32(lo.x), floor_i32(lo.y), floor_i32(lo.z)],
            [floor_i32(hi.x), floor_i32(hi.y), floor_i32(hi.z)],
        )
    }

    /// Whether the window lies in the 3 × 3 × 3 block (⌊f − reach⌋ ≥ −1 and ⌊f + reach⌋ ≤ 1 per
    /// axis, tested on the same rounded sums without converting them).
    #[inline(always)]
    fn in_block(&self) -> bool {
        let (lo, hi) = (self.f - self.reach, self.f + self.reach);
        lo.cmpge(Vec3::splat(-1.0)).all() && hi.cmplt(Vec3::splat(2.0)).all()
    }

    /// Cell height in fitted kernel semi-axes along z (for upright kernels, whose local z is z).
    #[inline(always)]
    fn gap_scale_z_upright(&self) -> f32 {
        1.0 / (self.reach.z.max(f32::MIN_POSITIVE))
    }
}

/// Whether a kernel frame only turns about z (n = ẑ, s and t horizontal), as the distortion's
/// cylindrical frame does: then the kernel's local z is the world z.
#[inline(always)]
fn is_upright(frame: &Frame) -> bool {
    frame.n == Vec3::Z && frame.s.z == 0.0 && frame.t.z == 0.0
}

/// Slack on [`layer_shrink`], far above f32 rounding, so no cell holding a contributing impulse
/// is ever dropped.
const LAYER_SLACK: f32 = 1e-4;

/// For an upright kernel (z semi-axis e_z, window reach ρ_z = e_z / cell height in cells), the
/// fraction of its x and y extent left in the layer of cells at z offset `oz` from a point at
/// `fz` in its cell: the layer lies g = gap / ρ_z semi-axes away along z, where the ellipsoid's
/// slice is the ellipse scaled by √(1 − g²), so its bounding box (eq. 9) scales by that too.
/// Returned with slack, capped at 1.
#[inline(always)]
fn layer_shrink(oz: i32, fz: f32, cells_per_semi_axis: f32) -> f32 {
    let gap = ((oz as f32 + 0.5 - fz).abs() - 0.5).max(0.0) * cells_per_semi_axis;
    ((1.0 - gap * gap).max(0.0).sqrt() + LAYER_SLACK).min(1.0)
}

/// The indices of the set bits of `mask`, ascending.
#[inline(always)]
fn lanes(mut mask: u32) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (mask != 0).then(|| {
            let i = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            i
        })
    })
}

/// Lanes of the block search: the 27 cells of the 3 × 3 × 3 block plus 5 padding lanes.
const BLOCK: usize = 32;

/// Cell offsets (x, y, z) of each block lane, z outermost and x innermost like the scalar loop;
/// the padding lanes sit at z = 2, outside every window.
const BLOCK_OFFSETS: [[i32; BLOCK]; 3] = {
    let mut o = [[0; BLOCK]; 3];
    let mut i = 0;
    while i < BLOCK {
        o[0][i] = (i % 3) as i32 - 1;
        o[1][i] = ((i / 3) % 3) as i32 - 1;
        o[2][i] = (i / 9) as i32 - 1;
        i += 1;
    }
    o
};

impl Band {
    /// A band with lengths already scaled; `seed` is the band's own.
    fn new(kernel: Kernel, env: Vec3, cell: Vec3, intensity: f32, signed: bool, seed: u32) -> Band {
        Band {
            kernel,
            env,
            cell,
            intensity,
            signed,
            offsets: seed_offsets(seed),
            cell_counts: PoissonTable::new((intensity * cell.x * cell.y * cell.z) as f64),
        }
    }

    /// The query setup shared by both Cartesian paths: the fit, the kernel map and the window.
    #[inline(always)]
    fn cartesian_query(&self, p: Vec3, frame: Option<&Frame>, kernel_scale: f32) -> CartesianQuery {
        // Kernel extent per axis before the fit (eq. 9), then the fit (eq. 11) against the cell.
        let env = self.env * kernel_scale;
        let (ext, axes) = match frame {
            None => (env, None),
            Some(f) => (bbox_half_extent(env, f), Some(*f)),
        };
        let sb = (self.cell.x / ext.x)
            .min(self.cell.y / ext.y)
            .min(self.cell.z / ext.z)
            .min(1.0);
        let map = KernelMap {
            axes,
            inv: 1.0 / (sb * env),
        };
        let reach = sb * ext / self.cell; // ≤ 1 cell per axis
        let pc = p / self.cell;
        let base = [floor_i32(pc.x), floor_i32(pc.y), floor_i32(pc.z)];
        let f = Vec3::new(
            pc.x - base[0] as f32,
            pc.y - base[1] as f32,
            pc.z - base[2] as f32,
        );
        // Axis-aligned kernels: cells whose box lies outside the kernel's ellipsoid about p (semi-
        // axes s_b·Sₑ) cannot hold a contributing centre and are skipped before hashing (each
        // axis' gap to the cell bounds that axis' term of q from below). Oriented kernels: no
        // such test (scale 0) — separating-axis tests against the kernel's box culled ≈ 6 % of
        // the cells of the presets and cost more than they saved (notes/wood.md §12).
        let gap_scale = match frame {
            None => self.cell / (sb * env),
            Some(_) => Vec3::ZERO,
        };
        CartesianQuery {
            map,
            reach,
            base,
            f,
            gap_scale,
        }
    }

    /// Cartesian cells: at the AVX-512 or AVX2 level ([`Simd::best`]) the 3 × 3 × 3 block of
    /// cells is searched in SIMD lanes ([`Band::cartesian_block`]: 32 lanes, two AVX-512 or four
    /// AVX2 registers), else (and for windows wider than the block, which only rounding can
    /// make) one cell at a time. All give the same value, bit for bit.
    fn cartesian<const GRAD: bool>(
        &self,
        p: Vec3,
        frame: Option<&Frame>,
        kernel_scale: f32,
    ) -> (f32, Vec3) {
        let q = self.cartesian_query(p, frame, kernel_scale);
        self.cartesian_search::<GRAD>(&q)
    }

    /// The cell search of a prepared query (see [`Band::cartesian`]).
    #[inline(always)]
    fn cartesian_search<const GRAD: bool>(&self, q: &CartesianQuery) -> (f32, Vec3) {
        // SAFETY: the level `Simd::best` allows.
        unsafe { self.cartesian_search_on::<GRAD>(Simd::best(), q) }
    }

    /// [`Band::cartesian_search`] at the level `simd` (tests run every level).
    ///
    /// # Safety
    /// `simd` must be no wider than [`Simd::best`]. (A precondition rather than a check: this
    /// runs once per noise query.)
    #[inline(always)]
    unsafe fn cartesian_search_on<const GRAD: bool>(
        &self,
        simd: Simd,
        q: &CartesianQuery,
    ) -> (f32, Vec3) {
        #[cfg(target_arch = "x86_64")]
        if q.in_block() {
            let upright = q.map.axes.as_ref().is_some_and(is_upright);
            match simd {
                // SAFETY: `simd` is no wider than `Simd::best()` (the caller's promise), which
                // detected its features.
                Simd::Avx512 => return unsafe { self.cartesian_avx512::<GRAD>(q, upright) },
                Simd::Avx2 => return unsafe { self.cartesian_avx2::<GRAD>(q, upright) },
                Simd::Sse2 | Simd::Scalar => {}
            }
        }
        self.cartesian_cells::<GRAD>(q)
    }

    /// [`Band::cartesian_query`] for `N` points with their frames and kernel scales: one loop with
    /// no call and no data-dependent branch, which the compiler runs in SIMD lanes.
    #[inline(always)]
    fn cartesian_queries<const N: usize>(
        &self,
        p: &[Vec3; N],
        frames: &[Frame; N],
        scale: &[f32; N],
    ) -> [CartesianQuery; N] {
        let mut queries = [CartesianQuery {
            map: KernelMap {
                axes: None,
                inv: Vec3::ZERO,
            },
            reach: Vec3::ZERO,
            base: [0; 3],
            f: Vec3::ZERO,
            gap_scale: Vec3::ZERO,
        }; N];
        for (i, q) in queries.iter_mut().enumerate() {
            *q = self.cartesian_query(p[i], Some(&frames[i]), scale[i]);
        }
        queries
    }

    /// One cell at a time over the window (the reference the block search must equal).
    fn cartesian_cells<const GRAD: bool>(&self, q: &CartesianQuery) -> (f32, Vec3) {
        let (f, base) = (q.f, q.base);
        let (lo, hi) = q.window();
        let mut acc = (0.0, Vec3::ZERO);
        for oz in lo[2]..hi[2] + 1 {
            for oy in lo[1]..hi[1] + 1 {
                for ox in lo[0]..hi[0] + 1 {
                    let o = Vec3::new(ox as f32, oy as f32, oz as f32);
                    // Distance from f to the cell [o, o + 1] per axis, in kernel semi-axes.
                    let gap = ((o + 0.5 - f).abs() - 0.5).max(Vec3::ZERO) * q.gap_scale;
                    if gap.length_squared() >= 1.0 {
                        continue;
                    }
                    let h = cell3_offset(
                        base[0].wrapping_add(ox),
                        base[1].wrapping_add(oy),
                        base[2].wrapping_add(oz),
                        &self.offsets,
                    );
                    for k in 0..self.cell_counts.count(h[0]) {
                        let (u, w) = impulse(h, k);
                        let d = (f - o - u) * self.cell;
                        let w = if self.signed { w } else { 1.0 };
                        q.map.add::<GRAD>(self.kernel, d, w, &mut acc);
                    }
                }
            }
        }
        acc
    }

    simd_wide! {
        unsafe fn cartesian_avx2 / cartesian_avx512<const GRAD: bool>(
            &self,
            q: &CartesianQuery,
            upright: bool,
        ) -> (f32, Vec3) {
            self.cartesian_block::<GRAD>(q, upright)
        }
    }

    /// The window searched in lanes, one lane per cell of the 3 × 3 × 3 block (in the order of
    /// [`Band::cartesian_cells`]): every lane hashes its cell and draws its count; then, impulse k
    /// of every cell at once, each lane tests whether the impulse reaches p (q < 1, the same
    /// operations as the scalar test). Only those impulses — ≈ the density, out of ≈ 20 tested
    /// for the distortion — are then summed one by one, in the scalar order, by the scalar code:
    /// the value is [`Band::cartesian_cells`]' bit for bit. Loops over whole lane arrays with no
    /// early exit, so the compiler vectorises them for the enclosing `target_feature`.
    #[inline(always)]
    fn cartesian_block<const GRAD: bool>(&self, q: &CartesianQuery, upright: bool) -> (f32, Vec3) {
        let (f, base, seed) = (q.f, q.base, &self.offsets);
        let per_semi_axis_z = q.gap_scale_z_upright();
        // Three plain loops over the lanes (each vectorises on its own): which cells the window
        // keeps, their hashes, their counts.
        let mut inside = [false; BLOCK];
        for (i, inside) in inside.iter_mut().enumerate() {
            let o = Vec3::new(
                BLOCK_OFFSETS[0][i] as f32,
                BLOCK_OFFSETS[1][i] as f32,
                BLOCK_OFFSETS[2][i] as f32,
            );
            // Upright kernels: the layer's x and y window (1 keeps the whole window exactly).
            let shrink = if upright {
                layer_shrink(BLOCK_OFFSETS[2][i], f.z, per_semi_axis_z)
            } else {
                1.0
            };
            let (lo, hi) = (f - shrink * q.reach, f + shrink * q.reach);
            // o ≥ ⌊lo⌋ ⇔ lo < o + 1 and o ≤ ⌊hi⌋ ⇔ o ≤ hi for integer o: the window of
            // `cartesian_query` without the float-to-int conversions.
            let gap = ((o + 0.5 - f).abs() - 0.5).max(Vec3::ZERO) * q.gap_scale;
            *inside = (lo.x < o.x + 1.0)
                & (o.x <= hi.x)
                & (lo.y < o.y + 1.0)
                & (o.y <= hi.y)
                & (f.z - q.reach.z < o.z + 1.0)
                & (o.z <= f.z + q.reach.z)
                & (gap.length_squared() < 1.0);
        }
        let mut h = [[0u32; BLOCK]; 3];
        for i in 0..BLOCK {
            let hash = pcg3d([
                (base[0].wrapping_add(BLOCK_OFFSETS[0][i]) as u32).wrapping_add(seed[0]),
                (base[1].wrapping_add(BLOCK_OFFSETS[1][i]) as u32).wrapping_add(seed[1]),
                (base[2].wrapping_add(BLOCK_OFFSETS[2][i]) as u32).wrapping_add(seed[2]),
            ]);
            (h[0][i], h[1][i], h[2][i]) = (hash[0], hash[1], hash[2]);
        }
        let mut count = [0u32; BLOCK];
        let mut walk = 0u32;
        for i in 0..BLOCK {
            let c = self.cell_counts.table_count(h[0][i]);
            count[i] = if inside[i] { c } else { 0 };
            walk |= ((count[i] >= TABLE as u32) as u32) << i;
        }
        for i in lanes(walk) {
            count[i] = self.cell_counts.count(h[0][i]);
        }
        let rounds = count.iter().fold(0, |m, &c| m.max(c));
        if rounds > u32::BITS {
            return self.cartesian_cells::<GRAD>(q);
        }
        // Bit k of lane i: impulse k of cell i reaches p.
        let mut hits = [0u32; BLOCK];
        let axes = q.map.axes;
        for k in 0..rounds {
            for i in 0..BLOCK {
                let (u, _) = impulse_numbers(impulse_stream(h[1][i], h[2][i], k));
                let o = Vec3::new(
                    BLOCK_OFFSETS[0][i] as f32,
                    BLOCK_OFFSETS[1][i] as f32,
                    BLOCK_OFFSETS[2][i] as f32,
                );
                let d = (f - o - u) * self.cell;
                let local = match &axes {
                    None => d,
                    Some(fr) => fr.to_local(d),
                };
                let reaches = (local * q.map.inv).length_squared() < 1.0;
                hits[i] |= ((reaches & (k < count[i])) as u32) << k;
            }
        }
        let mut hit_cells = 0u32;
        for (i, &bits) in hits.iter().enumerate() {
            hit_cells |= ((bits != 0) as u32) << i;
        }
        let mut acc = (0.0, Vec3::ZERO);
        for i in lanes(hit_cells) {
            for k in lanes(hits[i]) {
                let k = k as u32;
                let o = Vec3::new(
                    BLOCK_OFFSETS[0][i] as f32,
                    BLOCK_OFFSETS[1][i] as f32,
                    BLOCK_OFFSETS[2][i] as f32,
                );
                let (u, w) = impulse([h[0][i], h[1][i], h[2][i]], k);
                let d = (f - o - u) * self.cell;
                let w = if self.signed { w } else { 1.0 };
                q.map.add::<GRAD>(self.kernel, d, w, &mut acc);
            }
        }
        acc
    }

    fn cylindrical<const GRAD: bool>(
        &self,
        p: Vec3,
        frame: Option<&Frame>,
        kernel_scale: f32,
    ) -> (f32, Vec3) {
        let env = self.env * kernel_scale;
        let r = (p.x * p.x + p.y * p.y).sqrt();
        let radial = if r > 0.0 {
            Vec3::new(p.x / r, p.y / r, 0.0)
        } else {
            Vec3::X
        };
        let cyl = Frame {
            s: radial,
            t: Vec3::new(-radial.y, radial.x, 0.0),
            n: Vec3::Z,
        };
        let kf = frame.copied().unwrap_or(cyl);
        // Eq. 9 with R expressed in the cylindrical frame at p, against (radial, arc, height).
        let rel = Frame {
            s: cyl.to_local(kf.s),
            t: cyl.to_local(kf.t),
            n: cyl.to_local(kf.n),
        };
        let ext = bbox_half_extent(env, &rel);
        let sb = (self.cell.x / ext.x)
            .min(self.cell.y / ext.y)
            .min(self.cell.z / ext.z)
            .min(1.0);
        let map = KernelMap {
            axes: Some(kf),
            inv: 1.0 / (sb * env),
        };
        // Search window (notes/noise.md): a kernel reaching p has its centre within ρ = s_b·max(Sₑ)
        // of p, so in bands overlapping [r − ρ, r + ρ], at angles within asin(ρ / r) of θ(p), and
        // within s_b·ext_z of p along z.
        let rho = sb * env.max_element();
        let reach_z = sb * ext.z / self.cell.z;
        let theta = p.y.atan2(p.x).rem_euclid(2.0 * PI);
        // A kernel at k reaching p has |(p − k)·θ̂| = r_k |sin Δθ| ≤ s_b·ext_y and
        // |(p − k)·r̂| ≤ s_b·ext_x, so cos Δθ > 0 and r_k ≥ r − s_b·ext_x when r > s_b·ext_x.
        let (ex, ey) = (sb * ext.x, sb * ext.y);
        let dtheta = if ex < r && ey < r - ex {
            (ey / (r - ex)).asin()
        } else {
            PI
        };
        let (cr, ca, cz) = (self.cell.x, self.cell.y, self.cell.z);
        let pz = p.z / cz;
        let bz = floor_i32(pz);
        let fz = pz - bz as f32;
        let (z_lo, z_hi) = (floor_i32(fz - reach_z), floor_i32(fz + reach_z));
        let j_lo = floor_i32((r - rho) / cr).max(0);
        let j_hi = floor_i32((r + rho) / cr);
        let mut acc = (0.0, Vec3::ZERO);
        for j in j_lo..=j_hi {
            let n = band_cells(j, cr, ca);
            let width = 2.0 * PI / n as f32;
            let volume = PI * (2 * j + 1) as f32 * cr * cr * cz / n as f32;
            let counts = PoissonTable::new((self.intensity * volume) as f64);
            let (a_lo, a_hi) = arc_window(theta, dtheta, width, n);
            let (r0, r1) = (j as f32 * cr, (j + 1) as f32 * cr);
            for oz in z_lo..=z_hi {
                for a in a_lo..=a_hi {
                    let cell_a = wrap_arc(a, n);
                    let h = cell3_offset(j, cell_a, bz.wrapping_add(oz), &self.offsets);
                    for k in 0..counts.count(h[0]) {
                        let (u, w) = impulse(h, k);
                        // Uniform in the annular sector: r² uniform between r0² and r1².
                        let rk = (r0 * r0 + u.x * (r1 * r1 - r0 * r0)).sqrt();
                        let tk = (cell_a as f32 + u.y) * width;
                        let d = Vec3::new(
                            p.x - rk * tk.cos(),
                            p.y - rk * tk.sin(),
                            (fz - oz as f32 - u.z) * cz,
                        );
                        let w = if self.signed { w } else { 1.0 };
                        map.add::<GRAD>(self.kernel, d, w, &mut acc);
                    }
                }
            }
        }
        acc
    }
}

/// The cells of a band of `n` cells, each `width` radians, that a kernel reaching the point at
/// angle `theta` can sit in: within `dtheta` of it (every cell when that is π, or covers the
/// band). The ends may lie outside [0, n) ([`wrap_arc`] brings them back).
#[inline]
fn arc_window(theta: f32, dtheta: f32, width: f32, n: i32) -> (i32, i32) {
    if dtheta >= PI {
        return (0, n - 1);
    }
    let lo = floor_i32((theta - dtheta) / width);
    let hi = floor_i32((theta + dtheta) / width);
    if hi - lo + 1 >= n {
        (0, n - 1)
    } else {
        (lo, hi)
    }
}

/// Cell `a` of an [`arc_window`] in a band of `n` cells: a ∈ [−n, 2n) (θ ∈ [0, 2π), window ≤
/// π/2 each side), so it wraps without a division.
#[inline(always)]
fn wrap_arc(a: i32, n: i32) -> i32 {
    if a < 0 {
        a + n
    } else if a >= n {
        a - n
    } else {
        a
    }
}

/// Cells in cylindrical band `j` (Liu 2016 §4.2): proportional to the band's midpoint radius so
/// that every cell is ≈ `arc` long and all cells have ≈ equal volume.
#[inline]
pub fn band_cells(j: i32, radial: f32, arc: f32) -> i32 {
    ((2.0 * PI * (j as f32 + 0.5) * radial / arc).round() as i32).max(1)
}

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{uniform_sphere, Pcg32};

    impl Band {
        /// Oracle for the search window: every cell within `w` cells (Cartesian) or every band
        /// within `w` bands and every angular cell (cylindrical), same kernels and shrink.
        fn brute(&self, p: Vec3, frame: &Frame, cylindrical: bool, w: i32) -> f32 {
            let mut acc = (0.0, Vec3::ZERO);
            if !cylindrical {
                let ext = bbox_half_extent(self.env, frame);
                let sb = (self.cell / ext).min_element().min(1.0);
                let map = KernelMap {
                    axes: Some(*frame),
                    inv: 1.0 / (sb * self.env),
                };
                let pc = p / self.cell;
                let base = [floor_i32(pc.x), floor_i32(pc.y), floor_i32(pc.z)];
                let f = pc - Vec3::new(base[0] as f32, base[1] as f32, base[2] as f32);
                let m = self.intensity * self.cell.x * self.cell.y * self.cell.z;
                for oz in -w..=w {
                    for oy in -w..=w {
                        for ox in -w..=w {
                            let h = cell3_offset(
                                base[0] + ox,
                                base[1] + oy,
                                base[2] + oz,
                                &self.offsets,
                            );
                            let o = Vec3::new(ox as f32, oy as f32, oz as f32);
                            for k in 0..poisson(h[0], m) {
                                let (u, wt) = impulse(h, k);
                                let wt = if self.signed { wt } else { 1.0 };
                                map.add::<false>(
                                    self.kernel,
                                    (f - o - u) * self.cell,
                                    wt,
                                    &mut acc,
                                );
                            }
                        }
                    }
                }
            } else {
                let r = (p.x * p.x + p.y * p.y).sqrt();
                let radial = Vec3::new(p.x / r, p.y / r, 0.0);
                let cyl = Frame {
                    s: radial,
                    t: Vec3::new(-radial.y, radial.x, 0.0),
                    n: Vec3::Z,
                };
                let rel = Frame {
                    s: cyl.to_local(frame.s),
                    t: cyl.to_local(frame.t),
                    n: cyl.to_local(frame.n),
                };
                let sb = (self.cell / bbox_half_extent(self.env, &rel))
                    .min_element()
                    .min(1.0);
                let map = KernelMap {
                    axes: Some(*frame),
                    inv: 1.0 / (sb * self.env),
                };
                let (cr, ca, cz) = (self.cell.x, self.cell.y, self.cell.z);
                let bz = floor_i32(p.z / cz);
                let fz = p.z / cz - bz as f32;
                let j0 = floor_i32(r / cr);
                for j in (j0 - w).max(0)..=j0 + w {
                    let n = band_cells(j, cr, ca);
                    let width = 2.0 * PI / n as f32;
                    let m = self.intensity * PI * (2 * j + 1) as f32 * cr * cr * cz / n as f32;
                    let (r0, r1) = (j as f32 * cr, (j + 1) as f32 * cr);
                    for oz in -w..=w {
                        for a in 0..n {
                            let h = cell3_offset(j, a, bz + oz, &self.offsets);
                            for k in 0..poisson(h[0], m) {
                                let (u, wt) = impulse(h, k);
                                let rk = (r0 * r0 + u.x * (r1 * r1 - r0 * r0)).sqrt();
                                let tk = (a as f32 + u.y) * width;
                                let d = Vec3::new(
                                    p.x - rk * tk.cos(),
                                    p.y - rk * tk.sin(),
                                    (fz - oz as f32 - u.z) * cz,
                                );
                                let wt = if self.signed { wt } else { 1.0 };
                                map.add::<false>(self.kernel, d, wt, &mut acc);
                            }
                        }
                    }
                }
            }
            acc.0
        }
    }

    fn band(env: Vec3, cell: Vec3, seed: u32) -> Band {
        let intensity = 3.0 / (4.0 / 3.0 * PI * env.x * env.y * env.z);
        Band::new(Kernel::Wyvill, env, cell, intensity, true, seed)
    }

    /// The bounding-box fit (eq. 9–12) keeps every contributing kernel inside the searched cells:
    /// the windowed sum equals, bit for bit up to summation order, the sum over a ±3-cell block.
    #[test]
    fn oriented_kernels_stay_in_search_window() {
        let mut rng = Pcg32::new(11, 0);
        for i in 0..300 {
            // Strongly prolate kernels (aspect 8) in random orientations, cells partway (§4.5).
            let b = band(Vec3::new(0.2, 0.2, 1.6), Vec3::new(0.4, 0.4, 1.2), i);
            let p = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 20.0 - 10.0;
            let f = Frame::from_normal(uniform_sphere(rng.next_vec2()));
            let fast = b.cartesian::<false>(p, Some(&f), 1.0).0;
            let slow = b.brute(p, &f, false, 3);
            assert!(
                (fast - slow).abs() <= 1e-5 * (1.0 + slow.abs()),
                "{fast} vs {slow} at {p}"
            );
        }
        // Axis-aligned kernels (no frame: the per-cell ellipsoid skip) against the same oracle.
        let identity = Frame {
            s: Vec3::X,
            t: Vec3::Y,
            n: Vec3::Z,
        };
        for i in 0..300 {
            let b = band(Vec3::new(0.35, 0.2, 1.0), Vec3::new(0.4, 0.4, 1.2), i);
            let p = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 20.0 - 10.0;
            let fast = b.cartesian::<false>(p, None, 1.0).0;
            let slow = b.brute(p, &identity, false, 3);
            assert!(
                (fast - slow).abs() <= 1e-5 * (1.0 + slow.abs()),
                "{fast} vs {slow} at {p}"
            );
        }
        let mut nonzero = 0;
        for i in 0..200 {
            let b = band(Vec3::new(0.3, 0.5, 2.0), Vec3::new(0.4, 0.6, 1.5), i);
            let r = 0.2 + 30.0 * rng.next_f32();
            let t = 2.0 * PI * rng.next_f32();
            let p = Vec3::new(r * t.cos(), r * t.sin(), 10.0 * rng.next_f32());
            // Mostly along the pith (as wood features are), some far off it.
            let n = Vec3::Z + 0.7 * uniform_sphere(rng.next_vec2());
            let f = Frame::from_normal(n.normalize());
            let fast = b.cylindrical::<false>(p, Some(&f), 1.0).0;
            let slow = b.brute(p, &f, true, 3);
            nonzero += (slow != 0.0) as i32;
            assert!(
                (fast - slow).abs() <= 1e-5 * (1.0 + slow.abs()),
                "{fast} vs {slow} at {p}"
            );
        }
        assert!(nonzero > 60, "the comparison must see kernels");
    }

    /// The SIMD block search (AVX-512 and AVX2) gives the one-cell-at-a-time value and gradient
    /// bit for bit, for
    /// axis-aligned, upright (turned about z, the layer shrink) and tilted kernels, sparse and
    /// dense cells (counts past the threshold table, many rounds), and both signs of coordinates.
    #[test]
    fn block_search_matches_the_cell_loop() {
        let mut rng = Pcg32::new(5, 0);
        let mut compared = 0;
        for i in 0..3000u32 {
            let env = Vec3::new(
                0.2 + rng.next_f32(),
                0.2 + 2.0 * rng.next_f32(),
                0.2 + 4.0 * rng.next_f32(),
            );
            let per_cell = [0.05f32, 1.2, 6.0][i as usize % 3];
            let cell = env * (0.6 + 0.8 * rng.next_f32());
            let kernel = if i % 4 == 1 {
                Kernel::Bump { sharpness: 1.0 }
            } else {
                Kernel::Wyvill
            };
            let intensity = per_cell / (cell.x * cell.y * cell.z);
            let b = Band::new(kernel, env, cell, intensity, i % 2 == 0, i);
            let p = (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0) * 200.0;
            let angle = 2.0 * PI * rng.next_f32();
            let (c, s) = (angle.cos(), angle.sin());
            let upright = Frame {
                s: Vec3::new(c, s, 0.0),
                t: Vec3::new(-s, c, 0.0),
                n: Vec3::Z,
            };
            let tilted = Frame::from_normal(uniform_sphere(rng.next_vec2()));
            for frame in [None, Some(&upright), Some(&tilted)] {
                let q = b.cartesian_query(p, frame, 1.0);
                let reference = b.cartesian_cells::<true>(&q);
                let value = b.cartesian_cells::<false>(&q).0;
                // The dispatched search and the search at every level this CPU has.
                let mut searches = vec![(
                    b.cartesian::<true>(p, frame, 1.0),
                    b.cartesian::<false>(p, frame, 1.0).0,
                )];
                for simd in Simd::ALL.into_iter().filter(|&s| s <= Simd::best()) {
                    // SAFETY: no wider than `Simd::best()`.
                    searches.push(unsafe {
                        (
                            b.cartesian_search_on::<true>(simd, &q),
                            b.cartesian_search_on::<false>(simd, &q).0,
                        )
                    });
                }
                for (fast, fast_value) in searches {
                    assert_eq!(
                        fast.0.to_bits(),
                        reference.0.to_bits(),
                        "value at {p} ({i})"
                    );
                    assert_eq!(fast_value.to_bits(), value.to_bits(), "value at {p} ({i})");
                    for k in 0..3 {
                        assert_eq!(
                            fast.1[k].to_bits(),
                            reference.1[k].to_bits(),
                            "∇ at {p} ({i})"
                        );
                    }
                }
                compared += (reference.0 != 0.0) as u32;
            }
        }
        assert!(
            compared > 3000,
            "the comparison must see kernels ({compared})"
        );
    }

    /// The integer thresholds reproduce the f64 walk exactly: at random hashes, at every threshold
    /// and one below it (where a rounding slip would show), and past the table (the walk fallback).
    #[test]
    fn poisson_table_matches_the_walk() {
        for m in [1e-4f64, 0.0716, 0.256, 1.19, 3.0, 11.0, 64.0] {
            let table = PoissonTable::new(m);
            let walk = |h: u32| poisson_with(h, m, (-m).exp());
            // The lane count equals the walk below the table's end and says so past it.
            let check = |h: u32| {
                assert_eq!(table.count(h), walk(h), "m {m} h {h}");
                let lanes = table.table_count(h);
                assert_eq!(lanes, walk(h).min(TABLE as u32), "lanes: m {m} h {h}");
            };
            (0..20_000u32).for_each(|i| check(mix32(i ^ 0x1234_5678)));
            for &t in &table.thresholds {
                for h in [t.saturating_sub(1), t, t + 1] {
                    if h <= u32::MAX as u64 {
                        check(h as u32);
                    }
                }
            }
            [0, 1, u32::MAX - 1, u32::MAX].into_iter().for_each(check);
        }
    }

    #[test]
    fn poisson_mean_and_variance() {
        // Mean and variance of the count both equal m; 10⁵ draws: σ(mean) = sqrt(m/1e5).
        for m in [0.3f32, 2.0, 10.0, 60.0] {
            let n = 100_000;
            let (mut s, mut s2) = (0.0f64, 0.0f64);
            for i in 0..n {
                let k = poisson(mix32(i), m) as f64;
                s += k;
                s2 += k * k;
            }
            let mean = s / n as f64;
            let var = s2 / n as f64 - mean * mean;
            let sd = (m as f64 / n as f64).sqrt();
            assert!((mean - m as f64).abs() < 5.0 * sd, "m={m} mean={mean}");
            assert!((var / m as f64 - 1.0).abs() < 0.03, "m={m} var={var}");
        }
    }
}
