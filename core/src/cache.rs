//! The pyramidal cache (Wei & Levoy 2003; design note §1.7): synthesized pixels kept per level
//! and per *generation* (0 = upsampled and jittered, `k` = after correction subpass `k`) in
//! aligned square blocks, so that neighbouring and overlapping requests share their coarse
//! levels and their padding instead of recomputing them.
//!
//! Every pixel's value at a generation is a function of the previous generation's values around
//! it only (design note §1.5), so a value from the cache is the value a cold synthesis computes:
//! what is cached changes the work done, never the result. [`crate::modes::synth::window`] asks for the blocks
//! a window's plan touches, computes only the pixels no block holds (and what those need), and
//! offers back every block it now knows completely.
//!
//! The same byte bound holds everything else a render derives and keeps: the coordinates of the
//! last windows synthesized (another map of the same tile costs lookups only) and the texel
//! stacks derived from a texture on first use (an exemplar's or a map's box means at every
//! scale, a map's low-pass) — all counted in [`PyramidStats::bytes`] and evicted, least recently
//! used first, to stay within the limit.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};

use lru::LruCache;

use crate::geom::Rect;

/// Side of a cached block in pixels of its level. Even, so that parity classes line up with
/// block origins.
pub const BLOCK: i64 = 32;

/// Bytes charged for a block besides its coordinates (key, map slot, allocation).
const BLOCK_OVERHEAD: u64 = 96;

/// One synthesis stream: an analysis with the parameters that determine its pixels. Blocks of
/// different streams never mix.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct StreamId([u8; 16]);

impl StreamId {
    /// The stream named by `identity`: everything that determines its pixels (mode, mode
    /// version, analysis id, canonical parameters).
    pub fn new(identity: &str) -> Self {
        let h = blake3::hash(identity.as_bytes());
        let mut id = [0u8; 16];
        id.copy_from_slice(&h.as_bytes()[..16]);
        StreamId(id)
    }
}

/// Where a block sits: stream, level and block indices (pixel `(x, y)` is in block
/// `(⌊x/BLOCK⌋, ⌊y/BLOCK⌋)`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) struct BlockKey {
    pub stream: StreamId,
    pub level: u32,
    pub bx: i64,
    pub by: i64,
}

/// A block's history: for each pixel the highest generation held (`lo`, −1: none); the
/// `BLOCK²` coordinates after generation 0, then for each generation `k ≥ 1` the coordinates of
/// the pixels its subpass updated (`class_len` each, row-major within the class). Entries of
/// pixels whose `lo` is below a generation are meaningless.
#[derive(Debug, Clone)]
pub(crate) struct Block {
    pub lo: Box<[i8]>,
    /// Smallest and largest entry of `lo`.
    pub min_lo: i8,
    pub max_lo: i8,
    pub class_len: usize,
    pub data: Box<[u32]>,
}

impl Block {
    /// A block from its parts.
    pub fn new(lo: Vec<i8>, class_len: usize, data: Vec<u32>) -> Self {
        let min_lo = lo.iter().copied().min().unwrap_or(-1);
        let max_lo = lo.iter().copied().max().unwrap_or(-1);
        Block { lo: lo.into_boxed_slice(), min_lo, max_lo, class_len, data: data.into_boxed_slice() }
    }

    /// The generation-`k` array (`k ≥ 1`: the pixels of that subpass's class).
    pub fn generation(&self, k: usize) -> &[u32] {
        let n = (BLOCK * BLOCK) as usize;
        if k == 0 {
            &self.data[..n]
        } else {
            let start = n + (k - 1) * self.class_len;
            &self.data[start..start + self.class_len]
        }
    }

    fn bytes(&self) -> u64 {
        self.data.len() as u64 * 4 + self.lo.len() as u64 + BLOCK_OVERHEAD
    }
}

/// Counters of a [`Pyramid`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PyramidStats {
    /// Block lookups answered from the cache.
    pub hits: u64,
    /// Block lookups that found nothing.
    pub misses: u64,
    /// Blocks dropped to stay within the byte limit.
    pub evictions: u64,
    /// Bytes held.
    pub bytes: u64,
    /// Blocks held.
    pub blocks: u64,
}

/// Texel stacks derived from a texture on first use: each level row-major, keyed by what they
/// are of (see [`Pyramid::derived`]).
pub type Stack = Arc<Vec<Vec<[u8; 3]>>>;

/// Finished windows a cache keeps, besides its blocks: the coordinates of the last windows
/// rendered, so that another map of the same tile (issue 39) costs only lookups. At most
/// [`WINDOW_PIXELS`] each (a `@2x` tile).
const WINDOWS: usize = 16;
/// Largest window whose coordinates are kept.
const WINDOW_PIXELS: usize = 512 * 512;
/// Bytes charged for a kept window or stack besides its data.
const ENTRY_OVERHEAD: u64 = 128;

