//! Wood read from baked texture maps (what `xylem bake` writes) on a flat face: the image-texture
//! counterpart of the procedural volume, so `xylem tradeoff` can compare the two in rendered
//! images. The maps hold what glTF-style materials carry — base colour, fibre direction as a
//! KHR_materials_anisotropy texel, highlight width, ray mask, tangent-space normal — and are
//! filtered bilinearly (clamped at the edges).
//!
//! What the maps cannot carry, and this material therefore approximates (notes/sweep.md
//! "Baked textures"): the sign of the fibre's tilt out of the face (the anisotropy strength is
//! |cos|, so fibres are assumed to dip *into* the face), the ray direction (taken in the face,
//! across the fibre, as on a quartersawn face), and the fibre colour, rebuilt from the base colour
//! as c^s with the preset's fibre saturation s (exact for the Beer's-law colours of
//! `wood::BeerColor`, whose fibre colour is exp(−s a) = c^s).
//!
//! The maps are baked here too ([`bake_face`], and `bake::raster` over a mesh's UV layout through
//! [`texel_values`]), below `scene`, whose `[quality]` presets may swap a wood material for its
//! baked maps; `bake` writes them out as files for other tools.

use super::face::{bilinear_taps, face_shading, FaceRect, FaceTexel};
use super::{MaterialHit, Shading, ShadingSwitches};
use crate::bsdf::Finish;
use crate::math::safe_sqrt;
use crate::wood::{Needs, WoodTexel, WoodVolume};
use glam::{Affine3A, Mat3, Vec2, Vec3};
use rayon::prelude::*;
use std::sync::Arc;

/// Baked maps, row-major, top row first; texel (0, 0) is the top-left corner (glTF).
#[derive(Clone, Debug)]
pub struct BakedMaps {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Diffuse colour (linear RGB).
    pub base_color: Vec<Vec3>,
    /// Fibre highlight colour k_f (linear RGB; Marschner et al. 2005 eq. 3's tint of the fibre
    /// lobe), as the volume gives it.
    pub fiber_color: Vec<Vec3>,
    /// KHR_materials_anisotropy texel: the direction the highlight stretches (across the fibre,
    /// [`across_fiber`]) in [−1, 1] stored as 0.5 + 0.5·d, and the strength.
    pub anisotropy: Vec<Vec3>,
    /// Fibre highlight width β (radians).
    pub highlight_width: Vec<f32>,
    /// Ray-cell fraction (0–1).
    pub ray_mask: Vec<f32>,
    /// Tangent-space normal (unit), stored as 0.5 + 0.5·n in the PNG.
    pub normal: Vec<Vec3>,
    /// Tangent-space fibre direction (unit, x right, y up, z out of the face), stored as
    /// 0.5 + 0.5·f: unlike the anisotropy texel it keeps the sign of the tilt out of the face.
    pub fiber: Vec<Vec3>,
    /// Tangent-space ray-cell direction (unit, the frame of `fiber`): the volume's radial ray
    /// axis, which xylem's own baked material replaces by the in-face axis across the fibre;
    /// written for renderers that shade the ray lobe from it (the Mitsuba plugin
    /// `xylem_wood_baked`).
    pub ray: Vec<Vec3>,
}

/// Which map gives a baked material its fibre direction.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub enum BakedFibers {
    /// The glTF KHR_materials_anisotropy texel (the tilt out of the face taken as "into").
    #[default]
    Anisotropy,
    /// The signed tangent-space fibre direction map.
    Direction,
}

/// Everything one bilinear lookup of the maps returns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BakedTexel {
    /// Diffuse colour (linear RGB).
    pub base_color: Vec3,
    /// Encoded anisotropy (as stored).
    pub anisotropy: Vec3,
    /// Fibre highlight width β (radians).
    pub highlight_width: f32,
    /// Ray-cell fraction (0–1).
    pub ray_mask: f32,
    /// Tangent-space normal (renormalised).
    pub normal: Vec3,
    /// Tangent-space fibre direction (renormalised).
    pub fiber: Vec3,
}

