//! The per-texel model and its fit. The model is the renderer's own finished-wood BSDF
//! ([`WoodBsdf`], Marschner et al. 2005 §4: Lambertian substrate plus the fibre lobe under a
//! smooth dielectric finish), evaluated through the same `eval_pdf_many` the sweep renderer
//! lights its frames with, so nothing here restates a BSDF formula.
//!
//! A pixel's radiance divided by its irradiance factor (I/d² or E) is
//! z_c = (ρ''_c D + k_f,c F(u, β)) cos θi per channel (notes/fit.md eq. 1): linear in the six
//! colour numbers, non-linear in the fibre axis u (in-plane angle φ, dip δ) and β. The colours
//! are projected out exactly for every (φ, δ, β) (variable projection, Golub & Pereyra 1973), so
//! Levenberg–Marquardt (Marquardt 1963) searches three dimensions only. Initialisation: the
//! highlight first — u ⊥ the refracted half-vectors of the frames where the texel is brighter than
//! its diffuse (the ψh = 0 cone, Marschner et al. 2005 eq. 3; notes/fit.md §2).

use crate::bsdf::{refract_in, WoodBsdf, WoodBsdfParams};
use glam::{Mat3, Vec3};

/// One texel's observations: the view direction and per frame the light direction (board
/// frame), the normalised radiance z (radiance / irradiance factor) and a weight (0: rejected).
#[derive(Clone, Debug, Default)]
pub struct TexelData {
    /// View direction (unit, board frame).
    pub wo: Vec3,
    /// Light direction per frame (unit, board frame).
    pub wi: Vec<Vec3>,
    /// Normalised radiance per frame: pixel radiance / irradiance factor, linear RGB.
    pub z: Vec<Vec3>,
    /// Weight per frame: 1 kept, 0 rejected (clipped, grazing or glint).
    pub w: Vec<f32>,
}

/// A fitted texel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TexelFit {
    /// Substrate albedo ρ' (the bounded one the BSDF uses), linear RGB.
    pub diffuse: Vec3,
    /// Fibre colour k_f of the energy-bounded lobe.
    pub fiber_color: Vec3,
    /// Unit fibre axis (board frame), a line: the sign is chosen with x ≥ 0 (or y ≥ 0 at x = 0).
    pub axis: Vec3,
    /// β, radians.
    pub beta: f32,
    /// √(Σ w |r|² / Σ w |z|²) over the frames kept.
    pub residual: f32,
    /// Frames kept after rejection.
    pub used: u32,
}

/// β searched in [0.5°, 45°], dip in ±80° (notes/fit.md §2).
const BETA_MIN: f32 = 0.5 * std::f32::consts::PI / 180.0;
const BETA_MAX: f32 = 45.0 * std::f32::consts::PI / 180.0;
const DIP_MAX: f32 = 80.0 * std::f32::consts::PI / 180.0;

/// u(φ, δ) = (cos δ cos φ, cos δ sin φ, sin δ).
pub(crate) fn axis_of(phi: f32, dip: f32) -> Vec3 {
    let (sd, cd) = dip.sin_cos();
    let (sp, cp) = phi.sin_cos();
    Vec3::new(cd * cp, cd * sp, sd)
}

fn bsdf(eta: f32, diffuse: Vec3, fiber_color: Vec3, u: Vec3, beta: f32) -> WoodBsdf {
    WoodBsdf::new(WoodBsdfParams {
        diffuse,
        fiber_color,
        fiber_dir: u,
        ray_dir: Vec3::Z,
        ray_mask: 0.0,
        highlight_width: beta.clamp(BETA_MIN, BETA_MAX),
        eta,
        roughness: 0.0,
    })
    .expect("fit parameters are kept inside the BSDF's ranges")
}

/// Scratch buffers of one worker.
#[derive(Default)]
pub struct Scratch {
    f: Vec<Vec3>,
    pdf: Vec<f32>,
    b: Vec<f32>,
}

