//! The BSDF validation suite: for every case of `validation/bsdf_cases.toml` (a grid over β, η,
//! fibre inclination, ray mask and finish roughness, plus named cases) and every view angle,
//!
//! - **white furnace**: directional albedo by Monte Carlo of `sample` and by quadrature of `eval`
//!   (they must agree; never above 1 + 3σ; ≥ 0.99 for a white substrate under a smooth finish);
//! - **reciprocity**: max relative |f(ωo, ωi) − f(ωi, ωo)| over random pairs;
//! - **chi-square** goodness of fit of `sample` against `pdf` (the method of pbrt-v4's
//!   `chi2test` and Mitsuba 3's `ChiSquareTest`: histogram over the hemisphere, expected counts
//!   by integrating `pdf` per bin, low-expectation bins pooled, significance with Šidák correction);
//! - **pdf normalisation**: ∫pdf dω equals the fraction of non-delta samples `sample` returns;
//! - **sample weights**: a sample's f and pdf equal `eval` and `pdf`;
//! - **extremes**: no NaN, Inf or negative value at grazing and degenerate configurations;
//! - **rough finish** ([`super::rough_finish`]): the analytic albedo against the layered
//!   random-walk reference, and a white substrate under a rough finish.

use crate::report::{all_passed, checks_table, markdown_table, Check};
use crate::rough_finish::{run_rough, white_row_checked, white_row_ok, RoughRow, RoughSettings};
use glam::Vec3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use statrs::distribution::{ChiSquared, ContinuousCDF};
use std::path::{Path, PathBuf};
use xylem::bsdf::{
    fresnel_dielectric, Bsdf, BsdfError, FiberNormalization, WoodBsdf, WoodBsdfParams,
};
use xylem::math::{cosine_hemisphere, Pcg32, PI};

mod checks;
pub use checks::*;
mod report;
pub use report::*;

/// Errors while loading the case file.
#[derive(Debug, thiserror::Error)]
pub enum CasesError {
    /// The case file could not be read.
    #[error("cannot read {path}: {source}")]
    Io {
        /// The case file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The case file is not valid TOML for [`CasesFile`].
    #[error("{path}: {source}")]
    Toml {
        /// The case file.
        path: PathBuf,
        /// toml's error (names the field).
        source: toml::de::Error,
    },
    /// A case's parameters are out of range for [`WoodBsdf`].
    #[error("{path}: case `{case}`: {source}")]
    Params {
        /// The case file.
        path: PathBuf,
        /// The case's name.
        case: String,
        /// Which parameter is out of range.
        source: BsdfError,
    },
    /// A setting is out of range (the message names it and the allowed range).
    #[error("{path}: {message}")]
    Invalid {
        /// The case file.
        path: PathBuf,
        /// The setting and its allowed range.
        message: String,
    },
}

/// Fibre-lobe normalisation as written in the case file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Normalization {
    /// [`FiberNormalization::EnergyBounded`]: directional albedo ≤ 1 at every angle.
    #[default]
    EnergyBounded,
    /// [`FiberNormalization::Published`]: Marschner et al. 2005 eq. 3, not normalised.
    Published,
}

/// One BSDF configuration; angles in degrees. The fibre axis dips `fiber_dip_deg` below the
/// surface plane at azimuth `fiber_azimuth_deg`; the ray axis is perpendicular to it in azimuth
/// and dips `ray_dip_deg`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CaseSpec {
    /// Case name in the report (grid cases are named from their parameters).
    pub name: String,
    /// Diffuse (subsurface) colour, linear RGB 0–1.
    pub diffuse: [f32; 3],
    /// Fibre highlight colour, linear RGB 0–1.
    pub fiber_color: [f32; 3],
    /// Fibre highlight width β (degrees).
    pub highlight_width_deg: f32,
    /// Refractive index of the finish.
    pub eta: f32,
    /// Dip of the fibre axis below the surface plane (degrees).
    pub fiber_dip_deg: f32,
    /// Azimuth of the fibre axis in the surface plane (degrees).
    pub fiber_azimuth_deg: f32,
    /// Fraction of ray cells, 0–1.
    pub ray_mask: f32,
    /// Dip of the ray axis below the surface plane (degrees).
    pub ray_dip_deg: f32,
    /// GGX roughness of the finish, 0–1 (0 = smooth).
    pub roughness: f32,
    /// Fibre-lobe normalisation (default energy-bounded).
    pub normalization: Normalization,
    /// A white non-absorbing substrate: its albedo must reach `white_min_albedo`.
    pub white: bool,
    /// The albedo must stay ≤ 1 (false for the published lobe, which is not normalised).
    pub bounded: bool,
    /// Draw a polar plot of f·cos in the incidence plane for this case.
    pub plot: bool,
}

