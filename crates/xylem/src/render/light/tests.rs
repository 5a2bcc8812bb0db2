//! Lights against their closed forms: sampling densities, hits, the environment map.

use super::sphere::one_minus_cos_cone;
use super::*;
use crate::math::uniform_sphere;

#[test]
fn cone_of_a_tiny_sphere_keeps_its_solid_angle() {
    // Against the Taylor series 1 − √(1 − s) = s/2 + s²/8 + s³/16 + 5s⁴/128 + O(s⁵) in f64
    // (truncation below 1e-18 relative for s ≤ 4e-4), from a 1 mm sphere at 50 mm down to a
    // 1e-4 mm one: relative error within 1e-6, where the f32 form was off by up to 100 %.
    for r in [1.0f64, 0.1, 0.01, 1e-3, 1e-4] {
        let s = (r / 50.0).powi(2);
        let want = s / 2.0 + s * s / 8.0 + s.powi(3) / 16.0 + 5.0 * s.powi(4) / 128.0;
        let got = one_minus_cos_cone(s as f32) as f64;
        assert!(
            (got - want).abs() <= 1e-6 * want,
            "r = {r}: {got} vs {want}"
        );
    }
    assert_eq!(one_minus_cos_cone(1.0), 1.0);
}
use crate::math::Pcg32;

#[test]
fn sampled_pdf_matches_hit_pdf() {
    let lights = [
        Light::Rect(RectLight::new(
            Vec3::new(-1.0, -1.0, 5.0),
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(3.0, 0.0, 0.0),
            Vec3::ONE,
        )),
        Light::Sphere(SphereLight {
            center: Vec3::new(0.5, 0.0, 4.0),
            radius: 1.0,
            radiance: Vec3::ONE,
        }),
    ];
    let mut rng = Pcg32::new(1, 1);
    for l in &lights {
        for _ in 0..100 {
            let s = l.sample(Vec3::ZERO, rng.next_vec2()).unwrap();
            let LightHit {
                distance: t, pdf, ..
            } = l
                .hit(&Ray {
                    o: Vec3::ZERO,
                    d: s.wi,
                })
                .unwrap();
            assert!((t - s.dist).abs() < 1e-3 * t, "{t} {}", s.dist);
            assert!((pdf - s.pdf).abs() < 1e-3 * pdf, "{pdf} {}", s.pdf);
        }
    }
}

#[test]
fn sphere_samples_for_many_centres_equal_sample_at() {
    // The column sampler (a light sweep's frames in SIMD lanes) must give `sample_at`'s bits
    // for every centre, including centres so near that the point is inside the sphere (no
    // sample) and directions along ±z (the frame's branch).
    let mut rng = Pcg32::new(41, 2);
    let mut cones = LightSamples::default();
    let (mut inside, mut outside) = (0, 0);
    for n in [1, 3, 8, 37, 48] {
        for _ in 0..50 {
            let p = 100.0 * (2.0 * rng.next_vec2().extend(rng.next_f32()) - 1.0);
            let radius = 1.0 + 60.0 * rng.next_f32();
            let centers: Vec<Vec3> = (0..n)
                .map(|k| match k % 5 {
                    0 => p + Vec3::Z * (200.0 * rng.next_f32() - 100.0),
                    _ => 150.0 * (2.0 * rng.next_vec2().extend(rng.next_f32()) - 1.0),
                })
                .collect();
            let cols = [0, 1, 2].map(|i| centers.iter().map(|c| c[i]).collect());
            let u = LightU::new(rng.next_vec2());
            cones.sample_sphere(p, &cols, radius, Vec3::splat(2.0), &u);
            for (k, &center) in centers.iter().enumerate() {
                let light = Light::Sphere(SphereLight {
                    center,
                    radius,
                    radiance: Vec3::splat(2.0),
                });
                let want = light.sample_at(p, &u);
                let got = cones.get(k);
                match (want, got) {
                    (None, None) => inside += 1,
                    (Some(a), Some(b)) => {
                        outside += 1;
                        assert_eq!(
                            a.wi.to_array().map(f32::to_bits),
                            b.wi.to_array().map(f32::to_bits)
                        );
                        assert_eq!(a.dist.to_bits(), b.dist.to_bits());
                        assert_eq!(a.pdf.to_bits(), b.pdf.to_bits());
                        assert_eq!(a.li, b.li);
                        assert!(!b.is_delta);
                    }
                    (a, b) => panic!("{a:?} {b:?}"),
                }
            }
        }
    }
    assert!(inside > 50 && outside > 3000, "{inside} {outside}");
}

