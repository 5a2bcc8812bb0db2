//! Where an object sits in the tree: the map from object (or world) space to tree space
//! (mm, pith along +z), in one of three ways (Liu et al. 2016 §7.2–7.3): carved from one solid
//! block, veneered with one slice per face, or laid as boards of a floor layout.

use crate::wood::{board_at, board_to_tree, veneer_to_tree, BoardLayout, TreeRegion};
use glam::{Affine3A, Mat3, Quat, Vec2, Vec3};
use serde::{Deserialize, Serialize};

/// A [`SawnCut`] out of range, naming the field ([`Placement::sawn`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct SawnCutError {
    /// The `SawnCut` field at fault.
    pub field: &'static str,
    /// What is wrong, naming the field and its allowed range.
    pub message: String,
}

/// A solid board's cut stated as a sawyer states it (`tree.sawn` in a scene): how far its face
/// lies from the pith, at what angle to the growth rings, and how high up the stem. Flat-sawn
/// (plain-sawn) faces are tangential to the rings (angle 0°) and show cathedral arches; quartersawn
/// faces are radial (90°) and show straight stripes and ray fleck; rift-sawn lies between
/// (Hoadley, *Understanding Wood*, 2000, ch. 2 and 11; Forest Products Laboratory, *Wood
/// Handbook*, 2010, §3 "Plainsawn and quartersawn"). [`Placement::sawn`] turns it into the rigid
/// object → tree map; [`Placement::cut_at`] reads it back from any solid placement.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SawnCut {
    /// Distance of the face's centre from the pith, mm (> 0).
    pub pith_distance: f32,
    /// Angle between the face and the rings at the face's centre, degrees: 0 flat-sawn, 90
    /// quartersawn, between them rift-sawn.
    pub ring_angle_deg: f32,
    /// Height of the face's centre along the stem, mm (selects which stretch of the tree).
    #[serde(default)]
    pub height: f32,
    /// Angle about the pith at which the board was taken, degrees (selects which side of the
    /// tree: another board of the same cut).
    #[serde(default)]
    pub azimuth_deg: f32,
    /// Slope of the face to the pith along the grain, degrees (−45 to 45): a board sawn parallel
    /// to the bark of a tapering log, or off the pith's line, rises through the rings along its
    /// length, so a flat-sawn face cuts them in nested parabolas (cathedral arches; on a face
    /// r ≈ d + y²/2d + x·sin s, a ring r₀ shows where y² = 2d(r₀ − d − x·sin s)). The fibres dip
    /// into the face by the same angle (grain runout). 0: parallel to the pith.
    #[serde(default)]
    pub slope_deg: f32,
    /// The face's centre, object space (the box `size = [.., .., 18]` has its top face's centre
    /// at [0, 0, 9]).
    #[serde(default)]
    pub face_point: [f32; 3],
    /// The face's outward normal, object space (perpendicular to the grain `axis`).
    #[serde(default = "plus_z")]
    pub face_normal: [f32; 3],
}

fn plus_z() -> [f32; 3] {
    [0.0, 0.0, 1.0]
}

impl SawnCut {
    /// A cut of the top face of a board lying flat (face normal +z, centre `face_point`).
    pub fn new(pith_distance: f32, ring_angle_deg: f32, face_point: Vec3) -> SawnCut {
        SawnCut {
            pith_distance,
            ring_angle_deg,
            height: 0.0,
            azimuth_deg: 0.0,
            slope_deg: 0.0,
            face_point: face_point.into(),
            face_normal: plus_z(),
        }
    }

    /// Flat-sawn: the face tangential to the rings.
    pub fn flat(pith_distance: f32, face_point: Vec3) -> SawnCut {
        SawnCut::new(pith_distance, 0.0, face_point)
    }

    /// Quartersawn: the face radial, across the rings.
    pub fn quarter(pith_distance: f32, face_point: Vec3) -> SawnCut {
        SawnCut::new(pith_distance, 90.0, face_point)
    }

