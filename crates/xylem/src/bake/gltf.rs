//! A baked board as a glTF 2.0 binary (`.glb`): the board mesh with normals and tangents, and a
//! metallic-roughness material with base colour, normal map, roughness and
//! `KHR_materials_anisotropy`, for glTF viewers and engines. The document is built with the
//! `gltf-json` crate; the GLB container (glTF 2.0 §4.4: a 12-byte header, a JSON chunk and a
//! binary chunk, each 4-byte aligned) is written here, since that crate has none.
//!
//! How the fibre lobe becomes an anisotropic GGX lobe (the direction across the fibre, the
//! roughness from β) is derived in notes/gltf.md, with its measured error.
//!
//! Space: glTF's (y up, metres). The board's length runs along x, its width along z, its
//! thickness along y; the baked face is the top (+y), texture u along +x and v along +z, so the
//! tangent is +x and the bitangent (normal × tangent, w = +1) is −z: the image's up, as the bake's
//! tangent space has it.

use super::uv_mesh::UvMesh;
use super::{BakedMaps, BoardCut};
use crate::picture::png::{encode_png_rgb8, PngTag};
use crate::picture::srgb::to_srgb8;
use gltf_json as json;
use json::validation::{Checked::Valid, USize64};
use json::Index;
use std::path::Path;

/// The finish's refractive index the exported material assumes: glTF's default dielectric
/// (ior 1.5, F0 = 0.04; glTF 2.0 Appendix B.3.4).
pub(crate) const FINISH_IOR: f32 = 1.5;

/// GGX slope width α per unit of Gaussian slope deviation σ, matched at half maximum through the
/// peak: GGX's slope density along one axis through its peak, (1 + x²/α²)⁻², halves at
/// x = α √(√2 − 1), a Gaussian at x = σ √(2 ln 2), so α = σ √(2 ln 2) / √(√2 − 1) = 1.8295 σ.
const GGX_PER_SIGMA: f32 = 1.829_47;

/// The GGX α along the fibre that gives the fibre highlight's width β (radians, the Gaussian
/// deviation of ψi + ψr in Marschner et al. 2005 eq. 3): the exterior half-vector's slope along
/// the fibre is η (sin ψi + sin ψr)/2 near the normal (the finish scales tangential components by
/// η, Snell), deviation σ = η β / 2; α = 1.8295 σ (`GGX_PER_SIGMA`). Derivation: notes/gltf.md.
pub(crate) fn ggx_alpha_along_fiber(beta: f32) -> f32 {
    GGX_PER_SIGMA * FINISH_IOR * beta / 2.0
}

/// glTF's perceptual roughness for the fibre lobe of width `beta`: √α (glTF 2.0 Appendix B.3.2,
/// α = roughness²), clamped to [0, 1]. The extension's α_t = mix(α, 1, s²) acts across the fibre.
pub fn gltf_roughness(beta: f32) -> f32 {
    let a = ggx_alpha_along_fiber(beta);
    if a.is_finite() {
        a.max(0.0).sqrt().min(1.0)
    } else {
        1.0
    }
}

