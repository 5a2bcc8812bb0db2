//! The renderer's ray traversal: an 8-wide BVH with uncompressed child bounds in SoA layout and
//! leaves of up to eight triangles stored as one 8-lane SoA packet, in the style of Embree's
//! BVH8 + Triangle4 (Wald et al. 2014, "Embree: a kernel framework for efficient CPU ray
//! tracing", §4), with 8-lane leaves so that one AVX2 test covers a leaf. The tree itself comes
//! from obvhs (PLOC + reinsertion BVH2, Meister & Bittner 2018); [`WideBvh::from_bvh2`] only
//! collapses it: each wide node takes its BVH2 node's two children and keeps opening the child
//! of largest surface area until it has eight (the usual BVH2 → BVH8 collapse); a subtree of at
//! most eight triangles becomes one leaf packet.
//!
//! Why not obvhs's own CWBVH traversal: measured in notes/render.md, it reached 0.37× Embree's
//! closest-hit speed on camera rays; this layout trades memory (256-byte nodes instead of 80)
//! for node tests without dequantisation, near-to-far ordered traversal with a distance-culled
//! stack, and eight triangles per SIMD test.
//!
//! The portable code is written so that it auto-vectorises (fixed 8-lane loops, no
//! NaN-sensitive `f32::min`/`max`). On x86-64 the traversal is also compiled with AVX2 enabled,
//! with the node and leaf tests written in AVX2 intrinsics, and picked at run time; both paths do
//! the same IEEE operations in the same order (Rust never contracts to FMA), so they return
//! identical hits (tested).

use crate::simd::{simd_level, Simd};
use glam::{Vec2, Vec3};
use obvhs::bvh2::Bvh2;

/// Children per node.
const WIDTH: usize = 8;
/// Triangles per leaf packet.
const PACKET: usize = 8;
/// Child reference flag: the child is a leaf (packet index in the low bits).
const LEAF: u32 = 1 << 31;
/// Child reference of an empty slot (its bounds are empty, so it is never entered).
const EMPTY: u32 = u32::MAX;
/// Slab-test tolerance: t_far is scaled by 1 + 2γ₃ so that rounding in (b − o)·(1/d) never
/// culls a box the ray touches (Ize 2013, "Robust BVH ray traversal", §3, with γₙ = nε/(1 − nε)).
pub(crate) const ROBUST_FAR: f32 =
    1.0 + 2.0 * (3.0 * f32::EPSILON * 0.5) / (1.0 - 3.0 * f32::EPSILON * 0.5);

/// One wide node: child bounds as `bounds[min = 0 | max = 1][axis][lane]`, child references.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Node {
    bounds: [[[f32; WIDTH]; 3]; 2],
    child: [u32; WIDTH],
}

impl Node {
    const fn empty() -> Self {
        Node {
            bounds: [[[f32::INFINITY; WIDTH]; 3], [[f32::NEG_INFINITY; WIDTH]; 3]],
            child: [EMPTY; WIDTH],
        }
    }
}

/// Eight triangles in SoA form with the vertex and edges of obvhs's `RtTriangle` (v0,
/// e1 = v0 − v1, e2 = v2 − v0) and their triangle ids: 320 bytes, five cache lines. The normal
/// e1 × e2 is recomputed in the test (six multiplies per eight triangles): storing it took seven
/// lines, and the smaller leaves measured faster any-hit and incoherent closest-hit tracing.
/// Unused lanes repeat the last triangle.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Packet {
    v0: [[f32; PACKET]; 3],
    e1: [[f32; PACKET]; 3],
    e2: [[f32; PACKET]; 3],
    id: [u32; PACKET],
}

impl Packet {
    /// The packet of triangles `ids` (1 to `PACKET` of them) of `triangles`.
    fn new(ids: &[u32], triangles: &[[Vec3; 3]]) -> Self {
        let mut p = Packet {
            v0: [[0.0; PACKET]; 3],
            e1: [[0.0; PACKET]; 3],
            e2: [[0.0; PACKET]; 3],
            id: [0; PACKET],
        };
        for l in 0..PACKET {
            let id = ids[l.min(ids.len() - 1)];
            let [a, b, c] = triangles[id as usize];
            let (e1, e2) = (a - b, c - a);
            let put = |soa: &mut [[f32; PACKET]; 3], x: Vec3| {
                soa[0][l] = x.x;
                soa[1][l] = x.y;
                soa[2][l] = x.z;
            };
            put(&mut p.v0, a);
            put(&mut p.e1, e1);
            put(&mut p.e2, e2);
            p.id[l] = id;
        }
        p
    }
}

/// A ray hit from the wide BVH: distance, triangle id (as given to the builder) and barycentrics
/// (p = (1 − u − v)·v0 + u·v1 + v·v2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WideHit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// Triangle id, as given to the builder.
    pub triangle: u32,
    /// Barycentrics (u, v) of the hit.
    pub uv: Vec2,
}

