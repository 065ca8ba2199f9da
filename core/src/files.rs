//! Files written whole or not at all — analyses, extractions, uploads, rendered images and
//! archives, by the library and the service alike: the temporary name a file is written under until it is
//! complete (`.NAME.tmp-PID` beside it), the atomic write through it (replacing, or only where
//! no file is: exclusive), and telling whether such a
//! temporary file belongs to a process that still runs (another replica sharing a directory)
//! or was left by one that was killed.

use std::path::{Path, PathBuf};

/// `path` with its final name prefixed by a dot and suffixed by the process id: the name a
/// file is written under until it is complete.
pub fn temp_path(path: &Path) -> PathBuf {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    path.with_file_name(format!(".{name}.tmp-{}", std::process::id()))
}

/// Write `bytes` to `path` through its [`temp_path`], synced, then renamed into place; on
/// failure the temporary file is removed and `path` is untouched.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    through_temp(path, bytes, |tmp| std::fs::rename(tmp, path))
}

/// Write `bytes` to `path` only if no file is there: through its [`temp_path`], synced, then
/// linked into place, which fails with [`std::io::ErrorKind::AlreadyExists`] if `path` exists —
/// also when another process created it a moment ago. The temporary file is removed either way.
pub fn write_exclusive(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    through_temp(path, bytes, |tmp| std::fs::hard_link(tmp, path))
}

/// Write `bytes` to `path`'s temporary file, sync it, and put it in place with `place`; the
/// temporary file is removed afterwards if it is still there (always after a failure).
fn through_temp(path: &Path, bytes: &[u8], place: impl FnOnce(&Path) -> std::io::Result<()>) -> std::io::Result<()> {
    use std::io::Write;
    let tmp = temp_path(path);
    let written = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        place(&tmp)
    })();
    if written.is_err() || tmp.exists() {
        let _ = std::fs::remove_file(&tmp);
    }
    written
}

/// For a temporary file name (`….tmp-PID`), whether its writer still runs; `None` for any
/// other name.
pub fn writer_alive(name: &str) -> Option<bool> {
    let pid = name.rsplit_once(".tmp-")?.1.parse::<u32>().ok()?;
    Some(Path::new(&format!("/proc/{pid}")).exists())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_whole_files_and_knows_live_writers() {
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("a.png");
        write_atomic(&p, b"bytes").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"bytes");
        assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 1, "no temporary file is left");
        let mine = temp_path(&p);
        assert_eq!(writer_alive(&mine.file_name().unwrap().to_string_lossy()), Some(true));
        assert_eq!(writer_alive(".a.png.tmp-4294967295"), Some(false));
        assert_eq!(writer_alive("a.png"), None);
        assert!(write_atomic(&d.path().join("no/such/dir/b"), b"x").is_err());
        // Exclusive: the first write wins, the second fails and changes nothing.
        let q = d.path().join("b.toml");
        write_exclusive(&q, b"first").unwrap();
        let e = write_exclusive(&q, b"second").unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::AlreadyExists);
        assert_eq!(std::fs::read(&q).unwrap(), b"first");
        assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 2, "no temporary file is left");
    }
}
