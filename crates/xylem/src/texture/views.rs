//! Grey-scale views of the raw noises, so each can be looked at as a slice: gradient and value
//! noise, fBm / turbulence / ridged sums, Worley features, the domain warp (coloured by its q and r
//! fields as in Quilez, "Domain warping"), and sparse convolution noise (Liu 2016 §4).

use super::params::{p, ParamSpec, Values};
use super::ramp::{grey, Ramp};
use super::SolidTexture;
use crate::noise::hash::unit_f32;
use crate::noise::{
    cellular3, gradient3, gradient3_many, value3, Basis, Cells, Fractal, FractalKind, Kernel,
    SparseConvolution, Warp, Weights,
};
use glam::Vec3;

const SEED: ParamSpec = p("seed", 1.0, 0.0, 1e9, "noise seed");

pub(crate) const LATTICE_PARAMS: &[ParamSpec] = &[
    p("scale", 10.0, 1e-4, 1e6, "size of one lattice cell (mm)"),
    SEED,
];

/// Gradient or value noise, mapped from [−1, 1] to grey.
pub(crate) struct LatticeView {
    basis: Basis,
    scale: f32,
    seed: u32,
}

impl LatticeView {
    pub(crate) fn new(v: &Values, basis: Basis) -> Self {
        LatticeView {
            basis,
            scale: v.get("scale"),
            seed: v.seed(),
        }
    }
}

impl SolidTexture for LatticeView {
    fn eval(&self, p: Vec3) -> Vec3 {
        let q = p / self.scale;
        let n = match self.basis {
            Basis::Gradient => gradient3(q, self.seed),
            Basis::Value => value3(q, self.seed),
        };
        grey(0.5 + 0.5 * n)
    }

    fn eval_many(&self, points: &[Vec3], out: &mut [Vec3]) {
        let q: Vec<Vec3> = points.iter().map(|&p| p / self.scale).collect();
        let mut n = vec![0.0f32; q.len()];
        match self.basis {
            Basis::Gradient => gradient3_many(&q, self.seed, &mut n),
            Basis::Value => n
                .iter_mut()
                .zip(&q)
                .for_each(|(n, &q)| *n = value3(q, self.seed)),
        }
        for (o, n) in out.iter_mut().zip(n) {
            *o = grey(0.5 + 0.5 * n);
        }
    }
}

pub(crate) const FBM_PARAMS: &[ParamSpec] = &[
    p(
        "scale",
        30.0,
        1e-4,
        1e6,
        "size of the first octave's cell (mm)",
    ),
    p("octaves", 5.0, 1.0, 16.0, "number of octaves"),
    p(
        "lacunarity",
        2.0,
        1.0,
        8.0,
        "frequency ratio between octaves",
    ),
    p("gain", 0.5, 0.0, 1.0, "amplitude ratio between octaves"),
    p("kind", 0.0, 0.0, 2.0, "0: fBm, 1: turbulence, 2: ridged"),
    p("basis", 0.0, 0.0, 1.0, "0: gradient noise, 1: value noise"),
    SEED,
];

/// A fractal sum, normalised by its amplitude sum.
pub(crate) struct FbmView {
    fractal: Fractal,
    /// sqrt(Σ gain²ⁱ): the standard deviation of the sum in units of one octave's.
    rms_amplitude: f32,
    scale: f32,
    seed: u32,
}

impl FbmView {
    pub(crate) fn new(v: &Values) -> Self {
        let kind = match v.int("kind") {
            0 => FractalKind::Fbm,
            1 => FractalKind::Turbulence,
            _ => FractalKind::Ridged,
        };
        let basis = if v.int("basis") == 0 {
            Basis::Gradient
        } else {
            Basis::Value
        };
        let octaves = v.int("octaves");
        let rms_amplitude = (0..octaves)
            .map(|i| v.get("gain").powi(2 * i as i32))
            .sum::<f32>()
            .sqrt();
        FbmView {
            rms_amplitude,
            fractal: Fractal {
                kind,
                basis,
                octaves: v.int("octaves"),
                lacunarity: v.get("lacunarity"),
                gain: v.get("gain"),
            },
            scale: v.get("scale"),
            seed: v.seed(),
        }
    }
}

