//! The texture registry: for each configured texture, its exemplar (embedded or from disk), its
//! analysis (loaded from the data directory when current, recomputed and stored atomically when
//! missing, stale or damaged) and the defaults requests fall back to. Loading has two phases:
//! [`prepare_registry`] decodes every exemplar (fast: modes that need only the exemplar can
//! serve at once), then [`analyse_registry`] loads or computes each analysis.

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Arc, OnceLock};

use textile_core::{Analysis, Cancel, Defaults, Exemplar, ExemplarOptions, Progress, Source};

use crate::analysing;
use crate::config::{Config, TextureConfig};

/// Zoom steps served beyond native, magnified (design note §1.8); `@2x` tiles at the highest
/// zoom are rendered one step further, within [`textile_core::modes::magnify::MAX_ZOOM_IN`].
pub const MAGNIFY_STEPS: u32 = 3;

/// Exemplars compiled into the binary (`config/exemplars`; licences in LICENSE.md there).
const EMBEDDED: &[(&str, &[u8])] = &[
    ("gravel.png", include_bytes!("../../config/exemplars/gravel.png")),
    ("grass.png", include_bytes!("../../config/exemplars/grass.png")),
    ("brick.png", include_bytes!("../../config/exemplars/brick.png")),
    ("corkboard.png", include_bytes!("../../config/exemplars/corkboard.png")),
];

/// The bytes of an embedded exemplar.
pub fn embedded(name: &str) -> Option<&'static [u8]> {
    EMBEDDED.iter().find(|(n, _)| *n == name).map(|(_, b)| *b)
}

/// A texture ready to serve.
pub struct Texture {
    /// Its configuration.
    pub config: TextureConfig,
    /// The prepared exemplar.
    pub exemplar: Exemplar,
    /// The exemplar analysis and the hash of its stored bytes (part of the ETags of modes that
    /// need the analysis, and of the TileJSON version), once loaded or computed.
    pub analysis: OnceLock<(Arc<Analysis>, String)>,
    /// Hash of the prepared exemplar (side, toroidal flag, pixels): part of the ETags of modes
    /// that need only the exemplar, so a new analysis never expires their tiles.
    pub exemplar_hash: String,
    /// The prepared exemplar as PNG.
    pub exemplar_png: Vec<u8>,
    /// Parameters a request starts from: default mode, and each mode's configured defaults.
    pub defaults: Defaults,
    /// Analysis progress, in percent.
    pub progress: AtomicU32,
    /// Why the analysis failed, if it did.
    pub failure: OnceLock<String>,
    /// Set when the texture is removed from the catalogue: its analysis stops.
    pub removed: Cancel,
}

/// Where a texture stands: its analysis being computed, done, or failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// The analysis is being loaded or computed (modes that need only the exemplar serve).
    Analysing,
    /// Every mode serves.
    Ready,
    /// The analysis could not be computed.
    Failed,
}

impl Status {
    /// As the API writes it.
    pub fn as_str(self) -> &'static str {
        match self {
            Status::Analysing => "analysing",
            Status::Ready => "ready",
            Status::Failed => "failed",
        }
    }
}

impl Texture {
    /// A texture from its configuration (`index`: its place in the configuration, for errors)
    /// and prepared exemplar, without its analysis yet.
    pub fn prepare(config: TextureConfig, index: usize, exemplar: Exemplar) -> Result<Self, LoadError> {
        let m = exemplar.side;
        let rgb: Vec<u8> = exemplar.pixels.iter().flatten().copied().collect();
        let exemplar_png = crate::encode::encode(&rgb, m, m, crate::encode::Format::Png, crate::encode::Effort::Tight)
            .map_err(|e| LoadError::Core {
                id: config.id.clone(),
                source: textile_core::CoreError::ExemplarUndecodable(e.to_string()),
            })?;
        let src = Source { exemplar: &exemplar, analysis: None };
        let defaults = Defaults::configure(&src, &config.default_mode, config.default_seed, &config.mode_tables())
            .map_err(|source| LoadError::Defaults { id: config.id.clone(), index, source })?;
        let mut h = blake3::Hasher::new();
        exemplar.hash_content(&mut h);
        let exemplar_hash = h.finalize().to_hex()[..16].to_string();
        Ok(Texture {
            config,
            exemplar,
            analysis: OnceLock::new(),
            exemplar_hash,
            exemplar_png,
            defaults,
            progress: AtomicU32::new(0),
            failure: OnceLock::new(),
            removed: Cancel::default(),
        })
    }

