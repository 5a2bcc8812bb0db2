//! The procedural solid-wood model of Liu, Dong, Hašan and Marschner 2016 ("Simulating the
//! structure and texture of solid wood"): `WoodVolume::eval(p, needs) -> WoodTexel`.

mod board;
mod color;
mod error;
mod eyes;
mod features;
mod growth;
mod knots;
mod params;
mod preview;
mod volume;

pub use board::*;
pub use color::BeerColor;
pub use error::WoodError;
pub use eyes::{EyeSample, Eyes};
pub use growth::{RingExpTable, SmoothRectangleWave, SmoothTriangleWave};
pub use knots::{KnotSample, Knots};
pub use params::*;
pub use preview::preview_color;
pub use volume::{Footprint, WoodVolume};

use glam::Vec3;

/// Names of the built-in species presets (`scenes/presets/<name>.toml`).
pub const PRESET_NAMES: [&str; 11] = [
    "african_mahogany",
    "curly_maple",
    "padauk",
    "yellowheart",
    "red_oak",
    "quartersawn_white_oak",
    "walnut",
    "cherry",
    "birdseye_maple",
    "quilted_maple",
    "knotty_pine",
];

/// Distance from the pith (mm) of the face of every showcase board: the gallery's, `validate
/// appearance`'s preset boards. Far enough out (about a 25 cm log) that a flat-sawn face shows
/// arches, not the pith.
pub const SHOWCASE_PITH_DISTANCE_MM: f32 = 120.0;

/// Slope of every showcase board's face to the pith along the grain (degrees; `SawnCut::slope_deg`):
/// boards are sawn along the bark of a tapering, not quite straight log, so a flat-sawn face rises
/// through the rings along its length and shows cathedral arches (parallel to the pith it shows
/// only straight stripes, mirror-symmetric about its centre line).
pub const SHOWCASE_SLOPE_DEG: f32 = 3.0;

/// Presets whose figure shows on a flat-sawn face (tangential to the rings): quilt and birdseye,
/// the cathedral arches of oak, walnut and cherry, round knots; yellowheart as it is commonly sold
/// (plain-sawn lumber). The rest show on a quartersawn face: the ribbon stripe of interlocked grain
/// (mahogany, padauk), oak ray fleck, curl across the grain (Hoadley, *Understanding Wood*, 2000,
/// ch. 11).
const FLAT_SAWN_SHOWCASE: [&str; 7] = [
    "quilted_maple",
    "birdseye_maple",
    "red_oak",
    "walnut",
    "cherry",
    "knotty_pine",
    "yellowheart",
];

/// The ring angle (degrees: 0 flat-sawn, 90 quartersawn) of the face on which preset `name`'s
/// figure shows (flat-sawn for the presets listed in `FLAT_SAWN_SHOWCASE`); with [`SHOWCASE_PITH_DISTANCE_MM`] it is the cut of
/// every showcase board (`material::SawnCut`).
pub fn showcase_ring_angle_deg(name: &str) -> f32 {
    if FLAT_SAWN_SHOWCASE.contains(&name) {
        0.0
    } else {
        90.0
    }
}

/// The preset files, embedded so lookup works from any directory.
const PRESET_FILES: [&str; 11] = [
    include_str!("../../../../scenes/presets/african_mahogany.toml"),
    include_str!("../../../../scenes/presets/curly_maple.toml"),
    include_str!("../../../../scenes/presets/padauk.toml"),
    include_str!("../../../../scenes/presets/yellowheart.toml"),
    include_str!("../../../../scenes/presets/red_oak.toml"),
    include_str!("../../../../scenes/presets/quartersawn_white_oak.toml"),
    include_str!("../../../../scenes/presets/walnut.toml"),
    include_str!("../../../../scenes/presets/cherry.toml"),
    include_str!("../../../../scenes/presets/birdseye_maple.toml"),
    include_str!("../../../../scenes/presets/quilted_maple.toml"),
    include_str!("../../../../scenes/presets/knotty_pine.toml"),
];

