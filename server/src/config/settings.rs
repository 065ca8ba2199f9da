//! Every setting declared once. [`SERVICE`]: the service's keys — type, range, default,
//! whether the environment sets it (`TEXTILE_<KEY>`), its command-line flag if it has one, and
//! what it does — which drive the defaults under the built-in configuration, the environment
//! keys read, the flags of `textile serve` (and `--data-dir` of every command that reads the
//! configuration: `cmd::args::SettingFlags`), range validation and the comments of
//! `--print-config`. [`TEXTURE_FIELDS`]: the texture keys an upload may set, as
//! parameter specs, which drive upload field checks and the admin API's OpenAPI.

use serde_json::{json, Map, Value as Json};
use textile_core::modes::params::{Kind, ParamSpec, Scope};
use textile_core::MODE_NAMES;

/// A service setting's type, range and default.
#[derive(Debug, Clone, Copy)]
pub enum ValueKind {
    /// A whole number in `min..=max`; `zero` says what 0 means, when it means something.
    Int {
        /// Least value.
        min: u64,
        /// Largest value.
        max: u64,
        /// Default.
        default: u64,
        /// What 0 means, if it is special.
        zero: Option<&'static str>,
    },
    /// Text (checked by its own rule where it has one).
    Text {
        /// Default.
        default: &'static str,
    },
    /// A list of text.
    List {
        /// Default.
        default: &'static [&'static str],
    },
    /// A flag.
    Bool {
        /// Default.
        default: bool,
    },
}

/// One service setting.
#[derive(Debug, Clone, Copy)]
pub struct Setting {
    /// Key in the configuration file.
    pub key: &'static str,
    /// Type, range, default.
    pub kind: ValueKind,
    /// Whether `TEXTILE_<KEY>` sets it.
    pub env: bool,
    /// Its command-line flag, if it has one.
    pub flag: Option<Flag>,
    /// What it does.
    pub help: &'static str,
}

/// A setting's command-line flag.
#[derive(Debug, Clone, Copy)]
pub struct Flag {
    /// `--LONG`.
    pub long: &'static str,
    /// The value's name in `--help`.
    pub value: &'static str,
    /// Whether every command that reads the configuration takes it (else `textile serve` only).
    pub every_command: bool,
}

impl Setting {
    /// This setting with flag `--long VALUE` on `textile serve`.
    const fn flag(self, long: &'static str, value: &'static str) -> Setting {
        Setting { flag: Some(Flag { long, value, every_command: false }), ..self }
    }

    /// This setting with flag `--long VALUE` on every command that reads the configuration.
    const fn flag_everywhere(self, long: &'static str, value: &'static str) -> Setting {
        Setting { flag: Some(Flag { long, value, every_command: true }), ..self }
    }
}

const fn int(key: &'static str, min: u64, max: u64, default: u64, help: &'static str) -> Setting {
    Setting { key, kind: ValueKind::Int { min, max, default, zero: None }, env: true, flag: None, help }
}

const fn int0(key: &'static str, max: u64, default: u64, zero: &'static str, help: &'static str) -> Setting {
    Setting { key, kind: ValueKind::Int { min: 0, max, default, zero: Some(zero) }, env: true, flag: None, help }
}

const fn text(key: &'static str, default: &'static str, help: &'static str) -> Setting {
    Setting { key, kind: ValueKind::Text { default }, env: true, flag: None, help }
}

