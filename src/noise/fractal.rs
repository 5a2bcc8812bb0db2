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
        match (self.kind, self.basis) {
            (FractalKind::Fbm, Basis::Gradient) => self.fbm_gradient(p, seed),
            _ => self.sum::<false>(p, seed).0,
        }
    }

    /// Value and analytic gradient (the chain rule through |·| uses sign(n); at n = 0 the
    /// turbulence and ridged sums have a crease where the gradient is one-sided).
    #[inline]
    pub fn eval_grad(&self, p: Vec3, seed: u32) -> (f32, Vec3) {
        self.sum::<true>(p, seed)
    }

    /// The hot path: fBm of gradient noise. Octaves are independent, so four at a time go
    /// through the 4-lane kernel (lane k = octave i + k); octave seeds are one add apart on the
    /// scrambled seed. Same points, seeds and summation order as the scalar path.
    #[inline]
    fn fbm_gradient(&self, p: Vec3, seed: u32) -> f32 {
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
            total += amps[0] * n[0];
            total += amps[1] * n[1];
            total += amps[2] * n[2];
            total += amps[3] * n[3];
            left = left.saturating_sub(4);
        }
        if left == 1 {
            total += amp * gradient3_s(p * freq + shift, s);
        }
        total
    }

    fn sum<const GRAD: bool>(&self, p: Vec3, seed: u32) -> (f32, Vec3) {
        let mut s = mix32(seed);
        let (mut freq, mut amp) = (1.0f32, 1.0f32);
        let (mut total, mut grad) = (0.0f32, Vec3::ZERO);
        let mut shift = Vec3::ZERO;
        for _ in 0..self.octaves {
            let q = p * freq + shift;
            let (n, g) = if GRAD {
                match self.basis {
                    Basis::Gradient => gradient3_grad_s(q, s),
                    Basis::Value => value3_grad_s(q, s),
                }
            } else {
                let n = match self.basis {
                    Basis::Gradient => gradient3_s(q, s),
                    Basis::Value => value3_grad_s(q, s).0,
                };
                (n, Vec3::ZERO)
            };
            // d/dp of n(freq p + shift) = freq ∇n.
            let (v, dv) = match self.kind {
                FractalKind::Fbm => (n, g),
                FractalKind::Turbulence => (n.abs(), g * n.signum()),
                FractalKind::Ridged => {
                    let r = 1.0 - n.abs();
                    (r * r, g * (-2.0 * r * n.signum()))
                }
            };
            total += amp * v;
            if GRAD {
                grad += (amp * freq) * dv;
            }
            freq *= self.lacunarity;
            amp *= self.gain;
            shift += SHIFT;
            s = s.wrapping_add(OCTAVE_SEED_STEP);
        }
        (total, grad)
    }
}
