//! Turns a surface hit into a BSDF by evaluating a solid texture or the wood volume.
//!
//! A material sees the hit in world space (position, normals, a tangent) and in object space
//! (the point before the instance transform, so the texture moves with the object). Solid
//! textures live in *tree space* (mm, pith along +z); [`Placement`] says where the object sits
//! in the tree, so the same log can be cut along different planes.

mod baked;
mod face;
mod measured;
mod placement;
mod surface;

pub use baked::{
    across_fiber, anisotropy_texel, bake_face, fiber_from_anisotropy, BakedFibers, BakedMaps,
    BakedTexel, BakedWoodMaterial,
};
pub(crate) use baked::{texel_values, TexelFrame};
pub use face::FaceRect;
pub use measured::{
    energy_bounded_fiber_color, BoardFace, ColorSpace, MeasuredBoard, MeasuredError, MeasuredFiles,
    MeasuredMaterial, DEFAULT_FIBER_COLOR_SCALE, DEFAULT_HIGHLIGHT_WIDTH_DEG,
};
pub(crate) use measured::{FIT_PNG_MARK, FIT_RECORD};
pub use placement::{CutAt, Cutting, Placement, SawnCut, SawnCutError};
pub(crate) use surface::SurfaceAtWo;
pub use surface::SurfaceBsdf;

use crate::bsdf::{Finish, FinishModel, Glass, Lambertian, Mirror, WoodBsdf, WoodBsdfParams};
use crate::math::Frame;
use crate::wood::{Footprint, Needs, WoodVolume};
use glam::{Mat3, Vec3};
use std::sync::Arc;

/// What a material needs to know about a hit. Built by the renderer.
#[derive(Clone, Copy, Debug)]
pub struct MaterialHit {
    /// Object-space position (mm).
    pub p_object: Vec3,
    /// World-space position (mm).
    pub p_world: Vec3,
    /// Geometric normal in object space (unit).
    pub n_object: Vec3,
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
    /// Width (world mm) of the camera pixel's footprint on the surface at a first hit; 0 where
    /// unknown (later bounces), which switches footprint filtering off.
    pub footprint: f32,
}

/// First-hit values the film records as AOV layers besides the beauty image.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SurfaceAov {
    /// Diffuse albedo.
    pub albedo: Vec3,
    /// Fibre direction (world, unit) or zero where the material has no fibres.
    pub fiber: Vec3,
    /// Ray-cell fraction at the hit (0–1), zero where the material has none.
    pub ray_mask: f32,
    /// Growth time (years from the pith) for wood; zero otherwise.
    pub growth_time: f32,
}

/// The result of shading a hit: the BSDF, the world shading frame it lives in (z = the possibly
/// bump-mapped shading normal) and the AOV values.
#[derive(Clone, Copy, Debug)]
pub struct Shading {
    /// The BSDF at the hit.
    pub bsdf: SurfaceBsdf,
    /// The world shading frame the BSDF lives in.
    pub frame: Frame,
    /// First-hit values for the AOV layers.
    pub aov: SurfaceAov,
}

/// A material of the scene.
#[derive(Clone, Debug)]
pub enum Material {
    /// Ideal diffuse reflector.
    Lambertian {
        /// Reflectance, linear RGB 0–1.
        albedo: Vec3,
    },
    /// The finished-wood BSDF with the same parameters everywhere; `fiber_dir` and `ray_dir` are
    /// in object space (for validation scenes).
    Fiber {
        /// The BSDF's parameters (directions in object space).
        params: WoodBsdfParams,
    },
    /// The procedural wood volume seen through a finish.
    Wood(Box<WoodMaterial>),
    /// Wood from baked texture maps on one flat face (the procedural volume's image-texture
    /// counterpart, for `xylem tradeoff`).
    BakedWood(Box<BakedWoodMaterial>),
    /// A board measured by Marschner et al. 2005: per-texel BSDF parameters from image maps on
    /// one flat face.
    Measured(Box<MeasuredMaterial>),
    /// Perfect mirror.
    Mirror {
        /// Reflectance, linear RGB 0–1.
        reflectance: Vec3,
    },
    /// Smooth dielectric (glass).
    Glass {
        /// Refractive index.
        eta: f32,
        /// Transmission tint, linear RGB 0–1.
        tint: Vec3,
    },
    /// A classic solid texture (marble, stone, …) as the albedo of a Lambertian surface, looked
    /// up at the object's placement point (a solid cutting's texture space).
    Texture(TextureMaterial),
}

