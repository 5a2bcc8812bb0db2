//! Parameters of the wood model as data (`scenes/presets/*.toml`): serde structs that reject
//! unknown fields, plus range validation whose errors name the file, field and allowed range.
//! Lengths are millimetres, angles degrees, colours linear RGB, times years.

use super::error::WoodError;
use super::growth::SmoothTriangleWave;
use crate::noise::SparseConvolution1;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The whole model. Optional sections switch a feature off when absent (and its work is skipped).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WoodParams {
    /// Growth rings: width and the earlywood/latewood profile.
    pub rings: RingParams,
    /// Slow and fast growth periods; absent: every ring the mean width.
    #[serde(default)]
    pub growth: Option<GrowthParams>,
    /// Interlocked grain (a helix angle that reverses with r); absent: fibres along the pith.
    #[serde(default)]
    pub interlock: Option<InterlockParams>,
    /// Distortions of the rings (figure); each direction off when absent.
    #[serde(default)]
    pub distortion: DistortionParams,
    /// Pores; absent: no pores (and no pore bump).
    #[serde(default)]
    pub pores: Option<PoreParams>,
    /// Rays; absent: no rays.
    #[serde(default)]
    pub rays: Option<RayParams>,
    /// Earlywood and latewood colours and the fibre colour's saturation.
    pub color: ColorParams,
    /// Fibre highlight width between earlywood and latewood.
    #[serde(default)]
    pub highlight: HighlightParams,
    /// Knots; absent: clear wood.
    #[serde(default)]
    pub knots: Option<KnotParams>,
    /// Fine-scale grain deviation (fibre dip and wander, deflection around pores); absent: the
    /// fibres of the frame, interlock, knots and distortion alone, bit for bit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fibre_wander: Option<FibreWanderParams>,
    /// Birdseye: radial bud traces the rings dip around, with dark centres; absent: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub eyes: Option<EyeParams>,
    /// Cell-scale colour texture (fibres, vessels and parenchyma below the pixel); absent: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub texture: Option<TextureParams>,
}

/// Cell-scale colour texture (ours, notes/wood.md §9c): a zero-mean extra absorption path, added
/// to Liu et al. 2016 eq. 25's ℓ_g g + ℓ_p p, that varies over fractions of a millimetre and is
/// longer along the grain than across it: the fine "texture" by which the trade grades woods,
/// from the size and contrast of their cells (Hoadley, "Understanding Wood", ch. 5).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TextureParams {
    /// Standard deviation of the extra path, in latewood absorbance units (0.1: ±10 % of the
    /// latewood's absorbance).
    pub path: f32,
    /// Correlation length along the grain, mm (1/e lag, as [`FibreWanderParams::along`]).
    pub along: f32,
    /// Correlation length across the grain, mm (1/e lag).
    pub across: f32,
    /// Mean number of kernels overlapping a point.
    #[serde(default = "two")]
    pub density: f32,
    /// A second, independent scale added to this one (the same fields; its paths' variances
    /// add): streaks millimetres across and centimetres long, e.g. the colour streaks of maple,
    /// where the first scale is the cells. Its own `streaks` must be absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub streaks: Option<Box<TextureParams>>,
}

/// Birdseye figure (ours, `eyes.rs`): aborted bud traces running radially, each an eye on a
/// flat-sawn face with the rings dipping round it and a dark centre.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EyeParams {
    /// Mean number of eyes per cm² of tangential (flat-sawn) face.
    pub density: f32,
    /// Range `[min, max]` of the dimple's diameter, mm (uniform); the visible eye, the ring loop
    /// round the centre, is about half of it to all of it.
    pub diameter: [f32; 2],
    /// Depth of the rings' dip at an eye's centre, mm.
    pub depth: f32,
    /// Radial length of a trace, mm (it fades in and out over this length).
    #[serde(default = "eye_length")]
    pub length: f32,
    /// Radius of the dark centre, mm.
    #[serde(default = "eye_core")]
    pub core: f32,
    /// Extra absorbance at the centre (multiples of the latewood path).
    #[serde(default = "one")]
    pub darkening: f32,
}

