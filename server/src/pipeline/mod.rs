//! From a validated request to bytes, one way for every front end: the HTTP routes, `textile
//! render` and (later) exports all describe what they want as an [`ImageJob`], whose cache key
//! and ETag say everything that determines its bytes, whose [`ImageJob::bytes`] renders it
//! (tiles and windows mapped onto a mode's view at the right zoom-out; `@2x` tiles one zoom-out
//! less at twice the size, or each texel as 2×2 pixels at native zoom) and encodes it, and whose
//! [`produce`] runs that through the tile cache (single flight) on the synthesis pool. A
//! landscape's image is a [`landscape::LandscapeJob`]: its layers' jobs, joined.

pub mod landscape;
pub mod subject;

use std::fmt::Write as _;
use std::sync::Arc;

use axum::body::Bytes;
use textile_core::maps::MapChoice;
use textile_core::modes::{Cost, Needs};
use textile_core::{Cancel, ModeParams, Pyramid, Rect, Rendered, RgbWindow, Source, View, TILE_SIZE};

use crate::encode::{encode, Effort, Format, ENCODER_VERSION, MAP_ENCODER_VERSION};
use crate::error::ApiError;
use crate::request::{TileSpec, WindowSpec};
use crate::state::AppState;
use crate::terrain::Dem;
use crate::textures::Texture;

/// Version of everything besides the analysis and the mode that determines bytes (each mode's
/// version is part of its parameters' canonical text).
pub fn engine_version() -> &'static str {
    static VERSION: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    VERSION.get_or_init(|| format!("textile/{}/enc{ENCODER_VERSION}", env!("CARGO_PKG_VERSION")))
}

/// The strong ETag (quoted) for a cache key.
pub fn etag_for(key: &str) -> String {
    format!("\"{}\"", &blake3::hash(key.as_bytes()).to_hex()[..32])
}

/// A cache key: everything that determines an answer's bytes — engine, texture, what the mode
/// renders from (the analysis file, or only the exemplar for modes that need nothing more, and
/// what of the mode's prepared state the exemplar does not determine, such as a hand-made set),
/// the mode's canonical parameters (name and version included) — then `what` it is.
pub fn cache_key(tex: &Texture, p: &ModeParams, what: std::fmt::Arguments) -> String {
    let source = match p.info().needs {
        Needs::Analysis => tex.file_hash().unwrap_or("analysing"),
        Needs::Exemplar | Needs::Prepared => &tex.exemplar_hash,
    };
    // Empty unless the state says otherwise, so that the keys of every other texture and mode
    // stay as they were.
    let prepared = tex.prepared.etag(p.name());
    let sep = if prepared.is_empty() { "" } else { "|" };
    let canonical = p.canonical();
    // Sized once: a key grown by formatting reallocated several times per request.
    let mut key = String::with_capacity(128 + canonical.len() + prepared.len());
    let id = &tex.config.id;
    let _ = write!(key, "{}|{id}|{source}|{prepared}{sep}{canonical}|{what}", engine_version());
    key
}

/// What part of the texture an image shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// A tile.
    Tile(TileSpec),
    /// A window.
    Window(WindowSpec),
}

/// An image to produce: texture, mode with parameters, target, and which map.
#[derive(Clone)]
pub struct ImageJob {
    /// The texture.
    pub tex: Arc<Texture>,
    /// The mode and its parameters.
    pub params: ModeParams,
    /// What part.
    pub target: Target,
    /// The colour, a material map or the coordinates.
    pub map: MapChoice,
    /// Heights as a raster-dem: `map` is then the height map, or the colour whose luma serves.
    pub dem: Option<Dem>,
}

impl ImageJob {
    /// The encoding.
    pub fn format(&self) -> Format {
        match self.target {
            Target::Tile(t) => t.format,
            Target::Window(w) => w.format,
        }
    }

