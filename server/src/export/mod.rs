//! `textile export`: a finite part of the texture pre-rendered into one archive file that any
//! static host or CDN serves — PMTiles v3 ([`pmtiles_sink`]) or MBTiles ([`mbtiles_sink`]).
//!
//! The infinite plane becomes a Web-Mercator world by periodicity: with `world = 2^k` native
//! tiles the texture repeats exactly once around the world, archive zoom `a` is textile zoom
//! `a + native − k`, and archive tiles are `0 ≤ x, y < 2^a` — MapLibre, OpenLayers and Leaflet
//! show a seamless world. A sub-rectangle (`--bbox`, tile coordinates at the highest zoom) keeps
//! textile's own zooms and coordinates.
//!
//! Tiles are made by the same [`crate::pipeline::Picture`] as served tiles (an exported tile's
//! bytes equal the server's answer for the same URL; a landscape's are its [`LandscapeJob`]'s),
//! rendered in parallel in chunks, in ascending Hilbert tile id (the order PMTiles needs to be
//! clustered), with progress and bounded memory, into a
//! [`part`] file with a checkpoint after every chunk (an interrupted export resumes); [`merge`]
//! then lays parts into the archive, written under a temporary name and renamed when complete,
//! so an interrupted export never leaves a half-written file under the target name. A
//! [`Shard`] renders a contiguous range of the tiles into a part of its own: parts of every
//! shard merge into the bytes of a single process's export.

pub mod layout;
pub mod mbtiles_sink;
pub mod merge;
pub mod part;
pub mod pmtiles_sink;

use std::path::Path;

use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use serde_json::json;
use textile_core::maps::MapChoice;
use textile_core::{ParamReader, Pyramid};

pub use layout::Layout;

use crate::encode::Format;
use crate::pipeline::landscape::{LandscapeJob, LandscapeMap};
use crate::pipeline::subject::Subject;
use crate::pipeline::{engine_version, Target};
use crate::request::TileSpec;
use crate::textures::Served;

/// Tiles rendered per chunk per pool thread: what is held in memory before it is written.
const CHUNK_PER_THREAD: usize = 32;
/// Level cache shared by the export's tiles (tiles come in Hilbert order: neighbours share it).
const LEVEL_CACHE: u64 = 256 << 20;
/// Web-Mercator latitude limit.
const MAX_LAT: f64 = 85.051_128_779_806_59;

/// Which part of the texture to export.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Area {
    /// A periodic world of `2^k` native tiles, archive zooms `lo..=hi` (`hi ≤ k`).
    World {
        /// log2 of the period in native tiles.
        k: u32,
    },
    /// Tiles `[x0, x1) × [y0, y1)` at the highest zoom (and their parents below), textile zooms.
    Bbox {
        /// First column at the highest zoom.
        x0: u32,
        /// First row.
        y0: u32,
        /// One past the last column.
        x1: u32,
        /// One past the last row.
        y1: u32,
    },
}

/// An export, validated.
#[derive(Clone)]
pub struct Plan {
    /// What its tiles show (a landscape's job for tile 0/0/0 at zoom 0).
    pub what: Subject,
    /// The query string that gives the server's tiles the same bytes (`world` included).
    pub query: String,
    /// The area.
    pub area: Area,
    /// Archive zooms, inclusive.
    pub zooms: (u32, u32),
    /// Tile encoding.
    pub format: Format,
}

/// One tile to write: archive address and the textile tile.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Entry {
    /// Archive zoom, column, row.
    pub z: u8,
    /// Column.
    pub x: u32,
    /// Row.
    pub y: u32,
    /// The textile tile.
    pub tile: TileSpec,
}

/// Where tiles go: an archive format.
pub trait Sink {
    /// Add archive tile `z/x/y` (called in ascending PMTiles tile id).
    fn add(&mut self, z: u8, x: u32, y: u32, bytes: &[u8]) -> Result<(), String>;
    /// Complete the archive.
    fn finish(self: Box<Self>) -> Result<(), String>;
}

