//! Validated synthesis parameters (design note §1.9–1.10). Everything is parsed once into
//! canonical fixed point, so "0.5" and "0.50" are the same request, and the engine trusts it.

use crate::analysis::FIRST_CORRECTED_LEVEL;
use crate::error::{CoreError, Result};
use serde_json::{json, Value};

use crate::modes::declared::{unit_text, unit_value, Canonical, ParamValue};
use crate::modes::params::{check_period, parse_unit, Kind, ParamSpec, ONE_Q16};

use super::controls::Controls;

/// Largest number of correction passes accepted.
pub const MAX_PASSES: u32 = 4;

/// Per-level randomness: one value for every level, or an explicit list (coarse to fine).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Randomness {
    /// The default schedule (see [`default_randomness`]).
    Default,
    /// The same value at every level (fixed point, `[0, 65536]`).
    Uniform(u32),
    /// One value per level `0..=L` (fixed point).
    PerLevel(Vec<u32>),
}

/// The default schedule, coarse to fine: 1.0 at levels 0–1, 0.8 at 2, 0.6 at 3, then a
/// linear decrease to 0.1 at the finest level `L` — except at `L − 2` (when corrected), which
/// gets 0.15: at its stride `h = 4` that moves about one pixel in six by one texel, where the
/// linear schedule (0.35 for `L = 7`) moved most by one or two, more than correction repairs
/// (the texture's fine structure came out choppier: mean nn_err/nn_ref 1.32 → 1.20 together
/// with the extra pass of [`super::plan::Schedules`]); less (0.14) copied more once edge texels
/// became candidates (bench/README.md). Values in fixed point.
pub fn default_randomness(levels: u32) -> Vec<u32> {
    (0..=levels)
        .map(|l| {
            let r = match l {
                0 | 1 => 1.0,
                2 => 0.8,
                _ if l + 2 == levels && l >= FIRST_CORRECTED_LEVEL => 0.15,
                _ => {
                    let span = (levels as f64 - 3.0).max(1.0);
                    0.6 - 0.5 * (l as f64 - 3.0) / span
                }
            };
            (r * ONE_Q16 as f64).round() as u32
        })
        .collect()
}

impl Randomness {
    /// Parse `"0.5"` (every level), `"1,0.8,…"` (one value per level, coarse to fine) or
    /// `"default"` (the default schedule).
    pub fn parse(s: &str) -> Result<Randomness> {
        if s.trim() == "default" {
            return Ok(Randomness::Default);
        }
        let parts: Vec<&str> = s.split(',').collect();
        if parts.len() == 1 {
            return Ok(Randomness::Uniform(parse_unit("randomness", parts[0])?));
        }
        Ok(Randomness::PerLevel(parts.iter().map(|p| parse_unit("randomness", p)).collect::<Result<_>>()?))
    }

    /// The fixed-point value at every level `0..=levels`.
    pub fn resolve(&self, levels: u32) -> Vec<u32> {
        match self {
            Randomness::Default => default_randomness(levels),
            Randomness::Uniform(r) => vec![*r; levels as usize + 1],
            Randomness::PerLevel(v) => v.clone(),
        }
    }

    /// Canonical text form (fixed-point values), for cache keys and ETags.
    pub fn canonical(&self) -> String {
        match self {
            Randomness::Default => "default".into(),
            Randomness::Uniform(r) => r.to_string(),
            Randomness::PerLevel(v) => v.iter().map(|x| x.to_string()).collect::<Vec<_>>().join(","),
        }
    }
}

crate::declare_params! {
    /// Everything besides the analysis that determines synthesized pixels.
    pub struct SynthParams {
        /// Selects another, equally good texture.
        pub seed: u64 { default: 0, canonical: "seed=", seed }
        /// Per-level jitter strength.
        pub randomness: Randomness { default: Randomness::Default, canonical: ";r=",
            spec RANDOMNESS = "randomness", Kind::Levels, Request,
            "jitter strength per synthesis level: one value in [0, 1] for every level, or a comma list of one per level, coarse to fine" }
        /// Correction passes per corrected level; level `L − 2` gets one more (see
        /// [`super::plan::Schedules`]). 0 switches correction off.
        pub passes: u32 { default: 2, canonical: ";passes=",
            spec PASSES = "passes", Kind::Integer { min: 0, max: MAX_PASSES as u64 }, Texture,
            "correction passes per corrected level, one more at the third-finest (0 switches correction off)" }
        /// Subpasses per pass: 4 (parity classes, the paper's order) or 1 (all pixels at once).
        pub subpasses: u32 { default: 4, canonical: ";sub=",
            spec SUBPASSES = "subpasses", Kind::Integer { min: 1, max: 4 }, Texture,
            "subpasses per pass: 4 (parity classes, the paper's order) or 1 (all pixels at once)" }
        /// κ in fixed point (`[0, 65536]`): penalty on jumps to the second candidate.
        pub kappa: u32 { default: ONE_Q16, canonical: ";kappa=",
            spec KAPPA = "kappa", Kind::Unit, Texture,
            "κ, the penalty on jumps to a pixel's second candidate (default 1): higher keeps exemplar patches more coherent and the colour distribution closer to the exemplar's" }
        /// Optional period in texels (a power of two ≥ the exemplar's longer side): periodic output.
        pub period: Option<i64> { default: None, canonical: ";period=", period }
        /// Spatial modulation of randomness over the output (`R_S`), from the request; part of
        /// the canonical text only when given, so that every other request keeps its identity.
        pub controls: Controls { default: Controls::default(), canonical: (unless_default ";controls="),
            spec CONTROLS = "controls", Kind::Text { max_len: super::controls::MAX_CONTROLS_LEN as u64 }, Request,
            "spatial modulation of randomness over the output (R_S): base64url of JSON {\"noise\": {\"scale\": 64, \"range\": [0.2, 1]}, \"strokes\": [{\"at\": [x, y], \"radius\": 40, \"soft\": 8, \"value\": 0}], \"features\": [{\"at\": [x, y], \"source\": [u, v], \"inner\": 12, \"outer\": 40}]} (native texels; values in [0, 1]: 0 calm, 1 the full randomness; a feature shows the exemplar around its source within its inner radius; at most 64 strokes and 32 features)" }
    }
    check(p, src) { p.validate(src.dims()) }
}

