//! Descriptive endpoints: health and readiness, the catalog, texture metadata and exemplar,
//! TileJSON 3.0.0, the OpenAPI document and the viewer page.

use std::sync::Arc;

use axum::extract::rejection::PathRejection;
use axum::extract::{Path, RawQuery, State};
use axum::http::{header, HeaderMap, HeaderValue, Method, Uri};
use axum::response::{IntoResponse, Response};
use axum::Json;
use serde_json::{json, Value};
use utoipa::OpenApi;

use crate::http::content::engine_version;
use crate::http::error::ApiError;
use crate::http::images::path_error;
use crate::http::state::AppState;
use crate::textures::{Registry, Texture};
use crate::tile_request::{parse_query, render_params, MODES, PARAM_KEYS};

/// The texture with `id`, or a 404 naming the available ones.
pub(crate) fn texture(reg: &Registry, id: &str) -> Result<Arc<Texture>, ApiError> {
    reg.get(id).cloned().ok_or_else(|| {
        let known: Vec<String> = reg.list.iter().map(|t| t.config.id.clone()).collect();
        ApiError::unknown_texture(id, &known)
    })
}

/// `http://HOST` of a request (for absolute URLs in documents).
pub(crate) fn base_url(st: &AppState, headers: &HeaderMap) -> String {
    let host = headers.get(header::HOST).and_then(|h| h.to_str().ok()).unwrap_or(&st.config.bind);
    format!("http://{host}")
}

/// Liveness.
#[utoipa::path(get, path = "/health", tag = "service", responses((status = 200, description = "alive")))]
pub async fn health(State(st): State<Arc<AppState>>) -> Json<Value> {
    let (entries, bytes) = st.cache.usage();
    let pyr = st.pyramid.stats();
    Json(json!({
        "status": "ok",
        "version": env!("CARGO_PKG_VERSION"),
        "engine": engine_version(),
        "ready": st.registry.get().is_some(),
        "textures": st.registry.get().map(|r| r.list.len()).unwrap_or(0),
        "tiles_synthesized": st.syntheses(),
        "shed": st.metrics.shed.get(),
        "cache": {
            "entries": entries, "bytes": bytes, "limit_bytes": st.config.cache_mib << 20,
            "hits": st.cache.stats.hits.get(),
            "misses": st.cache.stats.misses.get(),
            "evictions": st.cache.stats.evictions.get(),
        },
        "level_cache": {
            "blocks": pyr.blocks, "bytes": pyr.bytes, "limit_bytes": st.config.level_cache_mib << 20,
            "hits": pyr.hits, "misses": pyr.misses, "evictions": pyr.evictions,
        },
    }))
}

/// Readiness: 200 once every texture is loaded, 503 before.
#[utoipa::path(get, path = "/ready", tag = "service",
    responses((status = 200, description = "ready"), (status = 503, description = "still loading")))]
pub async fn ready(State(st): State<Arc<AppState>>) -> Result<Json<Value>, ApiError> {
    st.ready()?;
    Ok(Json(json!({"status": "ready"})))
}

/// The textures served.
#[utoipa::path(get, path = "/catalog", tag = "textures", responses((status = 200, description = "catalog")))]
pub async fn catalog(State(st): State<Arc<AppState>>, headers: HeaderMap) -> Result<Json<Value>, ApiError> {
    let reg = st.ready()?;
    let base = base_url(&st, &headers);
    let textures: Vec<Value> = reg
        .list
        .iter()
        .map(|t| {
            json!({
                "id": t.config.id, "name": t.config.name, "modes": MODES, "default_mode": t.config.default_mode,
                "tilejson": format!("{base}/tiles/{}/tilejson.json", t.config.id),
                "exemplar": format!("{base}/textures/{}/exemplar.png", t.config.id),
            })
        })
        .collect();
    Ok(Json(json!({ "textures": textures })))
}

/// Metadata of one texture.
#[utoipa::path(get, path = "/textures/{id}", tag = "textures",
    params(("id" = String, Path, description = "texture id")),
    responses((status = 200, description = "metadata"), (status = 404, description = "unknown texture")))]