/// Errors while exporting a board to glTF, naming the file.
#[derive(Debug, thiserror::Error)]
pub enum GltfError {
    /// The file could not be written.
    #[error("cannot write glTF {path}: {source}")]
    Io {
        /// The `.glb` file.
        path: String,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A texture could not be PNG-encoded.
    #[error("cannot encode a texture of {path}: {source}")]
    Png {
        /// The `.glb` file.
        path: String,
        /// The encoder's error.
        source: png::EncodingError,
    },
    /// The glTF JSON could not be serialised.
    #[error("cannot serialise the glTF document of {path}: {source}")]
    Json {
        /// The `.glb` file.
        path: String,
        /// serde_json's error.
        source: serde_json::Error,
    },
    /// The maps and board do not fit together (map sizes, non-positive board size).
    #[error("glTF {path}: {message}")]
    Invalid {
        /// The `.glb` file.
        path: String,
        /// What does not fit.
        message: String,
    },
}

/// Writes `maps` (baked over `board`'s top face) as a `.glb` at `path`, whole or not at all
/// ([`stage_glb`], then renamed).
pub fn write_glb(
    path: &Path,
    board: &BoardCut,
    maps: &BakedMaps,
    sides: &BakedMaps,
    name: &str,
) -> Result<(), GltfError> {
    stage_glb(path, board, maps, sides, name)?
        .commit()
        .map_err(|source| GltfError::Io {
            path: path.display().to_string(),
            source,
        })
}

/// Encodes the `.glb` of [`write_glb`] into a temporary file beside `path`, to commit later.
pub fn stage_glb(
    path: &Path,
    board: &BoardCut,
    maps: &BakedMaps,
    sides: &BakedMaps,
    name: &str,
) -> Result<crate::output::Staged, GltfError> {
    let bytes = glb_bytes(board, maps, sides, name).map_err(|e| e.at(path))?;
    crate::output::stage_bytes(path, &bytes).map_err(|source| GltfError::Io {
        path: path.display().to_string(),
        source,
    })
}

impl GltfError {
    /// The same error naming `path`.
    fn at(self, path: &Path) -> Self {
        let p = path.display().to_string();
        match self {
            GltfError::Io { source, .. } => GltfError::Io { path: p, source },
            GltfError::Png { source, .. } => GltfError::Png { path: p, source },
            GltfError::Json { source, .. } => GltfError::Json { path: p, source },
            GltfError::Invalid { message, .. } => GltfError::Invalid { path: p, message },
        }
    }
}

/// The glTF primitive data of one set of faces (positions in metres).
#[derive(Default)]
struct Faces {
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    tangents: Vec<[f32; 4]>,
    uvs: Vec<[f32; 2]>,
    indices: Vec<u32>,
}

impl Faces {
    /// Adds the quad with corner `o` and edges `u`, `v` (texture u along `u`, v along `v`),
    /// facing n = v × u (counter-clockwise seen from outside, glTF 2.0 §3.7.2.1), tangent `u`.
    fn quad(&mut self, o: [f32; 3], u: [f32; 3], v: [f32; 3]) {
        let (o, u, v) = (
            glam::Vec3::from(o),
            glam::Vec3::from(u),
            glam::Vec3::from(v),
        );
        let n = v.cross(u).normalize();
        let base = self.positions.len() as u32;
        for (s, t) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
            self.positions.push((o + s * u + t * v).to_array());
            self.normals.push(n.to_array());
            let tu = u.normalize();
            // w: bitangent = w (n × t) must be −v (texture v runs down the image).
            let w = if n.cross(tu).dot(v) < 0.0 { 1.0 } else { -1.0 };
            self.tangents.push([tu.x, tu.y, tu.z, w]);
            self.uvs.push([s, t]);
        }
        // Counter-clockwise seen from +n: (0, 0) → (0, 1) → (1, 1) with n = v × u.
        self.indices
            .extend([0, 3, 2, 0, 2, 1].map(|i: u32| base + i));
    }

    /// A UV mesh's vertices (mm) carried into glTF space (metres) by `to_gltf`, a rotation and
    /// uniform scale, with its tangents ([`UvMesh::tangents`]).
    fn mesh(mesh: &UvMesh, to_gltf: glam::Affine3A) -> Faces {
        let rot = glam::Mat3::from(to_gltf.matrix3);
        let tangents = mesh.tangents();
        Faces {
            positions: (mesh.positions.iter())
                .map(|p| to_gltf.transform_point3(*p).to_array())
                .collect(),
            normals: (mesh.normals.iter())
                .map(|n| unit_or(rot * *n, glam::Vec3::Y).to_array())
                .collect(),
            tangents: (tangents.iter())
                .map(|t| {
                    let d = unit_or(rot * t.truncate(), glam::Vec3::X);
                    [d.x, d.y, d.z, t.w]
                })
                .collect(),
            uvs: mesh.uvs.iter().map(|t| t.to_array()).collect(),
            indices: mesh.indices.iter().flatten().copied().collect(),
        }
    }
}

/// `v` normalised, or `fallback` where it has no direction (glTF requires unit normals).
fn unit_or(v: glam::Vec3, fallback: glam::Vec3) -> glam::Vec3 {
    v.try_normalize().unwrap_or(fallback)
}

