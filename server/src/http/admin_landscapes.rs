//! The admin API's landscapes: `POST /admin/landscapes` adds one from a multipart form — a
//! `config` part (JSON: the fields of a configured landscape) and, for a painted splat, a
//! `splat` part (the PNG) — checked as a configured one is, stored (`crate::uploads::landscapes`)
//! and served at once (`201 Created`, its description at `Location`); `DELETE
//! /admin/landscapes/{id}` removes a stored one. Both need the admin token, as the textures'
//! admin routes do; a texture a landscape uses cannot be deleted (`crate::http::admin`).

use std::sync::Arc;

use axum::extract::rejection::PathRejection;
use axum::extract::{FromRequest, Multipart, OriginalUri, Path, Request, State};
use axum::http::{header, HeaderMap, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::Json;
use textile_core::error::clip;
use textile_core::landscape::splat::{MAX_IMAGE_BYTES, MAX_IMAGE_SIDE};

use crate::config::{LandscapeConfig, SplatConfig};
use crate::error::{ApiError, Kind};
use crate::http::admin::{admit, too_large};
use crate::http::extract::{media_type, path_error};
use crate::state::AppState;
use crate::textures::landscape::describe;
use crate::textures::{Landscape, LoadError};
use crate::uploads::landscapes::{self as store, StoreError, MAX_CONFIG_BYTES};

/// Most landscapes the admin API may add.
pub const MAX_STORED_LANDSCAPES: usize = 64;

/// The value of `splat.image` in an uploaded configuration: its painted splat is the form's part.
const SPLAT_PART: &str = "splat";

fn invalid(field: &str, message: String) -> ApiError {
    ApiError::bad_request("invalid_landscape", format!("{field}: {message}"))
}

/// The form's `config` and `splat` parts, each within its limit.
async fn read_form(req: Request, limit: u64) -> Result<(Vec<u8>, Option<Vec<u8>>), ApiError> {
    if media_type(req.headers()) != "multipart/form-data" {
        return Err(ApiError::new(
            Kind::UnsupportedMediaType,
            "unsupported_media_type",
            "send multipart/form-data with a 'config' part (JSON) and, for a painted splat, a 'splat' part (PNG)",
        ));
    }
    let read_error = |e: String| crate::http::extract::body_error(&e, || too_large(limit));
    let mut form = Multipart::from_request(req, &()).await.map_err(|e| {
        ApiError::bad_request("invalid_body", format!("not a multipart form: {}", clip(&e.body_text())))
    })?;
    let (mut config, mut splat) = (None, None);
    while let Some(mut part) = form.next_field().await.map_err(|e| read_error(e.body_text()))? {
        let name = part.name().unwrap_or("").to_string();
        let max = match name.as_str() {
            "config" => MAX_CONFIG_BYTES,
            SPLAT_PART => MAX_IMAGE_BYTES,
            other => {
                return Err(invalid(
                    &format!("part '{}'", clip(other)),
                    "unknown; a landscape upload has the parts 'config' and 'splat'".into(),
                ))
            }
        };
        // Read in chunks, so that a part over its limit is refused before it is all in memory.
        let mut bytes = Vec::new();
        while let Some(chunk) = part.chunk().await.map_err(|e| read_error(e.body_text()))? {
            if bytes.len() + chunk.len() > max {
                return Err(invalid(&name, format!("over the {} KiB a part '{name}' may have", max >> 10)));
            }
            bytes.extend_from_slice(&chunk);
        }
        let slot = if name == "config" { &mut config } else { &mut splat };
        if slot.replace(bytes).is_some() {
            return Err(invalid(&name, "given twice".into()));
        }
    }
    let config = config.ok_or_else(|| invalid("config", "the form has no part named 'config'".into()))?;
    Ok((config, splat))
}

/// The splat part checked against the splat limits: a PNG of at most [`MAX_IMAGE_SIDE`]² pixels.
fn check_splat(bytes: &[u8]) -> Result<(), ApiError> {
    let fail = |m: String| invalid(SPLAT_PART, m);
    let reader = image::ImageReader::with_format(std::io::Cursor::new(bytes), image::ImageFormat::Png);
    if image::guess_format(bytes).ok() != Some(image::ImageFormat::Png) {
        return Err(fail("not a PNG file (a splat is a PNG)".into()));
    }
    let (w, h) = reader.into_dimensions().map_err(|e| fail(format!("undecodable PNG: {}", clip(&e.to_string()))))?;
    if w.max(h) > MAX_IMAGE_SIDE {
        return Err(fail(format!("{w}x{h} pixels is over the limit of {MAX_IMAGE_SIDE}x{MAX_IMAGE_SIDE}")));
    }
    Ok(())
}

/// The configuration of an upload, read and checked against the catalogue's textures.
fn read_config(bytes: &[u8], splat: Option<&[u8]>, textures: &[&str]) -> Result<LandscapeConfig, ApiError> {
    let l: LandscapeConfig =
        serde_json::from_slice(bytes).map_err(|e| invalid("config", format!("not a landscape's JSON: {e}")))?;
    match (&l.splat, splat) {
        (SplatConfig::Image { image, .. }, _) if image != SPLAT_PART => {
            return Err(invalid(
                "config.splat.image",
                format!(
                    "'{}': an uploaded landscape's painted splat is its form part; write \"{SPLAT_PART}\"",
                    clip(image)
                ),
            ))
        }
        (SplatConfig::Image { .. }, None) => {
            return Err(invalid(SPLAT_PART, "a painted splat (kind image) needs the part 'splat'".into()))
        }
        (SplatConfig::Noise { .. }, Some(_)) => {
            return Err(invalid(SPLAT_PART, "given, but the configuration's splat is noise".into()))
        }
        _ => {}
    }
    l.validate("config", textures).map_err(|(field, message)| invalid(&field, message))?;
    Ok(l)
}

fn exists(id: &str) -> ApiError {
    ApiError::new(
        Kind::Conflict,
        "landscape_exists",
        format!("a texture or landscape '{id}' exists; DELETE the landscape first to replace it"),
    )
}

/// Add a landscape of the served textures.
#[utoipa::path(post, path = "/admin/landscapes", tag = "admin",
    request_body(description = "multipart/form-data: a `config` part, JSON with the fields of a configured [[landscapes]] entry (id, name, layers, splat, blend, attribution, height_scale), at most 64 KiB; for a painted splat (`\"splat\": {\"kind\": \"image\", \"image\": \"splat\", …}`) a `splat` part, the PNG, at most 16 MiB and 4096×4096 pixels.",
        content(("multipart/form-data"))),
    responses((status = 201, description = "added and served: its description (Location: /textures/{id})"),
              (status = 400, description = "a bad configuration or splat: the message names the field and the limit"),
              (status = 401, description = "no or wrong bearer token"),
              (status = 404, description = "the admin API is off (no admin token configured)"),
              (status = 409, description = "the id is in use, or the limit of stored landscapes is reached"),
              (status = 413, description = "the body is over max_upload_mib"),
              (status = 415, description = "not a multipart form"),
              (status = 507, description = "the data directory could not store it"),
              (status = 503, description = "still loading")),
    security(("admin_token" = [])))]
