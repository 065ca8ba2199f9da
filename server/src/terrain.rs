//! Heights as a MapLibre `raster-dem`: `map=height&encoding=terrarium|mapbox` turns a tile's
//! heights (its material's height map, or its luma when it has none) into elevations —
//! `base + height × height_scale` metres, height in 0–1 — encoded in Terrarium or Mapbox
//! Terrain-RGB, as a lossless PNG.

use textile_core::ParamReader;

use crate::encode::{encode, Effort, Format};
use crate::error::ApiError;

/// The encodings, as the query names them.
pub const ENCODINGS: &[&str] = &["terrarium", "mapbox"];
/// Largest `height_scale`, in metres.
pub const MAX_HEIGHT_SCALE: f64 = 100_000.0;
/// Largest `|base|`, in metres.
pub const MAX_BASE: f64 = 10_000.0;
/// Default relief, in texels at the native zoom: a height of 1 rises as high as this many
/// texels are wide, so the relief shows at every zoom a texture is seen at.
pub const DEFAULT_RELIEF_TEXELS: f64 = 4.0;
/// The equator's length in Web-Mercator metres.
const EQUATOR_M: f64 = 40_075_016.685_578_5;

/// A raster-dem encoding.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Encoding {
    /// Mapzen Terrarium: `(R·256 + G + B/256) − 32768` metres.
    Terrarium,
    /// Mapbox Terrain-RGB: `−10000 + (R·65536 + G·256 + B)·0.1` metres.
    Mapbox,
}

impl Encoding {
    /// As the query and TileJSON name it.
    pub fn name(self) -> &'static str {
        match self {
            Encoding::Terrarium => "terrarium",
            Encoding::Mapbox => "mapbox",
        }
    }

    /// The smallest step of elevation it carries, in metres.
    pub fn quantum(self) -> f64 {
        match self {
            Encoding::Terrarium => 1.0 / 256.0,
            Encoding::Mapbox => 0.1,
        }
    }

    /// An elevation's RGB (clamped to what the encoding carries).
    pub fn rgb(self, metres: f64) -> [u8; 3] {
        match self {
            Encoding::Terrarium => {
                let v = (metres + 32768.0).clamp(0.0, 65535.996);
                let n = (v * 256.0).round() as u32;
                [(n >> 16) as u8, (n >> 8) as u8, n as u8]
            }
            Encoding::Mapbox => {
                let n = ((metres + 10000.0) * 10.0).round().clamp(0.0, 16_777_215.0) as u32;
                [(n >> 16) as u8, (n >> 8) as u8, n as u8]
            }
        }
    }

    /// The elevation an RGB carries.
    pub fn metres(self, [r, g, b]: [u8; 3]) -> f64 {
        match self {
            Encoding::Terrarium => r as f64 * 256.0 + g as f64 + b as f64 / 256.0 - 32768.0,
            Encoding::Mapbox => -10000.0 + (r as f64 * 65536.0 + g as f64 * 256.0 + b as f64) * 0.1,
        }
    }
}

/// How a tile's heights become elevations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dem {
    /// The encoding.
    pub encoding: Encoding,
    /// Metres per unit of height (height runs 0–1).
    pub height_scale: f64,
    /// Elevation of height 0, in metres.
    pub base: f64,
}

/// The default `height_scale` of something whose native zoom is `native`: a height of 1 rises
/// [`DEFAULT_RELIEF_TEXELS`] texels' width at that zoom, in Web-Mercator metres at the equator.
pub fn default_height_scale(native: u32) -> f64 {
    DEFAULT_RELIEF_TEXELS * EQUATOR_M / (256.0 * f64::from(1u32 << native.min(30)))
}

impl Dem {
    /// Read `encoding`, `height_scale` and `base` from a query whose `map` is `map` (`None`:
    /// absent); `None` when it asks for no raster-dem. `height_scale` defaults to `scale`.
    pub fn read(r: &mut ParamReader, map: Option<&str>, format: Format, scale: f64) -> Result<Option<Dem>, ApiError> {
        let bad = |m: String| ApiError::bad_request("invalid_parameter", m);
        let Some(enc) = r.take("encoding") else {
            for k in ["height_scale", "base"] {
                if r.take(k).is_some() {
                    return Err(bad(format!(
                        "parameter '{k}': goes with encoding={} and map=height",
                        ENCODINGS.join("|")
                    )));
                }
            }
            return Ok(None);
        };
        let encoding = match enc.as_str() {
            "terrarium" => Encoding::Terrarium,
            "mapbox" => Encoding::Mapbox,
            other => {
                return Err(bad(format!(
                    "parameter 'encoding': '{}' is not one of {}",
                    textile_core::error::clip(other),
                    ENCODINGS.join(", ")
                )))
            }
        };
        if map != Some("height") {
            return Err(bad("parameter 'encoding': a raster-dem encodes heights; add map=height".into()));
        }
        if format != Format::Png {
            return Err(bad("parameter 'encoding': raster-dem tiles are lossless PNG (use .png)".into()));
        }
        let mut number = |k: &str, lo: f64, hi: f64, default: f64| -> Result<f64, ApiError> {
            match r.take(k) {
                None => Ok(default),
                Some(v) => v.parse::<f64>().ok().filter(|x| x.is_finite() && (lo..=hi).contains(x)).ok_or_else(|| {
                    bad(format!(
                        "parameter '{k}': '{}' is not a number in [{lo}, {hi}] metres",
                        textile_core::error::clip(&v)
                    ))
                }),
            }
        };
        let height_scale = number("height_scale", 0.0, MAX_HEIGHT_SCALE, scale)?;
        let base = number("base", -MAX_BASE, MAX_BASE, 0.0)?;
        Ok(Some(Dem { encoding, height_scale, base }))
    }

    /// What the cache key and ETag add.
    pub fn key(&self) -> String {
        format!("|dem={}:{}:{}", self.encoding.name(), self.height_scale, self.base)
    }

    /// The PNG of heights given as RGB bytes whose red channel is the height (0–255).
    pub fn png(&self, heights: &[u8], w: u32, h: u32) -> Result<Vec<u8>, ApiError> {
        // 256 heights at most: each encoded once.
        let table: Vec<[u8; 3]> =
            (0..=255u8).map(|v| self.encoding.rgb(self.base + v as f64 / 255.0 * self.height_scale)).collect();
        let rgb: Vec<u8> = heights.chunks_exact(3).flat_map(|p| table[p[0] as usize]).collect();
        encode(&rgb, w, h, Format::Png, Effort::Map).map_err(|e| ApiError::internal(format!("encoding: {e}")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_encodings_round_trip_within_their_quantum() {
        for enc in [Encoding::Terrarium, Encoding::Mapbox] {
            for i in 0..=2000 {
                let m = -500.0 + i as f64 * 7.377;
                let back = enc.metres(enc.rgb(m));
                assert!((back - m).abs() <= enc.quantum() / 2.0 + 1e-9, "{enc:?}: {m} -> {back}");
            }
        }
        // The published reference points: sea level.
        assert_eq!(Encoding::Terrarium.rgb(0.0), [128, 0, 0]);
        assert_eq!(Encoding::Mapbox.rgb(0.0), [1, 134, 160]);
    }
}
