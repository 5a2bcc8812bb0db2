//! Level of detail from the scene (issue 28, "model only what a scene requires"): before a
//! render, the smallest pixel footprint the camera leaves on each wood material, and which of
//! its fine features ([`fading_features`](crate::wood::WoodVolume::fading_features)) that
//! footprint already fades to their means in every pixel, so that no camera hit evaluates them (`xylem render --explain`).
//!
//! The footprint of a camera hit at depth z along the view axis is at least
//! `footprint_scale(spp) · 2 tan(fov/2) / height · z` ([`Camera::pixel_footprint`]; the
//! integrator divides it by √|cos| ≤ 1 on oblique faces, which only widens it), so the smallest
//! depth of the object's part inside the view frustum bounds every first hit's footprint from
//! below. That depth is found exactly by clipping each triangle to the frustum's four side planes
//! (Sutherland & Hodgman 1974, "Reentrant polygon clipping", CACM 17(1)): depth is linear, so its
//! minimum over a clipped polygon lies at one of its vertices. Derivation and figures:
//! notes/render.md "Level of detail from the scene".

use super::camera::{Camera, Projection};
use super::integrator::footprint_scale;
use super::Scene;
use crate::material::Material;
use glam::Vec3;

/// What the smallest footprint on a material does to one feature.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Detail {
    /// Evaluated in full in at least some pixel (footprint under the feature's size).
    Kept,
    /// Partly faded to its mean everywhere, evaluated still (footprint between one and two
    /// sizes).
    Fading,
    /// Faded to its mean in every pixel: never evaluated at a camera hit (footprint ≥ twice the
    /// size).
    Skipped,
}

/// One fine feature of a wood material and what the scene's camera does to it.
#[derive(Clone, Debug, PartialEq)]
pub struct FeaturePlan {
    /// The feature (`pores`, `rays`, `cell texture`, `texture streaks`).
    pub name: &'static str,
    /// Its size, tree mm ([`fading_features`](crate::wood::WoodVolume::fading_features)).
    pub size: f32,
    /// Kept, fading or skipped at the smallest footprint.
    pub detail: Detail,
}

/// The level of detail of one procedural wood material.
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialPlan {
    /// Index into the scene's materials.
    pub material: usize,
    /// Objects (instances) that use it.
    pub objects: usize,
    /// Smallest camera-hit footprint over those objects, tree mm; infinite where none of them is
    /// inside the view.
    pub footprint: f32,
    /// Its fine features, in [`WoodVolume::fading_features`](crate::wood::WoodVolume::fading_features)
    /// order; all skipped where `footprint` is infinite.
    pub features: Vec<FeaturePlan>,
}

/// The detail of a feature of size `size` under footprints of at least `footprint` (both tree
/// mm), by the footprint filter's ramp (`footprint_weight` in wood/features.rs: the feature in
/// full below `size`, its mean alone from `2 · size`).
pub fn detail(size: f32, footprint: f32) -> Detail {
    if footprint >= 2.0 * size {
        Detail::Skipped
    } else if footprint > size {
        Detail::Fading
    } else {
        Detail::Kept
    }
}

/// The level of detail of every procedural wood material of `scene` rendered at `spp` samples
/// per pixel (materials no object uses are left out). Only the footprint filter's own fading is
/// described: with `footprint_filter` off a material keeps everything.
pub fn plan(scene: &Scene, spp: u32) -> Vec<MaterialPlan> {
    let cam = &scene.camera;
    let scale = footprint_scale(spp);
    let mut out: Vec<MaterialPlan> = Vec::new();
    for inst in &scene.accel.instances {
        let m = inst.material as usize;
        let Some(Material::Wood(w)) = scene.materials.get(m) else {
            continue;
        };
        // World mm → tree mm as `WoodMaterial::shade` converts the hit's footprint.
        let unit = if inst.placement.world_space {
            1.0
        } else {
            inst.transform
                .to_world
                .matrix3
                .determinant()
                .abs()
                .cbrt()
                .max(1e-12)
        };
        let world = match cam.projection {
            Projection::Perspective { fov_y, .. } => {
                let depth = nearest_depth(cam, fov_y, inst);
                scale * 2.0 * (0.5 * fov_y).tan() / cam.height as f32 * depth
            }
            Projection::Orthographic { width } => scale * width / cam.width as f32,
        };
        let footprint = if w.switches.footprint_filter {
            world / unit * inst.placement.scale
        } else {
            0.0
        };
        match out.iter_mut().find(|p| p.material == m) {
            Some(p) => {
                p.objects += 1;
                p.footprint = p.footprint.min(footprint);
            }
            None => out.push(MaterialPlan {
                material: m,
                objects: 1,
                footprint,
                features: Vec::new(),
            }),
        }
    }
    for p in &mut out {
        let Some(Material::Wood(w)) = scene.materials.get(p.material) else {
            unreachable!("only wood materials are planned");
        };
        p.features = w
            .volume
            .fading_features()
            .into_iter()
            .map(|(name, size)| FeaturePlan {
                name,
                size,
                detail: detail(size, p.footprint),
            })
            .collect();
    }
    out
}

/// The smallest depth along the view axis (world mm) of the part of `inst` inside the
/// perspective camera's view frustum (vertical field of view `fov_y`), or infinity where no part
/// of it is inside.
fn nearest_depth(cam: &Camera, fov_y: f32, inst: &super::geometry::Instance) -> f32 {
    let ty = (0.5 * fov_y).tan();
    let tx = ty * cam.width as f32 / cam.height as f32;
    let f = &cam.frame;
    let to_cam = |p: Vec3| {
        let d = inst.transform.point_to_world(p) - cam.eye;
        Vec3::new(d.dot(f.s), d.dot(f.t), d.dot(f.n))
    };
    // Inside where every plane function is ≥ 0 (together they also imply depth ≥ 0).
    let planes: [fn(Vec3, f32, f32) -> f32; 4] = [
        |p, tx, _| tx * p.z - p.x,
        |p, tx, _| tx * p.z + p.x,
        |p, _, ty| ty * p.z - p.y,
        |p, _, ty| ty * p.z + p.y,
    ];
    let mut best = f32::INFINITY;
    let (mut poly, mut next) = (Vec::with_capacity(8), Vec::with_capacity(8));
    for tri in &inst.mesh.indices {
        poly.clear();
        poly.extend(tri.iter().map(|&i| to_cam(inst.mesh.positions[i as usize])));
        for plane in planes {
            next.clear();
            for (k, &a) in poly.iter().enumerate() {
                let b = poly[(k + 1) % poly.len()];
                let (da, db) = (plane(a, tx, ty), plane(b, tx, ty));
                if da >= 0.0 {
                    next.push(a);
                }
                if (da >= 0.0) != (db >= 0.0) {
                    next.push(a + (b - a) * (da / (da - db)));
                }
            }
            std::mem::swap(&mut poly, &mut next);
            if poly.is_empty() {
                break;
            }
        }
        for p in &poly {
            best = best.min(p.z.max(0.0));
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn detail_follows_the_footprint_weight_ramp() {
        assert_eq!(detail(0.26, 0.2), Detail::Kept);
        assert_eq!(detail(0.26, 0.26), Detail::Kept);
        assert_eq!(detail(0.26, 0.4), Detail::Fading);
        assert_eq!(detail(0.26, 0.52), Detail::Skipped);
        assert_eq!(detail(0.26, f32::INFINITY), Detail::Skipped);
    }
}
