//! One owner per data directory: `textile serve` holds an exclusive lock on `DATA_DIR/textile.lock`
//! (an advisory `flock`, released by the kernel however the process ends, so no stale lock
//! survives a crash) with its pid written in it. A second server on the directory is refused
//! with a message naming that pid; the other commands (`render`, `export`) read a directory a
//! server owns without writing to it (what they compute they keep in memory).

use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The lock file's name in the data directory.
pub const LOCK_FILE: &str = "textile.lock";

/// The directory this process owns, once [`DataDirLock::acquire`] succeeded.
static OWNED: OnceLock<PathBuf> = OnceLock::new();

/// Why a data directory could not be taken.
#[derive(Debug, thiserror::Error)]
pub enum LockError {
    /// Another process holds it.
    #[error(
        "the data directory {dir} is in use by another textile server (pid {pid}); give this one a data directory of \
         its own (--data-dir), or stop that one"
    )]
    Owned {
        /// The directory.
        dir: PathBuf,
        /// The owner's pid, as its lock file says (`unknown` if unreadable).
        pid: String,
    },
    /// The lock file could not be opened or written.
    #[error("cannot lock the data directory {dir}: {source}")]
    Io {
        /// The directory.
        dir: PathBuf,
        /// What failed.
        source: std::io::Error,
    },
}

/// The held lock: the directory stays this process's while it lives.
#[derive(Debug)]
pub struct DataDirLock {
    _file: File,
}

fn open(dir: &Path) -> std::io::Result<File> {
    std::fs::create_dir_all(dir)?;
    OpenOptions::new().read(true).write(true).create(true).truncate(false).open(dir.join(LOCK_FILE))
}

/// The pid an owned lock file names.
fn owner_pid(f: &mut File) -> String {
    let mut s = String::new();
    let _ = f.rewind().and_then(|()| f.read_to_string(&mut s));
    match s.trim() {
        "" => "unknown".into(),
        pid => pid.chars().take(20).collect(),
    }
}

impl DataDirLock {
    /// Take `dir` (created if missing) for this process, or say who holds it.
    pub fn acquire(dir: &Path) -> Result<DataDirLock, LockError> {
        let io = |source| LockError::Io { dir: dir.to_path_buf(), source };
        let mut f = open(dir).map_err(io)?;
        match f.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => {
                return Err(LockError::Owned { dir: dir.to_path_buf(), pid: owner_pid(&mut f) })
            }
            Err(std::fs::TryLockError::Error(e)) => return Err(io(e)),
        }
        f.set_len(0).and_then(|()| f.rewind()).and_then(|()| writeln!(f, "{}", std::process::id())).map_err(io)?;
        let _ = OWNED.set(dir.to_path_buf());
        Ok(DataDirLock { _file: f })
    }
}

/// Whether this process may write in `dir`: it owns it, or no server does. `Err(pid)` names the
/// server that owns it.
pub fn may_write(dir: &Path) -> Result<(), String> {
    if OWNED.get().is_some_and(|d| d == dir) {
        return Ok(());
    }
    let Ok(mut f) = OpenOptions::new().read(true).open(dir.join(LOCK_FILE)) else { return Ok(()) };
    match f.try_lock_shared() {
        Ok(()) => {
            let _ = f.unlock();
            Ok(())
        }
        Err(_) => Err(owner_pid(&mut f)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_held_directory_is_refused_naming_the_owner() {
        let dir = tempfile_dir();
        let held = DataDirLock::acquire(&dir).unwrap();
        // A second open file description conflicts, as another process's would.
        let mut f = open(&dir).unwrap();
        assert!(matches!(f.try_lock(), Err(std::fs::TryLockError::WouldBlock)));
        assert_eq!(owner_pid(&mut f), std::process::id().to_string());
        assert!(may_write(&dir).is_ok(), "the owner itself may write");
        drop(held);
        assert!(f.try_lock().is_ok(), "released with its file");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    fn tempfile_dir() -> PathBuf {
        let d = std::env::temp_dir().join(format!("textile-lock-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }
}
