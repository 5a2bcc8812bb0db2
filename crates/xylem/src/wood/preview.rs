//! A quick look at a texel without a renderer: the diffuse colour plus the fibre highlight seen with
//! light and eye along one direction. Used by `xylem texture --preset` and `xylem preset cuts`.

use super::WoodTexel;
use glam::Vec3;

/// Preview colour of `texel` seen along unit `view` (e.g. the normal of a cut): a fibre at angle
/// ψ out of the plane ⟂ `view` reflects like the Gaussian longitudinal lobe of the fibre BSDF
/// (Marschner et al. 2005), ∝ exp(−ψ² / 2β²) with the texel's highlight width β, tinted by the
/// fibre colour — enough to show the figure of curly, quilted and interlocked woods in a flat
/// image. `shade_fibers = false` gives the plain diffuse colour.
pub fn preview_color(texel: &WoodTexel, view: Vec3, shade_fibers: bool) -> Vec3 {
    if !shade_fibers {
        return texel.diffuse;
    }
    let psi = crate::math::safe_asin(texel.fiber_dir.dot(view).abs());
    let beta = texel.highlight_width.max(1e-3);
    let lobe = (-psi * psi / (2.0 * beta * beta)).exp();
    0.8 * texel.diffuse + 0.4 * lobe * texel.fiber_color
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn highlight_only_for_fibres_in_the_plane() {
        let mut t = WoodTexel {
            fiber_dir: Vec3::X,
            ..Default::default()
        };
        let lit = preview_color(&t, Vec3::Z, true);
        t.fiber_dir = Vec3::Z;
        let end = preview_color(&t, Vec3::Z, true);
        assert!(lit.x > end.x + 0.1);
        assert_eq!(preview_color(&t, Vec3::Z, false), t.diffuse);
    }
}