/// `n` random points where boards come from: 30–230 mm from the pith, 0–1000 mm along it. Shared
/// by `xylem bench wood` and `crates/xylem-lab/benches/wood.rs` so both time the same texels.
pub fn sample_points(n: usize, seed: u64) -> Vec<Vec3> {
    let mut rng = crate::math::Pcg32::new(seed, 0);
    (0..n)
        .map(|_| {
            let r = 30.0 + 200.0 * rng.next_f32();
            let a = std::f32::consts::TAU * rng.next_f32();
            Vec3::new(r * a.cos(), r * a.sin(), 1000.0 * rng.next_f32())
        })
        .collect()
}

/// The TOML text of a built-in preset.
pub fn preset_text(name: &str) -> Result<&'static str, WoodError> {
    PRESET_NAMES
        .iter()
        .position(|n| *n == name)
        .map(|i| PRESET_FILES[i])
        .ok_or_else(|| WoodError::UnknownPreset {
            name: name.to_string(),
            valid: PRESET_NAMES.join(", "),
        })
}

/// The parameters of a built-in preset by name; an unknown name lists the valid ones.
pub fn preset(name: &str) -> Result<WoodParams, WoodError> {
    let text = preset_text(name)?;
    WoodParams::from_toml_str(text, &format!("scenes/presets/{name}.toml"))
}

/// What a caller needs from a wood lookup; the model skips the work for anything not asked for
/// ("model only what a scene requires").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Needs {
    /// Diffuse and fibre colour (and growth time).
    pub color: bool,
    /// Fibre and ray-fibre directions, ray mask and highlight width (what the fibre lobe needs).
    pub fibers: bool,
    /// Bump height and gradient from the pore mask.
    pub bump: bool,
}

impl Needs {
    /// Colour only (slices, previews).
    pub const COLOR: Needs = Needs {
        color: true,
        fibers: false,
        bump: false,
    };
    /// Colour and the fibre lobe's inputs, no bump.
    pub const COLOR_FIBERS: Needs = Needs {
        color: true,
        fibers: true,
        bump: false,
    };
    /// Everything, for rendering with pore bump.
    pub const ALL: Needs = Needs {
        color: true,
        fibers: true,
        bump: true,
    };
}

/// Everything the BSDF and the renderer need at one point of the tree. Directions and the bump
/// gradient are in tree space (millimetres, pith along z).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WoodTexel {
    /// Diffuse colour (Beer's law, linear RGB).
    pub diffuse: Vec3,
    /// Fibre highlight colour (linear RGB).
    pub fiber_color: Vec3,
    /// Longitudinal fibre direction (unit).
    pub fiber_dir: Vec3,
    /// Ray-fibre direction (unit, radial).
    pub ray_dir: Vec3,
    /// Ray-fibre BSDF blend weight in [0, 1].
    pub ray_mask: f32,
    /// Pore mask in [0, 1].
    pub pore_mask: f32,
    /// Bump height (mm; ≤ 0 inside pores).
    pub bump: f32,
    /// Gradient of `bump` with respect to tree-space position.
    pub bump_grad: Vec3,
    /// Fibre highlight width β, radians.
    pub highlight_width: f32,
    /// Growth time (years from the pith) for the AOV.
    pub growth_time: f32,
}

impl Default for WoodTexel {
    fn default() -> Self {
        WoodTexel {
            diffuse: Vec3::splat(0.5),
            fiber_color: Vec3::splat(0.5),
            fiber_dir: Vec3::Z,
            ray_dir: Vec3::X,
            ray_mask: 0.0,
            pore_mask: 0.0,
            bump: 0.0,
            bump_grad: Vec3::ZERO,
            highlight_width: 8.0_f32.to_radians(),
            growth_time: 0.0,
        }
    }
}
