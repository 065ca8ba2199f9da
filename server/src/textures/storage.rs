//! Where a texture's files are: its exemplar (embedded in the binary or a regular file of
//! bounded size, relative to the configuration), files its settings name, and the data
//! directory that keeps what its preparations computed (`<texture>.<extension>`), checked
//! writable at start (and not another process's server's: [`super::lock`]), with temporary
//! files of interrupted writes removed.

use super::LoadError;
use crate::config::{Config, TextureConfig};
use textile_core::Analysis;

/// Exemplars compiled into the binary (`config/exemplars`; licences in LICENSE.md there).
const EMBEDDED: &[(&str, &[u8])] = &[
    ("gravel.png", include_bytes!("../../../config/exemplars/gravel.png")),
    ("grass.png", include_bytes!("../../../config/exemplars/grass.png")),
    ("brick.png", include_bytes!("../../../config/exemplars/brick.png")),
    ("corkboard.png", include_bytes!("../../../config/exemplars/corkboard.png")),
    ("materials/flagstones/albedo.png", include_bytes!("../../../config/exemplars/materials/flagstones/albedo.png")),
    ("materials/flagstones/normal.png", include_bytes!("../../../config/exemplars/materials/flagstones/normal.png")),
    ("materials/flagstones/height.png", include_bytes!("../../../config/exemplars/materials/flagstones/height.png")),
    (
        "materials/flagstones/specular.png",
        include_bytes!("../../../config/exemplars/materials/flagstones/specular.png"),
    ),
    (
        "materials/forest_floor/albedo.png",
        include_bytes!("../../../config/exemplars/materials/forest_floor/albedo.png"),
    ),
    (
        "materials/forest_floor/normal.png",
        include_bytes!("../../../config/exemplars/materials/forest_floor/normal.png"),
    ),
    (
        "materials/forest_floor/height.png",
        include_bytes!("../../../config/exemplars/materials/forest_floor/height.png"),
    ),
    (
        "materials/forest_floor/specular.png",
        include_bytes!("../../../config/exemplars/materials/forest_floor/specular.png"),
    ),
];

/// Names of the embedded images, for errors.
pub fn embedded_names() -> Vec<&'static str> {
    EMBEDDED.iter().map(|(n, _)| *n).collect()
}

/// The bytes of an embedded exemplar.
pub fn embedded(name: &str) -> Option<&'static [u8]> {
    EMBEDDED.iter().find(|(n, _)| *n == name).map(|(_, b)| *b)
}

/// Read the exemplar bytes a texture config names.
pub fn exemplar_bytes(cfg: &Config, t: &TextureConfig) -> Result<Vec<u8>, LoadError> {
    image_bytes(cfg, t, t.image())
}

/// Read the bytes of an image a texture config names (`embedded:NAME` or a path).
pub(crate) fn image_bytes(cfg: &Config, t: &TextureConfig, image: &str) -> Result<Vec<u8>, LoadError> {
    file_bytes(cfg, &t.id, image, MAX_EXEMPLAR_FILE)
}

/// Read the bytes of a file the configuration names for `id` (`embedded:NAME`, or a regular
/// file relative to the configuration of at most `max` bytes).
pub fn file_bytes(cfg: &Config, id: &str, image: &str, max: u64) -> Result<Vec<u8>, LoadError> {
    if let Some(name) = image.strip_prefix("embedded:") {
        return embedded(name)
            .map(|b| b.to_vec())
            .ok_or_else(|| LoadError::NoEmbedded { id: id.to_string(), name: name.into() });
    }
    let path = cfg.base_dir.join(image);
    // Regular files only (a FIFO or device would block the read or never end), of a bounded size.
    let meta = std::fs::metadata(&path).map_err(|source| LoadError::Read {
        id: id.to_string(),
        path: path.clone(),
        source,
    })?;
    let bad = |message: String| LoadError::NotAnImageFile { id: id.to_string(), path: path.clone(), message };
    if !meta.is_file() {
        return Err(bad("is not a regular file".into()));
    }
    if meta.len() > max {
        return Err(bad(format!("is {} bytes; at most {max} are read", meta.len())));
    }
    std::fs::read(&path).map_err(|source| LoadError::Read { id: id.to_string(), path, source })
}

/// Largest exemplar file read (bytes): far beyond any accepted exemplar side, compressed.
const MAX_EXEMPLAR_FILE: u64 = 256 << 20;

/// The extensions of the files a texture's preparations keep in the data directory
/// (`<texture>.<extension>`): the analysis's, then each mode's.
pub fn stored_extensions() -> Vec<&'static str> {
    let modes = textile_core::modes::preparations();
    std::iter::once(<Analysis as textile_core::prepare::Preparation>::EXTENSION)
        .chain(modes.iter().map(|(_, p)| p.extension()))
        .collect()
}

/// Remove temporary files of preparations (`.ID.tex.tmp-PID`) left by processes that no longer
/// run (killed while writing); those of live processes (another replica sharing the directory)
/// stay.
pub(crate) fn remove_stale_temp_files(dir: &std::path::Path, log: &dyn Fn(String)) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    let extensions = stored_extensions();
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if !(name.starts_with('.') && extensions.iter().any(|x| name.contains(&format!(".{x}.tmp-")))) {
            continue;
        }
        if textile_core::files::writer_alive(&name) != Some(true) && std::fs::remove_file(e.path()).is_ok() {
            log(format!("removed {}, left by an interrupted analysis", e.path().display()));
        }
    }
}

/// Whether analyses can be stored in `dir` (created if missing): a probe file is written and
/// removed.
pub(crate) fn writable(dir: &std::path::Path) -> Result<(), std::io::Error> {
    std::fs::create_dir_all(dir)?;
    let probe = dir.join(format!(".probe-{}", std::process::id()));
    std::fs::write(&probe, b"textile")?;
    std::fs::remove_file(&probe)
}

/// Whether analyses can be stored in the data directory (checked first, with stale temporary
/// files of interrupted writes removed); if not, a warning is logged. A directory another
/// process's server owns ([`super::lock`]) is read, never written: not even probed.
pub(crate) fn data_dir_storable(cfg: &Config, log: &dyn Fn(String)) -> bool {
    let data_dir = cfg.data_dir();
    if let Err(why) = super::lock::may_write(&data_dir) {
        log(format!("{why}: reading its analyses, storing none (what is computed here is kept in memory)"));
        return false;
    }
    match writable(&data_dir) {
        Ok(()) => {
            remove_stale_temp_files(&data_dir, log);
            true
        }
        Err(e) => {
            log(format!(
                "warning: analyses cannot be stored in {} ({e}); computing them and keeping them in memory only",
                data_dir.display()
            ));
            false
        }
    }
}

/// Read the bytes of a file a texture setting names (relative to the configuration), as a
/// preparation's [`Input::read`] asks; an uploaded texture's settings read none.
pub(crate) fn setting_file(cfg: &Config, t: &TextureConfig, name: &str) -> Result<Vec<u8>, textile_core::CoreError> {
    // An upload names no file on the server (its record may predate that rule): nothing is read.
    if t.uploaded {
        return Err(textile_core::CoreError::Param {
            name: "file",
            message: "an uploaded texture reads no file on the server".into(),
        });
    }
    image_bytes(cfg, t, name).map_err(|e| textile_core::CoreError::Param { name: "file", message: e.to_string() })
}
