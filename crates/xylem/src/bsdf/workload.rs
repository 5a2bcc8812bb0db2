//! The fixed benchmark workload shared by `crates/xylem-lab/benches/bsdf.rs` and `xylem bench bsdf`, so both time
//! the same parameter sets, directions and random numbers.

use super::WoodBsdfParams;
use crate::math::{cosine_hemisphere, Pcg32};
use glam::{Vec2, Vec3};

/// A smooth finish, a rough finish and a ray-mask blend with dipping fibres.
pub fn cases() -> [(&'static str, WoodBsdfParams); 3] {
    let base = WoodBsdfParams::default();
    [
        ("smooth", base),
        (
            "rough",
            WoodBsdfParams {
                roughness: 0.3,
                ..base
            },
        ),
        (
            "ray_blend",
            WoodBsdfParams {
                ray_mask: 0.5,
                fiber_dir: Vec3::new(1.0, 0.0, -0.3).normalize(),
                ray_dir: Vec3::new(0.0, 0.8, -0.6),
                ..base
            },
        ),
    ]
}

/// Direction pairs (wo, wi) at which a BSDF is evaluated.
pub(crate) type DirectionPairs = Vec<(Vec3, Vec3)>;
/// Sample inputs (uc, u) of `Bsdf::sample`.
pub(crate) type SampleInputs = Vec<(f32, Vec2)>;

/// 1024 (wo, wi) pairs and 1024 (uc, u) sample inputs from a fixed seed.
pub fn inputs() -> (DirectionPairs, SampleInputs) {
    let mut rng = Pcg32::new(1, 0);
    let dirs = (0..1024)
        .map(|_| {
            (
                cosine_hemisphere(rng.next_vec2()),
                cosine_hemisphere(rng.next_vec2()),
            )
        })
        .collect();
    let us = (0..1024)
        .map(|_| (rng.next_f32(), rng.next_vec2()))
        .collect();
    (dirs, us)
}
