//! Where an object sits in the tree: the map from object (or world) space to tree space
//! (mm, pith along +z), in one of three ways (Liu et al. 2016 §7.2–7.3): carved from one solid
//! block, veneered with one slice per face, or laid as boards of a floor layout.

use crate::wood::{board_at, board_to_tree, veneer_to_tree, BoardLayout, TreeRegion};
use glam::{Affine3A, Mat3, Quat, Vec2, Vec3};

/// How surface points find their wood.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Cutting {
    /// Carved from one block: `p_tree = origin + scale · Rz(rotation) · A · p`.
    Solid,
    /// Each face (by its dominant normal axis) is its own flat-sawn slice from `region`.
    Veneer {
        /// Where the slices are cut from.
        region: TreeRegion,
        /// Selects each face's slice.
        seed: u64,
    },
    /// The xy plane is divided into boards by `layout`; each board is hashed into `region`.
    Boards {
        /// How the floor is divided into boards.
        layout: BoardLayout,
        /// Where the boards are cut from.
        region: TreeRegion,
        /// Selects each board's place in `region`.
        seed: u64,
    },
}

/// `p_tree = origin + scale · Rz(rotation) · A · p`, where `A` turns the direction `axis` onto
/// the pith direction +z. So `axis` is the direction the fibres run along, `rotation` turns the
/// object about the pith (flat- vs quarter-sawn), and `origin` is the tree-space point (mm from
/// the pith) of the object's origin. `p` is the object-space point, or the world point when
/// `world_space` is set (so separate objects can share one block, as the parts of a joint do).
/// Veneer and board cuttings use only `scale` and `world_space` of these.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// Tree-space point (mm from the pith) of the object's origin.
    pub origin: Vec3,
    /// Object direction the fibres run along (mapped to +z).
    pub axis: Vec3,
    /// Radians.
    pub rotation: f32,
    /// Tree millimetres per object unit (> 0).
    pub scale: f32,
    /// Solid block, veneer or boards.
    pub cutting: Cutting,
    /// Read world points instead of object points (several objects share one block).
    pub world_space: bool,
}

impl Default for Placement {
    fn default() -> Self {
        Placement {
            origin: Vec3::ZERO,
            axis: Vec3::Z,
            rotation: 0.0,
            scale: 1.0,
            cutting: Cutting::Solid,
            world_space: false,
        }
    }
}

impl Placement {
    /// The rotation part `Rz(rotation) · A` of a solid cutting (object → tree directions).
    pub fn rotation_matrix(&self) -> Mat3 {
        let a = Quat::from_rotation_arc(self.axis.normalize(), Vec3::Z);
        Mat3::from_quat(Quat::from_rotation_z(self.rotation) * a)
    }

    /// The affine object → tree map of a solid cutting.
    pub fn object_to_tree(&self) -> Affine3A {
        Affine3A::from_mat3_translation(self.rotation_matrix() * self.scale, self.origin)
    }

    /// The tree point of surface point `p` with unit normal `n` (both in the placement's space),
    /// and the rotation `J` carrying directions from that space into tree space.
    pub fn to_tree(&self, p: Vec3, n: Vec3) -> (Vec3, Mat3) {
        match self.cutting {
            Cutting::Solid => (
                self.object_to_tree().transform_point3(p),
                self.rotation_matrix(),
            ),
            Cutting::Veneer { region, seed } => {
                let f = |q: Vec3| veneer_to_tree(q * self.scale, n, &region, seed);
                (f(p), surface_rotation(&f, p, n))
            }
            Cutting::Boards {
                layout,
                region,
                seed,
            } => {
                let f = |q: Vec3| {
                    let b = board_at(&layout, Vec2::new(q.x, q.y) * self.scale);
                    // Depth below the floor's top face (z = 0 in object space).
                    board_to_tree(b.index, b.along, b.across, -q.z * self.scale, &region, seed)
                };
                (f(p), surface_rotation(&f, p, n))
            }
        }
    }
}

/// The rotation a piecewise-rigid map `f` applies near `p` on a surface with normal `n`: forward
/// differences along two tangents (a step far below any board size), orthonormalised; the normal
/// goes to their cross product.
fn surface_rotation(f: &dyn Fn(Vec3) -> Vec3, p: Vec3, n: Vec3) -> Mat3 {
    const H: f32 = 1e-2;
    let frame = crate::math::Frame::from_normal(n);
    let p0 = f(p);
    let d1 = ((f(p + frame.s * H) - p0) / H).normalize_or(Vec3::X);
    let d2 = (f(p + frame.t * H) - p0) / H;
    let d2 = (d2 - d1 * d1.dot(d2)).normalize_or(d1.any_orthonormal_vector());
    let d3 = d1.cross(d2);
    // J = [d1 d2 d3] · [s t n]ᵀ maps s → d1, t → d2, n → d3.
    Mat3::from_cols(d1, d2, d3) * frame.matrix().transpose()
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
            ..Default::default()
        };
        let m = p.object_to_tree();
        let d = m.transform_vector3(Vec3::X);
        assert!((d - Vec3::new(0.0, 0.0, 2.0)).length() < 1e-5);
        assert!((m.transform_point3(Vec3::ZERO) - p.origin).length() < 1e-6);
    }

    #[test]
    fn board_rotation_is_orthonormal_and_maps_grain_to_pith() {
        let p = Placement {
            cutting: Cutting::Boards {
                layout: BoardLayout::Planks {
                    width: 100.0,
                    length: 1000.0,
                    stagger: 0.3,
                },
                region: TreeRegion::default(),
                seed: 3,
            },
            ..Default::default()
        };
        let (_, j) = p.to_tree(Vec3::new(123.0, 45.0, 0.0), Vec3::Z);
        assert!((j * j.transpose() - Mat3::IDENTITY).abs_diff_eq(Mat3::ZERO, 1e-3));
        // Planks run along x: the grain (object x) goes to the pith direction.
        assert!((j * Vec3::X - Vec3::Z).length() < 1e-3, "{}", j * Vec3::X);
    }
}
