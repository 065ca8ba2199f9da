//! What every route needs from a request, in one leaf module the routes share: the texture an
//! id names (or a 404 naming the available ones), the base URL for absolute links, and path
//! rejections as JSON errors.

use std::sync::Arc;

use axum::extract::rejection::PathRejection;
use axum::http::{header, HeaderMap};

use crate::error::ApiError;
use crate::state::AppState;
use crate::textures::{Registry, Texture};

/// The texture with `id`, or a 404 naming the available ones.
pub fn texture(reg: &Registry, id: &str) -> Result<Arc<Texture>, ApiError> {
    reg.get(id).cloned().ok_or_else(|| {
        let known: Vec<String> = reg.list.iter().map(|t| t.config.id.clone()).collect();
        ApiError::unknown_texture(id, &known)
    })
}

/// `http://HOST` of a request (for absolute URLs in documents).
pub fn base_url(st: &AppState, headers: &HeaderMap) -> String {
    let host = headers.get(header::HOST).and_then(|h| h.to_str().ok()).unwrap_or(&st.config.bind);
    format!("http://{host}")
}

/// A malformed path as a 400.
pub fn path_error(e: PathRejection) -> ApiError {
    ApiError::bad_request("invalid_path", format!("malformed path: {}", e.body_text()))
}
