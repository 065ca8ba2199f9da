//! The access log's middleware: the outermost layer (so it sees every answer as sent —
//! compressed, CORS, JSON errors, panics turned into 500s) notes each request's arrival, and its
//! response body is wrapped to count the bytes sent; the line is handed to
//! [`crate::access_log::AccessLog`] when the body ends, or when the client goes away first.

use std::net::SocketAddr;
use std::pin::Pin;
use std::sync::Arc;
use std::task::{Context, Poll};
use std::time::{Instant, SystemTime, UNIX_EPOCH};

use axum::body::{Body, Bytes};
use axum::extract::{ConnectInfo, Request, State};
use axum::http::{header, Method, Version};
use axum::middleware::Next;
use axum::response::Response;
use http_body::{Body as _, Frame, SizeHint};

use crate::access_log::Entry;
use crate::state::AppState;

/// Note the request, answer it, and log it when its body has been sent.
pub async fn record(State(st): State<Arc<AppState>>, req: Request, next: Next) -> Response {
    let started = Instant::now();
    let entry = arrival(&req);
    let head = req.method() == Method::HEAD;
    let resp = next.run(req).await;
    logged(st, entry, started, head, resp)
}

/// `resp`, the answer of the request noted as `entry` at `started`, logged when its body has
/// been sent (a HEAD answer's body never is).
pub fn logged(st: Arc<AppState>, entry: Entry, started: Instant, head: bool, resp: Response) -> Response {
    let (parts, body) = resp.into_parts();
    let cache = match parts.headers.get("x-cache").map(|v| v.as_bytes()) {
        Some(b"HIT") => "hit",
        Some(b"MISS") => "miss",
        _ => "-",
    };
    let entry = Entry { status: parts.status.as_u16(), cache, ..entry };
    let body = Counted { inner: body, sent: 0, head, pending: Some((st, entry, started)) };
    Response::from_parts(parts, Body::new(body))
}

/// The log entry of a request as it arrives (answer fields to be filled).
pub fn arrival<B>(req: &axum::http::Request<B>) -> Entry {
    let ts_ms = SystemTime::now().duration_since(UNIX_EPOCH).map_or(0, |d| d.as_millis() as u64);
    let header_text = |h: header::HeaderName| req.headers().get(h).and_then(|v| v.to_str().ok()).map(str::to_owned);
    Entry {
        ts_ms,
        client: req.extensions().get::<ConnectInfo<SocketAddr>>().map_or("-".into(), |c| c.0.ip().to_string()),
        method: req.method().to_string(),
        path: req.uri().path_and_query().map_or_else(|| req.uri().path().to_owned(), |pq| pq.as_str().to_owned()),
        version: match req.version() {
            Version::HTTP_09 => "HTTP/0.9",
            Version::HTTP_10 => "HTTP/1.0",
            Version::HTTP_2 => "HTTP/2.0",
            Version::HTTP_3 => "HTTP/3.0",
            _ => "HTTP/1.1",
        },
        status: 0,
        bytes: 0,
        ms: 0.0,
        cache: "-",
        aborted: false,
        referer: header_text(header::REFERER),
        user_agent: header_text(header::USER_AGENT),
    }
}

/// A response body that counts what is sent of it and logs the request when it ends.
struct Counted {
    inner: Body,
    sent: u64,
    /// A HEAD answer's body is never sent, and that is its end.
    head: bool,
    pending: Option<(Arc<AppState>, Entry, Instant)>,
}

impl Counted {
    fn finish(&mut self, aborted: bool) {
        let Some((st, mut e, started)) = self.pending.take() else { return };
        if let Some(log) = &st.access_log {
            e.bytes = self.sent;
            e.ms = started.elapsed().as_secs_f64() * 1000.0;
            e.aborted = aborted;
            log.record(&e);
        }
    }
}

impl http_body::Body for Counted {
    type Data = Bytes;
    type Error = axum::Error;

    fn poll_frame(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<Option<Result<Frame<Bytes>, Self::Error>>> {
        let this = &mut *self;
        let r = Pin::new(&mut this.inner).poll_frame(cx);
        match &r {
            Poll::Ready(Some(Ok(f))) => {
                this.sent += f.data_ref().map_or(0, |d| d.len() as u64);
                if this.inner.is_end_stream() {
                    this.finish(false);
                }
            }
            Poll::Ready(None) => this.finish(false),
            Poll::Ready(Some(Err(_))) => this.finish(true),
            Poll::Pending => {}
        }
        r
    }

    fn is_end_stream(&self) -> bool {
        self.inner.is_end_stream()
    }

    fn size_hint(&self) -> SizeHint {
        self.inner.size_hint()
    }
}

impl Drop for Counted {
    fn drop(&mut self) {
        let ended = self.head || self.inner.is_end_stream();
        self.finish(!ended);
    }
}
