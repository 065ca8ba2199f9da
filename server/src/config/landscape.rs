//! `[[landscapes]]`: several configured textures composed into one endless ground — each layer
//! a texture with its mode, parameters and scale, a splat saying where each shows, and a blend
//! saying how they join. Checked here against the configured textures, with messages naming
//! the landscape and the field; made into a served landscape by `crate::landscapes`.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::texture::text;
use super::valid_id;

/// Smallest and largest layer `scale` (zoom steps the layer is magnified by).
pub const SCALE_RANGE: std::ops::RangeInclusive<i32> = -6..=6;

/// One landscape.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LandscapeConfig {
    /// Id, in the same space as the textures'.
    pub id: String,
    /// Display name (defaults to the id).
    #[serde(default)]
    pub name: String,
    /// The layers, in order (the first wins ties and takes weightless ground).
    pub layers: Vec<LayerConfig>,
    /// Where each layer shows.
    pub splat: SplatConfig,
    /// How layers join.
    #[serde(default)]
    pub blend: BlendConfig,
    /// Shown in the viewer and TileJSON.
    #[serde(default)]
    pub attribution: String,
    /// Metres per unit of height in its raster-dem tiles (unset: a relief of a few texels at
    /// its native zoom).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height_scale: Option<f64>,
    /// Added through the admin API and stored in the data directory (not a field of any file).
    #[serde(skip)]
    pub uploaded: bool,
}

/// One layer: a configured texture, rendered as its own tiles are.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LayerConfig {
    /// The texture's id.
    pub texture: String,
    /// Its mode (default: the texture's default mode).
    #[serde(default)]
    pub mode: Option<String>,
    /// Zoom steps its texels are magnified by in the landscape (a power of two: 1 doubles them),
    /// so that exemplars of different sizes meet at one texel size.
    #[serde(default)]
    pub scale: i32,
    /// The mode's request parameters for this layer (`seed` included).
    #[serde(default)]
    pub params: BTreeMap<String, toml::Value>,
    /// Its share of the ground (noise splat).
    #[serde(default)]
    pub share: Option<f64>,
    /// Its colour in a painted splat with a palette, `#rrggbb`; also its colour in the overlay.
    #[serde(default)]
    pub colour: Option<String>,
}

impl LayerConfig {
    /// The layer's request parameters as query-string text (mode first when given).
    pub fn query(&self) -> Vec<(String, String)> {
        let mode = self.mode.iter().map(|m| ("mode".to_string(), m.clone()));
        mode.chain(self.params.iter().map(|(k, v)| (k.clone(), text(v)))).collect()
    }
}

/// Where each layer shows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum SplatConfig {
    /// Regions of fractal noise, each layer its `share` of the ground.
    Noise {
        /// Seed of the noise (a request's `seed` replaces it).
        #[serde(default)]
        seed: u64,
        /// Size of the noise's largest features, in texels.
        #[serde(default = "default_feature")]
        feature: f64,
        /// Octaves of detail.
        #[serde(default = "default_octaves")]
        octaves: u32,
        /// Fraction of the ground in transitions between layers (0–0.5).
        #[serde(default = "default_transition")]
        transition: f64,
    },
    /// A painted map.
    Image {
        /// The PNG (a path relative to the configuration, or `embedded:NAME`).
        image: String,
        /// `palette` (each layer its `colour`) or `rgba` (up to four layers, the channels' weights).
        #[serde(default = "default_key")]
        key: String,
        /// Texels one map pixel covers.
        #[serde(default = "default_tpp")]
        texels_per_pixel: f64,
        /// Texel of the map's top-left corner.
        #[serde(default)]
        origin: [f64; 2],
        /// Outside the map: `repeat`, or the texture id of the layer shown.
        #[serde(default = "default_outside")]
        outside: String,
        /// Amplitude, in texels, of the noise that wobbles its pixel boundaries.
        #[serde(default)]
        warp: f64,
        /// Seed of the warp (a request's `seed` replaces it).
        #[serde(default)]
        seed: u64,
    },
}

/// How layers join.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlendConfig {
    /// `height` (the taller material wins) or `linear`.
    #[serde(default = "default_blend")]
    pub kind: String,
    /// Height blend: the width of the band where layers mix (0–1).
    #[serde(default = "default_depth")]
    pub depth: f64,
}

impl Default for BlendConfig {
    fn default() -> Self {
        BlendConfig { kind: default_blend(), depth: default_depth() }
    }
}