/// A window's coordinates: stream, level and pixels.
type WindowKey = (StreamId, u32, Rect);

/// What a cache holds, under one byte count.
struct Lru {
    map: LruCache<BlockKey, Arc<Block>>,
    windows: LruCache<WindowKey, Arc<[u32]>>,
    stacks: LruCache<String, Stack>,
    bytes: u64,
}

fn window_bytes(coords: &[u32]) -> u64 {
    coords.len() as u64 * 4 + ENTRY_OVERHEAD
}

fn stack_bytes(stack: &Stack) -> u64 {
    stack.iter().map(|l| l.len() as u64 * 3).sum::<u64>() + ENTRY_OVERHEAD
}

impl Lru {
    /// Evict, least recently used first — blocks, then windows, then stacks (the dearest to
    /// derive again) — until at most `limit` bytes are held; the number of blocks evicted.
    fn evict_to(&mut self, limit: u64) -> u64 {
        let mut evicted = 0;
        while self.bytes > limit {
            if let Some((_, old)) = self.map.pop_lru() {
                self.bytes -= old.bytes();
                evicted += 1;
            } else if let Some((_, old)) = self.windows.pop_lru() {
                self.bytes -= window_bytes(&old);
            } else if let Some((_, old)) = self.stacks.pop_lru() {
                self.bytes -= stack_bytes(&old);
            } else {
                break;
            }
        }
        evicted
    }
}

/// A byte-bounded, thread-safe LRU of synthesized blocks shared by any number of streams, with
/// the coordinates of the last [`WINDOWS`] windows synthesized and the texel stacks renders
/// derive, all within one limit. A limit of 0 turns it off: nothing is kept and every
/// synthesis starts cold.
pub struct Pyramid {
    lru: Mutex<Lru>,
    limit: u64,
    hits: AtomicU64,
    misses: AtomicU64,
    evictions: AtomicU64,
}

impl Pyramid {
    /// A cache holding at most `limit` bytes.
    pub fn new(limit: u64) -> Self {
        let windows = std::num::NonZeroUsize::new(WINDOWS).map_or_else(LruCache::unbounded, LruCache::new);
        Pyramid {
            lru: Mutex::new(Lru { map: LruCache::unbounded(), windows, stacks: LruCache::unbounded(), bytes: 0 }),
            limit,
            hits: AtomicU64::new(0),
            misses: AtomicU64::new(0),
            evictions: AtomicU64::new(0),
        }
    }

    /// No cache: every synthesis computes everything it needs.
    pub fn off() -> Self {
        Pyramid::new(0)
    }

    /// Bytes it may hold.
    pub fn limit(&self) -> u64 {
        self.limit
    }

    /// True when blocks are kept.
    pub fn is_on(&self) -> bool {
        self.limit > 0
    }

    /// Current counters.
    pub fn stats(&self) -> PyramidStats {
        let g = self.lock();
        PyramidStats {
            hits: self.hits.load(Ordering::Relaxed),
            misses: self.misses.load(Ordering::Relaxed),
            evictions: self.evictions.load(Ordering::Relaxed),
            bytes: g.bytes,
            blocks: g.map.len() as u64,
        }
    }

    fn lock(&self) -> MutexGuard<'_, Lru> {
        // A panic while holding the lock cannot leave the map inconsistent (single calls into
        // `LruCache`), so a poisoned lock is still usable.
        self.lru.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The coordinates of a finished window, when kept.
    pub(crate) fn window(&self, key: &WindowKey) -> Option<Arc<[u32]>> {
        if !self.is_on() {
            return None;
        }
        self.lock().windows.get(key).cloned()
    }

    /// Keep a finished window's coordinates (the least recently used of [`WINDOWS`] goes, and
    /// whatever the byte limit asks).
    pub(crate) fn keep_window(&self, key: WindowKey, coords: Arc<[u32]>) {
        if !self.is_on() || coords.len() > WINDOW_PIXELS {
            return;
        }
        let mut g = self.lock();
        g.bytes += window_bytes(&coords);
        if let Some((_, old)) = g.windows.push(key, coords) {
            g.bytes -= window_bytes(&old);
        }
        let evicted = g.evict_to(self.limit);
        self.evictions.fetch_add(evicted, Ordering::Relaxed);
    }

    /// The texel stack called `key` (everything it is derived from, by id or hash), derived by
    /// `make` on first use and kept within the limit; derived afresh each time when the cache
    /// is off or it was evicted.
    pub fn derived(&self, key: &str, make: impl FnOnce() -> Vec<Vec<[u8; 3]>>) -> Stack {
        if !self.is_on() {
            return Arc::new(make());
        }
        if let Some(s) = self.lock().stacks.get(key) {
            return s.clone();
        }
        let stack: Stack = Arc::new(make());
        let mut g = self.lock();
        g.bytes += stack_bytes(&stack);
        if let Some(old) = g.stacks.put(key.to_string(), stack.clone()) {
            g.bytes -= stack_bytes(&old);
        }
        let evicted = g.evict_to(self.limit);
        self.evictions.fetch_add(evicted, Ordering::Relaxed);
        stack
    }

