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
    /// `[render]`: image size, sampling, filter (defaults when the table is absent).
    #[serde(default)]
    pub render: RenderTable,
    /// `[camera]` (required).
    pub camera: CameraTable,
    /// `[[lights]]`, any number; lights do not cast shadows or block rays.
    #[serde(default)]
    pub lights: Vec<LightTable>,
    /// `[materials.NAME]`, keyed by the name objects refer to.
    #[serde(default)]
    pub materials: BTreeMap<String, MaterialTable>,
    /// `[[objects]]`; a scene needs at least one.
    #[serde(default)]
    pub objects: Vec<ObjectTable>,
    /// Light-sweep setup (used by `xylem sweep`).
    pub sweep: Option<SweepTable>,
    /// `[quality]`: the speed/accuracy preset and wood-model knobs (none: the full model).
    pub quality: Option<QualityTable>,
    /// `[expect]`: what the scene's render must show, as checks a validation lab runs on it
    /// (`xylem gallery`; the vocabulary is `xylem_lab::scenes::Expectations`). The renderer
    /// carries the table through unread.
    pub expect: Option<toml::Table>,
}

/// `[quality]`: what the scene trades for speed, as `--quality` does on the command line
/// (validation/TRADEOFF.md). The preset comes first, then the knobs named here, then
/// `[render] spp` and `[render] footprint_filter` where they are given.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct QualityTable {
    /// `draft`, `default` or `final`: 4, 16 or 64 spp, the exact distortion Jacobian and the
    /// footprint filter.
    pub preset: Option<crate::scene::quality::Quality>,
    /// Distortion Jacobian: `simplified` (Liu et al. 2016 eq. 22) or `exact`.
    pub jacobian: Option<JacobianName>,
    /// Keep the wood's pores and rays (false drops them: "model only what the scene needs").
    pub pores_and_rays: Option<bool>,
    /// Keep at most this many bands of every multiband distortion noise, 1 to 16.
    pub max_noise_bands: Option<u32>,
}

/// `[quality] jacobian`.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum JacobianName {
    /// Liu et al. 2016 eq. 22 (the full model's default).
    Simplified,
    /// The exact derivative (the quality presets').
    Exact,
}

/// `[render]`: image size and sampling.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RenderTable {
    /// Image width in pixels, 1–16384 (default 512; `--res` overrides).
    pub width: u32,
    /// Image height in pixels, 1–16384 (default 512; `--res` overrides).
    pub height: u32,
    /// Samples per pixel, 1–1000000 (default: `[quality] preset`'s, else 16; `--spp` overrides).
    pub spp: Option<u32>,
    /// Direct lighting only (default) or path tracing.
    pub integrator: IntegratorName,
    /// Path tracing: most bounces, 1–1000 (default 8).
    pub max_depth: u32,
    /// Random seed (default 0; `--seed` overrides): same seed, same image on any thread count.
    pub seed: u64,
    /// PNG exposure in stops.
    pub exposure: f32,
    /// Pixel reconstruction filter (default gaussian).
    pub filter: FilterName,
    /// Filter radius in pixels (box: half-width).
    pub filter_radius: Option<f32>,
    /// Band-limit wood by the pixel footprint (default true; false point-samples it, as
    /// before issue 28; `xylem render --footprint-filter` overrides).
    pub footprint_filter: bool,
    /// `"adaptive"` (default: a pilot, then the rest of the samples where the pixels are
    /// noisy) or `"uniform"` (spp in every pixel); `xylem render --sampling` overrides.
    pub sampling: crate::render::Sampling,
}

impl Default for RenderTable {
    fn default() -> Self {
        RenderTable {
            width: 512,
            height: 512,
            spp: None,
            integrator: IntegratorName::Direct,
            max_depth: 8,
            seed: 0,
            exposure: 0.0,
            filter: FilterName::Gaussian,
            filter_radius: None,
            footprint_filter: true,
            sampling: crate::render::Sampling::Adaptive,
        }
    }
}

