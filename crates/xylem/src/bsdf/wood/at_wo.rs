//! [`WoodAtWo`]: the wood BSDF with ωo fixed, for a renderer that lights one shading point by
//! many light samples; the stages of `Bsdf::eval` and `pdf`, shared through [`WoodBsdf::value`]
//! and [`WoodBsdf::density`].

use super::super::fiber::{FiberAtWo, FiberAxis, BATCH};
use super::super::fresnel::refract_in;
use super::{finite_nonnegative, finite_or_zero, LobeProbs, RoughView, WoodBsdf};
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
    pub(super) probs: LobeProbs,
    fiber: FiberAtWo,
    ray: FiberAtWo,
    pub(super) rough: Option<RoughView>,
}

impl WoodBsdf {
    /// This BSDF with `wo` fixed.
    pub fn at_wo(&self, wo: Vec3) -> WoodAtWo<'_> {
        let wo_in = refract_in(wo, self.params.eta);
        let prepare = |axis: &FiberAxis, used: bool| {
            if used {
                axis.at_wo(wo_in)
            } else {
                FiberAtWo::default()
            }
        };
        WoodAtWo {
            bsdf: self,
            wo,
            t_o: self.transmittance(wo.z),
            probs: self.lobe_probs(wo),
            // A lobe the ray mask leaves out is neither evaluated nor sampled.
            fiber: prepare(&self.fiber, self.params.ray_mask < 1.0),
            ray: prepare(&self.ray, self.params.ray_mask > 0.0),
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
            let (p_fib, p_ray) = b.rough_lobe_densities(probs, view, wi_in);
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
    /// `wi`): [`WoodAtWo::eval_pdf_lanes`] on columns copied `BATCH` directions at a time.
    pub(crate) fn eval_pdf_many(
        &self,
        wi: &[Vec3],
        with_pdf: bool,
        f: &mut [Vec3],
        pdf: &mut [f32],
    ) {
        assert!(f.len() == wi.len() && pdf.len() == wi.len());
        for ((wi, f), pdf) in wi
            .chunks(BATCH)
            .zip(f.chunks_mut(BATCH))
            .zip(pdf.chunks_mut(BATCH))
        {
            let n = wi.len();
            let (mut w, mut v) = ([[0.0; BATCH]; 3], [[0.0; BATCH]; 3]);
            for (k, d) in wi.iter().enumerate() {
                [w[0][k], w[1][k], w[2][k]] = d.to_array();
            }
            let [vx, vy, vz] = &mut v;
            self.eval_pdf_lanes(
                [&w[0][..n], &w[1][..n], &w[2][..n]],
                with_pdf,
                [&mut vx[..n], &mut vy[..n], &mut vz[..n]],
                pdf,
            );
            for (k, f) in f.iter_mut().enumerate() {
                *f = Vec3::new(v[0][k], v[1][k], v[2][k]);
            }
        }
    }

    /// [`WoodAtWo::eval_pdf`] of the directions whose components are `wi[0][k]`, `wi[1][k]`,
    /// `wi[2][k]` (columns: structure of arrays, one lane per direction) into the colour columns
    /// `f[c][k]` and `pdf[k]` (all as long as `pdf`): the same stages, each a loop over
    /// `BATCH` directions at a time ([`FiberAxis::eval_pdf_many_at`] for the fibre lobes), so
    /// that the same values come out (tested) with the arithmetic in SIMD lanes. Under a rough
    /// finish every direction has its own spreads, and they are taken one at a time.
    #[inline(always)]
    pub(crate) fn eval_pdf_lanes(
        &self,
        wi: [&[f32]; 3],
        with_pdf: bool,
        f: [&mut [f32]; 3],
        pdf: &mut [f32],
    ) {
        let n = pdf.len();
        let [wx, wy, wz] = wi;
        let [fr, fg, fb] = f;
        let (wx, wy, wz) = (&wx[..n], &wy[..n], &wz[..n]);
        let (fr, fg, fb) = (&mut fr[..n], &mut fg[..n], &mut fb[..n]);
        if self.rough.is_some() {
            for k in 0..n {
                let (v, p) = self.eval_pdf(Vec3::new(wx[k], wy[k], wz[k]), with_pdf);
                [fr[k], fg[k], fb[k], pdf[k]] = [v.x, v.y, v.z, p];
            }
            return;
        }
        let (b, probs) = (self.bsdf, &self.probs);
        let p = &b.params;
        for start in (0..n).step_by(BATCH) {
            let m = BATCH.min(n - start);
            let lanes = start..start + m;
            let (x, y, z) = (&wx[lanes.clone()], &wy[lanes.clone()], &wz[lanes.clone()]);
            let mut wi_in = [[0.0; BATCH]; 3];
            for k in 0..m {
                let w = refract_in(Vec3::new(x[k], y[k], z[k]), p.eta);
                [wi_in[0][k], wi_in[1][k], wi_in[2][k]] = w.to_array();
            }
            let wi_in = [&wi_in[0][..m], &wi_in[1][..m], &wi_in[2][..m]];
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
            let (fr, fg, fb, pdf) = (
                &mut fr[lanes.clone()],
                &mut fg[lanes.clone()],
                &mut fb[lanes.clone()],
                &mut pdf[lanes],
            );
            for k in 0..m {
                let above = (self.wo.z > 0.0) & (z[k] > 0.0);
                let t = self.transmission_from(b.smooth_transmittance(z[k]));
                let v = finite_nonnegative(b.blend(f_fib[k], f_ray[k]) * t);
                let d = b.substrate_density(probs, z[k], wi_in[2][k], p_fib[k], p_ray[k]);
                let d = if with_pdf { finite_or_zero(d) } else { 0.0 };
                let (v, d) = if above { (v, d) } else { (Vec3::ZERO, 0.0) };
                [fr[k], fg[k], fb[k], pdf[k]] = [v.x, v.y, v.z, d];
            }
        }
    }

    /// One fibre lobe (`axis`, seen from `at`) at up to `BATCH` interior directions (columns),
    /// its values and densities, or zeros where neither is needed (`in_f`: the lobe is in f;
    /// `in_pdf`: it is sampled). A method rather than a closure so that it inlines into the
    /// caller's SIMD level.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn lobe_many(
        &self,
        axis: &FiberAxis,
        at: &FiberAtWo,
        wi_in: [&[f32]; 3],
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
        self.transmission_from(self.bsdf.transmittance(wi_z))
    }

    /// [`WoodAtWo::transmission`] from T(θi) = `t_i`.
    #[inline(always)]
    fn transmission_from(&self, t_i: f32) -> f32 {
        self.t_o * t_i * self.bsdf.inv_eta2
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
