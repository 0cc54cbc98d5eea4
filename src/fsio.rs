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

/// The temporary name a file is written under before it is renamed into place.
pub fn partial_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.partial"))
}

/// Flush `partial` to disk and rename it to `path` (replacing what was there).
fn publish(partial: &Path, path: &Path) -> Result<(), IoFailure> {
    let f = File::open(partial).map_err(|e| IoFailure::new("write", path, e))?;
    f.sync_all().map_err(|e| IoFailure::new("write", path, e))?;
    std::fs::rename(partial, path).map_err(|e| IoFailure::new("write", path, e))
}

/// Run `write` on the temporary file of `path` and publish it; on any failure remove the
/// temporary file (the old `path`, if any, is left as it was).
fn through_partial(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), IoFailure>,
) -> Result<(), IoFailure> {
    let partial = partial_path(path);
    let result = write(&partial).and_then(|()| publish(&partial, path));
    if result.is_err() {
        let _ = std::fs::remove_file(&partial);
    }
    result
}

/// Write `path` through `fill`, which writes the whole content to the file it is given
/// (a temporary one); then publish it. Whatever stops `fill` (the disk, a plot's backend,
/// the CSV writer) is an [`IoFailure`] naming `path`: the output could not be written.
pub fn write_with<E>(
    path: &Path,
    fill: impl FnOnce(&Path) -> Result<(), E>,
) -> Result<(), IoFailure>
where
    E: Into<anyhow::Error>,
{
    through_partial(path, |partial| {
        fill(partial).map_err(|e| {
            let e: anyhow::Error = e.into();
            let kind = e
                .chain()
                .find_map(|c| c.downcast_ref::<std::io::Error>().map(|io| io.kind()))
                .unwrap_or(std::io::ErrorKind::Other);
            IoFailure::new("write", path, std::io::Error::new(kind, format!("{e:#}")))
        })
    })
}

/// Write `bytes` to `path` atomically (temporary file, flush, rename).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), IoFailure> {
    through_partial(path, |partial| {
        std::fs::write(partial, bytes).map_err(|e| IoFailure::new("write", path, e))
    })
}

/// Write `value` as pretty JSON with a final newline to `path`, atomically.
pub fn write_json(path: &Path, value: &impl serde::Serialize) -> anyhow::Result<()> {
    write_atomic(
        path,
        (serde_json::to_string_pretty(value)? + "\n").as_bytes(),
    )?;
    Ok(())
}

/// A CSV writer's failure on `path` as an [`IoFailure`].
pub fn csv_failure(path: &Path, e: csv::Error) -> IoFailure {
    match e.into_kind() {
        csv::ErrorKind::Io(io) => IoFailure::new("write", path, io),
        other => IoFailure::new("write", path, std::io::Error::other(format!("{other:?}"))),
    }
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
    /// process is refused with [`FolderBusy`] naming that process. Writing the holder's
    /// record into the lock file also proves that files can be written in the folder, before
    /// any compute is spent (`sppm run` takes the lock before it sets the scene up).
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