pub async fn texture_meta(
    State(st): State<Arc<AppState>>,
    path: Result<Path<String>, PathRejection>,
) -> Result<Json<Value>, ApiError> {
    let reg = st.ready()?;
    let Path(id) = path.map_err(path_error)?;
    let t = texture(reg, &id)?;
    let h = &t.analysis.header;
    let levels = h.levels;
    Ok(Json(json!({
        "id": t.config.id,
        "name": t.config.name,
        "attribution": t.config.attribution,
        "exemplar": {
            "width": h.side, "height": h.side, "toroidal": h.toroidal,
            "input_width": h.preparation.input_width, "input_height": h.preparation.input_height,
            "crop_side": h.preparation.crop_side, "toroidal_forced": h.preparation.toroidal_forced,
        },
        "analysis": { "id": h.id, "file_hash": t.file_hash, "algorithm_version": h.algorithm_version },
        "modes": MODES,
        "default_mode": t.config.default_mode,
        "native_zoom": t.native_zoom(),
        "minzoom": t.min_zoom(),
        "maxzoom": t.max_zoom(),
        "tile_size": crate::tile_request::TILE_SIZE,
        "levels": levels + 1,
        "synthesis": {
            "kappa": t.defaults.kappa as f64 / 65536.0,
            "passes": t.defaults.passes,
            "subpasses": t.defaults.subpasses,
            "description": "fixed settings of this texture's synth mode (set in the configuration, not per request)",
        },
        "parameters": {
            "seed": { "default": t.defaults.seed, "min": 0, "max": u64::MAX },
            "randomness": {
                "modes": ["synth"],
                "default": t.defaults.randomness.resolve(levels).iter().map(|&r| r as f64 / 65536.0).collect::<Vec<_>>(),
                "min": 0.0, "max": 1.0, "values": levels + 1,
                "description": "one value for every level or a comma list of one per level, coarse to fine",
            },
            "world": { "default": null, "min": (h.side as i64 / crate::tile_request::TILE_SIZE).max(1),
                       "max": crate::tile_request::MAX_WORLD, "description": "power of two: period in native tiles" },
            "mode": { "default": t.config.default_mode, "values": MODES },
            "iterations": { "default": 10, "min": 0, "max": textile_core::mosaic::MAX_ITERATIONS, "modes": ["mosaic"] },
            "smoothing": { "default": 3, "min": 0, "max": textile_core::mosaic::MAX_SMOOTHING, "modes": ["mosaic"] },
            "block_area": { "default": [0.5, 0.75], "min": 0.05, "max": 1.0, "modes": ["mosaic"],
                            "description": "MIN,MAX block area as fractions of the exemplar area" },
        },
    })))
}

/// The prepared exemplar image.
#[utoipa::path(get, path = "/textures/{id}/exemplar.png", tag = "textures",
    params(("id" = String, Path, description = "texture id")),
    responses((status = 200, description = "PNG"), (status = 404, description = "unknown texture")))]
pub async fn exemplar(
    State(st): State<Arc<AppState>>,
    path: Result<Path<String>, PathRejection>,
) -> Result<Response, ApiError> {
    let reg = st.ready()?;
    let Path(id) = path.map_err(path_error)?;
    let t = texture(reg, &id)?;
    let mut r = t.exemplar_png.clone().into_response();
    r.headers_mut().insert(header::CONTENT_TYPE, HeaderValue::from_static("image/png"));
    r.headers_mut().insert(header::CACHE_CONTROL, HeaderValue::from_static("public, max-age=3600"));
    Ok(r)
}

/// TileJSON 3.0.0 of a texture; query parameters are validated and carried into `tiles`.
#[utoipa::path(get, path = "/tiles/{id}/tilejson.json", tag = "tiles",
    params(("id" = String, Path, description = "texture id"),
           ("mode" = Option<String>, Query, description = "carried into the tiles template"),
           ("seed" = Option<u64>, Query, description = "carried into the tiles template"),
           ("randomness" = Option<String>, Query, description = "carried into the tiles template"),
           ("world" = Option<u64>, Query, description = "carried into the tiles template")),
    responses((status = 200, description = "TileJSON"), (status = 404, description = "unknown texture")))]
