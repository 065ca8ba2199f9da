//! Shared state of the running service (no HTTP in it): configuration, the texture registry (set once textures
//! are loaded), the tile cache, admission control and counters; and the one way work reaches
//! the synthesis thread pool.

use std::panic::AssertUnwindSafe;
use std::sync::{Arc, RwLock};
use std::time::Duration;

use axum::body::Bytes;
use textile_core::{Cancel, Pyramid};
use tokio::sync::Semaphore;

use crate::cache::{CacheStats, TileCache};
use crate::config::Config;
use crate::error::ApiError;
use crate::metrics::Metrics;
use crate::queue::RunQueue;
use crate::textures::analysing::AnalysisPool;
use crate::textures::Registry;

/// Waiters per pool thread beyond which the synthesis queue serves the newest first.
const LIFO_ABOVE_PER_THREAD: usize = 4;

/// State shared by all handlers.
pub struct AppState {
    /// Effective configuration.
    pub config: Config,
    /// The catalogue: set once the exemplars are decoded, then replaced whole (never edited in
    /// place) when an upload adds or a deletion removes a texture, so every request works with
    /// one consistent catalogue.
    registry: RwLock<Option<Arc<Registry>>>,
    /// The ETags of recent tile requests by URL, valid while the catalogue is the same.
    pub etags: crate::etag_memo::EtagMemo,
    /// Held while the catalogue is being changed (uploads and deletions, one at a time).
    pub catalogue_writer: tokio::sync::Mutex<()>,
    /// Permits to run analyses of uploaded textures (`max_concurrent_analyses`).
    pub analyses: Arc<Semaphore>,
    /// Where every analysis runs: its own threads, at the lowest CPU priority.
    pub analysis_pool: AnalysisPool,
    /// Set when the service is stopping: background analyses stop at their next step.
    pub stopping: Cancel,
    /// Set once the textures present at start-up are analysed (readiness; uploads analysed
    /// later do not make the service unready).
    pub loaded: std::sync::atomic::AtomicBool,
    /// Encoded images.
    pub cache: TileCache,
    /// Permits for syntheses in flight (running or waiting); beyond them requests are shed.
    pub admission: Arc<Semaphore>,
    /// Permits to run on the synthesis pool: one per pool thread, first come first served
    /// while the queue is short, newest first when it is long (see [`RunQueue`]). Without it,
    /// rayon workers waiting inside one synthesis steal other queued syntheses and unlucky
    /// requests stack up behind many others (seconds of tail latency).
    pub running: Arc<RunQueue>,
    /// Synthesized levels shared between requests (Wei & Levoy's pyramidal cache).
    pub pyramid: Arc<Pyramid>,
    /// Big windows in flight at once: one fewer than the pool's threads (at least one), so that
    /// however many big windows are asked for, a worker is left for tiles.
    pub big_windows: Arc<Semaphore>,
    /// The memory budget, in MiB permits (`memory_budget_mib`): see [`AppState::reserve`].
    pub memory: Arc<Semaphore>,
    /// Prometheus metrics.
    pub metrics: Metrics,
    /// `Cache-Control` of tiles (`cache_control`), parsed once.
    pub cache_control: axum::http::HeaderValue,
    /// The access log, if one is configured (`access_log`; opened by `textile serve`).
    pub access_log: Option<crate::access_log::AccessLog>,
}

/// Working memory reserved from the budget, given back when dropped.
pub type Reservation = tokio::sync::OwnedSemaphorePermit;

const MIB: u64 = 1 << 20;

