//! The fibre lobe of Marschner et al. 2005 ("Measuring and modeling the appearance of finished
//! wood", SIGGRAPH 2005, §4.2, eq. 3; restated as eq. 1 of Liu et al. 2016): light reflected by
//! subsurface fibres of axis u leaves on the cone ψr ≈ −ψi, spread by a Gaussian of width β.
//! All directions here are *inside* the finish. The normalisation and the sampling density are
//! derived in notes/bsdf.md.

use super::rough_transmission::TransmittedPart;
use crate::math::elementary::{acos, asin, exp, sin_cos};
use crate::math::{safe_sqrt, Frame, PI};
use glam::{Vec2, Vec3};

/// How the fibre lobe is normalised.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FiberNormalization {
    /// `g(β, ψh) / (2π max(cos ψi, cos ψr))`: directional albedo ≤ 1 at every angle (notes/bsdf.md §2).
    #[default]
    EnergyBounded,
    /// The published `g(β, ψh) / cos²(ψd/2)` (Marschner et al. 2005, eq. 3): reflects ≈ 2·k_f at
    /// normal incidence and without bound towards grazing along the fibre.
    Published,
}

/// Below this cos ψ a direction is treated as lying on the fibre axis: the cone degenerates to a
/// point there, so `sample` never returns it and `pdf` is 0 (a cap of solid angle ~3e-10 sr).
const MIN_COS_PSI: f32 = 1e-5;

/// Smallest half-width of the azimuth interval `sample` draws from. Where the arc of the cone
/// above the surface is shorter (the cone only grazes the horizon), φ is drawn from ±MIN_ARC and
/// directions off the arc are rejected: the density stays bounded instead of growing like 1/Δ
/// on a sliver where f·cos vanishes anyway.
const MIN_ARC: f32 = PI / 8.0;

/// ψr = asin(ωo·u) and cos ψr of one outgoing direction, for [`FiberAxis::eval_pdf_at`]
/// (the default: a lobe that is not used).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FiberAtWo {
    psi_r: f32,
    cos_psi_r: f32,
}

/// One part of the light a rough finish transmits as a fibre sees it: its share of the
/// transmitted energy and the mean and variance of its longitudinal angle ψ ([`FiberAxis::spread`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PsiSpread {
    pub share: f32,
    pub psi: f32,
    pub cos_psi: f32,
    pub var: f32,
}

/// A fibre axis `u` with a frame `(v, w)` around it for the azimuth of the reflection cone.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FiberAxis {
    frame: Frame,
}

/// cos x by the polynomial of [`sin_cos`]: the lobe's transcendental functions are all
/// `math::elementary`'s, which vectorise in [`FiberAxis::eval_pdf_many_at`]'s loops and give the
/// same bits there as in the one-direction forms.
#[inline(always)]
fn cos(x: f32) -> f32 {
    sin_cos(x).1
}

/// Normalised Gaussian g(β, x) = exp(−x²/2β²) / (β√(2π)) (Marschner et al. 2005, §4.2).
#[inline]
pub fn gaussian(beta: f32, x: f32) -> f32 {
    gaussian_scale(beta, exp(gaussian_exponent(beta, x)))
}

/// Directions per call of [`FiberAxis::eval_pdf_many_at`] (its columns live on the stack).
pub(crate) const BATCH: usize = 16;

/// −x²/2β², the exponent of [`gaussian`].
#[inline(always)]
fn gaussian_exponent(beta: f32, x: f32) -> f32 {
    -0.5 * (x / beta) * (x / beta)
}

/// [`gaussian`] from e = exp(−x²/2β²): e / (β√(2π)).
#[inline(always)]
fn gaussian_scale(beta: f32, e: f32) -> f32 {
    const INV_SQRT_2PI: f32 = 0.398_942_3;
    INV_SQRT_2PI / beta * e
}

/// The cosine the lobe's normalisation needs: cos ψi (energy-bounded) or cos((ψr − ψi)/2)
/// (published, Marschner et al. 2005 eq. 3).
#[inline(always)]
fn lobe_cos(norm: FiberNormalization, psi_i: f32, at: &FiberAtWo) -> f32 {
    match norm {
        FiberNormalization::EnergyBounded => cos(psi_i),
        FiberNormalization::Published => cos(0.5 * (at.psi_r - psi_i)),
    }
}

