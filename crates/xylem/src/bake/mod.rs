//! Baking a wood preset into texture maps for other tools (`xylem bake`): base colour, fibre
//! direction as a glTF `KHR_materials_anisotropy` map, highlight width, ray mask, a normal map
//! from the pore bump and a signed tangent-space fibre-direction map (the anisotropy texel cannot
//! hold the sign of the fibre's tilt out of the face), over the top face of a board cut from the
//! tree. `xylem tradeoff` renders from these maps (`material::BakedWoodMaterial`, via
//! [`bake_face`]) as the "baked texture" alternative to the procedural volume. Uses `wood`,
//! `material` (the map type) and `picture` (the files).
//!
//! Conventions (as glTF 2.0 and KHR_materials_anisotropy use them): texel (0, 0) is the top-left
//! corner; tangent-space x points to the image's right (+u, along the board's length), y to the
//! image's top, z out of the face. Data maps (anisotropy, normal) are stored linearly, not sRGB.

pub use crate::material::{across_fiber, anisotropy_texel, bake_face, BakedMaps, FaceRect};
pub(crate) use crate::material::{texel_values, TexelFrame};
use crate::output::Staged;
use crate::picture::exr::{stage_exr_layers, ExrCompression, ExrLayer};
use crate::picture::png::{stage_png_rgb8, stage_png_tagged, PngTag};
use crate::picture::srgb::to_srgb8;
use crate::picture::ImageError;

pub mod gltf;
pub mod materialx;
pub mod preview;
pub mod raster;
pub mod usd;
pub mod uv_mesh;
use crate::wood::WoodVolume;
use glam::{Affine3A, Mat3, Vec2, Vec3};

/// Which face of the log the board shows (Liu et al. 2016 §7.2; the classical sawing terms).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BakeCut {
    /// Flat-sawn: the face is tangent to the growth rings (its normal is radial).
    Tangential,
    /// Quartersawn: the face contains the radius (its normal is tangential, θ̂).
    Radial,
    /// End grain: the face is perpendicular to the pith.
    Transverse,
}

/// The cuts by their command-line names (parsed and printed from this one table).
const CUTS: [(BakeCut, &str); 3] = [
    (BakeCut::Tangential, "tangential"),
    (BakeCut::Radial, "radial"),
    (BakeCut::Transverse, "transverse"),
];

impl std::str::FromStr for BakeCut {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        (CUTS.iter().find(|(_, n)| *n == s).map(|(c, _)| *c))
            .ok_or_else(|| format!("cut `{s}`: expected tangential, radial or transverse"))
    }
}

/// The command-line name (`radial`), not the Rust variant.
impl std::fmt::Display for BakeCut {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(CUTS.iter().find(|(c, _)| c == self).map_or("?", |(_, n)| n))
    }
}

/// The board and where it was cut: `size` = [length W, width H, thickness T] (mm); its centre
/// sits `radius` mm from the pith; the baked face is the one `T/2` out along the face normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoardCut {
    /// [length W, width H, thickness T] (mm).
    pub size: [f32; 3],
    /// Which face of the log the board shows.
    pub cut: BakeCut,
    /// Distance of the board's centre from the pith (mm).
    pub radius: f32,
}

impl BoardCut {
    /// The face's frame in tree space: (origin of texel (0,0)'s corner, right = +u per mm,
    /// down = +v per mm, normal). Right × up = normal, with up = −down.
    fn face(&self) -> (Vec3, Vec3, Vec3, Vec3) {
        let [w, h, t] = self.size;
        let centre = Vec3::new(0.0, self.radius, 0.0);
        // (right, down, normal) for each cut; the grain (tree z) runs along the length where it can.
        let (right, down, normal) = match self.cut {
            BakeCut::Tangential => (Vec3::Z, -Vec3::X, Vec3::Y),
            BakeCut::Radial => (Vec3::Z, Vec3::Y, Vec3::X),
            BakeCut::Transverse => (Vec3::X, -Vec3::Y, Vec3::Z),
        };
        let corner = centre + 0.5 * t * normal - 0.5 * w * right - 0.5 * h * down;
        (corner, right, down, normal)
    }

    /// The baked face as a rectangle in tree space.
    pub fn rect(&self) -> FaceRect {
        let (corner, right, down, _) = self.face();
        FaceRect {
            corner,
            right,
            down,
            size: Vec2::new(self.size[0], self.size[1]),
        }
    }

    /// Texture size for `res` texels along the length (at least 1 × 1).
    #[cfg(test)]
    pub(crate) fn texture_size(&self, res: u32) -> (u32, u32) {
        self.rect().texture_size(res)
    }

