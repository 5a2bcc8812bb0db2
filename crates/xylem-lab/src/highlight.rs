//! Where the fibre highlight of a flat finished board peaks along a light arc.
//!
//! Marschner et al. 2005 (eq. 1–3 as quoted by Liu et al. 2016, §2.1): the fibre lobe is a
//! Gaussian in ψh = ψi + ψr, with ψ = asin(ω′·u) for the directions ω′ *refracted into the finish*
//! and u the fibre axis; it peaks at ψh = 0. For a flat board (normal +z in the local frame) and a
//! light moving along an arc through the zenith, ψh = 0 has a closed-form solution for the light
//! angle; the derivation is in `notes/sweep.md` ("Highlight peak").

use xylem::math::{safe_asin, safe_sqrt, Vec3};

/// The direction inside a smooth finish of index `eta` (above: air) of the exterior direction
/// `w`; both point away from the surface (z > 0). Snell's law keeps the tangential component of
/// a unit direction scaled by 1/η, and the normal component makes it unit again.
#[inline]
pub fn refract_into_finish(w: Vec3, eta: f32) -> Vec3 {
    let tx = w.x / eta;
    let ty = w.y / eta;
    Vec3::new(tx, ty, safe_sqrt(1.0 - tx * tx - ty * ty))
}

/// ψh = asin(ω′i·u) + asin(ω′o·u) (Marschner 2005, eq. 3 of Liu 2016) for exterior directions
/// `wi`, `wo` (local frame, z = normal) refracted into a finish of index `eta`.
pub fn psi_h(u: Vec3, wi: Vec3, wo: Vec3, eta: f32) -> f32 {
    safe_asin(refract_into_finish(wi, eta).dot(u)) + safe_asin(refract_into_finish(wo, eta).dot(u))
}

/// The light angles θ (degrees from the zenith, towards `toward`) at which ψh = 0 for the light
/// direction `cos θ · z + sin θ · toward`, seen from `wo` through a finish of index `eta` on
/// fibres `u` (all in the local frame; `toward` horizontal and unit). Sorted; empty when the
/// highlight never peaks above the horizon; at most two.
///
/// With s = sin θ, a = toward: u·ω′i = A s + B √(1 − s²/η²), A = (u·a)/η, B = u_z
/// (refraction scales the horizontal part by 1/η), and ψh = 0 ⇔ u·ω′i = −u·ω′o = −c. Squaring gives
/// (A² + B²/η²) s² + 2Ac s + c² − B² = 0; roots of the unsquared equation are kept.
pub fn peak_light_angles_deg(u: Vec3, wo: Vec3, toward: Vec3, eta: f32) -> Vec<f32> {
    let c = refract_into_finish(wo, eta).dot(u) as f64;
    let eta = eta as f64;
    let a = u.dot(toward) as f64 / eta;
    let b = u.z as f64;
    let qa = a * a + b * b / (eta * eta);
    if qa < 1e-12 {
        return Vec::new();
    }
    let disc = a * a * c * c - qa * (c * c - b * b);
    if disc < 0.0 {
        return Vec::new();
    }
    let r = disc.sqrt();
    let mut out: Vec<f32> = [(-a * c - r) / qa, (-a * c + r) / qa]
        .into_iter()
        .filter(|s| s.abs() <= 1.0)
        .filter(|&s| {
            let q = (1.0 - s * s / (eta * eta)).max(0.0).sqrt();
            (a * s + b * q + c).abs() < 1e-6
        })
        .map(|s| s.asin().to_degrees() as f32)
        .collect();
    out.sort_by(f32::total_cmp);
    out.dedup_by(|x, y| (*x - *y).abs() < 1e-4);
    out
}

/// The one peak inside the arc `[lo, hi]` degrees, or `None` when there is none or two.
pub fn peak_in_arc_deg(u: Vec3, wo: Vec3, toward: Vec3, eta: f32, lo: f32, hi: f32) -> Option<f32> {
    let (lo, hi) = (lo.min(hi), lo.max(hi));
    let inside: Vec<f32> = peak_light_angles_deg(u, wo, toward, eta)
        .into_iter()
        .filter(|t| (lo..=hi).contains(t))
        .collect();
    match inside.as_slice() {
        [t] => Some(*t),
        _ => None,
    }
}