/// The 8-wide BVH over a triangle list.
#[derive(Clone, Debug)]
pub struct WideBvh {
    nodes: Vec<Node>,
    packets: Vec<Packet>,
    /// The root reference (a node index, a leaf, or `EMPTY` for no triangles).
    root: u32,
    /// Largest number of stack entries a traversal can need (7 per level of depth).
    stack_need: usize,
    /// Whether the AVX2 compilation of the traversal is used (decided once, at build).
    avx2: bool,
}

/// The BVH of no triangles: its root is `EMPTY`, so every ray misses (a derived default would
/// point the root at a node that does not exist).
impl Default for WideBvh {
    fn default() -> Self {
        WideBvh {
            nodes: Vec::new(),
            packets: Vec::new(),
            root: EMPTY,
            stack_need: 0,
            avx2: false,
        }
    }
}

/// Per-ray data shared by the node and triangle tests.
#[derive(Clone, Copy)]
struct RayData {
    o: [f32; 3],
    d: [f32; 3],
    /// 1/d with zero components replaced by ±1e-20 (sign kept), so slab distances stay finite.
    inv: [f32; 3],
    /// Index into `Node::bounds` of the near plane per axis (0 = min when d ≥ 0, 1 = max).
    near: [usize; 3],
}

impl RayData {
    #[inline(always)]
    fn new(o: Vec3, d: Vec3) -> Self {
        let safe = |x: f32| {
            if x.abs() < 1e-20 {
                1.0 / 1e-20f32.copysign(x)
            } else {
                1.0 / x
            }
        };
        let inv = [safe(d.x), safe(d.y), safe(d.z)];
        RayData {
            o: o.to_array(),
            d: d.to_array(),
            inv,
            near: inv.map(|i| (i < 0.0) as usize),
        }
    }
}

#[derive(Clone, Copy, Default)]
struct Entry {
    child: u32,
    t: f32,
}

/// Slab test of a ray against a node's eight child boxes (Kay & Kajiya 1986): the bit mask of
/// the children whose [t_near, t_far] meets [t_min, t_max], and each child's t_near.
#[inline(always)]
fn intersect_node(node: &Node, r: &RayData, t_min: f32, t_max: f32) -> (u32, [f32; WIDTH]) {
    let [nx, ny, nz] = r.near;
    let (near_x, far_x) = (&node.bounds[nx][0], &node.bounds[1 - nx][0]);
    let (near_y, far_y) = (&node.bounds[ny][1], &node.bounds[1 - ny][1]);
    let (near_z, far_z) = (&node.bounds[nz][2], &node.bounds[1 - nz][2]);
    let [ox, oy, oz] = r.o;
    let [ix, iy, iz] = r.inv;
    let max = |a: f32, b: f32| if a > b { a } else { b };
    let min = |a: f32, b: f32| if a < b { a } else { b };
    let mut t_near = [0.0; WIDTH];
    let mut hit = [false; WIDTH];
    for l in 0..WIDTH {
        let tn = max(
            max((near_x[l] - ox) * ix, (near_y[l] - oy) * iy),
            max((near_z[l] - oz) * iz, t_min),
        );
        let tf = min(
            min((far_x[l] - ox) * ix, (far_y[l] - oy) * iy),
            min((far_z[l] - oz) * iz, t_max),
        );
        t_near[l] = tn;
        hit[l] = tn <= tf * ROBUST_FAR;
    }
    let mut mask = 0u32;
    for (l, &h) in hit.iter().enumerate() {
        mask |= (h as u32) << l;
    }
    (mask, t_near)
}

/// A hit lane of a leaf packet: (lane, t, u, v).
type LaneHit = (usize, f32, f32, f32);

/// The node and packet tests as one compilation target runs them best; every implementation does
/// the same IEEE operations in the same order as [`intersect_node`] and [`intersect_packet`],
/// so all return the same bits.
trait Kernel {
    fn node(node: &Node, r: &RayData, t_min: f32, t_max: f32) -> (u32, [f32; WIDTH]);
    fn packet(p: &Packet, r: &RayData, t_min: f32, t_max: f32) -> Option<LaneHit>;
}

/// The baseline target: the auto-vectorised lane loops.
struct Portable;

impl Kernel for Portable {
    #[inline(always)]
    fn node(node: &Node, r: &RayData, t_min: f32, t_max: f32) -> (u32, [f32; WIDTH]) {
        intersect_node(node, r, t_min, t_max)
    }

    #[inline(always)]
    fn packet(p: &Packet, r: &RayData, t_min: f32, t_max: f32) -> Option<LaneHit> {
        intersect_packet(p, r, t_min, t_max)
    }
}

