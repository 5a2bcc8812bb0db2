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

mod collapse;
mod kernels;
#[cfg(test)]
mod tests;

use collapse::CollapsePlan;
use kernels::{Avx2, Kernel, Portable};

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

/// Entries of the traversal stack kept on the call stack ([`WideBvh::with_stack`]): trees of
/// depth ≤ 4 (a few hundred triangles).
const SMALL_STACK: usize = 32;

#[derive(Clone, Copy, Default)]
struct Entry {
    child: u32,
    t: f32,
}

/// A closest-hit traversal between steps ([`WideBvh::closest_pair`]): the ray, the closest hit
/// so far, the stack depth and the node or leaf to visit next.
struct Walk {
    r: RayData,
    best: Option<(u32, f32, f32)>,
    t_hit: f32,
    sp: usize,
    cur: u32,
}

impl Walk {
    #[inline(always)]
    fn new(root: u32, o: Vec3, d: Vec3, t_max: f32) -> Self {
        Walk {
            r: RayData::new(o, d),
            best: None,
            t_hit: t_max,
            sp: 0,
            cur: root,
        }
    }

    #[inline(always)]
    fn hit(&self) -> Option<WideHit> {
        self.best.map(|(triangle, u, v)| WideHit {
            t: self.t_hit,
            triangle,
            uv: Vec2::new(u, v),
        })
    }
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

    /// [`WideBvh::closest`] of two rays at once: their traversals advance in turn, a node or a
    /// leaf each, so that the CPU overlaps the two chains of dependent tests (a single ray's
    /// traversal of a small tree is a chain of latencies). Each ray visits what it visits alone,
    /// in the same order, so each hit is [`WideBvh::closest`]'s bit for bit.
    pub fn closest_pair(&self, rays: [(Vec3, Vec3); 2], t_max: f32) -> [Option<WideHit>; 2] {
        if self.root == EMPTY {
            return [None, None];
        }
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: as in `closest`.
            return unsafe { self.closest_pair_avx2(rays, t_max) };
        }
        self.with_stacks(|a, b| self.closest_pair_in::<Portable>(rays, t_max, [a, b]))
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