impl Default for CaseSpec {
    fn default() -> Self {
        CaseSpec {
            name: String::new(),
            diffuse: [0.45, 0.22, 0.10],
            fiber_color: [0.6, 0.4, 0.25],
            highlight_width_deg: 8.0,
            eta: 1.5,
            fiber_dip_deg: 0.0,
            fiber_azimuth_deg: 0.0,
            ray_mask: 0.0,
            ray_dip_deg: 0.0,
            roughness: 0.0,
            normalization: Normalization::EnergyBounded,
            white: false,
            bounded: true,
            plot: false,
        }
    }
}

/// Unit vector dipping `dip_deg` below the surface plane at azimuth `azimuth_deg`.
pub fn dipping_axis(dip_deg: f32, azimuth_deg: f32) -> Vec3 {
    let (d, a) = (dip_deg.to_radians(), azimuth_deg.to_radians());
    Vec3::new(d.cos() * a.cos(), d.cos() * a.sin(), -d.sin()).normalize()
}

impl CaseSpec {
    /// The [`WoodBsdfParams`] of this case (angles converted to radians and axes).
    pub fn params(&self) -> WoodBsdfParams {
        WoodBsdfParams {
            diffuse: Vec3::from(self.diffuse),
            fiber_color: Vec3::from(self.fiber_color),
            fiber_dir: dipping_axis(self.fiber_dip_deg, self.fiber_azimuth_deg),
            ray_dir: dipping_axis(self.ray_dip_deg, self.fiber_azimuth_deg + 90.0),
            ray_mask: self.ray_mask,
            highlight_width: self.highlight_width_deg.to_radians(),
            eta: self.eta,
            roughness: self.roughness,
        }
    }

    /// The BSDF of this case; an error where a parameter is out of range.
    pub fn bsdf(&self) -> Result<WoodBsdf, BsdfError> {
        let norm = match self.normalization {
            Normalization::EnergyBounded => FiberNormalization::EnergyBounded,
            Normalization::Published => FiberNormalization::Published,
        };
        Ok(WoodBsdf::new(self.params())?.with_normalization(norm))
    }
}

/// The grid: the product of the lists, every other field from `base`.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Grid {
    /// β values of the grid (degrees).
    pub highlight_width_deg: Vec<f32>,
    /// η values of the grid.
    pub eta: Vec<f32>,
    /// Fibre dips of the grid (degrees).
    pub fiber_dip_deg: Vec<f32>,
    /// Ray-mask values of the grid.
    pub ray_mask: Vec<f32>,
    /// Finish roughness values of the grid.
    pub roughness: Vec<f32>,
    /// Every field the grid does not vary.
    #[serde(default)]
    pub base: CaseSpec,
}

/// Sample counts, angle grids and thresholds.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Settings {
    /// Seed of every random stream of the run.
    pub seed: u64,
    /// View zenith angles of the furnace check, degrees.
    pub theta_o_deg: Vec<f32>,
    /// Monte Carlo samples per furnace albedo.
    pub furnace_samples: u32,
    /// Largest quadrature step, degrees (the step is also at most β/2).
    pub quadrature_step_deg: f32,
    /// Agreement of MC and quadrature: |mc − quad| ≤ furnace_sigmas·σ + furnace_abs_tol.
    pub furnace_sigmas: f64,
    /// Absolute slack of the furnace agreement (see `furnace_sigmas`).
    pub furnace_abs_tol: f64,
    /// Least albedo of a white case (quadrature, and MC + 3σ).
    pub white_min_albedo: f64,
    /// The white-case bound applies at view zenith angles up to this (degrees).
    pub white_max_theta_deg: f32,
    /// Samples per chi-square test.
    pub chi2_samples: u32,
    /// View zenith angles of the chi-square test (degrees).
    pub chi2_theta_o_deg: Vec<f32>,
    /// Histogram bins in θ for the chi-square test (≥ 2).
    pub chi2_theta_bins: u32,
    /// Histogram bins in φ for the chi-square test (≥ 2).
    pub chi2_phi_bins: u32,
    /// Bins whose expected count is below this are pooled.
    pub chi2_min_expected: f64,
    /// Family-wise significance level α of the chi-square tests, in (0, 1) (Šidák-corrected per
    /// test).
    pub significance: f64,
    /// Relative tolerance of ∫pdf dω against the fraction of non-delta samples (or 5σ).
    pub pdf_tolerance: f64,
    /// Random direction pairs of the reciprocity check.
    pub reciprocity_pairs: u32,
    /// Largest allowed relative reciprocity error.
    pub reciprocity_tolerance: f64,
    /// Largest allowed relative error of a sample's f and pdf against `eval` and `pdf`.
    pub weight_tolerance: f64,
    /// Random samples per degenerate configuration of the extremes check.
    pub extreme_samples: u32,
}

