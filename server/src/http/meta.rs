//! Descriptive endpoints: health and readiness, the catalog, texture metadata and exemplar,
//! TileJSON 3.0.0 and the Prometheus metrics. Parameters are described from the modes' specs.

use std::sync::Arc;

use axum::extract::rejection::PathRejection;
use axum::extract::{Path, RawQuery, State};
use axum::http::{header, HeaderMap, HeaderValue, Uri};
use axum::response::{IntoResponse, Response};
use axum::Json;
use serde_json::{json, Map, Value};
use textile_core::error::clip;
use textile_core::modes::params::{Scope, COMMON, MODE, SEED, WORLD};
use textile_core::modes::{Cost, Needs};
use textile_core::{MODE_NAMES, TILE_SIZE};

use crate::encode::{Effort, Format};
use crate::error::{ApiError, Kind};
use crate::http::content::{if_none_match, image, not_modified};
use crate::http::extract::{base_url, path_error, texture, Peer};
use crate::pipeline::{engine_version, etag_for};
use crate::request::{params, query_pairs, MAX_CALLER_V};
use crate::state::AppState;
use crate::textures::Texture;

/// Liveness.
#[utoipa::path(get, path = "/health", tag = "service", responses((status = 200, description = "alive")))]
pub async fn health(State(st): State<Arc<AppState>>) -> Json<Value> {
    let (entries, bytes) = st.cache.usage();
    let pyr = st.pyramid.stats();
    Json(json!({
        "status": "ok",
        "version": env!("CARGO_PKG_VERSION"),
        "engine": engine_version(),
        "ready": st.loaded(),
        "textures": st.registry().map(|r| r.list.len()).unwrap_or(0),
        "tiles_synthesized": st.syntheses(),
        "shed": st.metrics.shed.get(),
        "cache": {
            "entries": entries, "bytes": bytes, "limit_bytes": st.config.cache_mib << 20,
            "hits": st.cache.stats.hits.get(),
            "misses": st.cache.stats.misses.get(),
            "evictions": st.cache.stats.evictions.get(),
        },
        "memory": {
            "budget_bytes": st.config.memory_budget_mib << 20,
            "reserved_bytes": st.reserved(),
            "prepared_caches_bytes": crate::state::prepared_share_mib(&st.config) << 20,
            "textures_bytes": st.registry().map_or(0, |r| r.list.iter().map(|t| t.held_bytes()).sum::<u64>()),
        },
        "level_cache": {
            "blocks": pyr.blocks, "bytes": pyr.bytes, "limit_bytes": st.config.level_cache_mib << 20,
            "hits": pyr.hits, "misses": pyr.misses, "evictions": pyr.evictions,
        },
    }))
}

/// Readiness: 200 once every configured texture is loaded and analysed (uploads load after, in
/// the background), 503 before (modes that need only the exemplar already serve while analyses
/// are computed).
#[utoipa::path(get, path = "/ready", tag = "service",
    responses((status = 200, description = "ready"), (status = 503, description = "still loading or analysing")))]
pub async fn ready(State(st): State<Arc<AppState>>) -> Result<Json<Value>, ApiError> {
    if !st.loaded() {
        return Err(ApiError::not_ready());
    }
    Ok(Json(json!({"status": "ready"})))
}

/// The textures served.
#[utoipa::path(get, path = "/catalog", tag = "textures", responses((status = 200, description = "catalog")))]
pub async fn catalog(State(st): State<Arc<AppState>>, headers: HeaderMap, peer: Peer) -> Result<Json<Value>, ApiError> {
    let reg = st.ready()?;
    let base = base_url(&st, &headers, peer);
    let textures: Vec<Value> = reg
        .list
        .iter()
        .map(|t| {
            json!({
                "id": t.config.id, "name": t.config.name, "modes": MODE_NAMES, "default_mode": t.defaults.mode,
                "status": t.status().as_str(), "uploaded": t.config.uploaded,
                "tilejson": format!("{base}/tiles/{}/tilejson.json", t.config.id),
                "exemplar": format!("{base}/textures/{}/exemplar.png", t.config.id),
            })
        })
        .collect();
    let landscapes: Vec<Value> = reg
        .landscapes
        .iter()
        .map(|l| {
            let id = &l.config.id;
            json!({
                "id": id, "name": l.config.name, "kind": "landscape", "status": l.status().0.as_str(),
                "layers": l.layers.iter().map(|y| y.tex.config.id.clone()).collect::<Vec<_>>(),
                "tilejson": format!("{base}/tiles/{id}/tilejson.json"),
                "description": format!("{base}/textures/{id}"),
            })
        })
        .collect();
    Ok(Json(json!({ "textures": textures, "landscapes": landscapes, "uploads": !st.config.admin_token.is_empty() })))
}

