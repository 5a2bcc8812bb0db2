//! What a render or a sweep will need — memory, disk — estimated before any large allocation or
//! write, and refused with a clear error above what the machine has (`crate::resources`).

use super::film::{Aov, PixelSum, RadianceSum};
use super::geometry::{Instance, TriMesh};
use crate::resources::{available_disk, available_memory, check_writable, Bytes, ResourceError};
use glam::Vec3;
use std::mem::size_of;
use std::path::Path;

/// Memory and disk a run needs (estimates from the sizes of the buffers it allocates).
#[derive(Clone, Debug, PartialEq)]
pub struct Resources {
    /// What the run is (a render, a sweep), for messages.
    pub what: String,
    /// Peak memory estimate (bytes).
    pub memory: u64,
    /// Disk estimate of the files written (bytes).
    pub disk: u64,
    /// What to lower to need less, for the message ("lower the resolution or the frame count").
    pub remedy: &'static str,
}

/// The remedy of an image's estimate: its size and, for a sweep, its length.
const LOWER_RESOLUTION: &str = "lower the resolution or the frame count";
/// The remedy of a geometry estimate: the triangles it builds.
pub(crate) const LOWER_TRIANGLES: &str =
    "use fewer triangles (a shape's `segments`, a lighter or decimated mesh)";

/// Peak bytes per stored triangle while its BVH is built: the triangle copies, obvhs's BVH2 and
/// PLOC buffers, the reinsertion pass and the wide BVH (444–459 B measured with VmHWM on 1 M and
/// 4 M triangles, notes/render.md), rounded up.
pub(crate) const BUILD_BYTES_PER_TRIANGLE: u64 = 480;

/// Channels of a render's EXR: beauty RGB, albedo RGB, normal XYZ, depth, fibre XYZ, ray mask,
/// growth time, standard error.
const RENDER_EXR_CHANNELS: u64 = 17;
/// Channels of a sweep frame's EXR (RGB and standard error).
const FRAME_EXR_CHANNELS: u64 = 4;

impl Resources {
    /// A still render of `width × height`: the film's sums, the finished image with its AOVs,
    /// and the EXR's channel copies; on disk an uncompressed EXR and PNG at most.
    pub fn render(width: u32, height: u32) -> Self {
        let px = width as u64 * height as u64;
        let image = (size_of::<Vec3>() + size_of::<f32>() + size_of::<Aov>()) as u64;
        Resources {
            what: format!("a {width}x{height} render"),
            memory: px * (size_of::<PixelSum>() as u64 + image + 2 * 4 * RENDER_EXR_CHANNELS),
            disk: px * (4 * RENDER_EXR_CHANNELS + 3),
            remedy: LOWER_RESOLUTION,
        }
    }

    /// `frames` frames of a `width × height` sweep rendered `batch` frames at a time: a batch's
    /// frames are held until written ([`Resources::sweep_frame_bytes`] each), plus the shared
    /// AOVs and the frames being written; the disk holds every frame.
    pub fn sweep(width: u32, height: u32, frames: usize, batch: usize, threads: usize) -> Self {
        let px = width as u64 * height as u64;
        let batch = batch.min(frames) as u64;
        Resources {
            what: format!("{frames} frames of a {width}x{height} sweep ({batch} at a time)"),
            memory: batch * Self::sweep_frame_bytes(width, height, threads)
                + Self::sweep_fixed_bytes(width, height, threads),
            disk: frames as u64 * px * (4 * FRAME_EXR_CHANNELS + 3) + px * 4 * 14,
            remedy: LOWER_RESOLUTION,
        }
    }

    /// Bytes one more frame of a sweep batch holds: its finished radiance and standard error
    /// twice (the tiles' results and the assembled image coexist at the end of
    /// `render_frames`), and its pixel sums in the tiles being rendered.
    pub fn sweep_frame_bytes(width: u32, height: u32, threads: usize) -> u64 {
        let px = width as u64 * height as u64;
        let image = (size_of::<Vec3>() + size_of::<f32>()) as u64;
        let tile = (super::TILE * super::TILE) as u64;
        2 * px * image + worker_threads(threads) * tile * size_of::<RadianceSum>() as u64
    }

