//! Image endpoints: tiles (`/tiles/{id}/{z}/{x}/{y}.{fmt}`) and windows (`/windows/{id}.{fmt}`),
//! of textures and of landscapes.
//! Each validates its request into an [`ImageJob`] and answers it as an [`Output`] (`If-None-Match`
//! without rendering, else the bytes through the pipeline). The mode parameters accepted
//! in the query are documented from the modes' specs (see `http::openapi`).

use std::sync::Arc;

use axum::extract::rejection::PathRejection;
use axum::extract::{Path, RawQuery, State};
use axum::http::HeaderMap;
use axum::response::Response;

use crate::error::ApiError;
use crate::etag_memo::{url_key, Stamp};
use crate::http::content::{answer, answer_tagged};
use crate::http::extract::{path_error, texture};
use crate::output::Output;
use crate::pipeline::landscape::{LandscapeJob, LandscapeMap};
use crate::pipeline::{ImageJob, Target};
use crate::request::{
    map_and_dem, params, parse_tile, parse_tile_in, parse_window, parse_window_in, query_reader, split_format,
};
use crate::state::AppState;

/// A tile of the infinite texture.
#[utoipa::path(get, path = "/tiles/{id}/{z}/{x}/{y}.{fmt}", tag = "tiles",
    params(("id" = String, Path, description = "texture id"),
           ("z" = u32, Path, description = "zoom, minzoom..=maxzoom"),
           ("x" = i64, Path, description = "column, -2^31..2^31-1"),
           ("y" = i64, Path, description = "row, -2^31..2^31-1; append @2x for 512 px tiles"),
           ("fmt" = String, Path, description = "png, jpg, jpeg or webp"),
           ("map" = Option<String>, Query, description = "albedo (default), one of the texture's material maps, or uv (16-bit PNG coordinates)"),
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
    // Read before the catalogue: a memo made with an older catalogue is never used.
    let generation = st.etags.generation();
    let reg = st.ready()?;
    let Path((id, z, x, y)) = path.map_err(path_error)?;
    // Remembered with its ETag, and the textures it renders as they stand: asked again, the hot
    // path answers it (`http::hot_tiles`).
    let url = url_key(&format!("{id}/{z}/{x}/{y}"), q.as_deref());
    let (out, stamps) = if let Some(land) = reg.landscape(&id) {
        let spec = parse_tile_in(land.zooms(), &z, &x, &y)?;
        let mut r = query_reader(q.as_deref())?;
        let map = LandscapeMap::read(land, &mut r, spec.format)?;
        let job = LandscapeJob::new(land.clone(), Target::Tile(spec), map, r)?;
        let stamps = job.layers.iter().map(|j| Stamp::new(&j.tex, j.params.name())).collect();
        (Output::Landscape(job), stamps)
    } else {
        let tex = texture(&reg, &id)?;
        let spec = parse_tile(&tex, &z, &x, &y)?;
        let mut r = query_reader(q.as_deref())?;
        let (map, dem) = map_and_dem(&tex, &mut r, spec.format)?;
        let params = params(&tex, r)?;
        let stamps = vec![Stamp::new(&tex, params.name())];
        (Output::Image(ImageJob { tex, params, target: Target::Tile(spec), map, dem }), stamps)
    };
    let etag = out.etag();
    st.etags.put(&url, generation, &etag, out.content_type(), stamps);
    answer_tagged(&st, &headers, out, etag).await
}

/// Any rectangle of the texture at zoom `z`, as one image.
#[utoipa::path(get, path = "/windows/{id}.{fmt}", tag = "tiles",
    params(("id" = String, Path, description = "texture id"), ("fmt" = String, Path, description = "png, jpg, jpeg or webp"),
           ("x" = i64, Query, description = "left pixel at zoom z"), ("y" = i64, Query, description = "top pixel at zoom z"),
           ("w" = u32, Query, description = "width, 1..=4096"), ("h" = u32, Query, description = "height, 1..=4096"),
           ("z" = Option<u32>, Query, description = "zoom (default: native)"),
           ("map" = Option<String>, Query, description = "albedo (default), one of the texture's material maps, or uv"),
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
    if let Some(land) = reg.landscape(id) {
        let mut r = query_reader(q.as_deref())?;
        let spec = parse_window_in(land.zooms(), &mut r, fmt)?;
        let map = LandscapeMap::read(land, &mut r, fmt)?;
        let job = LandscapeJob::new(land.clone(), Target::Window(spec), map, r)?;
        return answer(&st, &headers, Output::Landscape(job)).await;
    }
    let tex = texture(&reg, id)?;
    let mut r = query_reader(q.as_deref())?;
    let spec = parse_window(&tex, &mut r, fmt)?;
    let (map, dem) = map_and_dem(&tex, &mut r, fmt)?;
    let params = params(&tex, r)?;
    answer(&st, &headers, Output::Image(ImageJob { tex, params, target: Target::Window(spec), map, dem })).await
}
