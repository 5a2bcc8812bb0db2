//! The noise-driven parts of the model, each built once from its parameters: distortion
//! magnitudes (§6.2), pores and rays (§6.1.6), growth-rate noise (eq. 24) and the interlock angle
//! (§6.1.5). All noise comes from `crate::noise`.

use super::params::{
    FibreWanderParams, NoiseParams, PoreParams, RayParams, TextureParams, WanderScale,
};
use crate::math::Frame;
use crate::noise::{Cells, Kernel, SeededSparse, SparseConvolution, SparseConvolution1, Weights};
use glam::Vec3;

/// Cell size in units of the kernel's (fitted) semi-axes: cells as large as the kernel's diameter
/// mean each query visits 2 cells per axis (8 in all) instead of 3 (27), holding more impulses
/// each; measured faster for every preset (notes/wood.md).
const CELL_SCALE: f32 = 1.0;
const RAY_ARC_CELLS: f32 = 2.0;

/// A sub-seed for one noise field from the volume seed and a salt.
pub(crate) fn sub_seed(seed: u64, salt: u32) -> u32 {
    use crate::noise::hash::mix32;
    mix32(mix32(seed as u32 ^ salt) ^ mix32((seed >> 32) as u32).wrapping_add(salt))
}

/// A distortion magnitude: multiband sparse convolution noise with the Wyvill kernel and signed
/// weights (zero mean), envelope `[r, θ, z]` oriented by the cylindrical frame at the query (§4.5).
/// Cartesian cells as wide as the larger of the r and θ semi-axes fit the kernel at any rotation
/// about ẑ, so the eq. 11 shrink never applies.
#[derive(Clone, Debug)]
pub(crate) struct DistortionNoise {
    noise: SeededSparse,
}

impl DistortionNoise {
    pub fn new(p: &NoiseParams, seed: u32) -> Self {
        let env = Vec3::from(p.size);
        let xy = env.x.max(env.y);
        DistortionNoise {
            noise: SeededSparse::new(
                SparseConvolution {
                    kernel: Kernel::Wyvill,
                    density: p.density,
                    envelope: env,
                    cell: CELL_SCALE * Vec3::new(xy, xy, env.z),
                    magnitude: p.magnitude,
                    weights: Weights::Signed,
                    cells: Cells::Cartesian,
                    bands: p.bands,
                    size_factor: p.size_factor,
                    dropoff: p.dropoff,
                },
                seed,
            ),
        }
    }

    /// (m, ∇m) at `p`, kernels aligned with the cylindrical frame `cyl` at `p`; without `GRAD`
    /// the gradient is zero (enough for the lookup point f(p)).
    #[inline]
    pub fn eval<const GRAD: bool>(&self, p: Vec3, cyl: &Frame) -> (f32, Vec3) {
        self.eval_bands::<GRAD>(p, cyl, self.noise.noise().bands)
    }

    /// [`DistortionNoise::eval`]'s value at `N` points with their cylindrical frames (the query
    /// set-up in lanes, [`SeededSparse::eval_oriented_many`]).
    #[inline(always)]
    pub fn eval_many<const N: usize>(&self, p: &[Vec3; N], cyl: &[Frame; N]) -> [f32; N] {
        match self.noise.noise().bands {
            0 => [0.0; N],
            bands => self
                .noise
                .eval_oriented_many(p, cyl, bands as usize, &[1.0; N]),
        }
    }

    /// How many bands (from the largest) have kernels at least `footprint` mm across: band i has
    /// semi-axes βⁱ Sₑ (Liu 2016 eq. 8), so its narrowest diameter is 2 βⁱ min(Sₑ).
    #[inline]
    pub(crate) fn bands_above(&self, footprint: f32) -> u32 {
        let noise = self.noise.noise();
        let mut d = 2.0 * noise.envelope.min_element();
        let mut n = 0;
        while n < noise.bands && d >= footprint {
            n += 1;
            d *= noise.size_factor;
        }
        n
    }

    /// [`DistortionNoise::eval`] with only the first `bands` bands (the finer ones dropped: their
    /// mean is zero, signed weights); all bands give exactly `eval`.
    #[inline]
    pub(crate) fn eval_bands<const GRAD: bool>(
        &self,
        p: Vec3,
        cyl: &Frame,
        bands: u32,
    ) -> (f32, Vec3) {
        if bands == 0 {
            return (0.0, Vec3::ZERO);
        }
        self.noise
            .eval_oriented_with::<GRAD>(p, cyl, bands as usize, 1.0)
    }
}

