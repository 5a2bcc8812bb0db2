//! The finished-wood BSDF: a Lambertian substrate plus the fibre lobes of Marschner et al. 2005
//! (longitudinal and ray fibres blended by the ray mask, Liu et al. 2016 §6.3.1), seen through a
//! dielectric finish (Marschner et al. 2005 §4.3), smooth or rough (GGX). The exterior BSDF, its
//! reciprocity, the closed-form internal reflections of the diffuse part and the sampling
//! densities are derived in notes/bsdf.md.

use super::fiber::{FiberAxis, FiberNormalization, PsiSpread};
use super::fiber_albedo::{dip_of, max_lobe_albedo};
use super::fresnel::{fresnel_dielectric, fresnel_diffuse_reflectance, refract_in, refract_out};
use super::rough_finish::RoughFinish;
use super::rough_transmission::RoughTransmission;
use super::{Bsdf, BsdfError, BsdfSample, WoodBsdfParams, WOOD_BSDF_PARAMS};
use crate::math::{cosine_hemisphere, luminance, safe_sqrt, INV_PI, PI};
use glam::{Vec2, Vec3};

mod at_wo;
pub use at_wo::WoodAtWo;

/// Below this roughness the finish is treated as smooth (a delta reflection): a GGX lobe of
/// α < 1e-3 is narrower than f32 directions resolve reliably.
const MIN_ROUGHNESS: f32 = 1e-3;

/// The finished-wood BSDF for one shading point. Cheap to build (no allocation, one 12-point
/// quadrature when η > 1).
///
/// ```
/// use xylem::math::{Vec2, Vec3};
/// use xylem::bsdf::{Bsdf, WoodBsdf, WoodBsdfParams};
///
/// // Fibres along x in the surface, a smooth finish of index 1.5 (local frame: z = normal).
/// let bsdf = WoodBsdf::new(WoodBsdfParams::default())?;
/// let wo = Vec3::new(0.3, 0.0, 1.0).normalize();
/// let wi = Vec3::new(-0.3, 0.0, 1.0).normalize(); // on the fibre's specular cone
/// let f = bsdf.eval(wo, wi);
/// assert!(f.min_element() > 0.0 && bsdf.pdf(wo, wi) > 0.0);
/// // Importance sampling returns a direction with its f and density.
/// if let Some(s) = bsdf.sample(wo, 0.5, Vec2::new(0.3, 0.7)) {
///     assert!(s.wi.is_normalized());
/// }
/// // Out-of-range parameters are an error naming the field.
/// let bad = WoodBsdfParams { eta: 0.5, ..Default::default() };
/// assert!(WoodBsdf::new(bad).unwrap_err().to_string().contains("eta"));
/// # Ok::<(), xylem::bsdf::BsdfError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WoodBsdf {
    params: WoodBsdfParams,
    norm: FiberNormalization,
    fiber: FiberAxis,
    ray: FiberAxis,
    /// ρ'/(1 − ρ' F̄_int): the diffuse albedo including the closed-form series of internal
    /// reflections under the finish (notes/bsdf.md §1.3), with ρ' = s ρ scaled just enough that
    /// ρ' ≤ 1 − k_f Ā in every channel ([`bounded_diffuse`], notes/bsdf.md §2.3).
    diffuse_eff: Vec3,
    /// 1 − R̄_int = (1 − R̄)/η², R̄ the finish's hemispherical reflectance from outside (F̄_ext
    /// when smooth): fraction of Lambertian light from the substrate that leaves (notes/bsdf.md
    /// §1.3, §4.3).
    escape: f32,
    inv_eta2: f32,
    /// cos of the critical angle inside the finish: interior directions with z ≤ this cannot leave.
    z_crit: f32,
    /// The rough finish (GGX with energy compensation), or `None` when smooth.
    rough: Option<RoughFinish>,
    /// Where the rough finish sends the light it transmits (for the fibre lobes).
    transmission: Option<RoughTransmission>,
    finish: FinishModel,
}

/// How the diffuse light reflected back down by the finish is counted (notes/bsdf.md §1.3): the
/// closed-form geometric series ρ/(1 − ρ F̄_int) of every internal bounce, or only the first pass
/// ρ (light the finish reflects back is dropped). Both cost the same per evaluation; the knob
/// exists so `xylem tradeoff` can measure what the series changes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FinishModel {
    /// Σₖ (ρ F̄_int)ᵏ = 1/(1 − ρ F̄_int): all internal reflections (the default).
    #[default]
    ClosedForm,
    /// k = 0 only: one pass through the finish, no internal reflections.
    SingleBounce,
}

