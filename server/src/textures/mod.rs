//! The texture catalogue: each served texture ([`Texture`]) — its configuration, prepared
//! exemplar, analysis, what its modes prepared, and the defaults requests fall back to — and
//! the parts that make one: [`storage`] (where exemplars and prepared files are read and
//! written), [`registry`] (the catalogue, decoded in one fast phase so that modes needing only
//! the exemplar serve at once), [`preparation`] (the analysis and every mode's preparation,
//! loaded when current, else computed in the background and stored), [`analysing`] (the
//! low-priority pool they run on), and [`lock`] (one server per data directory).

pub mod analysing;
pub mod landscape;
pub mod lock;
pub mod preparation;
pub mod registry;
pub mod storage;

use std::path::PathBuf;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Arc, OnceLock};

use textile_core::modes::Prepared;
use textile_core::{Analysis, Cancel, Defaults, Exemplar, Source};

use crate::config::TextureConfig;
pub use landscape::Landscape;
pub use preparation::{analyse_registry, analyse_texture, load_registry};
pub use registry::{prepare_registry, prepare_texture, Registry};
pub use storage::{embedded, exemplar_bytes, stored_extensions};

/// Zoom steps served beyond native, magnified (design note §1.8); `@2x` tiles at the highest
/// zoom are rendered one step further, within [`textile_core::modes::magnify::MAX_ZOOM_IN`].
pub const MAGNIFY_STEPS: u32 = 3;

/// The zooms a texture or landscape serves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Zooms {
    /// Smallest.
    pub min: u32,
    /// Largest.
    pub max: u32,
    /// Native (one pixel per texel).
    pub native: u32,
}

/// What an id names in the catalogue: a texture or a landscape.
#[derive(Clone)]
pub enum Served {
    /// A texture.
    Texture(Arc<Texture>),
    /// A landscape.
    Landscape(Arc<Landscape>),
}

impl Served {
    /// Its id.
    pub fn id(&self) -> &str {
        match self {
            Served::Texture(t) => &t.config.id,
            Served::Landscape(l) => &l.config.id,
        }
    }

    /// The zooms it serves.
    pub fn zooms(&self) -> Zooms {
        match self {
            Served::Texture(t) => t.zooms(),
            Served::Landscape(l) => l.zooms(),
        }
    }
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
    /// What its modes prepared (see [`textile_core::prepare`]), once loaded or computed.
    pub prepared: Prepared,
    /// Bytes of caches its prepared states may keep (a share of the memory budget, set when the
    /// registry changes: [`crate::state::AppState::set_registry`]).
    pub cache_limit: std::sync::atomic::AtomicU64,
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
        let (w, h) = (exemplar.width, exemplar.height);
        let rgb: Vec<u8> = exemplar.pixels.iter().flatten().copied().collect();
        let exemplar_png = crate::encode::encode(&rgb, w, h, crate::encode::Format::Png, crate::encode::Effort::Tight)
            .map_err(|e| LoadError::Core {
                id: config.id.clone(),
                source: textile_core::CoreError::ExemplarUndecodable(e.to_string()),
            })?;
        let src = Source::exemplar(&exemplar);
        let defaults = Defaults::configure(&src, &config.default_mode, config.default_seed, &config.mode_tables())
            .map_err(|source| LoadError::Defaults { id: config.id.clone(), index, source })?;
        let mut h = blake3::Hasher::new();
        exemplar.hash_content(&mut h);
        let exemplar_hash = h.finalize().to_hex()[..16].to_string();
        Ok(Texture {
            config,
            exemplar,
            analysis: OnceLock::new(),
            prepared: Prepared::new(),
            cache_limit: std::sync::atomic::AtomicU64::new(0),
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
        Source {
            exemplar: &self.exemplar,
            analysis: self.analysis().map(|a| a.as_ref()),
            prepared: Some(&self.prepared),
            map: None,
        }
    }

    /// Bytes it holds in memory: its exemplar (and high-resolution and PNG copies), its
    /// material maps, its analysis, and its modes' prepared states with their caches. What
    /// requests derive from it (box-mean stacks, low-passes) is held by the pyramidal cache,
    /// within its limit.
    pub fn held_bytes(&self) -> u64 {
        let texels = |v: &[[u8; 3]]| v.len() as u64 * 3;
        let ex = &self.exemplar;
        let maps: u64 = ex.maps.iter().map(|m| texels(&m.texels) + m.hires.as_deref().map_or(0, texels)).sum();
        let analysis = self.analysis().map_or(0, |a| <Analysis as textile_core::prepare::Preparation>::memory_bytes(a));
        texels(&ex.pixels)
            + ex.hires.as_deref().map_or(0, texels)
            + self.exemplar_png.len() as u64
            + maps
            + analysis
            + self.prepared.memory_bytes()
    }

    /// Let its prepared states keep at most `bytes` of caches.
    pub fn limit_caches(&self, bytes: u64) {
        self.cache_limit.store(bytes, Ordering::Relaxed);
        for (_, state) in self.prepared.all() {
            state.limit_caches(bytes);
        }
    }
    /// Zoom at which one tile pixel is one texel: `⌈log2⌉` of the exemplar's longer side (a
    /// whole exemplar fits in one tile at zoom 0).
    pub fn native_zoom(&self) -> u32 {
        self.exemplar.levels()
    }
    /// The zooms it serves.
    pub fn zooms(&self) -> Zooms {
        Zooms { min: self.min_zoom(), max: self.max_zoom(), native: self.native_zoom() }
    }
    /// Metres per unit of height in its raster-dem tiles, unless a request says: configured,
    /// else [`crate::terrain::default_height_scale`] of its native zoom.
    pub fn height_scale(&self) -> f64 {
        self.config.height_scale.unwrap_or_else(|| crate::terrain::default_height_scale(self.native_zoom()))
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
    #[error("texture '{id}': no embedded image '{name}' (have: {})", storage::embedded_names().join(", "))]
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
    /// A landscape cannot be made from its configuration.
    #[error("landscape '{id}': key '{field}': {message}")]
    Landscape {
        /// Landscape id.
        id: String,
        /// The key at fault.
        field: String,
        /// What is wrong.
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
