//! Board functions (Liu et al. 2016 §7.2, Fig. 15): a surface point → a board index and an offset
//! in the board; the index is hashed into a region of the tree where that board was cut, so every
//! board shows different wood. Also the two ways of making an object (§7.3, Fig. 18): carved from
//! one solid block, or veneered with a thin tangential slice per face. All pure functions.

use crate::math::Pcg32;
use glam::{Vec2, Vec3};
use serde::{Deserialize, Serialize};

/// How a floor or panel is divided into boards (surface coordinates in mm).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum BoardLayout {
    /// Parallel planks `width` across, `length` along u (the grain); each row is shifted along u by
    /// `stagger` × length (a running bond).
    Planks {
        /// Plank width across the grain (mm).
        width: f32,
        /// Plank length along the grain (mm).
        length: f32,
        /// Shift of each row along u, as a fraction of `length` (0–1).
        stagger: f32,
    },
    /// Nested-square parquet (the Sponza floor of Fig. 14): square tiles of side `tile`, each made
    /// of concentric square frames of width `strip`; every frame has four strips whose grain runs
    /// along the frame's side.
    Parquet {
        /// Side of a square tile (mm).
        tile: f32,
        /// Width of each frame's strips (mm, at most tile/2).
        strip: f32,
    },
}

/// Which face of the log a board shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Cut {
    /// Flat-sawn: the face is tangential (normal along r̂) — cathedral rings.
    Flat,
    /// Quartersawn: the face is radial (normal along θ̂) — straight stripes, ray fleck.
    Quarter,
}

/// The part of the tree boards are cut from: radii and heights (mm) and the cut.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TreeRegion {
    /// Smallest distance from the pith a board is cut at (mm, default 60).
    pub r_min: f32,
    /// Largest distance from the pith (mm, default 200).
    pub r_max: f32,
    /// Boards start at heights in [0, z_span) along the pith (mm, default 5000).
    pub z_span: f32,
    /// Flat-sawn or quartersawn (default flat).
    pub cut: Cut,
}

impl Default for TreeRegion {
    fn default() -> Self {
        TreeRegion {
            r_min: 60.0,
            r_max: 200.0,
            z_span: 5000.0,
            cut: Cut::Flat,
        }
    }
}

/// A board of a layout: its index (hashed into the tree) and the point's coordinates in the board:
/// `along` the grain and `across` it, mm from the board's corner.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct BoardPoint {
    /// Which board (hashed into the tree by [`board_to_tree`]).
    pub index: [i32; 3],
    /// Distance along the grain from the board's corner (mm).
    pub along: f32,
    /// Distance across the grain from the board's corner (mm).
    pub across: f32,
}

/// The board under surface point `uv` (mm).
pub(crate) fn board_at(layout: &BoardLayout, uv: Vec2) -> BoardPoint {
    match *layout {
        BoardLayout::Planks {
            width,
            length,
            stagger,
        } => {
            let row = (uv.y / width).floor();
            let u = uv.x + row * stagger * length;
            let col = (u / length).floor();
            BoardPoint {
                index: [col as i32, row as i32, 0],
                along: u - col * length,
                across: uv.y - row * width,
            }
        }
        BoardLayout::Parquet { tile, strip } => {
            let (ti, tj) = ((uv.x / tile).floor(), (uv.y / tile).floor());
            // Centred coordinates in the tile; the frame is set by the Chebyshev distance.
            let c = Vec2::new(uv.x - (ti + 0.5) * tile, uv.y - (tj + 0.5) * tile);
            let ring = ((0.5 * tile - c.x.abs().max(c.y.abs())) / strip)
                .floor()
                .max(0.0);
            // Which side of the frame: the strip runs along x on the top/bottom sides.
            let horizontal = c.y.abs() >= c.x.abs();
            let side = match (horizontal, c.x + c.y >= 0.0, c.y - c.x >= 0.0) {
                (true, _, true) => 0,
                (true, _, false) => 1,
                (false, true, _) => 2,
                (false, false, _) => 3,
            };
            let (along, across) = if horizontal {
                (c.x + 0.5 * tile, c.y.abs())
            } else {
                (c.y + 0.5 * tile, c.x.abs())
            };
            BoardPoint {
                index: [ti as i32, tj as i32, (ring as i32) * 4 + side],
                along,
                across: across - (0.5 * tile - (ring + 1.0) * strip),
            }
        }
    }
}