    /// The glTF space of the board's `.glb` (metres; length along x, thickness along y, width
    /// along z, centred) → tree space: x → the top face's right, y → its normal, z → its down,
    /// ×1000, about the board's centre. A rotation (right · (normal × down) = 1) and a scale, so
    /// the top face's texel (u, v) lands where [`BoardCut::rect`] puts it.
    pub(crate) fn gltf_to_tree(&self) -> Affine3A {
        let (_, right, down, normal) = self.face();
        Affine3A::from_mat3_translation(
            Mat3::from_cols(1000.0 * right, 1000.0 * normal, 1000.0 * down),
            Vec3::new(0.0, self.radius, 0.0),
        )
    }

    /// The five faces other than the baked top as one UV mesh in the `.glb`'s space (metres),
    /// each face its own chart of a shelf-packed atlas at one scale (square texels): the bottom,
    /// then front and back (W × T), then right and left (H × T) side by side where they fit,
    /// with a gutter of `ATLAS_GUTTER` of the atlas width around every chart for padding. Also
    /// the atlas's size in mm.
    pub fn side_atlas(&self) -> (uv_mesh::UvMesh, Vec2) {
        let [w, h, t] = self.size;
        let g = ATLAS_GUTTER * w.max(h);
        // (origin, u edge, v edge) in mm, glTF axes, and the chart's (width, height) = (|u|, |v|).
        let (x0, y0, z0) = (-w / 2.0, -t / 2.0, -h / 2.0);
        let quads = [
            ([x0, y0, -z0], [w, 0.0, 0.0], [0.0, 0.0, -h]), // bottom (−y)
            ([x0, -y0, -z0], [w, 0.0, 0.0], [0.0, -t, 0.0]), // front (+z)
            ([-x0, -y0, z0], [-w, 0.0, 0.0], [0.0, -t, 0.0]), // back (−z)
            ([-x0, -y0, -z0], [0.0, 0.0, -h], [0.0, -t, 0.0]), // right (+x)
            ([x0, -y0, z0], [0.0, 0.0, h], [0.0, -t, 0.0]), // left (−x)
        ];
        let width = g + w.max(2.0 * h + g) + g;
        // Shelf packing, left to right, a new shelf when the next chart does not fit.
        let (mut at, mut shelf, mut mins) = (Vec2::splat(g), 0.0f32, Vec::new());
        for (_, u, v) in &quads {
            let size = Vec2::new(Vec3::from(*u).length(), Vec3::from(*v).length());
            if at.x + size.x + g > width + 1e-3 {
                at = Vec2::new(g, at.y + shelf + g);
                shelf = 0.0;
            }
            mins.push((at, size));
            at.x += size.x + g;
            shelf = shelf.max(size.y);
        }
        let atlas = Vec2::new(width, at.y + shelf + g);
        let mut m = uv_mesh::UvMesh::default();
        for ((o, u, v), (min, size)) in quads.iter().zip(mins) {
            let (o, u, v) = (Vec3::from(*o), Vec3::from(*u), Vec3::from(*v));
            let n = v.cross(u).normalize();
            let base = m.positions.len() as u32;
            for (a, b) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
                m.positions.push((o + a * u + b * v) / 1000.0);
                m.normals.push(n);
                m.uvs.push((min + Vec2::new(a, b) * size) / atlas);
            }
            m.indices.push([base, base + 3, base + 2]);
            m.indices.push([base, base + 2, base + 1]);
        }
        (m, atlas)
    }

    /// The five other faces baked through [`BoardCut::side_atlas`], `res` texels along the
    /// atlas's width, padded [`PAD_TEXELS`].
    pub fn bake_sides(&self, volume: &WoodVolume, res: u32) -> raster::MeshBake {
        let (mesh, atlas) = self.side_atlas();
        let w = res.max(1);
        let h = ((res as f32 * atlas.y / atlas.x).round() as u32).max(1);
        raster::bake_mesh(volume, &mesh, self.gltf_to_tree(), w, h, PAD_TEXELS)
    }
}

/// The gutter around each chart of a board's side atlas, as a fraction of its longer face side.
const ATLAS_GUTTER: f32 = 0.02;

/// Texels of padding grown around every chart of a mesh bake (a bilinear tap reaches 1 texel,
/// the 4th mip level 8 texels of the base level: 4 covers bilinear lookup to the 2nd level).
pub const PAD_TEXELS: u32 = 4;

/// Bakes `volume` over the board's face at `res` texels along its length, one sample at each
/// texel centre.
pub fn bake(volume: &WoodVolume, board: &BoardCut, res: u32) -> BakedMaps {
    bake_face(volume, &board.rect(), Affine3A::IDENTITY, res)
}

