//! Boards measured by Marschner, Westin, Arbree, Moon 2005 ("Measuring and modeling the
//! appearance of finished wood", SIGGRAPH 2005): per-texel diffuse colour, fibre highlight colour
//! and fibre axis fitted to photographs, stored as 8-bit images (data/marschner2005/README.md),
//! and the material that renders them on one flat face of an object.
//!
//! Every assumption about the encoding (colour space, highlight scale, the conversion from the
//! published fibre lobe to xylem's energy-bounded one, the sign of y, β, η, pixel pitch) is stated
//! in notes/measured.md.

use super::face::{bilinear_taps, face_shading, FaceRect, FaceTexel};
use super::{MaterialHit, Shading};
use crate::bsdf::{Finish, FinishModel};
use crate::picture::png::{decode_png, decode_png_text, decoded_rgb8, open_png};
use crate::picture::Rgb8;
use glam::{Vec2, Vec3};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// How the 8-bit colours of the maps decode to linear RGB.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ColorSpace {
    /// v/255, as the ported GLSL shader uses the maps (the default).
    #[default]
    Linear,
    /// The sRGB transfer function (IEC 61966-2-1) of v/255.
    Srgb,
}

impl ColorSpace {
    /// The linear value of an 8-bit channel.
    pub fn decode(self, v: u8) -> f32 {
        match self {
            ColorSpace::Linear => v as f32 / 255.0,
            ColorSpace::Srgb => crate::picture::srgb::srgb8_to_linear(v),
        }
    }
}

/// The image files of one board. Paths as given (the scene resolves them against its file).
#[derive(Clone, Debug, PartialEq)]
pub struct MeasuredFiles {
    /// Diffuse colour map (8-bit PNG).
    pub diffuse: PathBuf,
    /// Fibre highlight colour map (8-bit PNG).
    pub fiber_color: PathBuf,
    /// Fibre axis map (8-bit PNG, axis = 2v/255 − 1).
    pub fiber_axis: PathBuf,
    /// Optional β map: β = 90° · v/255 from the first channel.
    pub highlight_width: Option<PathBuf>,
}

impl MeasuredFiles {
    /// `diffuse.png`, `fiber_color.png` and `fiber_axis.png` in `dir` (the layout of
    /// data/marschner2005/), no β map.
    pub fn in_dir(dir: &Path) -> Self {
        MeasuredFiles {
            diffuse: dir.join("diffuse.png"),
            fiber_color: dir.join("fiber_color.png"),
            fiber_axis: dir.join("fiber_axis.png"),
            highlight_width: None,
        }
    }
}

/// Why a measured board could not be read; `field()` is the map it concerns.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeasuredError {
    #[error(
        "{field} map {path}: cannot read it: {cause} (allowed: an 8-bit RGB, RGBA or grey PNG)"
    )]
    /// A map could not be read or decoded as an 8-bit PNG.
    Read {
        /// The map's scene field (`diffuse`, `fiber_axis`, ...).
        field: &'static str,
        /// The image file.
        path: String,
        /// The decoder's error.
        cause: String,
    },
    /// A map's size differs from the diffuse map's.
    #[error("{field} map {path} is {got}, but the diffuse map is {want} (allowed: every map the same size)")]
    Size {
        /// The map's scene field.
        field: &'static str,
        /// The image file.
        path: String,
        /// Its size, "W×H".
        got: String,
        /// The diffuse map's size.
        want: String,
    },
    /// A texel's value is out of range (e.g. a fibre axis far from unit length).
    #[error("{field} map {path}: texel (column {x}, row {y}) {what} (allowed {allowed})")]
    Value {
        /// The map's scene field.
        field: &'static str,
        /// The image file.
        path: String,
        /// The texel's column.
        x: u32,
        /// The texel's row.
        y: u32,
        /// What is wrong with the value.
        what: String,
        /// The allowed range.
        allowed: &'static str,
    },
}

impl MeasuredError {
    /// The map (scene field) the error concerns.
    pub fn field(&self) -> &'static str {
        match self {
            MeasuredError::Read { field, .. }
            | MeasuredError::Size { field, .. }
            | MeasuredError::Value { field, .. } => field,
        }
    }
}

