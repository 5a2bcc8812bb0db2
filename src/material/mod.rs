//! Turns a surface hit into a BSDF by evaluating a solid texture or the wood volume.
//!
//! A material sees the hit in world space (position, normals, a tangent) and in object space
//! (the point before the instance transform, so the texture moves with the object). Solid
//! textures live in *tree space* (mm, pith along +z); [`Placement`] says where the object sits
//! in the tree, so the same log can be cut along different planes.

mod placement;

pub use placement::Placement;

use crate::bsdf::{Bsdf, BsdfSample, Lambertian};
use crate::math::Frame;
use glam::{Mat3, Vec2, Vec3};

/// What a material needs to know about a hit. Built by the renderer.
#[derive(Clone, Copy, Debug)]
pub struct MaterialHit {
    /// Object-space position (mm).
    pub p_object: Vec3,
    /// Geometric normal (world, unit).
    pub ng: Vec3,
    /// Interpolated shading normal (world, unit).
    pub ns: Vec3,
    /// A surface tangent (world, unit), for a stable frame orientation.
    pub tangent: Vec3,
    /// Linear part of the object → world map (transforms directions).
    pub object_to_world: Mat3,
    /// Inverse transpose of `object_to_world` (transforms normals and gradients).
    pub normal_to_world: Mat3,
    /// Where the object sits in the tree.
    pub placement: Placement,
}

/// First-hit values the film records as AOV layers besides the beauty image.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SurfaceAov {
    /// Diffuse albedo.
    pub albedo: Vec3,
    /// Fibre direction (world, unit) or zero where the material has no fibres.
    pub fiber: Vec3,
    pub ray_mask: f32,
    /// Growth time (years from the pith) for wood; zero otherwise.
    pub growth_time: f32,
}

/// The BSDF at one hit, in its local shading frame. Small and `Copy`, so a light sweep can cache
/// it per pixel sample.
#[derive(Clone, Copy, Debug)]
pub enum SurfaceBsdf {
    Lambertian(Lambertian),
}

impl SurfaceBsdf {
    /// True when every lobe is a delta lobe (light sampling is useless there).
    pub fn is_delta(&self) -> bool {
        false
    }

    /// True when the BSDF transmits (the renderer must not flip the normal towards the viewer).
    pub fn is_transmissive(&self) -> bool {
        false
    }
}

impl Bsdf for SurfaceBsdf {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        match self {
            SurfaceBsdf::Lambertian(b) => b.eval(wo, wi),
        }
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self {
            SurfaceBsdf::Lambertian(b) => b.pdf(wo, wi),
        }
    }

    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
        match self {
            SurfaceBsdf::Lambertian(b) => b.sample(wo, uc, u),
        }
    }
}

/// The result of shading a hit: the BSDF, the world shading frame it lives in (z = the possibly
/// bump-mapped shading normal) and the AOV values.
#[derive(Clone, Copy, Debug)]
pub struct Shading {
    pub bsdf: SurfaceBsdf,
    pub frame: Frame,
    pub aov: SurfaceAov,
}

/// A material of the scene.
#[derive(Clone, Debug)]
pub enum Material {
    /// Ideal diffuse reflector.
    Lambertian { albedo: Vec3 },
}

impl Material {
    /// Evaluates the material at a hit.
    pub fn shade(&self, hit: &MaterialHit) -> Shading {
        let frame = Frame::from_normal_tangent(hit.ns, hit.tangent);
        match self {
            Material::Lambertian { albedo } => Shading {
                bsdf: SurfaceBsdf::Lambertian(Lambertian { albedo: *albedo }),
                frame,
                aov: SurfaceAov {
                    albedo: *albedo,
                    ..Default::default()
                },
            },
        }
    }
}