/// 3∫₀¹ r² K(r²) dr for the bump kernel K(q) = exp(−s q/(1 − q)) (Liu 2016 eq. 6): the mean of
/// the kernel over its unit ball. With unit weights and on average `density` kernels overlapping
/// a point (λ V = density), the mean of the summed mask is density × this (Campbell's theorem,
/// notes/sweep.md "Footprint"). 512-point midpoint rule.
pub(crate) fn bump_kernel_mean(sharpness: f32) -> f32 {
    let n = 512;
    let mut sum = 0.0f64;
    for i in 0..n {
        let r = (i as f64 + 0.5) / n as f64;
        let q = r * r;
        sum += r * r * (-(sharpness as f64) * q / (1.0 - q)).exp();
    }
    (3.0 * sum / n as f64) as f32
}

/// E[exp(−c · min(1, S))] for each c of `scales`, where S is the unit-weight shot noise of bump
/// kernels (sharpness `sharpness`) with on average `overlap` kernels covering a point: what
/// Beer's law makes of a pore or ray mask over a footprint that cannot resolve it (the colour is
/// convex in the mask, so the colour of the mean mask, exp(−c E[min(1, S)]), is too dark;
/// notes/wood.md §3b). The kernels' centres are a Poisson process, so S is compound Poisson: a
/// Poisson(`overlap`) count of values Y = K(‖u‖²), u uniform in the unit ball (Campbell's
/// theorem; Daley & Vere-Jones 2003, "An Introduction to the Theory of Point Processes" I, §6.1),
/// whose tail P(Y ≥ y) = q^{3/2} with q = L/(s + L), L = −ln y (the kernel K(q) = exp(−s q/(1 − q))
/// of Liu et al. 2016 eq. 6 inverted). Y is rounded to a grid of 1/`CELLS` and S's law on
/// [0, 1] follows by Panjer's recursion (Panjer 1981, "Recursive evaluation of a family of
/// compound distributions", ASTIN Bulletin 12(1), eq. for the Poisson case:
/// f(0) = exp(−λ(1 − p₀)), f(k) = (λ/k) Σⱼ j pⱼ f(k − j)); the rest of the mass lies above 1, where
/// the mask is clamped.
pub(crate) fn clamped_shot_noise_exp_means(
    sharpness: f32,
    overlap: f32,
    scales: &[Vec3],
) -> Vec<Vec3> {
    const CELLS: usize = 256;
    let h = 1.0 / CELLS as f64;
    let s = sharpness as f64;
    // P(Y ≥ y).
    let tail = |y: f64| -> f64 {
        if y <= 0.0 {
            1.0
        } else if y > 1.0 {
            0.0
        } else {
            let l = -y.ln();
            if l + s <= 0.0 {
                1.0
            } else {
                (l / (s + l)).powf(1.5)
            }
        }
    };
    let p: Vec<f64> = (0..=CELLS)
        .map(|j| tail((j as f64 - 0.5) * h) - tail((j as f64 + 0.5) * h))
        .collect();
    let lambda = overlap.max(0.0) as f64;
    let mut f = vec![0.0f64; CELLS + 1];
    f[0] = (-lambda * (1.0 - p[0])).exp();
    for k in 1..=CELLS {
        let sum: f64 = (1..=k).map(|j| j as f64 * p[j] * f[k - j]).sum();
        f[k] = lambda / k as f64 * sum;
    }
    let below: f64 = f.iter().sum();
    let above = (1.0 - below).max(0.0);
    scales
        .iter()
        .map(|c| {
            let mean = |c: f32| {
                let c = c as f64;
                let v: f64 = f
                    .iter()
                    .enumerate()
                    .map(|(k, fk)| fk * (-c * k as f64 * h).exp())
                    .sum();
                (v + above * (-c).exp()) as f32
            };
            Vec3::new(mean(c.x), mean(c.y), mean(c.z))
        })
        .collect()
}

/// Weight of a feature `size` mm across seen through a pixel footprint `footprint` mm wide:
/// 1 (kept) up to footprint = size, 0 (replaced by its mean) from footprint = 2 size, linear in
/// between so the change is not a visible seam (notes/sweep.md "Footprint").
#[inline]
pub(crate) fn footprint_weight(size: f32, footprint: f32) -> f32 {
    (2.0 - footprint / size).clamp(0.0, 1.0)
}

