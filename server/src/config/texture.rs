//! A texture's configuration: one `[[textures]]` entry — its exemplar, its flags, its defaults
//! and its per-mode tables (mode parameters, and settings of a mode's preparation) — with the
//! checks that name the key at fault.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};
use textile_core::analysis::IndexChoice;
use textile_core::error::clip;
use textile_core::lattice::LatticeChoice;
use textile_core::maps::NormalConvention;
use textile_core::MODE_NAMES;

pub use textile_core::recipe::Toroidal;

/// One served texture.
///
/// Besides the keys below, a texture may hold one table per mode (`[textures.synth]`,
/// `[textures.mosaic]`, …) of that mode's parameters: request parameters as the texture's
/// defaults (`randomness = "0.5"`) and texture settings (`kappa = 0.5`). The keys and their
/// ranges are the modes' own parameter specs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TextureConfig {
    /// URL id: 1–64 of `a-z 0-9 _ -`.
    pub id: String,
    /// Display name (default: the id).
    #[serde(default)]
    pub name: String,
    /// Exemplar path (relative to the config file) or `embedded:NAME`.
    #[serde(default)]
    pub exemplar: String,
    /// Instead of `exemplar`: a high-resolution image (path or `embedded:NAME`); the exemplar
    /// is its 2× reduction, and magnified zooms show the image's own detail.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub exemplar_hires: Option<String>,
    /// Randomness mask over the exemplar (`R_E`): a greyscale image the size of the exemplar
    /// image (path or `embedded:NAME`), white where synthesis moves content freely, black
    /// where it keeps the exemplar as it is.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub randomness_mask: Option<String>,
    /// Near-regular texture: `"auto"` (detected from the exemplar, the default), `"none"`,
    /// `[nx, ny]` cells that tile a rectified exemplar (makes it toroidal), or explicit waves
    /// `[{ period = P, angle = A }, …]`; the output keeps the lattice while the cells vary.
    #[serde(default)]
    pub lattice: LatticeChoice,
    /// Toroidal flag.
    #[serde(default = "default_toroidal")]
    pub toroidal: Toroidal,
    /// Candidate search of the analysis: `auto` (coherent from 256² up), `exact`, `coherent`
    /// (the key `index`).
    #[serde(default, rename = "index")]
    pub candidate_search: IndexChoice,
    /// Mode used when a request names none.
    #[serde(default = "default_mode")]
    pub default_mode: String,
    /// Seed used when a request names none (every mode).
    #[serde(default)]
    pub default_seed: u64,
    /// Attribution shown in TileJSON.
    #[serde(default)]
    pub attribution: String,
    /// Metres per unit of height (0–1) in its raster-dem tiles (`map=height&encoding=…`);
    /// unset: a relief of a few texels at its native zoom.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height_scale: Option<f64>,
    /// Co-registered material maps (`[textures.maps]`): map name → image (path or
    /// `embedded:NAME`, the size of the exemplar image), plus `normal_convention = "opengl" |
    /// "directx"` when there is a `normal` map.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub maps: BTreeMap<String, String>,
    /// Per-mode tables, and any other key (refused by validation, naming it).
    #[serde(flatten)]
    pub modes: BTreeMap<String, toml::Value>,
    /// Added through the admin API (kept in the data directory), not configured.
    #[serde(skip)]
    pub uploaded: bool,
}

impl TextureConfig {
    /// How its exemplar is made ([`textile_core::recipe::Recipe`]), images up to
    /// `max_input_side` pixels a side.
    pub fn recipe(&self, max_input_side: u32) -> textile_core::recipe::Recipe {
        textile_core::recipe::Recipe {
            max_input_side,
            toroidal: self.toroidal,
            hires: self.exemplar_hires.is_some(),
            lattice: self.lattice.clone(),
            normal_convention: self.normal_convention(),
        }
    }

    /// The image file the texture is made from: `exemplar_hires` when given, else `exemplar`.
    pub fn image(&self) -> &str {
        self.exemplar_hires.as_deref().unwrap_or(&self.exemplar)
    }

