//! The BSDF of one hit ([`SurfaceBsdf`], one variant per kind) and its form with `wo` fixed for
//! lighting by many light samples ([`SurfaceAtWo`]).

use crate::bsdf::{Bsdf, BsdfSample, Glass, Lambertian, Mirror, WoodAtWo, WoodBsdf};
use glam::{Vec2, Vec3};

/// The BSDF at one hit, in its local shading frame. Small and `Copy`, so a light sweep can cache
/// it per pixel sample.
#[derive(Clone, Copy, Debug)]
// The wood variant is most of the size, and most hits are wood: a box would add an indirection
// and an allocation per shading point for the rare small variants' sake.
#[allow(clippy::large_enum_variant)]
pub enum SurfaceBsdf {
    /// Ideal diffuse reflection.
    Lambertian(Lambertian),
    /// The finished-wood BSDF (Marschner et al. 2005 fibre lobe under a dielectric finish).
    Wood(WoodBsdf),
    /// Perfect specular reflection (a delta lobe).
    Mirror(Mirror),
    /// Smooth dielectric reflection and refraction (delta lobes).
    Glass(Glass),
}

impl SurfaceBsdf {
    /// The probability that `sample` gives a delta lobe's direction at `wo`: a smooth wood
    /// finish's mirror ([`WoodBsdf::mirror_probability`]), 1 for the mirror and glass (all
    /// delta), 0 for the Lambertian.
    pub fn delta_probability(&self, wo: Vec3) -> f32 {
        match self {
            SurfaceBsdf::Wood(b) => b.mirror_probability(wo),
            SurfaceBsdf::Mirror(_) | SurfaceBsdf::Glass(_) => 1.0,
            SurfaceBsdf::Lambertian(_) => 0.0,
        }
    }

    /// True when every lobe is a delta lobe (light sampling is useless there).
    pub fn is_delta(&self) -> bool {
        match self {
            SurfaceBsdf::Mirror(_) | SurfaceBsdf::Glass(_) => true,
            SurfaceBsdf::Lambertian(_) | SurfaceBsdf::Wood(_) => false,
        }
    }

    /// The same BSDF, copied variant by variant: moving the enum copies all of its bytes (the
    /// wood variant's hundreds), this only the variant's own (12 for a Lambertian), which the
    /// path loop's shading points of small materials were spending 3–5 % of a Cornell-box
    /// render on (`memmove` in `perf`).
    #[inline(always)]
    pub fn copied(&self) -> Self {
        match self {
            SurfaceBsdf::Lambertian(b) => SurfaceBsdf::Lambertian(*b),
            SurfaceBsdf::Wood(b) => SurfaceBsdf::Wood(*b),
            SurfaceBsdf::Mirror(b) => SurfaceBsdf::Mirror(*b),
            SurfaceBsdf::Glass(b) => SurfaceBsdf::Glass(*b),
        }
    }

    /// [`SurfaceBsdf::copied`] written into `out`, where a shading point keeps it: where `out`
    /// holds the same variant only the payload is written. (Assigning a whole variant, LLVM
    /// copied the whole enum, 480 bytes by `memcpy`, for every variant: 2.6 % of a Cornell-box
    /// render's instructions.)
    #[inline(always)]
    pub(crate) fn copy_to(&self, out: &mut Self) {
        match (self, &mut *out) {
            (SurfaceBsdf::Lambertian(b), SurfaceBsdf::Lambertian(o)) => *o = *b,
            (SurfaceBsdf::Wood(b), SurfaceBsdf::Wood(o)) => *o = *b,
            (SurfaceBsdf::Mirror(b), SurfaceBsdf::Mirror(o)) => *o = *b,
            (SurfaceBsdf::Glass(b), SurfaceBsdf::Glass(o)) => *o = *b,
            _ => *out = self.copied(),
        }
    }

    /// True when the BSDF transmits (the renderer must not flip the normal towards the viewer).
    pub(crate) fn is_transmissive(&self) -> bool {
        match self {
            SurfaceBsdf::Glass(_) => true,
            SurfaceBsdf::Lambertian(_) | SurfaceBsdf::Wood(_) | SurfaceBsdf::Mirror(_) => false,
        }
    }
}