/// A mask of discrete features: one band of bump kernels (sharpness `sharpness`, semi-axes `env`)
/// with unit weights (`SparseConvolution::default()`'s tail), `density` overlapping a point on
/// average, in `cells` of size `cell`.
fn bump_mask_noise(
    sharpness: f32,
    density: f32,
    env: Vec3,
    (cell, cells): (Vec3, Cells),
    seed: u32,
) -> SeededSparse {
    let noise = SparseConvolution {
        kernel: Kernel::Bump { sharpness },
        density,
        envelope: env,
        cell,
        cells,
        ..SparseConvolution::default()
    };
    SeededSparse::new(noise, seed)
}

/// Pores (vessels): bump-kernel noise with unit weights, kernels elongated along the fibre frame.
/// Ring porosity scales each pore's size by s = 1 − porosity · g (§6.1.6: "modulate the pore sizes
/// using one minus the growth ring volume", interpolated towards uniform size).
#[derive(Clone, Debug)]
pub struct Pores {
    noise: SeededSparse,
    ring_porosity: f32,
    /// Bump depth at full mask, mm (depth fraction × radius, §6.1.7).
    pub depth: f32,
    /// Narrowest diameter of a pore (2 × radius), mm.
    pub diameter: f32,
    /// Mean mask at full pore size, min(1, density · bump_kernel_mean(s)).
    mean_full: f32,
}

impl Pores {
    /// `max_tilt`: the largest angle (radians) between the fibre frame and ẑ (the interlock
    /// angle), so the Cartesian cells hold the tilted kernel's bounding box (eq. 9) unshrunk.
    pub fn new(p: &PoreParams, max_tilt: f32, seed: u32) -> Self {
        let env = Vec3::new(p.radius, p.radius, 0.5 * p.length);
        let xy = (env.x * env.x + (env.z * max_tilt.sin()).powi(2)).sqrt() * 1.001;
        Pores {
            noise: bump_mask_noise(
                p.sharpness,
                p.density,
                env,
                (
                    CELL_SCALE * Vec3::new(xy, xy, env.z * 1.001),
                    Cells::Cartesian,
                ),
                seed,
            ),
            ring_porosity: p.ring_porosity,
            depth: p.depth * p.radius,
            diameter: 2.0 * p.radius,
            mean_full: (p.density * bump_kernel_mean(p.sharpness)).min(1.0),
        }
    }

    /// The mean of [`Pores::mask`] over a footprint whose ring values g have the means
    /// `moments` = (E[g], E[g²], E[g³]) (at one g: (g, g², g³)). Every pore shrunk by
    /// size = 1 − porosity · g in all three axes about its own centre keeps its count, so by
    /// Campbell's theorem the mean of the (unclamped) kernel sum scales by size³ (notes/noise.md;
    /// the clamp at 1 only matters where pores overlap), and size³ = (1 − ρg)³ is a cubic in g:
    /// E[size³] = 1 − 3ρE[g] + 3ρ²E[g²] − ρ³E[g³] (the mean of a ring-porous wood's pores over
    /// rings it cannot resolve; the mean size's cube would drop most of the earlywood vessels).
    #[inline]
    pub(crate) fn mean_mask_over(&self, moments: Vec3) -> f32 {
        let r = self.ring_porosity;
        let cube = 1.0 - 3.0 * r * moments.x + 3.0 * r * r * moments.y - r * r * r * moments.z;
        self.mean_full * cube.clamp(0.0, 1.0)
    }

    /// Pore mask in [0, 1] and its gradient at `q` for growth-ring value `g`, kernels along `fiber`
    /// (s, t across the fibre, n along it). Ring porosity (Liu et al. 2016 §6.1.6) shrinks every
    /// pore kernel about its centre by size = 1 − porosity · g: the same vessels, narrower in the
    /// latewood, vanishing where size reaches 0. Overlapping kernels saturate at a full mask.
    /// The gradient holds the frame and the size fixed (eq. 14).
    #[inline]
    pub fn mask<const GRAD: bool>(&self, q: Vec3, fiber: &Frame, g: f32) -> (f32, Vec3) {
        let size = 1.0 - self.ring_porosity * g;
        if size <= 1e-3 {
            return (0.0, Vec3::ZERO);
        }
        let (v, grad) = self
            .noise
            .eval_oriented_with::<GRAD>(q, fiber, 1, size.min(1.0));
        if v <= 1e-12 {
            (0.0, Vec3::ZERO)
        } else if v >= 1.0 {
            (1.0, Vec3::ZERO)
        } else {
            (v, grad)
        }
    }

