//! Rust: corrosion patches from an aggressively domain-warped fBm (two warp levels, large
//! displacement), mapped through several colour stops from bare steel through dark scale to
//! bright orange oxide ("Procedural Textures: wood, marble and beyond", the rust example: "aggressive
//! domain warping … multiple colour stops and noise-driven transitions"; the warp is Quilez's,
//! "Domain warping"). `time` moves the warp coordinates (not the final lookup), so the patches
//! flow and re-form rather than slide (the same article's advice for animation).

use super::params::{p, ParamSpec, Values};
use super::ramp::{smoothstep, Ramp};
use super::SolidTexture;
use crate::noise::{Fractal, Warp};
use glam::Vec3;

pub(crate) const RUST_PARAMS: &[ParamSpec] = &[
    p("scale", 30.0, 0.01, 1e5, "size of one noise unit (mm)"),
    p(
        "strength",
        3.0,
        0.0,
        100.0,
        "warp displacement s (aggressive: 3)",
    ),
    p("octaves", 5.0, 1.0, 12.0, "fBm octaves"),
    p(
        "coverage",
        0.6,
        0.0,
        1.0,
        "fraction of the surface rusted, roughly",
    ),
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

pub struct Rust {
    scale: f32,
    warp: Warp,
    coverage: f32,
    drift: Vec3,
    ramp: Ramp,
    seed: u32,
}

impl Rust {
    pub(crate) fn new(v: &Values) -> Self {
        Rust {
            scale: v.get("scale"),
            warp: Warp {
                fractal: Fractal::fbm(v.int("octaves")),
                strength: v.get("strength"),
                levels: 2,
            },
            coverage: v.get("coverage"),
            drift: super::drift(v),
            ramp: Ramp::new(&[
                (0.0, Vec3::new(0.22, 0.12, 0.06)),
                (0.35, Vec3::new(0.35, 0.12, 0.04)),
                (0.7, Vec3::new(0.55, 0.22, 0.05)),
                (1.0, Vec3::new(0.72, 0.38, 0.12)),
            ]),
            seed: v.seed(),
        }
    }
}

/// Bare steel, where the rust has not reached.
pub(crate) const STEEL: Vec3 = Vec3::new(0.42, 0.43, 0.45);

impl SolidTexture for Rust {
    fn eval(&self, p: Vec3) -> Vec3 {
        let s = self
            .warp
            .sample_drifting(p / self.scale, self.drift, self.seed);
        // fBm of gradient noise has σ ≈ 0.33; map ±2σ to [0, 1].
        let v = (0.5 + 0.75 * s.value).clamp(0.0, 1.0);
        // The edge runs from just above 1 (coverage 0: no rust) to just below 0 (coverage 1).
        let edge = 1.05 - 1.1 * self.coverage;
        let rusted = smoothstep(edge - 0.05, edge + 0.05, v);
        // The oxide's state follows the second warp field, so the stops break up the patches.
        let state = (0.5 + 0.6 * s.r.x).clamp(0.0, 1.0);
        STEEL.lerp(self.ramp.eval(state), rusted)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::by_name;
    use std::collections::BTreeMap;

    fn tex(name: &str, params: &[(&str, f32)]) -> Box<dyn SolidTexture> {
        let map: BTreeMap<String, f32> = params.iter().map(|(k, v)| (k.to_string(), *v)).collect();
        by_name(name, &map).unwrap()
    }

    fn points() -> impl Iterator<Item = Vec3> {
        (0..200).map(|i| Vec3::new(i as f32 * 3.7, (i * 7 % 13) as f32 * 5.1, 2.0))
    }

    #[test]
    fn coverage_bounds_the_rust() {
        // Coverage 0: bare steel everywhere; coverage 1: nowhere.
        let none = tex("rust", &[("coverage", 0.0)]);
        let all = tex("rust", &[("coverage", 1.0)]);
        for p in points() {
            assert_eq!(none.eval(p), STEEL, "{p}");
            assert_ne!(all.eval(p), STEEL, "{p}");
        }
    }

    #[test]
    fn time_drifts_the_warp_coordinates() {
        // The warp fields at time t are the fields at p + drift: exactly, by construction.
        let warp = Warp {
            fractal: Fractal::fbm(4),
            strength: 3.0,
            levels: 2,
        };
        let d = Vec3::new(0.3, -0.2, 0.1);
        for p in points() {
            let p = p / 30.0;
            assert_eq!(warp.sample_drifting(p, d, 5).q, warp.sample(p + d, 5).q);
        }
        // Time 0 is the still texture; a later time changes the colour wherever it depends on the
        // warp: at least half the points (clear sky and bare steel stay as they are; with cover
        // 0.45 and coverage 0.6 those are under half of the surface).
        for name in crate::texture::ANIMATED {
            let still = tex(name, &[]);
            let t0 = tex(name, &[("time", 0.0)]);
            let t1 = tex(name, &[("time", 20.0)]);
            let moved = points().filter(|&p| t1.eval(p) != still.eval(p)).count();
            assert!(points().all(|p| t0.eval(p) == still.eval(p)), "{name}");
            assert!(moved >= 100, "{name}: {moved} of 200 moved");
        }
    }

    #[test]
    fn fabric_alternates_warp_and_weft() {
        // Thread pitch 1.5 mm, no fuzz: at the middle of cell (0, 0) the warp is on top and at
        // the crest of its profile (sin(π/2) = 1); the next cell along x shows the weft.
        let f = tex("fabric", &[("thread", 1.5), ("fuzz", 0.0)]);
        let warp = f.eval(Vec3::new(0.75, 0.75, 0.0));
        let weft = f.eval(Vec3::new(2.25, 0.75, 0.0));
        assert!(
            (warp - crate::texture::fabric::WARP).length() < 1e-6,
            "{warp}"
        );
        assert!(
            (weft - crate::texture::fabric::WEFT).length() < 1e-6,
            "{weft}"
        );
        // At a thread's edge the profile goes to zero (the dark gap between threads).
        assert!(f.eval(Vec3::new(1.5 - 1e-4, 0.75, 0.0)).length() < 0.05);
    }
}
