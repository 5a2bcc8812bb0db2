//! Triangle meshes, instances with affine transforms, and the acceleration structure: meshes
//! placed once are flattened into world space, a mesh placed several times keeps one BVH in its
//! object space under a top-level BVH of its placements ([`Accel`]); obvhs builds each BVH2 (PLOC
//! with reinsertion, its recommended builder), and `WideBvh` collapses it into the 8-wide layout
//! the renderer traverses (faster than obvhs's CWBVH traversal here: notes/render.md).

mod accel;
mod slab;

pub use accel::{brute_force_closest, Accel, BUILD_PARAMS};
pub(crate) use slab::{segment_misses_box, slab_misses, Slab};

use crate::material::Placement;
use glam::{Affine3A, Mat3, Vec2, Vec3};
use std::sync::Arc;

/// An indexed triangle mesh in object space (millimetres).
#[derive(Clone, Debug, Default)]
pub struct TriMesh {
    /// Vertex positions (object space, mm).
    pub positions: Vec<Vec3>,
    /// Per-vertex shading normals (same length as `positions`), if the mesh has them.
    pub normals: Option<Vec<Vec3>>,
    /// Triangles as indices into `positions`; the winding gives the geometric normal
    /// (v1 − v0) × (v2 − v0).
    pub indices: Vec<[u32; 3]>,
}

impl TriMesh {
    /// Drops triangles with out-of-range indices, non-finite vertices or zero area and returns
    /// how many were dropped (scene loading reports the count as a warning).
    pub fn drop_degenerate(&mut self) -> usize {
        let n = self.positions.len() as u32;
        let before = self.indices.len();
        let pos = &self.positions;
        self.indices.retain(|t| {
            if t.iter().any(|&i| i >= n) {
                return false;
            }
            let [a, b, c] = t.map(|i| pos[i as usize]);
            let area2 = (b - a).cross(c - a).length_squared();
            a.is_finite() && b.is_finite() && c.is_finite() && area2 > 0.0 && area2.is_finite()
        });
        if let Some(ns) = &mut self.normals {
            for v in ns.iter_mut() {
                *v = v.normalize_or_zero();
            }
        }
        before - self.indices.len()
    }

    /// Appends `other` (re-indexing its triangles); normals are kept only if both have them.
    pub(crate) fn append(&mut self, other: &TriMesh) {
        let base = self.positions.len() as u32;
        let keep_normals =
            (self.normals.is_some() || self.positions.is_empty()) && other.normals.is_some();
        self.normals = if keep_normals {
            let mut n = self.normals.take().unwrap_or_default();
            n.extend_from_slice(other.normals.as_ref().unwrap());
            Some(n)
        } else {
            None
        };
        self.positions.extend_from_slice(&other.positions);
        self.indices
            .extend(other.indices.iter().map(|t| t.map(|i| i + base)));
    }

    /// Bytes of the vertex, normal and index arrays.
    pub fn bytes(&self) -> u64 {
        let normals = self.normals.as_ref().map_or(0, Vec::len);
        ((self.positions.len() + normals) * size_of::<Vec3>()
            + self.indices.len() * size_of::<[u32; 3]>()) as u64
    }
}

/// Object → world placement of one mesh: an affine map, with the inverse and the normal matrix
/// (inverse transpose of the linear part) precomputed.
#[derive(Clone, Copy, Debug)]
pub struct Transform {
    /// Object → world map.
    pub to_world: Affine3A,
    /// World → object map (the inverse of `to_world`).
    pub to_object: Affine3A,
    /// Transforms normals and gradients (covectors) from object to world.
    pub normal_to_world: Mat3,
}

impl Transform {
    /// The placement `to_world` with its inverse and normal matrix worked out.
    pub fn new(to_world: Affine3A) -> Self {
        let to_object = to_world.inverse();
        Transform {
            to_world,
            to_object,
            normal_to_world: Mat3::from(to_object.matrix3).transpose(),
        }
    }

    /// The placement that leaves the mesh where it is.
    pub fn identity() -> Self {
        Transform::new(Affine3A::IDENTITY)
    }

    /// True when the map is invertible and finite.
    pub(crate) fn is_valid(&self) -> bool {
        let d = self.to_world.matrix3.determinant();
        d.is_finite() && d.abs() > 1e-12 && self.to_object.is_finite()
    }

    /// A point (object space) in world space.
    #[inline]
    pub fn point_to_world(&self, p: Vec3) -> Vec3 {
        self.to_world.transform_point3(p)
    }

    /// A point (world space) in object space.
    #[inline]
    pub(crate) fn point_to_object(&self, p: Vec3) -> Vec3 {
        self.to_object.transform_point3(p)
    }

    /// A direction (object space) in world space, not renormalised.
    #[inline]
    pub(crate) fn vector_to_world(&self, v: Vec3) -> Vec3 {
        self.to_world.transform_vector3(v)
    }

    /// A normal (object space) in world space by the inverse transpose, not renormalised.
    #[inline]
    pub fn normal_to_world(&self, n: Vec3) -> Vec3 {
        self.normal_to_world * n
    }
}

/// One placed mesh: which mesh, where, and which material (index into the scene's materials).
#[derive(Clone, Debug)]
pub struct Instance {
    /// The mesh; instances that share one `Arc` share one object-space BVH.
    pub mesh: Arc<TriMesh>,
    /// Where the mesh is placed.
    pub transform: Transform,
    /// Index into the scene's materials.
    pub material: u32,
    /// Where the object sits in the tree (solid-texture space).
    pub placement: Placement,
}

/// A ray in world space; `d` need not be unit length for intersection, but the renderer keeps it unit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Origin (world, mm).
    pub o: Vec3,
    /// Direction (world).
    pub d: Vec3,
}

impl Ray {
    /// The point at parameter `t` (`o + t·d`).
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.o + self.d * t
    }
}

/// The closest intersection: distance, instance, triangle within the instance's mesh, and
/// barycentrics (p = (1 − u − v)·v0 + u·v1 + v·v2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit (mm along a unit-length ray).
    pub t: f32,
    /// Index into [`Accel::instances`].
    pub instance: u32,
    /// Index into the instance mesh's `indices`.
    pub triangle: u32,
    /// Barycentrics (u, v) of the hit in that triangle.
    pub uv: Vec2,
}

/// Surface data at a hit: world position, geometric and shading normals (world, unit, not yet
/// flipped towards the viewer), object-space position.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceHit {
    /// Hit point (world, mm), from the ray equation.
    pub p: Vec3,
    /// Hit point in the instance's object space (mm), from the barycentrics.
    pub p_object: Vec3,
    /// Geometric normal in object space (unit).
    pub n_object: Vec3,
    /// Geometric normal (world, unit).
    pub ng: Vec3,
    /// Shading normal (world, unit): the interpolated vertex normals, or `ng` where the mesh has
    /// none.
    pub ns: Vec3,
    /// A tangent along the triangle's first edge (world), for a stable shading frame.
    pub tangent: Vec3,
    /// Index into [`Accel::instances`].
    pub instance: u32,
}

#[cfg(test)]
mod tests;
