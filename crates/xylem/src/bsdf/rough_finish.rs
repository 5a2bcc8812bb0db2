//! The rough (GGX) finish as an interface with energy compensation: its single-scattering
//! reflectance R_ss(μ, α, η) (deterministic quadrature) and its multiple-scattering reflectance
//! R_ms(μ, α, η) (the microsurface random walk of Heitz et al. 2016, orders ≥ 2) tabulated in
//! crates/xylem/src/bsdf/rough_finish_table.rs; a separable, reciprocal multiple-scattering lobe in the form
//! of Kulla & Conty 2017 ("Revisiting physically based shading at Imageworks", SIGGRAPH course:
//! f_ms = (1 − E(μo))(1 − E(μi))/(π(1 − E_avg)), here with R_ms in place of 1 − E); and the
//! interface's total reflectance R = R_ss + R_ms, whose complement the substrate is seen
//! through. Derivation and choices: notes/bsdf.md §4.

use super::fresnel::fresnel_dielectric;
use super::ggx::Ggx;
use super::layered_reference::{LayeredReference, Substrate};
use super::rough_finish_table::{
    ALPHA_NODES, ETA_NODES, MULTIPLE_REFLECTANCE, MU_NODES, MU_WEIGHTS, SINGLE_REFLECTANCE,
};
use super::rough_transmission::{RoughTransmission, PER_NODE};
use crate::math::{Pcg32, INV_PI};
use glam::{Vec2, Vec3};

/// μ node i is (i/(N−1))² (dense at grazing, where the albedos change fastest).
pub fn mu_node(i: usize) -> f32 {
    let s = i as f32 / (MU_NODES - 1) as f32;
    s * s
}

/// α node j is (j/(N−1))², node 0 computed at α = 10⁻³ (the smooth threshold of `WoodBsdf`).
pub fn alpha_node(j: usize) -> f32 {
    let s = j as f32 / (ALPHA_NODES - 1) as f32;
    (s * s).max(1e-3)
}

/// η node k is 1 + 3 (k/(N−1))² (dense near 1, where the Fresnel factor changes fastest).
pub fn eta_node(k: usize) -> f32 {
    let s = k as f32 / (ETA_NODES - 1) as f32;
    1.0 + 3.0 * s * s
}

/// R_ss is raised by 1 % where it sets what enters the finish, so that the table's
/// interpolation error (≤ 2.5·10⁻³, tested) cannot push the white furnace above 1.
pub(crate) const SS_MARGIN: f32 = 0.01;

/// Smallest μ the quadrature is run at (μ = 0 itself is a horizontal view).
pub(crate) const MU_FLOOR: f32 = 1e-4;

/// Single-scattering reflectance of the GGX interface seen from above at cos θo = `mu`,
/// [R_ss(μ, α, η) for η in `etas`], by an n × n midpoint rule over the visible-normal sampling
/// square (Heitz 2018): ∫ f cos dωi = E_{h ~ D_vis}[F(ωo·h) G2/G1(ωo)] with the reflected ωi
/// above the surface (Heitz 2014, eq. 99 for G2).
pub fn single_scattering_reflectance(mu: f32, alpha: f32, etas: &[f32], n: usize) -> Vec<f64> {
    let mu = mu.clamp(MU_FLOOR, 1.0);
    let wo = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let ggx = Ggx { alpha };
    let lo = ggx.lambda(wo);
    let mut r = vec![0.0f64; etas.len()];
    for a in 0..n {
        for b in 0..n {
            let u = Vec2::new((a as f32 + 0.5) / n as f32, (b as f32 + 0.5) / n as f32);
            let h = ggx.sample_visible_normal(wo, u);
            let c = wo.dot(h);
            let wi = 2.0 * c * h - wo;
            if wi.z <= 0.0 || c <= 0.0 {
                continue;
            }
            let w = ((1.0 + lo) / (1.0 + lo + ggx.lambda(wi))) as f64;
            for (rk, &eta) in r.iter_mut().zip(etas) {
                *rk += w * fresnel_dielectric(c, eta) as f64;
            }
        }
    }
    let norm = 1.0 / (n * n) as f64;
    r.into_iter().map(|x| x * norm).collect()
}

/// Where `x` falls on nodes 0..n−1 spaced uniformly in √x·… : (lower node, weight of the upper).
#[inline]
pub(crate) fn locate(t: f32, n: usize) -> (usize, f32) {
    let x = t.clamp(0.0, 1.0) * (n - 1) as f32;
    let i = (x as usize).min(n - 2);
    (i, x - i as f32)
}