/// A solid texture shared between hits.
#[derive(Clone)]
pub struct TextureMaterial {
    /// The texture's name (for messages and `Debug`).
    pub name: String,
    /// The texture, evaluated at the placement point (mm).
    pub texture: Arc<dyn crate::texture::SolidTexture>,
}

impl std::fmt::Debug for TextureMaterial {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "TextureMaterial({})", self.name)
    }
}

/// [`Material::shading_cost`] of procedural wood, in rays.
pub const WOOD_SHADING_COST: u32 = 16;

/// Solid wood: the volume, the finish over it, and the bump-mapping strength.
#[derive(Clone, Debug)]
pub struct WoodMaterial {
    /// The procedural wood volume (colours, fibres, pores) of a preset and tree.
    pub volume: Arc<WoodVolume>,
    /// The finish: its refractive index (1 = unfinished) and GGX roughness, with what the BSDF
    /// needs of them worked out once ([`Finish::new`]).
    pub finish: Finish,
    /// Scale of the pore-mask bump (0 = no bump mapping, and the volume skips the bump work).
    pub bump: f32,
    /// Speed/accuracy switches (`xylem tradeoff`); the default is the full model.
    pub switches: ShadingSwitches,
}

/// Speed/accuracy switches of a wood material, measured by `xylem tradeoff`
/// (validation/TRADEOFF.md). `Default` is what a scene renders with: the full finish, the wood
/// band-limited by the pixel footprint (issue 28; a scene's `[render] footprint_filter = false`
/// or `xylem render --footprint-filter off` point-samples it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadingSwitches {
    /// Internal reflections under the finish: closed-form series or one pass.
    pub finish: FinishModel,
    /// Band-limit the wood by the pixel footprint (`WoodVolume::eval_footprint`): rings and
    /// their colour box-filtered, finer features faded to their means.
    pub footprint_filter: bool,
}

impl Default for ShadingSwitches {
    fn default() -> Self {
        ShadingSwitches {
            finish: FinishModel::default(),
            footprint_filter: true,
        }
    }
}

impl Material {
    /// Switches footprint band-limiting on or off for a wood material (procedural or baked);
    /// other materials have nothing to filter.
    pub fn set_footprint_filter(&mut self, on: bool) {
        match self {
            Material::Wood(w) => w.switches.footprint_filter = on,
            Material::BakedWood(b) => b.switches.footprint_filter = on,
            _ => {}
        }
    }

    /// What shading one hit of this material costs, in rays (a ray traced with its share of the
    /// path loop = 1): what adaptive sampling weighs a pixel's samples by (`render::adaptive`).
    /// Procedural wood 16 ([`WOOD_SHADING_COST`]), measured on the carved bunny (420 × 360,
    /// 16 spp, uniform, 2 threads, 2 runs each): 4.53–4.65 user s with red oak against 1.67–1.93 s
    /// with a Lambertian bunny, 2.8 s over the 0.65 M samples whose first hit is the bunny, 16.9
    /// rays' time each (notes/render.md "Adaptive sampling"); the texture-map materials and
    /// solid textures a few lookups, counted as 2; the rest 1.
    pub fn shading_cost(&self) -> u32 {
        match self {
            Material::Wood(_) => WOOD_SHADING_COST,
            Material::BakedWood(_) | Material::Measured(_) | Material::Texture(_) => 2,
            Material::Lambertian { .. }
            | Material::Fiber { .. }
            | Material::Mirror { .. }
            | Material::Glass { .. } => 1,
        }
    }

