//! The noise benchmark behind `xylem bench noise`: evaluations per second (one thread) of each
//! noise over the same random points as the criterion bench (the batch calls `gradient3_many` and
//! `Fractal::eval_many` on each instruction set the CPU has, then one call per point)
//! (`cargo bench --bench noise`, which also times the peers noise-rs and fastnoise-lite). Best of
//! several passes, so a shared machine's interruptions count less; figures in notes/noise.md.

use glam::Vec3;
use std::time::Instant;
use xylem::math::{Frame, Pcg32};
use xylem::noise::{
    cellular3, gradient3, gradient3_grad, gradient3_many_with, value3, Cells, Fractal, FractalKind,
    Kernel, SparseConvolution, Warp, Weights,
};
use xylem::simd::Simd;

/// The benchmark points: uniform in [0, 64)³ (the criterion bench uses the same).
pub fn bench_points(n: usize) -> Vec<Vec3> {
    let mut r = Pcg32::new(2024, 0);
    (0..n)
        .map(|_| Vec3::new(r.next_f32(), r.next_f32(), r.next_f32()) * 64.0)
        .collect()
}

/// Million points per second of a batch call `f(points, out)`, best of `passes`.
fn batch_rate(points: &[Vec3], passes: usize, f: impl Fn(&[Vec3], &mut [f32])) -> f64 {
    let mut out = vec![0.0f32; points.len()];
    let mut best = f64::INFINITY;
    for _ in 0..passes.max(1) {
        let t = Instant::now();
        f(std::hint::black_box(points), &mut out);
        best = best.min(t.elapsed().as_secs_f64());
        std::hint::black_box(&out);
    }
    points.len() as f64 / best / 1e6
}

/// Million evaluations per second of `f` over `points`, best of `passes`.
fn rate(points: &[Vec3], passes: usize, f: impl Fn(Vec3) -> f32) -> f64 {
    let mut best = f64::INFINITY;
    let mut sink = 0.0f32;
    for _ in 0..passes.max(1) {
        let t = Instant::now();
        for &p in points {
            sink += f(std::hint::black_box(p));
        }
        best = best.min(t.elapsed().as_secs_f64());
    }
    std::hint::black_box(sink);
    points.len() as f64 / best / 1e6
}

/// (function, million evaluations per second) of every noise over `points` random points,
/// best of `passes` passes each: the batch calls on every instruction set this CPU has,
/// widest first, then one call per point.
pub fn rates(points: usize, passes: usize) -> Vec<(String, f64)> {
    let pts = bench_points(points.max(1));
    let n = passes;
    let fbm5 = Fractal::fbm(5);
    let turb5 = Fractal {
        kind: FractalKind::Turbulence,
        ..Fractal::fbm(5)
    };
    let warp = Warp::default();
    let sparse = SparseConvolution::default();
    let pores = SparseConvolution {
        kernel: Kernel::Bump { sharpness: 1.0 },
        density: 0.5,
        envelope: Vec3::new(0.3, 0.3, 2.0),
        cell: Vec3::new(0.6, 0.6, 2.5),
        ..Default::default()
    };
    let rays = SparseConvolution {
        cells: Cells::Cylindrical,
        envelope: Vec3::new(3.0, 0.2, 1.0),
        cell: Vec3::new(3.0, 0.6, 1.5),
        density: 1.0,
        ..pores
    };
    let bands = SparseConvolution {
        weights: Weights::Signed,
        bands: 3,
        ..sparse
    };
    let frame = Frame::from_normal(Vec3::new(0.2, 0.1, 1.0).normalize());
    // The batch calls on every instruction set this CPU has, widest first (the first row of each
    // is what `gradient3_many` / `Fractal::eval_many` use).
    let isas: Vec<Simd> = Simd::ALL
        .into_iter()
        .rev()
        .filter(|&s| s <= Simd::best())
        .collect();
    let mut rows: Vec<(String, f64)> = Vec::new();
    for &s in &isas {
        let name = match s {
            Simd::Scalar => "gradient3_many (scalar)".to_string(),
            _ => format!("gradient3_many ({}, {} lanes)", s.name(), s.lanes()),
        };
        let r = batch_rate(&pts, n, |p, o| gradient3_many_with(s, p, 7, o));
        rows.push((name, r));
    }
    // (Without lanes `eval_many` is the per-point `eval`, its own row below.)
    for &s in isas.iter().filter(|&&s| s != Simd::Scalar) {
        let name = format!("fbm5 eval_many ({}, {} lanes)", s.name(), s.lanes());
        let r = batch_rate(&pts, n, |p, o| fbm5.eval_many_with(s, p, 7, o));
        rows.push((name, r));
    }
    let single: Vec<(&str, f64)> = vec![
        ("gradient3", rate(&pts, n, |p| gradient3(p, 7))),
        ("gradient3_grad", rate(&pts, n, |p| gradient3_grad(p, 7).0)),
        ("value3", rate(&pts, n, |p| value3(p, 7))),
        ("fbm5 (eval per point)", rate(&pts, n, |p| fbm5.eval(p, 7))),
        ("fbm5 eval_grad", rate(&pts, n, |p| fbm5.eval_grad(p, 7).0)),
        ("turbulence5", rate(&pts, n, |p| turb5.eval(p, 7))),
        ("cellular3", rate(&pts, n, |p| cellular3(p, 1.0, 7).f1)),
        ("warp (2 levels, fbm4)", rate(&pts, n, |p| warp.eval(p, 7))),
        (
            "sparse Wyvill, density 4",
            rate(&pts, n, |p| sparse.eval(p, 7)),
        ),
        (
            "sparse Wyvill, 3 bands",
            rate(&pts, n, |p| bands.eval(p, 7)),
        ),
        (
            "sparse bump, oriented (pores)",
            rate(&pts, n, |p| pores.eval_oriented(p, &frame, 7)),
        ),
        (
            "sparse bump, cylindrical (rays)",
            rate(&pts, n, |p| rays.eval(p + Vec3::new(40.0, 0.0, 0.0), 7)),
        ),
    ];
    rows.extend(single.into_iter().map(|(k, v)| (k.to_string(), v)));
    rows
}