/// The case file.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CasesFile {
    /// Sample counts and thresholds.
    pub settings: Settings,
    /// The grid of cases.
    pub grid: Grid,
    /// Named cases beside the grid.
    #[serde(default)]
    pub cases: Vec<CaseSpec>,
    /// Parameter sets of the extremes check.
    #[serde(default)]
    pub extremes: Vec<CaseSpec>,
    /// The rough-finish rows against the layered reference.
    #[serde(default)]
    pub rough_finish: Option<RoughSettings>,
}

/// A loaded, checked suite: the expanded case list.
#[derive(Clone, Debug)]
pub struct Suite {
    /// Sample counts and thresholds.
    pub settings: Settings,
    /// Grid cases, then named cases.
    pub cases: Vec<CaseSpec>,
    /// Parameter sets of the extremes check.
    pub extremes: Vec<CaseSpec>,
    /// The rough-finish rows, if the file has them.
    pub rough: Option<RoughSettings>,
}

impl CasesFile {
    /// The grid cases (named from their parameters) followed by the named cases.
    pub fn expand(&self) -> Vec<CaseSpec> {
        let g = &self.grid;
        let mut out = Vec::new();
        for &beta in &g.highlight_width_deg {
            for &eta in &g.eta {
                for &dip in &g.fiber_dip_deg {
                    for &mask in &g.ray_mask {
                        for &rough in &g.roughness {
                            out.push(CaseSpec {
                                name: format!("β{beta} η{eta} dip{dip} ray{mask} rough{rough}"),
                                highlight_width_deg: beta,
                                eta,
                                fiber_dip_deg: dip,
                                ray_mask: mask,
                                roughness: rough,
                                ..g.base.clone()
                            });
                        }
                    }
                }
            }
        }
        out.extend(self.cases.iter().cloned());
        out
    }
}

/// The largest cases file read (it is text; this bounds `/dev/zero` and the like).
const MAX_CASES_BYTES: u64 = 16 << 20;

/// Reads and checks `path`: every case must make a valid `WoodBsdf`.
pub fn load_suite(path: &Path) -> Result<Suite, CasesError> {
    // From disk, or the embedded validation/bsdf_cases.toml (`xylem::builtin`).
    let bytes = xylem::builtin::read(path, MAX_CASES_BYTES).map_err(|e| CasesError::Io {
        path: path.to_owned(),
        source: std::io::Error::other(e.reason()),
    })?;
    let text = String::from_utf8_lossy(&bytes);
    let file: CasesFile = toml::from_str(&text).map_err(|source| CasesError::Toml {
        path: path.to_owned(),
        source,
    })?;
    let suite = Suite {
        cases: file.expand(),
        extremes: file.extremes.clone(),
        settings: file.settings,
        rough: file.rough_finish,
    };
    for c in suite.cases.iter().chain(&suite.extremes) {
        c.bsdf().map_err(|source| CasesError::Params {
            path: path.to_owned(),
            case: c.name.clone(),
            source,
        })?;
    }
    let s = &suite.settings;
    let invalid = |message: &str| CasesError::Invalid {
        path: path.to_owned(),
        message: message.to_owned(),
    };
    if !(s.significance > 0.0 && s.significance < 1.0) {
        return Err(invalid("settings.significance must lie in (0, 1)"));
    }
    if s.chi2_theta_bins < 2 || s.chi2_phi_bins < 2 {
        return Err(invalid(
            "settings.chi2_theta_bins and chi2_phi_bins must be ≥ 2",
        ));
    }
    if !(s.quadrature_step_deg > 0.0) {
        return Err(invalid("settings.quadrature_step_deg must be > 0"));
    }
    if s.furnace_samples == 0 || s.chi2_samples == 0 {
        return Err(invalid(
            "settings.furnace_samples and chi2_samples must be > 0",
        ));
    }
    Ok(suite)
}

