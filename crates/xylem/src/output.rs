//! Output files written whole or not at all, and the folder lock that keeps runs apart.
//!
//! Every file xylem writes is first written to a uniquely named temporary file in its final
//! folder ([`Staged`], through the `tempfile` crate) and then renamed over the final name, which
//! is atomic on one file system: a reader sees the old file or the new one, never a mix, and two
//! runs writing the same name never share a temporary. A run that writes a group of files that
//! belong together (a render's EXR and PNG, a sweep's frames) holds a [`FolderLock`] while it
//! commits them, so the group always comes from one run. A set of outputs that a reader must
//! take whole (fit's maps, bake's maps) is committed by [`commit_set`]: its record, written
//! last, lists every member with its size and CRC-32, and a kill mid-commit leaves no record
//! and no member of the previous set ([`verify_set`] checks a folder).
//!
//! Temporaries carry this host's name and the process id ([`Staged::new`]); the first file a
//! process stages in a folder removes the temporaries there of dead processes of this host
//! (runs killed before they could clean up), never those of live runs or other hosts, and the
//! older builds' `.NAME.XXXXXX.tmp` that no process has open and nothing has written for ten
//! minutes.

use std::collections::BTreeSet;
use std::fs::File;
use std::io;
use std::io::{Read, Seek};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use tempfile::NamedTempFile;

/// A file being written under a temporary name beside `path`; [`Staged::commit`] renames it
/// over `path`, dropping it without commit deletes it.
pub struct Staged {
    tmp: NamedTempFile,
    path: PathBuf,
    _live: Live,
}

/// The temporary files of this process not yet committed or dropped, for
/// [`remove_temporaries_on_signal`].
static LIVE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn live() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    LIVE.lock().unwrap_or_else(|e| e.into_inner())
}

/// A temporary's entry in [`LIVE`], removed when the [`Staged`] file is committed or dropped.
struct Live(PathBuf);

impl Drop for Live {
    fn drop(&mut self) {
        let mut live = live();
        if let Some(i) = live.iter().rposition(|p| *p == self.0) {
            live.swap_remove(i);
        }
    }
}

/// Makes SIGINT and SIGTERM remove this process's temporaries ([`Staged`] files not yet
/// committed) before the process ends as the signal's default action would end it (so the exit
/// status still tells the signal). The handler only writes the signal's number to a pipe; a
/// thread waiting on the pipe removes the files, holding the registry's lock so that no new
/// temporary appears meanwhile, and re-raises the signal. For the `xylem` binary: a library
/// embedder (Python) keeps its own signal handling. Unix only: elsewhere a killed run's
/// temporaries stay (they carry the `.xylem-tmp.` mark and are never taken for outputs).
#[cfg(not(unix))]
pub fn remove_temporaries_on_signal() {}

/// See the non-Unix stand-in above for what this does.
#[cfg(unix)]
pub fn remove_temporaries_on_signal() {
    use std::sync::atomic::{AtomicI32, Ordering};
    static PIPE: AtomicI32 = AtomicI32::new(-1);
    extern "C" fn on_signal(sig: libc::c_int) {
        let b = sig as u8;
        // SAFETY: write(2) is async-signal-safe; the pipe outlives the process.
        unsafe { libc::write(PIPE.load(Ordering::Relaxed), (&b as *const u8).cast(), 1) };
    }
    let mut fds = [0; 2];
    // SAFETY: `fds` has room for the two descriptors.
    if unsafe { libc::pipe2(fds.as_mut_ptr(), libc::O_CLOEXEC) } != 0 {
        return;
    }
    PIPE.store(fds[1], Ordering::Relaxed);
    std::thread::spawn(move || {
        let mut b = 0u8;
        loop {
            // SAFETY: reads one byte into `b`.
            match unsafe { libc::read(fds[0], (&mut b as *mut u8).cast(), 1) } {
                1 => break,
                -1 if io::Error::last_os_error().kind() == io::ErrorKind::Interrupted => {}
                _ => return,
            }
        }
        let live = live();
        for p in live.iter() {
            let _ = std::fs::remove_file(p);
        }
        // SAFETY: restores the default action and ends the process with the signal.
        unsafe {
            libc::signal(b as libc::c_int, libc::SIG_DFL);
            libc::raise(b as libc::c_int);
        }
        drop(live);
    });
    for sig in [libc::SIGINT, libc::SIGTERM] {
        // SAFETY: `on_signal` only calls write(2); an ignored signal (a background job's SIGINT,
        // nohup) stays ignored.
        unsafe {
            if libc::signal(sig, on_signal as *const () as libc::sighandler_t) == libc::SIG_IGN {
                libc::signal(sig, libc::SIG_IGN);
            }
        }
    }
}

