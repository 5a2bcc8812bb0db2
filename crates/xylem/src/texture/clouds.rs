//! Clouds: warped fBm (the q / r domain warp of Quilez, "Domain warping"), thresholded into cover
//! over a sky colour, with the warp field q shading the cloud bodies (Quilez's colouring by |q|).
//! `time` drifts the warp coordinates, so the clouds billow as they move ("Procedural Textures:
//! wood, marble and beyond": "the warp coordinates themselves are animated").

use super::params::{p, ParamSpec, Values};
use super::ramp::smoothstep;
use super::SolidTexture;
use crate::noise::{Fractal, Warp};
use glam::Vec3;

pub(crate) const CLOUD_PARAMS: &[ParamSpec] = &[
    p("scale", 80.0, 0.01, 1e5, "size of one noise unit (mm)"),
    p("strength", 1.0, 0.0, 100.0, "warp displacement s"),
    p("octaves", 5.0, 1.0, 12.0, "fBm octaves"),
    p(
        "cover",
        0.45,
        0.0,
        1.0,
        "fraction of the sky covered, roughly",
    ),
    p("softness", 0.35, 0.001, 1.0, "width of the cloud edge"),
    p("time", 0.0, -1e6, 1e6, "animation time (s)"),
    p(
        "flow",
        0.05,
        0.0,
        100.0,
        "speed of the warp coordinates (noise units per s)",
    ),
    p("seed", 1.0, 0.0, 1e9, "noise seed"),
];

pub(crate) struct Clouds {
    scale: f32,
    warp: Warp,
    cover: f32,
    softness: f32,
    drift: Vec3,
    seed: u32,
}

impl Clouds {
    pub(crate) fn new(v: &Values) -> Self {
        Clouds {
            scale: v.get("scale"),
            warp: Warp {
                fractal: Fractal::fbm(v.int("octaves")),
                strength: v.get("strength"),
                levels: 2,
            },
            cover: v.get("cover"),
            softness: v.get("softness"),
            drift: super::drift(v),
            seed: v.seed(),
        }
    }
}

impl SolidTexture for Clouds {
    fn eval(&self, p: Vec3) -> Vec3 {
        let s = self
            .warp
            .sample_drifting(p / self.scale, self.drift, self.seed);
        // fBm of gradient noise has σ ≈ 0.33; map ±2σ to [0, 1].
        let v = 0.5 + 0.75 * s.value;
        let edge = 1.0 - self.cover;
        let c = smoothstep(edge - 0.5 * self.softness, edge + 0.5 * self.softness, v);
        let sky = Vec3::new(0.16, 0.32, 0.75);
        let shade = 1.0 - 0.35 * smoothstep(0.0, 0.8, s.q.length());
        sky.lerp(Vec3::splat(0.95) * shade, c)
    }
}