        unsafe fn closest_pair_avx2(
            &self,
            rays: [(Vec3, Vec3); 2],
            t_max: f32,
        ) -> [Option<WideHit>; 2] {
            self.with_stacks(|a, b| self.closest_pair_in::<Avx2>(rays, t_max, [a, b]))
        }
    }

    /// [`WideBvh::with_stack`] with two stacks, for [`WideBvh::closest_pair`].
    #[inline(always)]
    fn with_stacks<R>(&self, f: impl FnOnce(&mut [Entry], &mut [Entry]) -> R) -> R {
        if self.stack_need <= SMALL_STACK {
            let mut both = [Entry::default(); 2 * SMALL_STACK];
            let (a, b) = both.split_at_mut(SMALL_STACK);
            return f(a, b);
        }
        self.with_stack_of(2 * self.stack_need, |s| {
            let (a, b) = s.split_at_mut(self.stack_need);
            f(a, b)
        })
    }

    /// The two traversals of [`WideBvh::closest_pair`], each a [`Walk`] stepped in turn.
    #[inline(always)]
    fn closest_pair_in<K: Kernel>(
        &self,
        [(oa, da), (ob, db)]: [(Vec3, Vec3); 2],
        t_max: f32,
        [sa, sb]: [&mut [Entry]; 2],
    ) -> [Option<WideHit>; 2] {
        let (mut a, mut b) = (
            Walk::new(self.root, oa, da, t_max),
            Walk::new(self.root, ob, db, t_max),
        );
        let (mut on_a, mut on_b) = (true, true);
        while on_a & on_b {
            on_a = self.step::<K>(&mut a, sa);
            on_b = self.step::<K>(&mut b, sb);
        }
        while on_a {
            on_a = self.step::<K>(&mut a, sa);
        }
        while on_b {
            on_b = self.step::<K>(&mut b, sb);
        }
        [a.hit(), b.hit()]
    }

    /// One step of a closest-hit traversal (`closest_in`, `closest_pair_in`) for `w`: the leaf
    /// or node `w.cur` tested and the next one to visit chosen (false when none is left). At a
    /// node with two or more hit children all are prefetched (the ones pushed now are visited
    /// later, so their cache misses overlap this subtree's work), pushed, that part of the stack
    /// sorted by distance, farthest at the bottom, and the nearest taken; after a leaf, or a
    /// node with no hit child, the nearest pending child that can still hold a closer hit.
    #[inline(always)]
    fn step<K: Kernel>(&self, w: &mut Walk, stack: &mut [Entry]) -> bool {
        let cur = w.cur;
        if cur & LEAF != 0 {
            let p = &self.packets[(cur & !LEAF) as usize];
            if let Some((lane, t, u, v)) = K::packet(p, &w.r, 0.0, w.t_hit) {
                w.t_hit = t;
                w.best = Some((p.id[lane], u, v));
            }
        } else {
            let node = &self.nodes[cur as usize];
            prefetch(&node.child);
            let (mut mask, t_near) = K::node(node, &w.r, 0.0, w.t_hit);
            if mask != 0 {
                let first = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                if mask == 0 {
                    w.cur = node.child[first];
                    return true;
                }
                self.prefetch(node.child[first]);
                let mut rest = mask;
                while rest != 0 {
                    self.prefetch(node.child[rest.trailing_zeros() as usize]);
                    rest &= rest - 1;
                }
                let base = w.sp;
                stack[w.sp] = Entry {
                    child: node.child[first],
                    t: t_near[first],
                };
                w.sp += 1;
                while mask != 0 {
                    let i = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    let e = Entry {
                        child: node.child[i],
                        t: t_near[i],
                    };
                    let mut j = w.sp;
                    while j > base && stack[j - 1].t < e.t {
                        stack[j] = stack[j - 1];
                        j -= 1;
                    }
                    stack[j] = e;
                    w.sp += 1;
                }
                w.sp -= 1;
                w.cur = stack[w.sp].child;
                return true;
            }
        }
        // Pop the nearest pending child that can still hold a closer hit.
        while w.sp > 0 {
            w.sp -= 1;
            if stack[w.sp].t <= w.t_hit {
                w.cur = stack[w.sp].child;
                return true;
            }
        }
        false
    }

    /// Runs `f` with a traversal stack large enough for this tree: for a shallow tree (at most
    /// [`SMALL_STACK`] entries) an array on the call stack, else a per-thread buffer that grows
    /// to the deepest tree traced on the thread. (A 96-entry array on the call stack, zeroed on
    /// every query, measured 10–16 % slower any-hit tracing; a heap stack per query would be
    /// slower still. The small array is four 64-byte stores; the thread-local lookup, its
    /// `RefCell` and size check cost ≈ 50 instructions a query, 2.4 % of a Cornell-box render.)
    #[inline(always)]
    fn with_stack<R>(&self, f: impl FnOnce(&mut [Entry]) -> R) -> R {
        if self.stack_need <= SMALL_STACK {
            return f(&mut [Entry::default(); SMALL_STACK]);
        }
        self.with_stack_of(self.stack_need, f)
    }

    /// Runs `f` with the per-thread traversal buffer, grown to at least `need` entries.
    #[inline(always)]
    fn with_stack_of<R>(&self, need: usize, f: impl FnOnce(&mut [Entry]) -> R) -> R {
        thread_local! {
            static STACK: std::cell::RefCell<Vec<Entry>> =
                const { std::cell::RefCell::new(Vec::new()) };
        }
        STACK.with(|s| {
            let mut s = s.borrow_mut();
            if s.len() < need {
                s.resize(need, Entry::default());
            }
            f(&mut s)
        })
    }

    /// Closest-hit traversal, near child first ([`WideBvh::step`] until no node is left): the
    /// hit children of a node are pushed farthest first with their entry distance, and a popped
    /// entry farther than the closest hit so far is skipped.
    #[inline(always)]
    fn closest_in<K: Kernel>(
        &self,
        o: Vec3,
        d: Vec3,
        t_max: f32,
        stack: &mut [Entry],
    ) -> Option<WideHit> {
        let mut walk = Walk::new(self.root, o, d, t_max);
        while self.step::<K>(&mut walk, stack) {}
        walk.hit()
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
