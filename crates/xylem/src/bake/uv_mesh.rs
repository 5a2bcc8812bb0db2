//! A triangle mesh with texture coordinates, the surface a mesh bake ([`super::raster`]) maps its
//! texels through: from an OBJ's `vt`, or a built-in shape's own layout (the teapot's 32 patch
//! charts, the turned bowl's lathe (φ, arc length) chart, a board's box atlas). Texture space is
//! glTF's: (0, 0) the image's top-left corner, v running down.
//!
//! Tangent frames (per vertex, as glTF's TANGENT attribute carries them): t = ∂p/∂u and
//! b = ∂p/∂v of each triangle solved from its edges and UV edges (Lengyel, "Computing Tangent
//! Space Basis Vectors for an Arbitrary Mesh", 2001), area-weighted over the triangles sharing the
//! vertex, t orthogonalised against the normal; the sign w makes w (n × t) point along −∂p/∂v,
//! the image's up, as the flat bake's tangent space has it (notes/gltf.md).

use crate::render::TriMesh;
use crate::scene::mesh_io::{load_mesh_uv, MeshError};
use crate::scene::{shapes, teapot};
use glam::{Vec2, Vec3, Vec4};
use std::path::Path;

/// Vertices with positions (object space, mm), unit normals and texture coordinates, and
/// triangles indexing them (counter-clockwise seen from outside).
#[derive(Clone, Debug, Default)]
pub struct UvMesh {
    /// Object-space positions (mm).
    pub positions: Vec<Vec3>,
    /// Unit shading normals, one per vertex.
    pub normals: Vec<Vec3>,
    /// Texture coordinates, one per vertex (glTF: v down the image).
    pub uvs: Vec<Vec2>,
    /// Triangles.
    pub indices: Vec<[u32; 3]>,
}

/// The built-in shapes `xylem bake --mesh` knows by name, with the tree placement of the scene
/// that shows each: (name, scene, what it is).
pub const BUILTIN_MESHES: [(&str, &str); 2] = [
    (
        "teapot",
        "scenes/teapot.toml: 30 mm per unit, 10 × 10 quads per patch",
    ),
    (
        "bowl",
        "scenes/turned_bowl.toml: the lathe profile at 128 segments",
    ),
];

/// The turned bowl's (radius, z) profile, mm (scenes/turned_bowl.toml).
const BOWL_PROFILE: [[f32; 2]; 11] = [
    [0.0, 0.0],
    [40.0, 0.0],
    [44.0, 4.0],
    [70.0, 25.0],
    [92.0, 55.0],
    [100.0, 75.0],
    [96.0, 77.0],
    [88.0, 60.0],
    [66.0, 32.0],
    [40.0, 14.0],
    [0.0, 10.0],
];

impl UvMesh {
    /// A built-in shape by name ([`BUILTIN_MESHES`]), or `None`.
    pub fn builtin(name: &str) -> Option<UvMesh> {
        let (m, uvs) = match name {
            "teapot" => (teapot::make_teapot(30.0, 10), teapot::teapot_uvs(10)),
            "bowl" => {
                let p: Vec<Vec2> = BOWL_PROFILE.iter().map(|&q| Vec2::from(q)).collect();
                (shapes::make_lathe(&p, 128), shapes::lathe_uvs(&p, 128))
            }
            _ => return None,
        };
        UvMesh::from_trimesh(m, uvs).ok()
    }

    /// An OBJ file with `vt` on every face corner (a PLY, or an OBJ without them, is refused
    /// naming the file and what is missing).
    pub fn load(path: &Path) -> Result<UvMesh, MeshError> {
        let (m, uvs) = load_mesh_uv(path)?;
        let bad = |message: String| MeshError::Bad {
            path: path.display().to_string(),
            message,
        };
        let uvs = uvs.ok_or_else(|| {
            bad(
                "has no texture coordinates: every face corner needs a `vt` \
                 (allowed: an .obj with a UV layout; a .ply carries none here)"
                    .into(),
            )
        })?;
        if let Some(i) = uvs.iter().position(|t| !t.is_finite()) {
            return Err(bad(format!(
                "texture coordinate {} of {} is not finite (allowed: finite u, v)",
                i + 1,
                uvs.len()
            )));
        }
        UvMesh::from_trimesh(m, uvs).map_err(bad)
    }

