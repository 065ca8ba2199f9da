//! 3D asset endpoints: a tile as glTF (`.glb` with its image embedded, `.gltf` referencing it),
//! an N×N patch of tiles as one GLB scene, and X3D scenes of a tile or a patch. Each route only
//! reads its request into a [`Model`] and answers its [`Output`] (`crate::output`: key, ETag,
//! parts and assembly, the same as `textile render` writes): same parameters, validation, ETags
//! and caching as tiles.

use std::sync::Arc;

use axum::extract::rejection::PathRejection;
use axum::extract::{Path, RawQuery, State};
use axum::http::HeaderMap;
use axum::response::Response;
use base64::Engine;

use textile_core::ParamReader;

use crate::error::ApiError;
use crate::http::content::answer;
use crate::http::extract::{base_url, path_error, served, Peer};
use crate::output::Output;
use crate::request::{parse_tile_in, query_pairs};
use crate::scene::assets::Slot;
use crate::scene::model::{Model, MAX_PATCH, SLOT};
use crate::state::AppState;

pub(super) fn split_ext<'a>(s: &'a str, allowed: &[&str]) -> Result<(&'a str, &'a str), ApiError> {
    match s.rsplit_once('.') {
        Some((stem, ext)) if allowed.contains(&ext) => Ok((stem, ext)),
        _ => Err(ApiError::bad_request("invalid_format", format!("'{s}' must end in .{}", allowed.join(" or .")))),
    }
}

/// A .gltf document's sibling image: the slot (`slot=NAME`) among its pairs, if any, which the
/// texture must have a map for.
fn sibling_slot(model: &Model, pairs: &[(String, String)]) -> Result<Option<Slot>, ApiError> {
    let Some((_, v)) = pairs.iter().find(|(k, _)| k == SLOT) else { return Ok(None) };
    let slot = Slot::parse(v).ok_or_else(|| {
        ApiError::bad_request(
            "invalid_map",
            format!("slot '{}' is not a material image of this texture", textile_core::error::clip(v)),
        )
    })?;
    if !model.material_maps().iter().any(|(s, _)| s.image() == slot) {
        return Err(ApiError::bad_request(
            "invalid_map",
            format!("slot '{}': the texture has no map for it", slot.name()),
        ));
    }
    Ok(Some(slot))
}

/// A tile's model and its extension from the path: `{y}.{ext}`, or for an image beside a
/// .gltf `{y}.{token}.png` (the parameters, base64url, in the path) with its slot.
fn tile_request(
    st: &AppState,
    path: Result<Path<(String, String, String, String)>, PathRejection>,
    raw: Option<String>,
    exts: &[&str],
) -> Result<(Model, String, Option<Slot>), ApiError> {
    let reg = st.ready()?;
    let Path((id, z, x, y)) = path.map_err(path_error)?;
    let subject = served(&reg, &id)?;
    let (y, ext) = split_ext(&y, exts)?;
    let (y, raw) = match (ext, y.split_once('.')) {
        ("png", Some((y, token))) if raw.is_none() => {
            let q = base64::engine::general_purpose::URL_SAFE_NO_PAD
                .decode(token)
                .ok()
                .and_then(|b| String::from_utf8(b).ok())
                .ok_or_else(|| {
                    ApiError::bad_request("invalid_parameter", format!("'{token}' is not a parameter token"))
                })?;
            (y, Some(q))
        }
        _ => (y, raw),
    };
    let spec = parse_tile_in(subject.zooms(), &z, &x, &format!("{y}.png"))?;
    let pairs = query_pairs(raw.as_deref());
    if ext != "png" {
        return Ok((Model::request(subject, spec, pairs)?, ext.to_string(), None));
    }
    // The slot is read after the parameters, as a key of the sibling's own.
    let without: Vec<(String, String)> = pairs.iter().filter(|(k, _)| k != SLOT).cloned().collect();
    let model = Model::request(subject, spec, without)?;
    let slot = sibling_slot(&model, &pairs)?;
    Ok((model, ext.to_string(), slot))
}

/// A tile as a glTF 2.0 ground quad: `.glb` embeds the PNG tile, `.gltf` references the tile
/// endpoint (a URI relative to the document; the absolute URL is in `images[0].extras.tile_url`).
#[utoipa::path(get, path = "/gltf/{id}/{z}/{x}/{y}.{ext}", tag = "3d",
    params(("id" = String, Path, description = "texture or landscape id"), ("z" = u32, Path, description = "zoom"),
           ("x" = i64, Path, description = "column"), ("y" = i64, Path, description = "row"),
           ("ext" = String, Path, description = "glb (binary, image embedded), gltf (JSON, image beside it), or png: the image itself, as `{y}.png` or `{y}.{token}.png` (a material image's token has slot=normal|occlusion|specular|metallic_roughness)"),
           ("relief" = Option<f32>, Query, description = "glb of a texture with a height map: the mesh displaced, white this many texels high, (0, 256]")),
    responses((status = 200, description = "model/gltf-binary or model/gltf+json"), (status = 304, description = "not modified"),
              (status = 400, description = "bad coordinates or parameters"), (status = 404, description = "unknown texture")))]
