//! Validated tile and window requests: path segments and query strings parsed once, at the
//! edge, into typed values with errors that name the parameter, the value and what is allowed.

use std::collections::BTreeMap;

use textile_core::{MosaicParams, Randomness, SynthParams};

use crate::encode::{Effort, Format};
use crate::http::error::ApiError;
use crate::textures::Texture;

/// Synthesis modes served.
pub const MODES: &[&str] = &["synth", "mosaic"];
/// Tile side in pixels (`@2x` tiles are twice that).
pub const TILE_SIZE: i64 = 256;
/// Smallest tile coordinate.
pub const COORD_MIN: i64 = -(1 << 31);
/// Largest tile coordinate.
pub const COORD_MAX: i64 = (1 << 31) - 1;
/// Largest window side.
pub const MAX_WINDOW_SIDE: i64 = 4096;
/// Largest window origin magnitude, in pixels at the requested zoom.
pub const MAX_WINDOW_COORD: i64 = 1 << 40;
/// Largest `world` (tiles at native zoom).
pub const MAX_WORLD: i64 = 1 << 31;
/// Query parameters every image endpoint accepts.
pub const PARAM_KEYS: &[&str] = &["mode", "seed", "randomness", "world", "v", "iterations", "block_area", "smoothing"];

/// Parsed, de-duplicated query parameters.
pub type Query = BTreeMap<String, String>;

/// Parse a raw query string; unknown or repeated keys are errors.
pub fn parse_query(raw: Option<&str>, allowed: &[&str]) -> Result<Query, ApiError> {
    let mut q = Query::new();
    for (k, v) in form_urlencoded::parse(raw.unwrap_or("").as_bytes()) {
        if !allowed.contains(&k.as_ref()) {
            return Err(ApiError::bad_request(
                "unknown_parameter",
                format!("unknown query parameter '{k}'; allowed: {}", allowed.join(", ")),
            ));
        }
        if q.insert(k.to_string(), v.to_string()).is_some() {
            return Err(ApiError::bad_request("invalid_parameter", format!("parameter '{k}' is given more than once")));
        }
    }
    Ok(q)
}

/// The engine and its parameters for a request.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum RenderParams {
    /// Parallel controllable synthesis.
    Synth(SynthParams),
    /// Chaos mosaic.
    Mosaic(MosaicParams),
}

impl RenderParams {
    /// Canonical form for cache keys and ETags.
    pub fn canonical(&self) -> String {
        match self {
            RenderParams::Synth(p) => format!("mode=synth;{}", p.canonical()),
            RenderParams::Mosaic(p) => format!("mode=mosaic;{}", p.canonical()),
        }
    }

    /// The mode's name.
    pub fn mode(&self) -> &'static str {
        match self {
            RenderParams::Synth(_) => "synth",
            RenderParams::Mosaic(_) => "mosaic",
        }
    }

    /// How hard to compress this engine's images (see [`Effort`]).
    pub fn effort(&self) -> Effort {
        match self {
            RenderParams::Synth(_) => Effort::Tight,
            RenderParams::Mosaic(_) => Effort::Quick,
        }
    }
}

fn invalid(message: String) -> ApiError {
    ApiError::bad_request("invalid_parameter", message)
}

fn parse_u32(name: &str, s: &str, max: u32) -> Result<u32, ApiError> {
    s.parse()
        .ok()
        .filter(|v| *v <= max)
        .ok_or_else(|| invalid(format!("parameter '{name}': '{s}' is not an integer in 0..={max}")))
}

/// Resolve a request's parameters against a texture's defaults.
pub fn render_params(tex: &Texture, q: &Query) -> Result<RenderParams, ApiError> {
    let mode = q.get("mode").cloned().unwrap_or_else(|| tex.config.default_mode.clone());
    let only = |keys: &[&str], m: &str| -> Result<(), ApiError> {
        match keys.iter().find(|k| q.contains_key(**k)) {
            Some(k) => Err(invalid(format!("parameter '{k}' does not apply to mode={mode}; it is for mode={m}"))),
            None => Ok(()),
        }
    };
    let seed =
        match q.get("seed") {
            Some(s) => Some(s.parse::<u64>().map_err(|_| {
                invalid(format!("parameter 'seed': '{s}' is not an integer in 0..=18446744073709551615"))
            })?),
            None => None,
        };
    let period = match q.get("world") {
        Some(s) => {
            let w: i64 =
                s.parse().ok().filter(|w: &i64| *w >= 1 && *w <= MAX_WORLD && w.count_ones() == 1).ok_or_else(
                    || {
                        invalid(format!(
                            "parameter 'world': '{s}' is not a power of two from 1 to 2^31 (tiles at the native zoom)"
                        ))
                    },
                )?;
            Some(w * TILE_SIZE)
        }
        None => None,
    };
    if q.get("v").is_some_and(|v| v.len() > 64) {
        return Err(invalid("parameter 'v': at most 64 characters".into()));
    }
    let world_error = |e: textile_core::CoreError| match e {
        textile_core::CoreError::Param { name: "period", .. } => invalid(format!(
            "parameter 'world': the period must be at least the exemplar side ({} texels), so world >= {}",
            tex.analysis.side(),
            (tex.analysis.side() as i64 / TILE_SIZE).max(1)
        )),
        other => ApiError::from(other),
    };
    match mode.as_str() {
        "synth" => {
            only(&["iterations", "block_area", "smoothing"], "mosaic")?;
            let mut p = tex.defaults.clone();
            p.seed = seed.unwrap_or(p.seed);
            p.period = period;
            if let Some(s) = q.get("randomness") {
                p.randomness = Randomness::parse(s).map_err(ApiError::from)?;
            }
            p.validate_for(&tex.analysis).map_err(world_error)?;
            Ok(RenderParams::Synth(p))
        }
        "mosaic" => {
            only(&["randomness"], "synth")?;
            let mut p = MosaicParams { seed: seed.unwrap_or(tex.defaults.seed), period, ..MosaicParams::default() };
            if let Some(s) = q.get("iterations") {
                p.iterations = parse_u32("iterations", s, textile_core::mosaic::MAX_ITERATIONS)?;
            }
            if let Some(s) = q.get("smoothing") {
                p.smoothing = parse_u32("smoothing", s, textile_core::mosaic::MAX_SMOOTHING)?;
            }
            if let Some(s) = q.get("block_area") {
                let msg = || {
                    invalid(format!("parameter 'block_area': '{s}' must be MIN,MAX fractions of the exemplar area with 0.05 <= MIN <= MAX <= 1"))
                };
                let (a, b) = s.split_once(',').ok_or_else(msg)?;
                let f = |v: &str| v.trim().parse::<f64>().ok().filter(|x| x.is_finite()).map(|x| (x * 1000.0).round());
                let (a, b) = (f(a).ok_or_else(msg)?, f(b).ok_or_else(msg)?);
                if !(50.0..=1000.0).contains(&a) || !(a..=1000.0).contains(&b) {
                    return Err(msg());
                }
                (p.area_min, p.area_max) = (a as u32, b as u32);
            }
            p.validate_for(&tex.analysis).map_err(world_error)?;
            Ok(RenderParams::Mosaic(p))
        }
        _ => Err(invalid(format!("parameter 'mode': '{mode}' is not available; allowed: {}", MODES.join(", ")))),
    }
}

