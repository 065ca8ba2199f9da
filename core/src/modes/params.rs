//! Parameters, written once: each mode declares its keys as [`ParamSpec`]s (name, type, range,
//! help, scope), and one [`ParamReader`] reads a request's query, a texture's configuration
//! table or the command line's `--param` pairs. The server, the CLI, the OpenAPI document and
//! the viewer describe parameters from the specs; nothing lists them by hand.
//!
//! Reading is the mini-redis `Parse` shape: the caller takes the keys it knows (the server its
//! own, such as `v` or a window's `x`), the common keys ([`COMMON`]) and the mode's keys are
//! taken next, and [`ParamReader::finish`] rejects whatever nobody consumed, naming the mode
//! that would have accepted it.

use std::collections::{BTreeMap, BTreeSet};

use serde_json::{json, Value};

use crate::error::{clip, CoreError, Result};

/// Tile side in pixels: `world` is counted in tiles of this size at the native zoom.
pub const TILE_SIZE: i64 = 256;
/// Largest `world` (tiles at the native zoom).
pub const MAX_WORLD: u64 = 1 << 31;
/// Largest period any mode accepts, in texels (2^40).
pub const MAX_PERIOD: i64 = 1 << 40;
/// Fixed-point one for values in `[0, 1]` (2^16).
pub const ONE_Q16: u32 = 1 << 16;

/// Where a parameter may be given.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scope {
    /// In a request (query string, `textile render --param`), and as a texture's configured
    /// default.
    Request,
    /// Only as a texture's setting (configuration, `textile render --param`): part of the
    /// texture, like its exemplar, not of a request.
    Texture,
}

/// The type and range of a parameter's value, as text.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Kind {
    /// One of these words.
    Choice(&'static [&'static str]),
    /// An integer in `min..=max`.
    Integer {
        /// Smallest value.
        min: u64,
        /// Largest value.
        max: u64,
    },
    /// A power of two in `min..=max`.
    PowerOfTwo {
        /// Smallest value.
        min: u64,
        /// Largest value.
        max: u64,
    },
    /// A number in `[0, 1]`.
    Unit,
    /// One number in `[0, 1]` for every synthesis level, or a comma list of one per level,
    /// coarse to fine.
    Levels,
    /// `LOW,HIGH`: two numbers with `min <= LOW <= HIGH <= max`.
    Interval {
        /// Smallest value.
        min: f64,
        /// Largest value.
        max: f64,
    },
    /// Structured text checked by its mode (e.g. synth's `controls`), at most `max_len`
    /// characters.
    Text {
        /// Longest value.
        max_len: u64,
    },
}

/// One parameter: its name as the API spells it, its type and range, where it may be given, and
/// a one-line help text.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParamSpec {
    /// Query key (and configuration key).
    pub name: &'static str,
    /// Type and range.
    pub kind: Kind,
    /// Where it may be given.
    pub scope: Scope,
    /// What it does.
    pub help: &'static str,
}

impl ParamSpec {
    /// A machine-readable description: `type`, range, `scope` and `description`.
    pub fn describe(&self) -> Value {
        let mut v = match self.kind {
            Kind::Choice(values) => json!({ "type": "choice", "values": values }),
            Kind::Integer { min, max } => json!({ "type": "integer", "min": min, "max": max }),
            Kind::PowerOfTwo { min, max } => json!({ "type": "power_of_two", "min": min, "max": max }),
            Kind::Unit => json!({ "type": "number", "min": 0.0, "max": 1.0 }),
            Kind::Levels => json!({ "type": "levels", "min": 0.0, "max": 1.0 }),
            Kind::Interval { min, max } => json!({ "type": "interval", "min": min, "max": max }),
            Kind::Text { max_len } => json!({ "type": "text", "max_length": max_len }),
        };
        v["scope"] = json!(match self.scope {
            Scope::Request => "request",
            Scope::Texture => "texture",
        });
        v["description"] = json!(self.help);
        v
    }

