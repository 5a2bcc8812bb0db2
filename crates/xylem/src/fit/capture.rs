//! Reading a capture: the sweep folder's manifest checked field by field, the frames read (EXR
//! radiance, or 8/16-bit sRGB PNG photographs with an optional black frame), and every texel of
//! the board projected into the frames. The geometry of one texel — view direction, and per
//! frame the light direction and irradiance — is what the model needs (notes/fit.md §1).

use crate::math::Vec3;
use crate::picture::srgb::srgb_to_linear;
use crate::picture::Image;
use crate::sweep::claim::CLAIM_FILE;
use crate::sweep::manifest::{
    BoardManifest, CameraManifest, FrameManifest, Manifest, MANIFEST_FILE,
};
use std::path::{Path, PathBuf};

/// Why a capture cannot be fitted; every message names the file and the field.
#[derive(Debug, thiserror::Error)]
pub enum CaptureError {
    /// A file (manifest or frame) could not be read.
    #[error("{path}: cannot read it: {cause}")]
    Read {
        /// The file.
        path: String,
        /// The I/O or decoding error.
        cause: String,
    },
    /// The manifest is not valid JSON for the format.
    #[error("{path}: {cause} (the manifest format is described in notes/fit.md)")]
    Parse {
        /// The manifest.
        path: String,
        /// serde's message.
        cause: String,
    },
    /// A manifest field is missing, out of range or inconsistent.
    #[error("{path}: field `{field}`: {message}")]
    Field {
        /// The manifest.
        path: String,
        /// The field at fault.
        field: String,
        /// What is allowed.
        message: String,
    },
    /// A frame image is unreadable or does not match the manifest (size, channels).
    #[error("{path}: frame image {image} ({field}): {message}")]
    Frame {
        /// The manifest.
        path: String,
        /// The manifest field naming the image.
        field: String,
        /// The image file.
        image: String,
        /// What is wrong with it.
        message: String,
    },
}

/// The camera of a capture, able to project world points to film coordinates (pixels).
#[derive(Clone, Copy, Debug)]
pub struct FilmCamera {
    /// Film width (pixels).
    pub width: u32,
    /// Film height (pixels).
    pub height: u32,
    /// Camera position (world mm).
    pub eye: Vec3,
    right: Vec3,
    up: Vec3,
    forward: Vec3,
    /// tan(fov_y/2) (perspective) or half the film height in mm (orthographic).
    scale: f32,
    orthographic: bool,
}

impl FilmCamera {
    /// Film coordinates (pixels, (0, 0) the top-left corner) of world point `p`: the inverse of
    /// `render::Camera::ray` (ndc = ((2x − w)/h, (h − 2y)/h), pinhole direction n + s·ndc.x·k +
    /// t·ndc.y·k with k = tan(fov/2)). `None` behind a pinhole camera.
    pub fn project(&self, p: Vec3) -> Option<(f32, f32)> {
        let d = p - self.eye;
        let (x, y) = if self.orthographic {
            (d.dot(self.right) / self.scale, d.dot(self.up) / self.scale)
        } else {
            let z = d.dot(self.forward);
            if z <= 0.0 {
                return None;
            }
            (
                d.dot(self.right) / (z * self.scale),
                d.dot(self.up) / (z * self.scale),
            )
        };
        let (w, h) = (self.width as f32, self.height as f32);
        Some((0.5 * (x * h + w), 0.5 * (h - y * h)))
    }

    /// The ray (origin, unit direction) through film point (x, y) in pixels: the inverse of
    /// [`FilmCamera::project`].
    pub fn ray(&self, x: f32, y: f32) -> (Vec3, Vec3) {
        let (w, h) = (self.width as f32, self.height as f32);
        let (nx, ny) = ((2.0 * x - w) / h, (h - 2.0 * y) / h);
        let side = self.right * nx * self.scale + self.up * ny * self.scale;
        if self.orthographic {
            (self.eye + side, self.forward)
        } else {
            (self.eye, (self.forward + side).normalize())
        }
    }

    /// The unit direction from `p` towards the camera.
    pub fn view_dir(&self, p: Vec3) -> Vec3 {
        if self.orthographic {
            -self.forward
        } else {
            (self.eye - p).normalize()
        }
    }
}

