//! Spatial modulation of randomness over the output, `R_S` (design note §1.9), carried by a
//! request as its `controls` parameter: hash-based value noise of absolute coordinates (a
//! scale and a range) and painted strokes (discs with a value and a soft edge, painted in
//! order over the noise) — "calm here, wild there". Each level's jitter is scaled by `R_S` at
//! the centre of the 4×4-pixel block (aligned in absolute coordinates) around the pixel, a pure
//! function of absolute coordinates, so windows stay the same pixels cut from larger ones and
//! replicas agree with no shared state.
//!
//! Features (design note §1.9, drag-and-drop) travel with them: each imposes the exemplar
//! around a source coordinate over a disc of the output, exactly at native zoom within its inner
//! radius, over a disc growing to its outer radius at the coarsest level (the surroundings
//! adapt); imposed pixels are not corrected.
//!
//! The parameter is base64url (unpadded) of JSON, at most [`MAX_CONTROLS_LEN`] characters:
//! `{"noise": {"scale": 64, "range": [0.2, 1]}, "strokes": [{"at": [x, y], "radius": 40,
//! "soft": 8, "value": 0}], "features": [{"at": [x, y], "source": [u, v], "inner": 12,
//! "outer": 40}]}` (native texels; values in `[0, 1]`; at most [`MAX_STROKES`] strokes and
//! [`MAX_FEATURES`] features). It is parsed once into fixed point; its canonical text is part of cache keys
//! and ETags, so equal controls written differently are one request.

use base64::Engine;
use serde_json::{Map, Value};

use crate::error::{CoreError, Result};
use crate::hash::{hash, TAG_NOISE};
use crate::modes::params::ONE_Q16;

/// Longest `controls` value accepted (characters of base64url).
pub const MAX_CONTROLS_LEN: usize = 2048;
/// Most strokes in one request.
pub const MAX_STROKES: usize = 64;
/// Largest noise scale, stroke radius and soft edge (texels).
pub const MAX_EXTENT: i64 = 1 << 20;
/// Largest stroke centre coordinate (texels), as for windows.
pub const MAX_COORD: i64 = 1 << 40;

/// Value noise: a lattice of `scale` texels with hashed values in `[lo, hi]` at its points,
/// bilinearly interpolated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Noise {
    /// Lattice spacing in native texels (a power of two).
    pub scale: i64,
    /// Lowest value (fixed point, `[0, 65536]`).
    pub lo: u32,
    /// Highest value (fixed point).
    pub hi: u32,
}

/// A painted disc: `value` within `radius` of `(x, y)`, fading to what is below over `soft`
/// more texels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Stroke {
    /// Centre, native texels.
    pub x: i64,
    /// Centre, native texels.
    pub y: i64,
    /// Radius of the full-strength disc (texels).
    pub radius: i64,
    /// Width of the soft edge (texels).
    pub soft: i64,
    /// Value (fixed point, `[0, 65536]`).
    pub value: u32,
}

/// A dragged-and-dropped exemplar feature (design note §1.9): around output position
/// `(x, y)` the texture is the exemplar around `(u, v)`, exactly within `inner` texels at native
/// zoom; the disc it is imposed on grows linearly to `outer` at the coarsest level, so the
/// surroundings adapt.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Feature {
    /// Output position, native texels.
    pub x: i64,
    /// Output position, native texels.
    pub y: i64,
    /// Exemplar coordinate.
    pub u: i64,
    /// Exemplar coordinate.
    pub v: i64,
    /// Radius kept exact at native zoom (texels).
    pub inner: i64,
    /// Radius at the coarsest level (texels), at least `inner`.
    pub outer: i64,
}

