//! HTTP semantics of every content answer, in one place: [`answer`] answers an
//! [`Output`] (images, GLB, glTF, X3D) with its strong ETag (derived from everything that
//! determines the bytes), `If-None-Match` → 304, Cache-Control, Content-Type and `X-Cache`.

use std::sync::Arc;

use axum::body::Bytes;
use axum::http::{header, HeaderMap, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};

use crate::error::ApiError;
use crate::output::{produce, Output};
use crate::state::AppState;

/// Does `If-None-Match` match this ETag? (Weak comparison, as RFC 9110 asks for this header.)
pub fn if_none_match(headers: &HeaderMap, etag: &str) -> bool {
    headers.get_all(header::IF_NONE_MATCH).iter().any(|v| {
        v.to_str()
            .map(|s| {
                s.split(',').any(|t| {
                    let t = t.trim();
                    t == "*" || t.strip_prefix("W/").unwrap_or(t) == etag
                })
            })
            .unwrap_or(false)
    })
}

fn common(h: &mut HeaderMap, etag: &str, cache_control: &HeaderValue) {
    if let Ok(v) = HeaderValue::from_str(etag) {
        h.insert(header::ETAG, v);
    }
    h.insert(header::CACHE_CONTROL, cache_control.clone());
}

/// 304 Not Modified with the validators.
pub fn not_modified(etag: &str, cache_control: &HeaderValue) -> Response {
    let mut r = StatusCode::NOT_MODIFIED.into_response();
    common(r.headers_mut(), etag, cache_control);
    r
}

/// 200 with an encoded image or model of the given content type.
pub fn image(bytes: Bytes, content_type: &'static str, etag: &str, cache_control: &HeaderValue, hit: bool) -> Response {
    let mut r = bytes.into_response();
    let h = r.headers_mut();
    h.insert(header::CONTENT_TYPE, HeaderValue::from_static(content_type));
    common(h, etag, cache_control);
    h.insert("x-cache", HeaderValue::from_static(if hit { "HIT" } else { "MISS" }));
    r
}

/// An output's answer: `304` when the client has it, else its bytes (through the tile cache
/// where it keeps them) with its ETag and content type.
pub async fn answer(st: &Arc<AppState>, headers: &HeaderMap, out: Output) -> Result<Response, ApiError> {
    let etag = out.etag();
    answer_tagged(st, headers, out, etag).await
}

/// [`answer`] of an output whose ETag (its [`Output::etag`]) the caller computed already.
pub async fn answer_tagged(
    st: &Arc<AppState>,
    headers: &HeaderMap,
    out: Output,
    etag: String,
) -> Result<Response, ApiError> {
    let cc = &st.cache_control;
    if if_none_match(headers, &etag) {
        return Ok(not_modified(&etag, cc));
    }
    let content_type = out.content_type();
    let (bytes, hit) = produce(st, &etag, out).await;
    Ok(image(bytes?, content_type, &etag, cc, hit))
}
