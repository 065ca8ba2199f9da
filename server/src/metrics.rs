//! Prometheus metrics (the `prometheus` crate): requests by route and status, latency
//! histograms, tile-cache hits/misses/evictions/bytes, syntheses by mode, in-flight and shed
//! syntheses, pyramidal (level) cache blocks, access log lines written and dropped. One registry per server; `/metrics` renders it in
//! the text format.

use prometheus::{
    Encoder, Histogram, HistogramOpts, HistogramVec, IntCounter, IntCounterVec, IntGauge, Opts, Registry, TextEncoder,
};
use textile_core::PyramidStats;

/// Label under which glTF documents are counted in the per-mode metrics, besides the modes.
pub const GLTF_LABEL: &str = "gltf";
/// Label under which landscapes' images are counted in the per-mode metrics (their layers'
/// syntheses happen inside them).
pub const LANDSCAPE_LABEL: &str = "landscape";

/// Every metric of the service.
pub struct Metrics {
    registry: Registry,
    /// HTTP requests by route template and status.
    pub requests: IntCounterVec,
    /// Request latency by route template.
    pub latency: HistogramVec,
    /// Cache answers served from memory.
    pub cache_hits: IntCounter,
    /// Cache lookups that missed.
    pub cache_misses: IntCounter,
    /// Repeated tile requests answered from their remembered ETag, before routing.
    pub hot_tiles: IntCounter,
    /// Cache entries evicted to stay within the byte limit.
    pub cache_evictions: IntCounter,
    /// Bytes held by the cache.
    pub cache_bytes: IntGauge,
    /// Entries held by the cache.
    pub cache_entries: IntGauge,
    /// Syntheses started, by mode.
    pub syntheses: IntCounterVec,
    /// Synthesis time by mode.
    pub synthesis_seconds: HistogramVec,
    /// Syntheses running or queued.
    pub in_flight: IntGauge,
    /// Requests shed with 503 because of the in-flight limit.
    pub shed: IntCounter,
    /// Syntheses stopped because their requester went away (or timed out).
    pub cancelled: IntCounter,
    /// Pixels synthesized at all levels (padding included), by mode.
    pub pixels_synthesized: IntCounterVec,
    /// Pixels delivered by those syntheses, by mode: the computation ratio is
    /// synthesized ÷ delivered.
    pub pixels_delivered: IntCounterVec,
    /// Pyramidal cache block lookups answered.
    pub level_cache_hits: IntCounter,
    /// Pyramidal cache block lookups that found nothing.
    pub level_cache_misses: IntCounter,
    /// Pyramidal cache blocks evicted.
    pub level_cache_evictions: IntCounter,
    /// Bytes held by the pyramidal cache.
    pub level_cache_bytes: IntGauge,
    /// Blocks held by the pyramidal cache.
    pub level_cache_blocks: IntGauge,
    /// Bytes held by the textures (exemplars, maps, analyses, extractions and their caches).
    pub prepared_bytes: IntGauge,
    /// Bytes of caches the textures' prepared states may keep, in all.
    pub prepared_cache_limit_bytes: IntGauge,
    /// Access log lines written.
    pub access_log_lines: IntCounter,
    /// Access log lines dropped because the writer was behind (its buffer full).
    pub access_log_dropped: IntCounter,
}

fn must<T>(r: prometheus::Result<T>) -> T {
    // Metric definitions are static; an error here is a programming error caught by tests.
    r.unwrap_or_else(|e| panic!("metric definition: {e}"))
}