/// A decoded measured board: row-major, top row first; texel (0, 0) is the top-left corner.
/// The board frame is x along the columns (left to right), y towards the top row, z out of the
/// face (right-handed; notes/measured.md "y sign").
#[derive(Clone, Debug, PartialEq)]
pub struct MeasuredBoard {
    /// Width in texels (image columns).
    pub width: u32,
    /// Height in texels (image rows).
    pub height: u32,
    /// Diffuse colour ρ_d, linear RGB.
    pub diffuse: Vec<Vec3>,
    /// Fibre highlight colour as stored (decoded to linear, scale-free): the published lobe's
    /// k_f is `fiber_color_scale` times this (see [`MeasuredBoard::fiber_color_scaled`]).
    pub fiber_color: Vec<Vec3>,
    /// Fibre axis u (unit, board frame; a line, u ≡ −u), decoded as 2v/255 − 1 and renormalised.
    pub fiber_axis: Vec<Vec3>,
    /// β per texel (radians), when a β map was given.
    pub highlight_width: Option<Vec<f32>>,
}

/// The memory a board needs per texel while its maps are read and converted (the decoded
/// samples and 8-bit copies of each map, then three maps of linear `Vec3`s, and β): measured
/// 45 bytes (three 4096² maps: peak RSS 798 MB, 46 MB of it the process before reading).
/// The diffuse map, read first, is checked against this for the whole board.
pub(crate) const BOARD_BYTES_PER_TEXEL: u64 = 48;

/// Reads one map; `want` is the diffuse map's size (None when reading the diffuse map itself),
/// checked on the header before a texel is decoded.
fn read_png8(
    field: &'static str,
    path: &Path,
    want: Option<(u32, u32)>,
) -> Result<Rgb8, MeasuredError> {
    let fail = |cause: String| MeasuredError::Read {
        field,
        path: path.display().to_string(),
        cause,
    };
    let declared = std::cell::Cell::new(None);
    let size_ok = |w: u32, h: u32| -> Result<(), String> {
        match want {
            Some(want) if (w, h) != want => {
                declared.set(Some((w, h)));
                Err(format!("declares {w}x{h}"))
            }
            _ => Ok(()),
        }
    };
    let size_error = |(w, h): (u32, u32)| {
        let want = want.unwrap_or_default();
        MeasuredError::Size {
            field,
            path: path.display().to_string(),
            got: format!("{w}x{h}"),
            want: format!("{}x{}", want.0, want.1),
        }
    };
    // The first map read answers for the whole board's memory.
    let extra = match want {
        None => BOARD_BYTES_PER_TEXEL,
        Some(_) => 3,
    };
    // From disk, or the embedded copy of the repository's measured boards (`crate::builtin`).
    let expand = png::Transformations::EXPAND;
    let (info, buf) = match crate::builtin::stand_in(path) {
        Some((_, bytes)) => decode_png(path, bytes, expand, extra, &size_ok),
        None => open_png(path).and_then(|file| {
            let (info, buf, text) = decode_png_text(path, file, expand, extra, &size_ok)?;
            check_fit_record(path, &text)?;
            Ok((info, buf))
        }),
    }
    .map_err(|e| match declared.get() {
        Some(size) => size_error(size),
        None => fail(e),
    })?;
    if want.is_some_and(|w| w != (info.width, info.height)) {
        return Err(size_error((info.width, info.height)));
    }
    if info.bit_depth != png::BitDepth::Eight {
        return Err(fail(format!("{:?} bits per channel", info.bit_depth)));
    }
    Ok(decoded_rgb8(&info, buf))
}

/// The `tEXt` chunk (`Software`) that marks a PNG map written by `xylem fit`: a reader of such
/// a map requires the fit's record [`FIT_RECORD`] beside it, so the maps of a fit killed while
/// committing are never read as a complete set. Here, with the encoding `fit` writes in.
pub(crate) const FIT_PNG_MARK: (&str, &str) = ("Software", "xylem fit");

/// The record of a fit's outputs: the report, with the maps' sizes and CRC-32s, written last.
pub(crate) const FIT_RECORD: &str = "fit.json";