pub async fn upload(
    State(st): State<Arc<AppState>>,
    OriginalUri(uri): OriginalUri,
    req: Request,
) -> Result<Response, ApiError> {
    admit(&st, req.headers(), &uri)?;
    let reg = st.ready()?;
    let limit = st.config.max_upload_mib << 20;
    let declared = req.headers().get(header::CONTENT_LENGTH).and_then(|v| v.to_str().ok()?.parse::<u64>().ok());
    if declared.is_some_and(|n| n > limit) {
        return Err(too_large(limit));
    }
    // The body, and the splat decoded to check it (4 bytes a pixel, at most 4096²).
    let _memory = st.reserve((80 << 20) + declared.unwrap_or(limit)).await?;
    let (config, splat) = read_form(req, limit).await?;
    if let Some(bytes) = &splat {
        check_splat(bytes)?;
    }
    let textures: Vec<&str> = reg.list.iter().map(|t| t.config.id.as_str()).collect();
    let mut l = read_config(&config, splat.as_deref(), &textures)?;
    l.uploaded = true;
    let id = l.id.clone();
    if reg.get(&id).is_some() || reg.landscape(&id).is_some() {
        return Err(exists(&id));
    }
    let built = {
        let (st, l, reg, splat) = (st.clone(), l.clone(), reg.clone(), splat.clone());
        tokio::task::spawn_blocking(move || Landscape::build(&st.config, &l, "config", &reg, splat.as_deref()))
            .await
            .map_err(|_| ApiError::internal("making the landscape failed unexpectedly"))?
    };
    let land = Arc::new(built.map_err(|e| match e {
        LoadError::Landscape { field, message, .. } => invalid(&field, message),
        other => invalid("config", other.to_string()),
    })?);
    {
        let _writer = st.catalogue_writer.lock().await;
        let reg = st.ready()?;
        if reg.get(&id).is_some() || reg.landscape(&id).is_some() {
            return Err(exists(&id));
        }
        // Its layers must still be served (a texture may have been deleted meanwhile).
        if let Some(y) = land.layers.iter().find(|y| reg.get(&y.tex.config.id).is_none()) {
            return Err(invalid("config.layers", format!("texture '{}' was deleted meanwhile", y.tex.config.id)));
        }
        if reg.stored_landscapes() >= MAX_STORED_LANDSCAPES {
            return Err(ApiError::new(
                Kind::Conflict,
                "too_many_landscapes",
                format!("{MAX_STORED_LANDSCAPES} landscapes are stored already, the limit"),
            ));
        }
        let dir = store::dir(&st.config);
        let stored = {
            let (dir, l) = (dir.clone(), l.clone());
            tokio::task::spawn_blocking(move || store::store(&dir, &l, splat.as_deref())).await
        };
        match stored {
            Ok(Ok(())) => {}
            Ok(Err(StoreError::Taken)) => return Err(exists(&id)),
            Ok(Err(e)) => {
                tracing::error!("landscape '{id}': not stored in {}: {e}", dir.display());
                return Err(ApiError::new(
                    Kind::InsufficientStorage,
                    "storage_failed",
                    "the landscape could not be stored in the data directory; see the server log",
                ));
            }
            Err(_) => return Err(ApiError::internal("storing the landscape failed unexpectedly")),
        }
        st.set_registry(Arc::new(reg.with_landscape(land.clone())));
    }
    tracing::info!("landscape '{id}': added ({} layers)", land.layers.len());
    let mut resp = (StatusCode::CREATED, Json(describe(&land))).into_response();
    if let Ok(v) = HeaderValue::from_str(&format!("/textures/{id}")) {
        resp.headers_mut().insert(header::LOCATION, v);
    }
    resp.headers_mut().insert(header::CACHE_CONTROL, HeaderValue::from_static("no-store"));
    Ok(resp)
}

