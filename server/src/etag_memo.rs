//! The ETags of recent tile requests by their URL, so that a repeated request of a cached tile
//! — the hot path of a tile server: a browser's or CDN's revalidation, or a popular tile — is
//! answered without parsing its parameters or hashing its cache key again. An entry holds what
//! the ETag was computed from besides the URL: the catalogue's generation and, for each
//! texture it renders (a landscape's layers), the analysis hash and prepared state the key
//! named. It is used only while all of them are unchanged, so a memoised answer is always the
//! one the full path would give.

use std::num::NonZeroUsize;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

use crate::textures::Texture;

/// Entries kept (about 200 bytes each).
const ENTRIES: usize = 8192;

/// What a texture's part of an ETag was computed from, besides the request: the texture and
/// mode, its analysis hash and the mode's prepared state's ETag then.
pub struct Stamp {
    tex: Arc<Texture>,
    mode: &'static str,
    analysis: Option<Box<str>>,
    prepared: String,
}

impl Stamp {
    /// Texture `tex` rendered by `mode`, as it stands now.
    pub fn new(tex: &Arc<Texture>, mode: &'static str) -> Stamp {
        Stamp { tex: tex.clone(), mode, analysis: tex.file_hash().map(Into::into), prepared: tex.prepared.etag(mode) }
    }

    fn holds(&self) -> bool {
        self.tex.file_hash() == self.analysis.as_deref() && self.tex.prepared.etag(self.mode) == self.prepared
    }
}

/// A memoised answer: its ETag and content type.
pub struct Memo {
    /// The strong ETag.
    pub etag: Arc<str>,
    /// Its media type.
    pub content_type: &'static str,
    generation: u64,
    stamps: Vec<Stamp>,
}

/// The memo's key of the tile at `path` (`{id}/{z}/{x}/{y}`, after `/tiles/`) with `query`:
/// the tile route and the hot path (`http::hot_tiles`) must name a request alike.
pub fn url_key(path: &str, query: Option<&str>) -> String {
    format!("{path}?{}", query.unwrap_or(""))
}

/// Recent tile URLs and their ETags.
pub struct EtagMemo {
    entries: Mutex<lru::LruCache<Box<str>, Arc<Memo>>>,
    /// Bumped whenever the catalogue is replaced.
    generation: AtomicU64,
}

impl Default for EtagMemo {
    fn default() -> Self {
        EtagMemo {
            entries: Mutex::new(lru::LruCache::new(NonZeroUsize::new(ENTRIES).unwrap_or(NonZeroUsize::MIN))),
            generation: AtomicU64::new(0),
        }
    }
}

impl EtagMemo {
    /// The catalogue's generation now: read before the catalogue itself.
    pub fn generation(&self) -> u64 {
        self.generation.load(Ordering::Acquire)
    }

    /// The catalogue was replaced: every entry is stale.
    pub fn catalogue_changed(&self) {
        self.generation.fetch_add(1, Ordering::AcqRel);
    }

    /// The memo of `url`, if it holds for `generation` and the textures' states.
    pub fn get(&self, url: &str, generation: u64) -> Option<Arc<Memo>> {
        let m = self.entries.lock().unwrap_or_else(|e| e.into_inner()).get(url).cloned()?;
        (m.generation == generation && m.stamps.iter().all(Stamp::holds)).then_some(m)
    }

    /// Remember the answer of `url` computed in `generation` from the textures of `stamps`.
    pub fn put(&self, url: &str, generation: u64, etag: &str, content_type: &'static str, stamps: Vec<Stamp>) {
        let memo = Memo { etag: etag.into(), content_type, generation, stamps };
        self.entries.lock().unwrap_or_else(|e| e.into_inner()).put(url.into(), Arc::new(memo));
    }
}
