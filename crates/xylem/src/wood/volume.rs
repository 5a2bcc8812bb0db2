//! `WoodVolume`: the solid-wood model of Liu et al. 2016 §6 assembled from its parts, evaluated
//! lazily: `eval(p, needs)` computes only what `needs` asks for and what the parameters switch on.

use super::color::BeerColor;
use super::error::WoodError;
use super::eyes::Eyes;
use super::features::{
    footprint_weight, sub_seed, CellTexture, DistortionNoise, FibreWander, Noise1, Pores, Rays,
};
use super::growth::{RingExpTable, SmoothRectangleWave, SmoothTriangleWave};
use super::knots::{KnotSample, Knots};
use super::params::WoodParams;
use super::{Needs, WoodTexel};
use crate::field::{
    cylinder_cos_sin, cylinder_frame, cylinder_frame_from, exact_jacobian, rotate_about_radial,
    rotate_by, Cylindrical, Displacement, Distortion, JacobianModel,
};
use crate::math::Frame;
use crate::noise::SparseConvolution1;
use crate::simd::{simd_level, Simd};
use glam::Vec3;
use std::sync::Arc;

/// A wood volume ready to evaluate: parameters turned into precomputed waves, colours and noise.
/// Immutable after construction, so it is `Send + Sync` and `eval` allocates nothing.
///
/// ```
/// use xylem::math::Vec3;
/// use xylem::wood::{preset, Needs, WoodVolume};
///
/// // A built-in species preset, tree seed 7; points are tree space in mm (pith along z).
/// let wood = WoodVolume::new(preset("curly_maple")?, 7)?;
/// let texel = wood.eval(Vec3::new(0.0, 120.0, 30.0), Needs::ALL);
/// assert!(texel.diffuse.min_element() >= 0.0 && texel.diffuse.max_element() <= 1.0);
/// assert!((texel.fiber_dir.length() - 1.0).abs() < 1e-4);
/// // Many points at once, computing only the colour.
/// let points = [Vec3::new(0.0, 100.0, 0.0), Vec3::new(5.0, 100.0, 0.0)];
/// let mut out = vec![Default::default(); points.len()];
/// wood.eval_many(&points, Needs::COLOR, &mut out);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug)]
pub struct WoodVolume {
    params: WoodParams,
    seed: u64,
    inv_ring_width: f32,
    growth: Option<SmoothTriangleWave>,
    growth_noise: Option<Noise1>,
    /// The growth wave's phase warp a·m(u) (ours, notes/wood.md §2).
    growth_phase: Option<Noise1>,
    interlock: Option<Noise1>,
    /// Distortion magnitudes along r̂, θ̂, ẑ.
    distortion: [Option<DistortionNoise>; 3],
    rings: SmoothRectangleWave,
    highlight: SmoothRectangleWave,
    /// Beer's law over the ring wave for the diffuse and the fibre colour (footprint filter).
    ring_tables: Arc<[RingExpTable; 2]>,
    color: BeerColor,
    pores: Option<Pores>,
    rays: Option<Rays>,
    knots: Option<Knots>,
    /// Fine-scale grain deviation (notes/wood.md §9a), evaluated only for fibres.
    wander: Option<FibreWander>,
    /// Cell-scale colour texture (notes/wood.md §9c), evaluated only for colour.
    texture: Option<CellTexture>,
    /// Birdseye traces (ours, `eyes.rs`).
    eyes: Option<Eyes>,
    jacobian: JacobianModel,
}

/// A pixel's footprint on the surface, in tree space: what [`WoodVolume::eval_footprint`]
/// band-limits the wood by.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Footprint {
    /// Width (tree mm): the geometric mean of the footprint ellipse's axes; 0 = no filtering.
    pub width: f32,
    /// Unit normal (tree space) of the surface the footprint lies in, or zero where unknown: the
    /// rings are then filtered by the whole 3D gradient of the growth time (wider than what any
    /// surface through the point shows, so they never alias, but blur more on a face cut at a
    /// low angle to the rings).
    pub normal: Vec3,
}

impl Footprint {
    /// A footprint `width` mm wide on a surface of unknown orientation.
    pub fn isotropic(width: f32) -> Self {
        Footprint {
            width,
            normal: Vec3::ZERO,
        }
    }
}

/// Pieces of equal radial extent over which the footprint's rings are box-filtered in time
/// (`WoodVolume::ring_window`): t(r) is taken as linear within each. Red oak (growth noise of
/// 0.42 years over 1.2): RMS colour error against the supersampled footprint 0.010 with one
/// piece, 0.0056 with two, see notes/wood.md §3a for four.
const RING_PIECES: usize = 4;

