//! The fitted maps and their files, in the encoding of the `measured` material
//! (`material::measured`, data/marschner2005/README.md) so a fitted board renders directly:
//! `diffuse.png` ρ' · 255, `fiber_color.png` k_f · 255 (the energy-bounded k_f, which is what
//! the material's default `fiber_color_scale = 1/(2π)` reads back), `fiber_axis.png`
//! (u + 1)/2 · 255 in the board frame (x along the columns, y towards the top row, z out),
//! `highlight_width.png` β/90° · 255; all stored linearly. `maps.exr` holds the same maps in
//! float (β in radians) with the residual; `residual.png` shows the relative residual (white =
//! 20 % or more); `fit.json` reports the run.

use super::model::TexelFit;
use crate::material::{MeasuredBoard, FIT_PNG_MARK, FIT_RECORD};
use crate::output::{FolderLock, LockError, LockMode, Staged};
use crate::picture::exr::{stage_exr_layers, ExrCompression, ExrLayer};
use crate::picture::png::{stage_png_rgb8, stage_png_rgb8_text};
use crate::picture::ImageError;
use glam::Vec3;
use std::path::Path;

/// Why the maps could not be written.
#[derive(Debug, thiserror::Error)]
pub enum MapsError {
    /// A map image could not be written.
    #[error(transparent)]
    Image(#[from] ImageError),
    /// The output folder's lock could not be taken.
    #[error(transparent)]
    Lock(#[from] LockError),
    /// A map holds a NaN or an infinity (no fit makes one; refused so none reaches a file).
    #[error(
        "{dir}: the {map} map holds a non-finite value at texel {index} (allowed: finite values)"
    )]
    NotFinite {
        /// The output folder.
        dir: String,
        /// The map.
        map: &'static str,
        /// The texel's index (row-major).
        index: usize,
    },
    /// A file of the output could not be written.
    #[error("{path}: {cause}")]
    Io {
        /// The file.
        path: String,
        /// The I/O error.
        cause: std::io::Error,
    },
}

/// Per-texel fitted parameters, row-major, top row first (the `measured` layout).
#[derive(Clone, Debug, PartialEq)]
pub struct FittedMaps {
    /// Map width (texels).
    pub width: usize,
    /// Map height (texels).
    pub height: usize,
    /// Substrate albedo ρ' per texel, linear RGB.
    pub diffuse: Vec<Vec3>,
    /// Fibre highlight colour k_f per texel, linear RGB.
    pub fiber_color: Vec<Vec3>,
    /// Unit fibre axis per texel in the board frame (x = columns, y = towards the top row, z = out
    /// of the face).
    pub fiber_axis: Vec<Vec3>,
    /// β, radians.
    pub beta: Vec<f32>,
    /// Relative residual (1 where the texel could not be fitted).
    pub residual: Vec<f32>,
    /// Frames each texel kept (0: not fitted).
    pub used: Vec<u32>,
}

impl FittedMaps {
    /// Maps from per-texel fits; a texel that could not be fitted (too few usable frames) gets
    /// black colours, the x axis, β = 10° and residual 1, so no map holds a NaN.
    pub(crate) fn from_fits(width: usize, height: usize, fits: &[Option<TexelFit>]) -> FittedMaps {
        let blank = TexelFit {
            diffuse: Vec3::ZERO,
            fiber_color: Vec3::ZERO,
            axis: Vec3::X,
            beta: 10f32.to_radians(),
            residual: 1.0,
            used: 0,
        };
        let f: Vec<TexelFit> = fits.iter().map(|f| f.unwrap_or(blank)).collect();
        FittedMaps {
            width,
            height,
            diffuse: f.iter().map(|t| t.diffuse).collect(),
            fiber_color: f.iter().map(|t| t.fiber_color).collect(),
            fiber_axis: f.iter().map(|t| t.axis).collect(),
            beta: f.iter().map(|t| t.beta).collect(),
            residual: f.iter().map(|t| t.residual).collect(),
            used: f.iter().map(|t| t.used).collect(),
        }
    }

    /// Refuses maps holding a NaN or an infinity (the error names the map and texel).
    pub(crate) fn check_finite(&self, dir: &Path) -> Result<(), MapsError> {
        let vectors = [
            ("diffuse", &self.diffuse),
            ("fiber_color", &self.fiber_color),
            ("fiber_axis", &self.fiber_axis),
        ];
        let scalars = [
            ("highlight_width", &self.beta),
            ("residual", &self.residual),
        ];
        let bad = vectors
            .iter()
            .find_map(|(m, v)| v.iter().position(|c| !c.is_finite()).map(|i| (*m, i)))
            .or_else(|| {
                scalars
                    .iter()
                    .find_map(|(m, v)| v.iter().position(|c| !c.is_finite()).map(|i| (*m, i)))
            });
        match bad {
            Some((map, index)) => Err(MapsError::NotFinite {
                dir: dir.display().to_string(),
                map,
                index,
            }),
            None => Ok(()),
        }
    }

