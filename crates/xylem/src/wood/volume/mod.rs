//! `WoodVolume`: the solid-wood model of Liu et al. 2016 §6 assembled from its parts, evaluated
//! lazily: `eval(p, needs)` computes only what `needs` asks for and what the parameters switch on.

use super::color::BeerColor;
use super::error::WoodError;
use super::eyes::Eyes;
use super::features::{
    clamped_shot_noise_exp_means, footprint_weight, sub_seed, CellTexture, DistortionNoise,
    FibreWander, Noise1, Pores, Rays,
};
use super::growth::{RingExpTable, SmoothRectangleWave, SmoothTriangleWave};
use super::knots::{KnotSample, Knots};
use super::params::{DistortionParams, WoodParams};
use super::{Needs, WoodTexel};
use crate::field::{
    cylinder_cos_sin, cylinder_frame, cylinder_frame_from, exact_jacobian, rotate_about_radial,
    rotate_by, Cylindrical, Displacement, Distortion, JacobianModel,
};
use crate::math::Frame;
use crate::noise::SparseConvolution1;
use crate::simd::{simd_wide, Simd};
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
    /// Beer's law averaged over the pore and ray masks (footprint filter).
    mask_means: MaskColorMeans,
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

mod batch;
mod footprint;

pub use footprint::Footprint;
use footprint::MaskColorMeans;

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
        let (growth_noise, growth_phase, interlock) = one_dimensional_noises(p, seed);
        let max_tilt = interlock.map_or(0.0, |i| i.amp);
        let distortion = distortion_noises(&p.distortion, seed);
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
            mask_means: MaskColorMeans::new(p, &BeerColor::new(&p.color)),
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

/// The growth-rate noise, the growth wave's phase warp and the interlock's helix angle, each a
/// 1D noise with its own seed (absent where its amplitude is 0).
fn one_dimensional_noises(
    p: &WoodParams,
    seed: u64,
) -> (Option<Noise1>, Option<Noise1>, Option<Noise1>) {
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
    (growth_noise, growth_phase, interlock)
}

/// The distortion noises along r̂, θ̂, ẑ (absent where their magnitude is 0).
fn distortion_noises(d: &DistortionParams, seed: u64) -> [Option<DistortionNoise>; 3] {
    let noises = [&d.radial, &d.tangential, &d.longitudinal];
    std::array::from_fn(|i| {
        noises[i]
            .as_ref()
            .filter(|n| n.magnitude > 0.0)
            .map(|n| DistortionNoise::new(n, sub_seed(seed, salt::DISTORT[i])))
    })
}