fn eye_length() -> f32 {
    40.0
}
fn eye_core() -> f32 {
    0.4
}

/// Growth rings (§6.1.4): mean yearly ring width and the year's earlywood/latewood proportions of
/// the C² rectangle wave g(t) (0 = earlywood, 1 = latewood).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RingParams {
    /// Mean ring width, mm.
    pub width: f32,
    /// Fractions of a year `[earlywood, transition, latewood, fall]` (normalised to sum 1).
    pub proportions: [f32; 4],
}

/// Slow / fast growth periods (§6.1.3, eq. 23–24): a C¹ triangle wave in radius plus 1D sparse
/// convolution noise n(t_pre) (App. A.3: Wyvill kernel, one band, magnitude, kernel width).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GrowthParams {
    /// Triangle-wave segment lengths `[rise, top, fall, bottom]`, years at mean growth.
    pub wave: [f32; 4],
    /// Peak-to-peak amplitude of the wave, years.
    pub amplitude: f32,
    /// Largest |n(t_pre)|, years (a bound; the standard deviation is 0.413 of it). At most
    /// 0.95 · noise_scale / 2.5462, so that time grows with radius (notes/wood.md §2).
    #[serde(default)]
    pub noise_amplitude: f32,
    /// Kernel half-width of the growth noise, years.
    #[serde(default = "one")]
    pub noise_scale: f32,
    /// Largest shift of the wave's phase, years: the wave is read at u + a·m(u), m a unit 1D
    /// sparse convolution noise of its own seed, so slow and fast periods come at different radii
    /// in different trees instead of at the same r for every seed (ours; notes/wood.md §2). At
    /// most 0.95 · phase_scale · (1/s_down − 1) / 2.5462 (monotone time). 0 = eq. 23 as printed.
    #[serde(default)]
    pub phase_amplitude: f32,
    /// Kernel half-width of the phase noise, years.
    #[serde(default = "phase_scale_default")]
    pub phase_scale: f32,
}

fn phase_scale_default() -> f32 {
    8.0
}

/// Interlocked grain (§6.1.5): the fibre helix angle is 1D sparse convolution noise of r (App. A.3).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InterlockParams {
    /// Largest helix angle |φ|, degrees (a bound; the standard deviation is 0.413 of it).
    pub angle: f32,
    /// Mean distance along r between reversals of the helix (sign changes of φ), mm.
    pub period: f32,
}

/// Multiband sparse convolution noise (Wyvill kernel) used as a distortion magnitude (§4.4, §6.2).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NoiseParams {
    /// Magnitude of the base band, mm.
    pub magnitude: f32,
    /// Kernel envelope `[r, θ, z]` of the base band, mm (Fig. 10: its shape sets the figure).
    pub size: [f32; 3],
    /// Mean number of kernels overlapping a point.
    #[serde(default = "two")]
    pub density: f32,
    /// Number of bands.
    #[serde(default = "one_u32")]
    pub bands: u32,
    /// Kernel size factor β from one band to the next.
    #[serde(default = "half")]
    pub size_factor: f32,
    /// Power-law magnitude drop-off exponent γ.
    #[serde(default = "one")]
    pub dropoff: f32,
}

/// Distortion along r̂ (blister, quilted, birdseye), θ̂ (curly, fiddleback) and ẑ (§6.2).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DistortionParams {
    /// Along r̂: blister, quilted, birdseye figure.
    #[serde(default)]
    pub radial: Option<NoiseParams>,
    /// Along θ̂: curly and fiddleback figure.
    #[serde(default)]
    pub tangential: Option<NoiseParams>,
    /// Along ẑ.
    #[serde(default)]
    pub longitudinal: Option<NoiseParams>,
}

