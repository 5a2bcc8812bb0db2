//! Knots (beyond Liu et al. 2016, who list them as future work; after Larsson et al. 2022,
//! "Procedural texturing of solid wood with knots", ACM TOG 41(4)): each branch leaves the pith in
//! a whorl and grows its own rings about its axis. The combined growth time is the (smooth) minimum
//! of the trunk's and the branch's time fields, so the knot is exactly where the branch reached a
//! point first: a cone from the pith, and the trunk rings bend around it. A dead branch stops
//! growing at its death year: beyond it the knot is a cylinder rimmed by bark, and the trunk rings
//! close around it without merging.

use super::params::KnotParams;
use crate::math::{Pcg32, PI};
use glam::Vec3;

/// The golden angle π (3 − √5), radians.
const GOLDEN_ANGLE: f32 = 2.399_963;

/// Width of the bark rim around a dead knot, mm.
const BARK_RIM: f32 = 0.4;

/// Knot layout and time fields, precomputed from [`KnotParams`].
#[derive(Clone, Debug)]
pub struct Knots {
    spacing: f32,
    per_whorl: u32,
    cos_rise: f32,
    tan_rise: f32,
    sin_rise: f32,
    /// Ring width inside the branch, mm: the cone half-angle β satisfies tan β = w_b cos α / W,
    /// because the knot boundary is where ρ / w_b = r / W with r ≈ s cos α (notes/wood.md).
    inv_branch_ring: f32,
    death_year: Option<f32>,
    /// Smooth-minimum width, years (live knots only).
    blend: f32,
    pub darkening: f32,
    seed: u64,
}

/// What a knot does at one point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KnotSample {
    /// Combined growth time (years).
    pub time: f32,
    /// 1 inside the knot, 0 outside.
    pub inside: f32,
    /// 1 on the bark rim of a dead knot.
    pub bark: f32,
    /// Unit branch axis.
    pub axis: Vec3,
    /// Offset of the point from the axis, perpendicular to it (mm).
    pub offset: Vec3,
    /// Knot radius at this point's position along the axis (mm).
    pub radius: f32,
}

impl Knots {
    pub fn new(p: &KnotParams, ring_width: f32, seed: u64) -> Self {
        let rise = p.rise.to_radians();
        let cone = p.cone.to_radians();
        let branch_ring = cone.tan() * ring_width / rise.cos();
        Knots {
            spacing: p.whorl_spacing,
            per_whorl: p.per_whorl,
            cos_rise: rise.cos(),
            tan_rise: rise.tan(),
            sin_rise: rise.sin(),
            inv_branch_ring: 1.0 / branch_ring,
            death_year: p.death_year,
            blend: 0.3,
            darkening: p.darkening,
            seed,
        }
    }

    /// The branch of whorl `k` nearest in azimuth to `theta`: (origin on the pith, unit axis).
    #[inline]
    fn branch(&self, k: i64, theta: f32) -> (Vec3, Vec3) {
        let mut rng = Pcg32::new(self.seed, k as u64);
        let step = 2.0 * PI / self.per_whorl as f32;
        // Whorls turn by the golden angle (phyllotaxis), so knots of successive whorls do not line up.
        let phase = (k as f32 * GOLDEN_ANGLE).rem_euclid(step);
        let j = ((theta - phase) / step).round();
        let az = phase + j * step;
        let z0 = (k as f32 + (rng.next_f32() - 0.5) * 0.2) * self.spacing;
        let (s, c) = az.sin_cos();
        let axis = Vec3::new(c * self.cos_rise, s * self.cos_rise, self.sin_rise);
        (Vec3::new(0.0, 0.0, z0), axis)
    }

    /// The knot field at `q` (tree space after distortion) with polar angle `theta`, radius `r` and
    /// trunk time `t_trunk`; `None` far from every knot.
    pub fn eval(&self, q: Vec3, theta: f32, r: f32, t_trunk: f32) -> Option<KnotSample> {
        // A branch of whorl k passes height z_k + r tan α at radius r: check the two nearest whorls.
        let kf = (q.z - r * self.tan_rise) / self.spacing;
        let mut best: Option<KnotSample> = None;
        for k in [kf.floor() as i64, kf.floor() as i64 + 1] {
            let (origin, axis) = self.branch(k, theta);
            let d = q - origin;
            let s = d.dot(axis);
            if s <= 0.0 {
                continue;
            }
            let offset = d - s * axis;
            let rho = offset.length();
            let t_branch = rho * self.inv_branch_ring;
            let radius_live = t_trunk.max(0.0) / self.inv_branch_ring;
            let sample = match self.death_year {
                Some(death) => {
                    // Dead: the branch's rings stop at `death`; a bark rim surrounds the stub.
                    let radius = death / self.inv_branch_ring;
                    if t_branch < t_trunk && t_branch <= death {
                        KnotSample {
                            time: t_branch,
                            inside: 1.0,
                            bark: 0.0,
                            axis,
                            offset,
                            radius,
                        }
                    } else if t_trunk > death && rho < radius + BARK_RIM {
                        KnotSample {
                            time: t_trunk,
                            inside: 0.0,
                            bark: 1.0,
                            axis,
                            offset,
                            radius,
                        }
                    } else {
                        KnotSample {
                            time: t_trunk,
                            inside: 0.0,
                            bark: 0.0,
                            axis,
                            offset,
                            radius: radius.min(radius_live),
                        }
                    }
                }
                None => KnotSample {
                    time: smooth_min(t_trunk, t_branch, self.blend),
                    inside: if t_branch < t_trunk { 1.0 } else { 0.0 },
                    bark: 0.0,
                    axis,
                    offset,
                    radius: radius_live,
                },
            };
            let nearer = match &best {
                Some(b) => sample.time < b.time || sample.inside > b.inside,
                None => true,
            };
            if nearer {
                best = Some(sample);
            }
        }
        best
    }