/// A map beside a fit's record (`fit.json`) must be the file it lists, and a map `xylem fit`
/// wrote (its `Software` text chunk) must have that record beside it: a fit killed while
/// committing leaves maps without a record, never a set of two runs read as one.
fn check_fit_record(path: &Path, text: &[(String, String)]) -> Result<(), String> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
    let by_fit = (text.iter()).any(|(k, v)| k == FIT_PNG_MARK.0 && v == FIT_PNG_MARK.1);
    let record = dir.join(FIT_RECORD);
    if std::fs::symlink_metadata(&record).is_err() {
        return match by_fit {
            true => Err(format!("written by `xylem fit`, but {} is missing: an incomplete fit (its record is written last); fit again", record.display())),
            false => Ok(()),
        };
    }
    match crate::output::check_member(dir, FIT_RECORD, name)? {
        false if by_fit => Err(format!(
            "written by `xylem fit`, but not listed in {}: another fit's map",
            record.display()
        )),
        _ => Ok(()),
    }
}

impl MeasuredBoard {
    /// Reads the board in `dir` (data/marschner2005/{maple,padauk}/), colours as linear.
    pub fn load(dir: &Path) -> Result<MeasuredBoard, MeasuredError> {
        Self::from_files(&MeasuredFiles::in_dir(dir), ColorSpace::Linear)
    }

    /// Reads and checks every map: equal sizes, unit fibre axes (length 0.95–1.05 as decoded;
    /// 8-bit rounding alone stays within 0.01), β in 0.06–90°.
    pub fn from_files(
        files: &MeasuredFiles,
        colors: ColorSpace,
    ) -> Result<MeasuredBoard, MeasuredError> {
        let diffuse = read_png8("diffuse", &files.diffuse, None)?;
        let (width, height) = (diffuse.width, diffuse.height);
        let same_size = |field: &'static str, path: &Path| -> Result<Rgb8, MeasuredError> {
            read_png8(field, path, Some((width, height)))
        };
        let bad = |field: &'static str, path: &Path, i: usize, what: String, allowed| {
            MeasuredError::Value {
                field,
                path: path.display().to_string(),
                x: i as u32 % width,
                y: i as u32 / width,
                what,
                allowed,
            }
        };
        let color = |t: &[u8; 3]| Vec3::from_array(t.map(|v| colors.decode(v)));
        let fiber_color = same_size("fiber_color", &files.fiber_color)?;
        let axes = same_size("fiber_axis", &files.fiber_axis)?;
        let mut fiber_axis = Vec::with_capacity(axes.pixels().len());
        for (i, t) in axes.pixels().enumerate() {
            let u = Vec3::from_array(t.map(|v| 2.0 * v as f32 / 255.0 - 1.0));
            let len = u.length();
            if !(0.95..=1.05).contains(&len) {
                return Err(bad(
                    "fiber_axis",
                    &files.fiber_axis,
                    i,
                    format!("decodes to an axis of length {len:.3}"),
                    "length 0.95 to 1.05: a unit axis stored as 2v/255 − 1",
                ));
            }
            fiber_axis.push(u / len);
        }
        let highlight_width = match &files.highlight_width {
            None => None,
            Some(path) => {
                let mut beta = Vec::with_capacity(axes.pixels().len());
                for (i, t) in same_size("highlight_width", path)?.pixels().enumerate() {
                    let deg = 90.0 * t[0] as f32 / 255.0;
                    if deg < 0.06 {
                        return Err(bad(
                            "highlight_width",
                            path,
                            i,
                            format!("holds β = {deg}°"),
                            "0.06° to 90°, stored as 90° · v/255, so v ≥ 1",
                        ));
                    }
                    beta.push(deg.to_radians());
                }
                Some(beta)
            }
        };
        Ok(MeasuredBoard {
            width,
            height,
            diffuse: diffuse.pixels().map(|t| color(&t)).collect(),
            fiber_color: fiber_color.pixels().map(|t| color(&t)).collect(),
            fiber_axis,
            highlight_width,
        })
    }

    /// The fibre colour of texel `i` for xylem's energy-bounded lobe, before any clamp: the
    /// published lobe's k_f = `scale` · stored, converted by [`energy_bounded_fiber_color`].
    pub fn fiber_color_scaled(&self, i: usize, scale: f32) -> Vec3 {
        energy_bounded_fiber_color(scale * self.fiber_color[i])
    }
}

/// The default `fiber_color_scale`, 1/(2π): the stored value is then the energy-bounded lobe's
/// k_f itself, so the 8-bit range [0, 1] fills the BSDF's k_f range [0, 1] and no texel of either
/// board is clamped (the ported shader's ×10 would clamp nearly all; notes/measured.md).
pub const DEFAULT_FIBER_COLOR_SCALE: f32 = 0.5 * std::f32::consts::FRAC_1_PI;

