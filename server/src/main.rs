//! The `textile` binary: parses the command line and runs one command — `serve` (HTTP tile
//! server, the default), `analyze`, `render` or `info`.

mod cache;
mod cli;
mod commands;
mod config;
mod encode;
mod http;
mod render;
mod serve;
mod textures;
mod tile_request;

use clap::Parser;

fn main() -> std::process::ExitCode {
    let cli = cli::Cli::parse();
    let result = match cli.command {
        None => serve::run(cli.serve),
        Some(cli::Command::Serve(a)) => serve::run(a),
        Some(cli::Command::Analyze(a)) => commands::analyze(a),
        Some(cli::Command::Render(a)) => commands::render(a),
        Some(cli::Command::Info(a)) => commands::info(a),
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("textile: error: {e}");
            std::process::ExitCode::FAILURE
        }
    }
}
