//! What a texture prepares once and keeps: the exemplar analysis every synthesizing mode needs,
//! and whatever a mode prepares for itself (the umbrella mode's element extraction). Each is a
//! [`Preparation`]: made from an [`Input`] (the exemplar and the texture's settings), stored in
//! the data directory beside the texture (`<texture>.<extension>`: versioned, checksummed,
//! written whole or not at all), loaded back when its id still matches, and described for the
//! API, the CLI and the logs. [`load_or_compute`] is the one path that drives every one of them.
//! Nothing here knows a mode: what each mode prepares, typed, is `modes::prepared`.

use std::any::Any;
use std::path::Path;
use std::sync::Arc;

use serde_json::{Map, Value};

use crate::cancel::Cancel;
use crate::error::{AnalysisFileProblem, CoreError, Result};
use crate::exemplar::Exemplar;
use crate::files::write_atomic;
use crate::progress::Progress;

/// A texture setting a preparation reads (in the texture's table of its mode): its key and what
/// it does.
#[derive(Debug, Clone, Copy)]
pub struct PreparationSetting {
    /// Key.
    pub name: &'static str,
    /// What it does.
    pub help: &'static str,
}

/// What a texture gives a preparation.
pub struct Input<'a> {
    /// The prepared exemplar.
    pub exemplar: &'a Exemplar,
    /// The texture's values of the preparation's [`Preparation::SETTINGS`].
    pub settings: &'a [(String, String)],
    /// Reads a file a setting names (relative to the configuration that names it).
    pub read: &'a (dyn Fn(&str) -> Result<Vec<u8>> + Sync),
}

impl<'a> Input<'a> {
    /// The input of an exemplar alone: every setting at its default, no files.
    pub fn exemplar(exemplar: &'a Exemplar) -> Input<'a> {
        fn no_files(name: &str) -> Result<Vec<u8>> {
            Err(CoreError::Param { name: "file", message: format!("cannot read '{name}' here") })
        }
        Input { exemplar, settings: &[], read: &no_files }
    }

    /// The value of setting `name`, if the texture gives one.
    pub fn setting(&self, name: &str) -> Option<&str> {
        self.settings.iter().find(|(k, _)| k == name).map(|(_, v)| v.as_str())
    }
}

/// Something a texture prepares once: how it is made, stored, read back and described.
pub trait Preparation: Sized + Send + Sync + 'static {
    /// What it is, for logs and descriptions ("analysis", "umbrella extraction").
    const WHAT: &'static str;
    /// The extension of its file in the data directory (`<texture>.<EXTENSION>`).
    const EXTENSION: &'static str;
    /// The texture settings it reads.
    const SETTINGS: &'static [PreparationSetting] = &[];

    /// A state the texture's settings give outright (nothing computed or stored), if they do.
    fn given(_input: &Input) -> Result<Option<Self>> {
        Ok(None)
    }
    /// The id a stored state must have to be this input's: a hash of everything it depends on,
    /// its algorithm version included.
    fn id(input: &Input) -> String;
    /// Compute it, asking `cancel` between steps and telling `progress`.
    fn compute(input: &Input, progress: &dyn Progress, cancel: &Cancel) -> Result<Self>;
    /// Its file's bytes.
    fn to_bytes(&self) -> Vec<u8>;
    /// Read a file's bytes, every way they can be wrong a typed problem.
    fn from_bytes(bytes: &[u8]) -> std::result::Result<Self, AnalysisFileProblem>;
    /// The id it was made for.
    fn stored_id(&self) -> &str;
    /// A description: what `/textures/{id}` and `textile info` show.
    fn describe(&self) -> Map<String, Value>;
    /// One line for logs.
    fn summary(&self) -> String;
    /// What of it is part of the ETags of the modes that use it beyond the exemplar's hash
    /// (empty when the exemplar determines it).
    fn etag(&self) -> String {
        String::new()
    }
    /// Bytes it holds in memory now, its caches included.
    fn memory_bytes(&self) -> u64;
    /// Bound the caches it keeps while serving to `bytes` (ignored by those that keep none).
    fn limit_caches(&self, _bytes: u64) {}
}

/// Where a prepared state came from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Origin {
    /// Given by the texture's settings: nothing computed, nothing stored.
    Given,
    /// Read from its file.
    Loaded,
    /// Computed (`why`: no file, a stale or a damaged one) and written to its file.
    Stored {
        /// Why it was computed.
        why: String,
    },
    /// Computed and not written (`not_stored`: why not, when a write was asked for and failed).
    Computed {
        /// Why it was computed.
        why: String,
        /// Why it was not written, when writing was asked for.
        not_stored: Option<String>,
    },
}