/// The default β where a board has no β map: the ported GLSL shader's 0.1745 rad
/// (mckennapsean/wood-shader, openGL4/wood.frag).
pub const DEFAULT_HIGHLIGHT_WIDTH_DEG: f32 = 10.0;

/// The k_f of xylem's energy-bounded fibre lobe that matches a k_f fitted to the published lobe
/// of Marschner et al. 2005 (eq. 3, f = k_f g/cos²(ψd/2)): near the specular cone the
/// energy-bounded lobe is the published one times cos(ψd/2)/(2π), so the two agree at normal
/// incidence when k_f(energy-bounded) = 2π k_f(published) (notes/bsdf.md §2.2; notes/measured.md).
pub fn energy_bounded_fiber_color(published: Vec3) -> Vec3 {
    2.0 * std::f32::consts::PI * published
}

/// Which face of the object the board lies on (object space); the image is seen from outside
/// that face with its top row towards `up`: +z (up +y), −z (up −y), ±x and ±y (up +z).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BoardFace {
    /// +z, image top towards +y (the default).
    #[default]
    PosZ,
    /// −z, image top towards −y.
    NegZ,
    /// +x, image top towards +z.
    PosX,
    /// −x, image top towards +z.
    NegX,
    /// +y, image top towards +z.
    PosY,
    /// −y, image top towards +z.
    NegY,
}

impl BoardFace {
    /// The faces' names, as scenes give them.
    pub const NAMES: [&'static str; 6] = ["+z", "-z", "+x", "-x", "+y", "-y"];

    /// The face named by one of [`NAMES`](Self::NAMES).
    pub(crate) fn from_name(name: &str) -> Option<BoardFace> {
        Some(match name {
            "+z" => BoardFace::PosZ,
            "-z" => BoardFace::NegZ,
            "+x" => BoardFace::PosX,
            "-x" => BoardFace::NegX,
            "+y" => BoardFace::PosY,
            "-y" => BoardFace::NegY,
            _ => return None,
        })
    }

    /// The `size` rectangle on this face centred on the object's origin (the plane's offset along
    /// the normal does not matter: points are projected onto it).
    pub fn rect(self, size: Vec2) -> FaceRect {
        let (right, up) = match self {
            BoardFace::PosZ => (Vec3::X, Vec3::Y),
            BoardFace::NegZ => (Vec3::X, -Vec3::Y),
            BoardFace::PosX => (Vec3::Y, Vec3::Z),
            BoardFace::NegX => (-Vec3::Y, Vec3::Z),
            BoardFace::PosY => (-Vec3::X, Vec3::Z),
            BoardFace::NegY => (Vec3::X, Vec3::Z),
        };
        FaceRect {
            corner: -right * (0.5 * size.x) + up * (0.5 * size.y),
            right,
            down: -up,
            size,
        }
    }
}

/// A measured board on one face of an object, seen through a finish. The fibre colours are
/// converted once, at construction, to the energy-bounded lobe's k_f; a texel whose k_f exceeds
/// 1 in some channel (the BSDF's range) is scaled down uniformly to max 1, keeping its hue
/// (`clamped` counts them; notes/measured.md "Highlight scale").
#[derive(Clone, Debug)]
pub struct MeasuredMaterial {
    /// The decoded maps, shared between objects that use the same files.
    pub board: Arc<MeasuredBoard>,
    /// The face the board covers (object space, mm); outside it the edge texels repeat.
    pub face: FaceRect,
    /// Energy-bounded k_f per texel, after the clamp.
    fiber_color: Vec<Vec3>,
    /// How many texels the clamp changed.
    pub clamped: usize,
    /// β (radians) where the board has no β map.
    pub highlight_width: f32,
    /// The finish (index 1–4, GGX roughness 0–1, 0 = smooth), worked out once
    /// ([`Finish::new`]).
    pub finish: Finish,
}

impl MeasuredMaterial {
    /// `fiber_color_scale`: the published lobe's k_f per stored unit; `highlight_width`: β in
    /// radians (used where the board has no β map).
    pub fn new(
        board: Arc<MeasuredBoard>,
        face: FaceRect,
        fiber_color_scale: f32,
        highlight_width: f32,
        eta: f32,
        roughness: f32,
    ) -> MeasuredMaterial {
        let mut clamped = 0;
        let fiber_color = (0..board.fiber_color.len())
            .map(|i| {
                let k = board.fiber_color_scaled(i, fiber_color_scale);
                let peak = k.max_element();
                if peak > 1.0 {
                    clamped += 1;
                    k / peak
                } else {
                    k
                }
            })
            .collect();
        MeasuredMaterial {
            board,
            face,
            fiber_color,
            clamped,
            highlight_width,
            finish: Finish::new(eta, roughness),
        }
    }