/// The mean of `piece(a, b)` over consecutive pieces [ends[i], ends[i + 1]] (equal weights:
/// the pieces have equal extent on the surface).
#[inline]
fn ring_pieces_mean<T>(ends: &[f32; RING_PIECES + 1], piece: impl Fn(f32, f32) -> T) -> T
where
    T: std::ops::Add<Output = T> + std::ops::Mul<f32, Output = T>,
{
    let mut sum = piece(ends[0], ends[1]);
    for w in ends[1..].windows(2) {
        sum = sum + piece(w[0], w[1]);
    }
    sum * (1.0 / RING_PIECES as f32)
}

/// Points per block of [`WoodVolume::eval_many`] (16 f32 lanes: one AVX-512 register).
const BATCH: usize = 16;

/// Salts of the independent noise fields, so each feature has its own seed.
mod salt {
    pub(crate) const GROWTH: u32 = 1;
    pub(crate) const INTERLOCK: u32 = 2;
    pub(crate) const DISTORT: [u32; 3] = [3, 4, 5];
    pub(crate) const PORES: u32 = 6;
    pub(crate) const RAYS: u32 = 7;
    pub(crate) const PHASE: u32 = 8;
    pub(crate) const WANDER: [u32; 4] = [9, 10, 11, 12];
    pub(crate) const TEXTURE: [u32; 2] = [13, 14];
    pub(crate) const KNOTS: u64 = 0x6b6e_6f74;
    pub(crate) const EYES: u64 = 0x6579_6573;
    pub(crate) const RAY_WANDER: u32 = 15;
}

/// What `eval` computes at the distorted point before deciding what else it needs.
struct Core {
    dist: Distortion,
    /// Distance of f(p) from the pith.
    r: f32,
    time: f32,
    /// The trunk's growth time at r and its dt/dr (eq. 23–24); `time` is the knots' where
    /// they take over.
    trunk_time: f32,
    dt_dr: f32,
    knot: Option<KnotSample>,
    /// Dark-centre weight of the birdseye traces (0 without eyes).
    eye_core: f32,
}

impl WoodVolume {
    /// Build a volume from validated parameters; `seed` selects the tree.
    pub fn new(params: WoodParams, seed: u64) -> Result<WoodVolume, WoodError> {
        params.validate("<parameters>")?;
        let p = &params;
        let rings = SmoothRectangleWave::new(p.rings.proportions, 0.0, 1.0);
        let highlight = SmoothRectangleWave::new(
            p.rings.proportions,
            p.highlight.earlywood.to_radians(),
            p.highlight.latewood.to_radians(),
        );
        let growth = p
            .growth
            .as_ref()
            .map(|g| SmoothTriangleWave::new(g.wave, g.amplitude));
        // Growth-rate noise n(t_pre) (eq. 24) and the helix angle (§6.1.5): 1D sparse convolution
        // noise scaled to its largest value; the interlock's kernel width gives mean reversal
        // spacing `period` (notes/wood.md §2, §4).
        let growth_noise = p
            .growth
            .as_ref()
            .filter(|g| g.noise_amplitude > 0.0)
            .map(|g| {
                Noise1::new(
                    g.noise_amplitude,
                    g.noise_scale,
                    sub_seed(seed, salt::GROWTH),
                )
            });
        let growth_phase = p
            .growth
            .as_ref()
            .filter(|g| g.phase_amplitude > 0.0 && g.amplitude > 0.0)
            .map(|g| {
                Noise1::new(
                    g.phase_amplitude,
                    g.phase_scale,
                    sub_seed(seed, salt::PHASE),
                )
            });
        let interlock = p.interlock.as_ref().filter(|i| i.angle > 0.0).map(|i| {
            Noise1::new(
                i.angle.to_radians(),
                i.period / SparseConvolution1::ZERO_SPACING,
                sub_seed(seed, salt::INTERLOCK),
            )
        });
        let max_tilt = interlock.map_or(0.0, |i| i.amp);
        let d = &p.distortion;
        let distortion = [&d.radial, &d.tangential, &d.longitudinal]
            .into_iter()
            .zip(salt::DISTORT)
            .map(|(n, s)| {
                n.as_ref()
                    .filter(|n| n.magnitude > 0.0)
                    .map(|n| DistortionNoise::new(n, sub_seed(seed, s)))
            })
            .collect::<Vec<_>>();
        let distortion = [
            distortion[0].clone(),
            distortion[1].clone(),
            distortion[2].clone(),
        ];
        let pores = p
            .pores
            .as_ref()
            .map(|x| Pores::new(x, max_tilt, sub_seed(seed, salt::PORES)));
        let rays = p
            .rays
            .as_ref()
            .filter(|r| r.strength > 0.0)
            .map(|r| Rays::new(r, [salt::RAYS, salt::RAY_WANDER].map(|s| sub_seed(seed, s))));
        let knots = p
            .knots
            .as_ref()
            .map(|k| Knots::new(k, p.rings.width, seed ^ salt::KNOTS));
        let wander = p
            .fibre_wander
            .as_ref()
            .map(|w| FibreWander::new(w, salt::WANDER.map(|s| sub_seed(seed, s))));
        let eyes = p.eyes.as_ref().map(|e| Eyes::new(e, seed ^ salt::EYES));
        let texture = p
            .texture
            .as_ref()
            .map(|t| CellTexture::new(t, salt::TEXTURE.map(|s| sub_seed(seed, s))));
        Ok(WoodVolume {
            inv_ring_width: 1.0 / p.rings.width,
            growth,
            growth_noise,
            growth_phase,
            interlock,
            distortion,
            rings,
            highlight,
            ring_tables: Arc::new(
                BeerColor::new(&p.color)
                    .ring_scales()
                    .map(|k| rings.exp_table(k)),
            ),
            color: BeerColor::new(&p.color),
            pores,
            rays,
            knots,
            wander,
            texture,
            eyes,
            params,
            seed,
            jacobian: JacobianModel::Simplified,
        })
    }

