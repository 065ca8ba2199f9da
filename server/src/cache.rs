//! The encoded-tile cache: an LRU (the `lru` crate) bounded by bytes, with single-flight so that
//! concurrent requests for one key cause one synthesis and all receive its result.

use std::collections::HashMap;
use std::future::Future;
use std::sync::{Arc, Mutex};

use axum::body::Bytes;
use lru::LruCache;
use prometheus::{IntCounter, IntGauge};
use tokio::sync::OnceCell;

use crate::error::ApiError;

type Flight = Arc<OnceCell<Result<Bytes, ApiError>>>;

struct Lru {
    map: LruCache<String, Bytes>,
    bytes: u64,
}

/// Counters and gauges of the cache (Prometheus handles, shared with the metrics registry).
#[derive(Clone)]
pub struct CacheStats {
    /// Answers served from the cache.
    pub hits: IntCounter,
    /// Answers not in the cache.
    pub misses: IntCounter,
    /// Entries evicted to stay under the byte limit.
    pub evictions: IntCounter,
    /// Bytes held.
    pub bytes: IntGauge,
    /// Entries held.
    pub entries: IntGauge,
}

impl CacheStats {
    /// Handles not registered anywhere (for a cache used on its own).
    pub fn unregistered() -> Self {
        let c = |n: &str| IntCounter::new(n, n).unwrap_or_else(|e| panic!("{e}"));
        let g = |n: &str| IntGauge::new(n, n).unwrap_or_else(|e| panic!("{e}"));
        CacheStats { hits: c("h"), misses: c("m"), evictions: c("e"), bytes: g("b"), entries: g("n") }
    }
}

/// Byte-bounded LRU of encoded images with request coalescing.
pub struct TileCache {
    lru: Mutex<Lru>,
    limit: u64,
    inflight: Mutex<HashMap<String, Flight>>,
    /// Counters.
    pub stats: CacheStats,
}

impl TileCache {
    /// A cache holding at most `limit` bytes of values (keys are small and not counted).
    pub fn new(limit: u64, stats: CacheStats) -> Self {
        TileCache {
            lru: Mutex::new(Lru { map: LruCache::unbounded(), bytes: 0 }),
            limit,
            inflight: Mutex::new(HashMap::new()),
            stats,
        }
    }

    /// Entries and bytes held.
    pub fn usage(&self) -> (usize, u64) {
        let l = self.lru.lock().unwrap_or_else(|e| e.into_inner());
        (l.map.len(), l.bytes)
    }

    /// The cached value for `key`, counted as a hit; `None` when absent (not counted).
    pub fn peek(&self, key: &str) -> Option<Bytes> {
        let v = self.get(key);
        if v.is_some() {
            self.stats.hits.inc();
        }
        v
    }

    fn get(&self, key: &str) -> Option<Bytes> {
        self.lru.lock().unwrap_or_else(|e| e.into_inner()).map.get(key).cloned()
    }

    fn insert(&self, key: &str, value: Bytes) {
        let size = value.len() as u64;
        if size > self.limit {
            return;
        }
        let mut l = self.lru.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(old) = l.map.put(key.to_string(), value) {
            l.bytes -= old.len() as u64;
        }
        l.bytes += size;
        while l.bytes > self.limit {
            match l.map.pop_lru() {
                Some((_, v)) => {
                    l.bytes -= v.len() as u64;
                    self.stats.evictions.inc();
                }
                None => break,
            }
        }
        self.stats.bytes.set(l.bytes as i64);
        self.stats.entries.set(l.map.len() as i64);
    }

    /// The cached value for `key`, or the result of `compute` — run once for all concurrent
    /// callers with the same key. Returns whether it was a cache hit. Errors are not cached.
    pub async fn get_or_compute<F, Fut>(&self, key: &str, compute: F) -> (Result<Bytes, ApiError>, bool)
    where
        F: FnOnce() -> Fut,
        Fut: Future<Output = Result<Bytes, ApiError>>,
    {
        if let Some(v) = self.get(key) {
            self.stats.hits.inc();
            return (Ok(v), true);
        }
        self.stats.misses.inc();
        let cell = {
            let mut m = self.inflight.lock().unwrap_or_else(|e| e.into_inner());
            m.entry(key.to_string()).or_default().clone()
        };
        let result = cell
            .get_or_init(|| async {
                let r = compute().await;
                if let Ok(b) = &r {
                    self.insert(key, b.clone());
                }
                r
            })
            .await
            .clone();
        {
            let mut m = self.inflight.lock().unwrap_or_else(|e| e.into_inner());
            if m.get(key).is_some_and(|c| Arc::ptr_eq(c, &cell)) {
                m.remove(key);
            }
        }
        (result, false)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[tokio::test]
    async fn evicts_by_bytes_and_coalesces() {
        let c = TileCache::new(10, CacheStats::unregistered());
        let (r, hit) = c.get_or_compute("a", || async { Ok(Bytes::from_static(b"123456")) }).await;
        assert_eq!((r.unwrap().len(), hit), (6, false));
        let (_, hit) = c.get_or_compute("a", || async { Err(ApiError::internal("not called")) }).await;
        assert!(hit);
        let _ = c.get_or_compute("b", || async { Ok(Bytes::from_static(b"123456")) }).await;
        assert_eq!(c.usage(), (1, 6));
        assert_eq!(c.stats.evictions.get(), 1);
    }
}
