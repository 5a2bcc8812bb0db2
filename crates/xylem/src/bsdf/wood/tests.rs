use super::*;
use crate::math::{Pcg32, PI};

fn dir(theta_deg: f32, phi_deg: f32) -> Vec3 {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

fn configs() -> Vec<WoodBsdfParams> {
    let base = WoodBsdfParams::default();
    vec![
        base,
        WoodBsdfParams { eta: 1.0, ..base },
        WoodBsdfParams {
            fiber_dir: Vec3::new(1.0, 0.0, -0.5).normalize(),
            ray_dir: Vec3::new(0.0, 0.6, 0.8),
            ray_mask: 0.5,
            highlight_width: 0.3,
            eta: 1.8,
            ..base
        },
        WoodBsdfParams {
            roughness: 0.3,
            ..base
        },
    ]
}

/// Every configuration with ray masks 0, 0.4 and 1, in both normalisations.
fn variants() -> Vec<WoodBsdf> {
    let norms = [
        FiberNormalization::EnergyBounded,
        FiberNormalization::Published,
    ];
    configs()
        .into_iter()
        .flat_map(|base| [0.0, 0.4, 1.0].map(|ray_mask| WoodBsdfParams { ray_mask, ..base }))
        .flat_map(|p| norms.map(|n| WoodBsdf::new(p).unwrap().with_normalization(n)))
        .collect()
}

/// ∫ f cos dω over the upper hemisphere by the midpoint rule in (cos θ, φ).
fn quadrature_albedo(b: &WoodBsdf, wo: Vec3, n: usize) -> Vec3 {
    let mut s = Vec3::ZERO;
    for i in 0..n {
        let mu = (i as f32 + 0.5) / n as f32;
        let st = (1.0 - mu * mu).sqrt();
        for j in 0..2 * n {
            let phi = (j as f32 + 0.5) / (2 * n) as f32 * 2.0 * PI;
            let wi = Vec3::new(st * phi.cos(), st * phi.sin(), mu);
            s += b.eval(wo, wi) * mu;
        }
    }
    s * (2.0 * PI / (2 * n * n) as f32)
}

#[test]
fn batch_eval_pdf_equals_one_at_a_time() {
    // `eval_pdf_many` (a light sweep's frames in SIMD lanes) must give `eval_pdf`'s bits for
    // every direction: all configurations, both normalisations, ray masks 0, 0.4, 1, with and
    // without the density, batches of 1..=40 directions (partial and several chunks),
    // directions over the whole sphere, within 0.1° of the horizon and exactly ±z; a grazing wo.
    let mut rng = Pcg32::new(53, 9);
    let (mut nonzero, mut below) = (0, 0);
    for b in variants() {
        for n in [1, 7, 16, 17, 40] {
            let wo = match n % 3 {
                0 => dir(89.95, 360.0 * rng.next_f32()),
                _ => crate::math::uniform_sphere(rng.next_vec2()),
            };
            let at = b.at_wo(wo);
            let wi: Vec<Vec3> = (0..n)
                .map(|k| match k % 4 {
                    0 => dir(90.0 - 0.1 * rng.next_f32(), 360.0 * rng.next_f32()),
                    1 if k % 8 == 1 => Vec3::Z,
                    1 => -Vec3::Z,
                    _ => crate::math::uniform_sphere(rng.next_vec2()),
                })
                .collect();
            for with_pdf in [true, false] {
                let (mut f, mut pdf) = (vec![Vec3::NAN; n], vec![f32::NAN; n]);
                at.eval_pdf_many(&wi, with_pdf, &mut f, &mut pdf);
                for k in 0..n {
                    let (f1, p1) = at.eval_pdf(wi[k], with_pdf);
                    let bits = |v: Vec3| v.to_array().map(f32::to_bits);
                    assert_eq!(bits(f[k]), bits(f1), "{wo} {}", wi[k]);
                    assert_eq!(pdf[k].to_bits(), p1.to_bits(), "{wo} {}", wi[k]);
                    assert!(f[k].is_finite() && pdf[k].is_finite());
                    nonzero += (pdf[k] > 0.0) as u32;
                    below += (wi[k].z <= 0.0) as u32;
                }
            }
        }
    }
    assert!(nonzero > 300 && below > 300, "{nonzero} {below}");
}

#[test]
fn rejects_bad_parameters_naming_the_field() {
    let base = WoodBsdfParams::default();
    let cases: [(WoodBsdfParams, &str); 6] = [
        (WoodBsdfParams { eta: 0.5, ..base }, "eta"),
        (
            WoodBsdfParams {
                roughness: f32::NAN,
                ..base
            },
            "roughness",
        ),
        (
            WoodBsdfParams {
                highlight_width: 0.0,
                ..base
            },
            "highlight_width",
        ),
        (
            WoodBsdfParams {
                fiber_dir: Vec3::ZERO,
                ..base
            },
            "fiber_dir",
        ),
        (
            WoodBsdfParams {
                diffuse: Vec3::splat(1.5),
                ..base
            },
            "diffuse",
        ),
        (
            WoodBsdfParams {
                ray_mask: -0.1,
                ..base
            },
            "ray_mask",
        ),
    ];
    for (p, field) in cases {
        let e = WoodBsdf::new(p).unwrap_err().to_string();
        assert!(e.contains(field), "{e}");
    }
    assert!(WoodBsdf::new(base).is_ok());
}

#[test]
fn eval_is_reciprocal() {
    let mut r = Pcg32::new(5, 0);
    for p in configs() {
        for norm in [
            FiberNormalization::EnergyBounded,
            FiberNormalization::Published,
        ] {
            let b = WoodBsdf::new(p).unwrap().with_normalization(norm);
            for _ in 0..2000 {
                let a = cosine_hemisphere(r.next_vec2());
                let c = cosine_hemisphere(r.next_vec2());
                let (f1, f2) = (b.eval(a, c), b.eval(c, a));
                let d = (f1 - f2).abs().max_element();
                assert!(
                    d <= 1e-4 * f1.max(f2).max_element().max(1e-6),
                    "{p:?} {f1} {f2}"
                );
            }
        }
    }
}

#[test]
fn white_substrate_under_smooth_finish_reflects_everything() {
    // Independent check: delta reflection F(θo) plus a quadrature of eval·cos.
    for eta in [1.0f32, 1.33, 1.5, 2.0, 2.5] {
        let b = WoodBsdf::new(WoodBsdfParams {
            diffuse: Vec3::ONE,
            fiber_color: Vec3::ZERO,
            eta,
            ..WoodBsdfParams::default()
        })
        .unwrap();
        for theta in [0.0f32, 30.0, 60.0, 80.0, 85.0] {
            let wo = dir(theta, 20.0);
            let a = quadrature_albedo(&b, wo, 200).x + fresnel_dielectric(wo.z, eta);
            assert!((0.99..=1.001).contains(&a), "eta {eta} θ {theta}: {a}");
        }
    }
}

#[test]
fn samples_match_eval_and_pdf_and_weights_stay_bounded() {
    let mut r = Pcg32::new(8, 3);
    for p in configs() {
        let b = WoodBsdf::new(p).unwrap();
        for theta in [5.0f32, 45.0, 80.0] {
            let wo = dir(theta, 60.0);
            for _ in 0..3000 {
                let Some(s) = b.sample(wo, r.next_f32(), r.next_vec2()) else {
                    continue;
                };
                assert!(s.f.is_finite() && s.pdf.is_finite() && s.pdf > 0.0);
                if s.is_delta {
                    let w = s.f * s.wi.z / s.pdf;
                    assert!(w.max_element() <= 1.0 + 1e-4, "{w}");
                    continue;
                }
                let (f, pdf) = (b.eval(wo, s.wi), b.pdf(wo, s.wi));
                assert!((f - s.f).abs().max_element() <= 1e-5 * f.max_element().max(1e-6));
                assert!((pdf - s.pdf).abs() <= 1e-5 * pdf);
            }
        }
    }
}

#[test]
fn sampled_fraction_equals_integral_of_pdf() {
    // P(sample returns a non-delta direction) = ∫ pdf dω: pdf is the density of `sample`.
    for p in configs() {
        let b = WoodBsdf::new(p).unwrap();
        let wo = dir(40.0, 10.0);
        let n_q = 400;
        let mut integral = 0.0f64;
        for i in 0..n_q {
            let mu = (i as f32 + 0.5) / n_q as f32;
            let st = (1.0 - mu * mu).sqrt();
            for j in 0..2 * n_q {
                let phi = (j as f32 + 0.5) / (2 * n_q) as f32 * 2.0 * PI;
                let wi = Vec3::new(st * phi.cos(), st * phi.sin(), mu);
                integral += b.pdf(wo, wi) as f64;
            }
        }
        integral *= 2.0 * PI as f64 / (2 * n_q * n_q) as f64;
        let mut r = Pcg32::new(21, 0);
        let n = 200_000;
        let hits = (0..n)
            .filter(|_| matches!(b.sample(wo, r.next_f32(), r.next_vec2()), Some(s) if !s.is_delta))
            .count() as f64
            / n as f64;
        // Binomial standard error ≤ 0.5/√n ≈ 1.1e-3; allow 5σ plus 0.5 % quadrature error.
        assert!(
            (hits - integral).abs() < 5.5e-3 + 0.005 * integral,
            "{p:?}: {hits} vs {integral}"
        );
    }
}

#[test]
fn energy_bounded_lobe_never_exceeds_one() {
    // Worst case for the bound: white diffuse, k_f = 1, grazing and along-fibre views.
    let mut r = Pcg32::new(77, 0);
    for fiber_dir in [Vec3::X, Vec3::new(1.0, 0.0, -1.0).normalize(), Vec3::Z] {
        let b = WoodBsdf::new(WoodBsdfParams {
            diffuse: Vec3::ONE,
            fiber_color: Vec3::ONE,
            fiber_dir,
            highlight_width: 0.5,
            eta: 1.0,
            ..WoodBsdfParams::default()
        })
        .unwrap();
        for wo in [
            dir(0.0, 0.0),
            dir(60.0, 0.0),
            dir(88.0, 0.0),
            dir(88.0, 180.0),
        ] {
            let n = 100_000;
            let mut s = 0.0f64;
            for _ in 0..n {
                if let Some(x) = b.sample(wo, r.next_f32(), r.next_vec2()) {
                    s += (x.f.x * x.wi.z / x.pdf) as f64;
                }
            }
            let a = s / n as f64;
            assert!(a <= 1.0 + 0.01, "{fiber_dir} {wo}: {a}");
        }
    }
}

/// A BSDF built under a finish worked out beforehand (`new_under`, what a wood material does)
/// equals the one `new` builds, value for value, for smooth and rough finishes; a finish of
/// another roughness is not used (the BSDF is the params' own). Control: a BSDF of the other
/// roughness does differ, so the comparison can see a wrong finish.
#[test]
fn a_finish_worked_out_once_gives_the_same_bsdf() {
    let mut rng = Pcg32::new(11, 5);
    let pairs: Vec<(Vec3, Vec3)> = (0..60)
        .map(|k| {
            let wo = [dir(10.0, 20.0), dir(55.0, 200.0), dir(80.0, 95.0)][k % 3];
            (wo, dir(rng.next_f32() * 89.0, rng.next_f32() * 360.0))
        })
        .collect();
    let values = |b: &WoodBsdf| -> Vec<u32> {
        let at = |&(wo, wi): &(Vec3, Vec3)| {
            let (f, pdf) = (b.eval(wo, wi), b.pdf(wo, wi));
            [f.x, f.y, f.z, pdf].map(f32::to_bits)
        };
        pairs.iter().flat_map(at).collect()
    };
    for p in configs() {
        let own = values(&WoodBsdf::new(p).unwrap());
        let under = WoodBsdf::new_under(p, &Finish::new(p.eta, p.roughness)).unwrap();
        assert_eq!(own, values(&under), "{p:?}");
        let other = Finish::new(p.eta, if p.roughness > 0.1 { 0.0 } else { 0.3 });
        assert_eq!(
            own,
            values(&WoodBsdf::new_under(p, &other).unwrap()),
            "{p:?}"
        );
        let changed = WoodBsdfParams {
            roughness: other.roughness(),
            ..p
        };
        assert_ne!(own, values(&WoodBsdf::new(changed).unwrap()), "{p:?}");
    }
}

/// `mirror_probability` is where `sample` switches from the smooth finish's mirror to the
/// other lobes: uc just below it gives the mirror, uc at it does not; 0 under a rough finish,
/// whose reflection is no delta lobe. Both sides of the boundary are checked, so a probability
/// off by one f32 step either way fails.
#[test]
fn mirror_probability_is_where_sample_leaves_the_mirror() {
    for p in configs() {
        let b = WoodBsdf::new(p).unwrap();
        for wo in [dir(10.0, 30.0), dir(60.0, 120.0), dir(85.0, 250.0)] {
            let pm = b.mirror_probability(wo);
            let u = Vec2::new(0.3, 0.6);
            let is_delta = |uc: f32| b.sample(wo, uc, u).is_some_and(|s| s.is_delta);
            if p.roughness > 0.0 || p.eta <= 1.0 {
                assert_eq!(pm, 0.0, "{p:?}");
                continue;
            }
            assert!(pm > 0.0 && pm < 1.0, "{p:?} {pm}");
            assert!(is_delta(pm.next_down()) && is_delta(0.5 * pm), "{p:?} {pm}");
            assert!(!is_delta(pm), "{p:?} {pm}");
        }
        assert_eq!(b.mirror_probability(dir(100.0, 0.0)), 0.0);
    }
}