    /// A texture with its analysis.
    pub fn new(config: TextureConfig, index: usize, exemplar: Exemplar, analysis: Analysis) -> Result<Self, LoadError> {
        let t = Texture::prepare(config, index, exemplar)?;
        t.set_analysis(analysis).map_err(|source| LoadError::Core { id: t.config.id.clone(), source })?;
        Ok(t)
    }

    /// Attach the analysis (once; later calls are ignored), with what it keeps with the
    /// exemplar (its randomness mask) attached to it: an analysis made for another mask is
    /// refused.
    pub fn set_analysis(&self, mut analysis: Analysis) -> Result<(), textile_core::CoreError> {
        analysis.attach(&self.exemplar)?;
        let hash = analysis.file_hash();
        self.progress.store(100, Ordering::Relaxed);
        let _ = self.analysis.set((Arc::new(analysis), hash));
        Ok(())
    }

    /// Where the texture stands.
    pub fn status(&self) -> Status {
        if self.analysis.get().is_some() {
            Status::Ready
        } else if self.failure.get().is_some() {
            Status::Failed
        } else {
            Status::Analysing
        }
    }

    /// The analysis, once available.
    pub fn analysis(&self) -> Option<&Arc<Analysis>> {
        self.analysis.get().map(|(a, _)| a)
    }

    /// The hash of the stored analysis, once available.
    pub fn file_hash(&self) -> Option<&str> {
        self.analysis.get().map(|(_, h)| h.as_str())
    }

    /// What the modes render from.
    pub fn source(&self) -> Source<'_> {
        Source { exemplar: &self.exemplar, analysis: self.analysis().map(|a| a.as_ref()) }
    }
    /// Zoom at which one tile pixel is one texel.
    pub fn native_zoom(&self) -> u32 {
        self.exemplar.side.trailing_zeros()
    }
    /// Smallest zoom served.
    pub fn min_zoom(&self) -> u32 {
        0
    }
    /// Largest zoom served: magnified [`MAGNIFY_STEPS`] steps beyond native.
    pub fn max_zoom(&self) -> u32 {
        self.native_zoom() + MAGNIFY_STEPS
    }
}

/// All served textures: configured ones in configuration order, then uploaded ones in upload
/// order. Never changed in place: a change makes a new registry ([`Registry::with`],
/// [`Registry::without`]) that replaces the old one whole.
pub struct Registry {
    /// Textures in catalogue order.
    pub list: Vec<Arc<Texture>>,
    by_id: HashMap<String, Arc<Texture>>,
}

impl Registry {
    /// A registry of these textures (ids unique).
    pub fn new(list: Vec<Arc<Texture>>) -> Self {
        let by_id = list.iter().map(|t| (t.config.id.clone(), t.clone())).collect();
        Registry { list, by_id }
    }

    /// This registry with `tex` added at the end.
    pub fn with(&self, tex: Arc<Texture>) -> Self {
        let mut list: Vec<_> = self.list.iter().filter(|t| t.config.id != tex.config.id).cloned().collect();
        list.push(tex);
        Registry::new(list)
    }

    /// This registry without the texture `id`.
    pub fn without(&self, id: &str) -> Self {
        Registry::new(self.list.iter().filter(|t| t.config.id != id).cloned().collect())
    }

    /// Uploaded textures in it.
    pub fn uploads(&self) -> usize {
        self.list.iter().filter(|t| t.config.uploaded).count()
    }

    /// The texture with this id.
    pub fn get(&self, id: &str) -> Option<&Arc<Texture>> {
        self.by_id.get(id)
    }
}

/// A texture that could not be prepared.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// The exemplar file is missing or unreadable.
    #[error("texture '{id}': cannot read exemplar {path}: {source}")]
    Read {
        /// Texture id.
        id: String,
        /// Exemplar path.
        path: PathBuf,
        /// Cause.
        source: std::io::Error,
    },
    /// `embedded:NAME` names no embedded exemplar.
    #[error("texture '{id}': no embedded exemplar '{name}' (have: gravel.png, grass.png, brick.png, corkboard.png)")]
    NoEmbedded {
        /// Texture id.
        id: String,
        /// The name asked for.
        name: String,
    },
    /// A configured default or setting is unusable for this exemplar.
    #[error("texture '{id}' (textures[{index}]): {source}")]
    Defaults {
        /// Texture id.
        id: String,
        /// Position in the configuration.
        index: usize,
        /// Cause.
        source: textile_core::modes::DefaultsError,
    },
    /// The exemplar path is not a regular file, or is larger than any exemplar can be.
    #[error("texture '{id}': exemplar {path}: {message}")]
    NotAnImageFile {
        /// Texture id.
        id: String,
        /// Exemplar path.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// Loading was stopped by a shutdown signal.
    #[error("loading stopped by a shutdown signal")]
    Stopped,
    /// An analysis ran out of its time budget.
    #[error("texture '{id}': {message}")]
    AnalysisTimeout {
        /// Texture id.
        id: String,
        /// What happened.
        message: String,
    },
    /// The exemplar or its analysis is unusable.
    #[error("texture '{id}': {source}")]
    Core {
        /// Texture id.
        id: String,
        /// Cause.
        source: textile_core::CoreError,
    },
}