    /// Trunk fibre `v` deflected around the knot as 2D potential flow past a cylinder of radius R in
    /// the plane across the axis: u = v⊥ − (R²/ρ²)(2 (v⊥·e) e − v⊥) + (v·a) a, with e the unit offset
    /// (Milne-Thomson, "Theoretical Hydrodynamics", flow past a circular cylinder); tangent to the
    /// knot on its boundary, undisturbed far away. Inside the knot the fibre is the branch axis.
    pub fn deflect_fiber(&self, v: Vec3, k: &KnotSample) -> Vec3 {
        if k.inside > 0.5 {
            return k.axis;
        }
        let rho2 = k.offset.length_squared();
        if !(rho2 > 1e-12) {
            return v;
        }
        let along = v.dot(k.axis) * k.axis;
        let perp = v - along;
        let e = k.offset / rho2.sqrt();
        let ratio = (k.radius * k.radius / rho2).min(1.0);
        let u = perp - ratio * (2.0 * perp.dot(e) * e - perp) + along;
        let len = u.length();
        if len > 1e-6 {
            u / len
        } else {
            v
        }
    }
}

/// Polynomial smooth minimum of width `k` (Quílez 2013, "smooth minimum"): C¹, equals min(a, b)
/// when |a − b| ≥ k.
#[inline]
pub fn smooth_min(a: f32, b: f32, k: f32) -> f32 {
    let h = (0.5 + 0.5 * (b - a) / k).clamp(0.0, 1.0);
    b + (a - b) * h - k * h * (1.0 - h)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params(death: Option<f32>) -> KnotParams {
        KnotParams {
            whorl_spacing: 300.0,
            per_whorl: 4,
            rise: 20.0,
            cone: 6.0,
            death_year: death,
            darkening: 0.5,
        }
    }

    #[test]
    fn knot_is_a_cone_from_the_pith() {
        let w = 4.0;
        let knots = Knots::new(&params(None), w, 1);
        // Walk along a branch axis: points on it are inside; far off it, outside.
        let (o, a) = knots.branch(0, 0.0);
        for s in [20.0, 60.0, 120.0] {
            let q = o + a * s;
            let r = (q.x * q.x + q.y * q.y).sqrt();
            let theta = q.y.atan2(q.x);
            let k = knots.eval(q, theta, r, r / w).unwrap();
            assert_eq!(k.inside, 1.0, "on the axis at s = {s}");
            // The radius grows linearly: R ≈ s tan β (cos α of the trunk time cancels).
            let expect = s * 6f32.to_radians().tan();
            assert!(
                (k.radius - expect).abs() < 0.05 * expect,
                "{} vs {expect}",
                k.radius
            );
        }
    }

    #[test]
    fn dead_knots_stop_growing_and_have_bark_live_knots_keep_growing() {
        let w = 4.0;
        let (dead, live) = (
            Knots::new(&params(Some(10.0)), w, 1),
            Knots::new(&params(None), w, 1),
        );
        let (o, a) = dead.branch(0, 0.0);
        let side = a.cross(Vec3::Z).normalize();
        let at = |k: &Knots, s: f32, rho: f32| {
            let q = o + a * s + side * rho;
            let r = (q.x * q.x + q.y * q.y).sqrt();
            k.eval(q, q.y.atan2(q.x), r, r / w).unwrap()
        };
        // Far out (trunk time ≈ 45 years ≫ 10), the dead knot is a cylinder of radius w_b · 10.
        let s = 190.0;
        let rd = at(&dead, s, 0.0).radius;
        let wb = 6f32.to_radians().tan() * w / 20f32.to_radians().cos();
        assert!((rd - 10.0 * wb).abs() < 1e-3, "dead radius {rd}");
        assert_eq!(at(&dead, s, 0.5 * rd).inside, 1.0);
        assert_eq!(at(&dead, s, rd + 0.2).bark, 1.0, "bark rim");
        assert_eq!(
            at(&dead, s, rd + 1.0).inside + at(&dead, s, rd + 1.0).bark,
            0.0
        );
        // The live knot is still growing there: wider, no bark.
        let live_in = at(&live, s, 2.0 * rd);
        assert_eq!((live_in.inside, live_in.bark), (1.0, 0.0));
        assert!(live_in.radius > 3.0 * rd);
    }

    #[test]
    fn deflected_fibre_is_tangent_on_the_boundary() {
        let knots = Knots::new(&params(None), 4.0, 1);
        let k = KnotSample {
            time: 0.0,
            inside: 0.0,
            bark: 0.0,
            axis: Vec3::X,
            offset: Vec3::new(0.0, 0.0, 2.0),
            radius: 2.0,
        };
        let u = knots.deflect_fiber(Vec3::Z, &k);
        // Flow straight at the knot stagnates; pick an oblique one instead.
        let u2 = knots.deflect_fiber(Vec3::new(0.0, 0.6, 0.8), &k);
        assert!(u2.dot(Vec3::Z).abs() < 1e-5 && (u2.length() - 1.0).abs() < 1e-5);
        assert!(u.is_finite());
    }

    #[test]
    fn smooth_min_matches_min_far_apart() {
        assert_eq!(smooth_min(1.0, 3.0, 0.5), 1.0);
        assert!(smooth_min(1.0, 1.0, 0.5) < 1.0);
    }
}