/// The service's settings, in the order `--print-config` shows them.
pub const SERVICE: &[Setting] = &[
    text("bind", "127.0.0.1:8080", "listen address (host:port; port 0: any free port)").flag("bind", "ADDR"),
    text("data_dir", "", "directory of analyses and uploads (empty: $XDG_DATA_HOME/textile)")
        .flag_everywhere("data-dir", "DIR"),
    int("cache_mib", 1, 65536, 256, "tile cache size in MiB").flag("cache-mib", "MIB"),
    int0("level_cache_mib", 65536, 128, "off", "pyramidal (synthesis level) cache size in MiB")
        .flag("level-cache-mib", "MIB"),
    text("cache_control", "public, max-age=31536000, immutable", "Cache-Control of tiles"),
    Setting {
        key: "cors_origins",
        kind: ValueKind::List { default: &["*"] },
        env: false,
        flag: None,
        help: "CORS origins (\"*\": any)",
    },
    int0("worker_threads", 1024, 0, "one per core", "synthesis threads").flag("workers", "N"),
    int("request_timeout_secs", 1, 3600, 30, "request timeout in seconds"),
    int("max_in_flight", 1, 100_000, 64, "syntheses in flight before shedding with 503").flag("max-in-flight", "N"),
    int("max_queue_wait_ms", 1, 600_000, 1000, "longest wait for a pool thread or memory before 503, in ms"),
    int("max_exemplar_side", 16, 8192, 1024, "largest exemplar side accepted, in pixels"),
    Setting {
        key: "include_default_textures",
        kind: ValueKind::Bool { default: false },
        env: false,
        flag: None,
        help: "keep the built-in textures beside a configuration file's own",
    },
    text("public_url", "", "the URL clients reach the service at, for absolute URLs (empty: from the request)"),
    Setting {
        key: "trusted_proxies",
        kind: ValueKind::List { default: &[] },
        env: false,
        flag: None,
        help: "addresses of reverse proxies whose forwarded headers are believed",
    },
    int("max_connections", 1, 1_000_000, 1024, "open connections at most; beyond, new ones wait"),
    int("header_read_timeout_secs", 1, 3600, 10, "seconds to send a request's headers; longest keep-alive idle time"),
    int0("shutdown_grace_secs", 3600, 10, "exit at once", "seconds in-flight requests get after SIGINT/SIGTERM"),
    text("archives_dir", "", "directory of exported archives served under /archives/ (empty: none)"),
    text("admin_token", "", "bearer token of the admin API, at least 16 characters (empty: admin API off)"),
    int("max_upload_mib", 1, 4096, 32, "largest upload body, in MiB"),
    int("max_concurrent_analyses", 1, 64, 1, "analyses of uploads run at once at most"),
    int0("analysis_threads", 1024, 0, "one fewer than the cores", "threads of the low-priority analysis pool"),
    int("analysis_timeout_secs", 1, 86_400, 600, "longest an analysis may take, in seconds"),
    int0("max_uploaded_textures", 100_000, 100, "uploads off", "uploaded textures kept at most"),
    int("memory_budget_mib", 64, 1 << 20, 1024, "MiB of working memory requests and analyses may reserve"),
    text("access_log", "", "access log file, appended to and reopened on SIGHUP (\"-\": stdout; empty: off)")
        .flag("access-log", "FILE|-"),
    text("access_log_format", "json", "access log lines: json (one object a line) or combined (Apache/nginx)"),
    int(
        "access_log_buffer",
        1,
        1_000_000,
        8192,
        "access log lines waiting for the writer; beyond, dropped and counted",
    ),
];

/// The setting `key`.
pub fn get(key: &str) -> Option<&'static Setting> {
    SERVICE.iter().find(|s| s.key == key)
}

/// The keys the environment sets (as `TEXTILE_<KEY>`).
pub fn env_keys() -> Vec<&'static str> {
    SERVICE.iter().filter(|s| s.env).map(|s| s.key).collect()
}

/// Every setting's default, as the layer under the built-in configuration.
pub fn defaults() -> Map<String, Json> {
    SERVICE
        .iter()
        .map(|s| {
            let v = match s.kind {
                ValueKind::Int { default, .. } => json!(default),
                ValueKind::Text { default } => json!(default),
                ValueKind::List { default } => json!(default),
                ValueKind::Bool { default } => json!(default),
            };
            (s.key.to_string(), v)
        })
        .collect()
}

/// Check every whole-number setting of `values` (the configuration as JSON) against its range:
/// the first out of range as `(key, message)`.
pub fn check_ranges(values: &Json) -> Result<(), (&'static str, String)> {
    for s in SERVICE {
        let ValueKind::Int { min, max, zero, .. } = s.kind else { continue };
        let Some(v) = values.get(s.key).and_then(Json::as_u64) else { continue };
        if !(min..=max).contains(&v) {
            let zero = zero.map(|z| format!(" (0 = {z})")).unwrap_or_default();
            return Err((s.key, format!("{v} is outside {min}..={max}{zero}")));
        }
    }
    Ok(())
}

/// One comment line for `--print-config`: what the setting does, its range and default, and
/// its environment variable.
pub fn comment(s: &Setting) -> String {
    format!("# {}", describe(s))
}

