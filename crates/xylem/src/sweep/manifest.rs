//! The capture format of a sweep: one JSON manifest (`manifest.json`) beside the frames that
//! says everything a fit needs without the scene file — the camera (intrinsics and pose), the
//! board plane, the finish's index and, per frame, the image and the light (position or
//! direction, intensity). `xylem sweep` writes it for every sweep; a photographed sweep supplies
//! its own (fields in notes/fit.md "Capture format").

use super::path::SweepPath;
use crate::render::{DistantLight, Light, PointLight, Projection, SphereLight, SpotLight};
use crate::scene::LoadedScene;
use glam::Vec3;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The manifest's file name in a sweep folder.
pub const MANIFEST_FILE: &str = "manifest.json";

/// The largest manifest read: 64 MiB (a frame's entry is about 300 bytes, so some 200 000
/// frames); this bounds `/dev/zero` and the like.
pub const MAX_MANIFEST_BYTES: u64 = 64 << 20;

/// Reads a manifest's text: a regular file of at most [`MAX_MANIFEST_BYTES`] (a FIFO or a
/// device is refused at once instead of blocking or reading forever).
pub fn read_text(path: &Path) -> Result<String, crate::resources::ResourceError> {
    crate::resources::read_text_bounded(path, MAX_MANIFEST_BYTES, "JSON text")
}

/// The format tag the manifest carries.
pub const FORMAT: &str = "xylem-sweep-manifest/1";

/// A pinhole or orthographic camera: `right`, `up`, `forward` are the orthonormal image-right,
/// image-up and view directions (world); pixel (0, 0) is the top-left corner of the film.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraManifest {
    /// `"perspective"` (pinhole) or `"orthographic"`.
    pub projection: String,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Camera position (world, mm).
    pub eye: [f32; 3],
    /// Image-right direction (world, unit).
    pub right: [f32; 3],
    /// Image-up direction (world, unit).
    pub up: [f32; 3],
    /// View direction (world, unit).
    pub forward: [f32; 3],
    /// Vertical field of view (perspective), degrees.
    #[serde(default)]
    pub fov_y_deg: Option<f32>,
    /// Film width in mm (orthographic).
    #[serde(default)]
    pub film_width_mm: Option<f32>,
}

/// The flat board face (world mm): centre, x axis (image columns of the maps), y axis (towards
/// their top row), size, and the index of its smooth finish.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoardManifest {
    /// Centre of the face (world, mm).
    pub origin: [f32; 3],
    /// Unit direction of the maps' image columns (world).
    pub x_axis: [f32; 3],
    /// Unit direction towards the maps' top row (world), perpendicular to `x_axis`.
    pub y_axis: [f32; 3],
    /// [width, height] of the face along `x_axis` and `y_axis` (mm).
    pub size_mm: [f32; 2],
    /// Refractive index of the smooth finish (1–4).
    pub eta: f32,
}

/// One frame: its image (relative to the folder), the light and which arc it lies on.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrameManifest {
    /// The frame's image, relative to the folder (`.exr` or `.png`).
    pub image: String,
    /// `"point"` (position, intensity in W/sr-like units: radiance of a pixel seeing a white
    /// Lambertian at distance d is I cos θ/(π d²)) or `"distant"` (direction, irradiance).
    pub light: String,
    /// Light position (world, mm), for a `"point"` light.
    #[serde(default)]
    pub position: Option<[f32; 3]>,
    /// Unit direction towards the light (world), for a `"distant"` light.
    #[serde(default)]
    pub direction: Option<[f32; 3]>,
    /// Radius of a sphere light (mm; 0 for a point), used to reject the finish's mirror glint.
    #[serde(default)]
    pub radius: f32,
    /// Intensity (point) or irradiance (distant), linear RGB.
    pub intensity: [f32; 3],
    /// Index of the arc the frame lies on (0-based).
    pub arc: usize,
    /// Azimuth of that arc about the zenith (degrees).
    pub azimuth_deg: f32,
    /// Light angle from the zenith along the arc (degrees).
    pub light_deg: f32,
}

