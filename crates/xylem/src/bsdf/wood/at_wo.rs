//! [`WoodAtWo`]: the wood BSDF with ωo fixed, for a renderer that lights one shading point by
//! many light samples; the stages of `Bsdf::eval` and `pdf`, shared through [`WoodBsdf::value`]
//! and [`WoodBsdf::density`].

use super::super::fiber::{FiberAtWo, FiberAxis, BATCH};
use super::super::fresnel::refract_in;
use super::{About, LobeProbs, RoughView, WoodBsdf};
use glam::Vec3;

/// [`WoodBsdf`]'s `eval` and `pdf` for one fixed `wo`, with what depends on `wo` alone — its
/// refraction into the finish, the transmittance T(θo), the lobe probabilities and the fibre
/// angles ψr — worked out once, and ψi and the Gaussian shared between `eval` and `pdf`. A
/// renderer lighting one shading point by many light samples (next-event estimation, a light
/// sweep) uses it; the values are those of `eval` and `pdf` exactly (tested).
#[derive(Clone, Copy, Debug)]
pub struct WoodAtWo<'a> {
    bsdf: &'a WoodBsdf,
    wo: Vec3,
    t_o: f32,
    probs: LobeProbs,
    fiber: FiberAtWo,
    ray: FiberAtWo,
    rough: Option<RoughView>,
}

impl WoodBsdf {
    /// This BSDF with `wo` fixed.
    pub fn at_wo(&self, wo: Vec3) -> WoodAtWo<'_> {
        let wo_in = refract_in(wo, self.params.eta);
        WoodAtWo {
            bsdf: self,
            wo,
            t_o: self.transmittance(wo.z),
            probs: self.lobe_probs(wo),
            fiber: self.fiber.at_wo(wo_in),
            ray: self.ray.at_wo(wo_in),
            rough: self.rough_view(wo),
        }
    }
}

