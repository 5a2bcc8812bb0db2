//! [`Accel`]: the two-level BVH over the placed meshes, its build, traversal entry points and
//! the reconstruction of a hit's surface.

use super::{Hit, Instance, Ray, SurfaceHit, TriMesh};
use crate::render::wide_bvh::{WideBvh, WideHit, ROBUST_FAR};
use glam::{Vec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::bvh2::{reinsertion::ReinsertionOptimizer, Bvh2};
use obvhs::ploc::PlocBuilder;
use obvhs::ray::Ray as BvhRay;
use obvhs::rt_triangle::RtTriangle;
use obvhs::splits::split_aabbs_preset;
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;
use std::collections::{HashMap, HashSet};
use std::mem::size_of;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// The scene's triangles in two levels (the design's "instancing" row): the meshes placed once
/// are flattened into one world-space wide BVH (one traversal, as fast as a single mesh); a mesh
/// placed two or more times (the same `Arc`) gets one wide BVH in its own object space, and its
/// placements sit in a top-level BVH over their world boxes, traversed with the ray moved into
/// object space by the inverse affine map. An affine map keeps the ray parameter, so a hit's `t`
/// (and barycentrics) in object space is its world-space `t`: the levels share one `t_max`.
/// Memory therefore grows with the distinct geometry, not with the copies.
pub struct Accel {
    /// The meshes placed once, in world space.
    world: WideBvh,
    /// First global triangle id of each flattened instance (prefix sums), plus the total.
    offsets: Vec<u32>,
    /// The instance each flattened range belongs to.
    flat: Vec<u32>,
    /// The flattened range (index into `flat`) of each world triangle, where more than one
    /// mesh is flattened; empty otherwise (every triangle is range 0). A load instead of a
    /// binary search over `offsets` per hit (half of `Accel::intersect`'s own time, ≈ 2 % of a
    /// Cornell-box render); 4 bytes a triangle.
    range_of: Vec<u32>,
    /// Per instance, the world-constant normals and tangent of each of its triangles
    /// ([`triangle_frame`]) where the mesh is placed once (flattened); empty for shared meshes,
    /// whose frames are worked out per hit. A load instead of a cross product, two transforms
    /// and three normalisations in a chain per hit (`Accel::surface`); 36 bytes a triangle.
    frames: Vec<Vec<TriangleFrame>>,
    /// One object-space BVH per mesh placed more than once.
    shared: Vec<WideBvh>,
    /// The placements of shared meshes (the top level's primitive ids index this).
    placed: Vec<Placed>,
    /// Per instance: true when its mesh is shared (traced in object space).
    instanced: Vec<bool>,
    /// The top-level BVH over the widened world boxes of `placed` (None when nothing is shared).
    top: Option<Bvh2>,
    /// The placed meshes, indexed by [`Hit::instance`].
    pub instances: Vec<Instance>,
    /// Time spent building: obvhs's BVH2s (PLOC, reinsertion) and their collapse to wide BVHs.
    pub build_time: Duration,
    bounds_radius: f32,
    /// Triangles over all instances (each placement counted).
    scene_triangles: usize,
    /// Triangles stored in the BVHs (each shared mesh counted once).
    stored_triangles: usize,
}

/// One placement of a shared mesh: which object-space BVH and which instance.
#[derive(Clone, Copy, Debug)]
struct Placed {
    mesh: u32,
    instance: u32,
}

/// The BVH build parameters used by the renderer (`medium_build`: PLOC with reinsertion; measured
/// against the others in notes/render.md). Only the BVH2 settings matter (leaf size and the
/// CWBVH/BVH2 collapse settings are not used: the wide BVH makes leaves of up to 8 triangles).
pub const BUILD_PARAMS: BvhBuildParams = BvhBuildParams::medium_build();

/// The wide BVH of `triangles` (empty when there are none).
fn wide_bvh(triangles: &[Triangle], params: &BvhBuildParams) -> WideBvh {
    if triangles.is_empty() {
        return WideBvh::default();
    }
    let corners: Vec<[Vec3; 3]> = triangles
        .iter()
        .map(|t| [t.v0.into(), t.v1.into(), t.v2.into()])
        .collect();
    WideBvh::from_bvh2(&build_bvh2(triangles, params), &corners)
}

/// The triangles of `mesh` with its vertices mapped by `to`.
fn mapped_triangles(mesh: &TriMesh, to: impl Fn(Vec3) -> Vec3) -> Vec<Triangle> {
    let p: Vec<Vec3A> = mesh.positions.iter().map(|&v| to(v).into()).collect();
    mesh.indices
        .iter()
        .map(|t| Triangle {
            v0: p[t[0] as usize],
            v1: p[t[1] as usize],
            v2: p[t[2] as usize],
        })
        .collect()
}

/// World bounds (min, max) of the vertices the triangles of `inst` use.
fn world_bounds(inst: &Instance, used: &[u32]) -> (Vec3, Vec3) {
    used.iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &i| {
            let w = inst
                .transform
                .point_to_world(inst.mesh.positions[i as usize]);
            (lo.min(w), hi.max(w))
        })
}

