//! Landscapes added through the admin API, without HTTP: their store in the data directory's
//! `landscapes/` folder — the painted splat as sent (`ID.splat.png`, when it has one), then its
//! configuration (`ID.json`, the same fields as a configured landscape's, the splat named as
//! the file beside it), each written to a temporary file, synced and linked into place, the
//! configuration last: a configuration present means a complete landscape, and whatever an
//! interrupted upload or deletion left is removed at start-up.

use std::path::{Path, PathBuf};

use textile_core::error::clip;
use textile_core::files::{write_exclusive, writer_alive};

use crate::config::{Config, LandscapeConfig, SplatConfig};

/// The folder of stored landscapes inside the data directory.
pub const LANDSCAPES_DIR: &str = "landscapes";

/// Largest `config` part of a landscape upload, bytes.
pub const MAX_CONFIG_BYTES: usize = 64 << 10;

/// The folder of stored landscapes of a configuration's data directory.
pub fn dir(cfg: &Config) -> PathBuf {
    cfg.data_dir().join(LANDSCAPES_DIR)
}

/// The file a stored landscape's splat is kept in, beside its record.
pub fn splat_file(id: &str) -> String {
    format!("{id}.splat.png")
}

/// The record's file name.
fn record_file(id: &str) -> String {
    format!("{id}.json")
}

/// Why a landscape could not be stored.
#[derive(Debug, thiserror::Error)]
pub enum StoreError {
    /// Another process stored a landscape of this id meanwhile.
    #[error("another process has stored a landscape of this id in the data directory")]
    Taken,
    /// The data directory refused the files.
    #[error("{0}")]
    Io(#[from] std::io::Error),
    /// This server may not write in the data directory (removed or replaced while it ran).
    #[error("{0}")]
    NotOwned(#[from] crate::textures::lock::NotWritable),
}

/// Store a landscape: its splat's bytes first (when it has a painted one), then its record, each
/// written whole and linked into place only where no file is. `l`'s splat image is replaced by
/// the stored file's name.
pub fn store(dir: &Path, l: &LandscapeConfig, splat: Option<&[u8]>) -> Result<(), StoreError> {
    if let Some(data_dir) = dir.parent() {
        crate::textures::lock::may_write(data_dir)?;
    }
    std::fs::create_dir_all(dir)?;
    let taken = |e: std::io::Error| match e.kind() {
        std::io::ErrorKind::AlreadyExists => StoreError::Taken,
        _ => StoreError::Io(e),
    };
    let mut stored = l.clone();
    let splat_path = dir.join(splat_file(&l.id));
    if let (Some(bytes), SplatConfig::Image { image, .. }) = (splat, &mut stored.splat) {
        *image = splat_file(&l.id);
        // A splat file without a record is an orphan of an interrupted upload: replaced.
        if !dir.join(record_file(&l.id)).exists() {
            let _ = std::fs::remove_file(&splat_path);
        }
        write_exclusive(&splat_path, bytes).map_err(taken)?;
    }
    let text = serde_json::to_vec_pretty(&stored).map_err(std::io::Error::other)?;
    if let Err(e) = write_exclusive(&dir.join(record_file(&l.id)), &text) {
        if splat.is_some() {
            let _ = std::fs::remove_file(&splat_path);
        }
        return Err(taken(e));
    }
    Ok(())
}

/// Remove a stored landscape: its record first (what makes it a landscape at the next start),
/// then its splat (best effort: what is left is an orphan the next start removes).
pub fn remove(dir: &Path, id: &str) -> std::io::Result<()> {
    match std::fs::remove_file(dir.join(record_file(id))) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => return Err(e),
        _ => {}
    }
    let _ = std::fs::remove_file(dir.join(splat_file(id)));
    Ok(())
}

/// A stored record read and checked: a landscape configuration whose splat, if painted, is the
/// file beside it.
pub fn parse_record(text: &str, id: &str) -> Result<LandscapeConfig, String> {
    let l: LandscapeConfig = serde_json::from_str(text).map_err(|e| e.to_string())?;
    if l.id != id {
        return Err(format!("the record of '{id}' holds landscape '{}'", clip(&l.id)));
    }
    if let SplatConfig::Image { image, .. } = &l.splat {
        if *image != splat_file(id) {
            return Err(format!("splat image '{}' is not the file beside the record", clip(image)));
        }
    }
    Ok(l)
}

/// The stored landscapes, in the order they were stored, their splat paths made absolute and
/// marked uploaded. Files no record owns (left by an interrupted upload or deletion, their
/// writer gone) are removed; an unreadable record is skipped with a warning.
pub fn stored(dir: &Path, log: &dyn Fn(String)) -> Vec<LandscapeConfig> {
    let Ok(entries) = std::fs::read_dir(dir) else { return Vec::new() };
    let (mut records, mut others) = (Vec::new(), Vec::new());
    for e in entries.flatten() {
        let path = e.path();
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        match name.strip_suffix(".json") {
            Some(id) if !name.contains(".tmp-") => {
                let modified = e.metadata().and_then(|m| m.modified()).ok();
                records.push((modified, id.to_string(), path));
            }
            _ => others.push((name, path)),
        }
    }
    records.sort();
    let mut out = Vec::new();
    for (_, id, path) in records {
        match std::fs::read_to_string(&path).map_err(|e| e.to_string()).and_then(|s| parse_record(&s, &id)) {
            Ok(mut l) => {
                if let SplatConfig::Image { image, .. } = &mut l.splat {
                    *image = dir.join(&*image).to_string_lossy().into_owned();
                }
                l.uploaded = true;
                out.push(l);
            }
            Err(e) => log(format!("warning: {}: {e}; skipped", path.display())),
        }
    }
    for (name, path) in others {
        let owned = out.iter().any(|l| name == splat_file(&l.id));
        if owned || writer_alive(&name) == Some(true) {
            continue;
        }
        if std::fs::remove_file(&path).is_ok() {
            log(format!("removed {}, left by an interrupted landscape upload or deletion", path.display()));
        }
    }
    out
}

/// A configuration with the stored landscapes added after its own (one whose id a configured
/// texture or landscape has is left out, with a warning).
pub fn with_stored(cfg: &Config, log: &dyn Fn(String)) -> Config {
    let mut all = cfg.clone();
    for l in stored(&dir(cfg), log) {
        let taken = cfg.textures.iter().any(|t| t.id == l.id) || cfg.landscapes.iter().any(|c| c.id == l.id);
        if taken {
            log(format!("warning: stored landscape '{}' is not served: a configured one has its id", l.id));
        } else {
            all.landscapes.push(l);
        }
    }
    all
}