/// Remove a landscape added through the admin API (and its stored files).
#[utoipa::path(delete, path = "/admin/landscapes/{id}", tag = "admin",
    params(("id" = String, Path, description = "landscape id")),
    responses((status = 204, description = "removed"),
              (status = 401, description = "no or wrong bearer token"),
              (status = 404, description = "no such landscape, or the admin API is off"),
              (status = 409, description = "a configured landscape (remove it from the configuration instead)"),
              (status = 500, description = "its record could not be removed: the landscape is kept"),
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
    let Some(land) = reg.landscape(&id) else {
        let known: Vec<&str> = reg.landscapes.iter().map(|l| l.config.id.as_str()).collect();
        return Err(ApiError::new(
            Kind::NotFound,
            "unknown_landscape",
            format!("no landscape '{}'; landscapes: {}", clip(&id), known.join(", ")),
        ));
    };
    if !land.config.uploaded {
        return Err(ApiError::new(
            Kind::Conflict,
            "configured_landscape",
            format!(
                "landscape '{id}' is configured, not added through the admin API: remove it from the configuration"
            ),
        ));
    }
    let (dir, rid) = (store::dir(&st.config), id.clone());
    let gone = tokio::task::spawn_blocking(move || store::remove(&dir, &rid))
        .await
        .map_err(|e| ApiError::internal(format!("removing landscape '{id}': {e}")))?;
    if let Err(e) = gone {
        tracing::warn!("landscape '{id}': not deleted, its record could not be removed: {e}");
        return Err(ApiError::new(
            Kind::Internal,
            "not_deleted",
            format!("landscape '{id}' is kept: its record could not be removed ({})", e.kind()),
        ));
    }
    st.set_registry(Arc::new(reg.without_landscape(&id)));
    tracing::info!("landscape '{id}': deleted");
    Ok(StatusCode::NO_CONTENT.into_response())
}
