//! `cargo bench --bench wood`: wood texels per second (one thread) for every species preset, with
//! `needs` = colour only (in batches, `eval_many`, and point by point, `eval`) and = everything.
//! Results: target/criterion/wood/<preset>/<id>/.
//! Figures and machine: notes/wood.md (also `xylem bench wood`, which prints the table).

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use std::time::Duration;
use xylem::wood::{preset, sample_points, Needs, WoodTexel, WoodVolume, PRESET_NAMES};

const POINTS: usize = 2048;

fn bench(c: &mut Criterion) {
    let points = sample_points(POINTS, 42);
    for name in PRESET_NAMES {
        let volume = WoodVolume::new(preset(name).unwrap(), 1).unwrap();
        let mut group = c.benchmark_group(format!("wood/{name}"));
        group.throughput(Throughput::Elements(POINTS as u64));
        group.warm_up_time(Duration::from_millis(500));
        group.measurement_time(Duration::from_secs(2));
        group.sample_size(20);
        let mut out = vec![WoodTexel::default(); POINTS];
        group.bench_function("colour_batch", |b| {
            b.iter(|| {
                volume.eval_many(black_box(&points), Needs::COLOR, &mut out);
                out.iter().map(|t| t.diffuse.x).sum::<f32>()
            })
        });
        for (id, needs) in [("colour", Needs::COLOR), ("all", Needs::ALL)] {
            group.bench_function(id, |b| {
                b.iter(|| {
                    let mut sink = 0.0f32;
                    for &p in &points {
                        let t = volume.eval(black_box(p), needs);
                        sink += t.diffuse.x + t.fiber_dir.z + t.bump;
                    }
                    sink
                })
            });
        }
        group.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
