//! Light-sweep sequences: the light path, whole `xylem sweep` runs, the capture manifest, the
//! assembled sequence and its viewer. The frames themselves are rendered by the one renderer
//! ([`crate::render::render_frames`]), the moving light's places given as its `LightFrames`.
//!
//! - [`path`]: the arc of light directions, frame angles, `--frames-range` slices and where the
//!   moving light goes in each frame ([`SweepPath`]);
//! - [`batch`]: the batches of frames that fit `--memory`, rendered and written one by one;
//! - [`job`]: a whole `xylem sweep` run (render, write, assemble);
//! - [`claim`]: which sweep an output folder is for (`sweep.json`), so slices never mix;
//! - [`openjd`]: the sweep as an Open Job Description job template (`--emit-openjd`);
//! - [`manifest`]: the capture format (camera, board, lights per frame) a fit reads;
//! - [`sequence`]: per-frame records and the assembly of a folder of frames into the contact
//!   sheet, animated PNG, CSV and the HTML [`viewer`].

pub mod batch;
pub mod claim;
pub mod job;
pub mod manifest;
pub mod openjd;
pub mod path;
pub mod sequence;
pub mod viewer;

pub use crate::scene::MAX_ARCS;
pub use path::{parse_arc, ArcPlane, LightArc, PathError, SetupError, SweepPath};
pub use sequence::{assemble, AssembleOptions, FrameRecord, Region, SequenceError};

use crate::render::{
    render_frames, Frames, LightFrames, RenderError, RenderSettings, RunOptions, Scene,
};
use std::ops::Range;
use std::time::Instant;

/// Renders frames `frames` of a sweep in which light `moving` of the scene follows `path`, all
/// frames in one pass of the renderer (the light-independent work done once per pixel sample).
pub fn render_sweep(
    scene: &Scene,
    settings: &RenderSettings,
    path: &SweepPath,
    moving: usize,
    frames: Range<usize>,
    run: &RunOptions,
) -> Result<Frames, RenderError> {
    render_frames(
        scene,
        &path.light_frames(&scene.lights, moving, frames),
        settings,
        run,
    )
}

/// The same frames rendered naively, one whole render per frame (nothing shared between
/// frames): the reference the one-pass sweep is tested and timed against.
pub(crate) fn render_naive(
    scene: &Scene,
    settings: &RenderSettings,
    path: &SweepPath,
    moving: usize,
    frames: Range<usize>,
    run: &RunOptions,
) -> Result<Frames, RenderError> {
    let start = Instant::now();
    let all = path.light_frames(&scene.lights, moving, frames);
    let mut out: Option<Frames> = None;
    for k in 0..all.len() {
        let r = render_frames(scene, &LightFrames::fixed(all.frame(k)), settings, run)?;
        match &mut out {
            Some(o) => o.frames.extend(r.frames),
            None => out = Some(r),
        }
    }
    let mut out = out.expect("a sweep has at least one frame");
    out.elapsed = start.elapsed();
    Ok(out)
}