/// AVX2 intrinsics: LLVM builds the hit masks of the lane loops from `bool` arrays with chains
/// of pack/shift/or steps and picks the nearest lane with scalar compares; `vmovmskps` and a
/// vector minimum do each in a few instructions.
#[cfg(target_arch = "x86_64")]
struct Avx2;

#[cfg(target_arch = "x86_64")]
impl Kernel for Avx2 {
    #[inline(always)]
    fn node(node: &Node, r: &RayData, t_min: f32, t_max: f32) -> (u32, [f32; WIDTH]) {
        // SAFETY: `Avx2` is only used by the traversals compiled for the AVX2 level
        // (`simd_level!`), which run only when `Simd::best` allows that level.
        unsafe { intersect_node_avx2(node, r, t_min, t_max) }
    }

    #[inline(always)]
    fn packet(p: &Packet, r: &RayData, t_min: f32, t_max: f32) -> Option<LaneHit> {
        // SAFETY: as in `node`.
        unsafe { intersect_packet_avx2(p, r, t_min, t_max) }
    }
}

simd_level! { Avx2
    /// [`intersect_node`] with AVX2 intrinsics: `vmaxps(a, b)` is `a > b ? a : b` and
    /// `vminps(a, b)` is `a < b ? a : b`, the portable code's `max` and `min` exactly.
    #[inline]
    unsafe fn intersect_node_avx2(
        node: &Node,
        r: &RayData,
        t_min: f32,
        t_max: f32,
    ) -> (u32, [f32; WIDTH]) {
        use std::arch::x86_64::*;
        let slab = |plane: &[f32; WIDTH], o: f32, inv: f32| {
            _mm256_mul_ps(
                _mm256_sub_ps(_mm256_loadu_ps(plane.as_ptr()), _mm256_set1_ps(o)),
                _mm256_set1_ps(inv),
            )
        };
        let [nx, ny, nz] = r.near;
        let [ox, oy, oz] = r.o;
        let [ix, iy, iz] = r.inv;
        let t_near = _mm256_max_ps(
            _mm256_max_ps(
                slab(&node.bounds[nx][0], ox, ix),
                slab(&node.bounds[ny][1], oy, iy),
            ),
            _mm256_max_ps(slab(&node.bounds[nz][2], oz, iz), _mm256_set1_ps(t_min)),
        );
        let t_far = _mm256_min_ps(
            _mm256_min_ps(
                slab(&node.bounds[1 - nx][0], ox, ix),
                slab(&node.bounds[1 - ny][1], oy, iy),
            ),
            _mm256_min_ps(slab(&node.bounds[1 - nz][2], oz, iz), _mm256_set1_ps(t_max)),
        );
        let far = _mm256_mul_ps(t_far, _mm256_set1_ps(ROBUST_FAR));
        let hit = _mm256_cmp_ps::<_CMP_LE_OQ>(t_near, far);
        let mut out = [0.0; WIDTH];
        _mm256_storeu_ps(out.as_mut_ptr(), t_near);
        (_mm256_movemask_ps(hit) as u32, out)
    }
}