    /// A mesh and one texture coordinate per vertex; smooth area-weighted normals where the mesh
    /// has none. Degenerate triangles are dropped; an error when none is left.
    pub(crate) fn from_trimesh(mut m: TriMesh, uvs: Vec<Vec2>) -> Result<UvMesh, String> {
        if uvs.len() != m.positions.len() {
            return Err(format!(
                "{} texture coordinates for {} vertices",
                uvs.len(),
                m.positions.len()
            ));
        }
        m.drop_degenerate();
        if m.indices.is_empty() {
            return Err("no triangle with a non-zero area".into());
        }
        let normals = match m.normals.take() {
            Some(n) if n.len() == m.positions.len() => n,
            _ => {
                let mut n = vec![Vec3::ZERO; m.positions.len()];
                for t in &m.indices {
                    let [a, b, c] = t.map(|i| m.positions[i as usize]);
                    let g = (b - a).cross(c - a);
                    for i in t {
                        n[*i as usize] += g;
                    }
                }
                n.iter().map(|v| v.normalize_or_zero()).collect()
            }
        };
        Ok(UvMesh {
            positions: m.positions,
            normals,
            uvs,
            indices: m.indices,
        })
    }

    /// Per-triangle (∂p/∂u, ∂p/∂v), zero where the triangle's UVs are degenerate.
    pub(crate) fn triangle_derivatives(&self, t: [u32; 3]) -> (Vec3, Vec3) {
        let [p0, p1, p2] = t.map(|i| self.positions[i as usize]);
        let [t0, t1, t2] = t.map(|i| self.uvs[i as usize]);
        let (e1, e2, d1, d2) = (p1 - p0, p2 - p0, t1 - t0, t2 - t0);
        let det = d1.x * d2.y - d2.x * d1.y;
        if det.abs() < 1e-20 || !det.is_finite() {
            return (Vec3::ZERO, Vec3::ZERO);
        }
        let r = 1.0 / det;
        ((e1 * d2.y - e2 * d1.y) * r, (e2 * d1.x - e1 * d2.x) * r)
    }

    /// The mesh as Wavefront OBJ text: `v` (mm), `vn`, `vt` with v = 1 − the texture's v (OBJ's
    /// bottom-up convention, which [`UvMesh::load`] and Mitsuba's loader flip back), one
    /// `f a/a/a b/b/b c/c/c` per triangle; numbers as f32's shortest round trip, so loading
    /// it gives this mesh again.
    pub fn to_obj(&self) -> String {
        use std::fmt::Write;
        let mut s =
            String::from("# xylem bake: the mesh as baked (mm, z up); vt v = 1 - the maps' v\n");
        for ((p, n), t) in self.positions.iter().zip(&self.normals).zip(&self.uvs) {
            let _ = writeln!(s, "v {:?} {:?} {:?}", p.x, p.y, p.z);
            let _ = writeln!(s, "vn {:?} {:?} {:?}", n.x, n.y, n.z);
            let _ = writeln!(s, "vt {:?} {:?}", t.x, 1.0 - t.y);
        }
        for t in &self.indices {
            let [a, b, c] = t.map(|i| i + 1);
            let _ = writeln!(s, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}");
        }
        s
    }