pub async fn tilejson(
    State(st): State<Arc<AppState>>,
    path: Result<Path<String>, PathRejection>,
    RawQuery(raw): RawQuery,
    headers: HeaderMap,
) -> Result<Json<Value>, ApiError> {
    let reg = st.ready()?;
    let Path(id) = path.map_err(path_error)?;
    let t = texture(reg, &id)?;
    let q = parse_query(raw.as_deref(), PARAM_KEYS)?;
    render_params(&t, &q)?;
    // Everything that decides a tile's bytes besides its own request: engine, analysis, and the
    // texture's configured defaults (a changed default seed or κ must not hit stale immutable copies).
    let version = &blake3::hash(
        format!("{}|{}|{}|{}", engine_version(), t.file_hash, t.config.default_mode, t.defaults.canonical()).as_bytes(),
    )
    .to_hex()[..12];
    let mut qs = form_urlencoded::Serializer::new(String::new());
    qs.append_pair("v", version);
    for (k, v) in q.iter().filter(|(k, _)| k.as_str() != "v") {
        qs.append_pair(k, v);
    }
    let base = base_url(&st, &headers);
    Ok(Json(json!({
        "tilejson": "3.0.0",
        "name": t.config.name,
        "description": format!("Infinite example-based texture '{}' synthesized by textile", t.config.id),
        "version": "1.0.0",
        "attribution": t.config.attribution,
        "scheme": "xyz",
        "tiles": [format!("{base}/tiles/{}/{{z}}/{{x}}/{{y}}.png?{}", t.config.id, qs.finish())],
        "minzoom": t.min_zoom(),
        "maxzoom": t.max_zoom(),
        "bounds": [-180.0, -85.051_128_779_806_59, 180.0, 85.051_128_779_806_59],
        "center": [0.0, 0.0, t.native_zoom()],
        "tileSize": crate::tile_request::TILE_SIZE,
        "textile": { "texture": t.config.id, "native_zoom": t.native_zoom(), "exemplar_side": t.analysis.side() },
    })))
}

/// The OpenAPI 3 document of every route, generated from the handlers' annotations.
#[derive(OpenApi)]
#[openapi(
    info(title = "textile", description = "Infinite, deterministic, example-based texture tiles"),
    paths(
        crate::http::meta::health,
        crate::http::meta::ready,
        crate::http::meta::catalog,
        crate::http::meta::texture_meta,
        crate::http::meta::exemplar,
        crate::http::meta::tilejson,
        crate::http::images::tile,
        crate::http::images::window,
        crate::http::meta::openapi,
        crate::http::meta::metrics,
        crate::http::static_files::index,
        crate::http::static_files::world,
        crate::http::models::gltf_tile,
        crate::http::models::gltf_patch,
        crate::http::models::x3d_tile
    )
)]
pub struct ApiDoc;

/// This document.
#[utoipa::path(get, path = "/openapi.json", tag = "service", responses((status = 200, description = "OpenAPI 3")))]
pub async fn openapi() -> Json<utoipa::openapi::OpenApi> {
    Json(ApiDoc::openapi())
}

/// Prometheus metrics in the text exposition format.
#[utoipa::path(get, path = "/metrics", tag = "service", responses((status = 200, description = "Prometheus text format")))]
pub async fn metrics(State(st): State<Arc<AppState>>) -> Response {
    st.metrics.observe_pyramid(&st.pyramid.stats());
    let mut r = st.metrics.render().into_response();
    r.headers_mut().insert(header::CONTENT_TYPE, HeaderValue::from_static("text/plain; version=0.0.4; charset=utf-8"));
    r
}

/// 404 for unknown routes.
pub async fn not_found(uri: Uri) -> ApiError {
    ApiError::not_found_route(uri.path())
}

/// 405 for known routes with another method.
pub async fn method_not_allowed(method: Method, uri: Uri) -> ApiError {
    ApiError::new(
        axum::http::StatusCode::METHOD_NOT_ALLOWED,
        "method_not_allowed",
        format!("{method} is not allowed on '{}'; use GET or HEAD", uri.path()),
    )
}