    /// Check a value's syntax and range (what can be checked without a texture: a per-level
    /// list's length is checked when it meets one).
    pub fn check(&self, s: &str) -> Result<()> {
        match self.kind {
            Kind::Choice(values) if values.contains(&s) => Ok(()),
            Kind::Choice(values) => Err(self.error(format!("'{}' is not one of {}", clip(s), values.join(", ")))),
            Kind::Integer { .. } | Kind::PowerOfTwo { .. } => self.integer(s).map(drop),
            Kind::Unit => self.unit(s).map(drop),
            Kind::Levels => s.split(',').try_for_each(|v| self.unit(v).map(drop)),
            Kind::Interval { .. } => self.interval_milli(s).map(drop),
            Kind::Text { max_len } if s.chars().count() as u64 <= max_len => Ok(()),
            Kind::Text { max_len } => {
                Err(self.error(format!("is {} characters; at most {max_len}", s.chars().count())))
            }
        }
    }

    /// The error for a value of this parameter.
    pub fn error(&self, message: impl Into<String>) -> CoreError {
        CoreError::Param { name: self.name, message: message.into() }
    }

    /// Parse an [`Kind::Integer`] or [`Kind::PowerOfTwo`] value.
    pub fn integer(&self, s: &str) -> Result<u64> {
        let (min, max, pow2) = match self.kind {
            Kind::Integer { min, max } => (min, max, false),
            Kind::PowerOfTwo { min, max } => (min, max, true),
            _ => return Err(self.error("is not an integer parameter")),
        };
        s.trim().parse::<u64>().ok().filter(|v| (min..=max).contains(v) && (!pow2 || v.is_power_of_two())).ok_or_else(
            || {
                let what = if pow2 { "a power of two" } else { "an integer" };
                self.error(format!("'{}' is not {what} in {min}..={max}", clip(s)))
            },
        )
    }

    /// Parse a [`Kind::Unit`] value to fixed point (`[0, 2^16]`).
    pub fn unit(&self, s: &str) -> Result<u32> {
        parse_unit(self.name, s)
    }

    /// Parse a [`Kind::Interval`] value to two numbers in thousandths.
    pub fn interval_milli(&self, s: &str) -> Result<(u32, u32)> {
        let Kind::Interval { min, max } = self.kind else {
            return Err(self.error("is not an interval parameter"));
        };
        let bad = || self.error(format!("'{}' must be LOW,HIGH with {min} <= LOW <= HIGH <= {max}", clip(s)));
        let (a, b) = s.split_once(',').ok_or_else(bad)?;
        let f = |v: &str| v.trim().parse::<f64>().ok().filter(|x| x.is_finite()).map(|x| (x * 1000.0).round());
        let (a, b) = (f(a).ok_or_else(bad)?, f(b).ok_or_else(bad)?);
        if a < (min * 1000.0).round() || b < a || b > (max * 1000.0).round() {
            return Err(bad());
        }
        Ok((a as u32, b as u32))
    }
}

/// Parse one value in `[0, 1]` to fixed point.
pub(crate) fn parse_unit(name: &'static str, s: &str) -> Result<u32> {
    let v: f64 = s.trim().parse().map_err(|_| CoreError::Param {
        name,
        message: format!("'{}' is not a number; expected a value in [0, 1]", clip(s)),
    })?;
    if !v.is_finite() || !(0.0..=1.0).contains(&v) {
        return Err(CoreError::Param { name, message: format!("{} is outside [0, 1]", clip(s)) });
    }
    Ok((v * ONE_Q16 as f64).round() as u32)
}

