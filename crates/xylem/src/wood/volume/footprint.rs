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

/// Beer's law averaged over the pore and ray masks a footprint cannot resolve (notes/wood.md
/// §3b): the colour is exp(−a − c_p m_p − c_r m_r) with the masks' fields independent of each
/// other and of the rings at a given ring value, so its mean over the masks is exp(−a) times
/// E[exp(−c_p m_p)] times E[exp(−c_r m_r)] ([`clamped_shot_noise_exp_means`]), not the colour
/// of the mean masks (exp is convex: red oak's earlywood pores 7 % too dark in green).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct MaskColorMeans {
    /// Per colour (diffuse, fibre), E[exp(−c_p m_p)] as a cubic in the ring value s, the
    /// coefficients of 1, s, s², s³: ring porosity scales the pores' overlap by
    /// (1 − ρ s)³, the cubic interpolates the exact means at s = 0, ⅓, ⅔, 1 (Newton's forward
    /// differences), so a footprint's mean over its ring values follows from the moments
    /// E[s], E[s²], E[s³] as the mean mask does ([`Pores::mean_mask_over`]).
    pore: [[Vec3; 4]; 2],
    /// Per colour, E[exp(−c_r m_r)] (the rays do not depend on the ring value).
    ray: [Vec3; 2],
    /// Per colour, c_p and c_r: the absorbance of a full mask ([`BeerColor::mask_scales`]).
    scales: [[Vec3; 2]; 2],
}

impl MaskColorMeans {
    /// The means for `params`' pores and rays under `color`.
    pub(crate) fn new(params: &WoodParams, color: &BeerColor) -> Self {
        let scales = color.mask_scales();
        let mut pore = [[Vec3::ONE, Vec3::ZERO, Vec3::ZERO, Vec3::ZERO]; 2];
        if let Some(p) = &params.pores {
            let at = |s: f32| {
                let size = (1.0 - p.ring_porosity * s).clamp(0.0, 1.0);
                let overlap = if size <= 1e-3 {
                    0.0
                } else {
                    p.density * size.powi(3)
                };
                clamped_shot_noise_exp_means(p.sharpness, overlap, &scales[0])
            };
            let h: Vec<Vec<Vec3>> = [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0].map(at).to_vec();
            for (k, coeffs) in pore.iter_mut().enumerate() {
                let (h0, h1, h2, h3) = (h[0][k], h[1][k], h[2][k], h[3][k]);
                // Newton's forward form in x = 3 s: h0 + Δ₁x + Δ₂ x(x − 1)/2 + Δ₃ x(x − 1)(x − 2)/6.
                let d1 = h1 - h0;
                let d2 = h2 - 2.0 * h1 + h0;
                let d3 = h3 - 3.0 * h2 + 3.0 * h1 - h0;
                *coeffs = [
                    h0,
                    3.0 * (d1 - 0.5 * d2 + d3 / 3.0),
                    9.0 * (0.5 * d2 - 0.5 * d3),
                    27.0 * (d3 / 6.0),
                ];
            }
        }
        let mut ray = [Vec3::ONE; 2];
        if let Some(r) = params.rays.as_ref().filter(|r| r.strength > 0.0) {
            let c = scales[1].map(|c| c * r.strength);
            let m = clamped_shot_noise_exp_means(r.sharpness, r.density, &c);
            ray = [m[0], m[1]];
        }
        MaskColorMeans { pore, ray, scales }
    }

    /// The most a pore and a ray together can lower the diffuse absorbance (≥ 0 per channel):
    /// a negative path (rays lighter than the fibres) lightens.
    fn lightening(&self) -> Vec3 {
        -(self.scales[0][0].min(Vec3::ZERO) + self.scales[1][0].min(Vec3::ZERO))
    }

    /// E[exp(−c_p m_p)] for colour `k` over ring values with moments (E[s], E[s²], E[s³]).
    #[inline]
    fn pore_mean(&self, k: usize, moments: Vec3) -> Vec3 {
        let [a, b, c, d] = self.pore[k];
        a + b * moments.x + c * moments.y + d * moments.z
    }
}

/// A mask faded by the footprint: its weight w ([`footprint_weight`]) and its value at the point
/// (the faded mask is w · point + (1 − w) · mean).
#[derive(Clone, Copy, Debug)]
struct Fade {
    w: f32,
    point: f32,
}