/// The board's top face (the flat bake's maps), in metres.
fn board_top(board: &BoardCut) -> Faces {
    let [w, h, t] = board.size.map(|mm| mm / 1000.0);
    let mut top = Faces::default();
    top.quad([-w / 2.0, t / 2.0, -h / 2.0], [w, 0.0, 0.0], [0.0, 0.0, h]);
    top
}

/// The binary chunk being filled and the document's views into it.
struct Bin<'a> {
    root: &'a mut json::Root,
    bytes: Vec<u8>,
}

impl Bin<'_> {
    /// Appends `data` (4-byte aligned, glTF 2.0 §3.6.2.4) as a buffer view.
    fn view(
        &mut self,
        data: &[u8],
        target: Option<json::buffer::Target>,
    ) -> Index<json::buffer::View> {
        while !self.bytes.len().is_multiple_of(4) {
            self.bytes.push(0);
        }
        let offset = self.bytes.len();
        self.bytes.extend_from_slice(data);
        self.root.push(json::buffer::View {
            buffer: Index::new(0),
            byte_length: USize64::from(data.len()),
            byte_offset: Some(USize64::from(offset)),
            byte_stride: None,
            name: None,
            target: target.map(Valid),
            extensions: None,
            extras: Default::default(),
        })
    }

    /// An accessor of `n`-component f32 vectors (with min and max where glTF requires them).
    fn floats<const N: usize>(
        &mut self,
        v: &[[f32; N]],
        type_: json::accessor::Type,
        bounds: bool,
    ) -> Index<json::Accessor> {
        let bytes: Vec<u8> = v.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes, Some(json::buffer::Target::ArrayBuffer));
        let (min, max) = if bounds {
            let lo = (0..N).map(|k| v.iter().map(|p| p[k]).fold(f32::MAX, f32::min));
            let hi = (0..N).map(|k| v.iter().map(|p| p[k]).fold(f32::MIN, f32::max));
            (
                Some(json::Value::from(lo.collect::<Vec<_>>())),
                Some(json::Value::from(hi.collect::<Vec<_>>())),
            )
        } else {
            (None, None)
        };
        self.accessor(
            view,
            v.len(),
            json::accessor::ComponentType::F32,
            type_,
            min,
            max,
        )
    }

    fn accessor(
        &mut self,
        view: Index<json::buffer::View>,
        count: usize,
        component: json::accessor::ComponentType,
        type_: json::accessor::Type,
        min: Option<json::Value>,
        max: Option<json::Value>,
    ) -> Index<json::Accessor> {
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64::from(count),
            component_type: Valid(json::accessor::GenericComponentType(component)),
            extensions: None,
            extras: Default::default(),
            type_: Valid(type_),
            min,
            max,
            name: None,
            normalized: false,
            sparse: None,
        })
    }

    /// A primitive of `faces` drawn with `material`; tangents and texture coordinates only
    /// where the material is `textured` (the validator reports unused ones).
    fn primitive(
        &mut self,
        faces: &Faces,
        material: Index<json::Material>,
        textured: bool,
    ) -> json::mesh::Primitive {
        use json::accessor::Type;
        use json::mesh::Semantic;
        let mut attributes = vec![
            (
                Semantic::Positions,
                self.floats(&faces.positions, Type::Vec3, true),
            ),
            (
                Semantic::Normals,
                self.floats(&faces.normals, Type::Vec3, false),
            ),
        ];
        if textured {
            attributes.push((
                Semantic::Tangents,
                self.floats(&faces.tangents, Type::Vec4, false),
            ));
            attributes.push((
                Semantic::TexCoords(0),
                self.floats(&faces.uvs, Type::Vec2, false),
            ));
        }
        // 16-bit indices where they fit, else 32-bit (glTF 2.0 §3.7.2.1 allows both).
        let small = faces.positions.len() <= usize::from(u16::MAX);
        let idx: Vec<u8> = if small {
            (faces.indices.iter())
                .flat_map(|&i| (i as u16).to_le_bytes())
                .collect()
        } else {
            faces.indices.iter().flat_map(|i| i.to_le_bytes()).collect()
        };
        let view = self.view(&idx, Some(json::buffer::Target::ElementArrayBuffer));
        let indices = self.accessor(
            view,
            faces.indices.len(),
            if small {
                json::accessor::ComponentType::U16
            } else {
                json::accessor::ComponentType::U32
            },
            Type::Scalar,
            None,
            None,
        );
        json::mesh::Primitive {
            attributes: attributes.into_iter().map(|(s, a)| (Valid(s), a)).collect(),
            extensions: None,
            extras: Default::default(),
            indices: Some(indices),
            material: Some(material),
            mode: Valid(json::mesh::Mode::Triangles),
            targets: None,
        }
    }

    /// A PNG texture (sampled with the document's one sampler).
    fn texture(&mut self, name: &str, png: &[u8]) -> json::texture::Info {
        let view = self.view(png, None);
        let image = self.root.push(json::Image {
            buffer_view: Some(view),
            mime_type: Some(json::image::MimeType("image/png".into())),
            name: Some(name.into()),
            uri: None,
            extensions: None,
            extras: Default::default(),
        });
        let texture = self.root.push(json::Texture {
            name: Some(name.into()),
            sampler: Some(Index::new(0)),
            source: image,
            extensions: None,
            extras: Default::default(),
        });
        json::texture::Info {
            index: texture,
            tex_coord: 0,
            extensions: None,
            extras: Default::default(),
        }
    }
}

