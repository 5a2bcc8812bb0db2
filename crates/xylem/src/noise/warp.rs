//! Domain warping: a fractal sum evaluated at a point displaced by other fractal sums, in the
//! nested q / r form of I. Quilez, "Domain warping" (2002/2012): `q(p) = (F₀(p), F₁(p), F₂(p))`,
//! `r(p) = (F₃(p + s q), F₄(…), F₅(…))`, `value = F(p + s r)` (one level: `F(p + s q)`), with
//! the analytic gradient by the chain rule through both displacements. Quilez separates the
//! components by constant offsets of one noise; we give each component its own seed instead, which
//! keeps the coordinates (and their f32 resolution) where the caller put them.

use super::fractal::Fractal;
use glam::{Mat3, Vec3};
use serde::{Deserialize, Serialize};

/// Parameters of a warped fractal.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Warp {
    /// The sum used for q, r and the final lookup.
    pub fractal: Fractal,
    /// Displacement scale s (Quilez uses 4).
    pub strength: f32,
    /// 1: value = F(p + s q); 2: value = F(p + s r) with r warped by q.
    pub levels: u32,
}

impl Default for Warp {
    fn default() -> Self {
        Warp {
            fractal: Fractal::fbm(4),
            strength: 4.0,
            levels: 2,
        }
    }
}

/// A warped-fractal evaluation with its intermediate fields (textures colour by |q| and r).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WarpSample {
    /// The warped fractal's value at p + s r.
    pub value: f32,
    /// The first warp field q(p).
    pub q: Vec3,
    /// Equal to `q` when `levels` is 1.
    pub r: Vec3,
}

/// Seed of component `k` (0–2: q, 3–5: r).
#[inline]
fn component_seed(seed: u32, k: u32) -> u32 {
    seed ^ super::hash::mix32(0x68e3_1da4 ^ k)
}

impl Warp {
    fn field(&self, p: Vec3, first: u32, seed: u32) -> Vec3 {
        Vec3::new(
            self.fractal.eval(p, component_seed(seed, first)),
            self.fractal.eval(p, component_seed(seed, first + 1)),
            self.fractal.eval(p, component_seed(seed, first + 2)),
        )
    }

    /// Value with the intermediate q and r.
    pub fn sample(&self, p: Vec3, seed: u32) -> WarpSample {
        self.sample_drifting(p, Vec3::ZERO, seed)
    }

    /// [`Warp::sample`] with the warp fields q and r looked up at `drift` from where they would
    /// be (the final lookup stays at p + s r): animating `drift` over time makes the pattern flow
    /// and re-form instead of sliding ("Procedural Textures: wood, marble and beyond").
    pub(crate) fn sample_drifting(&self, p: Vec3, drift: Vec3, seed: u32) -> WarpSample {
        let s = self.strength;
        let q = self.field(p + drift, 0, seed);
        let r = if self.levels >= 2 {
            self.field(p + s * q + drift, 3, seed)
        } else {
            q
        };
        WarpSample {
            value: self.fractal.eval(p + s * r, seed),
            q,
            r,
        }
    }

    /// The warped fractal's value at `p` (see [`Warp::sample`]).
    pub fn eval(&self, p: Vec3, seed: u32) -> f32 {
        self.sample(p, seed).value
    }

    /// Value and gradient: with J_q the Jacobian of q, J_r = J_F(p + s q) (I + s J_q) and
    /// ∇value = (I + s J_r)ᵀ ∇F(p + s r).
    pub fn eval_grad(&self, p: Vec3, seed: u32) -> (f32, Vec3) {
        let s = self.strength;
        let field = |x: Vec3, first: u32| {
            let c: [(f32, Vec3); 3] = std::array::from_fn(|k| {
                self.fractal
                    .eval_grad(x, component_seed(seed, first + k as u32))
            });
            // Rows of the Jacobian are the component gradients.
            let jac = Mat3::from_cols(c[0].1, c[1].1, c[2].1).transpose();
            (Vec3::new(c[0].0, c[1].0, c[2].0), jac)
        };
        let (q, jq) = field(p, 0);
        let (r, jr) = if self.levels >= 2 {
            let (r, jf) = field(p + s * q, 3);
            (r, jf * (Mat3::IDENTITY + s * jq))
        } else {
            (q, jq)
        };
        let (v, g) = self.fractal.eval_grad(p + s * r, seed);
        (v, (Mat3::IDENTITY + s * jr).transpose() * g)
    }
}
