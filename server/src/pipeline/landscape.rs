//! A landscape's image: the layers a window needs, each rendered as that texture's own tile or
//! window (the same job, at the layer's zoom), weighed by the splat and the blend, and encoded.
//! Where one layer alone has weight over the window, the image is that layer's, pixel for
//! pixel; layers without weight are never rendered.

use std::sync::Arc;

use textile_core::hash::hash;
use textile_core::landscape::blend::{grey_heights, luma_heights, mix, Heights};
use textile_core::landscape::Weights;
use textile_core::maps::MapChoice;
use textile_core::modes::params::{SEED, WORLD};
use textile_core::{Cancel, ParamReader, Pyramid, View, TILE_SIZE};

use super::{engine_version, etag_for, view_of, ImageJob, Target, PIECE};
use crate::encode::{encode, Effort, Format};
use crate::error::ApiError;
use crate::request::{params, MAX_V};
use crate::terrain::Dem;
use crate::textures::Landscape;

/// Hash tag of the seeds layers derive from a request's `seed`.
const TAG_LAYER_SEED: u64 = 0x4C41_5945_5200_0001;

/// Which image of a landscape.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum LandscapeMap {
    /// The colour.
    Albedo,
    /// A map every layer has (`height` always).
    Map(String),
    /// The splat itself, each layer in its overlay colour.
    Splat,
}

impl LandscapeMap {
    /// Read `map=` of a landscape's request (default `albedo`): the colour, a map every layer
    /// has, or `splat` (PNG only); with `map=height`, a raster-dem's parameters too.
    pub fn read(
        land: &Landscape,
        r: &mut ParamReader,
        format: Format,
    ) -> Result<(LandscapeMap, Option<Dem>), ApiError> {
        let name = r.take("map");
        let dem = Dem::read(r, name.as_deref(), format, land.height_scale())?;
        let Some(name) = name else { return Ok((LandscapeMap::Albedo, None)) };
        let maps = land.maps();
        let map = match name.as_str() {
            "albedo" => LandscapeMap::Albedo,
            "splat" => LandscapeMap::Splat,
            n if maps.iter().any(|m| m == n) => LandscapeMap::Map(n.to_string()),
            n => {
                let have: Vec<&str> =
                    ["albedo"].into_iter().chain(maps.iter().map(String::as_str)).chain(["splat"]).collect();
                return Err(ApiError::bad_request(
                    "invalid_map",
                    format!(
                        "map '{}': landscape '{}' has no such map (a map must be every layer's); it has: {}",
                        textile_core::error::clip(n),
                        land.config.id,
                        have.join(", ")
                    ),
                ));
            }
        };
        if map == LandscapeMap::Splat && format != Format::Png {
            return Err(ApiError::bad_request(
                "invalid_map",
                "map 'splat' is served as PNG only (use .png)".to_string(),
            ));
        }
        Ok((map, dem))
    }
}

/// One image of a landscape to produce.
#[derive(Clone)]
pub struct LandscapeJob {
    /// The landscape.
    pub land: Arc<Landscape>,
    /// What part.
    pub target: Target,
    /// Which image.
    pub map: LandscapeMap,
    /// Each layer's job for the same place (its colour), with its parameters.
    pub layers: Vec<ImageJob>,
    /// The splat's seed.
    pub seed: u64,
    /// The period in texels (`world=`), if any.
    pub period: Option<i64>,
    /// Its heights as a raster-dem (with `map=height`).
    pub dem: Option<Dem>,
}

