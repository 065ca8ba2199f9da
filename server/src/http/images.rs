//! Image endpoints: tiles (`/tiles/{id}/{z}/{x}/{y}.{fmt}`) and windows (`/windows/{id}.{fmt}`).
//! Each validates its request, answers `If-None-Match` without rendering, and otherwise goes
//! through the cache to a synthesis.

use std::sync::Arc;

use axum::body::Bytes;
use axum::extract::rejection::PathRejection;
use axum::extract::{Path, RawQuery, State};
use axum::http::HeaderMap;
use axum::response::Response;

use crate::encode::{encode, Effort, Format};
use textile_core::{Pyramid, Rendered};

use crate::http::content::{engine_version, etag_for, if_none_match, image, not_modified};
use crate::http::error::ApiError;
use crate::http::meta::texture;
use crate::http::state::AppState;
use crate::render::{render_tile, render_window};
use crate::textures::Texture;
use crate::tile_request::{
    parse_query, parse_tile, parse_window, render_params, split_format, RenderParams, TileSpec, PARAM_KEYS, WINDOW_KEYS,
};

pub(crate) fn path_error(e: PathRejection) -> ApiError {
    ApiError::bad_request("invalid_path", format!("malformed path: {}", e.body_text()))
}

/// Bytes for a key from the cache, or from `make` on the synthesis pool (single-flight).
pub(crate) async fn cached<F>(st: &Arc<AppState>, etag: &str, mode: &str, make: F) -> (Result<Bytes, ApiError>, bool)
where
    F: FnOnce() -> Result<Vec<u8>, ApiError> + Send + 'static,
{
    st.cache.get_or_compute(etag, || st.synthesize(mode, make)).await
}

/// [`cached`] for an image render: the job renders (through the pyramidal cache) and encodes,
/// and counts its pixels (synthesized and delivered) when it actually runs.
async fn cached_render<F>(
    st: &Arc<AppState>,
    etag: &str,
    mode: &'static str,
    fmt: Format,
    effort: Effort,
    render: F,
) -> (Result<Bytes, ApiError>, bool)
where
    F: FnOnce(&Pyramid) -> Result<Rendered, textile_core::CoreError> + Send + 'static,
{
    let (synthesized, delivered) = (st.metrics.pixels_synthesized.clone(), st.metrics.pixels_delivered.clone());
    let pyramid = st.pyramid.clone();
    cached(st, etag, mode, move || {
        let r = render(&pyramid)?;
        synthesized.with_label_values(&[mode]).inc_by(r.synthesized);
        delivered.with_label_values(&[mode]).inc_by(r.image.width as u64 * r.image.height as u64);
        encode_window(r.image, fmt, effort)
    })
    .await
}

/// A cache key (and, hashed, the ETag): everything that determines an answer's bytes — engine
/// version, texture and analysis, canonical parameters — then `what` (the kind and address).
pub(crate) fn cache_key(tex: &Texture, p: &RenderParams, what: std::fmt::Arguments) -> String {
    format!("{}|{}|{}|{}|{what}", engine_version(), tex.config.id, tex.file_hash, p.canonical())
}

/// The cache key of a tile.
pub(crate) fn tile_key(tex: &Texture, p: &RenderParams, t: &TileSpec) -> String {
    cache_key(tex, p, format_args!("tile|{}|{}|{}|{}|{}", t.z, t.x, t.y, t.scale, t.format.ext()))
}

/// The encoded bytes of a tile, through the cache.
pub(crate) async fn tile_bytes(
    st: &Arc<AppState>,
    tex: &Arc<Texture>,
    p: &RenderParams,
    spec: TileSpec,
) -> Result<Bytes, ApiError> {
    let (tex, p) = (tex.clone(), p.clone());
    let etag = etag_for(&tile_key(&tex, &p, &spec));
    cached_render(st, &etag, p.mode(), spec.format, p.effort(), move |pyr| render_tile(pyr, &tex, &p, &spec)).await.0
}

fn encode_window(img: textile_core::RgbWindow, fmt: Format, effort: Effort) -> Result<Vec<u8>, ApiError> {
    encode(&img.pixels, img.width, img.height, fmt, effort).map_err(|e| ApiError::internal(format!("encoding: {e}")))
}

async fn answer<F>(
    st: &Arc<AppState>,
    headers: &HeaderMap,
    key: String,
    mode: &'static str,
    fmt: Format,
    effort: Effort,
    job: F,
) -> Result<Response, ApiError>
where
    F: FnOnce(&Pyramid) -> Result<Rendered, textile_core::CoreError> + Send + 'static,
{
    let etag = etag_for(&key);
    let cc = &st.config.cache_control;
    if if_none_match(headers, &etag) {
        return Ok(not_modified(&etag, cc));
    }
    let (bytes, hit) = cached_render(st, &etag, mode, fmt, effort, job).await;
    Ok(image(bytes?, fmt.content_type(), &etag, cc, hit))
}

