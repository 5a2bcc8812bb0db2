//! Cellular (Worley) noise: distances to the nearest and second-nearest feature points of a
//! jittered grid, one point per unit cell (Worley 1996, "A Cellular Texture Basis Function",
//! SIGGRAPH; the one-point-per-cell jittered variant as in Quilez, "Voronoi edges", 2012), with
//! F1, F2, F2 − F1, the id of the nearest cell and the analytic gradients.

use super::hash::{cell3_offset, floor_i32, seed_offsets, unit_f32};
use glam::Vec3;

/// One evaluation of cellular noise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CellularSample {
    /// Distance to the nearest feature point.
    pub f1: f32,
    /// Distance to the second-nearest feature point.
    pub f2: f32,
    /// A hash of the nearest point's cell: constant over each Voronoi cell.
    pub id: u32,
    /// ∇F1 = (p − c₁)/|p − c₁| (unit; undefined only exactly on a feature point, where it is 0).
    pub grad_f1: Vec3,
    /// ∇F2 = (p − c₂)/|p − c₂|.
    pub grad_f2: Vec3,
    /// The nearest feature point.
    pub nearest: Vec3,
}

impl CellularSample {
    /// F2 − F1: zero on the Voronoi edges (cracks, cell borders).
    pub fn edge(&self) -> f32 {
        self.f2 - self.f1
    }

    /// ∇(F2 − F1).
    pub fn grad_edge(&self) -> Vec3 {
        self.grad_f2 - self.grad_f1
    }
}

/// Cellular noise at `p`: one feature point per unit cell, at the cell centre plus a uniform
/// offset in [−jitter/2, jitter/2]³ (`jitter` in [0, 1]; 1 is Worley's fully random placement
/// within the cell). Exact: the 27 cells around `p` are searched, and a 125-cell search runs in
/// the rare case the second distance exceeds what the 27 cells guarantee (notes/noise.md).
pub fn cellular3(p: Vec3, jitter: f32, seed: u32) -> CellularSample {
    let jitter = if jitter.is_finite() {
        jitter.clamp(0.0, 1.0)
    } else {
        1.0
    };
    let offsets = seed_offsets(seed);
    let base = [floor_i32(p.x), floor_i32(p.y), floor_i32(p.z)];
    let f = p - Vec3::new(base[0] as f32, base[1] as f32, base[2] as f32);
    let mut best = Search::new();
    best.cells(base, f, &offsets, jitter, 1);
    // Any point outside the 3×3×3 block is at least this far from p along some axis.
    let margin = 1.5 - 0.5 * jitter;
    let guaranteed = (f + Vec3::splat(margin))
        .min(Vec3::splat(1.0 + margin) - f)
        .min_element();
    if best.d2 > guaranteed * guaranteed {
        best = Search::new();
        best.cells(base, f, &offsets, jitter, 2);
    }
    let (f1, f2) = (best.d1.sqrt(), best.d2.sqrt());
    let unit = |v: Vec3, d: f32| if d > 0.0 { v / d } else { Vec3::ZERO };
    CellularSample {
        f1,
        f2,
        id: best.id,
        grad_f1: unit(best.v1, f1),
        grad_f2: unit(best.v2, f2),
        nearest: p - best.v1,
    }
}

/// The feature point of integer cell `cell` (what [`cellular3`] measures distances to).
pub fn feature_point(cell: [i32; 3], jitter: f32, seed: u32) -> Vec3 {
    let h = cell3_offset(cell[0], cell[1], cell[2], &seed_offsets(seed));
    point_in_cell(h, jitter.clamp(0.0, 1.0))
        + Vec3::new(cell[0] as f32, cell[1] as f32, cell[2] as f32)
}

/// Position of a cell's point relative to the cell's corner.
#[inline(always)]
fn point_in_cell(h: [u32; 3], jitter: f32) -> Vec3 {
    let u = Vec3::new(unit_f32(h[0]), unit_f32(h[1]), unit_f32(h[2]));
    Vec3::splat(0.5) + jitter * (u - Vec3::splat(0.5))
}

/// Running two-nearest search in cell-local coordinates.
struct Search {
    d1: f32,
    d2: f32,
    v1: Vec3,
    v2: Vec3,
    id: u32,
}

impl Search {
    fn new() -> Self {
        Search {
            d1: f32::INFINITY,
            d2: f32::INFINITY,
            v1: Vec3::ZERO,
            v2: Vec3::ZERO,
            id: 0,
        }
    }

    fn cells(&mut self, base: [i32; 3], f: Vec3, offsets: &[u32; 3], jitter: f32, reach: i32) {
        for oz in -reach..=reach {
            for oy in -reach..=reach {
                for ox in -reach..=reach {
                    let h = cell3_offset(
                        base[0].wrapping_add(ox),
                        base[1].wrapping_add(oy),
                        base[2].wrapping_add(oz),
                        offsets,
                    );
                    let point =
                        Vec3::new(ox as f32, oy as f32, oz as f32) + point_in_cell(h, jitter);
                    let v = f - point;
                    let d = v.length_squared();
                    if d < self.d1 {
                        (self.d2, self.v2) = (self.d1, self.v1);
                        (self.d1, self.v1, self.id) = (d, v, h[0] ^ h[1].rotate_left(16));
                    } else if d < self.d2 {
                        (self.d2, self.v2) = (d, v);
                    }
                }
            }
        }
    }
}