impl Staged {
    /// Creates the temporary file in `path`'s folder (so the rename stays on one file system).
    pub fn new(path: &Path) -> io::Result<Self> {
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        remove_stale_temporaries(dir);
        let stem = path.file_name().map(|n| n.to_string_lossy().into_owned());
        let prefix = format!(
            ".{}{TMP_MARK}{}-{}-",
            stem.unwrap_or_default(),
            host(),
            std::process::id()
        );
        let mut builder = tempfile::Builder::new();
        builder.prefix(&prefix).suffix(".tmp");
        // A temporary file is created owner-only (0600); an output is a plain file, so it gets
        // what `File::create` would give it: 0666 less the umask.
        #[cfg(unix)]
        builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
        // Created and registered under the registry's lock, so a signal's clean-up sees it.
        let mut registry = live();
        let tmp = builder.tempfile_in(dir)?;
        registry.push(tmp.path().to_path_buf());
        drop(registry);
        Ok(Staged {
            _live: Live(tmp.path().to_path_buf()),
            tmp,
            path: path.to_path_buf(),
        })
    }

    /// The temporary file, to write into.
    pub fn file(&mut self) -> &mut File {
        self.tmp.as_file_mut()
    }

    /// The final name.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The size and CRC-32 of what was written (read back from the temporary file).
    pub fn checksum(&mut self) -> io::Result<(u64, u32)> {
        let f = self.tmp.as_file_mut();
        f.rewind()?;
        checksum(f)
    }

    /// Renames the temporary file over the final name. (No `fsync`: this guards against killed
    /// and concurrent runs, which the page cache survives, not against power loss.)
    pub fn commit(self) -> io::Result<()> {
        self.tmp.persist(&self.path).map_err(|e| e.error)?;
        Ok(())
    }

    /// Renames the temporary file to the final name only where no file has that name yet
    /// (atomically: of two runs committing at once exactly one succeeds); otherwise an
    /// [`io::ErrorKind::AlreadyExists`] error, and the temporary is removed.
    pub(crate) fn commit_new(self) -> io::Result<()> {
        self.tmp
            .persist_noclobber(&self.path)
            .map_err(|e| e.error)?;
        Ok(())
    }
}

/// Writes `bytes` into a [`Staged`] file for `path`, to commit later.
pub fn stage_bytes(path: &Path, bytes: &[u8]) -> io::Result<Staged> {
    let mut staged = Staged::new(path)?;
    io::Write::write_all(staged.file(), bytes)?;
    Ok(staged)
}

/// Writes `bytes` to `path` through a [`Staged`] file.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    stage_bytes(path, bytes)?.commit()
}

/// The length and CRC-32 of everything `r` yields.
fn checksum(mut r: impl Read) -> io::Result<(u64, u32)> {
    let mut h = crc32fast::Hasher::new();
    let mut buf = vec![0; 1 << 16];
    let mut len = 0u64;
    loop {
        let n = r.read(&mut buf)?;
        if n == 0 {
            return Ok((len, h.finalize()));
        }
        h.update(&buf[..n]);
        len += n as u64;
    }
}

/// What marks xylem's temporary names: `.NAME.xylem-tmp.HOST-PID-RANDOM.tmp`.
const TMP_MARK: &str = ".xylem-tmp.";