/// The vertices the triangles of `mesh` use, each once, in index order.
fn used_vertices(mesh: &TriMesh) -> Vec<u32> {
    let mut seen = vec![false; mesh.positions.len()];
    let mut used = Vec::new();
    for &i in mesh.indices.iter().flatten() {
        if !std::mem::replace(&mut seen[i as usize], true) {
            used.push(i);
        }
    }
    used
}

/// The distinct meshes of `instances` by identity (the same `Arc`), in first-use order
/// (deterministic), each with the instances that place it.
fn users_by_mesh(instances: &[Instance]) -> Vec<Vec<u32>> {
    let mut users: Vec<Vec<u32>> = Vec::new();
    let mut slot: HashMap<*const TriMesh, usize> = HashMap::new();
    for (i, inst) in instances.iter().enumerate() {
        let k = *slot.entry(Arc::as_ptr(&inst.mesh)).or_insert(users.len());
        if k == users.len() {
            users.push(Vec::new());
        }
        users[k].push(i as u32);
    }
    users
}

/// [`Accel`]'s `range_of`: the flattened range of each world triangle, from the ranges' first
/// triangles `offsets` (plus the total); empty when there is one range.
fn range_of_triangles(offsets: &[u32]) -> Vec<u32> {
    let ranges = offsets.len().saturating_sub(1);
    if ranges <= 1 {
        return Vec::new();
    }
    (0..ranges as u32)
        .flat_map(|k| {
            let n = offsets[k as usize + 1] - offsets[k as usize];
            std::iter::repeat_n(k, n as usize)
        })
        .collect()
}

/// The top-level BVH over the shared meshes' placement boxes (PLOC, one box per leaf).
fn top_level(boxes: &[Aabb], params: &BvhBuildParams) -> Bvh2 {
    let indices = (0..boxes.len() as u32).collect();
    PlocBuilder::with_capacity(boxes.len()).build(
        params.ploc_search_distance,
        boxes,
        indices,
        params.sort_precision,
        params.search_depth_threshold,
    )
}

/// [`Accel`]'s `frames`: each flattened instance's triangle frames; empty for shared meshes.
fn frames_table(instances: &[Instance], instanced: &[bool]) -> Vec<Vec<TriangleFrame>> {
    (instances.iter().zip(instanced))
        .map(|(inst, &shared)| match shared {
            true => Vec::new(),
            false => (0..inst.mesh.indices.len())
                .map(|t| triangle_frame(inst, t))
                .collect(),
        })
        .collect()
}

impl Accel {
    /// Builds the acceleration structure over `instances` with [`BUILD_PARAMS`].
    pub fn new(instances: Vec<Instance>) -> Self {
        Self::with_params(instances, BUILD_PARAMS)
    }