/// `[render] integrator`.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum IntegratorName {
    /// Direct lighting only.
    Direct,
    /// Path tracing: next-event estimation + MIS + Russian roulette, up to `max_depth` bounces.
    Path,
}

/// `[render] filter`: the pixel reconstruction filter.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum FilterName {
    /// Box of half-width `filter_radius` (default 0.5 px).
    Box,
    /// Tent of radius `filter_radius` (default 1 px).
    Tent,
    /// Gaussian with σ = `filter_radius` / 3 (default radius 1.5 px).
    Gaussian,
}

/// `[camera] projection`.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum ProjectionName {
    /// Pinhole or thin-lens perspective with vertical field of view `fov_deg`.
    #[default]
    Perspective,
    /// Parallel projection with film `width` (mm).
    Orthographic,
}

/// `[camera]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraTable {
    /// Perspective (default) or orthographic.
    #[serde(default)]
    pub projection: ProjectionName,
    /// Camera position (mm, finite).
    #[serde(deserialize_with = "exact")]
    pub eye: [f32; 3],
    /// Point at the image centre (mm, ≠ `eye`).
    #[serde(deserialize_with = "exact")]
    pub target: [f32; 3],
    /// Image-up direction, not parallel to the view (default [0, 0, 1]).
    #[serde(default = "default_up")]
    #[serde(deserialize_with = "exact")]
    pub up: [f32; 3],
    /// Perspective only (default [`DEFAULT_FOV_DEG`]); `None` when the file does not give it.
    pub fov_deg: Option<f32>,
    /// Perspective: thin-lens aperture radius (mm, 0–1e6; 0 = pinhole, default).
    #[serde(default)]
    pub lens_radius: f32,
    /// Perspective: distance of the plane in focus (mm, 0.001–1e9; default |target − eye|).
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

/// `[[lights]]`, one table per light, chosen by `type`; ranges and defaults in
/// [`fields::LIGHTS`](super::fields::LIGHTS).
#[derive(Debug, Clone, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum LightTable {
    /// Point light at `position`.
    Point {
        /// Unique name (the sweep moves a light by name).
        name: Option<String>,
        /// Position (mm).
        #[serde(deserialize_with = "exact")]
        position: [f32; 3],
        /// Radiant intensity (W/sr).
        intensity: f32,
        /// Multiplies the strength.
        #[serde(default = "defaults::light_color")]
        #[serde(deserialize_with = "exact")]
        color: [f32; 3],
    },
    /// Spot light at `position` pointing at `target`, with a smooth-edged cone.
    Spot {
        /// Unique name (the sweep moves a light by name).
        name: Option<String>,
        /// Position (mm).
        #[serde(deserialize_with = "exact")]
        position: [f32; 3],
        /// The point the cone's axis passes through (mm).
        #[serde(deserialize_with = "exact")]
        target: [f32; 3],
        /// Radiant intensity on the axis (W/sr).
        intensity: f32,
        /// Multiplies the strength.
        #[serde(default = "defaults::light_color")]
        #[serde(deserialize_with = "exact")]
        color: [f32; 3],
        /// Half-angle of the cone (degrees).
        cone_deg: f32,
        /// Width of the smooth edge inside the cone (degrees, at most `cone_deg`).
        #[serde(default)]
        falloff_deg: f32,
    },
    /// Distant (directional) light, like the sun.
    Distant {
        /// Unique name.
        name: Option<String>,
        /// Direction towards the light.
        #[serde(deserialize_with = "exact")]
        direction: [f32; 3],
        /// Irradiance on a surface facing the light (W/mm²).
        irradiance: f32,
        /// Multiplies the strength.
        #[serde(default = "defaults::light_color")]
        #[serde(deserialize_with = "exact")]
        color: [f32; 3],
    },
    /// Parallelogram area light; emits to the side of `edge_u × edge_v`.
    Rect {
        /// Unique name.
        name: Option<String>,
        /// One corner (mm).
        #[serde(deserialize_with = "exact")]
        corner: [f32; 3],
        /// First edge from `corner` (mm).
        #[serde(deserialize_with = "exact")]
        edge_u: [f32; 3],
        /// Second edge from `corner` (mm); the edges must span a non-zero area.
        #[serde(deserialize_with = "exact")]
        edge_v: [f32; 3],
        /// Emitted radiance (W/(sr·mm²)).
        radiance: f32,
        /// Multiplies the strength.
        #[serde(default = "defaults::light_color")]
        #[serde(deserialize_with = "exact")]
        color: [f32; 3],
    },
    /// Spherical area light.
    Sphere {
        /// Unique name (the sweep moves a light by name).
        name: Option<String>,
        /// Centre (mm).
        #[serde(deserialize_with = "exact")]
        center: [f32; 3],
        /// Radius (mm).
        radius: f32,
        /// Emitted radiance (W/(sr·mm²)).
        radiance: f32,
        /// Multiplies the strength.
        #[serde(default = "defaults::light_color")]
        #[serde(deserialize_with = "exact")]
        color: [f32; 3],
    },
    /// Light from infinitely far away in every direction, constant or from a lat-long map.
    Environment {
        /// Unique name.
        name: Option<String>,
        /// Radiance scale.
        #[serde(default = "defaults::env_radiance")]
        radiance: f32,
        /// Multiplies the strength.
        #[serde(default = "defaults::light_color")]
        #[serde(deserialize_with = "exact")]
        color: [f32; 3],
        /// Optional lat-long EXR map (z up, u = φ/2π from +x, v = θ/π from +z); path relative
        /// to the scene file.
        map: Option<String>,
        /// Turn of the map about z (degrees).
        #[serde(default)]
        rotate_deg: f32,
    },
}