    /// True for a mirror or glass: every lobe of its BSDF is a delta lobe.
    pub fn is_delta(&self) -> bool {
        match self {
            Material::Mirror { .. } | Material::Glass { .. } => true,
            Material::Lambertian { .. }
            | Material::Fiber { .. }
            | Material::Wood(_)
            | Material::BakedWood(_)
            | Material::Measured(_)
            | Material::Texture(_) => false,
        }
    }

    /// Evaluates the material at a hit.
    #[inline(always)]
    pub fn shade(&self, hit: &MaterialHit) -> Shading {
        let geometric_frame = || Frame::from_normal_tangent(hit.ns, hit.tangent);
        match self {
            Material::Lambertian { albedo } => lambertian(*albedo, geometric_frame()),
            Material::Fiber { params } => {
                let frame = geometric_frame();
                let to_local =
                    |d: Vec3| frame.to_local((hit.object_to_world * d).normalize_or_zero());
                let fiber_world = (hit.object_to_world * params.fiber_dir).normalize_or_zero();
                let local = WoodBsdfParams {
                    fiber_dir: to_local(params.fiber_dir),
                    ray_dir: to_local(params.ray_dir),
                    ..*params
                };
                // Worked out per hit: kept in this variant, a finish (≈ 300 bytes of tables)
                // would grow every `Material`, and the fibre material is for validation scenes.
                let finish = Finish::new(params.eta, params.roughness);
                wood_shading(
                    local,
                    frame,
                    fiber_world,
                    0.0,
                    FinishModel::ClosedForm,
                    &finish,
                )
            }
            Material::Wood(w) => w.shade(hit),
            Material::BakedWood(b) => b.shade(hit),
            Material::Measured(m) => m.shade(hit),
            Material::Mirror { reflectance } => Shading {
                bsdf: SurfaceBsdf::Mirror(Mirror {
                    reflectance: *reflectance,
                }),
                frame: geometric_frame(),
                aov: SurfaceAov {
                    albedo: *reflectance,
                    ..Default::default()
                },
            },
            Material::Texture(t) => {
                let place = &hit.placement;
                let (p, n) = if place.world_space {
                    (hit.p_world, hit.ng)
                } else {
                    (hit.p_object, hit.n_object)
                };
                let c = t.texture.eval(place.to_tree(p, n).0);
                // A texture colour outside [0, 1] (or NaN) would break energy conservation.
                let albedo = if c.is_finite() {
                    c.clamp(Vec3::ZERO, Vec3::ONE)
                } else {
                    Vec3::ZERO
                };
                lambertian(albedo, geometric_frame())
            }
            Material::Glass { eta, tint } => Shading {
                bsdf: SurfaceBsdf::Glass(Glass {
                    eta: *eta,
                    tint: *tint,
                }),
                frame: geometric_frame(),
                aov: SurfaceAov {
                    albedo: *tint,
                    ..Default::default()
                },
            },
        }
    }
}

fn lambertian(albedo: Vec3, frame: Frame) -> Shading {
    Shading {
        bsdf: SurfaceBsdf::Lambertian(Lambertian { albedo }),
        frame,
        aov: SurfaceAov {
            albedo,
            ..Default::default()
        },
    }
}

/// A wood BSDF from local-frame parameters under the material's `finish` (worked out once per
/// material); parameters the BSDF rejects (which a correct texel never produces) fall back to a
/// Lambertian of the diffuse colour rather than a NaN.
fn wood_shading(
    local: WoodBsdfParams,
    frame: Frame,
    fiber_world: Vec3,
    growth_time: f32,
    model: FinishModel,
    finish: &Finish,
) -> Shading {
    match WoodBsdf::new_under(local, finish) {
        Ok(b) => Shading {
            bsdf: SurfaceBsdf::Wood(b.with_finish(model)),
            frame,
            aov: SurfaceAov {
                albedo: local.diffuse,
                fiber: fiber_world,
                ray_mask: local.ray_mask,
                growth_time,
            },
        },
        Err(_) => lambertian(local.diffuse.clamp(Vec3::ZERO, Vec3::ONE), frame),
    }
}