impl Feature {
    /// The exemplar coordinate (before wrapping) this feature imposes on the pixel whose
    /// footprint centre is native position `(px, py)` at level `l` of `levels`, if its disc
    /// there (radius from `outer` at level 0 to `inner` at `levels`) holds that centre; with a
    /// `period`, the disc wraps.
    #[inline]
    pub fn imposes(&self, l: u32, levels: u32, px: i64, py: i64, period: Option<i64>) -> Option<(i64, i64)> {
        let r = (self.inner * l as i64 + self.outer * (levels - l) as i64) / levels.max(1) as i64;
        let d = |a: i64, b: i64| match period {
            Some(p) => {
                let d = (a - b).rem_euclid(p);
                if d > p / 2 {
                    d - p
                } else {
                    d
                }
            }
            None => a - b,
        };
        let (dx, dy) = (d(px, self.x), d(py, self.y));
        (dx.abs() < r && dy.abs() < r && dx * dx + dy * dy < r * r).then_some((self.u + dx, self.v + dy))
    }
}

/// Most features in one request.
pub const MAX_FEATURES: usize = 32;

/// The request's controls (empty: `R_S ≡ 1`, no features).
#[derive(Debug, Clone, PartialEq, Eq, Hash, Default)]
pub struct Controls {
    /// Noise modulation, if any (else 1 under the strokes).
    pub noise: Option<Noise>,
    /// Strokes, painted in order.
    pub strokes: Vec<Stroke>,
    /// Features; where discs overlap, the later one wins.
    pub features: Vec<Feature>,
}

fn err(message: impl Into<String>) -> CoreError {
    CoreError::Param { name: "controls", message: message.into() }
}

fn unit(v: &Value, what: &str) -> Result<u32> {
    match v.as_f64() {
        Some(x) if (0.0..=1.0).contains(&x) => Ok((x * ONE_Q16 as f64).round() as u32),
        _ => Err(err(format!("{what} must be a number in [0, 1]"))),
    }
}

fn integer(v: &Value, what: &str, lo: i64, hi: i64) -> Result<i64> {
    match v.as_i64() {
        Some(x) if (lo..=hi).contains(&x) => Ok(x),
        _ => Err(err(format!("{what} must be an integer in {lo}..={hi}"))),
    }
}

fn object<'a>(v: &'a Value, what: &str, keys: &[&str]) -> Result<&'a Map<String, Value>> {
    let o = v.as_object().ok_or_else(|| err(format!("{what} must be an object")))?;
    if let Some(k) = o.keys().find(|k| !keys.contains(&k.as_str())) {
        return Err(err(format!("{what} has no key '{}'; keys are {}", crate::error::clip(k), keys.join(", "))));
    }
    Ok(o)
}

impl Controls {
    /// Parse a `controls` value (base64url of JSON, see the module documentation).
    pub fn parse(s: &str) -> Result<Controls> {
        if s.len() > MAX_CONTROLS_LEN {
            return Err(err(format!("is {} characters; at most {MAX_CONTROLS_LEN}", s.len())));
        }
        let bytes = base64::engine::general_purpose::URL_SAFE_NO_PAD
            .decode(s.trim_end_matches('='))
            .map_err(|e| err(format!("is not base64url: {e}")))?;
        let json: Value = serde_json::from_slice(&bytes).map_err(|e| err(format!("is not JSON: {e}")))?;
        Controls::from_json(&json)
    }