    /// Builds the acceleration structure with other obvhs BVH2 build parameters (for the BVH
    /// builder comparison of `xylem bench trace`).
    pub fn with_params(instances: Vec<Instance>, params: BvhBuildParams) -> Self {
        let start = Instant::now();
        let users = users_by_mesh(&instances);
        let mut world: Vec<Triangle> = Vec::new();
        let (mut offsets, mut flat) = (Vec::new(), Vec::new());
        let (mut shared, mut placed, mut boxes) = (Vec::new(), Vec::new(), Vec::new());
        let mut bounds_radius = 1.0f32;
        let mut stored_triangles = 0;
        let mut instanced = vec![false; instances.len()];
        for user in &users {
            let mesh = &instances[user[0] as usize].mesh;
            stored_triangles += mesh.indices.len();
            let used = used_vertices(mesh);
            if used.is_empty() {
                continue; // nothing to hit, and no box to bound it
            }
            for &i in user {
                let (lo, hi) = world_bounds(&instances[i as usize], &used);
                bounds_radius = bounds_radius.max(lo.abs().max(hi.abs()).max_element());
                if user.len() > 1 {
                    instanced[i as usize] = true;
                    // Widened so that the top level's slab test never culls a box a ray
                    // grazes (the bottom level's own test is robust).
                    let m = (hi - lo).max(lo.abs().max(hi.abs())) * 1e-6;
                    boxes.push(Aabb::new((lo - m).into(), (hi + m).into()));
                    placed.push(Placed {
                        mesh: shared.len() as u32,
                        instance: i,
                    });
                }
            }
            if user.len() > 1 {
                shared.push(wide_bvh(&mapped_triangles(mesh, |v| v), &params));
            } else {
                let inst = &instances[user[0] as usize];
                offsets.push(world.len() as u32);
                flat.push(user[0]);
                world.extend(mapped_triangles(mesh, |v| inst.transform.point_to_world(v)));
            }
        }
        offsets.push(world.len() as u32);
        let range_of = range_of_triangles(&offsets);
        // `bounds_radius` ignores a non-finite vertex as the flat build did (max skips NaN).
        let top = (!placed.is_empty()).then(|| top_level(&boxes, &params));
        let scene_triangles = instances.iter().map(|i| i.mesh.indices.len()).sum();
        // The frames table once the BVH is built and its buffers freed, so that it does not add
        // to the build's peak (`resources::BUILD_BYTES_PER_TRIANGLE`).
        let world_bvh = wide_bvh(&world, &params);
        drop(world);
        let frames = frames_table(&instances, &instanced);
        Accel {
            world: world_bvh,
            offsets,
            flat,
            range_of,
            frames,
            shared,
            placed,
            instanced,
            top,
            instances,
            build_time: start.elapsed(),
            bounds_radius,
            scene_triangles,
            stored_triangles,
        }
    }

    /// True when instance `i`'s mesh is shared, so that it is traced in object space.
    pub(crate) fn is_instanced(&self, i: usize) -> bool {
        self.instanced[i]
    }

    /// Number of triangles over all instances (each placement of a mesh counted).
    pub fn triangle_count(&self) -> usize {
        self.scene_triangles
    }

    /// Number of triangles the BVHs store (a mesh placed many times counted once).
    pub fn stored_triangle_count(&self) -> usize {
        self.stored_triangles
    }

    /// Bytes held by the BVHs and the distinct meshes (what instancing keeps from growing).
    pub fn memory_bytes(&self) -> u64 {
        let bvhs: u64 = std::iter::once(&self.world)
            .chain(&self.shared)
            .map(WideBvh::bytes)
            .sum();
        let top = self.top.as_ref().map_or(0, |t| {
            (t.nodes.len() * size_of::<obvhs::bvh2::node::Bvh2Node>()
                + t.primitive_indices.len() * 4) as u64
        });
        let mut seen = HashSet::new();
        let mesh_bytes: u64 = (self.instances.iter())
            .filter(|i| seen.insert(Arc::as_ptr(&i.mesh)))
            .map(|i| i.mesh.bytes())
            .sum();
        let frames =
            (self.frames.iter().map(Vec::len).sum::<usize>() * size_of::<TriangleFrame>()) as u64;
        bvhs + top + mesh_bytes + frames + (self.instances.len() * size_of::<Instance>()) as u64
    }