impl BakedMaps {
    /// Bilinear lookup at texture coordinates `uv` (texel centres at (i + ½)/W), clamped to the
    /// edge texels outside [0, 1]².
    pub fn lookup(&self, uv: Vec2) -> BakedTexel {
        let weights = bilinear_taps(uv, self.width, self.height);
        let mut t = BakedTexel {
            base_color: Vec3::ZERO,
            anisotropy: Vec3::ZERO,
            highlight_width: 0.0,
            ray_mask: 0.0,
            normal: Vec3::ZERO,
            fiber: Vec3::ZERO,
        };
        for (i, k) in weights {
            t.base_color += self.base_color[i] * k;
            t.anisotropy += self.anisotropy[i] * k;
            t.highlight_width += self.highlight_width[i] * k;
            t.ray_mask += self.ray_mask[i] * k;
            t.normal += self.normal[i] * k;
            t.fiber += self.fiber[i] * k;
        }
        t.normal = unit_or(t.normal, Vec3::Z);
        t.fiber = unit_or(t.fiber, Vec3::X);
        t
    }
}

fn unit_or(v: Vec3, fallback: Vec3) -> Vec3 {
    let n = v.normalize_or_zero();
    if n == Vec3::ZERO {
        fallback
    } else {
        n
    }
}

/// The in-face direction a fibre with in-face direction `d` stretches its highlight along: `d`
/// turned 90° counter-clockwise, (−d_y, d_x). KHR_materials_anisotropy stores this direction
/// ([`anisotropy_texel`] says why); the sign is immaterial to the extension.
pub fn across_fiber(d: Vec2) -> Vec2 {
    Vec2::new(-d.y, d.x)
}

/// The fibre direction of an anisotropy texel in tangent space (x right, y up, z out of the
/// face): the stored in-face direction turned back by −90° (the inverse of [`across_fiber`])
/// and scaled by the strength s, dipping into the face by √(1 − s²) (the sign the encoding drops
/// is taken as "into").
pub fn fiber_from_anisotropy(a: Vec3) -> Vec3 {
    let t = Vec2::new(2.0 * a.x - 1.0, 2.0 * a.y - 1.0).normalize_or_zero();
    let s = a.z.clamp(0.0, 1.0);
    let d = if t == Vec2::ZERO {
        Vec2::X
    } else {
        -across_fiber(t)
    };
    Vec3::new(s * d.x, s * d.y, -safe_sqrt(1.0 - s * s))
}

/// Wood from baked maps over one flat face of an object (object space), seen through a finish.
#[derive(Clone, Debug)]
pub struct BakedWoodMaterial {
    /// The maps, shared between objects.
    pub maps: Arc<BakedMaps>,
    /// The face the maps cover, in object space.
    pub face: FaceRect,
    /// Fibre colour = base colour ^ this, per channel (the preset's `color.fiber_saturation`).
    pub fiber_saturation: Vec3,
    /// Where the fibre direction comes from.
    pub fibers: BakedFibers,
    /// The finish (index 1–4, GGX roughness 0–1), worked out once ([`Finish::new`]).
    pub finish: Finish,
    /// Normal-map strength (0 = off).
    pub bump: f32,
    /// Speed/accuracy switches (`xylem tradeoff`).
    pub switches: ShadingSwitches,
}

impl BakedWoodMaterial {
    /// Looks the hit's object-space point up in the maps (projected onto the face) and builds the
    /// finished-wood BSDF.
    pub fn shade(&self, hit: &MaterialHit) -> Shading {
        let t = self.maps.lookup(self.face.uv(hit.p_object));
        let f = &self.face;
        let mut n = hit.ns;
        if self.bump != 0.0 && t.normal.z > 1e-3 {
            // The normal map stores n ∝ (−∂h/∂x, −∂h/∂y, 1): the height gradient in the face is
            // (−n_x/n_z, −n_y/n_z); it tilts the normal as the volume's bump does (Blinn 1978).
            let (hx, hy) = (-t.normal.x / t.normal.z, -t.normal.y / t.normal.z);
            let g = hit.normal_to_world * (f.right * hx - f.down * hy) * self.bump;
            let tilted = (n - (g - n * g.dot(n))).normalize_or_zero();
            if tilted != Vec3::ZERO && tilted.is_finite() {
                n = tilted;
            }
        }
        let fiber = match self.fibers {
            BakedFibers::Anisotropy => fiber_from_anisotropy(t.anisotropy),
            BakedFibers::Direction => t.fiber,
        };
        let diffuse = t.base_color.clamp(Vec3::ZERO, Vec3::ONE);
        let texel = FaceTexel {
            diffuse,
            fiber_color: Vec3::new(
                diffuse.x.powf(self.fiber_saturation.x),
                diffuse.y.powf(self.fiber_saturation.y),
                diffuse.z.powf(self.fiber_saturation.z),
            )
            .clamp(Vec3::ZERO, Vec3::ONE),
            fiber,
            ray_mask: t.ray_mask.clamp(0.0, 1.0),
            highlight_width: t.highlight_width.clamp(1e-3, 0.5 * std::f32::consts::PI),
        };
        face_shading(hit, f, n, texel, &self.finish, self.switches.finish)
    }
}

