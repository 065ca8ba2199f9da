//! What a 3D model of tiles is made of: a tile (or an N×N patch of tiles) of a texture with a
//! mode's parameters or of a landscape ([`Subject`]), `relief`, and the query carried into its URLs — its ground quads, the
//! images they show (each tile with a border of the neighbouring texture, [`BORDER`] texels, a
//! window of the one texture), its glTF material's maps, and the parts of its cache keys.
//! [`crate::output::Output`] turns a [`Model`] into GLB, glTF and X3D bytes; `http/` only
//! parses requests into one.

use base64::Engine;
use std::collections::BTreeMap;
use textile_core::maps::MapChoice;
use textile_core::{ParamReader, TILE_SIZE};

use crate::encode::Format;
use crate::error::ApiError;
use crate::pipeline::landscape::{LandscapeJob, LandscapeMap};
pub use crate::pipeline::subject::Subject;
use crate::pipeline::{engine_version, Picture, Target};
use crate::request::{params, query_string, TileSpec, WindowSpec, COORD_MAX};
use crate::scene::assets::{image_side, metallic_roughness, Quad, Slot, BORDER, LAYOUT};
use crate::textures::{Served, Texture};

/// A request's parameters, sorted, as carried into tile URLs.
pub type Query = BTreeMap<String, String>;

/// Largest patch side in tiles.
pub const MAX_PATCH: i64 = 8;

/// The parameter of a .gltf document's sibling image naming the material slot it fills.
pub const SLOT: &str = "slot";

/// The `generator` of every 3D document.
pub fn generator() -> String {
    format!("textile {} ({})", env!("CARGO_PKG_VERSION"), engine_version())
}

/// A model of `tiles × tiles` tiles from `spec` (its top-left tile) of a texture or landscape.
#[derive(Clone)]
pub struct Model {
    /// What it shows.
    pub subject: Subject,
    /// The (top-left) tile.
    pub spec: TileSpec,
    /// Side in tiles: 1 for a tile, up to [`MAX_PATCH`] for a patch.
    pub tiles: i64,
    /// The request's parameters, carried into URLs.
    pub query: Query,
    /// `relief=SCALE`: a GLB's mesh displaced by the height map (a landscape's blended heights),
    /// white `SCALE` texels high.
    pub relief: Option<f32>,
    /// Above zoom 0 (3D Tiles' levels over the XYZ pyramid): the quad spans `2^span` zoom-0
    /// tiles a side from `spec`'s, and shows zoom 0's uniform colour. 0 for a tile.
    pub span: u32,
}

/// Side of the image of a tile above zoom 0: its colour is uniform (a zoom-0 pixel already
/// covers the whole exemplar), so a few texels show it exactly.
const LIFTED_IMAGE: i64 = 8;

impl Model {
    /// Tile `spec` of a texture or landscape (a patch of `tiles` from it) with the parameters
    /// `r` reads (its `relief` first), carrying `query` into URLs.
    pub fn read(served: Served, spec: TileSpec, tiles: i64, r: ParamReader, query: Query) -> Result<Model, ApiError> {
        if !(1..=MAX_PATCH).contains(&tiles) {
            return Err(ApiError::bad_request(
                "invalid_parameter",
                format!("parameter 'tiles': '{tiles}' is not an integer in 1..={MAX_PATCH}"),
            ));
        }
        if spec.x > COORD_MAX - (tiles - 1) || spec.y > COORD_MAX - (tiles - 1) {
            return Err(ApiError::bad_request(
                "invalid_coordinate",
                format!("the patch must end at or before {COORD_MAX}"),
            ));
        }
        let (subject, relief) = subject_with_relief(served, spec, r)?;
        Ok(Model { subject, spec, tiles, query, relief, span: 0 })
    }

    /// Tile `spec` with the request parameters of the query's `pairs`.
    pub fn request(served: Served, spec: TileSpec, pairs: Vec<(String, String)>) -> Result<Model, ApiError> {
        let r = ParamReader::request(pairs.clone())?;
        Model::read(served, spec, 1, r, pairs.into_iter().collect())
    }

    /// This zoom-0 tile's model spanning `2^span` zoom-0 tiles a side (3D Tiles' levels above
    /// zoom 0).
    pub fn lifted(self, span: u32) -> Model {
        Model { span, ..self }
    }

    /// Refuse `relief` where the answer has no mesh to displace.
    pub fn flat_only(&self, what: &str) -> Result<(), ApiError> {
        match self.relief {
            Some(_) => Err(ApiError::bad_request(
                "invalid_parameter",
                format!("parameter 'relief' applies to .glb tiles (and 3D Tiles content), not {what}"),
            )),
            None => Ok(()),
        }
    }

