//! The admin API: `POST /admin/textures` adds a texture from an uploaded exemplar (a PNG, JPEG
//! or WebP body with its fields in the query, or `multipart/form-data` with an `image` part and
//! field parts), answered `202 Accepted` with the texture's status at `Location` while it is
//! analysed in the background; `DELETE /admin/textures/{id}` removes an uploaded texture. Both
//! need `Authorization: Bearer TOKEN` (the configured `admin_token`); without a configured token
//! the routes do not exist (404). The catalogue is changed under one lock and replaced whole.
//! `POST /textures` and `DELETE /textures/{id}` (the names the API contract gives them) are the
//! same handlers (documented by copy in the OpenAPI document). Storage and field rules are [`crate::uploads`]'s.

use std::sync::Arc;

use axum::body::to_bytes;
use axum::extract::rejection::PathRejection;
use axum::extract::{FromRequest, Multipart, OriginalUri, Path, RawQuery, Request, State};
use axum::http::{header, HeaderMap, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::Json;
use textile_core::error::clip;
use textile_core::CoreError;

use crate::error::{ApiError, Kind};
use crate::http::extract::{media_type, path_error};
use crate::state::AppState;
use crate::textures::{prepare_texture, LoadError};
use crate::uploads;

/// The admin routes exist (a token is configured) and the request carries the token.
pub(crate) fn admit(st: &AppState, headers: &HeaderMap, uri: &axum::http::Uri) -> Result<(), ApiError> {
    if st.config.admin_token.is_empty() {
        return Err(ApiError::not_found_route(uri.path()));
    }
    let given = headers.get(header::AUTHORIZATION).map(|v| v.as_bytes());
    if !uploads::authorized(&st.config.admin_token, given) {
        let why = if given.is_some() { "the bearer token is wrong" } else { "an Authorization header is required" };
        return Err(ApiError::new(
            Kind::Unauthorized,
            "unauthorized",
            format!("{why}: send Authorization: Bearer <admin token>"),
        ));
    }
    Ok(())
}

/// The answer to an upload over its limit.
pub(crate) fn too_large(limit: u64) -> ApiError {
    ApiError::new(Kind::TooLarge, "body_too_large", format!("the upload is over {} MiB", limit >> 20))
}

/// What an upload sent: its fields, the exemplar's bytes and its maps' (by name).
struct Sent {
    fields: Vec<(String, String)>,
    image: axum::body::Bytes,
    maps: Vec<(String, Vec<u8>)>,
}

/// The upload's fields and image bytes, from a raw image body (fields in the query) or a
/// multipart form (fields as parts, the image as the part named `image`, material maps as
/// parts named `map.NAME`).
async fn read_upload(req: Request, query: Option<&str>, limit: u64) -> Result<Sent, ApiError> {
    let mut fields: Vec<(String, String)> =
        form_urlencoded::parse(query.unwrap_or("").as_bytes()).map(|(k, v)| (k.into_owned(), v.into_owned())).collect();
    let media = media_type(req.headers());
    let read_error = |e: String| crate::http::extract::body_error(&e, || too_large(limit));
    match media.as_str() {
        "image/png" | "image/jpeg" | "image/webp" | "application/octet-stream" => {
            let image = to_bytes(req.into_body(), limit as usize).await.map_err(|e| read_error(e.to_string()))?;
            Ok(Sent { fields, image, maps: Vec::new() })
        }
        "multipart/form-data" => {
            let mut form = Multipart::from_request(req, &()).await.map_err(|e| {
                ApiError::bad_request("invalid_body", format!("not a multipart form: {}", clip(&e.body_text())))
            })?;
            let mut image = None;
            let mut maps: Vec<(String, Vec<u8>)> = Vec::new();
            while let Some(part) = form.next_field().await.map_err(|e| read_error(e.body_text()))? {
                let name = part.name().unwrap_or("").to_string();
                let bytes = part.bytes().await.map_err(|e| read_error(e.body_text()))?;
                if name == "image" {
                    if image.replace(bytes).is_some() {
                        return Err(ApiError::bad_request("invalid_upload", "the part 'image' is given twice"));
                    }
                } else if let Some(map) = name.strip_prefix("map.") {
                    textile_core::maps::check_name(map)
                        .map_err(|e| ApiError::bad_request("invalid_map", e.to_string()))?;
                    if maps.iter().any(|(n, _)| n == map) || maps.len() >= uploads::MAX_MAPS {
                        return Err(ApiError::bad_request(
                            "invalid_upload",
                            format!("the map '{map}' is given twice, or more than {} maps are", uploads::MAX_MAPS),
                        ));
                    }
                    maps.push((map.to_string(), bytes.to_vec()));
                } else {
                    let value = String::from_utf8(bytes.to_vec()).map_err(|_| {
                        ApiError::bad_request("invalid_upload", format!("field '{}' is not UTF-8 text", clip(&name)))
                    })?;
                    fields.push((name, value));
                }
                if fields.len() > uploads::MAX_FIELDS {
                    return Err(ApiError::bad_request(
                        "invalid_upload",
                        format!("more than {} fields", uploads::MAX_FIELDS),
                    ));
                }
            }
            let image =
                image.ok_or_else(|| ApiError::bad_request("invalid_upload", "the form has no part named 'image'"))?;
            Ok(Sent { fields, image, maps })
        }
        other => Err(ApiError::new(
            Kind::UnsupportedMediaType,
            "unsupported_media_type",
            format!(
                "Content-Type '{}': send image/png, image/jpeg or image/webp (fields in the query), or \
                 multipart/form-data with an 'image' part",
                clip(other)
            ),
        )),
    }
}

/// A failure to prepare an uploaded exemplar, as an answer.
fn refused(e: LoadError) -> ApiError {
    match e {
        LoadError::Core { source: CoreError::ExemplarSize { width, height, min, .. }, .. }
            if width.min(height) < min =>
        {
            ApiError::new(Kind::Unprocessable, "image_too_small", e.to_string())
        }
        LoadError::Core { source: CoreError::ExemplarSize { .. }, .. } => {
            ApiError::new(Kind::TooLarge, "image_too_large", e.to_string())
        }
        LoadError::Core { source: CoreError::ExemplarUndecodable(_), .. } => {
            ApiError::bad_request("invalid_image", e.to_string())
        }
        LoadError::Core { source: CoreError::FlatExemplar { .. }, .. } => {
            ApiError::bad_request("flat_image", e.to_string())
        }
        LoadError::Core { source: CoreError::Map { .. }, .. } => ApiError::bad_request("invalid_map", e.to_string()),
        other => ApiError::bad_request("invalid_upload", other.to_string()),
    }
}

/// The status document of a texture, as `GET /textures/{id}` also gives it.
fn status_body(tex: &crate::textures::Texture) -> serde_json::Value {
    serde_json::json!({
        "id": tex.config.id,
        "status": tex.status().as_str(),
        "progress": tex.progress.load(std::sync::atomic::Ordering::Relaxed),
        "location": format!("/textures/{}", tex.config.id),
    })
}

/// Add a texture from an uploaded exemplar.
#[utoipa::path(post, path = "/admin/textures", tag = "admin",
    request_body(description = "The exemplar as image/png, image/jpeg or image/webp, with the fields (id, required; name, toroidal, index, lattice, default_mode, default_seed, attribution) in the query; or multipart/form-data with an `image` part and one part per field. Per-mode settings are fields named MODE.KEY (`synth.kappa=0.5`). Material maps are image parts named `map.NAME` (`map.normal`, `map.height`, …; the exemplar's size), a normal map with the field `normal_convention` (opengl or directx). At most max_upload_mib MiB; each side at most max_exemplar_side.",
        content(("image/png"), ("image/jpeg"), ("image/webp"), ("multipart/form-data"))),
    responses((status = 202, description = "accepted: decoded and stored; analysing (Location: the texture's status)"),
              (status = 400, description = "a field is invalid, the image is corrupt or of another format, or it is flat (code flat_image); a map is corrupt, mis-sized or misnamed (code invalid_map)"),
              (status = 401, description = "no or wrong bearer token"),
              (status = 404, description = "the admin API is off (no admin token configured)"),
              (status = 409, description = "the id is in use, or the upload limit is reached"),
              (status = 408, description = "the body stopped arriving"),
              (status = 413, description = "the body or the image's dimensions are over the limits"),
              (status = 415, description = "neither an image nor a multipart form"),
              (status = 507, description = "the data directory could not store the upload (the path is in the server log)"),
              (status = 503, description = "still loading")),
    security(("admin_token" = [])))]
