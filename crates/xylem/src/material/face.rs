//! What the image-map materials share: the rectangle of a flat face their maps cover, the
//! bilinear taps of a lookup, and the step from a texel's tangent-space fibre to the
//! finished-wood BSDF at a hit. Used by the baked maps (`xylem tradeoff`) and by the measured
//! boards of Marschner et al. 2005.

use super::{wood_shading, MaterialHit, Shading};
use crate::bsdf::{Finish, FinishModel, WoodBsdfParams};
use crate::math::Frame;
use glam::{Vec2, Vec3};

/// A rectangle of a plane: texel (0, 0)'s corner, unit `right` (+u) and `down` (+v) axes and the
/// size along them. Lengths in the units of the space it lives in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaceRect {
    /// Corner of texel (0, 0) (the top-left one).
    pub corner: Vec3,
    /// Unit axis of +u (along the image columns).
    pub right: Vec3,
    /// Unit axis of +v (down the image rows).
    pub down: Vec3,
    /// Extent along `right` and `down`.
    pub size: Vec2,
}

impl FaceRect {
    /// The face normal right × up (up = −down).
    pub fn normal(&self) -> Vec3 {
        self.right.cross(-self.down)
    }

    /// The point at texture coordinates `uv` ∈ [0, 1]².
    pub fn point(&self, uv: Vec2) -> Vec3 {
        self.corner + self.right * (uv.x * self.size.x) + self.down * (uv.y * self.size.y)
    }

    /// Texture coordinates of the projection of `p` onto the face.
    pub fn uv(&self, p: Vec3) -> Vec2 {
        let d = p - self.corner;
        Vec2::new(
            d.dot(self.right) / self.size.x,
            d.dot(self.down) / self.size.y,
        )
    }

    /// Texture size for `res` texels along `right` (at least 1 × 1), square texels.
    pub(crate) fn texture_size(&self, res: u32) -> (u32, u32) {
        let res = res.max(1);
        (
            res,
            ((res as f32 * self.size.y / self.size.x).round() as u32).max(1),
        )
    }

    /// The object-space direction of tangent-space `t` (x right, y up = −down, z the normal).
    pub(crate) fn tangent_to_object(&self, t: Vec3) -> Vec3 {
        self.right * t.x - self.down * t.y + self.normal() * t.z
    }
}

/// The four texels and weights of a bilinear lookup at `uv` in a `width` × `height` row-major map
/// (texel centres at (i + ½)/W, clamped to the edge texels outside [0, 1]²).
pub(crate) fn bilinear_taps(uv: Vec2, width: u32, height: u32) -> [(usize, f32); 4] {
    let (w, h) = (width as usize, height as usize);
    let x = (uv.x * w as f32 - 0.5).clamp(0.0, (w - 1) as f32);
    let y = (uv.y * h as f32 - 0.5).clamp(0.0, (h - 1) as f32);
    let (x0, y0) = (x as usize, y as usize);
    let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
    let (fx, fy) = (x - x0 as f32, y - y0 as f32);
    [
        (y0 * w + x0, (1.0 - fx) * (1.0 - fy)),
        (y0 * w + x1, fx * (1.0 - fy)),
        (y1 * w + x0, (1.0 - fx) * fy),
        (y1 * w + x1, fx * fy),
    ]
}

/// One texel of a face material, everything in the face's tangent space (x right, y up, z out).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaceTexel {
    pub diffuse: Vec3,
    pub fiber_color: Vec3,
    /// Unit fibre axis in tangent space (may dip out of the face).
    pub fiber: Vec3,
    pub ray_mask: f32,
    /// β, radians.
    pub highlight_width: f32,
}

/// The finished-wood BSDF of `texel` on `face` at `hit`, with shading normal `n` (world): the
/// fibre goes tangent → object → world by the instance's linear map (directions are
/// contravariant, Liu et al. 2016 §6.2); the ray axis lies in the face across the fibre, as on a
/// quartersawn face.
pub(crate) fn face_shading(
    hit: &MaterialHit,
    face: &FaceRect,
    n: Vec3,
    texel: FaceTexel,
    finish: &Finish,
    model: FinishModel,
) -> Shading {
    let fiber_world =
        (hit.object_to_world * face.tangent_to_object(texel.fiber)).normalize_or_zero();
    let frame = Frame::from_normal_tangent(n, fiber_world);
    let local = WoodBsdfParams {
        diffuse: texel.diffuse,
        fiber_color: texel.fiber_color,
        fiber_dir: frame.to_local(fiber_world),
        ray_dir: frame.to_local(frame.t),
        ray_mask: texel.ray_mask,
        highlight_width: texel.highlight_width,
        eta: finish.eta(),
        roughness: finish.roughness(),
    };
    wood_shading(local, frame, fiber_world, 0.0, model, finish)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn face_maps_points_to_uv_and_back() {
        let f = FaceRect {
            corner: Vec3::new(-10.0, 5.0, 2.0),
            right: Vec3::X,
            down: -Vec3::Y,
            size: Vec2::new(20.0, 10.0),
        };
        assert_eq!(f.normal(), Vec3::Z);
        let uv = Vec2::new(0.3, 0.8);
        assert!((f.uv(f.point(uv)) - uv).length() < 1e-6);
        assert_eq!(f.texture_size(64), (64, 32));
        assert_eq!(
            f.tangent_to_object(Vec3::new(1.0, 2.0, 3.0)),
            Vec3::new(1.0, 2.0, 3.0)
        );
    }

    #[test]
    fn bilinear_taps_sum_to_one_and_clamp() {
        let taps = bilinear_taps(Vec2::new(0.5, 0.5), 2, 1);
        assert_eq!(taps[0], (0, 0.5));
        assert_eq!(taps[1], (1, 0.5));
        assert!((taps.iter().map(|t| t.1).sum::<f32>() - 1.0).abs() < 1e-6);
        // Outside the map only the corner texel carries weight.
        assert!(bilinear_taps(Vec2::new(-3.0, 9.0), 2, 1)
            .iter()
            .all(|&(i, w)| i == 0 || w == 0.0));
    }
}
