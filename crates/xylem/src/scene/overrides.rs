//! Settings a caller lays over a loaded scene — the command line's `--quality`, `--spp`,
//! `--res`, `--seed` and `--footprint-filter`, Python's keyword arguments — checked and applied
//! in one order by every caller: the quality preset first (its spp and wood-model knobs), then
//! the explicit values, which override the preset and the scene file.

use super::quality::{self, Quality, TradeoffError};
use super::LoadedScene;

/// The most samples per pixel a scene or an override may ask for (the scene's `render.spp`
/// range is 1 to this).
pub const MAX_SPP: u32 = 1_000_000;

/// The largest image side in pixels (`render.width` / `render.height`, `--res`).
pub const MAX_RESOLUTION: u32 = 16384;

/// Settings over a loaded scene; `None` keeps the scene file's.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Overrides {
    /// A speed/accuracy preset (validation/TRADEOFF.md): its spp and wood-model knobs.
    pub quality: Option<Quality>,
    /// Samples per pixel, 1 to [`MAX_SPP`] (over the preset's).
    pub spp: Option<u32>,
    /// Image size (width, height), each 1 to [`MAX_RESOLUTION`]; the camera keeps its field of
    /// view.
    pub res: Option<(u32, u32)>,
    /// Random seed of the render.
    pub seed: Option<u64>,
    /// Band-limit the wood by the pixel footprint (over the preset's).
    pub footprint_filter: Option<bool>,
    /// How the render spreads its samples over the pixels.
    pub sampling: Option<crate::render::Sampling>,
}

/// Why overrides could not be applied: the field and its allowed range, or the preset's error.
#[derive(Debug, thiserror::Error)]
pub enum OverrideError {
    /// Samples per pixel out of range.
    #[error("spp = {0}: out of range (allowed 1 to {MAX_SPP} samples per pixel)")]
    Spp(u32),
    /// An image side out of range.
    #[error("res {side} = {value}: must be a whole number in 1..={MAX_RESOLUTION}")]
    Resolution {
        /// `width` or `height`.
        side: &'static str,
        /// The value asked for.
        value: u32,
    },
    /// The quality preset could not be applied.
    #[error("applying quality {quality}: {source}")]
    Quality {
        /// The preset.
        quality: Quality,
        /// Why.
        source: TradeoffError,
    },
}

impl Overrides {
    /// Checks every value against its range, before anything is changed.
    pub fn check(&self) -> Result<(), OverrideError> {
        if let Some(spp) = self.spp {
            if !(1..=MAX_SPP).contains(&spp) {
                return Err(OverrideError::Spp(spp));
            }
        }
        if let Some((w, h)) = self.res {
            for (side, value) in [("width", w), ("height", h)] {
                if !(1..=MAX_RESOLUTION).contains(&value) {
                    return Err(OverrideError::Resolution { side, value });
                }
            }
        }
        Ok(())
    }

    /// Checks the overrides, then applies them to `loaded`: the preset first, then the rest.
    pub fn apply(&self, loaded: &mut LoadedScene) -> Result<(), OverrideError> {
        self.check()?;
        if let Some(q) = self.quality {
            quality::apply(loaded, &q.knobs())
                .map_err(|source| OverrideError::Quality { quality: q, source })?;
        }
        if let Some(spp) = self.spp {
            loaded.settings.spp = spp;
        }
        if let Some(seed) = self.seed {
            loaded.settings.seed = seed;
        }
        if let Some(sampling) = self.sampling {
            loaded.settings.sampling = sampling;
        }
        if let Some((w, h)) = self.res {
            loaded.scene.camera = loaded.scene.camera.with_resolution(w, h);
        }
        if let Some(on) = self.footprint_filter {
            for m in &mut loaded.scene.materials {
                m.set_footprint_filter(on);
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_are_checked_before_anything_changes() {
        let mut loaded = super::super::load(std::path::Path::new("sweep_board")).unwrap();
        let before = (loaded.settings.spp, loaded.scene.camera.width);
        let bad = Overrides {
            spp: Some(7),
            res: Some((64, 0)),
            ..Default::default()
        };
        let e = bad.apply(&mut loaded).unwrap_err().to_string();
        assert_eq!(e, "res height = 0: must be a whole number in 1..=16384");
        assert_eq!((loaded.settings.spp, loaded.scene.camera.width), before);
        let e = Overrides {
            spp: Some(MAX_SPP + 1),
            ..Default::default()
        };
        assert!(e.check().is_err());
    }

    #[test]
    fn explicit_values_override_the_preset() {
        let mut loaded = super::super::load(std::path::Path::new("sweep_board")).unwrap();
        Overrides {
            quality: Some(Quality::Final),
            spp: Some(3),
            res: Some((40, 30)),
            seed: Some(9),
            footprint_filter: None,
            sampling: None,
        }
        .apply(&mut loaded)
        .unwrap();
        assert_eq!(loaded.settings.spp, 3);
        assert_eq!(loaded.settings.seed, 9);
        assert_eq!(
            (loaded.scene.camera.width, loaded.scene.camera.height),
            (40, 30)
        );
        let mut preset_only = super::super::load(std::path::Path::new("sweep_board")).unwrap();
        Overrides {
            quality: Some(Quality::Final),
            ..Default::default()
        }
        .apply(&mut preset_only)
        .unwrap();
        assert_eq!(preset_only.settings.spp, Quality::Final.knobs().spp);
    }
}