/// The lobe from g = g(β, ψi + ψr) and c = [`lobe_cos`]: g / (2π max(cos ψi, cos ψr))
/// (notes/bsdf.md §2) or g / cos²(ψd/2) (Marschner et al. 2005 eq. 3).
#[inline(always)]
fn lobe_value(norm: FiberNormalization, g: f32, c: f32, at: &FiberAtWo) -> f32 {
    match norm {
        FiberNormalization::EnergyBounded => g / (2.0 * PI * c.max(at.cos_psi_r).max(MIN_COS_PSI)),
        FiberNormalization::Published => g / (c * c).max(MIN_COS_PSI * MIN_COS_PSI),
    }
}

/// Δ = acos t on (−1, 1), π at or below −1, 0 at or above 1 (see
/// [`FiberAxis::half_width_argument`]).
#[inline(always)]
fn arc_from_argument(t: f32) -> f32 {
    if t <= -1.0 {
        PI
    } else if t >= 1.0 {
        0.0
    } else {
        acos(t)
    }
}

/// Whether [`pdf_value`] looks at Δ (else it is 0 whatever Δ is).
#[inline(always)]
fn arc_needed(wi_z: f32, z_min: f32, cos_psi: f32) -> bool {
    wi_z > z_min && cos_psi >= MIN_COS_PSI
}

/// The density of [`FiberAxis::pdf`] from g, the interior z of ωi, cos ψi and the arc's Δ:
/// g / (2 max(Δ, MIN_ARC) cos ψi), 0 where ωi cannot leave the finish, lies on the axis or off
/// every arc.
#[inline(always)]
fn pdf_value(g: f32, wi_z: f32, z_min: f32, cos_psi: f32, delta: f32) -> f32 {
    if !arc_needed(wi_z, z_min, cos_psi) || delta <= 0.0 {
        return 0.0;
    }
    g / (2.0 * delta.max(MIN_ARC) * cos_psi)
}

/// Inverse error function, single-precision polynomial of Giles 2010 ("Approximating the erfinv
/// function", GPU Computing Gems Jade, ch. 10), relative error ≲ 4e-7 on (−1, 1).
pub fn erf_inv(x: f32) -> f32 {
    let w = -((1.0 - x) * (1.0 + x)).ln();
    let p = if w < 5.0 {
        let w = w - 2.5;
        let mut p = 2.810_226_4e-8_f32;
        for c in [
            3.432_739_4e-7,
            -3.523_387_7e-6,
            -4.391_506_5e-6,
            2.185_808_7e-4,
            -1.253_725e-3,
            -4.177_681_6e-3,
            2.466_407_3e-1,
            1.501_409_4,
        ] {
            p = c + p * w;
        }
        p
    } else {
        let w = w.sqrt() - 3.0;
        let mut p = -2.002_142_6e-4_f32;
        for c in [
            1.009_505_6e-4,
            1.349_343_2e-3,
            -3.673_428_4e-3,
            5.739_507_7e-3,
            -7.622_461_3e-3,
            9.438_870_5e-3,
            1.001_674_1,
            2.832_976_8,
        ] {
            p = c + p * w;
        }
        p
    };
    p * x
}

impl FiberAxis {
    /// `u` must be a unit vector.
    pub fn new(u: Vec3) -> Self {
        FiberAxis {
            frame: Frame::from_normal(u),
        }
    }

    /// The unit fibre axis u.
    #[inline]
    pub fn axis(&self) -> Vec3 {
        self.frame.n
    }

    /// Longitudinal angle ψ = asin(ω·u) (Marschner et al. 2005, eq. 2).
    #[inline]
    fn psi(&self, w: Vec3) -> f32 {
        asin(w.dot(self.frame.n))
    }

    /// The lobe without its colour k_f, for interior directions `wo`, `wi`.
    pub fn eval(&self, wo: Vec3, wi: Vec3, beta: f32, norm: FiberNormalization) -> f32 {
        self.lobe_at(&self.at_wo(wo), wi.dot(self.frame.n), beta, norm)
            .0
    }

    /// The lobe without k_f at sin ψi = `sin_psi` for the `wo` of `at`, and its Gaussian
    /// g(β, ψi + ψr) (Marschner et al. 2005 eq. 3, normalised by `norm`): the one scalar form,
    /// of [`FiberAxis::eval`] and [`FiberAxis::eval_pdf_at`].
    #[inline(always)]
    fn lobe_at(
        &self,
        at: &FiberAtWo,
        sin_psi: f32,
        beta: f32,
        norm: FiberNormalization,
    ) -> (f32, f32) {
        let psi_i = asin(sin_psi);
        let g = gaussian(beta, psi_i + at.psi_r);
        (lobe_value(norm, g, lobe_cos(norm, psi_i, at), at), g)
    }

