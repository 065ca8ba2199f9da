//! OGC 3D Tiles 1.1 endpoints: a texture's tileset (implicit quadtree over its zooms, same
//! query parameters as tiles, optional Earth anchoring with `lon`, `lat`, `height`), its subtree
//! files, and its content tiles (the glTF tiles of `/gltf`, addressed by implicit coordinates).
//! The documents themselves are built by [`crate::scene::tileset`].

use std::sync::Arc;

use axum::extract::rejection::PathRejection;
use axum::extract::{Path, RawQuery, State};
use axum::http::HeaderMap;
use axum::response::Response;

use crate::encode::Format;
use crate::error::ApiError;
use crate::http::content::answer;
use crate::http::content::{if_none_match, image, not_modified};
use crate::http::extract::{path_error, served};
use crate::http::models::split_ext;
use crate::output::Output;
use crate::pipeline::etag_for;
use crate::request::{query_pairs, query_string, TileSpec};
use crate::scene::model::{generator, subject_with_relief, Model};
use crate::scene::tileset::{enu_to_ecef, subtree, tileset, Content, Tree, SUBTREE_LEVELS};
use crate::state::AppState;
use crate::textures::Served;
use textile_core::ParamReader;

/// The tileset's anchoring parameters. Content requests accept and ignore them: CesiumJS carries
/// the tileset URL's query into every URL it resolves against it.
const ANCHORING: [&str; 3] = ["lon", "lat", "height"];

/// The pairs of query `raw` without the anchoring parameters.
fn without_anchoring(raw: Option<&str>) -> Vec<(String, String)> {
    query_pairs(raw).into_iter().filter(|(k, _)| !ANCHORING.contains(&k.as_str())).collect()
}

/// The tileset's tree for a texture or landscape: zooms `0..=max_zoom` below the levels above
/// zoom 0, world units being native texels.
fn tree(s: &Served) -> Tree {
    let z = s.zooms();
    Tree::new(z.native, z.max)
}

fn number(name: &str, v: &str, lo: f64, hi: f64) -> Result<f64, ApiError> {
    v.parse::<f64>().ok().filter(|x| (lo..=hi).contains(x)).ok_or_else(|| {
        ApiError::bad_request("invalid_parameter", format!("parameter '{name}': '{v}' is not a number in [{lo}, {hi}]"))
    })
}

/// Implicit tile coordinates from the path: level, x, y (the last one with its extension).
fn implicit(tree: &Tree, level: &str, x: &str, y: &str) -> Result<(u32, i64, i64), ApiError> {
    let bad = || {
        ApiError::bad_request(
            "invalid_coordinate",
            format!(
                "'{level}/{x}/{y}' is not a tile of the tileset (levels 0 to {}, x and y 0 to 2^level − 1)",
                tree.levels.saturating_sub(1)
            ),
        )
    };
    let level: u32 = level.parse().map_err(|_| bad())?;
    let (x, y): (i64, i64) = (x.parse().map_err(|_| bad())?, y.parse().map_err(|_| bad())?);
    if !tree.contains(level, x, y) {
        return Err(bad());
    }
    Ok((level, x, y))
}

/// The tileset JSON: implicit quadtree tiling of the texture's zooms with glTF content.
#[utoipa::path(get, path = "/3dtiles/{id}/tileset.json", tag = "3d",
    params(("id" = String, Path, description = "texture or landscape id"),
           ("lon" = Option<f64>, Query, description = "anchor the root on WGS 84: longitude in degrees (with lat)"),
           ("lat" = Option<f64>, Query, description = "latitude in degrees (with lon)"),
           ("height" = Option<f64>, Query, description = "metres above the ellipsoid (default 0)")),
    responses((status = 200, description = "application/json: a 3D Tiles 1.1 tileset"), (status = 304, description = "not modified"),
              (status = 400, description = "bad parameters"), (status = 404, description = "unknown texture")))]