    /// The same volume with fibre directions and gradients transported by `jacobian`
    /// (a speed/accuracy switch measured by `xylem tradeoff`).
    pub fn with_jacobian(mut self, jacobian: JacobianModel) -> Self {
        self.jacobian = jacobian;
        self
    }

    /// The Jacobian model this volume transports with.
    pub fn jacobian_model(&self) -> JacobianModel {
        self.jacobian
    }

    /// The parameters this volume was built from.
    pub fn params(&self) -> &WoodParams {
        &self.params
    }

    /// The seed this volume was built with.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Growth time t(r) in years and dt/dr (eq. 23–24): t_pre = u + w(u) with u = r / ring width,
    /// then t = t_pre + n(t_pre). Monotone in r under the bounds checked by the parameters
    /// (notes/wood.md).
    #[inline]
    pub fn time(&self, r: f32) -> (f32, f32) {
        self.time_with::<true>(r)
    }

    /// [`WoodVolume::time`]; without `CHECKED` only where the growth wave's
    /// [`SmoothTriangleWave::in_fast_range`] holds.
    #[inline(always)]
    fn time_with<const CHECKED: bool>(&self, r: f32) -> (f32, f32) {
        let u = r * self.inv_ring_width;
        let (mut t, mut dt) = (u, self.inv_ring_width);
        if let Some(w) = &self.growth {
            // The wave read at the warped year v = u + a·m(u), dv/du = 1 + a·m′(u).
            let (v, dv) = match &self.growth_phase {
                Some(m) => {
                    let (mv, md) = m.eval(u);
                    (u + mv, 1.0 + md)
                }
                None => (u, 1.0),
            };
            let (wv, wd) = if CHECKED {
                w.eval(v)
            } else {
                w.eval_unchecked(v)
            };
            t += wv;
            dt *= 1.0 + wd * dv;
        }
        if let Some(n) = &self.growth_noise {
            let (nv, nd) = n.eval(t);
            t += nv;
            dt *= 1.0 + nd;
        }
        (t, dt)
    }

    /// The interlocked-grain helix angle (radians) at radius r (§6.1.5): 1D sparse convolution
    /// noise of r, within ±`angle`, reversing on average once per `period` (notes/wood.md §4).
    #[inline]
    pub fn interlock_angle(&self, r: f32) -> f32 {
        self.interlock.map_or(0.0, |n| n.eval(r).0)
    }

    /// The knot at tree-space point `p` (after distortion, as `eval` sees it): whether `p` is
    /// inside a knot or on its bark rim, the knot's radius there and the combined growth time;
    /// `None` without knots or far from every knot.
    pub fn knot_at(&self, p: Vec3) -> Option<KnotSample> {
        self.core(p, Needs::COLOR, 0.0).knot
    }

    /// The distortion f(p) with its Jacobian (§5, eq. 15 and 22).
    #[inline]
    pub fn distortion(&self, p: Vec3) -> Distortion {
        self.distort::<true>(p, 0.0)
    }

    /// f(p), with the Jacobian only when `JACOBIAN` (colour alone needs just the point); bands
    /// narrower than `footprint` mm are dropped (0: every band).
    #[inline]
    fn distort<const JACOBIAN: bool>(&self, p: Vec3, footprint: f32) -> Distortion {
        self.distort_eyes::<JACOBIAN>(p, footprint).0
    }