    /// [`Pores::mask`]'s value at `N` points with their fibre frames and ring values (the query
    /// set-up in lanes, [`SeededSparse::eval_oriented_many`]); the same values.
    #[inline(always)]
    pub(crate) fn mask_many<const N: usize>(
        &self,
        q: &[Vec3; N],
        fiber: &[Frame; N],
        g: &[f32; N],
    ) -> [f32; N] {
        let size = g.map(|g| 1.0 - self.ring_porosity * g);
        // Vanished pores are searched at full size (cheap to run, then discarded).
        let scale = size.map(|s| if s <= 1e-3 { 1.0 } else { s.min(1.0) });
        let v = self.noise.eval_oriented_many(q, fiber, 1, &scale);
        let mut mask = [0.0; N];
        for i in 0..N {
            mask[i] = if size[i] <= 1e-3 || v[i] <= 1e-12 {
                0.0
            } else if v[i] >= 1.0 {
                1.0
            } else {
                v[i]
            };
        }
        mask
    }
}

/// Rays: bump-kernel noise with unit weights on cylindrical cells (§4.2), kernels thin in θ,
/// tall in z and long in r, aligned with (r̂, θ̂, ẑ).
#[derive(Clone, Debug)]
pub struct Rays {
    noise: SeededSparse,
    strength: f32,
    /// Ray width (its narrowest extent), mm.
    pub width: f32,
    /// The smaller of the ray's other extents (length along r̂, height along ẑ), mm: the widest
    /// its trace on a face can be.
    pub trace_limit: f32,
    /// Mean of [`Rays::mask`]: strength · min(1, density · bump_kernel_mean(s)).
    pub mean_mask: f32,
    /// Sideways displacement of the ray sheets (mm along θ̂), if they wander.
    wander: Option<SeededSparse>,
}

impl Rays {
    /// `seeds`: the rays', then their waviness's.
    pub fn new(p: &RayParams, seeds: [u32; 2]) -> Self {
        let env = Vec3::new(0.5 * p.length, 0.5 * p.width, 0.5 * p.height);
        Rays {
            // Arc cells wider than the ray: the search window along θ is set by the longest
            // semi-axis anyway (notes/noise.md), so thin cells would only add cells.
            noise: bump_mask_noise(
                p.sharpness,
                p.density,
                env,
                (
                    Vec3::new(env.x, RAY_ARC_CELLS * env.y, env.z),
                    Cells::Cylindrical,
                ),
                seeds[0],
            ),
            strength: p.strength,
            width: p.width,
            trace_limit: p.length.min(p.height),
            mean_mask: p.strength * (p.density * bump_kernel_mean(p.sharpness)).min(1.0),
            wander: (p.wander > 0.0)
                .then(|| grain_noise(p.wander, (p.wander_length, p.wander_length), 2.0, seeds[1])),
        }
    }

    /// Ray mask in [0, strength] at `q`: the sheets looked up at q moved sideways (along θ̂) by
    /// their waviness, so a flat face meets a wavy sheet where it is within half a width.
    #[inline]
    pub fn mask(&self, q: Vec3) -> f32 {
        let q = match &self.wander {
            Some(w) => {
                let frame = crate::field::cylinder_frame(q);
                q + w.eval_oriented_with::<false>(q, &frame, 1, 1.0).0 * frame.t
            }
            None => q,
        };
        self.noise.eval(q).min(1.0) * self.strength
    }
}

/// Fine-scale grain deviation ([`FibreWanderParams`], notes/wood.md §9a): two small tilt angles of
/// the fibre, each a zero-mean 3D sparse convolution noise (Wyvill kernel, signed weights, one
/// band; Liu et al. 2016 §4, eq. 4 and 7) with kernels long along the grain and short across it,
/// oriented by the cylindrical frame at the query, scaled so that each angle has the standard
/// deviation asked for (Campbell's theorem: variance = density · 1024/45045 · magnitude²).
#[derive(Clone, Debug)]
pub(crate) struct FibreWander {
    /// Per scale, tilt towards r̂ and towards θ̂ (None: that angle is zero at that scale).
    angles: Vec<[Option<SeededSparse>; 2]>,
    /// Per scale, the two angles' variances (rad²) and correlation lengths (mm, 1/e lag):
    /// across the grain and each angle's along it ([`FibreWander::band_limited`]).
    scales: Vec<WanderSpread>,
    /// Pore deflection strength (fibres pushed out by this × pore radius × mask).
    pub pore_deflection: f32,
}

