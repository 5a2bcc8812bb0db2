//! Built-in procedural shapes as triangle meshes in object space (mm): box, quad, sphere,
//! cylinder, lathe (a profile revolved about z) and the Utah teapot.

use crate::math::PI;
use crate::render::TriMesh;
use glam::{Vec2, Vec3};

/// An axis-aligned box of edge lengths `size`, centred at the origin, flat-shaded, normals out.
pub(crate) fn make_box(size: Vec3) -> TriMesh {
    let h = size * 0.5;
    let mut m = TriMesh::default();
    // Each face: outward normal n and two in-plane axes (a, b) with a × b = n.
    for (n, a, b) in [
        (Vec3::X, Vec3::Y, Vec3::Z),
        (-Vec3::X, Vec3::Z, Vec3::Y),
        (Vec3::Y, Vec3::Z, Vec3::X),
        (-Vec3::Y, Vec3::X, Vec3::Z),
        (Vec3::Z, Vec3::X, Vec3::Y),
        (-Vec3::Z, Vec3::Y, Vec3::X),
    ] {
        let base = m.positions.len() as u32;
        let c = n * h;
        for (s, t) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            m.positions.push(c + a * h * s + b * h * t);
        }
        m.indices.push([base, base + 1, base + 2]);
        m.indices.push([base, base + 2, base + 3]);
    }
    m
}

/// A `size.x` × `size.y` rectangle in the xy plane centred at the origin, facing +z.
pub fn make_quad(size: Vec2) -> TriMesh {
    let (x, y) = (size.x * 0.5, size.y * 0.5);
    TriMesh {
        positions: vec![
            Vec3::new(-x, -y, 0.0),
            Vec3::new(x, -y, 0.0),
            Vec3::new(x, y, 0.0),
            Vec3::new(-x, y, 0.0),
        ],
        normals: None,
        indices: vec![[0, 1, 2], [0, 2, 3]],
    }
}

/// A UV sphere of `radius` with `segments` around and `segments / 2` from pole to pole,
/// with exact normals.
pub fn make_sphere(radius: f32, segments: u32) -> TriMesh {
    let rings = (segments / 2).max(2);
    let profile: Vec<Vec2> = (0..=rings)
        .map(|i| {
            let theta = PI * i as f32 / rings as f32;
            // Exact poles, so the pole triangles are exactly degenerate and dropped.
            let r = if i == 0 || i == rings {
                0.0
            } else {
                radius * theta.sin()
            };
            Vec2::new(r, -radius * theta.cos())
        })
        .collect();
    let normals: Vec<Vec2> = profile.iter().map(|p| *p / radius).collect();
    revolve(&profile, Some(&normals), segments)
}

/// A cylinder of `radius` along z from 0 to `height`, smooth side and flat caps.
pub(crate) fn make_cylinder(radius: f32, height: f32, segments: u32) -> TriMesh {
    let side = revolve(
        &[Vec2::new(radius, 0.0), Vec2::new(radius, height)],
        Some(&[Vec2::X, Vec2::X]),
        segments,
    );
    let bottom = revolve(
        &[Vec2::new(0.0, 0.0), Vec2::new(radius, 0.0)],
        Some(&[-Vec2::Y, -Vec2::Y]),
        segments,
    );
    let top = revolve(
        &[Vec2::new(radius, height), Vec2::new(0.0, height)],
        Some(&[Vec2::Y, Vec2::Y]),
        segments,
    );
    let mut m = side;
    m.append(&bottom);
    m.append(&top);
    m
}