/// Pores / vessels (§6.1.6): bump-kernel noise aligned with the fibres.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PoreParams {
    /// Pore radius across the fibre, mm.
    pub radius: f32,
    /// Pore length along the fibre, mm.
    pub length: f32,
    /// Mean number of pores overlapping a point (at full size).
    pub density: f32,
    /// Bump-kernel sharpness s (0 box, 1 bump, large spike).
    #[serde(default = "one")]
    pub sharpness: f32,
    /// 0 diffuse-porous (uniform pores) … 1 ring-porous (pores vanish in latewood).
    pub ring_porosity: f32,
    /// Bump depth at full pore mask, as a fraction of the pore radius (§6.1.7).
    #[serde(default = "half")]
    pub depth: f32,
}

impl PoreParams {
    /// Narrowest vessel, mm across, that we call open grain: the coarse-textured woods whose
    /// pores a film finish leaves as dimples unless they are filled (oak, walnut, mahogany,
    /// padauk: 0.18–0.30 mm in the presets) against the fine-textured closed-grain ones (maple,
    /// cherry, yellowheart: 0.06–0.12 mm); texture by vessel size as in Hoadley, "Understanding
    /// Wood", ch. 5.
    pub const OPEN_DIAMETER: f32 = 0.15;

    /// Whether these pores are open grain ([`Self::OPEN_DIAMETER`] or wider).
    pub fn open(&self) -> bool {
        2.0 * self.radius >= Self::OPEN_DIAMETER
    }
}

/// Rays (§3.2, §6.1.6): bump-kernel noise in cylindrical cells, thin in θ, tall in z, long in r.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RayParams {
    /// Ray thickness along θ, mm.
    pub width: f32,
    /// Ray height along z, mm.
    pub height: f32,
    /// Ray extent along r, mm.
    pub length: f32,
    /// Mean number of rays overlapping a point.
    pub density: f32,
    /// Bump-kernel sharpness s (0 box, 1 bump, large spike).
    #[serde(default = "one")]
    pub sharpness: f32,
    /// Largest ray mask (blend weight of the ray-fibre BSDF), in [0, 1].
    #[serde(default = "one")]
    pub strength: f32,
    /// Standard deviation of the rays' sideways (θ) waviness, mm (0: flat radial sheets). Rays
    /// follow the wandering fibres round them, so a sheet a few tenths of a millimetre thick
    /// weaves in and out of a quartersawn face: the fleck is the ragged patch where it lies in
    /// the face, not the whole kernel's ellipse (notes/wood.md §9d).
    #[serde(default)]
    pub wander: f32,
    /// Correlation length (1/e) of that waviness, mm.
    #[serde(default = "ray_wander_length")]
    pub wander_length: f32,
}

fn ray_wander_length() -> f32 {
    4.0
}

/// Beer's-law colour (§6.1.8, eq. 25): the earlywood (g = 0) and latewood (g = 1) colours fix σℓ₀
/// and σℓ_g; pores and rays add path length in units of the latewood absorbance.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColorParams {
    /// Linear RGB of earlywood, each channel in (0, 1].
    pub earlywood: [f32; 3],
    /// Linear RGB of latewood, each channel in (0, 1].
    pub latewood: [f32; 3],
    /// Extra path length ℓ_p inside pores (multiples of the latewood path).
    #[serde(default)]
    pub pore_path: f32,
    /// Extra path length inside rays (negative: rays lighter).
    #[serde(default)]
    pub ray_path: f32,
    /// Fibre colour absorbance as a multiple of the diffuse absorbance, per channel (App. A.3's
    /// "absorption coefficients as diffuse times a scale", one scale per channel so a measured
    /// fibre colour that is greener but less blue than its diffuse can be reached; notes/wood.md).
    /// A number sets all three channels.
    #[serde(default = "half_rgb", deserialize_with = "number_or_rgb")]
    pub fiber_saturation: [f32; 3],
}