    /// A length that scales ray offsets: the largest coordinate magnitude in the scene (≥ 1 mm).
    pub fn scale(&self) -> f32 {
        self.bounds_radius
    }

    /// Closest hit with `t` in [0, t_max).
    #[inline(always)]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        let best = self
            .world
            .closest(ray.o, ray.d, t_max)
            .map(|h| self.world_hit(h));
        self.intersect_top(ray, t_max, best)
    }

    /// [`Accel::intersect`] of two rays, their world traversals advanced in turn
    /// ([`WideBvh::closest_pair`]): each hit is `intersect`'s bit for bit.
    #[inline(always)]
    pub fn intersect_pair(&self, rays: [&Ray; 2], t_max: f32) -> [Option<Hit>; 2] {
        let [a, b] = rays;
        let [ha, hb] = self.world.closest_pair([(a.o, a.d), (b.o, b.d)], t_max);
        [
            self.intersect_top(a, t_max, ha.map(|h| self.world_hit(h))),
            self.intersect_top(b, t_max, hb.map(|h| self.world_hit(h))),
        ]
    }

    /// A hit of the flattened world's BVH as the instance's triangle.
    #[inline(always)]
    fn world_hit(&self, h: WideHit) -> Hit {
        let k = match self.range_of.get(h.triangle as usize) {
            Some(&k) => k as usize,
            None => 0,
        };
        Hit {
            t: h.t,
            instance: self.flat[k],
            triangle: h.triangle - self.offsets[k],
            uv: h.uv,
        }
    }

    /// The closest of `best` (the flattened world's hit) and the instanced meshes' hits.
    #[inline(always)]
    fn intersect_top(&self, ray: &Ray, t_max: f32, mut best: Option<Hit>) -> Option<Hit> {
        if let Some(top) = &self.top {
            let mut t_hit = best.map_or(t_max, |h| h.t);
            self.traverse_top(top, ray, &mut t_hit, |p, o, d, t| {
                let h = self.shared[p.mesh as usize].closest(o, d, t)?;
                best = Some(Hit {
                    t: h.t,
                    instance: p.instance,
                    triangle: h.triangle,
                    uv: h.uv,
                });
                Some(h.t)
            });
        }
        best
    }

    /// True when nothing blocks the segment `o + t·d`, t in [0, t_max) (early-out shadow query).
    pub fn unoccluded(&self, ray: &Ray, t_max: f32) -> bool {
        if !self.world.unoccluded(ray.o, ray.d, t_max) {
            return false;
        }
        let Some(top) = &self.top else {
            return true;
        };
        let mut t = t_max;
        let mut blocked = false;
        self.traverse_top(top, ray, &mut t, |p, o, d, t| {
            blocked = !self.shared[p.mesh as usize].unoccluded(o, d, t);
            // A negative distance ends the traversal (every box starts at t ≥ 0).
            blocked.then_some(-1.0)
        });
        !blocked
    }

    /// Visits the placements whose widened boxes the ray meets within [0, `t_max`), nearer child
    /// first, with the ray in the placement's object space; `visit` returns the distance of a hit
    /// it found (which lowers `t_max`; a negative one stops the traversal) or None. The slab test is Ize's robust one, as the wide
    /// BVH's.
    fn traverse_top(
        &self,
        top: &Bvh2,
        ray: &Ray,
        t_max: &mut f32,
        mut visit: impl FnMut(Placed, Vec3, Vec3, f32) -> Option<f32>,
    ) {
        let o = Vec3A::from(ray.o);
        let safe = |x: f32| {
            1.0 / if x.abs() < 1e-20 {
                1e-20f32.copysign(x)
            } else {
                x
            }
        };
        let inv = Vec3A::new(safe(ray.d.x), safe(ray.d.y), safe(ray.d.z));
        let enter = |n: usize, t_max: f32| -> Option<f32> {
            let b = top.nodes[n].aabb();
            let (t1, t2) = ((b.min - o) * inv, (b.max - o) * inv);
            let tn = t1.min(t2).max_element().max(0.0);
            let tf = t1.max(t2).min_element().min(t_max);
            (tn <= tf * ROBUST_FAR).then_some(tn)
        };
        if enter(0, *t_max).is_none() {
            return;
        }
        let mut stack: Vec<(usize, f32)> = vec![(0, 0.0)];
        while let Some((n, tn)) = stack.pop() {
            if tn > *t_max * ROBUST_FAR {
                continue;
            }
            let node = &top.nodes[n];
            if node.prim_count > 0 {
                let f = node.first_index as usize;
                for &k in &top.primitive_indices[f..f + node.prim_count as usize] {
                    let p = self.placed[k as usize];
                    let tf = &self.instances[p.instance as usize].transform;
                    let (po, pd) = (
                        tf.point_to_object(ray.o),
                        tf.to_object.transform_vector3(ray.d),
                    );
                    if let Some(t) = visit(p, po, pd, *t_max) {
                        *t_max = t;
                    }
                }
                continue;
            }
            let (a, b) = (node.first_index as usize, node.first_index as usize + 1);
            match (enter(a, *t_max), enter(b, *t_max)) {
                (Some(ta), Some(tb)) => {
                    let (near, far) = if ta <= tb {
                        ((a, ta), (b, tb))
                    } else {
                        ((b, tb), (a, ta))
                    };
                    stack.push(far);
                    stack.push(near);
                }
                (Some(ta), None) => stack.push((a, ta)),
                (None, Some(tb)) => stack.push((b, tb)),
                (None, None) => {}
            }
        }
    }

    /// The world-space BVH of the meshes placed once (for the benchmark and the test that its
    /// AVX2 and portable paths agree).
    pub fn wide_bvh(&self) -> &WideBvh {
        &self.world
    }

    /// Position, normals and object-space point of a hit.
    #[inline(always)]
    pub fn surface(&self, ray: &Ray, hit: &Hit) -> SurfaceHit {
        let inst = &self.instances[hit.instance as usize];
        let mesh = &inst.mesh;
        let [i0, i1, i2] = mesh.indices[hit.triangle as usize].map(|i| i as usize);
        let (a, b, c) = (mesh.positions[i0], mesh.positions[i1], mesh.positions[i2]);
        let (u, v) = (hit.uv.x, hit.uv.y);
        let w = 1.0 - u - v;
        let p_object = a * w + b * u + c * v;
        let tf = &inst.transform;
        let TriangleFrame {
            n_object,
            ng,
            tangent,
        } = match self.frames[hit.instance as usize].get(hit.triangle as usize) {
            Some(f) => *f,
            None => triangle_frame(inst, hit.triangle as usize),
        };
        let ns = match &mesh.normals {
            Some(n) => {
                let n_obj = n[i0] * w + n[i1] * u + n[i2] * v;
                let ns = tf.normal_to_world(n_obj).normalize_or_zero();
                if ns == Vec3::ZERO {
                    ng
                } else {
                    ns
                }
            }
            None => ng,
        };
        SurfaceHit {
            // The ray equation is the accurate hit point; the barycentric point is in object space.
            p: ray.at(hit.t),
            p_object,
            n_object,
            ng,
            ns,
            tangent,
            instance: hit.instance,
        }
    }
}

