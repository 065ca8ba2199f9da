//! # textile-server
//!
//! The `textile` service and command line: configuration, the texture registry, request
//! validation, rendering and encoding, the tile cache, and the axum HTTP layer. The binary
//! (`src/main.rs`) only dispatches to [`run`].
//!
//! Data flow of a tile request: [`http`] route → [`tile_request`] validation → [`cache`] →
//! [`http::state::AppState::synthesize`] on the rayon pool → [`render`] (textile-core) →
//! [`encode`] → [`http::content`] headers.

pub mod assets;
pub mod cache;
pub mod cli;
pub mod commands;
pub mod config;
pub mod encode;
pub mod http;
pub mod loadtest;
pub mod memory;
pub mod metrics;
pub mod render;
pub mod serve;
pub mod textures;
pub mod tile_request;

/// Parse the command line and run the chosen command; the process exit code.
pub fn run() -> std::process::ExitCode {
    use clap::Parser;
    let cli = cli::Cli::parse();
    let result = match cli.command {
        None => serve::run(cli.serve),
        Some(cli::Command::Serve(a)) => serve::run(a),
        Some(cli::Command::Analyze(a)) => commands::analyze(a),
        Some(cli::Command::Render(a)) => commands::render(a),
        Some(cli::Command::Info(a)) => commands::info(a),
        Some(cli::Command::Loadtest(a)) => loadtest::run(a),
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("textile: error: {e}");
            std::process::ExitCode::FAILURE
        }
    }
}