    /// How this fibre sees the light a rough finish transmits from the exterior direction `w`
    /// ([`TransmittedPart`]s): per part its share, the mean longitudinal angle ψ̄ = asin E[t·u]
    /// and var ψ ≈ var(t·u)/(1 − E[t·u]²) (first-order propagation through asin).
    pub fn spread(&self, w: Vec3, parts: &[TransmittedPart; 2]) -> [PsiSpread; 2] {
        parts.map(|p| {
            let (mean, var) = p.along(w, self.frame.n);
            let mean = mean.clamp(-0.9999, 0.9999);
            let cos2 = 1.0 - mean * mean;
            PsiSpread {
                share: p.share,
                psi: asin(mean),
                cos_psi: cos2.sqrt(),
                var: var / cos2,
            }
        })
    }

    /// The lobe seen through a rough finish (notes/bsdf.md §4.6): the lobe depends on the two
    /// interior directions only through ψr and ψi, so with each spread as a Gaussian in ψ the
    /// convolution of g(β, ψi + ψr) is g(√(β² + var ψr + var ψi), ψ̄i + ψ̄r); summed over the
    /// single- and multiple-scattering parts of both ends with their shares. The normalisation
    /// is taken at the mean angles.
    pub(crate) fn eval_spread(
        o: &[PsiSpread; 2],
        i: &[PsiSpread; 2],
        beta: f32,
        norm: FiberNormalization,
    ) -> f32 {
        let mut f = 0.0;
        for a in o {
            for b in i {
                let w = a.share * b.share;
                if w <= 0.0 {
                    continue;
                }
                let width = (beta * beta + a.var + b.var).sqrt();
                let g = gaussian(width, a.psi + b.psi);
                let at = FiberAtWo {
                    psi_r: a.psi,
                    cos_psi_r: a.cos_psi,
                };
                let c = match norm {
                    FiberNormalization::EnergyBounded => b.cos_psi,
                    FiberNormalization::Published => lobe_cos(norm, b.psi, &at),
                };
                f += w * lobe_value(norm, g, c, &at);
            }
        }
        f
    }

    /// What [`FiberAxis::eval_pdf_at`] needs of `wo` alone, worked out once for many `wi`.
    #[inline]
    pub fn at_wo(&self, wo: Vec3) -> FiberAtWo {
        let psi_r = self.psi(wo);
        FiberAtWo {
            psi_r,
            cos_psi_r: cos(psi_r),
        }
    }

    /// `(eval(wo, wi, beta, norm), pdf(wo, wi, beta, z_min))` for the `wo` of `at`, sharing
    /// ψi and the Gaussian g(β, ψi + ψr) between the two; the same values as the two calls.
    /// Built from the stages of [`FiberAxis::eval_pdf_many_at`], so the two agree bit for bit.
    pub fn eval_pdf_at(
        &self,
        at: &FiberAtWo,
        wi: Vec3,
        beta: f32,
        norm: FiberNormalization,
        z_min: f32,
    ) -> (f32, f32) {
        let sin_psi = wi.dot(self.frame.n);
        let (f, g) = self.lobe_at(at, sin_psi, beta, norm);
        // As in `pdf`: sin ψi clamped, ψi = asin of it (= `psi(wi)`), so g is the same; the arc
        // (an acos) only where `pdf_value` needs it.
        let (cos_psi, t) = self.arc_argument(sin_psi, z_min);
        if !arc_needed(wi.z, z_min, cos_psi) {
            return (f, 0.0);
        }
        (f, pdf_value(g, wi.z, z_min, cos_psi, arc_from_argument(t)))
    }

