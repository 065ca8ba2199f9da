//! Command-line interface: argument definitions (clap) for `serve` (the default), `analyze`,
//! `render`, `tileable`, `info`, `export` and `loadtest`.

use std::path::PathBuf;

use clap::builder::PossibleValuesParser;
use clap::{Args, Parser, Subcommand};
use textile_core::analysis::IndexChoice;
use textile_core::lattice::LatticeChoice;
use textile_core::recipe::Toroidal;

pub use super::flags::SettingFlags;
use crate::config::{settings, Overrides};

/// Any error ending a command, as text for the user.
pub type CliResult = Result<(), Box<dyn std::error::Error>>;

/// `--index auto|exact|coherent`, read once here.
fn index_choice(s: &str) -> Result<IndexChoice, String> {
    IndexChoice::parse(s).map_err(|e| e.to_string())
}

/// textile — an infinite, deterministic, example-based texture as map tiles.
#[derive(Debug, Parser)]
#[command(name = "textile", version, about, long_about = None, args_conflicts_with_subcommands = true)]
pub struct Cli {
    /// Sub-command (default: serve).
    #[command(subcommand)]
    pub command: Option<Command>,
    /// Options of `serve` when no sub-command is given.
    #[command(flatten)]
    pub serve: ServeArgs,
}

/// Sub-commands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Serve tiles over HTTP (the default).
    Serve(ServeArgs),
    /// Analyse an exemplar image and store the analysis file.
    Analyze(AnalyzeArgs),
    /// Synthesize one seamless, tileable texture image from an exemplar (Wei & Levoy 2000).
    Tileable(TileableArgs),
    /// Render a tile or any window of a texture to an image file.
    Render(RenderArgs),
    /// Print the header of an analysis file.
    Info(InfoArgs),
    /// Pre-render tiles into a PMTiles or MBTiles archive (a periodic world, or a rectangle),
    /// whole or as one shard of many (`--shard I/N`), resumable.
    Export(ExportArgs),
    /// Merge the part files of an export's shards into its archive (the same bytes as one
    /// process's export).
    Merge(MergeArgs),
    /// Load-test a running textile server on this machine with scripted request patterns.
    Loadtest(LoadtestArgs),
}

/// Options shared by commands that read the configuration.
#[derive(Debug, Args, Clone, Default)]
pub struct ConfigArgs {
    /// Configuration file (TOML), layered over the built-in defaults.
    #[arg(long, value_name = "FILE", env = "TEXTILE_CONFIG", hide_env_values = true)]
    pub config: Option<PathBuf>,
    /// The settings every such command takes as flags (`--data-dir`), from the settings table.
    #[command(flatten)]
    pub settings: SettingFlags<true>,
}

impl ConfigArgs {
    /// What the flags set, over the configuration's other layers (`serve`: its own flags too).
    pub fn overrides(&self, serve: Option<&SettingFlags<false>>) -> Overrides {
        let mut values = self.settings.0.clone();
        values.extend(serve.map(|s| s.0.clone()).unwrap_or_default());
        Overrides(values)
    }
}

/// `textile serve`.
#[derive(Debug, Args, Clone, Default)]
pub struct ServeArgs {
    #[command(flatten)]
    pub config: ConfigArgs,
    /// The service settings that have a flag (`--bind`, `--cache-mib`, `--workers`, …), from
    /// the settings table.
    #[command(flatten)]
    pub settings: SettingFlags<false>,
    /// Print the effective configuration as TOML and exit.
    #[arg(long)]
    pub print_config: bool,
}

/// `textile analyze`.
#[derive(Debug, Args)]
pub struct AnalyzeArgs {
    /// Exemplar image (PNG, JPEG, WebP, TGA or BMP).
    pub exemplar: PathBuf,
    /// Output analysis file.
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,
    /// How the exemplar is made and analysed.
    #[command(flatten)]
    pub recipe: ExemplarArgs,
}

/// The settings of a texture's exemplar as flags (`textile analyze`, `textile render
/// --exemplar`), each with the help its texture setting declares (`config::settings`): the
/// same image and settings make the same exemplar and analysis as a configured texture.
#[derive(Debug, Args)]
pub struct ExemplarArgs {
    #[arg(long, default_value = "auto", value_parser = toroidal_choice, requires = "exemplar", help = settings::TOROIDAL.help)]
    pub toroidal: Toroidal,
    #[arg(long, default_value = "auto", value_parser = index_choice, requires = "exemplar", help = settings::INDEX.help)]
    pub index: IndexChoice,
    #[arg(long, value_name = "LATTICE", default_value = "auto", value_parser = lattice_choice, requires = "exemplar", help = settings::LATTICE.help)]
    pub lattice: LatticeChoice,
    /// The image is a high-resolution source, halved into the exemplar (as `exemplar_hires`).
    #[arg(long, requires = "exemplar")]
    pub hires: bool,
    /// The exemplar's randomness mask (as `randomness_mask`): an image of its size, white where
    /// synthesis may move content, black where it keeps it.
    #[arg(long, value_name = "IMAGE", requires = "exemplar")]
    pub randomness_mask: Option<PathBuf>,
    /// Largest accepted exemplar side (as `max_exemplar_side`).
    #[arg(long, default_value_t = 1024, requires = "exemplar")]
    pub max_side: u32,
}

