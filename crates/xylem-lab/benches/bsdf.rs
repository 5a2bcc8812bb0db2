//! WoodBsdf per-call cost (one thread): construction, eval, pdf and sample, for a smooth finish,
//! a rough finish and a ray-mask blend. Same workload as `xylem bench bsdf`.
//! Run: cargo bench --bench bsdf -- --warm-up-time 1 --measurement-time 3

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use xylem::bsdf::{workload, Bsdf, WoodBsdf};

fn bench(c: &mut Criterion) {
    let (dirs, us) = workload::inputs();
    for (name, p) in workload::cases() {
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
