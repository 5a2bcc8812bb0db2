//! The tracing benchmark behind `xylem bench trace` and crates/xylem-lab/benches/trace.rs: a bumpy sphere of about
//! N triangles, a fixed set of coherent (pinhole camera) and incoherent (random) rays, BVH build
//! time and closest-hit / any-hit rays per second on one core, for xylem's wide BVH and, on the
//! same mesh and rays, obvhs's CWBVH traversal (and Embree 3 with the feature `embree-anchor`).

use super::clock::CpuTimer;
use glam::{Vec2, Vec3};
use obvhs::cwbvh::{builder::build_cwbvh_from_tris, CwBvh};
use obvhs::ray::{Ray as BvhRay, RayHit};
use obvhs::rt_triangle::RtTriangle;
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;
use std::sync::Arc;
use std::time::{Duration, Instant};
use xylem::material::Placement;
use xylem::math::{uniform_sphere, Pcg32, PI};
use xylem::render::geometry::{Accel, Instance, Ray, Transform, TriMesh};

/// A sphere of radius 100 mm with a sinusoidal bump, tessellated into about `triangles` triangles.
pub fn bumpy_sphere(triangles: usize) -> TriMesh {
    // A (2n × n) longitude-latitude grid has 4n² triangles (two per cell).
    let n = ((triangles as f64 / 4.0).sqrt().ceil() as usize).max(4);
    let (cols, rows) = (2 * n, n);
    let mut m = TriMesh::default();
    for j in 0..=rows {
        let theta = PI * j as f32 / rows as f32;
        for i in 0..=cols {
            let phi = 2.0 * PI * i as f32 / cols as f32;
            let r = 100.0 * (1.0 + 0.05 * (9.0 * theta).sin() * (7.0 * phi).sin());
            m.positions.push(Vec3::new(
                r * theta.sin() * phi.cos(),
                r * theta.sin() * phi.sin(),
                r * theta.cos(),
            ));
        }
    }
    let w = cols as u32 + 1;
    for j in 0..rows as u32 {
        for i in 0..cols as u32 {
            let a = j * w + i;
            m.indices.push([a, a + w, a + w + 1]);
            m.indices.push([a, a + w + 1, a + 1]);
        }
    }
    m.drop_degenerate();
    m
}

/// `count` camera rays of a pinhole at distance 300 mm looking at the mesh, in scanline order
/// (neighbouring rays are nearly parallel: coherent).
pub fn coherent_rays(count: usize) -> Vec<Ray> {
    let side = (count as f64).sqrt().ceil() as usize;
    let eye = Vec3::new(0.0, -300.0, 40.0);
    let fwd = (Vec3::ZERO - eye).normalize();
    let right = fwd.cross(Vec3::Z).normalize();
    let up = right.cross(fwd);
    let k = (0.5 * 50f32.to_radians()).tan();
    (0..count)
        .map(|i| {
            let (x, y) = ((i % side) as f32, (i / side) as f32);
            let ndc = Vec2::new(
                2.0 * (x + 0.5) / side as f32 - 1.0,
                1.0 - 2.0 * (y + 0.5) / side as f32,
            );
            Ray {
                o: eye,
                d: (fwd + right * ndc.x * k + up * ndc.y * k).normalize(),
            }
        })
        .collect()
}

/// `count` rays from random points in a shell around the sphere's surface (radius 80 to 120 mm)
/// in random directions (incoherent, like diffuse bounces), from a fixed seed.
pub fn incoherent_rays(count: usize, seed: u64) -> Vec<Ray> {
    let mut rng = Pcg32::new(seed, 17);
    (0..count)
        .map(|_| Ray {
            o: uniform_sphere(rng.next_vec2()) * (80.0 + 40.0 * rng.next_f32()),
            d: uniform_sphere(rng.next_vec2()),
        })
        .collect()
}

/// One row of the benchmark report.
#[derive(Clone, Debug, serde::Serialize)]
pub struct TraceFigures {
    /// Rays traced.
    pub rays: usize,
    /// Rays that hit the mesh.
    pub closest_hits: usize,
    /// Closest-hit speed (million rays per second of thread CPU time).
    pub closest_mrays_per_s: f64,
    /// Any-hit (occlusion) speed (million rays per second of thread CPU time).
    pub any_hit_mrays_per_s: f64,
    /// Closest-hit speed with the rays traced two at a time, each pair's traversals stepped in
    /// turn (`Accel::intersect_pair`, as the renderer's waves trace their rays); xylem only.
    pub closest_pair_mrays_per_s: Option<f64>,
}

