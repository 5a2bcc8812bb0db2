//! Mesh files: Wavefront OBJ (through `tobj`) and PLY (ASCII and binary, read here: vertex
//! `x y z` with optional `nx ny nz`, faces as `vertex_indices` / `vertex_index` lists, polygons
//! fanned into triangles).

use crate::render::TriMesh;
use glam::Vec3;
use std::io::{BufRead, BufReader, Read};
use std::path::Path;

/// A mesh file that could not be read, naming the file and what is wrong.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// The file is unreadable, malformed or holds no usable triangles.
    #[error("mesh {path}: {message}")]
    Bad {
        /// The mesh file.
        path: String,
        /// What is wrong with it.
        message: String,
    },
    /// The file is neither `.obj` nor `.ply`.
    #[error("mesh {path}: unsupported extension (allowed: .obj, .ply)")]
    Extension {
        /// The mesh file.
        path: String,
    },
}

fn bad(path: &Path, message: impl Into<String>) -> MeshError {
    MeshError::Bad {
        path: path.display().to_string(),
        message: message.into(),
    }
}

/// Loads an OBJ or PLY file by extension (a regular file of at most
/// [`MAX_MESH_BYTES`](crate::resources::MAX_MESH_BYTES); a FIFO or `/dev/zero` is
/// refused), or the embedded copy of a built-in scene's mesh where the disk has none
/// (`crate::builtin`).
pub fn load_mesh(path: &Path) -> Result<TriMesh, MeshError> {
    load_mesh_uv(path).map(|(m, _)| m)
}

/// [`load_mesh`], and the texture coordinates of every vertex where the file gives every face
/// corner one (an OBJ's `vt`; glTF's orientation: v = 1 − the OBJ's v, so v runs down the
/// image). `None` for a PLY, or an OBJ with a face corner without `vt`.
pub(crate) fn load_mesh_uv(path: &Path) -> Result<(TriMesh, Option<Vec<glam::Vec2>>), MeshError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    if !matches!(ext.as_deref(), Some("obj" | "ply")) {
        return Err(MeshError::Extension {
            path: path.display().to_string(),
        });
    }
    let mut input: Box<dyn BufRead> = match crate::builtin::stand_in(path) {
        Some((_, bytes)) => Box::new(bytes),
        None => Box::new(BufReader::new(open_mesh(
            path,
            ext.as_deref() == Some("obj"),
        )?)),
    };
    let (mesh, uvs) = if ext.as_deref() == Some("obj") {
        parse_obj(&mut input, path)?
    } else {
        (parse_ply(input).map_err(|m| bad(path, m))?, None)
    };
    check_finite(path, &mesh)?;
    Ok((mesh, uvs))
}

/// Peak memory of reading an OBJ, per byte of the file: tobj's positions, its per-corner index
/// map (`single_index`) and our copy. Measured (`mesh_parse_peak obj`, notes/limits.md): a
/// 1026² grid (85 MB, 2.1 M triangles, every vector just past a doubling) raised the peak
/// address space 7.3× its size (resident 4.3×); 16 leaves room for other layouts.
pub(crate) const OBJ_PARSE_BYTES_PER_BYTE: u64 = 16;
/// The same for a PLY, whose parse holds only the mesh: a binary vertex of 12 (24 with normals)
/// bytes becomes 12 (24), a 13-byte triangle 12 bytes of indices, a 17-byte quad 24. Measured
/// (`mesh_parse_peak ply-*`, notes/limits.md) on the 1026² grid: peak address space 1.9× the
/// file (binary triangles), 2.3× (binary quads), 1.1× (ASCII); resident 0.6–1.2×. 4 covers
/// binary faces of up to six corners at the vectors' worst doubling; a PLY of larger
/// polygons or byte-sized indices that needs more ends in the `xylem` binary's clean
/// out-of-memory error.
pub(crate) const PLY_PARSE_BYTES_PER_BYTE: u64 = 4;