    /// [`WoodVolume::distort`] and the eyes' dark-centre weight (0 without eyes). The eyes'
    /// dimple is one more radial displacement, evaluated at p like the noise terms; with the
    /// exact Jacobian model it is left to the simplified transport (its gradient is small).
    #[inline]
    fn distort_eyes<const JACOBIAN: bool>(&self, p: Vec3, footprint: f32) -> (Distortion, f32) {
        let mut d = self.distort_noise::<JACOBIAN>(p, footprint);
        let mut core = 0.0;
        if let Some(eyes) = &self.eyes {
            let e = eyes.eval(p);
            if e.m != 0.0 || e.grad_m != Vec3::ZERO {
                d.add(Displacement {
                    dir: cylinder_frame(p).s,
                    m: e.m,
                    grad_m: e.grad_m,
                });
            }
            core = e.core;
        }
        (d, core)
    }

    #[inline]
    fn distort_noise<const JACOBIAN: bool>(&self, p: Vec3, footprint: f32) -> Distortion {
        let mut d = Distortion::identity(p);
        if self.distortion.iter().any(Option::is_some) {
            let frame = cylinder_frame(p);
            let exact = JACOBIAN && self.jacobian == JacobianModel::Exact;
            let mut terms = [(0.0, Vec3::ZERO); 3];
            for ((noise, dir), term) in self
                .distortion
                .iter()
                .zip([frame.s, frame.t, frame.n])
                .zip(&mut terms)
            {
                if let Some(noise) = noise {
                    let (m, grad_m) = if footprint > 0.0 {
                        noise.eval_bands::<JACOBIAN>(p, &frame, noise.bands_above(footprint))
                    } else {
                        noise.eval::<JACOBIAN>(p, &frame)
                    };
                    d.add(Displacement { dir, m, grad_m });
                    *term = (m, grad_m);
                }
            }
            if exact {
                d.jacobian = exact_jacobian(p, &frame, terms);
            }
        }
        d
    }

    #[inline]
    fn core(&self, p: Vec3, needs: Needs, footprint: f32) -> Core {
        self.core_with(p, needs.fibers || needs.bump, footprint)
    }

    /// [`WoodVolume::core`], with the distortion's Jacobian where `jacobian`.
    #[inline]
    fn core_with(&self, p: Vec3, jacobian: bool, footprint: f32) -> Core {
        let (dist, eye_core) = if jacobian {
            self.distort_eyes::<true>(p, footprint)
        } else {
            self.distort_eyes::<false>(p, footprint)
        };
        let q = dist.point;
        let r = (q.x * q.x + q.y * q.y).sqrt();
        let (trunk_time, dt_dr) = self.time(r);
        let mut time = trunk_time;
        // θ (an atan2) only where knots need it.
        let knot = self.knots.as_ref().and_then(|k| {
            let theta = Cylindrical::from_point(q).theta;
            k.eval(q, theta, r, time)
        });
        if let Some(k) = &knot {
            time = k.time;
        }
        Core {
            dist,
            r,
            time,
            trunk_time,
            dt_dr,
            knot,
            eye_core,
        }
    }

    /// The fibre frame at the distorted point q: the cylindrical frame rotated by the interlock
    /// angle (s = r̂, t = θ̂', n = longitudinal fibre).
    #[inline(always)]
    fn fiber_frame(&self, q: Vec3, r: f32) -> Frame {
        let frame = cylinder_frame(q);
        match &self.interlock {
            Some(_) => rotate_about_radial(&frame, self.interlock_angle(r)),
            None => frame,
        }
    }

    /// Evaluate the wood at tree-space point `p` (mm), computing only what `needs` asks for.
    pub fn eval(&self, p: Vec3, needs: Needs) -> WoodTexel {
        self.eval_filtered(p, needs, 0.0)
    }

    /// [`WoodVolume::eval`] band-limited by a pixel footprint `footprint` mm wide (tree space):
    /// distortion bands narrower than the footprint are dropped, pores and rays fade to their
    /// mean mask as the footprint grows from their width to twice it, and the cell texture fades
    /// to its zero mean the same way (none of them is evaluated beyond). A footprint below the smallest feature (or 0) gives exactly `eval`.
    /// The rings are box-filtered over the footprint too, on a surface of unknown orientation
    /// ([`Footprint::isotropic`]; [`WoodVolume::eval_footprint`] with the surface's normal blurs
    /// them only as much as that surface shows).
    pub fn eval_filtered(&self, p: Vec3, needs: Needs, footprint: f32) -> WoodTexel {
        self.eval_footprint(p, needs, Footprint::isotropic(footprint))
    }