/// This host's name (`gethostname`; `COMPUTERNAME` on Windows), or `host` where unknown.
fn host() -> String {
    #[cfg(unix)]
    let (ok, raw) = {
        let mut buf = [0u8; 256];
        // SAFETY: `buf` is writable for its length; the name is NUL-terminated when it fits.
        let ok = unsafe { libc::gethostname(buf.as_mut_ptr().cast(), buf.len()) } == 0;
        let end = buf.iter().position(|&b| b == 0).unwrap_or(0);
        (ok, String::from_utf8_lossy(&buf[..end]).into_owned())
    };
    #[cfg(not(unix))]
    let (ok, raw) = match std::env::var("COMPUTERNAME") {
        Ok(n) => (true, n),
        Err(_) => (false, String::new()),
    };
    let name = raw.replace(['/', '-'], "_");
    if ok && !name.is_empty() {
        name
    } else {
        "host".into()
    }
}

/// Whether process `pid` of this host is alive; without `kill(pid, 0)` (not Unix) every process
/// counts as alive, so no temporary is ever taken from a live run.
#[cfg(not(unix))]
fn alive(_pid: i32) -> bool {
    true
}

/// Whether process `pid` of this host is alive (`kill(pid, 0)`: no such process means dead).
#[cfg(unix)]
fn alive(pid: i32) -> bool {
    // SAFETY: signal 0 only checks for the process.
    let r = unsafe { libc::kill(pid, 0) };
    r == 0 || io::Error::last_os_error().raw_os_error() != Some(libc::ESRCH)
}

/// Removes from `dir` the temporaries of dead processes of this host (runs killed before they
/// could delete them), once per folder and process; live runs' temporaries and other hosts'
/// (a farm sharing the folder) stay. Failures are ignored: this is tidying, not output.
pub(crate) fn remove_stale_temporaries(dir: &Path) {
    static DONE: Mutex<BTreeSet<PathBuf>> = Mutex::new(BTreeSet::new());
    let key = std::path::absolute(dir).unwrap_or_else(|_| dir.to_path_buf());
    if !DONE.lock().map(|mut d| d.insert(key)).unwrap_or(false) {
        return;
    }
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let me = host();
    let mut old = Vec::new();
    for e in entries.flatten() {
        let name = e.file_name();
        let Some(name) = name.to_str() else { continue };
        let Some(tail) = name.rsplit_once(TMP_MARK).map(|(_, t)| t) else {
            if is_old_temporary(name) {
                old.push(e.path());
            }
            continue;
        };
        // HOST-PID-RANDOM.tmp
        let mut parts = tail.rsplitn(3, '-');
        let (Some(_random), Some(pid), Some(h)) = (parts.next(), parts.next(), parts.next()) else {
            continue;
        };
        let dead = pid.parse::<i32>().is_ok_and(|p| p > 0 && !alive(p));
        if h == me && dead && name.ends_with(".tmp") {
            let _ = std::fs::remove_file(e.path());
        }
    }
    remove_dead_old_temporaries(old);
}

/// Whether `name` is a temporary of a build before host and pid were in the name (up to
/// f97e541): `.NAME.XXXXXX.tmp`, `XXXXXX` six letters or digits (the `tempfile` crate's), NAME
/// an output of one of the kinds xylem writes.
fn is_old_temporary(name: &str) -> bool {
    let Some(inner) = name.strip_prefix('.').and_then(|n| n.strip_suffix(".tmp")) else {
        return false;
    };
    let Some((output, random)) = inner.rsplit_once('.') else {
        return false;
    };
    let kind = output.rsplit_once('.').map_or("", |(_, ext)| ext);
    random.len() == 6
        && random.bytes().all(|b| b.is_ascii_alphanumeric())
        && OUTPUT_KINDS.contains(&kind)
}

/// The extensions of the files xylem writes (so no other program's `.x.abcdef.tmp` is taken
/// for an old temporary).
const OUTPUT_KINDS: [&str; 8] = ["exr", "png", "json", "csv", "html", "glb", "md", "txt"];

/// How long an old-format temporary must have gone unwritten before it is taken for a dead
/// run's: its name tells neither host nor process, and a run on another host sharing the folder
/// (which no process table here shows) writes its temporary and renames it within moments.
const OLD_TEMPORARY_AGE: std::time::Duration = std::time::Duration::from_secs(600);