/// The PNG bytes of 8-bit RGB codes, untagged (glTF says how to read them: base colour as
/// sRGB, every other map as linear; §3.9.6).
fn png(w: u32, h: u32, rgb: &[u8]) -> Result<Vec<u8>, GltfError> {
    let mut out = Vec::new();
    encode_png_rgb8(&mut out, w, h, rgb, PngTag::Untagged).map_err(|source| GltfError::Png {
        path: String::new(),
        source,
    })?;
    Ok(out)
}

/// The `.glb` bytes of a board: its top face with the flat bake's `maps` and its other five
/// faces with `sides`, the bake of their atlas ([`BoardCut::side_atlas`]).
pub fn glb_bytes(
    board: &BoardCut,
    maps: &BakedMaps,
    sides: &BakedMaps,
    name: &str,
) -> Result<Vec<u8>, GltfError> {
    if board.size.iter().any(|s| !(s.is_finite() && *s > 0.0)) {
        return Err(GltfError::Invalid {
            path: String::new(),
            message: format!("board {:?} mm: allowed sizes above 0", board.size),
        });
    }
    let (atlas, _) = board.side_atlas();
    document(
        name,
        &[
            (board_top(board), maps, "baked face", ""),
            (
                Faces::mesh(&atlas, glam::Affine3A::IDENTITY),
                sides,
                "sides",
                "sides_",
            ),
        ],
    )
}

/// The `.glb` bytes of `mesh` (object space, mm, z up as xylem's scenes have it) baked into
/// `maps`: turned into glTF's space (metres, y up: (x, y, z) mm → (x, z, −y) / 1000).
pub fn mesh_glb_bytes(mesh: &UvMesh, maps: &BakedMaps, name: &str) -> Result<Vec<u8>, GltfError> {
    let faces = Faces::mesh(mesh, z_up_mm_to_gltf());
    document(name, &[(faces, maps, "baked", "")])
}

/// xylem's object space (mm, z up) → glTF's (metres, y up): a rotation of −90° about x and a
/// scale of 1/1000.
pub fn z_up_mm_to_gltf() -> glam::Affine3A {
    glam::Affine3A::from_mat3(glam::Mat3::from_cols(
        glam::Vec3::new(1e-3, 0.0, 0.0),
        glam::Vec3::new(0.0, 0.0, -1e-3),
        glam::Vec3::new(0.0, 1e-3, 0.0),
    ))
}

/// Writes the `.glb` of a mesh bake at `path` as a staged file ([`mesh_glb_bytes`]).
pub fn stage_mesh_glb(
    path: &Path,
    mesh: &UvMesh,
    maps: &BakedMaps,
    name: &str,
) -> Result<crate::output::Staged, GltfError> {
    let bytes = mesh_glb_bytes(mesh, maps, name).map_err(|e| e.at(path))?;
    crate::output::stage_bytes(path, &bytes).map_err(|source| GltfError::Io {
        path: path.display().to_string(),
        source,
    })
}