/// The fibre axis of a board whose fibres run along `toward` and dip `inclination_deg` into the
/// surface (local frame, z = normal): `cos α · toward − sin α · z`.
pub fn inclined_fibre(toward: Vec3, inclination_deg: f32) -> Vec3 {
    let (s, c) = inclination_deg.to_radians().sin_cos();
    (c * toward - s * Vec3::Z).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Refraction by the vector form of Snell's law for a ray travelling *down* through the
    /// interface (Heckbert's formulation, as in PBRT §8.2): t = d/η + (cos θi/η − cos θt) n with
    /// d the travel direction — written independently of `refract_into_finish`.
    fn snell_vector(w_out: Vec3, eta: f64) -> glam::DVec3 {
        let d = -w_out.as_dvec3(); // travelling into the surface
        let n = glam::DVec3::Z;
        let cos_i = -d.dot(n);
        let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
        let cos_t = (1.0 - sin2_t).sqrt();
        let t = d / eta + (cos_i / eta - cos_t) * n;
        -t // back to "pointing away from the surface"
    }

    fn psi_h_ref(u: Vec3, wi: Vec3, wo: Vec3, eta: f64) -> f64 {
        let u = u.as_dvec3();
        snell_vector(wi, eta).dot(u).asin() + snell_vector(wo, eta).dot(u).asin()
    }

    /// Roots of ψh(θ) found by a fine scan for sign changes and bisection, in degrees.
    fn roots_numeric(u: Vec3, wo: Vec3, toward: Vec3, eta: f64) -> Vec<f64> {
        let f = |deg: f64| {
            let t = deg.to_radians();
            let wi = (t.cos() * glam::DVec3::Z + t.sin() * toward.as_dvec3()).as_vec3();
            psi_h_ref(u, wi, wo, eta)
        };
        let mut roots = Vec::new();
        let n = 3600;
        for k in 0..n {
            let (mut lo, mut hi) = (
                -89.99 + 179.98 * k as f64 / n as f64,
                -89.99 + 179.98 * (k + 1) as f64 / n as f64,
            );
            if f(lo).signum() == f(hi).signum() {
                continue;
            }
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if f(mid).signum() == f(lo).signum() {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            roots.push(0.5 * (lo + hi));
        }
        roots
    }

    #[test]
    fn refraction_obeys_snell_and_stays_unit() {
        for deg in [0.0f32, 10.0, 45.0, 80.0, 89.9] {
            let t = deg.to_radians();
            let w = Vec3::new(t.sin() * 0.6, t.sin() * 0.8, t.cos());
            let r = refract_into_finish(w, 1.5);
            assert!((r.length() - 1.0).abs() < 1e-5);
            let sin_t = (r.x * r.x + r.y * r.y).sqrt();
            assert!((t.sin() - 1.5 * sin_t).abs() < 1e-5, "sin θi = η sin θt");
            assert!((r.as_dvec3() - snell_vector(w, 1.5)).length() < 1e-5);
        }
    }

    #[test]
    fn closed_form_peak_matches_numeric_root_finding() {
        let mut rng = xylem::math::Pcg32::new(11, 3);
        let mut checked = 0;
        for _ in 0..400 {
            let eta = 1.0 + rng.next_f32();
            let phi = rng.next_f32() * std::f32::consts::TAU;
            let toward = Vec3::new(phi.cos(), phi.sin(), 0.0);
            let u = xylem::math::uniform_sphere(rng.next_vec2());
            let wo = xylem::math::cosine_hemisphere(rng.next_vec2());
            if wo.z < 0.05 {
                continue;
            }
            let closed = peak_light_angles_deg(u, wo, toward, eta);
            let numeric = roots_numeric(u, wo, toward, eta as f64);
            assert_eq!(
                closed.len(),
                numeric.len(),
                "u {u} wo {wo} η {eta}: {closed:?} vs {numeric:?}"
            );
            for (c, n) in closed.iter().zip(&numeric) {
                assert!((*c as f64 - n).abs() < 2e-3, "{c} vs {n}");
            }
            checked += closed.len();
        }
        assert!(checked > 100, "enough peaks were compared: {checked}");
    }

    #[test]
    fn flat_fibres_seen_from_above_peak_overhead_and_mirror_otherwise() {
        // Fibres in the surface plane along the arc: the highlight is the mirror direction
        // of the view about the normal plane of the fibre, whatever η.
        let u = inclined_fibre(Vec3::X, 0.0);
        assert_eq!(peak_light_angles_deg(u, Vec3::Z, Vec3::X, 1.5), vec![0.0]);
        let t = 40f32.to_radians();
        let wo = Vec3::new(t.sin(), 0.0, t.cos());
        let p = peak_light_angles_deg(u, wo, Vec3::X, 1.5);
        assert!(p.len() == 1 && (p[0] + 40.0).abs() < 1e-3, "{p:?}");
        // Fibres dipping 30° seen from the zenith: no peak above the horizon for η = 1.5
        // (the refracted light can only reach 41.8° from the normal).
        assert!(
            peak_light_angles_deg(inclined_fibre(Vec3::X, 30.0), Vec3::Z, Vec3::X, 1.5).is_empty()
        );
    }

    #[test]
    fn psi_h_vanishes_at_the_predicted_peak() {
        let t = 40f32.to_radians();
        let wo = Vec3::new(t.sin(), 0.0, t.cos());
        for incl in [0.0, 15.0, 30.0] {
            let u = inclined_fibre(Vec3::X, incl);
            let th = peak_in_arc_deg(u, wo, Vec3::X, 1.5, -85.0, 85.0).unwrap();
            let r = th.to_radians();
            let wi = Vec3::new(r.sin(), 0.0, r.cos());
            assert!(
                psi_h(u, wi, wo, 1.5).abs() < 1e-5,
                "inclination {incl}: θ {th}"
            );
        }
    }
}
