//! Configuration: the typed settings of the service, loaded in layers — the built-in
//! `config/textile.toml` < `--config FILE` < `TEXTILE_*` environment < command-line flags —
//! and validated, with messages that name the key and the allowed values.

use std::path::{Path, PathBuf};

use figment::providers::{Env, Format, Serialized, Toml};
use figment::Figment;
use serde::{Deserialize, Serialize};

mod landscape;
pub mod settings;
mod texture;

pub use landscape::{parse_colour, BlendConfig, LandscapeConfig, LayerConfig, SplatConfig, SCALE_RANGE};
pub use texture::{valid_id, TextureConfig, Toroidal, NORMAL_CONVENTION};

/// The built-in layers: every setting's declared default, then `config/textile.toml`.
fn built_in() -> Figment {
    Figment::from(Serialized::defaults(settings::defaults())).merge(Toml::string(DEFAULT_CONFIG))
}

/// The default configuration, compiled in.
pub const DEFAULT_CONFIG: &str = include_str!("../../../config/textile.toml");

/// The whole service configuration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Config {
    /// Listen address.
    pub bind: String,
    /// Analysis directory (empty = platform default).
    pub data_dir: String,
    /// Tile cache size in MiB.
    pub cache_mib: u64,
    /// Pyramidal (synthesis level) cache size in MiB; 0 turns it off.
    pub level_cache_mib: u64,
    /// Cache-Control of tiles.
    pub cache_control: String,
    /// CORS origins (`*` = any).
    pub cors_origins: Vec<String>,
    /// Synthesis threads (0 = cores).
    pub worker_threads: usize,
    /// Request timeout in seconds.
    pub request_timeout_secs: u64,
    /// Syntheses in flight before shedding with 503.
    pub max_in_flight: usize,
    /// Longest wait for a pool thread before shedding with 503, in milliseconds.
    pub max_queue_wait_ms: u64,
    /// Largest exemplar side accepted.
    pub max_exemplar_side: u32,
    /// Keep the built-in textures beside a configuration file's own `[[textures]]` (which
    /// otherwise replace them); a texture of the same id replaces the built-in one.
    #[serde(default)]
    pub include_default_textures: bool,
    /// The URL clients reach the service at (e.g. behind a proxy), used for absolute URLs in
    /// documents (TileJSON `tiles`, catalog links, glTF extras, X3D textures); empty: from the
    /// request (its `Host`, or the forwarded headers of a trusted proxy).
    #[serde(default)]
    pub public_url: String,
    /// Addresses of reverse proxies whose `X-Forwarded-Proto`/`X-Forwarded-Host` (or
    /// `Forwarded`) headers are believed; from anyone else they are ignored.
    #[serde(default)]
    pub trusted_proxies: Vec<String>,
    /// Open connections at most; beyond, new connections wait to be accepted.
    #[serde(default)]
    pub max_connections: usize,
    /// Seconds a client has to send a request's headers; also the longest idle time of a
    /// keep-alive connection between requests.
    #[serde(default)]
    pub header_read_timeout_secs: u64,
    /// Seconds in-flight requests may take to finish after SIGINT/SIGTERM before the process
    /// exits anyway.
    #[serde(default)]
    pub shutdown_grace_secs: u64,
    /// A directory of exported archives served under `/archives/` (with range requests, for
    /// PMTiles readers); empty: none.
    #[serde(default)]
    pub archives_dir: String,
    /// Bearer token of the admin API (`POST /admin/textures`, `DELETE /admin/textures/{id}`);
    /// empty: the admin API is off (its routes answer 404). Best given by environment
    /// (`TEXTILE_ADMIN_TOKEN`) rather than in a file.
    #[serde(default)]
    pub admin_token: String,
    /// Largest upload body, in MiB.
    #[serde(default)]
    pub max_upload_mib: u64,
    /// Analyses of uploaded textures run at once at most; more wait their turn.
    #[serde(default)]
    pub max_concurrent_analyses: usize,
    /// Threads of the analysis pool, which runs every analysis (uploads, and those computed at
    /// start) at the lowest CPU priority, apart from the synthesis pool; 0 = one fewer than the
    /// cores (at least one), so a core is always left to serving.
    #[serde(default)]
    pub analysis_threads: usize,
    /// Longest an analysis may take, in seconds; beyond it the upload's status turns `failed`
    /// (a configured texture's stops the start-up) with a message saying so.
    #[serde(default)]
    pub analysis_timeout_secs: u64,
    /// Uploaded textures kept at most.
    #[serde(default)]
    pub max_uploaded_textures: usize,
    /// MiB of working memory that windows, glTF patches, sample batches, uploads and their
    /// analyses may hold at once (each reserves its estimated size before it starts and waits
    /// for room, at most `max_queue_wait_ms`, else 503); tiles are not counted: one per worker.
    #[serde(default)]
    pub memory_budget_mib: u64,
    /// Access log: a file appended to (reopened on SIGHUP), `-` for stdout, empty for none.
    #[serde(default)]
    pub access_log: String,
    /// Access log line format: `json` or `combined`.
    #[serde(default)]
    pub access_log_format: String,
    /// Lines the access log holds for its writer; beyond, lines are dropped (and counted), never
    /// waited for.
    #[serde(default)]
    pub access_log_buffer: usize,
    /// Served textures.
    pub textures: Vec<TextureConfig>,
    /// Served landscapes: configured textures composed into one ground.
    #[serde(default)]
    pub landscapes: Vec<LandscapeConfig>,
    /// Directory relative exemplar paths are resolved against (set by the loader).
    #[serde(skip)]
    pub base_dir: PathBuf,
}