    /// The BSDF parameters at texture coordinates `uv`, interpolated bilinearly. The fibre axes
    /// are lines, so each tap is flipped to the side of the first before they are averaged.
    pub fn texel(&self, uv: Vec2) -> FaceTexel {
        let b = &*self.board;
        let taps = bilinear_taps(uv, b.width, b.height);
        let reference = b.fiber_axis[taps[0].0];
        let mut t = FaceTexel {
            diffuse: Vec3::ZERO,
            fiber_color: Vec3::ZERO,
            fiber: Vec3::ZERO,
            ray_mask: 0.0,
            highlight_width: 0.0,
        };
        for (i, w) in taps {
            let u = b.fiber_axis[i];
            t.diffuse += b.diffuse[i] * w;
            t.fiber_color += self.fiber_color[i] * w;
            t.fiber += u.dot(reference).signum() * u * w;
            t.highlight_width += b
                .highlight_width
                .as_ref()
                .map_or(self.highlight_width, |m| m[i])
                * w;
        }
        t.fiber = t.fiber.normalize_or(reference);
        t
    }

    /// The finished-wood BSDF at a hit: the texel under the hit's object-space point projected
    /// onto the face.
    pub fn shade(&self, hit: &MaterialHit) -> Shading {
        let texel = self.texel(self.face.uv(hit.p_object));
        face_shading(
            hit,
            &self.face,
            hit.ns,
            texel,
            &self.finish,
            FinishModel::ClosedForm,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn faces_are_right_handed_and_centred() {
        for face in [
            BoardFace::PosZ,
            BoardFace::NegZ,
            BoardFace::PosX,
            BoardFace::NegX,
            BoardFace::PosY,
            BoardFace::NegY,
        ] {
            let r = face.rect(Vec2::new(4.0, 2.0));
            // The normal points out of the face it names, and uv (½, ½) is the origin.
            let want = match face {
                BoardFace::PosZ => Vec3::Z,
                BoardFace::NegZ => -Vec3::Z,
                BoardFace::PosX => Vec3::X,
                BoardFace::NegX => -Vec3::X,
                BoardFace::PosY => Vec3::Y,
                BoardFace::NegY => -Vec3::Y,
            };
            assert_eq!(r.normal(), want, "{face:?}");
            assert!(r.point(Vec2::splat(0.5)).length() < 1e-6);
        }
    }

    #[test]
    fn srgb_decoding_hits_the_standard_points() {
        assert_eq!(ColorSpace::Srgb.decode(0), 0.0);
        assert!((ColorSpace::Srgb.decode(255) - 1.0).abs() < 1e-6);
        // sRGB 0.5 (v = 127.5) is linear 0.214 (IEC 61966-2-1).
        let mid = 0.5 * (ColorSpace::Srgb.decode(127) + ColorSpace::Srgb.decode(128));
        assert!((mid - 0.214).abs() < 2e-3, "{mid}");
        assert_eq!(ColorSpace::Linear.decode(51), 0.2);
    }

    #[test]
    fn opposite_axes_average_as_one_line() {
        let board = MeasuredBoard {
            width: 2,
            height: 1,
            diffuse: vec![Vec3::splat(0.5); 2],
            fiber_color: vec![Vec3::splat(0.1); 2],
            fiber_axis: vec![Vec3::X, -Vec3::X],
            highlight_width: None,
        };
        let m = MeasuredMaterial::new(
            Arc::new(board),
            BoardFace::PosZ.rect(Vec2::new(2.0, 1.0)),
            1.0,
            0.1,
            1.5,
            0.0,
        );
        let t = m.texel(Vec2::new(0.5, 0.5));
        assert!((t.fiber.abs() - Vec3::X).length() < 1e-6, "{}", t.fiber);
        // 2π · 0.1 = 0.628 ≤ 1: nothing clamped.
        assert_eq!(m.clamped, 0);
        assert!((t.fiber_color - Vec3::splat(0.2 * std::f32::consts::PI)).length() < 1e-6);
    }
}