/// `mode`: which engine renders the texture (values filled in by [`super::MODE_NAMES`]).
pub const MODE: ParamSpec = ParamSpec {
    name: "mode",
    kind: Kind::Choice(super::MODE_NAMES),
    scope: Scope::Request,
    help: "the engine that renders the texture",
};
/// `seed`: selects another, equally good texture.
pub const SEED: ParamSpec = ParamSpec {
    name: "seed",
    kind: Kind::Integer { min: 0, max: u64::MAX },
    scope: Scope::Request,
    help: "selects another, equally good texture",
};
/// `world`: a period in native tiles.
pub const WORLD: ParamSpec = ParamSpec {
    name: "world",
    kind: Kind::PowerOfTwo { min: 1, max: MAX_WORLD },
    scope: Scope::Request,
    help: "period in tiles at the native zoom (power of two): the texture repeats exactly, for web maps that wrap the world",
};
/// The keys every mode accepts.
pub const COMMON: &[ParamSpec] = &[MODE, SEED, WORLD];

/// The common parameters of a request, read before the mode's own.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Common {
    /// `seed`, when given.
    pub seed: Option<u64>,
    /// `world` as a period in texels, when given.
    pub period: Option<i64>,
}

impl Common {
    /// Read `seed` and `world`; `side` is the exemplar's longer side (a period must be at least that).
    pub fn read(r: &mut ParamReader, side: u32) -> Result<Common> {
        let seed = r.get(&SEED).map(|s| SEED.integer(&s)).transpose()?;
        let period = match r.get(&WORLD) {
            Some(s) => {
                let w = WORLD.integer(&s)? as i64;
                let min = (side as u64).div_ceil(TILE_SIZE as u64).max(1) as i64;
                if w < min {
                    return Err(WORLD.error(format!(
                        "the period must be at least the exemplar side ({side} texels), so world >= {min}"
                    )));
                }
                Some(w * TILE_SIZE)
            }
            None => None,
        };
        Ok(Common { seed, period })
    }

    /// Apply to a mode's seed and period: a given seed replaces the default; the period is the
    /// request's (none unless given).
    pub fn apply(&self, seed: &mut u64, period: &mut Option<i64>) {
        if let Some(s) = self.seed {
            *seed = s;
        }
        *period = self.period;
    }
}

/// Check a period in texels: a power of two from the exemplar side to [`MAX_PERIOD`].
pub fn check_period(period: Option<i64>, side: u32) -> Result<()> {
    match period {
        Some(n) if n < side as i64 || n > MAX_PERIOD || n.count_ones() != 1 => Err(CoreError::Param {
            name: "period",
            message: format!("must be a power of two from {side} (the exemplar side) to 2^40 texels, got {n}"),
        }),
        _ => Ok(()),
    }
}

/// Key–value pairs being read: each key at most once, every key consumed by someone.
#[derive(Debug, Clone)]
pub struct ParamReader {
    values: BTreeMap<String, String>,
    asked: BTreeSet<String>,
    scope: Scope,
}

impl ParamReader {
    /// A reader of request parameters (texture settings are not taken from it).
    pub fn request<I, K, V>(pairs: I) -> Result<ParamReader>
    where
        I: IntoIterator<Item = (K, V)>,
        K: Into<String>,
        V: Into<String>,
    {
        Self::new(pairs, Scope::Request)
    }

    /// A reader of a texture's settings (configuration or command line): request parameters and
    /// texture settings alike.
    pub fn texture<I, K, V>(pairs: I) -> Result<ParamReader>
    where
        I: IntoIterator<Item = (K, V)>,
        K: Into<String>,
        V: Into<String>,
    {
        Self::new(pairs, Scope::Texture)
    }

    fn new<I, K, V>(pairs: I, scope: Scope) -> Result<ParamReader>
    where
        I: IntoIterator<Item = (K, V)>,
        K: Into<String>,
        V: Into<String>,
    {
        let mut values = BTreeMap::new();
        for (k, v) in pairs {
            let k = k.into();
            if values.contains_key(&k) {
                return Err(CoreError::ParamKey { key: clip(&k), message: "is given more than once".into() });
            }
            values.insert(k, v.into());
        }
        Ok(ParamReader { values, asked: BTreeSet::new(), scope })
    }

