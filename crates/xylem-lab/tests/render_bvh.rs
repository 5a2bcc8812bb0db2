//! The BVH closest hit equals a brute-force loop over every triangle (random meshes, random rays).

use glam::{Affine3A, Vec3};
use proptest::prelude::*;
use std::sync::Arc;
use xylem::material::Placement;
use xylem::render::geometry::brute_force_closest;
use xylem::render::{Accel, Instance, Ray, Transform, TriMesh};

fn mesh_from(points: &[[f32; 3]]) -> TriMesh {
    let positions: Vec<Vec3> = points.iter().map(|p| Vec3::from_array(*p)).collect();
    let indices = (0..positions.len() as u32 / 3)
        .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
        .collect();
    TriMesh {
        positions,
        normals: None,
        indices,
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    #[test]
    fn closest_hit_equals_brute_force(
        points in prop::collection::vec(prop::array::uniform3(-10.0f32..10.0), 3..900),
        rays in prop::collection::vec((prop::array::uniform3(-15.0f32..15.0), prop::array::uniform3(-1.0f32..1.0)), 64),
        shift in prop::array::uniform3(-5.0f32..5.0),
    ) {
        let mut mesh = mesh_from(&points[..points.len() / 3 * 3]);
        mesh.drop_degenerate();
        prop_assume!(!mesh.indices.is_empty());
        let mesh = Arc::new(mesh);
        // Two instances of the same mesh, one moved: also checks instance flattening.
        let instances = vec![
            Instance { mesh: mesh.clone(), transform: Transform::identity(), material: 0, placement: Placement::default() },
            Instance {
                mesh,
                transform: Transform::new(Affine3A::from_translation(Vec3::from_array(shift))),
                material: 0,
                placement: Placement::default(),
            },
        ];
        let accel = Accel::new(instances);
        // Random directions plus axis-aligned ones carrying signed zeros (an obvhs pitfall).
        let axis_rays = rays.iter().take(8).map(|(o, _)| (*o, [-0.0, -0.0, -1.0]));
        let all: Vec<([f32; 3], [f32; 3])> = rays.iter().copied().chain(axis_rays).collect();
        let mut previous = Ray { o: Vec3::ZERO, d: Vec3::Z };
        for (o, d) in all {
            let d = Vec3::from_array(d);
            prop_assume!(d.length() > 1e-3);
            let ray = Ray { o: Vec3::from_array(o), d: d / d.length() };
            // Traced beside the previous ray (through the instances' top level too), the same
            // hits bit for bit.
            let key = |h: Option<xylem::render::geometry::Hit>| {
                h.map(|h| (h.instance, h.triangle, [h.t, h.uv.x, h.uv.y].map(f32::to_bits)))
            };
            let paired = accel.intersect_pair([&ray, &previous], f32::INFINITY).map(key);
            let alone = [&ray, &previous].map(|r| key(accel.intersect(r, f32::INFINITY)));
            prop_assert_eq!(paired, alone);
            previous = ray;
            let bvh = accel.intersect(&ray, f32::INFINITY).map(|h| h.t);
            let brute = brute_force_closest(&accel, &ray, f32::INFINITY);
            match (bvh, brute) {
                (None, None) => {}
                (Some(a), Some(b)) => prop_assert!((a - b).abs() <= 1e-5 * b.max(1.0), "bvh {a} brute {b}"),
                other => prop_assert!(false, "bvh and brute force disagree: {other:?}"),
            }
            // The hit point lies on the reported triangle: the barycentric point (object space,
            // moved to world) equals the ray equation's point.
            if let Some(h) = accel.intersect(&ray, f32::INFINITY) {
                let s = accel.surface(&ray, &h);
                let inst = &accel.instances[h.instance as usize];
                let p = inst.transform.point_to_world(s.p_object);
                prop_assert!((p - ray.at(h.t)).length() < 1e-3, "{p} vs {}", ray.at(h.t));
                // Shadow query agrees with the closest hit.
                prop_assert!(!accel.unoccluded(&ray, h.t * 1.001 + 1e-4));
                prop_assert!(accel.unoccluded(&ray, h.t * 0.999));
            } else {
                prop_assert!(accel.unoccluded(&ray, f32::INFINITY));
            }
        }
    }
}

/// The wide BVH's AVX2 compilation (picked at run time when the CPU has AVX2) returns exactly the
/// hits of its baseline compilation: same triangle, same bits of t and barycentrics, same
/// occlusion answers. (On a CPU without AVX2 both calls run the baseline code.)
#[test]
fn wide_bvh_avx2_path_equals_portable_path() {
    use xylem_lab::bench::trace::{bumpy_sphere, coherent_rays, incoherent_rays};
    let accel = Accel::new(vec![Instance {
        mesh: Arc::new(bumpy_sphere(20_000)),
        transform: Transform::identity(),
        material: 0,
        placement: Placement::default(),
    }]);
    let bvh = accel.wide_bvh();
    let mut rays = coherent_rays(3_000);
    rays.extend(incoherent_rays(3_000, 9));
    let mut hits = 0;
    for r in &rays {
        let (a, b) = (
            bvh.closest(r.o, r.d, f32::INFINITY),
            bvh.closest_portable(r.o, r.d, f32::INFINITY),
        );
        assert_eq!(
            a.map(|h| (
                h.t.to_bits(),
                h.triangle,
                h.uv.x.to_bits(),
                h.uv.y.to_bits()
            )),
            b.map(|h| (
                h.t.to_bits(),
                h.triangle,
                h.uv.x.to_bits(),
                h.uv.y.to_bits()
            )),
            "{r:?}"
        );
        hits += a.is_some() as usize;
        for t_max in [f32::INFINITY, 50.0] {
            assert_eq!(
                bvh.unoccluded(r.o, r.d, t_max),
                bvh.unoccluded_portable(r.o, r.d, t_max)
            );
        }
    }
    // Both ray sets hit the sphere often (coherent ≈ 46 %, incoherent ≈ 67 % at 1M rays).
    assert!(hits > 2_500, "{hits}");
}

/// Two rays traced together (`Accel::intersect_pair`, the waves' closest hits) get exactly the
/// hits each gets alone: same instance and triangle, same bits of t and barycentrics, on the
/// bumpy sphere's coherent and incoherent rays paired in every mix, with and without a
/// distance limit. Control: the pair's answers swapped differ from the single ones.
#[test]
fn rays_traced_in_pairs_get_their_own_hits() {
    use xylem_lab::bench::trace::{bumpy_sphere, coherent_rays, incoherent_rays};
    let accel = Accel::new(vec![Instance {
        mesh: Arc::new(bumpy_sphere(20_000)),
        transform: Transform::identity(),
        material: 0,
        placement: Placement::default(),
    }]);
    let mut rays = coherent_rays(2_000);
    rays.extend(incoherent_rays(2_000, 5));
    // Neighbours (coherent, incoherent) and far apart (one of each kind).
    let pairs = rays
        .chunks(2)
        .map(|p| [p[0], p[1]])
        .chain((0..2_000).map(|k| [rays[k], rays[rays.len() - 1 - k]]));
    let bits = |h: Option<xylem::render::geometry::Hit>| {
        h.map(|h| {
            (
                h.instance,
                h.triangle,
                [h.t, h.uv.x, h.uv.y].map(f32::to_bits),
            )
        })
    };
    let (mut checked, mut swapped_differ) = (0, 0);
    for [a, b] in pairs {
        for t_max in [f32::INFINITY, 50.0] {
            let alone = [accel.intersect(&a, t_max), accel.intersect(&b, t_max)].map(bits);
            let paired = accel.intersect_pair([&a, &b], t_max).map(bits);
            assert_eq!(paired, alone, "{a:?} {b:?} t_max {t_max}");
            swapped_differ += (paired[0] != alone[1]) as usize;
            checked += 1;
        }
    }
    assert!(
        swapped_differ > checked / 2,
        "{swapped_differ} of {checked}"
    );
}
