//! The hot path of a tile server: a repeated `GET /tiles/{id}/{z}/{x}/{y}` whose ETag is
//! remembered ([`crate::etag_memo`]) and whose bytes are in the tile cache (or whose client has
//! them: 304) is answered here, per connection, before the router and its layers — routing,
//! the JSON-405 wrapper, the metrics and limits layer, compression negotiation, CORS, panic
//! catching and the access log cost a cached tile about as much as the rest of its answer.
//! What those layers do to such an answer is done here the same way, so that its status,
//! headers and bytes are those of the full path: the size limits (an oversized request takes
//! the full path, which refuses it), the CORS headers (from [`Cors`], the same settings
//! the router's CORS layer is built from), the request metrics of the tile route, and the access
//! log line. Every other request — any other route or method, a percent-encoded path, a tile
//! not remembered, a catalogue not ready — goes to the router unchanged.

use std::convert::Infallible;
use std::future::Future;
use std::net::SocketAddr;
use std::pin::Pin;
use std::sync::Arc;
use std::task::{Context, Poll};
use std::time::Instant;

use axum::extract::ConnectInfo;
use axum::http::{header, HeaderValue, Method, Request};
use axum::response::Response;
use axum::routing::future::RouteFuture;
use axum::Router;
use prometheus::{Histogram, IntCounter};
use tower::Service;

use super::content::{if_none_match, image, not_modified};
use super::Cors;
use crate::state::AppState;

/// The route template of tiles, as the metrics name it.
pub const TILE_ROUTE: &str = "/tiles/{id}/{z}/{x}/{y}";

/// What every connection's hot path shares: the state, the CORS headers, and the tile route's
/// metrics resolved once.
pub struct Shared {
    st: Arc<AppState>,
    cors: Cors,
    latency: Histogram,
    ok: IntCounter,
    not_modified: IntCounter,
}

impl Shared {
    /// The hot path of `st`'s tiles.
    pub fn new(st: Arc<AppState>) -> Arc<Shared> {
        let m = &st.metrics;
        Arc::new(Shared {
            cors: Cors::new(&st.config.cors_origins),
            latency: m.latency.with_label_values(&[TILE_ROUTE]),
            ok: m.requests.with_label_values(&[TILE_ROUTE, "200"]),
            not_modified: m.requests.with_label_values(&[TILE_ROUTE, "304"]),
            st,
        })
    }

    /// The answer of a remembered, cached tile, or `None` for the router to answer.
    fn answer<B>(&self, req: &Request<B>) -> Option<Response> {
        if req.method() != Method::GET || super::over_limits(req).is_some() {
            return None;
        }
        let rest = req.uri().path().strip_prefix("/tiles/")?;
        // Exactly the route's four segments, none empty or percent-encoded: then the router's
        // decoded parameters are these segments, and the memo's key is the handler's.
        let mut segments = 0;
        for s in rest.split('/') {
            if s.is_empty() {
                return None;
            }
            segments += 1;
        }
        if segments != 4 || rest.contains('%') {
            return None;
        }
        let started = Instant::now();
        let st = &self.st;
        let generation = st.etags.generation();
        st.registry()?;
        let m = st.etags.get(&crate::etag_memo::url_key(rest, req.uri().query()), generation)?;
        let mut resp = if if_none_match(req.headers(), &m.etag) {
            self.not_modified.inc();
            not_modified(&m.etag, &st.cache_control)
        } else {
            let bytes = st.cache.peek(&m.etag)?;
            self.ok.inc();
            let len = bytes.len();
            let mut r = image(bytes, m.content_type, &m.etag, &st.cache_control, true);
            r.headers_mut().insert(header::CONTENT_LENGTH, HeaderValue::from(len));
            r
        };
        self.cors.add(req.headers(), resp.headers_mut());
        st.metrics.hot_tiles.inc();
        self.latency.observe(started.elapsed().as_secs_f64());
        Some(match st.access_log {
            Some(_) => super::access::logged(st.clone(), super::access::arrival(req), started, false, resp),
            None => resp,
        })
    }
}

/// One connection's service: the hot path, else the router (with the peer's address, as the
/// access log and the router's handlers read it).
#[derive(Clone)]
pub struct HotTiles {
    shared: Arc<Shared>,
    app: Router,
    peer: SocketAddr,
}

impl HotTiles {
    /// The service of a connection from `peer`.
    pub fn new(shared: Arc<Shared>, app: Router, peer: SocketAddr) -> HotTiles {
        HotTiles { shared, app, peer }
    }
}

impl<B> Service<Request<B>> for HotTiles
where
    B: http_body::Body<Data = axum::body::Bytes> + Send + 'static,
    B::Error: Into<axum::BoxError>,
{
    type Response = Response;
    type Error = Infallible;
    type Future = Answer;

    fn poll_ready(&mut self, _cx: &mut Context<'_>) -> Poll<Result<(), Infallible>> {
        Poll::Ready(Ok(()))
    }

    fn call(&mut self, mut req: Request<B>) -> Self::Future {
        req.extensions_mut().insert(ConnectInfo(self.peer));
        match self.shared.answer(&req) {
            Some(resp) => Answer::Hot(Some(resp)),
            None => Answer::Routed(self.app.call(req)),
        }
    }
}

/// A connection's answer: from the hot path, or the router's.
pub enum Answer {
    /// Answered already (taken when polled).
    Hot(Option<Response>),
    /// The router's answer to come.
    Routed(RouteFuture<Infallible>),
}

impl Future for Answer {
    type Output = Result<Response, Infallible>;

    fn poll(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<Self::Output> {
        match self.get_mut() {
            Answer::Hot(resp) => match resp.take() {
                Some(r) => Poll::Ready(Ok(r)),
                None => Poll::Pending,
            },
            Answer::Routed(f) => Pin::new(f).poll(cx),
        }
    }
}
