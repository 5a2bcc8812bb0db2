//! Knots (beyond Liu et al. 2016, who list them as future work; after Larsson et al. 2022,
//! "Procedural texturing of solid wood with knots", ACM TOG 41(4)): each branch leaves the pith in
//! a whorl and grows its own rings about its axis. The combined growth time is the (smooth) minimum
//! of the trunk's and the branch's time fields, so the knot is exactly where the branch reached a
//! point first: a cone from the pith, and the trunk rings bend around it. A dead branch stops
//! growing at its death year: beyond it the knot is a cylinder rimmed by bark, and the trunk rings
//! close around it without merging.

use super::params::KnotParams;
use crate::math::{Pcg32, PI};
use glam::{Mat3, Vec3};

/// The golden angle π (3 − √5), radians.
const GOLDEN_ANGLE: f32 = 2.399_963;

/// How much further the branch collar (`KnotParams::swell`) reaches along the trunk than across.
const SWELL_ELONGATION: f32 = 2.0;

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
    /// Extra absorbance of knot wood (multiples of the latewood path).
    pub darkening: f32,
    /// Largest lowering of the trunk time round a knot (years; 0: none) and its fade width (mm).
    swell: f32,
    inv_swell_width: f32,
    /// Bark rim round a dead knot, mm.
    bark_width: f32,
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
    /// Unit axis of the governing branch (the one the point is inside, or nearest in time).
    pub axis: Vec3,
    /// Knot radius of the governing branch at this point's position along its axis (mm).
    pub radius: f32,
    /// The trunk fibre's deflection by the nearby knots, as one linear map: outside every knot
    /// the fibre is v + flow·v (see [`Knots::deflect_fiber`]).
    pub flow: Mat3,
}