/// The rough finish of one BSDF: its GGX distribution and, on the μ nodes, the total
/// reflectance R(μ) = R_ss(μ) + R_ms(μ) and the multiple-scattering part R_ms(μ) for this (α, η),
/// interpolated from the table once at construction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct RoughFinish {
    /// The finish's microfacet distribution (α = the finish roughness).
    pub ggx: Ggx,
    eta: f32,
    reflectance: [f32; MU_NODES],
    multiple: [f32; MU_NODES],
    /// 1/(π R̄_ms), or 0 when the finish scatters nothing twice.
    ms_norm: f32,
    /// R̄ = 2∫R(μ)μ dμ of the interpolated R (exactly, by [`MU_WEIGHTS`]).
    avg_reflectance: f32,
}

impl RoughFinish {
    /// `alpha` in [10⁻³, 1], `eta` in [1, 4] (checked by `WoodBsdf::new`).
    pub fn new(alpha: f32, eta: f32) -> RoughFinish {
        let (j, fa) = locate((alpha.clamp(0.0, 1.0)).sqrt(), ALPHA_NODES);
        let (k, fe) = locate(((eta - 1.0) / 3.0).max(0.0).sqrt(), ETA_NODES);
        let lerp = |a: f32, b: f32, t: f32| a + t * (b - a);
        let (mut reflectance, mut multiple) = ([0.0; MU_NODES], [0.0; MU_NODES]);
        let (mut ms_avg, mut r_avg) = (0.0, 0.0);
        for i in 0..MU_NODES {
            let at = |t: &[[[f32; MU_NODES]; ETA_NODES]; ALPHA_NODES], jj: usize| {
                lerp(t[jj][k][i], t[jj][k + 1][i], fe)
            };
            let r_ss = lerp(
                at(&SINGLE_REFLECTANCE, j),
                at(&SINGLE_REFLECTANCE, j + 1),
                fa,
            );
            let r_ms = lerp(
                at(&MULTIPLE_REFLECTANCE, j),
                at(&MULTIPLE_REFLECTANCE, j + 1),
                fa,
            );
            multiple[i] = r_ms.max(0.0);
            reflectance[i] = (r_ss * (1.0 + SS_MARGIN) + multiple[i]).min(1.0);
            ms_avg += MU_WEIGHTS[i] * multiple[i];
            r_avg += MU_WEIGHTS[i] * reflectance[i];
        }
        RoughFinish {
            ggx: Ggx { alpha },
            eta,
            reflectance,
            multiple,
            ms_norm: if ms_avg > 1e-7 { INV_PI / ms_avg } else { 0.0 },
            avg_reflectance: r_avg.clamp(0.0, 1.0),
        }
    }

    #[inline]
    fn lookup(table: &[f32; MU_NODES], mu: f32) -> f32 {
        let (i, t) = locate(mu.max(0.0).sqrt(), MU_NODES);
        table[i] + t * (table[i + 1] - table[i])
    }

    /// R(μ): all the light the finish reflects for a view of cosine `mu` (single and multiple
    /// scattering); 1 − R(μ) enters the finish.
    #[inline]
    pub fn reflectance(&self, mu: f32) -> f32 {
        Self::lookup(&self.reflectance, mu)
    }

    /// R̄ = 2∫R(μ)μ dμ, the finish's hemispherical reflectance from outside.
    pub(crate) fn avg_reflectance(&self) -> f32 {
        self.avg_reflectance
    }

    /// The directional albedo of the multiple-scattering lobe, R_ms(μ).
    #[inline]
    pub(crate) fn ms_albedo(&self, mu: f32) -> f32 {
        Self::lookup(&self.multiple, mu)
    }

    /// The reflection of the finish (no cosine): single scattering F(ωo·h) D G2 / (4 μo μi)
    /// (Walter et al. 2007, eq. 20; Heitz 2014, eq. 99) plus the multiple-scattering lobe
    /// R_ms(μo) R_ms(μi) / (π R̄_ms) (Kulla & Conty 2017's separable form; its albedo is exactly
    /// R_ms(μo) since ∫R_ms(μi) cos θi dωi = π R̄_ms). Reciprocal; its albedo is R(μo) up to the
    /// table's interpolation.
    #[inline]
    pub fn reflection(&self, wo: Vec3, wi: Vec3) -> f32 {
        let h = (wo + wi).normalize_or_zero();
        if h.z <= 0.0 {
            return 0.0;
        }
        let g = &self.ggx;
        let single =
            fresnel_dielectric(wo.dot(h), self.eta) * g.d(h) * g.g2(wo, wi) / (4.0 * wo.z * wi.z);
        let ms =
            Self::lookup(&self.multiple, wo.z) * Self::lookup(&self.multiple, wi.z) * self.ms_norm;
        single + ms
    }
}