    /// A texture of this id and exemplar with every other key at its default.
    pub fn new(id: &str, exemplar: &str) -> Self {
        TextureConfig {
            id: id.into(),
            name: id.into(),
            exemplar: exemplar.into(),
            exemplar_hires: None,
            randomness_mask: None,
            lattice: LatticeChoice::Auto,
            toroidal: Toroidal::Auto,
            candidate_search: IndexChoice::Auto,
            default_mode: default_mode(),
            default_seed: 0,
            attribution: String::new(),
            height_scale: None,
            maps: BTreeMap::new(),
            modes: BTreeMap::new(),
            uploaded: false,
        }
    }

    /// Check the id, the default mode and every per-mode setting against the modes' specs;
    /// on failure, the key (under `at`, e.g. `textures[2]`) and what is wrong with it.
    pub fn validate(&self, at: &str) -> Result<(), (String, String)> {
        let bad = |key: String, msg: String| Err((key, msg));
        if !valid_id(&self.id) {
            return bad(format!("{at}.id"), format!("'{}' must be 1-64 of a-z 0-9 _ -", clip(&self.id)));
        }
        let wraps = self.toroidal.with_lattice(&self.lattice);
        match (self.exemplar.is_empty(), &self.exemplar_hires) {
            (false, Some(_)) => {
                return bad(format!("{at}.exemplar_hires"), "replaces exemplar: give one of the two".into())
            }
            _ if self.randomness_mask.is_some() && self.toroidal == Toroidal::Synthesize => {
                return bad(
                    format!("{at}.toroidal"),
                    "\"synthesize\" remakes the exemplar, which randomness_mask could no longer follow".into(),
                )
            }
            _ if let Err(message) = wraps => return bad(format!("{at}.toroidal"), message.into()),
            (true, Some(_)) if self.toroidal == Toroidal::Synthesize => {
                return bad(
                    format!("{at}.toroidal"),
                    "\"synthesize\" would not match exemplar_hires's detail; use auto, true or false".into(),
                )
            }
            _ => {}
        }
        self.validate_maps(at)?;
        if !MODE_NAMES.contains(&self.default_mode.as_str()) {
            return bad(
                format!("{at}.default_mode"),
                format!("'{}' is not one of {}", clip(&self.default_mode), MODE_NAMES.join(", ")),
            );
        }
        for (key, value) in &self.modes {
            let at = format!("{at}.{}", clip(key));
            if let Some(moved) = textile_core::modes::params::moved_setting(key) {
                return bad(at, format!("is now written per mode: {moved}"));
            }
            let Some(info) = textile_core::modes::all().into_iter().find(|m| m.name == key) else {
                return bad(at, format!("unknown key; per-mode tables are {}", MODE_NAMES.join(", ")));
            };
            let Some(table) = value.as_table() else {
                return bad(at, format!("must be a table of mode={key}'s parameters ([textures.{key}])"));
            };
            for (k, v) in table {
                // A setting of the mode's preparation: a file name.
                if info.prepares_with(k) {
                    if !v.is_str() {
                        return bad(format!("{at}.{k}"), "must be a file name (a string)".into());
                    }
                    continue;
                }
                let Some(spec) = info.specs.iter().find(|s| s.name == k) else {
                    let known: Vec<&str> = info.specs.iter().map(|s| s.name).collect();
                    return bad(
                        format!("{at}.{}", clip(k)),
                        format!("mode={key} has no parameter '{}'; it has: {}", clip(k), known.join(", ")),
                    );
                };
                if let Err(e) = spec.check(&text(v)) {
                    return bad(format!("{at}.{k}"), e.to_string());
                }
            }
        }
        Ok(())
    }