    /// [`FiberAxis::eval_pdf_at`] of the directions whose components are `wi[0][k]`,
    /// `wi[1][k]`, `wi[2][k]` (columns, structure of arrays) into `f[k]` and, when `with_pdf`,
    /// `pdf[k]` (else left as they are), for `k < wi[0].len() ≤ BATCH`. Stage by stage over all
    /// directions: each stage is a loop LLVM vectorises (the transcendental functions are
    /// `math::elementary`'s polynomials), instead of one dependent chain per direction.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub fn eval_pdf_many_at(
        &self,
        at: &FiberAtWo,
        wi: [&[f32]; 3],
        beta: f32,
        norm: FiberNormalization,
        z_min: f32,
        with_pdf: bool,
        f: &mut [f32],
        pdf: &mut [f32],
    ) {
        let n = wi[0].len();
        let [wx, wy, wz] = wi;
        let (wx, wy, wz) = (&wx[..n], &wy[..n], &wz[..n]);
        assert!(n <= BATCH && f.len() >= n && pdf.len() >= n);
        let (mut sin_psi, mut psi, mut g, mut c) =
            ([0.0; BATCH], [0.0; BATCH], [0.0; BATCH], [0.0; BATCH]);
        for k in 0..n {
            sin_psi[k] = Vec3::new(wx[k], wy[k], wz[k]).dot(self.frame.n);
        }
        for k in 0..n {
            psi[k] = asin(sin_psi[k]);
        }
        for k in 0..n {
            g[k] = gaussian_exponent(beta, psi[k] + at.psi_r);
        }
        for x in &mut g[..n] {
            *x = exp(*x);
        }
        for k in 0..n {
            g[k] = gaussian_scale(beta, g[k]);
            c[k] = lobe_cos(norm, psi[k], at);
        }
        for k in 0..n {
            f[k] = lobe_value(norm, g[k], c[k], at);
        }
        if !with_pdf {
            return;
        }
        let (cos_psi, t) = (&mut psi, &mut c);
        for k in 0..n {
            (cos_psi[k], t[k]) = self.arc_argument(sin_psi[k], z_min);
        }
        for k in 0..n {
            if arc_needed(wz[k], z_min, cos_psi[k]) {
                t[k] = arc_from_argument(t[k]);
            }
        }
        for k in 0..n {
            pdf[k] = pdf_value(g[k], wz[k], z_min, cos_psi[k], t[k]);
        }
    }

    /// cos ψ of a direction with ω·u = `sin_psi` (clamped), and the argument of the arc cosine
    /// of [`FiberAxis::half_width`] for it ([`arc_from_argument`] gives Δ).
    #[inline(always)]
    fn arc_argument(&self, sin_psi: f32, z_min: f32) -> (f32, f32) {
        let sin_psi = sin_psi.clamp(-1.0, 1.0);
        let cos_psi = safe_sqrt(1.0 - sin_psi * sin_psi);
        (cos_psi, self.half_width_argument(sin_psi, cos_psi, z_min))
    }

    /// Half-width Δ of the azimuth arc of the cone at longitudinal angle ψ whose directions have
    /// z > `z_min` (those that can leave the finish): z(φ) = sinψ u_z + cosψ h cos(φ − φ0),
    /// with h = |(v_z, w_z)|. Returns (Δ, φ0); Δ = 0 when no part of the cone qualifies.
    #[inline]
    fn arc(&self, sin_psi: f32, cos_psi: f32, z_min: f32) -> (f32, f32) {
        let (v, w) = (self.frame.s, self.frame.t);
        (self.half_width(sin_psi, cos_psi, z_min), w.z.atan2(v.z))
    }

    /// Δ of [`FiberAxis::arc`] alone.
    #[inline]
    fn half_width(&self, sin_psi: f32, cos_psi: f32, z_min: f32) -> f32 {
        arc_from_argument(self.half_width_argument(sin_psi, cos_psi, z_min))
    }

    /// t with Δ = acos t clamped to [0, π] ([`arc_from_argument`]): z(φ) > z_min ⇔
    /// cos(φ − φ0) > t = (z_min − sinψ u_z) / (cosψ h). A cone whose z does not vary with φ
    /// (cosψ h < 1e-7) is wholly above (t = −1, Δ = π) or below (t = 1, Δ = 0).
    #[inline(always)]
    fn half_width_argument(&self, sin_psi: f32, cos_psi: f32, z_min: f32) -> f32 {
        let (u, v, w) = (self.frame.n, self.frame.s, self.frame.t);
        let h = (v.z * v.z + w.z * w.z).sqrt();
        let a = sin_psi * u.z;
        let b = cos_psi * h;
        if b < 1e-7 {
            return if a > z_min { -1.0 } else { 1.0 };
        }
        (z_min - a) / b
    }

    /// Samples an interior direction: ψi from the Gaussian about −ψr (inverse CDF), φ uniform on
    /// the arc of the cone above `z_min` (widened to at least ±`MIN_ARC`). `None` when ψi falls
    /// outside (−π/2, π/2) or φ off the arc; [`FiberAxis::pdf`] is the density of the returned
    /// directions exactly.
    pub fn sample(&self, wo: Vec3, u: Vec2, beta: f32, z_min: f32) -> Option<Vec3> {
        self.sample_about(self.psi(wo), u, beta, z_min)
    }

    /// [`FiberAxis::sample`] for a view given by its longitudinal angle ψr alone.
    pub(crate) fn sample_about(&self, psi_r: f32, u: Vec2, beta: f32, z_min: f32) -> Option<Vec3> {
        let x = (2.0 * u.x - 1.0).clamp(-0.999_999_9, 0.999_999_9);
        let psi_i = -psi_r + beta * std::f32::consts::SQRT_2 * erf_inv(x);
        if !(psi_i.abs() < 0.5 * PI) {
            return None;
        }
        let (sin_psi, cos_psi) = sin_cos(psi_i);
        if cos_psi < MIN_COS_PSI {
            return None;
        }
        let (delta, phi0) = self.arc(sin_psi, cos_psi, z_min);
        if delta <= 0.0 {
            return None;
        }
        let width = delta.max(MIN_ARC);
        let offset = width * (2.0 * u.y - 1.0);
        if offset.abs() >= delta {
            return None;
        }
        let phi = phi0 + offset;
        let (sp, cp) = sin_cos(phi);
        let w = sin_psi * self.frame.n + cos_psi * (cp * self.frame.s + sp * self.frame.t);
        if !(w.z > z_min) {
            return None;
        }
        Some(w)
    }

    /// Density per unit solid angle of [`FiberAxis::sample`]: g(β, ψi + ψr) / (2 max(Δ(ψi), MIN_ARC) cos ψi),
    /// the Jacobian dω = cos ψ dψ dφ of the fibre's (ψ, φ) coordinates (notes/bsdf.md §3).
    pub fn pdf(&self, wo: Vec3, wi: Vec3, beta: f32, z_min: f32) -> f32 {
        self.pdf_about(self.psi(wo), wi, beta, z_min)
    }

    /// [`FiberAxis::pdf`] for a view given by its longitudinal angle ψr alone.
    pub(crate) fn pdf_about(&self, psi_r: f32, wi: Vec3, beta: f32, z_min: f32) -> f32 {
        let sin_psi = wi.dot(self.frame.n).clamp(-1.0, 1.0);
        let (cos_psi, t) = self.arc_argument(sin_psi, z_min);
        if !arc_needed(wi.z, z_min, cos_psi) {
            return 0.0;
        }
        let g = gaussian(beta, asin(sin_psi) + psi_r);
        pdf_value(g, wi.z, z_min, cos_psi, arc_from_argument(t))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{uniform_sphere, Pcg32};

    #[test]
    fn erf_inv_inverts_statrs_erf() {
        for i in 1..200 {
            let y = -1.0 + i as f64 / 100.0;
            let x = erf_inv(y as f32) as f64;
            let back = statrs::function::erf::erf(x);
            assert!((back - y).abs() < 2e-6 * (1.0 + y.abs()), "{y}: {back}");
        }
    }

    #[test]
    fn lobe_is_reciprocal_and_peaks_on_the_cone() {
        let ax = FiberAxis::new(Vec3::new(1.0, 0.0, -0.3).normalize());
        let mut r = Pcg32::new(11, 0);
        for _ in 0..1000 {
            let a = uniform_sphere(r.next_vec2());
            let b = uniform_sphere(r.next_vec2());
            for n in [
                FiberNormalization::EnergyBounded,
                FiberNormalization::Published,
            ] {
                let (f1, f2) = (ax.eval(a, b, 0.2, n), ax.eval(b, a, 0.2, n));
                assert!((f1 - f2).abs() <= 1e-5 * f1.max(f2), "{f1} {f2}");
            }
        }
        // On the specular cone (ψi = −ψr) the Gaussian is at its maximum 1/(β√2π).
        let wo = Vec3::new(0.3, 0.2, 0.93).normalize();
        let u = ax.axis();
        let wi = (wo - 2.0 * wo.dot(u) * u).normalize();
        let psi = wo.dot(u).asin();
        let want = gaussian(0.2, 0.0) / (2.0 * PI * psi.cos());
        let got = ax.eval(wo, wi, 0.2, FiberNormalization::EnergyBounded);
        assert!((got - want).abs() < 1e-4 * want);
    }

    #[test]
    fn arc_contains_exactly_the_directions_above_z_min() {
        let ax = FiberAxis::new(Vec3::new(0.5, 0.5, 0.7).normalize());
        let mut r = Pcg32::new(3, 1);
        for _ in 0..2000 {
            let wo = uniform_sphere(r.next_vec2());
            if let Some(w) = ax.sample(wo, r.next_vec2(), 0.3, 0.4) {
                assert!(w.z > 0.4 && (w.length() - 1.0).abs() < 1e-5);
                assert!(ax.pdf(wo, w, 0.3, 0.4) > 0.0);
            }
        }
    }
}
