//! WoodBsdf per-call cost (one thread): construction, eval, pdf and sample, for a smooth finish,
//! a rough finish and a ray-mask blend. Same workload as `xylem bench bsdf`.
//! Run: cargo bench --bench bsdf -- --warm-up-time 1 --measurement-time 3

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use glam::Vec3;
use xylem::bsdf::{Bsdf, WoodBsdf, WoodBsdfParams};
use xylem::math::{cosine_hemisphere, Pcg32};

fn configs() -> [(&'static str, WoodBsdfParams); 3] {
    let base = WoodBsdfParams::default();
    [
        ("smooth", base),
        (
            "rough",
            WoodBsdfParams {
                roughness: 0.3,
                ..base
            },
        ),
        (
            "ray_blend",
            WoodBsdfParams {
                ray_mask: 0.5,
                fiber_dir: Vec3::new(1.0, 0.0, -0.3).normalize(),
                ray_dir: Vec3::new(0.0, 0.8, -0.6),
                ..base
            },
        ),
    ]
}

fn bench(c: &mut Criterion) {
    let mut rng = Pcg32::new(1, 0);
    let dirs: Vec<(Vec3, Vec3)> = (0..1024)
        .map(|_| {
            (
                cosine_hemisphere(rng.next_vec2()),
                cosine_hemisphere(rng.next_vec2()),
            )
        })
        .collect();
    let us: Vec<(f32, glam::Vec2)> = (0..1024)
        .map(|_| (rng.next_f32(), rng.next_vec2()))
        .collect();
    for (name, p) in configs() {
        let b = WoodBsdf::new(p).unwrap();
        let mut i = 0usize;
        c.bench_function(&format!("wood_{name}_new"), |bn| {
            bn.iter(|| WoodBsdf::new(black_box(p)))
        });
        c.bench_function(&format!("wood_{name}_eval"), |bn| {
            bn.iter(|| {
                i = (i + 1) & 1023;
                let (wo, wi) = dirs[i];
                b.eval(black_box(wo), black_box(wi))
            })
        });
        c.bench_function(&format!("wood_{name}_pdf"), |bn| {
            bn.iter(|| {
                i = (i + 1) & 1023;
                let (wo, wi) = dirs[i];
                b.pdf(black_box(wo), black_box(wi))
            })
        });
        c.bench_function(&format!("wood_{name}_sample"), |bn| {
            bn.iter(|| {
                i = (i + 1) & 1023;
                let (uc, u) = us[i];
                b.sample(black_box(dirs[i].0), black_box(uc), black_box(u))
            })
        });
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
