//! One owner per data directory: `textile serve` holds an exclusive lock on `DATA_DIR/textile.lock`
//! (an advisory `flock`, released by the kernel however the process ends, so no stale lock
//! survives a crash) with its pid written in it. A second server on the directory is refused
//! with a message naming that pid; the other commands (`render`, `export`) read a directory a
//! server owns without writing to it (what they compute they keep in memory).
//!
//! The lock file is opened without following a symbolic link and must be a regular file: a
//! link, a directory or a FIFO in its place stops the start and is left as it is. A directory
//! that cannot be written at all (read-only, or impossible to create) is served without a lock,
//! storing nothing. A server whose directory is removed or replaced while it runs finds its lock
//! file gone ([`may_write`]) and stores nothing more there, so it never shares a directory with
//! a server started on the new one.

use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, Write};
use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The lock file's name in the data directory.
pub const LOCK_FILE: &str = "textile.lock";

/// The directory this process owns, once [`DataDirLock::acquire`] succeeded, and the lock
/// file's identity (device, inode): a directory whose lock file is another is no longer owned.
static OWNED: OnceLock<(PathBuf, u64, u64)> = OnceLock::new();

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
    /// The lock file is not a regular file: nothing it is or points to is touched.
    #[error(
        "cannot lock the data directory: {path} is {what}, not a regular file; remove it (textile creates its lock \
         file itself) or give another --data-dir"
    )]
    NotAFile {
        /// The lock file.
        path: PathBuf,
        /// What it is instead.
        what: &'static str,
    },
    /// The directory cannot be created or written here: served without a lock, storing nothing.
    #[error("the data directory {dir} cannot be written ({source}): serving without storing anything there")]
    Unwritable {
        /// The directory.
        dir: PathBuf,
        /// What failed.
        source: std::io::Error,
    },
    /// The lock file could not be opened or written in a directory that can be written.
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

/// Open (creating) the lock file: never through a symbolic link (`O_NOFOLLOW`), never blocking
/// on a FIFO (`O_NONBLOCK`), and only a regular file is kept.
fn open(dir: &Path) -> Result<File, LockError> {
    let path = dir.join(LOCK_FILE);
    std::fs::create_dir_all(dir).map_err(|source| LockError::Unwritable { dir: dir.to_path_buf(), source })?;
    let not_a_file = |what| LockError::NotAFile { path: path.clone(), what };
    let opened = OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(false)
        .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK)
        .open(&path);
    let f = match opened {
        Ok(f) => f,
        Err(e) if e.raw_os_error() == Some(libc::ELOOP) => return Err(not_a_file("a symbolic link")),
        Err(e) if e.raw_os_error() == Some(libc::EISDIR) => return Err(not_a_file("a directory")),
        Err(e) if e.raw_os_error() == Some(libc::ENXIO) => return Err(not_a_file("a FIFO or socket")),
        Err(source) if matches!(source.raw_os_error(), Some(libc::EROFS | libc::EACCES)) && !writable(dir) => {
            return Err(LockError::Unwritable { dir: dir.to_path_buf(), source })
        }
        Err(source) => return Err(LockError::Io { dir: dir.to_path_buf(), source }),
    };
    let m = f.metadata().map_err(|source| LockError::Io { dir: dir.to_path_buf(), source })?;
    if !m.is_file() {
        let ft = m.file_type();
        use std::os::unix::fs::FileTypeExt;
        return Err(not_a_file(if ft.is_fifo() {
            "a FIFO"
        } else if ft.is_socket() {
            "a socket"
        } else {
            "a device"
        }));
    }
    Ok(f)
}

/// Whether this process may create files in `dir` (`access(2)` with `W_OK`).
fn writable(dir: &Path) -> bool {
    use std::os::unix::ffi::OsStrExt;
    let Ok(c) = std::ffi::CString::new(dir.as_os_str().as_bytes()) else { return false };
    // SAFETY: `c` is a NUL-terminated path that outlives the call; access(2) only reads it.
    unsafe { libc::access(c.as_ptr(), libc::W_OK) == 0 }
}

/// The pid an owned lock file names.
fn owner_pid(f: &mut File) -> String {
    let mut s = String::new();
    let _ = f.rewind().and_then(|()| f.take(64).read_to_string(&mut s));
    match s.trim() {
        "" => "unknown".into(),
        pid => pid.chars().take(20).collect(),
    }
}

impl DataDirLock {
    /// Take `dir` (created if missing) for this process, or say who holds it, or why it
    /// cannot be taken ([`LockError::Unwritable`]: nothing can be stored there either).
    pub fn acquire(dir: &Path) -> Result<DataDirLock, LockError> {
        let io = |source| LockError::Io { dir: dir.to_path_buf(), source };
        let mut f = open(dir)?;
        match f.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => {
                return Err(LockError::Owned { dir: dir.to_path_buf(), pid: owner_pid(&mut f) })
            }
            Err(std::fs::TryLockError::Error(e)) => return Err(io(e)),
        }
        f.set_len(0).and_then(|()| f.rewind()).and_then(|()| writeln!(f, "{}", std::process::id())).map_err(io)?;
        let m = f.metadata().map_err(io)?;
        let _ = OWNED.set((dir.to_path_buf(), m.dev(), m.ino()));
        Ok(DataDirLock { _file: f })
    }
}

/// Why this process may not write in a data directory.
#[derive(Debug, thiserror::Error)]
pub enum NotWritable {
    /// Another server owns it.
    #[error("the data directory {dir} belongs to the textile server of pid {pid}")]
    Owned {
        /// The directory.
        dir: PathBuf,
        /// The owner's pid.
        pid: String,
    },
    /// This server owned it, and it was removed or replaced since: it writes nothing there.
    #[error(
        "the data directory {dir} was removed or replaced while this server ran: it stores nothing there any more \
         (restart it to take the directory again)"
    )]
    Lost {
        /// The directory.
        dir: PathBuf,
    },
}

/// Whether this process may write in `dir`: it owns it (and its lock file is still the one it
/// locked), or no server does.
pub fn may_write(dir: &Path) -> Result<(), NotWritable> {
    if let Some((owned, dev, ino)) = OWNED.get().filter(|(d, _, _)| d == dir) {
        return match std::fs::symlink_metadata(owned.join(LOCK_FILE)) {
            Ok(m) if m.dev() == *dev && m.ino() == *ino => Ok(()),
            _ => Err(NotWritable::Lost { dir: dir.to_path_buf() }),
        };
    }
    let opened =
        OpenOptions::new().read(true).custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK).open(dir.join(LOCK_FILE));
    let Ok(mut f) = opened else { return Ok(()) };
    if !f.metadata().is_ok_and(|m| m.is_file()) {
        return Ok(());
    }
    match f.try_lock_shared() {
        Ok(()) => {
            let _ = f.unlock();
            Ok(())
        }
        Err(_) => Err(NotWritable::Owned { dir: dir.to_path_buf(), pid: owner_pid(&mut f) }),
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
