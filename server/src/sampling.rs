//! Per-sample requests (`POST /samples/{id}`), without HTTP: bodies — JSON, or little-endian
//! binary records — parsed and checked against the limits into typed samples, run on the
//! synthesis pool through the pyramidal cache (textile-core's [`textile_core::samples`]), and
//! the colours packed for the answer. A landscape's samples are read from its tiles (each made
//! through the tile cache as it is served) and filtered the same way.
//!
//! Binary records are 20 bytes each: `texels` (the default) are `i64 x, i64 y, u32 z` — a pixel
//! of the tile grid at zoom `z`; `footprints` are `f64 u, f64 v, f32 lod` — a position in native
//! texels and a level of detail, filtered trilinearly. The answer is 3 bytes (RGB) per sample.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use serde::Deserialize;
use textile_core::maps::MapChoice;
use textile_core::samples::{self, Footprint, Texel};
use textile_core::{ModeParams, Pyramid, TILE_SIZE};

use crate::error::{ApiError, Kind};
use crate::pipeline::landscape::LandscapeJob;
use crate::pipeline::{produce_picture, Target};
use crate::request::TileSpec;
use crate::request::{COORD_MAX, COORD_MIN};
use crate::state::AppState;
use crate::textures::{Texture, Zooms};

/// Most samples in one request.
pub const MAX_SAMPLES: usize = 262_144;
/// Largest request body, bytes.
pub const MAX_BODY: usize = 8 << 20;
/// Bytes of one binary record.
pub const RECORD: usize = 20;
/// Pyramidal cache of one batch when the server's is off, so that the batch still computes the
/// union of its samples' cones once.
pub const BATCH_CACHE: u64 = 64 << 20;

/// Smallest pixel coordinate at any zoom: the tile range times the tile size.
const PIXEL_MIN: i64 = COORD_MIN * TILE_SIZE;
/// Largest pixel coordinate at any zoom.
const PIXEL_MAX: i64 = (COORD_MAX + 1) * TILE_SIZE - 1;

/// Which binary records a body holds (`records=` in the query).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Records {
    /// `i64 x, i64 y, u32 z`.
    Texels,
    /// `f64 u, f64 v, f32 lod`.
    Footprints,
}

impl Records {
    /// Parse the `records` query value.
    pub fn parse(s: &str) -> Result<Records, ApiError> {
        match s {
            "texels" => Ok(Records::Texels),
            "footprints" => Ok(Records::Footprints),
            _ => Err(ApiError::bad_request(
                "invalid_parameter",
                format!("parameter 'records' = '{}': use texels or footprints", textile_core::error::clip(s)),
            )),
        }
    }
}

/// The samples of a request.
#[derive(Debug, Clone, PartialEq)]
pub enum Points {
    /// Pixels of the tile grid (converted to views of the texture).
    Texels(Vec<Texel>),
    /// Continuous positions with levels of detail.
    Footprints(Vec<Footprint>),
}

impl Points {
    /// Number of samples.
    pub fn len(&self) -> usize {
        match self {
            Points::Texels(v) => v.len(),
            Points::Footprints(v) => v.len(),
        }
    }

    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

fn too_many(n: usize) -> ApiError {
    ApiError::new(Kind::TooLarge, "too_many_samples", format!("{n} samples; at most {MAX_SAMPLES} per request"))
}

fn invalid(index: usize, message: String) -> ApiError {
    ApiError::bad_request("invalid_sample", format!("sample {index}: {message}"))
}

/// A tile-grid pixel checked against the texture's (or landscape's) zoom and coordinate ranges.
fn texel(zooms: Zooms, index: usize, x: i64, y: i64, z: i64) -> Result<Texel, ApiError> {
    // Samples are texels of the tile grid at native zoom or coarser (not magnified).
    let (zmin, zmax) = (zooms.min as i64, zooms.native as i64);
    if !(zmin..=zmax).contains(&z) {
        return Err(invalid(index, format!("z = {z} is outside {zmin}..={zmax} (samples are not magnified)")));
    }
    for (name, v) in [("x", x), ("y", y)] {
        if !(PIXEL_MIN..=PIXEL_MAX).contains(&v) {
            return Err(invalid(index, format!("{name} = {v} is outside the tile range {PIXEL_MIN}..={PIXEL_MAX}")));
        }
    }
    Ok(Texel { x, y, zoom_out: zooms.native - z as u32 })
}

/// A footprint checked against the native tile range; a finite `lod` is clamped when sampled,
/// NaN and infinities (also a JSON number beyond `f32`) are refused.
fn footprint(index: usize, u: f64, v: f64, lod: f32) -> Result<Footprint, ApiError> {
    for (name, p) in [("u", u), ("v", v)] {
        if !(p.is_finite() && p >= PIXEL_MIN as f64 && p < (PIXEL_MAX + 1) as f64) {
            return Err(invalid(
                index,
                format!("{name} = {p} is outside the tile range [{PIXEL_MIN}, {})", PIXEL_MAX + 1),
            ));
        }
    }
    if lod.is_nan() {
        return Err(invalid(index, "lod is not a number".into()));
    }
    if lod.is_infinite() {
        return Err(invalid(index, format!("lod = {lod} is not finite (beyond the range of a 32-bit float)")));
    }
    Ok(Footprint { u, v, lod })
}

/// The JSON body: `{"points": [[x, y] | [x, y, z], …], "z": Z}` or `{"footprints": [[u, v, lod], …]}`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonBody {
    points: Option<Vec<Vec<i64>>>,
    z: Option<i64>,
    footprints: Option<Vec<[f64; 3]>>,
}

