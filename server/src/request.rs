//! Validated tile and window requests: path segments and query strings parsed once, at the
//! edge, into typed values with errors that name the parameter, the value and what is allowed.
//!
//! A query is read by one [`ParamReader`]: the server takes its own keys (`v`, a window's
//! geometry), then the texture's [`textile_core::Defaults`] read `mode`, `seed`, `world` and the
//! mode's own keys, and whatever is left is refused, naming the mode it belongs to.

use textile_core::error::clip;
use textile_core::maps::MapChoice;
use textile_core::modes::Needs;
use textile_core::{ModeParams, ParamReader};

use crate::encode::Format;
use crate::error::ApiError;
use crate::terrain::Dem;
use crate::textures::{Texture, Zooms};

/// Smallest tile coordinate.
pub const COORD_MIN: i64 = -(1 << 31);
/// Largest tile coordinate.
pub const COORD_MAX: i64 = (1 << 31) - 1;
/// Largest window side.
pub const MAX_WINDOW_SIDE: i64 = 4096;
/// Largest window origin magnitude, in pixels at the requested zoom.
pub const MAX_WINDOW_COORD: i64 = 1 << 40;
/// Longest `v` (cache-busting version) a tile accepts: a TileJSON's own version (12) joined to a
/// caller's (at most [`MAX_CALLER_V`]).
pub const MAX_V: usize = 80;
/// Longest `v` a caller may give TileJSON (carried into its tiles template).
pub const MAX_CALLER_V: usize = 64;

/// A query string (percent-encoded, without the `?`) of key–value pairs, in their order.
pub fn query_string<'a>(pairs: impl IntoIterator<Item = (&'a String, &'a String)>) -> String {
    let mut qs = form_urlencoded::Serializer::new(String::new());
    for (k, v) in pairs {
        qs.append_pair(k, v);
    }
    qs.finish()
}

/// The key–value pairs of a raw query string, percent-decoded, in order.
pub fn query_pairs(raw: Option<&str>) -> Vec<(String, String)> {
    form_urlencoded::parse(raw.unwrap_or("").as_bytes()).into_owned().collect()
}

/// A reader over a raw query string (a repeated key is an error).
pub fn query_reader(raw: Option<&str>) -> Result<ParamReader, ApiError> {
    Ok(ParamReader::request(query_pairs(raw))?)
}

/// Resolve a request's parameters against a texture's defaults: takes `v` (checked, not part
/// of the content), then the texture reads the rest and refuses leftovers. A mode that needs
/// the texture's analysis, or what it prepares from the texture, answers 503 `not_ready` (with
/// `Retry-After`) while that is computed.
pub fn params(tex: &Texture, mut r: ParamReader) -> Result<ModeParams, ApiError> {
    if r.take("v").is_some_and(|v| v.len() > MAX_V) {
        return Err(ApiError::bad_request("invalid_parameter", format!("parameter 'v': at most {MAX_V} characters")));
    }
    let p = tex.defaults.request(&tex.source(), r)?;
    let mode = p.name();
    match p.info().needs {
        Needs::Analysis if tex.analysis().is_none() => Err(textile_core::CoreError::NotAnalysed { mode }.into()),
        Needs::Prepared if !tex.prepared.has(mode) => Err(textile_core::CoreError::NotPrepared { mode }.into()),
        _ => Ok(p),
    }
}

/// Read `map=` and, with `map=height`, a raster-dem's `encoding`, `height_scale` and `base`
/// (see [`Dem::read`]): a raster-dem renders the texture's height map, or, when it has none,
/// its colour, whose luma serves.
pub fn map_and_dem(tex: &Texture, r: &mut ParamReader, format: Format) -> Result<(MapChoice, Option<Dem>), ApiError> {
    let name = r.take("map");
    if let Some(dem) = Dem::read(r, name.as_deref(), format, tex.height_scale())? {
        let map = match tex.exemplar.map("height") {
            Some(_) => MapChoice::Map("height".into()),
            None => MapChoice::Albedo,
        };
        return Ok((map, Some(dem)));
    }
    match name {
        Some(n) => Ok((parse_map(tex, &n, format)?, None)),
        None => Ok((MapChoice::Albedo, None)),
    }
}