impl Metrics {
    /// A fresh registry with every metric registered.
    pub fn new() -> Metrics {
        let registry = Registry::new_custom(Some("textile".into()), None).unwrap_or_default();
        let buckets = vec![0.0005, 0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1.0, 2.5, 5.0, 10.0];
        let m = Metrics {
            requests: must(IntCounterVec::new(
                Opts::new("http_requests_total", "HTTP requests by route and status"),
                &["route", "status"],
            )),
            latency: must(HistogramVec::new(
                HistogramOpts::new("http_request_duration_seconds", "HTTP request latency by route")
                    .buckets(buckets.clone()),
                &["route"],
            )),
            cache_hits: must(IntCounter::new("cache_hits_total", "tile cache hits")),
            hot_tiles: must(IntCounter::new(
                "hot_tile_answers_total",
                "repeated tile requests answered from their remembered ETag, before routing",
            )),
            cache_misses: must(IntCounter::new("cache_misses_total", "tile cache misses")),
            cache_evictions: must(IntCounter::new("cache_evictions_total", "tile cache evictions")),
            cache_bytes: must(IntGauge::new("cache_bytes", "bytes held by the tile cache")),
            cache_entries: must(IntGauge::new("cache_entries", "entries held by the tile cache")),
            syntheses: must(IntCounterVec::new(Opts::new("syntheses_total", "syntheses started, by mode"), &["mode"])),
            synthesis_seconds: must(HistogramVec::new(
                HistogramOpts::new("synthesis_duration_seconds", "synthesis and encoding time, by mode")
                    .buckets(buckets),
                &["mode"],
            )),
            in_flight: must(IntGauge::new("syntheses_in_flight", "syntheses running or queued")),
            shed: must(IntCounter::new("shed_total", "requests answered 503 because of the in-flight limit")),
            cancelled: must(IntCounter::new(
                "syntheses_cancelled_total",
                "syntheses stopped because their requester went away or timed out",
            )),
            pixels_synthesized: must(IntCounterVec::new(
                Opts::new("pixels_synthesized_total", "pixels synthesized at all levels, padding included, by mode"),
                &["mode"],
            )),
            level_cache_hits: must(IntCounter::new("level_cache_hits_total", "pyramidal cache block lookups answered")),
            level_cache_misses: must(IntCounter::new(
                "level_cache_misses_total",
                "pyramidal cache block lookups that found nothing",
            )),
            level_cache_evictions: must(IntCounter::new(
                "level_cache_evictions_total",
                "pyramidal cache blocks evicted",
            )),
            level_cache_bytes: must(IntGauge::new("level_cache_bytes", "bytes held by the pyramidal cache")),
            level_cache_blocks: must(IntGauge::new("level_cache_blocks", "blocks held by the pyramidal cache")),
            prepared_bytes: must(IntGauge::new(
                "prepared_bytes",
                "bytes held by the textures: exemplars, maps, analyses, extractions and their caches",
            )),
            prepared_cache_limit_bytes: must(IntGauge::new(
                "prepared_cache_limit_bytes",
                "bytes of caches the textures' prepared states may keep, in all (part of memory_budget_mib)",
            )),
            pixels_delivered: must(IntCounterVec::new(
                Opts::new("pixels_delivered_total", "pixels delivered by syntheses, by mode"),
                &["mode"],
            )),
            access_log_lines: must(IntCounter::new("access_log_lines_total", "access log lines written")),
            access_log_dropped: must(IntCounter::new(
                "access_log_dropped_total",
                "access log lines dropped because the writer was behind (access_log_buffer full)",
            )),
            registry,
        };
        let all: Vec<Box<dyn prometheus::core::Collector>> = vec![
            Box::new(m.requests.clone()),
            Box::new(m.latency.clone()),
            Box::new(m.cache_hits.clone()),
            Box::new(m.hot_tiles.clone()),
            Box::new(m.cache_misses.clone()),
            Box::new(m.cache_evictions.clone()),
            Box::new(m.cache_bytes.clone()),
            Box::new(m.cache_entries.clone()),
            Box::new(m.syntheses.clone()),
            Box::new(m.synthesis_seconds.clone()),
            Box::new(m.in_flight.clone()),
            Box::new(m.shed.clone()),
            Box::new(m.cancelled.clone()),
            Box::new(m.pixels_synthesized.clone()),
            Box::new(m.pixels_delivered.clone()),
            Box::new(m.level_cache_hits.clone()),
            Box::new(m.level_cache_misses.clone()),
            Box::new(m.level_cache_evictions.clone()),
            Box::new(m.level_cache_bytes.clone()),
            Box::new(m.level_cache_blocks.clone()),
            Box::new(m.prepared_bytes.clone()),
            Box::new(m.prepared_cache_limit_bytes.clone()),
            Box::new(m.access_log_lines.clone()),
            Box::new(m.access_log_dropped.clone()),
        ];
        for c in all {
            must(m.registry.register(c));
        }
        m
    }

    /// The registry in the Prometheus text format.
    pub fn render(&self) -> String {
        let mut buf = Vec::new();
        let _ = TextEncoder::new().encode(&self.registry.gather(), &mut buf);
        String::from_utf8(buf).unwrap_or_default()
    }

    /// Bring the pyramidal cache figures up to date (its counters live in the core).
    pub fn observe_pyramid(&self, s: &PyramidStats) {
        let catch_up = |c: &IntCounter, v: u64| c.inc_by(v.saturating_sub(c.get()));
        catch_up(&self.level_cache_hits, s.hits);
        catch_up(&self.level_cache_misses, s.misses);
        catch_up(&self.level_cache_evictions, s.evictions);
        self.level_cache_bytes.set(s.bytes as i64);
        self.level_cache_blocks.set(s.blocks as i64);
    }

    /// A synthesis timer for a mode.
    pub fn synthesis_timer(&self, mode: &str) -> Histogram {
        self.syntheses.with_label_values(&[mode]).inc();
        self.synthesis_seconds.with_label_values(&[mode])
    }
}

impl Default for Metrics {
    fn default() -> Self {
        Self::new()
    }
}