/// The texel's model columns: `a[k]` = D cos θi per unit ρ'' and, per (u, β), the fibre column
/// F cos θi per unit k_f, with the channel-wise linear fit of the colours.
struct Problem<'a> {
    d: &'a TexelData,
    eta: f32,
    a: Vec<f32>,
    /// The finish's inverse series ρ'' → ρ' (a BSDF of this η).
    unit: WoodBsdf,
}

/// The colours (ρ''_c, k_f,c) minimising Σ w (z_c − ρ'' a − k b)² per channel, both ≥ 0, and
/// the weighted squared residual.
fn colours(a: &[f32], b: &[f32], d: &TexelData) -> (Vec3, Vec3, f32) {
    let (mut saa, mut sab, mut sbb) = (0.0f64, 0.0f64, 0.0f64);
    let (mut saz, mut sbz, mut szz) = ([0.0f64; 3], [0.0f64; 3], 0.0f64);
    for k in 0..a.len() {
        let w = d.w[k] as f64;
        if w == 0.0 {
            continue;
        }
        let (ak, bk) = (a[k] as f64, b[k] as f64);
        saa += w * ak * ak;
        sab += w * ak * bk;
        sbb += w * bk * bk;
        for c in 0..3 {
            let z = d.z[k][c] as f64;
            saz[c] += w * ak * z;
            sbz[c] += w * bk * z;
            szz += w * z * z;
        }
    }
    let (mut rho, mut kf) = (Vec3::ZERO, Vec3::ZERO);
    let mut cost = szz;
    for c in 0..3 {
        let det = saa * sbb - sab * sab;
        let (mut x, mut y) = if det > 1e-12 * saa * sbb && det > 0.0 {
            (
                (saz[c] * sbb - sbz[c] * sab) / det,
                (sbz[c] * saa - saz[c] * sab) / det,
            )
        } else {
            (-1.0, -1.0)
        };
        if !(x >= 0.0 && y >= 0.0) {
            // The best on the boundary: one colour 0, the other by its own 1-D fit.
            let xa = if saa > 0.0 {
                (saz[c] / saa).max(0.0)
            } else {
                0.0
            };
            let yb = if sbb > 0.0 {
                (sbz[c] / sbb).max(0.0)
            } else {
                0.0
            };
            let ca = -2.0 * xa * saz[c] + xa * xa * saa;
            let cb = -2.0 * yb * sbz[c] + yb * yb * sbb;
            (x, y) = if ca <= cb { (xa, 0.0) } else { (0.0, yb) };
        }
        // Σ w (z − x a − y b)² = Σ w z² − 2x Σ w a z − 2y Σ w b z + x² Saa + 2xy Sab + y² Sbb.
        cost +=
            -2.0 * x * saz[c] - 2.0 * y * sbz[c] + x * x * saa + 2.0 * x * y * sab + y * y * sbb;
        rho[c] = x as f32;
        kf[c] = y as f32;
    }
    (rho, kf, cost.max(0.0) as f32)
}

