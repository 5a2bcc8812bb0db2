//! Wood from rings. Ring wood: concentric cylinders about a tilted axis, radius perturbed by
//! `n sin(m θ + v / k)` (sinusoidal angular wobble with a twist along the axis), light and dark
//! bands by the radius modulo the ring spacing (the HyperGraph notes on 3D texture mapping).
//! Log wood: the log-coordinate model of A. T. Jørgensen, "Procedural Solid Texturing" (DTU 02562
//! report, 2025), §2 "Procedural Wood": ring phase `f (r̃ + α r̃²)` for rings that thin
//! toward the bark, radius domain-warped by two noises `r̃ = r + β₁ N₁ + β₂ N₂`, longitudinal grain
//! from fBm of (axial position, angle), two colours and a low-frequency tint.

use super::marble::direction;
use super::params::{p, ParamSpec, Values};
use super::ramp::smoothstep;
use super::SolidTexture;
use crate::math::Frame;
use crate::noise::{gradient3, Fractal};
use glam::Vec3;
use std::f32::consts::TAU;

const DARK: Vec3 = Vec3::new(0.33, 0.17, 0.08);
const LIGHT: Vec3 = Vec3::new(0.62, 0.42, 0.22);

pub(crate) const RING_PARAMS: &[ParamSpec] = &[
    p(
        "ring_spacing",
        4.0,
        0.001,
        1e5,
        "distance between rings (mm)",
    ),
    p("latewood", 0.3, 0.0, 1.0, "dark fraction of each ring"),
    p(
        "wobble",
        0.4,
        0.0,
        1e4,
        "amplitude n of the angular perturbation (mm)",
    ),
    p("wobble_count", 20.0, 0.0, 1000.0, "waves m around the axis"),
    p(
        "twist",
        150.0,
        0.001,
        1e6,
        "k: the wobble advances one radian per k mm along the axis",
    ),
    p(
        "tilt",
        8.0,
        -90.0,
        90.0,
        "tilt of the axis away from z (degrees)",
    ),
    p(
        "edge",
        0.08,
        0.0,
        0.5,
        "softness of band edges (fraction of a ring)",
    ),
];

/// Concentric-cylinder ring wood.
pub(crate) struct RingWood {
    spacing: f32,
    latewood: f32,
    wobble: f32,
    count: f32,
    twist: f32,
    axes: Frame,
    edge: f32,
}

impl RingWood {
    pub(crate) fn new(v: &Values) -> Self {
        let tilt = v.get("tilt").to_radians();
        let axis = Vec3::new(tilt.sin(), 0.0, tilt.cos());
        RingWood {
            spacing: v.get("ring_spacing"),
            latewood: v.get("latewood"),
            wobble: v.get("wobble"),
            count: v.get("wobble_count"),
            twist: v.get("twist"),
            axes: Frame::from_normal_tangent(axis, Vec3::X),
            edge: v.get("edge").max(1e-4),
        }
    }
}

impl SolidTexture for RingWood {
    fn eval(&self, p: Vec3) -> Vec3 {
        let l = self.axes.to_local(p);
        let angle = l.y.atan2(l.x);
        let radius = (l.x * l.x + l.y * l.y).sqrt()
            + self.wobble * (self.count * angle + l.z / self.twist).sin();
        let f = (radius / self.spacing).rem_euclid(1.0);
        // Dark band on [1 − latewood, 1), smoothed at both edges (no hard aliasing steps).
        let start = 1.0 - self.latewood;
        let dark =
            smoothstep(start - self.edge, start, f) * (1.0 - smoothstep(1.0 - self.edge, 1.0, f));
        LIGHT.lerp(DARK, dark)
    }
}

pub(crate) const LOG_PARAMS: &[ParamSpec] = &[
    p(
        "ring_width",
        3.0,
        0.001,
        1e5,
        "ring width near the pith (mm): f = 2π / ring_width",
    ),
    p(
        "taper",
        0.004,
        0.0,
        10.0,
        "α in f (r + α r²): rings thin toward the bark (1/mm)",
    ),
    p(
        "warp",
        3.0,
        0.0,
        1e4,
        "β₁: radius displacement by coarse noise (mm)",
    ),
    p(
        "warp_fine",
        0.5,
        0.0,
        1e4,
        "β₂: radius displacement by fine noise (mm)",
    ),
    p(
        "warp_scale",
        40.0,
        0.01,
        1e5,
        "size of the coarse warp noise (mm)",
    ),
    p("grain", 0.2, 0.0, 1.0, "strength of the longitudinal grain"),
    p(
        "grain_length",
        20.0,
        0.01,
        1e5,
        "length of grain streaks along the axis (mm)",
    ),
    p(
        "grain_density",
        40.0,
        0.0,
        1e4,
        "grain streaks around the log (per radian)",
    ),
    p("tint", 0.1, 0.0, 1.0, "low-frequency tint variation"),
    p(
        "axis_x",
        0.0,
        -1.0,
        1.0,
        "log axis x (normalised; all zero means x)",
    ),
    p("axis_y", 0.0, -1.0, 1.0, "log axis y"),
    p("axis_z", 1.0, -1.0, 1.0, "log axis z"),
    p("seed", 1.0, 0.0, 1e9, "noise seed"),
];

/// Log-coordinate wood.
pub(crate) struct LogWood {
    freq: f32,
    taper: f32,
    warp: f32,
    warp_fine: f32,
    warp_scale: f32,
    grain: f32,
    grain_length: f32,
    grain_density: f32,
    tint: f32,
    axes: Frame,
    fbm: Fractal,
    seed: u32,
}

impl LogWood {
    pub(crate) fn new(v: &Values) -> Self {
        LogWood {
            freq: TAU / v.get("ring_width"),
            taper: v.get("taper"),
            warp: v.get("warp"),
            warp_fine: v.get("warp_fine"),
            warp_scale: v.get("warp_scale"),
            grain: v.get("grain"),
            grain_length: v.get("grain_length"),
            grain_density: v.get("grain_density"),
            tint: v.get("tint"),
            axes: Frame::from_normal(direction(v, "axis")),
            fbm: Fractal::fbm(4),
            seed: v.seed(),
        }
    }
}

impl SolidTexture for LogWood {
    fn eval(&self, p: Vec3) -> Vec3 {
        let l = self.axes.to_local(p);
        let r = (l.x * l.x + l.y * l.y).sqrt();
        let s = self.seed;
        let n1 = self.fbm.eval(p / self.warp_scale, s);
        let n2 = gradient3(p * (3.0 / self.warp_scale), s ^ 0x51);
        let rw = (r + self.warp * n1 + self.warp_fine * n2).max(0.0);
        let rings = 0.5 * (1.0 + (self.freq * (rw + self.taper * rw * rw)).sin());
        let sharp = smoothstep(0.25, 0.85, rings);
        // Grain: fBm stretched along the axis, on the unit circle around it (no seam at ±π).
        let around = if r > 0.0 {
            Vec3::new(l.x / r, l.y / r, 0.0)
        } else {
            Vec3::X
        };
        let g = self.fbm.eval(
            Vec3::new(
                around.x * self.grain_density,
                around.y * self.grain_density,
                l.z / self.grain_length,
            ),
            s ^ 0x52,
        );
        let grain = smoothstep(-0.3, 0.3, g);
        let tint = self.fbm.eval(p / 400.0, s ^ 0x53);
        DARK.lerp(LIGHT, sharp) * (1.0 + self.grain * (grain - 0.5)) * (1.0 + self.tint * tint)
    }
}