/// `textile tileable`.
#[derive(Debug, Args)]
pub struct TileableArgs {
    /// Exemplar image (PNG, JPEG, WebP, TGA or BMP).
    pub exemplar: PathBuf,
    /// Output side in pixels: a multiple of 2^(levels−1) (8 for exemplars of 128² and up),
    /// 32–4096.
    #[arg(long, default_value_t = 256)]
    pub size: u32,
    /// Output image (.png, .jpg, .jpeg or .webp).
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,
    /// Seed of the starting noise: the same seed gives the same bytes.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Search every exemplar neighbourhood instead of the TSVQ (slow; for comparison).
    #[arg(long, conflicts_with = "backtrack")]
    pub exact: bool,
    /// Leaves of the TSVQ scanned per pixel (limited backtracking; 1 is greedy).
    #[arg(long, default_value_t = textile_core::tileable::DEFAULT_BACKTRACK)]
    pub backtrack: usize,
    /// Toroidal (wrap-around) exemplar: auto, true or false.
    #[arg(long, default_value = "auto", value_parser = ["auto", "true", "false"])]
    pub toroidal: String,
    /// Largest accepted exemplar side.
    #[arg(long, default_value_t = 1024)]
    pub max_side: u32,
}

/// `textile render`.
#[derive(Debug, Args)]
pub struct RenderArgs {
    #[command(flatten)]
    pub config: ConfigArgs,
    /// A configured texture id.
    #[arg(long, conflicts_with = "exemplar", required_unless_present_any = ["exemplar", "list_params"])]
    pub texture: Option<String>,
    /// An exemplar image, analysed on the fly.
    #[arg(long, value_name = "IMAGE")]
    pub exemplar: Option<PathBuf>,
    /// How the exemplar given with --exemplar is made and analysed.
    #[command(flatten)]
    pub recipe: ExemplarArgs,
    /// Zoom (default: the texture's native zoom).
    #[arg(long)]
    pub z: Option<u32>,
    /// Tile column (with --y); renders one 256 px tile.
    #[arg(long, allow_hyphen_values = true, requires = "y", conflicts_with = "window")]
    pub x: Option<i64>,
    /// Tile row (with --x).
    #[arg(long, allow_hyphen_values = true, requires = "x")]
    pub y: Option<i64>,
    /// A window instead of a tile: X,Y,W,H in pixels at zoom --z.
    #[arg(long, value_name = "X,Y,W,H", allow_hyphen_values = true)]
    pub window: Option<String>,
    /// A perspective view of the infinite ground plane instead of a tile, rendered entirely
    /// through per-sample queries with footprint-based level of detail: camera height above
    /// the plane (native texels), pitch below the horizon, yaw clockwise from north, and
    /// vertical field of view (degrees), e.g. `--camera 48,30,0,60`.
    #[arg(long, value_name = "HEIGHT,PITCH,YAW,FOV", conflicts_with_all = ["x", "window", "z"])]
    pub camera: Option<String>,
    /// The camera's position over the plane, in native texels.
    #[arg(long, value_name = "X,Y", default_value = "0,0", allow_hyphen_values = true, requires = "camera")]
    pub at: String,
    /// The camera's image size.
    #[arg(long, value_name = "WxH", default_value = "512x512", requires = "camera")]
    pub size: String,
    /// Mode (engine); default: the texture's default mode.
    #[arg(long, value_parser = PossibleValuesParser::new(textile_core::MODE_NAMES))]
    pub mode: Option<String>,
    /// Seed: selects another, equally good texture.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Period in native tiles (power of two): periodic, seamless output.
    #[arg(long)]
    pub world: Option<u64>,
    /// Material map to render: albedo (the colour), one of the texture's maps (normal,
    /// height, …: see its [textures.maps]) or uv (the coordinates, 16-bit PNG).
    #[arg(long, value_name = "NAME", default_value = "albedo")]
    pub map: String,
    /// Spatial controls (synth's `controls`) from a JSON file: `{"noise": {"scale": 64,
    /// "range": [0.2, 1]}, "strokes": [{"at": [x, y], "radius": 40, "soft": 8, "value": 0}]}`;
    /// renders what the server serves for the same file's base64url as `controls=`.
    #[arg(long, value_name = "FILE.json")]
    pub controls: Option<PathBuf>,
    /// A parameter of the mode, as in a query string or a texture's configuration (repeatable):
    /// e.g. `--param randomness=0.5`, `--param kappa=0.8`, `--param passes=0` (synth),
    /// `--param iterations=0` (mosaic). `textile render --list-params` lists them all.
    #[arg(long = "param", short = 'p', value_name = "KEY=VALUE")]
    pub params: Vec<String>,
    /// Instead of the texture, draw what the mode prepared for it (modes that prepare
    /// something: `--mode umbrella` draws each extracted base umbrella magnified with its rim
    /// and centre, and modified umbrellas of it below).
    #[arg(long)]
    pub sheet: bool,
    /// List every mode's parameters (name, range, description) and exit.
    #[arg(long)]
    pub list_params: bool,
    /// Output file: an image (.png, .jpg, .webp), or the tile's GLB (.glb: what
    /// /gltf/{id}/{z}/{x}/{y}.glb serves, byte for byte; `--param relief=SCALE` displaces its
    /// mesh by the texture's height map).
    #[arg(short, long, value_name = "FILE", required_unless_present = "list_params")]
    pub output: Option<PathBuf>,
}