    /// Bytes a sweep holds whatever its batch: the shared AOVs (tiles and image) and, per
    /// worker, a frame being written (RGBA and standard error copies, EXR and PNG encodings).
    pub fn sweep_fixed_bytes(width: u32, height: u32, threads: usize) -> u64 {
        let px = width as u64 * height as u64;
        let writing = 2 * 4 * FRAME_EXR_CHANNELS + 3 + 4;
        px * (2 * size_of::<Aov>() as u64 + worker_threads(threads) * writing)
    }

    /// Building the BVHs of `instances`: each distinct mesh (one `Arc`) is stored once however
    /// many objects place it (`Accel`'s instancing), so the estimate counts distinct meshes.
    pub fn geometry(instances: &[Instance]) -> Self {
        let mut seen = std::collections::HashSet::new();
        let distinct: Vec<&TriMesh> = (instances.iter())
            .filter(|i| seen.insert(std::sync::Arc::as_ptr(&i.mesh)))
            .map(|i| &*i.mesh)
            .collect();
        let triangles: u64 = distinct.iter().map(|m| m.indices.len() as u64).sum();
        Resources {
            what: format!(
                "the scene's geometry ({triangles} distinct triangles in {} meshes, {} objects)",
                distinct.len(),
                instances.len()
            ),
            memory: triangles * BUILD_BYTES_PER_TRIANGLE
                + (instances.len() * 2 * size_of::<Instance>()) as u64,
            disk: 0,
            remedy: LOWER_TRIANGLES,
        }
    }

    /// Refuses, for a run that writes files (`disk > 0`), an output folder `out` that cannot be
    /// written ([`check_writable`], even with `ignore`), then, unless `ignore`, an estimate above
    /// the available memory or the free space of the file system holding `out`; unknown amounts
    /// are not checked.
    pub fn check(&self, out: &Path, ignore: bool) -> Result<(), ResourceError> {
        if self.disk > 0 {
            check_writable(out)?;
        }
        if ignore {
            return Ok(());
        }
        let too_large = |kind, need, have| ResourceError::TooLarge {
            what: self.what.clone(),
            remedy: self.remedy,
            kind,
            need: Bytes(need),
            have: Bytes(have),
        };
        if let Some(have) = available_memory() {
            if self.memory > have {
                return Err(too_large("memory", self.memory, have));
            }
        }
        if let Some(have) = available_disk(out) {
            if self.disk > have {
                return Err(too_large("disk space", self.disk, have));
            }
        }
        Ok(())
    }
}

/// The worker threads `--threads` gives (0: one per core).
fn worker_threads(threads: usize) -> u64 {
    match threads {
        0 => std::thread::available_parallelism().map_or(1, |n| n.get()) as u64,
        n => n as u64,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::resources::check_threads;

    #[test]
    fn the_documented_maximum_resolution_is_refused_on_a_small_machine() {
        // 16384² pixels at ≥ 100 bytes each is ≥ 26 GiB, far beyond any of 8 GiB.
        let r = Resources::render(16384, 16384);
        assert!(r.memory > 26 << 30, "{}", Bytes(r.memory));
        // 100000 frames of 512×384 held at once (one batch) at ≥ 16 bytes of radiance each:
        // ≥ 290 GiB of memory; in batches of 48, the memory of 48 frames, but the same disk.
        let s = Resources::sweep(512, 384, 100_000, 100_000, 2);
        assert!(s.memory > 290 << 30 && s.disk > 290 << 30);
        let b = Resources::sweep(512, 384, 100_000, 48, 2);
        assert!(b.memory < 1 << 30 && b.disk == s.disk);
        assert!(check_threads(100_000).is_err());
        assert!(check_threads(0).is_ok() && check_threads(1).is_ok());
    }
}