/// The diffuse albedo scaled uniformly, s = min(1, min_c (1 − k_f,c Ā)/ρ_c), so that the diffuse
/// plus the most the fibre lobes can reflect at any view, k_f Ā, stays ≤ 1 per channel
/// (notes/bsdf.md §2.3). Ā = (1 − m) A_max(β, δ_fibre) + m A_max(β, δ_ray) is the ray-mask blend
/// of the lobes' largest directional albedos ([`max_lobe_albedo`]), not 1: bounding by k_f
/// alone made pale woods render at a fifth of their colour. A uniform scale keeps the wood's hue.
fn bounded_diffuse(p: &WoodBsdfParams) -> Vec3 {
    let m = p.ray_mask;
    let beta = p.highlight_width;
    let mut lobe_albedo = 0.0;
    if m < 1.0 {
        lobe_albedo += (1.0 - m) * max_lobe_albedo(beta, dip_of(p.fiber_dir.z));
    }
    if m > 0.0 {
        lobe_albedo += m * max_lobe_albedo(beta, dip_of(p.ray_dir.z));
    }
    let (rho, room) = (p.diffuse, Vec3::ONE - p.fiber_color * lobe_albedo);
    let mut s = 1.0f32;
    for c in 0..3 {
        if rho[c] > room[c] {
            s = s.min(room[c] / rho[c]);
        }
    }
    rho * s
}

/// Which lobe `sample` picked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Lobe {
    Specular,
    Diffuse,
    Fiber,
    Ray,
}

/// Lobe-selection probabilities for one `wo`, proportional to the estimated albedo of each lobe.
#[derive(Clone, Copy, Debug)]
struct LobeProbs {
    specular: f32,
    diffuse: f32,
    fiber: f32,
    ray: f32,
}

/// What the fibre lobes under a rough finish need of ωo alone: how each axis sees the light the
/// finish transmits from ωo, and the longitudinal angle and width their samples are drawn about
/// (the single-scattering part's mean angle; β widened by twice the mean spread, for the two
/// ends of the path).
#[derive(Clone, Copy, Debug)]
struct RoughView {
    fiber: [PsiSpread; 2],
    ray: [PsiSpread; 2],
    sample_fiber: (f32, f32),
    sample_ray: (f32, f32),
}

/// (ψ, β) to draw a fibre lobe's samples with, from ωo's spreads (see [`RoughView`]).
fn sampling_about(spread: &[PsiSpread; 2], beta: f32) -> (f32, f32) {
    let var: f32 = spread.iter().map(|p| p.share * p.var).sum();
    (
        spread[0].psi,
        (beta * beta + 2.0 * var).sqrt().min(0.5 * PI),
    )
}

/// The part of a [`WoodBsdf`] that depends on its finish's index and roughness alone: the rough
/// finish's reflectance tables interpolated for them, its transmission's table position, and
/// the finish's hemispherical reflectance. Worked out once per material
/// ([`crate::material::WoodMaterial::finish`]) instead of at every shading point, where it
/// cost 2.7 % of a rough-finished board's path-traced render (notes/render.md).
#[derive(Clone, Copy, Debug)]
pub struct Finish {
    eta: f32,
    roughness: f32,
    rough: Option<RoughFinish>,
    transmission: Option<RoughTransmission>,
    /// R̄: the mean reflectance of the finish from outside (Fresnel's under a smooth finish).
    avg_reflectance: f32,
}

impl Finish {
    /// The finish of index `eta` and GGX `roughness` (rough from roughness 10⁻³ up);
    /// values out of [`WoodBsdf::new`]'s ranges give a finish no BSDF will use, never a panic.
    pub fn new(eta: f32, roughness: f32) -> Finish {
        let rough = (roughness >= MIN_ROUGHNESS).then(|| RoughFinish::new(roughness, eta));
        Finish {
            eta,
            roughness,
            rough,
            transmission: rough.map(|_| RoughTransmission::new(roughness, eta)),
            avg_reflectance: rough
                .map_or_else(|| fresnel_diffuse_reflectance(eta), |r| r.avg_reflectance()),
        }
    }

    /// The finish's refractive index.
    pub fn eta(&self) -> f32 {
        self.eta
    }