pub async fn upload(
    State(st): State<Arc<AppState>>,
    OriginalUri(uri): OriginalUri,
    RawQuery(query): RawQuery,
    req: Request,
) -> Result<Response, ApiError> {
    admit(&st, req.headers(), &uri)?;
    let reg = st.ready()?;
    let limit = st.config.max_upload_mib << 20;
    let declared = req.headers().get(header::CONTENT_LENGTH).and_then(|v| v.to_str().ok()?.parse::<u64>().ok());
    if declared.is_some_and(|n| n > limit) {
        return Err(too_large(limit));
    }
    // The body and its decoding (the decoder's own allocations are capped by the image limits).
    let _memory = st.reserve((16 << 20) + 2 * declared.unwrap_or(limit)).await?;
    let Sent { fields, image, maps } = read_upload(req, query.as_deref(), limit).await?;
    let mut kinds = Vec::with_capacity(maps.len());
    for (name, bytes) in &maps {
        let Some(ext) = uploads::image_extension(bytes) else {
            return Err(ApiError::bad_request(
                "invalid_map",
                format!("map '{name}': the image is not a PNG, JPEG or WebP file"),
            ));
        };
        kinds.push((name.clone(), ext));
    }
    let config = uploads::texture_config(&fields, &kinds)?;
    let id = config.id.clone();
    let exists = |id: &str| {
        ApiError::new(
            Kind::Conflict,
            "texture_exists",
            format!("a texture '{id}' exists; DELETE it first to replace it"),
        )
    };
    if reg.get(&id).is_some() {
        return Err(exists(&id));
    }
    let Some(ext) = uploads::image_extension(&image) else {
        return Err(ApiError::bad_request("invalid_image", "the image is not a PNG, JPEG or WebP file"));
    };
    // Decode and prepare off the async workers (an 8-megapixel JPEG takes a while).
    let maps = Arc::new(maps);
    let prepared = {
        let (st, config, image, maps) = (st.clone(), config.clone(), image.clone(), maps.clone());
        tokio::task::spawn_blocking(move || {
            let log = |s: String| tracing::info!("{s}");
            prepare_texture(&st.config, &config, 0, &image, &maps, &log)
        })
        .await
        .map_err(|_| ApiError::internal("preparing the exemplar failed unexpectedly"))?
        .map_err(refused)?
    };
    let tex = Arc::new(prepared);
    {
        let _writer = st.catalogue_writer.lock().await;
        let reg = st.ready()?;
        if reg.get(&id).is_some() {
            return Err(exists(&id));
        }
        if reg.uploads() >= st.config.max_uploaded_textures {
            return Err(ApiError::new(
                Kind::Conflict,
                "too_many_uploads",
                format!("{} textures are uploaded already, the limit (max_uploaded_textures)", reg.uploads()),
            ));
        }
        let dir = uploads::dir(&st.config);
        let stored = {
            let (config, dir) = (config.clone(), dir.clone());
            // Each map in the file its configuration names.
            let files: Vec<(String, Vec<u8>)> = maps
                .iter()
                .zip(&kinds)
                .map(|((name, bytes), (_, ext))| (uploads::map_file(&id, name, ext), bytes.clone()))
                .collect();
            tokio::task::spawn_blocking(move || uploads::store(&dir, &config, &image, ext, &files)).await
        };
        match stored {
            Ok(Ok(())) => {}
            Ok(Err(uploads::StoreError::Taken)) => {
                return Err(ApiError::new(
                    Kind::Conflict,
                    "texture_exists",
                    format!(
                        "the data directory already holds files of an upload '{id}' that this server does not \
                         serve (put there while it ran); restart it to serve them, or remove them to replace it"
                    ),
                ))
            }
            Ok(Err(uploads::StoreError::NotOwned(e))) => {
                tracing::error!("texture '{id}': the upload is not stored: {e}");
                return Err(ApiError::new(
                    Kind::InsufficientStorage,
                    "storage_failed",
                    "the upload could not be stored: the data directory was removed or taken over while the server \
                     ran; see the server log",
                ));
            }
            // The path stays in the log: an answer names no part of the server's layout.
            Ok(Err(uploads::StoreError::Io(e))) => {
                tracing::error!("texture '{id}': the upload could not be stored in {}: {e}", dir.display());
                return Err(ApiError::new(
                    Kind::InsufficientStorage,
                    "storage_failed",
                    format!("the upload could not be stored in the data directory ({}); see the server log", e.kind()),
                ));
            }
            Err(_) => return Err(ApiError::internal("storing the upload failed unexpectedly")),
        }
        st.set_registry(Arc::new(reg.with(tex.clone())));
    }
    tracing::info!("texture '{id}': uploaded ({}x{}); analysing", tex.exemplar.width, tex.exemplar.height);
    uploads::analyse_in_background(st.clone(), tex.clone());
    let mut resp = (StatusCode::ACCEPTED, Json(status_body(&tex))).into_response();
    if let Ok(v) = HeaderValue::from_str(&format!("/textures/{id}")) {
        resp.headers_mut().insert(header::LOCATION, v);
    }
    resp.headers_mut().insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    Ok(resp)
}