/// The board face: centre, orthonormal axes (x along the map's columns, y towards its top row,
/// z = x × y out of the face), size and finish index.
#[derive(Clone, Copy, Debug)]
pub struct BoardPlane {
    /// Centre of the face (world mm).
    pub origin: Vec3,
    /// Unit axis along the map's columns.
    pub x: Vec3,
    /// Unit axis towards the map's top row.
    pub y: Vec3,
    /// Unit normal out of the face, x × y.
    pub z: Vec3,
    /// [width, height] of the face (mm).
    pub size: [f32; 2],
    /// Refractive index of the finish.
    pub eta: f32,
}

impl BoardPlane {
    /// The world point at the centre of texel (col, row) of a `w` × `h` map (row 0 at the top).
    pub(crate) fn texel_point(&self, col: usize, row: usize, w: usize, h: usize) -> Vec3 {
        let u = ((col as f32 + 0.5) / w as f32 - 0.5) * self.size[0];
        let v = (0.5 - (row as f32 + 0.5) / h as f32) * self.size[1];
        self.origin + u * self.x + v * self.y
    }

    /// Where the ray (`origin`, `dir`) meets the board's face, if it does, from its front.
    pub fn hit(&self, origin: Vec3, dir: Vec3) -> Option<Vec3> {
        let den = dir.dot(self.z);
        let t = (self.origin - origin).dot(self.z) / den;
        let p = origin + t * dir;
        let l = self.local(p - self.origin);
        let inside = l.x.abs() <= 0.5 * self.size[0] && l.y.abs() <= 0.5 * self.size[1];
        (den < 0.0 && t > 0.0 && inside).then_some(p)
    }

    /// World direction `d` in the board frame.
    pub fn local(&self, d: Vec3) -> Vec3 {
        Vec3::new(d.dot(self.x), d.dot(self.y), d.dot(self.z))
    }
}

/// A frame's light: a point (position) or a distant light (unit direction towards it).
#[derive(Clone, Copy, Debug)]
pub enum FrameLight {
    /// A point light, or a sphere light of `radius` mm (0 = point) whose mirror glint is masked.
    Point {
        /// Light position (world mm).
        position: Vec3,
        /// Sphere radius (mm, 0 = a point).
        radius: f32,
    },
    /// A distant light.
    Distant {
        /// Unit direction towards the light.
        direction: Vec3,
    },
}

/// One frame of the capture.
#[derive(Clone, Debug)]
pub struct CaptureFrame {
    /// The frame's image file.
    pub image: PathBuf,
    /// Where the light was for this frame.
    pub light: FrameLight,
    /// Radiant intensity (W/sr, point) or irradiance (distant) per channel, linear RGB.
    pub intensity: Vec3,
    /// Which arc of the sweep (0-based).
    pub arc: usize,
    /// That arc's azimuth about +z (degrees).
    pub azimuth_deg: f32,
}

impl CaptureFrame {
    /// The light's direction from `p` (unit) and the irradiance factor: I/d² for a point light,
    /// E for a distant one (the radiance of a pixel is f · cos θi times it per channel).
    pub(crate) fn light_at(&self, p: Vec3) -> (Vec3, Vec3) {
        match self.light {
            FrameLight::Point { position, .. } => {
                let d = position - p;
                let r2 = d.length_squared();
                (d / r2.sqrt(), self.intensity / r2)
            }
            FrameLight::Distant { direction } => (direction, self.intensity),
        }
    }

    /// True when the finish's mirror reflection of the view from `p` (direction `wo`, world)
    /// sees this frame's sphere light (with a 50 % margin): the delta glint the fibre model
    /// has no term for, so the frame is dropped for that texel.
    pub fn glint(&self, p: Vec3, wo: Vec3, n: Vec3) -> bool {
        let FrameLight::Point { position, radius } = self.light else {
            return false;
        };
        if radius <= 0.0 {
            return false;
        }
        let r = 2.0 * wo.dot(n) * n - wo;
        let d = position - p;
        let along = d.dot(r);
        along > 0.0 && (d - along * r).length() < 1.5 * radius
    }
}

/// A read and checked manifest: camera, board, frames, and how pixel values decode.
#[derive(Clone, Debug)]
pub struct Capture {
    /// The capture folder; frame paths are relative to it.
    pub dir: PathBuf,
    /// The manifest file read.
    pub manifest_path: PathBuf,
    /// The camera the frames were taken with.
    pub camera: FilmCamera,
    /// The board face to fit.
    pub board: BoardPlane,
    /// The frames, in manifest order.
    pub frames: Vec<CaptureFrame>,
    /// Photographs stored as sRGB (decoded to linear), else linear values.
    pub srgb: bool,
    /// A frame taken with the light off, subtracted from every frame.
    pub black_frame: Option<PathBuf>,
    /// Linear value at or above which a photograph's pixel counts as clipped.
    pub clip: Option<f32>,
}

