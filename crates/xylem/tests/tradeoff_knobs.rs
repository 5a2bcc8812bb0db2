//! The speed/accuracy switches `xylem tradeoff` measures (validation/TRADEOFF.md): each one must
//! be a no-op where its approximation is exact and must change the result where it is not.

use glam::{Mat3, Vec3};
use xylem::bsdf::{fresnel_dielectric, Bsdf, FinishModel, WoodBsdf, WoodBsdfParams};
use xylem::field::JacobianModel;
use xylem::wood::{preset, sample_points, Needs, WoodParams, WoodVolume};

fn dir(theta_deg: f32, phi_deg: f32) -> Vec3 {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

/// F̄_int = 1 − (1 − F̄_ext)/η² with F̄_ext = 2∫₀¹ F(μ) μ dμ by a 20 000-point midpoint rule
/// (independent of the BSDF's Gauss–Legendre quadrature).
fn internal_reflectance(eta: f32) -> f64 {
    let n = 20_000;
    let mut ext = 0.0f64;
    for i in 0..n {
        let mu = (i as f64 + 0.5) / n as f64;
        ext += 2.0 * fresnel_dielectric(mu as f32, eta) as f64 * mu / n as f64;
    }
    1.0 - (1.0 - ext) / (eta as f64 * eta as f64)
}

/// Directional albedo ∫ f cos θi dωi (no delta lobe) by a midpoint rule in (cos θ, φ).
fn albedo(b: &WoodBsdf, wo: Vec3) -> Vec3 {
    let (nt, np) = (200, 200);
    let mut a = Vec3::ZERO;
    for i in 0..nt {
        let mu = (i as f32 + 0.5) / nt as f32;
        let s = (1.0 - mu * mu).sqrt();
        for j in 0..np {
            let phi = std::f32::consts::TAU * (j as f32 + 0.5) / np as f32;
            let wi = Vec3::new(s * phi.cos(), s * phi.sin(), mu);
            a += b.eval(wo, wi) * mu;
        }
    }
    a * (std::f32::consts::TAU / (nt * np) as f32)
}

#[test]
fn single_bounce_finish_drops_exactly_the_internal_reflection_series() {
    // Diffuse only (k_f = 0): closed form ρ/(1 − ρF̄_int) against ρ, so at every pair of directions
    // single / closed = 1 − ρ F̄_int per channel (notes/bsdf.md §1.3).
    let rho = Vec3::new(0.45, 0.22, 0.10);
    for eta in [1.3f32, 1.5, 2.0] {
        let p = WoodBsdfParams {
            diffuse: rho,
            fiber_color: Vec3::ZERO,
            eta,
            ..WoodBsdfParams::default()
        };
        let closed = WoodBsdf::new(p).unwrap();
        let single = closed.with_finish(FinishModel::SingleBounce);
        let f_int = internal_reflectance(eta);
        for (wo, wi) in [
            (dir(10.0, 0.0), dir(40.0, 120.0)),
            (dir(70.0, 30.0), dir(5.0, 200.0)),
        ] {
            let (c, s) = (closed.eval(wo, wi), single.eval(wo, wi));
            for ch in 0..3 {
                let want = 1.0 - rho[ch] as f64 * f_int;
                let got = (s[ch] / c[ch]) as f64;
                assert!(
                    (got - want).abs() < 1e-4,
                    "η {eta} ch {ch}: {got} vs {want}"
                );
            }
        }
    }
}

#[test]
fn single_bounce_albedo_is_at_most_closed_form_and_equal_without_internal_reflection() {
    let configs = [
        WoodBsdfParams::default(),
        WoodBsdfParams {
            diffuse: Vec3::new(0.8, 0.7, 0.5),
            fiber_color: Vec3::new(0.2, 0.2, 0.2),
            fiber_dir: Vec3::new(1.0, 0.0, -0.4).normalize(),
            ray_mask: 0.3,
            eta: 1.8,
            ..WoodBsdfParams::default()
        },
    ];
    for p in configs {
        let closed = WoodBsdf::new(p).unwrap();
        let single = closed.with_finish(FinishModel::SingleBounce);
        for wo in [dir(0.0, 0.0), dir(45.0, 30.0), dir(80.0, 180.0)] {
            let (ac, as_) = (albedo(&closed, wo), albedo(&single, wo));
            assert!(as_.cmple(ac + Vec3::splat(1e-6)).all(), "{as_} > {ac}");
            // A finish with η > 1 reflects some diffuse light back: measurably less.
            assert!(ac.x - as_.x > 1e-3, "{wo}: {ac} vs {as_}");
        }
        // η = 1: no finish, F̄_int = 0, the two models are the same BSDF.
        let bare = WoodBsdf::new(WoodBsdfParams { eta: 1.0, ..p }).unwrap();
        let bare1 = bare.with_finish(FinishModel::SingleBounce);
        for (wo, wi) in [
            (dir(10.0, 0.0), dir(40.0, 120.0)),
            (dir(70.0, 30.0), dir(5.0, 200.0)),
        ] {
            let (a, b) = (bare.eval(wo, wi), bare1.eval(wo, wi));
            assert!(
                (a - b).abs().max_element() <= 1e-6 * a.max_element(),
                "{a} {b}"
            );
        }
    }
}

/// `params` with every distortion magnitude multiplied by `k`.
fn scaled_distortion(mut p: WoodParams, k: f32) -> WoodParams {
    for n in [
        &mut p.distortion.radial,
        &mut p.distortion.tangential,
        &mut p.distortion.longitudinal,
    ]
    .into_iter()
    .flatten()
    {
        n.magnitude *= k;
    }
    p
}

fn volumes(p: WoodParams) -> (WoodVolume, WoodVolume) {
    let simple = WoodVolume::new(p, 3).unwrap();
    let exact = simple.clone().with_jacobian(JacobianModel::Exact);
    assert_eq!(simple.jacobian_model(), JacobianModel::Simplified);
    (simple, exact)
}

/// Mean angle (radians) between the fibre directions of two volumes at `points`.
fn mean_fiber_angle(a: &WoodVolume, b: &WoodVolume, points: &[Vec3]) -> f64 {
    let mut s = 0.0f64;
    for p in points {
        let (fa, fb) = (
            a.eval(*p, Needs::ALL).fiber_dir,
            b.eval(*p, Needs::ALL).fiber_dir,
        );
        s += fa.dot(fb).clamp(-1.0, 1.0).acos() as f64;
    }
    s / points.len() as f64
}

#[test]
fn exact_and_simplified_jacobian_agree_for_gentle_distortion_and_differ_for_steep() {
    // Curly maple: tangential distortion with narrow kernels (the curl), made steep by 4× its
    // calibrated magnitude (about the uncalibrated preset's, whose fibre dips were 7° std).
    let base = preset("curly_maple").unwrap();
    let points = sample_points(3000, 11);
    let (s0, e0) = volumes(scaled_distortion(base.clone(), 1e-3));
    let gentle = mean_fiber_angle(&s0, &e0, &points);
    let (s1, e1) = volumes(scaled_distortion(base, 4.0));
    let steep = mean_fiber_angle(&s1, &e1, &points);
    // ‖∇m‖ → 0: both are I + a ⊗ ∇m to first order; the m ∂a/∂p terms are O(m / r).
    assert!(gentle < 1e-4, "gentle distortion: mean angle {gentle}");
    // Steep distortion: the compression 1/(1 + ‖∇m‖) and the m ∂a/∂p terms turn fibres visibly.
    assert!(steep > 1e-2, "steep distortion: mean angle {steep}");
    assert!(steep > 100.0 * gentle);
}

#[test]
fn exact_jacobian_is_closer_to_finite_differences_of_the_lookup_point() {
    // J_fd by central differences of the volume's own f(p) (h = 1e-3 of the smallest kernel
    // axis). Both models share the oriented-kernel gradient of Liu 2016 eq. 14, so neither is
    // exact; the exact model must still be the closer one on average.
    let base = preset("curly_maple").unwrap();
    let (simple, exact) = volumes(base);
    let h = 2e-3f32;
    let (mut err_s, mut err_e) = (0.0f64, 0.0f64);
    for p in sample_points(500, 5) {
        let mut cols = [Vec3::ZERO; 3];
        for (i, e) in [Vec3::X, Vec3::Y, Vec3::Z].into_iter().enumerate() {
            let f = |q: Vec3| simple.distortion(q).point.as_dvec3();
            cols[i] = ((f(p + e * h) - f(p - e * h)) / (2.0 * h as f64)).as_vec3();
        }
        let fd = Mat3::from_cols(cols[0], cols[1], cols[2]);
        let frob = |m: Mat3| {
            let d = m - fd;
            (d.x_axis.length_squared() + d.y_axis.length_squared() + d.z_axis.length_squared())
                .sqrt() as f64
        };
        err_s += frob(simple.distortion(p).jacobian);
        err_e += frob(exact.distortion(p).jacobian);
    }
    assert!(err_e < 0.8 * err_s, "exact {err_e} vs simplified {err_s}");
}

/// The narrowest feature of a preset (mm): pore diameter, ray width, finest distortion band, and
/// a tenth of the shorter ring transition, below which the rings are point-sampled (issue 28;
/// the growth wave and noise and the distortion steepen the time gradient over 1/width, by
/// less than 20× in every preset).
fn smallest_feature(p: &WoodParams) -> f32 {
    let [_, rise, _, fall] = p.rings.proportions;
    let sum: f32 = p.rings.proportions.iter().sum();
    let mut d = 0.1 * rise.min(fall) / sum * p.rings.width / 20.0;
    if let Some(x) = &p.pores {
        d = d.min(2.0 * x.radius);
    }
    if let Some(x) = &p.rays {
        d = d.min(x.width);
    }
    // The cell texture fades from twice its across-grain length (notes/wood.md §9c).
    if let Some(t) = &p.texture {
        for scale in std::iter::once(t).chain(t.streaks.as_deref()) {
            d = d.min(2.0 * scale.across);
        }
    }
    for n in [
        &p.distortion.radial,
        &p.distortion.tangential,
        &p.distortion.longitudinal,
    ]
    .into_iter()
    .flatten()
    {
        let finest = n.size_factor.powi(n.bands as i32 - 1);
        d = d.min(2.0 * n.size.iter().cloned().fold(f32::INFINITY, f32::min) * finest);
    }
    d
}

#[test]
fn footprint_below_the_smallest_feature_changes_nothing() {
    for name in xylem::wood::PRESET_NAMES {
        let p = preset(name).unwrap();
        let f = 0.99 * smallest_feature(&p);
        let v = WoodVolume::new(p, 9).unwrap();
        let wander = v.params().fibre_wander.is_some();
        for q in sample_points(300, 2) {
            let mut filtered = v.eval_filtered(q, Needs::ALL, f);
            let point = v.eval(q, Needs::ALL);
            if wander {
                // The fibre wander has no such size: any footprint averages some of it into the
                // highlight's width (continuously, from 0; checked in wander_filter.rs).
                assert!(
                    filtered.fiber_dir.dot(point.fiber_dir) > 0.999,
                    "{name} {q}"
                );
                assert!(
                    filtered.highlight_width >= point.highlight_width,
                    "{name} {q}"
                );
                filtered.fiber_dir = point.fiber_dir;
                filtered.highlight_width = point.highlight_width;
            }
            assert_eq!(filtered, point, "{name} {q}");
        }
    }
}

#[test]
fn footprint_filtered_pores_and_rays_keep_their_mean() {
    // Beyond twice their width pores and rays are replaced by the analytic mean mask
    // (density × 3∫r²K dr, scaled by size³ for ring porosity); the average of the unfiltered
    // masks over 40 000 independent points must agree. Standard error ≈ 2 % of the mean for the
    // sparsest feature here; 12 % allowed (> 5 σ).
    for name in ["african_mahogany", "red_oak", "quartersawn_white_oak"] {
        let v = WoodVolume::new(preset(name).unwrap(), 4).unwrap();
        let pts = sample_points(40_000, 8);
        let (mut pore, mut pore_f, mut ray, mut ray_f) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for q in &pts {
            let (a, b) = (
                v.eval(*q, Needs::ALL),
                v.eval_filtered(*q, Needs::ALL, 50.0),
            );
            pore += a.pore_mask as f64;
            pore_f += b.pore_mask as f64;
            ray += a.ray_mask as f64;
            ray_f += b.ray_mask as f64;
        }
        for (what, got, want) in [("pores", pore_f, pore), ("rays", ray_f, ray)] {
            if want > 0.0 {
                let rel = (got - want).abs() / want;
                assert!(
                    rel < 0.12,
                    "{name} {what}: filtered mean {got} vs {want} ({rel})"
                );
            }
        }
    }
}

#[test]
fn footprint_filtering_removes_the_aliasing_of_pores() {
    // A pixel 1 mm wide over mahogany pores (0.18 mm): its true colour is the box average of the
    // unfiltered wood over the pixel (256 points). One point sample per pixel aliases (it hits
    // a pore or not); the footprint-filtered point sample must be much closer to the average.
    let v = WoodVolume::new(preset("african_mahogany").unwrap(), 4).unwrap();
    let needs = Needs {
        color: true,
        fibers: false,
        bump: false,
    };
    let lum = |c: Vec3| 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
    let mut rng = xylem::math::Pcg32::new(21, 3);
    let (pixel, mut err_point, mut err_filtered) = (1.0f32, 0.0f64, 0.0f64);
    for centre in sample_points(200, 13) {
        let mut avg = 0.0f64;
        let n = 256;
        for _ in 0..n {
            let o = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5;
            avg += lum(v.eval(centre + o * pixel, needs).diffuse) as f64 / n as f64;
        }
        let point = lum(v.eval(centre, needs).diffuse) as f64;
        let filtered = lum(v.eval_filtered(centre, needs, pixel).diffuse) as f64;
        err_point += (point - avg).powi(2);
        err_filtered += (filtered - avg).powi(2);
    }
    assert!(
        err_filtered < 0.5 * err_point,
        "filtered {err_filtered} vs point {err_point}"
    );
}

mod baked {
    use super::*;
    use glam::{Affine3A, Vec2};
    use xylem::bake::{bake_face, BakeCut, BoardCut};
    use xylem::material::{
        BakedFibers, BakedWoodMaterial, FaceRect, Material, MaterialHit, Placement,
    };

    fn board() -> (WoodVolume, FaceRect) {
        let v = WoodVolume::new(preset("walnut").unwrap(), 2).unwrap();
        let cut = BoardCut {
            size: [120.0, 40.0, 20.0],
            cut: BakeCut::Tangential,
            radius: 140.0,
        };
        (v, cut.rect())
    }

    /// Mean |baked − procedural| of the diffuse colour over random points of the face.
    fn colour_error(v: &WoodVolume, face: &FaceRect, res: u32) -> f64 {
        let maps = bake_face(v, face, Affine3A::IDENTITY, res);
        let mut rng = xylem::math::Pcg32::new(5, 5);
        let n = 4000;
        let mut e = 0.0f64;
        for _ in 0..n {
            let uv = rng.next_vec2();
            let want = v.eval(face.point(uv), Needs::ALL).diffuse;
            e += (maps.lookup(uv).base_color - want).abs().max_element() as f64;
        }
        e / n as f64
    }

    #[test]
    fn baked_texture_converges_to_the_procedural_colour() {
        // Rings and figure without pores, rays and cell texture (which stay sub-texel up to
        // 0.1 mm texels):
        // bilinear interpolation of a smooth field errs by O(h²), so 16× finer texels must cut
        // the mean error far more than the 4× an O(h) (nearest-texel) lookup would.
        let mut p = preset("walnut").unwrap();
        p.pores = None;
        p.rays = None;
        p.texture = None;
        let v = WoodVolume::new(p, 2).unwrap();
        let face = board().1;
        let coarse = colour_error(&v, &face, 64);
        let fine = colour_error(&v, &face, 1024);
        assert!(
            fine < coarse / 16.0,
            "1024 texels {fine} vs 64 texels {coarse}"
        );
    }

    #[test]
    fn baked_material_reproduces_the_volume_at_texel_centres() {
        let (v, face) = board();
        let res = 96;
        let maps = bake_face(&v, &face, Affine3A::IDENTITY, res);
        let (w, h) = (maps.width, maps.height);
        let mat = Material::BakedWood(Box::new(BakedWoodMaterial {
            maps: std::sync::Arc::new(maps),
            face,
            fiber_saturation: preset("walnut").unwrap().color.fiber_saturation.into(),
            fibers: BakedFibers::Anisotropy,
            finish: xylem::bsdf::Finish::new(1.5, 0.0),
            bump: 0.0,
            switches: Default::default(),
        }));
        let n = face.normal();
        let mut checked = 0;
        for (x, y) in [(0, 0), (17, 5), (50, 20), (w - 1, h - 1)] {
            let uv = Vec2::new((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
            let p = face.point(uv);
            let hit = MaterialHit {
                p_object: p,
                p_world: p,
                n_object: n,
                ng: n,
                ns: n,
                tangent: face.right,
                object_to_world: Mat3::IDENTITY,
                normal_to_world: Mat3::IDENTITY,
                placement: Placement::default(),
                footprint: 0.0,
            };
            let s = mat.shade(&hit);
            let t = v.eval(p, Needs::ALL);
            assert!(
                (s.aov.albedo - t.diffuse).abs().max_element() < 1e-5,
                "({x}, {y})"
            );
            // The fibre axis: same in-face direction (up to sign), same tilt out of the face.
            let (fb, fp) = (s.aov.fiber, t.fiber_dir);
            let in_face = |f: Vec3| (f - n * f.dot(n)).normalize();
            assert!(
                in_face(fb).dot(in_face(fp)).abs() > 0.9999,
                "({x}, {y}): {fb} {fp}"
            );
            assert!((fb.dot(n).abs() - fp.dot(n).abs()).abs() < 1e-4);
            checked += 1;
        }
        assert_eq!(checked, 4);
    }
}

#[test]
fn fibre_direction_map_keeps_the_interlock_tilt_the_anisotropy_map_loses() {
    // Quartersawn mahogany: interlocked fibres tilt out of the face by ±φ, alternating with
    // radius (the ribbon figure). The KHR anisotropy texel stores only |cos| of the tilt.
    use glam::{Affine3A, Vec2};
    use xylem::bake::{bake_face, BakeCut, BoardCut};
    use xylem::material::{fiber_from_anisotropy, FaceRect};
    let v = WoodVolume::new(preset("african_mahogany").unwrap(), 7).unwrap();
    let face: FaceRect = BoardCut {
        size: [100.0, 60.0, 20.0],
        cut: BakeCut::Radial,
        radius: 120.0,
    }
    .rect();
    let maps = bake_face(&v, &face, Affine3A::IDENTITY, 64);
    let (w, h) = (maps.width, maps.height);
    let (mut tilted, mut lost) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            let uv = Vec2::new((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
            let t = maps.lookup(uv);
            let f = v.eval(face.point(uv), Needs::ALL).fiber_dir;
            let want = Vec3::new(f.dot(face.right), -f.dot(face.down), f.dot(face.normal()));
            assert!(
                (t.fiber - want).length() < 1e-4,
                "({x}, {y}): {} vs {want}",
                t.fiber
            );
            if want.z.abs() > 0.05 {
                tilted += 1;
                let a = fiber_from_anisotropy(t.anisotropy);
                // Same axis up to the sign of the out-of-face part, which is lost where > 0.
                if (a.z - want.z).abs() > 0.05 && (a.z + want.z).abs() < 1e-3 {
                    lost += 1;
                }
            }
        }
    }
    let n = (w * h) as usize;
    assert!(tilted > n / 4, "interlock tilts {tilted} of {n} texels");
    assert!(
        lost > tilted / 4,
        "sign lost at {lost} of {tilted} tilted texels"
    );
}
