//! Distortion of the wood volumes (Liu et al. 2016 §5): `f(p) = p + Σ mᵢ(p) aᵢ(p)` with the
//! displacement directions aᵢ ∈ {r̂, θ̂, ẑ} and scalar magnitude fields mᵢ (noise). Every volume is
//! looked up at f(p); vectors are transported contravariantly (J⁻¹ v, eq. 17) and gradients
//! covariantly (Jᵀ g, eq. 18).

use crate::math::Frame;
use glam::{Mat3, Vec3};

/// A scalar magnitude field m(p) with its gradient ∇m(p) (mm and mm/mm).
pub trait Magnitude {
    /// The magnitude m(p) and its gradient ∇m(p).
    fn eval(&self, p: Vec3) -> (f32, Vec3);
}

impl<F: Fn(Vec3) -> (f32, Vec3)> Magnitude for F {
    #[inline]
    fn eval(&self, p: Vec3) -> (f32, Vec3) {
        self(p)
    }
}

/// One displacement term: a unit direction `dir`, magnitude `m` and its gradient `grad_m` at p.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Displacement {
    /// Unit displacement direction aᵢ(p) (r̂, θ̂ or ẑ).
    pub dir: Vec3,
    /// Magnitude mᵢ(p) (mm).
    pub m: f32,
    /// Gradient ∇mᵢ(p).
    pub grad_m: Vec3,
}

/// The distorted lookup point f(p) and the foldover-safe Jacobian of f.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Distortion {
    /// f(p), where every volume is looked up.
    pub point: Vec3,
    /// J ≈ I + Σ aᵢ ⊗ ∇mᵢ / (1 + ‖∇mᵢ‖) (eq. 22, the m J_a term of eq. 20 omitted as in the paper),
    /// or the exact J where a volume uses [`JacobianModel::Exact`].
    pub jacobian: Mat3,
}

impl Distortion {
    /// No distortion: f(p) = p, J = I.
    #[inline]
    pub fn identity(p: Vec3) -> Self {
        Distortion {
            point: p,
            jacobian: Mat3::IDENTITY,
        }
    }

    /// Add one displacement term: f += m a (eq. 15) and J += a ⊗ ∇m / (1 + ‖∇m‖) (eq. 22). The
    /// compression keeps J = I + a ⊗ g with ‖g‖ < 1, so det J = 1 + a·g > 0 for one term: no
    /// singularity however steep the noise.
    #[inline]
    pub fn add(&mut self, d: Displacement) {
        self.point += d.m * d.dir;
        let g = d.grad_m / (1.0 + d.grad_m.length());
        self.jacobian += outer(d.dir, g);
    }

    /// J⁻¹ (for transporting several vectors); identity when J is singular (only possible when
    /// several terms combine badly), so results stay finite.
    #[inline]
    pub(crate) fn inverse_jacobian(&self) -> Mat3 {
        let det = self.jacobian.determinant();
        if det.abs() > 1e-6 && det.is_finite() {
            self.jacobian.inverse()
        } else {
            Mat3::IDENTITY
        }
    }

    /// Contravariant transport of a vector field looked up at f(p): J⁻¹ v (eq. 17).
    #[inline]
    pub fn vector(&self, v: Vec3) -> Vec3 {
        self.inverse_jacobian() * v
    }

    /// Covariant transport of a gradient looked up at f(p): Jᵀ g = ∇(s ∘ f)(p) (eq. 18).
    #[inline]
    pub fn gradient(&self, g: Vec3) -> Vec3 {
        self.jacobian.transpose() * g
    }
}

/// Which Jacobian of the distortion transports fibre directions and gradients (notes/wood.md §5).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum JacobianModel {
    /// Liu et al. 2016 eq. 22: J ≈ I + Σ aᵢ ⊗ ∇mᵢ / (1 + ‖∇mᵢ‖), the mᵢ ∂aᵢ/∂p terms of eq. 20
    /// dropped and each gradient compressed so one term can never fold J over (the default).
    #[default]
    Simplified,
    /// The full derivative of f(p) = p + Σ mᵢ aᵢ(p) ([`exact_jacobian`]: eq. 19–20 with the
    /// frame's rotation), uncompressed; J⁻¹ falls back to I where it is singular.
    Exact,
}

/// The outer product a ⊗ b as a matrix: (a ⊗ b)ᵢⱼ = aᵢ bⱼ.
#[inline]
fn outer(a: Vec3, b: Vec3) -> Mat3 {
    Mat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// The exact Jacobian of f(p) = p + Σ mᵢ aᵢ with aᵢ = (r̂, θ̂, ẑ)(p) (eq. 19 plus the m J_a term of
/// eq. 20): ∂r̂/∂p = θ̂ ⊗ θ̂ / r, ∂θ̂/∂p = −r̂ ⊗ θ̂ / r, ∂ẑ/∂p = 0 (notes/wood.md). `terms` are
/// (m, ∇m) along r̂, θ̂, ẑ. For tests and analysis; the model uses the safe form of
/// [`Distortion::add`].
pub fn exact_jacobian(p: Vec3, frame: &Frame, terms: [(f32, Vec3); 3]) -> Mat3 {
    let r = (p.x * p.x + p.y * p.y)
        .sqrt()
        .max(crate::field::PITH_EPSILON);
    let (rh, th, zh) = (frame.s, frame.t, frame.n);
    let [(mr, gr), (mt, gt), (_mz, gz)] = terms;
    Mat3::IDENTITY + outer(rh, gr) + outer(th, gt) + outer(zh, gz) + outer(th, th) * (mr / r)
        - outer(rh, th) * (mt / r)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::cylinder_frame;

    #[test]
    fn safe_jacobian_stays_invertible_for_steep_noise() {
        let mut d = Distortion::identity(Vec3::ONE);
        d.add(Displacement {
            dir: Vec3::X,
            m: 1.0,
            grad_m: Vec3::new(-1e6, 0.0, 0.0),
        });
        assert!(d.jacobian.determinant() > 0.0);
        let v = d.vector(Vec3::new(1.0, 2.0, 3.0));
        assert!(v.is_finite());
    }

    #[test]
    fn gradient_transport_is_the_chain_rule() {
        // s(q) = c·q, f(p) = p + m a with constant a and linear m: ∇(s∘f) = c + (a·c) ∇m, which
        // equals Jᵀ c for the exact J = I + a ⊗ ∇m.
        let a = Vec3::new(0.0, 0.6, 0.8);
        let gm = Vec3::new(0.01, -0.02, 0.005);
        let c = Vec3::new(1.0, -2.0, 0.5);
        let mut d = Distortion::identity(Vec3::ZERO);
        d.add(Displacement {
            dir: a,
            m: 0.0,
            grad_m: gm,
        });
        let expected = c + a.dot(c) * gm;
        // The compression 1/(1 + ‖∇m‖) changes the result by O(‖∇m‖²) only.
        assert!((d.gradient(c) - expected).length() < 2.0 * gm.length() * gm.length() * c.length());
        let _ = cylinder_frame(Vec3::X);
    }
}