    /// The finish's GGX roughness.
    pub fn roughness(&self) -> f32 {
        self.roughness
    }

    /// Whether this is the finish of `params` (the same bits of index and roughness).
    fn is_for(&self, params: &WoodBsdfParams) -> bool {
        self.eta.to_bits() == params.eta.to_bits()
            && self.roughness.to_bits() == params.roughness.to_bits()
    }
}

impl WoodBsdf {
    /// Validates `params` (every field finite and in range) and precomputes what every call needs.
    pub fn new(params: WoodBsdfParams) -> Result<WoodBsdf, BsdfError> {
        WoodBsdf::under(params, None)
    }

    /// [`WoodBsdf::new`] under a finish worked out before ([`Finish::new`]), the same bits; a
    /// finish of another index or roughness than `params`' is not used.
    pub fn new_under(params: WoodBsdfParams, finish: &Finish) -> Result<WoodBsdf, BsdfError> {
        WoodBsdf::under(params, Some(finish))
    }

    fn under(params: WoodBsdfParams, finish: Option<&Finish>) -> Result<WoodBsdf, BsdfError> {
        for (spec, v) in WOOD_BSDF_PARAMS.iter().zip(params.values()) {
            spec.check(v)?;
        }
        let (fiber_dir, ray_dir) = (
            params.fiber_dir / params.fiber_dir.length(),
            params.ray_dir / params.ray_dir.length(),
        );
        let mut params = params;
        params.fiber_dir = fiber_dir;
        params.ray_dir = ray_dir;

        let eta = params.eta;
        let finish = match finish {
            Some(f) if f.is_for(&params) => *f,
            _ => Finish::new(eta, params.roughness),
        };
        let (rough, r_avg) = (finish.rough, finish.avg_reflectance);
        let escape = (1.0 - r_avg) / (eta * eta);
        let f_int = 1.0 - escape;
        let rho = bounded_diffuse(&params);
        let diffuse_eff = rho / (Vec3::ONE - rho * f_int);
        Ok(WoodBsdf {
            finish: FinishModel::ClosedForm,
            params,
            norm: FiberNormalization::EnergyBounded,
            fiber: FiberAxis::new(fiber_dir),
            ray: FiberAxis::new(ray_dir),
            diffuse_eff,
            escape,
            inv_eta2: 1.0 / (eta * eta),
            z_crit: safe_sqrt(1.0 - 1.0 / (eta * eta)),
            rough,
            transmission: finish.transmission,
        })
    }

    /// The same BSDF with another fibre-lobe normalisation (the published one for comparison).
    pub fn with_normalization(mut self, norm: FiberNormalization) -> Self {
        self.norm = norm;
        self
    }

    /// The same BSDF with the internal reflections of the diffuse part counted by `finish`.
    pub fn with_finish(mut self, finish: FinishModel) -> Self {
        if finish == self.finish {
            return self;
        }
        let rho = bounded_diffuse(&self.params);
        self.diffuse_eff = match finish {
            // ρ'' = ρ'/(1 − ρ' F̄_int), F̄_int = 1 − escape (notes/bsdf.md eq. 1.3).
            FinishModel::ClosedForm => rho / (Vec3::ONE - rho * (1.0 - self.escape)),
            FinishModel::SingleBounce => rho,
        };
        self.finish = finish;
        self
    }

    /// How the finish's internal reflections are counted (see [`FinishModel`]).
    pub fn finish(&self) -> FinishModel {
        self.finish
    }

    /// The diffuse albedo f carries (f_d = T T ρ''/(π η²)): ρ'' = ρ'/(1 − ρ' F̄_int) with every
    /// internal reflection (closed form), or ρ' (single bounce); ρ' is the bounded albedo
    /// (notes/bsdf.md §1.3, §2.3).
    pub fn effective_diffuse(&self) -> Vec3 {
        self.diffuse_eff
    }

    /// The substrate albedo ρ' whose [`WoodBsdf::effective_diffuse`] under this BSDF's finish is
    /// `effective`: the series of notes/bsdf.md eq. 1.3 inverted, ρ' = ρ''/(1 + ρ'' F̄_int).
    pub fn diffuse_from_effective(&self, effective: Vec3) -> Vec3 {
        match self.finish {
            FinishModel::ClosedForm => effective / (Vec3::ONE + effective * (1.0 - self.escape)),
            FinishModel::SingleBounce => effective,
        }
    }