/// Refuses, before reading, a mesh file whose parse would need more memory than is available
/// (a 4 GiB OBJ needs about 64 GiB); the BVH's own estimate comes after
/// ([`crate::render::resources::Resources::geometry`]).
fn check_parse_memory(path: &Path, bytes: u64, obj: bool) -> Result<(), MeshError> {
    use crate::resources::{available_memory, Bytes};
    let per = if obj {
        OBJ_PARSE_BYTES_PER_BYTE
    } else {
        PLY_PARSE_BYTES_PER_BYTE
    };
    let need = bytes.saturating_mul(per);
    match available_memory() {
        Some(have) if need > have => Err(bad(
            path,
            format!(
                "{} of {} needs about {} of memory to read ({per} bytes per file byte) but {} is available",
                Bytes(bytes),
                if obj { "OBJ" } else { "PLY" },
                Bytes(need),
                Bytes(have)
            ),
        )),
        _ => Ok(()),
    }
}

/// Refuses a mesh with a NaN or infinite vertex or normal (a coordinate beyond f32's range
/// reads as infinite), naming it, so the error is the file's and not the transform's.
fn check_finite(path: &Path, mesh: &TriMesh) -> Result<(), MeshError> {
    let first_bad = |v: &[Vec3]| v.iter().position(|p| !p.is_finite());
    if let Some(i) = first_bad(&mesh.positions) {
        let p = mesh.positions[i];
        return Err(bad(
            path,
            format!(
                "vertex {} of {} is ({}, {}, {}) (allowed: finite coordinates within ±3.4e38)",
                i + 1,
                mesh.positions.len(),
                p.x,
                p.y,
                p.z
            ),
        ));
    }
    if let Some(normals) = &mesh.normals {
        if let Some(i) = first_bad(normals) {
            let n = normals[i];
            return Err(bad(
                path,
                format!(
                    "normal {} of {} is ({}, {}, {}) (allowed: finite)",
                    i + 1,
                    normals.len(),
                    n.x,
                    n.y,
                    n.z
                ),
            ));
        }
    }
    Ok(())
}

/// Opens a mesh file: a regular file of at most
/// [`MAX_MESH_BYTES`](crate::resources::MAX_MESH_BYTES), read no further than that,
/// whose parse fits the memory available ([`check_parse_memory`]).
fn open_mesh(path: &Path, obj: bool) -> Result<std::io::Take<std::fs::File>, MeshError> {
    use crate::resources::{open_regular, MAX_MESH_BYTES};
    let file = open_regular(path, MAX_MESH_BYTES).map_err(|e| bad(path, e.reason()))?;
    let bytes = file.metadata().map_or(0, |m| m.len());
    check_parse_memory(path, bytes, obj)?;
    Ok(file.take(MAX_MESH_BYTES))
}

/// Reads an OBJ mesh (a regular file within the mesh size limit, as [`load_mesh`] reads).
pub fn load_obj(path: &Path) -> Result<TriMesh, MeshError> {
    let file = open_mesh(path, true)?;
    parse_obj(&mut BufReader::new(file), path).map(|(m, _)| m)
}

