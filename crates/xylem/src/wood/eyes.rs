//! Birdseye (ours, beyond Liu et al. 2016's "bumps in the radial direction"): each eye is the
//! trace of an aborted bud, a thin radial rod of pith-like tissue that the growth layers dip
//! around for a few centimetres of radius (Bragg, Stokke & Hwang 1999 / Bragg 2006 on sugar maple
//! birdseye; Hoadley, *Understanding Wood*, 2000, ch. 11). A trace at azimuth θₑ and height zₑ
//! pushes the rings inward by a compact dimple of the distance ρ from its axis (a radial
//! displacement, so fibres and ring contours bend round it through the distortion's Jacobian) and
//! darkens a small core about the axis (the dark centre of an eye).
//!
//! Layout: traces live in radial shells `length` mm thick; within a shell each trace is a radial
//! segment at a fixed angle, tapered in and out with sin² over the shell. Two shell sets offset by
//! half a shell make every radius see the same mean density (sin² + cos² = 1), so eyes appear
//! across a flat-sawn face whatever its distance from the pith. Within a shell the (arc, z) plane
//! is cut into square cells (side `CELL` eye spacings) holding a Poisson number of traces.

use super::params::EyeParams;
use crate::math::Pcg32;
use glam::Vec3;

/// Cell side in mean eye spacings (1/√density): λ = 2.25 traces per cell on average.
const CELL: f32 = 1.5;
/// At most this many traces per cell (P(Poisson(2.25) > 8) < 10⁻³).
const MAX_PER_CELL: u32 = 8;

/// Birdseye traces, precomputed from [`EyeParams`].
#[derive(Clone, Debug)]
pub struct Eyes {
    cell: f32,
    length: f32,
    /// Mean traces per cell (Poisson λ) of one shell set (half the density each).
    lambda: f32,
    diameter: [f32; 2],
    depth: f32,
    core: f32,
    /// Extra absorbance at an eye's centre (multiples of the latewood path).
    pub darkening: f32,
    seed: u64,
}

/// What the eyes do at one point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EyeSample {
    /// Radial displacement (mm, negative: rings pulled toward the pith) and its gradient.
    pub m: f32,
    /// ∇m (tree space).
    pub grad_m: Vec3,
    /// Dark core weight in [0, 1].
    pub core: f32,
}

impl Eyes {
    /// The traces of `p`; `seed` selects them.
    pub fn new(p: &EyeParams, seed: u64) -> Self {
        // Eyes per mm² of tangential face, shared by two shell sets.
        let density = p.density / 100.0;
        let cell = CELL / density.sqrt();
        Eyes {
            cell,
            length: p.length,
            lambda: 0.5 * density * cell * cell,
            diameter: p.diameter,
            depth: p.depth,
            core: p.core,
            darkening: p.darkening,
            seed,
        }
    }