/// Removes the old-format temporaries `paths` that no process of this host has open (a live
/// old run holds its temporary open until it renames it) and that have gone unwritten for
/// [`OLD_TEMPORARY_AGE`]. Where the open files cannot be listed (no /proc) none is removed.
fn remove_dead_old_temporaries(paths: Vec<PathBuf>) {
    let stale: Vec<PathBuf> = paths
        .into_iter()
        .filter(|p| {
            let age = std::fs::metadata(p)
                .and_then(|m| m.modified())
                .ok()
                .and_then(|t| t.elapsed().ok());
            age.is_some_and(|a| a >= OLD_TEMPORARY_AGE)
        })
        .collect();
    if stale.is_empty() {
        return;
    }
    let Some(open) = open_files() else { return };
    for p in stale {
        if std::fs::metadata(&p).is_ok_and(|m| !open.contains(&file_id(&m))) {
            let _ = std::fs::remove_file(&p);
        }
    }
}

/// A file's identity (device and inode).
#[cfg(unix)]
fn file_id(m: &std::fs::Metadata) -> (u64, u64) {
    use std::os::unix::fs::MetadataExt;
    (m.dev(), m.ino())
}

#[cfg(not(unix))]
fn file_id(_: &std::fs::Metadata) -> (u64, u64) {
    (0, 0)
}

/// The files that processes of this host have open, as far as /proc shows them (every process
/// of this user; others' where readable); None without /proc.
#[cfg(target_os = "linux")]
fn open_files() -> Option<BTreeSet<(u64, u64)>> {
    let mut open = BTreeSet::new();
    for proc in std::fs::read_dir("/proc").ok()?.flatten() {
        let Ok(fds) = std::fs::read_dir(proc.path().join("fd")) else {
            continue;
        };
        for fd in fds.flatten() {
            if let Ok(m) = std::fs::metadata(fd.path()) {
                open.insert(file_id(&m));
            }
        }
    }
    Some(open)
}

#[cfg(not(target_os = "linux"))]
fn open_files() -> Option<BTreeSet<(u64, u64)>> {
    None
}

/// A set file's record: the members with their sizes and CRC-32s, beside what the caller adds.
const SET_FILES: &str = "files";

/// Commits `members` (staged in `dir`) as one set completed by `record` (a JSON object file in
/// `dir`, written last): first the old record goes, then every member of the old set it names
/// (where still as it lists it) and every old file under a new member's name, then the new members are renamed into place,
/// and last the record is written — `extra` with a `files` list of every member's name, size
/// and CRC-32. A kill at any point leaves either the old complete set, or members of the new
/// set alone without a record; never members of two runs side by side. The caller holds the
/// folder's lock.
pub fn commit_set(
    dir: &Path,
    mut members: Vec<Staged>,
    record: &str,
    mut extra: serde_json::Map<String, serde_json::Value>,
) -> io::Result<PathBuf> {
    let record_path = dir.join(record);
    let mut files = Vec::new();
    for m in &mut members {
        let (bytes, crc) = m.checksum()?;
        let name = m.path.file_name().unwrap_or_default().to_string_lossy();
        files
            .push(serde_json::json!({"name": name, "bytes": bytes, "crc32": format!("{crc:08x}")}));
    }
    extra.insert(SET_FILES.into(), files.into());
    let text = serde_json::to_string_pretty(&extra).map_err(io::Error::other)?;
    let record_file = stage_bytes(&record_path, text.as_bytes())?;
    let old = set_members(dir, &record_path);
    remove_if_present(&record_path)?;
    for name in old {
        remove_if_present(&dir.join(name))?;
    }
    for m in &members {
        remove_if_present(&m.path)?;
    }
    for m in members {
        m.commit()?;
    }
    record_file.commit()?;
    Ok(record_path)
}

/// Why a folder does not hold the complete set its record describes ([`verify_set`]).
#[derive(Debug, thiserror::Error)]
pub enum SetError {
    /// The record is missing, unreadable, not JSON or without a `files` list.
    #[error("{0}")]
    Record(String),
    /// A member the record names is not a plain file name in the folder, or cannot be read.
    #[error("{0}")]
    Member(String),
    /// A member is not the file the record lists (another run's, or changed since).
    #[error("{}: not the file {} lists (another run's)", file.display(), record.display())]
    Mismatch {
        /// The member.
        file: std::path::PathBuf,
        /// The record.
        record: std::path::PathBuf,
    },
}