    /// The blocks of `level` covering `r`, row-major over the block grid of `r` (see
    /// [`BlockGrid`]); `None` where nothing is cached.
    pub(crate) fn lookup(&self, stream: StreamId, level: u32, grid: &BlockGrid) -> Vec<Option<Arc<Block>>> {
        let n = grid.nbx * grid.nby;
        if !self.is_on() {
            return vec![None; n];
        }
        let mut out = Vec::with_capacity(n);
        let mut g = self.lock();
        for j in 0..grid.nby {
            for i in 0..grid.nbx {
                let key = BlockKey { stream, level, bx: grid.bx0 + i as i64, by: grid.by0 + j as i64 };
                out.push(g.map.get(&key).cloned());
            }
        }
        drop(g);
        let hits = out.iter().filter(|b| b.is_some()).count() as u64;
        self.hits.fetch_add(hits, Ordering::Relaxed);
        self.misses.fetch_add(n as u64 - hits, Ordering::Relaxed);
        out
    }

    /// Keep `blocks` (each replacing the history of the same block it was merged from),
    /// evicting the least recently used beyond the limit.
    pub(crate) fn store(&self, blocks: Vec<(BlockKey, Block)>) {
        if !self.is_on() || blocks.is_empty() {
            return;
        }
        let mut g = self.lock();
        for (key, block) in blocks {
            g.bytes += block.bytes();
            if let Some(old) = g.map.put(key, Arc::new(block)) {
                g.bytes -= old.bytes();
            }
        }
        let evicted = g.evict_to(self.limit);
        self.evictions.fetch_add(evicted, Ordering::Relaxed);
    }
}

/// The aligned blocks overlapping a rectangle.
#[derive(Debug, Clone, Copy)]
pub(crate) struct BlockGrid {
    pub bx0: i64,
    pub by0: i64,
    pub nbx: usize,
    pub nby: usize,
}

impl BlockGrid {
    /// The blocks overlapping `r` (non-empty).
    pub fn covering(r: Rect) -> Self {
        let (bx0, by0) = (r.x0.div_euclid(BLOCK), r.y0.div_euclid(BLOCK));
        let (bx1, by1) = ((r.x1 - 1).div_euclid(BLOCK) + 1, (r.y1 - 1).div_euclid(BLOCK) + 1);
        BlockGrid { bx0, by0, nbx: (bx1 - bx0) as usize, nby: (by1 - by0) as usize }
    }

    /// The pixels of block `(i, j)` of the grid.
    pub fn rect(&self, i: usize, j: usize) -> Rect {
        Rect::new((self.bx0 + i as i64) * BLOCK, (self.by0 + j as i64) * BLOCK, BLOCK, BLOCK)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stack(levels: usize, texels: usize) -> Vec<Vec<[u8; 3]>> {
        (0..levels).map(|l| vec![[l as u8; 3]; texels]).collect()
    }

    #[test]
    fn windows_and_derived_stacks_are_counted_and_evicted_within_the_limit() {
        let cache = Pyramid::new(1 << 20);
        // Derived once, then found.
        let made = std::cell::Cell::new(0);
        let make = || {
            made.set(made.get() + 1);
            stack(4, 40_000)
        };
        let a = cache.derived("a", make);
        assert_eq!(cache.derived("a", make), a);
        assert_eq!(made.get(), 1);
        assert_eq!(cache.stats().bytes, stack_bytes(&a));
        // Windows count too, and everything stays within the limit: the least recently used
        // goes (blocks first, then windows, then stacks).
        let stream = StreamId::new("s");
        for i in 0..12 {
            cache.keep_window((stream, 7, Rect::new(i * 300, 0, 256, 256)), vec![0u32; 256 * 256].into());
            assert!(cache.stats().bytes <= cache.limit(), "{:?}", cache.stats());
        }
        assert!(cache.window(&(stream, 7, Rect::new(11 * 300, 0, 256, 256))).is_some(), "the newest window is kept");
        assert!(cache.window(&(stream, 7, Rect::new(0, 0, 256, 256))).is_none(), "the oldest window went");
        let b = cache.derived("b", || stack(4, 60_000));
        assert!(cache.stats().bytes <= cache.limit());
        assert_eq!(b.len(), 4);
        // A cache that is off keeps nothing and derives each time.
        let off = Pyramid::off();
        off.derived("a", make);
        off.derived("a", make);
        assert_eq!((made.get(), off.stats().bytes), (3, 0));
    }
}