/// Where board `index` sits in the tree: the index is hashed into `region` (§7.2). Returns the
/// tree-space point of board coordinates (along the grain, across it, depth below the face).
pub(crate) fn board_to_tree(
    index: [i32; 3],
    along: f32,
    across: f32,
    depth: f32,
    region: &TreeRegion,
    seed: u64,
) -> Vec3 {
    let stream = (index[0] as u32 as u64)
        .wrapping_mul(0x9e37_79b9_7f4a_7c15)
        .wrapping_add((index[1] as u32 as u64).wrapping_mul(0xc2b2_ae3d_27d4_eb4f))
        .wrapping_add((index[2] as u32 as u64).wrapping_mul(0x1656_67b1_9e37_79f9));
    let mut rng = Pcg32::new(seed, stream);
    let r0 = region.r_min + (region.r_max - region.r_min) * rng.next_f32();
    let theta = std::f32::consts::TAU * rng.next_f32();
    let z0 = region.z_span * rng.next_f32();
    let (s, c) = theta.sin_cos();
    let (radial, tangential) = (Vec3::new(c, s, 0.0), Vec3::new(-s, c, 0.0));
    let z = Vec3::Z * (z0 + along);
    match region.cut {
        Cut::Flat => radial * (r0 - depth) + tangential * across + z,
        Cut::Quarter => radial * (r0 + across) + tangential * depth + z,
    }
}

/// Solid: an object carved from one block. `p` in object space (mm) maps rigidly into the tree:
/// the block's origin sits at `origin` in tree space and its `grain` axis (object space, unit) runs
/// along the pith direction ẑ.
#[cfg(test)]
pub(crate) fn solid_to_tree(p: Vec3, origin: Vec3, grain: Vec3) -> Vec3 {
    let rot = glam::Quat::from_rotation_arc(grain.normalize_or(Vec3::Z), Vec3::Z);
    origin + rot * p
}

/// Veneer: every face of an object is covered by its own thin tangential slice (Fig. 18 right).
/// `p` is the object-space point and `normal` its face normal; the face is identified by the
/// dominant axis of the normal and its sign, hashed into `region` as a flat-sawn board whose grain
/// runs along the face's first in-plane axis.
pub(crate) fn veneer_to_tree(p: Vec3, normal: Vec3, region: &TreeRegion, seed: u64) -> Vec3 {
    let a = normal.abs();
    let (axis, u, v) = if a.x >= a.y && a.x >= a.z {
        (0, p.y, p.z)
    } else if a.y >= a.z {
        (1, p.z, p.x)
    } else {
        (2, p.x, p.y)
    };
    let sign = if normal[axis] >= 0.0 { 0 } else { 1 };
    let flat = TreeRegion {
        cut: Cut::Flat,
        ..*region
    };
    board_to_tree([axis as i32, sign, 7], u, v, 0.0, &flat, seed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn planks_partition_the_plane() {
        let l = BoardLayout::Planks {
            width: 100.0,
            length: 1000.0,
            stagger: 0.3,
        };
        let b = board_at(&l, Vec2::new(1234.0, 250.0));
        assert_eq!(b.index[1], 2);
        assert!((0.0..1000.0).contains(&b.along) && (0.0..100.0).contains(&b.across));
        // Neighbouring points in one plank share its index; across a row they do not.
        assert_eq!(board_at(&l, Vec2::new(1235.0, 251.0)).index, b.index);
        assert_ne!(board_at(&l, Vec2::new(1234.0, 301.0)).index, b.index);
    }

    #[test]
    fn parquet_strips_lie_inside_their_frame() {
        let l = BoardLayout::Parquet {
            tile: 400.0,
            strip: 50.0,
        };
        for (x, y) in [
            (10.0, 200.0),
            (200.0, 10.0),
            (390.0, 200.0),
            (200.0, 390.0),
            (130.0, 220.0),
        ] {
            let b = board_at(&l, Vec2::new(x, y));
            assert!(
                (0.0..=50.0).contains(&b.across),
                "across {} at ({x}, {y})",
                b.across
            );
            assert!((0.0..=400.0).contains(&b.along));
        }
        // Top and left strips of the outer frame are different boards.
        let top = board_at(&l, Vec2::new(200.0, 390.0)).index;
        let left = board_at(&l, Vec2::new(10.0, 200.0)).index;
        assert_ne!(top, left);
    }

    #[test]
    fn boards_land_in_their_region_and_differ() {
        let region = TreeRegion::default();
        let a = board_to_tree([0, 0, 0], 10.0, 5.0, 0.0, &region, 3);
        let b = board_to_tree([1, 0, 0], 10.0, 5.0, 0.0, &region, 3);
        assert_ne!(a, b);
        let r = (a.x * a.x + a.y * a.y).sqrt();
        assert!(r >= region.r_min - 1.0 && r <= region.r_max + 6.0);
        let s = solid_to_tree(Vec3::new(0.0, 5.0, 0.0), Vec3::ZERO, Vec3::Y);
        assert!((s - Vec3::new(0.0, 0.0, 5.0)).length() < 1e-4);
    }
}
