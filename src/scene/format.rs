//! The TOML scene format as plain serde data. Every table denies unknown fields, so a typo is an
//! error naming the field and the allowed names. Documented field by field in scenes/README.md.

use serde::{de::Error as _, Deserialize, Deserializer};
use std::collections::BTreeMap;

/// An array of exactly `N` numbers: serde's `[f32; N]` reads the first `N` of a longer TOML
/// array and silently drops the rest (a 4-number position lost its 4th).
fn exact<'de, D: Deserializer<'de>, const N: usize>(d: D) -> Result<[f32; N], D::Error> {
    let v = Vec::<f32>::deserialize(d)?;
    let n = v.len();
    v.try_into()
        .map_err(|_| D::Error::invalid_length(n, &format!("an array of {N} numbers").as_str()))
}

/// `profile`: (radius, z) pairs of exactly two numbers each.
fn exact_pairs<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Vec<[f32; 2]>>, D::Error> {
    let Some(v) = Option::<Vec<Vec<f32>>>::deserialize(d)? else {
        return Ok(None);
    };
    v.into_iter()
        .map(|p| {
            let n = p.len();
            <[f32; 2]>::try_from(p)
                .map_err(|_| D::Error::invalid_length(n, &"a (radius, z) pair of 2 numbers"))
        })
        .collect::<Result<_, _>>()
        .map(Some)
}

/// A whole scene file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    #[serde(default)]
    pub render: RenderTable,
    pub camera: CameraTable,
    #[serde(default)]
    pub lights: Vec<LightTable>,
    #[serde(default)]
    pub materials: BTreeMap<String, MaterialTable>,
    #[serde(default)]
    pub objects: Vec<ObjectTable>,
    /// Light-sweep setup (used by `xylem sweep`).
    pub sweep: Option<SweepTable>,
}

/// `[render]`: image size and sampling.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RenderTable {
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub integrator: IntegratorName,
    pub max_depth: u32,
    pub seed: u64,
    /// PNG exposure in stops.
    pub exposure: f32,
    pub filter: FilterName,
    /// Filter radius in pixels (box: half-width).
    pub filter_radius: Option<f32>,
}

impl Default for RenderTable {
    fn default() -> Self {
        RenderTable {
            width: 512,
            height: 512,
            spp: 16,
            integrator: IntegratorName::Direct,
            max_depth: 8,
            seed: 0,
            exposure: 0.0,
            filter: FilterName::Gaussian,
            filter_radius: None,
        }
    }
}

#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum IntegratorName {
    Direct,
    Path,
}

#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum FilterName {
    Box,
    Tent,
    Gaussian,
}

#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum ProjectionName {
    #[default]
    Perspective,
    Orthographic,
}

/// `[camera]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraTable {
    #[serde(default)]
    pub projection: ProjectionName,
    #[serde(deserialize_with = "exact")]
    pub eye: [f32; 3],
    #[serde(deserialize_with = "exact")]
    pub target: [f32; 3],
    #[serde(default = "default_up")]
    #[serde(deserialize_with = "exact")]
    pub up: [f32; 3],
    /// Perspective only (default [`DEFAULT_FOV_DEG`]); `None` when the file does not give it.
    pub fov_deg: Option<f32>,
    #[serde(default)]
    pub lens_radius: f32,
    pub focus_distance: Option<f32>,
    /// Orthographic film width (mm).
    pub width: Option<f32>,
}

/// The perspective camera's vertical field of view when `fov_deg` is not given.
pub const DEFAULT_FOV_DEG: f32 = 40.0;

fn default_up() -> [f32; 3] {
    [0.0, 0.0, 1.0]
}
fn one() -> f32 {
    1.0
}
fn white() -> [f32; 3] {
    [1.0, 1.0, 1.0]
}