/// The fewest arcs a fit accepts, and how far apart (mod 180°) each pair must be: two arcs leave
/// a two-fold ambiguity of the fibre's in-plane angle whenever the highlights of both arcs peak
/// at the same half-vector (an in-plane fibre seen from above; notes/fit.md §3).
pub const MIN_ARCS: usize = 3;
/// How far apart (degrees, mod 180°) every pair of arcs must be; see [`MIN_ARCS`].
pub const MIN_ARC_SEPARATION_DEG: f32 = 20.0;

fn vec3(a: [f32; 3]) -> Vec3 {
    Vec3::from_array(a)
}

impl Capture {
    /// Reads `dir/manifest.json` and checks every field (frames are read by [`Capture::frame`]).
    pub fn open(dir: &Path) -> Result<Capture, CaptureError> {
        let manifest_path = dir.join(MANIFEST_FILE);
        let path = manifest_path.display().to_string();
        let text =
            crate::sweep::manifest::read_text(&manifest_path).map_err(|e| CaptureError::Read {
                path: path.clone(),
                // A sweep folder without its manifest: killed, or slices still missing.
                cause: if manifest_path.exists() || !dir.join(CLAIM_FILE).exists() {
                    e.reason()
                } else {
                    format!(
                        "{}: an incomplete sweep (its manifest is written once every frame is \
                         there; `xylem sweep --assemble {}` names the missing frames)",
                        e.reason(),
                        dir.display()
                    )
                },
            })?;
        let m: Manifest = serde_json::from_str(&text).map_err(|e| CaptureError::Parse {
            path: path.clone(),
            cause: crate::jsonpath::describe(&text, &e),
        })?;
        Capture::from_manifest(dir, &m)
    }

    /// Checks a parsed manifest; `dir` is the folder its image paths are relative to.
    pub(crate) fn from_manifest(dir: &Path, m: &Manifest) -> Result<Capture, CaptureError> {
        let manifest_path = dir.join(MANIFEST_FILE);
        let check = ManifestChecker {
            path: manifest_path.display().to_string(),
        };
        let bad = |field: &str, message: String| check.bad(field, message);
        if m.format != crate::sweep::manifest::FORMAT {
            return Err(bad(
                "format",
                format!(
                    "`{}` (allowed `{}`)",
                    m.format,
                    crate::sweep::manifest::FORMAT
                ),
            ));
        }
        let camera = check.camera(&m.camera)?;
        let board = check.board(m.board.as_ref())?;
        let srgb = match m.color_space.as_str() {
            "linear" => false,
            "srgb" => true,
            other => {
                return Err(bad(
                    "color_space",
                    format!("`{other}` (allowed `linear`, `srgb`)"),
                ))
            }
        };
        if let Some(clip) = m.clip {
            if !(clip.is_finite() && clip > 0.0) {
                return Err(bad(
                    "clip",
                    format!("{clip} (allowed finite and > 0: a pixel at or above the clip level counts as clipped, so 0 or less would clip every pixel)"),
                ));
            }
        }
        if m.frames.is_empty() {
            return Err(bad("frames", "empty (allowed one or more frames)".into()));
        }
        let mut frames = Vec::with_capacity(m.frames.len());
        for (k, f) in m.frames.iter().enumerate() {
            let field = |name: &str| format!("frames[{k}].{name}");
            let intensity = vec3(f.intensity);
            if !(intensity.is_finite()
                && intensity.min_element() >= 0.0
                && intensity.max_element() > 0.0)
            {
                return Err(bad(
                    &field("intensity"),
                    format!("{intensity} (allowed finite, ≥ 0, not all 0)"),
                ));
            }
            let light = check.frame_light(k, f, &board)?;
            frames.push(CaptureFrame {
                image: dir.join(&f.image),
                light,
                intensity,
                arc: f.arc,
                azimuth_deg: f.azimuth_deg,
            });
        }
        let capture = Capture {
            dir: dir.to_path_buf(),
            manifest_path,
            camera,
            board,
            frames,
            srgb,
            black_frame: m.black_frame.as_ref().map(|b| dir.join(b)),
            clip: m.clip,
        };
        capture.check_arcs()?;
        Ok(capture)
    }