    /// The maps as a measured board (fibre colour as stored: k_f itself, for the default scale).
    pub fn board(&self) -> MeasuredBoard {
        MeasuredBoard {
            width: self.width as u32,
            height: self.height as u32,
            diffuse: self.diffuse.clone(),
            fiber_color: self.fiber_color.clone(),
            fiber_axis: self.fiber_axis.clone(),
            highlight_width: Some(self.beta.clone()),
        }
    }
}

fn byte(x: f32) -> u8 {
    (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

fn rgb8(v: &[Vec3], f: impl Fn(Vec3) -> Vec3) -> Vec<u8> {
    v.iter().flat_map(|c| f(*c).to_array()).map(byte).collect()
}

/// Stages the PNG maps of `board` in the `measured` encoding into `dir` (β map if it has one).
pub fn stage_board_pngs(dir: &Path, board: &MeasuredBoard) -> Result<Vec<Staged>, MapsError> {
    stage_board_pngs_text(dir, board, &[])
}

/// [`stage_board_pngs`] with `tEXt` chunks in every map.
fn stage_board_pngs_text(
    dir: &Path,
    board: &MeasuredBoard,
    text: &[(&str, &str)],
) -> Result<Vec<Staged>, MapsError> {
    let (w, h) = (board.width, board.height);
    let png = |name: &str, bytes: &[u8]| stage_png_rgb8_text(&dir.join(name), w, h, bytes, text);
    let mut staged = vec![
        png("diffuse.png", &rgb8(&board.diffuse, |c| c))?,
        png("fiber_color.png", &rgb8(&board.fiber_color, |c| c))?,
        png(
            "fiber_axis.png",
            &rgb8(&board.fiber_axis, |u| 0.5 * (u + Vec3::ONE)),
        )?,
    ];
    if let Some(beta) = &board.highlight_width {
        // β = 90° · v/255 with v ≥ 1 (the material refuses v = 0).
        let bytes: Vec<u8> = beta
            .iter()
            .flat_map(|b| [byte(b.to_degrees() / 90.0).max(1); 3])
            .collect();
        staged.push(png("highlight_width.png", &bytes)?);
    }
    Ok(staged)
}

/// Writes the maps, the residual map, `maps.exr` and `report` (as `fit.json`) into `dir`,
/// holding the folder's lock; every file is staged first, and all are committed as one set
/// whose record `fit.json` comes last ([`crate::output::commit_set`]): a failure or a full
/// disk while encoding leaves the previous fit untouched, and a kill while committing leaves
/// no `fit.json` and no map of the previous fit.
pub fn write_maps(
    dir: &Path,
    maps: &FittedMaps,
    report: &serde_json::Value,
) -> Result<(), MapsError> {
    std::fs::create_dir_all(dir).map_err(|cause| MapsError::Io {
        path: dir.display().to_string(),
        cause,
    })?;
    maps.check_finite(dir)?;
    let _lock = FolderLock::try_new(dir, LockMode::Exclusive)?;
    let (w, h) = (maps.width as u32, maps.height as u32);
    let mut staged = stage_board_pngs_text(dir, &maps.board(), &[FIT_PNG_MARK])?;
    let grey: Vec<u8> = maps
        .residual
        .iter()
        .flat_map(|r| [byte(r / 0.2); 3])
        .collect();
    staged.push(stage_png_rgb8(&dir.join("residual.png"), w, h, &grey)?);
    let flat = |v: &[Vec3]| v.iter().flat_map(|c| c.to_array()).collect::<Vec<f32>>();
    let layers = [
        ExrLayer {
            name: "diffuse",
            channels: &["R", "G", "B"],
            data: flat(&maps.diffuse),
        },
        ExrLayer {
            name: "fiber_color",
            channels: &["R", "G", "B"],
            data: flat(&maps.fiber_color),
        },
        ExrLayer {
            name: "fiber_axis",
            channels: &["X", "Y", "Z"],
            data: flat(&maps.fiber_axis),
        },
        ExrLayer {
            name: "highlight_width",
            channels: &["Y"],
            data: maps.beta.clone(),
        },
        ExrLayer {
            name: "residual",
            channels: &["Y"],
            data: maps.residual.clone(),
        },
    ];
    staged.push(stage_exr_layers(
        &dir.join("maps.exr"),
        w,
        h,
        &layers,
        ExrCompression::Zip,
        &[("fit", "per-texel wood BSDF maps (xylem fit)".to_string())],
    )?);
    // fit.json, the report, is the set's record: written last, listing every map's size and
    // CRC-32 (`output::commit_set`).
    let record = report.as_object().cloned().unwrap_or_default();
    crate::output::commit_set(dir, staged, FIT_RECORD, record).map_err(|cause| MapsError::Io {
        path: dir.join(FIT_RECORD).display().to_string(),
        cause,
    })?;
    Ok(())
}