/// `[[lights]]`, one table per light, chosen by `type`.
#[derive(Debug, Clone, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum LightTable {
    Point {
        name: Option<String>,
        #[serde(deserialize_with = "exact")]
        position: [f32; 3],
        intensity: f32,
        #[serde(default = "white")]
        #[serde(deserialize_with = "exact")]
        color: [f32; 3],
    },
    Spot {
        name: Option<String>,
        #[serde(deserialize_with = "exact")]
        position: [f32; 3],
        #[serde(deserialize_with = "exact")]
        target: [f32; 3],
        intensity: f32,
        #[serde(default = "white")]
        #[serde(deserialize_with = "exact")]
        color: [f32; 3],
        cone_deg: f32,
        #[serde(default)]
        falloff_deg: f32,
    },
    Distant {
        name: Option<String>,
        #[serde(deserialize_with = "exact")]
        direction: [f32; 3],
        irradiance: f32,
        #[serde(default = "white")]
        #[serde(deserialize_with = "exact")]
        color: [f32; 3],
    },
    Rect {
        name: Option<String>,
        #[serde(deserialize_with = "exact")]
        corner: [f32; 3],
        #[serde(deserialize_with = "exact")]
        edge_u: [f32; 3],
        #[serde(deserialize_with = "exact")]
        edge_v: [f32; 3],
        radiance: f32,
        #[serde(default = "white")]
        #[serde(deserialize_with = "exact")]
        color: [f32; 3],
    },
    Sphere {
        name: Option<String>,
        #[serde(deserialize_with = "exact")]
        center: [f32; 3],
        radius: f32,
        radiance: f32,
        #[serde(default = "white")]
        #[serde(deserialize_with = "exact")]
        color: [f32; 3],
    },
    Environment {
        name: Option<String>,
        #[serde(default = "one")]
        radiance: f32,
        #[serde(default = "white")]
        #[serde(deserialize_with = "exact")]
        color: [f32; 3],
        map: Option<String>,
        #[serde(default)]
        rotate_deg: f32,
    },
}

impl LightTable {
    pub fn name(&self) -> Option<&str> {
        match self {
            LightTable::Point { name, .. }
            | LightTable::Spot { name, .. }
            | LightTable::Distant { name, .. }
            | LightTable::Rect { name, .. }
            | LightTable::Sphere { name, .. }
            | LightTable::Environment { name, .. } => name.as_deref(),
        }
    }
}

/// `[materials.NAME]`, chosen by `type`.
#[derive(Debug, Clone, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum MaterialTable {
    Lambertian {
        #[serde(deserialize_with = "exact")]
        albedo: [f32; 3],
    },
    /// The finished-wood BSDF with constant parameters; directions in object space.
    Fiber {
        #[serde(deserialize_with = "exact")]
        diffuse: [f32; 3],
        #[serde(deserialize_with = "exact")]
        fiber_color: [f32; 3],
        #[serde(deserialize_with = "exact")]
        fiber_dir: [f32; 3],
        #[serde(default = "default_ray_dir")]
        #[serde(deserialize_with = "exact")]
        ray_dir: [f32; 3],
        #[serde(default)]
        ray_mask: f32,
        #[serde(default = "default_highlight")]
        highlight_width_deg: f32,
        #[serde(default = "default_eta")]
        eta: f32,
        #[serde(default)]
        roughness: f32,
    },
    /// The procedural wood volume of a species preset under a finish.
    Wood {
        /// Built-in preset name (see `xylem preset list`).
        preset: Option<String>,
        /// A preset file instead (path relative to the scene file).
        preset_file: Option<String>,
        /// Selects the tree.
        #[serde(default)]
        seed: u64,
        #[serde(default = "default_eta")]
        eta: f32,
        #[serde(default)]
        roughness: f32,
        /// Pore bump strength (0 = off).
        #[serde(default)]
        bump: f32,
    },
    /// A board measured by Marschner et al. 2005: per-texel BSDF parameters from image maps (in
    /// the encoding of data/marschner2005/) on one face of the object. Paths relative to the scene.
    Measured {
        diffuse: String,
        fiber_color: String,
        fiber_axis: String,
        /// Optional β map (β = 90° · v/255); else `highlight_width_deg` everywhere.
        highlight_width: Option<String>,
        highlight_width_deg: Option<f32>,
        /// The published lobe's k_f per stored unit (notes/measured.md).
        #[serde(default = "default_fiber_color_scale")]
        fiber_color_scale: f32,
        /// "linear" (default) or "srgb".
        color_space: Option<String>,
        /// [width, height] of the image on the face (object-space mm).
        #[serde(deserialize_with = "exact")]
        size_mm: [f32; 2],
        /// "+z" (default), "-z", "+x", "-x", "+y" or "-y".
        face: Option<String>,
        #[serde(default = "default_eta")]
        eta: f32,
        #[serde(default)]
        roughness: f32,
    },
    /// A classic solid texture as a Lambertian albedo.
    Texture {
        /// Texture name (see `xylem texture --help`): marble, slab_marble, ring_wood, log_wood,
        /// stone, clouds, …
        texture: String,
        /// The texture's parameters (missing ones take their defaults).
        #[serde(default)]
        params: BTreeMap<String, f32>,
    },
    Mirror {
        #[serde(default = "default_reflectance")]
        #[serde(deserialize_with = "exact")]
        reflectance: [f32; 3],
    },
    Glass {
        #[serde(default = "default_eta")]
        eta: f32,
        #[serde(default = "white")]
        #[serde(deserialize_with = "exact")]
        tint: [f32; 3],
    },
}