/// What each mode prepared for a texture, by mode: its description, with `what` it is and the
/// bytes it holds (caches included); `{"status": "preparing"}` until it is ready.
fn prepared(t: &crate::textures::Texture) -> Value {
    let mut out = serde_json::Map::new();
    let states = t.prepared.all();
    for (mode, step) in textile_core::modes::preparations() {
        let v = match states.iter().find(|(m, _)| *m == mode) {
            Some((_, state)) => {
                let mut d = state.describe();
                d.insert("status".into(), json!("ready"));
                d.insert("what".into(), json!(state.what()));
                d.insert("memory_bytes".into(), json!(state.memory_bytes()));
                Value::Object(d)
            }
            None => json!({ "status": "preparing", "what": step.what() }),
        };
        out.insert(mode.to_string(), v);
    }
    Value::Object(out)
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
    if let Some(l) = reg.landscape(&id) {
        return Ok(Json(crate::textures::landscape::describe(l)));
    }
    let t = texture(&reg, &id)?;
    let (ex, prep) = (&t.exemplar, &t.exemplar.preparation);
    let analysis = match (t.analysis(), t.file_hash()) {
        (Some(a), Some(hash)) => json!({
            "status": "ready", "id": a.header.id, "file_hash": hash, "algorithm_version": a.header.algorithm_version,
            "index": a.header.index,
        }),
        _ => match t.failure.get() {
            Some(why) => json!({ "status": "failed", "error": why }),
            None => json!({ "status": "analysing" }),
        },
    };
    Ok(Json(json!({
        "id": t.config.id,
        "name": t.config.name,
        "status": t.status().as_str(),
        "progress": t.progress.load(std::sync::atomic::Ordering::Relaxed),
        "uploaded": t.config.uploaded,
        "attribution": t.config.attribution,
        "exemplar": {
            "width": ex.width, "height": ex.height, "toroidal": ex.toroidal,
            "input_width": prep.input_width, "input_height": prep.input_height,
            "toroidal_forced": prep.toroidal_forced,
            "toroidal_synthesized": prep.toroidal_synthesized,
            "randomness_mask": ex.randomness_mask.is_some(),
            "lattice": ex.lattice.as_ref().map(|l| l.summary()),
        },
        "structure": ex.structure,
        "analysis": analysis,
        "maps": maps(&t),
        "prepared": prepared(&t),
        "modes": MODE_NAMES,
        "declined_modes": declined_modes(&t),
        "default_mode": t.defaults.mode,
        "mode_info": mode_info(),
        "native_zoom": t.native_zoom(),
        "minzoom": t.min_zoom(),
        "maxzoom": t.max_zoom(),
        "magnification": {
            "steps": t.max_zoom() - t.native_zoom(),
            "method": "patch extrapolation (synth), bilinear (other modes)",
            "detail": match &t.exemplar.hires {
                Some(_) => format!("exemplar_hires {}x{}", 2 * ex.width, 2 * ex.height),
                None => "exemplar".to_string(),
            },
        },
        "tile_size": TILE_SIZE,
        "levels": t.native_zoom() + 1,
        "settings": settings(&t),
        "parameters": parameters(&t),
    })))
}

/// The modes that do not serve this texture, each with its reason (requests of them answer
/// 422 `mode_declines_texture` with the same reason).
fn declined_modes(t: &Texture) -> Value {
    let src = t.source();
    let each = t.defaults.params.iter().filter_map(|p| Some((p.name().to_string(), json!(p.declines(&src)?))));
    Value::Object(each.collect())
}