/// The anisotropy texel of a fibre direction `f` on a face with tangent-space axes `right`, `up`.
/// KHR_materials_anisotropy's direction is the one in which the highlight *stretches* (its
/// roughness α_t = mix(α, 1, s²) acts along it; the extension's "BRDF" section), and a fibre's
/// highlight stretches *across* the fibre (Marschner et al. 2005 §4.2: a cylinder scatters into a
/// cone about its axis, narrow along the axis, wide around it). So the direction is f projected
/// into the face, normalised and turned 90° ([`across_fiber`]); the strength is the length of
/// that projection — 1 for fibres lying in the face, 0 for fibres straight out of it (end grain),
/// where the highlight is no longer stretched along the face. Encoded as the extension stores
/// it: red, green = 0.5 + 0.5·direction, blue = strength.
pub fn anisotropy_texel(f: Vec3, right: Vec3, up: Vec3) -> Vec3 {
    let proj = Vec2::new(f.dot(right), f.dot(up));
    let strength = proj.length().min(1.0);
    let fiber = if strength > 1e-6 {
        proj / proj.length()
    } else {
        Vec2::X
    };
    let dir = across_fiber(fiber);
    Vec3::new(0.5 + 0.5 * dir.x, 0.5 + 0.5 * dir.y, strength)
}

/// The tangent-space normal of a height field h with tree-space gradient `g` seen on a face with
/// axes `right`, `up`: n ∝ (−∂h/∂x, −∂h/∂y, 1) (the surface z = h(x, y)).
pub(crate) fn bump_normal(g: Vec3, right: Vec3, up: Vec3) -> Vec3 {
    let n = Vec3::new(-g.dot(right), -g.dot(up), 1.0);
    let n = n.normalize_or_zero();
    if n == Vec3::ZERO {
        Vec3::Z
    } else {
        n
    }
}

