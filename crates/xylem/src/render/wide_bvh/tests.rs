use super::kernels::{intersect_packet, LaneHit};
use super::*;
use crate::math::Pcg32;

fn point(rng: &mut Pcg32, half: f32) -> Vec3 {
    Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * (2.0 * half) - half
}

/// A random direction, or (one time in four) an axis-aligned one with signed zeros.
fn direction(rng: &mut Pcg32) -> Vec3 {
    if rng.next_u32().is_multiple_of(4) {
        let axis = rng.next_u32() as usize % 3;
        let mut d = [-0.0, 0.0, -0.0];
        d[axis] = if rng.next_u32().is_multiple_of(2) {
            1.0
        } else {
            -1.0
        };
        Vec3::from_array(d)
    } else {
        point(rng, 1.0).normalize_or(Vec3::X)
    }
}

/// A node with random child boxes (some empty lanes, some flat boxes).
fn node(rng: &mut Pcg32) -> Node {
    let mut n = Node::empty();
    for lane in 0..WIDTH {
        if rng.next_u32().is_multiple_of(8) {
            continue;
        }
        let (a, b) = (point(rng, 2.0), point(rng, 2.0));
        let (lo, mut hi) = (a.min(b), a.max(b));
        if rng.next_u32().is_multiple_of(8) {
            hi.y = lo.y;
        }
        for axis in 0..3 {
            n.bounds[0][axis][lane] = lo[axis];
            n.bounds[1][axis][lane] = hi[axis];
        }
    }
    n
}

/// Eight random triangles, one of them degenerate (zero area), sometimes fewer repeated.
fn triangles(rng: &mut Pcg32) -> Vec<[Vec3; 3]> {
    let mut t: Vec<[Vec3; 3]> = (0..PACKET)
        .map(|_| [point(rng, 1.0), point(rng, 1.0), point(rng, 1.0)])
        .collect();
    t[rng.next_u32() as usize % PACKET][1] = t[0][0];
    t[3][2] = t[3][0];
    t
}

/// A caterpillar BVH2 over `n + 1` triangles (inner node k has leaf k and inner node k + 1 as
/// children), as deep as a BVH2 gets; the triangles stand in the planes x = 0, 1, …, n.
fn caterpillar(n: usize) -> (Bvh2, Vec<[Vec3; 3]>) {
    use obvhs::{aabb::Aabb, bvh2::node::Bvh2Node};
    let tris: Vec<[Vec3; 3]> = (0..=n)
        .map(|k| {
            [
                Vec3::new(k as f32, 0.0, 0.0),
                Vec3::new(k as f32, 1.0, 0.0),
                Vec3::new(k as f32, 0.0, 1.0),
            ]
        })
        .collect();
    let bounds = |t: &[Vec3; 3]| Aabb::from_points(&t.map(Into::into));
    let node = |aabb: Aabb, prim_count: u32, first_index: u32| Bvh2Node {
        aabb,
        prim_count,
        first_index,
        ..Default::default()
    };
    // Node 0 is inner node 0; inner node k's children sit at 2k + 1 (leaf k) and 2k + 2.
    let mut nodes = vec![Bvh2Node::default(); 2 * n + 1];
    nodes[2 * n] = node(bounds(&tris[n]), 1, n as u32);
    for k in (0..n).rev() {
        let leaf = node(bounds(&tris[k]), 1, k as u32);
        let next = nodes[2 * k + 2];
        nodes[2 * k + 1] = leaf;
        let inner = node(leaf.aabb.union(&next.aabb), 0, 2 * k as u32 + 1);
        nodes[if k == 0 { 0 } else { 2 * k }] = inner;
    }
    let bvh2 = Bvh2 {
        nodes,
        primitive_indices: (0..=n as u32).collect(),
        ..Default::default()
    };
    (bvh2, tris)
}

/// Trees of growing depth traced on one thread (so the per-thread stack must grow) give the
/// brute-force closest hit on every dispatch path.
#[test]
fn deep_trees_grow_the_thread_stack_and_find_the_closest_hit() {
    for n in [20, 300] {
        let (bvh2, tris) = caterpillar(n);
        let bvh = WideBvh::from_bvh2(&bvh2, &tris);
        assert!(bvh.stack_need > n / 2, "{}", bvh.stack_need);
        check_against_brute_force(&bvh, &tris);
    }
}