/// The parts of a hit's surface that are constant over its triangle ([`SurfaceHit`]'s
/// `n_object`, `ng`, `tangent`).
#[derive(Clone, Copy, Debug)]
pub(super) struct TriangleFrame {
    pub(super) n_object: Vec3,
    pub(super) ng: Vec3,
    pub(super) tangent: Vec3,
}

/// The frame of triangle `t` of `inst`: the object-space geometric normal (v1 − v0) × (v2 − v0)
/// normalised, the world normal by the inverse transpose (`Transform::normal_to_world`), and the
/// world tangent along the first edge, each normalised.
pub(super) fn triangle_frame(inst: &Instance, t: usize) -> TriangleFrame {
    let mesh = &inst.mesh;
    let [a, b, c] = mesh.indices[t].map(|i| mesh.positions[i as usize]);
    let tf = &inst.transform;
    let n_object = (b - a).cross(c - a).normalize_or_zero();
    TriangleFrame {
        n_object,
        ng: tf.normal_to_world(n_object).normalize_or_zero(),
        tangent: tf.vector_to_world(b - a).normalize_or_zero(),
    }
}

/// obvhs's BVH2 over `world`, built as its `build_cwbvh_from_tris` helper does up to the BVH2:
/// optional spatial pre-splits, PLOC (one primitive per leaf), reinsertion.
fn build_bvh2(world: &[Triangle], params: &BvhBuildParams) -> Bvh2 {
    let mut indices: Vec<u32> = (0..world.len() as u32).collect();
    let mut bvh2 = if params.pre_split {
        let mut aabbs: Vec<_> = world.iter().map(|t| t.aabb()).collect();
        let half_areas = aabbs.iter().map(|a| a.half_area());
        let largest = half_areas.clone().fold(0.0f32, f32::max);
        let average = half_areas.sum::<f32>() / world.len() as f32;
        split_aabbs_preset(&mut aabbs, &mut indices, world, average, largest);
        PlocBuilder::with_capacity(aabbs.len()).build(
            params.ploc_search_distance,
            &aabbs,
            indices,
            params.sort_precision,
            params.search_depth_threshold,
        )
    } else {
        PlocBuilder::with_capacity(world.len()).build(
            params.ploc_search_distance,
            world,
            indices,
            params.sort_precision,
            params.search_depth_threshold,
        )
    };
    bvh2.uses_spatial_splits = params.pre_split;
    ReinsertionOptimizer::default().run(&mut bvh2, params.reinsertion_batch_ratio, None);
    bvh2
}

