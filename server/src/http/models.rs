//! 3D asset endpoints: a tile as glTF (`.glb` with its image embedded, `.gltf` referencing it),
//! an N×N patch of tiles as one GLB scene, and X3D scenes of a tile or a patch. Same parameters,
//! validation, ETags and caching as tiles. Each quad's image is its tile with a border of the
//! neighbouring texture ([`BORDER`] texels, a window of the one texture), produced through the
//! tile cache like any window.

use std::sync::Arc;

use axum::extract::rejection::PathRejection;
use axum::extract::{Path, RawQuery, State};
use axum::http::HeaderMap;
use axum::response::Response;
use base64::Engine;

use std::collections::BTreeMap;

use textile_core::maps::MapChoice;
use textile_core::{ModeParams, ParamReader, TILE_SIZE};

use crate::assets::{glb, gltf_json, image_side, metallic_roughness, x3d, Quad, Relief, Slot, BORDER, LAYOUT};
use crate::encode::Format;
use crate::error::ApiError;
use crate::http::content::{if_none_match, image, not_modified};
use crate::http::extract::{base_url, path_error, texture, Peer};
use crate::metrics::GLTF_LABEL;
use crate::pipeline::{cache_key, cached, engine_version, etag_for, produce, ImageJob, Target};
use crate::request::{params, parse_tile, query_pairs, query_string, TileSpec, WindowSpec, COORD_MAX};
use crate::state::AppState;
use crate::textures::Texture;

/// A request's parameters, sorted, as carried into tile URLs.
type Query = BTreeMap<String, String>;

/// Largest patch side in tiles.
pub const MAX_PATCH: i64 = 8;

/// The `generator` of every 3D document.
pub(super) fn generator() -> String {
    format!("textile {} ({})", env!("CARGO_PKG_VERSION"), engine_version())
}

fn quad(tex: &Texture, t: &TileSpec) -> Quad {
    // Native texels per tile side (a fraction of a tile when magnified).
    let size = TILE_SIZE as f64 * 2f64.powi(tex.native_zoom() as i32 - t.z as i32);
    // `tile_z_x_y`: names clients keep as they are (three.js would fold "tile 7/1/11" and
    // "tile 7/11/1" into one).
    Quad { name: format!("tile_{}_{}_{}", t.z, t.x, t.y), origin: (size * t.x as f64, size * t.y as f64), size }
}

/// The tile URL (absolute) with the request's parameters.
fn tile_url(base: &str, tex: &Texture, t: &TileSpec, q: &Query) -> String {
    let qs = query_string(q);
    let sep = if qs.is_empty() { "" } else { "?" };
    format!("{base}/tiles/{}/{}/{}/{}.png{sep}{qs}", tex.config.id, t.z, t.x, t.y)
}

/// The relative URI of a tile's image served beside its .gltf document: `{y}.png`, or
/// `{y}.{token}.png` with the parameters as a base64url token (glTF wants URIs without a query);
/// a material image's (`slot`) has `slot=NAME` among them.
fn sibling_image(r: &TileRequest, spec: &TileSpec, slot: Option<Slot>) -> String {
    let mut q = r.query.clone();
    if let Some(s) = slot {
        q.insert(SLOT.into(), s.name().into());
    }
    if q.is_empty() {
        return format!("{}.png", spec.y);
    }
    format!("{}.{}.png", spec.y, base64::engine::general_purpose::URL_SAFE_NO_PAD.encode(query_string(&q)))
}

/// The parameter of a .gltf document's sibling image naming the material slot it fills.
const SLOT: &str = "slot";

/// The absolute URL of a tile's image (border included) for X3D documents, or of one of its
/// material images (`slot`).
fn image_url(base: &str, r: &TileRequest, spec: &TileSpec, slot: Option<Slot>) -> String {
    format!("{base}/gltf/{}/{}/{}/{}", r.tex.config.id, spec.z, spec.x, sibling_image(r, spec, slot))
}

