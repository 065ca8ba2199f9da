//! Keeping resident memory close to what the service holds. With glibc's allocator, freed
//! per-request buffers and evicted cache entries otherwise stay in per-thread arenas, and the
//! dynamic mmap threshold moves large buffers onto those heaps: measured under the soak load
//! (64 MiB tile cache + 64 MiB pyramidal cache), resident memory settled at ~280 MiB without
//! these settings and ~255–263 MiB with them. Elsewhere they are no-ops.

use std::time::Duration;

/// Allocations from this size up get their own mapping, returned to the system when freed.
/// Not lower: a tile's own buffers (196 KiB of RGB, ~100 KiB of PNG) must stay on the heap —
/// at 128 KiB, mapping and faulting them in halved mosaic throughput (1 117 → 616 tiles/s).
const MMAP_THRESHOLD: i32 = 1024 * 1024;

/// Free memory at the top of a heap is kept up to this size instead of being handed back at
/// once (glibc's default: 128 KiB): every request allocates and frees ~2 MB of buffers, and
/// handing them back after each one made the next request fault them in again. Measured on the
/// mosaic pan load: 900–990 → 956–1 079 tiles/s; soak resident memory 259–269 MiB against
/// 258–267 without (8 MiB: 263–278). [`return_freed_memory`] still trims every few seconds.
const TRIM_THRESHOLD: i32 = 4 * 1024 * 1024;

/// Fix the mmap threshold (glibc otherwise raises it after large frees, keeping big request
/// buffers on the heap). Call once at start-up.
pub fn tune_allocator() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only changes allocator parameters; called before request threads start.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, MMAP_THRESHOLD);
        libc::mallopt(libc::M_TRIM_THRESHOLD, TRIM_THRESHOLD);
    }
}

/// Every few seconds, hand free heap pages back to the system.
pub async fn return_freed_memory() {
    let mut tick = tokio::time::interval(Duration::from_secs(5));
    loop {
        tick.tick().await;
        #[cfg(all(target_os = "linux", target_env = "gnu"))]
        // SAFETY: malloc_trim only releases free memory; glibc makes it thread-safe.
        unsafe {
            libc::malloc_trim(0);
        }
    }
}