    /// The controls of a JSON document (what [`Controls::parse`] decodes).
    pub fn from_json(json: &Value) -> Result<Controls> {
        let o = object(json, "controls", &["noise", "strokes", "features"])?;
        let noise = match o.get("noise") {
            None | Some(Value::Null) => None,
            Some(n) => {
                let n = object(n, "noise", &["scale", "range"])?;
                let scale = integer(n.get("scale").unwrap_or(&Value::Null), "noise.scale", 2, MAX_EXTENT)?;
                if !(scale as u64).is_power_of_two() {
                    return Err(err(format!("noise.scale must be a power of two, not {scale}")));
                }
                let range = n.get("range").and_then(Value::as_array).filter(|r| r.len() == 2);
                let range = range.ok_or_else(|| err("noise.range must be [low, high]"))?;
                let (lo, hi) = (unit(&range[0], "noise.range")?, unit(&range[1], "noise.range")?);
                if lo > hi {
                    return Err(err("noise.range must be [low, high] with low ≤ high"));
                }
                Some(Noise { scale, lo, hi })
            }
        };
        let strokes = match o.get("strokes") {
            None | Some(Value::Null) => Vec::new(),
            Some(list) => {
                let list = list.as_array().ok_or_else(|| err("strokes must be a list"))?;
                if list.len() > MAX_STROKES {
                    return Err(err(format!("has {} strokes; at most {MAX_STROKES}", list.len())));
                }
                list.iter()
                    .map(|st| {
                        let st = object(st, "a stroke", &["at", "radius", "soft", "value"])?;
                        let at = st.get("at").and_then(Value::as_array).filter(|a| a.len() == 2);
                        let at = at.ok_or_else(|| err("a stroke's at must be [x, y]"))?;
                        let coord = |v: &Value| integer(v, "a stroke's at", -MAX_COORD, MAX_COORD);
                        let null = Value::Null;
                        Ok(Stroke {
                            x: coord(&at[0])?,
                            y: coord(&at[1])?,
                            radius: integer(st.get("radius").unwrap_or(&null), "a stroke's radius", 0, MAX_EXTENT)?,
                            soft: integer(st.get("soft").unwrap_or(&Value::from(0)), "a stroke's soft", 0, MAX_EXTENT)?,
                            value: unit(st.get("value").unwrap_or(&null), "a stroke's value")?,
                        })
                    })
                    .collect::<Result<_>>()?
            }
        };
        let features = match o.get("features") {
            None | Some(Value::Null) => Vec::new(),
            Some(list) => {
                let list = list.as_array().ok_or_else(|| err("features must be a list"))?;
                if list.len() > MAX_FEATURES {
                    return Err(err(format!("has {} features; at most {MAX_FEATURES}", list.len())));
                }
                list.iter()
                    .map(|f| {
                        let f = object(f, "a feature", &["at", "source", "inner", "outer"])?;
                        let pair = |key: &str, lo: i64, hi: i64| -> Result<(i64, i64)> {
                            let a = f.get(key).and_then(Value::as_array).filter(|a| a.len() == 2);
                            let a = a.ok_or_else(|| err(format!("a feature's {key} must be [x, y]")))?;
                            let what = format!("a feature's {key}");
                            Ok((integer(&a[0], &what, lo, hi)?, integer(&a[1], &what, lo, hi)?))
                        };
                        let (x, y) = pair("at", -MAX_COORD, MAX_COORD)?;
                        let (u, v) = pair("source", 0, 65535)?;
                        let null = Value::Null;
                        let inner = integer(f.get("inner").unwrap_or(&null), "a feature's inner", 0, MAX_EXTENT)?;
                        let outer = integer(f.get("outer").unwrap_or(&null), "a feature's outer", inner, MAX_EXTENT)?;
                        Ok(Feature { x, y, u, v, inner, outer })
                    })
                    .collect::<Result<_>>()?
            }
        };
        Ok(Controls { noise, strokes, features })
    }

    /// Check against an exemplar of side `side`: every feature's source lies in it.
    pub fn check_size(&self, w: u32, h: u32) -> Result<()> {
        match self.features.iter().find(|f| f.u >= w as i64 || f.v >= h as i64) {
            Some(f) => Err(err(format!(
                "a feature's source [{}, {}] is outside the {w}×{h} exemplar",
                f.u, f.v
            ))),
            None => Ok(()),
        }
    }

    /// No modulation and no features at all.
    pub fn is_empty(&self) -> bool {
        self.noise.is_none() && self.strokes.is_empty() && self.features.is_empty()
    }

    /// No modulation of randomness (`R_S ≡ 1`; features aside).
    pub fn is_unmodulated(&self) -> bool {
        self.noise.is_none() && self.strokes.is_empty()
    }