/// The archive `output` names (by its extension), written at `tmp`, with an export's metadata.
pub(crate) fn open_sink(output: &Path, tmp: &Path, meta: &serde_json::Value) -> Result<Box<dyn Sink>, String> {
    let ext = output.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    Ok(match ext.as_str() {
        "pmtiles" => Box::new(pmtiles_sink::PmtilesSink::create(tmp, meta)?),
        "mbtiles" => Box::new(mbtiles_sink::MbtilesSink::create(tmp, meta)?),
        _ => return Err(format!("{}: the archive must end in .pmtiles or .mbtiles", output.display())),
    })
}

/// `[west, south, east, north]` of an export's metadata.
pub(crate) fn meta_bounds(meta: &serde_json::Value) -> Result<[f64; 4], String> {
    let b: Vec<f64> =
        meta["bounds"].as_array().map(|a| a.iter().filter_map(|v| v.as_f64()).collect()).unwrap_or_default();
    b.try_into().map_err(|_| format!("export metadata without bounds: {}", meta["bounds"]))
}

/// `(min, max)` archive zooms of an export's metadata.
pub(crate) fn meta_zooms(meta: &serde_json::Value) -> Result<(u8, u8), String> {
    let z = |k: &str| meta[k].as_u64().and_then(|v| u8::try_from(v).ok());
    z("minzoom").zip(z("maxzoom")).ok_or_else(|| "export metadata without zooms".to_string())
}

impl Plan {
    /// Validate an export: `pairs` are the tile query parameters (mode, seed, the mode's own),
    /// `world` the period in native tiles (world exports), `bbox` a rectangle instead, `zooms`
    /// the archive zooms (default: all the area has).
    pub fn new(
        served: Served,
        mut pairs: Vec<(String, String)>,
        world: Option<u64>,
        bbox: Option<(u32, u32, u32, u32)>,
        zooms: Option<(u32, u32)>,
        format: Format,
    ) -> Result<Plan, String> {
        let (native, min_zoom) = (served.zooms().native, served.zooms().min);
        let (area, all) = match bbox {
            Some((x0, y0, x1, y1)) => {
                let (lo, hi) = zooms.unwrap_or((native, native));
                if hi > native || lo > hi {
                    return Err(format!("--zoom {lo}..{hi}: a bbox export has zooms {min_zoom}..={native}"));
                }
                if x0 >= x1 || y0 >= y1 || x1 > 1 << hi || y1 > 1 << hi {
                    return Err(format!(
                        "--bbox {x0},{y0},{x1},{y1}: needs X0 < X1 ≤ 2^{hi} and Y0 < Y1 ≤ 2^{hi} (archives address tiles 0 ≤ x, y < 2^z; use a world export for the whole plane)"
                    ));
                }
                (Area::Bbox { x0, y0, x1, y1 }, (lo, hi))
            }
            None => {
                let w = world.unwrap_or(1 << native);
                if !w.is_power_of_two() || w > 1 << 24 {
                    return Err(format!("--world {w}: a power of two up to 2^24 native tiles"));
                }
                let k = w.trailing_zeros();
                pairs.push(("world".into(), w.to_string()));
                let first = (k + min_zoom).saturating_sub(native);
                let (lo, hi) = zooms.unwrap_or((first, k));
                if lo < first || hi > k || lo > hi {
                    return Err(format!(
                        "--zoom {lo}..{hi}: a world of 2^{k} native tiles has archive zooms {first}..={k} (archive zoom a is textile zoom a + {native} - {k})"
                    ));
                }
                (Area::World { k }, (lo, hi))
            }
        };
        let query = form_urlencoded::Serializer::new(String::new()).extend_pairs(&pairs).finish();
        let mut r = ParamReader::request(pairs).map_err(|e| e.to_string())?;
        let what = match served {
            Served::Texture(tex) => {
                let map = crate::request::map_choice(&tex, &mut r, format).map_err(|e| e.message)?;
                if map == MapChoice::Uv {
                    return Err("map 'uv': coordinates are not exported; export albedo or a material map".into());
                }
                let params = tex.defaults.request(&tex.source(), r).map_err(|e| e.to_string())?;
                Subject::Texture { tex, params, map }
            }
            Served::Landscape(land) => {
                let (map, dem) = LandscapeMap::read(&land, &mut r, format).map_err(|e| e.message)?;
                if dem.is_some() {
                    return Err("raster-dem encodings are served, not exported".into());
                }
                let zero = Target::Tile(TileSpec { z: 0, x: 0, y: 0, scale: 1, format });
                Subject::Landscape(LandscapeJob::new(land, zero, (map, None), r).map_err(|e| e.message)?)
            }
        };
        Ok(Plan { what, query, area, zooms: all, format })
    }