/// Parse a JSON body for a texture or landscape serving `zooms`.
pub fn parse_json(zooms: Zooms, body: &[u8]) -> Result<Points, ApiError> {
    let b: JsonBody = serde_json::from_slice(body)
        .map_err(|e| ApiError::bad_request("invalid_body", format!("not a samples JSON body: {e}")))?;
    match (b.points, b.footprints) {
        (Some(pts), None) => {
            if pts.len() > MAX_SAMPLES {
                return Err(too_many(pts.len()));
            }
            let z = b.z.unwrap_or(zooms.native as i64);
            let out = pts
                .iter()
                .enumerate()
                .map(|(i, p)| match p[..] {
                    [x, y] => texel(zooms, i, x, y, z),
                    [x, y, z] => texel(zooms, i, x, y, z),
                    _ => Err(invalid(i, format!("{} numbers; a point is [x, y] or [x, y, z]", p.len()))),
                })
                .collect::<Result<_, _>>()?;
            Ok(Points::Texels(out))
        }
        (None, Some(fps)) => {
            if b.z.is_some() {
                return Err(ApiError::bad_request("invalid_body", "'z' goes with 'points', not with 'footprints'"));
            }
            if fps.len() > MAX_SAMPLES {
                return Err(too_many(fps.len()));
            }
            let out = fps
                .iter()
                .enumerate()
                .map(|(i, &[u, v, lod])| footprint(i, u, v, lod as f32))
                .collect::<Result<_, _>>()?;
            Ok(Points::Footprints(out))
        }
        _ => Err(ApiError::bad_request("invalid_body", "the body needs exactly one of 'points' and 'footprints'")),
    }
}

/// Parse a binary body of `records` for a texture or landscape serving `zooms`.
pub fn parse_binary(zooms: Zooms, body: &[u8], records: Records) -> Result<Points, ApiError> {
    if !body.len().is_multiple_of(RECORD) {
        return Err(ApiError::bad_request(
            "invalid_body",
            format!("{} bytes is not a whole number of {RECORD}-byte records (truncated?)", body.len()),
        ));
    }
    let n = body.len() / RECORD;
    if n > MAX_SAMPLES {
        return Err(too_many(n));
    }
    let f8 = |r: &[u8], at: usize| {
        let mut b = [0u8; 8];
        b.copy_from_slice(&r[at..at + 8]);
        b
    };
    let f4 = |r: &[u8]| {
        let mut b = [0u8; 4];
        b.copy_from_slice(&r[16..20]);
        b
    };
    let recs = body.chunks_exact(RECORD).enumerate();
    Ok(match records {
        Records::Texels => Points::Texels(
            recs.map(|(i, r)| {
                texel(
                    zooms,
                    i,
                    i64::from_le_bytes(f8(r, 0)),
                    i64::from_le_bytes(f8(r, 8)),
                    u32::from_le_bytes(f4(r)) as i64,
                )
            })
            .collect::<Result<_, _>>()?,
        ),
        Records::Footprints => Points::Footprints(
            recs.map(|(i, r)| {
                footprint(i, f64::from_le_bytes(f8(r, 0)), f64::from_le_bytes(f8(r, 8)), f32::from_le_bytes(f4(r)))
            })
            .collect::<Result<_, _>>()?,
        ),
    })
}

/// Colours of a request and the work they took.
#[derive(Debug, Clone)]
pub struct Answer {
    /// Packed RGB, 3 bytes per sample, in request order.
    pub rgb: Vec<u8>,
    /// Pixels computed at all levels (the computation ratio's numerator).
    pub computed: u64,
    /// Windows rendered.
    pub windows: u64,
}