    /// Canonical text (fixed point), for cache keys and ETags; empty for no controls.
    pub fn canonical(&self) -> String {
        let mut s = String::new();
        if let Some(n) = self.noise {
            s += &format!("n{}:{}:{}", n.scale, n.lo, n.hi);
        }
        for st in &self.strokes {
            s += &format!("s{},{},{},{},{}", st.x, st.y, st.radius, st.soft, st.value);
        }
        for f in &self.features {
            s += &format!("f{},{},{},{},{},{}", f.x, f.y, f.u, f.v, f.inner, f.outer);
        }
        s
    }

    /// The controls as JSON (values in `[0, 1]`), for descriptions.
    pub fn to_json(&self) -> Value {
        let unit = |v: u32| (v as f64 / ONE_Q16 as f64 * 10_000.0).round() / 10_000.0;
        let mut o = Map::new();
        if let Some(n) = self.noise {
            o.insert("noise".into(), serde_json::json!({ "scale": n.scale, "range": [unit(n.lo), unit(n.hi)] }));
        }
        if !self.strokes.is_empty() {
            let list: Vec<Value> = self
                .strokes
                .iter()
                .map(|s| serde_json::json!({ "at": [s.x, s.y], "radius": s.radius, "soft": s.soft, "value": unit(s.value) }))
                .collect();
            o.insert("strokes".into(), Value::Array(list));
        }
        if !self.features.is_empty() {
            let list: Vec<Value> = self
                .features
                .iter()
                .map(|f| serde_json::json!({ "at": [f.x, f.y], "source": [f.u, f.v], "inner": f.inner, "outer": f.outer }))
                .collect();
            o.insert("features".into(), Value::Array(list));
        }
        Value::Object(o)
    }

    /// Check against a periodic output of `period` texels: the noise lattice must tile it.
    pub fn check_period(&self, period: Option<i64>) -> Result<()> {
        match (self.noise, period) {
            (Some(n), Some(p)) if n.scale > p => {
                Err(err(format!("noise.scale {} is larger than the period {p}", n.scale)))
            }
            _ => Ok(()),
        }
    }

    /// `R_S` at native position `(x, y)` (fixed point, `[0, 65536]`); with a `period`, the
    /// field repeats with it (noise lattice and strokes wrap).
    pub fn at(&self, x: i64, y: i64, period: Option<i64>) -> i64 {
        let one = ONE_Q16 as i64;
        let mut r = match self.noise {
            None => one,
            Some(n) => {
                let s = n.scale;
                let (i, j) = (x.div_euclid(s), y.div_euclid(s));
                let (fx, fy) = (x - i * s, y - j * s);
                let cells = period.map(|p| p / s);
                let lattice = |a: i64, b: i64| {
                    let (a, b) = match cells {
                        Some(c) => (a.rem_euclid(c), b.rem_euclid(c)),
                        None => (a, b),
                    };
                    (hash(TAG_NOISE, 0, 0, a, b) >> 48) as i64
                };
                let top = lattice(i, j) * (s - fx) + lattice(i + 1, j) * fx;
                let bottom = lattice(i, j + 1) * (s - fx) + lattice(i + 1, j + 1) * fx;
                let v = (top * (s - fy) + bottom * fy) / (s * s); // [0, 65535]
                n.lo as i64 + (n.hi as i64 - n.lo as i64) * v / 65535
            }
        };
        for st in &self.strokes {
            let d = |a: i64, b: i64| match period {
                Some(p) => {
                    let d = (a - b).rem_euclid(p);
                    d.min(p - d)
                }
                None => (a - b).abs(),
            };
            let (dx, dy) = (d(x, st.x), d(y, st.y));
            if dx >= st.radius + st.soft || dy >= st.radius + st.soft {
                continue;
            }
            let (dx, dy) = (dx as f64, dy as f64);
            let dist = (dx * dx + dy * dy).sqrt();
            let (inner, outer) = (st.radius as f64, (st.radius + st.soft) as f64);
            let w = if dist <= inner {
                1.0
            } else if dist >= outer {
                0.0
            } else {
                (outer - dist) / (outer - inner)
            };
            r += ((st.value as i64 - r) as f64 * w).round() as i64;
        }
        r
    }
}

