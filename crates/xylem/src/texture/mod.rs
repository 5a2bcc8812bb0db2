//! Classic procedural solid textures behind one small trait, constructed by name with checked
//! parameters (the renderer's scene materials and `xylem texture` both go through [`by_name`]).
//!
//! | name | what | source |
//! | --- | --- | --- |
//! | `marble` | sine bands ½(1 + sin(ω x + γ T)) with turbulence, smooth threshold, ramp | Perlin 1985 |
//! | `slab_marble` | white / grey / black slabs perturbed by turbulence | HyperGraph notes |
//! | `ring_wood` | concentric cylinders, tilted axis, angular wobble with twist | HyperGraph notes |
//! | `log_wood` | ring phase f(r + α r²), warped radius, fBm grain, tint | course report (seeds/000) |
//! | `stone` | Worley cells, F2 − F1 cracks, layered noise | Worley 1996 |
//! | `clouds` | warped fBm with cover threshold; `time` drifts the warp | Quilez, domain warping |
//! | `rust` | aggressively warped fBm, colour stops of oxide over steel; `time` drifts the warp | "Procedural Textures: wood, marble and beyond" |
//! | `fabric` | plain weave: sine thread profiles, warp and weft on top by turns | the same article |
//! | `worley`, `value`, `gradient`, `fbm`, `warp`, `sparse_convolution` | views of the raw noises | see `noise` |
//!
//! Points are in millimetres; colours are linear RGB. Every texture is a pure function of the
//! point and its parameters (including `seed` where it has noise).

mod clouds;
mod fabric;
mod marble;
mod params;
mod ramp;
mod rings;
mod rust;
mod slice;
mod stone;
mod views;

pub use params::{ParamSpec, TextureError, Values};
pub use ramp::{smoothstep, Ramp};
pub use slice::{first_non_finite, Plane, Slice, DEFAULT_SLICE_SAMPLES, MAX_SLICE_SAMPLES};

use crate::noise::Basis;
use glam::Vec3;
use std::collections::BTreeMap;

/// A solid texture: linear RGB colour at a point (mm).
pub trait SolidTexture: Send + Sync {
    /// Linear RGB colour at point `p` (mm).
    fn eval(&self, p: Vec3) -> Vec3;

    /// [`SolidTexture::eval`] at every point of `points`, written to `out` (same length).
    /// Textures built on a batch noise call (`gradient3_many`, `Fractal::eval_many`) override it
    /// with the same values, faster; the rest evaluate point by point.
    fn eval_many(&self, points: &[Vec3], out: &mut [Vec3]) {
        for (p, o) in points.iter().zip(out) {
            *o = self.eval(*p);
        }
    }
}

/// The texture names [`by_name`] accepts.
pub const NAMES: [&str; 14] = [
    "marble",
    "slab_marble",
    "ring_wood",
    "log_wood",
    "stone",
    "clouds",
    "rust",
    "fabric",
    "worley",
    "value",
    "gradient",
    "fbm",
    "warp",
    "sparse_convolution",
];

/// The parameters texture `name` accepts (with defaults and ranges), or `None` for an unknown
/// name.
pub fn params(name: &str) -> Option<&'static [ParamSpec]> {
    Some(match name {
        "marble" => marble::MARBLE_PARAMS,
        "slab_marble" => marble::SLAB_PARAMS,
        "ring_wood" => rings::RING_PARAMS,
        "log_wood" => rings::LOG_PARAMS,
        "stone" => stone::STONE_PARAMS,
        "clouds" => clouds::CLOUD_PARAMS,
        "rust" => rust::RUST_PARAMS,
        "fabric" => fabric::FABRIC_PARAMS,
        "worley" => views::WORLEY_PARAMS,
        "value" | "gradient" => views::LATTICE_PARAMS,
        "fbm" => views::FBM_PARAMS,
        "warp" => views::WARP_PARAMS,
        "sparse_convolution" => views::SPARSE_PARAMS,
        _ => return None,
    })
}

/// Builds texture `name` from `params` (missing parameters take their defaults). Errors: an
/// unknown name (listing the valid ones), an unknown parameter (naming the allowed ones), a value
/// out of range (with the range).
pub fn by_name(
    name: &str,
    params: &BTreeMap<String, f32>,
) -> Result<Box<dyn SolidTexture>, TextureError> {
    let spec = self::params(name).ok_or_else(|| TextureError::UnknownTexture {
        name: name.to_string(),
        valid: NAMES.join(", "),
    })?;
    let v = Values::resolve(name, spec, params)?;
    Ok(match name {
        "marble" => Box::new(marble::Marble::new(&v)),
        "slab_marble" => Box::new(marble::SlabMarble::new(&v)),
        "ring_wood" => Box::new(rings::RingWood::new(&v)),
        "log_wood" => Box::new(rings::LogWood::new(&v)),
        "stone" => Box::new(stone::Stone::new(&v)),
        "clouds" => Box::new(clouds::Clouds::new(&v)),
        "rust" => Box::new(rust::Rust::new(&v)),
        "fabric" => Box::new(fabric::Fabric::new(&v)),
        "worley" => Box::new(views::WorleyView::new(&v)),
        "value" => Box::new(views::LatticeView::new(&v, Basis::Value)),
        "gradient" => Box::new(views::LatticeView::new(&v, Basis::Gradient)),
        "fbm" => Box::new(views::FbmView::new(&v)),
        "warp" => Box::new(views::WarpView::new(&v)),
        "sparse_convolution" => {
            let view = views::SparseView::new(&v);
            view.noise()
                .validate()
                .map_err(|source| TextureError::Noise {
                    texture: name.to_string(),
                    source,
                })?;
            Box::new(view)
        }
        _ => unreachable!("every name in NAMES has a parameter table"),
    })
}

/// The textures with a `time` parameter (animated by drifting their warp coordinates).
pub const ANIMATED: [&str; 2] = ["clouds", "rust"];

/// How far the warp coordinates have drifted at the texture's `time`: `flow · time` noise units
/// along a fixed oblique direction (so no axis is special).
fn drift(v: &Values) -> Vec3 {
    Vec3::new(1.0, 0.6, 0.3).normalize() * (v.get("flow") * v.get("time"))
}