/// Sample on the synthesis pool (admission, queue and timeout as for tiles), through the
/// server's pyramidal cache, or a cache of the batch's own when the server's is off. Work stops
/// between windows once the request is dropped.
pub async fn run(
    st: &Arc<AppState>,
    tex: Arc<Texture>,
    params: ModeParams,
    map: MapChoice,
    points: Points,
) -> Result<Answer, ApiError> {
    let mode = params.name();
    let figures = Arc::new([AtomicU64::new(0), AtomicU64::new(0)]);
    let (fig, pyramid) = (figures.clone(), st.pyramid.clone());
    let (synthesized, delivered) = (st.metrics.pixels_synthesized.clone(), st.metrics.pixels_delivered.clone());
    let max_zoom_out = tex.native_zoom() - tex.min_zoom();
    let n = points.len() as u64;
    let rgb = st
        .synthesize(mode, move |cancel| {
            let local;
            let cache: &Pyramid = if pyramid.is_on() {
                &pyramid
            } else {
                local = Pyramid::new(BATCH_CACHE);
                &local
            };
            let src = match &map {
                MapChoice::Map(n) => tex.source().with_map(tex.exemplar.map(n).ok_or_else(|| {
                    ApiError::bad_request("invalid_map", format!("texture '{}' has no map '{n}'", tex.config.id))
                })?),
                _ => tex.source(),
            };
            let s = match &points {
                Points::Texels(t) => samples::texels_until(&params, &src, cache, t, cancel)?,
                Points::Footprints(f) => samples::footprints_until(&params, &src, cache, f, max_zoom_out, cancel)?,
            };
            fig[0].store(s.synthesized, Ordering::Relaxed);
            fig[1].store(s.windows, Ordering::Relaxed);
            synthesized.with_label_values(&[mode]).inc_by(s.synthesized);
            delivered.with_label_values(&[mode]).inc_by(n);
            let mut rgb: Vec<u8> = s.colors.into_iter().flatten().collect();
            // Filtered footprints blend texels: blended normals are made unit again.
            if src.map.is_some_and(|m| m.normal) {
                textile_core::maps::renormalise(&mut rgb);
            }
            Ok(rgb)
        })
        .await?;
    Ok(Answer {
        rgb: rgb.to_vec(),
        computed: figures[0].load(Ordering::Relaxed),
        windows: figures[1].load(Ordering::Relaxed),
    })
}

/// Most tiles one request of a landscape's samples may read (each a tile the landscape serves,
/// made through the tile cache: 256 cold tiles are about a minute of work on two cores).
pub const MAX_LANDSCAPE_TILES: usize = 256;

/// A landscape's samples: every texel a sample reads (one for a texel, up to eight for a
/// footprint, as for a texture) taken from the landscape's tile that holds it, made as it is
/// served (through the tile cache and the pool), then filtered and blended as a texture's
/// samples are. `job` is the landscape with the request's seed, period and map. A sample at a
/// tile's pixel centre is that pixel.
pub async fn run_landscape(st: &Arc<AppState>, job: LandscapeJob, points: Points) -> Result<Answer, ApiError> {
    let zooms = job.land.zooms();
    let taps: Vec<Vec<(Texel, u32)>> = match &points {
        Points::Texels(t) => t.iter().map(|&texel| vec![(texel, 1 << 24)]).collect(),
        Points::Footprints(f) => {
            samples::filter::taps(f, zooms.native - zooms.min)?.iter().map(|t| t.iter().copied().collect()).collect()
        }
    };
    // The tiles the taps fall in, each with the taps it answers.
    let mut tiles: std::collections::BTreeMap<(u32, i64, i64), Vec<(usize, usize)>> = Default::default();
    for (i, t) in taps.iter().enumerate() {
        for (j, (texel, _)) in t.iter().enumerate() {
            let key = (texel.zoom_out, texel.x.div_euclid(TILE_SIZE), texel.y.div_euclid(TILE_SIZE));
            tiles.entry(key).or_default().push((i, j));
        }
    }
    if tiles.len() > MAX_LANDSCAPE_TILES {
        return Err(ApiError::bad_request(
            "too_many_tiles",
            format!(
                "landscape '{}': these samples lie in {} tiles; at most {MAX_LANDSCAPE_TILES} per request",
                job.land.config.id,
                tiles.len()
            ),
        ));
    }
    let mut colours: Vec<Vec<[u8; 3]>> = taps.iter().map(|t| vec![[0; 3]; t.len()]).collect();
    let mut computed = 0;
    for (&(k, tx, ty), at) in &tiles {
        let z = zooms.native - k;
        let spec = TileSpec { z, x: tx, y: ty, scale: 1, format: crate::encode::Format::Png };
        let picture = crate::pipeline::Picture::Landscape(job.at(Target::Tile(spec), job.map.clone()));
        let (bytes, hit) = produce_picture(st, &picture.etag(), picture).await;
        let img = image::load_from_memory(&bytes?)
            .map_err(|e| ApiError::internal(format!("a landscape tile: {e}")))?
            .to_rgb8();
        if !hit {
            computed += (TILE_SIZE * TILE_SIZE) as u64;
        }
        for &(i, j) in at {
            let t = taps[i][j].0;
            let (x, y) = (t.x.rem_euclid(TILE_SIZE) as u32, t.y.rem_euclid(TILE_SIZE) as u32);
            colours[i][j] = img.get_pixel(x, y).0;
        }
    }
    let mut rgb: Vec<u8> =
        taps.iter().zip(&colours).flat_map(|(t, c)| samples::filter::blend(t.iter().map(|&(_, w)| w).zip(c))).collect();
    if job.map == crate::pipeline::landscape::LandscapeMap::Map("normal".into()) {
        textile_core::maps::renormalise(&mut rgb);
    }
    Ok(Answer { rgb, computed, windows: tiles.len() as u64 })
}