impl crate::modes::declared::Canonical for Controls {
    fn canonical(&self) -> String {
        Controls::canonical(self)
    }
}

impl crate::modes::declared::ParamValue for Controls {
    fn parse(_: &crate::modes::params::ParamSpec, s: &str) -> Result<Self> {
        Controls::parse(s)
    }
    fn json(&self, _: &crate::modes::params::ParamSpec, _: u32) -> Value {
        self.to_json()
    }
    fn text(&self, _: &crate::modes::params::ParamSpec) -> String {
        let json = serde_json::to_vec(&self.to_json()).unwrap_or_default();
        base64::engine::general_purpose::URL_SAFE_NO_PAD.encode(json)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn encode(json: &str) -> String {
        base64::engine::general_purpose::URL_SAFE_NO_PAD.encode(json)
    }

    #[test]
    fn controls_parse_canonically_and_refuse_what_is_wrong() {
        let a = Controls::parse(&encode(r#"{"noise": {"scale": 64, "range": [0.2, 1]}, "strokes": [{"at": [-5, 7], "radius": 40, "soft": 8, "value": 0.5}], "features": [{"at": [1, 2], "source": [3, 4], "inner": 5, "outer": 9}]}"#)).unwrap();
        let b = Controls::parse(&encode(r#"{"strokes":[{"value":0.50,"at":[-5,7],"soft":8,"radius":40}],"features":[{"outer":9,"inner":5,"source":[3,4],"at":[1,2]}],"noise":{"range":[0.20,1.0],"scale":64}}"#)).unwrap();
        assert_eq!(a, b);
        assert_eq!(a.canonical(), b.canonical());
        assert_eq!(Controls::from_json(&a.to_json()).unwrap(), a);
        for bad in [
            "%%%".to_string(),
            encode("[1]"),
            encode(r#"{"nois": {}}"#),
            encode(r#"{"noise": {"scale": 48, "range": [0, 1]}}"#),
            encode(r#"{"noise": {"scale": 64, "range": [0.8, 0.2]}}"#),
            encode(r#"{"strokes": [{"at": [0, 0], "radius": 5, "value": 2}]}"#),
            encode(r#"{"features": [{"at": [0, 0], "source": [1, 1], "inner": 9, "outer": 4}]}"#),
            encode(&format!(r#"{{"strokes": [{}]}}"#, vec![r#"{"at":[0,0],"radius":1,"value":0}"#; 65].join(","))),
            "A".repeat(MAX_CONTROLS_LEN + 1),
        ] {
            let e = Controls::parse(&bad).unwrap_err().to_string();
            assert!(e.contains("controls"), "{bad}: {e}");
        }
    }

    #[test]
    fn the_field_is_the_strokes_value_inside_them_and_noise_within_its_range() {
        let c = Controls {
            noise: Some(Noise { scale: 16, lo: 13107, hi: 52429 }),
            strokes: vec![Stroke { x: 100, y: -40, radius: 10, soft: 10, value: 0 }],
            features: Vec::new(),
        };
        assert_eq!(c.at(105, -38, None), 0);
        for (x, y) in [(-1000, 3), (7, 7), (1 << 30, -(1 << 33))] {
            let v = c.at(x, y, None);
            assert!((13107..=52429).contains(&v), "{v}");
        }
        let half = c.at(115, -40, None);
        let outside = c.at(140, -40, None);
        assert!(half > 0 && half < outside, "{half} {outside}");
        // Periodic: the same field one period away.
        assert_eq!(c.at(100 + 256, -40 - 512, Some(256)), c.at(100, -40, Some(256)));
        assert_eq!(c.at(3 + 256, 9, Some(256)), c.at(3, 9, Some(256)));
    }
}
