//! Cellular stone: Worley cells (Worley 1996) give each stone its own tone (from the cell id),
//! F2 − F1 gives the cracks between them, and two layers of noise (fBm mottling and fine value
//! noise) texture the faces — the layered-cellular construction of Ebert et al., *Texturing and
//! Modeling* 3rd ed., ch. 4 ("cellular texturing" of flagstones).

use super::params::{p, ParamSpec, Values};
use super::ramp::{smoothstep, Ramp};
use super::SolidTexture;
use crate::noise::hash::unit_f32;
use crate::noise::{cellular3, value3, Fractal};
use glam::Vec3;

pub(crate) const STONE_PARAMS: &[ParamSpec] = &[
    p("cell_size", 12.0, 0.01, 1e5, "mean stone size (mm)"),
    p(
        "jitter",
        1.0,
        0.0,
        1.0,
        "randomness of the stone layout (0: a regular grid)",
    ),
    p(
        "crack_width",
        0.06,
        0.0,
        1.0,
        "crack half-width in units of the cell size",
    ),
    p("crack_depth", 0.8, 0.0, 1.0, "darkening inside a crack"),
    p("mottling", 0.35, 0.0, 1.0, "strength of the fBm mottling"),
    p("seed", 1.0, 0.0, 1e9, "noise seed"),
];

pub(crate) struct Stone {
    cell: f32,
    jitter: f32,
    crack: f32,
    depth: f32,
    mottling: f32,
    fbm: Fractal,
    seed: u32,
    tones: Ramp,
}

impl Stone {
    pub(crate) fn new(v: &Values) -> Self {
        Stone {
            cell: v.get("cell_size"),
            jitter: v.get("jitter"),
            crack: v.get("crack_width"),
            depth: v.get("crack_depth"),
            mottling: v.get("mottling"),
            fbm: Fractal::fbm(5),
            seed: v.seed(),
            tones: Ramp::new(&[
                (0.0, Vec3::new(0.30, 0.28, 0.26)),
                (0.4, Vec3::new(0.45, 0.40, 0.34)),
                (0.7, Vec3::new(0.55, 0.53, 0.50)),
                (1.0, Vec3::new(0.38, 0.36, 0.40)),
            ]),
        }
    }
}

impl SolidTexture for Stone {
    fn eval(&self, p: Vec3) -> Vec3 {
        let q = p / self.cell;
        let c = cellular3(q, self.jitter, self.seed);
        let tone = self.tones.eval(unit_f32(c.id));
        let mottle = 1.0 + self.mottling * self.fbm.eval(q * 3.0, self.seed ^ 0x71);
        let fine = 1.0 + 0.08 * value3(q * 40.0, self.seed ^ 0x72);
        let crack = 1.0 - smoothstep(0.0, self.crack.max(1e-4), c.edge());
        (tone * mottle * fine * (1.0 - self.depth * crack)).max(Vec3::ZERO)
    }
}
