//! What the machine has and what an input may cost, checked before anything large is read,
//! allocated or written: memory and disk available, worker threads, writable output folders,
//! and input files read only when regular and under a size bound (a scene, mesh, image or
//! record; this bounds `/dev/zero` and the like). Below every module that reads files; the
//! estimates of what a render or sweep needs are `render::resources`.

use std::path::Path;

/// The most worker threads per core `--threads` may ask for (more only adds switching, and
/// 100000 threads exhaust the machine).
pub const MAX_THREADS_PER_CORE: usize = 16;
/// The largest scene file read (a scene is text; this bounds `/dev/zero` and the like).
pub const MAX_SCENE_BYTES: u64 = 16 << 20;
/// The largest mesh file read.
pub const MAX_MESH_BYTES: u64 = 4 << 30;

/// A limit a run would exceed, with the flag that overrides it where one does.
#[derive(Debug, thiserror::Error)]
pub enum ResourceError {
    /// An estimate above what the machine has.
    #[error("{what} needs about {need} of {kind} but {have} is available; {remedy}, or pass --ignore-limits to try anyway")]
    TooLarge {
        /// What needs it (a render, a sweep, a scene).
        what: String,
        /// What to lower to need less (the knob of the thing that needs it).
        remedy: &'static str,
        /// `"memory"` or `"disk space"`.
        kind: &'static str,
        /// The estimate.
        need: Bytes,
        /// What is available.
        have: Bytes,
    },
    /// A `--threads` value above the allowed maximum.
    #[error("--threads {threads}: out of range (allowed 0 = all cores, up to {max} = {MAX_THREADS_PER_CORE} per core)")]
    Threads {
        /// The value asked for.
        threads: usize,
        /// The largest allowed.
        max: usize,
    },
    /// The output folder (or, where it does not exist yet, the nearest folder above it) cannot
    /// be written: a read-only file system, no permission, not a folder.
    #[error("cannot write into the output folder {path}: {cause}; choose another with --out")]
    Unwritable {
        /// The output folder as given.
        path: String,
        /// Why (the operating system's error, and which existing folder was tried).
        cause: String,
    },
    /// An input file that is not a regular file or is too large to read.
    #[error("{path}: {message}")]
    Input {
        /// The file.
        path: String,
        /// What is wrong with it.
        message: String,
    },
}

/// A byte count printed in binary units.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct Bytes(pub u64);

impl std::fmt::Display for Bytes {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let gib = self.0 as f64 / (1u64 << 30) as f64;
        if gib >= 1.0 {
            write!(f, "{gib:.1} GiB")
        } else {
            write!(f, "{:.1} MiB", self.0 as f64 / (1u64 << 20) as f64)
        }
    }
}

/// Checks `--threads` (0 means all cores).
pub fn check_threads(threads: usize) -> Result<(), ResourceError> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let max = cores * MAX_THREADS_PER_CORE;
    if threads > max {
        return Err(ResourceError::Threads { threads, max });
    }
    Ok(())
}

/// Refuses an output folder that cannot be written, before anything is rendered: `out` itself
/// where it exists, else the nearest existing folder above it (where `out` would be made), is
/// probed by creating and removing a temporary file in it. (Before, a read-only file system
/// such as /proc reported "needs … but 0.0 MiB is available".)
pub fn check_writable(out: &Path) -> Result<(), ResourceError> {
    let unwritable = |cause: String| ResourceError::Unwritable {
        path: out.display().to_string(),
        cause,
    };
    let abs = std::path::absolute(out).map_err(|e| unwritable(e.to_string()))?;
    let Some(existing) = abs.ancestors().find(|p| p.exists()) else {
        return Err(unwritable("no part of the path exists".into()));
    };
    let tried = if existing == abs {
        String::new()
    } else {
        format!(
            " (it does not exist yet; tried {}, where it would be made)",
            existing.display()
        )
    };
    if !existing.is_dir() {
        return Err(unwritable(format!(
            "{} is not a folder{tried}",
            existing.display()
        )));
    }
    tempfile::Builder::new()
        .prefix(".xylem-write-probe")
        .tempfile_in(existing)
        .map(drop)
        .map_err(|e| unwritable(format!("{e}{tried}")))
}