/// The absolute URLs of a tile's material images by slot, for X3D documents.
fn material_urls(base: &str, r: &TileRequest, spec: &TileSpec) -> Vec<(Slot, String)> {
    r.material_slots().into_iter().map(|s| (s, image_url(base, r, spec, Some(s)))).collect()
}

pub(super) fn split_ext<'a>(s: &'a str, allowed: &[&str]) -> Result<(&'a str, &'a str), ApiError> {
    match s.rsplit_once('.') {
        Some((stem, ext)) if allowed.contains(&ext) => Ok((stem, ext)),
        _ => Err(ApiError::bad_request("invalid_format", format!("'{s}' must end in .{}", allowed.join(" or .")))),
    }
}

/// A request for one tile's 3D asset: texture, tile, query and the mode's parameters.
pub(super) struct TileRequest {
    tex: Arc<Texture>,
    spec: TileSpec,
    query: Query,
    params: ModeParams,
    /// `relief=SCALE`: a GLB's mesh displaced by the height map, white `SCALE` texels high.
    relief: Option<f32>,
    /// `slot=NAME` of a .gltf document's sibling image: the material image it is.
    slot: Option<Slot>,
}

impl TileRequest {
    /// Tile `spec` of `tex` with the parameters of the query's `pairs`.
    pub(super) fn new(
        tex: Arc<Texture>,
        spec: TileSpec,
        pairs: Vec<(String, String)>,
    ) -> Result<TileRequest, ApiError> {
        let (params, relief) = params_with_relief(&tex, ParamReader::request(pairs.clone())?)?;
        Ok(TileRequest { tex, spec, query: pairs.into_iter().collect(), params, relief, slot: None })
    }

    /// A .gltf document's sibling image: [`TileRequest::new`] of the pairs but `slot=NAME`,
    /// which names the material image it is (the texture must have it).
    fn sibling(tex: Arc<Texture>, spec: TileSpec, mut pairs: Vec<(String, String)>) -> Result<TileRequest, ApiError> {
        let slot = match pairs.iter().position(|(k, _)| k == SLOT) {
            Some(i) => {
                let (_, v) = pairs.remove(i);
                let bad = || {
                    ApiError::bad_request(
                        "invalid_map",
                        format!("slot '{}' is not a material image of this texture", textile_core::error::clip(&v)),
                    )
                };
                Some(Slot::parse(&v).ok_or_else(bad)?)
            }
            None => None,
        };
        let mut r = TileRequest::new(tex, spec, pairs)?;
        if let Some(slot) = slot {
            if !r.material_maps().iter().any(|(s, _)| s.image() == slot) {
                return Err(ApiError::bad_request(
                    "invalid_map",
                    format!("slot '{}': the texture has no map for it", slot.name()),
                ));
            }
        }
        r.slot = slot;
        Ok(r)
    }

    /// Refuse `relief` where the answer has no mesh to displace.
    fn flat_only(&self, what: &str) -> Result<(), ApiError> {
        match self.relief {
            Some(_) => Err(ApiError::bad_request(
                "invalid_parameter",
                format!("parameter 'relief' applies to .glb tiles (and 3D Tiles content), not {what}"),
            )),
            None => Ok(()),
        }
    }

    /// The image of the tile this asset shows.
    fn image(&self) -> ImageJob {
        self.image_at(self.spec)
    }

    /// The image of the tile at `spec` with this request's texture and parameters: the PNG
    /// window of the tile and [`BORDER`] texels around it, at the tile's zoom.
    /// The material maps of this tile that go into its glTF material, `(slot, name)`: those of
    /// the texture with a glTF slot.
    fn material_maps(&self) -> Vec<(Slot, String)> {
        self.tex.exemplar.maps.iter().filter_map(|m| Slot::of(&m.name).map(|s| (s, m.name.clone()))).collect()
    }

