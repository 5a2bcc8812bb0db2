//! Baking onto a mesh through its UV layout: every texel centre is found in the UV triangle that
//! covers it, its barycentric coordinates give the surface point, normal and tangent frame
//! (interpolated as a glTF renderer interpolates the vertex attributes), and the wood volume is
//! evaluated at that point carried into the tree by the object's placement — the same
//! `texel_values` the flat bake uses, so a flat chart reproduces the flat bake.
//! Texels next to a chart are then padded by dilation, so bilinear and mip-mapped lookups near a
//! seam read wood and not background; texels no triangle reaches take the covered texels' mean.
//!
//! Rasterisation: texel (x, y) has its centre at ((x + ½)/W, (y + ½)/H) in UV space; it belongs to
//! a triangle when all three barycentric coordinates λ (solved in UV space) are ≥ −1e-6
//! relative. Where UV triangles overlap (mirrored or stacked charts) the first triangle in file
//! order keeps the texel — deterministic, and the shared texels show the first surface's wood —
//! and the overlap is counted ([`MeshBake::overlapping`]).

use super::uv_mesh::{frame, UvMesh};
use super::{texel_values, BakedMaps, TexelFrame};
use crate::wood::{Needs, WoodVolume};
use glam::{Affine3A, Mat3, Vec2, Vec3};
use rayon::prelude::*;

/// What a texel of a mesh bake holds, by how it was filled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Coverage {
    /// Its centre lies on the surface: the wood there.
    Covered,
    /// Within the padding of a chart: the mean of its filled neighbours.
    Padding,
    /// Reached by no chart: the covered texels' mean.
    Empty,
}

impl Coverage {
    /// Grey level in the coverage mask PNG (255 covered, 128 padding, 0 empty).
    pub fn code(self) -> u8 {
        match self {
            Coverage::Covered => 255,
            Coverage::Padding => 128,
            Coverage::Empty => 0,
        }
    }
}

/// A mesh bake: the maps, how each texel was filled, and what the layout did.
#[derive(Clone, Debug)]
pub struct MeshBake {
    /// The maps, in the mesh's texture space.
    pub maps: BakedMaps,
    /// Per texel, row-major.
    pub coverage: Vec<Coverage>,
    /// Texels whose centre lies strictly inside a triangle after an earlier one took it
    /// (overlapping UVs; the first wins; centres on a shared edge are not counted).
    pub overlapping: usize,
    /// Triangles reaching outside [0, 1]² in UV (the parts outside are not baked; a glTF sampler
    /// repeats the texture there).
    pub outside: usize,
}

impl MeshBake {
    /// Stages `DIR/coverage.png`: the [`Coverage::code`] of every texel as grey, untagged.
    pub fn stage_coverage(
        &self,
        dir: &std::path::Path,
    ) -> Result<crate::output::Staged, crate::picture::ImageError> {
        let mask: Vec<u8> = self.coverage.iter().flat_map(|c| [c.code(); 3]).collect();
        crate::picture::png::stage_png_tagged(
            &dir.join("coverage.png"),
            self.maps.width,
            self.maps.height,
            &mask,
            crate::picture::png::PngTag::Untagged,
        )
    }
}

/// Bakes `volume` onto `mesh` (object space; `to_tree` the placement's object → tree map) into
/// `width` × `height` texels, padding every chart by `pad` texels.
pub fn bake_mesh(
    volume: &WoodVolume,
    mesh: &UvMesh,
    to_tree: Affine3A,
    width: u32,
    height: u32,
    pad: u32,
) -> MeshBake {
    let (w, h) = (width.max(1) as usize, height.max(1) as usize);
    let (owner, overlapping, outside) = texel_owners(mesh, w, h);
    let tangents = mesh.tangents();
    let l = Mat3::from(to_tree.matrix3);
    let texels: Vec<Option<_>> = owner
        .par_iter()
        .map(|o| {
            o.map(|(k, bary)| {
                let t = mesh.indices[k as usize];
                let at = |v: &dyn Fn(usize) -> Vec3| {
                    v(t[0] as usize) * bary.x
                        + v(t[1] as usize) * bary.y
                        + v(t[2] as usize) * bary.z
                };
                let p = at(&|i| mesh.positions[i]);
                let n = at(&|i| mesh.normals[i]).normalize_or_zero();
                let [p0, p1, p2] = t.map(|i| mesh.positions[i as usize]);
                let n = if n == Vec3::ZERO {
                    (p1 - p0).cross(p2 - p0).normalize_or_zero()
                } else {
                    n
                };
                let tu = at(&|i| tangents[i].truncate());
                let (_, dv) = mesh.triangle_derivatives(t);
                let (right, w) = frame(n, tu, dv);
                let f = TexelFrame {
                    right,
                    up: w * n.cross(right),
                    normal: n,
                };
                (volume.eval(to_tree.transform_point3(p), Needs::ALL), f)
            })
        })
        .collect();
    let mut maps = texel_values(width.max(1), height.max(1), &texels, l);
    let mut coverage: Vec<Coverage> = owner
        .iter()
        .map(|o| {
            if o.is_some() {
                Coverage::Covered
            } else {
                Coverage::Empty
            }
        })
        .collect();
    dilate(&mut maps, &mut coverage, pad);
    fill_empty(&mut maps, &coverage);
    MeshBake {
        maps,
        coverage,
        overlapping,
        outside,
    }
}

