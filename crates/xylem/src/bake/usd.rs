//! A baked board or mesh as a USD stage (`DIR/<name>.usda`, USD's text format) that binds the
//! MaterialX material of [`super::materialx`] to the baked surface, for USD pipelines.
//!
//! Sources: \[USD\] Pixar, *Universal Scene Description* documentation: the `.usda` layer syntax,
//! `UsdGeomMesh` (faceVertexCounts / faceVertexIndices, `orientation = rightHanded`: a face is
//! counter-clockwise seen from the side its normal points to; `primvars:st`, (0, 0) at the
//! image's lower left as UsdUVTexture reads it), `UsdShadeMaterialBindingAPI`
//! (`material:binding`), `UsdPreviewSurface`, and the usdMtlx file-format plugin, which reads a
//! `.mtlx` file as a layer whose material `M` is the prim `/MaterialX/Materials/M`, so a Material
//! prim can reference it.
//!
//! Space as the `.glb` has it (y up, metres): the board's length along x, its width along z, its
//! thickness along y; the baked face is the top (+y) with st = (u, 1 − v) of the bake's texel
//! coordinates (v down the image), so +s is +x and +t is −z, the image's up: MaterialX's tangent
//! and bitangent there are the bake's tangent-space x and y.

use super::gltf::gltf_roughness;
use super::materialx::{element_name, material_name};
use super::uv_mesh::UvMesh;
use super::{BakedMaps, BoardCut};
use crate::output::Staged;
use glam::Vec3;
use std::fmt::Write as _;
use std::path::Path;

/// One mesh of the stage: quads, then triangles, and, on a baked surface, texture coordinates
/// per vertex.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct UsdMesh {
    /// Prim name (a valid identifier).
    pub name: String,
    /// Vertex positions (metres).
    pub points: Vec<Vec3>,
    /// Unit normals: one per face (`uniform`), or one per vertex (`vertex`) when
    /// `normals_per_vertex`.
    pub normals: Vec<Vec3>,
    /// Whether `normals` has one per vertex (a smooth mesh) rather than one per face.
    pub normals_per_vertex: bool,
    /// Texture coordinates per vertex (`primvars:st`), or none.
    pub st: Vec<[f32; 2]>,
    /// Vertex indices, four per quad, counter-clockwise seen from outside.
    pub quads: Vec<[u32; 4]>,
    /// Vertex indices, three per triangle, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

impl UsdMesh {
    /// A baked UV mesh (object space: mm, z up) in the stage's space as the `.glb` has it
    /// (metres, y up: [`super::gltf::z_up_mm_to_gltf`]), st = (u, 1 − v).
    pub fn from_uv_mesh(mesh: &UvMesh, name: &str) -> UsdMesh {
        let to = super::gltf::z_up_mm_to_gltf();
        UsdMesh {
            name: name.into(),
            points: mesh
                .positions
                .iter()
                .map(|p| to.transform_point3(*p))
                .collect(),
            normals: (mesh.normals.iter())
                .map(|n| to.transform_vector3(*n).normalize_or_zero())
                .collect(),
            normals_per_vertex: true,
            st: mesh.uvs.iter().map(|uv| [uv.x, 1.0 - uv.y]).collect(),
            quads: Vec::new(),
            triangles: mesh.indices.clone(),
        }
    }

    /// Adds the quad with corner `o` and edges `u` (texture s) and `v` (the bake's v, down the
    /// image), facing v × u (as `gltf`'s faces); st = (s, 1 − v) when `textured`.
    fn quad(&mut self, o: Vec3, u: Vec3, v: Vec3, textured: bool) {
        let base = self.points.len() as u32;
        // Counter-clockwise seen from v × u: o → o + v → o + u + v → o + u.
        for (s, t) in [(0.0, 0.0), (0.0, 1.0), (1.0, 1.0), (1.0, 0.0)] {
            self.points.push(o + s * u + t * v);
            if textured {
                self.st.push([s, 1.0 - t]);
            }
        }
        self.normals.push(v.cross(u).normalize());
        self.quads.push([base, base + 1, base + 2, base + 3]);
    }
}