/// The whole benchmark report (serialised with `--json`).
#[derive(Clone, Debug, serde::Serialize)]
pub struct TraceReport {
    /// Triangles of the mesh.
    pub triangles: usize,
    /// Name of the obvhs build parameters.
    pub build_params: String,
    /// obvhs core build (PLOC + reinsertion + CWBVH conversion), seconds.
    pub build_core_s: f64,
    /// Everything from the mesh to a ready `Accel` (world transform, AABBs, reordering), seconds.
    pub build_total_s: f64,
    /// xylem's wide BVH on the coherent (pinhole camera) rays.
    pub coherent: TraceFigures,
    /// xylem's wide BVH on the incoherent (random) rays.
    pub incoherent: TraceFigures,
    /// The same mesh, build parameters and rays through obvhs's own CWBVH build and traversal
    /// (what the renderer used before the wide BVH), for comparison.
    pub obvhs_cwbvh: CwBvhFigures,
    /// The same mesh and rays through Embree 3 (feature `embree-anchor`).
    pub embree: Option<EmbreeFigures>,
}

/// obvhs CWBVH figures: core build time and both ray sets.
#[derive(Clone, Debug, serde::Serialize)]
pub struct CwBvhFigures {
    /// obvhs's CWBVH build time, seconds.
    pub build_core_s: f64,
    /// Traversal of the coherent rays.
    pub coherent: TraceFigures,
    /// Traversal of the incoherent rays.
    pub incoherent: TraceFigures,
}

/// obvhs's own CWBVH build and traversal of a mesh (object space = world space), with
/// `RtTriangle`s in BVH primitive order: the renderer's tracer before the wide BVH.
pub(crate) struct ObvhsCwBvh {
    bvh: CwBvh,
    tris: Vec<RtTriangle>,
    pub build_time: Duration,
}

impl ObvhsCwBvh {
    pub fn new(mesh: &TriMesh, params: BvhBuildParams) -> Self {
        let world: Vec<Triangle> = (mesh.indices.iter())
            .map(|t| {
                let [a, b, c] = t.map(|i| mesh.positions[i as usize].into());
                Triangle {
                    v0: a,
                    v1: b,
                    v2: c,
                }
            })
            .collect();
        let mut build_time = Duration::ZERO;
        let bvh = build_cwbvh_from_tris(&world, params, &mut build_time);
        let tris = (bvh.primitive_indices.iter())
            .map(|&i| RtTriangle::from(&world[i as usize]))
            .collect();
        ObvhsCwBvh {
            bvh,
            tris,
            build_time,
        }
    }

    /// Times `ray_traverse` (closest hit) and `ray_traverse_miss` (any hit) over `rays`.
    pub fn time_rays(&self, rays: &[Ray]) -> TraceFigures {
        // +0.0 turns −0.0 direction components into +0.0 (obvhs mishandles −0.0).
        let ray = |r: &Ray| BvhRay::new(r.o.into(), (r.d + Vec3::ZERO).into(), 0.0, f32::INFINITY);
        let tris = &self.tris;
        let t0 = CpuTimer::thread();
        let mut hits = 0usize;
        for r in rays {
            let mut hit = RayHit::none();
            hits +=
                (self.bvh).ray_traverse(ray(r), &mut hit, |r, id| tris[id].intersect(r)) as usize;
        }
        let closest = t0.elapsed();
        let t1 = CpuTimer::thread();
        for r in rays {
            std::hint::black_box(
                self.bvh
                    .ray_traverse_miss(ray(r), |r, id| tris[id].intersect(r)),
            );
        }
        figures(rays.len(), hits, closest, t1.elapsed())
    }
}

/// Rays per second from counts and times.
pub fn figures(rays: usize, hits: usize, closest: Duration, any: Duration) -> TraceFigures {
    let rate = |d: Duration| rays as f64 / d.as_secs_f64().max(1e-12) / 1e6;
    TraceFigures {
        rays,
        closest_hits: hits,
        closest_mrays_per_s: rate(closest),
        any_hit_mrays_per_s: rate(any),
        closest_pair_mrays_per_s: None,
    }
}