/// Texel → (triangle, barycentrics) of the first triangle covering its centre, for a `w × h`
/// texture of `mesh`'s UV layout; with the count of texel centres a second triangle covers
/// inside (overlapping charts) and of triangles reaching outside the unit square.
fn texel_owners(mesh: &UvMesh, w: usize, h: usize) -> (Vec<Option<(u32, Vec3)>>, usize, usize) {
    let size = Vec2::new(w as f32, h as f32);
    let mut owner: Vec<Option<(u32, Vec3)>> = vec![None; w * h];
    let (mut overlapping, mut outside) = (0, 0);
    for (k, t) in mesh.indices.iter().enumerate() {
        let [a, b, c] = t.map(|i| mesh.uvs[i as usize] * size);
        if [a, b, c]
            .iter()
            .any(|p| p.min_element() < 0.0 || p.x > size.x || p.y > size.y)
        {
            outside += 1;
        }
        let det = (b - a).perp_dot(c - a);
        if det.abs() < 1e-12 || !det.is_finite() {
            continue;
        }
        let lo = a.min(b).min(c);
        let hi = a.max(b).max(c);
        let x0 = (lo.x - 0.5).ceil().max(0.0) as usize;
        let y0 = (lo.y - 0.5).ceil().max(0.0) as usize;
        let x1 = ((hi.x - 0.5).floor().min(size.x - 1.0)).max(-1.0) as i64;
        let y1 = ((hi.y - 0.5).floor().min(size.y - 1.0)).max(-1.0) as i64;
        for y in y0 as i64..=y1 {
            for x in x0 as i64..=x1 {
                let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let l1 = (p - a).perp_dot(c - a) / det;
                let l2 = (b - a).perp_dot(p - a) / det;
                let l = Vec3::new(1.0 - l1 - l2, l1, l2);
                if l.min_element() < -1e-6 {
                    continue;
                }
                let slot = &mut owner[y as usize * w + x as usize];
                if slot.is_some() {
                    // A centre on an edge two triangles share is not an overlap.
                    if l.min_element() > 1e-5 {
                        overlapping += 1;
                    }
                } else {
                    *slot = Some((
                        k as u32,
                        l.max(Vec3::ZERO) / l.max(Vec3::ZERO).element_sum(),
                    ));
                }
            }
        }
    }
    (owner, overlapping, outside)
}

/// Every map's texel `i` set to the weighted sum Σ k·texel(j) over `taps`.
fn blend(m: &mut BakedMaps, i: usize, taps: &[(usize, f32)]) {
    let v3 = |v: &[Vec3]| taps.iter().map(|&(j, k)| v[j] * k).sum::<Vec3>();
    let s = |v: &[f32]| taps.iter().map(|&(j, k)| v[j] * k).sum::<f32>();
    m.base_color[i] = v3(&m.base_color);
    m.fiber_color[i] = v3(&m.fiber_color);
    m.anisotropy[i] = v3(&m.anisotropy);
    m.highlight_width[i] = s(&m.highlight_width);
    m.ray_mask[i] = s(&m.ray_mask);
    m.normal[i] = v3(&m.normal).try_normalize().unwrap_or(Vec3::Z);
    m.fiber[i] = v3(&m.fiber).try_normalize().unwrap_or(Vec3::X);
    m.ray[i] = v3(&m.ray).try_normalize().unwrap_or(Vec3::Y);
}

