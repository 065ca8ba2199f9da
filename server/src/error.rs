//! The service's error: what went wrong in a request, as a kind, a machine-readable code and a
//! message naming the problem. No HTTP in it: `http::error` maps each kind to one status and
//! the JSON body, in one place. Core errors are classified here and nowhere else.

use textile_core::error::clip;
use textile_core::CoreError;

/// What kind of failure, independent of the protocol that reports it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// The request is malformed or asks for something not allowed.
    BadRequest,
    /// No such texture or route.
    NotFound,
    /// The request needs credentials it lacks (the admin token).
    Unauthorized,
    /// The request conflicts with the catalogue (an id in use, a configured texture).
    Conflict,
    /// The method is not allowed on an existing route.
    MethodNotAllowed,
    /// The request body is larger than allowed.
    TooLarge,
    /// The request body stopped arriving (no data within the header deadline).
    RequestTimeout,
    /// The request target (path and query) is longer than allowed.
    UriTooLong,
    /// The request headers are more or larger than allowed.
    HeadersTooLarge,
    /// The request body is of a media type the route does not read.
    UnsupportedMediaType,
    /// The content (an image) cannot be used.
    Unprocessable,
    /// Temporarily unable: loading, overloaded or too slow; retry after `retry_after`.
    Unavailable,
    /// The data directory could not store what the request made.
    InsufficientStorage,
    /// A fault of ours.
    Internal,
}

/// An error answer.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ApiError {
    /// Kind of failure.
    pub kind: Kind,
    /// Machine-readable code.
    pub code: &'static str,
    /// Human-readable explanation.
    pub message: String,
    /// Seconds after which a retry may succeed (unavailable answers).
    pub retry_after: Option<u32>,
}

impl ApiError {
    /// A new error.
    pub fn new(kind: Kind, code: &'static str, message: impl Into<String>) -> Self {
        ApiError { kind, code, message: message.into(), retry_after: None }
    }
    /// A bad request.
    pub fn bad_request(code: &'static str, message: impl Into<String>) -> Self {
        Self::new(Kind::BadRequest, code, message)
    }
    /// The same answer, its message starting with `prefix` (saying where it arose).
    pub fn prefixed(mut self, prefix: &str) -> Self {
        self.message = format!("{prefix}{}", self.message);
        self
    }
    /// No route for a path.
    pub fn not_found_route(path: &str) -> Self {
        Self::new(Kind::NotFound, "not_found", format!("no route for '{}'; see /openapi.json", clip(path)))
    }
    /// No texture with this id.
    pub fn unknown_texture(id: &str, known: &[String]) -> Self {
        Self::new(
            Kind::NotFound,
            "unknown_texture",
            format!("no texture '{}'; available: {}", clip(id), known.join(", ")),
        )
    }
    /// Textures are still being prepared.
    pub fn not_ready() -> Self {
        ApiError { retry_after: Some(2), ..Self::new(Kind::Unavailable, "not_ready", "textures are still loading") }
    }
    /// The synthesis queue is full.
    pub fn overloaded() -> Self {
        ApiError {
            retry_after: Some(1),
            ..Self::new(Kind::Unavailable, "overloaded", "too many syntheses in flight; retry shortly")
        }
    }
    /// The synthesis took longer than the request timeout.
    pub fn timeout() -> Self {
        ApiError { retry_after: Some(5), ..Self::new(Kind::Unavailable, "timeout", "synthesis took too long") }
    }
    /// A fault of ours.
    pub fn internal(message: impl Into<String>) -> Self {
        Self::new(Kind::Internal, "internal", message)
    }
}

impl From<CoreError> for ApiError {
    fn from(e: CoreError) -> Self {
        let msg = e.to_string();
        match e {
            CoreError::Param { .. } | CoreError::ParamKey { .. } => Self::bad_request("invalid_parameter", msg),
            CoreError::UnknownParam { .. } => Self::bad_request("unknown_parameter", msg),
            CoreError::Window { .. } => Self::bad_request("invalid_window", msg),
            CoreError::Map { .. } => Self::bad_request("invalid_map", msg),
            CoreError::Sample { .. } => Self::bad_request("invalid_sample", msg),
            CoreError::Declined { .. } => Self::new(Kind::Unprocessable, "mode_declines_texture", msg),
            CoreError::Cancelled => Self::new(Kind::Unavailable, "cancelled", msg),
            CoreError::ExemplarUndecodable(_) => Self::new(Kind::Unprocessable, "undecodable_image", msg),
            CoreError::ExemplarSize { .. } => Self::new(Kind::Unprocessable, "image_size", msg),
            CoreError::FlatExemplar { .. } => Self::bad_request("flat_image", msg),
            CoreError::AnalysisWork { .. } => Self::new(Kind::Unprocessable, "analysis_work", msg),
            CoreError::NotAnalysed { .. } | CoreError::NotPrepared { .. } => {
                ApiError { retry_after: Some(2), ..Self::new(Kind::Unavailable, "not_ready", msg) }
            }
            CoreError::Io { .. } | CoreError::AnalysisFile { .. } => Self::internal(msg),
        }
    }
}

impl std::fmt::Display for ApiError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.code, self.message)
    }
}

impl std::error::Error for ApiError {}