    /// Textile zoom of archive zoom `a`.
    fn textile_zoom(&self, a: u32) -> u32 {
        match self.area {
            Area::World { k } => a + self.what.zooms().native - k,
            Area::Bbox { .. } => a,
        }
    }

    /// Which archive tiles the export holds, in the order they are written.
    pub fn layout(&self) -> Layout {
        let rect = match self.area {
            Area::World { .. } => None,
            Area::Bbox { x0, y0, x1, y1 } => Some([x0, y0, x1, y1]),
        };
        Layout { zooms: (self.zooms.0 as u8, self.zooms.1 as u8), rect }
    }

    /// Number of tiles.
    pub fn count(&self) -> u64 {
        self.layout().count()
    }

    /// Every tile, in ascending PMTiles tile id (zoom, then Hilbert order within it).
    pub fn entries(&self) -> Vec<Entry> {
        let layout = self.layout();
        let mut out = Vec::with_capacity(self.count() as usize);
        for a in self.zooms.0..=self.zooms.1 {
            let z = self.textile_zoom(a);
            out.extend(layout.zoom_tiles(a as u8).into_iter().map(|(a, x, y)| {
                let tile = TileSpec { z, x: x as i64, y: y as i64, scale: 1, format: self.format };
                Entry { z: a, x, y, tile }
            }));
        }
        out
    }

    /// Longitude/latitude bounds of the area.
    pub fn bounds(&self) -> [f64; 4] {
        let (x0, y0, x1, y1) = self.layout().tiles_at(self.zooms.1 as u8);
        let n = (1u64 << self.zooms.1) as f64;
        let lon = |x: u32| x as f64 / n * 360.0 - 180.0;
        let lat = |y: u32| (std::f64::consts::PI * (1.0 - 2.0 * y as f64 / n)).sinh().atan().to_degrees();
        [lon(x0), lat(y1).max(-MAX_LAT), lon(x1), lat(y0).min(MAX_LAT)]
    }

    /// The query of the archive's tiles as a URL suffix: `?QUERY`, or nothing when it is empty.
    pub fn query_suffix(&self) -> String {
        if self.query.is_empty() {
            String::new()
        } else {
            format!("?{}", self.query)
        }
    }

    /// The archive's JSON metadata: what it shows, and how to make the same tiles again.
    pub fn metadata(&self) -> serde_json::Value {
        let (offset, world) = match self.area {
            Area::World { k } => (self.what.zooms().native as i64 - k as i64, Some(1u64 << k)),
            Area::Bbox { .. } => (0, None),
        };
        let tile_url = format!(
            "/tiles/{}/{{z+{offset}}}/{{x}}/{{y}}.{}{}",
            self.what.id(),
            self.format.ext(),
            self.query_suffix()
        );
        let (name, description, attribution, textile) = match &self.what {
            Subject::Texture { tex, params, .. } => {
                let c = &tex.config;
                let description =
                    format!("textile texture '{}' ({}), exported by {}", c.id, params.name(), engine_version());
                let textile = json!({
                    "texture": c.id,
                    "mode": params.name(),
                    "parameters": params.canonical(),
                    "query": self.query,
                    "world": world,
                    "zoom_offset": offset,
                    "engine": engine_version(),
                    "analysis": tex.file_hash(),
                    "tile_url": tile_url,
                });
                (&c.name, description, &c.attribution, textile)
            }
            // A landscape's identity is its id and the hash of its job (configuration, splat
            // image, seed, period, map, and every layer's analysis, parameters and maps), so that
            // parts of another version of it are refused by the merge.
            Subject::Landscape(job) => {
                let l = &job.land.config;
                let layers: Vec<&str> = job.land.layers.iter().map(|y| y.tex.config.id.as_str()).collect();
                let analyses: Vec<Option<&str>> = job.land.layers.iter().map(|y| y.tex.file_hash()).collect();
                let description =
                    format!("textile landscape '{}' of {}, exported by {}", l.id, layers.join(", "), engine_version());
                let textile = json!({
                    "texture": l.id,
                    "landscape": l.id,
                    "mode": "landscape",
                    "parameters": job.identity(),
                    "layers": layers,
                    "query": self.query,
                    "world": world,
                    "zoom_offset": offset,
                    "engine": engine_version(),
                    "analysis": analyses,
                    "tile_url": tile_url,
                });
                (&l.name, description, &l.attribution, textile)
            }
        };
        json!({
            "name": name,
            "description": description,
            "attribution": attribution,
            "type": "baselayer",
            "format": self.format.ext(),
            "version": engine_version(),
            "minzoom": self.zooms.0,
            "maxzoom": self.zooms.1,
            "bounds": self.bounds(),
            "textile": textile,
        })
    }
}