    /// The azimuths (degrees, one per distinct arc) of the frames.
    pub(crate) fn arc_azimuths(&self) -> Vec<f32> {
        let mut arcs: Vec<(usize, f32)> = Vec::new();
        for f in &self.frames {
            if !arcs.iter().any(|a| a.0 == f.arc) {
                arcs.push((f.arc, f.azimuth_deg));
            }
        }
        arcs.into_iter().map(|a| a.1).collect()
    }

    /// At least [`MIN_ARCS`] arcs whose azimuths are pairwise [`MIN_ARC_SEPARATION_DEG`] apart
    /// modulo 180° (arcs closer than that count as one).
    pub fn check_arcs(&self) -> Result<(), CaptureError> {
        let az = self.arc_azimuths();
        let mut distinct: Vec<f32> = Vec::new();
        for a in &az {
            let far = distinct.iter().all(|b| {
                let d = (a - b).rem_euclid(180.0);
                d.min(180.0 - d) >= MIN_ARC_SEPARATION_DEG
            });
            if far {
                distinct.push(*a);
            }
        }
        if distinct.len() < MIN_ARCS {
            return Err(CaptureError::Field {
                path: self.manifest_path.display().to_string(),
                field: "frames[].arc".into(),
                message: format!(
                    "{} arc(s) at azimuths {az:?}°, {} of them at least {MIN_ARC_SEPARATION_DEG}° apart (mod 180°): a fit needs at least {MIN_ARCS} arcs that far apart (fewer leave the fibre's in-plane angle ambiguous; notes/fit.md §3)",
                    az.len(),
                    distinct.len()
                ),
            });
        }
        Ok(())
    }

    /// Only the frames whose indices are in `keep` (in that order); checks the arcs again
    /// unless `check_arcs` is false (the validation's curve over fewer arcs).
    pub fn select(&self, keep: &[usize], check_arcs: bool) -> Result<Capture, CaptureError> {
        let mut c = self.clone();
        c.frames = keep.iter().map(|&k| self.frames[k].clone()).collect();
        if check_arcs {
            c.check_arcs()?;
        }
        Ok(c)
    }

    /// Reads frame `k` as linear RGB (black frame subtracted); a pixel at or above the clip
    /// level in any channel comes back as NaN (rejected by the fit).
    pub fn frame(&self, k: usize, black: Option<&[Vec3]>) -> Result<Vec<Vec3>, CaptureError> {
        let f = &self.frames[k];
        let mut px = self.read_image(&f.image, &format!("frames[{k}].image"))?;
        if let Some(black) = black {
            for (p, b) in px.iter_mut().zip(black) {
                if p.is_finite() {
                    *p -= *b;
                }
            }
        }
        Ok(px)
    }

    /// The black frame, if the manifest names one.
    pub fn black(&self) -> Result<Option<Vec<Vec3>>, CaptureError> {
        match &self.black_frame {
            None => Ok(None),
            Some(p) => self.read_image(p, "black_frame").map(Some),
        }
    }

    fn read_image(&self, path: &Path, field: &str) -> Result<Vec<Vec3>, CaptureError> {
        let fail = |message: String| CaptureError::Frame {
            path: self.manifest_path.display().to_string(),
            field: field.to_string(),
            image: path.display().to_string(),
            message,
        };
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        // Checked on the header, before a pixel is decoded: a small file declaring a large
        // image must not cost its decoded size first.
        let camera = (self.camera.width, self.camera.height);
        let size_ok = |w: u32, h: u32| -> Result<(), String> {
            match (w, h) == camera {
                true => Ok(()),
                false => Err(format!(
                    "declares {w}x{h} pixels, the manifest's camera is {}x{} (allowed: every frame the camera's size)",
                    camera.0, camera.1
                )),
            }
        };
        let Image {
            width: w,
            height: h,
            pixels: mut px,
        } = match ext.as_str() {
            "exr" => Image::read_checked(path, &size_ok).map_err(|e| fail(e.to_string()))?,
            "png" => read_png(path, self.srgb, &size_ok).map_err(fail)?,
            other => return Err(fail(format!("extension `{other}` (allowed .exr, .png)"))),
        };
        // The decoder read the size it checked; a file replaced in between is caught here.
        size_ok(w, h).map_err(fail)?;
        if let Some(clip) = self.clip {
            for p in &mut px {
                if p.max_element() >= clip {
                    *p = Vec3::NAN;
                }
            }
        }
        for p in &mut px {
            if !p.is_finite() {
                *p = Vec3::NAN;
            }
        }
        Ok(px)
    }
}

