//! Typed errors of the core library: every way an exemplar, an analysis file or a synthesis
//! request can be wrong. The server maps each variant to one HTTP status in one place.

use std::path::PathBuf;

/// Everything that can go wrong in `textile-core`.
#[derive(Debug, thiserror::Error)]
pub enum CoreError {
    /// The exemplar bytes are not an image format we can decode, or the image data is corrupt.
    #[error("exemplar is not a decodable image: {0}")]
    ExemplarUndecodable(String),
    /// The exemplar decodes but its size is outside the accepted range.
    #[error("exemplar is {width}x{height} pixels; allowed is {min}x{min} to {max}x{max}")]
    ExemplarSize {
        /// Width of the offending image.
        width: u32,
        /// Height of the offending image.
        height: u32,
        /// Smallest accepted side.
        min: u32,
        /// Largest accepted side.
        max: u32,
    },
    /// The exemplar is flat: too little colour variation to synthesize anything from it.
    #[error(
        "exemplar is flat: its most varied channel has a standard deviation of {spread:.2} levels, under the \
         {min} needed to synthesize a texture from it"
    )]
    FlatExemplar {
        /// Standard deviation of the most varied channel, in 8-bit levels.
        spread: f64,
        /// The least accepted.
        min: f64,
    },
    /// An analysis file could not be read or written.
    #[error("analysis file {path}: {source}")]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: std::io::Error,
    },
    /// An analysis file is not usable; `problem` says why (truncated, wrong magic, …).
    #[error("analysis file {path}: {problem}")]
    AnalysisFile {
        /// The file concerned (empty when parsing from memory).
        path: PathBuf,
        /// What is wrong with it.
        problem: AnalysisFileProblem,
    },
    /// A synthesis parameter is outside its allowed range.
    #[error("parameter '{name}': {message}")]
    Param {
        /// Parameter name as the API spells it.
        name: &'static str,
        /// What was wrong and what is allowed.
        message: String,
    },
    /// A parameter key is misplaced: repeated, of another mode, or a texture setting given in a
    /// request.
    #[error("parameter '{key}' {message}")]
    ParamKey {
        /// The key as given.
        key: String,
        /// What is wrong with it.
        message: String,
    },
    /// A parameter key that no mode knows.
    #[error("unknown parameter '{key}'; allowed: {allowed}")]
    UnknownParam {
        /// The key as given.
        key: String,
        /// The keys that would have been read.
        allowed: String,
    },
    /// The mode needs the texture's analysis, which is not available (yet).
    #[error("mode={mode} needs the texture's analysis, which is not ready")]
    NotAnalysed {
        /// The mode asked for.
        mode: &'static str,
    },
    /// The mode renders from a state it prepares per texture, which is not prepared (yet).
    #[error("mode={mode} needs what it prepares from the texture, which is not ready")]
    NotPrepared {
        /// The mode asked for.
        mode: &'static str,
    },
    /// A requested window is empty or too large.
    #[error("window {width}x{height} is not allowed: {message}")]
    Window {
        /// Requested width.
        width: i64,
        /// Requested height.
        height: i64,
        /// What is allowed.
        message: String,
    },
    /// A sample of a per-sample query is not usable.
    #[error("sample {index}: {message}")]
    Sample {
        /// Its position in the request (0-based).
        index: usize,
        /// What was wrong and what is allowed.
        message: String,
    },
    /// An analysis's candidate search did far more work than any exemplar of its size needs (a
    /// search degenerating towards brute force), and was stopped.
    #[error(
        "the analysis of a {side}x{side} exemplar was stopped: its candidate search opened {leaves} k-d tree leaves \
         at one level, over its budget of {budget}"
    )]
    AnalysisWork {
        /// Exemplar side.
        side: u32,
        /// Leaves opened when it was stopped.
        leaves: u64,
        /// The level's budget.
        budget: u64,
    },
    /// A material map is unusable, or not one the texture or the mode has.
    #[error("map '{name}' {message}")]
    Map {
        /// The map's name as given.
        name: String,
        /// What is wrong with it.
        message: String,
    },
    /// The mode does not serve this texture (umbrella on a near-regular exemplar, whose lattice
    /// its patch collage would break); `reason` says why and what serves it instead.
    #[error("mode={mode} does not serve this texture: {reason}")]
    Declined {
        /// The mode asked for.
        mode: &'static str,
        /// Why, in a sentence.
        reason: String,
    },
    /// The work was abandoned: its requester went away, or the service is stopping.
    #[error("cancelled: the requester went away or the service is stopping")]
    Cancelled,
}

/// Why an analysis file was refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum AnalysisFileProblem {
    /// The file does not start with the textile analysis magic bytes.
    #[error("not a textile analysis file (wrong magic bytes)")]
    BadMagic,
    /// The file was written by an incompatible format or algorithm version.
    #[error("unsupported version {found} (this build reads {expected})")]
    UnsupportedVersion {
        /// Version found in the file.
        found: u32,
        /// Version this build understands.
        expected: u32,
    },
    /// The file is shorter than its header says.
    #[error("truncated: {actual} bytes, header declares {declared}")]
    Truncated {
        /// Size on disk.
        actual: u64,
        /// Size the header declares.
        declared: u64,
    },
    /// The trailing checksum does not match the content.
    #[error("checksum mismatch (file corrupted)")]
    ChecksumMismatch,
    /// The content is structurally invalid.
    #[error("corrupt content: {0}")]
    Corrupt(String),
}

/// Result alias used throughout the crate.
pub type Result<T, E = CoreError> = std::result::Result<T, E>;

/// Longest piece of a request echoed back in an error message, in characters.
pub const ECHO_MAX: usize = 100;

/// `s` as an error message echoes it: control characters escaped, at most [`ECHO_MAX`]
/// characters, longer input cut with its full length noted — a hostile 60 KB key does not come
/// back as a 60 KB answer.
pub fn clip(s: &str) -> String {
    let escaped: String = s.escape_debug().collect();
    if escaped.chars().count() <= ECHO_MAX {
        escaped
    } else {
        let head: String = escaped.chars().take(ECHO_MAX).collect();
        format!("{head}… ({} bytes)", s.len())
    }
}