impl FbmView {
    /// The grey of a sum value `n`.
    fn shade(&self, n: f32) -> Vec3 {
        grey(match self.fractal.kind {
            // ±3σ to black / white: σ = σ_n sqrt(Σ gain²ⁱ), σ_n ≈ 0.286 (notes/noise.md).
            FractalKind::Fbm => 0.5 + n / (6.0 * 0.286 * self.rms_amplitude),
            _ => n / self.fractal.amplitude_sum(),
        })
    }
}

impl SolidTexture for FbmView {
    fn eval(&self, p: Vec3) -> Vec3 {
        self.shade(self.fractal.eval(p / self.scale, self.seed))
    }

    fn eval_many(&self, points: &[Vec3], out: &mut [Vec3]) {
        let q: Vec<Vec3> = points.iter().map(|&p| p / self.scale).collect();
        let mut n = vec![0.0f32; q.len()];
        self.fractal.eval_many(&q, self.seed, &mut n);
        for (o, n) in out.iter_mut().zip(n) {
            *o = self.shade(n);
        }
    }
}

pub(crate) const WORLEY_PARAMS: &[ParamSpec] = &[
    p("scale", 10.0, 1e-4, 1e6, "cell size (mm)"),
    p("jitter", 1.0, 0.0, 1.0, "feature-point randomness"),
    p(
        "feature",
        0.0,
        0.0,
        3.0,
        "0: F1, 1: F2, 2: F2 − F1, 3: cell id",
    ),
    SEED,
];

pub(crate) struct WorleyView {
    scale: f32,
    jitter: f32,
    feature: u32,
    seed: u32,
}

impl WorleyView {
    pub(crate) fn new(v: &Values) -> Self {
        WorleyView {
            scale: v.get("scale"),
            jitter: v.get("jitter"),
            feature: v.int("feature"),
            seed: v.seed(),
        }
    }
}

impl SolidTexture for WorleyView {
    fn eval(&self, p: Vec3) -> Vec3 {
        let c = cellular3(p / self.scale, self.jitter, self.seed);
        match self.feature {
            0 => grey(c.f1),
            1 => grey(c.f2 / 1.5),
            2 => grey(c.edge() * 2.0),
            _ => Vec3::new(
                unit_f32(c.id),
                unit_f32(c.id.rotate_left(11)),
                unit_f32(c.id.rotate_left(22)),
            ),
        }
    }
}

pub(crate) const WARP_PARAMS: &[ParamSpec] = &[
    p("scale", 60.0, 1e-4, 1e6, "size of one noise unit (mm)"),
    p("strength", 1.0, 0.0, 100.0, "displacement s"),
    p("levels", 2.0, 1.0, 2.0, "1: F(p + s q); 2: F(p + s r)"),
    p("octaves", 4.0, 1.0, 12.0, "fBm octaves"),
    SEED,
];

pub(crate) struct WarpView {
    warp: Warp,
    scale: f32,
    seed: u32,
    ramp: Ramp,
}

impl WarpView {
    pub(crate) fn new(v: &Values) -> Self {
        WarpView {
            warp: Warp {
                fractal: Fractal::fbm(v.int("octaves")),
                strength: v.get("strength"),
                levels: v.int("levels"),
            },
            scale: v.get("scale"),
            seed: v.seed(),
            ramp: Ramp::new(&[
                (0.0, Vec3::new(0.02, 0.05, 0.12)),
                (0.45, Vec3::new(0.10, 0.38, 0.45)),
                (0.7, Vec3::new(0.75, 0.62, 0.35)),
                (1.0, Vec3::new(0.95, 0.92, 0.85)),
            ]),
        }
    }
}