/// All models of an OBJ stream merged into one mesh (normals kept when every model has them);
/// `mtllib` lines are not followed (xylem's materials come from the scene file).
/// With the texture coordinates when every model has one per vertex (v flipped to run down).
fn parse_obj(
    input: &mut dyn BufRead,
    path: &Path,
) -> Result<(TriMesh, Option<Vec<glam::Vec2>>), MeshError> {
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, _) = tobj::load_obj_buf(&mut &mut *input, &opts, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| bad(path, e.to_string()))?;
    let mut out = TriMesh::default();
    let mut uvs = Some(Vec::new());
    for m in models {
        let mesh = &m.mesh;
        if mesh.positions.len() % 3 != 0 || mesh.indices.len() % 3 != 0 {
            return Err(bad(path, format!("model `{}` is malformed", m.name)));
        }
        let v3 = |f: &[f32]| {
            f.chunks_exact(3)
                .map(|c| Vec3::new(c[0], c[1], c[2]))
                .collect::<Vec<_>>()
        };
        let positions = v3(&mesh.positions);
        uvs = uvs.filter(|_| mesh.texcoords.len() / 2 == positions.len());
        if let Some(uv) = &mut uvs {
            let t = mesh.texcoords.chunks_exact(2);
            uv.extend(t.map(|c| glam::Vec2::new(c[0], 1.0 - c[1])));
        }
        let normals = (mesh.normals.len() == mesh.positions.len()).then(|| v3(&mesh.normals));
        let part = TriMesh {
            positions,
            normals,
            indices: mesh
                .indices
                .chunks_exact(3)
                .map(|c| [c[0], c[1], c[2]])
                .collect(),
        };
        out.append(&part);
    }
    if out.indices.is_empty() {
        return Err(bad(path, "no triangles"));
    }
    Ok((out, uvs))
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Format {
    Ascii,
    BinaryLe,
    BinaryBe,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(s: &str) -> Option<Scalar> {
        Some(match s {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
}

#[derive(Clone, Debug)]
struct Property {
    name: String,
    /// `Some(count type)` for list properties.
    list: Option<Scalar>,
    ty: Scalar,
}

#[derive(Clone, Debug)]
struct Element {
    name: String,
    count: usize,
    props: Vec<Property>,
}

/// Reads values one at a time from the body of a PLY file.
struct Body<R: BufRead> {
    r: R,
    format: Format,
    tokens: std::vec::IntoIter<String>,
}

impl<R: BufRead> Body<R> {
    fn value(&mut self, ty: Scalar) -> Result<f64, String> {
        match self.format {
            Format::Ascii => loop {
                if let Some(t) = self.tokens.next() {
                    return t.parse::<f64>().map_err(|_| format!("bad number `{t}`"));
                }
                let mut line = String::new();
                if self.r.read_line(&mut line).map_err(|e| e.to_string())? == 0 {
                    return Err("file ends early".into());
                }
                self.tokens = line
                    .split_whitespace()
                    .map(str::to_string)
                    .collect::<Vec<_>>()
                    .into_iter();
            },
            Format::BinaryLe | Format::BinaryBe => {
                let mut b = [0u8; 8];
                let n = ty.size();
                self.r
                    .read_exact(&mut b[..n])
                    .map_err(|_| "file ends early".to_string())?;
                if self.format == Format::BinaryBe {
                    b[..n].reverse();
                }
                Ok(match ty {
                    Scalar::I8 => b[0] as i8 as f64,
                    Scalar::U8 => b[0] as f64,
                    Scalar::I16 => i16::from_le_bytes([b[0], b[1]]) as f64,
                    Scalar::U16 => u16::from_le_bytes([b[0], b[1]]) as f64,
                    Scalar::I32 => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                    Scalar::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                    Scalar::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                    Scalar::F64 => f64::from_le_bytes(b),
                })
            }
        }
    }
}

/// Reads a PLY mesh (checked as [`load_obj`]).
#[cfg(test)]
pub(crate) fn load_ply(path: &Path) -> Result<TriMesh, MeshError> {
    let file = open_mesh(path, false)?;
    parse_ply(BufReader::new(file)).map_err(|m| bad(path, m))
}

/// The header of a PLY file: its body format and its elements with their properties.
fn read_ply_header<R: BufRead>(r: &mut R) -> Result<(Format, Vec<Element>), String> {
    let mut line = String::new();
    let read_line = |r: &mut R, line: &mut String| -> Result<(), String> {
        line.clear();
        if r.read_line(line).map_err(|e| e.to_string())? == 0 {
            return Err("header ends early (no end_header)".into());
        }
        Ok(())
    };
    read_line(r, &mut line)?;
    if line.trim() != "ply" {
        return Err("not a PLY file (first line is not `ply`)".into());
    }
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        read_line(r, &mut line)?;
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["end_header"] => break,
            ["format", f, _] => {
                format = Some(match *f {
                    "ascii" => Format::Ascii,
                    "binary_little_endian" => Format::BinaryLe,
                    "binary_big_endian" => Format::BinaryBe,
                    _ => return Err(format!("unknown format `{f}`")),
                })
            }
            ["element", name, count] => elements.push(Element {
                name: name.to_string(),
                count: count
                    .parse()
                    .map_err(|_| format!("bad element count `{count}`"))?,
                props: Vec::new(),
            }),
            ["property", "list", ct, ty, name] => {
                let e = elements.last_mut().ok_or("property before any element")?;
                e.props.push(Property {
                    name: name.to_string(),
                    list: Some(Scalar::parse(ct).ok_or(format!("unknown type `{ct}`"))?),
                    ty: Scalar::parse(ty).ok_or(format!("unknown type `{ty}`"))?,
                });
            }
            ["property", ty, name] => {
                let e = elements.last_mut().ok_or("property before any element")?;
                e.props.push(Property {
                    name: name.to_string(),
                    list: None,
                    ty: Scalar::parse(ty).ok_or(format!("unknown type `{ty}`"))?,
                });
            }
            ["comment", ..] | ["obj_info", ..] | [] => {}
            _ => return Err(format!("unexpected header line `{}`", line.trim())),
        }
    }
    Ok((format.ok_or("no format line")?, elements))
}

fn parse_ply<R: BufRead>(mut r: R) -> Result<TriMesh, String> {
    let (format, elements) = read_ply_header(&mut r)?;
    let mut body = Body {
        r,
        format,
        tokens: Vec::new().into_iter(),
    };
    let mut mesh = TriMesh::default();
    let mut normals = Vec::new();
    for e in &elements {
        let idx = |n: &str| e.props.iter().position(|p| p.name == n);
        let (px, py, pz) = (idx("x"), idx("y"), idx("z"));
        let (nx, ny, nz) = (idx("nx"), idx("ny"), idx("nz"));
        let face_prop = idx("vertex_indices").or(idx("vertex_index"));
        if e.name == "vertex" && (px.is_none() || py.is_none() || pz.is_none()) {
            return Err("vertex element lacks x, y or z".into());
        }
        let mut vals = vec![0.0f64; e.props.len()];
        let mut list: Vec<u32> = Vec::new();
        for _ in 0..e.count {
            for (k, p) in e.props.iter().enumerate() {
                match p.list {
                    None => vals[k] = body.value(p.ty)?,
                    Some(ct) => {
                        let n = body.value(ct)?;
                        if !(0.0..=1e6).contains(&n) {
                            return Err(format!("bad list length {n}"));
                        }
                        let is_face = e.name == "face" && Some(k) == face_prop;
                        if is_face {
                            list.clear();
                        }
                        for _ in 0..n as usize {
                            let v = body.value(p.ty)?;
                            if is_face {
                                if v < 0.0 {
                                    return Err(format!("negative vertex index {v}"));
                                }
                                list.push(v as u32);
                            }
                        }
                    }
                }
            }
            if e.name == "vertex" {
                let g = |i: Option<usize>| vals[i.unwrap()] as f32;
                mesh.positions.push(Vec3::new(g(px), g(py), g(pz)));
                if let (Some(_), Some(_), Some(_)) = (nx, ny, nz) {
                    normals.push(Vec3::new(g(nx), g(ny), g(nz)));
                }
            } else if e.name == "face" {
                if face_prop.is_none() {
                    return Err("face element lacks vertex_indices".into());
                }
                for i in 1..list.len().saturating_sub(1) {
                    mesh.indices.push([list[0], list[i], list[i + 1]]);
                }
            }
        }
    }
    if !normals.is_empty() && normals.len() == mesh.positions.len() {
        mesh.normals = Some(normals);
    }
    if mesh.indices.is_empty() {
        return Err("no faces".into());
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mesh_files_read_directly_are_bounded_like_scene_meshes() {
        for e in [
            load_obj(Path::new("/dev/zero")).unwrap_err(),
            load_ply(Path::new("/dev/zero")).unwrap_err(),
        ] {
            assert!(e.to_string().contains("not a regular file"), "{e}");
        }
    }

    #[test]
    fn ascii_and_binary_ply_agree() {
        let ascii = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
        let a = parse_ply(ascii.as_bytes()).unwrap();
        assert_eq!(a.indices, vec![[0, 1, 2], [0, 2, 3]]);
        let mut bin = b"ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n".to_vec();
        for p in &a.positions {
            for c in p.to_array() {
                bin.extend_from_slice(&c.to_le_bytes());
            }
        }
        bin.push(4);
        for i in [0i32, 1, 2, 3] {
            bin.extend_from_slice(&i.to_le_bytes());
        }
        let b = parse_ply(&bin[..]).unwrap();
        assert_eq!(a.positions, b.positions);
        assert_eq!(a.indices, b.indices);
        assert!(parse_ply(&bin[..bin.len() - 2]).is_err());
        assert!(
            parse_ply("ply\nformat ascii 1.0\nelement vertex 1\nend_header\n".as_bytes()).is_err()
        );
    }
}