    /// The cache key: a map's tiles are keyed by that map's hash (and the colour's keys stay
    /// as they were), so changing one map changes only its own tiles.
    pub fn key(&self) -> String {
        let f = self.format().ext();
        let map = match &self.map {
            MapChoice::Albedo => String::new(),
            MapChoice::Uv => format!("|map=uv:enc{MAP_ENCODER_VERSION}"),
            MapChoice::Map(n) => {
                let hash = self.tex.exemplar.map(n).map_or("missing", |m| m.hash.as_str());
                format!("|map={n}:{hash}:enc{MAP_ENCODER_VERSION}")
            }
        };
        // Empty unless a raster-dem is asked for, so that every other key stays as it was.
        let dem = self.dem.map(|d| d.key()).unwrap_or_default();
        match self.target {
            Target::Tile(t) => cache_key(
                &self.tex,
                &self.params,
                format_args!("tile|{}|{}|{}|{}|{f}{map}{dem}", t.z, t.x, t.y, t.scale),
            ),
            Target::Window(w) => cache_key(
                &self.tex,
                &self.params,
                format_args!("window|{}|{}|{}|{}|{}|{f}{map}{dem}", w.z, w.x, w.y, w.w, w.h),
            ),
        }
    }

    /// What the mode renders from: the texture, showing the job's map.
    fn source(&self) -> Result<Source<'_>, ApiError> {
        let src = self.tex.source();
        match &self.map {
            MapChoice::Map(n) => {
                let map = self.tex.exemplar.map(n).ok_or_else(|| {
                    ApiError::bad_request("invalid_map", format!("texture '{}' has no map '{n}'", self.tex.config.id))
                })?;
                Ok(src.with_map(map))
            }
            _ => Ok(src),
        }
    }

    /// The strong ETag.
    pub fn etag(&self) -> String {
        etag_for(&self.key())
    }

    /// The view rendered, and whether it is upscaled 2× (see [`view_of`]).
    fn view(&self) -> (View, bool) {
        view_of(self.target, self.tex.native_zoom())
    }

    /// Whether this is a big window (over [`PIECE`]² pixels): rendered in pieces, and admitted
    /// through the big-window lane so that big windows never take every worker from tiles.
    pub fn is_big(&self) -> bool {
        self.view().0.rect.area() > PIECE * PIECE
    }

    /// Working memory a window reserves from the budget (tiles reserve none: one per worker):
    /// a piece's synthesis (measured: about 3 MiB for a tile, 14 MiB for 1024²) and the
    /// image twice (pixels and encoded bytes). A 4096² window: about 110 MiB (measured 82).
    pub fn working_bytes(&self) -> u64 {
        match self.target {
            Target::Tile(_) => 0,
            Target::Window(_) => {
                let px = self.view().0.rect.area() as u64;
                (4 << 20) + 8 * px.min((PIECE * PIECE) as u64) + 6 * px
            }
        }
    }

    /// Render the image through a pyramidal cache. Views over [`PIECE`]² pixels are rendered
    /// as `PIECE × PIECE` pieces one after another and stitched (the same pixels: a window equals
    /// the same area cut from any other window), so the memory a request holds while rendering
    /// is bounded by a piece's, not the window's.
    pub fn render(&self, cache: &Pyramid) -> Result<Rendered, ApiError> {
        self.render_until(cache, &Cancel::default())
    }

    /// [`ImageJob::render`], abandoned between pieces once `cancel` is set.
    fn render_until(&self, cache: &Pyramid, cancel: &Cancel) -> Result<Rendered, ApiError> {
        let (view, upscale) = self.view();
        let src = self.source()?;
        let mut r = if view.rect.area() > PIECE * PIECE {
            render_pieces(&self.params, &src, cache, view, cancel)?
        } else {
            self.params.render(&src, cache, view)?
        };
        if upscale {
            r.image = upscale2(&r.image);
        }
        Ok(r)
    }

    /// Encode a rendered image: tightly for modes whose pixels are expensive, fast for cheap ones,
    /// fastest for material maps (a second map of a tile costs lookups and encoding only, so the
    /// encoding is its cost; grey maps as grey PNGs).
    pub fn encode(&self, img: &RgbWindow) -> Result<Vec<u8>, ApiError> {
        let effort = match (self.params.info().cost, &self.map) {
            (_, MapChoice::Map(_)) => Effort::Map,
            (Cost::Heavy, MapChoice::Albedo) => Effort::Tight,
            _ => Effort::Quick,
        };
        encode(&img.pixels, img.width, img.height, self.format(), effort)
            .map_err(|e| ApiError::internal(format!("encoding: {e}")))
    }

    /// Render and encode: the bytes every front end serves or writes, with the render's figures.
    pub fn bytes(&self, cache: &Pyramid) -> Result<(Vec<u8>, Rendered), ApiError> {
        self.bytes_until(cache, &Cancel::default())
    }

    /// [`ImageJob::bytes`], abandoned between the pieces of a big view once `cancel` is set.
    pub fn bytes_until(&self, cache: &Pyramid, cancel: &Cancel) -> Result<(Vec<u8>, Rendered), ApiError> {
        if self.map == MapChoice::Uv {
            return self.uv_bytes(cache);
        }
        let r = self.render_until(cache, cancel)?;
        if let Some(dem) = &self.dem {
            let (w, h) = (r.image.width, r.image.height);
            let bytes = match self.map {
                MapChoice::Map(_) => dem.png(&r.image.pixels, w, h)?,
                // A texture without a height map: its luma serves.
                _ => dem.png(&luma_grey(&r.image.pixels), w, h)?,
            };
            return Ok((bytes, r));
        }
        Ok((self.encode(&r.image)?, r))
    }

    /// `map=uv`: the coordinates as a 16-bit PNG (the figures count its pixels, none rendered).
    fn uv_bytes(&self, cache: &Pyramid) -> Result<(Vec<u8>, Rendered), ApiError> {
        let (view, upscale) = self.view();
        if view.rect.area() > PIECE * PIECE {
            return Err(ApiError::bad_request(
                "invalid_window",
                format!("map 'uv': windows of at most {PIECE}x{PIECE} pixels at a time"),
            ));
        }
        let mut uv = self.params.coordinates(&self.tex.source(), cache, view)?;
        if upscale {
            let w = uv.width as usize;
            uv.uv = uv
                .uv
                .chunks(w)
                .flat_map(|row| {
                    let doubled: Vec<[u16; 2]> = row.iter().flat_map(|&c| [c, c]).collect();
                    [doubled.clone(), doubled]
                })
                .flatten()
                .collect();
            (uv.width, uv.height) = (2 * uv.width, 2 * uv.height);
        }
        let bytes = crate::encode::png_uv(&uv).map_err(|e| ApiError::internal(format!("encoding: {e}")))?;
        let image = RgbWindow { width: uv.width, height: uv.height, pixels: Vec::new() };
        Ok((bytes, Rendered { image, synthesized: 0 }))
    }
}

