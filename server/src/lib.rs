//! # textile-server
//!
//! The `textile` service and command line: configuration, the texture registry, request
//! validation, rendering and encoding, the tile cache, and the axum HTTP layer. The binary
//! (`src/main.rs`) only dispatches to [`run`].
//!
//! Data flow of a tile request: [`http`] route → [`request`] validation (the texture's mode
//! defaults read the query) → [`pipeline`]: [`cache`] (single flight) →
//! [`state::AppState::synthesize`] on the rayon pool → the mode renders (textile-core) →
//! [`encode`] → [`http::content`] headers. `textile render` goes through the same
//! [`pipeline::ImageJob`].

pub mod access_log;
pub mod cache;
pub mod cmd;
pub mod config;
pub mod encode;
pub mod error;
pub mod etag_memo;
pub mod export;
pub mod http;
pub mod memory;
pub mod metrics;
pub mod output;
pub mod pipeline;
pub mod queue;
pub mod request;
pub mod robustness;
pub mod sampling;
pub mod scene;
pub mod state;
pub mod terrain;
pub mod textures;
pub mod uploads;

/// Parse the command line and run the chosen command; the process exit code.
pub fn run() -> std::process::ExitCode {
    cmd::run()
}