/// Data (not colour) texels as 8-bit codes: `v` in [0, 1] → round(255 v), no transfer curve.
fn data8(values: impl Iterator<Item = f32>) -> Vec<u8> {
    values
        .map(|v| (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8)
        .collect()
}

/// The 8-bit RGB codes of the data maps (linear, no transfer curve), as the folder's PNGs and
/// the `.glb` both carry them.
pub(crate) struct DataCodes {
    /// The KHR_materials_anisotropy texel as stored.
    pub anisotropy: Vec<u8>,
    /// 0.5 + 0.5·n.
    pub normal: Vec<u8>,
    /// glTF's metallic-roughness texture: R unused (255, no occlusion if read as one), G the
    /// perceptual roughness of the fibre lobe ([`gltf::gltf_roughness`]), B metalness 0.
    pub metallic_roughness: Vec<u8>,
    /// β / 45° as grey.
    pub highlight_width: Vec<u8>,
    pub ray_mask: Vec<u8>,
    /// 0.5 + 0.5·f, a tangent-space unit vector like the normal.
    pub fiber: Vec<u8>,
}

pub(crate) fn textures(m: &BakedMaps) -> DataCodes {
    let grey = |v: &[f32], scale: f32| data8(v.iter().flat_map(|x| [x * scale; 3]));
    let unit = |v: &[Vec3]| data8(v.iter().flat_map(|c| (0.5 + 0.5 * *c).to_array()));
    let beta_scale = 1.0 / 45f32.to_radians();
    DataCodes {
        anisotropy: data8(m.anisotropy.iter().flat_map(|c| c.to_array())),
        normal: unit(&m.normal),
        metallic_roughness: data8(
            m.highlight_width
                .iter()
                .flat_map(|&b| [1.0, gltf::gltf_roughness(b), 0.0]),
        ),
        highlight_width: grey(&m.highlight_width, beta_scale),
        ray_mask: grey(&m.ray_mask, 1.0),
        fiber: unit(&m.fiber),
    }
}

/// Stages every map as `NAME.png` and `NAME.exr` in `dir`, to commit as one set
/// ([`crate::output::commit_set`]; `xylem bake` adds the `.glb` and the record `bake.json`).
/// PNG: base and fibre colour in sRGB (tagged so); the data maps (`DataCodes`: anisotropy, normal,
/// metallic-roughness, highlight width, ray mask, fibre direction) as linear codes with no
/// colour-space chunk. EXR: the same maps as 32-bit floats, with the anisotropy and normal maps
/// *decoded* (direction components in [−1, 1], strength; unit normal) and β in radians, and the
/// tangent-space ray direction (`ray_direction.exr`, no PNG: only the Mitsuba plugin reads it).
pub fn stage_maps(dir: &std::path::Path, m: &BakedMaps) -> Result<Vec<Staged>, ImageError> {
    let (w, h) = (m.width, m.height);
    let mut files = vec![
        stage_png_rgb8(
            &dir.join("base_color.png"),
            w,
            h,
            &to_srgb8(&m.base_color, 0.0),
        )?,
        stage_png_rgb8(
            &dir.join("fiber_color.png"),
            w,
            h,
            &to_srgb8(&m.fiber_color, 0.0),
        )?,
    ];
    let c = textures(m);
    let pngs: [(&str, Vec<u8>); 6] = [
        ("anisotropy", c.anisotropy),
        ("metallic_roughness", c.metallic_roughness),
        ("highlight_width", c.highlight_width),
        ("ray_mask", c.ray_mask),
        ("normal", c.normal),
        ("fiber_direction", c.fiber),
    ];
    for (name, bytes) in pngs {
        let p = dir.join(format!("{name}.png"));
        files.push(stage_png_tagged(&p, w, h, &bytes, PngTag::Untagged)?);
    }
    let flat = |v: &[Vec3]| v.iter().flat_map(|c| c.to_array()).collect::<Vec<f32>>();
    let aniso: Vec<Vec3> = m
        .anisotropy
        .iter()
        .map(|a| Vec3::new(2.0 * a.x - 1.0, 2.0 * a.y - 1.0, a.z))
        .collect();
    let exrs: [(&str, &[&str], Vec<f32>); 8] = [
        ("base_color", &["R", "G", "B"], flat(&m.base_color)),
        ("fiber_color", &["R", "G", "B"], flat(&m.fiber_color)),
        ("anisotropy", &["R", "G", "B"], flat(&aniso)),
        ("highlight_width", &["Y"], m.highlight_width.clone()),
        ("ray_mask", &["Y"], m.ray_mask.clone()),
        ("normal", &["R", "G", "B"], flat(&m.normal)),
        ("fiber_direction", &["R", "G", "B"], flat(&m.fiber)),
        ("ray_direction", &["R", "G", "B"], flat(&m.ray)),
    ];
    for (name, channels, data) in exrs {
        let layer = ExrLayer {
            name: "",
            channels,
            data,
        };
        let p = dir.join(format!("{name}.exr"));
        files.push(stage_exr_layers(
            &p,
            w,
            h,
            &[layer],
            ExrCompression::Zip,
            &[],
        )?);
    }
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn face_frames_are_right_handed_and_cut_as_named() {
        for cut in [BakeCut::Tangential, BakeCut::Radial, BakeCut::Transverse] {
            let b = BoardCut {
                size: [200.0, 100.0, 20.0],
                cut,
                radius: 150.0,
            };
            let (corner, right, down, n) = b.face();
            assert!((right.cross(-down) - n).length() < 1e-6, "{cut:?}");
            // The board's centre sits on the +y radius.
            let radial = Vec3::Y;
            let face_centre = corner + 100.0 * right + 50.0 * down;
            assert!((face_centre - (Vec3::new(0.0, 150.0, 0.0) + 10.0 * n)).length() < 1e-4);
            match cut {
                BakeCut::Tangential => assert!((n.dot(radial) - 1.0).abs() < 1e-6),
                BakeCut::Radial => assert!(n.dot(radial).abs() < 1e-6 && n.z == 0.0),
                BakeCut::Transverse => assert_eq!(n, Vec3::Z),
            }
        }
        assert_eq!(
            BoardCut {
                size: [300.0, 100.0, 20.0],
                cut: BakeCut::Radial,
                radius: 100.0
            }
            .texture_size(512),
            (512, 171)
        );
        assert!("diagonal".parse::<BakeCut>().is_err());
    }

    #[test]
    fn anisotropy_encodes_direction_and_in_plane_strength() {
        let (r, u) = (Vec3::X, Vec3::Y);
        // A fibre along the image's right stretches its highlight up the image: direction
        // (0, 1) → (0.5, 1), full strength.
        assert_eq!(anisotropy_texel(Vec3::X, r, u), Vec3::new(0.5, 1.0, 1.0));
        // Dipping 60° into the face: strength cos 60° = 0.5, direction still across x.
        let f = Vec3::new(60f32.to_radians().cos(), 0.0, -60f32.to_radians().sin());
        let a = anisotropy_texel(f, r, u);
        assert!((a.z - 0.5).abs() < 1e-6 && (a.y - 1.0).abs() < 1e-6 && (a.x - 0.5).abs() < 1e-6);
        // End grain: no strength, a defined direction.
        assert_eq!(anisotropy_texel(Vec3::Z, r, u).z, 0.0);
        // Fibre up the image: the highlight stretches along x (red 0 or 1, green ½).
        let a = anisotropy_texel(Vec3::Y, r, u);
        assert!((a.x - 0.5).abs() > 0.499 && (a.y - 0.5).abs() < 1e-6);
        // A diagonal fibre: direction ⟂ fibre, and decoding gives the fibre back.
        let f = Vec3::new(0.6, 0.8, 0.0);
        let a = anisotropy_texel(f, r, u);
        let d = Vec2::new(2.0 * a.x - 1.0, 2.0 * a.y - 1.0);
        assert!(d.dot(Vec2::new(0.6, 0.8)).abs() < 1e-6 && (d.length() - 1.0).abs() < 1e-6);
        assert!((crate::material::fiber_from_anisotropy(a) - f).length() < 1e-5);
    }

    #[test]
    fn baking_a_preset_gives_finite_maps_with_rings() {
        let v = WoodVolume::new(crate::wood::preset("walnut").unwrap(), 1).unwrap();
        let b = BoardCut {
            size: [120.0, 40.0, 20.0],
            cut: BakeCut::Transverse,
            radius: 120.0,
        };
        let m = bake(&v, &b, 48);
        assert_eq!((m.width, m.height), (48, 16));
        assert!(m
            .base_color
            .iter()
            .all(|c| c.is_finite() && c.min_element() >= 0.0));
        assert!(m.normal.iter().all(|n| (n.length() - 1.0).abs() < 1e-4));
        // End grain: fibres leave the face, so anisotropy strength is small (walnut's fibres
        // wander a few degrees, so a few texels lean further: the 95th percentile).
        let mut strength: Vec<f32> = m.anisotropy.iter().map(|a| a.z).collect();
        strength.sort_by(f32::total_cmp);
        let p95 = strength[strength.len() * 95 / 100];
        assert!(p95 < 0.2, "end grain: p95 strength {p95}");
        // Rings vary the colour across the face.
        let lum: Vec<f32> = m
            .base_color
            .iter()
            .map(|c| crate::math::luminance(*c))
            .collect();
        let (lo, hi) = lum
            .iter()
            .fold((f32::MAX, f32::MIN), |(a, b), &l| (a.min(l), b.max(l)));
        assert!(hi > 1.2 * lo, "rings visible: {lo}..{hi}");
    }
}
