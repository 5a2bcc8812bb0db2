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

mod cartesian;
mod cylindrical;
mod impulses;
mod one_dimensional;
#[cfg(test)]
mod tests;

use impulses::{impulse, impulse_numbers, impulse_stream, poisson, PoissonTable, TABLE};
pub use one_dimensional::SparseConvolution1;

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
pub(crate) const MAX_IMPULSES_PER_CELL: f32 = 64.0;
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
    pub(crate) fn eval_oriented_with<const GRAD: bool>(
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
    pub(crate) fn eval_oriented_many<const N: usize>(
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
}
