//! A whole `xylem sweep` job: set up the path from the scene, render the selected frames (cached
//! or naive), write each frame's EXR, PNG and record, and assemble the sequence once every frame
//! of the sweep is in the output folder.

use super::cache::{render_naive, render_sweep, SetupError, SweepPath, SweepRender};
use super::path::{parse_frames_range, PathError};
use super::sequence::{
    assemble, frame_stem, read_records, write_frame, AssembleOptions, Assembled, FrameRecord,
    Region, SequenceError,
};
use crate::render::image_io::{
    aov_layers, write_exr_layers, write_exr_layers_with, ExrCompression, ExrLayer, ImageError,
};
use crate::render::{RenderError, RunOptions};
use crate::scene::LoadedScene;
use rayon::prelude::*;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Anything that stops a sweep job.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    #[error(transparent)]
    Setup(#[from] SetupError),
    #[error(transparent)]
    Path(#[from] PathError),
    #[error(transparent)]
    Render(#[from] RenderError),
    #[error(transparent)]
    Sequence(#[from] SequenceError),
    #[error(transparent)]
    Image(#[from] ImageError),
    #[error("cannot create output folder {path}: {cause}")]
    OutDir { path: String, cause: std::io::Error },
}

/// What to render and where.
#[derive(Clone, Debug, Default)]
pub struct SweepJob {
    /// Frames along the arc (default: the scene's `[sweep] frames`).
    pub frames: Option<usize>,
    /// Arc ends in degrees (default: the scene's `[sweep] arc_deg`).
    pub arc: Option<(f32, f32)>,
    /// `--frames-range` text; `None` renders every frame.
    pub range: Option<String>,
    pub out: PathBuf,
    /// Render every frame from scratch instead of caching (for timing and checking the cache).
    pub naive: bool,
    pub run: RunOptions,
    /// Compression of each frame's EXR (the shared AOV file is always ZIP).
    pub exr: ExrCompression,
}

/// What a job did.
#[derive(Debug)]
pub struct JobReport {
    pub rendered: Range<usize>,
    pub total: usize,
    pub render_time: Duration,
    /// Set when every frame was present and the sequence outputs were written.
    pub assembled: Option<Assembled>,
}

/// The scene's named regions, for the CSV.
pub fn scene_regions(loaded: &LoadedScene) -> Vec<Region> {
    loaded
        .sweep
        .iter()
        .flat_map(|t| &t.regions)
        .map(|r| Region {
            name: r.name.clone(),
            x0: r.x0,
            y0: r.y0,
            x1: r.x1,
            y1: r.y1,
        })
        .collect()
}

/// The file holding the first-hit AOV layers that every frame of a sweep shares.
pub const AOV_FILE: &str = "aov.exr";

/// Writes every frame of `render` (EXR of radiance and standard error, PNG, record) into `dir`,
/// frames in parallel, and the AOVs they share once into [`AOV_FILE`] (the camera and geometry
/// do not move, so the AOVs are the same in every frame).
pub fn write_frames(
    dir: &Path,
    render: &SweepRender,
    total: usize,
    exposure: f32,
    regions: &[Region],
    compression: ExrCompression,
) -> Result<(), SweepError> {
    let (w, h) = (render.width, render.height);
    write_exr_layers(&dir.join(AOV_FILE), w, h, &aov_layers(&render.aov))?;
    render.frames.par_iter().try_for_each(|f| {
        let layers = [
            ExrLayer {
                name: "",
                channels: &["R", "G", "B"],
                data: f.beauty.iter().flat_map(|c| c.to_array()).collect(),
            },
            ExrLayer {
                name: "std_error",
                channels: &["Y"],
                data: f.std_error.clone(),
            },
        ];
        write_exr_layers_with(
            &dir.join(format!("{}.exr", frame_stem(f.index))),
            w,
            h,
            &layers,
            compression,
        )?;
        let rec = FrameRecord::measure(f.index, total, f.light_deg, (w, h), &f.beauty, regions);
        write_frame(dir, &rec, &f.beauty, exposure)?;
        Ok(())
    })
}

/// Runs a sweep job on a loaded scene.
pub fn run_job(loaded: &LoadedScene, job: &SweepJob) -> Result<JobReport, SweepError> {
    let (path, moving) = SweepPath::from_scene(loaded, job.frames, job.arc)?;
    let total = path.arc.frames;
    let range = match &job.range {
        Some(text) => parse_frames_range(text, total)?,
        None => 0..total,
    };
    std::fs::create_dir_all(&job.out).map_err(|cause| SweepError::OutDir {
        path: job.out.display().to_string(),
        cause,
    })?;
    if job.range.is_none() {
        clear_frames(&job.out)?;
    }
    let render = if job.naive {
        render_naive
    } else {
        render_sweep
    };
    let r = render(
        &loaded.scene,
        &loaded.settings,
        &path,
        moving,
        range.clone(),
        &job.run,
    )?;
    write_frames(
        &job.out,
        &r,
        total,
        loaded.exposure,
        &scene_regions(loaded),
        job.exr,
    )?;
    // Assemble when the folder now holds the complete sweep (always, unless farming slices).
    let complete = match read_records(&job.out) {
        Ok(_) => true,
        Err(SequenceError::Missing { .. }) => false,
        Err(e) => return Err(e.into()),
    };
    let assembled = if complete {
        let opts = AssembleOptions {
            title: format!("{} — light sweep", loaded.name),
            ..Default::default()
        };
        Some(assemble(&job.out, &opts)?)
    } else {
        None
    };
    Ok(JobReport {
        rendered: range,
        total,
        render_time: r.elapsed,
        assembled,
    })
}

/// Removes the frame files (`frame_NNNN.{json,png,exr}`) a previous sweep left in `dir`, so a new
/// complete sweep never mixes with them.
fn clear_frames(dir: &Path) -> Result<(), SweepError> {
    let io = |cause| SweepError::OutDir {
        path: dir.display().to_string(),
        cause,
    };
    for entry in std::fs::read_dir(dir).map_err(io)? {
        let p = entry.map_err(io)?.path();
        let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
        let is_frame = name
            .strip_prefix("frame_")
            .and_then(|r| r.split_once('.'))
            .is_some_and(|(digits, ext)| {
                digits.bytes().all(|b| b.is_ascii_digit()) && ["json", "png", "exr"].contains(&ext)
            });
        if is_frame {
            std::fs::remove_file(&p).map_err(io)?;
        }
    }
    Ok(())
}