    /// `extra` for a cache key, with [`TileRequest::material_key`] after it when there are maps
    /// (so that documents of textures without maps keep their keys).
    fn with_material(&self, extra: &str) -> String {
        match self.material_key() {
            m if m.is_empty() => extra.to_string(),
            m => format!("{extra}|{m}"),
        }
    }

    /// The material images of this tile's glTF material, one per slot (roughness and metallic
    /// maps share the packed one).
    fn material_slots(&self) -> Vec<Slot> {
        let mut slots: Vec<Slot> = Vec::new();
        for (s, _) in self.material_maps() {
            if !slots.contains(&s.image()) {
                slots.push(s.image());
            }
        }
        slots
    }

    /// What of the texture's maps the glTF material holds, for cache keys: empty without maps.
    fn material_key(&self) -> String {
        let maps = self.material_maps();
        let each: Vec<String> =
            maps.iter().filter_map(|(_, n)| self.tex.exemplar.map(n).map(|m| format!("{n}:{}", m.hash))).collect();
        if each.is_empty() {
            String::new()
        } else {
            format!("maps{}={}", crate::encode::MAP_ENCODER_VERSION, each.join(","))
        }
    }

    fn image_at(&self, spec: TileSpec) -> ImageJob {
        let (b, side) = (BORDER as i64, image_side() as i64);
        let window = WindowSpec {
            z: spec.z,
            x: TILE_SIZE * spec.x - b,
            y: TILE_SIZE * spec.y - b,
            w: side,
            h: side,
            format: Format::Png,
        };
        ImageJob {
            tex: self.tex.clone(),
            params: self.params.clone(),
            target: Target::Window(window),
            map: MapChoice::Albedo,
        }
    }
}

/// A 3D asset's query: the mode's parameters and `relief`.
pub(super) fn params_with_relief(tex: &Texture, mut r: ParamReader) -> Result<(ModeParams, Option<f32>), ApiError> {
    let relief = r.take("relief").map(|v| relief_scale(tex, &v)).transpose()?;
    Ok((params(tex, r)?, relief))
}

/// Read `relief=SCALE`: the height in texels of the height map's white, in (0, 256]; the
/// texture must have a height map.
fn relief_scale(tex: &Texture, v: &str) -> Result<f32, ApiError> {
    let bad = |m: String| ApiError::bad_request("invalid_parameter", format!("parameter 'relief': {m}"));
    let scale: f32 = v.parse().map_err(|_| bad(format!("'{}' is not a number", textile_core::error::clip(v))))?;
    if !(scale > 0.0 && scale <= 256.0) {
        return Err(bad(format!("{scale} is outside (0, 256] texels")));
    }
    if tex.exemplar.map("height").is_none() {
        return Err(bad(format!("texture '{}' has no height map", tex.config.id)));
    }
    Ok(scale)
}

/// The bytes of a tile's image, through the pipeline.
async fn tile_png(st: &Arc<AppState>, etag: &str, job: ImageJob) -> Result<Vec<u8>, ApiError> {
    Ok(produce(st, etag, job).await.0?.to_vec())
}

fn tile_request(
    st: &AppState,
    path: Result<Path<(String, String, String, String)>, PathRejection>,
    raw: Option<String>,
    exts: &[&str],
) -> Result<(TileRequest, String), ApiError> {
    let reg = st.ready()?;
    let Path((id, z, x, y)) = path.map_err(path_error)?;
    let tex = texture(&reg, &id)?;
    let (y, ext) = split_ext(&y, exts)?;
    // `{y}.{token}.png`: the parameters of an image beside a .gltf, base64url in the path.
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
    let spec = parse_tile(&tex, &z, &x, &format!("{y}.png"))?;
    let pairs = query_pairs(raw.as_deref());
    let r = if ext == "png" { TileRequest::sibling(tex, spec, pairs)? } else { TileRequest::new(tex, spec, pairs)? };
    Ok((r, ext.to_string()))
}

