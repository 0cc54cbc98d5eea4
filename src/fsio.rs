//! Files that are never half-written, and folders that one process owns at a time.
//!
//! - [`write_atomic`] / [`publish`]: a file is written under a temporary name in its own
//!   folder (`.<name>.partial`), flushed to disk and renamed over the final name, so a reader
//!   (or a later run) sees either the old file or the whole new one, never a truncated one.
//! - [`FolderLock`]: an advisory lock (`flock`) on `<folder>/.sppm.lock`, held for as long
//!   as the value lives and released by the kernel when the process dies, so a killed run
//!   never leaves a stale lock. The file records the holder's process id and command line,
//!   and a second sppm that finds the lock taken names them.
//! - [`IoFailure`] and [`FolderBusy`]: the two errors the CLI maps to their own exit codes
//!   (4 and 5; `docs/reliability.md`).

use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};

/// An input/output operation on `path` failed (unwritable folder, full disk, …).
#[derive(Debug, thiserror::Error)]
#[error("cannot {action} {}", path.display())]
pub struct IoFailure {
    pub action: &'static str,
    pub path: PathBuf,
    #[source]
    pub source: std::io::Error,
}

impl IoFailure {
    pub fn new(action: &'static str, path: &Path, source: std::io::Error) -> Self {
        IoFailure {
            action,
            path: path.to_path_buf(),
            source,
        }
    }
}

/// Another process holds the lock of a folder.
#[derive(Debug, thiserror::Error)]
#[error("{} is in use by another sppm process ({holder}); wait for it to finish, or use another --out folder", folder.display())]
pub struct FolderBusy {
    pub folder: PathBuf,
    /// "process 1234: sppm run …", as the holder recorded it.
    pub holder: String,
}

/// The temporary name a file is written under before [`publish`] renames it.
pub fn partial_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.partial"))
}

/// Flush `partial` to disk and rename it to `path` (replacing what was there).
pub fn publish(partial: &Path, path: &Path) -> Result<(), IoFailure> {
    let f = File::open(partial).map_err(|e| IoFailure::new("write", path, e))?;
    f.sync_all().map_err(|e| IoFailure::new("write", path, e))?;
    std::fs::rename(partial, path).map_err(|e| {
        let _ = std::fs::remove_file(partial);
        IoFailure::new("write", path, e)
    })
}

/// Write `path` through `fill`, which writes the whole content to the file it is given
/// (a temporary one); then publish it. On any failure the temporary file is removed and the
/// old `path`, if any, is left as it was.
pub fn write_with<E>(
    path: &Path,
    fill: impl FnOnce(&Path) -> Result<(), E>,
) -> Result<(), anyhow::Error>
where
    E: Into<anyhow::Error>,
{
    let partial = partial_path(path);
    let result = fill(&partial)
        .map_err(|e| {
            let e: anyhow::Error = e.into();
            // an I/O error deep in a writer (a plot, the CSV writer) becomes an IoFailure
            // naming the final file
            match find_io(&e) {
                Some(kind) => anyhow::Error::new(IoFailure::new(
                    "write",
                    path,
                    std::io::Error::new(kind, format!("{e:#}")),
                )),
                None => e.context(format!("cannot write {}", path.display())),
            }
        })
        .and_then(|()| publish(&partial, path).map_err(anyhow::Error::new));
    if result.is_err() {
        let _ = std::fs::remove_file(&partial);
    }
    result
}

/// The kind of the first I/O error in an error's chain (also inside plotters' and csv's own
/// error types, which keep the `std::io::Error` as their source or in their text).
fn find_io(e: &anyhow::Error) -> Option<std::io::ErrorKind> {
    for cause in e.chain() {
        if let Some(io) = cause.downcast_ref::<std::io::Error>() {
            return Some(io.kind());
        }
        if let Some(c) = cause.downcast_ref::<csv::Error>() {
            if let csv::ErrorKind::Io(io) = c.kind() {
                return Some(io.kind());
            }
        }
    }
    let text = format!("{e:#}");
    [
        "No space left",
        "File too large",
        "Permission denied",
        "Read-only file system",
        "Disk quota",
    ]
    .iter()
    .any(|s| text.contains(s))
    .then_some(std::io::ErrorKind::Other)
}