/// Brute-force closest hit over every triangle with obvhs's own triangle test
/// (`RtTriangle::intersect`), the independent reference the BVH is tested against. Like
/// [`Accel`], it tests an instanced mesh's triangles in object space with the ray mapped there
/// (same `t`), the others in world space, so that both round alike.
pub fn brute_force_closest(accel: &Accel, ray: &Ray, t_max: f32) -> Option<f32> {
    // +0.0 turns a −0.0 direction component into +0.0 (obvhs's ray setup mishandles −0.0).
    let bvh_ray = |o: Vec3, d: Vec3| BvhRay::new(o.into(), (d + Vec3::ZERO).into(), 0.0, t_max);
    (accel.instances.iter().enumerate())
        .flat_map(|(i, inst)| {
            let tf = inst.transform;
            let (r, p): (BvhRay, Vec<Vec3A>) = if accel.is_instanced(i) {
                let r = bvh_ray(
                    tf.point_to_object(ray.o),
                    tf.to_object.transform_vector3(ray.d),
                );
                (r, inst.mesh.positions.iter().map(|&v| v.into()).collect())
            } else {
                let p = inst.mesh.positions.iter();
                (
                    bvh_ray(ray.o, ray.d),
                    p.map(|&v| tf.point_to_world(v).into()).collect(),
                )
            };
            (inst.mesh.indices.iter())
                .map(|t| RtTriangle::new(p[t[0] as usize], p[t[1] as usize], p[t[2] as usize]))
                .map(|t| t.intersect(&r))
                .collect::<Vec<_>>()
        })
        .filter(|t| *t < t_max)
        .min_by(|a, b| a.total_cmp(b))
}