#[test]
fn spot_light_is_a_point_light_inside_its_cone_and_dark_outside() {
    let (i, pos) = (Vec3::splat(50.0), Vec3::new(0.0, 0.0, 10.0));
    let spot = Light::Spot(SpotLight {
        position: pos,
        direction: -Vec3::Z,
        intensity: i,
        cos_inner: 20f32.to_radians().cos(),
        cos_outer: 30f32.to_radians().cos(),
    });
    // 10° off axis: full intensity, E = I / d² (inverse-square law).
    let p = Vec3::new(10.0 * 10f32.to_radians().tan(), 0.0, 0.0);
    let s = spot.sample(p, Vec2::ZERO).unwrap();
    assert!((s.li - i / (pos - p).length_squared()).abs().max_element() < 1e-6);
    // 40° off axis: outside the cone.
    let q = Vec3::new(10.0 * 40f32.to_radians().tan(), 0.0, 0.0);
    assert_eq!(spot.sample(q, Vec2::ZERO).unwrap().li, Vec3::ZERO);
    // 25°: inside the smooth edge, strictly between.
    let r = Vec3::new(10.0 * 25f32.to_radians().tan(), 0.0, 0.0);
    let e = spot.sample(r, Vec2::ZERO).unwrap().li.x * (pos - r).length_squared() / i.x;
    assert!(e > 0.0 && e < 1.0, "{e}");
}

#[test]
fn rotated_env_map_samples_and_pdf_agree_with_its_lookup() {
    let (w, h) = (16, 8);
    let texels: Vec<Vec3> = (0..w * h)
        .map(|i| Vec3::splat(1.0 + (i % 5) as f32))
        .collect();
    let plain = EnvMap::new(w, h, texels.clone());
    let turned = EnvMap::new(w, h, texels).rotated(37.0);
    let r = glam::Mat3::from_rotation_z(37f32.to_radians());
    let mut rng = Pcg32::new(5, 0);
    for _ in 0..1000 {
        let u = rng.next_vec2();
        let (d0, p0) = plain.sample(u).unwrap();
        let (d1, p1) = turned.sample(u).unwrap();
        // The same sample, turned; same density there; same radiance seen there.
        assert!((r * d0 - d1).length() < 1e-5);
        assert!((p0 - p1).abs() <= 1e-4 * p0);
        // Away from texel edges (where 1e-7 of rounding may pick the neighbour).
        let uv = EnvMap::uv(d0) * Vec2::new(w as f32, h as f32);
        let inside = |x: f32| (0.02..0.98).contains(&x.fract());
        if inside(uv.x) && inside(uv.y) {
            assert!((turned.pdf(d1) - plain.pdf(d0)).abs() <= 1e-3 * p0);
            assert_eq!(turned.lookup(d1), plain.lookup(d0));
        }
    }
}

#[test]
fn env_map_pdf_integrates_to_one_and_matches_sampling() {
    let (w, h) = (16, 8);
    let texels = (0..w * h)
        .map(|i| Vec3::splat(1.0 + (i % 7) as f32))
        .collect();
    let map = EnvMap::new(w, h, texels);
    let mut rng = Pcg32::new(3, 0);
    // ∫ p dω estimated with uniform sphere samples: mean of p / (1/4π) must be 1.
    let n = 200_000;
    let mean: f64 = (0..n)
        .map(|_| map.pdf(uniform_sphere(rng.next_vec2())) as f64 * 4.0 * std::f64::consts::PI)
        .sum::<f64>()
        / n as f64;
    assert!((mean - 1.0).abs() < 0.02, "{mean}");
    for _ in 0..1000 {
        let (d, pdf) = map.sample(rng.next_vec2()).unwrap();
        assert!(
            (map.pdf(d) - pdf).abs() <= 1e-2 * pdf,
            "{} {pdf}",
            map.pdf(d)
        );
    }
}