/// Direction at zenith `theta` and azimuth `phi` (radians).
#[inline]
pub fn spherical(theta: f32, phi: f32) -> Vec3 {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    Vec3::new(st * cp, st * sp, ct)
}

/// Monte Carlo directional albedo ∫ f cos dωi of `sample` (delta lobes included): mean and
/// standard error per channel.
pub fn albedo_mc(b: &(impl Bsdf + ?Sized), wo: Vec3, n: u32, rng: &mut Pcg32) -> (Vec3, Vec3) {
    let (mut s, mut s2) = ([0.0f64; 3], [0.0f64; 3]);
    for _ in 0..n {
        if let Some(x) = b.sample(wo, rng.next_f32(), rng.next_vec2()) {
            let w = x.f * x.wi.z.abs() / x.pdf;
            for c in 0..3 {
                s[c] += w[c] as f64;
                s2[c] += (w[c] as f64) * (w[c] as f64);
            }
        }
    }
    let n = n as f64;
    let mean = Vec3::from(s.map(|v| (v / n) as f32));
    let sigma = Vec3::from(
        [0, 1, 2].map(|c| (((s2[c] / n - (s[c] / n).powi(2)).max(0.0)) / n).sqrt() as f32),
    );
    (mean, sigma)
}

/// Quadrature of ∫ f cos dωi over the upper hemisphere (midpoint rule in θ and φ with steps of at
/// most `step` radians; non-delta part only). f64 accumulation.
pub fn albedo_quadrature(b: &(impl Bsdf + ?Sized), wo: Vec3, step: f32) -> Vec3 {
    let nt = ((0.5 * PI / step).ceil() as usize).max(8);
    let np = 4 * nt;
    let (dt, dp) = (0.5 * PI as f64 / nt as f64, 2.0 * PI as f64 / np as f64);
    let mut s = [0.0f64; 3];
    for i in 0..nt {
        let t = (i as f64 + 0.5) * dt;
        let w = t.sin() * t.cos() * dt * dp;
        for j in 0..np {
            let p = (j as f64 + 0.5) * dp;
            let f = b.eval(wo, spherical(t as f32, p as f32));
            for c in 0..3 {
                s[c] += f[c] as f64 * w;
            }
        }
    }
    Vec3::from(s.map(|v| v as f32))
}

/// Max relative |f(a, b) − f(b, a)| over `pairs` random direction pairs (cosine-distributed),
/// ignoring pairs where both values are below 1e-8.
pub fn reciprocity_error(b: &(impl Bsdf + ?Sized), pairs: u32, rng: &mut Pcg32) -> f64 {
    let mut worst = 0.0f64;
    for _ in 0..pairs {
        let x = cosine_hemisphere(rng.next_vec2());
        let y = cosine_hemisphere(rng.next_vec2());
        let (f1, f2) = (b.eval(x, y), b.eval(y, x));
        let m = f1.max(f2).max_element() as f64;
        if m > 1e-8 {
            worst = worst.max((f1 - f2).abs().max_element() as f64 / m);
        }
    }
    worst
}

/// Result of one chi-square test of `sample` against `pdf` for one `wo`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Chi2Outcome {
    /// The chi-square statistic over the pooled bins.
    pub statistic: f64,
    /// Degrees of freedom (pooled bins − 1).
    pub dof: u32,
    /// Probability of a statistic this large if `sample` follows `pdf`.
    pub p_value: f64,
    /// ∫ pdf dω over the hemisphere (sum of expected counts / N).
    pub pdf_integral: f64,
    /// Fraction of the N calls that returned a non-delta sample.
    pub accepted: f64,
    /// Samples in bins whose expected count is 0 (or below the horizon).
    pub impossible: u64,
    /// Max relative error of a sample's f and pdf against `eval` and `pdf`.
    pub weight_error: f64,
}