/// Each mode's version, summary, needs and cost.
fn mode_info() -> Value {
    let each = textile_core::modes::all().into_iter().map(|m| {
        let needs = match m.needs {
            Needs::Exemplar => "exemplar",
            Needs::Analysis => "analysis",
            Needs::Prepared => "prepared",
        };
        let cost = match m.cost {
            Cost::Heavy => "heavy",
            Cost::Light => "light",
        };
        (m.name.to_string(), json!({ "version": m.version, "summary": m.summary, "needs": needs, "cost": cost }))
    });
    Value::Object(each.collect())
}

/// The request parameters of every mode, from their specs: type, range, help, the modes that
/// accept each, and this texture's default.
fn parameters(t: &Texture) -> Value {
    let src = t.source();
    let mut out = Map::new();
    for spec in COMMON {
        out.insert(spec.name.into(), spec.describe());
    }
    out[MODE.name]["default"] = json!(t.defaults.mode);
    let default_params = t.defaults.get(t.defaults.mode).map(|p| p.values(&src)).unwrap_or_default();
    out[SEED.name]["default"] = default_params.get("seed").cloned().unwrap_or(Value::Null);
    out[WORLD.name]["default"] = Value::Null;
    out[WORLD.name]["min"] = json!(((src.exemplar.size().longer() as i64 + TILE_SIZE - 1) / TILE_SIZE).max(1));
    for info in textile_core::modes::all() {
        let values = t.defaults.get(info.name).map(|p| p.values(&src)).unwrap_or_default();
        for spec in info.specs.iter().filter(|s| s.scope == Scope::Request) {
            let entry = out.entry(spec.name).or_insert_with(|| {
                let mut d = spec.describe();
                d["default"] = values.get(spec.name).cloned().unwrap_or(Value::Null);
                d["modes"] = json!([]);
                if spec.kind == textile_core::modes::params::Kind::Levels {
                    d["values"] = json!(src.levels() + 1);
                }
                d
            });
            if let Some(modes) = entry["modes"].as_array_mut() {
                modes.push(json!(info.name));
            }
        }
    }
    Value::Object(out)
}

/// This texture's settings of each mode (texture-scope parameters, set in the configuration).
fn settings(t: &Texture) -> Value {
    let src = t.source();
    let each = textile_core::modes::all().into_iter().filter_map(|info| {
        let values = t.defaults.get(info.name)?.values(&src);
        let s: Map<String, Value> = info
            .specs
            .iter()
            .filter(|s| s.scope == Scope::Texture)
            .map(|s| (s.name.to_string(), values.get(s.name).cloned().unwrap_or(Value::Null)))
            .collect();
        (!s.is_empty()).then(|| (info.name.to_string(), Value::Object(s)))
    });
    Value::Object(each.collect())
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
    if reg.landscape(&id).is_some() {
        return Err(ApiError::new(
            crate::error::Kind::NotFound,
            "no_exemplar",
            format!(
                "'{}' is a landscape: it has no exemplar (its layers' textures do: see /textures/{})",
                clip(&id),
                clip(&id)
            ),
        ));
    }
    let t = texture(&reg, &id)?;
    let mut r = t.exemplar_png.clone().into_response();
    r.headers_mut().insert(header::CONTENT_TYPE, HeaderValue::from_static("image/png"));
    r.headers_mut().insert(header::CACHE_CONTROL, HeaderValue::from_static("public, max-age=3600"));
    Ok(r)
}

/// A prepared material map of a texture, as `map=` tiles look it up (`albedo`: the exemplar;
/// normals in glTF's OpenGL convention, unit length): what a client of `map=uv` needs.
#[utoipa::path(get, path = "/textures/{id}/maps/{name}.png", tag = "textures",
    params(("id" = String, Path, description = "texture id"), ("name" = String, Path, description = "map name")),
    responses((status = 200, description = "PNG"), (status = 400, description = "no such map"),
              (status = 404, description = "unknown texture")))]
