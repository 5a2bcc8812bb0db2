//! The wood band-limited by a pixel footprint: rings box-filtered in closed form, pores, rays
//! and texture faded to their means, fibre wander folded into the highlight width.

use super::*;

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

impl WoodVolume {
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
            self.pores_into(&mut texel, &c, &frame, needs, fp.width, g_point, moments);
        }
        if want_rays {
            texel.ray_mask = self.ray_mask(q, fp);
        }
        if needs.color {
            self.colors_into(&mut texel, &c, ring_window, g, fp.width);
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
    pub(super) fn ring_window(
        &self,
        c: &Core,
        q: Vec3,
        fp: Footprint,
    ) -> Option<[f32; RING_PIECES + 1]> {
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

    /// The pore mask of `texel` (and its bump where `needs` asks), faded to the mean over the
    /// footprint's ring `moments` as the footprint outgrows the pores.
    #[allow(clippy::too_many_arguments)]
    fn pores_into(
        &self,
        texel: &mut WoodTexel,
        c: &Core,
        frame: &Frame,
        needs: Needs,
        footprint: f32,
        g_point: f32,
        moments: Vec3,
    ) {
        let q = c.dist.point;
        let pores = self.pores.as_ref().expect("checked");
        let w = footprint_weight(pores.diameter, footprint);
        let (mut mask, mut grad) = if w <= 0.0 {
            (0.0, Vec3::ZERO)
        } else if needs.bump {
            pores.mask::<true>(q, frame, g_point)
        } else {
            pores.mask::<false>(q, frame, g_point)
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

    /// The ray mask at `q`, faded to its mean as the footprint outgrows the trace the face cuts.
    fn ray_mask(&self, q: Vec3, fp: Footprint) -> f32 {
        let footprint = fp.width;
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
        if w >= 1.0 {
            rays.mask(q)
        } else if w <= 0.0 {
            rays.mean_mask
        } else {
            w * rays.mask(q) + (1.0 - w) * rays.mean_mask
        }
    }

    /// The diffuse and fibre colours of `texel` (Beer's law over the ring value `g`, or over
    /// the footprint's ring window in closed form), its pore and ray masks already set.
    fn colors_into(
        &self,
        texel: &mut WoodTexel,
        c: &Core,
        ring_window: Option<[f32; RING_PIECES + 1]>,
        g: f32,
        footprint: f32,
    ) {
        let q = c.dist.point;
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
}
