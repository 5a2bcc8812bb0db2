//! Statistical and analytic checks of the noise module (run in release mode: `cargo test --release`).
//! Expected moments are derived in notes/noise.md (not measured from this code); every statistical
//! test uses a fixed seed and states its tolerance in standard errors.

use xylem::math::{uniform_sphere, Frame, Pcg32, Vec3};
use xylem::noise::*;

const N: usize = 1_000_000;

fn random_point(r: &mut Pcg32, half: f32) -> Vec3 {
    Vec3::new(r.next_f32(), r.next_f32(), r.next_f32()) * (2.0 * half) - Vec3::splat(half)
}

/// Mean and variance (f64 accumulators) of `f` over `n` random points in a cube of half-width `half`.
fn moments(n: usize, half: f32, seed: u64, f: impl Fn(Vec3) -> f32) -> (f64, f64) {
    let mut r = Pcg32::new(seed, 0);
    let (mut s, mut s2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let v = f(random_point(&mut r, half)) as f64;
        assert!(v.is_finite());
        s += v;
        s2 += v * v;
    }
    let m = s / n as f64;
    (m, s2 / n as f64 - m * m)
}

// Derived in notes/noise.md (exact rationals): B = 2∫fade² = 181/231, A = 2∫(1−fade)² t² = 535/9009.
const B: f64 = 181.0 / 231.0;
const A: f64 = 535.0 / 9009.0;
/// Var of 3D gradient noise: E[g gᵀ] = ¾ I, so Var = ¾ · 3 A B².
const VAR_GRADIENT3: f64 = 0.75 * 3.0 * A * B * B;
/// Var of 3D value noise: values uniform in [−1, 1) (variance ⅓), Var = ⅓ B³.
const VAR_VALUE3: f64 = B * B * B / 3.0;
const VAR_GRADIENT1: f64 = A / 3.0;
const VAR_VALUE1: f64 = B / 3.0;

#[test]
fn lattice_noise_moments_match_derivation() {
    // 10⁶ points spread over ~10⁹ cells are effectively independent. Var estimate: relative
    // standard error ≈ sqrt((κ − 1)/n) < 2e-3 for these bounded noises; tolerance 2 % (> 10σ).
    // Mean: σ = sqrt(Var/n) ≤ 4e-4; tolerance 3e-3 (> 7σ).
    for (name, var, f) in [
        (
            "gradient3",
            VAR_GRADIENT3,
            gradient3 as fn(Vec3, u32) -> f32,
        ),
        ("value3", VAR_VALUE3, value3),
    ] {
        let (m, v) = moments(N, 500.0, 1, |p| f(p, 9));
        assert!(m.abs() < 3e-3, "{name} mean {m}");
        assert!(
            (v / var - 1.0).abs() < 0.02,
            "{name} var {v} vs derived {var}"
        );
    }
    // 1D: 4·10⁴ cells along x (|x| ≤ 2·10⁴), so fewer independent cells: σ(var)/var ≈ 1 %;
    // tolerance 5 %.
    for (name, var, f) in [
        ("gradient1", VAR_GRADIENT1, gradient1 as fn(f32, u32) -> f32),
        ("value1", VAR_VALUE1, value1),
    ] {
        let (m, v) = moments(N / 4, 2e4, 2, |p| f(p.x, 9));
        assert!(m.abs() < 0.02, "{name} mean {m}");
        assert!(
            (v / var - 1.0).abs() < 0.05,
            "{name} var {v} vs derived {var}"
        );
    }
}

#[test]
fn ranges() {
    let mut r = Pcg32::new(5, 0);
    for _ in 0..N / 2 {
        let p = random_point(&mut r, 100.0);
        // Gradient noise: measured ±1.03 over 10⁶ points; the usual normalisation of improved
        // Perlin noise (≈ 1/0.96) implies the same; 1.1 leaves margin but catches a scaling bug.
        assert!(gradient3(p, 3).abs() < 1.1);
        // Value noise is a convex combination of values in [−1, 1).
        assert!((-1.0..1.0).contains(&value3(p, 3)));
        // 1D gradient: |g₀ t (1 − u) + g₁ (t − 1) u| ≤ t(1 − u) + (1 − t)u ≤ ½ (max at t = ½).
        assert!(gradient1(p.x, 3).abs() <= 0.5);
        assert!((-1.0..1.0).contains(&value1(p.x, 3)));
    }
    // Gradient noise vanishes on the lattice.
    assert_eq!(gradient3(Vec3::new(3.0, -7.0, 12.0), 1), 0.0);
}