/// An 8- or 16-bit PNG as linear RGB (sRGB decoded when `srgb`, IEC 61966-2-1), each channel
/// v / (2^bits − 1) first; a pixel with a channel at the top code is clipped (NaN): its true
/// value is unknown.
fn read_png(
    path: &Path,
    srgb: bool,
    size_ok: crate::resources::SizeCheck,
) -> Result<Image, String> {
    use crate::picture::png::{decode_png, open_png, rgb_samples, sample_max};
    let px_bytes = std::mem::size_of::<Vec3>() as u64;
    let (info, buf) = decode_png(
        path,
        open_png(path)?,
        png::Transformations::EXPAND,
        px_bytes,
        size_ok,
    )?;
    let max = sample_max(&info);
    let decode = |v: f32| match srgb {
        true => srgb_to_linear(v / max),
        false => v / max,
    };
    let px = rgb_samples(&info, &buf)
        .map(|p| match p.map(|v| v as f32) {
            [r, g, b] if r >= max || g >= max || b >= max => Vec3::NAN,
            [r, g, b] => Vec3::new(decode(r), decode(g), decode(b)),
        })
        .collect();
    Ok(Image::new(info.width, info.height, px))
}
/// Where a manifest's errors point: its file, and the field named by each check.
struct ManifestChecker {
    path: String,
}

impl ManifestChecker {
    /// The error for `field` of the manifest, with `message`.
    fn bad(&self, field: &str, message: String) -> CaptureError {
        CaptureError::Field {
            path: self.path.clone(),
            field: field.to_string(),
            message,
        }
    }

    /// `a` as a unit vector (normalised), or the error for `field`: finite, length 1 ± 1e-3.
    fn unit(&self, field: &str, a: [f32; 3]) -> Result<Vec3, CaptureError> {
        let v = vec3(a);
        if v.is_finite() && (v.length() - 1.0).abs() < 1e-3 {
            Ok(v.normalize())
        } else {
            Err(self.bad(field, format!("{v} (allowed a unit vector)")))
        }
    }

    /// The manifest's camera checked: size, orthonormal axes, a finite eye, the projection and
    /// its field of view or film width.
    fn camera(&self, c: &CameraManifest) -> Result<FilmCamera, CaptureError> {
        let (bad, unit) = (
            |at: &str, m: String| self.bad(at, m),
            |at: &str, a| self.unit(at, a),
        );
        if c.width == 0 || c.height == 0 || c.width > 16384 || c.height > 16384 {
            return Err(bad(
                "camera.width",
                format!("{}x{} (allowed 1 to 16384 each)", c.width, c.height),
            ));
        }
        let (right, up, forward) = (
            unit("camera.right", c.right)?,
            unit("camera.up", c.up)?,
            unit("camera.forward", c.forward)?,
        );
        // A camera whose axes are not orthogonal projects the board onto a line (a 1×23 map).
        for (field, a, b, an) in [
            ("camera.up", up, right, "camera.right"),
            ("camera.forward", forward, right, "camera.right"),
            ("camera.forward", forward, up, "camera.up"),
        ] {
            if a.dot(b).abs() > 1e-3 {
                return Err(bad(
                    field,
                    format!(
                        "{a} is {:.2}° from {an} {b} (allowed: perpendicular, within 0.06°)",
                        a.dot(b).clamp(-1.0, 1.0).acos().to_degrees()
                    ),
                ));
            }
        }
        if !vec3(c.eye).is_finite() {
            return Err(bad("camera.eye", "must be finite".into()));
        }
        let (scale, orthographic) = match c.projection.as_str() {
            "perspective" => {
                let fov = c
                    .fov_y_deg
                    .ok_or_else(|| bad("camera.fov_y_deg", "missing (perspective)".into()))?;
                if !(fov > 0.01 && fov < 179.0) {
                    return Err(bad(
                        "camera.fov_y_deg",
                        format!("{fov} (allowed 0.01 to 179)"),
                    ));
                }
                ((0.5 * fov.to_radians()).tan(), false)
            }
            "orthographic" => {
                let w = c
                    .film_width_mm
                    .ok_or_else(|| bad("camera.film_width_mm", "missing (orthographic)".into()))?;
                if !(w > 0.0 && w.is_finite()) {
                    return Err(bad("camera.film_width_mm", format!("{w} (allowed > 0)")));
                }
                (0.5 * w * c.height as f32 / c.width as f32, true)
            }
            other => {
                return Err(bad(
                    "camera.projection",
                    format!("`{other}` (allowed `perspective`, `orthographic`)"),
                ))
            }
        };
        Ok(FilmCamera {
            width: c.width,
            height: c.height,
            eye: vec3(c.eye),
            right,
            up,
            forward,
            scale,
            orthographic,
        })
    }

