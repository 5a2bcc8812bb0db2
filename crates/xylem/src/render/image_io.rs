//! What a render writes into an EXR: the beauty layer `R G B A` (alpha = coverage) and the AOV
//! layers, through [`crate::picture::exr`], which owns the format.

use crate::output::Staged;
use crate::picture::exr::{stage_exr_layers, ExrCompression, ExrLayer, ExrMeta};
use crate::picture::file::{commit, ImageError};
use glam::Vec3;
use std::path::Path;

/// Writes a rendered image as EXR: beauty `R G B A` (alpha = the fraction of the pixel's camera
/// samples that hit something; misses add what they saw, black without an environment light)
/// plus the AOV layers `albedo` (RGB), `normal` (XYZ), `depth` (Z, +∞ where nothing was hit),
/// `fiber` (XYZ), `ray_mask` (Y), `growth_time` (Y) and `std_error` (Y), with `meta` in the
/// header ([`stage_exr_layers`]).
pub fn write_image_exr(
    path: &Path,
    image: &super::RenderedImage,
    meta: ExrMeta,
) -> Result<(), ImageError> {
    commit(stage_image_exr(path, image, meta)?)
}

/// [`write_image_exr`] staged, to [`commit`] later.
pub fn stage_image_exr(
    path: &Path,
    image: &super::RenderedImage,
    meta: ExrMeta,
) -> Result<Staged, ImageError> {
    let mut layers = vec![beauty_rgba(&image.beauty, &image.aov)];
    layers.extend(aov_layers(&image.aov));
    layers.push(ExrLayer {
        name: "std_error",
        channels: &["Y"],
        data: image.std_error.clone(),
    });
    stage_exr_layers(
        path,
        image.width,
        image.height,
        &layers,
        ExrCompression::Zip,
        meta,
    )
}

/// The beauty layer `R G B A` of radiance and the AOVs' coverage (alpha).
pub(crate) fn beauty_rgba(beauty: &[Vec3], aov: &[super::Aov]) -> ExrLayer<'static> {
    ExrLayer {
        name: "",
        channels: &["R", "G", "B", "A"],
        data: beauty
            .iter()
            .zip(aov)
            .flat_map(|(c, a)| [c.x, c.y, c.z, a.coverage])
            .collect(),
    }
}

/// The AOV layers of [`write_image_exr`] (`albedo` … `growth_time`), e.g. for a file of AOVs that
/// several images share.
pub(crate) fn aov_layers(aov: &[super::Aov]) -> Vec<ExrLayer<'static>> {
    let v3 = |f: &dyn Fn(&super::Aov) -> Vec3| -> Vec<f32> {
        aov.iter().flat_map(|a| f(a).to_array()).collect()
    };
    let s = |f: &dyn Fn(&super::Aov) -> f32| -> Vec<f32> { aov.iter().map(f).collect() };
    vec![
        ExrLayer {
            name: "albedo",
            channels: &["R", "G", "B"],
            data: v3(&|a| a.albedo),
        },
        ExrLayer {
            name: "normal",
            channels: &["X", "Y", "Z"],
            data: v3(&|a| a.normal),
        },
        ExrLayer {
            name: "depth",
            channels: &["Z"],
            data: s(&|a| a.depth),
        },
        ExrLayer {
            name: "fiber",
            channels: &["X", "Y", "Z"],
            data: v3(&|a| a.fiber),
        },
        ExrLayer {
            name: "ray_mask",
            channels: &["Y"],
            data: s(&|a| a.ray_mask),
        },
        ExrLayer {
            name: "growth_time",
            channels: &["Y"],
            data: s(&|a| a.growth_time),
        },
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::picture::exr::{read_exr_channels, read_exr_text};

    #[test]
    fn rendered_exr_has_alpha_infinite_depth_on_misses_and_header_metadata() {
        let hit = crate::render::Aov {
            depth: 250.0,
            coverage: 1.0,
            ..Default::default()
        };
        let miss = crate::render::Aov {
            depth: f32::INFINITY,
            ..Default::default()
        };
        let image = crate::render::RenderedImage {
            width: 2,
            height: 1,
            beauty: vec![Vec3::new(0.5, 0.25, 0.125), Vec3::ZERO],
            std_error: vec![0.0; 2],
            aov: vec![hit, miss],
            nonfinite: 0,
        };
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("r.exr");
        let meta = [
            ("spp", "64".to_string()),
            ("scene", "board – ø".to_string()),
        ];
        write_image_exr(&p, &image, &meta).unwrap();
        let ch = read_exr_channels(&p).unwrap();
        let get = |n: &str| ch.iter().find(|(c, _)| c == n).unwrap().1.clone();
        assert_eq!(get("A"), vec![1.0, 0.0]);
        assert_eq!(get("R"), vec![0.5, 0.0]);
        assert_eq!(get("depth.Z"), vec![250.0, f32::INFINITY]);
        let text = read_exr_text(&p).unwrap();
        let version = format!("xylem {}", env!("CARGO_PKG_VERSION"));
        let get = |k: &str| text.iter().find(|(n, _)| n == k).unwrap().1.clone();
        assert_eq!(get("software"), version);
        assert_eq!(get("spp"), "64");
        // Printable ASCII, everything else escaped (OpenEXR names no encoding).
        assert_eq!(get("scene"), "board \\u{2013} \\u{f8}");
    }
}