/// Grows the filled texels `pad` rings outward: each pass gives every unfilled texel with a
/// filled 8-neighbour the mean of those neighbours (as they were before the pass), the standard
/// "edge padding" of texture bakers, so a bilinear tap or a mip level straddling a chart's edge
/// averages wood with wood.
fn dilate(m: &mut BakedMaps, coverage: &mut [Coverage], pad: u32) {
    let (w, h) = (m.width as i64, m.height as i64);
    for _ in 0..pad {
        let mut grown = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) as usize;
                if coverage[i] != Coverage::Empty {
                    continue;
                }
                let mut taps = Vec::with_capacity(8);
                for (dx, dy) in [
                    (-1, -1),
                    (0, -1),
                    (1, -1),
                    (-1, 0),
                    (1, 0),
                    (-1, 1),
                    (0, 1),
                    (1, 1),
                ] {
                    let (u, v) = (x + dx, y + dy);
                    if (0..w).contains(&u) && (0..h).contains(&v) {
                        let j = (v * w + u) as usize;
                        if coverage[j] != Coverage::Empty {
                            taps.push(j);
                        }
                    }
                }
                if !taps.is_empty() {
                    grown.push((i, taps));
                }
            }
        }
        if grown.is_empty() {
            break;
        }
        // Blend from the pre-pass values: each grown texel reads only texels filled before.
        for (i, taps) in &grown {
            let k = 1.0 / taps.len() as f32;
            let taps: Vec<(usize, f32)> = taps.iter().map(|&j| (j, k)).collect();
            blend(m, *i, &taps);
        }
        for (i, _) in grown {
            coverage[i] = Coverage::Padding;
        }
    }
}

