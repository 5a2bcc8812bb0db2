//! Presets stripped to one feature, for the filter checks
//! (`#[path = "common/bare.rs"] mod bare;`).

use xylem::wood::{preset, WoodParams};

/// Preset `name` with its pores, rays, cell texture, eyes, knots, fibre wander and distortions
/// off: the rings (and the growth variation and interlock that set them) alone.
pub fn rings_only(name: &str) -> WoodParams {
    let mut p = preset(name).unwrap();
    p.pores = None;
    p.rays = None;
    p.texture = None;
    p.eyes = None;
    p.knots = None;
    p.fibre_wander = None;
    p.distortion.radial = None;
    p.distortion.tangential = None;
    p.distortion.longitudinal = None;
    p
}