/// Fibre highlight width (App. A.3): a rectangle wave of time between earlywood and latewood.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HighlightParams {
    /// Earlywood highlight width β, degrees.
    pub earlywood: f32,
    /// Latewood highlight width β, degrees.
    pub latewood: f32,
}

impl Default for HighlightParams {
    fn default() -> Self {
        HighlightParams {
            earlywood: 8.0,
            latewood: 8.0,
        }
    }
}

/// Fine-scale grain deviation (ours, notes/wood.md §9a): the fibres of real wood are not parallel
/// to the stem even in straight-grained wood; they dip and wander by a few degrees over
/// millimetres to centimetres and bend around vessels and ray bundles (Hoadley, "Understanding
/// Wood", ch. 2 and 5; Panshin & de Zeeuw, "Textbook of Wood Technology", ch. 9 on grain
/// deviation). Two small rotation angles of the fibre, each a zero-mean sparse convolution noise
/// (Wyvill kernel, signed weights, one band; Liu et al. 2016 §4) with kernels oriented by the
/// cylindrical frame (long along the grain, short across it), applied at the distorted point
/// before the fibre is transported by J⁻¹ (Liu et al. 2016 eq. 17), so wander and figure combine.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FibreWanderParams {
    /// Standard deviation of the fibre's tilt towards r̂ (a rotation about θ̂), degrees: the dip
    /// out of a flat-sawn face, the in-plane wander of a quartersawn one.
    pub radial: f32,
    /// Standard deviation of the fibre's tilt towards θ̂ (a rotation about r̂), degrees: the
    /// in-plane wander of a flat-sawn face, the dip out of a quartersawn one.
    pub tangential: f32,
    /// Correlation length along the grain, mm: the lag at which the autocorrelation of either
    /// angle falls to 1/e (the kernel's semi-axis is this / 0.656; notes/wood.md §9a).
    pub along: f32,
    /// Correlation length across the grain (r̂ and θ̂), mm, as `along`.
    pub across: f32,
    /// Mean number of kernels overlapping a point (more: closer to Gaussian).
    #[serde(default = "two")]
    pub density: f32,
    /// Deflection of the fibres around pores: a fibre beside a vessel is pushed outwards by
    /// this × the pore radius × the pore mask, and turns by the along-fibre slope of that push
    /// (0: none; needs a `[pores]` section).
    #[serde(default)]
    pub pore_deflection: f32,
    /// A second, independent scale added to the first (its angles' variances add): cell-scale
    /// waviness, e.g. fibres deflected around vessels and rays, correlated over tenths of a
    /// millimetre where the first is over centimetres.
    #[serde(default)]
    pub fine: Option<WanderScale>,
}

/// One scale of [`FibreWanderParams`]: the same fields, without pore deflection.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WanderScale {
    /// Standard deviation of the tilt towards r̂, degrees.
    pub radial: f32,
    /// Standard deviation of the tilt towards θ̂, degrees.
    pub tangential: f32,
    /// Correlation length along the grain, mm (1/e lag).
    pub along: f32,
    /// Correlation length across the grain, mm (1/e lag).
    pub across: f32,
    /// Mean number of kernels overlapping a point.
    #[serde(default = "two")]
    pub density: f32,
    /// Correlation length along the grain of the tangential tilt alone, mm (default: `along`):
    /// at the cell scale the two tilts have different causes — fibres bend tangentially round
    /// the rays, whose height sets the length, and radially round vessels and growth
    /// irregularities (Hoadley, "Understanding Wood", ch. 2: fibres part round the ray spindles
    /// seen on a tangential face).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tangential_along: Option<f32>,
}

impl FibreWanderParams {
    /// The first scale's fields as a [`WanderScale`].
    pub fn coarse(&self) -> WanderScale {
        WanderScale {
            radial: self.radial,
            tangential: self.tangential,
            along: self.along,
            across: self.across,
            density: self.density,
            tangential_along: None,
        }
    }
}