/// Texels no chart reaches: the mean of the covered ones (a flat background of the wood's mean,
/// so a far mip level tends to the surface's average).
fn fill_empty(m: &mut BakedMaps, coverage: &[Coverage]) {
    let covered: Vec<usize> = (0..coverage.len())
        .filter(|&i| coverage[i] == Coverage::Covered)
        .collect();
    if covered.is_empty() {
        return;
    }
    let k = 1.0 / covered.len() as f32;
    let taps: Vec<(usize, f32)> = covered.iter().map(|&j| (j, k)).collect();
    let Some(first) = (0..coverage.len()).find(|&i| coverage[i] == Coverage::Empty) else {
        return;
    };
    blend(m, first, &taps);
    for (i, c) in coverage.iter().enumerate().skip(first + 1) {
        if *c == Coverage::Empty {
            blend(m, i, &[(first, 1.0)]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bake::{bake, BakeCut, BoardCut};
    use crate::render::TriMesh;

    fn walnut() -> WoodVolume {
        WoodVolume::new(crate::wood::preset("walnut").unwrap(), 2).unwrap()
    }

    /// A quad in tree space over `board`'s baked face, its UVs the affine image
    /// uv' = offset + scale · uv of the face's own (u, v), wound outward.
    fn face_chart(board: &BoardCut, offset: Vec2, scale: f32) -> UvMesh {
        let r = board.rect();
        let corners = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
        let positions = corners
            .iter()
            .map(|&(s, t)| r.corner + s * r.size.x * r.right + t * r.size.y * r.down)
            .collect();
        let uvs = corners
            .iter()
            .map(|&(s, t)| offset + scale * Vec2::new(s, t))
            .collect();
        let m = TriMesh {
            positions,
            normals: None,
            indices: vec![[0, 2, 1], [0, 3, 2]],
        };
        UvMesh::from_trimesh(m, uvs).unwrap()
    }

    /// Largest difference between the flat bake's texel (x, y) and the mesh bake's texel
    /// (x + dx, y + dy), over every map.
    fn max_difference(flat: &BakedMaps, mesh: &BakedMaps, dx: usize, dy: usize) -> f32 {
        let mut worst = 0.0f32;
        for y in 0..flat.height as usize {
            for x in 0..flat.width as usize {
                let i = y * flat.width as usize + x;
                let j = (y + dy) * mesh.width as usize + x + dx;
                let d3 = |a: &[Vec3], b: &[Vec3]| (a[i] - b[j]).abs().max_element();
                let d1 = |a: &[f32], b: &[f32]| (a[i] - b[j]).abs();
                worst = worst
                    .max(d3(&flat.base_color, &mesh.base_color))
                    .max(d3(&flat.fiber_color, &mesh.fiber_color))
                    .max(d3(&flat.anisotropy, &mesh.anisotropy))
                    .max(d3(&flat.normal, &mesh.normal))
                    .max(d3(&flat.fiber, &mesh.fiber))
                    .max(d1(&flat.highlight_width, &mesh.highlight_width))
                    .max(d1(&flat.ray_mask, &mesh.ray_mask));
            }
        }
        worst
    }

    /// A chart that is an affine image (half scale, offset by a quarter) of a flat board's face
    /// reproduces the flat bake texel for texel: the chart's texel (x + W/2, y + H/2) of a
    /// 2W × 2H texture has its centre at the face's (x + ½)/W, (y + ½)/H. Independently, the base
    /// colour is the volume's at the face point worked out by hand. Negative control: the chart
    /// moved by one texel no longer matches.
    #[test]
    fn an_affine_chart_of_a_flat_board_reproduces_the_flat_bake() {
        let v = walnut();
        let board = BoardCut {
            size: [64.0, 32.0, 10.0],
            cut: BakeCut::Radial,
            radius: 120.0,
        };
        let flat = bake(&v, &board, 32);
        assert_eq!((flat.width, flat.height), (32, 16));
        let chart = face_chart(&board, Vec2::splat(0.25), 0.5);
        let m = bake_mesh(&v, &chart, Affine3A::IDENTITY, 64, 32, 0);
        assert_eq!(m.overlapping, 0);
        let covered = m
            .coverage
            .iter()
            .filter(|&&c| c == Coverage::Covered)
            .count();
        assert_eq!(covered, 32 * 16);
        let err = max_difference(&flat, &m.maps, 16, 8);
        assert!(err < 2e-3, "max difference {err}");
        // The face point by hand: radial cut, right = tree z, down = tree y, normal = tree x,
        // the face 5 mm out along x from the board centre (0, 120, 0).
        for (x, y) in [(0usize, 0usize), (31, 15), (10, 7)] {
            let (s, t) = ((x as f32 + 0.5) / 32.0, (y as f32 + 0.5) / 16.0);
            let p = Vec3::new(5.0, 120.0 - 16.0 + 32.0 * t, -32.0 + 64.0 * s);
            let want = v.eval(p, Needs::ALL).diffuse;
            let got = m.maps.base_color[(y + 8) * 64 + x + 16];
            assert!(
                (want - got).abs().max_element() < 2e-3,
                "{x},{y}: {want} vs {got}"
            );
        }
        // Negative control: one texel off.
        let shifted = face_chart(&board, Vec2::splat(0.25) + Vec2::new(1.0 / 64.0, 0.0), 0.5);
        let s = bake_mesh(&v, &shifted, Affine3A::IDENTITY, 64, 32, 0);
        let off = max_difference(&flat, &s.maps, 16, 8);
        assert!(
            off > 20.0 * err.max(1e-4),
            "shifted chart still matches: {off}"
        );
    }

    /// Padding fills the texels around a chart with the mean of their filled neighbours and
    /// leaves the chart itself as it was; the bilinear lookup on the chart's edge then reads wood
    /// (near the wood at the edge) instead of the background. Negative control: no padding.
    #[test]
    fn padding_fills_the_texels_next_to_a_chart_and_leaves_its_interior() {
        let v = walnut();
        let board = BoardCut {
            size: [32.0, 32.0, 10.0],
            cut: BakeCut::Tangential,
            radius: 150.0,
        };
        let chart = face_chart(&board, Vec2::splat(0.25), 0.5);
        let bare = bake_mesh(&v, &chart, Affine3A::IDENTITY, 32, 32, 0);
        let padded = bake_mesh(&v, &chart, Affine3A::IDENTITY, 32, 32, 2);
        let at = |x: usize, y: usize| y * 32 + x;
        for y in 0..32 {
            for x in 0..32 {
                let i = at(x, y);
                let inside = (8..24).contains(&x) && (8..24).contains(&y);
                let ring = (6..26).contains(&x) && (6..26).contains(&y);
                let want = if inside {
                    Coverage::Covered
                } else if ring {
                    Coverage::Padding
                } else {
                    Coverage::Empty
                };
                assert_eq!(padded.coverage[i], want, "{x},{y}");
                if inside {
                    assert_eq!(padded.maps.base_color[i], bare.maps.base_color[i]);
                    assert_eq!(padded.maps.normal[i], bare.maps.normal[i]);
                }
            }
        }
        // Texel (7, 12): the mean of (8, 11), (8, 12), (8, 13).
        let mean = (8..14)
            .filter(|y| (11..=13).contains(y))
            .map(|y| bare.maps.base_color[at(8, y)])
            .sum::<Vec3>()
            / 3.0;
        assert!(
            (padded.maps.base_color[at(7, 12)] - mean)
                .abs()
                .max_element()
                < 1e-6
        );
        assert_eq!(bare.coverage[at(7, 12)], Coverage::Empty);
        // On the chart's left edge (u = 0.25) a bilinear tap takes half of texel 7 (outside) and
        // half of texel 8 (the chart's edge texel): padded, it stays near the edge texel.
        let (e_pad, e_bare) = (seam_error(&padded.maps), seam_error(&bare.maps));
        eprintln!("seam error: padded {e_pad}, bare {e_bare}");
        assert!(
            e_pad < 0.85 * e_bare,
            "edge error padded {e_pad}, bare {e_bare}"
        );
    }

    /// Mean |lookup − edge texel| of the base colour on the left edge (u = 0.25) of the chart
    /// [0.25, 0.75]² of a 32 × 32 map, at the rows' centres: what the texel outside the chart
    /// adds to a bilinear tap on the seam.
    pub(crate) fn seam_error(m: &BakedMaps) -> f32 {
        let mut e = 0.0;
        for y in 8..24 {
            let uv = Vec2::new(0.25, (y as f32 + 0.5) / 32.0);
            let edge = m.base_color[y * 32 + 8];
            e += (m.lookup(uv).base_color - edge).abs().element_sum() / 3.0;
        }
        e / 16.0
    }

    /// Every face of a board's side atlas is baked: its texels vary (wood, not one colour) and
    /// each equals the volume at that texel's point on the face, found from the face's chart by
    /// hand (faces are axis-aligned rectangles in UV). Negative control: the point mirrored to
    /// the opposite face does not match.
    #[test]
    fn every_side_of_a_board_is_baked_from_its_own_points() {
        let v = walnut();
        let board = BoardCut {
            size: [60.0, 30.0, 12.0],
            cut: BakeCut::Tangential,
            radius: 100.0,
        };
        let sides = board.bake_sides(&v, 96);
        let (mesh, _) = board.side_atlas();
        let to_tree = board.gltf_to_tree();
        let (w, h) = (sides.maps.width as usize, sides.maps.height as usize);
        let centre = Vec3::new(0.0, 100.0, 0.0);
        for face in 0..5 {
            let q = (0..4).map(|k| face * 4 + k);
            let uv: Vec<Vec2> = q.clone().map(|k| mesh.uvs[k]).collect();
            let p: Vec<Vec3> = q.map(|k| mesh.positions[k]).collect();
            let (lo, hi) = (uv[0].min(uv[2]), uv[0].max(uv[2]));
            let (mut lum, mut mismatch, mut n) = (Vec::new(), 0, 0);
            for y in 0..h {
                for x in 0..w {
                    let c = Vec2::new((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
                    if c.cmplt(lo).any() || c.cmpgt(hi).any() {
                        continue;
                    }
                    let i = y * w + x;
                    assert_eq!(sides.coverage[i], Coverage::Covered, "face {face} {x},{y}");
                    // (s, t) along the chart's edges 0→1 (u) and 0→3 (v).
                    let s = (c.x - uv[0].x) / (uv[1].x - uv[0].x);
                    let t = (c.y - uv[0].y) / (uv[3].y - uv[0].y);
                    let pt = to_tree.transform_point3(p[0] + s * (p[1] - p[0]) + t * (p[3] - p[0]));
                    let want = v.eval(pt, Needs::ALL).diffuse;
                    let got = sides.maps.base_color[i];
                    assert!(
                        (want - got).abs().max_element() < 2e-3,
                        "face {face}: {want} {got}"
                    );
                    let mirrored = 2.0 * centre - pt;
                    if (v.eval(mirrored, Needs::ALL).diffuse - got)
                        .abs()
                        .max_element()
                        > 2e-3
                    {
                        mismatch += 1;
                    }
                    lum.push(crate::math::luminance(got));
                    n += 1;
                }
            }
            assert!(n > 50, "face {face}: {n} texels");
            assert!(
                mismatch > n / 2,
                "face {face}: the opposite face matches {}/{n}",
                n - mismatch
            );
            let (a, b) = lum
                .iter()
                .fold((f32::MAX, f32::MIN), |(a, b), &l| (a.min(l), b.max(l)));
            assert!(b > 1.05 * a, "face {face}: one colour {a}..{b}");
        }
    }
}