/// Read the exemplar bytes a texture config names.
pub fn exemplar_bytes(cfg: &Config, t: &TextureConfig) -> Result<Vec<u8>, LoadError> {
    image_bytes(cfg, t, t.image())
}

/// Read the bytes of an image a texture config names (`embedded:NAME` or a path).
fn image_bytes(cfg: &Config, t: &TextureConfig, image: &str) -> Result<Vec<u8>, LoadError> {
    if let Some(name) = image.strip_prefix("embedded:") {
        return embedded(name)
            .map(|b| b.to_vec())
            .ok_or_else(|| LoadError::NoEmbedded { id: t.id.clone(), name: name.into() });
    }
    let path = cfg.base_dir.join(image);
    // Regular files only (a FIFO or device would block the read or never end), of a bounded size.
    let meta =
        std::fs::metadata(&path).map_err(|source| LoadError::Read { id: t.id.clone(), path: path.clone(), source })?;
    let bad = |message: String| LoadError::NotAnImageFile { id: t.id.clone(), path: path.clone(), message };
    if !meta.is_file() {
        return Err(bad("is not a regular file".into()));
    }
    if meta.len() > MAX_EXEMPLAR_FILE {
        return Err(bad(format!("is {} bytes; exemplar files are at most {MAX_EXEMPLAR_FILE}", meta.len())));
    }
    std::fs::read(&path).map_err(|source| LoadError::Read { id: t.id.clone(), path, source })
}

/// Largest exemplar file read (bytes): far beyond any accepted exemplar side, compressed.
const MAX_EXEMPLAR_FILE: u64 = 256 << 20;

/// Remove temporary analysis files (`.ID.tex.tmp-PID`) left by processes that no longer run
/// (killed while writing); those of live processes (another replica sharing the directory) stay.
fn remove_stale_temp_files(dir: &std::path::Path, log: &dyn Fn(String)) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if !(name.starts_with('.') && (name.contains(".tex.tmp-") || name.contains(".umbrella.tmp-"))) {
            continue;
        }
        if textile_core::files::writer_alive(&name) != Some(true) && std::fs::remove_file(e.path()).is_ok() {
            log(format!("removed {}, left by an interrupted analysis", e.path().display()));
        }
    }
}

/// Whether analyses can be stored in `dir` (created if missing): a probe file is written and
/// removed.
fn writable(dir: &std::path::Path) -> Result<(), std::io::Error> {
    std::fs::create_dir_all(dir)?;
    let probe = dir.join(format!(".probe-{}", std::process::id()));
    std::fs::write(&probe, b"textile")?;
    std::fs::remove_file(&probe)
}

