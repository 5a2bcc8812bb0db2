//! Beer's-law colour (Liu et al. 2016 §6.1.8, eq. 25): c = exp(−σ (ℓ₀ + ℓ_g g + ℓ_p p)).

use super::params::ColorParams;
use glam::Vec3;

/// Absorbances fitted to the earlywood (g = 0) and latewood (g = 1) colours, as the paper fits
/// them to photograph percentiles: σℓ₀ = −ln c_early, σℓ_g = ln c_early − ln c_late; pore, ray and
/// knot path lengths are in units of the latewood absorbance σ(ℓ₀ + ℓ_g) = −ln c_late.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BeerColor {
    base: Vec3,
    ring: Vec3,
    late: Vec3,
    pore_path: f32,
    ray_path: f32,
    fiber_saturation: Vec3,
}

impl BeerColor {
    /// Fits the absorbances to the preset's earlywood and latewood colours.
    pub fn new(p: &ColorParams) -> Self {
        let early = -Vec3::from(p.earlywood).ln();
        let late = -Vec3::from(p.latewood).ln();
        BeerColor {
            base: early,
            ring: late - early,
            late,
            pore_path: p.pore_path,
            ray_path: p.ray_path,
            fiber_saturation: Vec3::from(p.fiber_saturation),
        }
    }

    /// Absorbance σℓ for ring value g, pore mask p, ray mask `ray` and extra path `extra`
    /// (latewood units, e.g. knot wood).
    #[inline(always)]
    pub(crate) fn absorbance(&self, g: f32, pore: f32, ray: f32, extra: f32) -> Vec3 {
        let channel = |ch| self.channel_absorbance(ch, g, pore, ray, extra);
        Vec3::new(channel(0), channel(1), channel(2))
    }

    /// (diffuse, fibre) colours of an absorbance; the fibre colour uses the absorbance scaled per
    /// channel by the fibre saturation (App. A.3; below 1: less saturated than the diffuse). Clamped to [0, 1] (a negative path may lighten).
    #[inline(always)]
    pub(crate) fn colors(&self, absorbance: Vec3) -> (Vec3, Vec3) {
        let (r, g, b) = (
            self.channel_colors(0, absorbance.x),
            self.channel_colors(1, absorbance.y),
            self.channel_colors(2, absorbance.z),
        );
        (Vec3::new(r.0, g.0, b.0), Vec3::new(r.1, g.1, b.1))
    }

    /// The absorbance per unit ring value g, k = σℓ_g, of the diffuse and of the fibre colour
    /// (× the fibre saturation).
    pub(crate) fn ring_scales(&self) -> [Vec3; 2] {
        [self.ring, self.ring * self.fiber_saturation]
    }

    /// The absorbance of a full pore mask and of a full ray mask (mask 1), each for the diffuse
    /// and the fibre colour: `[pore, ray]`, each `[diffuse, fibre]` (eq. 25's σℓ_p, σℓ_r; the
    /// fibre's × the fibre saturation).
    pub(crate) fn mask_scales(&self) -> [[Vec3; 2]; 2] {
        let [p, r] = [self.pore_path, self.ray_path].map(|l| self.late * l);
        [
            [p, p * self.fiber_saturation],
            [r, r * self.fiber_saturation],
        ]
    }

    /// The fibre saturation per channel (App. A.3).
    pub(crate) fn fiber_saturation(&self) -> Vec3 {
        self.fiber_saturation
    }

    /// (diffuse, fibre) colours averaged over a window of the ring wave: with the pore, ray and
    /// extra paths held, the absorbance is a₀ + k g (k of [`BeerColor::ring_scales`]), so Beer's
    /// law averages to exp(−a₀) · E[exp(−k g)], which `mean_exp(i)` gives for `ring_scales()[i]`.
    /// `None` where the clamp at zero absorbance would act (a negative path: the caller falls
    /// back to the colour of the mean ring value).
    pub(crate) fn ring_filtered_colors(
        &self,
        pore: f32,
        ray: f32,
        extra: f32,
        mean_exp: impl Fn(usize) -> Vec3,
    ) -> Option<(Vec3, Vec3)> {
        let a0 = self.absorbance(0.0, pore, ray, extra);
        if a0.min_element() < 0.0 || (a0 + self.ring).min_element() < 0.0 {
            return None;
        }
        let diffuse = (-a0).exp() * mean_exp(0);
        let fiber = (-a0 * self.fiber_saturation).exp() * mean_exp(1);
        Some((diffuse, fiber))
    }

    /// Channel `ch` (0 red, 1 green, 2 blue) of [`BeerColor::absorbance`]: one scalar expression,
    /// so a loop over many texels runs it in SIMD lanes.
    #[inline(always)]
    pub(crate) fn channel_absorbance(
        &self,
        ch: usize,
        g: f32,
        pore: f32,
        ray: f32,
        extra: f32,
    ) -> f32 {
        self.base[ch]
            + self.ring[ch] * g
            + self.late[ch] * (self.pore_path * pore + self.ray_path * ray + extra)
    }

    /// Channel `ch` of [`BeerColor::colors`]: (diffuse, fibre), by the branch-free `exp` that
    /// vectorises.
    #[inline(always)]
    pub(crate) fn channel_colors(&self, ch: usize, absorbance: f32) -> (f32, f32) {
        use crate::math::elementary::exp;
        let a = absorbance.max(0.0);
        (exp(-a), exp(-a * self.fiber_saturation[ch]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reproduces_earlywood_and_latewood_colours() {
        let p = ColorParams {
            earlywood: [0.6, 0.4, 0.2],
            latewood: [0.3, 0.15, 0.05],
            pore_path: 0.5,
            ray_path: 0.0,
            fiber_saturation: [0.5; 3],
        };
        let b = BeerColor::new(&p);
        let (e, _) = b.colors(b.absorbance(0.0, 0.0, 0.0, 0.0));
        let (l, f) = b.colors(b.absorbance(1.0, 0.0, 0.0, 0.0));
        assert!((e - Vec3::new(0.6, 0.4, 0.2)).abs().max_element() < 1e-5);
        assert!((l - Vec3::new(0.3, 0.15, 0.05)).abs().max_element() < 1e-5);
        // Fibre colour = sqrt of the diffuse for saturation 0.5.
        assert!(
            (f - Vec3::new(0.3f32.sqrt(), 0.15f32.sqrt(), 0.05f32.sqrt()))
                .abs()
                .max_element()
                < 1e-5
        );
        // Pores darken by (c_late)^(ℓ_p).
        let (pc, _) = b.colors(b.absorbance(0.0, 1.0, 0.0, 0.0));
        assert!((pc.x - 0.6 * 0.3f32.powf(0.5)).abs() < 1e-5);
    }

    #[test]
    fn fibre_saturation_scales_each_channel_on_its_own() {
        let p = ColorParams {
            earlywood: [0.6, 0.4, 0.2],
            latewood: [0.3, 0.15, 0.05],
            pore_path: 0.0,
            ray_path: 0.0,
            fiber_saturation: [0.5, 1.0, 2.0],
        };
        let b = BeerColor::new(&p);
        let (d, f) = b.colors(b.absorbance(0.0, 0.0, 0.0, 0.0));
        // Beer's law with absorbance × s_c: fibre_c = diffuse_c ^ s_c.
        let expect = Vec3::new(0.6f32.sqrt(), 0.4, 0.2 * 0.2);
        assert!((f - expect).abs().max_element() < 1e-5, "{d} {f}");
    }
}