/// What an export did.
#[derive(Debug, Clone, Copy)]
pub struct Report {
    /// Tiles written.
    pub tiles: u64,
    /// Bytes of the archive.
    pub bytes: u64,
    /// Seconds.
    pub secs: f64,
}

/// Which share of an export's tiles a process renders: shard `index` of `count` (0-based), a
/// contiguous range of the tiles in ascending tile id (the Hilbert order within each zoom), so
/// that the parts concatenate into the archive's sequence.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// This shard, `0..count`.
    pub index: u64,
    /// Shards in all.
    pub count: u64,
}

impl Shard {
    /// Parse `I/N` (`0 ≤ I < N`, as Kubernetes' `JOB_COMPLETION_INDEX` counts).
    pub fn parse(s: &str) -> Result<Shard, String> {
        let bad = || format!("--shard '{s}' must be I/N with 0 ≤ I < N (0-based, like JOB_COMPLETION_INDEX)");
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let (index, count) = (i.trim().parse::<u64>().map_err(|_| bad())?, n.trim().parse::<u64>().map_err(|_| bad())?);
        if count == 0 || index >= count || count > 1 << 20 {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }

    /// Its range of `total` tiles: `[index·total/count, (index+1)·total/count)`.
    pub fn range(self, total: u64) -> (u64, u64) {
        let at = |i: u64| ((i as u128 * total as u128) / self.count as u128) as u64;
        (at(self.index), at(self.index + 1))
    }
}

/// The hidden part file a whole export renders into beside its archive (kept across an
/// interruption: the export resumes from it).
fn own_part(output: &Path) -> std::path::PathBuf {
    let name = output.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    output.with_file_name(format!(".{name}.part"))
}

/// Run an export to `output` (`.pmtiles` or `.mbtiles`): its tiles rendered into a part file
/// beside it (resumed if an earlier run was interrupted), then laid into the archive.
pub fn run(plan: &Plan, output: &Path) -> Result<Report, String> {
    let started = std::time::Instant::now();
    let ext = output.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    if !matches!(ext.as_str(), "pmtiles" | "mbtiles") {
        return Err(format!("{}: the archive must end in .pmtiles or .mbtiles", output.display()));
    }
    let part = own_part(output);
    merge::check_output(std::slice::from_ref(&part), output, true)?;
    render_part(plan, Shard { index: 0, count: 1 }, &part)?;
    let r = merge::merge(std::slice::from_ref(&part), output, true)?;
    let _ = std::fs::remove_file(&part);
    Ok(Report { secs: started.elapsed().as_secs_f64(), ..r })
}

/// Render shard `shard` of an export into the part file `output` (resumed from its checkpoint
/// if an earlier run with the same arguments was interrupted; nothing to do if it is complete).
pub fn render_part(plan: &Plan, shard: Shard, output: &Path) -> Result<Report, String> {
    let started = std::time::Instant::now();
    let entries = plan.entries();
    let total = entries.len() as u64;
    let (start, end) = shard.range(total);
    let header = part::Header {
        archive: plan.metadata(),
        total,
        layout: plan.layout(),
        shard: (shard.index, shard.count),
        range: (start, end),
    };
    let Some(mut w) = part::Writer::open(output, &header)? else {
        eprintln!("{}: already complete", output.display());
        return Ok(Report { tiles: 0, bytes: 0, secs: 0.0 });
    };
    let mine = &entries[start as usize..end as usize];
    let done = w.done() as usize;
    if done > 0 {
        eprintln!("{}: resuming after {done} of {} tiles", output.display(), mine.len());
    }
    let label = if shard.count > 1 { format!("shard {}/{}", shard.index, shard.count) } else { "export".into() };
    let progress = Progress::new(&label, mine.len() as u64, done as u64);
    let pyramid = Pyramid::new(LEVEL_CACHE);
    let chunk = CHUNK_PER_THREAD * rayon::current_num_threads().max(1);
    for part in mine[done..].chunks(chunk) {
        let bytes: Vec<Result<Vec<u8>, String>> = part
            .par_iter()
            .map(|e| {
                let picture = plan.what.picture(Target::Tile(e.tile));
                picture.bytes(&pyramid, &textile_core::Cancel::default()).map_err(|err| err.message)
            })
            .collect();
        for (e, b) in part.iter().zip(bytes) {
            w.add(e, &b?)?;
        }
        w.checkpoint()?;
        progress.advance(part.len() as u64);
    }
    progress.finish();
    w.finish()?;
    let bytes = std::fs::metadata(output).map(|m| m.len()).unwrap_or(0);
    Ok(Report { tiles: (mine.len() - done) as u64, bytes, secs: started.elapsed().as_secs_f64() })
}

/// Progress of a rendering: a bar on a terminal; elsewhere (a container's log) a line every
/// [`Progress::EVERY`] with tiles done of total, rate and time left.
struct Progress {
    bar: ProgressBar,
    label: String,
    total: u64,
    first: u64,
    done: std::sync::atomic::AtomicU64,
    started: std::time::Instant,
    last_line: std::sync::Mutex<std::time::Instant>,
    lines: bool,
}

impl Progress {
    const EVERY: std::time::Duration = std::time::Duration::from_secs(10);

