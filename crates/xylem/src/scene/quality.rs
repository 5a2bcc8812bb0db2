//! Production quality settings: the model knobs a render can trade for speed (`Knobs`), the named
//! `--quality` presets chosen from their measurements (validation/TRADEOFF.md, made by
//! `xylem tradeoff`), and applying them to a loaded scene.

use crate::bsdf::FinishModel;
use crate::field::JacobianModel;
use crate::material::{bake_face, BakedFibers, BakedWoodMaterial, FaceRect, Material};
use crate::scene::LoadedScene;
use crate::wood::{NoiseParams, WoodParams, WoodVolume};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// One setting of the model knobs.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Knobs {
    /// Samples per pixel.
    pub spp: u32,
    /// Keep at most this many bands of every multiband noise (None: the preset's).
    pub max_bands: Option<u32>,
    /// Scale of every sparse-convolution impulse density (1 = the preset's).
    pub density_scale: f32,
    /// Keep pores and rays (false: drop them, "model only what the scene needs").
    pub pores_and_rays: bool,
    /// Distortion Jacobian: the paper's simplified eq. 22 or the exact derivative.
    #[serde(serialize_with = "debug_name")]
    pub jacobian: JacobianModel,
    /// Internal reflections under the finish: closed-form series or a single pass.
    #[serde(serialize_with = "debug_name")]
    pub finish: FinishModel,
    /// Band-limit the wood by the pixel footprint (drop features narrower than a pixel).
    pub footprint_filter: bool,
    /// Replace each wood material by its maps baked at this many texels along the object's top
    /// face (None: the procedural volume).
    pub baked_res: Option<u32>,
    /// Which baked map gives the fibre direction.
    pub baked_fibers: BakedFibers,
}

fn debug_name<T: std::fmt::Debug, S: serde::Serializer>(v: &T, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(&format!("{v:?}"))
}

impl Knobs {
    /// The default model (what a scene renders with when no knob is set, footprint
    /// band-limiting on since issue 28) at `spp`.
    pub const fn full(spp: u32) -> Knobs {
        Knobs {
            spp,
            max_bands: None,
            density_scale: 1.0,
            pores_and_rays: true,
            jacobian: JacobianModel::Simplified,
            finish: FinishModel::ClosedForm,
            footprint_filter: true,
            baked_res: None,
            baked_fibers: BakedFibers::Anisotropy,
        }
    }

    /// The most accurate setting of every knob at `spp`: the reference the others are measured
    /// against (the exact Jacobian instead of the simplified default, and the wood
    /// point-sampled, so that its pixels converge to the pixel filter's average of the
    /// unfiltered wood rather than to the footprint-blurred one).
    pub const fn reference(spp: u32) -> Knobs {
        Knobs {
            jacobian: JacobianModel::Exact,
            footprint_filter: false,
            ..Knobs::full(spp)
        }
    }
}

/// The named quality presets, chosen from the measurements in validation/TRADEOFF.md (mahogany)
/// and validation/TRADEOFF_curly_maple.md: the exact distortion Jacobian everywhere (it costs no
/// measurable time, and the simplified one alone leaves curly maple at SSIM 0.967 however many
/// samples are taken), footprint band-limiting everywhere (10–20 % faster and lower error at
/// ≤ 16 spp), and 4 / 16 / 64 spp for SSIM ≥ 0.9 / 0.97 / 0.99 on the mahogany board. Noise bands
/// and impulse density are not reduced: they change the figure itself (≤ 1 band drops curly
/// maple to SSIM 0.86).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Quality {
    /// 4 spp: SSIM ≥ 0.9 on the mahogany board.
    Draft,
    /// 16 spp: SSIM ≥ 0.97.
    Default,
    /// 64 spp: SSIM ≥ 0.99.
    Final,
}

impl Quality {
    /// Every preset, in order of rising cost.
    pub const ALL: [Quality; 3] = [Quality::Draft, Quality::Default, Quality::Final];
    /// Their `--quality` names, in the order of [`Quality::ALL`].
    pub const NAMES: [&'static str; 3] = ["draft", "default", "final"];

    /// The `--quality` name (`draft`).
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }
}

impl std::fmt::Display for Quality {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Quality {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|q| q.name() == s)
            .ok_or_else(|| {
                format!(
                    "`{s}` is not a quality (allowed: {})",
                    Self::NAMES.join(", ")
                )
            })
    }
}

impl Quality {
    /// The knobs of the preset.
    pub fn knobs(self) -> Knobs {
        let spp = match self {
            Quality::Draft => 4,
            Quality::Default => 16,
            Quality::Final => 64,
        };
        Knobs {
            jacobian: JacobianModel::Exact,
            footprint_filter: true,
            ..Knobs::full(spp)
        }
    }
}

