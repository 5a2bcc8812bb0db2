use super::bounded_diffuse;
use crate::bsdf::fiber_albedo::TABLE_MARGIN;
use crate::bsdf::WoodBsdfParams;
use glam::Vec3;
use std::f32::consts::FRAC_1_PI;

fn params(diffuse: Vec3, fiber_color: Vec3) -> WoodBsdfParams {
    WoodBsdfParams {
        diffuse,
        fiber_color,
        fiber_dir: Vec3::X,
        ray_dir: Vec3::Z,
        ray_mask: 0.0,
        highlight_width: 1e-3,
        eta: 1.5,
        roughness: 0.0,
    }
}

/// In-plane fibres with a sharp highlight reflect at most 1/π (notes/bsdf.md §2.1, C = 2 cos ψ),
/// so a pale maple keeps (1 − k_f/π)/ρ of its colour, not (1 − k_f)/ρ, in the same hue.
#[test]
fn leaves_room_for_what_the_lobe_reflects() {
    let (rho, kf) = (Vec3::new(0.9, 0.8, 0.6), Vec3::new(0.9, 0.85, 0.75));
    let b = bounded_diffuse(&params(rho, kf));
    let lobe = FRAC_1_PI * (1.0 + TABLE_MARGIN);
    let s = (1.0 - kf.x * lobe) / rho.x;
    assert!((b / rho - Vec3::splat(s)).abs().max_element() < 1e-4, "{b}");
    assert!((b + kf * lobe).max_element() <= 1.0 + 1e-4);
    // Colours that already fit are unchanged.
    let dark = Vec3::new(0.3, 0.2, 0.1);
    assert_eq!(bounded_diffuse(&params(dark, kf)), dark);
}

/// Ray fibres along the normal reflect every sharp highlight into the surface (the cone about
/// ψi = −ψr lies below it), so a full ray mask leaves the diffuse as it is.
#[test]
fn blends_the_ray_lobe_by_the_mask() {
    let (rho, kf) = (Vec3::splat(0.95), Vec3::ONE);
    let mut p = params(rho, kf);
    p.ray_mask = 1.0;
    assert!((bounded_diffuse(&p) - rho).abs().max_element() < 2e-3);
    p.ray_mask = 0.5;
    let half = bounded_diffuse(&p).x;
    let want = (1.0 - 0.5 * FRAC_1_PI * (1.0 + TABLE_MARGIN)) / 0.95;
    assert!((half / 0.95 - want.min(1.0)).abs() < 2e-3, "{half}");
}