/// A solid of revolution: the (radius, z) `profile` turned about z. Normals are the profile's
/// normals, averaged at interior profile points (so a sharp rim should repeat its point).
/// The outside is on the right of the profile when walking along it (bottom to top = outward).
pub(crate) fn make_lathe(profile: &[Vec2], segments: u32) -> TriMesh {
    let n = profile.len();
    let seg_normal = |i: usize| {
        let d = profile[i + 1] - profile[i];
        Vec2::new(d.y, -d.x).normalize_or_zero()
    };
    let normals: Vec<Vec2> = (0..n)
        .map(|i| {
            let a = if i > 0 { seg_normal(i - 1) } else { Vec2::ZERO };
            let b = if i + 1 < n { seg_normal(i) } else { Vec2::ZERO };
            let s = a + b;
            if s.length_squared() > 1e-12 {
                s.normalize()
            } else if a != Vec2::ZERO {
                a
            } else {
                b
            }
        })
        .collect();
    revolve(profile, Some(&normals), segments)
}

/// Texture coordinates of [`make_lathe`]'s vertices, in its vertex order: u = φ / 2π around the
/// axis (the seam at φ = 0 has its own column of vertices at u = 0 and u = 1) and v the arc length
/// along the profile over the whole profile's length (0 at its first point).
pub(crate) fn lathe_uvs(profile: &[Vec2], segments: u32) -> Vec<Vec2> {
    let segments = segments.max(3);
    let mut arc = vec![0.0f32];
    for w in profile.windows(2) {
        arc.push(arc[arc.len() - 1] + (w[1] - w[0]).length());
    }
    let total = arc.last().copied().unwrap_or(0.0).max(f32::MIN_POSITIVE);
    (0..=segments)
        .flat_map(|j| {
            let arc = &arc;
            (0..profile.len()).map(move |i| Vec2::new(j as f32 / segments as f32, arc[i] / total))
        })
        .collect()
}

/// Revolves a (r, z) polyline about z; `normals` are (n_r, n_z) per profile point.
fn revolve(profile: &[Vec2], normals: Option<&[Vec2]>, segments: u32) -> TriMesh {
    let segments = segments.max(3);
    let mut m = TriMesh {
        normals: normals.map(|_| Vec::new()),
        ..Default::default()
    };
    let ring = profile.len() as u32;
    for j in 0..=segments {
        let phi = 2.0 * PI * j as f32 / segments as f32;
        let (s, c) = if j == segments {
            (0.0, 1.0)
        } else {
            phi.sin_cos()
        };
        for (i, p) in profile.iter().enumerate() {
            m.positions.push(Vec3::new(p.x * c, p.x * s, p.y));
            if let (Some(ns), Some(out)) = (normals, m.normals.as_mut()) {
                out.push(Vec3::new(ns[i].x * c, ns[i].x * s, ns[i].y));
            }
        }
    }
    for j in 0..segments {
        for i in 0..ring - 1 {
            let a = j * ring + i;
            let b = (j + 1) * ring + i;
            // Counter-clockwise seen from outside when the profile runs bottom to top.
            m.indices.push([a, b, b + 1]);
            m.indices.push([a, b + 1, a + 1]);
        }
    }
    m.drop_degenerate();
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Signed volume by the divergence theorem: Σ (a · (b × c)) / 6 over outward triangles.
    fn volume(m: &TriMesh) -> f32 {
        m.indices
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| m.positions[i as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    #[test]
    fn closed_shapes_have_outward_orientation_and_right_volume() {
        let b = make_box(Vec3::new(1.0, 2.0, 3.0));
        assert!((volume(&b) - 6.0).abs() < 1e-4);
        let s = make_sphere(1.0, 128);
        assert!((volume(&s) - 4.0 / 3.0 * PI).abs() < 0.01, "{}", volume(&s));
        let c = make_cylinder(1.0, 2.0, 128);
        assert!((volume(&c) - 2.0 * PI).abs() < 0.01, "{}", volume(&c));
        for m in [&s, &c] {
            // Smooth normals agree with the geometric normal's side.
            for t in &m.indices {
                let [a, b, cc] = t.map(|i| m.positions[i as usize]);
                let ng = (b - a).cross(cc - a);
                let ns = m.normals.as_ref().unwrap()[t[0] as usize];
                assert!(ng.dot(ns) > 0.0, "{a} {b} {cc} ng {ng} ns {ns}");
            }
        }
    }
}