/// Embree's figures on the same mesh and rays, and xylem's closest-hit speed as a fraction of it.
#[derive(Clone, Debug, serde::Serialize)]
pub struct EmbreeFigures {
    /// Embree's build time, seconds.
    pub build_s: f64,
    /// Embree on the coherent rays.
    pub coherent: TraceFigures,
    /// Embree on the incoherent rays.
    pub incoherent: TraceFigures,
    /// xylem's closest-hit speed over Embree's, coherent rays.
    pub closest_ratio_coherent: f64,
    /// xylem's closest-hit speed over Embree's, incoherent rays.
    pub closest_ratio_incoherent: f64,
    /// xylem's closest-hit speed with rays two at a time over Embree's one at a time, coherent
    /// and incoherent rays (the renderer's tracing against Embree's single-ray queries).
    pub pair_ratio: [f64; 2],
}

/// Traces `rays` closest-hit and any-hit on the calling thread and times both.
pub fn time_rays(accel: &Accel, rays: &[Ray]) -> TraceFigures {
    let t0 = CpuTimer::thread();
    let mut hits = 0usize;
    for r in rays {
        if accel.intersect(r, f32::INFINITY).is_some() {
            hits += 1;
        }
    }
    let closest = t0.elapsed();
    let t1 = CpuTimer::thread();
    let mut free = 0usize;
    for r in rays {
        if accel.unoccluded(r, f32::INFINITY) {
            free += 1;
        }
    }
    let any = t1.elapsed();
    debug_assert_eq!(free + hits, rays.len());
    let t2 = CpuTimer::thread();
    let mut pair_hits = 0usize;
    for pair in rays.chunks(2) {
        pair_hits += match pair {
            [a, b] => accel
                .intersect_pair([a, b], f32::INFINITY)
                .iter()
                .flatten()
                .count(),
            _ => pair
                .iter()
                .filter_map(|r| accel.intersect(r, f32::INFINITY))
                .count(),
        };
    }
    let pairs = t2.elapsed();
    assert_eq!(
        pair_hits, hits,
        "rays traced in pairs hit what they hit alone"
    );
    TraceFigures {
        closest_pair_mrays_per_s: Some(figures(rays.len(), hits, pairs, any).closest_mrays_per_s),
        ..figures(rays.len(), hits, closest, any)
    }
}

/// Keeps the faster of two measurements per figure: on a shared machine the least disturbed run
/// is the best estimate.
fn keep_best(best: &mut Option<TraceFigures>, r: TraceFigures) {
    match best {
        Some(b) => {
            b.closest_mrays_per_s = b.closest_mrays_per_s.max(r.closest_mrays_per_s);
            b.any_hit_mrays_per_s = b.any_hit_mrays_per_s.max(r.any_hit_mrays_per_s);
            b.closest_pair_mrays_per_s =
                match (b.closest_pair_mrays_per_s, r.closest_pair_mrays_per_s) {
                    (Some(x), Some(y)) => Some(x.max(y)),
                    (x, y) => x.or(y),
                };
        }
        None => *best = Some(r),
    }
}

/// Timing rounds: each figure is the best of these, and every round times all tracers one after
/// the other, so that a burst of load from other processes hits them alike.
pub const ROUNDS: usize = 3;

/// Builds the mesh's BVH with `params` (named `name` in the report) and times both ray sets.
pub fn run_trace_benchmark(
    triangles: usize,
    rays: usize,
    params: BvhBuildParams,
    name: &str,
) -> TraceReport {
    let mesh = Arc::new(bumpy_sphere(triangles));
    let (coherent, incoherent) = (coherent_rays(rays), incoherent_rays(rays, 1));
    let t = Instant::now();
    let accel = Accel::with_params(
        vec![Instance {
            mesh,
            transform: Transform::identity(),
            material: 0,
            placement: Placement::default(),
        }],
        params,
    );
    let build_total_s = t.elapsed().as_secs_f64();
    let mesh = &accel.instances[0].mesh;
    let cwbvh = ObvhsCwBvh::new(mesh, params);
    #[cfg(feature = "embree-anchor")]
    let embree_scene = super::embree::EmbreeScene::new(mesh);
    // [xylem, obvhs CWBVH, Embree] × [coherent, incoherent]
    let mut best: [[Option<TraceFigures>; 2]; 3] = Default::default();
    for _ in 0..ROUNDS {
        for (set, rays) in [&coherent, &incoherent].into_iter().enumerate() {
            keep_best(&mut best[0][set], time_rays(&accel, rays));
            keep_best(&mut best[1][set], cwbvh.time_rays(rays));
            #[cfg(feature = "embree-anchor")]
            if let Some(e) = &embree_scene {
                keep_best(
                    &mut best[2][set],
                    super::embree::time_rays(e, rays, set == 0),
                );
            }
        }
    }
    let [[c, i], [cw_c, cw_i], [e_c, e_i]] = best;
    let (c, i) = (c.expect("ROUNDS > 0"), i.expect("ROUNDS > 0"));
    let obvhs_cwbvh = CwBvhFigures {
        build_core_s: cwbvh.build_time.as_secs_f64(),
        coherent: cw_c.expect("ROUNDS > 0"),
        incoherent: cw_i.expect("ROUNDS > 0"),
    };
    #[cfg(feature = "embree-anchor")]
    let embree = embree_scene
        .zip(e_c.zip(e_i))
        .map(|(e, (ec, ei))| EmbreeFigures {
            build_s: e.build_time.as_secs_f64(),
            closest_ratio_coherent: c.closest_mrays_per_s / ec.closest_mrays_per_s,
            closest_ratio_incoherent: i.closest_mrays_per_s / ei.closest_mrays_per_s,
            pair_ratio: [(&c, &ec), (&i, &ei)].map(|(x, e)| {
                x.closest_pair_mrays_per_s.unwrap_or(f64::NAN) / e.closest_mrays_per_s
            }),
            coherent: ec,
            incoherent: ei,
        });
    #[cfg(not(feature = "embree-anchor"))]
    let embree = {
        let _ = (e_c, e_i);
        None
    };
    TraceReport {
        triangles: accel.triangle_count(),
        build_params: name.to_string(),
        build_core_s: accel.build_time.as_secs_f64(),
        build_total_s,
        coherent: c,
        incoherent: i,
        obvhs_cwbvh,
        embree,
    }
}