/// The material of `maps` (base colour, normal map, metallic-roughness, anisotropy), its images
/// named with `prefix`.
fn material(
    bin: &mut Bin<'_>,
    maps: &BakedMaps,
    label: String,
    prefix: &str,
) -> Result<Index<json::Material>, GltfError> {
    let (w, h) = (maps.width, maps.height);
    let n = w as usize * h as usize;
    let sizes = [
        maps.base_color.len(),
        maps.anisotropy.len(),
        maps.normal.len(),
        maps.highlight_width.len(),
    ];
    if sizes.iter().any(|&s| s != n) || n == 0 {
        return Err(GltfError::Invalid {
            path: String::new(),
            message: format!("maps of {w}x{h} texels hold {sizes:?} values"),
        });
    }
    let codes = super::textures(maps);
    let mut tex = |name: &str, rgb: &[u8]| -> Result<json::texture::Info, GltfError> {
        Ok(bin.texture(&format!("{prefix}{name}"), &png(w, h, rgb)?))
    };
    let base = tex("base_color", &to_srgb8(&maps.base_color, 0.0))?;
    let normal = tex("normal", &codes.normal)?;
    let rough = tex("metallic_roughness", &codes.metallic_roughness)?;
    let aniso = tex("anisotropy", &codes.anisotropy)?;
    Ok(bin.root.push(json::Material {
        name: Some(label),
        pbr_metallic_roughness: json::material::PbrMetallicRoughness {
            base_color_texture: Some(base),
            metallic_factor: json::material::StrengthFactor(0.0),
            roughness_factor: json::material::StrengthFactor(1.0),
            metallic_roughness_texture: Some(rough),
            ..Default::default()
        },
        normal_texture: Some(json::material::NormalTexture {
            index: normal.index,
            scale: 1.0,
            tex_coord: 0,
            extensions: None,
            extras: Default::default(),
        }),
        extensions: Some(json::extensions::material::Material {
            others: [(
                "KHR_materials_anisotropy".to_string(),
                serde_json::json!({
                    "anisotropyStrength": 1.0,
                    "anisotropyRotation": 0.0,
                    "anisotropyTexture": { "index": aniso.index.value(), "texCoord": 0 },
                }),
            )]
            .into_iter()
            .collect(),
        }),
        ..Default::default()
    }))
}

/// One mesh of textured primitives: (faces, maps, material label, image name prefix) each.
fn document(name: &str, parts: &[(Faces, &BakedMaps, &str, &str)]) -> Result<Vec<u8>, GltfError> {
    let mut root = json::Root {
        asset: json::Asset {
            copyright: None,
            extensions: None,
            extras: Default::default(),
            generator: Some(format!("xylem {}", env!("CARGO_PKG_VERSION"))),
            min_version: None,
            version: "2.0".into(),
        },
        ..Default::default()
    };
    root.push(json::texture::Sampler {
        mag_filter: Some(Valid(json::texture::MagFilter::Linear)),
        min_filter: Some(Valid(json::texture::MinFilter::LinearMipmapLinear)),
        ..Default::default()
    });
    let mut bin = Bin {
        root: &mut root,
        bytes: Vec::new(),
    };
    let mut primitives = Vec::new();
    for (faces, maps, label, prefix) in parts {
        let m = material(&mut bin, maps, format!("{name} ({label})"), prefix)?;
        primitives.push(bin.primitive(faces, m, true));
    }
    let mut bytes = std::mem::take(&mut bin.bytes);
    while !bytes.len().is_multiple_of(4) {
        bytes.push(0);
    }
    let mesh = root.push(json::Mesh {
        extensions: None,
        extras: Default::default(),
        name: Some(name.into()),
        primitives,
        weights: None,
    });
    let node = root.push(json::Node {
        mesh: Some(mesh),
        name: Some(name.into()),
        ..Default::default()
    });
    root.scenes.push(json::Scene {
        extensions: None,
        extras: Default::default(),
        name: Some(name.into()),
        nodes: vec![node],
    });
    root.scene = Some(Index::new(0));
    root.buffers.push(json::Buffer {
        byte_length: USize64::from(bytes.len()),
        name: None,
        uri: None,
        extensions: None,
        extras: Default::default(),
    });
    root.extensions_used.push("KHR_materials_anisotropy".into());
    let json = root.to_vec().map_err(|source| GltfError::Json {
        path: String::new(),
        source,
    })?;
    Ok(glb(json, bytes))
}

