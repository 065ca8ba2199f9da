//! The HTTP service: routes, middleware (CORS, compression of JSON, panic → 500 JSON) and the
//! modules behind them (errors, content headers, state, image and descriptive endpoints).

pub mod content;
pub mod error;
pub mod images;
pub mod meta;
pub mod models;
pub mod state;
pub mod static_files;

use std::sync::Arc;

use axum::http::{header, HeaderValue, Method};
use axum::response::IntoResponse;
use axum::routing::get;
use axum::Router;
use tower_http::catch_panic::CatchPanicLayer;
use tower_http::compression::CompressionLayer;
use tower_http::cors::{AllowOrigin, CorsLayer};

use self::error::ApiError;
use self::state::AppState;

/// Build the router for a state.
pub fn router(state: Arc<AppState>) -> Router {
    let cors = CorsLayer::new()
        .allow_methods([Method::GET, Method::HEAD])
        .allow_headers([header::IF_NONE_MATCH])
        .expose_headers([header::ETAG, header::HeaderName::from_static("x-cache")])
        .allow_origin(if state.config.cors_origins.iter().any(|o| o == "*") {
            AllowOrigin::any()
        } else {
            AllowOrigin::list(state.config.cors_origins.iter().filter_map(|o| HeaderValue::from_str(o).ok()))
        });
    Router::new()
        .route("/", get(static_files::index))
        .route("/world.html", get(static_files::world))
        .route("/static/{*path}", get(static_files::static_file))
        .route("/health", get(meta::health))
        .route("/ready", get(meta::ready))
        .route("/catalog", get(meta::catalog))
        .route("/openapi.json", get(meta::openapi))
        .route("/textures/{id}", get(meta::texture_meta))
        .route("/textures/{id}/exemplar.png", get(meta::exemplar))
        .route("/tiles/{id}/tilejson.json", get(meta::tilejson))
        .route("/tiles/{id}/{z}/{x}/{y}", get(images::tile))
        .route("/windows/{file}", get(images::window))
        .route("/gltf/{id}/patch.glb", get(models::gltf_patch))
        .route("/gltf/{id}/{z}/{x}/{y}", get(models::gltf_tile))
        .route("/x3d/{id}/{z}/{x}/{y}", get(models::x3d_tile))
        .fallback(meta::not_found)
        .method_not_allowed_fallback(meta::method_not_allowed)
        .with_state(state)
        .layer(CompressionLayer::new())
        .layer(cors)
        .layer(CatchPanicLayer::custom(|_| ApiError::internal("the request handler panicked").into_response()))
}