/// Remove an uploaded texture (and its stored files).
#[utoipa::path(delete, path = "/admin/textures/{id}", tag = "admin",
    params(("id" = String, Path, description = "texture id")),
    responses((status = 204, description = "removed"),
              (status = 401, description = "no or wrong bearer token"),
              (status = 404, description = "no such texture, or the admin API is off"),
              (status = 409, description = "a configured texture (remove it from the configuration instead), or a layer of a landscape (named)"),
              (status = 500, description = "its record could not be removed: the texture is kept"),
              (status = 503, description = "still loading")),
    security(("admin_token" = [])))]
pub async fn delete(
    State(st): State<Arc<AppState>>,
    OriginalUri(uri): OriginalUri,
    headers: HeaderMap,
    path: Result<Path<String>, PathRejection>,
) -> Result<Response, ApiError> {
    admit(&st, &headers, &uri)?;
    let Path(id) = path.map_err(path_error)?;
    let _writer = st.catalogue_writer.lock().await;
    let reg = st.ready()?;
    let tex = crate::http::extract::texture(&reg, &id)?;
    if !tex.config.uploaded {
        return Err(ApiError::new(
            Kind::Conflict,
            "configured_texture",
            format!("texture '{id}' is configured, not uploaded: remove it from the configuration"),
        ));
    }
    // A layer of a landscape stays while the landscape does.
    let users = reg.landscapes_using(&id);
    if !users.is_empty() {
        return Err(ApiError::new(
            Kind::Conflict,
            "texture_in_use",
            format!("texture '{id}' is a layer of landscape '{}': delete the landscape first", users.join("', '")),
        ));
    }
    // Its record first: if that cannot go, nothing has changed and the answer says so (a
    // texture answered as deleted must not come back at the next start).
    let (dir, data_dir) = (uploads::dir(&st.config), st.config.data_dir());
    let record = dir.clone();
    let rid = id.clone();
    let gone = tokio::task::spawn_blocking(move || uploads::remove_record(&record, &rid))
        .await
        .map_err(|e| ApiError::internal(format!("removing texture '{id}': {e}")))?;
    if let Err(e) = gone {
        tracing::warn!("texture '{id}': not deleted, its record could not be removed: {e}");
        return Err(ApiError::new(
            Kind::Internal,
            "not_deleted",
            format!("texture '{id}' is kept: its record could not be removed from the uploads directory ({e})"),
        ));
    }
    tex.removed.set();
    st.set_registry(Arc::new(reg.without(&id)));
    let _ = tokio::task::spawn_blocking(move || uploads::remove_files(&dir, &data_dir, &id)).await;
    tracing::info!("texture '{}': deleted", tex.config.id);
    Ok(StatusCode::NO_CONTENT.into_response())
}