/// Memory available to this process: `MemAvailable` of /proc/meminfo, lowered to the cgroup's
/// remaining allowance (`memory.max − memory.current`) where one is set, and (on Unix) to the
/// address space left under `ulimit -v` (`RLIMIT_AS − VmSize`) where one is set. None where
/// unknown: on systems without /proc/meminfo (macOS, Windows) the memory is not checked.
pub fn available_memory() -> Option<u64> {
    let have = available_system_memory()?;
    Some(have.min(address_space_left().unwrap_or(u64::MAX)))
}

/// The address space left under `ulimit -v` (`RLIMIT_AS − VmSize`); None where there is no
/// limit or no such notion.
#[cfg(unix)]
fn address_space_left() -> Option<u64> {
    let mut lim = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: `lim` is a writable rlimit.
    if unsafe { libc::getrlimit(libc::RLIMIT_AS, &mut lim) } != 0
        || lim.rlim_cur == libc::RLIM_INFINITY
    {
        return None;
    }
    let status = std::fs::read_to_string("/proc/self/status").ok();
    let vm_kib: u64 = (status.as_deref())
        .and_then(|s| s.lines().find_map(|l| l.strip_prefix("VmSize:")))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        .unwrap_or(0);
    Some(lim.rlim_cur.saturating_sub(vm_kib * 1024))
}

#[cfg(not(unix))]
fn address_space_left() -> Option<u64> {
    None
}

/// [`available_memory`] before the address-space limit.
fn available_system_memory() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    let kib: u64 = meminfo
        .lines()
        .find_map(|l| l.strip_prefix("MemAvailable:"))?
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    let mut have = kib * 1024;
    let read = |p: &str| -> Option<u64> { std::fs::read_to_string(p).ok()?.trim().parse().ok() };
    if let (Some(max), Some(cur)) = (
        read("/sys/fs/cgroup/memory.max"),
        read("/sys/fs/cgroup/memory.current"),
    ) {
        have = have.min(max.saturating_sub(cur));
    }
    Some(have)
}

/// Free space (for unprivileged users) on the file system that holds `dir` or, when it does not
/// exist yet, its nearest existing ancestor (the `fs4` crate: statvfs on Unix,
/// GetDiskFreeSpaceExW on Windows). None where unknown.
pub(crate) fn available_disk(dir: &Path) -> Option<u64> {
    let abs = std::path::absolute(dir).ok()?;
    let existing = abs.ancestors().find(|p| p.exists())?;
    fs4::available_space(existing).ok()
}

/// Opens an input file, refusing what is not a regular file (a FIFO, a device such as
/// /dev/zero, a socket, a folder) or is larger than `max` bytes. The file is opened
/// non-blocking, so a FIFO without a writer is refused at once instead of waiting, and its type
/// and size are checked on the opened handle, so nothing can be swapped in between.
pub fn open_regular(path: &Path, max: u64) -> Result<std::fs::File, ResourceError> {
    let input = |message: String| ResourceError::Input {
        path: path.display().to_string(),
        message,
    };
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    std::os::unix::fs::OpenOptionsExt::custom_flags(&mut options, libc::O_NONBLOCK);
    let file = options.open(path).map_err(|e| input(e.to_string()))?;
    let meta = file.metadata().map_err(|e| input(e.to_string()))?;
    let t = meta.file_type();
    let kind = if t.is_file() {
        None
    } else if t.is_dir() {
        Some("a folder")
    } else {
        Some(special_kind(&t))
    };
    if let Some(kind) = kind {
        return Err(input(format!(
            "{kind}, not a regular file (allowed: a regular file)"
        )));
    }
    if meta.len() > max {
        return Err(input(format!(
            "{} is larger than the {} allowed",
            Bytes(meta.len()),
            Bytes(max)
        )));
    }
    Ok(file)
}

/// What a file that is neither a regular file nor a folder is.
#[cfg(unix)]
fn special_kind(t: &std::fs::FileType) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    if t.is_fifo() {
        "a FIFO"
    } else if t.is_char_device() || t.is_block_device() {
        "a device"
    } else if t.is_socket() {
        "a socket"
    } else {
        "a special file"
    }
}