#[test]
fn deterministic_and_seed_sensitive() {
    let mut r = Pcg32::new(8, 0);
    let sc = SparseConvolution {
        weights: Weights::Signed,
        ..Default::default()
    };
    let (mut differ, mut s_ab, mut s_aa, mut s_bb) = (0, 0.0f64, 0.0f64, 0.0f64);
    let (mut sc_differ, mut sc_nonzero) = (0, 0);
    let n = 20_000;
    for _ in 0..n {
        let p = random_point(&mut r, 50.0);
        assert_eq!(gradient3(p, 4).to_bits(), gradient3(p, 4).to_bits());
        assert_eq!(value3(p, 4).to_bits(), value3(p, 4).to_bits());
        assert_eq!(sc.eval(p, 4).to_bits(), sc.eval(p, 4).to_bits());
        let (a, b) = (gradient3(p, 4) as f64, gradient3(p, 5) as f64);
        differ += (a != b) as i32;
        s_ab += a * b;
        s_aa += a * a;
        s_bb += b * b;
        sc_differ += (sc.eval(p, 4) != sc.eval(p, 5)) as i32;
        sc_nonzero += (sc.eval(p, 4) != 0.0) as i32;
    }
    assert!(differ as f64 > 0.99 * n as f64);
    // P(no kernel overlaps) = e⁻⁴ ≈ 2 %, for each seed.
    assert!(sc_differ as f64 > 0.95 * n as f64 && sc_nonzero as f64 > 0.95 * n as f64);
    // Correlation between seeds: σ ≈ 1/sqrt(n) = 0.007; tolerance 0.035 (5σ).
    let corr = s_ab / (s_aa * s_bb).sqrt();
    assert!(corr.abs() < 0.035, "seed correlation {corr}");
}

/// Fourth-order central differences (stencil −1, 8, −8, 1 over 12h) accumulated in f64. f32
/// rounding leaves ≈ 1e-6 of noise in the values; the wide stencil keeps its effect on the
/// derivative near 1e-4 while the truncation error stays O(h⁴).
fn central(f: &impl Fn(Vec3) -> f32, p: Vec3, h: f32) -> Vec3 {
    let d = |e: Vec3| {
        let v = |k: f32| f(p + e * (k * h)) as f64;
        (v(-2.0) - 8.0 * v(-1.0) + 8.0 * v(1.0) - v(2.0)) / (12.0 * h as f64)
    };
    Vec3::new(d(Vec3::X) as f32, d(Vec3::Y) as f32, d(Vec3::Z) as f32)
}

fn check_gradient(
    name: &str,
    f: impl Fn(Vec3) -> f32,
    g: impl Fn(Vec3) -> (f32, Vec3),
    half: f32,
    h: f32,
) {
    check_gradient_creased(name, f, g, half, h, 0.2)
}

/// [`check_gradient`] allowing a fraction `max_skipped` of points near creases (turbulence and
/// ridged sums fold every octave at its zero set).
fn check_gradient_creased(
    name: &str,
    f: impl Fn(Vec3) -> f32,
    g: impl Fn(Vec3) -> (f32, Vec3),
    half: f32,
    h: f32,
    max_skipped: f32,
) {
    // Relative error ≤ 1e-3; the floor (a tenth of the largest gradient seen) keeps points where
    // the gradient nearly vanishes from dividing rounding noise by zero.
    let mut r = Pcg32::new(21, 0);
    let mut scale = 0.0f32;
    let pts: Vec<Vec3> = (0..2000).map(|_| random_point(&mut r, half)).collect();
    for &p in &pts {
        scale = scale.max(g(p).1.length());
    }
    assert!(scale > 0.0, "{name}: all gradients vanish");
    let mut skipped = 0;
    for &p in &pts {
        let (v, an) = g(p);
        // Same value up to rounding (the _grad form expands the blend differently, and a domain
        // warp amplifies that by its strength and inner gradients).
        assert!(
            (v - f(p)).abs() <= 1e-4 * (1.0 + v.abs()),
            "{name}: value of _grad differs"
        );
        let tol = 1e-3 * an.length().max(0.1 * scale);
        let (fd, fd_half, fd_double) = (
            central(&f, p, h),
            central(&f, p, 0.5 * h),
            central(&f, p, 2.0 * h),
        );
        // "Away from edges": where the stencil straddles a cell face or a kernel's support
        // boundary (a jump in a higher derivative), differences with steps h/2, h and 2h disagree
        // (their errors scale differently); such points are skipped, and must be rare.
        if (fd - fd_half).length() > 0.5 * tol || (fd - fd_double).length() > 0.5 * tol {
            skipped += 1;
            continue;
        }
        let err = (an - fd).length();
        assert!(
            err <= tol,
            "{name} at {p}: analytic {an} vs differences {fd}"
        );
    }
    assert!(
        (skipped as f32) < max_skipped * pts.len() as f32,
        "{name}: {skipped} of {} points skipped",
        pts.len()
    );
}

