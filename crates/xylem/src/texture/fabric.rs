//! Fabric: a plain weave of warp threads (along y) and weft threads (along x) on the xy plane,
//! from high-frequency sines: each thread is shaded by sin(π·u) across it (its round profile),
//! and which thread lies on top switches every half period, checkerwise ("Procedural Textures:
//! wood, marble and beyond", the fabric example: "high-frequency sine waves … checking which half
//! of a period we are in, switching between horizontal and vertical emphasis"). Value noise
//! along each thread adds its fuzz.

use super::params::{p, ParamSpec, Values};
use super::SolidTexture;
use crate::noise::gradient3;
use glam::Vec3;

pub(crate) const FABRIC_PARAMS: &[ParamSpec] = &[
    p(
        "thread",
        1.5,
        0.001,
        1e5,
        "thread pitch (mm): one warp and one weft thread per pitch",
    ),
    p(
        "fuzz",
        0.15,
        0.0,
        1.0,
        "brightness variation along a thread",
    ),
    p("seed", 1.0, 0.0, 1e9, "noise seed"),
];

/// Thread colours (linear RGB): a red warp and a cream weft.
pub(crate) const WARP: Vec3 = Vec3::new(0.45, 0.06, 0.05);
pub(crate) const WEFT: Vec3 = Vec3::new(0.7, 0.62, 0.45);

pub(crate) struct Fabric {
    thread: f32,
    fuzz: f32,
    seed: u32,
}

impl Fabric {
    pub(crate) fn new(v: &Values) -> Self {
        Fabric {
            thread: v.get("thread"),
            fuzz: v.get("fuzz"),
            seed: v.seed(),
        }
    }
}

impl SolidTexture for Fabric {
    fn eval(&self, p: Vec3) -> Vec3 {
        let (u, v) = (p.x / self.thread, p.y / self.thread);
        // The warp is on top in cells where the two half-period indices have equal parity.
        let warp_on_top = ((u.floor() + v.floor()) as i64).rem_euclid(2) == 0;
        let (across, along, colour, lane) = if warp_on_top {
            (u, v, WARP, u.floor())
        } else {
            (v, u, WEFT, v.floor() + 0.5)
        };
        let profile = (std::f32::consts::PI * (across - across.floor()))
            .sin()
            .max(0.0)
            .sqrt();
        let fuzz = 1.0 + self.fuzz * gradient3(Vec3::new(lane * 7.31, along * 4.0, 0.0), self.seed);
        colour * profile * fuzz.max(0.0)
    }
}