/// The view a target shows of a texture whose native zoom is `native`, and whether it is
/// upscaled 2× (`@2x` at native zoom, pixel-doubled as it always was; `@2x` tiles at other
/// zooms are rendered one zoom finer).
pub fn view_of(target: Target, native: u32) -> (View, bool) {
    let native = native as i64;
    match target {
        Target::Window(w) => (View::at(native - w.z as i64, Rect::new(w.x, w.y, w.w, w.h)), false),
        Target::Tile(t) => {
            let k = native - t.z as i64;
            let (s, big) = (TILE_SIZE, 2 * TILE_SIZE);
            match (t.scale, k) {
                (1, _) => (View::at(k, Rect::new(s * t.x, s * t.y, s, s)), false),
                (_, 0) => (View::native(Rect::new(s * t.x, s * t.y, s, s)), true),
                _ => (View::at(k - 1, Rect::new(big * t.x, big * t.y, big, big)), false),
            }
        }
    }
}

/// Bytes for `key` from the tile cache, or from `make` on the synthesis pool (single flight;
/// counted under `label`). Returns whether it was a cache hit.
pub async fn cached<F>(st: &Arc<AppState>, key: &str, label: &'static str, make: F) -> (Result<Bytes, ApiError>, bool)
where
    F: FnOnce(&Cancel) -> Result<Vec<u8>, ApiError> + Send + 'static,
{
    st.cache.get_or_compute(key, || st.synthesize(label, make)).await
}

/// A job's bytes through the tile cache (keyed by `etag`, the job's [`ImageJob::etag`], which
/// callers have already computed for `If-None-Match`) and the pool, through the shared pyramidal
/// cache; the pixels it synthesized and delivered are counted when it actually runs.
pub async fn produce(st: &Arc<AppState>, etag: &str, job: ImageJob) -> (Result<Bytes, ApiError>, bool) {
    let mode = job.params.name();
    let big = job.is_big();
    let memory = job.working_bytes();
    let (synthesized, delivered) = (st.metrics.pixels_synthesized.clone(), st.metrics.pixels_delivered.clone());
    let pyramid = st.pyramid.clone();
    let make = move |cancel: &Cancel| {
        let (bytes, r) = job.bytes_until(&pyramid, cancel)?;
        synthesized.with_label_values(&[mode]).inc_by(r.synthesized);
        delivered.with_label_values(&[mode]).inc_by(r.image.width as u64 * r.image.height as u64);
        Ok(bytes)
    };
    // Inside the single flight: concurrent requests for one big window take one place in the
    // big-window lane and one reservation of memory, and wait for them without holding a worker.
    st.cache
        .get_or_compute(etag, || async {
            let _lane = if big { Some(st.big_window_lane().await?) } else { None };
            let _memory = if memory > 0 { Some(st.reserve(memory).await?) } else { None };
            st.synthesize(mode, make).await
        })
        .await
}

/// An image of a texture or of a landscape: what 3D models and exports are made of.
#[derive(Clone)]
pub enum Picture {
    /// A texture's image.
    Texture(ImageJob),
    /// A landscape's image.
    Landscape(landscape::LandscapeJob),
}

impl Picture {
    /// The cache key.
    pub fn key(&self) -> String {
        match self {
            Picture::Texture(j) => j.key(),
            Picture::Landscape(j) => j.key(),
        }
    }

    /// The strong ETag.
    pub fn etag(&self) -> String {
        etag_for(&self.key())
    }

    /// The encoding.
    pub fn format(&self) -> Format {
        match self {
            Picture::Texture(j) => j.format(),
            Picture::Landscape(j) => j.format(),
        }
    }

    /// Render and encode here and now (`textile render`, exports).
    pub fn bytes(&self, cache: &Pyramid, cancel: &Cancel) -> Result<Vec<u8>, ApiError> {
        match self {
            Picture::Texture(j) => Ok(j.bytes_until(cache, cancel)?.0),
            Picture::Landscape(j) => j.bytes(cache, cancel),
        }
    }
}

/// A picture's bytes through the tile cache and the pool, as [`produce`] makes a texture's
/// (`etag`: its [`Picture::etag`]).
pub async fn produce_picture(st: &Arc<AppState>, etag: &str, p: Picture) -> (Result<Bytes, ApiError>, bool) {
    match p {
        Picture::Texture(job) => produce(st, etag, job).await,
        Picture::Landscape(job) => {
            let pyramid = st.pyramid.clone();
            let (synthesized, delivered) = (st.metrics.pixels_synthesized.clone(), st.metrics.pixels_delivered.clone());
            // Its layers' syntheses are counted by their modes, as their own tiles' are.
            let count = move |mode: &'static str, s: u64, d: u64| {
                synthesized.with_label_values(&[mode]).inc_by(s);
                delivered.with_label_values(&[mode]).inc_by(d);
            };
            cached(st, etag, crate::metrics::LANDSCAPE_LABEL, move |cancel| job.bytes_counted(&pyramid, cancel, &count))
                .await
        }
    }
}