/// One finish's tables (α, η fixed) on the μ nodes [`mu_node`], to be interpolated linearly in
/// √μ between them as `RoughFinish` and [`RoughTransmission`] do: for code that evaluates the
/// rough finish outside this crate (the Dr.Jit Mitsuba plugin `xylem_wood_baked`, through the
/// Python extension), so that it reads xylem's numbers instead of re-deriving them.
#[derive(Clone, Debug, PartialEq)]
pub struct FinishNodes {
    /// R(μᵢ) = min(1, R_ss (1 + `SS_MARGIN`) + R_ms): all the finish reflects.
    pub reflectance: Vec<f32>,
    /// R_ms(μᵢ): the albedo of the multiple-scattering lobe.
    pub multiple: Vec<f32>,
    /// 1/(π R̄_ms), the multiple-scattering lobe's normalisation (0 when it scatters nothing).
    pub ms_norm: f32,
    /// R̄ = 2∫R(μ)μ dμ, the finish's hemispherical reflectance from outside.
    pub avg_reflectance: f32,
    /// [`RoughTransmission::node`]: the transmitted light's spreads at μᵢ (the share of single
    /// scattering, then mean x and z as offsets from the smooth refraction, cov xx, yy, xz of
    /// the single- and of the multiple-scattering part).
    pub transmission: Vec<[f32; PER_NODE]>,
}

/// [`FinishNodes`] of the rough finish of roughness `alpha` in [10⁻³, 1] and index `eta` in
/// [1, 4] (clamped into the tables' range as `RoughFinish::new` does).
pub fn finish_nodes(alpha: f32, eta: f32) -> FinishNodes {
    let f = RoughFinish::new(alpha, eta);
    let t = RoughTransmission::new(alpha, eta);
    FinishNodes {
        reflectance: f.reflectance.to_vec(),
        multiple: f.multiple.to_vec(),
        ms_norm: f.ms_norm,
        avg_reflectance: f.avg_reflectance,
        transmission: (0..MU_NODES).map(|i| t.node(i)).collect(),
    }
}

/// η of every table node, in order.
fn etas() -> Vec<f32> {
    (0..ETA_NODES).map(eta_node).collect()
}

/// Visible-normal quadrature points per side for the tabulated R_ss.
const QUAD_N: usize = 256;
/// Microsurface walks per node for the tabulated R_ms.
const WALKS: u32 = 30_000;

/// R_ms(μ, α, η): the fraction of `WALKS` microsurface random walks (Heitz et al. 2016, as in
/// [`super::layered_reference`]) from a view of cosine `mu` that leave upward after two or
/// more events. Binomial standard error ≤ √(0.25/WALKS) ≈ 3·10⁻³, ≈ 10⁻³ where R_ms ≤ 0.03.
fn multiple_scattering_reflectance(mu: f32, alpha: f32, eta: f32, seed: u64) -> f64 {
    let mu = mu.clamp(MU_FLOOR, 1.0) as f64;
    let walk = LayeredReference {
        alpha: alpha as f64,
        eta: eta as f64,
        substrate: Substrate::Lambertian(0.0),
    };
    let d = glam::DVec3::new(-(1.0 - mu * mu).max(0.0).sqrt(), 0.0, -mu);
    let mut rng = Pcg32::new(0x12, seed);
    let up = (0..WALKS)
        .filter(|_| matches!(walk.interface(d, true, &mut rng), Some((_, true, n)) if n >= 2))
        .count();
    up as f64 / WALKS as f64
}

/// The walk seed of node (μ_i, α_j, η_k): every node its own stream, the same in every run.
fn node_seed(i: usize, j: usize, k: usize) -> u64 {
    ((j * ETA_NODES + k) * MU_NODES + i) as u64
}

/// 4∫φᵢ(s) s³ ds for the hat functions φᵢ on the s = √μ nodes (3-point Gauss–Legendre per
/// interval, exact for the quartic integrand): the weights of 2∫f(μ) μ dμ.
fn mu_weights() -> Vec<f64> {
    let n = MU_NODES;
    let h = 1.0 / (n - 1) as f64;
    let (x, w) = (
        [-(0.6f64).sqrt(), 0.0, (0.6f64).sqrt()],
        [5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0],
    );
    let mut out = vec![0.0; n];
    for seg in 0..n - 1 {
        for q in 0..3 {
            let t = 0.5 * (x[q] + 1.0);
            let s = (seg as f64 + t) * h;
            let g = 4.0 * s * s * s * 0.5 * h * w[q];
            out[seg] += g * (1.0 - t);
            out[seg + 1] += g * t;
        }
    }
    out
}