    /// Check `[textures.maps]`: valid names, an image for each, and the normal convention with
    /// (and only with) a normal map.
    fn validate_maps(&self, at: &str) -> Result<(), (String, String)> {
        let at = format!("{at}.maps");
        if !self.maps.is_empty() && self.toroidal == Toroidal::Synthesize {
            return Err((
                at.clone(),
                "toroidal = \"synthesize\" remakes the exemplar, which its maps could no longer follow".into(),
            ));
        }
        for (name, value) in &self.maps {
            if name == NORMAL_CONVENTION {
                continue;
            }
            if let Err(e) = textile_core::maps::check_name(name) {
                return Err((format!("{at}.{}", clip(name)), e.to_string()));
            }
            if value.trim().is_empty() {
                return Err((format!("{at}.{name}"), "must name an image (a path or embedded:NAME)".into()));
            }
        }
        match (self.maps.contains_key("normal"), self.maps.get(NORMAL_CONVENTION)) {
            (true, None) => Err((
                format!("{at}.{NORMAL_CONVENTION}"),
                "is required with a normal map: \"opengl\" (+Y up, glTF's) or \"directx\" (+Y down)".into(),
            )),
            (false, Some(_)) => Err((format!("{at}.{NORMAL_CONVENTION}"), "is given without a normal map".into())),
            (_, Some(c)) if self.normal_convention().is_none() => {
                Err((format!("{at}.{NORMAL_CONVENTION}"), format!("'{}' is not \"opengl\" or \"directx\"", clip(c))))
            }
            _ => Ok(()),
        }
    }

    /// The material maps, `(name, image)`, in name order.
    pub fn map_images(&self) -> impl Iterator<Item = (&str, &str)> {
        self.maps.iter().filter(|(k, _)| *k != NORMAL_CONVENTION).map(|(k, v)| (k.as_str(), v.as_str()))
    }

    /// The normal map's convention, when given and valid.
    pub fn normal_convention(&self) -> Option<NormalConvention> {
        match self.maps.get(NORMAL_CONVENTION)?.as_str() {
            "opengl" => Some(NormalConvention::OpenGl),
            "directx" => Some(NormalConvention::DirectX),
            _ => None,
        }
    }

    /// The per-mode settings that name a file on the server (what a mode's preparation reads,
    /// e.g. a hand-made element set), as `MODE.KEY`. A configuration may; an upload may not.
    pub fn file_settings(&self) -> Vec<String> {
        let modes = textile_core::modes::all();
        self.mode_tables()
            .into_iter()
            .flat_map(|(mode, table)| table.into_iter().map(move |(k, _)| (mode.clone(), k)))
            .filter(|(mode, k)| modes.iter().any(|m| m.name == mode && m.prepares_with(k)))
            .map(|(mode, k)| format!("{mode}.{k}"))
            .collect()
    }

    /// Why an uploaded texture cannot be served as its record stands, if it cannot: a record
    /// stored before uploads were refused file settings names a file on the server.
    pub fn upload_refusal(&self) -> Option<String> {
        let named = self.file_settings();
        (self.uploaded && !named.is_empty()).then(|| {
            format!(
                "its stored upload names a file on the server in the setting {}, which uploads may no longer do: \
                 DELETE /admin/textures/{} and upload it again without that field",
                named.join(", "),
                self.id
            )
        })
    }

    /// The per-mode tables as `key = value` text pairs (lists joined with commas).
    pub fn mode_tables(&self) -> BTreeMap<String, Vec<(String, String)>> {
        self.modes
            .iter()
            .filter_map(|(m, v)| {
                v.as_table().map(|t| (m.clone(), t.iter().map(|(k, v)| (k.clone(), text(v))).collect()))
            })
            .collect()
    }
}

/// The key of `[textures.maps]` that says how its normal map encodes +Y.
pub const NORMAL_CONVENTION: &str = "normal_convention";

/// A configuration value as the text a query string would carry.
pub(crate) fn text(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => s.clone(),
        toml::Value::Array(a) => a.iter().map(text).collect::<Vec<_>>().join(","),
        other => other.to_string(),
    }
}

fn default_toroidal() -> Toroidal {
    Toroidal::Auto
}

fn default_mode() -> String {
    textile_core::modes::DEFAULT_MODE.into()
}

/// Texture ids: 1–64 characters of `a-z 0-9 _ -`.
pub fn valid_id(id: &str) -> bool {
    !id.is_empty()
        && id.len() <= 64
        && id.bytes().all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'_' || b == b'-')
}
