//! `POST /samples/{id}`: per-sample queries for renderers. The body — JSON
//! (`application/json`) or binary records (`application/octet-stream`, kind chosen by
//! `records=`) — is read up to its limit and parsed by [`crate::sampling`]; the answer is JSON
//! colours or packed RGB, in request order, with the work it took in `X-Textile-Computed`
//! (pixels computed at all levels) and `X-Textile-Windows`. A landscape's samples are its
//! tiles' pixels (its blended colour, or a map every layer has), filtered as a texture's.

use std::sync::Arc;

use axum::body::{to_bytes, Body};
use axum::extract::rejection::PathRejection;
use axum::extract::{Path, RawQuery, State};
use axum::http::{header, HeaderMap, HeaderValue};
use axum::response::{IntoResponse, Response};
use axum::Json;
use textile_core::maps::MapChoice;

use crate::encode::Format;
use crate::error::{ApiError, Kind};
use crate::http::extract::{media_type, path_error, served};
use crate::pipeline::landscape::{LandscapeJob, LandscapeMap};
use crate::pipeline::subject::Subject;
use crate::pipeline::Target;
use crate::request::{params, query_reader, TileSpec};
use crate::sampling::{self, parse_binary, parse_json, Records, MAX_BODY};
use crate::state::AppState;
use crate::textures::Served;

/// Colours of scattered samples of the texture, equal to the pixels of the tiles that hold them.
#[utoipa::path(post, path = "/samples/{id}", tag = "tiles",
    params(("id" = String, Path, description = "texture or landscape id"),
           ("records" = Option<String>, Query, description = "binary bodies: `texels` (default; 20-byte records i64 x, i64 y, u32 z, little-endian: pixel (x, y) of the tile grid at zoom z) or `footprints` (20-byte records f64 u, f64 v, f32 lod: a position in native texels, filtered bilinearly within a level and linearly between levels)"),
           ("map" = Option<String>, Query, description = "albedo (default) or one of the texture's material maps (normals filtered as vectors); a landscape's: a map every layer has, or splat"),
           ("seed" = Option<u64>, Query, description = "a landscape's seed (reseeds its splat and layers), as its tiles take it"),
           ("v" = Option<String>, Query, description = "cache-busting version (content unchanged)")),
    request_body(description = "JSON `{\"points\": [[x, y], …], \"z\": Z}` (a point may be [x, y, z]; z defaults to the native zoom) or `{\"footprints\": [[u, v, lod], …]}`; or binary records (application/octet-stream). At most 262144 samples and 8 MiB.",
        content(("application/json"), ("application/octet-stream"))),
    responses((status = 200, description = "JSON `{\"colors\": [[r, g, b], …]}`, or packed RGB8 (3 bytes per sample) for a binary request; X-Textile-Computed: pixels computed for it"),
              (status = 400, description = "malformed body, sample outside the tile range or bad parameters"),
              (status = 404, description = "unknown texture"),
              (status = 408, description = "the body stopped arriving"),
              (status = 413, description = "more than 262144 samples or a body over 8 MiB"),
              (status = 415, description = "body neither application/json nor application/octet-stream"),
              (status = 503, description = "overloaded or loading; see Retry-After")))]
pub async fn samples(
    State(st): State<Arc<AppState>>,
    path: Result<Path<String>, PathRejection>,
    RawQuery(q): RawQuery,
    headers: HeaderMap,
    body: Body,
) -> Result<Response, ApiError> {
    let reg = st.ready()?;
    let Path(id) = path.map_err(path_error)?;
    let subject = served(&reg, &id)?;
    let zooms = subject.zooms();
    let mut r = query_reader(q.as_deref())?;
    let records = r.take("records").map(|s| Records::parse(&s)).transpose()?;
    // What is sampled: a texture's mode, parameters and map, or a landscape's job for its map.
    let what = match subject {
        Served::Texture(tex) => {
            let map = crate::request::map_choice(&tex, &mut r, Format::Png)?;
            if map == MapChoice::Uv {
                return Err(ApiError::bad_request(
                    "invalid_map",
                    "map 'uv': samples answer colours; the coordinates come as map=uv tiles and windows",
                ));
            }
            let params = params(&tex, r)?;
            Subject::Texture { tex, params, map }
        }
        Served::Landscape(land) => {
            let (map, dem) = LandscapeMap::read(&land, &mut r, Format::Png)?;
            if dem.is_some() {
                return Err(ApiError::bad_request(
                    "invalid_parameter",
                    "parameter 'encoding': samples answer colours, not raster-dem heights",
                ));
            }
            let zero = Target::Tile(TileSpec { z: land.native_zoom, x: 0, y: 0, scale: 1, format: Format::Png });
            Subject::Landscape(LandscapeJob::new(land, zero, (map, None), r)?)
        }
    };
    let binary = match media_type(&headers).as_str() {
        "application/json" => false,
        "application/octet-stream" => true,
        other => {
            return Err(ApiError::new(
                Kind::UnsupportedMediaType,
                "unsupported_media_type",
                format!(
                    "Content-Type '{}': use application/json or application/octet-stream",
                    textile_core::error::clip(other)
                ),
            ))
        }
    };
    if records.is_some() && !binary {
        return Err(ApiError::bad_request("invalid_parameter", "parameter 'records' applies to binary bodies only"));
    }
    let too_large =
        || ApiError::new(Kind::TooLarge, "body_too_large", format!("the body is over {MAX_BODY} bytes (8 MiB)"));
    let declared = headers.get(header::CONTENT_LENGTH).and_then(|v| v.to_str().ok()?.parse::<u64>().ok());
    if declared.is_some_and(|n| n > MAX_BODY as u64) {
        return Err(too_large());
    }
    // The body, the parsed samples, a chunk's plan and the answer (about 12 times the body's
    // size at most, measured), and a batch cache of its own when the shared one is off.
    let own_cache = if st.pyramid.is_on() { 0 } else { sampling::BATCH_CACHE };
    let _memory = st.reserve((16 << 20) + 12 * declared.unwrap_or(MAX_BODY as u64) + own_cache).await?;
    let bytes =
        to_bytes(body, MAX_BODY).await.map_err(|e| crate::http::extract::body_error(&e.to_string(), too_large))?;
    let points = if binary {
        parse_binary(zooms, &bytes, records.unwrap_or(Records::Texels))?
    } else {
        parse_json(zooms, &bytes)?
    };
    let a = match what {
        Subject::Texture { tex, params, map } => sampling::run(&st, tex, params, map, points).await?,
        Subject::Landscape(job) => sampling::run_landscape(&st, job, points).await?,
    };
    let mut resp = if binary {
        ([(header::CONTENT_TYPE, "application/octet-stream")], a.rgb).into_response()
    } else {
        let colors: Vec<[u8; 3]> = a.rgb.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        Json(serde_json::json!({ "colors": colors })).into_response()
    };
    let h = resp.headers_mut();
    h.insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    h.insert("x-textile-computed", HeaderValue::from(a.computed));
    h.insert("x-textile-windows", HeaderValue::from(a.windows));
    Ok(resp)
}