/// ∫ pdf sinθ dθ dφ over one bin by the midpoint rule on an `nt × np` sub-grid.
// The bin's four edges and its sub-grid, in the order the χ² test (pbrt-v4, Mitsuba 3) writes them.
#[allow(clippy::too_many_arguments)]
fn bin_integral(
    b: &(impl Bsdf + ?Sized),
    wo: Vec3,
    t0: f64,
    t1: f64,
    p0: f64,
    p1: f64,
    nt: usize,
    np: usize,
) -> f64 {
    let (dt, dp) = ((t1 - t0) / nt as f64, (p1 - p0) / np as f64);
    let mut s = 0.0;
    for i in 0..nt {
        let t = t0 + (i as f64 + 0.5) * dt;
        let st = t.sin();
        for j in 0..np {
            let p = p0 + (j as f64 + 0.5) * dp;
            s += b.pdf(wo, spherical(t as f32, p as f32)) as f64 * st;
        }
    }
    s * dt * dp
}

/// Pearson's chi-square with pooling of low-expectation cells, as in pbrt-v4's `chi2test`
/// (cells sorted by expected count; those below `min_expected` pooled until the pool reaches it).
/// Returns (statistic, degrees of freedom).
pub fn pooled_chi_square(cells: &mut [(f64, f64)], min_expected: f64) -> (f64, u32) {
    cells.sort_by(|a, b| a.1.total_cmp(&b.1));
    let (mut pooled_obs, mut pooled_exp, mut pooled_cells) = (0.0, 0.0, 0u32);
    let (mut chi2, mut dof) = (0.0, 0u32);
    for &(obs, exp) in cells.iter() {
        if exp <= 0.0 {
            continue;
        }
        if exp < min_expected || (pooled_exp > 0.0 && pooled_exp < min_expected) {
            pooled_obs += obs;
            pooled_exp += exp;
            pooled_cells += 1;
        } else {
            chi2 += (obs - exp) * (obs - exp) / exp;
            dof += 1;
        }
    }
    if pooled_cells > 0 && pooled_exp > 0.0 {
        chi2 += (pooled_obs - pooled_exp) * (pooled_obs - pooled_exp) / pooled_exp;
        dof += 1;
    }
    (chi2, dof.saturating_sub(1))
}

/// Chi-square test of `sample` against `pdf` for direction `wo`: `n` samples binned on a
/// `theta_bins × phi_bins` grid of the upper hemisphere; expected counts by integrating `pdf`
/// per bin with sub-steps of at most `sub_step` radians.
// The test's settings as pbrt-v4's and Mitsuba 3's χ² tests take them, each named at the call.
#[allow(clippy::too_many_arguments)]
pub fn chi_square(
    b: &(impl Bsdf + ?Sized),
    wo: Vec3,
    n: u32,
    theta_bins: u32,
    phi_bins: u32,
    sub_step: f32,
    min_expected: f64,
    rng: &mut Pcg32,
) -> Chi2Outcome {
    let (tb, pb) = (theta_bins as usize, phi_bins as usize);
    let (dt, dp) = (0.5 * PI as f64 / tb as f64, 2.0 * PI as f64 / pb as f64);
    let mut obs = vec![0.0f64; tb * pb];
    let (mut accepted, mut below, mut weight_error) = (0u64, 0u64, 0.0f64);
    for k in 0..n {
        let Some(s) = b.sample(wo, rng.next_f32(), rng.next_vec2()) else {
            continue;
        };
        if s.is_delta {
            continue;
        }
        accepted += 1;
        if !(s.wi.z > 0.0) {
            below += 1;
            continue;
        }
        if k < 20_000 {
            let (f, pdf) = (b.eval(wo, s.wi), b.pdf(wo, s.wi));
            let ef = (f - s.f).abs().max_element() as f64 / (f.max_element() as f64).max(1e-12);
            let ep = ((pdf - s.pdf).abs() / pdf.max(1e-12)) as f64;
            weight_error = weight_error.max(ef).max(ep);
        }
        let t = (s.wi.z as f64).clamp(-1.0, 1.0).acos();
        let p = (s.wi.y as f64)
            .atan2(s.wi.x as f64)
            .rem_euclid(2.0 * PI as f64);
        let i = ((t / dt) as usize).min(tb - 1);
        let j = ((p / dp) as usize).min(pb - 1);
        obs[i * pb + j] += 1.0;
    }
    let nt = ((dt as f32 / sub_step).ceil() as usize).max(2);
    let np = ((dp as f32 / sub_step).ceil() as usize).max(2);
    let mut cells = Vec::with_capacity(tb * pb);
    let mut integral = 0.0;
    let mut impossible = below;
    for i in 0..tb {
        for j in 0..pb {
            let t0 = i as f64 * dt;
            let p0 = j as f64 * dp;
            let e = bin_integral(b, wo, t0, t0 + dt, p0, p0 + dp, nt, np);
            integral += e;
            let o = obs[i * pb + j];
            let exp = e * n as f64;
            // pbrt-v4's test: observations in a cell the pdf says is empty (beyond rounding).
            if exp <= 0.0 && o > n as f64 * 1e-5 {
                impossible += o as u64;
            }
            cells.push((o, exp));
        }
    }
    let (statistic, dof) = pooled_chi_square(&mut cells, min_expected);
    let p_value = if dof == 0 {
        1.0
    } else {
        ChiSquared::new(dof as f64)
            .map(|d| d.sf(statistic))
            .unwrap_or(0.0)
    };
    Chi2Outcome {
        statistic,
        dof,
        p_value,
        pdf_integral: integral,
        accepted: accepted as f64 / n as f64,
        impossible,
        weight_error,
    }
}