#[test]
fn analytic_gradients_match_central_differences() {
    check_gradient(
        "gradient3",
        |p| gradient3(p, 1),
        |p| gradient3_grad(p, 1),
        8.0,
        1e-2,
    );
    check_gradient("value3", |p| value3(p, 1), |p| value3_grad(p, 1), 8.0, 1e-2);
    let one = |f: fn(f32, u32) -> (f32, f32)| move |p: Vec3| (f(p.x, 2).0, Vec3::X * f(p.x, 2).1);
    check_gradient(
        "gradient1",
        |p| gradient1(p.x, 2),
        one(gradient1_grad),
        8.0,
        1e-2,
    );
    check_gradient("value1", |p| value1(p.x, 2), one(value1_grad), 8.0, 1e-2);

    let wy = SparseConvolution {
        weights: Weights::Signed,
        envelope: Vec3::new(1.0, 0.7, 2.0),
        cell: Vec3::new(1.0, 1.0, 2.0),
        bands: 3,
        ..Default::default()
    };
    check_gradient(
        "sparse wyvill",
        |p| wy.eval(p, 3),
        |p| wy.eval_grad(p, 3),
        6.0,
        2e-3,
    );
    // Steps are a hundredth of the smallest kernel (band 3: 0.175); bump kernels are steeper.
    let bump = SparseConvolution {
        kernel: Kernel::Bump { sharpness: 1.0 },
        bands: 1,
        ..wy
    };
    check_gradient(
        "sparse bump",
        |p| bump.eval(p, 3),
        |p| bump.eval_grad(p, 3),
        6.0,
        3e-3,
    );
    let f = Frame::from_normal(Vec3::new(0.3, -0.5, 1.0).normalize());
    check_gradient(
        "sparse oriented",
        |p| wy.eval_oriented(p, &f, 3),
        |p| wy.eval_oriented_grad(p, &f, 3),
        6.0,
        2e-3,
    );
    // Cylindrical cells with a fixed frame (the default frame turns with p, and eq. 13 omits ∇R)
    // and kernels small enough that the fit s_b stays 1 for every rotation (eq. 13 omits ∇s_b).
    // At |p| ≈ 10 the f32 spacing (1e-6) limits how small the step can be.
    let cyl = SparseConvolution {
        cells: Cells::Cylindrical,
        envelope: Vec3::new(0.5, 0.5, 0.9),
        bands: 1,
        ..wy
    };
    check_gradient(
        "sparse cylindrical",
        |p| cyl.eval_oriented(p + Vec3::new(8.0, 0.0, 0.0), &f, 3),
        |p| cyl.eval_oriented_grad(p + Vec3::new(8.0, 0.0, 0.0), &f, 3),
        4.0,
        5e-3,
    );
    let s1 = SparseConvolution1::new(0.7, 3);
    check_gradient(
        "sparse 1D",
        |p| s1.eval(p.x).0,
        |p| (s1.eval(p.x).0, Vec3::X * s1.eval(p.x).1),
        8.0,
        2e-3,
    );
}