/// The `files` list of the set record at `path`.
fn record_files(path: &Path) -> Result<Vec<serde_json::Value>, SetError> {
    let text =
        crate::resources::read_text_bounded(path, MAX_RECORD_BYTES, "JSON").map_err(|e| {
            SetError::Record(format!(
                "{e} (an incomplete set: its record is written last)"
            ))
        })?;
    let v: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| SetError::Record(format!("{}: {e}", path.display())))?;
    match v.get(SET_FILES) {
        Some(serde_json::Value::Array(files)) => Ok(files.clone()),
        _ => Err(SetError::Record(format!(
            "{}: no `{SET_FILES}` list",
            path.display()
        ))),
    }
}

/// A record entry's member in `dir`: its name, and whether the file has the size and CRC-32
/// the entry lists. Only a plain name is accepted (a record cannot point outside its folder).
fn member_status(dir: &Path, entry: &serde_json::Value) -> Result<(String, bool), SetError> {
    let name = entry.get("name").and_then(|n| n.as_str()).unwrap_or("");
    if name.is_empty() || name.contains('/') || name == "." || name == ".." {
        return Err(SetError::Member(format!(
            "{}: member `{name}` (allowed: a file name in the folder)",
            dir.display()
        )));
    }
    let member = dir.join(name);
    let file = crate::resources::open_regular(&member, u64::MAX)
        .map_err(|e| SetError::Member(e.to_string()))?;
    let (len, crc) =
        checksum(file).map_err(|e| SetError::Member(format!("{}: {e}", member.display())))?;
    let crc = format!("{crc:08x}");
    let want = (
        entry.get("bytes").and_then(|b| b.as_u64()),
        entry.get("crc32").and_then(|c| c.as_str()),
    );
    Ok((name.to_string(), want == (Some(len), Some(crc.as_str()))))
}

/// The members of the set recorded at `record` that are still as it lists them (so a record
/// never makes [`commit_set`] remove a file it did not write); none where it is unreadable.
fn set_members(dir: &Path, record: &Path) -> Vec<String> {
    let files = record_files(record).unwrap_or_default();
    let status = files.iter().filter_map(|f| member_status(dir, f).ok());
    status.filter(|(_, same)| *same).map(|(n, _)| n).collect()
}

/// The largest set record read (a record lists a few files; this bounds `/dev/zero`).
const MAX_RECORD_BYTES: u64 = 1 << 20;

/// Checks that `dir` holds the complete set `record` describes: the record exists and every
/// member has the size and CRC-32 it lists. The error names the record or the member at fault.
pub fn verify_set(dir: &Path, record: &str) -> Result<(), SetError> {
    let path = dir.join(record);
    for f in record_files(&path)? {
        let (name, same) = member_status(dir, &f)?;
        if !same {
            return Err(SetError::Mismatch {
                file: dir.join(name),
                record: path,
            });
        }
    }
    Ok(())
}

/// Checks the file `name` in `dir` against the set record `record` there: `Ok(true)` where the
/// record lists it with its size and CRC-32, `Ok(false)` where the record does not list it,
/// and an error naming both where the record is unreadable or lists another file (another
/// run's, or one changed since).
pub(crate) fn check_member(dir: &Path, record: &str, name: &str) -> Result<bool, String> {
    let path = dir.join(record);
    let files = record_files(&path).map_err(|e| e.to_string())?;
    let Some(entry) = files
        .iter()
        .find(|f| f.get("name").and_then(|n| n.as_str()) == Some(name))
    else {
        return Ok(false);
    };
    let (_, same) = member_status(dir, entry).map_err(|e| e.to_string())?;
    if same {
        Ok(true)
    } else {
        Err(format!(
            "not the file {} lists (another run's, or changed since)",
            path.display()
        ))
    }
}

/// Removes `path` if it exists (a stale output that must not outlive the run replacing it).
pub fn remove_if_present(path: &Path) -> io::Result<()> {
    match std::fs::remove_file(path) {
        Err(e) if e.kind() != io::ErrorKind::NotFound => Err(e),
        _ => Ok(()),
    }
}