    /// The parameters the BSDF was built from.
    pub fn params(&self) -> &WoodBsdfParams {
        &self.params
    }

    /// The fibre lobe's normalisation.
    pub fn normalization(&self) -> FiberNormalization {
        self.norm
    }

    /// True when the finish reflects through a delta lobe (η > 1 and roughness below 1e-3).
    pub fn has_delta(&self) -> bool {
        self.params.eta > 1.0 && self.rough.is_none()
    }

    /// Transmittance of the finish for an exterior direction with cosine `cos`: 1 − F (smooth),
    /// 1 − R(μ) with R all the rough finish reflects (notes/bsdf.md §4.3).
    #[inline]
    fn transmittance(&self, cos: f32) -> f32 {
        match &self.rough {
            Some(r) => 1.0 - r.reflectance(cos),
            None => self.smooth_transmittance(cos),
        }
    }

    /// [`WoodBsdf::transmittance`] of the smooth finish, 1 − F (Fresnel,
    /// [`fresnel_dielectric`]): branch-free, so a loop of it over many directions runs in SIMD
    /// lanes (`WoodAtWo::eval_pdf_lanes`).
    #[inline(always)]
    fn smooth_transmittance(&self, cos: f32) -> f32 {
        1.0 - fresnel_dielectric(cos, self.params.eta)
    }

    /// [`RoughView`] of `wo`, or `None` for a smooth finish.
    fn rough_view(&self, wo: Vec3) -> Option<RoughView> {
        let parts = self.transmission?.parts(wo.z);
        let m = self.params.ray_mask;
        let spread = |axis: &FiberAxis, used: bool| {
            if used {
                axis.spread(wo, &parts)
            } else {
                [PsiSpread::default(); 2]
            }
        };
        let (fiber, ray) = (spread(&self.fiber, m < 1.0), spread(&self.ray, m > 0.0));
        let beta = self.params.highlight_width;
        Some(RoughView {
            fiber,
            ray,
            sample_fiber: sampling_about(&fiber, beta),
            sample_ray: sampling_about(&ray, beta),
        })
    }

    /// The fibre and ray lobes (without k_f) for exterior `wi` under the rough finish seen from
    /// `view`'s ωo ([`FiberAxis::eval_spread`], notes/bsdf.md §4.6).
    fn rough_lobes(&self, view: &RoughView, wi: Vec3) -> (f32, f32) {
        let p = &self.params;
        let parts = match &self.transmission {
            Some(t) => t.parts(wi.z),
            None => return (0.0, 0.0),
        };
        let (beta, norm) = (p.highlight_width, self.norm);
        let lobe = |axis: &FiberAxis, at: &[PsiSpread; 2]| {
            FiberAxis::eval_spread(at, &axis.spread(wi, &parts), beta, norm)
        };
        let f_fib = if p.ray_mask < 1.0 {
            lobe(&self.fiber, &view.fiber)
        } else {
            0.0
        };
        let f_ray = if p.ray_mask > 0.0 {
            lobe(&self.ray, &view.ray)
        } else {
            0.0
        };
        (f_fib, f_ray)
    }

    /// The substrate from the fibre and ray lobes' values: diffuse (with its internal
    /// reflections) plus k_f times their ray-mask blend.
    #[inline(always)]
    fn blend(&self, f_fib: f32, f_ray: f32) -> Vec3 {
        let p = &self.params;
        let mut fib = 0.0;
        if p.ray_mask < 1.0 {
            fib += (1.0 - p.ray_mask) * f_fib;
        }
        if p.ray_mask > 0.0 {
            fib += p.ray_mask * f_ray;
        }
        self.diffuse_eff * INV_PI + p.fiber_color * fib
    }

    /// The interior density of the fibre and ray lobes' samples for `wi_in` (0 for a lobe never
    /// picked) under a rough finish, drawn about its view's angles (a smooth finish's come with
    /// the lobes' values, [`FiberAxis::eval_pdf_at`]).
    fn rough_lobe_densities(&self, probs: &LobeProbs, view: &RoughView, wi_in: Vec3) -> (f32, f32) {
        let z = self.z_crit;
        let density =
            |axis: &FiberAxis, (psi, width): (f32, f32)| axis.pdf_about(psi, wi_in, width, z);
        let p_fib = if probs.fiber > 0.0 {
            density(&self.fiber, view.sample_fiber)
        } else {
            0.0
        };
        let p_ray = if probs.ray > 0.0 {
            density(&self.ray, view.sample_ray)
        } else {
            0.0
        };
        (p_fib, p_ray)
    }

