//! Shared state of the running service: configuration, the texture registry (set once textures
//! are loaded), the tile cache, admission control and counters; and the one way work reaches
//! the synthesis thread pool.

use std::panic::AssertUnwindSafe;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, OnceLock};
use std::time::Duration;

use axum::body::Bytes;
use tokio::sync::Semaphore;

use crate::cache::TileCache;
use crate::config::Config;
use crate::http::error::ApiError;
use crate::textures::Registry;

/// State shared by all handlers.
pub struct AppState {
    /// Effective configuration.
    pub config: Config,
    /// Set once every texture is loaded.
    pub registry: OnceLock<Arc<Registry>>,
    /// Encoded images.
    pub cache: TileCache,
    /// Permits for syntheses in flight.
    pub admission: Arc<Semaphore>,
    /// Syntheses started.
    pub syntheses: AtomicU64,
    /// Requests shed with 503 because of the in-flight limit.
    pub shed: AtomicU64,
}

impl AppState {
    /// New state for a configuration.
    pub fn new(config: Config) -> Self {
        AppState {
            cache: TileCache::new(config.cache_mib << 20),
            admission: Arc::new(Semaphore::new(config.max_in_flight)),
            config,
            registry: OnceLock::new(),
            syntheses: AtomicU64::new(0),
            shed: AtomicU64::new(0),
        }
    }

    /// The registry, or 503 while loading.
    pub fn ready(&self) -> Result<&Arc<Registry>, ApiError> {
        self.registry.get().ok_or_else(ApiError::not_ready)
    }

    /// Run a synthesis job on the rayon pool (never on a tokio worker), within the in-flight
    /// limit and the request timeout. A panic in the job becomes a 500.
    pub async fn synthesize<F>(&self, job: F) -> Result<Bytes, ApiError>
    where
        F: FnOnce() -> Result<Vec<u8>, ApiError> + Send + 'static,
    {
        let permit = self.admission.clone().try_acquire_owned().map_err(|_| {
            self.shed.fetch_add(1, Ordering::Relaxed);
            ApiError::overloaded()
        })?;
        self.syntheses.fetch_add(1, Ordering::Relaxed);
        let (tx, rx) = tokio::sync::oneshot::channel();
        rayon::spawn(move || {
            let r = std::panic::catch_unwind(AssertUnwindSafe(job));
            drop(permit);
            let _ = tx.send(r);
        });
        let wait = Duration::from_secs(self.config.request_timeout_secs);
        match tokio::time::timeout(wait, rx).await {
            Err(_) => Err(ApiError {
                retry_after: Some(5),
                ..ApiError::new(axum::http::StatusCode::SERVICE_UNAVAILABLE, "timeout", "synthesis took too long")
            }),
            Ok(Err(_)) | Ok(Ok(Err(_))) => Err(ApiError::internal("synthesis failed unexpectedly")),
            Ok(Ok(Ok(r))) => r.map(Bytes::from),
        }
    }
}