/// Values that must never appear: NaN, ±Inf, negative f or pdf.
fn bad(v: Vec3) -> bool {
    !v.is_finite() || v.min_element() < 0.0
}

/// Counts NaN / Inf / negative values of eval, pdf and sample at degenerate directions for one
/// parameter set: θ = 89.99°, ωo exactly on the horizon, ωi = −ωo, ωi along the fibre, …
pub fn extreme_violations(b: &WoodBsdf, samples: u32, rng: &mut Pcg32) -> u64 {
    let p = b.params();
    let mut wos = vec![Vec3::Z, Vec3::X, Vec3::new(0.6, 0.8, 0.0), -Vec3::Z];
    for theta in [30.0f32, 89.99, 90.0] {
        for phi in [0.0f32, 45.0, 90.0, 180.0] {
            wos.push(spherical(theta.to_radians(), phi.to_radians()));
        }
    }
    for axis in [p.fiber_dir, p.ray_dir] {
        wos.push(axis);
        wos.push(-axis);
        wos.push(Vec3::new(axis.x, axis.y, axis.z.abs()).normalize_or(Vec3::Z));
    }
    let mut count = 0u64;
    for &wo in &wos {
        let mut wis = vec![
            -wo,
            wo,
            Vec3::new(-wo.x, -wo.y, wo.z),
            Vec3::Z,
            Vec3::X,
            p.fiber_dir,
            -p.fiber_dir,
        ];
        for _ in 0..64 {
            wis.push(cosine_hemisphere(rng.next_vec2()));
        }
        for wi in wis {
            count += bad(b.eval(wo, wi)) as u64;
            let pdf = b.pdf(wo, wi);
            count += (!pdf.is_finite() || pdf < 0.0) as u64;
        }
        for _ in 0..samples {
            let uc = if rng.next_f32() < 0.05 {
                0.999_999_9
            } else {
                rng.next_f32()
            };
            if let Some(s) = b.sample(wo, uc, rng.next_vec2()) {
                count +=
                    (bad(s.f) || !s.pdf.is_finite() || !(s.pdf > 0.0) || !s.wi.is_finite()) as u64;
            }
        }
    }
    count
}

/// Furnace result for one view direction.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FurnacePoint {
    /// View zenith angle (degrees).
    pub theta_o_deg: f32,
    /// View azimuth (degrees).
    pub phi_o_deg: f32,
    /// Max channel of the Monte Carlo albedo, its standard error, and the quadrature albedo
    /// (plus the delta reflectance F(θo) of a smooth finish) of the same channel.
    pub mc: f64,
    /// Standard error of `mc`.
    pub sigma: f64,
    /// Quadrature albedo of the same channel (plus F(θo) of a smooth finish).
    pub quadrature: f64,
    /// Largest |mc − quad| over the channels, and that difference in standard errors.
    pub worst_diff: f64,
    /// `worst_diff` in standard errors.
    pub worst_z: f64,
    /// Every channel within furnace_sigmas·σ + furnace_abs_tol.
    pub agrees: bool,
}

