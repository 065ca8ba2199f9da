//! A byte-bounded memo: the LRU a prepared state keeps its serving caches in (the umbrella
//! mode's cell lists and merged levels of detail, its colour calibrations), so that what a
//! texture holds is bounded, counted and adjustable ([`crate::prepare::Preparation::limit_caches`])
//! rather than sitting in process-wide tables.

use std::hash::Hash;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

use lru::LruCache;

type Held<K, V> = (LruCache<K, (V, u64)>, u64);

/// An LRU map from `K` to `V` holding at most a limit of bytes (each entry's charged size
/// given when it is put); cheap values are cloned out (`Arc`s, small arrays).
pub struct Memo<K: Hash + Eq, V: Clone> {
    /// Entries with their charged bytes, and the bytes held.
    map: Mutex<Held<K, V>>,
    limit: AtomicU64,
}

impl<K: Hash + Eq, V: Clone> Memo<K, V> {
    /// An empty memo of at most `limit` bytes.
    pub fn new(limit: u64) -> Self {
        Memo { map: Mutex::new((LruCache::unbounded(), 0)), limit: AtomicU64::new(limit) }
    }

    /// The value of `key`, if held (made the most recently used).
    pub fn get(&self, key: &K) -> Option<V> {
        self.map.lock().ok()?.0.get(key).map(|(v, _)| v.clone())
    }

    /// Hold `value` for `key`, charged `bytes`; older entries go to make room (a value larger
    /// than the limit is not held).
    pub fn put(&self, key: K, value: V, bytes: u64) {
        let limit = self.limit.load(Ordering::Relaxed);
        let Ok(mut m) = self.map.lock() else { return };
        let (map, held) = &mut *m;
        if let Some((_, old)) = map.pop(&key) {
            *held -= old;
        }
        if bytes > limit {
            return;
        }
        while *held + bytes > limit {
            match map.pop_lru() {
                Some((_, (_, b))) => *held -= b,
                None => break,
            }
        }
        map.put(key, (value, bytes));
        *held += bytes;
    }

    /// Bytes held.
    pub fn bytes(&self) -> u64 {
        self.map.lock().map(|m| m.1).unwrap_or(0)
    }

    /// Change the limit, evicting what no longer fits.
    pub fn set_limit(&self, limit: u64) {
        self.limit.store(limit, Ordering::Relaxed);
        let Ok(mut m) = self.map.lock() else { return };
        let (map, held) = &mut *m;
        while *held > limit {
            match map.pop_lru() {
                Some((_, (_, b))) => *held -= b,
                None => break,
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Memo;

    #[test]
    fn a_memo_evicts_the_least_recently_used_to_stay_under_its_limit() {
        let m: Memo<u32, u32> = Memo::new(100);
        m.put(1, 10, 40);
        m.put(2, 20, 40);
        assert_eq!(m.get(&1), Some(10));
        m.put(3, 30, 40);
        assert_eq!((m.get(&1), m.get(&2), m.get(&3)), (Some(10), None, Some(30)));
        assert_eq!(m.bytes(), 80);
        m.put(4, 40, 101);
        assert_eq!((m.get(&4), m.bytes()), (None, 80));
        m.set_limit(50);
        assert_eq!((m.get(&1), m.get(&3), m.bytes()), (None, Some(30), 40));
        m.set_limit(0);
        assert_eq!(m.bytes(), 0);
    }
}