impl SolidTexture for WarpView {
    fn eval(&self, p: Vec3) -> Vec3 {
        let s = self.warp.sample(p / self.scale, self.seed);
        let base = self.ramp.eval(0.5 + 1.2 * s.value);
        // Quilez tints by the warp fields: |q| darkens, r.x shifts toward blue.
        base * (1.0 - 0.3 * s.q.length().min(1.0))
            + Vec3::new(0.0, 0.0, 0.15) * s.r.x.abs().min(1.0)
    }
}

pub(crate) const SPARSE_PARAMS: &[ParamSpec] = &[
    p(
        "kernel",
        0.0,
        0.0,
        1.0,
        "0: Wyvill (1 − r²)³, 1: bump exp(−s r²/(1 − r²))",
    ),
    p("sharpness", 1.0, 0.0, 100.0, "bump sharpness s"),
    p(
        "density",
        4.0,
        0.001,
        50.0,
        "mean kernels overlapping a point",
    ),
    p(
        "envelope_x",
        4.0,
        1e-4,
        1e6,
        "kernel semi-axis x or radial (mm)",
    ),
    p(
        "envelope_y",
        4.0,
        1e-4,
        1e6,
        "kernel semi-axis y or tangential (mm)",
    ),
    p("envelope_z", 4.0, 1e-4, 1e6, "kernel semi-axis z (mm)"),
    p(
        "cell_scale",
        1.0,
        0.1,
        10.0,
        "cell size as a multiple of the envelope",
    ),
    p(
        "cylindrical",
        0.0,
        0.0,
        1.0,
        "1: cylindrical cells about the z axis (Liu §4.2)",
    ),
    p(
        "signed",
        0.0,
        0.0,
        1.0,
        "1: impulse weights uniform in [−1, 1]",
    ),
    p("bands", 1.0, 1.0, 8.0, "number of bands"),
    p("size_factor", 0.5, 0.05, 1.0, "β: size ratio between bands"),
    p("dropoff", 1.0, 0.0, 4.0, "γ: band i has magnitude β^(γ i)"),
    SEED,
];

pub(crate) struct SparseView {
    noise: SparseConvolution,
    seed: u32,
    /// Display mapping: value ↦ offset + gain · value.
    offset: f32,
    gain: f32,
}

impl SparseView {
    pub(crate) fn new(v: &Values) -> Self {
        let envelope = Vec3::new(
            v.get("envelope_x"),
            v.get("envelope_y"),
            v.get("envelope_z"),
        );
        let signed = v.int("signed") == 1;
        let noise = SparseConvolution {
            kernel: if v.int("kernel") == 0 {
                Kernel::Wyvill
            } else {
                Kernel::Bump {
                    sharpness: v.get("sharpness"),
                }
            },
            density: v.get("density"),
            envelope,
            cell: envelope * v.get("cell_scale"),
            magnitude: 1.0,
            weights: if signed {
                Weights::Signed
            } else {
                Weights::Unit
            },
            cells: if v.int("cylindrical") == 1 {
                Cells::Cylindrical
            } else {
                Cells::Cartesian
            },
            bands: v.int("bands"),
            size_factor: v.get("size_factor"),
            dropoff: v.get("dropoff"),
        };
        // Campbell moments of one Wyvill band (notes/noise.md) set the grey scale: ±3σ.
        let sd = (noise.density * 1024.0 / 15015.0).sqrt();
        let (offset, gain) = if signed {
            (0.5, 0.5 / (3.0 * sd / 3f32.sqrt()))
        } else {
            (0.0, 1.0 / (noise.density * 48.0 / 315.0 + 3.0 * sd))
        };
        SparseView {
            noise,
            seed: v.seed(),
            offset,
            gain,
        }
    }

    /// Parameters that the declaration ranges cannot check on their own (impulses per cell).
    pub(crate) fn noise(&self) -> &SparseConvolution {
        &self.noise
    }
}

impl SolidTexture for SparseView {
    fn eval(&self, p: Vec3) -> Vec3 {
        grey(self.offset + self.gain * self.noise.eval(p, self.seed))
    }
}