/// Decode one texture's exemplar from its bytes: a texture without its analysis yet (`index`:
/// its place in the configuration, for errors). `log` hears of any crop or resize.
pub fn prepare_texture(
    cfg: &Config,
    t: &TextureConfig,
    index: usize,
    bytes: &[u8],
    log: &dyn Fn(String),
) -> Result<Texture, LoadError> {
    // A lattice tiles the exemplar, which therefore wraps around.
    let toroidal = if t.lattice.is_some() { Some(true) } else { t.toroidal.as_option() };
    let opts = ExemplarOptions { max_input_side: cfg.max_exemplar_side, toroidal };
    let core = |source| LoadError::Core { id: t.id.clone(), source };
    let mut ex = Exemplar::from_bytes(bytes, &opts).map_err(core)?;
    ex.check_not_flat().map_err(core)?;
    // The mask is prepared like the exemplar's image, so that they stay aligned.
    let mask = match &t.randomness_mask {
        Some(path) => Some(Exemplar::from_bytes(&image_bytes(cfg, t, path)?, &opts).map_err(core)?),
        None => None,
    };
    if t.exemplar_hires.is_some() {
        ex = Exemplar::from_hires(ex).map_err(core)?;
        let (m, big) = (ex.side, 2 * ex.side);
        log(format!("texture '{}': exemplar {m}x{m} reduced from its {big}x{big} exemplar_hires", t.id));
    }
    if t.toroidal == crate::config::Toroidal::Synthesize {
        let started = std::time::Instant::now();
        ex = textile_core::tileable::make_toroidal(&ex, 0).map_err(core)?;
        log(format!(
            "texture '{}': exemplar made toroidal by synthesis (toroidal = \"synthesize\") in {:.2}s",
            t.id,
            started.elapsed().as_secs_f64()
        ));
    }
    if let Some([nx, ny]) = t.lattice {
        ex = ex.with_lattice(nx, ny).map_err(core)?;
    }
    if let Some(mask) = &mask {
        ex = ex.with_randomness_mask(mask).map_err(core)?;
    }
    if let Some(set) = &t.umbrellas {
        let json = image_bytes(cfg, t, set)?;
        // The set's images are named relative to the set file.
        let dir = std::path::Path::new(set).parent().unwrap_or(std::path::Path::new(""));
        let read = |name: &str| {
            image_bytes(cfg, t, &dir.join(name).to_string_lossy())
                .map_err(|e| textile_core::CoreError::Param { name: "umbrellas", message: e.to_string() })
        };
        let set_elements = textile_core::modes::umbrella::handmade::load(&json, &read).map_err(core)?;
        log(format!("texture '{}': hand-made umbrella set {set} ({} bases)", t.id, set_elements.bases.len()));
        ex = ex.with_umbrella_set(set_elements);
    }
    let prep = &ex.preparation;
    if prep.input_width != prep.input_height || prep.crop_side != ex.side {
        log(format!(
            "texture '{}': exemplar {}x{} {}resized to {}x{} (exemplars are used as power-of-two squares)",
            t.id,
            prep.input_width,
            prep.input_height,
            if prep.input_width != prep.input_height {
                format!("cropped to its central {0}x{0} and ", prep.crop_side)
            } else {
                String::new()
            },
            ex.side,
            ex.side
        ));
    }
    Texture::prepare(t.clone(), index, ex)
}

/// Decode every texture's exemplar: a registry whose textures have no analysis yet. A
/// configured texture that cannot be prepared is an error; an uploaded one (which was checked
/// when it was uploaded) is skipped with a warning, so a changed limit cannot stop the service.
/// `log` receives one line per event.
pub fn prepare_registry(cfg: &Config, log: &dyn Fn(String)) -> Result<Registry, LoadError> {
    let mut list = Vec::new();
    for (index, t) in cfg.textures.iter().enumerate() {
        let prepared = exemplar_bytes(cfg, t).and_then(|bytes| prepare_texture(cfg, t, index, &bytes, log));
        match prepared {
            Ok(tex) => list.push(Arc::new(tex)),
            Err(e) if t.uploaded => log(format!("warning: uploaded {e}; not served")),
            Err(e) => return Err(e),
        }
    }
    Ok(Registry::new(list))
}

/// Load or compute the analysis of every texture of a prepared registry that `which` selects,
/// in configuration order (each texture serves its analysis-needing modes as soon as its own is
/// attached), each watched by an [`analysing::Watch`]: `stop` is asked between textures and
/// during each analysis, and ends the loading with [`LoadError::Stopped`] once it is set;
/// an analysis longer than `analysis_timeout_secs` ends it with [`LoadError::AnalysisTimeout`].
///
/// The data directory is checked first: stale temporary files of interrupted writes are removed,
/// and if analyses cannot be stored there (read-only, full, not a directory) the server warns
/// and keeps them in memory only (recomputed at each start) rather than exit after computing them.
pub fn analyse_registry(
    cfg: &Config,
    reg: &Registry,
    which: &dyn Fn(&Texture) -> bool,
    log: &dyn Fn(String),
    stop: &Cancel,
) -> Result<(), LoadError> {
    let data_dir = cfg.data_dir();
    let storable = data_dir_storable(cfg, log);
    let budget = std::time::Duration::from_secs(cfg.analysis_timeout_secs);
    for tex in reg.list.iter().filter(|t| which(t)) {
        if stop.is_set() {
            return Err(LoadError::Stopped);
        }
        let watch = analysing::Watch::new(&tex.config.id, &tex.progress, &tex.removed, stop, budget);
        match analyse_texture(&data_dir, storable, tex, log, &watch, watch.cancel()) {
            Ok(()) => {}
            Err(textile_core::CoreError::Cancelled) if watch.timed_out() => {
                return Err(LoadError::AnalysisTimeout { id: tex.config.id.clone(), message: watch.timeout_message() })
            }
            // Removed meanwhile (DELETE): nothing of it is kept; on to the next.
            Err(textile_core::CoreError::Cancelled) if tex.removed.is_set() => {}
            Err(textile_core::CoreError::Cancelled) => return Err(LoadError::Stopped),
            Err(source) => return Err(LoadError::Core { id: tex.config.id.clone(), source }),
        }
    }
    Ok(())
}