#[test]
fn bounded_1d_sparse_noise_matches_its_derived_moments() {
    // notes/noise.md "Bounded 1D sparse convolution noise": mean 0, Var n = 512/3003,
    // Var n′ h² = 2304/3465 (Campbell's theorem; ±1 signs make them those of Poisson impulses),
    // mean zero-crossing spacing 1.978 h (Kac–Rice, Monte Carlo ±0.3 %). 200 seeds × 5000 points
    // over 4000 cells each: ≈ 4·10⁵ independent cells, relative standard error of each variance
    // < 0.5 %, tolerance 3 %; mean: σ ≈ 7·10⁻⁴, tolerance 4·10⁻³.
    let h = 0.7f32;
    let mut r = Pcg32::new(17, 0);
    let (mut s, mut s2, mut d2, mut n) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for seed in 0..200 {
        let noise = SparseConvolution1::new(h, seed);
        for _ in 0..5000 {
            let (v, d) = noise.eval((r.next_f32() - 0.5) * 4000.0 * h);
            s += v as f64;
            s2 += (v * v) as f64;
            d2 += (d * h * d * h) as f64;
            n += 1.0;
        }
    }
    let (m, var, dvar) = (s / n, s2 / n - (s / n).powi(2), d2 / n);
    assert!(m.abs() < 4e-3, "mean {m}");
    assert!((var / (512.0 / 3003.0) - 1.0).abs() < 0.03, "var {var}");
    assert!(
        (dvar / (2304.0 / 3465.0) - 1.0).abs() < 0.03,
        "slope var {dvar}"
    );
    let std = SparseConvolution1::STD as f64;
    assert!((std * std / (512.0 / 3003.0) - 1.0).abs() < 1e-5);
    let std_slope = SparseConvolution1::STD_SLOPE as f64;
    assert!((std_slope * std_slope / (2304.0 / 3465.0) - 1.0).abs() < 1e-5);
    // Zero crossings every h/400 over 2000 h for 50 seeds: ≈ 5·10⁴ spacings with a coefficient
    // of variation ≈ 0.7, so the mean has a standard error of 0.3 %; tolerance 3 %.
    let (mut crossings, mut length) = (0usize, 0.0f64);
    for seed in 0..50 {
        let noise = SparseConvolution1::new(h, 1000 + seed);
        let (mut first, mut last, mut prev) = (None, 0.0f64, noise.eval(0.0).0);
        for i in 1..800_000 {
            let x = i as f32 * h / 400.0;
            let v = noise.eval(x).0;
            if v != 0.0 && prev != 0.0 && v.signum() != prev.signum() {
                first.get_or_insert(x as f64);
                last = x as f64;
                crossings += 1;
            }
            if v != 0.0 {
                prev = v;
            }
        }
        length += last - first.unwrap();
        crossings -= 1;
    }
    let spacing = length / crossings as f64 / h as f64;
    assert!(
        (spacing / SparseConvolution1::ZERO_SPACING as f64 - 1.0).abs() < 0.03,
        "mean zero-crossing spacing {spacing} h"
    );
}

#[test]
fn continuous_across_cell_boundaries_near_and_far() {
    // On a lattice plane x = k, the values just left and right differ by at most 2ε·max|∇n|.
    // |∇n| ≤ 8 is a loose bound (measured max ≈ 2.5 for gradient, 3.8 for value noise).
    let mut r = Pcg32::new(3, 0);
    for far in [0.0f32, 1e5] {
        // ε must exceed the f32 spacing at the coordinate (2⁻⁷ at 1e5).
        let eps = if far > 0.0 { 1.0 / 64.0 } else { 1e-4 };
        for _ in 0..20_000 {
            let mut p = random_point(&mut r, 50.0) + Vec3::splat(far);
            let axis = (r.next_u32() % 3) as usize;
            p[axis] = p[axis].round();
            let mut e = Vec3::ZERO;
            e[axis] = eps;
            for (name, f) in [
                ("gradient3", gradient3 as fn(Vec3, u32) -> f32),
                ("value3", value3),
            ] {
                let jump = (f(p + e, 1) - f(p - e, 1)).abs();
                assert!(jump <= 2.0 * eps * 8.0, "{name} jumps {jump} at {p}");
            }
        }
    }
}

#[test]
fn far_from_origin_keeps_variance() {
    // Near the origin vs around 1e5: same variance within 10 % (each estimate ±1 % at 2·10⁵
    // points), and no lattice artefact: the values are not constant along a line.
    let (_, near) = moments(N / 5, 50.0, 4, |p| gradient3(p, 2));
    let (_, far) = moments(N / 5, 50.0, 4, |p| gradient3(p + Vec3::splat(1e5), 2));
    assert!((far / near - 1.0).abs() < 0.10, "var near {near} far {far}");
    let (_, vfar) = moments(N / 5, 50.0, 4, |p| value3(p + Vec3::new(-1e5, 1e5, 3e4), 2));
    assert!(
        (vfar / VAR_VALUE3 - 1.0).abs() < 0.10,
        "value var far {vfar}"
    );
}