/// The board's top face (baked, textured) and its other five faces, in metres, as the `.glb`
/// lays them out.
pub fn board_meshes(board: &BoardCut) -> (UsdMesh, UsdMesh) {
    let [w, h, t] = board.size.map(|mm| mm / 1000.0);
    let (x0, y0, z0) = (-w / 2.0, -t / 2.0, -h / 2.0);
    let mut top = UsdMesh {
        name: "top".into(),
        ..Default::default()
    };
    top.quad(
        Vec3::new(x0, -y0, z0),
        Vec3::new(w, 0.0, 0.0),
        Vec3::new(0.0, 0.0, h),
        true,
    );
    let mut sides = UsdMesh {
        name: "sides".into(),
        ..Default::default()
    };
    for (o, u, v) in [
        ([x0, y0, -z0], [w, 0.0, 0.0], [0.0, 0.0, -h]), // bottom (−y)
        ([x0, -y0, -z0], [w, 0.0, 0.0], [0.0, -t, 0.0]), // front (+z)
        ([-x0, -y0, z0], [-w, 0.0, 0.0], [0.0, -t, 0.0]), // back (−z)
        ([-x0, -y0, -z0], [0.0, 0.0, -h], [0.0, -t, 0.0]), // right (+x)
        ([x0, -y0, z0], [0.0, 0.0, h], [0.0, -t, 0.0]), // left (−x)
    ] {
        sides.quad(Vec3::from(o), Vec3::from(u), Vec3::from(v), false);
    }
    (top, sides)
}

/// `v` as USD writes a tuple.
fn tuple(v: &[f32]) -> String {
    let parts: Vec<String> = v.iter().map(|x| format!("{x}")).collect();
    format!("({})", parts.join(", "))
}

fn list(items: impl Iterator<Item = String>) -> String {
    format!("[{}]", items.collect::<Vec<_>>().join(", "))
}

/// The mesh prim, bound to `material` (a prim path).
fn mesh_prim(x: &mut String, m: &UsdMesh, material: &str) {
    let _ = writeln!(
        x,
        "    def Mesh \"{}\" (\n        prepend apiSchemas = [\"MaterialBindingAPI\"]\n    )\n    {{",
        element_name(&m.name)
    );
    let counts = (m.quads.iter().map(|_| "4")).chain(m.triangles.iter().map(|_| "3"));
    let _ = writeln!(
        x,
        "        int[] faceVertexCounts = {}",
        list(counts.map(str::to_string))
    );
    let indices = (m.quads.iter().flatten()).chain(m.triangles.iter().flatten());
    let _ = writeln!(
        x,
        "        int[] faceVertexIndices = {}",
        list(indices.map(|i| i.to_string()))
    );
    let _ = writeln!(
        x,
        "        point3f[] points = {}",
        list(m.points.iter().map(|p| tuple(&p.to_array())))
    );
    let _ = writeln!(
        x,
        "        normal3f[] normals = {} (\n            interpolation = \"{}\"\n        )",
        list(m.normals.iter().map(|n| tuple(&n.to_array()))),
        if m.normals_per_vertex {
            "vertex"
        } else {
            "uniform"
        }
    );
    if !m.st.is_empty() {
        let _ = writeln!(
            x,
            "        texCoord2f[] primvars:st = {} (\n            interpolation = \"vertex\"\n        )",
            list(m.st.iter().map(|s| tuple(s)))
        );
    }
    let _ = writeln!(x, "        uniform token orientation = \"rightHanded\"");
    let _ = writeln!(x, "        uniform token subdivisionScheme = \"none\"");
    let _ = writeln!(x, "        rel material:binding = <{material}>");
    let _ = writeln!(x, "    }}");
}

/// The layer's header: `root` the default prim, y up, metres.
fn header(x: &mut String, root: &str, name: &str, mtlx_file: &str) {
    let _ = writeln!(
        x,
        "#usda 1.0\n(\n    defaultPrim = \"{root}\"\n    doc = \"xylem bake: preset {}; the baked surface's material is the OpenPBR MaterialX document {}\"\n    metersPerUnit = 1\n    upAxis = \"Y\"\n)\n",
        element_name(name),
        mtlx_file.replace(['"', '\\', '@'], "_")
    );
}

/// The Material prim `wood`, referencing `mtlx_file` (relative to the stage) at
/// `/MaterialX/Materials/M_<name>`.
fn wood_material(x: &mut String, name: &str, mtlx_file: &str) {
    let _ = writeln!(
        x,
        "        def Material \"wood\" (\n            prepend references = @./{}@</MaterialX/Materials/{}>\n        )\n        {{\n        }}\n",
        mtlx_file.replace(['"', '\\', '@'], "_"),
        material_name(name)
    );
}