pub async fn tileset_json(
    State(st): State<Arc<AppState>>,
    path: Result<Path<String>, PathRejection>,
    RawQuery(raw): RawQuery,
    headers: HeaderMap,
) -> Result<Response, ApiError> {
    let reg = st.ready()?;
    let Path(id) = path.map_err(path_error)?;
    let subject = served(&reg, &id)?;
    let mut reader = ParamReader::request(query_pairs(raw.as_deref()))?;
    let (lon, lat, height) = (reader.take("lon"), reader.take("lat"), reader.take("height"));
    let transform = match (lon, lat) {
        (Some(lon), Some(lat)) => {
            let h = height.as_deref().map(|h| number("height", h, -11_000.0, 100_000.0)).transpose()?;
            let (lon, lat) = (number("lon", &lon, -180.0, 180.0)?, number("lat", &lat, -90.0, 90.0)?);
            Some(enu_to_ecef(lon, lat, h.unwrap_or(0.0)))
        }
        (None, None) if height.is_none() => None,
        _ => {
            return Err(ApiError::bad_request(
                "missing_parameter",
                "anchoring the tileset needs both 'lon' and 'lat' ('height' is optional)",
            ))
        }
    };
    // Everything else is the tiles' query: validated here, carried into the content URIs.
    let pairs = without_anchoring(raw.as_deref());
    let mut reader = ParamReader::request(pairs.clone())?;
    // Taken above: named among the allowed keys when an unknown one is refused.
    for key in ANCHORING {
        reader.take(key);
    }
    let zero = TileSpec { z: 0, x: 0, y: 0, scale: 1, format: Format::Png };
    let (what, relief) = subject_with_relief(subject.clone(), zero, reader)?;
    // Sorted: one URI (and cache entry) per set of parameters, however they were ordered.
    let query = query_string(&pairs.into_iter().collect::<std::collections::BTreeMap<_, _>>());
    let etag = etag_for(&what.key(format_args!("tileset{}|{query}|{transform:?}", crate::scene::assets::LAYOUT)));
    let cc = &st.cache_control;
    if if_none_match(&headers, &etag) {
        return Ok(not_modified(&etag, cc));
    }
    let doc = tileset(&tree(&subject), &query, transform, relief, &generator());
    let body = serde_json::to_vec(&doc).map_err(|e| ApiError::internal(e.to_string()))?;
    Ok(image(body.into(), "application/json", &etag, cc, false))
}

/// A subtree file of the tileset (binary `.subtree`).
#[utoipa::path(get, path = "/3dtiles/{id}/subtrees/{level}/{x}/{y}.subtree", tag = "3d",
    params(("id" = String, Path, description = "texture or landscape id"), ("level" = u32, Path, description = "implicit level (a multiple of the subtree levels)"),
           ("x" = i64, Path, description = "implicit x (east)"), ("y" = i64, Path, description = "implicit y (north)")),
    responses((status = 200, description = "application/octet-stream: a 3D Tiles 1.1 subtree"),
              (status = 400, description = "not a subtree of the tileset"), (status = 404, description = "unknown texture")))]
pub async fn subtree_file(
    State(st): State<Arc<AppState>>,
    path: Result<Path<(String, String, String, String)>, PathRejection>,
    headers: HeaderMap,
) -> Result<Response, ApiError> {
    let reg = st.ready()?;
    let Path((id, level, x, y)) = path.map_err(path_error)?;
    let tree = tree(&served(&reg, &id)?);
    let (y, _) = split_ext(&y, &["subtree"])?;
    let (level, _, _) = implicit(&tree, &level, &x, y)?;
    if !level.is_multiple_of(SUBTREE_LEVELS) {
        return Err(ApiError::bad_request(
            "invalid_coordinate",
            format!("subtrees start at levels that are multiples of {SUBTREE_LEVELS}, not {level}"),
        ));
    }
    let etag = etag_for(&format!("subtree|{}|{}|{level}", tree.native, tree.levels));
    let cc = &st.cache_control;
    if if_none_match(&headers, &etag) {
        return Ok(not_modified(&etag, cc));
    }
    Ok(image(subtree(&tree, level).into(), "application/octet-stream", &etag, cc, false))
}

/// A content tile of the tileset: the GLB of XYZ tile `level − lift / x − 2^(level−1) /
/// 2^(level−1) − 1 − y`, or above zoom 0 a quad of zoom 0's colour ([`Tree::content`]; the
/// tileset's anchoring parameters, if a client carries them along, are ignored).
#[utoipa::path(get, path = "/3dtiles/{id}/tiles/{level}/{x}/{y}.glb", tag = "3d",
    params(("id" = String, Path, description = "texture or landscape id"), ("level" = u32, Path, description = "implicit level = zoom + lift (the tileset's extras.level_of_zoom_0)"),
           ("x" = i64, Path, description = "implicit x (east) = column + 2^(level−1)"), ("y" = i64, Path, description = "implicit y (north) = 2^(level−1) − 1 − row")),
    responses((status = 200, description = "model/gltf-binary"), (status = 304, description = "not modified"),
              (status = 400, description = "not a tile of the tileset, or bad parameters"), (status = 404, description = "unknown texture")))]
pub async fn content_tile(
    State(st): State<Arc<AppState>>,
    path: Result<Path<(String, String, String, String)>, PathRejection>,
    RawQuery(raw): RawQuery,
    headers: HeaderMap,
) -> Result<Response, ApiError> {
    let reg = st.ready()?;
    let Path((id, level, x, y)) = path.map_err(path_error)?;
    let subject = served(&reg, &id)?;
    let (y, _) = split_ext(&y, &["glb"])?;
    let tree = tree(&subject);
    let (level, x, y) = implicit(&tree, &level, &x, y)?;
    let pairs = without_anchoring(raw.as_deref());
    let model = match tree.content(level, x, y) {
        Content::Tile { z, x, y } => {
            Model::request(subject, TileSpec { z, x, y, scale: 1, format: Format::Png }, pairs)?
        }
        Content::Lifted { span, x, y } => {
            Model::request(subject, TileSpec { z: 0, x, y, scale: 1, format: Format::Png }, pairs)?.lifted(span)
        }
    };
    answer(&st, &headers, Output::Glb(model)).await
}