#[test]
fn gradient_noise_is_isotropic() {
    // Directional-derivative variance along x, y, z and the diagonal: within 5 % of each other.
    // Each estimate has relative σ ≈ 0.3 % at 10⁶ points.
    let dirs = [Vec3::X, Vec3::Y, Vec3::Z, Vec3::ONE.normalize()];
    let mut s2 = [0.0f64; 4];
    let mut r = Pcg32::new(6, 0);
    for _ in 0..N {
        let (_, g) = gradient3_grad(random_point(&mut r, 500.0), 1);
        for (k, d) in dirs.iter().enumerate() {
            s2[k] += (g.dot(*d) as f64).powi(2);
        }
    }
    let (lo, hi) = s2
        .iter()
        .fold((f64::MAX, 0.0f64), |(a, b), &v| (a.min(v), b.max(v)));
    assert!(hi / lo < 1.05, "directional variances {s2:?}");
}

#[test]
fn sparse_convolution_moments_match_campbell() {
    // Campbell's theorem for a Poisson process of intensity λ (notes/noise.md): with the Wyvill
    // kernel, mean = λ E[w] ∫K = density·48/315, Var = λ E[w²] ∫K² = density·1024/15015 (unit
    // weights; E[w²] = ⅓ for signed). Relative σ of the variance estimate ≈ 0.5 % at 2·10⁵ points
    // (heavier tails than Gaussian); tolerance 3 %.
    let density = 3.0;
    let unit = SparseConvolution {
        density,
        envelope: Vec3::new(0.5, 0.8, 1.2),
        cell: Vec3::new(0.6, 0.8, 1.2),
        magnitude: 1.0,
        ..Default::default()
    };
    let (m, v) = moments(N / 5, 200.0, 7, |p| unit.eval(p, 1));
    let (m0, v0) = (
        density as f64 * 48.0 / 315.0,
        density as f64 * 1024.0 / 15015.0,
    );
    assert!((m / m0 - 1.0).abs() < 0.01, "mean {m} vs {m0}");
    assert!((v / v0 - 1.0).abs() < 0.03, "var {v} vs {v0}");
    let signed = SparseConvolution {
        weights: Weights::Signed,
        cells: Cells::Cylindrical,
        ..unit
    };
    // Kernels along (r̂, θ̂, ẑ) fit the cells unshrunk, so the nominal density holds.
    let (m, v) = moments(N / 5, 200.0, 8, |p| signed.eval(p, 1));
    assert!(m.abs() < 0.01, "signed mean {m}");
    assert!(
        (v / (v0 / 3.0) - 1.0).abs() < 0.03,
        "signed var {v} vs {}",
        v0 / 3.0
    );
}

#[test]
fn impulse_density_is_as_requested() {
    // Impulses per cell: Poisson with mean m; over 10⁵ cells σ(mean) = sqrt(m / 10⁵) ≈ 0.15 %
    // of m = 4.2; tolerance 2 % (> 10σ).
    let sc = SparseConvolution {
        density: 2.0,
        envelope: Vec3::new(0.3, 0.3, 0.6),
        cell: Vec3::new(0.4, 0.4, 0.8),
        ..Default::default()
    };
    let m = sc.impulses_per_cell();
    let n = 100_000;
    let total: u64 = (0..n)
        .map(|i| sc.cell_impulse_count([i % 47, (i / 47) % 53, i / (47 * 53)], 3) as u64)
        .sum();
    let mean = total as f64 / n as f64;
    assert!((mean / m as f64 - 1.0).abs() < 0.02, "{mean} vs {m}");
    // With the box kernel (bump, s = 0: K = 1 inside), the noise counts the kernels overlapping a
    // point; its mean must be the requested density, for Cartesian and cylindrical cells.
    for cells in [Cells::Cartesian, Cells::Cylindrical] {
        let boxes = SparseConvolution {
            kernel: Kernel::Bump { sharpness: 0.0 },
            cells,
            ..sc
        };
        let (mean, var) = moments(N / 5, 60.0, 9, |p| boxes.eval(p, 5));
        // Count is Poisson(density): σ(mean) = sqrt(2/2·10⁵) = 0.3 %.
        assert!(
            (mean / 2.0 - 1.0).abs() < 0.02,
            "{cells:?} overlap mean {mean}"
        );
        assert!(
            (var / 2.0 - 1.0).abs() < 0.05,
            "{cells:?} overlap variance {var}"
        );
    }
}

