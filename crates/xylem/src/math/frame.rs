//! Orthonormal frames: the local shading frame (z = normal) and the wood frame fields.

use glam::{Mat3, Vec3};

/// An orthonormal basis `(s, t, n)`; `to_local` maps world vectors into coordinates where `n` is +z.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// First tangent (local +x).
    pub s: Vec3,
    /// Second tangent (local +y), n × s.
    pub t: Vec3,
    /// Normal (local +z).
    pub n: Vec3,
}

impl Frame {
    /// A frame around unit normal `n`, branch-free and continuous except on one half-line
    /// (Duff et al. 2017, "Building an Orthonormal Basis, Revisited", JCGT 6(1), Listing 3).
    #[inline]
    pub fn from_normal(n: Vec3) -> Self {
        let sign = 1.0_f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let s = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        Frame { s, t, n }
    }

    /// A frame with normal `n` whose `s` axis is the projection of `tangent` onto the plane of `n`
    /// (Gram–Schmidt); falls back to [`Frame::from_normal`] when `tangent` is parallel to `n`.
    #[inline(always)]
    pub fn from_normal_tangent(n: Vec3, tangent: Vec3) -> Self {
        let s = tangent - n * n.dot(tangent);
        let len2 = s.length_squared();
        if !(len2 > 1e-12) || !len2.is_finite() {
            return Frame::from_normal(n);
        }
        let s = s / len2.sqrt();
        Frame {
            s,
            t: n.cross(s),
            n,
        }
    }

    /// World vector `v` in frame coordinates (n = +z).
    #[inline]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    /// Frame coordinates `v` back in world space (the inverse of [`Frame::to_local`]).
    #[inline]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }

    /// The matrix whose columns are `s, t, n` (local → world).
    pub fn matrix(&self) -> Mat3 {
        Mat3::from_cols(self.s, self.t, self.n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn assert_orthonormal(f: &Frame) {
        for (a, b) in [(f.s, f.t), (f.t, f.n), (f.s, f.n)] {
            assert!(a.dot(b).abs() < 1e-5);
        }
        for v in [f.s, f.t, f.n] {
            assert!((v.length() - 1.0).abs() < 1e-5);
        }
        assert!((f.s.cross(f.t) - f.n).length() < 1e-5, "right-handed");
    }

    #[test]
    fn frames_are_orthonormal_and_round_trip() {
        let mut rng = crate::math::Pcg32::new(7, 0);
        for _ in 0..1000 {
            let n = crate::math::uniform_sphere(rng.next_vec2());
            let f = Frame::from_normal(n);
            assert_orthonormal(&f);
            let v = crate::math::uniform_sphere(rng.next_vec2());
            assert!((f.to_world(f.to_local(v)) - v).length() < 1e-5);
        }
        assert_orthonormal(&Frame::from_normal(-Vec3::Z));
        assert_orthonormal(&Frame::from_normal_tangent(Vec3::Z, Vec3::Z));
        assert_orthonormal(&Frame::from_normal_tangent(
            Vec3::Z,
            Vec3::new(1.0, 1.0, 5.0),
        ));
    }
}
