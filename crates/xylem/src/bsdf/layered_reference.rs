//! The ground truth for the rough finish: a position-free Monte Carlo random walk (Guo, Hašan,
//! Zhao 2018, "Position-free Monte Carlo simulation for arbitrary layered BSDFs", §4: a clear
//! layer needs directions only) through a rough dielectric interface over a substrate, the
//! interface itself simulated by the microsurface random walk of Heitz, Hanika, d'Eon, Dachsbacher
//! 2016 ("Multiple-scattering microfacet BSDFs with the Smith model", §5 and Alg. 2: uniform
//! heights, GGX visible normals, Fresnel choice of reflection or refraction), so that every order
//! of scattering on the microsurface is counted and a lossless interface loses nothing.
//!
//! Written apart from the analytic model in `bsdf::wood` and `bsdf::rough_finish`: its own f64
//! GGX, Fresnel and visible-normal sampling; only the fibre lobe's `eval`/`sample`/`pdf` are
//! shared, as the substrate being layered.
//!
//! It lives in the engine, not the lab, because the rough-finish and rough-transmission tables are
//! generated from it (by the lab's binary `xylem-tables`); the lab's rough-finish suite
//! measures the analytic model against it (`xylem_lab::layered_reference`).

use super::{FiberAxis, FiberNormalization};
use crate::math::Pcg32;
use glam::{DVec3, Vec2, Vec3};

/// What lies under the finish.
#[derive(Clone, Copy, Debug)]
pub enum Substrate {
    /// Lambertian of albedo ρ.
    Lambertian(f64),
    /// The energy-bounded fibre lobe with colour k_f and Gaussian width β (radians).
    Fiber {
        /// The fibre axis in the surface frame.
        axis: FiberAxis,
        /// Highlight width β (radians).
        beta: f32,
        /// Fibre colour k_f.
        k_f: f64,
    },
}

/// A rough dielectric interface (GGX α, relative index η over the substrate) over a substrate.
#[derive(Clone, Copy, Debug)]
pub struct LayeredReference {
    /// GGX roughness α of the interface.
    pub alpha: f64,
    /// Relative refractive index η of the finish over the outside.
    pub eta: f64,
    /// What lies under the finish.
    pub substrate: Substrate,
}

/// How a path that came back out had travelled, for per-lobe comparisons.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PathKind {
    /// Never entered the finish: the interface's reflection (all orders on the microsurface).
    Interface,
    /// Reached the substrate once.
    SinglePass,
    /// Reached the substrate two or more times (internal reflections).
    MultiplePass,
}

/// How a traced path ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PathEnd {
    /// It left upward in this direction with this weight, after this kind of path.
    Exit(Vec3, f64, PathKind),
    /// It was absorbed (by the substrate or the weight's roulette).
    Absorbed,
    /// It was cut at the event limit, neither counted nor lost (`ReferenceAlbedo::truncated`).
    Truncated,
}

/// The estimate over one view: albedo per path kind and the reflected light binned by exit
/// direction (`BINS_MU` bins in cos θi × 2 half-planes: the mirror side first).
#[derive(Clone, Debug, Default)]
pub struct ReferenceAlbedo {
    /// Albedo of paths that never entered the finish.
    pub interface: f64,
    /// Albedo of paths that reached the substrate once.
    pub single_pass: f64,
    /// Albedo of paths that reached the substrate two or more times.
    pub multiple_pass: f64,
    /// Standard error of the total.
    pub sigma: f64,
    /// Reflected light per exit-direction bin (`2 · BINS_MU` bins, mirror side first), fraction of
    /// the incident light.
    pub bins: Vec<f64>,
    /// Paths cut at the event cap (should be 0).
    pub truncated: u64,
}

impl ReferenceAlbedo {
    /// The whole albedo: interface + single pass + multiple pass.
    pub fn total(&self) -> f64 {
        self.interface + self.single_pass + self.multiple_pass
    }
}

/// Bins of the exit direction's cos θi (uniform in μ).
pub const BINS_MU: usize = 8;

/// The bin of `wi` for a view `wo`: μ bin, then 0 on the mirror side of the plane through the
/// normal perpendicular to wo's azimuth, 1 on the back side.
pub fn direction_bin(wo: Vec3, wi: Vec3) -> usize {
    let m = ((wi.z.clamp(0.0, 1.0) * BINS_MU as f32) as usize).min(BINS_MU - 1);
    let back = wo.x * wi.x + wo.y * wi.y > 0.0;
    m + BINS_MU * back as usize
}