    /// The top face (centre [0, 0, 9]) of an 18 mm board lying flat, as every showcase board is
    /// cut: `wood::SHOWCASE_PITH_DISTANCE_MM` from the pith at `ring_angle_deg`, and faces nearer
    /// flat- than quartersawn sloped `wood::SHOWCASE_SLOPE_DEG` along the grain (arches).
    pub fn showcase_board(ring_angle_deg: f32) -> SawnCut {
        use crate::wood::{SHOWCASE_PITH_DISTANCE_MM, SHOWCASE_SLOPE_DEG};
        SawnCut {
            slope_deg: if ring_angle_deg < 45.0 {
                SHOWCASE_SLOPE_DEG
            } else {
                0.0
            },
            ..SawnCut::new(
                SHOWCASE_PITH_DISTANCE_MM,
                ring_angle_deg,
                Vec3::new(0.0, 0.0, 9.0),
            )
        }
    }

    /// The scene file's `tree` inline table of this cut for a board whose grain runs along
    /// object x.
    pub fn tree_toml(&self) -> String {
        format!(
            "{{ axis = [1.0, 0.0, 0.0], sawn = {} }}",
            toml::to_string(self)
                .map(|t| format!("{{ {} }}", t.trim().replace('\n', ", ")))
                .unwrap_or_default()
        )
    }
}

/// Where a face point lies in the tree ([`Placement::cut_at`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CutAt {
    /// Distance from the pith, mm.
    pub pith_distance: f32,
    /// Angle between the face and the rings there, degrees (0 flat-sawn … 90 quartersawn).
    pub ring_angle_deg: f32,
    /// Height along the stem, mm.
    pub height: f32,
}

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
    /// A tree-space rotation applied after `Rz(rotation) · A` (identity but for a sloped
    /// [`SawnCut`]).
    pub tilt: Mat3,
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
            tilt: Mat3::IDENTITY,
            scale: 1.0,
            cutting: Cutting::Solid,
            world_space: false,
        }
    }
}