    /// The eyes' displacement and dark core at tree-space point `p`.
    pub fn eval(&self, p: Vec3) -> EyeSample {
        let r = (p.x * p.x + p.y * p.y).sqrt();
        let mut out = EyeSample::default();
        if r < 1e-3 {
            return out;
        }
        let theta = p.y.atan2(p.x);
        let rhat = Vec3::new(p.x / r, p.y / r, 0.0);
        for set in 0..2u32 {
            let offset = 0.5 * set as f32 * self.length;
            let x = (r - offset) / self.length;
            let shell = x.floor();
            let f = x - shell;
            // Taper sin²(πf) and its derivative along r.
            let (s, c) = (std::f32::consts::PI * f).sin_cos();
            let taper = s * s;
            let dtaper = 2.0 * std::f32::consts::PI * s * c / self.length;
            let r_mid = offset + (shell + 0.5) * self.length;
            if r_mid <= 0.0 {
                continue;
            }
            let n_arc = ((std::f32::consts::TAU * r_mid / self.cell).round() as i64).max(1);
            let arc_cell = std::f32::consts::TAU * r_mid / n_arc as f32;
            let a = theta.rem_euclid(std::f32::consts::TAU) * r_mid;
            let (ia, iz) = (
                (a / arc_cell).floor() as i64,
                (p.z / self.cell).floor() as i64,
            );
            for da in -1..=1 {
                for dz in -1..=1 {
                    let ca = (ia + da).rem_euclid(n_arc);
                    let cz = iz + dz;
                    let key = (shell as i64 as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
                        ^ (ca as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
                        ^ (cz as u64).wrapping_mul(0x1656_67B1_9E37_79F9)
                        ^ u64::from(set);
                    let mut rng = Pcg32::new(self.seed ^ key, key.rotate_left(17));
                    let count = poisson(self.lambda, rng.next_f32()).min(MAX_PER_CELL);
                    for _ in 0..count {
                        let te = (ca as f32 + rng.next_f32()) * arc_cell / r_mid;
                        let ze = (cz as f32 + rng.next_f32()) * self.cell;
                        let d = self.diameter[0]
                            + (self.diameter[1] - self.diameter[0]) * rng.next_f32();
                        let (se, ce) = te.sin_cos();
                        // Lateral offset from the trace (across it in the xy plane) and along z.
                        let w = -se * p.x + ce * p.y;
                        let h = p.z - ze;
                        if ce * p.x + se * p.y <= 0.0 {
                            continue;
                        }
                        // Compact dimple (1 − q)³, q = ρ² / d² (zero from ρ = d, the eye's rim
                        // at about half of it).
                        let q = (w * w + h * h) / (d * d);
                        if q >= 1.0 {
                            continue;
                        }
                        let k = (1.0 - q) * (1.0 - q) * (1.0 - q);
                        let dk_dq = -3.0 * (1.0 - q) * (1.0 - q);
                        let grad_q = (2.0 / (d * d)) * Vec3::new(-se * w, ce * w, h);
                        out.m -= self.depth * taper * k;
                        out.grad_m -= self.depth * (dtaper * k * rhat + taper * dk_dq * grad_q);
                        let qc = (w * w + h * h) / (self.core * self.core);
                        if qc < 1.0 {
                            let kc = (1.0 - qc) * (1.0 - qc);
                            out.core = out.core.max(taper.sqrt() * kc);
                        }
                    }
                }
            }
        }
        out
    }
}

/// The Poisson(λ) count whose CDF first exceeds `u` (inversion; λ is small).
fn poisson(lambda: f32, u: f32) -> u32 {
    let mut p = (-lambda).exp();
    let mut cdf = p;
    let mut k = 0;
    while u > cdf && k < 64 {
        k += 1;
        p *= lambda / k as f32;
        cdf += p;
    }
    k
}

#[cfg(test)]
mod tests {
    use super::*;

    fn eyes() -> Eyes {
        Eyes::new(
            &EyeParams {
                density: 3.0,
                diameter: [2.0, 5.0],
                depth: 1.0,
                length: 40.0,
                core: 0.4,
                darkening: 2.0,
            },
            5,
        )
    }

    #[test]
    fn gradient_matches_finite_differences() {
        let e = eyes();
        let mut rng = Pcg32::new(2, 0);
        let mut checked = 0;
        for _ in 0..4000 {
            let p = Vec3::new(
                80.0 + 60.0 * rng.next_f32(),
                40.0 * rng.next_f32(),
                100.0 * rng.next_f32(),
            );
            let s = e.eval(p);
            if s.m == 0.0 {
                continue;
            }
            let h = 1e-3;
            for (i, axis) in [Vec3::X, Vec3::Y, Vec3::Z].into_iter().enumerate() {
                let fd = (e.eval(p + h * axis).m - e.eval(p - h * axis).m) / (2.0 * h);
                assert!(
                    (fd - s.grad_m[i]).abs() < 2e-2,
                    "{p} axis {i}: {fd} vs {}",
                    s.grad_m
                );
            }
            checked += 1;
        }
        assert!(checked > 50, "{checked}");
    }
}
