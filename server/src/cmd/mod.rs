//! The commands of the `textile` binary, one file each — `serve` (the service's process:
//! configuration, listening, loading, shutdown), `analyze` and `tileable` (with progress bars),
//! `render` (a tile, a window or a perspective camera view, to an image file, for scripts),
//! `export` (an archive of tiles, or one shard's part of it) and `merge` (parts into the
//! archive), `info` (an analysis file and what is stored beside it) and
//! `loadtest` — with their arguments ([`args`]) and what they share here.

pub mod analyze;
pub mod args;
pub mod export;
pub mod flags;
pub mod info;
pub mod loadtest;
pub mod render;
pub mod serve;
pub mod tileable;

use std::path::Path;
use std::sync::{Arc, Mutex};

use indicatif::{ProgressBar, ProgressStyle};
use textile_core::{Exemplar, ExemplarOptions, Progress};

use crate::config::Config;
use crate::encode::Format;
use crate::textures::{exemplar_bytes, load_registry, Texture};
use args::ConfigArgs;

/// Parse the command line and run the chosen command; the process exit code.
pub fn run() -> std::process::ExitCode {
    use clap::Parser;
    let cli = args::Cli::parse();
    let result = match cli.command {
        None => serve::run(cli.serve),
        Some(args::Command::Serve(a)) => serve::run(a),
        Some(args::Command::Analyze(a)) => analyze::run(a),
        Some(args::Command::Tileable(a)) => tileable::run(a),
        Some(args::Command::Render(a)) => render::run(a),
        Some(args::Command::Info(a)) => info::run(a),
        Some(args::Command::Export(a)) => export::run(a),
        Some(args::Command::Merge(a)) => export::merge(a),
        Some(args::Command::Loadtest(a)) => loadtest::run(a),
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("textile: error: {e}");
            std::process::ExitCode::FAILURE
        }
    }
}

/// A progress bar on the terminal, labelled with what the work is.
pub(crate) struct Bar(pub(crate) Mutex<Option<ProgressBar>>, pub(crate) &'static str);

impl Progress for Bar {
    fn step(&self, done: u32, total: u32, what: &str) {
        let mut g = self.0.lock().unwrap_or_else(|e| e.into_inner());
        let bar = g.get_or_insert_with(|| {
            let b = ProgressBar::new(total as u64);
            let template = format!("{{spinner}} {} [{{bar:30}}] {{pos}}/{{len}} {{msg}} ({{elapsed}})", self.1);
            if let Ok(s) = ProgressStyle::with_template(&template) {
                b.set_style(s.progress_chars("=> "));
            }
            b
        });
        bar.set_position(done as u64);
        bar.set_message(what.to_string());
        if done >= total {
            bar.finish();
        }
    }
}

/// `--toroidal auto|true|false` as the exemplar option (`auto`: detected).
pub(crate) fn toroidal_flag(s: &str) -> Option<bool> {
    match s {
        "true" => Some(true),
        "false" => Some(false),
        _ => None,
    }
}

impl args::ExemplarArgs {
    /// The exemplar of the image at `path`, made by the one recipe
    /// ([`textile_core::recipe::Recipe`]) with these flags; what the recipe did is printed.
    pub(crate) fn make(&self, path: &Path) -> Result<Exemplar, Box<dyn std::error::Error>> {
        let read = |p: &Path| std::fs::read(p).map_err(|e| format!("cannot read {}: {e}", p.display()));
        let bytes = read(path)?;
        let mask = self.randomness_mask.as_deref().map(read).transpose()?;
        let recipe = textile_core::recipe::Recipe {
            max_input_side: self.max_side,
            toroidal: self.toroidal,
            hires: self.hires,
            lattice: self.lattice.clone(),
            normal_convention: None,
        };
        let images = textile_core::recipe::Images { exemplar: &bytes, mask: mask.as_deref(), maps: &[] };
        Ok(recipe
            .make(&images, &|note| eprintln!("{}: {note}", path.display()))
            .map_err(|e| format!("{}: {e}", path.display()))?)
    }
}

pub(crate) fn read_exemplar(path: &Path, opts: &ExemplarOptions) -> Result<Exemplar, Box<dyn std::error::Error>> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    Ok(Exemplar::from_bytes(&bytes, opts).map_err(|e| format!("{}: {e}", path.display()))?)
}

/// The image format an output file's extension names.
pub(crate) fn output_format(output: &Path) -> Result<Format, &'static str> {
    output
        .extension()
        .and_then(|e| e.to_str())
        .and_then(Format::from_ext)
        .ok_or("output must end in .png, .jpg, .jpeg or .webp (or, for `textile render`, .glb)")
}

/// A configured or uploaded texture, loaded (analysed if its analysis is not stored) from the
/// data directory.
pub(crate) fn configured_texture(c: &ConfigArgs, id: &str) -> Result<Arc<Texture>, Box<dyn std::error::Error>> {
    let overrides = c.overrides(None);
    let cfg = crate::uploads::with_stored(&Config::load(c.config.as_deref(), &overrides)?, &|s| eprintln!("{s}"));
    let mut only = cfg.clone();
    only.textures.retain(|t| t.id == id);
    only.landscapes.clear();
    if only.textures.is_empty() {
        let ids: Vec<_> = cfg.textures.iter().map(|t| t.id.as_str()).collect();
        return Err(format!("no texture '{id}'; configured: {}", ids.join(", ")).into());
    }
    let _ = exemplar_bytes(&only, &only.textures[0])?;
    let reg = load_registry(&only, &|s| eprintln!("{s}"))?;
    Ok(reg.list[0].clone())
}

/// The configured landscape `id` with the textures it is made of, analysed; `None` if `id` is
/// no landscape.
pub(crate) fn configured_landscape(
    c: &ConfigArgs,
    id: &str,
) -> Result<Option<Arc<crate::textures::Landscape>>, Box<dyn std::error::Error>> {
    let cfg =
        crate::uploads::with_stored(&Config::load(c.config.as_deref(), &c.overrides(None))?, &|s| eprintln!("{s}"));
    let Some(l) = cfg.landscapes.iter().find(|l| l.id == id) else { return Ok(None) };
    let mut only = cfg.clone();
    only.textures.retain(|t| l.layers.iter().any(|y| y.texture == t.id));
    only.landscapes.retain(|m| m.id == id);
    let reg = load_registry(&only, &|s| eprintln!("{s}"))?;
    Ok(reg.landscape(id).cloned())
}

/// The `--param KEY=VALUE` pairs and the flags, as query pairs.
pub(crate) fn param_pairs(
    params: &[String],
    mode: &Option<String>,
    seed: Option<u64>,
    world: Option<u64>,
) -> Result<Vec<(String, String)>, String> {
    let mut pairs: Vec<(String, String)> = Vec::new();
    let flags =
        [("mode", mode.clone()), ("seed", seed.map(|s| s.to_string())), ("world", world.map(|w| w.to_string()))];
    pairs.extend(flags.into_iter().filter_map(|(k, v)| v.map(|v| (k.to_string(), v))));
    for p in params {
        let (k, v) = p.split_once('=').ok_or_else(|| format!("--param '{p}' must be KEY=VALUE"))?;
        pairs.push((k.trim().to_string(), v.trim().to_string()));
    }
    Ok(pairs)
}
