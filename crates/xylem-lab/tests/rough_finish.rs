//! Issue 12: the rough finish keeps the energy a lossless interface must return. Expected values
//! come from energy conservation (a white, non-absorbing substrate under a lossless finish reflects
//! everything), from the Fresnel equations, and from the independent layered random-walk
//! reference (crates/xylem/src/bsdf/layered_reference.rs); never from the model itself. Fixed seeds,
//! release mode (`cargo test --release --test rough_finish`).

use glam::Vec3;
use xylem::bsdf::{fresnel_dielectric, Bsdf, WoodBsdf, WoodBsdfParams};
use xylem::math::{cosine_hemisphere, Pcg32};
use xylem_lab::layered_reference::{LayeredReference, Substrate};
use xylem_lab::rough_finish::{glossy_albedo_quadrature, rough_row, RoughRow};

fn white(eta: f32, roughness: f32) -> WoodBsdf {
    WoodBsdf::new(WoodBsdfParams {
        diffuse: Vec3::ONE,
        fiber_color: Vec3::ZERO,
        eta,
        roughness,
        ..WoodBsdfParams::default()
    })
    .unwrap()
}

/// |model − reference| ≤ 2 % of the reference + 3σ (issue 12's criterion).
fn assert_within_two_percent(row: &RoughRow) {
    let tol = 0.02 * row.reference + 3.0 * row.sigma;
    assert!(
        (row.model - row.reference).abs() <= tol,
        "{}: model {} reference {} ± {}",
        row.label(),
        row.model,
        row.reference,
        row.sigma
    );
}

fn view(theta_deg: f32) -> Vec3 {
    let t = theta_deg.to_radians();
    Vec3::new(-t.sin(), 0.0, t.cos())
}

/// On main this was 0.907 (α 0.05), 0.761 (0.2), 0.714 (0.5) at 80° under η 2.
#[test]
fn white_substrate_under_rough_finish_reflects_nearly_everything() {
    for eta in [1.5f32, 2.0] {
        for alpha in [0.05f32, 0.2, 0.5] {
            let b = white(eta, alpha);
            for theta in [0.0f32, 30.0, 60.0, 80.0] {
                let (a, _) = glossy_albedo_quadrature(&b, view(theta), alpha, 192);
                assert!(
                    (0.97..=1.002).contains(&a),
                    "η {eta} α {alpha} θo {theta}: {a}"
                );
            }
        }
    }
}

/// The reference itself: a white substrate under a lossless interface returns every path
/// (energy 1 to the sampling error of 0 — every weight is 1), and with a tiny roughness its
/// interface reflection is the Fresnel reflectance (±4σ of a binomial).
#[test]
fn reference_conserves_energy_and_has_the_smooth_limit() {
    let mut rng = Pcg32::new(12, 1);
    for (alpha, eta) in [(0.05, 1.5), (0.5, 2.5), (1.0, 2.0)] {
        let r = LayeredReference {
            alpha,
            eta,
            substrate: Substrate::Lambertian(1.0),
        };
        let a = r.albedo(view(70.0), 4000, &mut rng);
        assert!(a.truncated == 0 && (a.total() - 1.0).abs() < 1e-9, "{a:?}");
    }
    for theta in [0.0f32, 60.0, 85.0] {
        let r = LayeredReference {
            alpha: 1e-4,
            eta: 1.5,
            substrate: Substrate::Lambertian(0.0),
        };
        let n = 20_000;
        let a = r.albedo(view(theta), n, &mut rng);
        let f = fresnel_dielectric(view(theta).z, 1.5) as f64;
        let sigma = (f * (1.0 - f) / n as f64).sqrt();
        assert!(
            (a.interface - f).abs() < 4.0 * sigma + 1e-3,
            "θ {theta}: {} vs {f}",
            a.interface
        );
    }
}

/// The analytic albedo within 2 % (+3σ) of the random walk, white and grey substrates, smooth-ish
/// to very rough, moderate to high index, normal to grazing view; 20 000 paths per row.
#[test]
fn model_agrees_with_the_layered_reference() {
    let mut rng = Pcg32::new(12, 2);
    for rho in [1.0, 0.5] {
        for (alpha, eta) in [(0.05f32, 1.5f32), (0.5, 2.5), (1.0, 1.5)] {
            for theta in [0.0f32, 60.0, 85.0] {
                let row = rough_row(
                    Substrate::Lambertian(rho),
                    alpha,
                    eta,
                    theta,
                    20_000,
                    160,
                    &mut rng,
                );
                assert_within_two_percent(&row);
            }
        }
    }
}