#[test]
fn sparse_convolution_is_finite_everywhere() {
    let mut r = Pcg32::new(12, 0);
    let kinds = [
        Kernel::Wyvill,
        Kernel::Bump { sharpness: 0.0 },
        Kernel::Bump { sharpness: 40.0 },
    ];
    for kernel in kinds {
        for cells in [Cells::Cartesian, Cells::Cylindrical] {
            let sc = SparseConvolution {
                kernel,
                cells,
                bands: 4,
                weights: Weights::Signed,
                ..Default::default()
            };
            sc.validate().unwrap();
            for p in [Vec3::ZERO, Vec3::new(0.0, 0.0, 5.0), Vec3::splat(-1e5)] {
                let (v, g) = sc.eval_grad(p, 1);
                assert!(
                    v.is_finite() && g.is_finite(),
                    "{kernel:?} {cells:?} at {p}"
                );
            }
            for _ in 0..2000 {
                let p = random_point(&mut r, 30.0);
                let f = Frame::from_normal(uniform_sphere(r.next_vec2()));
                let (v, g) = sc.eval_oriented_grad(p, &f, 1);
                assert!(v.is_finite() && g.is_finite());
            }
        }
    }
}

#[test]
fn bad_parameters_are_named() {
    let bad = SparseConvolution {
        density: -1.0,
        ..Default::default()
    };
    let e = bad.validate().unwrap_err().to_string();
    assert!(e.contains("density") && e.contains("(0, ∞)"), "{e}");
    let bad = SparseConvolution {
        size_factor: 1.5,
        ..Default::default()
    };
    assert!(bad
        .validate()
        .unwrap_err()
        .to_string()
        .contains("size_factor"));
    let dense = SparseConvolution {
        density: 1000.0,
        cell: Vec3::splat(2.0),
        ..Default::default()
    };
    assert!(dense
        .validate()
        .unwrap_err()
        .to_string()
        .contains("impulses per cell"));
}

#[test]
fn fbm_variance_is_sum_of_octaves() {
    // Octaves use independent seeds, so Var(Σ aᵢ nᵢ) = Var(n) Σ gain²ⁱ (derived, notes/noise.md).
    let f = Fractal::fbm(5);
    let sum2: f64 = (0..5).map(|i| 0.25f64.powi(i)).sum();
    let (m, v) = moments(N / 2, 500.0, 10, |p| f.eval(p, 3));
    let want = VAR_GRADIENT3 * sum2;
    assert!(m.abs() < 5e-3, "fbm mean {m}");
    assert!((v / want - 1.0).abs() < 0.03, "fbm var {v} vs {want}");
    // eval (four octaves per SIMD call) and eval_grad (scalar) agree.
    let mut r = Pcg32::new(2, 0);
    for _ in 0..10_000 {
        let p = random_point(&mut r, 100.0);
        let (a, b) = (f.eval(p, 3), f.eval_grad(p, 3).0);
        assert!((a - b).abs() < 1e-5, "{a} vs {b}");
    }
}

#[test]
fn fractal_and_warp_gradients_match_central_differences() {
    for kind in [
        FractalKind::Fbm,
        FractalKind::Turbulence,
        FractalKind::Ridged,
    ] {
        for basis in [Basis::Gradient, Basis::Value] {
            let f = Fractal {
                kind,
                basis,
                octaves: 4,
                ..Default::default()
            };
            // Octave 4 has period 1/8; the step stays well inside it. Turbulence and ridged
            // sums have creases at every octave's zero set.
            let creased = if kind == FractalKind::Fbm { 0.2 } else { 0.6 };
            check_gradient_creased(
                &format!("{kind:?} {basis:?}"),
                |p| f.eval(p, 5),
                |p| f.eval_grad(p, 5),
                4.0,
                2e-3,
                creased,
            );
        }
    }
    // Warps compound the fBm's gradients (|∇| up to ~20 here), so a finer step.
    for levels in [1, 2] {
        let w = Warp {
            levels,
            strength: 1.0,
            fractal: Fractal::fbm(3),
        };
        // Four (one level) or seven (two levels) fBm lookups of three octaves each: their lattice
        // faces, where the quintic fade's third derivative jumps, come 21 per unit length per
        // lookup, so 20–50 % of the stencils straddle one and are skipped.
        check_gradient_creased(
            &format!("warp {levels}"),
            |p| w.eval(p, 5),
            |p| w.eval_grad(p, 5),
            4.0,
            1e-3,
            0.6,
        );
    }
}

