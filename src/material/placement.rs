//! Where an object sits in the tree: the map from object space to tree space (mm, pith along +z).

use glam::{Affine3A, Mat3, Quat, Vec3};

/// `p_tree = origin + scale · Rz(rotation) · A · p_object`, where `A` turns the object-space
/// direction `axis` onto the pith direction +z. So `axis` is the object direction the fibres
/// run along, `rotation` turns the object about the pith (flat- vs quarter-sawn), and `origin`
/// is the tree-space point (mm from the pith) where the object's origin lies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    pub origin: Vec3,
    pub axis: Vec3,
    /// Radians.
    pub rotation: f32,
    /// Tree millimetres per object unit (> 0).
    pub scale: f32,
}

impl Default for Placement {
    fn default() -> Self {
        Placement {
            origin: Vec3::ZERO,
            axis: Vec3::Z,
            rotation: 0.0,
            scale: 1.0,
        }
    }
}

impl Placement {
    /// The rotation part `Rz(rotation) · A` (object → tree directions).
    pub fn rotation_matrix(&self) -> Mat3 {
        let a = Quat::from_rotation_arc(self.axis.normalize(), Vec3::Z);
        Mat3::from_quat(Quat::from_rotation_z(self.rotation) * a)
    }

    /// The affine object → tree map.
    pub fn object_to_tree(&self) -> Affine3A {
        Affine3A::from_mat3_translation(self.rotation_matrix() * self.scale, self.origin)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_maps_to_pith_direction() {
        let p = Placement {
            origin: Vec3::new(0.0, 150.0, 0.0),
            axis: Vec3::X,
            rotation: 0.3,
            scale: 2.0,
        };
        let m = p.object_to_tree();
        let d = m.transform_vector3(Vec3::X);
        assert!((d - Vec3::new(0.0, 0.0, 2.0)).length() < 1e-5);
        assert!((m.transform_point3(Vec3::ZERO) - p.origin).length() < 1e-6);
    }
}