impl Fade {
    const NONE: Fade = Fade { w: 1.0, point: 0.0 };
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
        let (mut pore_fade, mut ray_fade) = (Fade::NONE, Fade::NONE);
        if want_pores {
            pore_fade = self.pores_into(&mut texel, &c, &frame, needs, fp.width, g_point, moments);
        }
        if want_rays {
            let faded;
            (faded, ray_fade) = self.ray_mask(q, fp);
            texel.ray_mask = faded;
        }
        if needs.color {
            let fades = [pore_fade, ray_fade];
            self.colors_into(&mut texel, &c, ring_window, moments, fp.width, fades);
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
    /// footprint's ring `moments` as the footprint outgrows the pores; returns the fade.
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
    ) -> Fade {
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
        let fade = Fade { w, point: mask };
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
        fade
    }

    /// The ray mask at `q`, faded to its mean as the footprint outgrows the trace the face cuts,
    /// and the fade.
    fn ray_mask(&self, q: Vec3, fp: Footprint) -> (f32, Fade) {
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
            let m = rays.mask(q);
            (m, Fade { w, point: m })
        } else if w <= 0.0 {
            (rays.mean_mask, Fade { w, point: 0.0 })
        } else {
            let m = rays.mask(q);
            (w * m + (1.0 - w) * rays.mean_mask, Fade { w, point: m })
        }
    }

    /// The diffuse and fibre colours of `texel` (Beer's law over the ring moments' value, or over
    /// the footprint's ring window in closed form), its pore and ray masks already set. Where
    /// the footprint fades the pores or rays (`fades`), the colour fades to the mean colour over
    /// the masks ([`MaskColorMeans`]), not to the colour of the mean masks.
    fn colors_into(
        &self,
        texel: &mut WoodTexel,
        c: &Core,
        ring_window: Option<[f32; RING_PIECES + 1]>,
        moments: Vec3,
        footprint: f32,
        fades: [Fade; 2],
    ) {
        let g = moments.x;
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
        if fades.iter().any(|f| f.w < 1.0) {
            if let Some(colors) = self.faded_colors(ring_window, moments, extra, fades) {
                (texel.diffuse, texel.fiber_color) = colors;
                return;
            }
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

    /// (diffuse, fibre) colours with the pores and rays faded as `fades` says: per colour,
    /// exp(−a) · F_p · F_r with F = w · exp(−c · point) + (1 − w) · E[exp(−c m)] for each mask
    /// (the linear fade of the colour, whose w = 0 end is the footprint's mean colour), a the
    /// absorbance of the rings and `extra`. Over a ring window the pores' mean goes with each
    /// piece's ring values (exp(−k s) and the pores' size both follow s): the mean over the
    /// pieces of E[exp(−k s)] · E[F_p] per piece, exact where a piece lies on a plateau.
    /// `None` where the clamp at zero absorbance could act (a negative pore or ray path where
    /// the wood is light): Beer's law is then not the product of the masks' factors.
    fn faded_colors(
        &self,
        ring_window: Option<[f32; RING_PIECES + 1]>,
        moments: Vec3,
        extra: f32,
        [pore, ray]: [Fade; 2],
    ) -> Option<(Vec3, Vec3)> {
        let means = &self.mask_means;
        let mut out = [Vec3::ZERO; 2];
        let a0 = self.color.absorbance(0.0, 0.0, 0.0, extra);
        let ring = self.color.ring_scales();
        let least = a0 - means.lightening();
        if least.min_element() < 0.0 || (least + ring[0]).min_element() < 0.0 {
            return None;
        }
        let saturation = [Vec3::ONE, self.color.fiber_saturation()];
        for (k, out) in out.iter_mut().enumerate() {
            let [c_p, c_r] = [means.scales[0][k], means.scales[1][k]];
            let f_r = ray.w * (-c_r * ray.point).exp() + (1.0 - ray.w) * means.ray[k];
            let point = (-c_p * pore.point).exp();
            let rings_and_pores = match ring_window {
                Some(ends) => {
                    let table = &self.ring_tables[k];
                    let (mut at_point, mut mean) = (Vec3::ZERO, Vec3::ZERO);
                    for w in ends.windows(2) {
                        let e = self.rings.box_exp_mean(w[0], w[1], table);
                        at_point += e;
                        if pore.w < 1.0 {
                            mean += e * means.pore_mean(k, self.rings.box_moments(w[0], w[1]));
                        }
                    }
                    let n = 1.0 / RING_PIECES as f32;
                    pore.w * point * at_point * n + (1.0 - pore.w) * mean * n
                }
                None => {
                    let e = (-ring[k] * moments.x).exp();
                    e * (pore.w * point + (1.0 - pore.w) * means.pore_mean(k, moments))
                }
            };
            *out = (-a0 * saturation[k]).exp() * f_r * rings_and_pores;
        }
        Some((out[0], out[1]))
    }
}
