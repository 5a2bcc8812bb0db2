//! Property tests of the wood BSDF over random valid parameters and directions: values are
//! finite and non-negative, eval is reciprocal, samples agree with eval/pdf, and the directional
//! albedo never exceeds 1 (Monte Carlo, bound 1 + 4σ + 0.005, i.e. significance ≈ 3e-5 per
//! channel). Proptest runs from a fixed seed (RngSeed::Fixed), so the test is deterministic.

use glam::{Vec2, Vec3};
use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use xylem::bsdf::{Bsdf, Glass, Mirror, WoodBsdf, WoodBsdfParams};
use xylem::math::Pcg32;

fn unit() -> impl Strategy<Value = f32> {
    0.0f32..=1.0
}

fn colour() -> impl Strategy<Value = Vec3> {
    (unit(), unit(), unit()).prop_map(|(a, b, c)| Vec3::new(a, b, c))
}

fn direction() -> impl Strategy<Value = Vec3> {
    (-1.0f32..=1.0, 0.0f32..std::f32::consts::TAU).prop_map(|(z, phi)| {
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    })
}

fn upper() -> impl Strategy<Value = Vec3> {
    (0.0f32..=1.0, 0.0f32..std::f32::consts::TAU).prop_map(|(z, phi)| {
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    })
}

fn params() -> impl Strategy<Value = WoodBsdfParams> {
    (
        colour(),
        colour(),
        direction(),
        direction(),
        unit(),
        0.002f32..1.5,
        1.0f32..2.6,
        prop_oneof![Just(0.0f32), 0.0f32..=1.0],
    )
        .prop_map(
            |(diffuse, fiber_color, fiber_dir, ray_dir, ray_mask, beta, eta, roughness)| {
                WoodBsdfParams {
                    diffuse,
                    fiber_color,
                    fiber_dir,
                    ray_dir,
                    ray_mask,
                    highlight_width: beta,
                    eta,
                    roughness,
                }
            },
        )
}

fn ok(v: Vec3) -> bool {
    v.is_finite() && v.min_element() >= 0.0
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, failure_persistence: None, rng_seed: RngSeed::Fixed(2005), ..ProptestConfig::default() })]

    #[test]
    fn values_are_finite_non_negative_and_reciprocal(p in params(), a in direction(), b in direction(),
                                                     uc in unit(), u in (unit(), unit())) {
        let bsdf = WoodBsdf::new(p).unwrap();
        let (f1, f2) = (bsdf.eval(a, b), bsdf.eval(b, a));
        prop_assert!(ok(f1) && ok(f2));
        let m = f1.max(f2).max_element();
        prop_assert!((f1 - f2).abs().max_element() <= 1e-4 * m.max(1e-6), "{} {}", f1, f2);
        let pdf = bsdf.pdf(a, b);
        prop_assert!(pdf.is_finite() && pdf >= 0.0);
        if let Some(s) = bsdf.sample(a, uc.min(0.999_999_9), Vec2::new(u.0.min(0.999_999_9), u.1.min(0.999_999_9))) {
            prop_assert!(ok(s.f) && s.pdf.is_finite() && s.pdf > 0.0 && s.wi.is_finite());
            prop_assert!((s.wi.length() - 1.0).abs() < 1e-4);
            if !s.is_delta {
                let (f, q) = (bsdf.eval(a, s.wi), bsdf.pdf(a, s.wi));
                prop_assert!((f - s.f).abs().max_element() <= 1e-4 * f.max_element().max(1e-6));
                prop_assert!((q - s.pdf).abs() <= 1e-4 * q);
            }
        }
    }

    #[test]
    fn specular_bsdfs_are_finite(eta in 1.0f32..3.0, wo in direction(), uc in unit()) {
        let g = Glass::new(eta);
        if let Some(s) = g.sample(wo, uc, Vec2::ZERO) {
            prop_assert!(ok(s.f) && s.pdf > 0.0 && s.pdf <= 1.0 + 1e-6 && s.is_delta);
        }
        let m = Mirror { reflectance: Vec3::ONE };
        if let Some(s) = m.sample(wo, uc, Vec2::ZERO) {
            prop_assert!(ok(s.f) && s.wi.z == wo.z);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, failure_persistence: None, rng_seed: RngSeed::Fixed(2005), ..ProptestConfig::default() })]

    #[test]
    fn albedo_never_exceeds_one(p in params(), wo in upper(), seed in 0u64..1000) {
        let bsdf = WoodBsdf::new(p).unwrap();
        let mut rng = Pcg32::new(seed, 7);
        let n = 20_000;
        let (mut s, mut s2) = (Vec3::ZERO.as_dvec3(), Vec3::ZERO.as_dvec3());
        for _ in 0..n {
            if let Some(x) = bsdf.sample(wo, rng.next_f32(), rng.next_vec2()) {
                let w = (x.f * x.wi.z / x.pdf).as_dvec3();
                s += w;
                s2 += w * w;
            }
        }
        let mean = s / n as f64;
        let sigma = ((s2 / n as f64 - mean * mean).max(glam::DVec3::ZERO) / n as f64).powf(0.5);
        for c in 0..3 {
            prop_assert!(mean[c] <= 1.0 + 4.0 * sigma[c] + 0.005, "channel {}: {} ± {}", c, mean[c], sigma[c]);
        }
    }
}
