//! A whole `xylem sweep` job: set up the path from the scene, render the selected frames (in one
//! pass or each alone), write each frame's EXR, PNG and record, and assemble the sequence once every frame
//! of the sweep is in the output folder.

use super::batch::{batches, default_plan, plan, BudgetError, Plan, PrimaryMode, SweepSize};
use super::claim::{claim_for_slice, replace_claim, Claim};
use super::manifest::{Manifest, MANIFEST_FILE};
use super::path::{parse_frames_range, PathError};
use super::path::{SetupError, SweepPath};
use super::render_naive;
use super::sequence::{
    assemble, clear_assembled, frame_stem, read_records, unmark_frame, write_record,
    AssembleOptions, Assembled, FrameRecord, Region, SequenceError, SweepSettings,
};
use crate::output::{remove_if_present, FolderLock, LockError, LockMode};
use crate::picture::exr::{stage_exr_layers, write_exr_layers, ExrCompression, ExrLayer};
use crate::picture::file::commit;
use crate::picture::png::stage_png_linear;
use crate::picture::ImageError;
use crate::render::image_io::{aov_layers, beauty_rgba};
use crate::render::resources::Resources;
use crate::render::{render_frames_reusing, Frames, Primaries};
use crate::render::{RenderError, RunOptions};
use crate::resources::ResourceError;
use crate::scene::LoadedScene;
use rayon::prelude::*;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Anything that stops a sweep job.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// The scene's `[sweep]` table does not describe a path.
    #[error(transparent)]
    Setup(#[from] SetupError),
    /// A bad `--frames`, `--arc` or `--frames-range` value.
    #[error(transparent)]
    Path(#[from] PathError),
    /// The renderer could not start.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// A frame record or an assembled output could not be written or read.
    #[error(transparent)]
    Sequence(#[from] SequenceError),
    /// A frame's EXR or PNG could not be written.
    #[error(transparent)]
    Image(#[from] ImageError),
    /// The output folder could not be created.
    #[error("cannot create output folder {path}: {cause}")]
    OutDir {
        /// The folder.
        path: String,
        /// Why.
        cause: std::io::Error,
    },
    /// Another job holds the output folder.
    #[error(transparent)]
    Lock(#[from] LockError),
    /// The sweep would need more memory or disk than the machine has.
    #[error(transparent)]
    Resources(#[from] ResourceError),
    /// `--memory` cannot hold one frame.
    #[error(transparent)]
    Budget(#[from] BudgetError),
    /// A slice's sweep differs from the capture already in its folder.
    #[error("{path} describes another sweep ({theirs}) than this slice ({ours}); render the slice with the same scene, --frames and --arc, or into another --out")]
    OtherSweep {
        /// The folder's manifest.
        path: String,
        /// What the folder's manifest describes.
        theirs: String,
        /// What this slice would write.
        ours: String,
    },
    /// The folder holds (or is being filled with) a sweep of other settings.
    #[error("{path}: this folder holds a sweep of other settings ({difference}); render every slice with the same scene and settings (--frames, --arc, --spp, --res, --quality), rerun the whole sweep, or choose another --out")]
    Claimed {
        /// The folder's claim (`sweep.json`) or the frame record that differs.
        path: String,
        /// How: the setting, the folder's value and this run's.
        difference: String,
    },
}

/// What to render and where.
#[derive(Clone, Debug, Default)]
pub struct SweepJob<'a> {
    /// Frames along the arc (default: the scene's `[sweep] frames`).
    pub frames: Option<usize>,
    /// Arc ends in degrees (default: the scene's `[sweep] arc_deg`).
    pub arc: Option<(f32, f32)>,
    /// `--frames-range` text; `None` renders every frame.
    pub range: Option<String>,
    /// Output folder of the frames, records and assembled sequence.
    pub out: PathBuf,
    /// Render every frame from scratch instead of in one pass (for timing and checking the sharing).
    pub naive: bool,
    /// Threads and progress reporting (never change a pixel).
    pub run: RunOptions<'a>,
    /// Compression of each frame's EXR (the shared AOV file is always ZIP).
    pub exr: ExrCompression,
    /// Skip the memory and disk estimate (`--ignore-limits`).
    pub ignore_limits: bool,
    /// Memory budget in bytes for the frames held at once (`--memory`; default
    /// [`default_plan`]): frames are rendered and written in batches that fit it.
    pub memory: Option<u64>,
    /// Whether the primary samples are kept across batches (`--primaries`).
    pub primaries: PrimaryMode,
    /// What else decides the frames (scene file digest, quality preset), recorded with each frame
    /// so that `--assemble` refuses slices that disagree.
    pub provenance: String,
}

/// What a job did.
#[derive(Debug)]
pub struct JobReport {
    /// The frames this job rendered (indices into the whole sweep).
    pub rendered: Range<usize>,
    /// Frames of the whole sweep.
    pub total: usize,
    /// Wall time of the rendering (without writing the files).
    pub render_time: Duration,
    /// Most frames rendered at once (the batch the memory budget allows).
    pub batch: usize,
    /// Batches rendered.
    pub batches: usize,
    /// Whether the primary samples were kept from the first batch for the others.
    pub kept_primaries: bool,
    /// Set when every frame was present and the sequence outputs were written.
    pub assembled: Option<Assembled>,
}

/// The scene's named regions, for the CSV.
pub(crate) fn scene_regions(loaded: &LoadedScene) -> Vec<Region> {
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

/// The file holding the first-hit AOV layers that every frame of a sweep shares. It is written
/// by the job that renders frame 0 (the whole sweep, or the first slice of a farmed one), so no
/// two slices ever write it.
pub(crate) const AOV_FILE: &str = "aov.exr";

/// Writes every frame of `render` into `dir`, frames in parallel. Each frame's old record goes
/// first, then its EXR (radiance and standard error) and PNG are renamed into place and its new
/// record is written last, so a record always describes the images beside it, even when the run
/// is killed. The job that renders frame 0 also writes the AOVs every frame shares into
/// [`AOV_FILE`] (the camera and geometry do not move). `render` holds frames `range` of the
/// sweep `path`.
///
/// Each frame's EXR header carries one attribute, `sweep_frame` (one, because the exr crate
/// writes several in hash-map order and frames must be byte-stable): the frame, the light's
/// angle, azimuth, direction and position on the arc, then `header` (the render's spp, seed,
/// integrator and camera, [`frame_header`]).
#[allow(clippy::too_many_arguments)]
pub(crate) fn write_frames(
    dir: &Path,
    render: &Frames,
    path: &SweepPath,
    range: Range<usize>,
    total: usize,
    exposure: f32,
    regions: &[Region],
    compression: ExrCompression,
    settings: &SweepSettings,
    header: &str,
) -> Result<(), SweepError> {
    let (w, h) = (render.width, render.height);
    if range.start == 0 && !render.frames.is_empty() {
        write_exr_layers(&dir.join(AOV_FILE), w, h, &aov_layers(&render.aov))?;
    }
    render
        .frames
        .par_iter()
        .zip(range)
        .try_for_each(|(f, index)| {
            let light_deg = path.light_deg(index);
            let stem = frame_stem(index);
            let layers = [
                beauty_rgba(&f.beauty, &render.aov),
                ExrLayer {
                    name: "std_error",
                    channels: &["Y"],
                    data: f.std_error.clone(),
                },
            ];
            // One attribute: the exr crate writes its extra attributes in hash-map order, which
            // differs run to run, and frames must be byte-stable (crates/xylem-cli/tests/robustness.rs).
            let (to, at) = (
                path.direction(index),
                path.pivot + path.radius * path.direction(index),
            );
            let meta = [(
                "sweep_frame",
                format!(
                    "frame {index} of {total}, light at {light_deg} deg, azimuth {} deg, \
                     direction ({}, {}, {}), position ({}, {}, {}) mm; {header}",
                    path.azimuth_deg(index),
                    to.x,
                    to.y,
                    to.z,
                    at.x,
                    at.y,
                    at.z
                ),
            )];
            let exr = stage_exr_layers(
                &dir.join(format!("{stem}.exr")),
                w,
                h,
                &layers,
                compression,
                &meta,
            )?;
            let png =
                stage_png_linear(&dir.join(format!("{stem}.png")), w, h, &f.beauty, exposure)?;
            let mut rec = FrameRecord::measure(index, total, light_deg, (w, h), &f.beauty, regions);
            rec.sweep = settings.clone();
            unmark_frame(dir, index)?;
            commit(exr)?;
            commit(png)?;
            write_record(dir, &rec)?;
            Ok(())
        })
}

/// What every frame of a sweep shares, for its EXR header: the moving light (its name and
/// kind, the arc's pivot and radius), spp, seed, integrator and the camera (as
/// [`RenderSettings::exr_meta`](crate::render::RenderSettings::exr_meta) words it).
pub(crate) fn frame_header(loaded: &LoadedScene, path: &SweepPath, moving: usize) -> String {
    let light = loaded
        .light_names
        .get(moving)
        .cloned()
        .flatten()
        .unwrap_or_else(|| format!("lights[{moving}]"));
    use crate::render::Light;
    let kind = match loaded.scene.lights.get(moving) {
        Some(Light::Point(_)) => "point",
        Some(Light::Spot(_)) => "spot",
        Some(Light::Distant(_)) => "distant",
        Some(Light::Rect(_)) => "rect",
        Some(Light::Sphere(_)) => "sphere",
        Some(Light::Environment(_)) => "environment",
        None => "?",
    };
    let p = path.pivot;
    let meta = loaded
        .settings
        .exr_meta(&loaded.name, &loaded.name, &loaded.scene.camera);
    let field = |k: &str| meta.iter().find(|m| m.0 == k).map_or("", |m| m.1.as_str());
    format!(
        "moving light {light} ({kind}) about pivot ({}, {}, {}) mm at radius {} mm; {} spp, seed {}, integrator {}; camera {}",
        p.x,
        p.y,
        p.z,
        path.radius,
        field("spp"),
        field("seed"),
        field("integrator"),
        field("camera")
    )
}

/// Runs a sweep job on a loaded scene. A whole sweep holds its output folder alone, clears what
/// an earlier sweep left there, claims the folder for its settings ([`super::claim`]) and
/// assembles at the end; a slice (`range` set) shares the folder with the other slices of the
/// folder's claim (refusing one of other settings before touching a file), writes only its own
/// frames and leaves assembling to `--assemble`. Either removes the manifest before its first
/// frame and writes it last, once every frame is there.
pub fn run_job(loaded: &LoadedScene, job: &SweepJob) -> Result<JobReport, SweepError> {
    let (path, moving) = SweepPath::from_scene(loaded, job.frames, job.arc)?;
    let total = path.frames();
    let range = match &job.range {
        Some(text) => parse_frames_range(text, total)?,
        None => 0..total,
    };
    let cam = &loaded.scene.camera;
    let size = SweepSize {
        width: cam.width,
        height: cam.height,
        spp: loaded.settings.spp,
        threads: job.run.threads,
        frames: range.len(),
    };
    let plan = batch_plan(job, &size)?;
    let batch = plan.batch.max(1);
    let _lock = lock_out(job)?;
    let manifest = Manifest::of_sweep(loaded, &path, moving);
    let settings = SweepSettings {
        scene: loaded.name.clone(),
        arc_deg: [path.arc.from_deg, path.arc.to_deg],
        spp: loaded.settings.spp,
        seed: loaded.settings.seed,
        provenance: job.provenance.clone(),
    };
    let claim = Claim {
        settings: settings.clone(),
        frames: total,
        camera: format!("{}x{}", cam.width, cam.height),
        manifest_crc32: format!("{:08x}", crc32fast::hash(manifest.text().as_bytes())),
    };
    prepare_out(job, &manifest, &claim)?;
    let regions = scene_regions(loaded);
    let header = frame_header(loaded, &path, moving);
    let (mut render_time, mut n_batches) = (Duration::ZERO, 0);
    let mut primaries = Primaries::default();
    hold_malloc_thresholds();
    // Each batch is written before the next is rendered, so only one batch is ever held.
    for frames in batches(range.clone(), batch) {
        let (scene, look, run) = (&loaded.scene, &loaded.settings, &job.run);
        let r = if job.naive {
            render_naive(scene, look, &path, moving, frames.clone(), run)?
        } else {
            let lights = path.light_frames(&scene.lights, moving, frames.clone());
            let kept = plan.keep.then_some(&mut primaries);
            render_frames_reusing(scene, &lights, look, run, kept)?
        };
        render_time += r.elapsed;
        n_batches += 1;
        write_frames(
            &job.out,
            &r,
            &path,
            frames,
            total,
            loaded.exposure,
            &regions,
            job.exr,
            &settings,
            &header,
        )?;
        release_freed_memory();
    }
    // The capture manifest for `xylem fit` (the same text from every slice), written last and
    // only once every frame of the sweep is in the folder: the slice that completes it writes
    // it (each slice looks after writing its own records, so the last to look sees them all).
    if job.range.is_none() || read_records(&job.out).is_ok() {
        let manifest_path = job.out.join(MANIFEST_FILE);
        (manifest.write(&job.out)).map_err(|cause| SweepError::OutDir {
            path: manifest_path.display().to_string(),
            cause,
        })?;
    }
    let assembled = if job.range.is_none() {
        Some(assemble(&job.out, &AssembleOptions::default())?)
    } else {
        None
    };
    Ok(JobReport {
        rendered: range,
        total,
        render_time,
        batch,
        batches: n_batches,
        kept_primaries: plan.keep,
        assembled,
    })
}

/// The job's batch plan: within `--memory` if given, else the default budget; primary samples
/// are never kept for a naive sweep. The output folder's disk and the plan's memory are
/// checked (unless the job ignores limits).
fn batch_plan(job: &SweepJob, size: &SweepSize) -> Result<Plan, SweepError> {
    let mut plan = match job.memory {
        Some(budget) => plan(size, budget, job.primaries)?,
        None => default_plan(size, job.primaries)?,
    };
    plan.keep &= !job.naive;
    let batch = plan.batch.max(1);
    let mut need = Resources::sweep(size.width, size.height, size.frames, batch, size.threads);
    need.memory = plan.memory(size);
    need.check(&job.out, job.ignore_limits)?;
    Ok(plan)
}

/// Creates the output folder and locks it: shared for a slice (`--frames-range`, other slices
/// may render beside it), exclusive for a whole sweep.
fn lock_out(job: &SweepJob) -> Result<FolderLock, SweepError> {
    std::fs::create_dir_all(&job.out).map_err(|cause| SweepError::OutDir {
        path: job.out.display().to_string(),
        cause,
    })?;
    let mode = if job.range.is_some() {
        LockMode::Shared
    } else {
        LockMode::Exclusive
    };
    Ok(FolderLock::try_new(&job.out, mode)?)
}

/// Makes the output folder ready for the job's frames: a slice must belong to the sweep
/// already there (its manifest and claim); a whole sweep clears old frames and claims the
/// folder. Either way what describes the finished sweep goes first.
fn prepare_out(job: &SweepJob, manifest: &Manifest, claim: &Claim) -> Result<(), SweepError> {
    if job.range.is_some() {
        check_same_sweep(&job.out, manifest)?;
        claim_for_slice(&job.out, claim)?;
    }
    // The manifest (what `xylem fit` takes as a complete capture) and the old viewer, CSV and
    // sheet describe frames about to change: they go before any frame, and come back only
    // once every frame is there.
    clear_assembled(&job.out)?;
    let manifest_path = job.out.join(MANIFEST_FILE);
    remove_if_present(&manifest_path).map_err(|cause| SweepError::OutDir {
        path: manifest_path.display().to_string(),
        cause,
    })?;
    if job.range.is_none() {
        clear_frames(&job.out)?;
        replace_claim(&job.out, claim)?;
    }
    Ok(())
}

/// Hands the pages a written batch freed back to the system. glibc keeps them in the arenas of
/// the threads that freed them, and a long sweep's peak crept ≈ 20 % above a short one's
/// (notes/cluster.md); trimming between batches keeps the peak that of one batch.
fn release_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim only returns free memory to the system; it touches no live allocation.
    unsafe {
        libc::malloc_trim(0);
    }
}

/// Holds glibc's thresholds for serving a block by `mmap` and for trimming the heap's top at
/// their initial 128 KiB. glibc raises both whenever an mmapped block is freed (to 32 MiB and
/// twice that), so from a sweep's second batch on the frames' buffers came from the heap and
/// its freed top stayed: a 128² sweep peaked 9 % higher at 480 frames than at 48, 1.5 % with
/// the thresholds held (`GLIBC_TUNABLES=glibc.malloc.trim_threshold=131072`; notes/cluster.md).
fn hold_malloc_thresholds() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only changes tuning parameters of the allocator.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 128 << 10);
        libc::mallopt(libc::M_TRIM_THRESHOLD, 128 << 10);
    }
}

/// Refuses a slice whose manifest differs from the one already in `dir` (a capture of other
/// settings, whose frames the slice would mix with its own); a folder without a manifest is
/// fine. Every slice of one sweep writes the same manifest text.
fn check_same_sweep(dir: &Path, ours: &Manifest) -> Result<(), SweepError> {
    let file = dir.join(MANIFEST_FILE);
    if std::fs::symlink_metadata(&file).is_err() {
        return Ok(());
    }
    let text = super::manifest::read_text(&file)?;
    let summary = |m: &Manifest| {
        let camera = format!("{}x{}", m.camera.width, m.camera.height);
        format!("{} frames, {camera} camera", m.frames.len())
    };
    let theirs = match serde_json::from_str::<Manifest>(&text) {
        Ok(m) if m.text() == ours.text() => return Ok(()),
        Ok(m) if summary(&m) == summary(ours) => {
            format!("{}, other lights or camera pose", summary(&m))
        }
        Ok(m) => summary(&m),
        Err(e) => format!("unreadable: {}", crate::jsonpath::describe(&text, &e)),
    };
    Err(SweepError::OtherSweep {
        path: file.display().to_string(),
        theirs,
        ours: summary(ours),
    })
}

/// Removes the frame files (`frame_NNNN.{json,png,exr}`) and the AOV file a previous sweep left
/// in `dir`, so a new complete sweep never mixes with them. The records go first: a frame whose
/// record is gone no longer looks complete.
fn clear_frames(dir: &Path) -> Result<(), SweepError> {
    let io = |cause| SweepError::OutDir {
        path: dir.display().to_string(),
        cause,
    };
    let mut stale = vec![dir.join(MANIFEST_FILE), dir.join(AOV_FILE)];
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
            stale.push(p);
        }
    }
    stale.sort_by_key(|p| p.extension().is_none_or(|e| e != "json"));
    for p in stale {
        remove_if_present(&p).map_err(io)?;
    }
    Ok(())
}