    /// Per-vertex tangents (xyz unit, ⟂ the normal; w = ±1 with bitangent w (n × t) along
    /// −∂p/∂v), as glTF's TANGENT attribute.
    pub(crate) fn tangents(&self) -> Vec<Vec4> {
        let mut tu = vec![Vec3::ZERO; self.positions.len()];
        let mut tv = vec![Vec3::ZERO; self.positions.len()];
        for t in &self.indices {
            let [a, b, c] = t.map(|i| self.positions[i as usize]);
            let area = 0.5 * (b - a).cross(c - a).length();
            let (du, dv) = self.triangle_derivatives(*t);
            for i in t {
                tu[*i as usize] += du.normalize_or_zero() * area;
                tv[*i as usize] += dv.normalize_or_zero() * area;
            }
        }
        (0..self.positions.len())
            .map(|i| {
                let (t, w) = frame(self.normals[i], tu[i], tv[i]);
                t.extend(w)
            })
            .collect()
    }
}

/// The unit tangent (∂p/∂u less its part along `n`) and the handedness w = ±1 for which
/// w (n × t) points along −∂p/∂v (`dv`), the image's up. Any unit vector ⟂ n where ∂p/∂u is
/// degenerate.
pub fn frame(n: Vec3, du: Vec3, dv: Vec3) -> (Vec3, f32) {
    let t = (du - n * n.dot(du)).normalize_or_zero();
    let t = if t == Vec3::ZERO || !t.is_finite() {
        n.any_orthonormal_vector()
    } else {
        t
    };
    let w = if n.cross(t).dot(-dv) < 0.0 { -1.0 } else { 1.0 };
    (t, w)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The OBJ text of the built-in teapot reads back as the same mesh: positions, normals and
    /// uvs equal to 1e-6 (the `1 − v` round trip), the same triangles.
    #[test]
    fn obj_text_reads_back_as_the_mesh() {
        let m = UvMesh::builtin("teapot").unwrap();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("teapot.obj");
        std::fs::write(&path, m.to_obj()).unwrap();
        let back = UvMesh::load(&path).unwrap();
        assert_eq!(back.indices.len(), m.indices.len());
        let close = |a: Vec3, b: Vec3| (a - b).abs().max_element() < 1e-6;
        // tobj may reorder vertices: compare each triangle's corners.
        for (ta, tb) in m.indices.iter().zip(&back.indices) {
            for (&i, &j) in ta.iter().zip(tb) {
                let (i, j) = (i as usize, j as usize);
                assert!(close(m.positions[i], back.positions[j]));
                assert!(close(m.normals[i], back.normals[j]));
                assert!((m.uvs[i] - back.uvs[j]).abs().max_element() < 1e-6);
            }
        }
    }

    #[test]
    fn builtin_shapes_have_a_uv_per_vertex_inside_the_unit_square() {
        for (name, _) in BUILTIN_MESHES {
            let m = UvMesh::builtin(name).unwrap();
            assert_eq!(m.uvs.len(), m.positions.len(), "{name}");
            assert!(m
                .uvs
                .iter()
                .all(|t| (0.0..=1.0).contains(&t.x) && (0.0..=1.0).contains(&t.y)));
            assert!(m.indices.len() > 1000, "{name}: {}", m.indices.len());
        }
        assert!(UvMesh::builtin("dragon").is_none());
    }

    #[test]
    fn tangent_follows_u_and_bitangent_the_image_up() {
        // A quad in the xy plane facing +z, u along +x, v (down the image) along −y.
        let m = UvMesh::from_trimesh(
            crate::scene::shapes::make_quad(Vec2::new(2.0, 2.0)),
            vec![
                Vec2::new(0.0, 1.0),
                Vec2::new(1.0, 1.0),
                Vec2::new(1.0, 0.0),
                Vec2::new(0.0, 0.0),
            ],
        )
        .unwrap();
        for t in m.tangents() {
            // Bitangent w (n × t) = z × x = +y = −∂p/∂v: w = +1.
            assert_eq!(t, Vec4::new(1.0, 0.0, 0.0, 1.0));
        }
        assert!(UvMesh::from_trimesh(TriMesh::default(), vec![Vec2::ZERO]).is_err());
    }
}