fn default_ray_dir() -> [f32; 3] {
    [0.0, 0.0, 1.0]
}
fn default_highlight() -> f32 {
    8.0
}
fn default_fiber_color_scale() -> f32 {
    crate::material::DEFAULT_FIBER_COLOR_SCALE
}
fn default_eta() -> f32 {
    1.5
}
fn default_reflectance() -> [f32; 3] {
    [0.95, 0.95, 0.95]
}

/// A uniform or per-axis scale.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(untagged)]
pub enum Scale {
    Uniform(f32),
    Axes(#[serde(deserialize_with = "exact")] [f32; 3]),
}

impl Default for Scale {
    fn default() -> Self {
        Scale::Uniform(1.0)
    }
}

/// `[[objects]]`: a shape, its material, its placement in the world and in the tree. Which of
/// the shape fields (`size` ... `file`) are required depends on `shape`; the loader rejects the
/// ones a shape does not use.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectTable {
    pub name: Option<String>,
    pub shape: ShapeKind,
    pub material: String,
    /// box: [x, y, z]; quad: [x, y] (mm).
    pub size: Option<Vec<f32>>,
    pub radius: Option<f32>,
    pub height: Option<f32>,
    pub segments: Option<u32>,
    /// lathe: (radius, z) points (mm).
    #[serde(default, deserialize_with = "exact_pairs")]
    pub profile: Option<Vec<[f32; 2]>>,
    /// teapot: tessellation steps per patch side.
    pub resolution: Option<u32>,
    /// mesh: OBJ or PLY path, relative to the scene file.
    pub file: Option<String>,
    #[serde(default)]
    #[serde(deserialize_with = "exact")]
    pub translate: [f32; 3],
    #[serde(default)]
    #[serde(deserialize_with = "exact")]
    pub rotate_deg: [f32; 3],
    #[serde(default)]
    pub scale: Scale,
    /// Use smooth (interpolated) normals where the shape or mesh has them.
    #[serde(default = "yes")]
    pub smooth: bool,
    pub tree: Option<TreeTable>,
}

fn yes() -> bool {
    true
}

/// The built-in shapes and meshes from files.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum ShapeKind {
    /// Axis-aligned box centred at the origin (`size`).
    Box,
    /// Rectangle in the xy plane centred at the origin, facing +z (`size` = [x, y]).
    Quad,
    /// Sphere about the origin (`radius`, `segments`).
    Sphere,
    /// Cylinder along z from 0 to `height`, with caps (`radius`, `height`, `segments`).
    Cylinder,
    /// A `profile` of (radius, z) points revolved about z (`segments`).
    Lathe,
    /// The Utah teapot from Newell's Bézier patches, `size` = [mm per patch unit], `resolution`.
    Teapot,
    /// A triangle mesh from an OBJ or PLY `file`.
    Mesh,
}