    /// [`WoodVolume::eval_filtered`] over a footprint whose surface normal may be known. The
    /// growth rings, their colour and the highlight width they drive are box-filtered in closed
    /// form over the growth-time window the footprint spans (notes/wood.md §3a):
    /// w_t = width · |∇t − (∇t·n) n|, ∇t = dt/dr · Jᵀ r̂(f(p)) (the time gradient carried by eq. 18),
    /// the box whose variance is the square footprint's (a·u + b·v over a w × w square has
    /// variance (a² + b²) w²/12, a box of width w_t has w_t²/12).
    pub fn eval_footprint(&self, p: Vec3, needs: Needs, fp: Footprint) -> WoodTexel {
        let footprint = fp.width;
        let mut texel = WoodTexel::default();
        // The ring filter needs the time gradient through the distortion's Jacobian.
        let c = self.core_with(p, needs.fibers || needs.bump || footprint > 0.0, footprint);
        let q = c.dist.point;
        texel.growth_time = c.time;
        let ring_window = self.ring_window(&c, q, fp);
        // The ring value at the point (the pores here have its size) and its footprint means
        // of g, g², g³ (the filtered colour's ring value; the mean pore volume's cubic).
        let g_point = self.rings.eval(c.time);
        let moments = match ring_window {
            Some(ends) => ring_pieces_mean(&ends, |a, b| self.rings.box_moments(a, b)),
            None => Vec3::new(g_point, g_point * g_point, g_point * g_point * g_point),
        };
        let g = moments.x;
        let want_pores = self.pores.is_some() && (needs.color || needs.bump);
        let want_rays = self.rays.is_some() && (needs.fibers || self.color_uses_rays());
        let frame = if want_pores || needs.fibers {
            self.fiber_frame(q, c.r)
        } else {
            Frame {
                s: Vec3::X,
                t: Vec3::Y,
                n: Vec3::Z,
            }
        };
        if want_pores {
            let pores = self.pores.as_ref().expect("checked");
            let w = footprint_weight(pores.diameter, footprint);
            let (mut mask, mut grad) = if w <= 0.0 {
                (0.0, Vec3::ZERO)
            } else if needs.bump {
                pores.mask::<true>(q, &frame, g_point)
            } else {
                pores.mask::<false>(q, &frame, g_point)
            };
            if w < 1.0 {
                // Linear filtering: the pore detail fades to its mean (which has no gradient).
                mask = w * mask + (1.0 - w) * pores.mean_mask_over(moments);
                grad *= w;
            }
            texel.pore_mask = mask;
            if needs.bump {
                // §6.1.7: height = −depth · mask; its gradient transported covariantly (eq. 18).
                texel.bump = -pores.depth * mask;
                texel.bump_grad = c.dist.gradient(grad * -pores.depth);
            }
        }
        if want_rays {
            let rays = self.rays.as_ref().expect("checked");
            // A ray is a sheet `width` thick with normal θ̂: a face with normal n cuts it in a
            // trace width / |θ̂ × n| wide (at most the sheet's other extents), so on a
            // quartersawn face (n ≈ θ̂) the fleck is broad and stays; on a flat-sawn face it is a
            // thin line that fades like a pore. Unknown face: the width itself.
            let trace = if fp.normal == Vec3::ZERO {
                rays.width
            } else {
                let theta = Vec3::new(-q.y, q.x, 0.0).normalize_or_zero();
                let sin = (1.0 - theta.dot(fp.normal).powi(2)).max(0.0).sqrt();
                (rays.width / sin.max(1e-6))
                    .min(rays.trace_limit)
                    .max(rays.width)
            };
            let w = footprint_weight(trace, footprint);
            texel.ray_mask = if w >= 1.0 {
                rays.mask(q)
            } else if w <= 0.0 {
                rays.mean_mask
            } else {
                w * rays.mask(q) + (1.0 - w) * rays.mean_mask
            };
        }
        if needs.color {
            let mut extra = match (&c.knot, &self.knots) {
                (Some(k), Some(kn)) => kn.darkening * (k.inside + 3.0 * k.bark),
                _ => 0.0,
            };
            if let Some(eyes) = &self.eyes {
                extra += eyes.darkening * c.eye_core;
            }
            if let Some(t) = &self.texture {
                extra += t.path(q, footprint);
            }
            let filtered = ring_window.and_then(|ends| {
                self.color
                    .ring_filtered_colors(texel.pore_mask, texel.ray_mask, extra, |k| {
                        let table = &self.ring_tables[k];
                        ring_pieces_mean(&ends, |a, b| self.rings.box_exp_mean(a, b, table))
                    })
            });
            let (diffuse, fiber) = filtered.unwrap_or_else(|| {
                let a = self
                    .color
                    .absorbance(g, texel.pore_mask, texel.ray_mask, extra);
                self.color.colors(a)
            });
            texel.diffuse = diffuse;
            texel.fiber_color = fiber;
        }
        if needs.fibers {
            self.fibers_into(&mut texel, &c, &frame, fp, g, g_point);
        }
        texel
    }