/// The `.usda` text: `/Board` (the default prim) with the meshes of [`board_meshes`]; the top
/// face bound to `/Board/Materials/wood`, which references `mtlx_file` (relative to the stage)
/// at `/MaterialX/Materials/M_<name>`; the other faces bound to a `UsdPreviewSurface` of the
/// face's mean colour and the `.glb`'s roughness of the mean β, as the `.glb` draws them.
/// Deterministic.
pub fn usda_stage(board: &BoardCut, maps: &BakedMaps, name: &str, mtlx_file: &str) -> String {
    let (top, sides) = board_meshes(board);
    let n = maps.base_color.len().max(1) as f32;
    let mean = maps.base_color.iter().copied().sum::<Vec3>() / n;
    let mean_beta = maps.highlight_width.iter().sum::<f32>() / n;
    let mut x = String::new();
    header(&mut x, "Board", name, mtlx_file);
    let _ = writeln!(x, "def Xform \"Board\" (\n    kind = \"component\"\n)\n{{");
    mesh_prim(&mut x, &top, "/Board/Materials/wood");
    mesh_prim(&mut x, &sides, "/Board/Materials/unbaked_faces");
    let _ = writeln!(x, "\n    def Scope \"Materials\"\n    {{");
    wood_material(&mut x, name, mtlx_file);
    let _ = writeln!(
        x,
        "        def Material \"unbaked_faces\"\n        {{\n            token outputs:surface.connect = </Board/Materials/unbaked_faces/PreviewSurface.outputs:surface>\n\n            def Shader \"PreviewSurface\"\n            {{\n                uniform token info:id = \"UsdPreviewSurface\"\n                color3f inputs:diffuseColor = {}\n                float inputs:metallic = 0\n                float inputs:roughness = {}\n                token outputs:surface\n            }}\n        }}",
        tuple(&mean.to_array()),
        gltf_roughness(mean_beta)
    );
    let _ = writeln!(x, "    }}\n}}");
    x
}

/// The `.usda` text of a mesh bake: `/Object` (the default prim) with the mesh as `/Object/mesh`
/// ([`UsdMesh::from_uv_mesh`]) bound to `/Object/Materials/wood`, which references `mtlx_file`
/// as [`usda_stage`]'s does. Deterministic.
pub fn usda_mesh_stage(mesh: &UvMesh, name: &str, mtlx_file: &str) -> String {
    let mut x = String::new();
    header(&mut x, "Object", name, mtlx_file);
    let _ = writeln!(x, "def Xform \"Object\" (\n    kind = \"component\"\n)\n{{");
    mesh_prim(
        &mut x,
        &UsdMesh::from_uv_mesh(mesh, "mesh"),
        "/Object/Materials/wood",
    );
    let _ = writeln!(x, "\n    def Scope \"Materials\"\n    {{");
    wood_material(&mut x, name, mtlx_file);
    let _ = writeln!(x, "    }}\n}}");
    x
}

/// Stages `path` (`DIR/<name>.usda`) with [`usda_stage`], to commit with the other bake outputs.
pub fn stage_usda(
    path: &Path,
    board: &BoardCut,
    maps: &BakedMaps,
    name: &str,
    mtlx_file: &str,
) -> std::io::Result<Staged> {
    crate::output::stage_bytes(path, usda_stage(board, maps, name, mtlx_file).as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bake::BakeCut;

    #[test]
    fn faces_point_outwards_and_st_runs_up_the_image() {
        let board = BoardCut {
            size: [200.0, 80.0, 20.0],
            cut: BakeCut::Radial,
            radius: 150.0,
        };
        let (top, sides) = board_meshes(&board);
        assert_eq!(top.normals, vec![Vec3::Y]);
        for m in [&top, &sides] {
            for (q, n) in m.quads.iter().zip(&m.normals) {
                let p = q.map(|i| m.points[i as usize]);
                // Counter-clockwise seen from n, and n points away from the board's centre.
                assert!((p[1] - p[0]).cross(p[2] - p[1]).dot(*n) > 0.0);
                assert!(p[0].dot(*n) > 0.0);
            }
        }
        // +s along +x, +t along −z (the image's up, v down).
        let (s, t) = (top.st[3][0] - top.st[0][0], top.st[0][1] - top.st[1][1]);
        assert!(s > 0.0 && t > 0.0);
        assert!(top.points[3].x > top.points[0].x && top.points[0].z < top.points[1].z);
        let maps = crate::bake::BakedMaps {
            width: 1,
            height: 1,
            base_color: vec![Vec3::splat(0.25)],
            anisotropy: vec![Vec3::new(0.5, 1.0, 1.0)],
            highlight_width: vec![0.1],
            ray_mask: vec![0.0],
            normal: vec![Vec3::Z],
            fiber: vec![Vec3::X],
            ray: vec![Vec3::Y],
            fiber_color: vec![Vec3::ONE],
        };
        let a = usda_stage(&board, &maps, "walnut", "walnut.mtlx");
        assert_eq!(a, usda_stage(&board, &maps, "walnut", "walnut.mtlx"));
        assert!(a.contains("@./walnut.mtlx@</MaterialX/Materials/M_walnut>"));
    }
}