impl Placement {
    /// The solid placement of `cut` for a board whose fibres run along object direction `axis`,
    /// `scale` tree mm per object unit. The face's centre goes to the tree point at
    /// `pith_distance`, `azimuth_deg` and `height`; the object is turned about the pith so that
    /// the face normal lies at `ring_angle_deg` from the radial direction there (n = cos φ r̂ +
    /// sin φ θ̂), which makes the face meet the rings at φ. Errors name the field.
    pub fn sawn(axis: Vec3, scale: f32, cut: &SawnCut) -> Result<Placement, SawnCutError> {
        let err = |field: &'static str, message: String| Err(SawnCutError { field, message });
        let finite = |v: [f32; 3]| v.iter().all(|x| x.is_finite());
        let d = cut.pith_distance;
        if !(d.is_finite() && d > 0.0 && d <= 1e6) {
            let m = format!("pith_distance {d} is out of range (allowed above 0 to 1e6 mm)");
            return err("pith_distance", m);
        }
        if !(0.0..=90.0).contains(&cut.ring_angle_deg) {
            let m = format!(
                "ring_angle_deg {} is out of range (allowed 0 = flat-sawn to 90 = quartersawn)",
                cut.ring_angle_deg
            );
            return err("ring_angle_deg", m);
        }
        if !(cut.height.is_finite() && cut.height.abs() <= 1e7) {
            let m = format!("height {} is out of range (allowed ±1e7 mm)", cut.height);
            return err("height", m);
        }
        if !(-360.0..=360.0).contains(&cut.azimuth_deg) {
            let m = format!(
                "azimuth_deg {} is out of range (allowed -360 to 360)",
                cut.azimuth_deg
            );
            return err("azimuth_deg", m);
        }
        if !(-45.0..=45.0).contains(&cut.slope_deg) {
            let m = format!(
                "slope_deg {} is out of range (allowed -45 to 45)",
                cut.slope_deg
            );
            return err("slope_deg", m);
        }
        if !finite(cut.face_point) || Vec3::from(cut.face_point).abs().max_element() > 1e7 {
            let m = "face_point must be finite, each coordinate within ±1e7".into();
            return err("face_point", m);
        }
        let (axis, normal) = (axis.normalize_or_zero(), Vec3::from(cut.face_normal));
        if !finite(cut.face_normal) || normal.length() < 1e-6 {
            let m = "face_normal must be a finite non-zero direction".into();
            return err("face_normal", m);
        }
        let normal = normal.normalize();
        if axis.dot(normal).abs() > 1e-3 {
            let m = format!(
                "face_normal {normal} must be perpendicular to the grain axis {axis} (the face \
                 of a board contains its grain)"
            );
            return err("face_normal", m);
        }
        let a = Quat::from_rotation_arc(axis, Vec3::Z);
        let n = a * normal;
        let (az, phi) = (
            cut.azimuth_deg.to_radians(),
            cut.ring_angle_deg.to_radians(),
        );
        // The tree's radial direction at the face centre is at angle `az`; the normal turns from
        // it by φ towards θ̂.
        let rotation = az + phi - n.y.atan2(n.x);
        let centre = Vec3::new(az.cos(), az.sin(), 0.0) * cut.pith_distance + Vec3::Z * cut.height;
        let mut p = Placement {
            axis,
            rotation,
            scale,
            ..Placement::default()
        };
        if cut.slope_deg != 0.0 {
            // Tilt about the face's across-grain line (ẑ × normal): the grain ẑ turns towards
            // the face normal, so the face climbs through the rings along +axis.
            let normal = p.rotation_matrix() * normal;
            let tilt = Quat::from_axis_angle(Vec3::Z.cross(normal), cut.slope_deg.to_radians());
            p.tilt = Mat3::from_quat(tilt);
        }
        p.origin = centre - p.rotation_matrix() * Vec3::from(cut.face_point) * scale;
        Ok(p)
    }

    /// Where the face through object point `p` with outward normal `n` lies in the tree of this
    /// solid placement: its distance from the pith, the angle between face and rings, and the
    /// height (the inverse of [`Placement::sawn`], for any solid placement).
    pub fn cut_at(&self, p: Vec3, n: Vec3) -> CutAt {
        let q = self.object_to_tree().transform_point3(p);
        let m = self.rotation_matrix() * n;
        let m = Vec3::new(m.x, m.y, 0.0).normalize_or_zero();
        let radial = Vec3::new(q.x, q.y, 0.0).normalize_or_zero();
        // The face meets the rings at the angle between its normal (across the pith, i.e. less
        // any slope along it) and the radial direction (the rings' normal), as a line: 0° when
        // the normal is radial.
        let cos = m.dot(radial).abs().min(1.0);
        CutAt {
            pith_distance: q.truncate().length(),
            ring_angle_deg: cos.acos().to_degrees(),
            height: q.z,
        }
    }

    /// The rotation part `tilt · Rz(rotation) · A` of a solid cutting (object → tree directions).
    pub fn rotation_matrix(&self) -> Mat3 {
        let a = Quat::from_rotation_arc(self.axis.normalize(), Vec3::Z);
        self.tilt * Mat3::from_quat(Quat::from_rotation_z(self.rotation) * a)
    }

    /// The affine object → tree map of a solid cutting.
    pub fn object_to_tree(&self) -> Affine3A {
        self.solid_map(self.rotation_matrix())
    }

    /// [`Placement::object_to_tree`] of the rotation `r` ([`Placement::rotation_matrix`]).
    fn solid_map(&self, r: Mat3) -> Affine3A {
        Affine3A::from_mat3_translation(r * self.scale, self.origin)
    }