    /// Take a key the caller itself knows (e.g. the server's `v`).
    pub fn take(&mut self, key: &str) -> Option<String> {
        // The keys asked for only name the allowed ones when a value is left over; values only
        // go, so once none is left none ever will be, and the asking need not be kept (a request
        // without a query then reads its parameters without allocating).
        if self.values.is_empty() {
            return None;
        }
        self.asked.insert(key.to_string());
        self.values.remove(key)
    }

    /// Take a spec'd parameter; a texture setting is not taken from a request.
    pub fn get(&mut self, spec: &ParamSpec) -> Option<String> {
        if spec.scope == Scope::Texture && self.scope == Scope::Request {
            return None;
        }
        self.take(spec.name)
    }

    /// Is anything left?
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// Reject what nobody consumed. `mode` is the mode the parameters were read for; `specs`
    /// lists every mode with its parameters, to say where a stray key belongs.
    pub fn finish(self, mode: &str, specs: &[(&'static str, &'static [ParamSpec])]) -> Result<()> {
        let Some((key, _)) = self.values.into_iter().next() else {
            return Ok(());
        };
        let owners: Vec<(&str, &ParamSpec)> =
            specs.iter().flat_map(|(m, ss)| ss.iter().filter(|s| s.name == key).map(move |s| (*m, s))).collect();
        if owners.iter().any(|(_, s)| s.scope == Scope::Texture) && self.scope == Scope::Request {
            let m = owners[0].0;
            return Err(CoreError::ParamKey {
                key: key.clone(),
                message: format!(
                    "is a setting of the texture, not a request parameter (configure it as [textures.{m}] {key} = …)"
                ),
            });
        }
        if !owners.is_empty() {
            let modes: Vec<String> = owners.iter().map(|(m, _)| format!("mode={m}")).collect();
            return Err(CoreError::ParamKey {
                key,
                message: format!("belongs to {}, not to mode={mode}", modes.join(" and ")),
            });
        }
        let allowed: Vec<String> = self.asked.into_iter().collect();
        Err(CoreError::UnknownParam { key: clip(&key), allowed: allowed.join(", ") })
    }
}

/// Where a texture key of older configurations went, now that it belongs to one mode's table
/// (for the error that names it).
pub fn moved_setting(key: &str) -> Option<&'static str> {
    match key {
        "kappa" => Some("[textures.synth] kappa = …"),
        "default_randomness" => Some("[textures.synth] randomness = …"),
        "umbrellas" => Some("[textures.umbrella] set = …"),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integers_and_powers_of_two_are_checked() {
        assert_eq!(SEED.integer("18446744073709551615").unwrap(), u64::MAX);
        assert!(SEED.integer("-1").is_err());
        assert!(WORLD.integer("3").is_err());
        assert!(WORLD.integer("0").is_err());
        assert_eq!(WORLD.integer("4").unwrap(), 4);
    }

    #[test]
    fn the_reader_rejects_repeats_and_leftovers() {
        assert!(ParamReader::request([("a", "1"), ("a", "2")]).is_err());
        let mut r = ParamReader::request([("seed", "1"), ("bogus", "2")]).unwrap();
        assert_eq!(r.get(&SEED).as_deref(), Some("1"));
        let e = r.finish("synth", &[]).unwrap_err();
        assert!(matches!(e, CoreError::UnknownParam { ref key, ref allowed } if key == "bogus" && allowed == "seed"));
    }

    #[test]
    fn texture_settings_are_not_request_parameters() {
        const K: ParamSpec = ParamSpec { name: "k", kind: Kind::Unit, scope: Scope::Texture, help: "" };
        let mut r = ParamReader::request([("k", "0.5")]).unwrap();
        assert_eq!(r.get(&K), None);
        let e = r.finish("m", &[("m", &[K])]).unwrap_err().to_string();
        assert!(e.contains("[textures.m] k"), "{e}");
        let mut r = ParamReader::texture([("k", "0.5")]).unwrap();
        assert_eq!(r.get(&K).as_deref(), Some("0.5"));
    }
}