#[cfg(not(unix))]
fn special_kind(_: &std::fs::FileType) -> &'static str {
    "a special file"
}

/// Reads an input file whole through [`open_regular`] (regular files of at most `max` bytes).
pub fn read_bounded(path: &Path, max: u64) -> Result<Vec<u8>, ResourceError> {
    use std::io::Read;
    let mut bytes = Vec::new();
    // `take` also bounds a file that grows after the check.
    open_regular(path, max)?
        .take(max)
        .read_to_end(&mut bytes)
        .map_err(|e| ResourceError::Input {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
    Ok(bytes)
}

/// [`read_bounded`] as UTF-8 text; `what` names the content in the error (e.g. "JSON").
pub fn read_text_bounded(path: &Path, max: u64, what: &str) -> Result<String, ResourceError> {
    String::from_utf8(read_bounded(path, max)?).map_err(|_| ResourceError::Input {
        path: path.display().to_string(),
        message: format!("not UTF-8 text (allowed: {what})"),
    })
}

/// The largest side of an image read (pixels): twice `--res`'s 16384.
pub(crate) const MAX_IMAGE_SIDE: u64 = 32768;
/// The most pixels an image read may declare: 2²⁸ = 16384², the largest render.
pub(crate) const MAX_IMAGE_PIXELS: u64 = 1 << 28;
/// The largest image file read (EXR or PNG): a 16384² render's uncompressed 17-channel float
/// EXR is 17 GiB.
pub(crate) const MAX_IMAGE_BYTES: u64 = 20 << 30;

/// A check of an image's declared size (width, height) made on its header alone, before a pixel
/// is decoded or its buffer allocated: a fit's frame must be the manifest's camera size, a
/// measured map the diffuse map's, a sweep frame its record's. `Err` says why, naming the
/// declared size; the caller names the file.
pub(crate) type SizeCheck<'a> = &'a dyn Fn(u32, u32) -> Result<(), String>;

/// A [`SizeCheck`] that takes any size ([`check_image`] still bounds it).
pub(crate) fn any_size(_: u32, _: u32) -> Result<(), String> {
    Ok(())
}

/// Checks an image's declared size before it is decoded: each side 1 to [`MAX_IMAGE_SIDE`],
/// at most [`MAX_IMAGE_PIXELS`] pixels, and `bytes_per_pixel` × pixels (what the decoder and
/// the caller allocate for it) within the available memory.
pub(crate) fn check_image(
    path: &Path,
    width: u64,
    height: u64,
    bytes_per_pixel: u64,
) -> Result<(), ResourceError> {
    let input = |message: String| ResourceError::Input {
        path: path.display().to_string(),
        message,
    };
    let pixels = width.saturating_mul(height);
    if !(1..=MAX_IMAGE_SIDE).contains(&width)
        || !(1..=MAX_IMAGE_SIDE).contains(&height)
        || pixels > MAX_IMAGE_PIXELS
    {
        return Err(input(format!(
            "declares {width}x{height} pixels (allowed: each side 1 to {MAX_IMAGE_SIDE}, at most {MAX_IMAGE_PIXELS} pixels = 16384²)"
        )));
    }
    let need = pixels.saturating_mul(bytes_per_pixel);
    match available_memory() {
        Some(have) if need > have => Err(input(format!(
            "a {width}x{height} image needs about {} of memory to decode but {} is available",
            Bytes(need),
            Bytes(have)
        ))),
        _ => Ok(()),
    }
}

impl ResourceError {
    /// The message without the file name (for errors that name the file themselves).
    pub fn reason(&self) -> String {
        match self {
            ResourceError::Input { message, .. } => message.clone(),
            other => other.to_string(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn devices_and_oversized_files_are_refused_before_reading() {
        let e = read_bounded(Path::new("/dev/zero"), 1 << 20).unwrap_err();
        assert!(
            e.to_string().contains("a device, not a regular file"),
            "{e}"
        );
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("big.toml");
        std::fs::write(&p, vec![b' '; 2048]).unwrap();
        assert!(read_bounded(&p, 1024).is_err());
        assert_eq!(read_bounded(&p, 4096).unwrap().len(), 2048);
    }
}