    /// The fibre and ray directions and the highlight width of `texel` at the core `c` (fibre
    /// frame `frame`, ring value g filtered and `g_point` at the point), band-limited by `fp`.
    fn fibers_into(
        &self,
        texel: &mut WoodTexel,
        c: &Core,
        frame: &Frame,
        fp: Footprint,
        g: f32,
        g_point: f32,
    ) {
        let (q, footprint) = (c.dist.point, fp.width);
        let mut fiber = frame.n;
        // The fibres' dip out of the face that the footprint averages (rad²).
        let mut unresolved_dip = 0.0;
        if let Some(w) = &self.wander {
            (fiber, unresolved_dip) = w.band_limited(q, frame, footprint, fp.normal);
            if let Some(pores) = self.pores.as_ref().filter(|_| w.pore_deflection > 0.0) {
                let fade = footprint_weight(pores.diameter, footprint);
                if fade > 0.0 {
                    let (_, grad) = pores.mask::<true>(q, frame, g_point);
                    fiber = w.around_pore(fiber, frame.n, fade * grad, 0.5 * pores.diameter);
                }
            }
        }
        if let (Some(k), Some(knots)) = (&c.knot, &self.knots) {
            fiber = knots.deflect_fiber(fiber, k);
        }
        // §5.2 eq. 17: directions looked up at f(p) are transported by J⁻¹.
        let inv = c.dist.inverse_jacobian();
        texel.fiber_dir = normalize_or(inv * fiber, Vec3::Z);
        texel.ray_dir = normalize_or(inv * frame.s, Vec3::X);
        // The highlight width is the ring wave between two levels: the same filtered mean,
        // widened by the dip the footprint leaves unresolved: a tilt a moves ψi + ψr by ≈ 2a
        // (both interior directions near the normal), so g(β, ψi + ψr) averaged over
        // a ~ N(0, σ²) is g(√(β² + 4σ²), ·) (notes/wood.md §9e).
        let beta = self.highlight.level(g);
        texel.highlight_width = if unresolved_dip > 0.0 {
            (beta * beta + 4.0 * unresolved_dip).sqrt()
        } else {
            beta
        };
    }

    /// The sizes (tree mm) of the features [`WoodVolume::eval_footprint`] fades to their means:
    /// each is evaluated in full under a footprint of its size, fades linearly to its mean as the
    /// footprint grows to twice it, and is not evaluated at all beyond (`footprint_weight`).
    /// Pores by their diameter, rays by the widest trace a face can cut through their sheet (the
    /// quartersawn fleck, `trace_limit`: the conservative size when the face is not known), each
    /// scale of the cell texture by twice its across-grain correlation length.
    pub fn fading_features(&self) -> Vec<(&'static str, f32)> {
        let mut v = Vec::new();
        if let Some(p) = &self.pores {
            v.push(("pores", p.diameter));
        }
        if let Some(r) = &self.rays {
            v.push(("rays", r.trace_limit.max(r.width)));
        }
        if let Some(t) = &self.texture {
            for (i, across) in t.widths().enumerate() {
                v.push((["cell texture", "texture streaks"][i.min(1)], 2.0 * across));
            }
        }
        if let Some(w) = &self.params.fibre_wander {
            // Faded into the highlight's width rather than dropped (FibreWander::band_limited);
            // the size is half the footprint from which it is not evaluated.
            v.push(("fibre wander", 0.5 * FibreWander::skipped_from(&w.coarse())));
            if let Some(f) = &w.fine {
                v.push(("fine fibre wander", 0.5 * FibreWander::skipped_from(f)));
            }
        }
        v
    }

    /// The growth times t(r + Δ (i/N − ½)), i = 0…N (N = [`RING_PIECES`]), across the radial
    /// extent Δ = width · |Jᵀ r̂ − ((Jᵀ r̂)·n) n| of the footprint (Jᵀ r̂ the gradient of the
    /// distorted radius, eq. 18, projected into the surface where its normal n is known), or
    /// `None` where the footprint spans less time than the ring wave's
    /// [`SmoothRectangleWave::min_box`] (point-sampled rings). The rings are box-filtered over
    /// each piece: t(r) is read along the extent rather than extrapolated from dt/dr, since the
    /// growth noise bends it within a ring (notes/wood.md §3a). Near knots the trunk's times are
    /// shifted by the knot's.
    fn ring_window(&self, c: &Core, q: Vec3, fp: Footprint) -> Option<[f32; RING_PIECES + 1]> {
        if !(fp.width > 0.0) {
            return None;
        }
        let r_hat = Vec3::new(q.x, q.y, 0.0).normalize_or_zero();
        let grad = c.dist.gradient(r_hat);
        let extent = fp.width * (grad - fp.normal * grad.dot(fp.normal)).length();
        if !(extent * c.dt_dr >= self.rings.min_box()) {
            return None;
        }
        let shift = c.time - c.trunk_time;
        let mut ends = [0.0; RING_PIECES + 1];
        for (i, t) in ends.iter_mut().enumerate() {
            let r = c.r + extent * (i as f32 / RING_PIECES as f32 - 0.5);
            // Across the pith: from the pith.
            *t = if 2 * i == RING_PIECES {
                c.time
            } else {
                self.time(r.max(0.0)).0 + shift
            };
        }
        Some(ends)
    }