/// `[objects.tree]`: where the object sits in the tree (see `material::Placement`).
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TreeTable {
    /// How the object was made: "solid" (carved from one block), "veneer" (a slice per face) or
    /// "boards" (a floor `layout` of boards).
    #[serde(default)]
    pub cut: CutName,
    /// "object" (default) or "world": the space the placement reads points in.
    #[serde(default)]
    pub space: SpaceName,
    /// Board layout (cut = "boards"), e.g. { kind = "parquet", tile = 400, strip = 50 }.
    pub layout: Option<crate::wood::BoardLayout>,
    /// Where veneer slices and boards are cut from (cut = "veneer" / "boards").
    pub region: Option<crate::wood::TreeRegion>,
    /// Selects which boards / slices (cut = "veneer" / "boards").
    #[serde(default)]
    pub seed: u64,
    #[serde(default)]
    #[serde(deserialize_with = "exact")]
    pub origin: [f32; 3],
    #[serde(default = "default_axis")]
    #[serde(deserialize_with = "exact")]
    pub axis: [f32; 3],
    #[serde(default)]
    pub rotation_deg: f32,
    #[serde(default = "one")]
    pub scale: f32,
}

#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum CutName {
    #[default]
    Solid,
    Veneer,
    Boards,
}

#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum SpaceName {
    #[default]
    Object,
    World,
}

fn default_axis() -> [f32; 3] {
    [0.0, 0.0, 1.0]
}

/// `[sweep]`: the light-sweep setup. A light named `light` moves on an arc of radius `radius`
/// about `pivot`, turning about `axis`; angle 0 is straight above the pivot (+z), positive angles
/// turn by the right-hand rule about `axis`.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SweepTable {
    #[serde(default = "default_frames")]
    pub frames: u32,
    /// Arc from / to, degrees from the zenith, each in [-90, 90].
    #[serde(deserialize_with = "exact")]
    pub arc_deg: [f32; 2],
    /// Name of the light that moves (a point, spot or sphere light).
    pub light: String,
    #[serde(default)]
    #[serde(deserialize_with = "exact")]
    pub pivot: [f32; 3],
    /// Distance from the pivot to the light (mm).
    pub radius: f32,
    #[serde(default = "default_sweep_axis")]
    #[serde(deserialize_with = "exact")]
    pub axis: [f32; 3],
    /// Named image regions the sweep reports on (pixels, x0 < x1, y0 < y1, top-left origin).
    #[serde(default)]
    pub regions: Vec<SweepRegion>,
    /// Azimuths of the arcs (degrees about +z from the arc that `axis` defines): the light runs
    /// the whole arc once per azimuth, `frames` frames each (default: one arc, `[0]`). A fit of
    /// the fibre axis needs two or more (notes/fit.md).
    #[serde(default = "default_azimuths")]
    pub azimuths_deg: Vec<f32>,
    /// The measured board's plane, written to the sweep's manifest for `xylem fit`.
    pub board: Option<SweepBoard>,
}

/// `[sweep.board]`: the flat board face a fit measures (world mm): the centre of the face,
/// its x axis (image columns) and y axis (towards the image's top row), its size, and the index
/// of its smooth finish.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SweepBoard {
    #[serde(deserialize_with = "exact")]
    pub origin: [f32; 3],
    #[serde(default = "default_board_x")]
    #[serde(deserialize_with = "exact")]
    pub x_axis: [f32; 3],
    #[serde(default = "default_board_y")]
    #[serde(deserialize_with = "exact")]
    pub y_axis: [f32; 3],
    #[serde(deserialize_with = "exact")]
    pub size_mm: [f32; 2],
    #[serde(default = "default_eta")]
    pub eta: f32,
}

/// The most arcs (`[sweep] azimuths_deg` entries) a sweep may have.
pub const MAX_ARCS: usize = 8;

fn default_azimuths() -> Vec<f32> {
    vec![0.0]
}
fn default_board_x() -> [f32; 3] {
    [1.0, 0.0, 0.0]
}
fn default_board_y() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}

fn default_frames() -> u32 {
    48
}
fn default_sweep_axis() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}

/// One `[[sweep.regions]]` entry.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SweepRegion {
    pub name: String,
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}