impl Knots {
    /// The knot layout of `p` in a tree of ring width `ring_width` (mm); `seed` selects the knots.
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
            swell: p.swell,
            inv_swell_width: 1.0 / p.swell_width,
            bark_width: p.bark_width,
            seed,
        }
    }

    /// Branch `j` of whorl `k`: (origin on the pith, unit axis, azimuth). Whorls turn by the
    /// golden angle (phyllotaxis), so knots of successive whorls do not line up.
    #[inline]
    fn branch(&self, k: i64, j: f32) -> (Vec3, Vec3, f32) {
        let mut rng = Pcg32::new(self.seed, k as u64);
        let az = self.phase(k) + j * self.step();
        let z0 = (k as f32 + (rng.next_f32() - 0.5) * 0.2) * self.spacing;
        let (s, c) = az.sin_cos();
        let axis = Vec3::new(c * self.cos_rise, s * self.cos_rise, self.sin_rise);
        (Vec3::new(0.0, 0.0, z0), axis, az)
    }

    /// Azimuth between the branches of a whorl, radians.
    #[inline]
    fn step(&self) -> f32 {
        2.0 * PI / self.per_whorl as f32
    }

    /// Azimuth of branch 0 of whorl `k`, radians.
    #[inline]
    fn phase(&self, k: i64) -> f32 {
        (k as f32 * GOLDEN_ANGLE).rem_euclid(self.step())
    }

    /// The knot field at `q` (tree space after distortion) with polar angle `theta`, radius `r` and
    /// trunk time `t_trunk`; `None` far from every knot. The candidates are the two branches
    /// bracketing `theta` in each of the two whorls bracketing `q` (a branch of whorl k passes
    /// height z_k + r tan α at radius r); the one the point is inside (or nearest in time) governs
    /// time and colour, and all four deflect the fibres (superposed flows, each tapered to zero
    /// before it leaves the candidate set, so the fibre field has no seams).
    pub fn eval(&self, q: Vec3, theta: f32, r: f32, t_trunk: f32) -> Option<KnotSample> {
        let kf = (q.z - r * self.tan_rise) / self.spacing;
        let (step, mut best, mut flow) = (self.step(), None::<KnotSample>, Mat3::ZERO);
        let mut swell = 0.0f32;
        for k in [kf.floor() as i64, kf.floor() as i64 + 1] {
            let j0 = ((theta - self.phase(k)) / step).floor();
            for j in [j0, j0 + 1.0] {
                let (origin, axis, az) = self.branch(k, j);
                let d = q - origin;
                let s = d.dot(axis);
                if s <= 0.0 {
                    continue;
                }
                let offset = d - s * axis;
                let rho = offset.length();
                let sample = self.sample(axis, rho, t_trunk);
                // Whorl k leaves the candidates at |kf − k| = 1 (jitter ±0.1), branch j at one
                // step of azimuth: the taper reaches zero before either, and is 1 over the knot.
                let weight = taper((kf - origin.z / self.spacing).abs())
                    * taper(((theta - az) / step).abs())
                    * (2.0 * s / d.length()).min(1.0);
                if rho > 1e-6 && sample.inside == 0.0 && weight > 0.0 {
                    flow += weight * cylinder_flow(axis, offset / rho, sample.radius / rho);
                }
                if self.swell > 0.0 && sample.inside == 0.0 && weight > 0.0 {
                    // The collar: exp(−x²) of the distance x from the knot's surface in swell
                    // widths; a live knot's rings merge with the trunk's, so there it also
                    // rises from 0 at the surface (no step in time).
                    // The collar reaches `SWELL_ELONGATION` times further along the trunk
                    // (offset along ẑ) than across it: loops longer along the grain.
                    let along = if rho > 1e-6 { offset.z / rho } else { 0.0 };
                    let stretch = 1.0 + (SWELL_ELONGATION - 1.0) * along * along;
                    let x = ((rho - sample.radius) * self.inv_swell_width / stretch).max(0.0);
                    let rise = if self.death_year.is_some() {
                        1.0
                    } else {
                        1.0 - (-(4.0 * x) * (4.0 * x)).exp()
                    };
                    swell = swell.max(weight * rise * (-x * x).exp());
                }
                // Inside a knot beats its bark rim beats outside, then the earlier time.
                let rank = |k: &KnotSample| 2.0 * k.inside + k.bark;
                let nearer = match &best {
                    Some(b) => {
                        rank(&sample) > rank(b)
                            || (rank(&sample) == rank(b) && sample.time < b.time)
                    }
                    None => true,
                };
                if nearer {
                    best = Some(sample);
                }
            }
        }
        best.map(|b| {
            let time = if b.inside == 0.0 && b.bark == 0.0 && swell > 0.0 {
                b.time - self.swell * swell
            } else {
                b.time
            };
            KnotSample { flow, time, ..b }
        })
    }

    /// The knot of the branch with unit `axis` at distance `rho` from it, trunk time `t_trunk`.
    #[inline]
    fn sample(&self, axis: Vec3, rho: f32, t_trunk: f32) -> KnotSample {
        let t_branch = rho * self.inv_branch_ring;
        let radius_live = t_trunk.max(0.0) / self.inv_branch_ring;
        let knot = |time, inside, bark, radius| KnotSample {
            time,
            inside,
            bark,
            axis,
            radius,
            flow: Mat3::ZERO,
        };
        match self.death_year {
            Some(death) => {
                // Dead: the branch's rings stop at `death`; a bark rim surrounds the stub.
                let radius = death / self.inv_branch_ring;
                if t_branch < t_trunk && t_branch <= death {
                    knot(t_branch, 1.0, 0.0, radius)
                } else if t_trunk > death && rho < radius + self.bark_width {
                    knot(t_trunk, 0.0, 1.0, radius)
                } else {
                    knot(t_trunk, 0.0, 0.0, radius.min(radius_live))
                }
            }
            None => knot(
                smooth_min(t_trunk, t_branch, self.blend),
                if t_branch < t_trunk { 1.0 } else { 0.0 },
                0.0,
                radius_live,
            ),
        }
    }

    /// Trunk fibre `v` deflected around the nearby knots (the sample's superposed flows); inside
    /// a knot the fibre is the branch axis.
    pub fn deflect_fiber(&self, v: Vec3, k: &KnotSample) -> Vec3 {
        if k.inside > 0.5 {
            return k.axis;
        }
        let u = v + k.flow * v;
        let len = u.length();
        if len > 1e-6 {
            u / len
        } else {
            v
        }
    }
}