    /// [`WoodVolume::eval`] at every point of `points` into `out` (same length): the same texels,
    /// bit for bit. Colour alone (`Needs::COLOR`, no knots: what flat texture slices and colour
    /// previews ask for) runs in blocks of `BATCH` points, stage by stage: the noise lookups
    /// (distortion, pores, rays) point by point, everything between them (frames, growth time,
    /// rings, interlock, Beer's law) in SIMD lanes. Anything else, and a last partial block, goes
    /// point by point.
    pub fn eval_many(&self, points: &[Vec3], needs: Needs, out: &mut [WoodTexel]) {
        self.eval_many_on(Simd::best(), points, needs, out);
    }

    /// [`WoodVolume::eval_many`] with the lane stages compiled for `simd` (which the CPU must
    /// have; tests run every level).
    #[doc(hidden)]
    pub fn eval_many_on(&self, simd: Simd, points: &[Vec3], needs: Needs, out: &mut [WoodTexel]) {
        assert_eq!(points.len(), out.len(), "eval_many: one texel per point");
        assert!(simd <= Simd::best(), "{simd:?} not available");
        let mut done = 0;
        if needs == Needs::COLOR && self.knots.is_none() && self.eyes.is_none() {
            for (p, o) in points.chunks_exact(BATCH).zip(out.chunks_exact_mut(BATCH)) {
                let p: &[Vec3; BATCH] = p.try_into().expect("a whole block");
                let o: &mut [WoodTexel; BATCH] = o.try_into().expect("a whole block");
                if !self.color_block_on(simd, p, o) {
                    for (o, &p) in o.iter_mut().zip(p) {
                        *o = self.eval(p, needs);
                    }
                }
                done += BATCH;
            }
        }
        for (o, &p) in out[done..].iter_mut().zip(&points[done..]) {
            *o = self.eval(p, needs);
        }
    }

    /// [`WoodVolume::color_block`] compiled for `simd`.
    #[inline]
    fn color_block_on(&self, simd: Simd, p: &[Vec3; BATCH], out: &mut [WoodTexel; BATCH]) -> bool {
        #[cfg(target_arch = "x86_64")]
        match simd {
            // SAFETY: the caller checked `simd <= Simd::best()`, which detected its features.
            Simd::Avx512 => return unsafe { self.color_block_avx512(p, out) },
            Simd::Avx2 => return unsafe { self.color_block_avx2(p, out) },
            _ => {}
        }
        let _ = simd;
        self.color_block(p, out)
    }

    simd_level! { Avx512
        unsafe fn color_block_avx512(
            &self,
            p: &[Vec3; BATCH],
            out: &mut [WoodTexel; BATCH],
        ) -> bool {
            self.color_block(p, out)
        }
    }

    simd_level! { Avx2
        unsafe fn color_block_avx2(&self, p: &[Vec3; BATCH], out: &mut [WoodTexel; BATCH]) -> bool {
            self.color_block(p, out)
        }
    }