fn default_feature() -> f64 {
    256.0
}
fn default_octaves() -> u32 {
    4
}
fn default_transition() -> f64 {
    0.1
}
fn default_key() -> String {
    "palette".into()
}
fn default_tpp() -> f64 {
    1.0
}
fn default_outside() -> String {
    "repeat".into()
}
fn default_blend() -> String {
    "height".into()
}
fn default_depth() -> f64 {
    0.2
}

/// `#rrggbb` as bytes.
pub fn parse_colour(s: &str) -> Option<[u8; 3]> {
    let hex = s.strip_prefix('#').filter(|h| h.len() == 6 && h.is_ascii())?;
    let c = |i: usize| u8::from_str_radix(&hex[i..i + 2], 16).ok();
    Some([c(0)?, c(2)?, c(4)?])
}

impl LandscapeConfig {
    /// Check it against the configured texture ids; errors name the key (`at` is its place,
    /// e.g. `landscapes[0]`) and say what is allowed.
    pub fn validate(&self, at: &str, textures: &[&str]) -> Result<(), (String, String)> {
        let key = |k: &str| format!("{at}.{k}");
        let lid = &self.id;
        if !valid_id(lid) {
            return Err((key("id"), format!("'{lid}' must be 1-64 characters of a-z 0-9 _ -")));
        }
        let n = self.layers.len();
        if !(2..=textile_core::landscape::MAX_LAYERS).contains(&n) {
            return Err((
                key("layers"),
                format!("landscape '{lid}' has {n} layers; 2 to {} are allowed", textile_core::landscape::MAX_LAYERS),
            ));
        }
        for (i, l) in self.layers.iter().enumerate() {
            let lk = |k: &str| key(&format!("layers[{i}].{k}"));
            if l.texture == *lid {
                return Err((lk("texture"), format!("landscape '{lid}' cannot be a layer of itself")));
            }
            if !textures.contains(&l.texture.as_str()) {
                return Err((
                    lk("texture"),
                    format!(
                        "landscape '{lid}': '{}' is not a configured texture (have: {})",
                        l.texture,
                        textures.join(", ")
                    ),
                ));
            }
            if !SCALE_RANGE.contains(&l.scale) {
                return Err((
                    lk("scale"),
                    format!(
                        "landscape '{lid}': {} is outside [{}, {}] (zoom steps)",
                        l.scale,
                        SCALE_RANGE.start(),
                        SCALE_RANGE.end()
                    ),
                ));
            }
            if let Some(c) = l.colour.as_deref().filter(|c| parse_colour(c).is_none()) {
                return Err((lk("colour"), format!("landscape '{lid}': '{c}' is not a colour like #5a8f3c")));
            }
            if let Some(k) = l.params.keys().find(|k| k.as_str() == "mode") {
                return Err((lk("params"), format!("landscape '{lid}': '{k}' is the layer's own field `mode`")));
            }
        }
        match &self.splat {
            SplatConfig::Noise { .. } => {
                if let Some(i) = self.layers.iter().position(|l| l.share.is_none()) {
                    return Err((
                        key(&format!("layers[{i}].share")),
                        format!("landscape '{lid}': a noise splat needs every layer's share of the ground"),
                    ));
                }
            }
            SplatConfig::Image { key: k, outside, .. } => {
                match k.as_str() {
                    "palette" => {
                        if let Some(i) = self.layers.iter().position(|l| l.colour.is_none()) {
                            return Err((
                                key(&format!("layers[{i}].colour")),
                                format!("landscape '{lid}': a palette splat needs every layer's colour"),
                            ));
                        }
                    }
                    "rgba" if n > 4 => {
                        return Err((
                            key("splat.key"),
                            format!("landscape '{lid}': rgba carries at most 4 layers, not {n}"),
                        ))
                    }
                    "rgba" => {}
                    other => {
                        return Err((key("splat.key"), format!("landscape '{lid}': '{other}' is not palette or rgba")))
                    }
                }
                if outside != "repeat" && !self.layers.iter().any(|l| l.texture == *outside) {
                    return Err((
                        key("splat.outside"),
                        format!("landscape '{lid}': '{outside}' is neither \"repeat\" nor one of its layers' textures"),
                    ));
                }
            }
        }
        match self.blend.kind.as_str() {
            "height" | "linear" => {}
            other => return Err((key("blend.kind"), format!("landscape '{lid}': '{other}' is not height or linear"))),
        }
        if !(0.0..=1.0).contains(&self.blend.depth) {
            return Err((key("blend.depth"), format!("landscape '{lid}': {} is outside [0, 1]", self.blend.depth)));
        }
        Ok(())
    }
}
