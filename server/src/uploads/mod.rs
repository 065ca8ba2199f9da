//! Uploaded textures, without HTTP: the admin token check, an upload's fields read into a
//! texture configuration, and the store in the data directory's `uploads/` folder — its
//! material maps as sent (`ID.map.NAME.png|jpg|webp`), the exemplar file as sent
//! (`ID.png|jpg|webp`) and its configuration (`ID.toml`), each written to a temporary file and
//! renamed into place, the configuration last: a configuration present means a complete
//! upload, and whatever an interrupted upload left is removed at start-up — and the background
//! analysis of an upload. Landscapes added through the admin API are stored by [`landscapes`].

pub mod landscapes;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use textile_core::analysis::IndexChoice;
use textile_core::error::clip;

use std::sync::Arc;

use crate::config::{settings, Config, TextureConfig, NORMAL_CONVENTION};
use crate::error::ApiError;
use crate::state::AppState;
use crate::textures::analysing::Watch;
use crate::textures::Texture;
use textile_core::files::{write_exclusive, writer_alive};

/// The folder of uploaded textures inside the data directory.
pub const UPLOADS_DIR: &str = "uploads";

/// The uploads folder of a configuration's data directory.
pub fn dir(cfg: &Config) -> PathBuf {
    cfg.data_dir().join(UPLOADS_DIR)
}

/// Whether `authorization` (the header's value) carries the configured admin token. Both sides
/// are hashed and the hashes compared in constant time, so the comparison's duration says
/// nothing about the token.
pub fn authorized(token: &str, authorization: Option<&[u8]>) -> bool {
    // `Bearer TOKEN`, the scheme in any case (RFC 9110: auth-schemes are case-insensitive).
    let Some(given) = authorization.and_then(|a| {
        let (scheme, rest) = a.split_at_checked(7)?;
        (scheme.eq_ignore_ascii_case(b"bearer ")).then_some(rest)
    }) else {
        return false;
    };
    let given = given.trim_ascii_start();
    !token.is_empty() && blake3::hash(given) == blake3::hash(token.as_bytes())
}

/// The image formats accepted, by their file extension.
pub fn image_extension(bytes: &[u8]) -> Option<&'static str> {
    match image::guess_format(bytes).ok()? {
        image::ImageFormat::Png => Some("png"),
        image::ImageFormat::Jpeg => Some("jpg"),
        image::ImageFormat::WebP => Some("webp"),
        _ => None,
    }
}

/// Files without a configuration younger than this are left alone (see [`stored`]).
const ORPHAN_AGE: std::time::Duration = std::time::Duration::from_secs(60);

/// Most fields an upload may carry.
pub const MAX_FIELDS: usize = 64;

/// Most material maps an upload may carry.
pub const MAX_MAPS: usize = 16;

/// The file an uploaded texture's map `name` is stored in, beside its record.
pub fn map_file(id: &str, name: &str, ext: &str) -> String {
    format!("{id}.map.{name}.{ext}")
}