    fn new(label: &str, total: u64, done: u64) -> Progress {
        let lines = !std::io::IsTerminal::is_terminal(&std::io::stderr());
        let bar = if lines { ProgressBar::hidden() } else { ProgressBar::new(total) };
        let template = format!("{{spinner}} {label} [{{bar:30}}] {{pos}}/{{len}} tiles ({{per_sec}}, {{eta}} left)");
        if let Ok(s) = ProgressStyle::with_template(&template) {
            bar.set_style(s.progress_chars("=> "));
        }
        bar.set_position(done);
        let now = std::time::Instant::now();
        Progress {
            bar,
            label: label.to_string(),
            total,
            first: done,
            done: done.into(),
            started: now,
            last_line: std::sync::Mutex::new(now),
            lines,
        }
    }

    fn line(&self) -> String {
        let done = self.done.load(std::sync::atomic::Ordering::Relaxed);
        let secs = self.started.elapsed().as_secs_f64().max(1e-9);
        let rate = (done - self.first) as f64 / secs;
        let eta = if rate > 0.0 { format!("{:.0} s left", (self.total - done) as f64 / rate) } else { "-".into() };
        let pct = 100.0 * done as f64 / self.total.max(1) as f64;
        format!("{}: {done}/{} tiles ({pct:.1} %), {rate:.1} tiles/s, {eta}", self.label, self.total)
    }

    fn advance(&self, n: u64) {
        self.done.fetch_add(n, std::sync::atomic::Ordering::Relaxed);
        self.bar.inc(n);
        if self.lines {
            let mut last = self.last_line.lock().unwrap_or_else(|e| e.into_inner());
            if last.elapsed() >= Self::EVERY {
                *last = std::time::Instant::now();
                eprintln!("{}", self.line());
            }
        }
    }

    fn finish(&self) {
        self.bar.finish_and_clear();
        if self.lines {
            eprintln!("{}", self.line());
        }
    }
}