pub async fn map_image(
    State(st): State<Arc<AppState>>,
    path: Result<Path<(String, String)>, PathRejection>,
    headers: HeaderMap,
) -> Result<Response, ApiError> {
    let reg = st.ready()?;
    let Path((id, file)) = path.map_err(path_error)?;
    let t = texture(&reg, &id)?;
    let name = file.strip_suffix(".png").unwrap_or(&file);
    if name == "albedo" {
        let mut r = t.exemplar_png.clone().into_response();
        r.headers_mut().insert(header::CONTENT_TYPE, HeaderValue::from_static("image/png"));
        r.headers_mut().insert(header::CACHE_CONTROL, HeaderValue::from_static("public, max-age=3600"));
        return Ok(r);
    }
    let map = t.exemplar.map(name).ok_or_else(|| {
        let have: Vec<&str> =
            std::iter::once("albedo").chain(t.exemplar.maps.iter().map(|m| m.name.as_str())).collect();
        ApiError::bad_request(
            "invalid_map",
            format!("map '{}': texture '{id}' has no such map; it has: {}", clip(name), have.join(", ")),
        )
    })?;
    // Keyed by the map's own hash; encoded once (off the async workers) into the tile cache.
    let etag = etag_for(&format!("map-image|{}|{}", engine_version(), map.hash));
    let cc = &st.cache_control;
    if if_none_match(&headers, &etag) {
        return Ok(not_modified(&etag, cc));
    }
    let (texels, (w, h)) = (map.texels.clone(), (map.width, map.height));
    let (png, hit) = st
        .cache
        .get_or_compute(&etag, || async move {
            tokio::task::spawn_blocking(move || {
                crate::encode::encode(texels.as_flattened(), w, h, Format::Png, Effort::Tight)
                    .map(Into::into)
                    .map_err(|e| ApiError::internal(format!("encoding: {e}")))
            })
            .await
            .map_err(|_| ApiError::internal("encoding the map failed unexpectedly"))?
        })
        .await;
    Ok(image(png?, "image/png", &etag, cc, hit))
}

/// TileJSON 3.0.0 of a texture; query parameters are validated and carried into `tiles`, with
/// `world` = 2^native added when the query has none (one copy around the Web-Mercator world).
#[utoipa::path(get, path = "/tiles/{id}/tilejson.json", tag = "tiles",
    params(("id" = String, Path, description = "texture id")),
    responses((status = 200, description = "TileJSON"), (status = 404, description = "unknown texture")))]
