//! The Utah teapot (Newell 1975) from its 32 bicubic Bézier patches. The data are written the
//! way the teapot was designed: rim, body, lid and bottom are surfaces of revolution, each a
//! 4-point (radius, z) profile swept through four quarter-circle patches (control offset 0.56 r,
//! the classic cubic circle approximation); handle and spout are tubes between two (x, z) curves
//! with a half-width per row, mirrored in y. Units: the original's (height 3.15); scale by `size`.

use crate::render::TriMesh;
use glam::{Vec2, Vec3};

type Patch = [[Vec3; 4]; 4];

/// (radius, z) profiles of the surfaces of revolution, and whether the quarter patches turn
/// counter-clockwise (the bottom) instead of clockwise.
const REVOLVED: [([[f32; 2]; 4], bool); 6] = [
    (
        [[1.4, 2.4], [1.3375, 2.53125], [1.4375, 2.53125], [1.5, 2.4]],
        false,
    ), // rim
    ([[1.5, 2.4], [1.75, 1.875], [2.0, 1.35], [2.0, 0.9]], false), // upper body
    ([[2.0, 0.9], [2.0, 0.45], [1.5, 0.225], [1.5, 0.15]], false), // lower body
    ([[0.0, 3.15], [0.8, 3.15], [0.0, 2.85], [0.2, 2.7]], false),  // lid knob
    ([[0.2, 2.7], [0.4, 2.55], [1.3, 2.55], [1.3, 2.4]], false),   // lid
    ([[0.0, 0.0], [1.425, 0.0], [1.5, 0.075], [1.5, 0.15]], true), // bottom
];

/// Four Bézier control points (x, z).
type Curve = [[f32; 2]; 4];

/// Tubes: curve A, curve B (x, z) and the half-width of each row.
const TUBES: [(Curve, Curve, [f32; 4]); 4] = [
    (
        [[-1.6, 2.025], [-2.3, 2.025], [-2.7, 2.025], [-2.7, 1.8]],
        [[-1.5, 2.25], [-2.5, 2.25], [-3.0, 2.25], [-3.0, 1.8]],
        [0.3; 4],
    ), // upper handle
    (
        [[-2.7, 1.8], [-2.7, 1.575], [-2.5, 1.125], [-2.0, 0.9]],
        [[-3.0, 1.8], [-3.0, 1.35], [-2.65, 0.9375], [-1.9, 0.6]],
        [0.3; 4],
    ), // lower handle
    (
        [[1.7, 1.425], [2.6, 1.425], [2.3, 2.1], [2.7, 2.4]],
        [[1.7, 0.6], [3.1, 0.825], [2.4, 2.025], [3.3, 2.4]],
        [0.66, 0.66, 0.25, 0.25],
    ), // spout body
    (
        [[2.7, 2.4], [2.8, 2.475], [2.9, 2.475], [2.8, 2.4]],
        [[3.3, 2.4], [3.525, 2.49375], [3.45, 2.5125], [3.2, 2.4]],
        [0.25, 0.25, 0.15, 0.15],
    ), // spout tip
];

/// The 32 control-point patches.
pub(crate) fn patches() -> Vec<Patch> {
    let mut out = Vec::with_capacity(32);
    for (profile, ccw) in REVOLVED {
        for quarter in 0..4 {
            let sign = if ccw { 1.0 } else { -1.0 };
            let turn = sign * std::f32::consts::FRAC_PI_2 * quarter as f32;
            let (s, c) = turn.sin_cos();
            let mut p = [[Vec3::ZERO; 4]; 4];
            for (i, [r, z]) in profile.into_iter().enumerate() {
                // A quarter circle from +x towards ∓y, rotated by `turn`.
                let q = [(r, 0.0), (r, 0.56 * r), (0.56 * r, r), (0.0, r)];
                for (j, (a, b)) in q.into_iter().enumerate() {
                    let (x, y) = (a, sign * b);
                    p[i][j] = Vec3::new(c * x - s * y, s * x + c * y, z);
                }
            }
            out.push(p);
        }
    }
    for (a, b, w) in TUBES {
        for side in [-1.0f32, 1.0] {
            let mut p = [[Vec3::ZERO; 4]; 4];
            for i in 0..4 {
                let (pa, pb) = (Vec2::from(a[i]), Vec2::from(b[i]));
                let y = side * w[i];
                p[i] = [
                    Vec3::new(pa.x, 0.0, pa.y),
                    Vec3::new(pa.x, y, pa.y),
                    Vec3::new(pb.x, y, pb.y),
                    Vec3::new(pb.x, 0.0, pb.y),
                ];
            }
            out.push(p);
        }
    }
    out
}

/// Cubic Bernstein weights and their derivatives at t.
fn bernstein(t: f32) -> ([f32; 4], [f32; 4]) {
    let s = 1.0 - t;
    (
        [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t],
        [
            -3.0 * s * s,
            3.0 * s * s - 6.0 * t * s,
            6.0 * t * s - 3.0 * t * t,
            3.0 * t * t,
        ],
    )
}

