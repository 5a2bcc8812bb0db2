//! Evaluates the finished-wood BSDF in the plane of the fibre and prints f·cos θi: the fibre
//! highlight on its specular cone, over the diffuse floor.
//!
//! `cargo run --release --example eval_bsdf`

use xylem::bsdf::{Bsdf, WoodBsdf, WoodBsdfParams};
use xylem::math::Vec3;

fn main() -> Result<(), xylem::bsdf::BsdfError> {
    // Fibres along x lying in the surface, β = 8°, a smooth finish of index 1.5.
    let bsdf = WoodBsdf::new(WoodBsdfParams::default())?;
    let wo = Vec3::new(30f32.to_radians().sin(), 0.0, 30f32.to_radians().cos());
    println!("view 30° along the fibre; light in the fibre's plane:");
    println!("{:>8} {:>10} {:>10} {:>10}", "θi (°)", "R", "G", "B");
    for deg in (-80..=80).step_by(10) {
        let t = (deg as f32).to_radians();
        let wi = Vec3::new(t.sin(), 0.0, t.cos());
        let fc = bsdf.eval(wo, wi) * wi.z;
        println!("{deg:>8} {:>10.4} {:>10.4} {:>10.4}", fc.x, fc.y, fc.z);
    }
    Ok(())
}