impl Bsdf for SurfaceBsdf {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        match self {
            SurfaceBsdf::Lambertian(b) => b.eval(wo, wi),
            SurfaceBsdf::Wood(b) => b.eval(wo, wi),
            SurfaceBsdf::Mirror(b) => b.eval(wo, wi),
            SurfaceBsdf::Glass(b) => b.eval(wo, wi),
        }
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self {
            SurfaceBsdf::Lambertian(b) => b.pdf(wo, wi),
            SurfaceBsdf::Wood(b) => b.pdf(wo, wi),
            SurfaceBsdf::Mirror(b) => b.pdf(wo, wi),
            SurfaceBsdf::Glass(b) => b.pdf(wo, wi),
        }
    }

    #[inline(always)]
    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
        match self {
            SurfaceBsdf::Lambertian(b) => b.sample(wo, uc, u),
            SurfaceBsdf::Wood(b) => b.sample(wo, uc, u),
            SurfaceBsdf::Mirror(b) => b.sample(wo, uc, u),
            SurfaceBsdf::Glass(b) => b.sample(wo, uc, u),
        }
    }
}

/// A shading point's BSDF with `wo` fixed, for lighting it by many light samples: the wood BSDF
/// with its `wo`-only terms worked out once (`WoodBsdf::at_wo`), any other BSDF as it is.
/// Values identical to `eval` and `pdf`.
#[derive(Clone, Copy, Debug)]
pub(crate) enum SurfaceAtWo<'a> {
    /// The wood BSDF with its `wo`-only terms worked out.
    Wood(WoodAtWo<'a>),
    /// Any other BSDF, with `wo` (local frame).
    Other(&'a SurfaceBsdf, Vec3),
}

impl SurfaceBsdf {
    /// This BSDF with its `wo` fixed (local frame).
    #[inline]
    pub(crate) fn at_wo(&self, wo: Vec3) -> SurfaceAtWo<'_> {
        match self {
            SurfaceBsdf::Wood(b) => SurfaceAtWo::Wood(b.at_wo(wo)),
            other @ (SurfaceBsdf::Lambertian(_)
            | SurfaceBsdf::Mirror(_)
            | SurfaceBsdf::Glass(_)) => SurfaceAtWo::Other(other, wo),
        }
    }
}

impl SurfaceAtWo<'_> {
    /// `(eval(wo, wi), pdf(wo, wi))`, the density only when `with_pdf` (else 0).
    #[inline]
    pub(crate) fn eval_pdf(&self, wi: Vec3, with_pdf: bool) -> (Vec3, f32) {
        match self {
            SurfaceAtWo::Wood(w) => w.eval_pdf(wi, with_pdf),
            SurfaceAtWo::Other(b, wo) => b.eval_pdf(*wo, wi, with_pdf),
        }
    }

    /// [`SurfaceAtWo::eval_pdf`] of the directions in the columns `wi` (x, y, z; one lane per
    /// direction) into the colour columns `f` and `pdf` (the wood BSDF in SIMD lanes,
    /// [`WoodAtWo::eval_pdf_lanes`]; others one by one).
    #[inline(always)]
    pub(crate) fn eval_pdf_lanes(
        &self,
        wi: [&[f32]; 3],
        with_pdf: bool,
        f: [&mut [f32]; 3],
        pdf: &mut [f32],
    ) {
        match self {
            SurfaceAtWo::Wood(w) => w.eval_pdf_lanes(wi, with_pdf, f, pdf),
            // The material's kind chosen once, not per direction.
            SurfaceAtWo::Other(SurfaceBsdf::Lambertian(b), wo) => {
                b.eval_pdf_lanes(*wo, wi, with_pdf, f, pdf)
            }
            SurfaceAtWo::Other(b, wo) => b.eval_pdf_lanes(*wo, wi, with_pdf, f, pdf),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `SurfaceBsdf::copy_to` leaves the slot equal to the BSDF, whether the slot held the same
    /// variant (payload only) or another one.
    #[test]
    fn copy_to_equals_the_bsdf_from_any_slot() {
        let all = [
            SurfaceBsdf::Lambertian(Lambertian {
                albedo: Vec3::new(0.1, 0.2, 0.3),
            }),
            SurfaceBsdf::Mirror(Mirror {
                reflectance: Vec3::splat(0.9),
            }),
            SurfaceBsdf::Glass(Glass {
                eta: 1.5,
                tint: Vec3::ONE,
            }),
        ];
        for from in &all {
            for to in &all {
                let mut slot = to.copied();
                from.copy_to(&mut slot);
                assert_eq!(format!("{slot:?}"), format!("{from:?}"));
            }
        }
    }
}