/// The obvhs build presets by name.
pub fn build_params(name: &str) -> Option<BvhBuildParams> {
    Some(match name {
        "fastest" => BvhBuildParams::fastest_build(),
        "very_fast" => BvhBuildParams::very_fast_build(),
        "fast" => BvhBuildParams::fast_build(),
        "medium" => BvhBuildParams::medium_build(),
        "slow" => BvhBuildParams::slow_build(),
        "very_slow" => BvhBuildParams::very_slow_build(),
        _ => return None,
    })
}

/// Names accepted by [`build_params`].
pub const BUILD_PRESETS: [&str; 6] = [
    "fastest",
    "very_fast",
    "fast",
    "medium",
    "slow",
    "very_slow",
];

/// An argument of [`run_presets`] out of range or an unknown preset, as `xylem bench trace`
/// spells it.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct TraceArgError(pub String);

/// [`run_trace_benchmark`] for each preset of the comma-separated `build` ([`BUILD_PRESETS`]),
/// in order, each report handed to `each` as soon as it is measured; refuses `triangles` outside
/// 1 to 50 000 000, `rays` outside 1 to 100 000 000 and (when reached) an unknown preset.
pub fn run_presets(
    triangles: usize,
    rays: usize,
    build: &str,
    mut each: impl FnMut(&TraceReport),
) -> Result<Vec<TraceReport>, TraceArgError> {
    if !(1..=50_000_000).contains(&triangles) {
        return Err(TraceArgError(format!(
            "--triangles {triangles}: allowed 1 to 50000000"
        )));
    }
    if !(1..=100_000_000).contains(&rays) {
        return Err(TraceArgError(format!(
            "--rays {rays}: allowed 1 to 100000000"
        )));
    }
    let mut reports = Vec::new();
    for name in build.split(',').map(str::trim) {
        let Some(params) = build_params(name) else {
            return Err(TraceArgError(format!(
                "--build {name}: unknown preset (allowed: {})",
                BUILD_PRESETS.join(", ")
            )));
        };
        let r = run_trace_benchmark(triangles, rays, params, name);
        each(&r);
        reports.push(r);
    }
    Ok(reports)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bumpy_sphere_has_about_the_asked_triangles_and_rays_hit_it() {
        let m = bumpy_sphere(10_000);
        assert!(
            (9_000..=11_000).contains(&m.indices.len()),
            "{}",
            m.indices.len()
        );
        let r = run_trace_benchmark(2_000, 400, BvhBuildParams::fast_build(), "fast");
        // The sphere (radius ≈ 100 mm at 300 mm) covers π·100² / (2·300·tan 25°)² ≈ 40 % of the view.
        assert!((120..=220).contains(&r.coherent.closest_hits), "{r:?}");
        assert!(r.incoherent.closest_hits > 0);
        for f in [&r.coherent, &r.incoherent] {
            assert!(f.closest_pair_mrays_per_s.is_some_and(|p| p > 0.0), "{f:?}");
        }
        assert!(r.obvhs_cwbvh.coherent.closest_pair_mrays_per_s.is_none());
    }
}
