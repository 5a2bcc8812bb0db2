//! Procedural noise: integer hashes, value / gradient noise, and the sparse convolution noise of
//! Liu et al. 2016 §4 that the wood model is built from.
//!
//! Every function here is a **pure function of (point, parameters, seed)**: no tables to build,
//! no global state, random access anywhere, the same bits for the same inputs on every run and
//! thread. Everything is `f32`, allocation-free and inlinable; hashing is integer-only, so
//! precision does not degrade far from the origin beyond the f32 resolution of the point itself.
//!
//! # Lattice noise (unit cells; scale the point to change frequency)
//! | function | what | range |
//! | --- | --- | --- |
//! | [`gradient3`], [`gradient3_grad`] | improved Perlin noise (Perlin 2002), quintic fade | ±1.04 (measured) |
//! | [`gradient1`], [`gradient1_grad`] | 1D gradient noise | ±0.5 |
//! | [`value3`], [`value3_grad`] | value noise, quintic fade | [−1, 1) |
//! | [`value1`], [`value1_grad`] | 1D value noise | [−1, 1) |
//!
//! Many points at once: [`gradient3_many`]`(&points, seed, &mut out)` runs the kernel on 16 / 8 /
//! 4 points per call (AVX-512 / AVX2 / SSE2, detected at run time —
//! [`crate::simd::Simd::best`]; scalar elsewhere), with the values of [`gradient3`];
//! [`Fractal::eval_many`] likewise.
//!
//! `*_grad` returns `(value, ∇value)` with the analytic gradient. The [`Noise3`] trait wraps
//! them ([`Gradient`], [`Value`]) and [`SparseConvolution`] for code generic over the noise.
//! Gradient noise at lattice points is 0; its variance is 0.0820 (value noise: 0.1604), derived
//! in notes/noise.md.
//!
//! # Sums, cells and warps
//! - [`Fractal`] `{ kind: Fbm | Turbulence | Ridged, basis: Gradient | Value, octaves,
//!   lacunarity, gain }` with `eval(p, seed)` / `eval_grad(p, seed)`; `Fractal::fbm(n)` is the
//!   usual fBm (lacunarity 2, gain ½). Gradient-basis sums evaluate their octaves in SIMD lanes
//!   (8 per AVX2 call, else 4 per SSE2 call); `eval_many` puts points in the lanes instead.
//! - [`cellular3`]`(p, jitter, seed)` → [`CellularSample`] `{ f1, f2, id, grad_f1, grad_f2,
//!   nearest }` (`edge()` = F2 − F1); [`feature_point`] gives a cell's point.
//! - [`Warp`] `{ fractal, strength, levels }`: Quilez's q / r domain warp, `sample` also returns
//!   q and r; `eval_grad` by the chain rule.
//! - [`hash`]: `pcg3d`, `cell3`, `mix32` and the lattice hash, for anything that needs
//!   per-cell random numbers.
//!
//! # Sparse convolution noise (Liu, Dong, Hašan, Marschner 2016 §4)
//! [`SparseConvolution`] is a plain struct of parameters (serde-ready); evaluate with
//! ```
//! use xylem::noise::{SparseConvolution, Kernel, Weights, Cells};
//! use xylem::math::{Frame, Vec3};
//! let pores = SparseConvolution {
//!     kernel: Kernel::Bump { sharpness: 1.0 },    // eq. 6; Kernel::Wyvill is eq. 4
//!     density: 0.5,                              // mean kernels overlapping a point
//!     envelope: Vec3::new(0.05, 0.05, 0.6),      // semi-axes Sₑ (mm) along the kernel axes
//!     cell: Vec3::new(0.1, 0.1, 0.8),            // cell size S_c, decoupled from Sₑ (§4.5)
//!     magnitude: 1.0,                            // α
//!     weights: Weights::Unit,                    // eq. 7 (Weights::Signed: zero mean)
//!     cells: Cells::Cartesian,                   // or Cells::Cylindrical (§4.2, pith = z axis)
//!     bands: 1, size_factor: 0.5, dropoff: 1.0,  // eq. 8: band i is β^i smaller, α β^(γ i)
//! };
//! pores.validate().unwrap();
//! let p = Vec3::new(1.0, 2.0, 3.0);
//! let v: f32 = pores.eval(p, 7);                       // kernels aligned to the cells
//! let (v2, grad) = pores.eval_grad(p, 7);              // eq. 13
//! let frame = Frame::from_normal(Vec3::new(0.0, 0.3, 1.0).normalize());
//! let w = pores.eval_oriented(p, &frame, 7);           // eq. 12, frame queried at p
//! let (w2, gw) = pores.eval_oriented_grad(p, &frame, 7);
//! assert_eq!(v, v2);
//! assert_eq!(w, w2);
//! assert!(grad.is_finite() && gw.is_finite());
//! ```
//! - **Impulses**: per cell a Poisson count with mean λ·V_cell, λ = density / (4/3 π eₓ e_y e_z),
//!   drawn from the cell hash; positions uniform in the cell from a hash of (cell, index) (§4.1).
//! - **Orientation**: the frame's `s, t, n` carry the envelope's x, y, z semi-axes. Each kernel is
//!   shrunk by s_b = min(1, min_i S_c,i / ext_i) (eq. 9–11, ext = row norms of R·Sₑ) so it never
//!   reaches further than one cell; the search window is then the cells the shrunk kernel's
//!   bounding box around `p` overlaps (at most 3 per axis). `density` refers to the nominal
//!   (unshrunk) kernels. Without a frame, Cartesian kernels are axis-aligned and cylindrical
//!   kernels follow (r̂, θ̂, ẑ) at `p`.
//! - **Cylindrical cells** (§4.2): `cell = (radial width, arc length, height)`; points are in
//!   pith coordinates (pith along z); band j holds `max(1, round(2π r_mid / arc))` cells and its
//!   impulse count uses the cell's exact volume, so λ is uniform.
//! - **Moments** (Campbell's theorem, derivation in notes/noise.md): Wyvill kernel, one band,
//!   nominal kernels: mean = α·density·48/315 for unit weights (0 for signed), variance =
//!   α²·density·0.0682 for unit weights (one third of that for signed weights).
//! - [`SparseConvolution1`]`::new(width, seed).eval(x)` → (value, derivative): the 1D version
//!   with one impulse per cell (Wyvill kernel of half-width `width`, signs ±1), bounded by
//!   construction: |n| ≤ 1, |n′| ≤ 2.5462 / width; standard deviation 0.4129, mean zero-crossing
//!   spacing 1.978 width (the wood model's growth-time noise and interlock angle).