/// Knots after Larsson et al. 2022: branches leave the pith in whorls as cones with their own rings
/// (the knot ring width follows from the cone angle, see `knots.rs`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KnotParams {
    /// Distance between whorls along z, mm.
    pub whorl_spacing: f32,
    /// Branches per whorl.
    pub per_whorl: u32,
    /// Upward angle of a branch from the horizontal, degrees.
    pub rise: f32,
    /// Half-angle of the knot cone, degrees.
    pub cone: f32,
    /// Year the branches die (the knot stops growing and becomes a dead, bark-rimmed cylinder);
    /// absent: live knots.
    #[serde(default)]
    pub death_year: Option<f32>,
    /// Extra absorbance of knot wood (multiples of the latewood path).
    #[serde(default = "half")]
    pub darkening: f32,
    /// The trunk's growth layers swell round a branch (the branch collar): outside a knot the
    /// trunk time is lowered by up to `swell` years, fading over `swell_width` mm from the knot's
    /// surface, so on a flat-sawn face the rings loop round the knot. 0 (absent): no swell.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub swell: f32,
    /// Distance from the knot's surface over which the swell fades, mm.
    #[serde(default = "swell_width", skip_serializing_if = "is_swell_width")]
    pub swell_width: f32,
    /// Thickness of the bark rim round a dead knot, mm: the branch's bark, which the trunk grew
    /// over when the branch died (an encased knot's dark ring).
    #[serde(default = "bark_width", skip_serializing_if = "is_bark_width")]
    pub bark_width: f32,
}

fn is_zero(v: &f32) -> bool {
    *v == 0.0
}
fn swell_width() -> f32 {
    20.0
}
fn is_swell_width(v: &f32) -> bool {
    *v == 20.0
}
fn bark_width() -> f32 {
    0.4
}
fn is_bark_width(v: &f32) -> bool {
    *v == 0.4
}

fn one() -> f32 {
    1.0
}
fn two() -> f32 {
    2.0
}
fn half() -> f32 {
    0.5
}
fn half_rgb() -> [f32; 3] {
    [0.5; 3]
}

/// A number (all channels) or an array of three numbers (red, green, blue).
fn number_or_rgb<'de, D: serde::Deserializer<'de>>(d: D) -> Result<[f32; 3], D::Error> {
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum NumberOrRgb {
        Number(f32),
        Rgb([f32; 3]),
    }
    match NumberOrRgb::deserialize(d) {
        Ok(NumberOrRgb::Number(v)) => Ok([v; 3]),
        Ok(NumberOrRgb::Rgb(c)) => Ok(c),
        Err(_) => Err(serde::de::Error::custom(
            "expected a number or an array of three numbers [red, green, blue]",
        )),
    }
}
fn one_u32() -> u32 {
    1
}

/// Bound on |dn/dt_pre| · noise_scale / noise_amplitude for the growth noise (the unit 1D sparse
/// convolution noise's [`SparseConvolution1::MAX_SLOPE`]); keeps the time volume monotone
/// (notes/wood.md §2).
pub const GROWTH_NOISE_SLOPE_BOUND: f32 = SparseConvolution1::MAX_SLOPE;

struct Checker<'a> {
    file: &'a str,
}

