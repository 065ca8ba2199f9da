//! What every route needs from a request, in one leaf module the routes share: the texture an
//! id names (or a 404 naming the available ones), the base URL for absolute links (configured,
//! forwarded by a trusted proxy, or the request's own), and path
//! rejections as JSON errors.

use std::sync::Arc;

use std::net::{IpAddr, SocketAddr};

use axum::extract::rejection::PathRejection;
use axum::extract::{ConnectInfo, FromRequestParts};
use axum::http::request::Parts;
use axum::http::{header, HeaderMap};

use crate::error::ApiError;
use crate::state::AppState;
use crate::textures::{Registry, Served, Texture};

/// The texture with `id`, or a 404 naming the available ones.
pub fn texture(reg: &Registry, id: &str) -> Result<Arc<Texture>, ApiError> {
    if reg.landscape(id).is_some() {
        return Err(ApiError::new(
            crate::error::Kind::NotFound,
            "landscape_not_served_here",
            format!(
                "'{}' is a landscape: it is served as tiles, windows, TileJSON and its description \
                 (/textures/{}); this endpoint serves textures",
                textile_core::error::clip(id),
                textile_core::error::clip(id)
            ),
        ));
    }
    reg.get(id).cloned().ok_or_else(|| {
        let known: Vec<String> = reg.list.iter().map(|t| t.config.id.clone()).collect();
        ApiError::unknown_texture(id, &known)
    })
}

/// The texture or landscape with `id`, or a 404 naming the available ones.
pub fn served(reg: &Registry, id: &str) -> Result<Served, ApiError> {
    match reg.landscape(id) {
        Some(l) => Ok(Served::Landscape(l.clone())),
        None => texture(reg, id).map(Served::Texture),
    }
}

/// The media type of a request body, without parameters, lower-cased (empty if none).
pub fn media_type(headers: &HeaderMap) -> String {
    let ct = headers.get(header::CONTENT_TYPE).and_then(|v| v.to_str().ok()).unwrap_or("");
    ct.split(';').next().unwrap_or("").trim().to_ascii_lowercase()
}

/// The address of the client connected to us (a proxy, when there is one); `None` where the
/// service runs without connection information (in-process tests).
#[derive(Debug, Clone, Copy)]
pub struct Peer(pub Option<IpAddr>);

impl<S: Send + Sync> FromRequestParts<S> for Peer {
    type Rejection = std::convert::Infallible;

    async fn from_request_parts(parts: &mut Parts, _: &S) -> Result<Self, Self::Rejection> {
        Ok(Peer(parts.extensions.get::<ConnectInfo<SocketAddr>>().map(|c| c.0.ip())))
    }
}

/// A host (with optional port) safe to put in a URL: letters, digits, `.-:[]_`.
fn clean_host(h: &str) -> Option<&str> {
    let ok = !h.is_empty() && h.len() <= 255 && h.chars().all(|c| c.is_ascii_alphanumeric() || ".-:[]_".contains(c));
    ok.then_some(h)
}

/// The first value of a comma-separated header.
fn first<'a>(headers: &'a HeaderMap, name: &str) -> Option<&'a str> {
    headers.get(name)?.to_str().ok()?.split(',').next().map(str::trim)
}

/// `proto` and `host` of the first element of an RFC 7239 `Forwarded` header.
fn forwarded(headers: &HeaderMap) -> (Option<String>, Option<String>) {
    let Some(v) = first(headers, "forwarded") else { return (None, None) };
    let (mut proto, mut host) = (None, None);
    for pair in v.split(';') {
        if let Some((k, val)) = pair.split_once('=') {
            let val = val.trim().trim_matches('"').to_string();
            match k.trim().to_ascii_lowercase().as_str() {
                "proto" => proto = Some(val),
                "host" => host = Some(val),
                _ => {}
            }
        }
    }
    (proto, host)
}

/// The base URL clients reach the service at, for absolute URLs in documents: the configured
/// `public_url`; else, for a request from a trusted proxy, its forwarded scheme and host
/// (`X-Forwarded-Proto`/`X-Forwarded-Host`, or `Forwarded`); else `http://` and the `Host`
/// header (the listen address without one).
pub fn base_url(st: &AppState, headers: &HeaderMap, peer: Peer) -> String {
    let cfg = &st.config;
    if !cfg.public_url.is_empty() {
        return cfg.public_url.trim_end_matches('/').to_string();
    }
    let host = headers.get(header::HOST).and_then(|h| h.to_str().ok()).and_then(clean_host);
    let trusted =
        peer.0.is_some_and(|ip| cfg.trusted_proxies.iter().any(|p| p.parse::<IpAddr>().is_ok_and(|t| t == ip)));
    if trusted {
        let (f_proto, f_host) = forwarded(headers);
        let proto = first(headers, "x-forwarded-proto").map(str::to_string).or(f_proto);
        let proto = proto.filter(|p| p == "http" || p == "https").unwrap_or_else(|| "http".into());
        let fwd_host = first(headers, "x-forwarded-host").map(str::to_string).or(f_host);
        if let Some(h) = fwd_host.as_deref().and_then(clean_host).or(host) {
            return format!("{proto}://{h}");
        }
    }
    format!("http://{}", host.unwrap_or(&cfg.bind))
}

/// A malformed path as a 400.
pub fn path_error(e: PathRejection) -> ApiError {
    ApiError::bad_request("invalid_path", format!("malformed path: {}", e.body_text()))
}

/// The answer to a request body that could not be read: `408 body_timeout` when it stopped
/// arriving (the router's idle deadline, `header_read_timeout_secs`, the same as the headers'),
/// else `too_large` when over its limit, else `400 invalid_body` saying why.
pub fn body_error(e: &str, too_large: impl FnOnce() -> ApiError) -> ApiError {
    if e.contains("designated timeout") {
        ApiError::new(
            crate::error::Kind::RequestTimeout,
            "body_timeout",
            "the request body stopped arriving: no data within the header deadline",
        )
    } else if e.contains("length limit") || e.contains("limit exceeded") || e.contains("too large") {
        too_large()
    } else {
        ApiError::bad_request("invalid_body", format!("the body could not be read: {}", textile_core::error::clip(e)))
    }
}