fn limit_noise(n: &mut NoiseParams, k: &Knobs) {
    if let Some(b) = k.max_bands {
        n.bands = n.bands.min(b.max(1));
    }
    n.density *= k.density_scale;
}

/// The wood parameters with the knobs applied.
pub fn apply_to_params(p: &WoodParams, k: &Knobs) -> WoodParams {
    let mut p = p.clone();
    for n in [
        &mut p.distortion.radial,
        &mut p.distortion.tangential,
        &mut p.distortion.longitudinal,
    ]
    .into_iter()
    .flatten()
    {
        limit_noise(n, k);
    }
    if let Some(pores) = &mut p.pores {
        pores.density *= k.density_scale;
    }
    if let Some(rays) = &mut p.rays {
        rays.density *= k.density_scale;
    }
    if !k.pores_and_rays {
        p.pores = None;
        p.rays = None;
    }
    p
}

/// Why the knobs could not be applied to a scene.
#[derive(Debug, thiserror::Error)]
pub enum TradeoffError {
    /// A wood volume could not be rebuilt with the knobs.
    #[error(transparent)]
    Wood(#[from] crate::wood::WoodError),
    #[error(
        "baking: wood material #{material} is used by {objects} objects; a baked texture covers \
         one object's top face, so each wood material must be used by exactly one object"
    )]
    /// Baking needs one object per wood material.
    SharedMaterial {
        /// Index of the wood material.
        material: usize,
        /// Objects that use it.
        objects: usize,
    },
}

/// Applies the knobs to a loaded scene: its spp and every wood material's volume and switches.
pub fn apply(loaded: &mut LoadedScene, k: &Knobs) -> Result<(), TradeoffError> {
    loaded.settings.spp = k.spp.max(1);
    let scene = &mut loaded.scene;
    for (index, m) in scene.materials.iter_mut().enumerate() {
        if let Material::Wood(w) = m {
            let params = apply_to_params(w.volume.params(), k);
            w.volume =
                Arc::new(WoodVolume::new(params, w.volume.seed())?.with_jacobian(k.jacobian));
            w.switches.finish = k.finish;
            w.switches.footprint_filter = k.footprint_filter;
            if let Some(res) = k.baked_res {
                let users: Vec<_> = scene
                    .accel
                    .instances
                    .iter()
                    .filter(|i| i.material as usize == index)
                    .collect();
                if users.len() != 1 {
                    return Err(TradeoffError::SharedMaterial {
                        material: index,
                        objects: users.len(),
                    });
                }
                let face = top_face(&users[0].mesh.positions);
                let to_tree = users[0].placement.object_to_tree();
                let maps = bake_face(&w.volume, &face, to_tree, res);
                *m = Material::BakedWood(Box::new(BakedWoodMaterial {
                    maps: Arc::new(maps),
                    face,
                    fiber_saturation: w.volume.params().color.fiber_saturation.into(),
                    fibers: k.baked_fibers,
                    finish: w.finish,
                    bump: w.bump,
                    switches: w.switches,
                }));
            }
        }
    }
    Ok(())
}

/// The +z face of the bounding box of object-space `points`, seen from above with x to the
/// right and y up (a board lying on the xy plane).
pub fn top_face(points: &[glam::Vec3]) -> FaceRect {
    let (lo, hi) = points.iter().fold(
        (glam::Vec3::splat(f32::MAX), glam::Vec3::splat(f32::MIN)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    FaceRect {
        corner: glam::Vec3::new(lo.x, hi.y, hi.z),
        right: glam::Vec3::X,
        down: -glam::Vec3::Y,
        size: glam::Vec2::new(hi.x - lo.x, hi.y - lo.y).max(glam::Vec2::splat(1e-6)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quality_names_round_trip() {
        for q in Quality::ALL {
            assert_eq!(q.name().parse::<Quality>(), Ok(q));
        }
        assert!("fast".parse::<Quality>().is_err());
    }

    #[test]
    fn knobs_limit_bands_and_scale_density() {
        let p = crate::wood::preset("curly_maple").unwrap();
        let k = Knobs {
            max_bands: Some(1),
            density_scale: 0.5,
            ..Knobs::full(4)
        };
        let q = apply_to_params(&p, &k);
        let all = |p: &WoodParams| {
            [
                p.distortion.radial.clone(),
                p.distortion.tangential.clone(),
                p.distortion.longitudinal.clone(),
            ]
        };
        for (a, b) in all(&p).iter().zip(all(&q).iter()) {
            if let (Some(a), Some(b)) = (a, b) {
                assert_eq!(b.bands, 1, "≤ 1 band keeps exactly one band");
                assert!((b.density - 0.5 * a.density).abs() < 1e-6);
            }
        }
        assert!(WoodVolume::new(q, 1).is_ok());
    }
}