/// The fibre lobe (k_f = 1, in-plane fibres, β 15°) seen through a rough finish: interface plus
/// single pass within 2 % (+3σ) of the random walk, at the views where seeing the lobe through the
/// macro-surface refraction was furthest off (+43.5 % at α 1, η 2, θo 0°; +17.7 % at α 0.5,
/// η 1.5, θo 0°; −24 % at α 1, η 1.5, θo 89°; notes/bsdf.md §4.5) and near-smooth; 40 000 paths.
#[test]
fn fibre_under_rough_finish_agrees_with_the_layered_reference() {
    use xylem::bsdf::FiberAxis;
    let mut rng = Pcg32::new(12, 4);
    let fibre = Substrate::Fiber {
        axis: FiberAxis::new(Vec3::X),
        beta: 15f32.to_radians(),
        k_f: 1.0,
    };
    for (alpha, eta, theta) in [
        (1.0f32, 2.0f32, 0.0f32),
        (0.5, 1.5, 0.0),
        (1.0, 1.5, 89.0),
        (0.2, 2.0, 30.0),
        (0.05, 2.5, 60.0),
    ] {
        let row = rough_row(fibre, alpha, eta, theta, 40_000, 160, &mut rng);
        assert_within_two_percent(&row);
    }
}

/// Random rough wood parameters: albedo ≤ 1 (quadrature of the largest channel's substrate made
/// white, the worst case) and eval reciprocal.
#[test]
fn furnace_bound_and_reciprocity_over_random_rough_finishes() {
    let mut r = Pcg32::new(12, 3);
    for _ in 0..12 {
        let p = WoodBsdfParams {
            diffuse: Vec3::ONE,
            fiber_color: Vec3::splat(r.next_f32()),
            fiber_dir: Vec3::new(1.0, 0.0, -r.next_f32()).normalize(),
            ray_mask: 0.0,
            highlight_width: (5.0 + 20.0 * r.next_f32()).to_radians(),
            eta: 1.0 + 1.5 * r.next_f32(),
            roughness: 0.02 + 0.98 * r.next_f32(),
            ..WoodBsdfParams::default()
        };
        let b = WoodBsdf::new(p).unwrap();
        let theta = 85.0 * r.next_f32();
        let (a, _) = glossy_albedo_quadrature(&b, view(theta), p.roughness, 128);
        assert!(a <= 1.003, "{p:?} θo {theta}: {a}");
        for _ in 0..500 {
            let (x, y) = (
                cosine_hemisphere(r.next_vec2()),
                cosine_hemisphere(r.next_vec2()),
            );
            let (f1, f2) = (b.eval(x, y), b.eval(y, x));
            let d = (f1 - f2).abs().max_element();
            assert!(d <= 1e-4 * f1.max(f2).max_element().max(1e-6), "{p:?}");
        }
    }
}

/// The table of issue 12 remeasured, beside the reference (`cargo test --release --test
/// rough_finish issue_table -- --ignored --nocapture`; for notes/bsdf.md §4.5).
#[test]
#[ignore]
fn issue_table() {
    let mut rng = Pcg32::new(12, 9);
    let rows = [
        (2.0f32, 0.05f32),
        (2.0, 0.2),
        (2.0, 0.5),
        (1.5, 0.1),
        (1.5, 0.3),
    ];
    println!("| η | roughness | θo 0° | 60° | 80° | 89° |\n| --- | --- | --- | --- | --- | --- |");
    for (eta, alpha) in rows {
        let (mut m, mut r) = (Vec::new(), Vec::new());
        for theta in [0.0f32, 60.0, 80.0, 89.0] {
            let row = rough_row(
                Substrate::Lambertian(1.0),
                alpha,
                eta,
                theta,
                100_000,
                256,
                &mut rng,
            );
            m.push(format!("{:.4}", row.model));
            let rf = LayeredReference {
                alpha: alpha as f64,
                eta: eta as f64,
                substrate: Substrate::Lambertian(1.0),
            };
            r.push(format!(
                "{:.4}",
                rf.albedo(view(theta), 1000, &mut rng).total()
            ));
        }
        println!("| {eta} | {alpha} model | {} |", m.join(" | "));
        println!("| {eta} | {alpha} reference | {} |", r.join(" | "));
    }
}