/// Point, ∂/∂u and ∂/∂v of a bicubic Bézier patch (tensor product, Farin ch. 14).
fn eval(p: &Patch, u: f32, v: f32) -> (Vec3, Vec3, Vec3) {
    let (bu, du) = bernstein(u);
    let (bv, dv) = bernstein(v);
    let (mut x, mut xu, mut xv) = (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO);
    for i in 0..4 {
        for j in 0..4 {
            x += p[i][j] * bu[i] * bv[j];
            xu += p[i][j] * du[i] * bv[j];
            xv += p[i][j] * bu[i] * dv[j];
        }
    }
    (x, xu, xv)
}

/// The teapot tessellated `resolution` × `resolution` quads per patch, scaled by `size`
/// (z up, resting on z = 0), with normals from the patch derivatives.
pub(crate) fn make_teapot(size: f32, resolution: u32) -> TriMesh {
    let n = resolution.max(1);
    let mut m = TriMesh {
        normals: Some(Vec::new()),
        ..Default::default()
    };
    for p in patches() {
        let base = m.positions.len() as u32;
        for i in 0..=n {
            for j in 0..=n {
                let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
                let (x, xu, xv) = eval(&p, u, v);
                let mut nrm = xu.cross(xv);
                if nrm.length_squared() < 1e-12 {
                    // Degenerate at a pole (a whole row of equal control points): step inwards.
                    let (_, xu, xv) = eval(&p, (u - 1e-3).abs().min(1.0 - 1e-3), v);
                    nrm = xu.cross(xv);
                }
                m.positions.push(x * size);
                m.normals.as_mut().unwrap().push(nrm.normalize_or_zero());
            }
        }
        let w = n + 1;
        for i in 0..n {
            for j in 0..n {
                let a = base + i * w + j;
                // Wound so the geometric normal agrees with ∂u × ∂v, as the vertex normals do.
                m.indices.push([a, a + w, a + w + 1]);
                m.indices.push([a, a + w + 1, a + 1]);
            }
        }
    }
    m.drop_degenerate();
    m
}

/// Texture coordinates of [`make_teapot`]'s vertices, in its vertex order: each of the 32 patches
/// gets its own cell of an 8 × 4 atlas (patch k in column k mod 8, row k div 8), its (u, v)
/// parameter square mapped onto the cell inset by `UV_GUTTER` of the cell on every side, so a
/// baked map can pad each chart outward without touching its neighbours.
pub(crate) fn teapot_uvs(resolution: u32) -> Vec<Vec2> {
    let n = resolution.max(1);
    let cell = Vec2::new(1.0 / 8.0, 1.0 / 4.0);
    let mut out = Vec::with_capacity(32 * (n as usize + 1).pow(2));
    for k in 0..32u32 {
        let origin = Vec2::new((k % 8) as f32, (k / 8) as f32) * cell;
        for i in 0..=n {
            for j in 0..=n {
                let t = Vec2::new(i as f32, j as f32) / n as f32;
                out.push(origin + cell * (UV_GUTTER + (1.0 - 2.0 * UV_GUTTER) * t));
            }
        }
    }
    out
}

/// The gutter around each patch's chart in [`teapot_uvs`], as a fraction of its cell.
const UV_GUTTER: f32 = 0.04;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn teapot_patches_and_normals_are_consistent() {
        let ps = patches();
        assert_eq!(ps.len(), 32);
        // Corner control points of the rim's first quarter are the published ones.
        assert_eq!(ps[0][0][0], Vec3::new(1.4, 0.0, 2.4));
        assert!((ps[0][0][3] - Vec3::new(0.0, -1.4, 2.4)).length() < 1e-6);
        assert!((ps[0][0][1] - Vec3::new(1.4, -0.784, 2.4)).length() < 1e-6);
        // Quarters meet: the end of quarter k is the start of quarter k+1.
        for k in 0..3 {
            assert!((ps[k][3][3] - ps[k + 1][3][0]).length() < 1e-5);
        }
        let m = make_teapot(10.0, 6);
        assert_eq!(teapot_uvs(6).len(), m.positions.len());
        let ns = m.normals.as_ref().unwrap();
        let mut agree = 0;
        for t in &m.indices {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            let ng = (b - a).cross(c - a);
            if ng.dot(ns[t[0] as usize] + ns[t[1] as usize] + ns[t[2] as usize]) > 0.0 {
                agree += 1;
            }
        }
        assert!(
            agree as f32 >= 0.99 * m.indices.len() as f32,
            "{agree} / {}",
            m.indices.len()
        );
        let top = m.positions.iter().map(|p| p.z).fold(0.0, f32::max);
        assert!((top - 31.5).abs() < 1e-3);
    }
}
