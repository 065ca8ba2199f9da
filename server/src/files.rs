//! Files written whole or not at all: the temporary name a file is written under until it is
//! complete (`.NAME.tmp-PID` beside it), the atomic write through it, and telling whether such a
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
    use std::io::Write;
    let tmp = temp_path(path);
    let written = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if written.is_err() {
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
    }
}