    /// The manifest's board checked: present, orthonormal axes, a finite origin, a positive
    /// size and the finish's η in [1, 4].
    fn board(&self, b: Option<&BoardManifest>) -> Result<BoardPlane, CaptureError> {
        let (bad, unit) = (
            |at: &str, m: String| self.bad(at, m),
            |at: &str, a| self.unit(at, a),
        );
        let b = b.ok_or_else(|| {
            bad(
                "board",
                "missing (a scene's [sweep.board] table writes it; notes/fit.md)".into(),
            )
        })?;
        let (x, y) = (
            unit("board.x_axis", b.x_axis)?,
            unit("board.y_axis", b.y_axis)?,
        );
        if x.dot(y).abs() > 1e-3 {
            return Err(bad("board.y_axis", "not perpendicular to x_axis".into()));
        }
        if !vec3(b.origin).is_finite() {
            return Err(bad("board.origin", "must be finite".into()));
        }
        if !b.size_mm.iter().all(|s| s.is_finite() && *s > 0.0) {
            return Err(bad(
                "board.size_mm",
                format!("{:?} (allowed positive mm)", b.size_mm),
            ));
        }
        if !(1.0..=4.0).contains(&b.eta) {
            return Err(bad("board.eta", format!("{} (allowed 1 to 4)", b.eta)));
        }
        Ok(BoardPlane {
            origin: vec3(b.origin),
            x,
            y,
            z: x.cross(y),
            size: b.size_mm,
            eta: b.eta,
        })
    }

    /// The light of frame `k` checked against the board: a point light above the face (its
    /// radius below its height), or a distant light towards the face.
    fn frame_light(
        &self,
        k: usize,
        f: &FrameManifest,
        board: &BoardPlane,
    ) -> Result<FrameLight, CaptureError> {
        let (bad, unit) = (
            |at: &str, m: String| self.bad(at, m),
            |at: &str, a| self.unit(at, a),
        );
        let field = |name: &str| format!("frames[{k}].{name}");
        Ok(match f.light.as_str() {
            "point" => {
                let p = vec3(
                    f.position
                        .ok_or_else(|| bad(&field("position"), "missing (point light)".into()))?,
                );
                if !p.is_finite() {
                    return Err(bad(&field("position"), "must be finite".into()));
                }
                // The light must be above the board's plane (outside the board).
                let h = (p - board.origin).dot(board.z);
                if h <= 1e-3 * board.size[0].max(board.size[1]) {
                    return Err(bad(
                        &field("position"),
                        format!(
                            "{p} lies {h} mm from the board plane, inside or below the board (allowed: above the face)"
                        ),
                    ));
                }
                if !(f.radius.is_finite() && f.radius >= 0.0 && f.radius < h) {
                    return Err(bad(
                        &field("radius"),
                        format!("{} (allowed 0 to the light's height {h} mm)", f.radius),
                    ));
                }
                FrameLight::Point {
                    position: p,
                    radius: f.radius,
                }
            }
            "distant" => {
                let d = unit(
                    &field("direction"),
                    f.direction.ok_or_else(|| {
                        bad(&field("direction"), "missing (distant light)".into())
                    })?,
                )?;
                if d.dot(board.z) <= 0.0 {
                    return Err(bad(
                        &field("direction"),
                        "below the board's horizon (allowed: towards the face)".into(),
                    ));
                }
                FrameLight::Distant { direction: d }
            }
            other => {
                return Err(bad(
                    &field("light"),
                    format!("`{other}` (allowed `point`, `distant`)"),
                ))
            }
        })
    }
}