/// The whole manifest.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// The format tag, [`FORMAT`].
    pub format: String,
    /// The camera, the same for every frame.
    pub camera: CameraManifest,
    /// `None` when the scene's `[sweep]` has no `[sweep.board]` (a fit then refuses the folder).
    pub board: Option<BoardManifest>,
    /// `"linear"` (EXR radiance) or `"srgb"` (8/16-bit photographs).
    pub color_space: String,
    /// An image taken with the light off, subtracted from every frame (relative path).
    #[serde(default)]
    pub black_frame: Option<String>,
    /// Pixel value at or above which a photograph is clipped (`None`: never clipped).
    #[serde(default)]
    pub clip: Option<f32>,
    /// The frames, in sweep order.
    pub frames: Vec<FrameManifest>,
}

impl Manifest {
    /// The manifest of a sweep of `loaded` along `path` (light `moving`), frames as
    /// `frame_NNNN.exr`.
    pub(crate) fn of_sweep(loaded: &LoadedScene, path: &SweepPath, moving: usize) -> Manifest {
        let cam = &loaded.scene.camera;
        let (fov_y_deg, film_width_mm, projection) = match cam.projection {
            Projection::Perspective { fov_y, .. } => {
                (Some(fov_y.to_degrees()), None, "perspective")
            }
            Projection::Orthographic { width } => (None, Some(width), "orthographic"),
        };
        let camera = CameraManifest {
            projection: projection.into(),
            width: cam.width,
            height: cam.height,
            eye: cam.eye.to_array(),
            right: cam.frame.s.to_array(),
            up: cam.frame.t.to_array(),
            forward: cam.frame.n.to_array(),
            fov_y_deg,
            film_width_mm,
        };
        let board = loaded
            .sweep
            .as_ref()
            .and_then(|t| t.board.as_ref())
            .map(|b| BoardManifest {
                origin: b.origin,
                x_axis: Vec3::from_array(b.x_axis).normalize().to_array(),
                y_axis: Vec3::from_array(b.y_axis).normalize().to_array(),
                size_mm: b.size_mm,
                eta: b.eta,
            });
        let frames = (0..path.frames())
            .map(|k| {
                let light = path.place(&loaded.scene.lights[moving], k);
                let (kind, position, direction, radius, intensity) = match light {
                    Light::Point(PointLight {
                        position,
                        intensity,
                    })
                    | Light::Spot(SpotLight {
                        position,
                        intensity,
                        ..
                    }) => ("point", Some(position), None, 0.0, intensity),
                    // A uniform sphere of radiance L and radius r has intensity L π r² in every
                    // direction (its projected area is π r²).
                    Light::Sphere(SphereLight {
                        center,
                        radius,
                        radiance,
                    }) => (
                        "point",
                        Some(center),
                        None,
                        radius,
                        radiance * std::f32::consts::PI * radius * radius,
                    ),
                    Light::Distant(DistantLight {
                        direction,
                        irradiance,
                    }) => ("distant", None, Some(direction), 0.0, irradiance),
                    Light::Rect(_) | Light::Environment(_) => ("none", None, None, 0.0, Vec3::ZERO),
                };
                FrameManifest {
                    image: format!("{}.exr", super::sequence::frame_stem(k)),
                    light: kind.into(),
                    position: position.map(|p| p.to_array()),
                    direction: direction.map(|d| d.to_array()),
                    radius,
                    intensity: intensity.to_array(),
                    arc: k / path.arc.frames,
                    azimuth_deg: path.azimuth_deg(k),
                    light_deg: path.light_deg(k),
                }
            })
            .collect();
        Manifest {
            format: FORMAT.into(),
            camera,
            board,
            color_space: "linear".into(),
            black_frame: None,
            clip: None,
            frames,
        }
    }

    /// The manifest's JSON text, as [`Manifest::write`] writes it.
    pub fn text(&self) -> String {
        serde_json::to_string_pretty(self).expect("a manifest serializes")
    }

    /// Writes the manifest into `dir` atomically.
    pub fn write(&self, dir: &Path) -> std::io::Result<()> {
        crate::output::write_atomic(&dir.join(MANIFEST_FILE), self.text().as_bytes())
    }
}
