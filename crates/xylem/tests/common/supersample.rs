//! The point-evaluated wood averaged over a footprint, the reference of the footprint filter's
//! checks (`#[path = "common/supersample.rs"] mod supersample;`).

use xylem::math::Vec3;
use xylem::wood::{Needs, WoodVolume};

/// Colour only.
pub const COLOR: Needs = Needs {
    color: true,
    fibers: false,
    bump: false,
};

/// The unfiltered diffuse colour averaged over a `w` × `w` square spanned by the unit vectors
/// `u`, `v` around `c` (`n` × `n` midpoints): the supersampled footprint.
pub fn supersampled(vol: &WoodVolume, c: Vec3, (u, v): (Vec3, Vec3), w: f32, n: u32) -> Vec3 {
    let mut sum = Vec3::ZERO;
    for i in 0..n {
        for j in 0..n {
            let (a, b) = (
                ((i as f32 + 0.5) / n as f32 - 0.5) * w,
                ((j as f32 + 0.5) / n as f32 - 0.5) * w,
            );
            sum += vol.eval(c + a * u + b * v, COLOR).diffuse;
        }
    }
    sum / (n * n) as f32
}