    /// The tiles, row by row.
    pub fn tile_specs(&self) -> impl Iterator<Item = TileSpec> + '_ {
        let (o, n) = (self.spec, self.tiles);
        (0..n).flat_map(move |j| (0..n).map(move |i| TileSpec { x: o.x + i, y: o.y + j, ..o }))
    }

    /// The ground quad of tile `t`.
    pub fn quad(&self, t: &TileSpec) -> Quad {
        // Native texels per tile side (a fraction of a tile when magnified).
        let size = TILE_SIZE as f64 * 2f64.powi(self.subject.zooms().native as i32 - t.z as i32);
        let origin = (size * t.x as f64, size * t.y as f64);
        if self.span > 0 {
            let name = format!("tiles_0_{}_{}_span_{}", t.x, t.y, self.span);
            return Quad { name, origin, size: size * 2f64.powi(self.span as i32) };
        }
        // `tile_z_x_y`: names clients keep as they are (three.js would fold "tile 7/1/11" and
        // "tile 7/11/1" into one).
        Quad { name: format!("tile_{}_{}_{}", t.z, t.x, t.y), origin, size }
    }

    /// The image of the (top-left) tile.
    pub fn image(&self) -> Picture {
        self.image_at(self.spec)
    }

    /// The image of the tile at `spec` with this model's texture and parameters (or landscape):
    /// the PNG window of the tile and [`BORDER`] texels around it, at the tile's zoom.
    pub fn image_at(&self, spec: TileSpec) -> Picture {
        self.picture_at(spec, None)
    }

    /// [`Model::image_at`] of the colour or of map `map`.
    fn picture_at(&self, spec: TileSpec, map: Option<&str>) -> Picture {
        let (b, side) = (BORDER as i64, image_side() as i64);
        let window = match self.span {
            0 => WindowSpec {
                z: spec.z,
                x: TILE_SIZE * spec.x - b,
                y: TILE_SIZE * spec.y - b,
                w: side,
                h: side,
                format: Format::Png,
            },
            _ => WindowSpec { z: 0, x: 0, y: 0, w: LIFTED_IMAGE, h: LIFTED_IMAGE, format: Format::Png },
        };
        self.subject.picture_of(Target::Window(window), map)
    }

    /// The tile's image of material map `name`.
    pub fn map_image(&self, name: &str) -> Picture {
        self.picture_at(self.spec, Some(name))
    }

    /// The material maps of this tile that go into its glTF material, `(slot, name)`: those of
    /// the texture (every layer of the landscape) with a glTF slot.
    pub fn material_maps(&self) -> Vec<(Slot, String)> {
        self.subject.maps().into_iter().filter_map(|n| Slot::of(&n).map(|s| (s, n))).collect()
    }

    /// The material maps that fill image `only` (all, without one): roughness and metallic
    /// fill the packed one.
    pub fn material_maps_of(&self, only: Option<Slot>) -> Vec<(Slot, String)> {
        self.material_maps().into_iter().filter(|(s, _)| only.is_none_or(|o| s.image() == o)).collect()
    }

    /// The material images of this tile's glTF material, one per slot (roughness and metallic
    /// maps share the packed one).
    pub fn material_slots(&self) -> Vec<Slot> {
        let mut slots: Vec<Slot> = Vec::new();
        for (s, _) in self.material_maps() {
            if !slots.contains(&s.image()) {
                slots.push(s.image());
            }
        }
        slots
    }

    /// What of the texture's maps the glTF material holds, for cache keys: empty without maps.
    pub fn material_key(&self) -> String {
        let each: Vec<String> = self
            .material_maps()
            .iter()
            .filter_map(|(_, n)| self.subject.map_hashes(n).map(|h| format!("{n}:{h}")))
            .collect();
        if each.is_empty() {
            String::new()
        } else {
            format!("maps{}={}", crate::encode::MAP_ENCODER_VERSION, each.join(","))
        }
    }

    /// `extra` for a cache key, with [`Model::material_key`] after it when there are maps (so
    /// that documents of textures without maps keep their keys).
    pub fn with_material(&self, extra: &str) -> String {
        match self.material_key() {
            m if m.is_empty() => extra.to_string(),
            m => format!("{extra}|{m}"),
        }
    }

    /// The cache key of this model's answer of `kind`, with `extra`.
    pub fn key(&self, kind: &str, extra: &str) -> String {
        let s = self.spec;
        let span = if self.span > 0 { format!("|span{}", self.span) } else { String::new() };
        self.subject.key(format_args!("{kind}{LAYOUT}|{}|{}|{}{span}|{extra}", s.z, s.x, s.y))
    }

    /// The tile URL (absolute) with the request's parameters.
    pub fn tile_url(&self, base: &str, t: &TileSpec) -> String {
        let qs = query_string(&self.query);
        let sep = if qs.is_empty() { "" } else { "?" };
        format!("{base}/tiles/{}/{}/{}/{}.png{sep}{qs}", self.subject.id(), t.z, t.x, t.y)
    }

    /// The relative URI of a tile's image served beside its .gltf document: `{y}.png`, or
    /// `{y}.{token}.png` with the parameters as a base64url token (glTF wants URIs without a
    /// query); a material image's (`slot`) has `slot=NAME` among them.
    pub fn sibling_image(&self, spec: &TileSpec, slot: Option<Slot>) -> String {
        let mut q = self.query.clone();
        if let Some(s) = slot {
            q.insert(SLOT.into(), s.name().into());
        }
        if q.is_empty() {
            return format!("{}.png", spec.y);
        }
        format!("{}.{}.png", spec.y, base64::engine::general_purpose::URL_SAFE_NO_PAD.encode(query_string(&q)))
    }

    /// The absolute URL of a tile's image (border included) for X3D documents, or of one of its
    /// material images (`slot`).
    pub fn image_url(&self, base: &str, spec: &TileSpec, slot: Option<Slot>) -> String {
        format!("{base}/gltf/{}/{}/{}/{}", self.subject.id(), spec.z, spec.x, self.sibling_image(spec, slot))
    }

    /// The absolute URLs of a tile's material images by slot, for X3D documents.
    pub fn material_urls(&self, base: &str, spec: &TileSpec) -> Vec<(Slot, String)> {
        self.material_slots().into_iter().map(|s| (s, self.image_url(base, spec, Some(s)))).collect()
    }
}