/// A texture configuration from an upload's fields (query pairs or multipart fields): `id`
/// (required), `name`, `toroidal` (`auto|true|false|synthesize`), `index`
/// (`auto|exact|coherent`), `lattice` (`auto|none|NX,NY|P@A[,P@A]`), `default_mode`, `default_seed`,
/// `attribution`, `normal_convention` (with a normal map), and `MODE.KEY` for a per-mode
/// setting (`synth.kappa=0.5`); and its material `maps`, `(name, file extension)` (their
/// images are parts of a multipart form, `map.NAME`). Checked as a configured texture is, so an
/// upload is refused for what a configuration file would be.
pub fn texture_config(fields: &[(String, String)], maps: &[(String, &str)]) -> Result<TextureConfig, ApiError> {
    let bad = |m: String| ApiError::bad_request("invalid_upload", m);
    if fields.len() > MAX_FIELDS {
        return Err(bad(format!("{} fields; at most {MAX_FIELDS}", fields.len())));
    }
    let mut id = None;
    let mut t = TextureConfig::new("", "");
    t.name.clear();
    let mut modes: BTreeMap<String, toml::map::Map<String, toml::Value>> = BTreeMap::new();
    let mut seen = std::collections::HashSet::new();
    for (k, v) in fields {
        if !seen.insert(k.as_str()) {
            return Err(bad(format!("field '{}' is given twice", clip(k))));
        }
        let long = |max: usize| bad(format!("field '{}' is over {max} characters", clip(k)));
        // The texture's own fields, checked against their declared type and range.
        if let Some(spec) = settings::TEXTURE_FIELDS.iter().find(|s| s.name == k) {
            spec.check(v).map_err(|e| bad(e.to_string()))?;
        }
        match k.as_str() {
            "id" => id = Some(v.clone()),
            "name" => t.name = v.clone(),
            "attribution" => t.attribution = v.clone(),
            "default_mode" => t.default_mode = v.clone(),
            "default_seed" => t.default_seed = settings::DEFAULT_SEED.integer(v).map_err(|e| bad(e.to_string()))?,
            "toroidal" => {
                t.toroidal = serde_json::from_value(serde_json::json!(v)).map_err(|e| bad(format!("toroidal: {e}")))?
            }
            "index" => t.candidate_search = IndexChoice::parse(v).map_err(|e| bad(e.to_string()))?,
            "lattice" => t.lattice = v.parse().map_err(bad)?,
            NORMAL_CONVENTION => {
                t.maps.insert(NORMAL_CONVENTION.into(), v.clone());
            }
            other if other.starts_with("map.") => {
                return Err(bad(format!(
                    "field '{}': a map is an image, sent as a part of a multipart form",
                    clip(other)
                )))
            }
            other => {
                let Some((mode, key)) = other.split_once('.') else {
                    let fields: Vec<&str> = settings::TEXTURE_FIELDS.iter().map(|s| s.name).collect();
                    return Err(bad(format!(
                        "unknown field '{}'; fields are {} and MODE.KEY settings",
                        clip(other),
                        fields.join(", ")
                    )));
                };
                if v.len() > 256 {
                    return Err(long(256));
                }
                modes.entry(mode.to_string()).or_default().insert(key.to_string(), toml::Value::String(v.clone()));
            }
        }
    }
    t.id = id.ok_or_else(|| bad("the field 'id' is required".into()))?;
    if maps.len() > MAX_MAPS {
        return Err(bad(format!("{} maps; at most {MAX_MAPS}", maps.len())));
    }
    for (name, ext) in maps {
        t.maps.insert(name.clone(), map_file(&t.id, name, ext));
    }
    if t.name.is_empty() {
        t.name = t.id.clone();
    }
    t.modes = modes.into_iter().map(|(m, table)| (m, toml::Value::Table(table))).collect();
    t.uploaded = true;
    t.validate("upload").map_err(|(key, msg)| bad(format!("{key}: {msg}")))?;
    if let Some(field) = t.file_settings().first() {
        return Err(bad(format!(
            "field '{field}' names a file, and an upload reads no file on the server; upload without it (the \
             texture then uses what it derives from its exemplar)"
        )));
    }
    Ok(t)
}