impl Canonical for Randomness {
    fn canonical(&self) -> String {
        Randomness::canonical(self)
    }
}

impl ParamValue for Randomness {
    fn parse(_: &ParamSpec, s: &str) -> Result<Self> {
        Randomness::parse(s)
    }
    fn json(&self, _: &ParamSpec, levels: u32) -> Value {
        json!(self.resolve(levels).into_iter().map(unit_value).collect::<Vec<f64>>())
    }
    fn text(&self, _: &ParamSpec) -> String {
        match self {
            Randomness::Default => "default".into(),
            Randomness::Uniform(r) => unit_text(*r),
            Randomness::PerLevel(v) => v.iter().map(|r| unit_text(*r)).collect::<Vec<_>>().join(","),
        }
    }
}

impl SynthParams {
    /// Check the parameters for a `w × h` exemplar (list length, period, ranges).
    pub fn validate(&self, (w, h): (usize, usize)) -> Result<()> {
        let size = crate::geom::Size::of_dims((w, h));
        let (levels, side) = (size.levels(), size.longer());
        if let Randomness::PerLevel(v) = &self.randomness {
            if v.len() != levels as usize + 1 {
                return Err(CoreError::Param {
                    name: "randomness",
                    message: format!(
                        "a list needs exactly {} values (one per level, coarse to fine), got {}",
                        levels + 1,
                        v.len()
                    ),
                });
            }
        }
        let in_unit = |v: u32| v <= ONE_Q16;
        if !self.randomness.resolve(levels).into_iter().all(in_unit) {
            return Err(CoreError::Param { name: "randomness", message: "values must be in [0, 1]".into() });
        }
        if self.passes > MAX_PASSES {
            return Err(CoreError::Param { name: "passes", message: format!("must be 0 to {MAX_PASSES}") });
        }
        if self.subpasses != 1 && self.subpasses != 4 {
            return Err(CoreError::Param { name: "subpasses", message: "must be 1 or 4".into() });
        }
        if !in_unit(self.kappa) {
            return Err(CoreError::Param { name: "kappa", message: "must be in [0, 1]".into() });
        }
        check_period(self.period, side)?;
        self.controls.check_period(self.period)?;
        self.controls.check_size(w as u32, h as u32)?;
        Ok(())
    }

    /// Candidate weights `φ_1 = 2^16`, `φ_2 = (1+κ)²·2^16`, in integer arithmetic.
    pub(crate) fn phi(&self) -> [u64; 2] {
        let one = ONE_Q16 as u64;
        let k = one + self.kappa as u64;
        [one, (k * k + one / 2) >> 16]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn randomness_parsing_is_canonical() {
        assert_eq!(Randomness::parse("0.5").unwrap(), Randomness::parse("0.50").unwrap());
        assert!(Randomness::parse("1.5").is_err());
        assert!(Randomness::parse("NaN").is_err());
        assert!(Randomness::parse("x").is_err());
        assert_eq!(Randomness::parse("0,1").unwrap(), Randomness::PerLevel(vec![0, 65536]));
    }

    #[test]
    fn default_schedule_shape() {
        let r = default_randomness(7);
        assert_eq!(r.len(), 8);
        assert_eq!(r[0], 65536);
        assert_eq!(r[7], (0.1f64 * 65536.0).round() as u32);
        assert_eq!(r[5], (0.15f64 * 65536.0).round() as u32);
        assert_eq!(default_randomness(5)[3], (0.6f64 * 65536.0).round() as u32, "uncorrected L − 2 keeps its jitter");
    }
}