/// Side of the pieces big views are rendered in.
pub const PIECE: i64 = 1024;

/// Render `view` as pieces of at most `PIECE × PIECE` pixels, row by row, into one image.
fn render_pieces(
    params: &ModeParams,
    src: &Source,
    cache: &Pyramid,
    view: View,
    cancel: &Cancel,
) -> Result<Rendered, ApiError> {
    let (w, h) = (view.rect.width() as usize, view.rect.height() as usize);
    let mut pixels = vec![0u8; 3 * w * h];
    let mut synthesized = 0;
    for py in (0..h).step_by(PIECE as usize) {
        for px in (0..w).step_by(PIECE as usize) {
            if cancel.is_set() {
                return Err(textile_core::CoreError::Cancelled.into());
            }
            let (pw, ph) = ((w - px).min(PIECE as usize), (h - py).min(PIECE as usize));
            let rect = Rect::new(view.rect.x0 + px as i64, view.rect.y0 + py as i64, pw as i64, ph as i64);
            let r = params.render(src, cache, View { rect, ..view })?;
            synthesized += r.synthesized;
            for j in 0..ph {
                let dst = 3 * ((py + j) * w + px);
                pixels[dst..dst + 3 * pw].copy_from_slice(&r.image.pixels[3 * j * pw..3 * (j + 1) * pw]);
            }
        }
    }
    Ok(Rendered { image: RgbWindow { width: w as u32, height: h as u32, pixels }, synthesized })
}