/// Why an upload could not be stored.
#[derive(Debug, thiserror::Error)]
pub enum StoreError {
    /// Another process (a server sharing the data directory) stored or is storing an upload of
    /// this id.
    #[error("another process has stored an upload of this id in the data directory")]
    Taken,
    /// The data directory refused the files.
    #[error("{0}")]
    Io(#[from] std::io::Error),
    /// This server may not write in the data directory (removed or replaced while it ran).
    #[error("{0}")]
    NotOwned(#[from] crate::textures::lock::NotWritable),
}

/// Store an upload: its maps' bytes (`maps`: file name and bytes, the names `t.maps` gives),
/// then the exemplar bytes as `ID.EXT`, then its configuration as `ID.toml`, each written to a
/// temporary file, synced and linked into place only where no file is — so of two servers
/// sharing the data directory that store the same id, one wins and the other gets
/// [`StoreError::Taken`] and leaves nothing (it removes only the files it created). A file
/// without a record older than [`ORPHAN_AGE`] (left by an interrupted upload) is replaced.
pub fn store(
    dir: &Path,
    t: &TextureConfig,
    image: &[u8],
    ext: &str,
    maps: &[(String, Vec<u8>)],
) -> Result<(), StoreError> {
    // Never recreate a data directory that was removed under this server (another may own it).
    if let Some(data_dir) = dir.parent() {
        crate::textures::lock::may_write(data_dir)?;
    }
    std::fs::create_dir_all(dir)?;
    let record = dir.join(format!("{}.toml", t.id));
    let file = format!("{}.{ext}", t.id);
    let mut placed: Vec<PathBuf> = Vec::new();
    let files = maps.iter().map(|(f, b)| (f.as_str(), &b[..])).chain(std::iter::once((file.as_str(), image)));
    for (name, bytes) in files {
        let path = dir.join(name);
        if let Err(e) = place(&path, &record, bytes) {
            for p in &placed {
                let _ = std::fs::remove_file(p);
            }
            return Err(e);
        }
        placed.push(path);
    }
    let mut stored = t.clone();
    stored.exemplar = file;
    let claimed = toml::to_string(&stored)
        .map_err(std::io::Error::other)
        .and_then(|text| write_exclusive(&record, text.as_bytes()));
    if let Err(e) = claimed {
        for p in &placed {
            let _ = std::fs::remove_file(p);
        }
        return Err(if e.kind() == std::io::ErrorKind::AlreadyExists { StoreError::Taken } else { StoreError::Io(e) });
    }
    Ok(())
}

/// Link `bytes` into place at `path` where no file is, or where an orphan is: a file older
/// than [`ORPHAN_AGE`] while no `record` owns it.
fn place(path: &Path, record: &Path, bytes: &[u8]) -> Result<(), StoreError> {
    use std::io::ErrorKind::AlreadyExists;
    match write_exclusive(path, bytes) {
        Err(e) if e.kind() == AlreadyExists => {
            let age = std::fs::metadata(path).and_then(|m| m.modified()).ok().and_then(|t| t.elapsed().ok());
            if record.exists() || age.is_none_or(|a| a < ORPHAN_AGE) {
                return Err(StoreError::Taken);
            }
            std::fs::remove_file(path)?;
            write_exclusive(path, bytes).map_err(|e| match e.kind() {
                AlreadyExists => StoreError::Taken,
                _ => StoreError::Io(e),
            })
        }
        other => Ok(other?),
    }
}

/// Remove an uploaded texture's record, its configuration: what makes it a texture at the next
/// start. Until this succeeds nothing of it is gone; once it has, the rest of its files are
/// orphans that [`remove_files`] (or the next start) removes.
pub fn remove_record(dir: &Path, id: &str) -> std::io::Result<()> {
    match std::fs::remove_file(dir.join(format!("{id}.toml"))) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(e),
        _ => Ok(()),
    }
}

/// Remove the files of an uploaded texture whose record is gone (best effort: what is left is
/// an orphan the next start removes).
pub fn remove_files(dir: &Path, data_dir: &Path, id: &str) {
    for ext in ["png", "jpg", "webp"] {
        let _ = std::fs::remove_file(dir.join(format!("{id}.{ext}")));
    }
    // Its maps (ids have no dots, so `ID.map.` names only this texture's).
    let maps = format!("{id}.map.");
    for e in std::fs::read_dir(dir).into_iter().flatten().flatten() {
        if e.file_name().to_string_lossy().starts_with(&maps) {
            let _ = std::fs::remove_file(e.path());
        }
    }
    for ext in crate::textures::stored_extensions() {
        let _ = std::fs::remove_file(data_dir.join(format!("{id}.{ext}")));
    }
}

/// The stored uploads, in upload order (oldest first), their exemplar paths made absolute.
/// Files no configuration owns (left by an interrupted upload or deletion) are removed; an
/// unreadable configuration is skipped with a warning.
pub fn stored(dir: &Path, log: &dyn Fn(String)) -> Vec<TextureConfig> {
    let Ok(entries) = std::fs::read_dir(dir) else { return Vec::new() };
    let mut configs = Vec::new();
    let mut others = Vec::new();
    for e in entries.flatten() {
        let path = e.path();
        match path.extension().and_then(|x| x.to_str()) {
            Some("toml") => {
                let modified = e.metadata().and_then(|m| m.modified()).ok();
                configs.push((modified, path));
            }
            _ => others.push(path),
        }
    }
    configs.sort();
    let mut out: Vec<TextureConfig> = Vec::new();
    for (_, path) in configs {
        let parsed = std::fs::read_to_string(&path).map_err(|e| e.to_string()).and_then(|s| parse_record(&s));
        match parsed {
            Ok(mut t) if path.file_stem().is_some_and(|s| s == t.id.as_str()) => {
                let absolute = |f: &str| dir.join(f).to_string_lossy().into_owned();
                t.exemplar = absolute(&t.exemplar);
                for (name, file) in t.maps.iter_mut() {
                    if name != NORMAL_CONVENTION {
                        *file = absolute(file);
                    }
                }
                out.push(t);
            }
            Ok(_) => log(format!("warning: {} is not named after its id; skipped", path.display())),
            Err(e) => log(format!("warning: {}: {e}; skipped", path.display())),
        }
    }
    for path in others {
        let owned =
            out.iter().any(|t| Path::new(&t.exemplar) == path || t.map_images().any(|(_, f)| Path::new(f) == path));
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let writer = writer_alive(&name);
        if writer == Some(true) {
            continue; // being written by a live process (another replica sharing the directory)
        }
        // An exemplar renamed into place a moment ago may be an upload whose configuration is
        // being written by another process: only old orphans are removed.
        let age = std::fs::metadata(&path).and_then(|m| m.modified()).ok().and_then(|t| t.elapsed().ok());
        if writer.is_none() && age.is_none_or(|a| a < ORPHAN_AGE) {
            continue;
        }
        if !owned && std::fs::remove_file(&path).is_ok() {
            log(format!("removed {}, left by an interrupted upload or deletion", path.display()));
        }
    }
    out
}

/// An upload record (`ID.toml`) read and checked: a texture configuration whose exemplar and
/// maps are plain file names beside it.
pub fn parse_record(text: &str) -> Result<TextureConfig, String> {
    let mut t: TextureConfig = toml::from_str(text).map_err(|e| e.to_string())?;
    t.validate("upload").map_err(|(key, msg)| format!("{key}: {msg}"))?;
    let plain = |f: &str| Path::new(f).file_name().is_some_and(|n| n == f) && !f.starts_with('.');
    if !plain(&t.exemplar) {
        return Err(format!("exemplar '{}' is not a file name beside the record", clip(&t.exemplar)));
    }
    if let Some((name, f)) = t.map_images().find(|(_, f)| !plain(f)) {
        return Err(format!("map '{name}' ('{}') is not a file name beside the record", clip(f)));
    }
    t.uploaded = true;
    Ok(t)
}

/// A configuration with the stored uploads added after its own textures (an upload whose id a
/// configured texture has is left out, with a warning), and the stored landscapes after its own.
pub fn with_stored(cfg: &Config, log: &dyn Fn(String)) -> Config {
    let mut all = landscapes::with_stored(cfg, log);
    for t in stored(&dir(cfg), log) {
        if cfg.textures.iter().any(|c| c.id == t.id) {
            log(format!("warning: uploaded texture '{}' is not served: a configured texture has its id", t.id));
        } else {
            all.textures.push(t);
        }
    }
    all
}

/// Working memory an analysis of an exemplar of `texels` texels holds at its peak (measured:
/// 8 MiB for 128², 37 MiB for 256²; about 600 bytes a texel).
pub fn analysis_bytes(texels: u64) -> u64 {
    (16 << 20) + 600 * texels
}

/// Analyse an uploaded texture in the background on the analysis pool, at most
/// `max_concurrent_analyses` at once, its progress kept on the texture; it stops if the texture
/// is removed or the service stops, and fails once it takes longer than `analysis_timeout_secs`.
/// A failure is kept on the texture (its status becomes `failed`).
pub fn analyse_in_background(st: Arc<AppState>, tex: Arc<Texture>) {
    tokio::spawn(async move {
        let Ok(_permit) = st.analyses.clone().acquire_owned().await else { return };
        let Some(_memory) = st.reserve_patiently(analysis_bytes(tex.exemplar.pixels.len() as u64)).await else {
            return;
        };
        if tex.removed.is_set() || st.stopping.is_set() {
            return;
        }
        let job = {
            let (st, tex) = (st.clone(), tex.clone());
            move || {
                let data_dir = st.config.data_dir();
                let log = |s: String| tracing::info!("{s}");
                let budget = std::time::Duration::from_secs(st.config.analysis_timeout_secs);
                let watch = Watch::new(&tex.config.id, &tex.progress, &tex.removed, &st.stopping, budget);
                // The upload was just stored beside it, so the data directory is writable (a
                // failed save is still only a warning), unless it was removed since.
                let storable = match crate::textures::lock::may_write(&data_dir) {
                    Ok(()) => true,
                    Err(e) => {
                        tracing::warn!("texture '{}': {e}", tex.config.id);
                        false
                    }
                };
                let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                    st.analysis_pool.run(|| {
                        crate::textures::analyse_texture(
                            &st.config,
                            &data_dir,
                            storable,
                            &tex,
                            &log,
                            &watch,
                            watch.cancel(),
                        )
                    })
                }));
                match outcome {
                    Ok(Err(textile_core::CoreError::Cancelled)) if watch.timed_out() => Some(watch.timeout_message()),
                    Ok(Ok(())) | Ok(Err(textile_core::CoreError::Cancelled)) => None,
                    Ok(Err(e)) => Some(e.to_string()),
                    Err(_) => Some("the analysis failed unexpectedly".to_string()),
                }
            }
        };
        let failure = tokio::task::spawn_blocking(job)
            .await
            .unwrap_or_else(|_| Some("the analysis failed unexpectedly".to_string()));
        if let Some(f) = failure {
            tracing::warn!("texture '{}': analysis failed: {f}", tex.config.id);
            let _ = tex.failure.set(f);
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pairs(p: &[(&str, &str)]) -> Vec<(String, String)> {
        p.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect()
    }

    #[test]
    fn fields_become_a_checked_texture_configuration() {
        let t =
            texture_config(&pairs(&[("id", "cobble"), ("toroidal", "false"), ("synth.kappa", "0.5")]), &[]).unwrap();
        assert_eq!((t.id.as_str(), t.name.as_str(), t.toroidal), ("cobble", "cobble", crate::config::Toroidal::False));
        assert_eq!(t.mode_tables()["synth"], vec![("kappa".to_string(), "0.5".to_string())]);
        for bad in [
            vec![("name", "x")],
            vec![("id", "../x")],
            vec![("id", "a"), ("toroidal", "maybe")],
            vec![("id", "a"), ("synth.kappa", "7")],
            vec![("id", "a"), ("nosuch.key", "1")],
            vec![("id", "a"), ("colour", "red")],
            vec![("id", "a"), ("id", "b")],
            vec![("id", "a"), ("normal_convention", "opengl")],
            vec![("id", "a"), ("map.normal", "n.png")],
        ] {
            let e = texture_config(&pairs(&bad), &[]).unwrap_err();
            assert_eq!(e.code, "invalid_upload", "{bad:?}");
        }
        // Maps: a file each beside the record; a normal map needs its convention.
        let maps = [("normal".to_string(), "png"), ("height".to_string(), "jpg")];
        let t = texture_config(&pairs(&[("id", "m"), ("normal_convention", "directx")]), &maps).unwrap();
        assert_eq!(
            t.map_images().collect::<Vec<_>>(),
            [("height", "m.map.height.jpg"), ("normal", "m.map.normal.png")]
        );
        assert!(texture_config(&pairs(&[("id", "m")]), &maps).is_err(), "a normal map without its convention");
        assert!(texture_config(&pairs(&[("id", "m")]), &[("uv".to_string(), "png")]).is_err(), "a reserved name");
    }

    #[test]
    fn the_token_must_match_exactly() {
        let t = "0123456789abcdef";
        for right in [&b"Bearer 0123456789abcdef"[..], b"bearer 0123456789abcdef", b"BEARER  0123456789abcdef"] {
            assert!(authorized(t, Some(right)), "{}", String::from_utf8_lossy(right));
        }
        for wrong in [&b"Bearer 0123456789abcdeg"[..], b"Bearer0123456789abcdef", b"0123456789abcdef", b"Bearer "] {
            assert!(!authorized(t, Some(wrong)));
        }
        assert!(!authorized(t, None));
        assert!(!authorized("", Some(b"Bearer ")));
    }

    #[test]
    fn store_list_and_remove_leave_no_orphans() {
        let d = tempfile::tempdir().unwrap();
        let dir = d.path().join(UPLOADS_DIR);
        let t = texture_config(&pairs(&[("id", "one"), ("name", "One")]), &[("height".to_string(), "png")]).unwrap();
        store(&dir, &t, b"\x89PNG fake", "png", &[("one.map.height.png".into(), b"height".to_vec())]).unwrap();
        let orphan = std::fs::File::create(dir.join("orphan.jpg")).unwrap();
        orphan.set_modified(std::time::SystemTime::now() - 2 * ORPHAN_AGE).unwrap();
        std::fs::write(dir.join("fresh.jpg"), b"x").unwrap();
        let listed = stored(&dir, &|_| {});
        assert_eq!(listed.len(), 1);
        assert_eq!(listed[0].name, "One");
        assert_eq!(std::fs::read(&listed[0].exemplar).unwrap(), b"\x89PNG fake");
        assert_eq!(std::fs::read(listed[0].map_images().next().unwrap().1).unwrap(), b"height");
        assert!(!dir.join("orphan.jpg").exists());
        assert!(dir.join("fresh.jpg").exists(), "a file just written may be an upload in progress");
        remove_record(&dir, "one").unwrap();
        remove_files(&dir, d.path(), "one");
        assert!(stored(&dir, &|_| {}).is_empty());
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
    }
}