impl LightTable {
    /// The light's `name`, if it has one.
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

/// `[materials.NAME]`, chosen by `type`; ranges and defaults in
/// [`fields::MATERIALS`](super::fields::MATERIALS).
#[derive(Debug, Clone, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum MaterialTable {
    /// Lambertian diffuse surface.
    Lambertian {
        /// Reflectance.
        #[serde(deserialize_with = "exact")]
        albedo: [f32; 3],
    },
    /// The finished-wood BSDF with constant parameters; directions in object space.
    Fiber {
        /// Diffuse colour.
        #[serde(deserialize_with = "exact")]
        diffuse: [f32; 3],
        /// Fibre highlight colour.
        #[serde(deserialize_with = "exact")]
        fiber_color: [f32; 3],
        /// Fibre direction (object space).
        #[serde(deserialize_with = "exact")]
        fiber_dir: [f32; 3],
        /// Ray-cell direction (object space).
        #[serde(default = "defaults::ray_dir")]
        #[serde(deserialize_with = "exact")]
        ray_dir: [f32; 3],
        /// How much of the surface is ray cells.
        #[serde(default)]
        ray_mask: f32,
        /// Fibre highlight width β (degrees).
        #[serde(default = "defaults::fiber_width")]
        highlight_width_deg: f32,
        /// Refractive index of the finish.
        #[serde(default = "defaults::eta")]
        eta: f32,
        /// GGX roughness of the finish.
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
        /// Refractive index of the finish.
        #[serde(default = "defaults::eta")]
        eta: f32,
        /// GGX roughness of the finish.
        #[serde(default)]
        roughness: f32,
        /// Pore bump strength (0 = off, 1 = the preset's pore depth); absent: the preset's
        /// [`default_bump`](crate::wood::WoodParams::default_bump), on for open grain.
        bump: Option<f32>,
    },
    /// A board measured by Marschner et al. 2005: per-texel BSDF parameters from image maps (in
    /// the encoding of data/marschner2005/) on one face of the object. Paths relative to the scene.
    Measured {
        /// Diffuse colour map (8-bit PNG, relative to the scene file).
        diffuse: String,
        /// Fibre colour map (8-bit PNG, same size as `diffuse`).
        fiber_color: String,
        /// Fibre axis map (8-bit PNG; axis = 2v/255 − 1 in the frame x = columns,
        /// y = towards the top row, z = the normal).
        fiber_axis: String,
        /// Optional β map (β = 90° · v/255); else `highlight_width_deg` everywhere.
        highlight_width: Option<String>,
        /// Highlight width β everywhere (degrees) when there is no β map.
        highlight_width_deg: Option<f32>,
        /// The published lobe's k_f per stored unit (notes/measured.md).
        #[serde(default = "defaults::fiber_color_scale")]
        fiber_color_scale: f32,
        /// "linear" (default) or "srgb".
        color_space: Option<String>,
        /// [width, height] of the image on the face (object-space mm).
        #[serde(deserialize_with = "exact")]
        size_mm: [f32; 2],
        /// "+z" (default), "-z", "+x", "-x", "+y" or "-y".
        face: Option<String>,
        /// Refractive index of the finish.
        #[serde(default = "defaults::eta")]
        eta: f32,
        /// GGX roughness of the finish.
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
    /// Perfect mirror.
    Mirror {
        /// Reflectance.
        #[serde(default = "defaults::mirror_reflectance")]
        #[serde(deserialize_with = "exact")]
        reflectance: [f32; 3],
    },
    /// Smooth dielectric (refracting) surface.
    Glass {
        /// Refractive index.
        #[serde(default = "defaults::glass_eta")]
        eta: f32,
        /// Transmission tint.
        #[serde(default = "defaults::glass_tint")]
        #[serde(deserialize_with = "exact")]
        tint: [f32; 3],
    },
}

/// The serde defaults of the light and material tables, read from [`fields`](super::fields).
mod defaults {
    use crate::scene::fields::*;
    pub fn light_color() -> [f32; 3] {
        LIGHT_COLOR.default_triple()
    }
    pub fn env_radiance() -> f32 {
        ENV_RADIANCE.default_number()
    }
    pub fn ray_dir() -> [f32; 3] {
        RAY_DIR.default_triple()
    }
    pub fn fiber_width() -> f32 {
        FIBER_WIDTH.default_number()
    }
    pub fn eta() -> f32 {
        ETA.default_number()
    }
    pub fn fiber_color_scale() -> f32 {
        FIBER_COLOR_SCALE.default_number()
    }
    pub fn mirror_reflectance() -> [f32; 3] {
        MIRROR_REFLECTANCE.default_triple()
    }
    pub fn glass_eta() -> f32 {
        GLASS_ETA.default_number()
    }
    pub fn glass_tint() -> [f32; 3] {
        GLASS_TINT.default_triple()
    }
}

/// A uniform or per-axis scale.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(untagged)]
pub enum Scale {
    /// The same factor on every axis.
    Uniform(f32),
    /// Per-axis [x, y, z] factors.
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
    /// Optional label.
    pub name: Option<String>,
    /// Which shape: box, quad, sphere, cylinder, lathe, teapot or mesh.
    pub shape: ShapeKind,
    /// A name from `[materials]` (must exist).
    pub material: String,
    /// box: [x, y, z]; quad: [x, y] (mm).
    pub size: Option<Vec<f32>>,
    /// sphere (about the origin), cylinder: radius (mm, 1e-6–1e9).
    pub radius: Option<f32>,
    /// cylinder: height along z from 0 (mm, 1e-6–1e9).
    pub height: Option<f32>,
    /// sphere, cylinder, lathe: divisions around z (3–4096, default 64).
    pub segments: Option<u32>,
    /// lathe: (radius, z) points (mm).
    #[serde(default, deserialize_with = "exact_pairs")]
    pub profile: Option<Vec<[f32; 2]>>,
    /// teapot: tessellation steps per patch side.
    pub resolution: Option<u32>,
    /// mesh: OBJ or PLY path, relative to the scene file.
    pub file: Option<String>,
    /// Translation (mm, default [0, 0, 0]).
    #[serde(default)]
    #[serde(deserialize_with = "exact")]
    pub translate: [f32; 3],
    /// Rotation (degrees) about x, then y, then z (default [0, 0, 0]).
    #[serde(default)]
    #[serde(deserialize_with = "exact")]
    pub rotate_deg: [f32; 3],
    /// A number or [x, y, z] (non-zero, default 1).
    #[serde(default)]
    pub scale: Scale,
    /// Use smooth (interpolated) normals where the shape or mesh has them.
    #[serde(default = "yes")]
    pub smooth: bool,
    /// Where the object sits in the tree (default: carved at the pith, fibres along z).
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
    /// solid: tree point (mm) where the object's origin lies; its distance from the z axis is
    /// the distance from the pith (default [0, 0, 0]).
    #[serde(default)]
    #[serde(deserialize_with = "exact")]
    pub origin: [f32; 3],
    /// solid: the object direction the fibres run along, mapped to the pith direction
    /// (default [0, 0, 1]).
    #[serde(default = "default_axis")]
    #[serde(deserialize_with = "exact")]
    pub axis: [f32; 3],
    /// solid: turn about the pith (degrees, default 0): flat- vs quarter-sawn.
    #[serde(default)]
    pub rotation_deg: f32,
    /// solid: the cut stated physically instead of `origin` and `rotation_deg`, e.g.
    /// `{ pith_distance = 120.0, ring_angle_deg = 0.0, face_point = [0.0, 0.0, 9.0] }`
    /// (flat-sawn 0°, quartersawn 90°; `material::SawnCut`).
    pub sawn: Option<crate::material::SawnCut>,
    /// Tree mm per object unit (0.000001–1e6, default 1).
    #[serde(default = "one")]
    pub scale: f32,
}

/// `tree.cut`: how the object was made from the tree.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum CutName {
    /// Carved from one block.
    #[default]
    Solid,
    /// One flat-sawn slice per face (Liu 2016 Fig. 18).
    Veneer,
    /// A floor `layout` of boards, each cut from its own place.
    Boards,
}