impl AppState {
    /// New state for a configuration (fails only if the analysis pool's threads cannot be
    /// started).
    pub fn new(config: Config) -> Result<Self, rayon::ThreadPoolBuildError> {
        let metrics = Metrics::new();
        let stats = CacheStats {
            hits: metrics.cache_hits.clone(),
            misses: metrics.cache_misses.clone(),
            evictions: metrics.cache_evictions.clone(),
            bytes: metrics.cache_bytes.clone(),
            entries: metrics.cache_entries.clone(),
        };
        Ok(AppState {
            analysis_pool: AnalysisPool::new(config.analysis_threads)?,
            cache: TileCache::new(config.cache_mib << 20, stats),
            admission: Arc::new(Semaphore::new(config.max_in_flight)),
            running: RunQueue::new(
                rayon::current_num_threads().max(1),
                LIFO_ABOVE_PER_THREAD * rayon::current_num_threads().max(1),
            ),
            pyramid: Arc::new(Pyramid::new(config.level_cache_mib << 20)),
            big_windows: Arc::new(Semaphore::new(rayon::current_num_threads().saturating_sub(1).max(1))),
            analyses: Arc::new(Semaphore::new(config.max_concurrent_analyses)),
            memory: Arc::new(Semaphore::new((config.memory_budget_mib - prepared_share_mib(&config)) as usize)),
            // Checked as a header value when the configuration is loaded.
            cache_control: axum::http::HeaderValue::from_str(&config.cache_control)
                .unwrap_or_else(|_| axum::http::HeaderValue::from_static("no-cache")),
            config,
            registry: RwLock::new(None),
            etags: Default::default(),
            catalogue_writer: tokio::sync::Mutex::new(()),
            stopping: Cancel::default(),
            loaded: Default::default(),
            metrics,
            access_log: None,
        })
    }

    /// Syntheses started so far (every mode, and glTF documents).
    pub fn syntheses(&self) -> u64 {
        textile_core::MODE_NAMES
            .iter()
            .chain(&[crate::metrics::GLTF_LABEL])
            .map(|m| self.metrics.syntheses.with_label_values(&[m]).get())
            .sum()
    }

    /// Reserve `bytes` of working memory from the budget (at least 1 MiB, at most all of it),
    /// waiting for room at most the queue-wait bound (else 503, counted as shed).
    pub async fn reserve(&self, bytes: u64) -> Result<Reservation, ApiError> {
        self.within_queue_wait(&self.memory, self.mib_of(bytes)).await
    }

    /// [`AppState::reserve`] for background work: waits as long as it takes (`None` only if the
    /// budget is closed).
    pub async fn reserve_patiently(&self, bytes: u64) -> Option<Reservation> {
        self.memory.clone().acquire_many_owned(self.mib_of(bytes)).await.ok()
    }

    /// Budget permits (MiB) for `bytes`: at least one, at most the whole budget.
    fn mib_of(&self, bytes: u64) -> u32 {
        bytes.div_ceil(MIB).clamp(1, self.working_mib()) as u32
    }

    /// `units` permits of `sem`, waited for at most the queue-wait bound (else 503, counted as
    /// shed).
    async fn within_queue_wait(
        &self,
        sem: &Arc<Semaphore>,
        units: u32,
    ) -> Result<tokio::sync::OwnedSemaphorePermit, ApiError> {
        let wait = Duration::from_millis(self.config.max_queue_wait_ms);
        match tokio::time::timeout(wait, sem.clone().acquire_many_owned(units)).await {
            Ok(Ok(p)) => Ok(p),
            _ => {
                self.metrics.shed.inc();
                Err(ApiError::overloaded())
            }
        }
    }

    /// Working memory reserved now, in bytes.
    pub fn reserved(&self) -> u64 {
        (self.working_mib() - self.memory.available_permits() as u64) * MIB
    }

    /// A place in the big-window lane, waited for at most the queue-wait bound (else 503).
    pub async fn big_window_lane(&self) -> Result<tokio::sync::OwnedSemaphorePermit, ApiError> {
        self.within_queue_wait(&self.big_windows, 1).await
    }

    /// The catalogue, or 503 while loading.
    pub fn ready(&self) -> Result<Arc<Registry>, ApiError> {
        self.registry().ok_or_else(ApiError::not_ready)
    }