simd_level! { Avx2
    /// [`intersect_packet`] with AVX2 intrinsics on the eight lanes of a packet: the same
    /// operations in the same order (`_CMP_NEQ_UQ` is Rust's `!=`, the ordered compares its `>=`
    /// and `<`), then the first lane holding the minimum t, as the portable scan picks it.
    #[inline]
    unsafe fn intersect_packet_avx2(
        p: &Packet,
        r: &RayData,
        t_min: f32,
        t_max: f32,
    ) -> Option<LaneHit> {
        use std::arch::x86_64::*;
        let load = |a: &[f32; PACKET]| _mm256_loadu_ps(a.as_ptr());
        let (mul, sub, add) = (_mm256_mul_ps, _mm256_sub_ps, _mm256_add_ps);
        let dot = |a: [__m256; 3], b: [__m256; 3]| {
            add(add(mul(a[0], b[0]), mul(a[1], b[1])), mul(a[2], b[2]))
        };
        let [dx, dy, dz] = r.d.map(|x| _mm256_set1_ps(x));
        let [ox, oy, oz] = r.o.map(|x| _mm256_set1_ps(x));
        let c = [
            sub(load(&p.v0[0]), ox),
            sub(load(&p.v0[1]), oy),
            sub(load(&p.v0[2]), oz),
        ];
        let rv = [
            sub(mul(dy, c[2]), mul(dz, c[1])),
            sub(mul(dz, c[0]), mul(dx, c[2])),
            sub(mul(dx, c[1]), mul(dy, c[0])),
        ];
        let [e1, e2] = [&p.e1, &p.e2].map(|a| [load(&a[0]), load(&a[1]), load(&a[2])]);
        let ng = [
            sub(mul(e1[1], e2[2]), mul(e2[1], e1[2])),
            sub(mul(e1[2], e2[0]), mul(e2[2], e1[0])),
            sub(mul(e1[0], e2[1]), mul(e2[0], e1[1])),
        ];
        let det = dot(ng, [dx, dy, dz]);
        let inv_det = _mm256_div_ps(_mm256_set1_ps(1.0), det);
        let u = mul(dot(rv, e2), inv_det);
        let v = mul(dot(rv, e1), inv_det);
        let w = sub(sub(_mm256_set1_ps(1.0), u), v);
        let t = mul(dot(ng, c), inv_det);
        let signs = _mm256_castps_si256(_mm256_or_ps(_mm256_or_ps(u, v), w));
        let ok = _mm256_and_ps(
            _mm256_and_ps(
                _mm256_cmp_ps::<_CMP_NEQ_UQ>(det, _mm256_setzero_ps()),
                _mm256_castsi256_ps(_mm256_cmpgt_epi32(signs, _mm256_set1_epi32(-1))),
            ),
            _mm256_and_ps(
                _mm256_cmp_ps::<_CMP_GE_OQ>(t, _mm256_set1_ps(t_min)),
                _mm256_cmp_ps::<_CMP_LT_OQ>(t, _mm256_set1_ps(t_max)),
            ),
        );
        let t = _mm256_blendv_ps(_mm256_set1_ps(f32::INFINITY), t, ok);
        // Horizontal minimum: halves, then pairs, then neighbours.
        let m = _mm256_min_ps(t, _mm256_permute2f128_ps::<1>(t, t));
        let m = _mm256_min_ps(m, _mm256_permute_ps::<0b01_00_11_10>(m));
        let m = _mm256_min_ps(m, _mm256_permute_ps::<0b10_11_00_01>(m));
        let t_best = _mm256_cvtss_f32(m);
        (t_best < t_max).then(|| {
            let lane =
                _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_EQ_OQ>(t, m)).trailing_zeros() as usize;
            let (mut us, mut vs) = ([0.0; PACKET], [0.0; PACKET]);
            _mm256_storeu_ps(us.as_mut_ptr(), u);
            _mm256_storeu_ps(vs.as_mut_ptr(), v);
            (lane, t_best, us[lane], vs[lane])
        })
    }
}

/// Möller–Trumbore ray/triangle test on eight triangles at once (Möller & Trumbore 1997, in the
/// form of obvhs's `RtTriangle::intersect`: with c = v0 − o and r = d × c, det = ng·d,
/// u = r·e2 / det, v = r·e1 / det, t = ng·c / det; a hit needs u, v, 1 − u − v with a clear
/// sign bit and t in [t_min, t_max)). Returns the nearest hit lane as (lane, t, u, v).
#[inline(always)]
fn intersect_packet(p: &Packet, r: &RayData, t_min: f32, t_max: f32) -> Option<LaneHit> {
    let [ox, oy, oz] = r.o;
    let [dx, dy, dz] = r.d;
    let mut t = [f32::INFINITY; PACKET];
    let mut u = [0f32; PACKET];
    let mut v = [0f32; PACKET];
    for l in 0..PACKET {
        let cx = p.v0[0][l] - ox;
        let cy = p.v0[1][l] - oy;
        let cz = p.v0[2][l] - oz;
        let rx = dy * cz - dz * cy;
        let ry = dz * cx - dx * cz;
        let rz = dx * cy - dy * cx;
        // ng = e1 × e2 in glam's operation order.
        let (e1, e2) = (&p.e1, &p.e2);
        let ngx = e1[1][l] * e2[2][l] - e2[1][l] * e1[2][l];
        let ngy = e1[2][l] * e2[0][l] - e2[2][l] * e1[0][l];
        let ngz = e1[0][l] * e2[1][l] - e2[0][l] * e1[1][l];
        let det = ngx * dx + ngy * dy + ngz * dz;
        let inv_det = 1.0 / det;
        let ul = (rx * p.e2[0][l] + ry * p.e2[1][l] + rz * p.e2[2][l]) * inv_det;
        let vl = (rx * p.e1[0][l] + ry * p.e1[1][l] + rz * p.e1[2][l]) * inv_det;
        let wl = 1.0 - ul - vl;
        let tl = (ngx * cx + ngy * cy + ngz * cz) * inv_det;
        let signs = ul.to_bits() | vl.to_bits() | wl.to_bits();
        let ok = det != 0.0 && signs & 0x8000_0000 == 0 && tl >= t_min && tl < t_max;
        t[l] = if ok { tl } else { f32::INFINITY };
        u[l] = ul;
        v[l] = vl;
    }
    let mut best = 0;
    for l in 1..PACKET {
        if t[l] < t[best] {
            best = l;
        }
    }
    (t[best] < t_max).then(|| (best, t[best], u[best], v[best]))
}