pub async fn tilejson(
    State(st): State<Arc<AppState>>,
    path: Result<Path<String>, PathRejection>,
    RawQuery(raw): RawQuery,
    headers: HeaderMap,
    peer: Peer,
) -> Result<Json<Value>, ApiError> {
    let reg = st.ready()?;
    let Path(id) = path.map_err(path_error)?;
    let q = query_pairs(raw.as_deref());
    // A caller's `v` (e.g. busting its own cache of this document) is carried into the tiles'
    // version after the server's, which still changes with the analysis and engine.
    let caller_v = q.iter().find(|(k, _)| k == "v").map(|(_, v)| v.clone());
    if caller_v.as_ref().is_some_and(|v| v.len() > MAX_CALLER_V) {
        return Err(ApiError::bad_request(
            "invalid_parameter",
            format!("parameter 'v': at most {MAX_CALLER_V} characters"),
        ));
    }
    let base = base_url(&st, &headers, peer);
    if let Some(l) = reg.landscape(&id) {
        // Checked as its tiles' queries are (a layer not ready answers 503 as they do).
        let mut r = textile_core::ParamReader::request(q.clone())?;
        let map = crate::pipeline::landscape::LandscapeMap::read(l, &mut r, Format::Png)?;
        let encoding = map.1.map(|d| d.encoding.name());
        let target = crate::pipeline::Target::Tile(crate::request::TileSpec {
            z: l.native_zoom,
            x: 0,
            y: 0,
            scale: 1,
            format: Format::Png,
        });
        crate::pipeline::landscape::LandscapeJob::new(l.clone(), target, map, r)?;
        let layers: Vec<String> = l
            .layers
            .iter()
            .map(|y| format!("{}|{}", y.tex.file_hash().unwrap_or("analysing"), y.tex.defaults.canonical()))
            .collect();
        let version = blake3::hash(format!("{}|{}|{}", engine_version(), l.hash, layers.join("|")).as_bytes());
        // A world-wrapping client needs the splat to repeat; a painted one shown once cannot.
        let world = l.splat.check_period(TILE_SIZE << l.native_zoom).is_ok();
        let doc = Document {
            id: &id,
            name: &l.config.name,
            attribution: &l.config.attribution,
            version: &version.to_hex()[..12],
            zooms: l.zooms(),
            world,
            encoding,
        };
        let textile = json!({
            "landscape": id, "native_zoom": l.native_zoom,
            "layers": l.layers.iter().map(|y| y.tex.config.id.clone()).collect::<Vec<_>>(),
        });
        return Ok(Json(doc.tilejson(&base, q, caller_v, textile)));
    }
    let t = texture(&reg, &id)?;
    let mut r = textile_core::ParamReader::request(q.clone())?;
    let encoding = crate::request::map_and_dem(&t, &mut r, Format::Png)?.1.map(|d| d.encoding.name());
    params(&t, r)?;
    // Everything that decides a tile's bytes besides its own request: engine, analysis, and the
    // texture's configured defaults of every mode with the modes' versions (a changed default
    // seed or κ, or a new mode version, must not hit stale immutable copies).
    // While the analysis is computed the version lacks it, and changes once it is attached.
    let file_hash = t.file_hash().unwrap_or("analysing");
    let version =
        &blake3::hash(format!("{}|{file_hash}|{}", engine_version(), t.defaults.canonical()).as_bytes()).to_hex()[..12];
    let doc = Document {
        id: &id,
        name: &t.config.name,
        attribution: &t.config.attribution,
        version,
        zooms: t.zooms(),
        world: true,
        encoding,
    };
    let textile = json!({
        "texture": t.config.id, "native_zoom": t.native_zoom(), "exemplar_side": t.exemplar.size().longer(),
        "exemplar_width": t.exemplar.width, "exemplar_height": t.exemplar.height,
        "magnified_zooms": t.max_zoom() - t.native_zoom(),
    });
    Ok(Json(doc.tilejson(&base, q, caller_v, textile)))
}

/// What a TileJSON document says of a texture or a landscape.
struct Document<'a> {
    id: &'a str,
    name: &'a str,
    attribution: &'a str,
    /// The server's version of its tiles.
    version: &'a str,
    zooms: crate::textures::Zooms,
    /// Whether its tiles may repeat around the Web-Mercator world.
    world: bool,
    /// The raster-dem encoding of its tiles, when the query asks for one.
    encoding: Option<&'static str>,
}

impl Document<'_> {
    /// TileJSON 3.0.0, the query carried into `tiles`, with `textile`'s own facts.
    fn tilejson(&self, base: &str, mut q: Vec<(String, String)>, caller_v: Option<String>, textile: Value) -> Value {
        let mut qs = form_urlencoded::Serializer::new(String::new());
        match &caller_v {
            Some(cv) => qs.append_pair("v", &format!("{}-{cv}", self.version)),
            None => qs.append_pair("v", self.version),
        };
        // TileJSON's bounds are the wrapped Web-Mercator world, which world-wrapping clients
        // (MapLibre, OpenLayers) draw again past ±180°: unless the query names a period, the
        // tiles repeat exactly once around it (`world` = 2^native tiles), so the date line is
        // no seam.
        if self.world && !q.iter().any(|(k, _)| k == "world") {
            q.push(("world".to_string(), (1u64 << self.zooms.native).to_string()));
        }
        q.sort();
        for (k, v) in q.iter().filter(|(k, _)| k.as_str() != "v") {
            qs.append_pair(k, v);
        }
        let mut doc = json!({
            "tilejson": "3.0.0",
            "name": self.name,
            "description": format!("Infinite example-based texture '{}' synthesized by textile", self.id),
            "version": "1.0.0",
            "attribution": self.attribution,
            "scheme": "xyz",
            "tiles": [format!("{base}/tiles/{}/{{z}}/{{x}}/{{y}}.png?{}", self.id, qs.finish())],
            "minzoom": self.zooms.min,
            "maxzoom": self.zooms.max,
            "bounds": [-180.0, -85.051_128_779_806_59, 180.0, 85.051_128_779_806_59],
            "center": [0.0, 0.0, self.zooms.native],
            "tileSize": TILE_SIZE,
            "textile": textile,
        });
        // MapLibre's raster-dem source reads the encoding from the TileJSON it is given.
        if let Some(e) = self.encoding {
            doc["encoding"] = json!(e);
        }
        doc
    }
}