/// RGB pixels as grey ones of their luma (Rec. 601), for heights where no height map is.
pub fn luma_grey(rgb: &[u8]) -> Vec<u8> {
    textile_core::landscape::blend::luma_heights(rgb).iter().flat_map(|h| [(h * 255.0).round() as u8; 3]).collect()
}

fn upscale2(img: &RgbWindow) -> RgbWindow {
    let (w, h) = (img.width as usize, img.height as usize);
    let mut px = Vec::with_capacity(12 * w * h);
    for j in 0..2 * h {
        for i in 0..w * 2 {
            let s = 3 * ((j / 2) * w + i / 2);
            px.extend_from_slice(&img.pixels[s..s + 3]);
        }
    }
    RgbWindow { width: 2 * img.width, height: 2 * img.height, pixels: px }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::TextureConfig;
    use crate::encode::Format;
    use textile_core::{Analysis, Exemplar, ExemplarOptions, NoProgress, ParamReader};

    #[test]
    fn only_modes_that_need_the_analysis_are_keyed_by_it() {
        let bytes = crate::textures::embedded("gravel.png").unwrap_or_default();
        let ex = Exemplar::from_bytes(bytes, &ExemplarOptions::default()).expect("embedded exemplar");
        let an = Analysis::build(&ex, &NoProgress);
        let tex = Texture::new(TextureConfig::new("gravel", "embedded:gravel.png"), 0, ex, an).expect("texture");
        let target = Target::Tile(TileSpec { z: 7, x: 1, y: -2, scale: 1, format: Format::Png });
        let key = |tex: &Arc<Texture>, mode: &str| {
            let params = tex.defaults.request(&tex.source(), ParamReader::request([("mode", mode)]).unwrap()).unwrap();
            ImageJob { tex: tex.clone(), params, target, map: MapChoice::Albedo, dem: None }.key()
        };
        let a = Arc::new(tex);
        // The same texture with another analysis file (e.g. a new analysis version).
        let other = std::sync::OnceLock::new();
        let _ = other.set((a.analysis().cloned().expect("analysed"), "another analysis".to_string()));
        let b = Arc::new(Texture {
            config: a.config.clone(),
            exemplar: a.exemplar.clone(),
            analysis: other,
            prepared: Default::default(),
            cache_limit: Default::default(),
            exemplar_hash: a.exemplar_hash.clone(),
            exemplar_png: Vec::new(),
            defaults: a.defaults.clone(),
            progress: Default::default(),
            failure: Default::default(),
            removed: Default::default(),
        });
        assert_ne!(key(&a, "synth"), key(&b, "synth"));
        assert_eq!(key(&a, "mosaic"), key(&b, "mosaic"));
        assert_eq!(key(&a, "tiling"), key(&b, "tiling"));
    }
}