fn key(r: &TileRequest, kind: &str, extra: &str) -> String {
    cache_key(&r.tex, &r.params, format_args!("{kind}{LAYOUT}|{}|{}|{}|{extra}", r.spec.z, r.spec.x, r.spec.y))
}

/// A tile as a glTF 2.0 ground quad: `.glb` embeds the PNG tile, `.gltf` references the tile
/// endpoint (a URI relative to the document; the absolute URL is in `images[0].extras.tile_url`).
#[utoipa::path(get, path = "/gltf/{id}/{z}/{x}/{y}.{ext}", tag = "3d",
    params(("id" = String, Path, description = "texture id"), ("z" = u32, Path, description = "zoom"),
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
    let (r, ext) = tile_request(&st, path, raw, &["glb", "gltf", "png"])?;
    if ext != "glb" {
        r.flat_only(&format!(".{ext}"))?;
    }
    let cc = &st.config.cache_control;
    if ext == "png" {
        if let Some(slot) = r.slot {
            let etag = etag_for(&key(&r, "slot", &format!("{}|{}", slot.name(), r.material_key())));
            if if_none_match(&headers, &etag) {
                return Ok(not_modified(&etag, cc));
            }
            let png = material_images(&st, &r, Some(slot)).await?.pop().map(|(_, b)| b);
            let png = png.ok_or_else(|| ApiError::internal("a material image went missing"))?;
            return Ok(image(png.into(), "image/png", &etag, cc, false));
        }
        let job = r.image();
        let etag = job.etag();
        if if_none_match(&headers, &etag) {
            return Ok(not_modified(&etag, cc));
        }
        let hit = st.cache.peek(&etag);
        let found = hit.is_some();
        let bytes = match hit {
            Some(b) => b,
            None => tile_png(&st, &etag, job).await?.into(),
        };
        return Ok(image(bytes, "image/png", &etag, cc, found));
    }
    if ext == "gltf" {
        let base = base_url(&st, &headers, peer);
        let etag = etag_for(&key(&r, "gltf", &r.with_material(&base)));
        if if_none_match(&headers, &etag) {
            return Ok(not_modified(&etag, cc));
        }
        // glTF wants relative URIs without a query: the image is served beside this document as
        // `{y}.png` or `{y}.{token}.png` (the parameters, base64url) with the tile's bytes. The
        // tile endpoint's absolute URL is in the image's extras for clients that prefer it.
        let maps: Vec<(Slot, String)> =
            r.material_slots().into_iter().map(|s| (s, sibling_image(&r, &r.spec, Some(s)))).collect();
        let mut doc = gltf_json(&[quad(&r.tex, &r.spec)], &[sibling_image(&r, &r.spec, None)], &maps, &generator());
        doc["images"][0]["extras"] = serde_json::json!({ "tile_url": tile_url(&base, &r.tex, &r.spec, &r.query) });
        let body = serde_json::to_vec(&doc).map_err(|e| ApiError::internal(e.to_string()))?;
        return Ok(image(body.into(), "model/gltf+json", &etag, cc, false));
    }
    glb_tile(&st, &r, &headers).await
}

/// A tile's GLB answer (conditional requests, tile cache), for `/gltf` and 3D Tiles content.
pub(super) async fn glb_tile(st: &Arc<AppState>, r: &TileRequest, headers: &HeaderMap) -> Result<Response, ApiError> {
    let cc = &st.config.cache_control;
    let relief_key = r.relief.map(|v| format!("|relief={v}")).unwrap_or_default();
    let etag = etag_for(&key(r, "glb", &format!("{}{relief_key}", r.material_key())));
    if if_none_match(headers, &etag) {
        return Ok(not_modified(&etag, cc));
    }
    if let Some(b) = st.cache.peek(&etag) {
        return Ok(image(b, "model/gltf-binary", &etag, cc, true));
    }
    let job = r.image();
    let png = tile_png(st, &job.etag(), job).await?;
    let maps = material_images(st, r, None).await?;
    let relief = match r.relief {
        Some(scale) => {
            let job = ImageJob { map: MapChoice::Map("height".into()), ..r.image() };
            let png = tile_png(st, &job.etag(), job).await?;
            let img = image::load_from_memory(&png).map_err(|e| ApiError::internal(format!("height map: {e}")))?;
            Some(Relief::from_border_image(&img.to_luma8(), scale))
        }
        None => None,
    };
    let q = quad(&r.tex, &r.spec);
    let (bytes, hit) = cached(st, &etag, GLTF_LABEL, move |_| {
        Ok(glb(&[q], &[(png, "image/png")], &maps, relief.as_ref(), &generator()))
    })
    .await;
    Ok(image(bytes?, "model/gltf-binary", &etag, cc, hit))
}

