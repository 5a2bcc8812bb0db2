//! Output files written whole or not at all, and the folder lock that keeps runs apart.
//!
//! Every file xylem writes is first written to a uniquely named temporary file in its final
//! folder ([`Staged`], through the `tempfile` crate) and then renamed over the final name, which
//! is atomic on one file system: a reader sees the old file or the new one, never a mix, and two
//! runs writing the same name never share a temporary. A run that writes a group of files that
//! belong together (a render's EXR and PNG, a sweep's frames) holds a [`FolderLock`] while it
//! commits them, so the group always comes from one run.

use std::fs::File;
use std::io;
use std::path::{Path, PathBuf};
use tempfile::NamedTempFile;

/// A file being written under a temporary name beside `path`; [`Staged::commit`] renames it
/// over `path`, dropping it without commit deletes it.
pub struct Staged {
    tmp: NamedTempFile,
    path: PathBuf,
}

impl Staged {
    /// Creates the temporary file in `path`'s folder (so the rename stays on one file system).
    pub fn new(path: &Path) -> io::Result<Self> {
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        let stem = path.file_name().map(|n| n.to_string_lossy().into_owned());
        let prefix = format!(".{}.", stem.unwrap_or_default());
        let mut builder = tempfile::Builder::new();
        builder.prefix(&prefix).suffix(".tmp");
        // A temporary file is created owner-only (0600); an output is a plain file, so it gets
        // what `File::create` would give it: 0666 less the umask.
        #[cfg(unix)]
        builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
        let tmp = builder.tempfile_in(dir)?;
        Ok(Staged {
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

    /// Renames the temporary file over the final name. (No `fsync`: this guards against killed
    /// and concurrent runs, which the page cache survives, not against power loss.)
    pub fn commit(self) -> io::Result<()> {
        self.tmp.persist(&self.path).map_err(|e| e.error)?;
        Ok(())
    }
}

/// Writes `bytes` to `path` through a [`Staged`] file.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let mut staged = Staged::new(path)?;
    io::Write::write_all(staged.file(), bytes)?;
    staged.commit()
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