impl Checker<'_> {
    fn range(&self, field: &str, v: f32, lo: f32, hi: f32) -> Result<(), WoodError> {
        if v.is_finite() && v >= lo && v <= hi {
            Ok(())
        } else {
            Err(self.err(field, v, format!("[{lo}, {hi}]")))
        }
    }
    fn positive(&self, field: &str, v: f32, hi: f32) -> Result<(), WoodError> {
        if v.is_finite() && v > 0.0 && v <= hi {
            Ok(())
        } else {
            Err(self.err(field, v, format!("(0, {hi}]")))
        }
    }
    fn err(&self, field: &str, v: impl std::fmt::Display, allowed: String) -> WoodError {
        WoodError::OutOfRange {
            file: self.file.to_string(),
            field: field.to_string(),
            value: v.to_string(),
            allowed,
        }
    }
    fn wander(&self, name: &str, w: &WanderScale) -> Result<(), WoodError> {
        self.range(&format!("{name}.radial"), w.radial, 0.0, 20.0)?;
        self.range(&format!("{name}.tangential"), w.tangential, 0.0, 20.0)?;
        self.range(&format!("{name}.along"), w.along, 0.05, 1000.0)?;
        self.range(&format!("{name}.across"), w.across, 0.02, 1000.0)?;
        if let Some(l) = w.tangential_along {
            self.range(&format!("{name}.tangential_along"), l, 0.05, 1000.0)?;
        }
        self.range(&format!("{name}.density"), w.density, 0.25, 16.0)
    }
    fn texture(&self, name: &str, t: &TextureParams) -> Result<(), WoodError> {
        self.range(&format!("{name}.path"), t.path, 0.0, 2.0)?;
        self.range(&format!("{name}.along"), t.along, 0.05, 1000.0)?;
        self.range(&format!("{name}.across"), t.across, 0.02, 1000.0)?;
        self.range(&format!("{name}.density"), t.density, 0.25, 16.0)
    }
    fn noise(&self, name: &str, n: &NoiseParams) -> Result<(), WoodError> {
        self.range(&format!("{name}.magnitude"), n.magnitude, 0.0, 100.0)?;
        for (i, s) in n.size.iter().enumerate() {
            self.range(&format!("{name}.size[{i}]"), *s, 0.01, 10_000.0)?;
        }
        self.positive(&format!("{name}.density"), n.density, 64.0)?;
        if !(1..=8).contains(&n.bands) {
            return Err(self.err(&format!("{name}.bands"), n.bands, "1..=8".into()));
        }
        self.range(&format!("{name}.size_factor"), n.size_factor, 0.02, 0.9)?;
        self.range(&format!("{name}.dropoff"), n.dropoff, 0.0, 4.0)
    }

    /// The growth wave, its phase warp and its noise: time stays monotone.
    fn growth(&self, g: &GrowthParams) -> Result<(), WoodError> {
        for (i, l) in g.wave.iter().enumerate() {
            self.range(&format!("growth.wave[{i}]"), *l, 0.0, 1000.0)?;
        }
        let [_, top, _, bottom] = g.wave;
        self.range("growth.wave[1] (top)", top, 0.01, 1000.0)?;
        self.range("growth.wave[3] (bottom)", bottom, 0.01, 1000.0)?;
        self.range("growth.amplitude", g.amplitude, 0.0, 1000.0)?;
        // Monotone time (notes/wood.md): the wave's steepest descent must stay below 1.
        let descent = SmoothTriangleWave::new(g.wave, g.amplitude).max_descent();
        if descent >= 0.95 {
            return Err(self.err(
                "growth.amplitude",
                g.amplitude,
                format!(
                    "small enough that the wave's steepest descent is < 0.95 (it is {descent:.3}; time would run backwards)"
                ),
            ));
        }
        // Phase warp: dt_pre/du = 1 + w′(v)(1 + a m′) ≥ 1 − s_down (1 + a · 2.5462/h) > 0.
        self.positive("growth.phase_scale", g.phase_scale, 1000.0)?;
        let max_phase = if descent > 0.0 {
            (0.95 * g.phase_scale * (1.0 / descent - 1.0) / GROWTH_NOISE_SLOPE_BOUND).min(1000.0)
        } else {
            1000.0
        };
        self.range("growth.phase_amplitude", g.phase_amplitude, 0.0, max_phase)?;
        self.positive("growth.noise_scale", g.noise_scale, 1000.0)?;
        let max_noise = 0.95 * g.noise_scale / GROWTH_NOISE_SLOPE_BOUND;
        self.range("growth.noise_amplitude", g.noise_amplitude, 0.0, max_noise)?;
        Ok(())
    }

    /// The vessels' sizes, density and depth.
    fn pores(&self, p: &PoreParams) -> Result<(), WoodError> {
        self.range("pores.radius", p.radius, 0.005, 5.0)?;
        self.range("pores.length", p.length, 0.005, 100.0)?;
        self.positive("pores.density", p.density, 16.0)?;
        self.range("pores.sharpness", p.sharpness, 0.05, 100.0)?;
        self.range("pores.ring_porosity", p.ring_porosity, 0.0, 1.0)?;
        self.range("pores.depth", p.depth, 0.0, 4.0)?;
        Ok(())
    }

    /// The rays' sizes, density, strength and wander.
    fn rays(&self, r: &RayParams) -> Result<(), WoodError> {
        self.range("rays.width", r.width, 0.005, 10.0)?;
        self.range("rays.height", r.height, 0.005, 100.0)?;
        self.range("rays.length", r.length, 0.005, 1000.0)?;
        self.positive("rays.density", r.density, 16.0)?;
        self.range("rays.sharpness", r.sharpness, 0.0, 100.0)?;
        self.range("rays.strength", r.strength, 0.0, 1.0)?;
        self.range("rays.wander", r.wander, 0.0, 10.0)?;
        self.range("rays.wander_length", r.wander_length, 0.05, 1000.0)?;
        Ok(())
    }

    /// The knots' whorls, cones and bark.
    fn knots(&self, k: &KnotParams) -> Result<(), WoodError> {
        self.range("knots.whorl_spacing", k.whorl_spacing, 10.0, 100_000.0)?;
        if !(1..=12).contains(&k.per_whorl) {
            return Err(self.err("knots.per_whorl", k.per_whorl, "1..=12".into()));
        }
        self.range("knots.rise", k.rise, 0.0, 80.0)?;
        self.range("knots.cone", k.cone, 0.5, 30.0)?;
        if let Some(d) = k.death_year {
            self.range("knots.death_year", d, 0.0, 1000.0)?;
        }
        self.range("knots.darkening", k.darkening, 0.0, 10.0)?;
        self.range("knots.swell", k.swell, 0.0, 50.0)?;
        self.range("knots.swell_width", k.swell_width, 0.5, 500.0)?;
        self.range("knots.bark_width", k.bark_width, 0.0, 20.0)?;
        Ok(())
    }

    /// The birdseye traces.
    fn eyes(&self, e: &EyeParams) -> Result<(), WoodError> {
        self.range("eyes.density", e.density, 0.0, 10.0)?;
        self.range("eyes.diameter[0]", e.diameter[0], 0.1, 50.0)?;
        self.range("eyes.diameter[1]", e.diameter[1], e.diameter[0], 50.0)?;
        self.range("eyes.depth", e.depth, 0.0, 20.0)?;
        self.range("eyes.length", e.length, 1.0, 1000.0)?;
        self.range("eyes.core", e.core, 0.01, 10.0)?;
        self.range("eyes.darkening", e.darkening, 0.0, 10.0)?;
        Ok(())
    }
}