impl FibreWander {
    /// Variance of one band of signed-weight Wyvill sparse convolution noise of magnitude 1 per
    /// unit density: E[w²] · ∫K² dV / V = (1/3) · (4π · 1024/45045) / (4π/3) = 1024/45045
    /// (weights uniform in [−1, 1), ∫₀¹ r² (1 − r²)⁶ dr = 1024/45045; notes/wood.md §9a).
    pub(crate) const VARIANCE_PER_DENSITY: f32 = 1024.0 / 45045.0;
    /// Lag, in kernel semi-axes, at which that noise's autocorrelation along an axis falls to
    /// 1/e (numerical integration of the kernel's autocorrelation, notes/wood.md §9a; ½ at 0.549,
    /// 0 at 2).
    pub(crate) const CORRELATION_LAG: f32 = 0.656;

    /// The wander of `p`; `seeds` gives each noise field its own (coarse r, coarse θ, fine r,
    /// fine θ).
    pub fn new(p: &FibreWanderParams, seeds: [u32; 4]) -> Self {
        let coarse = p.coarse();
        let mut angles = vec![Self::scale(&coarse, [seeds[0], seeds[1]])];
        let mut scales = vec![Self::variances(&coarse)];
        if let Some(f) = &p.fine {
            angles.push(Self::scale(f, [seeds[2], seeds[3]]));
            scales.push(Self::variances(f));
        }
        FibreWander {
            angles,
            scales,
            pore_deflection: p.pore_deflection,
        }
    }

    /// The two angles' noises of one scale (the tangential one along its own length if given).
    fn scale(p: &WanderScale, seeds: [u32; 2]) -> [Option<SeededSparse>; 2] {
        let noise = |deg: f32, along: f32, seed: u32| {
            (deg > 0.0).then(|| grain_noise(deg.to_radians(), (along, p.across), p.density, seed))
        };
        [
            noise(p.radial, p.along, seeds[0]),
            noise(
                p.tangential,
                p.tangential_along.unwrap_or(p.along),
                seeds[1],
            ),
        ]
    }

    /// One scale's angle variances and correlation lengths.
    fn variances(p: &WanderScale) -> WanderSpread {
        WanderSpread {
            var: [p.radial, p.tangential].map(|deg| deg.to_radians().powi(2)),
            across: p.across,
            along: [p.along, p.tangential_along.unwrap_or(p.along)],
        }
    }

    /// The wander band-limited by a footprint `footprint` mm wide on a face of tree-space normal
    /// `normal` (zero: unknown). Each angle a of variance σ² is estimated by its best linear
    /// predictor from the centre value, C·a, C the centre's mean correlation with the footprint
    /// ([`centre_correlation`] across and along the grain), and the variance this leaves,
    /// (1 − C²) σ², is returned as the variance of the fibre's dip out of that face,
    /// σr² (r̂·n)² + σθ² (θ̂·n)² (both when the face is unknown): the unresolved tilts that widen
    /// the highlight instead of aliasing it (notes/wood.md §9e). An angle with C² below
    /// [`FibreWander::NEGLIGIBLE_SHARE`] is not evaluated.
    #[inline]
    pub(crate) fn band_limited(
        &self,
        q: Vec3,
        fiber: &Frame,
        footprint: f32,
        normal: Vec3,
    ) -> (Vec3, f32) {
        let cyl = crate::field::cylinder_frame(q);
        let (mut angle, mut lost) = ([0.0f32; 2], [0.0f32; 2]);
        for (noises, spread) in self.angles.iter().zip(&self.scales) {
            // C across the grain is the same for both angles, and C along it too unless their
            // lengths differ: each erf once.
            let (across, along) = if footprint > 0.0 {
                let along = centre_correlation(footprint / spread.along[0]);
                let along_t = if spread.along[1] == spread.along[0] {
                    along
                } else {
                    centre_correlation(footprint / spread.along[1])
                };
                (
                    centre_correlation(footprint / spread.across),
                    [along, along_t],
                )
            } else {
                (1.0, [1.0; 2])
            };
            for k in 0..2 {
                let Some(n) = &noises[k] else { continue };
                let c = across * along[k];
                if c * c >= Self::NEGLIGIBLE_SHARE {
                    let a = n.eval_oriented_with::<false>(q, &cyl, 1, 1.0).0;
                    angle[k] += if c < 1.0 { c * a } else { a };
                    lost[k] += (1.0 - c * c) * spread.var[k];
                } else {
                    lost[k] += spread.var[k];
                }
            }
        }
        let dip = if normal == Vec3::ZERO {
            lost[0] + lost[1]
        } else {
            lost[0] * fiber.s.dot(normal).powi(2) + lost[1] * fiber.t.dot(normal).powi(2)
        };
        (Self::tilted(fiber, angle[0], angle[1]), dip)
    }

