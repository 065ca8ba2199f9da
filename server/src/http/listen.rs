//! The accept loop: connections served by hyper with the limits a public service needs —
//! a maximum number of open connections (accepting waits for a free slot), a header-read
//! timeout that also closes idle keep-alive connections and slow (slowloris) senders, accept
//! errors (e.g. out of file descriptors) that back off instead of stopping service — and a
//! graceful shutdown that drains in-flight requests for at most a deadline.

use std::convert::Infallible;
use std::net::SocketAddr;
use std::sync::Arc;
use std::time::Duration;

use axum::response::Response;
use hyper::body::Incoming;
use hyper::server::conn::http1::Builder;
use hyper::Request;
use hyper_util::rt::{TokioIo, TokioTimer};
use hyper_util::server::graceful::GracefulShutdown;
use hyper_util::service::TowerToHyperService;
use tokio::net::TcpListener;
use tokio::sync::{watch, Semaphore};
use tower::Service;
use tracing::{info, warn};

/// Connection limits.
#[derive(Debug, Clone, Copy)]
pub struct Limits {
    /// Open connections at most.
    pub max_connections: usize,
    /// Time a client has to send a request's headers, and longest idle time between requests on
    /// a keep-alive connection.
    pub header_read_timeout: Duration,
    /// Longest drain of in-flight requests after a shutdown signal.
    pub shutdown_grace: Duration,
}

/// Serve on `listener` until `stop` turns true, then drain for at most the grace period; each
/// connection is served by `service(peer)`. Returns whether every connection finished within it.
pub async fn serve<F, S>(listener: TcpListener, service: F, limits: Limits, mut stop: watch::Receiver<bool>) -> bool
where
    F: Fn(SocketAddr) -> S,
    S: Service<Request<Incoming>, Response = Response, Error = Infallible> + Clone + Send + 'static,
    S::Future: Send + 'static,
{
    let slots = Arc::new(Semaphore::new(limits.max_connections.max(1)));
    let graceful = GracefulShutdown::new();
    // HTTP/1.1 only (browsers speak HTTP/2 only over TLS, which a proxy terminates): protocol
    // detection would wait for a silent client's first bytes with no timeout.
    let mut builder = Builder::new();
    // hyper reads up to 4× our header limits, so that our JSON 431 (http::limits) answers the
    // oversized requests most clients send; beyond that hyper answers a bare 431 itself.
    builder
        .timer(TokioTimer::new())
        .header_read_timeout(limits.header_read_timeout)
        .max_headers(4 * super::MAX_HEADERS)
        .max_buf_size(4 * super::MAX_HEADER_BYTES + (64 << 10));
    let mut backoff = Duration::from_millis(10);
    loop {
        let slot = tokio::select! {
            s = slots.clone().acquire_owned() => match s { Ok(s) => s, Err(_) => break },
            _ = stop.wait_for(|s| *s) => break,
        };
        let accepted = tokio::select! {
            a = listener.accept() => a,
            _ = stop.wait_for(|s| *s) => break,
        };
        let (stream, peer) = match accepted {
            Ok(a) => {
                backoff = Duration::from_millis(10);
                a
            }
            Err(e) => {
                // Out of descriptors or memory, or a connection reset before accept: wait a
                // little (longer while it persists) and go on serving the connections we have.
                warn!("accept error: {e}; retrying in {} ms", backoff.as_millis());
                tokio::time::sleep(backoff).await;
                backoff = (backoff * 2).min(Duration::from_secs(1));
                continue;
            }
        };
        let _ = stream.set_nodelay(true);
        let svc = service(peer);
        let io = TokioIo::new(super::bare_errors::JsonBareErrors::new(stream));
        let conn = builder.serve_connection(io, TowerToHyperService::new(svc));
        let conn = graceful.watch(conn);
        tokio::spawn(async move {
            let _ = conn.await;
            drop(slot);
        });
    }
    drop(listener);
    info!("draining in-flight requests (at most {} s)", limits.shutdown_grace.as_secs());
    tokio::time::timeout(limits.shutdown_grace, graceful.shutdown()).await.is_ok()
}