/// `textile export`.
#[derive(Debug, Args)]
pub struct ExportArgs {
    #[command(flatten)]
    pub config: ConfigArgs,
    /// A configured texture id.
    #[arg(long)]
    pub texture: String,
    /// Period of the exported world in native tiles (a power of two; default 2^native zoom): the
    /// texture repeats once around a Web-Mercator world whose archive zoom a is textile zoom
    /// a + native − log2(world).
    #[arg(long, conflicts_with = "bbox")]
    pub world: Option<u64>,
    /// A rectangle instead of a world: tiles X0..X1 × Y0..Y1 (end exclusive) at the highest
    /// zoom, in textile's own zooms and coordinates (0 ≤ X, Y ≤ 2^z).
    #[arg(long, value_name = "X0,Y0,X1,Y1")]
    pub bbox: Option<String>,
    /// Archive zooms MIN..MAX (default: every zoom the area has).
    #[arg(long, value_name = "MIN..MAX")]
    pub zoom: Option<String>,
    /// Tile encoding.
    #[arg(long, default_value = "png", value_parser = ["png", "jpg", "jpeg", "webp"])]
    pub format: String,
    /// Mode (engine); default: the texture's default mode.
    #[arg(long, value_parser = PossibleValuesParser::new(textile_core::MODE_NAMES))]
    pub mode: Option<String>,
    /// Seed.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Material map to export: albedo (the colour) or one of the texture's maps (normal,
    /// height, …: see its [textures.maps]).
    #[arg(long, value_name = "NAME", default_value = "albedo")]
    pub map: String,
    /// A tile query parameter of the mode (repeatable), e.g. `-p randomness=0.5`.
    #[arg(long = "param", short = 'p', value_name = "KEY=VALUE")]
    pub params: Vec<String>,
    /// Render only shard I of N (0 ≤ I < N: `JOB_COMPLETION_INDEX/N` in a Kubernetes Indexed
    /// Job): a contiguous share of the archive's tiles, written to the part file -o names, to be
    /// joined by `textile merge`. Run again with the same arguments after an interruption, it
    /// resumes from its checkpoint.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<String>,
    /// Threads rendering tiles (0: one per core).
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub workers: usize,
    /// Output archive: NAME.pmtiles or NAME.mbtiles; with --shard, the part file (e.g.
    /// parts/world-3.part).
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,
}

/// `textile merge`.
#[derive(Debug, Args)]
pub struct MergeArgs {
    /// The part files of every shard (any order).
    #[arg(required = true, value_name = "PART")]
    pub parts: Vec<PathBuf>,
    /// Output archive: NAME.pmtiles or NAME.mbtiles (never one of the parts).
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,
    /// Replace the output if it exists (without it, an existing file is refused).
    #[arg(long)]
    pub force: bool,
}

/// `textile info`.
#[derive(Debug, Args)]
pub struct InfoArgs {
    /// Analysis file.
    pub file: PathBuf,
}