/// Whether `data_dir` holds an analysis of `tex` that is current (by its header: loading it
/// still checks the whole file).
pub fn has_current_analysis(data_dir: &std::path::Path, tex: &Texture) -> bool {
    let path = data_dir.join(format!("{}.tex", tex.config.id));
    Analysis::read_header(&path).is_ok_and(|h| h.id == Analysis::id_for(&tex.exemplar, tex.config.index))
}

/// Whether analyses can be stored in the data directory (checked first, with stale temporary
/// files of interrupted writes removed); if not, a warning is logged.
fn data_dir_storable(cfg: &Config, log: &dyn Fn(String)) -> bool {
    let data_dir = cfg.data_dir();
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

/// Load one texture's analysis from `data_dir` when it is current, else compute it (stopped
/// when `progress` says so) and store it there if `storable`; then attach it to the texture.
pub fn analyse_texture(
    data_dir: &std::path::Path,
    storable: bool,
    tex: &Texture,
    log: &dyn Fn(String),
    progress: &dyn Progress,
    cancel: &Cancel,
) -> Result<(), textile_core::CoreError> {
    let t = &tex.config;
    let ex = &tex.exemplar;
    let path = data_dir.join(format!("{}.tex", t.id));
    let expected = Analysis::id_for(ex, t.index);
    let analysis = match Analysis::load(&path) {
        Ok(a) if a.header.id == expected => {
            log(format!("texture '{}': loaded analysis {} from {}", t.id, a.header.id, path.display()));
            a
        }
        other => {
            match other {
                Ok(_) => log(format!("texture '{}': stored analysis is stale (exemplar changed); recomputing", t.id)),
                Err(textile_core::CoreError::Io { .. }) => {
                    log(format!("texture '{}': no stored analysis; computing", t.id))
                }
                Err(e) => log(format!("texture '{}': {e}; recomputing", t.id)),
            }
            let started = std::time::Instant::now();
            let a = Analysis::try_build_with(ex, t.index, progress, cancel)?;
            // A texture removed while it was analysed leaves nothing behind.
            let stored = if tex.removed.is_set() {
                "not stored (the texture was removed)".to_string()
            } else if storable {
                match a.save(&path) {
                    Ok(()) => format!("stored {}", path.display()),
                    Err(e) => format!("warning: not stored ({e}); kept in memory only"),
                }
            } else {
                "kept in memory only".to_string()
            };
            log(format!(
                "texture '{}': analysed {}x{} in {:.2}s, {stored}",
                t.id,
                a.side(),
                a.side(),
                started.elapsed().as_secs_f64()
            ));
            a
        }
    };
    // The umbrella mode's extraction, beside the analysis: read when current, else computed
    // (and stored) now rather than on the first umbrella request — before the texture is
    // ready, so that a ready texture has both files.
    let path = data_dir.join(format!("{}.umbrella", t.id));
    let store = storable && !tex.removed.is_set();
    let started = std::time::Instant::now();
    let (outcome, source) = textile_core::modes::umbrella::store::load_or_extract(ex, &path, store);
    let what = match &outcome {
        Ok(el) => format!("{} bases", el.bases.len()),
        Err(_) => "no elements".to_string(),
    };
    use textile_core::modes::umbrella::store::Source;
    match source {
        // Logged when the set was read.
        Source::HandMade => {}
        Source::Loaded => {
            log(format!("texture '{}': loaded umbrella extraction ({what}) from {}", t.id, path.display()))
        }
        Source::Stored => log(format!(
            "texture '{}': extracted umbrellas ({what}) in {:.2}s, stored {}",
            t.id,
            started.elapsed().as_secs_f64(),
            path.display()
        )),
        Source::Computed(why) => log(format!(
            "texture '{}': extracted umbrellas ({what}) in {:.2}s, {}",
            t.id,
            started.elapsed().as_secs_f64(),
            why.map_or("kept in memory only".to_string(), |e| format!(
                "warning: not stored ({e}); kept in memory only"
            ))
        )),
    }
    tex.set_analysis(analysis)?;
    Ok(())
}

/// Both phases: every texture with its analysis.
pub fn load_registry(cfg: &Config, log: &dyn Fn(String)) -> Result<Registry, LoadError> {
    let reg = prepare_registry(cfg, log)?;
    analyse_registry(cfg, &reg, &|_| true, log, &Cancel::new())?;
    Ok(reg)
}