    fn lobe_probs(&self, wo: Vec3) -> LobeProbs {
        let p = &self.params;
        // The rough finish's multiple-scattering lobe is drawn with the diffuse (both cos θi/π).
        let (spec, ms) = match &self.rough {
            Some(r) => {
                let ms = r.ms_albedo(wo.z);
                ((r.reflectance(wo.z) - ms).max(0.0), ms)
            }
            None if p.eta > 1.0 => (fresnel_dielectric(wo.z, p.eta), 0.0),
            None => (0.0, 0.0),
        };
        let t = self.transmittance(wo.z);
        let diff = t * luminance(self.diffuse_eff) * self.escape + ms;
        let fib_scale = match self.norm {
            FiberNormalization::EnergyBounded => INV_PI,
            FiberNormalization::Published => 2.0,
        };
        let kf = t * luminance(p.fiber_color) * fib_scale;
        let (fib, ray) = (kf * (1.0 - p.ray_mask), kf * p.ray_mask);
        let sum = spec + diff + fib + ray;
        if !(sum > 0.0) {
            return LobeProbs {
                specular: 0.0,
                diffuse: 0.0,
                fiber: 0.0,
                ray: 0.0,
            };
        }
        LobeProbs {
            specular: spec / sum,
            diffuse: diff / sum,
            fiber: fib / sum,
            ray: ray / sum,
        }
    }

    /// The lobe whose cumulative probability interval holds `uc`; rounding never selects a
    /// lobe of probability 0 (the last positive one is the fallback).
    /// The probability that `sample` takes a smooth finish's mirror (its one delta lobe) at
    /// `wo`; 0 under a rough finish (its reflection has a density), without a finish, and below
    /// the surface. The lobes are picked in the order mirror first (`pick`), so a caller that
    /// leaves the mirror out (Mitsuba's component masks, python/xylem/mitsuba.py) draws the rest
    /// with `uc` mapped into [p, 1) and divides their density by 1 − p.
    pub fn mirror_probability(&self, wo: Vec3) -> f32 {
        if self.rough.is_some() || !(wo.z > 0.0) {
            return 0.0;
        }
        self.lobe_probs(wo).specular
    }

    fn pick(probs: &LobeProbs, uc: f32) -> Lobe {
        let lobes = [
            (Lobe::Specular, probs.specular),
            (Lobe::Diffuse, probs.diffuse),
            (Lobe::Fiber, probs.fiber),
            (Lobe::Ray, probs.ray),
        ];
        let mut acc = 0.0;
        let mut last = Lobe::Diffuse;
        for (lobe, p) in lobes {
            if p > 0.0 {
                acc += p;
                last = lobe;
                if uc < acc {
                    return lobe;
                }
            }
        }
        last
    }

    /// The density of [`Bsdf::sample`] from the lobe probabilities and the fibre and ray lobes'
    /// interior densities `p_fib`, `p_ray` at `wi_in` (ωi refracted into the finish): the
    /// diffuse's cos θi/π, the lobes' densities mapped to exterior solid angle, the rough
    /// finish's visible-normal density; 0 where not finite.
    #[inline(always)]
    fn density(
        &self,
        probs: &LobeProbs,
        wo: Vec3,
        wi: Vec3,
        wi_in: Vec3,
        p_fib: f32,
        p_ray: f32,
    ) -> f32 {
        let mut pdf = self.substrate_density(probs, wi.z, wi_in.z, p_fib, p_ray);
        if let Some(r) = &self.rough {
            if probs.specular > 0.0 {
                let h = (wo + wi).normalize_or_zero();
                pdf += probs.specular * r.ggx.reflection_pdf(wo, h);
            }
        }
        finite_or_zero(pdf)
    }