const MAX_EVENTS: u32 = 10_000;

/// Fresnel reflectance for cos θi = `c` > 0 into relative index `eta` (1 under total internal
/// reflection) (Born & Wolf §1.5.2).
fn fresnel(c: f64, eta: f64) -> f64 {
    let s2 = (1.0 - c * c) / (eta * eta);
    if s2 >= 1.0 {
        return 1.0;
    }
    let t = (1.0 - s2).sqrt();
    let rs = (c - eta * t) / (c + eta * t);
    let rp = (eta * c - t) / (eta * c + t);
    0.5 * (rs * rs + rp * rp)
}

impl LayeredReference {
    /// Signed Smith Λ of a direction (Heitz 2014 eq. 72; Λ(−ω) = −1 − Λ(ω), Heitz 2016 §3).
    fn lambda(&self, w: DVec3) -> f64 {
        let c2 = w.z * w.z;
        if c2 <= 0.0 {
            return 0.0;
        }
        let root = (1.0 + self.alpha * self.alpha * (1.0 - c2).max(0.0) / c2).sqrt();
        if w.z > 0.0 {
            0.5 * (-1.0 + root)
        } else {
            0.5 * (-1.0 - root)
        }
    }

    /// GGX normal visible from `w` (any z ≠ ±0; Heitz 2018's projected-hemisphere construction,
    /// which holds for directions below the horizon too).
    fn visible_normal(&self, w: DVec3, rng: &mut Pcg32) -> DVec3 {
        let a = self.alpha;
        let v = DVec3::new(a * w.x, a * w.y, w.z).normalize();
        let t1 = if v.x * v.x + v.y * v.y > 1e-14 {
            DVec3::new(-v.y, v.x, 0.0).normalize()
        } else {
            DVec3::X
        };
        let t2 = v.cross(t1);
        let (u1, u2) = (rng.next_f32() as f64, rng.next_f32() as f64);
        let r = u1.sqrt();
        let phi = 2.0 * std::f64::consts::PI * u2;
        let p1 = r * phi.cos();
        let s = 0.5 * (1.0 + v.z);
        let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * phi.sin();
        let n = p1 * t1 + p2 * t2 + (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt() * v;
        DVec3::new(a * n.x, a * n.y, n.z.max(1e-12)).normalize()
    }

    /// Next height along travel direction `d` from height `h` on the upper side (uniform height
    /// distribution on [−1, 1]: C1(h) = (h + 1)/2), or +∞ if the ray leaves (Heitz 2016, eq. 21).
    fn next_height(&self, d: DVec3, h: f64, u: f64) -> f64 {
        let c1 = |h: f64| (0.5 * (h + 1.0)).clamp(0.0, 1.0);
        if d.z > 0.9999 {
            return f64::INFINITY;
        }
        if d.z < -0.9999 {
            return 2.0 * (u * c1(h)) - 1.0;
        }
        if d.z.abs() < 1e-5 {
            return h;
        }
        let lam = self.lambda(d);
        let g1 = if d.z > 0.0 { c1(h).powf(lam) } else { 0.0 };
        if u > 1.0 - g1 {
            return f64::INFINITY;
        }
        let c = c1(h) / (1.0 - u).powf(1.0 / lam);
        (2.0 * c - 1.0).clamp(-1.0, 1.0)
    }

    /// The microsurface walk for light travelling along `d`, arriving from above (`outside`) or
    /// from inside the finish: the direction it leaves with, whether it leaves upward, and the
    /// number of scattering events on the microsurface; `None` if cut at the event cap.
    pub fn interface(
        &self,
        mut d: DVec3,
        mut outside: bool,
        rng: &mut Pcg32,
    ) -> Option<(DVec3, bool, u32)> {
        // Heights on the inner side are mirrored: the inside sees the surface flipped (h → −h,
        // normals → −normals), so each event is the upper-side event of the negated ray.
        // Index-matched (η = 1): the microsurface is optically absent. (Walked, a grazing ray
        // would cross it unchanged thousands of times.)
        if self.eta == 1.0 {
            return Some((d, d.z > 0.0, 0));
        }
        let mut h = if outside { 2.0 } else { -2.0 };
        for events in 0..MAX_EVENTS {
            let u = rng.next_f32() as f64;
            h = if outside {
                self.next_height(d, h, u)
            } else {
                -self.next_height(-d, -h, u)
            };
            if h.is_infinite() {
                return Some((d, outside, events));
            }
            let wi = -d;
            let m = if outside {
                self.visible_normal(wi, rng)
            } else {
                -self.visible_normal(-wi, rng)
            };
            let eta = if outside { self.eta } else { 1.0 / self.eta };
            let c = wi.dot(m).max(0.0);
            if (rng.next_f32() as f64) < fresnel(c, eta) {
                d = 2.0 * c * m - wi;
            } else {
                let t = (1.0 - (1.0 - c * c) / (eta * eta)).max(0.0).sqrt();
                d = (m * (c / eta - t) - wi / eta).normalize();
                outside = !outside;
            }
        }
        None
    }

    /// One path of light arriving from `wo` (z > 0): where it ended.
    pub fn trace(&self, wo: Vec3, rng: &mut Pcg32) -> PathEnd {
        let mut d = -wo.as_dvec3();
        let (mut weight, mut hits) = (1.0f64, 0u32);
        let mut outside = true;
        for _ in 0..MAX_EVENTS {
            let Some((out, up, _)) = self.interface(d, outside, rng) else {
                return PathEnd::Truncated;
            };
            if up {
                let kind = match hits {
                    0 => PathKind::Interface,
                    1 => PathKind::SinglePass,
                    _ => PathKind::MultiplePass,
                };
                return PathEnd::Exit(out.as_vec3().normalize(), weight, kind);
            }
            // Down to the substrate: nothing in a clear finish changes a direction on the way.
            hits += 1;
            let toward_light = (-out).as_vec3().normalize();
            let u = rng.next_vec2();
            let up_dir = match self.substrate {
                Substrate::Lambertian(rho) => {
                    weight *= rho;
                    cosine_up(u)
                }
                Substrate::Fiber { axis, beta, k_f } => {
                    let Some(wi) = axis.sample(toward_light, u, beta, 0.0) else {
                        return PathEnd::Absorbed;
                    };
                    let pdf = axis.pdf(toward_light, wi, beta, 0.0);
                    let f = axis.eval(toward_light, wi, beta, FiberNormalization::EnergyBounded);
                    if !(pdf > 0.0) || wi.z <= 0.0 {
                        return PathEnd::Absorbed;
                    }
                    weight *= k_f * (f * wi.z / pdf) as f64;
                    wi
                }
            };
            if weight <= 0.0 {
                return PathEnd::Absorbed;
            }
            d = up_dir.as_dvec3();
            outside = false;
        }
        PathEnd::Truncated
    }

    /// Albedo for light from `wo` over `n` paths, per kind and binned by exit direction.
    pub fn albedo(&self, wo: Vec3, n: u32, rng: &mut Pcg32) -> ReferenceAlbedo {
        let mut r = ReferenceAlbedo {
            bins: vec![0.0; 2 * BINS_MU],
            ..Default::default()
        };
        let mut sq = 0.0;
        for _ in 0..n {
            match self.trace(wo, rng) {
                PathEnd::Exit(wi, w, kind) => {
                    match kind {
                        PathKind::Interface => r.interface += w,
                        PathKind::SinglePass => r.single_pass += w,
                        PathKind::MultiplePass => r.multiple_pass += w,
                    }
                    r.bins[direction_bin(wo, wi)] += w;
                    sq += w * w;
                }
                PathEnd::Absorbed => {}
                PathEnd::Truncated => r.truncated += 1,
            }
        }
        let inv = 1.0 / n as f64;
        r.interface *= inv;
        r.single_pass *= inv;
        r.multiple_pass *= inv;
        r.bins.iter_mut().for_each(|b| *b *= inv);
        let mean = r.total();
        r.sigma = ((sq * inv - mean * mean).max(0.0) * inv).sqrt();
        r
    }
}

/// Cosine-weighted direction about +z (Malley's method), own copy so the reference shares no
/// sampling code with the model.
fn cosine_up(u: Vec2) -> Vec3 {
    let r = u.x.sqrt();
    let phi = 2.0 * std::f32::consts::PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u.x).max(0.0).sqrt())
}