    /// Whether the textures present at start-up are analysed.
    pub fn loaded(&self) -> bool {
        self.loaded.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// The catalogue, once the exemplars are decoded.
    pub fn registry(&self) -> Option<Arc<Registry>> {
        self.registry.read().unwrap_or_else(|e| e.into_inner()).clone()
    }

    /// Replace the catalogue (requests already holding the old one finish with it), sharing
    /// out the part of the memory budget set aside for the textures' prepared caches
    /// ([`prepared_share_mib`]): each texture's states may keep an equal part of it, at most
    /// [`PREPARED_CACHE_MIB`].
    pub fn set_registry(&self, reg: Arc<Registry>) {
        let each =
            (prepared_share_mib(&self.config) * MIB / reg.list.len().max(1) as u64).min(PREPARED_CACHE_MIB * MIB);
        for tex in &reg.list {
            tex.limit_caches(each);
        }
        *self.registry.write().unwrap_or_else(|e| e.into_inner()) = Some(reg);
        self.etags.catalogue_changed();
    }

    /// MiB of the memory budget that working memory may reserve (the rest is the textures'
    /// prepared caches').
    fn working_mib(&self) -> u64 {
        self.config.memory_budget_mib - prepared_share_mib(&self.config)
    }

    /// Run a synthesis job (counted under `mode`) on the rayon pool (never on a tokio worker),
    /// within the in-flight limit, the queue-wait bound and the request timeout (503s beyond
    /// them). A panic in the job becomes a 500. The job is given a [`Cancel`] that turns set
    /// when this call is dropped before the job ends (the client went away, or the request
    /// timed out); jobs that work in steps stop at the next one.
    pub async fn synthesize<F>(&self, mode: &str, job: F) -> Result<Bytes, ApiError>
    where
        F: FnOnce(&Cancel) -> Result<Vec<u8>, ApiError> + Send + 'static,
    {
        let job_cancel = Cancel::default();
        let abandon = AbandonOnDrop(Some(job_cancel.clone()));
        let cancelled = self.metrics.cancelled.clone();
        let job = move || {
            let r = job(&job_cancel);
            if job_cancel.is_set() {
                cancelled.inc();
            }
            r
        };
        let admitted = self.admission.clone().try_acquire_owned().map_err(|_| {
            self.metrics.shed.inc();
            ApiError::overloaded()
        })?;
        // Everything the job holds until it ends, released on drop even if it never starts.
        let guard = (admitted, InFlight::new(&self.metrics.in_flight));
        let queue_wait = Duration::from_millis(self.config.max_queue_wait_ms);
        let work = async {
            let Some(run) = self.running.acquire(queue_wait).await else {
                self.metrics.shed.inc();
                return Err(ApiError::overloaded());
            };
            let timer = self.metrics.synthesis_timer(mode).start_timer();
            let (tx, rx) = tokio::sync::oneshot::channel();
            rayon::spawn(move || {
                let r = std::panic::catch_unwind(AssertUnwindSafe(job));
                drop((guard, run));
                timer.observe_duration();
                let _ = tx.send(r);
            });
            match rx.await {
                Ok(Ok(r)) => r.map(Bytes::from),
                _ => Err(ApiError::internal("synthesis failed unexpectedly")),
            }
        };
        let wait = Duration::from_secs(self.config.request_timeout_secs);
        match tokio::time::timeout(wait, work).await {
            Ok(r) => {
                abandon.finished();
                r
            }
            // Timed out: `abandon` goes, and the job stops at its next step.
            Err(_) => Err(ApiError::timeout()),
        }
    }
}

/// Sets its [`Cancel`] when dropped before [`AbandonOnDrop::finished`].
struct AbandonOnDrop(Option<Cancel>);

impl AbandonOnDrop {
    fn finished(mut self) {
        self.0 = None;
    }
}

impl Drop for AbandonOnDrop {
    fn drop(&mut self) {
        if let Some(c) = self.0.take() {
            c.set();
        }
    }
}

/// Counts a synthesis in the in-flight gauge for as long as it lives.
struct InFlight(prometheus::IntGauge);

impl InFlight {
    fn new(g: &prometheus::IntGauge) -> Self {
        g.inc();
        InFlight(g.clone())
    }
}

impl Drop for InFlight {
    fn drop(&mut self) {
        self.0.dec();
    }
}

/// Most MiB of caches one texture's prepared states keep.
pub const PREPARED_CACHE_MIB: u64 = 16;

/// MiB of the memory budget set aside for the textures' prepared caches (the umbrella mode's
/// cell lists and levels of detail): an eighth of it, at most 256.
pub fn prepared_share_mib(config: &Config) -> u64 {
    (config.memory_budget_mib / 8).min(256)
}