/// Read a stored state from `path`, problems named with the path.
pub fn load<P: Preparation>(path: &Path) -> Result<P> {
    let bytes = std::fs::read(path).map_err(|source| CoreError::Io { path: path.to_path_buf(), source })?;
    P::from_bytes(&bytes).map_err(|problem| CoreError::AnalysisFile { path: path.to_path_buf(), problem })
}

/// The one path of every preparation: the state the settings give, else the one stored at
/// `path` when its id is current, else computed — and, if `store` (and `keep()` still says so
/// once it is computed), written to `path` whole or not at all. A missing, stale or damaged file
/// is replaced. `store = false` with `path = None` neither reads nor writes.
pub fn load_or_compute<P: Preparation>(
    input: &Input,
    path: Option<&Path>,
    store: bool,
    keep: &dyn Fn() -> bool,
    progress: &dyn Progress,
    cancel: &Cancel,
) -> Result<(P, Origin)> {
    if let Some(state) = P::given(input)? {
        return Ok((state, Origin::Given));
    }
    let id = P::id(input);
    let why = match path.map(load::<P>) {
        None => "not stored".to_string(),
        Some(Ok(state)) if state.stored_id() == id => return Ok((state, Origin::Loaded)),
        Some(Ok(_)) => format!("stored {} is stale (exemplar or version changed)", P::WHAT),
        Some(Err(CoreError::Io { .. })) => format!("no stored {}", P::WHAT),
        Some(Err(e)) => e.to_string(),
    };
    let state = P::compute(input, progress, cancel)?;
    let origin = match path {
        Some(path) if store && keep() => match write_atomic(path, &state.to_bytes()) {
            Ok(()) => Origin::Stored { why },
            Err(e) => Origin::Computed { why, not_stored: Some(e.to_string()) },
        },
        _ => Origin::Computed { why, not_stored: None },
    };
    Ok((state, origin))
}

/// A prepared state without its type: what lists of them hold.
pub trait State: Any + Send + Sync {
    /// See [`Preparation::WHAT`].
    fn what(&self) -> &'static str;
    /// See [`Preparation::stored_id`].
    fn id(&self) -> String;
    /// See [`Preparation::describe`].
    fn describe(&self) -> Map<String, Value>;
    /// See [`Preparation::summary`].
    fn summary(&self) -> String;
    /// See [`Preparation::etag`].
    fn etag(&self) -> String;
    /// See [`Preparation::memory_bytes`].
    fn memory_bytes(&self) -> u64;
    /// See [`Preparation::limit_caches`].
    fn limit_caches(&self, bytes: u64);
    /// For downcasting to the preparation's type.
    fn into_any(self: Arc<Self>) -> Arc<dyn Any + Send + Sync>;
}

impl<P: Preparation> State for P {
    fn what(&self) -> &'static str {
        P::WHAT
    }
    fn id(&self) -> String {
        self.stored_id().to_string()
    }
    fn describe(&self) -> Map<String, Value> {
        Preparation::describe(self)
    }
    fn summary(&self) -> String {
        Preparation::summary(self)
    }
    fn etag(&self) -> String {
        Preparation::etag(self)
    }
    fn memory_bytes(&self) -> u64 {
        Preparation::memory_bytes(self)
    }
    fn limit_caches(&self, bytes: u64) {
        Preparation::limit_caches(self, bytes)
    }
    fn into_any(self: Arc<Self>) -> Arc<dyn Any + Send + Sync> {
        self
    }
}

/// A versioned, checksummed envelope for a preparation's file: `magic`, a little-endian format
/// `version`, the `body`, and a BLAKE3 checksum of everything before it.
pub fn envelope(magic: &[u8; 8], version: u32, body: &[u8]) -> Vec<u8> {
    let mut b = Vec::with_capacity(12 + body.len() + 32);
    b.extend_from_slice(magic);
    b.extend_from_slice(&version.to_le_bytes());
    b.extend_from_slice(body);
    let sum = blake3::hash(&b);
    b.extend_from_slice(sum.as_bytes());
    b
}

/// The body of an [`envelope`], checked: magic, version, checksum.
pub fn open_envelope<'b>(
    magic: &[u8; 8],
    version: u32,
    bytes: &'b [u8],
) -> std::result::Result<&'b [u8], AnalysisFileProblem> {
    if bytes.len() < 8 || &bytes[..8] != magic {
        return Err(AnalysisFileProblem::BadMagic);
    }
    if bytes.len() < 12 + 32 {
        return Err(AnalysisFileProblem::Truncated { actual: bytes.len() as u64, declared: 12 + 32 });
    }
    let found = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]);
    if found != version {
        return Err(AnalysisFileProblem::UnsupportedVersion { found, expected: version });
    }
    let (body, sum) = bytes.split_at(bytes.len() - 32);
    if blake3::hash(body).as_bytes() != sum {
        return Err(AnalysisFileProblem::ChecksumMismatch);
    }
    Ok(&body[12..])
}