impl LandscapeJob {
    /// Read a request of a landscape: `v`, `seed`, `world` (the rest of a layer's parameters
    /// come from the configuration only). A layer that is not ready answers as its texture's
    /// tiles would (503 with `Retry-After`).
    pub fn new(
        land: Arc<Landscape>,
        target: Target,
        (map, dem): (LandscapeMap, Option<Dem>),
        mut r: ParamReader,
    ) -> Result<Self, ApiError> {
        if r.take("v").is_some_and(|v| v.len() > MAX_V) {
            return Err(ApiError::bad_request(
                "invalid_parameter",
                format!("parameter 'v': at most {MAX_V} characters"),
            ));
        }
        let seed = r.get(&SEED).map(|s| SEED.integer(&s)).transpose()?;
        let world = r.get(&WORLD).map(|s| WORLD.integer(&s)).transpose()?;
        if let Some(key) = (!r.is_empty()).then(|| r.finish("landscape", &[]).err()).flatten() {
            return Err(ApiError::bad_request(
                "invalid_parameter",
                format!("{key}; a landscape's layers take their parameters from its configuration"),
            ));
        }
        let id = &land.config.id;
        if let (Target::Window(w), LandscapeMap::Albedo | LandscapeMap::Map(_)) = (target, &map) {
            if w.w * w.h > PIECE * PIECE {
                return Err(ApiError::bad_request(
                    "invalid_window",
                    format!("landscape '{id}': windows of at most {PIECE}x{PIECE} pixels at a time"),
                ));
            }
        }
        let period = world.map(|w| w as i64 * TILE_SIZE);
        if let Some(p) = period {
            land.splat.check_period(p).map_err(|why| {
                ApiError::bad_request("invalid_parameter", format!("parameter 'world': landscape '{id}': {why}"))
            })?;
        }
        let mut layers = Vec::new();
        for (i, y) in land.layers.iter().enumerate() {
            let mut pairs = y.config.query();
            if let Some(s) = seed {
                pairs.retain(|(k, _)| k != "seed");
                pairs.push(("seed".into(), (hash(TAG_LAYER_SEED, s, i as i64, 0, 0) >> 1).to_string()));
            }
            if let Some(w) = world {
                let wi = w >> y.offset;
                if wi == 0 {
                    return Err(ApiError::bad_request(
                        "invalid_parameter",
                        format!(
                            "parameter 'world': landscape '{id}': layer '{}' is magnified {}x, so world >= {}",
                            y.tex.config.id,
                            1u64 << y.offset,
                            1u64 << y.offset
                        ),
                    ));
                }
                pairs.push(("world".into(), wi.to_string()));
            }
            let p = params(&y.tex, ParamReader::request(pairs)?)
                .map_err(|e| e.prefixed(&format!("layer '{}': ", y.tex.config.id)))?;
            layers.push(ImageJob {
                dem: None,
                tex: y.tex.clone(),
                params: p,
                target: layer_target(target, y.config.scale),
                map: MapChoice::Albedo,
            });
        }
        Ok(LandscapeJob { seed: seed.unwrap_or_else(|| land.splat_seed()), land, target, map, layers, period, dem })
    }

    /// The same landscape, seed and period, showing `map` of another place.
    pub fn at(&self, target: Target, map: LandscapeMap) -> LandscapeJob {
        let layers = self
            .layers
            .iter()
            .zip(&self.land.layers)
            .map(|(j, y)| ImageJob { target: layer_target(target, y.config.scale), ..j.clone() })
            .collect();
        LandscapeJob { target, map, layers, dem: None, ..self.clone() }
    }

    /// The encoding.
    pub fn format(&self) -> Format {
        match self.target {
            Target::Tile(t) => t.format,
            Target::Window(w) => w.format,
        }
    }

    /// The cache key: the landscape's hash, the splat's seed and period, every layer's own key
    /// (its analysis, parameters and place) and, for blends by height, its height map's.
    pub fn key(&self) -> String {
        let map = match &self.map {
            LandscapeMap::Albedo => "albedo".to_string(),
            LandscapeMap::Map(n) => format!("map={n}"),
            LandscapeMap::Splat => "splat".to_string(),
        };
        let map = format!("{map}{}", self.dem.map(|d| d.key()).unwrap_or_default());
        let target = match self.target {
            Target::Tile(t) => format!("tile|{}|{}|{}|{}", t.z, t.x, t.y, t.scale),
            Target::Window(w) => format!("window|{}|{}|{}|{}|{}", w.z, w.x, w.y, w.w, w.h),
        };
        let mut key = format!(
            "{}|landscape|{}|{}|{}|{:?}|{target}|{}|{map}",
            engine_version(),
            self.land.config.id,
            self.land.hash,
            self.seed,
            self.period,
            self.format().ext()
        );
        for job in &self.layers {
            key.push('|');
            key.push_str(&job.key());
            if let Some(m) = job.tex.exemplar.map("height") {
                key.push_str(&format!("|height:{}", m.hash));
            }
        }
        key
    }

    /// What determines its images wherever they are (the landscape's configuration and splat,
    /// the seed, period and map, every layer's analysis, parameters and height map), as a hash:
    /// an export's identity.
    pub fn identity(&self) -> String {
        let zero = Target::Tile(crate::request::TileSpec { z: 0, x: 0, y: 0, scale: 1, format: self.format() });
        blake3::hash(self.at(zero, self.map.clone()).key().as_bytes()).to_hex()[..32].to_string()
    }

    /// The strong ETag.
    pub fn etag(&self) -> String {
        etag_for(&self.key())
    }

    /// The landscape's pixels the image shows: its view, pixel-doubled views as their output.
    fn grid(&self) -> View {
        let (v, upscale) = view_of(self.target, self.land.native_zoom);
        if !upscale {
            return v;
        }
        let r = v.rect;
        View::at(
            v.zoom_out as i64 - v.zoom_in as i64 - 1,
            textile_core::Rect::new(2 * r.x0, 2 * r.y0, 2 * r.width(), 2 * r.height()),
        )
    }

    /// The splat's weights over the image.
    pub fn splat_weights(&self) -> Weights {
        self.land.splat.weights(self.grid(), self.seed, self.period)
    }

    /// Render and encode.
    pub fn bytes(&self, cache: &Pyramid, cancel: &Cancel) -> Result<Vec<u8>, ApiError> {
        self.bytes_counted(cache, cancel, &|_, _, _| {})
    }