/// The values of rough_finish_table.rs, computed afresh (for its generator, the lab's
/// `xylem-tables rough-finish`): slabs are indexed `[k][i]` (η, μ) per α row j.
#[derive(Clone, Debug)]
pub struct ReflectanceTable {
    /// Weights of 2∫f(μ)μ dμ for f linear in √μ between the μ nodes (one per μ node).
    pub mu_weights: Vec<f64>,
    /// R_ss(μ_i, α_j, η_k) by quadrature over `QUAD_N`² visible normals: `[j][k][i]`.
    pub single: Vec<Vec<Vec<f64>>>,
    /// R_ms(μ_i, α_j, η_k) by `WALKS` microsurface walks seeded per node: `[j][k][i]`.
    pub multiple: Vec<Vec<Vec<f64>>>,
}

/// [`ReflectanceTable`] of every node, α rows on all cores (each node seeded on its own, so
/// the result does not depend on the number of threads).
pub fn reflectance_table() -> ReflectanceTable {
    use rayon::prelude::*;
    type Slab = Vec<Vec<f64>>;
    let rows: Vec<(Slab, Slab)> = (0..ALPHA_NODES)
        .into_par_iter()
        .map(|j| {
            let mut r = vec![vec![0.0; MU_NODES]; ETA_NODES];
            let mut m = vec![vec![0.0; MU_NODES]; ETA_NODES];
            for i in 0..MU_NODES {
                let ri = single_scattering_reflectance(mu_node(i), alpha_node(j), &etas(), QUAD_N);
                for k in 0..ETA_NODES {
                    r[k][i] = ri[k];
                    m[k][i] = multiple_scattering_reflectance(
                        mu_node(i),
                        alpha_node(j),
                        eta_node(k),
                        node_seed(i, j, k),
                    );
                }
            }
            (r, m)
        })
        .collect();
    let (single, multiple) = rows.into_iter().unzip();
    ReflectanceTable {
        mu_weights: mu_weights(),
        single,
        multiple,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 12 random nodes: R_ss equals a fresh quadrature within 2·10⁻⁵ (the f32 rounding), R_ms a
    /// fresh walk of another seed within 5σ of their difference (σ from the binomial).
    #[test]
    fn table_is_current() {
        let mut r = Pcg32::new(12, 5);
        for _ in 0..12 {
            let i = (r.next_u32() as usize) % MU_NODES;
            let j = (r.next_u32() as usize) % ALPHA_NODES;
            let k = (r.next_u32() as usize) % ETA_NODES;
            let rs = single_scattering_reflectance(mu_node(i), alpha_node(j), &etas(), QUAD_N);
            let got = SINGLE_REFLECTANCE[j][k][i] as f64;
            assert!(
                (got - rs[k]).abs() < 2e-5,
                "R_ss node ({i}, {j}, {k}): {got} vs {}",
                rs[k]
            );
            let want =
                multiple_scattering_reflectance(mu_node(i), alpha_node(j), eta_node(k), 1 << 40);
            let got = MULTIPLE_REFLECTANCE[j][k][i] as f64;
            let sigma = (2.0 * want.max(1e-3) / WALKS as f64).sqrt();
            assert!(
                (got - want).abs() < 5.0 * sigma,
                "R_ms node ({i}, {j}, {k}): {got} vs {want}"
            );
        }
    }

    /// Between the nodes the interpolated R_ss stays within 2.5·10⁻³ of a fresh quadrature
    /// (what the white furnace can lose or gain through the table), at 40 random (μ, α, η).
    #[test]
    fn interpolation_error_is_small() {
        let mut r = Pcg32::new(3, 8);
        let mut worst = 0.0f64;
        for _ in 0..40 {
            let mu = r.next_f32().max(0.02);
            let alpha = 0.01 + 0.99 * r.next_f32();
            let eta = 1.0 + 1.5 * r.next_f32();
            let f = RoughFinish::new(alpha, eta);
            let rs = single_scattering_reflectance(mu, alpha, &[eta], 128);
            let got = ((f.reflectance(mu) - f.ms_albedo(mu)) / (1.0 + SS_MARGIN)) as f64;
            worst = worst.max((got - rs[0]).abs());
        }
        assert!(worst < 2.5e-3, "{worst}");
    }

    /// MU_WEIGHTS integrate the piecewise-linear interpolant: 2∫μ dμ = 1, 2∫μ·μ dμ = 2/3.
    #[test]
    fn mu_weights_integrate_the_interpolant() {
        let one: f32 = MU_WEIGHTS.iter().sum();
        let mu: f32 = (0..MU_NODES).map(|i| MU_WEIGHTS[i] * mu_node(i)).sum();
        assert!(
            (one - 1.0).abs() < 1e-5 && (mu - 2.0 / 3.0).abs() < 1e-3,
            "{one} {mu}"
        );
    }
}
