//! BSDFs in the local shading frame (z = shading normal, unit directions pointing away from
//! the surface): the finished-wood BSDF of Marschner et al. 2005 and the simple BSDFs scenes need.

mod fiber;
pub mod fiber_albedo;
mod fiber_albedo_table;
mod fresnel;
mod ggx;
mod lambertian;
pub mod layered_reference;
pub mod rough_finish;
mod rough_finish_table;
pub mod rough_transmission;
mod specular;
mod wood;
pub mod workload;

pub use fiber::{erf_inv, gaussian, FiberAtWo, FiberAxis, FiberNormalization};
pub use fresnel::{
    fresnel_dielectric, fresnel_diffuse_reflectance, refract, refract_in, refract_out,
};
pub use ggx::Ggx;
pub use lambertian::Lambertian;
pub use specular::{Glass, Mirror};
pub use wood::{Finish, FinishModel, WoodAtWo, WoodBsdf};

use crate::math::is_zero;
use glam::{Vec2, Vec3};

/// One importance sample of a BSDF. For a delta lobe `pdf` is the discrete lobe-selection
/// probability and `f / pdf · |cos θi|` is the path weight.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    /// Sampled incident direction (unit, shading frame).
    pub wi: Vec3,
    /// BSDF value f(wo, wi), without the cosine.
    pub f: Vec3,
    /// Solid-angle density of `wi`, or the lobe-selection probability for a delta lobe.
    pub pdf: f32,
    /// True when `wi` came from a delta lobe (`eval` and `pdf` do not see it).
    pub is_delta: bool,
    /// Relative index of refraction η' crossed by `wi`: η_inside/η_outside entering, its
    /// inverse leaving, 1 for reflection. `f` carries refraction's radiance scaling 1/η'²,
    /// which Russian roulette undoes (Veach 1997 §5.2; pbrt-v4 §13.4 `etaScale`).
    pub eta: f32,
}

/// A BSDF: `eval` is f(wo, wi) without the cosine and without delta lobes; `pdf` is the density
/// per unit solid angle that `sample` draws its non-delta directions from (0 for delta lobes).
pub trait Bsdf {
    /// f(wo, wi) without the cosine factor and without delta lobes (shading frame, z = normal).
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3;
    /// Density per unit solid angle with which `sample` draws `wi` given `wo` (0 for delta lobes).
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32;
    /// Draws `wi` for `wo` from the lobe chosen by `uc` and the 2D sample `u` (each in [0, 1));
    /// `None` when no direction is produced (e.g. `wo` below the surface).
    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample>;

    /// `(eval(wo, wi), pdf(wo, wi))` in one call, as Mitsuba 3's `BSDF::eval_pdf`, the density
    /// only when `with_pdf` and f ≠ 0 (else 0). Both are worked out and one is selected, so a
    /// loop of this over many directions has no branches and runs in SIMD lanes (the BSDFs that
    /// use it have cheap densities; the wood BSDF prepares `wo` instead, [`WoodBsdf::at_wo`]).
    #[inline(always)]
    fn eval_pdf(&self, wo: Vec3, wi: Vec3, with_pdf: bool) -> (Vec3, f32) {
        let (f, pdf) = (self.eval(wo, wi), self.pdf(wo, wi));
        (f, if with_pdf & !is_zero(f) { pdf } else { 0.0 })
    }

    /// [`Bsdf::eval_pdf`] of every direction of the columns `wi` (x, y, z; one lane per
    /// direction) into the colour columns `f` and `pdf`.
    #[inline(always)]
    fn eval_pdf_lanes(
        &self,
        wo: Vec3,
        wi: [&[f32]; 3],
        with_pdf: bool,
        f: [&mut [f32]; 3],
        pdf: &mut [f32],
    ) {
        let n = pdf.len();
        let ([wx, wy, wz], [fr, fg, fb]) = (wi, f);
        let (wx, wy, wz) = (&wx[..n], &wy[..n], &wz[..n]);
        let (fr, fg, fb) = (&mut fr[..n], &mut fg[..n], &mut fb[..n]);
        for k in 0..n {
            let (v, p) = self.eval_pdf(wo, Vec3::new(wx[k], wy[k], wz[k]), with_pdf);
            [fr[k], fg[k], fb[k], pdf[k]] = [v.x, v.y, v.z, p];
        }
    }
}

/// A BSDF parameter outside its allowed range (or not finite).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BsdfError {
    /// A parameter is not finite or outside its range.
    #[error("WoodBsdfParams.{field} = {value}: must be {range}")]
    OutOfRange {
        /// The parameter's field name in [`WoodBsdfParams`].
        field: &'static str,
        /// The value given.
        value: String,
        /// The allowed range, in words.
        range: &'static str,
    },
}

/// Parameters of the finished-wood BSDF (Marschner et al. 2005, §4; Liu et al. 2016, §6.3).
/// Directions are in the local shading frame; angles in radians.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WoodBsdfParams {
    /// Lambertian albedo of the wood substrate (under the finish).
    pub diffuse: Vec3,
    /// Fibre-lobe colour k_f, each channel in [0, 1].
    pub fiber_color: Vec3,
    /// Longitudinal fibre axis u (unit; may dip into the surface).
    pub fiber_dir: Vec3,
    /// Ray-fibre axis (unit), used where `ray_mask` > 0.
    pub ray_dir: Vec3,
    /// Blend weight of the ray-fibre BSDF, in [0, 1].
    pub ray_mask: f32,
    /// Gaussian width β of the fibre highlight, radians.
    pub highlight_width: f32,
    /// Refractive index of the finish; 1 means no finish.
    pub eta: f32,
    /// GGX roughness of the finish; 0 means smooth.
    pub roughness: f32,
}