/// What the setting does, its range and default, and its environment variable (its flag's
/// help, and [`comment`]).
pub fn describe(s: &Setting) -> String {
    let range = match s.kind {
        ValueKind::Int { min, max, default, zero } => {
            let zero = zero.map(|z| format!(", 0 = {z}")).unwrap_or_default();
            format!("{min}..={max}{zero}; default {default}")
        }
        ValueKind::Text { default } => format!("default {default:?}"),
        ValueKind::List { default } => format!("default {default:?}"),
        ValueKind::Bool { default } => format!("default {default}"),
    };
    let env = if s.env { format!("; env TEXTILE_{}", s.key.to_uppercase()) } else { String::new() };
    format!("{} ({range}{env})", s.help)
}

/// `id`: a texture's URL id.
pub const ID: ParamSpec = ParamSpec {
    name: "id",
    kind: Kind::Text { max_len: 64 },
    scope: Scope::Texture,
    help: "texture id, 1-64 of a-z 0-9 _ - (required)",
};
/// `name`: a display name.
pub const NAME: ParamSpec =
    ParamSpec { name: "name", kind: Kind::Text { max_len: 200 }, scope: Scope::Texture, help: "display name" };
/// `toroidal`: whether the exemplar wraps around.
pub const TOROIDAL: ParamSpec = ParamSpec {
    name: "toroidal",
    kind: Kind::Choice(&textile_core::recipe::TOROIDAL_VALUES),
    scope: Scope::Texture,
    help: "whether the exemplar wraps around (auto: detected; synthesize: replaced by a seamless one made from it)",
};
/// `index`: the analysis's candidate search.
pub const INDEX: ParamSpec = ParamSpec {
    name: "index",
    kind: Kind::Choice(&["auto", "exact", "coherent"]),
    scope: Scope::Texture,
    help: "candidate search of the analysis (auto: coherent from 256² up)",
};
/// `default_mode`: the mode of requests that name none.
pub const DEFAULT_MODE: ParamSpec = ParamSpec {
    name: "default_mode",
    kind: Kind::Choice(MODE_NAMES),
    scope: Scope::Texture,
    help: "mode of requests that name none",
};
/// `default_seed`: the seed of requests that name none.
pub const DEFAULT_SEED: ParamSpec = ParamSpec {
    name: "default_seed",
    kind: Kind::Integer { min: 0, max: u64::MAX },
    scope: Scope::Texture,
    help: "seed of requests that name none",
};
/// `lattice`: the lattice of a near-regular exemplar.
pub const LATTICE: ParamSpec = ParamSpec {
    name: "lattice",
    kind: Kind::Text { max_len: 100 },
    scope: Scope::Texture,
    help: "lattice of a near-regular exemplar: auto (detected, the default), none (no detection), NX,NY cells of a rectified exemplar, or PERIOD@ANGLE[,PERIOD@ANGLE] waves",
};
/// `attribution`: shown in TileJSON.
pub const ATTRIBUTION: ParamSpec = ParamSpec {
    name: "attribution",
    kind: Kind::Text { max_len: 1000 },
    scope: Scope::Texture,
    help: "attribution shown in TileJSON",
};

/// The texture keys an upload may set (besides `MODE.KEY` per-mode settings).
pub const TEXTURE_FIELDS: &[ParamSpec] = &[ID, NAME, TOROIDAL, INDEX, LATTICE, DEFAULT_MODE, DEFAULT_SEED, ATTRIBUTION];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_built_in_configuration_keeps_every_declared_default() {
        let built_in: toml::Value = toml::from_str(super::super::DEFAULT_CONFIG).unwrap();
        for (key, default) in defaults() {
            if let Some(v) = built_in.get(&key) {
                let v = serde_json::to_value(v).unwrap();
                assert_eq!(v, default, "config/textile.toml sets {key} to {v}, the table's default is {default}");
            }
        }
    }

    #[test]
    fn every_field_of_the_configuration_is_declared() {
        let cfg = super::super::Config::load(None, &Default::default()).unwrap();
        let json = serde_json::to_value(&cfg).unwrap();
        for key in json.as_object().unwrap().keys().filter(|k| *k != "textures" && *k != "landscapes") {
            assert!(get(key).is_some(), "{key} is not in settings::SERVICE");
        }
        assert_eq!(json.as_object().unwrap().len() - 2, SERVICE.len());
    }
}