impl WoodParams {
    /// The pore bump a scene gets when it names none: the pores at their anatomical depth
    /// ([`PoreParams::depth`], strength 1) where the grain is open ([`PoreParams::open`]), none
    /// where it is closed or has no pores (issue 28: Liu et al. 2016 §6.1.7 render open-pore
    /// woods with their pore bump).
    pub fn default_bump(&self) -> f32 {
        match &self.pores {
            Some(p) if p.open() => 1.0,
            _ => 0.0,
        }
    }

    /// Parse TOML text; `file` names the source in error messages.
    pub fn from_toml_str(text: &str, file: &str) -> Result<WoodParams, WoodError> {
        let params: WoodParams = toml::from_str(text).map_err(|e| WoodError::Parse {
            file: file.to_string(),
            message: e.to_string(),
        })?;
        params.validate(file)?;
        Ok(params)
    }

    /// Read and validate a parameter file (a regular file of at most
    /// [`MAX_SCENE_BYTES`](crate::resources::MAX_SCENE_BYTES), as scene files).
    pub fn from_toml_file(path: impl AsRef<Path>) -> Result<WoodParams, WoodError> {
        use crate::resources::{read_text_bounded, MAX_SCENE_BYTES};
        let path = path.as_ref();
        let text =
            read_text_bounded(path, MAX_SCENE_BYTES, "TOML text").map_err(|e| WoodError::Io {
                file: path.to_path_buf(),
                source: std::io::Error::other(e.reason()),
            })?;
        Self::from_toml_str(&text, &path.display().to_string())
    }