/// Write `bytes` to `path` atomically (temporary file, flush, rename).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), IoFailure> {
    let partial = partial_path(path);
    let result = (|| {
        let mut f = File::create(&partial)?;
        f.write_all(bytes)?;
        f.sync_all()
    })()
    .map_err(|e| IoFailure::new("write", path, e))
    .and_then(|()| publish(&partial, path));
    if result.is_err() {
        let _ = std::fs::remove_file(&partial);
    }
    result
}

/// Create `dir` (and its parents) and check that files can be written in it, before any
/// compute is spent.
pub fn ensure_writable_folder(dir: &Path) -> Result<(), IoFailure> {
    std::fs::create_dir_all(dir).map_err(|e| IoFailure::new("create the folder", dir, e))?;
    let probe = dir.join(format!(".sppm-write-test-{}", std::process::id()));
    let r = File::create(&probe).and_then(|mut f| f.write_all(b"sppm"));
    let _ = std::fs::remove_file(&probe);
    r.map_err(|e| IoFailure::new("write in the folder", dir, e))
}

/// The lock of one folder, held until dropped (or until the process ends).
#[derive(Debug)]
pub struct FolderLock {
    file: File,
    path: PathBuf,
}

/// Name of the lock file inside a locked folder.
pub const LOCK_FILE: &str = ".sppm.lock";

impl FolderLock {
    /// Create `dir` if needed and take its lock without waiting. A folder locked by another
    /// process is refused with [`FolderBusy`] naming that process.
    pub fn acquire(dir: &Path) -> anyhow::Result<FolderLock> {
        std::fs::create_dir_all(dir).map_err(|e| IoFailure::new("create the folder", dir, e))?;
        let path = dir.join(LOCK_FILE);
        let mut file = OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(&path)
            .map_err(|e| IoFailure::new("create the lock file", &path, e))?;
        match file.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => {
                let mut holder = String::new();
                let _ = file.read_to_string(&mut holder);
                let holder = holder.trim();
                return Err(FolderBusy {
                    folder: dir.to_path_buf(),
                    holder: if holder.is_empty() {
                        "a process that has not yet written its name".into()
                    } else {
                        holder.to_string()
                    },
                }
                .into());
            }
            Err(std::fs::TryLockError::Error(e)) => {
                return Err(IoFailure::new("lock", &path, e).into())
            }
        }
        let command: Vec<String> = std::env::args().collect();
        let text = format!("process {}: {}\n", std::process::id(), command.join(" "));
        (|| {
            file.set_len(0)?;
            file.rewind()?;
            file.write_all(text.as_bytes())?;
            file.flush()
        })()
        .map_err(|e| IoFailure::new("write the lock file", &path, e))?;
        Ok(FolderLock { file, path })
    }

    /// The lock file.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for FolderLock {
    fn drop(&mut self) {
        // empty the record; the lock itself goes with the file handle
        let _ = self.file.set_len(0);
        let _ = self.file.unlock();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_lock_on_a_folder_is_refused_naming_the_holder() {
        let dir = std::env::temp_dir().join(format!("sppm-fsio-lock-{}", std::process::id()));
        let first = FolderLock::acquire(&dir).unwrap();
        let second = FolderLock::acquire(&dir).unwrap_err();
        let busy = second.downcast_ref::<FolderBusy>().expect("FolderBusy");
        assert!(
            busy.holder
                .contains(&format!("process {}", std::process::id())),
            "{}",
            busy.holder
        );
        drop(first);
        FolderLock::acquire(&dir).expect("free again after the first is dropped");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_failed_write_leaves_the_old_file_whole() {
        let dir = std::env::temp_dir().join(format!("sppm-fsio-atomic-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("a.txt");
        write_atomic(&p, b"old").unwrap();
        let r = write_with(&p, |tmp: &Path| -> anyhow::Result<()> {
            std::fs::write(tmp, b"half")?;
            anyhow::bail!("disk full")
        });
        assert!(r.is_err());
        assert_eq!(std::fs::read(&p).unwrap(), b"old");
        assert!(!partial_path(&p).exists());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