impl WideBvh {
    /// Collapses an obvhs BVH2 (leaves of one primitive each, as PLOC builds them;
    /// `bvh2.primitive_indices` maps leaf entries to `triangles`) into the wide layout.
    pub fn from_bvh2(bvh2: &Bvh2, triangles: &[[Vec3; 3]]) -> Self {
        let mut bvh = WideBvh {
            root: EMPTY,
            avx2: avx2_available(),
            ..Default::default()
        };
        if bvh2.nodes.is_empty() || triangles.is_empty() {
            return bvh;
        }
        let plan = CollapsePlan::new(bvh2);
        let (nodes, packets) = plan.sizes(bvh2);
        bvh.nodes = with_huge_pages(nodes);
        bvh.packets = with_huge_pages(packets);
        let mut prims = Vec::with_capacity(PACKET);
        if plan.leaf[0] {
            bvh.root = bvh.leaf(bvh2, 0, triangles, &mut prims);
            bvh.stack_need = 1;
            return bvh;
        }
        bvh.root = 0;
        bvh.nodes.push(Node::empty());
        // (BVH2 node, wide node index, wide depth)
        let mut pending = vec![(0usize, 0usize, 1usize)];
        let mut max_depth = 1;
        let mut kids = Vec::with_capacity(WIDTH);
        while let Some((n2, wide, depth)) = pending.pop() {
            max_depth = max_depth.max(depth);
            kids.clear();
            plan.wide_children(bvh2, n2, &mut kids);
            for (lane, &k) in kids.iter().enumerate() {
                let aabb = bvh2.nodes[k].aabb();
                for a in 0..3 {
                    bvh.nodes[wide].bounds[0][a][lane] = aabb.min[a];
                    bvh.nodes[wide].bounds[1][a][lane] = aabb.max[a];
                }
                bvh.nodes[wide].child[lane] = if plan.leaf[k] {
                    bvh.leaf(bvh2, k, triangles, &mut prims)
                } else {
                    bvh.nodes.push(Node::empty());
                    pending.push((k, bvh.nodes.len() - 1, depth + 1));
                    (bvh.nodes.len() - 1) as u32
                };
            }
        }
        bvh.stack_need = max_depth * (WIDTH - 1) + 1;
        debug_assert_eq!((bvh.nodes.len(), bvh.packets.len()), (nodes, packets));
        bvh
    }

    /// Makes one leaf packet of the (at most eight) triangles under BVH2 node `n2`.
    fn leaf(
        &mut self,
        bvh2: &Bvh2,
        n2: usize,
        triangles: &[[Vec3; 3]],
        prims: &mut Vec<u32>,
    ) -> u32 {
        prims.clear();
        let mut stack = vec![n2];
        while let Some(n) = stack.pop() {
            let node = &bvh2.nodes[n];
            if node.prim_count == 0 {
                stack.extend([node.first_index as usize, node.first_index as usize + 1]);
            } else {
                let f = node.first_index as usize;
                prims.extend_from_slice(&bvh2.primitive_indices[f..f + node.prim_count as usize]);
            }
        }
        assert!(
            (1..=PACKET).contains(&prims.len()),
            "wide BVH leaf of {} triangles (the collapse only makes leaves of subtrees with at most {PACKET})",
            prims.len()
        );
        self.packets.push(Packet::new(prims, triangles));
        LEAF | (self.packets.len() - 1) as u32
    }

    /// Bytes of the nodes and leaf packets.
    pub fn bytes(&self) -> u64 {
        (self.nodes.len() * std::mem::size_of::<Node>()
            + self.packets.len() * std::mem::size_of::<Packet>()) as u64
    }

    /// Number of wide nodes and leaf packets (for the benchmark report).
    pub fn size(&self) -> (usize, usize) {
        (self.nodes.len(), self.packets.len())
    }