/// The material images of a tile's glTF material, by slot (all, or `only` the one): its maps'
/// bordered windows (through the tile cache), roughness and metallic packed into one
/// `metallicRoughnessTexture`.
async fn material_images(
    st: &Arc<AppState>,
    r: &TileRequest,
    only: Option<Slot>,
) -> Result<Vec<(Slot, Vec<u8>)>, ApiError> {
    let mut maps = Vec::new();
    let (mut roughness, mut metallic) = (None, None);
    for (slot, name) in r.material_maps().into_iter().filter(|(s, _)| only.is_none_or(|o| s.image() == o)) {
        let job = ImageJob { map: MapChoice::Map(name), ..r.image() };
        let png = tile_png(st, &job.etag(), job).await?;
        let grey = || image::load_from_memory(&png).map(|i| i.to_luma8());
        match slot {
            Slot::Roughness => roughness = Some(grey().map_err(|e| ApiError::internal(format!("roughness: {e}")))?),
            Slot::Metallic => metallic = Some(grey().map_err(|e| ApiError::internal(format!("metallic: {e}")))?),
            _ => maps.push((slot, png)),
        }
    }
    if roughness.is_some() || metallic.is_some() {
        let packed = metallic_roughness(roughness.as_ref(), metallic.as_ref());
        let side = image_side();
        let png = crate::encode::encode(packed.as_raw(), side, side, Format::Png, crate::encode::Effort::Map)
            .map_err(|e| ApiError::internal(format!("encoding: {e}")))?;
        maps.push((Slot::MetallicRoughness, png));
    }
    Ok(maps)
}

/// A patch's request: the tile request of its top-left tile and its side in tiles, from the
/// query's `z`, `x`, `y` and `tiles`.
fn patch_request(
    st: &AppState,
    path: Result<Path<String>, PathRejection>,
    raw: Option<String>,
) -> Result<(TileRequest, i64), ApiError> {
    let reg = st.ready()?;
    let Path(id) = path.map_err(path_error)?;
    let tex = texture(&reg, &id)?;
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
    let origin = parse_tile(&tex, &z, &x, &format!("{y}.png"))?;
    if origin.x > COORD_MAX - (n - 1) || origin.y > COORD_MAX - (n - 1) {
        return Err(ApiError::bad_request(
            "invalid_coordinate",
            format!("the patch must end at or before {COORD_MAX}"),
        ));
    }
    let (params, relief) = params_with_relief(&tex, reader)?;
    let query = pairs.into_iter().filter(|(k, _)| !["z", "x", "y", "tiles"].contains(&k.as_str())).collect();
    Ok((TileRequest { tex, spec: origin, query, params, relief, slot: None }, n))
}

/// The tiles of an N×N patch, row by row.
fn patch_tiles(origin: TileSpec, n: i64) -> impl Iterator<Item = TileSpec> {
    (0..n).flat_map(move |j| (0..n).map(move |i| TileSpec { x: origin.x + i, y: origin.y + j, ..origin }))
}