    /// The tree point of surface point `p` with unit normal `n` (both in the placement's space),
    /// and the rotation `J` carrying directions from that space into tree space.
    pub fn to_tree(&self, p: Vec3, n: Vec3) -> (Vec3, Mat3) {
        match self.cutting {
            Cutting::Solid => {
                // The rotation worked out once, for the map and for J.
                let r = self.rotation_matrix();
                (self.solid_map(r).transform_point3(p), r)
            }
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

    /// `sawn` puts the face where it says, checked by `cut_at` and by hand: a board lying flat
    /// with its grain along x, flat-sawn 120 mm from the pith, has its face's centre 120 mm out
    /// and its normal radial; quartersawn, its normal tangential.
    #[test]
    fn sawn_cut_puts_the_face_where_it_says() {
        let face = Vec3::new(0.0, 0.0, 9.0);
        for (cut, expect_normal) in [
            (SawnCut::flat(120.0, face), Vec3::X),
            (SawnCut::quarter(120.0, face), Vec3::Y),
        ] {
            let p = Placement::sawn(Vec3::X, 1.0, &cut).unwrap();
            let q = p.object_to_tree().transform_point3(face);
            assert!((q - Vec3::new(120.0, 0.0, 0.0)).length() < 1e-3, "{q}");
            let n = p.rotation_matrix() * Vec3::Z;
            assert!((n - expect_normal).length() < 1e-5, "{n}");
            assert!((p.rotation_matrix() * Vec3::X - Vec3::Z).length() < 1e-5);
            let at = p.cut_at(face, Vec3::Z);
            assert!((at.pith_distance - 120.0).abs() < 1e-3);
            assert!((at.ring_angle_deg - cut.ring_angle_deg).abs() < 0.01);
        }
        let rift = SawnCut {
            height: 300.0,
            azimuth_deg: 40.0,
            ..SawnCut::new(80.0, 45.0, face)
        };
        let at = Placement::sawn(Vec3::X, 1.0, &rift)
            .unwrap()
            .cut_at(face, Vec3::Z);
        assert!((at.pith_distance - 80.0).abs() < 1e-3 && (at.height - 300.0).abs() < 1e-3);
        assert!((at.ring_angle_deg - 45.0).abs() < 0.01);
    }

    /// A sloped flat-sawn face climbs through the rings along the grain by sin(slope) per mm,
    /// and its fibres dip into it by the slope.
    #[test]
    fn sloped_cut_climbs_through_the_rings() {
        let face = Vec3::new(0.0, 0.0, 9.0);
        let cut = SawnCut {
            slope_deg: 3.0,
            ..SawnCut::flat(120.0, face)
        };
        let p = Placement::sawn(Vec3::X, 1.0, &cut).unwrap();
        let r = |x: f32| p.cut_at(face + Vec3::X * x, Vec3::Z).pith_distance;
        assert!((r(0.0) - 120.0).abs() < 1e-3);
        let rise = (r(100.0) - r(-100.0)) / 200.0;
        assert!((rise - 3f32.to_radians().sin()).abs() < 1e-4, "{rise}");
        assert!(p.cut_at(face, Vec3::Z).ring_angle_deg < 0.01);
        let fibre_in_face = p.rotation_matrix().transpose() * Vec3::Z;
        assert!((fibre_in_face.z.asin().to_degrees().abs() - 3.0).abs() < 1e-3);
    }

    #[test]
    fn sawn_cut_rejects_what_no_saw_can_cut() {
        let face = Vec3::ZERO;
        let bad = [
            (SawnCut::flat(0.0, face), "pith_distance"),
            (SawnCut::new(100.0, 91.0, face), "ring_angle_deg"),
            (SawnCut::flat(f32::NAN, face), "pith_distance"),
            (
                SawnCut {
                    face_normal: [1.0, 0.0, 0.0],
                    ..SawnCut::flat(100.0, face)
                },
                "face_normal",
            ),
        ];
        for (cut, field) in bad {
            let e = Placement::sawn(Vec3::X, 1.0, &cut).unwrap_err();
            assert!(
                e.field == field && e.message.contains(field),
                "{cut:?}: {e:?}"
            );
        }
    }

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