/// A tile address.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TileSpec {
    /// Zoom.
    pub z: u32,
    /// Column.
    pub x: i64,
    /// Row.
    pub y: i64,
    /// 1 (256 px) or 2 (`@2x`, 512 px).
    pub scale: u32,
    /// Encoding.
    pub format: Format,
}

fn parse_int(name: &str, s: &str, lo: i64, hi: i64) -> Result<i64, ApiError> {
    let v: i64 = s.parse().map_err(|_| {
        ApiError::bad_request("invalid_coordinate", format!("'{name}' = '{s}' is not an integer in [{lo}, {hi}]"))
    })?;
    if v < lo || v > hi {
        return Err(ApiError::bad_request("invalid_coordinate", format!("'{name}' = {v} is outside [{lo}, {hi}]")));
    }
    Ok(v)
}

/// Split `NAME.EXT` and parse the format.
pub fn split_format(s: &str) -> Result<(&str, Format), ApiError> {
    let (stem, ext) = s.rsplit_once('.').ok_or_else(|| {
        ApiError::bad_request(
            "invalid_format",
            format!("'{s}' has no format extension; use .png, .jpg, .jpeg or .webp"),
        )
    })?;
    let fmt = Format::from_ext(ext).ok_or_else(|| {
        ApiError::bad_request("invalid_format", format!("format '{ext}' is not supported; use png, jpg, jpeg or webp"))
    })?;
    Ok((stem, fmt))
}

/// Parse `z`, `x` and `y[@2x].fmt` path segments for a texture.
pub fn parse_tile(tex: &Texture, z: &str, x: &str, y_fmt: &str) -> Result<TileSpec, ApiError> {
    let (y, format) = split_format(y_fmt)?;
    let (y, scale) = match y.strip_suffix("@2x") {
        Some(y) => (y, 2),
        None => (y, 1),
    };
    let z = parse_int("z", z, tex.min_zoom() as i64, tex.max_zoom() as i64)? as u32;
    let x = parse_int("x", x, COORD_MIN, COORD_MAX)?;
    let y = parse_int("y", y, COORD_MIN, COORD_MAX)?;
    Ok(TileSpec { z, x, y, scale, format })
}

/// A window request (`/windows/{id}.{fmt}`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WindowSpec {
    /// Zoom.
    pub z: u32,
    /// Left pixel at that zoom.
    pub x: i64,
    /// Top pixel at that zoom.
    pub y: i64,
    /// Width.
    pub w: i64,
    /// Height.
    pub h: i64,
    /// Encoding.
    pub format: Format,
}

/// Query keys of the window endpoint.
pub const WINDOW_KEYS: &[&str] =
    &["mode", "seed", "randomness", "world", "v", "iterations", "block_area", "smoothing", "x", "y", "w", "h", "z"];

/// Parse a window request's geometry from its query.
pub fn parse_window(tex: &Texture, q: &Query, format: Format) -> Result<WindowSpec, ApiError> {
    let need = |k: &str| {
        q.get(k).ok_or_else(|| ApiError::bad_request("missing_parameter", format!("parameter '{k}' is required")))
    };
    let z = match q.get("z") {
        Some(z) => parse_int("z", z, tex.min_zoom() as i64, tex.max_zoom() as i64)? as u32,
        None => tex.native_zoom(),
    };
    let x = parse_int("x", need("x")?, -MAX_WINDOW_COORD, MAX_WINDOW_COORD)?;
    let y = parse_int("y", need("y")?, -MAX_WINDOW_COORD, MAX_WINDOW_COORD)?;
    let w = parse_int("w", need("w")?, 1, MAX_WINDOW_SIDE)?;
    let h = parse_int("h", need("h")?, 1, MAX_WINDOW_SIDE)?;
    Ok(WindowSpec { z, x, y, w, h, format })
}