    /// Check every value against its allowed range; the error names `file`, the field and the range.
    pub fn validate(&self, file: &str) -> Result<(), WoodError> {
        let c = Checker { file };
        c.range("rings.width", self.rings.width, 0.05, 50.0)?;
        for (i, f) in self.rings.proportions.iter().enumerate() {
            c.range(&format!("rings.proportions[{i}]"), *f, 0.0, 1.0)?;
        }
        let [_, rise, _, fall] = self.rings.proportions;
        c.range("rings.proportions[1] (transition)", rise, 0.01, 1.0)?;
        c.range("rings.proportions[3] (fall)", fall, 0.01, 1.0)?;
        if let Some(g) = &self.growth {
            c.growth(g)?;
        }
        if let Some(i) = &self.interlock {
            c.range("interlock.angle", i.angle, 0.0, 45.0)?;
            c.positive("interlock.period", i.period, 10_000.0)?;
        }
        for (name, n) in [
            ("distortion.radial", &self.distortion.radial),
            ("distortion.tangential", &self.distortion.tangential),
            ("distortion.longitudinal", &self.distortion.longitudinal),
        ] {
            if let Some(n) = n {
                c.noise(name, n)?;
            }
        }
        if let Some(p) = &self.pores {
            c.pores(p)?;
        }
        if let Some(r) = &self.rays {
            c.rays(r)?;
        }
        for (name, col) in [
            ("color.earlywood", self.color.earlywood),
            ("color.latewood", self.color.latewood),
        ] {
            for (i, v) in col.iter().enumerate() {
                c.range(&format!("{name}[{i}]"), *v, 1e-4, 1.0)?;
            }
        }
        c.range("color.pore_path", self.color.pore_path, -1.0, 10.0)?;
        c.range("color.ray_path", self.color.ray_path, -1.0, 10.0)?;
        for (i, v) in self.color.fiber_saturation.iter().enumerate() {
            c.range(&format!("color.fiber_saturation[{i}]"), *v, 0.0, 2.0)?;
        }
        c.range("highlight.earlywood", self.highlight.earlywood, 0.5, 45.0)?;
        c.range("highlight.latewood", self.highlight.latewood, 0.5, 45.0)?;
        if let Some(w) = &self.fibre_wander {
            c.wander("fibre_wander", &w.coarse())?;
            if let Some(f) = &w.fine {
                c.wander("fibre_wander.fine", f)?;
            }
            c.range("fibre_wander.pore_deflection", w.pore_deflection, 0.0, 4.0)?;
        }
        if let Some(t) = &self.texture {
            c.texture("texture", t)?;
            if let Some(s) = &t.streaks {
                c.texture("texture.streaks", s)?;
                if s.streaks.is_some() {
                    return Err(c.err("texture.streaks.streaks", "a table", "absent".into()));
                }
            }
        }
        if let Some(k) = &self.knots {
            c.knots(k)?;
        }
        if let Some(e) = &self.eyes {
            c.eyes(e)?;
        }
        Ok(())
    }
}