/// The GLB container (glTF 2.0 §4.4): header (magic `glTF`, version 2, total length), then the
/// JSON chunk padded with spaces and the BIN chunk padded with zeros, each to 4 bytes.
fn glb(mut json: Vec<u8>, mut bin: Vec<u8>) -> Vec<u8> {
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    for word in [0x4654_6C67, 2, total as u32, json.len() as u32, 0x4E4F_534A] {
        out.extend_from_slice(&u32::to_le_bytes(word));
    }
    out.extend_from_slice(&json);
    for word in [bin.len() as u32, 0x004E_4942] {
        out.extend_from_slice(&u32::to_le_bytes(word));
    }
    out.extend_from_slice(&bin);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roughness_matches_the_fibre_lobe_at_half_maximum() {
        // Independent check of the constant: the two densities' half-maximum points.
        let sigma = 0.1f32;
        let alpha = GGX_PER_SIGMA * sigma;
        let x = sigma * (2.0 * 2f32.ln()).sqrt();
        let ggx = (1.0 + x * x / (alpha * alpha)).powi(-2);
        assert!((ggx - 0.5).abs() < 1e-4, "{ggx}");
        // β = 8°: α = 1.8295 · 1.5 · 0.1396 / 2 = 0.1916, roughness 0.4377.
        assert!((gltf_roughness(8f32.to_radians()) - 0.4377).abs() < 1e-3);
        assert_eq!(gltf_roughness(f32::NAN), 1.0);
        assert_eq!(gltf_roughness(10.0), 1.0);
        assert_eq!(gltf_roughness(0.0), 0.0);
    }

    #[test]
    fn faces_are_wound_outward_with_the_tangent_space_of_the_bake() {
        let board = BoardCut {
            size: [300.0, 100.0, 20.0],
            cut: super::super::BakeCut::Radial,
            radius: 100.0,
        };
        let top = board_top(&board);
        let sides = Faces::mesh(&board.side_atlas().0, glam::Affine3A::IDENTITY);
        for f in [&top, &sides] {
            for tri in f.indices.chunks(3) {
                let p = [tri[0], tri[1], tri[2]].map(|i| glam::Vec3::from(f.positions[i as usize]));
                let n = glam::Vec3::from(f.normals[tri[0] as usize]);
                // Counter-clockwise seen from outside, and the normal points away from the centre.
                assert!((p[1] - p[0]).cross(p[2] - p[0]).dot(n) > 0.0);
                assert!(p[0].dot(n) > 0.0);
            }
        }
        // Top: normal +y, tangent +x along u, bitangent = w (n × t) = −z, the image's up (−v).
        assert_eq!(top.normals[0], [0.0, 1.0, 0.0]);
        assert_eq!(top.tangents[0], [1.0, 0.0, 0.0, 1.0]);
        assert_eq!(top.positions[0], [-0.15, 0.01, -0.05]);
        assert_eq!(
            (top.uvs[2], top.positions[2]),
            ([1.0, 1.0], [0.15, 0.01, 0.05])
        );
    }

    #[test]
    fn glb_container_has_aligned_chunks() {
        let g = glb(b"{}".to_vec(), vec![1, 2, 3, 4, 5]);
        assert_eq!(&g[0..4], b"glTF");
        let word = |i: usize| u32::from_le_bytes(g[i..i + 4].try_into().unwrap());
        assert_eq!((word(4), word(8) as usize), (2, g.len()));
        assert_eq!(
            (word(12), &g[16..20], &g[20..24]),
            (4, &b"JSON"[..], &b"{}  "[..])
        );
        assert_eq!((word(24), &g[28..32]), (8, &b"BIN\0"[..]));
        assert_eq!(&g[32..], &[1, 2, 3, 4, 5, 0, 0, 0]);
    }
}