/// A 3D asset's query for tile `spec`: the mode's parameters (a landscape's `seed` and `world`)
/// and `relief`.
pub fn subject_with_relief(
    served: Served,
    spec: TileSpec,
    mut r: ParamReader,
) -> Result<(Subject, Option<f32>), ApiError> {
    let relief = r.take("relief");
    match served {
        Served::Texture(tex) => {
            let relief = relief.map(|v| relief_scale(Some(&tex), &v)).transpose()?;
            let params = params(&tex, r)?;
            Ok((Subject::Texture { tex, params, map: MapChoice::Albedo }, relief))
        }
        Served::Landscape(land) => {
            let relief = relief.map(|v| relief_scale(None, &v)).transpose()?;
            let job = LandscapeJob::new(land, Target::Tile(spec), (LandscapeMap::Albedo, None), r)?;
            Ok((Subject::Landscape(job), relief))
        }
    }
}

/// Read `relief=SCALE`: the height in texels of the height map's white, in (0, 256]; a
/// texture must have a height map (a landscape always has its blended heights).
fn relief_scale(tex: Option<&Texture>, v: &str) -> Result<f32, ApiError> {
    let bad = |m: String| ApiError::bad_request("invalid_parameter", format!("parameter 'relief': {m}"));
    let scale: f32 = v.parse().map_err(|_| bad(format!("'{}' is not a number", textile_core::error::clip(v))))?;
    if !(scale > 0.0 && scale <= 256.0) {
        return Err(bad(format!("{scale} is outside (0, 256] texels")));
    }
    if let Some(tex) = tex.filter(|t| t.exemplar.map("height").is_none()) {
        return Err(bad(format!("texture '{}' has no height map", tex.config.id)));
    }
    Ok(scale)
}

/// The material images of a glTF material from its maps' PNGs, by slot: roughness and
/// metallic packed into one `metallicRoughnessTexture`, the others as they are.
pub fn material_images(maps: Vec<(Slot, Vec<u8>)>) -> Result<Vec<(Slot, Vec<u8>)>, ApiError> {
    let mut out = Vec::new();
    let (mut roughness, mut metallic) = (None, None);
    for (slot, png) in maps {
        let grey = || image::load_from_memory(&png).map(|i| i.to_luma8());
        match slot {
            Slot::Roughness => roughness = Some(grey().map_err(|e| ApiError::internal(format!("roughness: {e}")))?),
            Slot::Metallic => metallic = Some(grey().map_err(|e| ApiError::internal(format!("metallic: {e}")))?),
            _ => out.push((slot, png)),
        }
    }
    if roughness.is_some() || metallic.is_some() {
        let packed = metallic_roughness(roughness.as_ref(), metallic.as_ref());
        let side = image_side();
        let png = crate::encode::encode(packed.as_raw(), side, side, Format::Png, crate::encode::Effort::Map)
            .map_err(|e| ApiError::internal(format!("encoding: {e}")))?;
        out.push((Slot::MetallicRoughness, png));
    }
    Ok(out)
}