    /// Closest hit with t in [0, t_max).
    pub fn closest(&self, o: Vec3, d: Vec3, t_max: f32) -> Option<WideHit> {
        if self.root == EMPTY {
            return None;
        }
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is set only when the CPU reports AVX2 (`avx2_available`).
            return unsafe { self.closest_avx2(o, d, t_max) };
        }
        self.closest_portable(o, d, t_max)
    }

    /// True when no triangle is hit with t in [0, t_max) (shadow rays; stops at the first hit).
    pub fn unoccluded(&self, o: Vec3, d: Vec3, t_max: f32) -> bool {
        if self.root == EMPTY {
            return true;
        }
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: as in `closest`.
            return unsafe { self.unoccluded_avx2(o, d, t_max) };
        }
        self.unoccluded_portable(o, d, t_max)
    }

    /// The traversal compiled for the baseline target (the reference the AVX2 path must equal).
    pub fn closest_portable(&self, o: Vec3, d: Vec3, t_max: f32) -> Option<WideHit> {
        self.with_stack(|s| self.closest_in::<Portable>(o, d, t_max, s))
    }

    /// Any-hit query compiled for the baseline target.
    pub fn unoccluded_portable(&self, o: Vec3, d: Vec3, t_max: f32) -> bool {
        self.with_stack(|s| self.unoccluded_in::<Portable>(o, d, t_max, s))
    }

    simd_level! { Avx2
        unsafe fn closest_avx2(&self, o: Vec3, d: Vec3, t_max: f32) -> Option<WideHit> {
            self.with_stack(|s| self.closest_in::<Avx2>(o, d, t_max, s))
        }

        unsafe fn unoccluded_avx2(&self, o: Vec3, d: Vec3, t_max: f32) -> bool {
            self.with_stack(|s| self.unoccluded_in::<Avx2>(o, d, t_max, s))
        }
    }

    /// Runs `f` with a traversal stack large enough for this tree: a per-thread buffer that
    /// grows to the deepest tree traced on the thread. (A 96-entry array on the call stack,
    /// zeroed on every query, measured 10–16 % slower any-hit tracing; a heap stack per query
    /// would be slower still.)
    #[inline(always)]
    fn with_stack<R>(&self, f: impl FnOnce(&mut [Entry]) -> R) -> R {
        thread_local! {
            static STACK: std::cell::RefCell<Vec<Entry>> =
                const { std::cell::RefCell::new(Vec::new()) };
        }
        STACK.with(|s| {
            let mut s = s.borrow_mut();
            if s.len() < self.stack_need {
                s.resize(self.stack_need, Entry::default());
            }
            f(&mut s)
        })
    }

    /// Closest-hit traversal, near child first: the hit children of a node are pushed farthest
    /// first with their entry distance, and a popped entry farther than the closest hit so far is
    /// skipped.
    #[inline(always)]
    fn closest_in<K: Kernel>(
        &self,
        o: Vec3,
        d: Vec3,
        t_max: f32,
        stack: &mut [Entry],
    ) -> Option<WideHit> {
        let r = RayData::new(o, d);
        let mut best: Option<(u32, f32, f32)> = None;
        let mut t_hit = t_max;
        let mut sp = 0usize;
        let mut cur = self.root;
        loop {
            // Descend from `cur` until a leaf is tested or the node has no hit child.
            loop {
                if cur & LEAF != 0 {
                    let p = &self.packets[(cur & !LEAF) as usize];
                    if let Some((lane, t, u, v)) = K::packet(p, &r, 0.0, t_hit) {
                        t_hit = t;
                        best = Some((p.id[lane], u, v));
                    }
                    break;
                }
                let node = &self.nodes[cur as usize];
                prefetch(&node.child);
                let (mut mask, t_near) = K::node(node, &r, 0.0, t_hit);
                if mask == 0 {
                    break;
                }
                let first = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                if mask == 0 {
                    cur = node.child[first];
                    continue;
                }
                // Two or more children: prefetch them all (the ones pushed now are visited
                // later, so their cache misses overlap this subtree's work), push all, sort that
                // part of the stack by distance, farthest at the bottom, and continue with the
                // nearest.
                self.prefetch(node.child[first]);
                let mut rest = mask;
                while rest != 0 {
                    self.prefetch(node.child[rest.trailing_zeros() as usize]);
                    rest &= rest - 1;
                }
                let base = sp;
                stack[sp] = Entry {
                    child: node.child[first],
                    t: t_near[first],
                };
                sp += 1;
                while mask != 0 {
                    let i = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    let e = Entry {
                        child: node.child[i],
                        t: t_near[i],
                    };
                    let mut j = sp;
                    while j > base && stack[j - 1].t < e.t {
                        stack[j] = stack[j - 1];
                        j -= 1;
                    }
                    stack[j] = e;
                    sp += 1;
                }
                sp -= 1;
                cur = stack[sp].child;
            }
            // Pop the nearest pending child that can still hold a closer hit.
            loop {
                if sp == 0 {
                    return best.map(|(triangle, u, v)| WideHit {
                        t: t_hit,
                        triangle,
                        uv: Vec2::new(u, v),
                    });
                }
                sp -= 1;
                if stack[sp].t <= t_hit {
                    cur = stack[sp].child;
                    break;
                }
            }
        }
    }

    /// Prefetches the node or leaf packet a child reference points to.
    #[inline(always)]
    fn prefetch(&self, child: u32) {
        if child & LEAF != 0 {
            prefetch(self.packets.as_ptr().wrapping_add((child & !LEAF) as usize));
        } else {
            prefetch(self.nodes.as_ptr().wrapping_add(child as usize));
        }
    }

    /// Any-hit traversal: unordered, stops at the first triangle hit in [0, t_max).
    #[inline(always)]
    fn unoccluded_in<K: Kernel>(&self, o: Vec3, d: Vec3, t_max: f32, stack: &mut [Entry]) -> bool {
        let r = RayData::new(o, d);
        stack[0] = Entry {
            child: self.root,
            t: 0.0,
        };
        let mut sp = 1usize;
        while sp > 0 {
            sp -= 1;
            let cur = stack[sp].child;
            if cur & LEAF != 0 {
                if K::packet(&self.packets[(cur & !LEAF) as usize], &r, 0.0, t_max).is_some() {
                    return false;
                }
                continue;
            }
            let node = &self.nodes[cur as usize];
            prefetch(&node.child);
            let (mut mask, _) = K::node(node, &r, 0.0, t_max);
            while mask != 0 {
                let i = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                self.prefetch(node.child[i]);
                stack[sp] = Entry {
                    child: node.child[i],
                    t: 0.0,
                };
                sp += 1;
            }
        }
        true
    }
}