    /// [`LandscapeJob::bytes`], telling `count` of each layer image it renders: the layer's
    /// mode, the pixels synthesized at all levels and the pixels delivered (what the server's
    /// metrics count for a texture's tile).
    pub fn bytes_counted(
        &self,
        cache: &Pyramid,
        cancel: &Cancel,
        count: &(dyn Fn(&'static str, u64, u64) + Sync),
    ) -> Result<Vec<u8>, ApiError> {
        let splat = self.splat_weights();
        if self.map == LandscapeMap::Splat {
            let colours: Vec<Vec<u8>> = self.land.layers.iter().map(|y| y.colour.repeat(splat.pixels())).collect();
            let images: Vec<Option<&[u8]>> = colours.iter().map(|c| Some(c.as_slice())).collect();
            let px = mix(&splat, &images);
            return encode(&px, splat.width as u32, splat.height as u32, Format::Png, Effort::Quick)
                .map_err(|e| ApiError::internal(format!("encoding: {e}")));
        }
        let used = splat.used();
        let n = used.iter().filter(|u| **u).count();
        let blend_heights = n > 1 && self.land.blend.needs_heights();
        let height_map = self.map == LandscapeMap::Map("height".into());
        let mut albedo: Vec<Option<Vec<u8>>> = vec![None; used.len()];
        let mut heights: Vec<Option<Heights>> = vec![None; used.len()];
        let mut grey: Vec<Option<Vec<u8>>> = vec![None; used.len()];
        let render = |job: &ImageJob| -> Result<Vec<u8>, ApiError> {
            if cancel.is_set() {
                return Err(textile_core::CoreError::Cancelled.into());
            }
            let r = job.render(cache)?;
            count(job.params.name(), r.synthesized, r.image.width as u64 * r.image.height as u64);
            Ok(r.image.pixels)
        };
        let map_job = |job: &ImageJob, name: &str| ImageJob { map: MapChoice::Map(name.into()), ..job.clone() };
        // Each layer's colour and height map rendered at most once: a layer without a height map
        // gives its luma, from its colour.
        for (i, job) in self.layers.iter().enumerate().filter(|(i, _)| used[*i]) {
            let has_height = job.tex.exemplar.map("height").is_some();
            if self.map == LandscapeMap::Albedo || (!has_height && (blend_heights || height_map)) {
                albedo[i] = Some(render(job)?);
            }
            let own = match has_height && (blend_heights || height_map) {
                true => Some(render(&map_job(job, "height"))?),
                false => None,
            };
            if blend_heights {
                heights[i] = match (&own, &albedo[i]) {
                    (Some(h), _) => Some(grey_heights(h)),
                    (None, a) => a.as_deref().map(luma_heights),
                };
            }
            if height_map {
                grey[i] = own.or_else(|| albedo[i].as_deref().map(super::luma_grey));
            }
        }
        let first = used.iter().position(|u| *u).unwrap_or(0);
        let weights = if n > 1 { self.land.blend.weights(&splat, &heights) } else { splat };
        let images: Vec<Option<Vec<u8>>> = match &self.map {
            LandscapeMap::Albedo => albedo,
            _ if height_map => grey,
            LandscapeMap::Map(name) => {
                // Any other map is every layer's (the request checked).
                let mut out = vec![None; used.len()];
                for (i, job) in self.layers.iter().enumerate().filter(|(i, _)| used[*i]) {
                    out[i] = Some(render(&map_job(job, name))?);
                }
                out
            }
            LandscapeMap::Splat => unreachable!("answered above"),
        };
        let mut px = match n {
            // One layer alone: its image as it is.
            1 => images.into_iter().nth(first).flatten().unwrap_or_default(),
            _ => mix(&weights, &images.iter().map(|i| i.as_deref()).collect::<Vec<_>>()),
        };
        if self.map == LandscapeMap::Map("normal".into()) {
            textile_core::maps::renormalise(&mut px);
        }
        if let Some(dem) = &self.dem {
            return dem.png(&px, weights.width as u32, weights.height as u32);
        }
        // Encoded as the first visible layer's own image is (a map, luma heights too, as a map),
        // so that a tile of one layer alone is that layer's tile, byte for byte.
        let enc = match &self.map {
            LandscapeMap::Map(n) => ImageJob { map: MapChoice::Map(n.clone()), ..self.layers[first].clone() },
            _ => self.layers[first].clone(),
        };
        let img = textile_core::RgbWindow { width: weights.width as u32, height: weights.height as u32, pixels: px };
        enc.encode(&img)
    }
}

/// A layer's target for a landscape's: the same place, `scale` zooms coarser.
fn layer_target(target: Target, scale: i32) -> Target {
    let z = |z: u32| (z as i64 - scale as i64).max(0) as u32;
    match target {
        Target::Tile(t) => Target::Tile(crate::request::TileSpec { z: z(t.z), ..t }),
        Target::Window(w) => Target::Window(crate::request::WindowSpec { z: z(w.z), ..w }),
    }
}
