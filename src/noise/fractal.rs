//! Fractal sums of a lattice noise: fBm, turbulence and ridged multifractal (Musgrave, in Ebert et
//! al., *Texturing and Modeling* 3rd ed., ch. 16: `fBm`, `Turbulence`, `RidgedMultifractal`),
//! with analytic gradients. Octave i samples the basis at `lacunarity^i · p + shift_i` with its
//! own seed; the small irrational shift keeps lattice points of different octaves apart (gradient
//! noise vanishes on its lattice, so unshifted octaves with lacunarity 2 would all vanish at the
//! integer points).

use super::gradient::{gradient3_grad_s, gradient3_s, gradient3_x4_affine};
use super::hash::mix32;
use super::value::value3_grad_s;
use glam::Vec3;
use serde::{Deserialize, Serialize};

/// Which lattice noise the octaves sum.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Basis {
    Gradient,
    Value,
}

/// How the octaves combine.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FractalKind {
    /// Σ gainⁱ n(λⁱ p): fractional Brownian motion.
    Fbm,
    /// Σ gainⁱ |n(λⁱ p)| (Perlin 1985's turbulence): creases where the noise crosses zero.
    Turbulence,
    /// Σ gainⁱ (1 − |n(λⁱ p)|)²: sharp ridges along the zero set (a simplified ridged
    /// multifractal without the inter-octave weighting, so every octave stays independent).
    Ridged,
}

/// A fractal sum of octaves of a basis noise.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fractal {
    pub kind: FractalKind,
    pub basis: Basis,
    pub octaves: u32,
    /// Frequency ratio between octaves (typically 2).
    pub lacunarity: f32,
    /// Amplitude ratio between octaves (typically ½; the Hurst exponent is −log₂ gain).
    pub gain: f32,
}

impl Default for Fractal {
    fn default() -> Self {
        Fractal {
            kind: FractalKind::Fbm,
            basis: Basis::Gradient,
            octaves: 5,
            lacunarity: 2.0,
            gain: 0.5,
        }
    }
}

/// Per-octave shifts (fractional parts of multiples of the plastic-number sequence, well spread).
/// Octave seeds: the scrambled seed plus i times the golden-ratio constant.
const OCTAVE_SEED_STEP: u32 = 0x9e37_79b9;

const SHIFT: Vec3 = Vec3::new(0.754_877_7, 0.569_840_3, 0.430_159_7);

impl Fractal {
    /// fBm with the default gradient basis, lacunarity 2 and gain ½.
    pub fn fbm(octaves: u32) -> Self {
        Fractal {
            octaves,
            ..Default::default()
        }
    }

    /// Σ of the amplitudes, Σ gainⁱ: a bound for |fBm| / max|basis| and the scale textures use
    /// to normalise.
    pub fn amplitude_sum(&self) -> f32 {
        (0..self.octaves).map(|i| self.gain.powi(i as i32)).sum()
    }

    #[inline]
    pub fn eval(&self, p: Vec3, seed: u32) -> f32 {
        match (self.basis, self.kind) {
            (Basis::Gradient, FractalKind::Fbm) => self.gradient_lanes(p, seed, |n| n),
            (Basis::Gradient, FractalKind::Turbulence) => self.gradient_lanes(p, seed, f32::abs),
            (Basis::Gradient, FractalKind::Ridged) => self.gradient_lanes(p, seed, ridge),
            (Basis::Value, _) => self.sum::<false, _>(p, seed, value3_grad_s).0,
        }
    }

    /// Value and analytic gradient (the chain rule through |·| uses sign(n); at n = 0 the
    /// turbulence and ridged sums have a crease where the gradient is one-sided).
    #[inline]
    pub fn eval_grad(&self, p: Vec3, seed: u32) -> (f32, Vec3) {
        match self.basis {
            Basis::Gradient => self.sum::<true, _>(p, seed, gradient3_grad_s),
            Basis::Value => self.sum::<true, _>(p, seed, value3_grad_s),
        }
    }

    /// (fold(n), d fold / dn) of this sum's kind.
    #[inline(always)]
    fn fold(&self, n: f32) -> (f32, f32) {
        match self.kind {
            FractalKind::Fbm => (n, 1.0),
            FractalKind::Turbulence => (n.abs(), n.signum()),
            FractalKind::Ridged => {
                let r = 1.0 - n.abs();
                (r * r, -2.0 * r * n.signum())
            }
        }
    }

    /// The hot path: sums of gradient noise. Octaves are independent, so four at a time go
    /// through the 4-lane kernel (lane k = octave i + k), each folded by `fold` (identity, |n|,
    /// ridge); octave seeds are one add apart on the scrambled seed. Same points, seeds and
    /// summation order as the scalar path.
    #[inline(always)]
    fn gradient_lanes(&self, p: Vec3, seed: u32, fold: impl Fn(f32) -> f32) -> f32 {
        let mut s = mix32(seed);
        let (mut freq, mut amp, mut total) = (1.0f32, 1.0f32, 0.0f32);
        let mut shift = Vec3::ZERO;
        let mut left = self.octaves;
        while left >= 2 {
            // Always four lanes (fully unrolled); lanes past the last octave get amplitude 0.
            let (mut f, mut sh, mut seeds, mut amps) =
                ([0.0f32; 4], [[0.0f32; 4]; 3], [0u32; 4], [0.0f32; 4]);
            for k in 0..4 {
                (f[k], sh[0][k], sh[1][k], sh[2][k], seeds[k]) =
                    (freq, shift.x, shift.y, shift.z, s);
                amps[k] = if (k as u32) < left { amp } else { 0.0 };
                freq *= self.lacunarity;
                amp *= self.gain;
                shift += SHIFT;
                s = s.wrapping_add(OCTAVE_SEED_STEP);
            }
            let n = gradient3_x4_affine(p, f, sh, seeds);
            total += amps[0] * fold(n[0]);
            total += amps[1] * fold(n[1]);
            total += amps[2] * fold(n[2]);
            total += amps[3] * fold(n[3]);
            left = left.saturating_sub(4);
        }
        if left == 1 {
            total += amp * fold(gradient3_s(p * freq + shift, s));
        }
        total
    }

    /// The general sum over a basis returning (value, gradient), with the fold of `kind`.
    #[inline]
    fn sum<const GRAD: bool, B: Fn(Vec3, u32) -> (f32, Vec3)>(
        &self,
        p: Vec3,
        seed: u32,
        basis: B,
    ) -> (f32, Vec3) {
        let mut s = mix32(seed);
        let (mut freq, mut amp) = (1.0f32, 1.0f32);
        let (mut total, mut grad) = (0.0f32, Vec3::ZERO);
        let mut shift = Vec3::ZERO;
        for _ in 0..self.octaves {
            let (n, g) = basis(p * freq + shift, s);
            let (v, dv) = self.fold(n);
            total += amp * v;
            if GRAD {
                // d/dp of fold(n(freq p + shift)) = fold'(n) freq ∇n.
                grad += (amp * freq * dv) * g;
            }
            freq *= self.lacunarity;
            amp *= self.gain;
            shift += SHIFT;
            s = s.wrapping_add(OCTAVE_SEED_STEP);
        }
        (total, grad)
    }
}

/// The ridged fold (1 − |n|)².
#[inline(always)]
fn ridge(n: f32) -> f32 {
    let r = 1.0 - n.abs();
    r * r
}