/// Asks the cache for the `size_of::<T>()` bytes at `p` (Embree prefetches each hit child the
/// same way, Wald et al. 2014 §4.3); a hint only, it never faults.
#[inline(always)]
fn prefetch<T>(p: *const T) {
    #[cfg(target_arch = "x86_64")]
    for line in (0..std::mem::size_of::<T>()).step_by(64) {
        // SAFETY: prefetching reads no memory architecturally and cannot fault.
        unsafe {
            std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(
                p.cast::<i8>().wrapping_add(line),
            )
        };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}

/// SAH cost of testing one wide node (its eight boxes) per unit of the ray's hit probability.
const NODE_COST: f32 = 1.0;
/// SAH cost of testing one leaf packet (eight triangles in one SIMD test).
const LEAF_COST: f32 = 1.0;

/// Which BVH2 subtrees become wide nodes and which leaf packets: the SAH-optimal collapse of
/// Ylitie, Karras & Laine 2017 ("Efficient incoherent ray traversal on GPUs through compressed
/// wide BVHs", §3.2), a dynamic programme over the BVH2 bottom-up. `cost[n][i − 1]` is the
/// least SAH cost (surface area × test cost, Goldsmith & Salmon 1987; MacDonald & Booth 1990)
/// of the subtree of BVH2 node n as a forest of at most i roots, each a leaf packet of at most
/// `PACKET` triangles or a wide node whose up to eight children are such a forest of its own.
/// The greedy collapse it replaces (open the child of largest area until eight) left 38 % of
/// the wide nodes with two children.
struct CollapsePlan {
    cost: Vec<[f32; WIDTH]>,
    /// For `cost[n][i − 1]`: roots taken from n's (left, right) BVH2 children, or (0, 0) when n
    /// itself is the one root.
    split: Vec<[(u8, u8); WIDTH]>,
    /// n's forest of at most eight roots with at least two (its children as a wide node).
    wide: Vec<(u8, u8)>,
    /// Whether n as a single root is a leaf packet (else a wide node).
    leaf: Vec<bool>,
}

impl CollapsePlan {
    fn new(bvh2: &Bvh2) -> Self {
        let len = bvh2.nodes.len();
        let mut plan = CollapsePlan {
            cost: vec![[f32::INFINITY; WIDTH]; len],
            split: vec![[(0, 0); WIDTH]; len],
            wide: vec![(0, 0); len],
            leaf: vec![false; len],
        };
        let mut counts = vec![0u32; len];
        // Iterative post-order, so that deep trees cannot overflow the call stack.
        let mut stack = vec![(0usize, false)];
        while let Some((n, children_done)) = stack.pop() {
            let node = &bvh2.nodes[n];
            let f = node.first_index as usize;
            if node.prim_count == 0 && !children_done {
                stack.extend([(n, true), (f, false), (f + 1, false)]);
                continue;
            }
            let area = node.aabb().half_area();
            counts[n] = if node.prim_count != 0 {
                node.prim_count
            } else {
                counts[f] + counts[f + 1]
            };
            let leaf_cost = if counts[n] as usize <= PACKET {
                area * LEAF_COST
            } else {
                f32::INFINITY
            };
            if node.prim_count != 0 {
                plan.cost[n] = [leaf_cost; WIDTH];
                plan.leaf[n] = true;
                continue;
            }
            plan.plan_inner(n, f, area, leaf_cost);
        }
        plan
    }

    /// Fills the tables of inner BVH2 node `n` (children `f`, `f + 1`, already planned).
    fn plan_inner(&mut self, n: usize, f: usize, area: f32, leaf_cost: f32) {
        // best[i − 1]: cheapest way to give the two children at most i roots in all (i ≥ 2).
        let mut best = [(f32::INFINITY, (0u8, 0u8)); WIDTH];
        for i in 2..=WIDTH {
            best[i - 1] = best[i - 2];
            for left in 1..i {
                let c = self.cost[f][left - 1] + self.cost[f + 1][i - left - 1];
                if c < best[i - 1].0 {
                    best[i - 1] = (c, (left as u8, (i - left) as u8));
                }
            }
        }
        let (children_cost, wide) = best[WIDTH - 1];
        let node_cost = area * NODE_COST + children_cost;
        self.wide[n] = wide;
        self.leaf[n] = leaf_cost <= node_cost;
        self.cost[n][0] = leaf_cost.min(node_cost);
        for i in 2..=WIDTH {
            let (c, s) = best[i - 1];
            (self.cost[n][i - 1], self.split[n][i - 1]) = if c < self.cost[n][i - 2] {
                (c, s)
            } else {
                (self.cost[n][i - 2], self.split[n][i - 2])
            };
        }
    }

    /// The children of BVH2 node `n` made a wide node (2 to 8 BVH2 nodes).
    /// The wide nodes and leaf packets the collapse makes (walked as [`WideBvh::from_bvh2`]
    /// walks it), so that both are allocated once at their size: grown by doubling, up to half
    /// of each was unused and the last doubling of the packets needed their size again, which
    /// failed under a tight `ulimit -v` after the memory estimate had passed.
    fn sizes(&self, bvh2: &Bvh2) -> (usize, usize) {
        if self.leaf[0] {
            return (0, 1);
        }
        let (mut nodes, mut packets) = (1, 0);
        let (mut pending, mut kids) = (vec![0usize], Vec::with_capacity(WIDTH));
        while let Some(n2) = pending.pop() {
            kids.clear();
            self.wide_children(bvh2, n2, &mut kids);
            for &k in &kids {
                if self.leaf[k] {
                    packets += 1;
                } else {
                    nodes += 1;
                    pending.push(k);
                }
            }
        }
        (nodes, packets)
    }

    fn wide_children(&self, bvh2: &Bvh2, n: usize, out: &mut Vec<usize>) {
        let f = bvh2.nodes[n].first_index as usize;
        let (left, right) = self.wide[n];
        self.roots(bvh2, f, left as usize, out);
        self.roots(bvh2, f + 1, right as usize, out);
    }

    /// The roots of BVH2 node `n`'s forest of at most `i` roots.
    fn roots(&self, bvh2: &Bvh2, n: usize, i: usize, out: &mut Vec<usize>) {
        match self.split[n][i - 1] {
            (0, 0) => out.push(n),
            (left, right) => {
                let f = bvh2.nodes[n].first_index as usize;
                self.roots(bvh2, f, left as usize, out);
                self.roots(bvh2, f + 1, right as usize, out);
            }
        }
    }
}

/// Whether the AVX2 compilation of the traversal may run here ([`Simd::best`]).
fn avx2_available() -> bool {
    Simd::best() >= Simd::Avx2
}

/// An empty vector with room for `len` items that the kernel is asked to back with transparent
/// huge pages (`madvise(MADV_HUGEPAGE)` before first touch): a traversal touches nodes all over
/// a ~100 MB tree, and with 4 KiB pages nearly every node visit is also a TLB miss.
fn with_huge_pages<T: Copy>(len: usize) -> Vec<T> {
    const HUGE: usize = 2 << 20;
    let bytes = len * std::mem::size_of::<T>();
    let out: Vec<T> = Vec::with_capacity(len);
    if bytes < 4 * HUGE {
        return out;
    }
    #[cfg(target_os = "linux")]
    {
        let start = out.as_ptr() as usize;
        let aligned = start.next_multiple_of(HUGE);
        let end = (start + bytes) / HUGE * HUGE;
        if end > aligned {
            // SAFETY: the range lies inside `out`'s allocation; MADV_HUGEPAGE is advice only and
            // changes no contents.
            unsafe {
                libc::madvise(
                    aligned as *mut libc::c_void,
                    end - aligned,
                    libc::MADV_HUGEPAGE,
                );
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
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
                    intersect_packet(&Packet::new(&[i], tris), &r, 0.0, f32::INFINITY)
                        .map(|h| (h.1, i))
                })
                .min_by(|a, b| a.0.total_cmp(&b.0));
            for hit in [
                bvh.closest(o, d, f32::INFINITY),
                bvh.closest_portable(o, d, f32::INFINITY),
            ] {
                assert_eq!(hit.map(|h| (h.t, h.triangle)), brute, "{o} {d}");
            }
            assert_eq!(bvh.unoccluded(o, d, f32::INFINITY), brute.is_none());
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
                let bits =
                    |h: Option<LaneHit>| h.map(|(l, t, u, v)| (l, [t, u, v].map(f32::to_bits)));
                let portable = Portable::packet(&p, &r, t_min, t_max);
                assert_eq!(bits(portable), bits(Avx2::packet(&p, &r, t_min, t_max)));
                hits += portable.is_some() as usize;
            }
        }
        assert!(hits > 10_000, "{hits}");
    }
}