impl<'a> Problem<'a> {
    fn new(d: &'a TexelData, eta: f32, s: &mut Scratch) -> Problem<'a> {
        // The diffuse column from the BSDF itself: f of a fibre-free grey board divided by its
        // effective albedo (notes/fit.md eq. 1).
        let grey = bsdf(eta, Vec3::splat(0.5), Vec3::ZERO, Vec3::X, 0.1);
        let eff = grey.effective_diffuse().x;
        let n = d.wi.len();
        s.f.resize(n, Vec3::ZERO);
        s.pdf.resize(n, 0.0);
        grey.at_wo(d.wo)
            .eval_pdf_many(&d.wi, false, &mut s.f[..n], &mut s.pdf[..n]);
        let a = (0..n)
            .map(|k| s.f[k].x / eff * d.wi[k].z.max(0.0))
            .collect();
        Problem {
            d,
            eta,
            a,
            unit: grey,
        }
    }

    /// The fibre column for (φ, δ, β) into `s.b`.
    fn fibre_column(&self, p: [f32; 3], s: &mut Scratch) {
        let n = self.d.wi.len();
        let u = axis_of(p[0], p[1]);
        let b = bsdf(self.eta, Vec3::ZERO, Vec3::ONE, u, p[2].exp());
        s.f.resize(n, Vec3::ZERO);
        s.pdf.resize(n, 0.0);
        b.at_wo(self.d.wo)
            .eval_pdf_many(&self.d.wi, false, &mut s.f[..n], &mut s.pdf[..n]);
        s.b.clear();
        s.b.extend((0..n).map(|k| s.f[k].x * self.d.wi[k].z.max(0.0)));
    }

    /// Variable-projection cost at p = (φ, δ, ln β).
    fn cost(&self, p: [f32; 3], s: &mut Scratch) -> f32 {
        self.fibre_column(p, s);
        colours(&self.a, &s.b, self.d).2
    }

    /// The residual vector √w (z − model) (3 per frame) at p.
    fn residuals(&self, p: [f32; 3], s: &mut Scratch, out: &mut Vec<f32>) -> f32 {
        self.fibre_column(p, s);
        let (rho, kf, cost) = colours(&self.a, &s.b, self.d);
        out.clear();
        for k in 0..self.a.len() {
            let w = self.d.w[k].sqrt();
            let m = rho * self.a[k] + kf * s.b[k];
            let r = (self.d.z[k] - m) * w;
            out.extend_from_slice(&r.to_array());
        }
        cost
    }
}

fn clamp_params(p: [f32; 3]) -> [f32; 3] {
    let p = p.map(|x| if x.is_finite() { x } else { 0.0 });
    [
        p[0],
        p[1].clamp(-DIP_MAX, DIP_MAX),
        p[2].clamp(BETA_MIN.ln(), BETA_MAX.ln()),
    ]
}

/// Levenberg–Marquardt (Marquardt 1963) on the projected residual, forward-difference Jacobian,
/// at most `iters` accepted-or-rejected steps.
fn levenberg_marquardt(prob: &Problem, mut p: [f32; 3], iters: usize, s: &mut Scratch) -> [f32; 3] {
    let mut r0 = Vec::new();
    let mut rj = Vec::new();
    let mut cost = prob.residuals(p, s, &mut r0);
    let mut lambda = 1e-2f32;
    const H: f32 = 1e-3;
    for _ in 0..iters {
        let mut jac = [Vec::new(), Vec::new(), Vec::new()];
        for (i, col) in jac.iter_mut().enumerate() {
            let mut q = p;
            q[i] += H;
            prob.residuals(q, s, &mut rj);
            *col = rj.iter().zip(&r0).map(|(a, b)| (a - b) / H).collect();
        }
        let mut jtj = [[0.0f64; 3]; 3];
        let mut jtr = [0.0f64; 3];
        for k in 0..r0.len() {
            for i in 0..3 {
                jtr[i] += (jac[i][k] * r0[k]) as f64;
                for j in 0..3 {
                    jtj[i][j] += (jac[i][k] * jac[j][k]) as f64;
                }
            }
        }
        let mut improved = false;
        for _ in 0..6 {
            let mut m = jtj;
            for (i, row) in m.iter_mut().enumerate() {
                row[i] += lambda as f64 * (jtj[i][i] + 1e-12);
            }
            let mat = Mat3::from_cols_array_2d(&m.map(|r| r.map(|x| x as f32))).transpose();
            if mat.determinant().abs() < 1e-30 {
                lambda *= 10.0;
                continue;
            }
            let step = -(mat.inverse() * Vec3::from_array(jtr.map(|x| x as f32)));
            if !step.is_finite() {
                // A degenerate Jacobian (e.g. too few arcs): damp harder, never step to NaN.
                lambda *= 10.0;
                continue;
            }
            let q = clamp_params([p[0] + step.x, p[1] + step.y, p[2] + step.z]);
            let c = prob.residuals(q, s, &mut rj);
            if c < cost {
                let gain = (cost - c) / cost.max(1e-30);
                p = q;
                cost = c;
                std::mem::swap(&mut r0, &mut rj);
                lambda = (lambda * 0.3).max(1e-6);
                improved = true;
                // Converged: the cost or the parameters no longer move.
                if gain < 1e-4 || step.abs().max_element() < 2e-4 {
                    return p;
                }
                break;
            }
            lambda *= 10.0;
        }
        if !improved {
            break;
        }
    }
    p
}

/// The unit eigenvector of the smallest eigenvalue of the symmetric positive semi-definite `m`
/// (inverse iteration on m + ε I).
fn smallest_eigenvector(m: Mat3) -> Option<Vec3> {
    let tr = m.x_axis.x + m.y_axis.y + m.z_axis.z;
    if !(tr > 0.0) {
        return None;
    }
    let inv = (m + Mat3::from_diagonal(Vec3::splat(1e-4 * tr))).inverse();
    let mut v = Vec3::new(0.3, 0.5, 0.8).normalize();
    for _ in 0..12 {
        v = (inv * v).try_normalize()?;
    }
    Some(v)
}

/// The highlight-first starting point (notes/fit.md §2): a diffuse level from the dimmer frames,
/// the frames' excess over it, and the axis u minimising Σ excess² (u·ĥ)², ĥ the normalised sum
/// of the refracted light and view directions (ψh = 0 ⇔ u·(ω′i + ω′r) = 0).
fn highlight_axis(prob: &Problem) -> Option<Vec3> {
    let d = prob.d;
    let mut ratios: Vec<f32> = (0..d.wi.len())
        .filter(|&k| d.w[k] > 0.0 && prob.a[k] > 0.0)
        .map(|k| d.z[k].element_sum() / 3.0 / prob.a[k])
        .collect();
    if ratios.len() < 4 {
        return None;
    }
    let q = ratios.len() * 3 / 10;
    let (_, base, _) = ratios.select_nth_unstable_by(q, |a, b| a.total_cmp(b));
    let base = *base;
    let wo_in = refract_in(d.wo, prob.eta);
    let mut m = Mat3::ZERO;
    for k in 0..d.wi.len() {
        if d.w[k] == 0.0 {
            continue;
        }
        let e = (d.z[k].element_sum() / 3.0 - base * prob.a[k]).max(0.0);
        let Some(h) = (refract_in(d.wi[k], prob.eta) + wo_in).try_normalize() else {
            continue;
        };
        let w = e * e;
        m += Mat3::from_cols(h * (w * h.x), h * (w * h.y), h * (w * h.z));
    }
    smallest_eigenvector(m)
}

/// Fits one texel (notes/fit.md §2): highlight-first axis, a scan over β, Levenberg–Marquardt
/// on (φ, δ, ln β), outlier frames (residual > 5 robust σ, at most a fifth of the frames)
/// rejected and the fit refined once more. `None` when fewer than 8 frames are usable.
pub(crate) fn fit_texel(d: &mut TexelData, eta: f32, s: &mut Scratch) -> Option<TexelFit> {
    let usable = d.w.iter().filter(|w| **w > 0.0).count();
    if usable < 8 {
        return None;
    }
    let mut p = {
        let prob = Problem::new(d, eta, s);
        let u = highlight_axis(&prob).unwrap_or(Vec3::X);
        let u = if u.x < 0.0 { -u } else { u };
        let (phi, dip) = (u.y.atan2(u.x), u.z.clamp(-1.0, 1.0).asin());
        let mut best = ([phi, dip, 10f32.to_radians().ln()], f32::INFINITY);
        for beta_deg in [2.0f32, 4.0, 7.0, 11.0, 16.0, 24.0] {
            let q = clamp_params([phi, dip, beta_deg.to_radians().ln()]);
            let c = prob.cost(q, s);
            if c < best.1 {
                best = (q, c);
            }
        }
        levenberg_marquardt(&prob, best.0, 12, s)
    };
    // Robust step: reject the frames the fit explains worst if they stand out.
    let mut r = Vec::new();
    {
        let prob = Problem::new(d, eta, s);
        prob.residuals(p, s, &mut r);
    }
    let per_frame: Vec<f32> = r
        .chunks_exact(3)
        .map(|c| (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt())
        .collect();
    let mut kept: Vec<f32> = per_frame
        .iter()
        .zip(&d.w)
        .filter(|(_, w)| **w > 0.0)
        .map(|(r, _)| *r)
        .collect();
    let mid = kept.len() / 2;
    let (_, med, _) = kept.select_nth_unstable_by(mid, |a, b| a.total_cmp(b));
    let sigma = 1.4826 * *med;
    let mut order: Vec<usize> = (0..per_frame.len())
        .filter(|&k| d.w[k] > 0.0 && per_frame[k] > 5.0 * sigma)
        .collect();
    order.sort_by(|&a, &b| per_frame[b].total_cmp(&per_frame[a]));
    order.truncate(usable / 5);
    if !order.is_empty() {
        for k in order {
            d.w[k] = 0.0;
        }
        let prob = Problem::new(d, eta, s);
        p = levenberg_marquardt(&prob, p, 8, s);
    }
    let prob = Problem::new(d, eta, s);
    prob.fibre_column(p, s);
    let (rho_eff, kf, cost) = colours(&prob.a, &s.b, d);
    let zz: f32 = (0..d.z.len())
        .map(|k| d.w[k] * d.z[k].length_squared())
        .sum();
    let mut u = axis_of(p[0], p[1]);
    if u.x < 0.0 || (u.x == 0.0 && u.y < 0.0) {
        u = -u;
    }
    let fit = TexelFit {
        diffuse: prob.unit.diffuse_from_effective(rho_eff).min(Vec3::ONE),
        fiber_color: kf.min(Vec3::ONE),
        axis: u,
        beta: p[2].exp(),
        residual: (cost / zz.max(1e-30)).sqrt(),
        used: d.w.iter().filter(|w| **w > 0.0).count() as u32,
    };
    // An overflow anywhere leaves the texel unfitted rather than a NaN in a map or fit.json.
    let finite = fit.diffuse.is_finite()
        && fit.fiber_color.is_finite()
        && fit.axis.is_finite()
        && fit.beta.is_finite()
        && fit.residual.is_finite();
    finite.then_some(fit)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::Bsdf;

    /// Noise-free observations of a known texel from three arcs, fitted back.
    #[test]
    fn recovers_a_texel_from_exact_bsdf_values() {
        let truth = WoodBsdfParams {
            diffuse: Vec3::new(0.5, 0.3, 0.15),
            fiber_color: Vec3::new(0.3, 0.25, 0.2),
            fiber_dir: axis_of(0.4, 0.15),
            ray_dir: Vec3::Z,
            ray_mask: 0.0,
            highlight_width: 8f32.to_radians(),
            eta: 1.5,
            roughness: 0.0,
        };
        let b = WoodBsdf::new(truth).unwrap();
        let wo = Vec3::new(0.1, -0.5, 0.86).normalize();
        let mut d = TexelData {
            wo,
            ..Default::default()
        };
        for az in [0.0f32, 60.0, 120.0] {
            for i in 0..32 {
                let th = (-60.0 + 120.0 * i as f32 / 31.0).to_radians();
                let a = az.to_radians();
                let wi = Vec3::new(th.sin() * a.cos(), th.sin() * a.sin(), th.cos());
                d.z.push(b.eval(wo, wi) * wi.z);
                d.wi.push(wi);
                d.w.push(1.0);
            }
        }
        let fit = fit_texel(&mut d, 1.5, &mut Scratch::default()).unwrap();
        let angle = fit
            .axis
            .dot(truth.fiber_dir)
            .abs()
            .min(1.0)
            .acos()
            .to_degrees();
        assert!(angle < 0.2, "axis off by {angle}° ({fit:?})");
        let want_rho = b.diffuse_from_effective(b.effective_diffuse());
        assert!(
            (fit.diffuse - want_rho).abs().max_element() < 2e-3,
            "{fit:?}"
        );
        assert!(
            (fit.fiber_color - truth.fiber_color).abs().max_element() < 3e-3,
            "{fit:?}"
        );
        assert!((fit.beta.to_degrees() - 8.0).abs() < 0.1, "{fit:?}");
    }
}
