//! Marble. Sine-band marble: `½(1 + sin(ω x + γ T(p)))` with x along a vein direction and T a
//! turbulence sum remapped to [−1, 1], a smooth threshold and a multi-stop ramp (Perlin 1985, "An
//! Image Synthesizer", SIGGRAPH; in the form of A. T. Jørgensen, "Procedural Solid Texturing",
//! DTU 02562 report, 2025, §2 "Procedural Marble"). Slab marble: white / grey / black slabs of widths 4 / 5 / 3 / 5 (of a
//! 17-unit period) displaced by turbulence, with per-slab intensity noise and the (0.9, 0.8, 0.6)
//! tint (the HyperGraph notes on 3D texture mapping).

use super::params::{p, ParamSpec, Values};
use super::ramp::{smoothstep, Ramp};
use super::SolidTexture;
use crate::noise::{gradient3, Fractal, FractalKind};
use glam::Vec3;

pub(crate) const MARBLE_PARAMS: &[ParamSpec] = &[
    p("scale", 25.0, 0.01, 1e5, "size of one noise unit (mm)"),
    p(
        "frequency",
        5.0,
        0.0,
        1000.0,
        "band frequency ω (radians per noise unit along the vein direction)",
    ),
    p("distortion", 3.0, 0.0, 1000.0, "turbulence gain γ"),
    p("octaves", 5.0, 1.0, 12.0, "turbulence octaves"),
    p(
        "dir_x",
        0.2,
        -1.0,
        1.0,
        "vein direction x (normalised; all zero means x)",
    ),
    p("dir_y", 0.6, -1.0, 1.0, "vein direction y"),
    p("dir_z", 0.77, -1.0, 1.0, "vein direction z"),
    p(
        "threshold_low",
        0.0,
        0.0,
        1.0,
        "smooth threshold start (veins below)",
    ),
    p(
        "threshold_high",
        0.12,
        0.0,
        1.0,
        "smooth threshold end (raised above the start if needed)",
    ),
    p("seed", 1.0, 0.0, 1e9, "noise seed"),
];

/// Sine-band marble.
pub(crate) struct Marble {
    scale: f32,
    frequency: f32,
    distortion: f32,
    dir: Vec3,
    turbulence: Fractal,
    low: f32,
    high: f32,
    seed: u32,
    ramp: Ramp,
}

/// A unit direction from three parameters; +x when they are all zero.
pub(crate) fn direction(v: &Values, prefix: &str) -> Vec3 {
    let d = Vec3::new(
        v.get(&format!("{prefix}_x")),
        v.get(&format!("{prefix}_y")),
        v.get(&format!("{prefix}_z")),
    );
    d.try_normalize().unwrap_or(Vec3::X)
}

impl Marble {
    pub(crate) fn new(v: &Values) -> Self {
        let low = v.get("threshold_low");
        Marble {
            scale: v.get("scale"),
            frequency: v.get("frequency"),
            distortion: v.get("distortion"),
            dir: direction(v, "dir"),
            turbulence: Fractal {
                kind: FractalKind::Turbulence,
                octaves: v.int("octaves"),
                ..Default::default()
            },
            low,
            high: v.get("threshold_high").max(low + 1e-3),
            seed: v.seed(),
            ramp: Ramp::new(&[
                (0.0, Vec3::new(0.06, 0.06, 0.08)),
                (0.25, Vec3::new(0.30, 0.30, 0.34)),
                (0.6, Vec3::new(0.72, 0.72, 0.74)),
                (1.0, Vec3::new(0.90, 0.90, 0.92)),
            ]),
        }
    }
}

impl SolidTexture for Marble {
    fn eval(&self, p: Vec3) -> Vec3 {
        let q = p / self.scale;
        // Turbulence is in [0, Σ gainⁱ · max|n|]; normalise to about [0, 1], remap to [−1, 1].
        let t = self.turbulence.eval(q, self.seed) / self.turbulence.amplitude_sum();
        let t = 2.0 * t.min(1.0) - 1.0;
        let bands = 0.5 * (1.0 + (self.frequency * q.dot(self.dir) + self.distortion * t).sin());
        self.ramp.eval(smoothstep(self.low, self.high, bands))
    }
}

pub(crate) const SLAB_PARAMS: &[ParamSpec] = &[
    p(
        "stripe",
        2.0,
        0.001,
        1e5,
        "width of one stripe unit (mm); a period is 17 units",
    ),
    p("scale", 40.0, 0.01, 1e5, "size of one turbulence unit (mm)"),
    p(
        "turbulence",
        7.0,
        0.0,
        1000.0,
        "displacement by turbulence, in stripe units",
    ),
    p(
        "dir_x",
        1.0,
        -1.0,
        1.0,
        "stripe normal x (normalised; all zero means x)",
    ),
    p("dir_y", 0.0, -1.0, 1.0, "stripe normal y"),
    p("dir_z", 0.0, -1.0, 1.0, "stripe normal z"),
    p("seed", 1.0, 0.0, 1e9, "noise seed"),
];

/// The classic three-stripe slab marble.
pub(crate) struct SlabMarble {
    stripe: f32,
    scale: f32,
    turbulence: f32,
    dir: Vec3,
    sum: Fractal,
    seed: u32,
}

impl SlabMarble {
    pub(crate) fn new(v: &Values) -> Self {
        SlabMarble {
            stripe: v.get("stripe"),
            scale: v.get("scale"),
            turbulence: v.get("turbulence"),
            dir: direction(v, "dir"),
            sum: Fractal {
                kind: FractalKind::Turbulence,
                octaves: 5,
                ..Default::default()
            },
            seed: v.seed(),
        }
    }
}

impl SolidTexture for SlabMarble {
    fn eval(&self, p: Vec3) -> Vec3 {
        let q = p / self.scale;
        let t = self.sum.eval(q, self.seed) / self.sum.amplitude_sum();
        let d = p.dot(self.dir) / self.stripe + self.turbulence * t;
        let dd = d.rem_euclid(17.0);
        // Intensity noise in [0, 1] at two scales (HyperGraph's noise(u/70 …), noise(u/100 …)).
        let n = |s: f32, k: u32| 0.5 + 0.5 * gradient3(p / (s * self.stripe), self.seed ^ k);
        let i = if dd < 4.0 {
            0.7 + 0.2 * n(35.0, 11)
        } else if !(9.0..12.0).contains(&dd) {
            // Grey slabs brighten toward the white ones: |dd − 10.5| / 6.5 in [0, 1].
            0.4 + 0.3 * ((dd - 10.5).abs() / 6.5) + 0.2 * n(50.0, 12)
        } else {
            0.2 + 0.2 * n(50.0, 13)
        };
        Vec3::new(0.9, 0.8, 0.6) * i
    }
}
