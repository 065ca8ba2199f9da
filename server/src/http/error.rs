//! API errors: one type for every failure a handler can report, rendered as
//! `{"error": "<code>", "message": "<what was wrong and what is allowed>"}` with its status.
//! Core errors are mapped to statuses here and nowhere else.

use axum::http::{header, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::Json;
use textile_core::CoreError;

/// An error answer.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ApiError {
    /// HTTP status.
    pub status: StatusCode,
    /// Machine-readable code.
    pub code: &'static str,
    /// Human-readable explanation.
    pub message: String,
    /// `Retry-After` seconds, for 503s.
    pub retry_after: Option<u32>,
}

impl ApiError {
    /// A new error.
    pub fn new(status: StatusCode, code: &'static str, message: impl Into<String>) -> Self {
        ApiError { status, code, message: message.into(), retry_after: None }
    }
    /// 400.
    pub fn bad_request(code: &'static str, message: String) -> Self {
        Self::new(StatusCode::BAD_REQUEST, code, message)
    }
    /// 404 for a route.
    pub fn not_found_route(path: &str) -> Self {
        Self::new(StatusCode::NOT_FOUND, "not_found", format!("no route for '{path}'; see /openapi.json"))
    }
    /// 404 for a texture id.
    pub fn unknown_texture(id: &str, known: &[String]) -> Self {
        Self::new(
            StatusCode::NOT_FOUND,
            "unknown_texture",
            format!("no texture '{}'; available: {}", id.escape_debug(), known.join(", ")),
        )
    }
    /// 503 while textures are still being prepared.
    pub fn not_ready() -> Self {
        ApiError {
            retry_after: Some(2),
            ..Self::new(StatusCode::SERVICE_UNAVAILABLE, "not_ready", "textures are still loading")
        }
    }
    /// 503 when the synthesis queue is full.
    pub fn overloaded() -> Self {
        ApiError {
            retry_after: Some(1),
            ..Self::new(StatusCode::SERVICE_UNAVAILABLE, "overloaded", "too many syntheses in flight; retry shortly")
        }
    }
    /// 500.
    pub fn internal(message: impl Into<String>) -> Self {
        Self::new(StatusCode::INTERNAL_SERVER_ERROR, "internal", message)
    }
}

impl From<CoreError> for ApiError {
    fn from(e: CoreError) -> Self {
        let msg = e.to_string();
        match e {
            CoreError::Param { .. } => Self::new(StatusCode::BAD_REQUEST, "invalid_parameter", msg),
            CoreError::Window { .. } => Self::new(StatusCode::BAD_REQUEST, "invalid_window", msg),
            CoreError::ExemplarUndecodable(_) => Self::new(StatusCode::UNPROCESSABLE_ENTITY, "undecodable_image", msg),
            CoreError::ExemplarSize { .. } => Self::new(StatusCode::UNPROCESSABLE_ENTITY, "image_size", msg),
            CoreError::Io { .. } | CoreError::AnalysisFile { .. } => Self::internal(msg),
        }
    }
}

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        let body = serde_json::json!({ "error": self.code, "message": self.message });
        let mut r = (self.status, Json(body)).into_response();
        if let Some(s) = self.retry_after {
            r.headers_mut().insert(header::RETRY_AFTER, HeaderValue::from(s));
        }
        r.headers_mut().insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
        r
    }
}