/// 2D potential flow past a cylinder of radius R in the plane across the unit `axis`, as the
/// linear map v ↦ u − v: u = v⊥ − (R²/ρ²)(2 (v⊥·e) e − v⊥) + (v·a) a, e the unit offset of the
/// point from the axis (Milne-Thomson, "Theoretical Hydrodynamics", flow past a circular
/// cylinder): tangent to the knot on its boundary, undisturbed far away. `ratio` = R/ρ.
#[inline]
fn cylinder_flow(axis: Vec3, e: Vec3, ratio: f32) -> Mat3 {
    let outer = |a: Vec3, b: Vec3| Mat3::from_cols(a * b.x, a * b.y, a * b.z);
    let perp = Mat3::IDENTITY - outer(axis, axis);
    let mirror = 2.0 * outer(e, e) - Mat3::IDENTITY;
    -(ratio * ratio).min(1.0) * (mirror * perp)
}

/// 1 for x ≤ 0.4, 0 for x ≥ 0.8, C¹ (smoothstep) between: the fade of a knot's flow with its
/// distance from the point in whorl spacings or in branch steps of azimuth.
#[inline]
fn taper(x: f32) -> f32 {
    let t = ((0.8 - x) / 0.4).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Polynomial smooth minimum of width `k` (Quílez 2013, "smooth minimum"): C¹, equals min(a, b)
/// when |a − b| ≥ k.
#[inline]
pub(crate) fn smooth_min(a: f32, b: f32, k: f32) -> f32 {
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
            swell: 0.0,
            swell_width: 20.0,
            bark_width: 0.4,
        }
    }

    #[test]
    fn knot_is_a_cone_from_the_pith() {
        let w = 4.0;
        let knots = Knots::new(&params(None), w, 1);
        // Walk along a branch axis: points on it are inside; far off it, outside.
        let (o, a, _) = knots.branch(0, 0.0);
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
        let (o, a, _) = dead.branch(0, 0.0);
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

    /// The knot sample of `knots` at `q` with the trunk time of ring width `w`.
    fn at(knots: &Knots, q: Vec3, w: f32) -> Option<KnotSample> {
        let r = (q.x * q.x + q.y * q.y).sqrt();
        knots.eval(q, q.y.atan2(q.x), r, r / w)
    }

    #[test]
    fn bark_rim_is_as_wide_as_asked() {
        let w = 4.0;
        let rim_at = |bark_width: f32, d: f32| {
            let knots = Knots::new(
                &KnotParams {
                    bark_width,
                    ..params(Some(10.0))
                },
                w,
                1,
            );
            let (o, a, _) = knots.branch(0, 0.0);
            let side = a.cross(Vec3::Z).normalize();
            let radius = at(&knots, o + a * 150.0, w).unwrap().radius;
            at(&knots, o + a * 150.0 + side * (radius + d), w)
                .unwrap()
                .bark
        };
        // 1 mm outside the knot: bark under a 1.5 mm rim, trunk wood under the 0.4 mm default.
        assert_eq!(rim_at(1.5, 1.0), 1.0);
        assert_eq!(rim_at(0.4, 1.0), 0.0);
        assert_eq!(rim_at(1.5, 1.6), 0.0);
    }

    #[test]
    fn deflected_fibre_is_tangent_on_the_boundary() {
        let (w, death) = (4.0, 10.0);
        let knots = Knots::new(&params(Some(death)), w, 1);
        let (o, a, _) = knots.branch(0, 0.0);
        let side = a.cross(Vec3::Z).normalize();
        let up = a.cross(side);
        // Just outside the dead knot's bark rim, on both sides and above it.
        let s = 150.0;
        let radius = at(&knots, o + a * s, w).unwrap().radius;
        for e in [side, -side, up] {
            let k = at(
                &knots,
                o + a * s + e * (radius + knots.bark_width + 1e-3),
                w,
            )
            .unwrap();
            assert_eq!((k.inside, k.bark), (0.0, 0.0));
            // A trunk fibre with a component across the knot is turned along its boundary: no
            // component along the offset e (potential flow is tangent on the cylinder).
            let u = knots.deflect_fiber(Vec3::new(0.0, 0.6, 0.8).normalize(), &k);
            let tangent_ratio = (radius / (radius + knots.bark_width)).powi(2);
            assert!(
                u.dot(e).abs() < 0.02 + (1.0 - tangent_ratio),
                "{e}: u·e = {}",
                u.dot(e)
            );
            assert!((u.length() - 1.0).abs() < 1e-5);
        }
    }

    /// Outside the knots the deflected fibre field is continuous: along lines through several
    /// whorls and around the tree, every step of 0.05 mm that turns the fibre by more than 0.002°
    /// is split in 50; a continuous field turns by at most a fifth of it in any sub-step (a
    /// seam, as where the old nearest-branch choice switched whorl or branch, keeps its whole
    /// jump in one sub-step).
    #[test]
    fn fibre_field_has_no_seams_between_knots() {
        let w = 4.0;
        // 2 asin(|a − b| / 2): exact for small angles, where acos of an f32 dot is quantised.
        let angle =
            |a: Vec3, b: Vec3| (2.0 * (0.5 * (a - b).length()).min(1.0).asin()).to_degrees();
        for death in [None, Some(20.0)] {
            let knots = Knots::new(&params(death), w, 3);
            let fibre = |t: f32, around: bool| {
                // Along the tree axis 120 mm out (a board's length, three whorls), or around
                // the tree at r = 120 mm, 30 mm above a whorl.
                let q = if around {
                    let phi = std::f32::consts::PI * t;
                    Vec3::new(120.0 * phi.cos(), 120.0 * phi.sin(), 75.0)
                } else {
                    Vec3::new(0.0, 120.0, -50.0 + 900.0 * t)
                };
                at(&knots, q, w)
                    .filter(|k| k.inside == 0.0 && k.bark == 0.0)
                    .map(|k| knots.deflect_fiber(Vec3::Z, &k))
            };
            for (around, length) in [(false, 900.0), (true, 120.0 * std::f32::consts::PI)] {
                let n = (length / 0.05) as usize;
                let mut checked = 0;
                for i in 0..n {
                    let (t0, t1) = (i as f32 / n as f32, (i + 1) as f32 / n as f32);
                    let (Some(a), Some(b)) = (fibre(t0, around), fibre(t1, around)) else {
                        continue;
                    };
                    let step = angle(a, b);
                    if step < 0.002 {
                        continue;
                    }
                    checked += 1;
                    let sub = (0..50)
                        .filter_map(|k| {
                            let u = fibre(t0 + (t1 - t0) * k as f32 / 50.0, around)?;
                            let v = fibre(t0 + (t1 - t0) * (k + 1) as f32 / 50.0, around)?;
                            Some(angle(u, v))
                        })
                        .fold(0.0f32, f32::max);
                    assert!(
                        sub < 0.2 * step,
                        "{death:?} around {around} at t = {t0}: step {step}°, sub-step {sub}°"
                    );
                }
                assert!(
                    checked > 0,
                    "the line passes no knot: the test tests nothing"
                );
            }
        }
    }

    #[test]
    fn smooth_min_matches_min_far_apart() {
        assert_eq!(smooth_min(1.0, 3.0, 0.5), 1.0);
        assert!(smooth_min(1.0, 1.0, 0.5) < 1.0);
    }
}