/// `textile loadtest`.
#[derive(Debug, Args)]
pub struct LoadtestArgs {
    /// Base URL of the server (loopback addresses only).
    #[arg(long, default_value = "http://127.0.0.1:8080")]
    pub url: String,
    /// Texture id.
    #[arg(long, default_value = "gravel")]
    pub texture: String,
    /// Request pattern: pan (viewport dragged across the plane), zoom (in and out), random
    /// (uniform tiles), hot (one tile), replay (the requests of --file, cycled or --once).
    #[arg(long, default_value = "pan", value_parser = ["pan", "zoom", "random", "hot", "replay"])]
    pub pattern: String,
    /// Requests for `--pattern replay`: one URL, /path, nginx/Apache combined (or common)
    /// access-log line, or line of textile's own JSON access log (`serve --access-log`) per
    /// line; access-log lines other than GET and HEAD are left out, and a log is played in the
    /// order of its times.
    #[arg(long, value_name = "FILE")]
    pub file: Option<PathBuf>,
    /// Replay the file once, in order, then end (by default it is cycled).
    #[arg(long)]
    pub once: bool,
    /// Replay an access log at its own pace, X times real time (2 = twice as fast), once: each
    /// request is due at its timestamp (an open model; latency from the due time).
    #[arg(long, value_name = "X")]
    pub speed: Option<f64>,
    /// Replay only access-log lines of these statuses, e.g. 200,304.
    #[arg(long, value_name = "CODES", value_delimiter = ',')]
    pub replay_status: Vec<u16>,
    /// Concurrent connections (1-1024).
    #[arg(long, default_value_t = 8)]
    pub concurrency: usize,
    /// Stop after this many requests (1-10000000). Alone, it ends the run (within an hour);
    /// with --duration, whichever comes first; with neither, the run lasts 30 s.
    #[arg(long)]
    pub requests: Option<u64>,
    /// Stop after this many seconds (up to 3600). Alone, it ends the run however many requests
    /// that takes; requests still in flight then are reported as timed out.
    #[arg(long)]
    pub duration: Option<f64>,
    /// Query string added to every tile URL, e.g. "mode=mosaic&seed=3".
    #[arg(long, default_value = "")]
    pub query: String,
    /// Seed of the random pattern.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Behave like a polite client: after a 503, a connection waits the advised Retry-After
    /// before its next request (by default it asks again at once, the harder test). Closed
    /// loop only.
    #[arg(long)]
    pub honor_retry_after: bool,
    /// Open model: offer this many requests per second (constant arrivals, as wrk2 -R or k6's
    /// constant-arrival-rate), whatever the answers; --concurrency bounds the connections.
    /// Latency is then measured from each request's intended send time (corrected for
    /// coordinated omission), with the uncorrected figure beside it. Without it: a closed loop.
    #[arg(long, value_name = "R")]
    pub rate: Option<f64>,
    /// Open model with a rate ramped linearly from FROM to TO requests per second over the run
    /// (needs --duration), e.g. 50:400.
    #[arg(long, value_name = "FROM:TO")]
    pub rate_ramp: Option<String>,
    /// Run the load this many seconds first, leaving it out of every figure (caches and
    /// connections warm).
    #[arg(long, value_name = "SECONDS")]
    pub warmup: Option<f64>,
    /// Verify under load: fetch each distinct URL's reference bytes once before the run (one at
    /// a time), then check every 200 under load against it; a difference is an error naming the
    /// URL, and the command fails. Needs the run's URLs up front: --pattern replay, or --requests
    /// N (the run then plays the first N of the pattern).
    #[arg(long)]
    pub verify: bool,
    /// Verify against the references of FILE (`URL sha256` lines, as --record writes) instead of
    /// fetching them (URLs not in it are fetched). Implies --verify.
    #[arg(long, value_name = "FILE")]
    pub expect: Option<PathBuf>,
    /// Write the references fetched before the run to FILE (`URL sha256` lines), e.g. from one
    /// replica, to --expect them of another. Implies --verify.
    #[arg(long, value_name = "FILE")]
    pub record: Option<PathBuf>,
    /// Draw the run's timeline to FILE.svg: p50 and p99 latency and requests and errors per
    /// second, in one chart.
    #[arg(long, value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
    /// Write the latency histogram to FILE in HdrHistogram's percentile-distribution text format
    /// (milliseconds; what HdrHistogram's plotters read).
    #[arg(long, value_name = "FILE")]
    pub histogram: Option<PathBuf>,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
}

/// `--toroidal`: see [`Toroidal`].
fn toroidal_choice(s: &str) -> Result<Toroidal, String> {
    s.parse()
}

/// `--lattice`: see [`LatticeChoice`]'s command-line spelling.
fn lattice_choice(s: &str) -> Result<LatticeChoice, String> {
    s.parse()
}
