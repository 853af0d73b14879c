//! Advisory locks that keep two runs out of one dataset or one scene folder.
//!
//! A lock is an empty file beside what it guards, locked with the operating system's `flock`
//! (through `std::fs::File::try_lock`): the kernel drops it when its process dies, so a killed
//! run never leaves a dataset locked, and it works across the hosts of a shared NFS v4
//! filesystem, where Linux maps it onto POSIX byte-range locks. Taking a lock never waits: a
//! second run fails at once, naming the lock and, for an exclusive one, the process that holds
//! it.
//!
//! An exclusive holder removes the file when it is done. Removal races with a process that
//! opened the old file just before: so every taker checks after locking that the path still
//! names the file it locked, and starts over otherwise.

use std::fs::{File, OpenOptions, TryLockError};
use std::io::{ErrorKind, Read, Seek, Write};
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};

/// A held lock; released (and, if exclusive, its file removed) on drop.
#[derive(Debug)]
pub struct Lock {
    file: File,
    path: PathBuf,
    exclusive: bool,
}

impl Lock {
    /// Takes `path` exclusively and records this process in it, or fails at once if anyone
    /// holds it.
    pub fn exclusive(path: &Path) -> Result<Self> {
        let mut lock = Self::take(path, true)?;
        if !is_lock_file(&mut lock.file) {
            lock.exclusive = false; // not ours to remove on drop
            return Err(Error::format(
                path,
                "holds something other than an lfgen lock; lfgen needs this name for its \
                 lock file: move or rename it",
            ));
        }
        let holder = format!("pid {} ({})\n", std::process::id(), command_line());
        lock.file.set_len(0).map_err(|e| Error::io(path, e))?;
        lock.file
            .write_all(holder.as_bytes())
            .map_err(|e| Error::io(path, e))?;
        Ok(lock)
    }

    /// Takes `path` shared (others may take it shared too, nobody exclusively), or fails at
    /// once if it is held exclusively.
    pub fn shared(path: &Path) -> Result<Self> {
        Self::take(path, false)
    }

    /// The lock file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    fn take(path: &Path, exclusive: bool) -> Result<Self> {
        // A previous holder may remove the file between our open and our lock: retry then.
        for _ in 0..8 {
            let file = OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(path)
                .map_err(|e| Error::io(path, e))?;
            let taken = if exclusive {
                file.try_lock()
            } else {
                file.try_lock_shared()
            };
            match taken {
                Ok(()) => {}
                Err(TryLockError::WouldBlock) => return Err(busy(path, file)),
                Err(TryLockError::Error(e)) => return Err(Error::io(path, e)),
            }
            if still_named(&file, path) {
                return Ok(Self {
                    file,
                    path: path.to_path_buf(),
                    exclusive,
                });
            }
        }
        Err(Error::io(
            path,
            std::io::Error::new(ErrorKind::WouldBlock, "lock file keeps being replaced"),
        ))
    }
}

impl Drop for Lock {
    fn drop(&mut self) {
        if self.exclusive {
            // Removed while still locked, so a waiting taker sees the path gone (see above).
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// Whether `file` is empty or holds a holder line: a file of the user's that happens to have
/// the lock's name is neither, and is never truncated or removed.
fn is_lock_file(file: &mut File) -> bool {
    let mut start = [0u8; 4];
    let n = file.read(&mut start).unwrap_or(usize::MAX);
    let rewound = file.rewind().is_ok();
    rewound && (n == 0 || (n == 4 && &start == b"pid "))
}

/// The error for a lock someone else holds, naming them when the file says who.
fn busy(path: &Path, mut file: File) -> Error {
    let mut holder = String::new();
    let _ = file.read_to_string(&mut holder);
    let holder = holder.trim();
    let who = if holder.is_empty() {
        "another lfgen run".to_string()
    } else {
        format!("another lfgen run, {holder}")
    };
    Error::io(
        path,
        std::io::Error::new(ErrorKind::WouldBlock, format!("in use by {who}")),
    )
}

/// Whether `path` still names the open `file` (same device and inode).
#[cfg(unix)]
fn still_named(file: &File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn still_named(_: &File, path: &Path) -> bool {
    path.exists()
}

/// This process's command line, shortened, for the holder line.
fn command_line() -> String {
    let line: Vec<String> = std::env::args().collect();
    let line = line.join(" ");
    match line.char_indices().nth(200) {
        Some((i, _)) => format!("{}…", &line[..i]),
        None => line,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exclusive_excludes_everyone_and_names_its_holder() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(".lock");
        let held = Lock::exclusive(&path).unwrap();
        let e = Lock::exclusive(&path).unwrap_err().to_string();
        assert!(e.contains(".lock") && e.contains("in use by"), "{e}");
        assert!(e.contains(&format!("pid {}", std::process::id())), "{e}");
        assert!(Lock::shared(&path).is_err());
        drop(held);
        assert!(!path.exists(), "an exclusive lock removes its file");
        let _again = Lock::exclusive(&path).unwrap();
    }

    #[test]
    fn shared_locks_coexist_and_keep_exclusive_ones_out() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(".lock");
        let a = Lock::shared(&path).unwrap();
        let b = Lock::shared(&path).unwrap();
        assert!(Lock::exclusive(&path).is_err());
        drop((a, b));
        assert!(path.exists(), "shared holders leave the file");
        let _x = Lock::exclusive(&path).unwrap();
    }

    #[test]
    fn a_file_of_the_lock_name_that_is_no_lock_is_kept() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(".out.lock");
        std::fs::write(&path, "my notes").unwrap();
        let e = Lock::exclusive(&path).unwrap_err().to_string();
        assert!(
            e.contains(".out.lock") && e.contains("move or rename"),
            "{e}"
        );
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "my notes");
        // A lock file left by a killed holder is taken over, its holder line replaced.
        std::fs::write(&path, "pid 1 (lfgen)\n").unwrap();
        let taken = Lock::exclusive(&path).unwrap();
        let holder = std::fs::read_to_string(&path).unwrap();
        assert!(
            holder.starts_with(&format!("pid {} (", std::process::id())),
            "{holder:?}"
        );
        drop(taken);
        assert!(!path.exists());
    }

    #[test]
    fn a_lock_in_a_missing_folder_names_the_path() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("no/such/.lock");
        let e = Lock::exclusive(&path).unwrap_err().to_string();
        assert!(e.contains("no/such/.lock"), "{e}");
    }
}