    /// One block of colour-only texels (see [`WoodVolume::eval_many`]): the operations of
    /// [`WoodVolume::eval_filtered`] with footprint 0, in its order, so the same bits. The lane
    /// stages hold one array per coordinate and loop with no call and no data-dependent branch,
    /// which the compiler vectorises. `false` (nothing written) where a point lies beyond the
    /// growth wave's fast range: the caller then evaluates the block point by point.
    #[inline(always)]
    fn color_block(&self, p: &[Vec3; BATCH], out: &mut [WoodTexel; BATCH]) -> bool {
        type Lanes = [f32; BATCH];
        let (mut qx, mut qy, mut qz): (Lanes, Lanes, Lanes) =
            ([0.0; BATCH], [0.0; BATCH], [0.0; BATCH]);
        for i in 0..BATCH {
            (qx[i], qy[i], qz[i]) = (p[i].x, p[i].y, p[i].z);
        }
        // f(p) (`Distortion::add`'s point update q += m a, in its order r̂, θ̂, ẑ): the magnitudes
        // point by point, frames and sums in lanes.
        if self.distortion.iter().any(Option::is_some) {
            let (mut c, mut s) = ([0.0; BATCH], [0.0; BATCH]);
            for i in 0..BATCH {
                (c[i], s[i]) = cylinder_cos_sin(p[i].x, p[i].y);
            }
            for (axis, noise) in self.distortion.iter().enumerate() {
                let Some(noise) = noise else { continue };
                let mut frames = [cylinder_frame_from(1.0, 0.0); BATCH];
                for i in 0..BATCH {
                    frames[i] = cylinder_frame_from(c[i], s[i]);
                }
                let m = noise.eval_many(p, &frames);
                for i in 0..BATCH {
                    // a = r̂ = (c, s, 0), θ̂ = (−s, c, 0) or ẑ = (0, 0, 1).
                    let (ax, ay, az) = match axis {
                        0 => (c[i], s[i], 0.0),
                        1 => (-s[i], c[i], 0.0),
                        _ => (0.0, 0.0, 1.0),
                    };
                    qx[i] += m[i] * ax;
                    qy[i] += m[i] * ay;
                    qz[i] += m[i] * az;
                }
            }
        }
        // Growth time and rings in lanes.
        let mut r: Lanes = [0.0; BATCH];
        for i in 0..BATCH {
            r[i] = (qx[i] * qx[i] + qy[i] * qy[i]).sqrt();
        }
        if let Some(w) = &self.growth {
            let mut ok = true;
            for &r in &r {
                let shift = self.growth_phase.map_or(0.0, |m| m.amp);
                ok &= w.in_fast_range((r * self.inv_ring_width).abs() + shift);
            }
            if !ok {
                return false;
            }
        }
        let (mut time, mut g): (Lanes, Lanes) = ([0.0; BATCH], [0.0; BATCH]);
        for i in 0..BATCH {
            time[i] = self.time_with::<false>(r[i]).0;
        }
        for i in 0..BATCH {
            g[i] = self.rings.eval(time[i]);
        }
        // Pores: the fibre frame in lanes, the noise point by point.
        let mut pore: Lanes = [0.0; BATCH];
        if let Some(pores) = &self.pores {
            let (mut c, mut s) = ([0.0; BATCH], [0.0; BATCH]);
            for i in 0..BATCH {
                (c[i], s[i]) = cylinder_cos_sin(qx[i], qy[i]);
            }
            let (mut sin, mut cos) = ([0.0; BATCH], [1.0; BATCH]);
            if let Some(n) = &self.interlock {
                for i in 0..BATCH {
                    (sin[i], cos[i]) = crate::math::elementary::sin_cos(n.eval(r[i]).0);
                }
            }
            let mut frames = [cylinder_frame_from(1.0, 0.0); BATCH];
            let mut q = [Vec3::ZERO; BATCH];
            for i in 0..BATCH {
                let frame = cylinder_frame_from(c[i], s[i]);
                frames[i] = if self.interlock.is_some() {
                    rotate_by(&frame, sin[i], cos[i])
                } else {
                    frame
                };
                q[i] = Vec3::new(qx[i], qy[i], qz[i]);
            }
            pore = pores.mask_many(&q, &frames, &g);
        }
        let mut ray: Lanes = [0.0; BATCH];
        if let Some(rays) = self.rays.as_ref().filter(|_| self.color_uses_rays()) {
            for i in 0..BATCH {
                ray[i] = rays.mask(Vec3::new(qx[i], qy[i], qz[i]));
            }
        }
        let mut texture: Lanes = [0.0; BATCH];
        if let Some(t) = &self.texture {
            for i in 0..BATCH {
                texture[i] = t.path(Vec3::new(qx[i], qy[i], qz[i]), 0.0);
            }
        }
        // Beer's law in lanes, a channel at a time.
        let mut diffuse = [[0.0f32; BATCH]; 3];
        let mut fiber = [[0.0f32; BATCH]; 3];
        for ch in 0..3 {
            for i in 0..BATCH {
                let a = self
                    .color
                    .channel_absorbance(ch, g[i], pore[i], ray[i], texture[i]);
                (diffuse[ch][i], fiber[ch][i]) = self.color.channel_colors(ch, a);
            }
        }
        for i in 0..BATCH {
            out[i] = WoodTexel {
                diffuse: Vec3::new(diffuse[0][i], diffuse[1][i], diffuse[2][i]),
                fiber_color: Vec3::new(fiber[0][i], fiber[1][i], fiber[2][i]),
                pore_mask: pore[i],
                ray_mask: ray[i],
                growth_time: time[i],
                ..WoodTexel::default()
            };
        }
        true
    }

    /// Whether rays change the colour (a non-zero ray path length).
    #[inline]
    fn color_uses_rays(&self) -> bool {
        self.params.color.ray_path != 0.0
    }
}

#[inline]
fn normalize_or(v: Vec3, fallback: Vec3) -> Vec3 {
    let len2 = v.length_squared();
    if len2 > 1e-20 && len2.is_finite() {
        v / len2.sqrt()
    } else {
        fallback
    }
}