/// How a field of a parameter table is checked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParamKind {
    /// Linear RGB, every channel finite and in [0, 1].
    Colour,
    /// A direction: finite, its length within 1e-3 of 1 (normalised when used).
    UnitVector,
    /// A finite scalar in `[min, max]`.
    Scalar {
        /// Smallest allowed value.
        min: f32,
        /// Largest allowed value.
        max: f32,
    },
}

/// One field of a parameter table: its name, how it is checked and the allowed range in words.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParamSpec {
    /// The field's name (as in the struct, Python's keyword arguments and scene files).
    pub name: &'static str,
    /// How it is checked.
    pub kind: ParamKind,
    /// The allowed range, in words (for error messages and documentation).
    pub range: &'static str,
}

/// A field's value, as [`ParamSpec::check`] takes it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParamValue {
    /// A colour or a direction.
    Vec3(Vec3),
    /// A scalar.
    Scalar(f32),
}

impl ParamSpec {
    /// `Ok` when `v` is finite and in range, else the field's [`BsdfError::OutOfRange`].
    pub fn check(&self, v: ParamValue) -> Result<(), BsdfError> {
        let ok = match (self.kind, v) {
            (ParamKind::Colour, ParamValue::Vec3(c)) => {
                c.is_finite() && c.min_element() >= 0.0 && c.max_element() <= 1.0
            }
            (ParamKind::UnitVector, ParamValue::Vec3(d)) => {
                d.is_finite() && (d.length() - 1.0).abs() <= 1e-3
            }
            (ParamKind::Scalar { min, max }, ParamValue::Scalar(x)) => {
                x.is_finite() && x >= min && x <= max
            }
            _ => false,
        };
        ok.then_some(()).ok_or_else(|| BsdfError::OutOfRange {
            field: self.name,
            value: match v {
                ParamValue::Vec3(c) => format!("{c}"),
                ParamValue::Scalar(x) => format!("{x}"),
            },
            range: self.range,
        })
    }
}

/// The unit interval [0, 1], the range of masks, weights and roughness.
const UNIT: ParamKind = ParamKind::Scalar { min: 0.0, max: 1.0 };

/// The fields of [`WoodBsdfParams`] in declaration order, with their checks: the one list that
/// [`WoodBsdf::new`] validates against, Python's `WoodBsdf` takes as keyword arguments (its
/// `FIELDS`) and the scene fields of the finishes take their ranges from (`scene::fields`).
pub const WOOD_BSDF_PARAMS: [ParamSpec; 8] = [
    ParamSpec {
        name: "diffuse",
        kind: ParamKind::Colour,
        range: "finite channels in [0, 1]",
    },
    ParamSpec {
        name: "fiber_color",
        kind: ParamKind::Colour,
        range: "finite channels in [0, 1]",
    },
    ParamSpec {
        name: "fiber_dir",
        kind: ParamKind::UnitVector,
        range: "a finite unit vector (length within 1e-3 of 1)",
    },
    ParamSpec {
        name: "ray_dir",
        kind: ParamKind::UnitVector,
        range: "a finite unit vector (length within 1e-3 of 1)",
    },
    ParamSpec {
        name: "ray_mask",
        kind: UNIT,
        range: "a finite value in [0, 1]",
    },
    ParamSpec {
        name: "highlight_width",
        kind: ParamKind::Scalar {
            min: 1e-3,
            max: 0.5 * std::f32::consts::PI,
        },
        range: "radians in [0.001, π/2]",
    },
    ParamSpec {
        name: "eta",
        kind: ParamKind::Scalar { min: 1.0, max: 4.0 },
        range: "a finite index in [1, 4]",
    },
    ParamSpec {
        name: "roughness",
        kind: UNIT,
        range: "a finite value in [0, 1]",
    },
];

impl WoodBsdfParams {
    /// The fields' values in [`WOOD_BSDF_PARAMS`]' order.
    pub fn values(&self) -> [ParamValue; 8] {
        use ParamValue::{Scalar, Vec3 as V};
        [
            V(self.diffuse),
            V(self.fiber_color),
            V(self.fiber_dir),
            V(self.ray_dir),
            Scalar(self.ray_mask),
            Scalar(self.highlight_width),
            Scalar(self.eta),
            Scalar(self.roughness),
        ]
    }

    /// The spec of field `name` in [`WOOD_BSDF_PARAMS`].
    pub fn spec(name: &str) -> Option<&'static ParamSpec> {
        WOOD_BSDF_PARAMS.iter().find(|p| p.name == name)
    }
}

impl Default for WoodBsdfParams {
    fn default() -> Self {
        WoodBsdfParams {
            diffuse: Vec3::new(0.45, 0.22, 0.10),
            fiber_color: Vec3::new(0.6, 0.4, 0.25),
            fiber_dir: Vec3::X,
            ray_dir: Vec3::Z,
            ray_mask: 0.0,
            highlight_width: 8.0_f32.to_radians(),
            eta: 1.5,
            roughness: 0.0,
        }
    }
}