/// Bakes `volume` over `face`, a rectangle in a space that `to_tree` maps into the tree (an
/// object's space and its placement, or tree space itself), one sample at each texel centre.
/// Fibre directions go back contravariantly (L⁻¹ f, L the linear part of `to_tree`) and the bump
/// gradient covariantly (Lᵀ g), as the renderer's materials transport them (Liu et al. 2016 §6.2).
pub fn bake_face(volume: &WoodVolume, face: &FaceRect, to_tree: Affine3A, res: u32) -> BakedMaps {
    let (w, h) = face.texture_size(res);
    let (right, up) = (face.right, -face.down);
    let frame = TexelFrame {
        right,
        up,
        normal: right.cross(up),
    };
    let texels: Vec<_> = (0..h)
        .into_par_iter()
        .flat_map_iter(|y| {
            (0..w).map(move |x| {
                let uv = Vec2::new((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
                let p = to_tree.transform_point3(face.point(uv));
                Some((volume.eval(p, Needs::ALL), frame))
            })
        })
        .collect();
    texel_values(w, h, &texels, Mat3::from(to_tree.matrix3))
}

/// A texel's tangent space in object space: x to the image's right (+u), y to its up (−v), z out
/// of the surface (unit, right-handed up to the mesh's handedness).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct TexelFrame {
    pub right: Vec3,
    pub up: Vec3,
    pub normal: Vec3,
}

/// The maps of `w` × `h` texels from the wood at each texel (`None`: not on the surface, zeros
/// for the caller to fill) seen in its frame. `l` is the linear part of the object → tree map:
/// fibre directions go back contravariantly (L⁻¹ f) and the bump gradient covariantly (Lᵀ g), as
/// the renderer's materials transport them (Liu et al. 2016 §6.2).
pub(crate) fn texel_values(
    w: u32,
    h: u32,
    texels: &[Option<(WoodTexel, TexelFrame)>],
    l: Mat3,
) -> BakedMaps {
    let l_inv = l.inverse();
    let each = |f: &dyn Fn(&WoodTexel, &TexelFrame) -> Vec3| -> Vec<Vec3> {
        texels
            .iter()
            .map(|t| t.as_ref().map_or(Vec3::ZERO, |(t, fr)| f(t, fr)))
            .collect()
    };
    let scalar = |f: &dyn Fn(&WoodTexel) -> f32| -> Vec<f32> {
        texels
            .iter()
            .map(|t| t.as_ref().map_or(0.0, |(t, _)| f(t)))
            .collect()
    };
    // Directions go back contravariantly: object-space unit vectors, then their components in
    // the texel's frame.
    let obj_dir = |d: Vec3| (l_inv * d).normalize_or_zero();
    let tangent =
        |d: Vec3, fr: &TexelFrame| Vec3::new(d.dot(fr.right), d.dot(fr.up), d.dot(fr.normal));
    let obj_fiber = |t: &WoodTexel| obj_dir(t.fiber_dir);
    BakedMaps {
        width: w,
        height: h,
        base_color: each(&|t, _| t.diffuse),
        fiber_color: each(&|t, _| t.fiber_color),
        fiber: each(&|t, fr| tangent(obj_fiber(t), fr)),
        ray: each(&|t, fr| tangent(obj_dir(t.ray_dir), fr)),
        anisotropy: each(&|t, fr| anisotropy_texel(obj_fiber(t), fr.right, fr.up)),
        highlight_width: scalar(&|t| t.highlight_width),
        ray_mask: scalar(&|t| t.ray_mask),
        normal: each(&|t, fr| bump_normal(l.transpose() * t.bump_grad, fr.right, fr.up)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bump_normal_tilts_against_the_slope() {
        // h = 0.5 x: the surface rises to the right, so its normal leans left (−x).
        let n = bump_normal(Vec3::new(0.5, 0.0, 0.0), Vec3::X, Vec3::Y);
        assert!((n - Vec3::new(-0.5, 0.0, 1.0).normalize()).length() < 1e-6);
        assert_eq!(bump_normal(Vec3::ZERO, Vec3::X, Vec3::Y), Vec3::Z);
        assert_eq!(
            bump_normal(Vec3::splat(f32::NAN), Vec3::X, Vec3::Y),
            Vec3::Z
        );
    }

    fn maps_2x1() -> BakedMaps {
        BakedMaps {
            width: 2,
            height: 1,
            base_color: vec![Vec3::new(0.2, 0.1, 0.0), Vec3::new(0.6, 0.3, 0.2)],
            fiber_color: vec![Vec3::splat(0.5); 2],
            anisotropy: vec![Vec3::new(0.5, 1.0, 1.0); 2],
            highlight_width: vec![0.1, 0.3],
            ray_mask: vec![0.0, 1.0],
            normal: vec![Vec3::Z; 2],
            fiber: vec![Vec3::X; 2],
            ray: vec![Vec3::Y; 2],
        }
    }

    #[test]
    fn lookup_hits_texel_centres_and_interpolates_between() {
        let m = maps_2x1();
        assert_eq!(m.lookup(Vec2::new(0.25, 0.5)).base_color, m.base_color[0]);
        assert_eq!(m.lookup(Vec2::new(0.75, 0.5)).base_color, m.base_color[1]);
        let mid = m.lookup(Vec2::new(0.5, 0.5));
        assert!((mid.highlight_width - 0.2).abs() < 1e-6 && (mid.ray_mask - 0.5).abs() < 1e-6);
        // Clamped outside.
        assert_eq!(m.lookup(Vec2::new(-3.0, 9.0)).base_color, m.base_color[0]);
    }

    #[test]
    fn anisotropy_decodes_to_a_unit_fibre() {
        // Highlight stretched up the image (0, 1): the fibre runs along x.
        let f = fiber_from_anisotropy(Vec3::new(0.5, 1.0, 1.0));
        assert!((f - Vec3::X).length() < 1e-6, "{f}");
        // Strength ½, stretched along −x: the fibre runs along y, its in-face part has length ½
        // and it dips into the face.
        let g = fiber_from_anisotropy(Vec3::new(0.0, 0.5, 0.5));
        assert!((g.length() - 1.0).abs() < 1e-6 && (g.y - 0.5).abs() < 1e-6 && g.z < 0.0);
        assert_eq!(across_fiber(Vec2::X), Vec2::Y);
    }
}