#[test]
fn cellular_is_exact_and_has_right_gradients() {
    let mut r = Pcg32::new(13, 0);
    for jitter in [0.0f32, 0.5, 1.0] {
        for _ in 0..3000 {
            let p = random_point(&mut r, 40.0);
            let c = cellular3(p, jitter, 4);
            // Brute force over a 7×7×7 block: the same two distances.
            let base = [p.x.floor() as i32, p.y.floor() as i32, p.z.floor() as i32];
            let mut d = Vec::with_capacity(343);
            for dz in -3..=3 {
                for dy in -3..=3 {
                    for dx in -3..=3 {
                        let cell = [base[0] + dx, base[1] + dy, base[2] + dz];
                        d.push((p - feature_point(cell, jitter, 4)).length());
                    }
                }
            }
            d.sort_by(|a, b| a.partial_cmp(b).unwrap());
            assert!(
                (c.f1 - d[0]).abs() < 1e-5 && (c.f2 - d[1]).abs() < 1e-5,
                "{c:?} vs {:?}",
                &d[..2]
            );
            assert!(c.f1 <= c.f2 && c.f1 >= 0.0 && c.f2.is_finite());
            // F1 is the distance to `nearest`, which is a feature point: F1 there is 0.
            assert!(((p - c.nearest).length() - c.f1).abs() < 1e-4);
            assert!(cellular3(c.nearest, jitter, 4).f1 < 1e-3);
            // Gradient of F1 is the unit vector away from the nearest point.
            if c.f1 > 1e-3 {
                assert!((c.grad_f1.length() - 1.0).abs() < 1e-4);
            }
        }
    }
    let c0 = cellular3(Vec3::new(0.3, 0.2, 0.9), 1.0, 4);
    assert_eq!(c0, cellular3(Vec3::new(0.3, 0.2, 0.9), 1.0, 4));
    assert_ne!(c0.f1, cellular3(Vec3::new(0.3, 0.2, 0.9), 1.0, 5).f1);
    // F1 and F2 are smooth except where the nearest or second-nearest point changes; compare
    // with differences only where both points are the same over the whole stencil.
    let h = 1e-3f32;
    let mut compared = 0;
    for _ in 0..3000 {
        let p = random_point(&mut r, 20.0);
        let c = cellular3(p, 1.0, 6);
        let second = |c: &CellularSample, q: Vec3| q - c.grad_f2 * c.f2;
        let stable = [Vec3::X, Vec3::Y, Vec3::Z].iter().all(|&e| {
            [-2.0f32, -1.0, 1.0, 2.0].iter().all(|&k| {
                let q = p + e * (k * h);
                let d = cellular3(q, 1.0, 6);
                d.id == c.id && (second(&d, q) - second(&c, p)).length() < 1e-3
            })
        });
        if !stable {
            continue;
        }
        compared += 1;
        let fd = central(&|q| cellular3(q, 1.0, 6).edge(), p, h);
        let err = (fd - c.grad_edge()).length();
        assert!(
            err <= 1e-3 * c.grad_edge().length().max(0.1),
            "F2-F1 at {p}: {fd} vs {c:?}"
        );
    }
    assert!(compared > 2500, "only {compared} stable points");
}

#[test]
fn cellular_moments() {
    // jitter 0: feature points at the cell centres, so F1 is the distance from a uniform point in
    // a unit cube to its centre: mean 0.48029 (numerical integral, notes/noise.md). σ(mean) ≈
    // 1.5e-4 at 10⁶ points; tolerance 1 %.
    let (m, _) = moments(N / 2, 100.0, 14, |p| cellular3(p, 0.0, 1).f1);
    assert!((m / 0.480_29 - 1.0).abs() < 0.01, "F1 mean {m}");
    // jitter 1: mean F1 measured once as 0.5206 (5·10⁵ points); tolerance 2 %.
    let (m1, _) = moments(N / 2, 100.0, 15, |p| cellular3(p, 1.0, 1).f1);
    assert!((m1 / 0.5206 - 1.0).abs() < 0.02, "F1 mean (jitter 1) {m1}");
}