/// An N×N patch of tiles (top-left tile `x, y`) as one GLB scene, one node per tile.
#[utoipa::path(get, path = "/gltf/{id}/patch.glb", tag = "3d",
    params(("id" = String, Path, description = "texture id"), ("z" = u32, Query, description = "zoom"),
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
    let (r, n) = patch_request(&st, path, raw)?;
    r.flat_only("patches")?;
    let etag = etag_for(&key(&r, "patch", &n.to_string()));
    let cc = &st.config.cache_control;
    if if_none_match(&headers, &etag) {
        return Ok(not_modified(&etag, cc));
    }
    if let Some(b) = st.cache.peek(&etag) {
        return Ok(image(b, "model/gltf-binary", &etag, cc, true));
    }
    // The tiles' images and the document are held together: reserve room for them.
    let _memory = st.reserve((4 << 20) + (n * n) as u64 * (320 << 10)).await?;
    let mut quads = Vec::new();
    let mut images = Vec::new();
    for spec in patch_tiles(r.spec, n) {
        let job = r.image_at(spec);
        images.push((tile_png(&st, &job.etag(), job).await?, "image/png"));
        quads.push(quad(&r.tex, &spec));
    }
    let (bytes, hit) = cached(&st, &etag, GLTF_LABEL, move |_| Ok(glb(&quads, &images, &[], None, &generator()))).await;
    Ok(image(bytes?, "model/gltf-binary", &etag, cc, hit))
}

/// An X3D answer with ETag `etag`: `304` when the client has it, else the document `doc` makes.
fn x3d_answer(st: &AppState, headers: &HeaderMap, etag: &str, doc: impl FnOnce() -> String) -> Response {
    let cc = &st.config.cache_control;
    if if_none_match(headers, etag) {
        return not_modified(etag, cc);
    }
    image(doc().into_bytes().into(), "model/x3d+xml", etag, cc, false)
}

/// A tile as an X3D scene (the VRML use case): its ground quad, whose `ImageTexture` points at
/// the tile's image (border included) — for a material, a `PhysicalMaterial` with its maps' images
/// too — and a `Viewpoint` looking down at it.
#[utoipa::path(get, path = "/x3d/{id}/{z}/{x}/{y}.x3d", tag = "3d",
    params(("id" = String, Path, description = "texture id"), ("z" = u32, Path, description = "zoom"),
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
    let (r, _) = tile_request(&st, path, raw, &["x3d"])?;
    r.flat_only("X3D")?;
    let base = base_url(&st, &headers, peer);
    let etag = etag_for(&key(&r, "x3d", &r.with_material(&base)));
    Ok(x3d_answer(&st, &headers, &etag, || {
        let maps = [material_urls(&base, &r, &r.spec)];
        x3d(&[quad(&r.tex, &r.spec)], &[image_url(&base, &r, &r.spec, None)], &maps, &generator())
    }))
}

/// An N×N patch of tiles (top-left tile `x, y`) as one X3D scene, one `Transform` per tile.
#[utoipa::path(get, path = "/x3d/{id}/patch.x3d", tag = "3d",
    params(("id" = String, Path, description = "texture id"), ("z" = u32, Query, description = "zoom"),
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
    let (r, n) = patch_request(&st, path, raw)?;
    r.flat_only("X3D")?;
    let base = base_url(&st, &headers, peer);
    let etag = etag_for(&key(&r, "x3d-patch", &r.with_material(&format!("{n}|{base}"))));
    Ok(x3d_answer(&st, &headers, &etag, || {
        let tiles: Vec<TileSpec> = patch_tiles(r.spec, n).collect();
        let quads: Vec<Quad> = tiles.iter().map(|t| quad(&r.tex, t)).collect();
        let urls: Vec<String> = tiles.iter().map(|t| image_url(&base, &r, t, None)).collect();
        let maps: Vec<Vec<(Slot, String)>> = tiles.iter().map(|t| material_urls(&base, &r, t)).collect();
        x3d(&quads, &urls, &maps, &generator())
    }))
}