/// Prometheus metrics in the text exposition format.
#[utoipa::path(get, path = "/metrics", tag = "service", responses((status = 200, description = "Prometheus text format")))]
pub async fn metrics(State(st): State<Arc<AppState>>) -> Response {
    st.metrics.observe_pyramid(&st.pyramid.stats());
    if let Some(reg) = st.registry() {
        let held: u64 = reg.list.iter().map(|t| t.held_bytes()).sum();
        st.metrics.prepared_bytes.set(held as i64);
        let limits: u64 = reg.list.iter().map(|t| t.cache_limit.load(std::sync::atomic::Ordering::Relaxed)).sum();
        st.metrics.prepared_cache_limit_bytes.set(limits as i64);
    }
    let mut r = st.metrics.render().into_response();
    r.headers_mut().insert(header::CONTENT_TYPE, HeaderValue::from_static("text/plain; version=0.0.4; charset=utf-8"));
    r
}

/// 404 for unknown routes.
pub async fn not_found(uri: Uri) -> ApiError {
    ApiError::not_found_route(uri.path())
}

/// Every 405 as the contract's JSON error naming the methods the route takes: the router (or a
/// file service) answers a known route asked with another method with its `Allow` header, which
/// this turns into the message, keeping the header.
pub async fn method_not_allowed(req: axum::extract::Request, next: axum::middleware::Next) -> Response {
    // Kept for the message of a 405 only: the URI shares its bytes (no copy per request).
    let (method, uri) = (req.method().clone(), req.uri().clone());
    let resp = next.run(req).await;
    if resp.status() != axum::http::StatusCode::METHOD_NOT_ALLOWED {
        return resp;
    }
    let allow = resp.headers().get(header::ALLOW).cloned();
    let listed: Vec<&str> = allow
        .as_ref()
        .and_then(|v| v.to_str().ok())
        .map(|v| v.split(',').map(str::trim).filter(|m| !m.is_empty()).collect())
        .unwrap_or_default();
    let hint = match listed.as_slice() {
        [] => String::new(),
        [one] => format!("; use {one}"),
        [rest @ .., last] => format!("; use {} or {last}", rest.join(", ")),
    };
    let message = format!("{method} is not allowed on '{}'{hint}", textile_core::error::clip(uri.path()));
    let mut fixed = ApiError::new(Kind::MethodNotAllowed, "method_not_allowed", message).into_response();
    if let Some(v) = allow {
        fixed.headers_mut().insert(header::ALLOW, v);
    }
    fixed
}

/// What `map=` offers for a texture: the colour, each material map (normals in glTF's OpenGL
/// convention), and the coordinates with the modes that have them.
fn maps(t: &crate::textures::Texture) -> Value {
    use textile_core::maps::UV_SCALE;
    let modes = textile_core::modes::all();
    let with_maps: Vec<&str> = modes.iter().map(|m| m.name).collect();
    let with_uv: Vec<&str> = modes.iter().filter(|m| m.has_uv).map(|m| m.name).collect();
    let mut list = vec![json!({ "name": "albedo", "kind": "colour" })];
    for m in &t.exemplar.maps {
        let kind = if m.normal { "normal" } else { "scalar" };
        let mut e = json!({ "name": m.name, "kind": kind, "hash": m.hash, "modes": with_maps });
        if m.normal {
            e["convention"] = json!("opengl (+Y up, glTF), unit length");
        }
        list.push(e);
    }
    list.push(json!({
        "name": "uv", "kind": "coordinates", "modes": with_uv,
        "encoding": format!("16-bit PNG: R = u, G = v in 1/{UV_SCALE} exemplar texel (texel x = R / {UV_SCALE}), B = 0"),
    }));
    Value::Array(list)
}