pub async fn gltf_tile(
    State(st): State<Arc<AppState>>,
    path: Result<Path<(String, String, String, String)>, PathRejection>,
    RawQuery(raw): RawQuery,
    headers: HeaderMap,
    peer: Peer,
) -> Result<Response, ApiError> {
    let (model, ext, slot) = tile_request(&st, path, raw, &["glb", "gltf", "png"])?;
    if ext != "glb" {
        model.flat_only(&format!(".{ext}"))?;
    }
    let out = match (ext.as_str(), slot) {
        ("png", Some(slot)) => Output::MaterialImage { model, slot },
        ("png", None) => Output::from(model.image()),
        ("gltf", _) => Output::Gltf { base: base_url(&st, &headers, peer), model },
        _ => Output::Glb(model),
    };
    answer(&st, &headers, out).await
}

/// A patch's model: its top-left tile and its side in tiles, from the query's `z`, `x`, `y`
/// and `tiles`.
fn patch_request(
    st: &AppState,
    path: Result<Path<String>, PathRejection>,
    raw: Option<String>,
) -> Result<Model, ApiError> {
    let reg = st.ready()?;
    let Path(id) = path.map_err(path_error)?;
    let subject = served(&reg, &id)?;
    let pairs = query_pairs(raw.as_deref());
    let mut reader = ParamReader::request(pairs.clone())?;
    let mut need = |k: &str| {
        reader.take(k).ok_or_else(|| ApiError::bad_request("missing_parameter", format!("parameter '{k}' is required")))
    };
    let (z, x, y, n) = (need("z")?, need("x")?, need("y")?, need("tiles")?);
    let n: i64 = n.parse().ok().filter(|n| (1..=MAX_PATCH).contains(n)).ok_or_else(|| {
        ApiError::bad_request(
            "invalid_parameter",
            format!("parameter 'tiles': '{n}' is not an integer in 1..={MAX_PATCH}"),
        )
    })?;
    let origin = parse_tile_in(subject.zooms(), &z, &x, &format!("{y}.png"))?;
    let query = pairs.into_iter().filter(|(k, _)| !["z", "x", "y", "tiles"].contains(&k.as_str())).collect();
    Model::read(subject, origin, n, reader, query)
}

/// An N×N patch of tiles (top-left tile `x, y`) as one GLB scene, one node per tile.
#[utoipa::path(get, path = "/gltf/{id}/patch.glb", tag = "3d",
    params(("id" = String, Path, description = "texture or landscape id"), ("z" = u32, Query, description = "zoom"),
           ("x" = i64, Query, description = "left tile column"), ("y" = i64, Query, description = "top tile row"),
           ("tiles" = u32, Query, description = "patch side in tiles, 1..=8")),
    responses((status = 200, description = "model/gltf-binary"), (status = 400, description = "bad parameters"),
              (status = 404, description = "unknown texture")))]
pub async fn gltf_patch(
    State(st): State<Arc<AppState>>,
    path: Result<Path<String>, PathRejection>,
    RawQuery(raw): RawQuery,
    headers: HeaderMap,
) -> Result<Response, ApiError> {
    let model = patch_request(&st, path, raw)?;
    model.flat_only("patches")?;
    answer(&st, &headers, Output::Glb(model)).await
}

/// A tile as an X3D scene (the VRML use case): its ground quad, whose `ImageTexture` points at
/// the tile's image (border included) — for a material, a `PhysicalMaterial` with its maps' images
/// too — and a `Viewpoint` looking down at it.
#[utoipa::path(get, path = "/x3d/{id}/{z}/{x}/{y}.x3d", tag = "3d",
    params(("id" = String, Path, description = "texture or landscape id"), ("z" = u32, Path, description = "zoom"),
           ("x" = i64, Path, description = "column"), ("y" = i64, Path, description = "row")),
    responses((status = 200, description = "model/x3d+xml"), (status = 400, description = "bad coordinates or parameters"),
              (status = 404, description = "unknown texture")))]
pub async fn x3d_tile(
    State(st): State<Arc<AppState>>,
    path: Result<Path<(String, String, String, String)>, PathRejection>,
    RawQuery(raw): RawQuery,
    headers: HeaderMap,
    peer: Peer,
) -> Result<Response, ApiError> {
    let (model, _, _) = tile_request(&st, path, raw, &["x3d"])?;
    model.flat_only("X3D")?;
    answer(&st, &headers, Output::X3d { base: base_url(&st, &headers, peer), model }).await
}

/// An N×N patch of tiles (top-left tile `x, y`) as one X3D scene, one `Transform` per tile.
#[utoipa::path(get, path = "/x3d/{id}/patch.x3d", tag = "3d",
    params(("id" = String, Path, description = "texture or landscape id"), ("z" = u32, Query, description = "zoom"),
           ("x" = i64, Query, description = "left tile column"), ("y" = i64, Query, description = "top tile row"),
           ("tiles" = u32, Query, description = "patch side in tiles, 1..=8")),
    responses((status = 200, description = "model/x3d+xml"), (status = 400, description = "bad parameters"),
              (status = 404, description = "unknown texture")))]
pub async fn x3d_patch(
    State(st): State<Arc<AppState>>,
    path: Result<Path<String>, PathRejection>,
    RawQuery(raw): RawQuery,
    headers: HeaderMap,
    peer: Peer,
) -> Result<Response, ApiError> {
    let model = patch_request(&st, path, raw)?;
    model.flat_only("X3D")?;
    answer(&st, &headers, Output::X3d { base: base_url(&st, &headers, peer), model }).await
}