fn check_against_brute_force(bvh: &WideBvh, tris: &[[Vec3; 3]]) {
    let mut rng = Pcg32::new(2, 8);
    let mut hits = 0;
    for _ in 0..2_000 {
        let o = Vec3::new(
            rng.next_f32() * (tris.len() + 20) as f32 - 10.0,
            rng.next_f32(),
            rng.next_f32(),
        );
        let d = (direction(&mut rng) + Vec3::X * (rng.next_f32() - 0.5)).normalize_or(Vec3::X);
        let r = RayData::new(o, d);
        let brute = (0..tris.len() as u32)
            .filter_map(|i| {
                intersect_packet(&Packet::new(&[i], tris), &r, 0.0, f32::INFINITY).map(|h| (h.1, i))
            })
            .min_by(|a, b| a.0.total_cmp(&b.0));
        for hit in [
            bvh.closest(o, d, f32::INFINITY),
            bvh.closest_portable(o, d, f32::INFINITY),
        ] {
            assert_eq!(hit.map(|h| (h.t, h.triangle)), brute, "{o} {d}");
        }
        assert_eq!(bvh.unoccluded(o, d, f32::INFINITY), brute.is_none());
        // Traced beside another ray (the per-thread stacks of deep trees), the same hit.
        let other = (o + Vec3::Y, -d);
        let [paired, _] = bvh.closest_pair([(o, d), other], f32::INFINITY);
        let bits =
            |h: Option<WideHit>| h.map(|h| (h.triangle, [h.t, h.uv.x, h.uv.y].map(f32::to_bits)));
        assert_eq!(
            bits(paired),
            bits(bvh.closest(o, d, f32::INFINITY)),
            "{o} {d}"
        );
        hits += brute.is_some() as usize;
    }
    assert!(hits > 100, "{hits}");
}

/// The AVX2 node and packet tests return exactly the portable tests' bits: masks, entry
/// distances, hit lane, t and barycentrics, on random nodes, packets and rays (many aimed at
/// a triangle so that hits and edge cases are common) and several t ranges.
#[test]
#[cfg(target_arch = "x86_64")]
fn avx2_kernel_equals_portable_kernel() {
    if !avx2_available() {
        return;
    }
    let mut rng = Pcg32::new(11, 3);
    let mut hits = 0;
    for _ in 0..20_000 {
        let n = node(&mut rng);
        let tris = triangles(&mut rng);
        let count = 1 + rng.next_u32() as usize % PACKET;
        let ids: Vec<u32> = (0..count as u32).collect();
        let p = Packet::new(&ids, &tris);
        let o = point(&mut rng, 3.0);
        let d = if rng.next_u32().is_multiple_of(2) {
            let [a, b, c] = tris[rng.next_u32() as usize % count];
            let (u, v) = (rng.next_f32(), rng.next_f32());
            (a + (b - a) * u + (c - a) * v * (1.0 - u) - o).normalize_or(Vec3::Z)
        } else {
            direction(&mut rng)
        };
        let r = RayData::new(o, d);
        for (t_min, t_max) in [(0.0, f32::INFINITY), (0.0, 2.0), (1.0, 3.0)] {
            let (pm, pt) = Portable::node(&n, &r, t_min, t_max);
            let (am, at) = Avx2::node(&n, &r, t_min, t_max);
            assert_eq!((pm, pt.map(f32::to_bits)), (am, at.map(f32::to_bits)));
            let bits = |h: Option<LaneHit>| h.map(|(l, t, u, v)| (l, [t, u, v].map(f32::to_bits)));
            let portable = Portable::packet(&p, &r, t_min, t_max);
            assert_eq!(bits(portable), bits(Avx2::packet(&p, &r, t_min, t_max)));
            hits += portable.is_some() as usize;
        }
    }
    assert!(hits > 10_000, "{hits}");
}