/// An advisory lock (`flock`) on an output folder, released when dropped (or when the process
/// dies, so a killed run never leaves the folder locked).
pub struct FolderLock {
    _dir: File,
}

/// Why a folder lock was not taken.
#[derive(Debug, thiserror::Error)]
pub enum LockError {
    /// Another run holds the lock.
    #[error("output folder {path} is in use by another xylem run ({what}); wait for it to finish or choose another --out")]
    Busy {
        /// The folder.
        path: String,
        /// What kind of run holds it (as far as the requested mode tells).
        what: &'static str,
    },
    /// The folder could not be opened or locked.
    #[error("cannot lock output folder {path}: {source}")]
    Io {
        /// The folder.
        path: String,
        /// The I/O error.
        source: io::Error,
    },
}

/// How a run uses an output folder.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LockMode {
    /// Many at once (slices of one farmed sweep).
    Shared,
    /// Alone (a whole sweep, an assembly, a render committing its files).
    Exclusive,
}

impl FolderLock {
    /// Takes the lock, failing at once with [`LockError::Busy`] when another run holds it.
    pub fn try_new(dir: &Path, mode: LockMode) -> Result<Self, LockError> {
        let path = dir.display().to_string();
        let file = File::open(dir).map_err(|source| LockError::Io {
            path: path.clone(),
            source,
        })?;
        let taken = match mode {
            LockMode::Shared => file.try_lock_shared(),
            LockMode::Exclusive => file.try_lock(),
        };
        match taken {
            Ok(()) => Ok(FolderLock { _dir: file }),
            Err(std::fs::TryLockError::WouldBlock) => Err(LockError::Busy {
                path,
                what: match mode {
                    LockMode::Shared => "a whole sweep or an assembly",
                    LockMode::Exclusive => "a sweep, a slice or an assembly",
                },
            }),
            Err(std::fs::TryLockError::Error(source)) => Err(LockError::Io { path, source }),
        }
    }

    /// Takes the exclusive lock, waiting for other runs to release it.
    pub fn wait_exclusive(dir: &Path) -> Result<Self, LockError> {
        let io = |source| LockError::Io {
            path: dir.display().to_string(),
            source,
        };
        let file = File::open(dir).map_err(io)?;
        file.lock().map_err(io)?;
        Ok(FolderLock { _dir: file })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn staged_files_appear_whole_and_only_on_commit() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.txt");
        std::fs::write(&p, "old").unwrap();
        let mut s = Staged::new(&p).unwrap();
        io::Write::write_all(s.file(), b"new").unwrap();
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "old");
        s.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "new");
        // Dropped without commit: the final name is untouched and no temporary is left.
        let mut s = Staged::new(&p).unwrap();
        io::Write::write_all(s.file(), b"lost").unwrap();
        drop(s);
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "new");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    /// An output's mode is a plain created file's (0666 less the umask), not a temporary's 0600.
    #[cfg(unix)]
    #[test]
    fn committed_files_have_the_permissions_of_a_created_file() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let (plain, staged) = (dir.path().join("plain"), dir.path().join("staged"));
        std::fs::write(&plain, "x").unwrap();
        write_atomic(&staged, b"x").unwrap();
        let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode(&staged), mode(&plain));
    }

    #[test]
    fn exclusive_lock_excludes_every_other_lock_and_shared_locks_coexist() {
        let dir = tempfile::tempdir().unwrap();
        let a = FolderLock::try_new(dir.path(), LockMode::Shared).unwrap();
        let b = FolderLock::try_new(dir.path(), LockMode::Shared).unwrap();
        assert!(matches!(
            FolderLock::try_new(dir.path(), LockMode::Exclusive),
            Err(LockError::Busy { .. })
        ));
        drop((a, b));
        let x = FolderLock::try_new(dir.path(), LockMode::Exclusive).unwrap();
        assert!(matches!(
            FolderLock::try_new(dir.path(), LockMode::Shared),
            Err(LockError::Busy { .. })
        ));
        drop(x);
        assert!(FolderLock::try_new(dir.path(), LockMode::Shared).is_ok());
    }
}