    /// The share C² of an angle's variance below which its estimate is left out (its standard
    /// deviation an eighth of the angle's).
    pub(crate) const NEGLIGIBLE_SHARE: f32 = 1.0 / 64.0;

    /// The narrowest footprint (mm) under which every angle of the wander falls below
    /// [`FibreWander::NEGLIGIBLE_SHARE`] and is no longer evaluated, for the scale `p`.
    pub(crate) fn skipped_from(p: &WanderScale) -> f32 {
        let s = Self::variances(p);
        let share = |w: f32| {
            (centre_correlation(w / s.across) * centre_correlation(w / s.along[0].min(s.along[1])))
                .powi(2)
        };
        // The share falls monotonically with the width: bisect between the across length and
        // 10⁴ of it.
        let (mut lo, mut hi) = (s.across, 1e4 * s.across);
        for _ in 0..60 {
            let mid = (lo * hi).sqrt();
            if share(mid) < Self::NEGLIGIBLE_SHARE {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        hi
    }

    /// The fibre of `fiber` (s = r̂, t across, n along the fibre) tilted by a_r and a_t:
    /// n + tan(a_r) s + tan(a_t) t, normalised: its projection on the (s, n) plane makes exactly
    /// a_r with n and that on the (t, n) plane exactly a_t.
    #[inline]
    fn tilted(fiber: &Frame, ar: f32, at: f32) -> Vec3 {
        (fiber.n + ar.tan() * fiber.s + at.tan() * fiber.t).normalize()
    }

    /// The fibre `fiber` bent around a pore whose mask has gradient `grad` at the point (fibre
    /// frame axis `along`, pore radius `radius` mm): a fibre beside the vessel is displaced
    /// outwards (−∇⊥m) by δ = pore_deflection · radius · m, so its tangent turns by
    /// dδ/dn = pore_deflection · radius · ∂m/∂n (streamlines around an obstacle; Hoadley,
    /// "Understanding Wood" ch. 2).
    #[inline]
    pub(crate) fn around_pore(&self, fiber: Vec3, along: Vec3, grad: Vec3, radius: f32) -> Vec3 {
        let dn = grad.dot(along);
        let across = grad - dn * along;
        let len = across.length();
        if self.pore_deflection <= 0.0 || len < 1e-12 || !len.is_finite() {
            return fiber;
        }
        (fiber - (self.pore_deflection * radius * dn / len) * across).normalize()
    }
}

/// One scale of the wander as a footprint sees it.
#[derive(Clone, Copy, Debug)]
struct WanderSpread {
    /// Variances of the tilts towards r̂ and θ̂, rad².
    var: [f32; 2],
    /// Correlation length across the grain, mm (1/e lag).
    across: f32,
    /// Each tilt's correlation length along the grain, mm.
    along: [f32; 2],
}

/// The mean correlation of a field's value at the centre of a segment `u` correlation lengths
/// long with its values over the segment, for the autocorrelation exp(−d²/ℓ²):
/// (1/u) ∫ exp(−x²) dx over [−u/2, u/2] = (√π / u) erf(u/2): the factor of the best linear
/// estimate of the segment's mean from the centre value.
pub(crate) fn centre_correlation(u: f32) -> f32 {
    let u = u as f64;
    if u < 1e-3 {
        return (1.0 - u * u / 12.0) as f32;
    }
    (std::f64::consts::PI.sqrt() / u * statrs::function::erf::erf(0.5 * u)) as f32
}

/// Zero-mean noise of standard deviation `std` with 1/e correlation lengths (`along`, `across`)
/// the grain (mm): one band of signed-weight Wyvill sparse convolution (Liu et al. 2016 §4,
/// eq. 4 and 7) with `density` kernels overlapping a point, kernels oriented by the cylindrical
/// frame at the query; the magnitude from Campbell's theorem
/// ([`FibreWander::VARIANCE_PER_DENSITY`]), the semi-axes from [`FibreWander::CORRELATION_LAG`].
fn grain_noise(std: f32, (along, across): (f32, f32), density: f32, seed: u32) -> SeededSparse {
    let across = across / FibreWander::CORRELATION_LAG;
    let env = Vec3::new(across, across, along / FibreWander::CORRELATION_LAG);
    SeededSparse::new(
        SparseConvolution {
            kernel: Kernel::Wyvill,
            density,
            envelope: env,
            // Equal r and θ semi-axes: the kernel's bounding box is the same at any rotation
            // about ẑ, so these cells never shrink it (eq. 11).
            cell: CELL_SCALE * env,
            magnitude: std / (density * FibreWander::VARIANCE_PER_DENSITY).sqrt(),
            weights: Weights::Signed,
            cells: Cells::Cartesian,
            bands: 1,
            size_factor: 0.5,
            dropoff: 1.0,
        },
        seed,
    )
}

/// Cell-scale colour texture ([`TextureParams`], notes/wood.md §9c): an extra Beer's-law absorption
/// path (latewood units) that varies over fractions of a millimetre, long along the grain, as the
/// density and extractive content of neighbouring fibres, vessels and parenchyma strands do (the
/// "texture" of the wood trade: Hoadley, "Understanding Wood", ch. 5).
#[derive(Clone, Debug)]
pub(crate) struct CellTexture {
    /// Per scale (cells, then streaks), the noise and its across-grain correlation length (mm):
    /// the feature size the footprint filter fades it at.
    scales: Vec<(SeededSparse, f32)>,
}

impl CellTexture {
    /// The texture of `p`, its noises seeded by `seeds` (cells, streaks).
    pub fn new(p: &TextureParams, seeds: [u32; 2]) -> Self {
        let scale = |t: &TextureParams, seed| {
            (
                grain_noise(t.path, (t.along, t.across), t.density, seed),
                t.across,
            )
        };
        let mut scales = vec![scale(p, seeds[0])];
        scales.extend(p.streaks.as_deref().map(|s| scale(s, seeds[1])));
        CellTexture { scales }
    }

    /// The across-grain correlation length (mm) of each scale: [`CellTexture::path`] fades a
    /// scale out at twice it and drops it at four times it.
    pub fn widths(&self) -> impl Iterator<Item = f32> + '_ {
        self.scales.iter().map(|&(_, across)| across)
    }

    /// The extra absorption path at the distorted point `q` (zero mean) for a pixel footprint
    /// `footprint` mm wide: each scale fades out as the footprint grows from twice its
    /// across-grain correlation length to four times it (and is not evaluated beyond), as pores do.
    #[inline]
    pub fn path(&self, q: Vec3, footprint: f32) -> f32 {
        let cyl = crate::field::cylinder_frame(q);
        let mut sum = 0.0;
        for (noise, across) in &self.scales {
            let w = footprint_weight(2.0 * across, footprint);
            if w > 0.0 {
                sum += w * noise.eval_oriented_with::<false>(q, &cyl, 1, 1.0).0;
            }
        }
        sum
    }
}

/// 1D sparse convolution noise ([`SparseConvolution1`]) scaled to its largest value `amp`:
/// |value| ≤ amp, |derivative| ≤ amp · MAX_SLOPE / width (notes/wood.md §2, §4).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Noise1 {
    pub amp: f32,
    noise: SparseConvolution1,
}