mod cellular;
mod fractal;
mod gradient;
pub mod hash;
mod lanes;
mod lattice;
mod sparse;
mod value;
mod warp;

pub use cellular::{cellular3, feature_point, CellularSample};
pub use fractal::{Basis, Fractal, FractalKind};
pub use gradient::{
    fade, gradient1, gradient1_grad, gradient3, gradient3_grad, gradient3_many, gradient3_many_with,
};
pub use sparse::{
    Cells, Kernel, NoiseError, SeededSparse, SparseConvolution, SparseConvolution1, Weights,
};
pub use value::{value1, value1_grad, value3, value3_grad};
pub use warp::{Warp, WarpSample};

use glam::Vec3;

/// A 3D scalar noise with its analytic gradient; a pure function of point and seed.
pub trait Noise3: Send + Sync {
    /// The noise value at `p` for `seed`.
    fn eval(&self, p: Vec3, seed: u32) -> f32;
    /// The noise value and its gradient ∇ at `p`.
    fn eval_grad(&self, p: Vec3, seed: u32) -> (f32, Vec3);
}

/// Improved Perlin gradient noise as a [`Noise3`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Gradient;

/// Value noise as a [`Noise3`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Value;

impl Noise3 for Gradient {
    #[inline(always)]
    fn eval(&self, p: Vec3, seed: u32) -> f32 {
        gradient3(p, seed)
    }
    #[inline(always)]
    fn eval_grad(&self, p: Vec3, seed: u32) -> (f32, Vec3) {
        gradient3_grad(p, seed)
    }
}

impl Noise3 for Value {
    #[inline(always)]
    fn eval(&self, p: Vec3, seed: u32) -> f32 {
        value3(p, seed)
    }
    #[inline(always)]
    fn eval_grad(&self, p: Vec3, seed: u32) -> (f32, Vec3) {
        value3_grad(p, seed)
    }
}

impl Noise3 for SparseConvolution {
    #[inline]
    fn eval(&self, p: Vec3, seed: u32) -> f32 {
        SparseConvolution::eval(self, p, seed)
    }
    #[inline]
    fn eval_grad(&self, p: Vec3, seed: u32) -> (f32, Vec3) {
        SparseConvolution::eval_grad(self, p, seed)
    }
}
