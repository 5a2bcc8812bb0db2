//! Criterion version of `xylem bench trace`: closest-hit and any-hit traversal of coherent and
//! incoherent rays through the obvhs CWBVH of a bumpy sphere, and the BVH build.
//! Run: `cargo bench --bench trace -- --warm-up-time 1 --measurement-time 3`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::sync::Arc;
use xylem::material::Placement;
use xylem::render::{Accel, Instance, Transform};
use xylem_lab::bench::trace::{bumpy_sphere, coherent_rays, incoherent_rays};

fn accel(triangles: usize) -> Accel {
    Accel::new(vec![Instance {
        mesh: Arc::new(bumpy_sphere(triangles)),
        transform: Transform::identity(),
        material: 0,
        placement: Placement::default(),
    }])
}

fn trace(c: &mut Criterion) {
    let a = accel(250_000);
    let n = 10_000;
    let mut g = c.benchmark_group("trace_250k");
    g.throughput(Throughput::Elements(n as u64));
    for (name, rays) in [
        ("coherent", coherent_rays(n)),
        ("incoherent", incoherent_rays(n, 1)),
    ] {
        g.bench_function(format!("closest_{name}"), |b| {
            b.iter(|| {
                rays.iter()
                    .filter(|r| a.intersect(r, f32::INFINITY).is_some())
                    .count()
            })
        });
        g.bench_function(format!("any_{name}"), |b| {
            b.iter(|| {
                rays.iter()
                    .filter(|r| a.unoccluded(r, f32::INFINITY))
                    .count()
            })
        });
    }
    g.finish();
    let mut g = c.benchmark_group("build");
    g.sample_size(10);
    let mesh = Arc::new(bumpy_sphere(100_000));
    g.bench_function("medium_100k", |b| {
        b.iter(|| {
            Accel::new(vec![Instance {
                mesh: mesh.clone(),
                transform: Transform::identity(),
                material: 0,
                placement: Placement::default(),
            }])
            .triangle_count()
        })
    });
    g.finish();
}

criterion_group!(benches, trace);
criterion_main!(benches);