/// A tile of the infinite texture.
#[utoipa::path(get, path = "/tiles/{id}/{z}/{x}/{y}.{fmt}", tag = "tiles",
    params(("id" = String, Path, description = "texture id"),
           ("z" = u32, Path, description = "zoom, minzoom..=maxzoom"),
           ("x" = i64, Path, description = "column, -2^31..2^31-1"),
           ("y" = i64, Path, description = "row, -2^31..2^31-1; append @2x for 512 px tiles"),
           ("fmt" = String, Path, description = "png, jpg, jpeg or webp"),
           ("mode" = Option<String>, Query, description = "synth"),
           ("seed" = Option<u64>, Query, description = "selects another, equally good texture"),
           ("randomness" = Option<String>, Query, description = "one value in [0,1] or one per level, coarse to fine"),
           ("world" = Option<u64>, Query, description = "period in native tiles (power of two): seamless wrapped world"),
           ("v" = Option<String>, Query, description = "cache-busting version (content unchanged)")),
    responses((status = 200, description = "the tile image"), (status = 304, description = "not modified"),
              (status = 400, description = "bad coordinates or parameters"), (status = 404, description = "unknown texture"),
              (status = 503, description = "overloaded or loading; see Retry-After")))]
pub async fn tile(
    State(st): State<Arc<AppState>>,
    path: Result<Path<(String, String, String, String)>, PathRejection>,
    RawQuery(q): RawQuery,
    headers: HeaderMap,
) -> Result<Response, ApiError> {
    let reg = st.ready()?;
    let Path((id, z, x, y)) = path.map_err(path_error)?;
    let tex = texture(reg, &id)?;
    let spec = parse_tile(&tex, &z, &x, &y)?;
    let q = parse_query(q.as_deref(), PARAM_KEYS)?;
    let p = render_params(&tex, &q)?;
    let key = tile_key(&tex, &p, &spec);
    answer(&st, &headers, key, p.mode(), spec.format, p.effort(), move |pyr| render_tile(pyr, &tex, &p, &spec)).await
}

/// Any rectangle of the texture at zoom `z`, as one image.
#[utoipa::path(get, path = "/windows/{id}.{fmt}", tag = "tiles",
    params(("id" = String, Path, description = "texture id"), ("fmt" = String, Path, description = "png, jpg, jpeg or webp"),
           ("x" = i64, Query, description = "left pixel at zoom z"), ("y" = i64, Query, description = "top pixel at zoom z"),
           ("w" = u32, Query, description = "width, 1..=4096"), ("h" = u32, Query, description = "height, 1..=4096"),
           ("z" = Option<u32>, Query, description = "zoom (default: native)"),
           ("mode" = Option<String>, Query, description = "synth"), ("seed" = Option<u64>, Query, description = "seed"),
           ("randomness" = Option<String>, Query, description = "randomness"), ("world" = Option<u64>, Query, description = "period in native tiles"),
           ("v" = Option<String>, Query, description = "cache-busting version")),
    responses((status = 200, description = "the window image"), (status = 400, description = "bad parameters"),
              (status = 404, description = "unknown texture")))]
pub async fn window(
    State(st): State<Arc<AppState>>,
    path: Result<Path<String>, PathRejection>,
    RawQuery(q): RawQuery,
    headers: HeaderMap,
) -> Result<Response, ApiError> {
    let reg = st.ready()?;
    let Path(file) = path.map_err(path_error)?;
    let (id, fmt) = split_format(&file)?;
    let tex = texture(reg, id)?;
    let q = parse_query(q.as_deref(), WINDOW_KEYS)?;
    let spec = parse_window(&tex, &q, fmt)?;
    let params: crate::tile_request::Query =
        q.iter().filter(|(k, _)| PARAM_KEYS.contains(&k.as_str())).map(|(k, v)| (k.clone(), v.clone())).collect();
    let p = render_params(&tex, &params)?;
    let key = cache_key(
        &tex,
        &p,
        format_args!("window|{}|{}|{}|{}|{}|{}", spec.z, spec.x, spec.y, spec.w, spec.h, fmt.ext()),
    );
    answer(&st, &headers, key, p.mode(), fmt, p.effort(), move |pyr| render_window(pyr, &tex, &p, &spec)).await
}