    /// The part of [`WoodBsdf::density`] that passes through the finish, for cos θi = `wi_z`
    /// and its refraction's cos θi' = `wi_in_z`: the diffuse's cos θi/π plus the fibre and ray
    /// lobes' interior densities mapped to exterior solid angle (not yet checked for being
    /// finite). Branch-free but for the lobe probabilities, which are the same for every ωi.
    #[inline(always)]
    fn substrate_density(
        &self,
        probs: &LobeProbs,
        wi_z: f32,
        wi_in_z: f32,
        p_fib: f32,
        p_ray: f32,
    ) -> f32 {
        let mut pdf = probs.diffuse * wi_z * INV_PI;
        if probs.fiber > 0.0 || probs.ray > 0.0 {
            // dω_int/dω_ext = cos θi / (η² cos θi') (notes/bsdf.md §1.1).
            let jac = wi_z * self.inv_eta2 / wi_in_z.max(1e-7);
            let mut p_int = 0.0;
            if probs.fiber > 0.0 {
                p_int += probs.fiber * p_fib;
            }
            if probs.ray > 0.0 {
                p_int += probs.ray * p_ray;
            }
            pdf += p_int * jac;
        }
        pdf
    }

    /// f from the substrate's value (no cosine, interior directions) and the finish's
    /// transmission `t` = T(θo) T(θi) / η²: their product plus the rough finish's reflection,
    /// clamped to ≥ 0, 0 where not finite (notes/bsdf.md eq. 1.4).
    #[inline(always)]
    fn value(&self, wo: Vec3, wi: Vec3, substrate: Vec3, t: f32) -> Vec3 {
        let mut f = substrate * t;
        if let Some(r) = &self.rough {
            f += Vec3::splat(r.reflection(wo, wi));
        }
        finite_nonnegative(f)
    }
}

/// `f` clamped to ≥ 0, or 0 where any channel is not finite (the last step of
/// [`WoodBsdf::value`]); branch-free.
#[inline(always)]
fn finite_nonnegative(f: Vec3) -> Vec3 {
    let finite = f.x.is_finite() & f.y.is_finite() & f.z.is_finite();
    if finite {
        f.max(Vec3::ZERO)
    } else {
        Vec3::ZERO
    }
}

/// `x`, or 0 where it is not finite (the last step of [`WoodBsdf::density`]).
#[inline(always)]
fn finite_or_zero(x: f32) -> f32 {
    if x.is_finite() {
        x
    } else {
        0.0
    }
}

impl Bsdf for WoodBsdf {
    /// f(ωo, ωi) = T(θo) T(θi) f_s(ωo', ωi') / η² (+ the rough reflection), ω' refracted into
    /// the finish (notes/bsdf.md eq. 1.4).
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        self.at_wo(wo).eval_pdf(wi, false).0
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.at_wo(wo).eval_pdf(wi, true).1
    }

    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
        if !(wo.z > 0.0) {
            return None;
        }
        let at = self.at_wo(wo);
        let (probs, view) = (&at.probs, at.rough.as_ref());
        let lobe = Self::pick(probs, uc);
        let eta = self.params.eta;
        let beta = self.params.highlight_width;
        let wi = match lobe {
            Lobe::Specular => match &self.rough {
                None => {
                    if probs.specular <= 0.0 {
                        return None;
                    }
                    let f = fresnel_dielectric(wo.z, eta);
                    return Some(BsdfSample {
                        wi: Vec3::new(-wo.x, -wo.y, wo.z),
                        f: Vec3::splat(f / wo.z),
                        pdf: probs.specular,
                        is_delta: true,
                        eta: 1.0,
                    });
                }
                Some(r) => {
                    let h = r.ggx.sample_visible_normal(wo, u);
                    2.0 * wo.dot(h) * h - wo
                }
            },
            Lobe::Diffuse => cosine_hemisphere(u),
            Lobe::Fiber | Lobe::Ray => {
                let axis = if lobe == Lobe::Fiber {
                    &self.fiber
                } else {
                    &self.ray
                };
                let about = view.map(|v| match lobe {
                    Lobe::Fiber => v.sample_fiber,
                    _ => v.sample_ray,
                });
                let wi_in = match about {
                    Some((psi, width)) => axis.sample_about(psi, u, width, self.z_crit)?,
                    None => axis.sample(refract_in(wo, eta), u, beta, self.z_crit)?,
                };
                refract_out(wi_in, eta)?
            }
        };
        if !(wi.z > 0.0) {
            return None;
        }
        let (f, pdf) = at.eval_pdf(wi, true);
        if !(pdf > 0.0) {
            return None;
        }
        Some(BsdfSample {
            wi,
            f,
            pdf,
            is_delta: false,
            eta: 1.0,
        })
    }
}

#[cfg(test)]
mod bounded_diffuse_tests;
#[cfg(test)]
mod tests;