impl WoodMaterial {
    /// What this material asks of the wood volume: colours and fibres always, bump only when on.
    pub fn needs(&self) -> Needs {
        Needs {
            color: true,
            fibers: true,
            bump: self.bump != 0.0,
        }
    }

    /// Looks the hit up in the tree and builds the finished-wood BSDF in the local frame.
    ///
    /// The placement's cutting (solid block, veneer slice per face, boards of a floor) maps the
    /// point into the tree and gives the rotation `J` from placement space to tree space; the
    /// placement space is the object's, or the world's for `world_space` placements.
    pub fn shade(&self, hit: &MaterialHit) -> Shading {
        let place = &hit.placement;
        // Placement space → world: directions by `to_world_dir`, gradients by `to_world_grad`.
        let (p, n, to_world_dir, to_world_grad) = if place.world_space {
            (hit.p_world, hit.ng, Mat3::IDENTITY, Mat3::IDENTITY)
        } else {
            (
                hit.p_object,
                hit.n_object,
                hit.object_to_world,
                hit.normal_to_world,
            )
        };
        let (p_tree, j) = place.to_tree(p, n);
        let texel = if self.switches.footprint_filter && hit.footprint > 0.0 {
            // World mm → placement units (|det|^⅓ of the placement → world map) → tree mm; the
            // surface's normal carried into the tree by J (a rotation), so that the rings are
            // filtered only as much as this face shows them.
            let unit = to_world_dir.determinant().abs().cbrt().max(1e-12);
            let footprint = Footprint {
                width: hit.footprint / unit * place.scale,
                normal: (j * n).normalize_or_zero(),
            };
            self.volume.eval_footprint(p_tree, self.needs(), footprint)
        } else {
            self.volume.eval(p_tree, self.needs())
        };
        // Tree → placement directions: Jᵀ (J is a rotation); placement → world: the instance's
        // linear map (directions are contravariant, Liu et al. 2016 §6.2).
        let to_world = |d: Vec3| (to_world_dir * (j.transpose() * d)).normalize_or_zero();
        let mut n = hit.ns;
        if self.bump != 0.0 && texel.bump_grad != Vec3::ZERO {
            // Bump mapping (Blinn 1978): h(q) = bump(p_tree(q)) with ∂p_tree/∂q = s J, so
            // ∇_q h = s Jᵀ ∇_tree h, and gradients (covariant) map to world by the normal
            // matrix; the normal tilts against the surface part of the gradient.
            let g = to_world_grad * (j.transpose() * texel.bump_grad * place.scale) * self.bump;
            let g_surface = g - n * g.dot(n);
            let tilted = (n - g_surface).normalize_or_zero();
            if tilted != Vec3::ZERO && tilted.is_finite() {
                n = tilted;
            }
        }
        let fiber_world = to_world(texel.fiber_dir);
        let frame = Frame::from_normal_tangent(n, fiber_world);
        let local = WoodBsdfParams {
            diffuse: texel.diffuse,
            fiber_color: texel.fiber_color,
            fiber_dir: frame.to_local(fiber_world),
            ray_dir: frame.to_local(to_world(texel.ray_dir)),
            ray_mask: texel.ray_mask,
            highlight_width: texel.highlight_width,
            eta: self.finish.eta(),
            roughness: self.finish.roughness(),
        };
        wood_shading(
            local,
            frame,
            fiber_world,
            texel.growth_time,
            self.switches.finish,
            &self.finish,
        )
    }
}