/// Read `map=` (default `albedo`): the colour, one of the texture's maps, or `uv` (PNG only).
pub fn map_choice(tex: &Texture, r: &mut ParamReader, format: Format) -> Result<MapChoice, ApiError> {
    match r.take("map") {
        Some(name) => parse_map(tex, &name, format),
        None => Ok(MapChoice::Albedo),
    }
}

/// The map called `name` (`albedo`, one of the texture's maps, or `uv`, PNG only).
pub fn parse_map(tex: &Texture, name: &str, format: Format) -> Result<MapChoice, ApiError> {
    let choice = match name {
        "albedo" => MapChoice::Albedo,
        "uv" => MapChoice::Uv,
        n if tex.exemplar.map(n).is_some() => MapChoice::Map(n.to_string()),
        n => {
            let have: Vec<&str> =
                ["albedo"].into_iter().chain(tex.exemplar.maps.iter().map(|m| m.name.as_str())).chain(["uv"]).collect();
            return Err(ApiError::bad_request(
                "invalid_map",
                format!("map '{}': texture '{}' has no such map; it has: {}", clip(n), tex.config.id, have.join(", ")),
            ));
        }
    };
    if choice == MapChoice::Uv && format != Format::Png {
        return Err(ApiError::bad_request(
            "invalid_map",
            "map 'uv': coordinates are served as 16-bit PNG only (use .png)".to_string(),
        ));
    }
    Ok(choice)
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
        ApiError::bad_request(
            "invalid_coordinate",
            format!("'{name}' = '{}' is not an integer in [{lo}, {hi}]", clip(s)),
        )
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
            format!("'{}' has no format extension; use .png, .jpg, .jpeg or .webp", clip(s)),
        )
    })?;
    let fmt = Format::from_ext(ext).ok_or_else(|| {
        ApiError::bad_request(
            "invalid_format",
            format!("format '{}' is not supported; use png, jpg, jpeg or webp", clip(ext)),
        )
    })?;
    Ok((stem, fmt))
}

/// Parse `z`, `x` and `y[@2x].fmt` path segments for a texture.
pub fn parse_tile(tex: &Texture, z: &str, x: &str, y_fmt: &str) -> Result<TileSpec, ApiError> {
    parse_tile_in(tex.zooms(), z, x, y_fmt)
}

/// Parse `z`, `x` and `y[@2x].fmt` path segments within `zooms`.
pub fn parse_tile_in(zooms: Zooms, z: &str, x: &str, y_fmt: &str) -> Result<TileSpec, ApiError> {
    let (y, format) = split_format(y_fmt)?;
    let (y, scale) = match y.strip_suffix("@2x") {
        Some(y) => (y, 2),
        None => (y, 1),
    };
    let z = parse_int("z", z, zooms.min as i64, zooms.max as i64)? as u32;
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

/// Take a window's geometry (`x`, `y`, `w`, `h`, optional `z`) from a query.
pub fn parse_window(tex: &Texture, r: &mut ParamReader, format: Format) -> Result<WindowSpec, ApiError> {
    parse_window_in(tex.zooms(), r, format)
}

/// Take a window's geometry (`x`, `y`, `w`, `h`, optional `z`) within `zooms` from a query.
pub fn parse_window_in(zooms: Zooms, r: &mut ParamReader, format: Format) -> Result<WindowSpec, ApiError> {
    let mut need = |k: &str| {
        r.take(k).ok_or_else(|| ApiError::bad_request("missing_parameter", format!("parameter '{k}' is required")))
    };
    let (x, y, w, h) = (need("x")?, need("y")?, need("w")?, need("h")?);
    let z = match r.take("z") {
        Some(z) => parse_int("z", &z, zooms.min as i64, zooms.max as i64)? as u32,
        None => zooms.native,
    };
    let x = parse_int("x", &x, -MAX_WINDOW_COORD, MAX_WINDOW_COORD)?;
    let y = parse_int("y", &y, -MAX_WINDOW_COORD, MAX_WINDOW_COORD)?;
    let w = parse_int("w", &w, 1, MAX_WINDOW_SIDE)?;
    let h = parse_int("h", &h, 1, MAX_WINDOW_SIDE)?;
    Ok(WindowSpec { z, x, y, w, h, format })
}