/// `tree.space`: the space placement points are read in.
#[derive(Debug, Clone, Copy, Deserialize, PartialEq, Eq, Default)]
#[serde(rename_all = "snake_case")]
pub enum SpaceName {
    /// Object space, before `translate/rotate/scale`: the wood moves with the object.
    #[default]
    Object,
    /// World space: several objects share one block.
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
    /// Number of frames per arc (1–100000, default 48).
    #[serde(default = "default_frames")]
    pub frames: u32,
    /// Arc from / to, degrees from the zenith, each in [-90, 90].
    #[serde(deserialize_with = "exact")]
    pub arc_deg: [f32; 2],
    /// Name of the light that moves (a point, spot or sphere light).
    pub light: String,
    /// Centre of the arc (mm, default [0, 0, 0]).
    #[serde(default)]
    #[serde(deserialize_with = "exact")]
    pub pivot: [f32; 3],
    /// Distance from the pivot to the light (mm).
    pub radius: f32,
    /// The arc turns about this axis through the pivot, right-hand rule (default [0, 1, 0]).
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
    /// Centre of the face (world mm).
    #[serde(deserialize_with = "exact")]
    pub origin: [f32; 3],
    /// Direction of the image columns (default [1, 0, 0]).
    #[serde(default = "default_board_x")]
    #[serde(deserialize_with = "exact")]
    pub x_axis: [f32; 3],
    /// Direction towards the image's top row (default [0, 1, 0]), ⟂ `x_axis`.
    #[serde(default = "default_board_y")]
    #[serde(deserialize_with = "exact")]
    pub y_axis: [f32; 3],
    /// [width, height] of the face (mm).
    #[serde(deserialize_with = "exact")]
    pub size_mm: [f32; 2],
    /// Refractive index of the finish (1–4, default 1.5); must match the board's material.
    #[serde(default = "defaults::eta")]
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
    /// Region name used in the report.
    pub name: String,
    /// Left edge (pixels, inclusive).
    pub x0: u32,
    /// Top edge (pixels, inclusive; top-left origin).
    pub y0: u32,
    /// Right edge (pixels, exclusive; x0 < x1 ≤ width).
    pub x1: u32,
    /// Bottom edge (pixels, exclusive; y0 < y1 ≤ height).
    pub y1: u32,
}
