//! Interlocked grain (Liu et al. 2016 §6.1.5): the cylindrical frame rotated about r̂ by an angle
//! that depends on r, so the fibre helix reverses with radius (stripe figure on radial cuts).

use crate::math::Frame;

/// Rotate the frame (r̂, θ̂, ẑ) about r̂ by `angle` (radians): the longitudinal axis tilts towards θ̂
/// (a helix of pitch angle `angle`), the radial axis stays. Orthonormality is preserved exactly up
/// to rounding. (sin, cos) from the branch-free polynomial, so batch evaluation vectorises.
#[inline]
pub fn rotate_about_radial(frame: &Frame, angle: f32) -> Frame {
    let (s, c) = crate::math::elementary::sin_cos(angle);
    rotate_by(frame, s, c)
}

/// [`rotate_about_radial`] by the angle whose sine and cosine are `s` and `c`.
#[inline(always)]
pub(crate) fn rotate_by(frame: &Frame, s: f32, c: f32) -> Frame {
    Frame {
        s: frame.s,
        t: frame.t * c - frame.n * s,
        n: frame.t * s + frame.n * c,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::cylinder_frame;
    use glam::Vec3;

    #[test]
    fn tilt_goes_towards_theta_and_keeps_handedness() {
        let f0 = cylinder_frame(Vec3::new(0.0, 2.0, 0.0));
        let f = rotate_about_radial(&f0, 0.3);
        assert!((f.n.dot(f0.t) - 0.3_f32.sin()).abs() < 1e-6);
        assert!((f.s.cross(f.t) - f.n).length() < 1e-6);
        assert_eq!(f.s, f0.s);
    }
}