impl WoodAtWo<'_> {
    /// `(eval(wo, wi), pdf(wo, wi))`; the density only when `with_pdf` (else 0).
    pub fn eval_pdf(&self, wi: Vec3, with_pdf: bool) -> (Vec3, f32) {
        let (b, probs) = (self.bsdf, &self.probs);
        if !(self.wo.z > 0.0 && wi.z > 0.0) {
            return (Vec3::ZERO, 0.0);
        }
        let p = &b.params;
        let wi_in = refract_in(wi, p.eta);
        if let Some(view) = &self.rough {
            let (f_fib, f_ray) = b.rough_lobes(view, wi);
            let f = self.value(wi, self.transmission(wi.z), f_fib, f_ray);
            if !with_pdf {
                return (f, 0.0);
            }
            let (p_fib, p_ray) = b.lobe_densities(probs, About::Rough(view), wi_in);
            return (f, self.density(wi, wi_in, p_fib, p_ray));
        }
        let lobe = |axis: &FiberAxis, at: &FiberAtWo, in_f: bool, in_pdf: bool| {
            if in_f || (with_pdf && in_pdf) {
                axis.eval_pdf_at(at, wi_in, p.highlight_width, b.norm, b.z_crit)
            } else {
                (0.0, 0.0)
            }
        };
        let (f_fib, p_fib) = lobe(&b.fiber, &self.fiber, p.ray_mask < 1.0, probs.fiber > 0.0);
        let (f_ray, p_ray) = lobe(&b.ray, &self.ray, p.ray_mask > 0.0, probs.ray > 0.0);
        let f = self.value(wi, self.transmission(wi.z), f_fib, f_ray);
        if !with_pdf {
            return (f, 0.0);
        }
        (f, self.density(wi, wi_in, p_fib, p_ray))
    }

    /// [`WoodAtWo::eval_pdf`] of every `wi[k]` into `f[k]`, `pdf[k]` (`f`, `pdf` as long as
    /// `wi`): the same stages, each run over `BATCH` directions at a time ([`FiberAxis::
    /// eval_pdf_many_at`] for the fibre lobes), so that the same values come out (tested) with
    /// the arithmetic in SIMD lanes.
    #[inline(always)]
    pub fn eval_pdf_many(&self, wi: &[Vec3], with_pdf: bool, f: &mut [Vec3], pdf: &mut [f32]) {
        assert!(f.len() == wi.len() && pdf.len() == wi.len());
        if self.rough.is_some() {
            // Under a rough finish every direction has its own spreads: one at a time.
            for k in 0..wi.len() {
                (f[k], pdf[k]) = self.eval_pdf(wi[k], with_pdf);
            }
            return;
        }
        let (b, probs) = (self.bsdf, &self.probs);
        let p = &b.params;
        for ((wi, f), pdf) in wi
            .chunks(BATCH)
            .zip(f.chunks_mut(BATCH))
            .zip(pdf.chunks_mut(BATCH))
        {
            let n = wi.len();
            let mut wi_in = [Vec3::ZERO; BATCH];
            for k in 0..n {
                wi_in[k] = refract_in(wi[k], p.eta);
            }
            let wi_in = &wi_in[..n];
            let (f_fib, p_fib) = self.lobe_many(
                &b.fiber,
                &self.fiber,
                wi_in,
                with_pdf,
                p.ray_mask < 1.0,
                probs.fiber > 0.0,
            );
            let (f_ray, p_ray) = self.lobe_many(
                &b.ray,
                &self.ray,
                wi_in,
                with_pdf,
                p.ray_mask > 0.0,
                probs.ray > 0.0,
            );
            let mut t = [0.0; BATCH];
            for k in 0..n {
                t[k] = self.transmission(wi[k].z);
            }
            for k in 0..n {
                let above = self.wo.z > 0.0 && wi[k].z > 0.0;
                f[k] = self.value(wi[k], t[k], f_fib[k], f_ray[k]);
                pdf[k] = if with_pdf {
                    self.density(wi[k], wi_in[k], p_fib[k], p_ray[k])
                } else {
                    0.0
                };
                if !above {
                    (f[k], pdf[k]) = (Vec3::ZERO, 0.0);
                }
            }
        }
    }

    /// One fibre lobe (`axis`, seen from `at`) at up to [`BATCH`] interior directions, its
    /// values and densities, or zeros where neither is needed (`in_f`: the lobe is in f;
    /// `in_pdf`: it is sampled). A method rather than a closure so that it inlines into the
    /// caller's SIMD level.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn lobe_many(
        &self,
        axis: &FiberAxis,
        at: &FiberAtWo,
        wi_in: &[Vec3],
        with_pdf: bool,
        in_f: bool,
        in_pdf: bool,
    ) -> ([f32; BATCH], [f32; BATCH]) {
        let b = self.bsdf;
        let (mut f, mut pdf) = ([0.0; BATCH], [0.0; BATCH]);
        if in_f || (with_pdf && in_pdf) {
            let (beta, norm) = (b.params.highlight_width, b.norm);
            axis.eval_pdf_many_at(at, wi_in, beta, norm, b.z_crit, with_pdf, &mut f, &mut pdf);
        }
        (f, pdf)
    }

    /// T(θo) T(θi) / η², the finish's share of f (notes/bsdf.md eq. 1.4) for cos θi = `wi_z`.
    #[inline(always)]
    fn transmission(&self, wi_z: f32) -> f32 {
        let b = self.bsdf;
        self.t_o * b.transmittance(wi_z) * b.inv_eta2
    }

    /// f from the finish's [`WoodAtWo::transmission`] `t` and the fibre and ray lobes' values at
    /// ωi ([`WoodBsdf::value`] of their blend).
    #[inline(always)]
    fn value(&self, wi: Vec3, t: f32, f_fib: f32, f_ray: f32) -> Vec3 {
        let b = self.bsdf;
        b.value(self.wo, wi, b.blend(f_fib, f_ray), t)
    }

    /// The density from the lobes' interior densities ([`WoodBsdf::density`] at this ωo).
    #[inline(always)]
    fn density(&self, wi: Vec3, wi_in: Vec3, p_fib: f32, p_ray: f32) -> f32 {
        let b = self.bsdf;
        b.density(&self.probs, self.wo, wi, wi_in, p_fib, p_ray)
    }
}