impl Noise1 {
    /// Largest value `amp`, kernel half-width `width`.
    pub fn new(amp: f32, width: f32, seed: u32) -> Self {
        Noise1 {
            amp,
            noise: SparseConvolution1::new(width, seed),
        }
    }

    /// Value and derivative with respect to x.
    #[inline(always)]
    pub fn eval(&self, x: f32) -> (f32, f32) {
        let (v, d) = self.noise.eval(x);
        (self.amp * v, self.amp * d)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Red oak's pores (ring porosity 1, overlapping bump kernels) at random points.
    fn ring_porous() -> (Pores, Vec<Vec3>) {
        let params = crate::wood::preset("red_oak").unwrap();
        let mut pores = params.pores.clone().expect("red oak has pores");
        pores.ring_porosity = 1.0;
        let mut r = crate::math::Pcg32::new(5, 0);
        let pts = (0..200_000)
            .map(|_| {
                Vec3::new(r.next_f32(), r.next_f32(), r.next_f32()) * Vec3::new(6.0, 6.0, 20.0)
            })
            .collect();
        (Pores::new(&pores, 0.0, 9), pts)
    }

    const UPRIGHT: Frame = Frame {
        s: Vec3::X,
        t: Vec3::Y,
        n: Vec3::Z,
    };

    /// Shrunk pores cover size³ of what full pores cover (Campbell's theorem on the kernels
    /// shrunk about their centres; at size 0.25 overlaps are rare, so the clamp hardly acts),
    /// and only where a full-size pore was.
    #[test]
    fn ring_porous_pores_shrink_about_their_centres() {
        let (pores, pts) = ring_porous();
        let size = 0.25;
        let g = 1.0 - size;
        let (mut full, mut shrunk) = (0.0f64, 0.0f64);
        for &p in &pts {
            let m1 = pores.mask::<false>(p, &UPRIGHT, 0.0).0;
            let ms = pores.mask::<false>(p, &UPRIGHT, g).0;
            assert!(
                ms <= 0.0 || m1 > 0.0,
                "a pore appeared at {p} when shrinking"
            );
            full += m1 as f64;
            shrunk += ms as f64;
        }
        let n = pts.len() as f64;
        let expect = pores.mean_mask_over(Vec3::new(g, g * g, g * g * g)) as f64;
        let got = shrunk / n;
        assert!(full / n > 0.05, "full-size pores cover {}", full / n);
        assert!(
            (got - expect).abs() < 0.15 * expect,
            "mean mask at size {size}: {got}, expected {expect}"
        );
    }

    /// The mask changes continuously as the pores shrink to nothing (no region that stays full
    /// and then vanishes at once).
    #[test]
    fn ring_porous_mask_is_continuous_in_size() {
        let (pores, pts) = ring_porous();
        for &p in pts
            .iter()
            .filter(|&&p| pores.mask::<false>(p, &UPRIGHT, 0.0).0 > 0.5)
            .take(300)
        {
            let mut last = pores.mask::<false>(p, &UPRIGHT, 0.0).0;
            for k in 1..=2000 {
                let g = k as f32 * 5e-4;
                let m = pores.mask::<false>(p, &UPRIGHT, g).0;
                assert!(
                    (m - last).abs() < 0.2,
                    "at {p}: mask {last} → {m} at g = {g}"
                );
                last = m;
            }
        }
    }

    #[test]
    fn clamped_mask_colour_mean_matches_monte_carlo_shot_noise() {
        // Independent expectation: the shot noise drawn directly — a Poisson count of kernels,
        // each at a point uniform in its unit ball — clamped at 1 and put through Beer's law,
        // 200 000 draws (standard error ≤ 6·10⁻⁴). Red oak's pores (sharpness 0.8, overlap
        // 0.5 at full size and 0.2 part-shrunk) under its colour (c = −ln latewood × path 1.0),
        // a sharper kernel at overlap 2 (the clamp often acting) and a flat one (sharpness 0).
        let late = -Vec3::new(0.42, 0.22, 0.12).ln();
        let mut rng = crate::math::Pcg32::new(7, 1);
        for (sharpness, overlap) in [(0.8f32, 0.5f32), (0.8, 0.2), (4.0, 2.0), (0.0, 0.3)] {
            let got = clamped_shot_noise_exp_means(sharpness, overlap, &[late])[0];
            let n = 200_000;
            let (mut want, mut mean_mask) = (Vec3::ZERO, 0.0f64);
            for _ in 0..n {
                // Poisson by inversion.
                let (mut k, mut p, u) = (0, (-overlap).exp(), rng.next_f32());
                let mut cdf = p;
                while u > cdf && k < 64 {
                    k += 1;
                    p *= overlap / k as f32;
                    cdf += p;
                }
                let mut sum = 0.0f32;
                for _ in 0..k {
                    // r³ uniform: a point uniform in the ball.
                    let q = rng.next_f32().powf(2.0 / 3.0);
                    sum += Kernel::Bump { sharpness }.eval_q(q).0;
                }
                let m = sum.min(1.0);
                mean_mask += m as f64 / n as f64;
                want += (-late * m).exp() / n as f32;
            }
            let err = (got - want).abs().max_element();
            assert!(
                err < 3e-3,
                "s {sharpness} λ {overlap}: {got} vs Monte Carlo {want}"
            );
            // Negative control: Beer's law of the mean mask is off by far more.
            let of_mean = (-late * mean_mask as f32).exp();
            let gap = (of_mean - want).abs().max_element();
            eprintln!("s {sharpness} λ {overlap}: {got} vs {want}; of the mean mask {of_mean}");
            assert!(gap > 0.01, "s {sharpness} λ {overlap}: no gap ({gap})");
        }
    }
}