/// Everything measured for one case.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CaseResult {
    /// The case.
    pub spec: CaseSpec,
    /// Furnace results per view direction.
    pub furnace: Vec<FurnacePoint>,
    /// Reciprocity error (max relative).
    pub reciprocity: f64,
    /// Chi-square outcome per view zenith angle (degrees).
    pub chi2: Vec<(f32, Chi2Outcome)>,
}

fn furnace_point(
    b: &WoodBsdf,
    theta_deg: f32,
    phi_deg: f32,
    s: &Settings,
    rng: &mut Pcg32,
) -> FurnacePoint {
    let wo = spherical(theta_deg.to_radians(), phi_deg.to_radians());
    let (mc, sigma) = albedo_mc(b, wo, s.furnace_samples, rng);
    let step = s
        .quadrature_step_deg
        .to_radians()
        .min(0.5 * b.params().highlight_width);
    let mut quad = albedo_quadrature(b, wo, step);
    if b.has_delta() {
        quad += Vec3::splat(fresnel_dielectric(wo.z, b.params().eta));
    }
    let c = (0..3).max_by(|&x, &y| mc[x].total_cmp(&mc[y])).unwrap_or(0);
    let (mut worst_diff, mut worst_z, mut agrees) = (0.0f64, 0.0f64, true);
    for k in 0..3 {
        let d = (mc[k] - quad[k]).abs() as f64;
        if d >= worst_diff {
            worst_diff = d;
            worst_z = d / (sigma[k] as f64).max(1e-12);
        }
        agrees &= d <= s.furnace_sigmas * sigma[k] as f64 + s.furnace_abs_tol;
    }
    FurnacePoint {
        theta_o_deg: theta_deg,
        phi_o_deg: phi_deg,
        mc: mc[c] as f64,
        sigma: sigma[c] as f64,
        quadrature: quad[c] as f64,
        worst_diff,
        worst_z,
        agrees,
    }
}

/// Runs every check of one case (deterministic for a given seed and case index).
pub fn run_case(spec: &CaseSpec, index: usize, s: &Settings) -> CaseResult {
    let b = spec.bsdf().expect("cases are checked when loaded");
    let mut rng = Pcg32::new(s.seed, index as u64);
    let furnace = s
        .theta_o_deg
        .iter()
        .enumerate()
        .map(|(k, &t)| furnace_point(&b, t, (k as f32 * 67.0) % 360.0, s, &mut rng))
        .collect();
    let reciprocity = reciprocity_error(&b, s.reciprocity_pairs, &mut rng);
    let sub_step = s
        .quadrature_step_deg
        .to_radians()
        .min(0.5 * b.params().highlight_width);
    let chi2 = s
        .chi2_theta_o_deg
        .iter()
        .enumerate()
        .map(|(k, &t)| {
            let wo = spherical(t.to_radians(), (k as f32 * 131.0 + 15.0).to_radians());
            let o = chi_square(
                &b,
                wo,
                s.chi2_samples,
                s.chi2_theta_bins,
                s.chi2_phi_bins,
                sub_step,
                s.chi2_min_expected,
                &mut rng,
            );
            (t, o)
        })
        .collect();
    CaseResult {
        spec: spec.clone(),
        furnace,
        reciprocity,
        chi2,
    }
}

#[cfg(test)]
mod embedded_tests {
    use super::*;

    #[test]
    fn the_embedded_cases_load_where_the_file_does_not_exist() {
        // `missing/..` makes the path absent on disk; it folds to validation/bsdf_cases.toml.
        let embedded = load_suite(Path::new("missing/../validation/bsdf_cases.toml")).unwrap();
        let disk = load_suite(
            &Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
                .join("validation/bsdf_cases.toml"),
        )
        .unwrap();
        assert_eq!(embedded.cases.len(), disk.cases.len());
        assert!(embedded.cases.len() > 10);
    }
}