/// Values the command line gives, by setting key (`cmd::flags`): they override every other
/// layer.
#[derive(Debug, Default, Clone, Serialize)]
#[serde(transparent)]
pub struct Overrides(pub serde_json::Map<String, serde_json::Value>);

/// A configuration problem, naming the key.
#[derive(Debug, thiserror::Error)]
#[error("invalid configuration: {0}")]
pub struct ConfigError(pub String);

impl Config {
    /// Load the layered configuration and validate it.
    pub fn load(file: Option<&Path>, overrides: &Overrides) -> Result<Config, ConfigError> {
        let mut fig = built_in();
        let mut base_dir = std::env::current_dir().unwrap_or_default();
        if let Some(path) = file {
            if !path.is_file() {
                return Err(ConfigError(format!("config file {} does not exist", path.display())));
            }
            std::fs::read_to_string(path).map_err(|e| ConfigError(format!("config file {}: {e}", path.display())))?;
            fig = fig.merge(Toml::file_exact(path));
            if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
                base_dir = dir.to_path_buf();
            }
        }
        fig = fig.merge(Env::prefixed("TEXTILE_").only(&settings::env_keys())).merge(Serialized::defaults(overrides));
        let mut cfg: Config = fig.extract().map_err(|e| {
            let msgs: Vec<String> = e
                .into_iter()
                .map(|e| {
                    let from = match e.metadata.as_ref() {
                        Some(m) => m.source.as_ref().map(|s| s.to_string()).unwrap_or_else(|| m.name.to_string()),
                        None => "the configuration".into(),
                    };
                    let from =
                        if from.contains("TOML source string") { "the built-in configuration".into() } else { from };
                    match e.path.is_empty() {
                        true => format!("{} (in {from})", e.kind),
                        false => format!("key '{}' (in {from}): {}", e.path.join("."), e.kind),
                    }
                })
                .collect();
            ConfigError(msgs.join("; "))
        })?;
        cfg.base_dir = base_dir;
        for t in &mut cfg.textures {
            if t.name.is_empty() {
                t.name = t.id.clone();
            }
        }
        for l in &mut cfg.landscapes {
            if l.name.is_empty() {
                l.name = l.id.clone();
            }
        }
        let builtin: Config =
            built_in().extract().map_err(|e| ConfigError(format!("the built-in configuration: {e}")))?;
        // The built-in landscapes stay where the textures they are made of do.
        if cfg.landscapes == builtin.landscapes {
            let ids: Vec<&str> = cfg.textures.iter().map(|t| t.id.as_str()).collect();
            let builtin_ids: Vec<&str> = builtin.textures.iter().map(|t| t.id.as_str()).collect();
            if !(cfg.include_default_textures || ids == builtin_ids) {
                cfg.landscapes.clear();
            }
        }
        if cfg.include_default_textures {
            let mine: Vec<String> = cfg.textures.iter().map(|t| t.id.clone()).collect();
            let mut all: Vec<TextureConfig> = builtin.textures.into_iter().filter(|t| !mine.contains(&t.id)).collect();
            all.append(&mut cfg.textures);
            cfg.textures = all;
        }
        cfg.validate()?;
        Ok(cfg)
    }

    fn validate(&self) -> Result<(), ConfigError> {
        let bad = |key: &str, msg: String| Err(ConfigError(format!("key '{key}': {msg}")));
        if self.bind.parse::<std::net::SocketAddr>().is_err() {
            return bad("bind", format!("'{}' is not an address like 127.0.0.1:8080", self.bind));
        }
        let values = serde_json::to_value(self).map_err(|e| ConfigError(e.to_string()))?;
        settings::check_ranges(&values).or_else(|(key, msg)| bad(key, msg))?;
        if axum::http::HeaderValue::from_str(&self.cache_control).is_err() {
            return bad("cache_control", "must be a valid header value".into());
        }
        if !self.public_url.is_empty() {
            let ok = url::Url::parse(&self.public_url)
                .is_ok_and(|u| matches!(u.scheme(), "http" | "https") && u.host().is_some() && u.query().is_none());
            if !ok {
                return bad(
                    "public_url",
                    format!("'{}' is not an http(s) URL like https://tiles.example.org", self.public_url),
                );
            }
        }
        if let Some(p) = self.trusted_proxies.iter().find(|p| p.parse::<std::net::IpAddr>().is_err()) {
            return bad("trusted_proxies", format!("'{p}' is not an IP address"));
        }
        if !matches!(self.access_log_format.as_str(), "json" | "combined") {
            return bad("access_log_format", format!("'{}' is not json or combined", self.access_log_format));
        }
        if !self.admin_token.is_empty() && self.admin_token.len() < 16 {
            return bad("admin_token", "must be at least 16 characters (or empty: admin API off)".into());
        }
        if axum::http::HeaderValue::from_str(&format!("Bearer {}", self.admin_token)).is_err() {
            return bad("admin_token", "must be printable ASCII".into());
        }
        if self.textures.is_empty() {
            return bad("textures", "at least one texture is needed".into());
        }
        let mut seen = std::collections::HashSet::new();
        for (i, t) in self.textures.iter().enumerate() {
            if t.exemplar.is_empty() && t.exemplar_hires.is_none() {
                return Err(ConfigError(format!("key 'textures[{i}].exemplar': is required (or exemplar_hires)")));
            }
            t.validate(&format!("textures[{i}]")).map_err(|(key, msg)| ConfigError(format!("key '{key}': {msg}")))?;
            if !seen.insert(&t.id) {
                return bad(&format!("textures[{i}].id"), format!("'{}' is used twice", t.id));
            }
        }
        let ids: Vec<&str> = self.textures.iter().map(|t| t.id.as_str()).collect();
        let landscape_ids: Vec<&str> = self.landscapes.iter().map(|l| l.id.as_str()).collect();
        for (i, l) in self.landscapes.iter().enumerate() {
            let at = format!("landscapes[{i}]");
            if !seen.insert(&l.id) {
                return bad(
                    &format!("{at}.id"),
                    format!("'{}' is used twice (texture and landscape ids are one space)", l.id),
                );
            }
            if let Some(j) = l.layers.iter().position(|y| landscape_ids.contains(&y.texture.as_str())) {
                return bad(
                    &format!("{at}.layers[{j}].texture"),
                    format!("landscape '{}': '{}' is a landscape; a layer is a texture", l.id, l.layers[j].texture),
                );
            }
            l.validate(&at, &ids).map_err(|(key, msg)| ConfigError(format!("key '{key}': {msg}")))?;
        }
        Ok(())
    }

    /// The configuration as `--print-config` prints it: TOML with each service setting preceded
    /// by what it does, its range and default and its environment variable; the admin token
    /// hidden.
    pub fn to_commented_toml(&self) -> Result<String, ConfigError> {
        let text = toml::to_string_pretty(&self.redacted()).map_err(|e| ConfigError(e.to_string()))?;
        let mut out = String::new();
        let mut top = true;
        for line in text.lines() {
            if line.starts_with('[') {
                top = false;
            }
            let key = line.split(" = ").next().unwrap_or("");
            if let Some(s) = settings::get(key).filter(|_| top) {
                out.push_str(&settings::comment(s));
                out.push('\n');
            }
            out.push_str(line);
            out.push('\n');
        }
        Ok(out)
    }

    /// The configuration as `--print-config` shows it: the admin token hidden.
    pub fn redacted(&self) -> Config {
        let mut c = self.clone();
        if !c.admin_token.is_empty() {
            c.admin_token = "(set)".into();
        }
        c
    }

    /// The analysis directory in effect.
    pub fn data_dir(&self) -> PathBuf {
        if !self.data_dir.is_empty() {
            return PathBuf::from(&self.data_dir);
        }
        if let Some(x) = std::env::var_os("XDG_DATA_HOME").filter(|x| !x.is_empty()) {
            return PathBuf::from(x).join("textile");
        }
        if let Some(h) = std::env::var_os("HOME").filter(|x| !x.is_empty()) {
            return PathBuf::from(h).join(".local/share/textile");
        }
        PathBuf::from("textile-data")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn built_in_config_is_valid() {
        let cfg = Config::load(None, &Overrides::default()).unwrap();
        assert_eq!(cfg.textures.len(), 5);
        assert_eq!(cfg.textures[4].map_images().count(), 3, "the flagstones material");
        assert_eq!(cfg.bind, "127.0.0.1:8080");
        assert_eq!(cfg.textures[3].lattice, textile_core::lattice::LatticeChoice::Cells(2, 4));
        assert_eq!(cfg.landscapes.len(), 1, "the meadow, of the built-in textures");
    }

    #[test]
    fn a_lattice_needs_a_wrapping_exemplar() {
        let mut t = TextureConfig::new("cork", "cork.png");
        t.lattice = textile_core::lattice::LatticeChoice::Cells(2, 4);
        assert!(t.validate("textures[0]").is_ok());
        t.toroidal = Toroidal::False;
        let (key, msg) = t.validate("textures[0]").unwrap_err();
        assert_eq!(key, "textures[0].toroidal");
        assert!(msg.contains("lattice"), "{msg}");
    }

    #[test]
    fn overrides_win() {
        let o = Overrides(
            [("bind".to_string(), serde_json::json!("127.0.0.1:0")), ("cache_mib".to_string(), serde_json::json!(5))]
                .into_iter()
                .collect(),
        );
        let cfg = Config::load(None, &o).unwrap();
        assert_eq!((cfg.bind.as_str(), cfg.cache_mib), ("127.0.0.1:0", 5));
    }

    #[test]
    fn ids_are_checked() {
        assert!(valid_id("gravel_2"));
        assert!(!valid_id("../etc"));
        assert!(!valid_id(""));
    }
}
