//! `cargo bench --bench noise`: xylem's 3D gradient noise and 5-octave fBm against the `noise`
//! crate (Perlin, Fbm<Perlin>) and `fastnoise-lite` (Perlin, FBm) over the same random points, one
//! thread, plus xylem's sparse convolution noise. Results: target/criterion/noise/<function>/<id>/.
//! Table and machine: notes/noise.md.
//!
//! `gradient3/xylem` times the batch call `gradient3_many` over the 4096 points (the lane kernel
//! on 16, 8 or 4 points at once, whichever of AVX-512 / AVX2 / SSE2 the CPU has, the same values
//! as `gradient3`); `gradient3/xylem-scalar` times one `gradient3` call per point, like the peers'
//! rows (the batch rows hand `out` to `black_box` instead of summing it: the sum is a serial
//! chain of 4096 dependent adds that the per-point rows overlap with their work). Likewise `fbm5/xylem` times the batch `Fractal::eval_many` (lanes are points, octaves a
//! loop) and `fbm5/xylem-per-point` one `Fractal::eval` call per point (there the octaves share
//! the lanes: AVX2 where the CPU has it, else SSE2).

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use fastnoise_lite::{FastNoiseLite, FractalType, NoiseType};
use noise::{Fbm, MultiFractal, NoiseFn, Perlin};
use xylem::math::{Pcg32, Vec3};
use xylem::noise::{gradient3, gradient3_many, Fractal, SparseConvolution};

const POINTS: usize = 4096;

/// The same points for every library: uniform in [0, 64)³ (f32 and the f64 copy `noise` wants).
fn points() -> (Vec<Vec3>, Vec<[f64; 3]>) {
    let mut r = Pcg32::new(2024, 0);
    let p: Vec<Vec3> = (0..POINTS)
        .map(|_| Vec3::new(r.next_f32(), r.next_f32(), r.next_f32()) * 64.0)
        .collect();
    let q = p
        .iter()
        .map(|v| [v.x as f64, v.y as f64, v.z as f64])
        .collect();
    (p, q)
}

fn fastnoise(octaves: Option<i32>) -> FastNoiseLite {
    let mut f = FastNoiseLite::with_seed(7);
    f.set_noise_type(Some(NoiseType::Perlin));
    f.set_frequency(Some(1.0));
    if let Some(o) = octaves {
        f.set_fractal_type(Some(FractalType::FBm));
        f.set_fractal_octaves(Some(o));
        f.set_fractal_lacunarity(Some(2.0));
        f.set_fractal_gain(Some(0.5));
    }
    f
}

fn bench(c: &mut Criterion) {
    let (p, q) = points();
    let mut g = c.benchmark_group("noise");
    g.throughput(Throughput::Elements(POINTS as u64));

    let mut out = vec![0.0f32; POINTS];
    g.bench_function("gradient3/xylem", |b| {
        b.iter(|| {
            gradient3_many(black_box(&p), 7, &mut out);
            black_box(&mut out);
        })
    });
    g.bench_function("gradient3/xylem-scalar", |b| {
        b.iter(|| p.iter().map(|&x| gradient3(black_box(x), 7)).sum::<f32>())
    });
    let perlin = Perlin::new(7);
    g.bench_function("gradient3/noise-rs", |b| {
        b.iter(|| q.iter().map(|&x| perlin.get(black_box(x))).sum::<f64>())
    });
    let fnl = fastnoise(None);
    g.bench_function("gradient3/fastnoise-lite", |b| {
        b.iter(|| {
            p.iter()
                .map(|&x| {
                    let x = black_box(x);
                    fnl.get_noise_3d(x.x, x.y, x.z)
                })
                .sum::<f32>()
        })
    });

    let fbm = Fractal::fbm(5);
    g.bench_function("fbm5/xylem", |b| {
        b.iter(|| {
            fbm.eval_many(black_box(&p), 7, &mut out);
            black_box(&mut out);
        })
    });
    g.bench_function("fbm5/xylem-per-point", |b| {
        b.iter(|| p.iter().map(|&x| fbm.eval(black_box(x), 7)).sum::<f32>())
    });
    let nfbm = Fbm::<Perlin>::new(7)
        .set_octaves(5)
        .set_lacunarity(2.0)
        .set_persistence(0.5);
    g.bench_function("fbm5/noise-rs", |b| {
        b.iter(|| q.iter().map(|&x| nfbm.get(black_box(x))).sum::<f64>())
    });
    let ffbm = fastnoise(Some(5));
    g.bench_function("fbm5/fastnoise-lite", |b| {
        b.iter(|| {
            p.iter()
                .map(|&x| {
                    let x = black_box(x);
                    ffbm.get_noise_3d(x.x, x.y, x.z)
                })
                .sum::<f32>()
        })
    });

    // Liu 2016 sparse convolution noise, Wyvill kernel, 4 kernels overlapping a point.
    let sc = SparseConvolution::default();
    g.bench_function("sparse3/xylem", |b| {
        b.iter(|| p.iter().map(|&x| sc.eval(black_box(x), 7)).sum::<f32>())
    });
    g.finish();
}

criterion_group!(noise, bench);
criterion_main!(noise);
