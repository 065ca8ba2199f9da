//! The one-shot commands: `analyze` and `tileable` (with progress bars), `render` (a tile, a window or a
//! perspective camera view through per-sample queries, to an image file, for scripts), `export`
//! (an archive of tiles) and `info` (an analysis file's header).

use std::path::Path;
use std::sync::{Arc, Mutex};

use base64::Engine;
use indicatif::{ProgressBar, ProgressStyle};
use textile_core::modes::params::{Scope, COMMON};
use textile_core::samples::{self, camera::GroundCamera, Footprint};
use textile_core::{Analysis, Cancel, Exemplar, ExemplarOptions, ModeParams, ParamReader, Progress, Pyramid};

use crate::cli::{AnalyzeArgs, CliResult, ConfigArgs, ExportArgs, InfoArgs, RenderArgs, TileableArgs};
use crate::config::{Config, Overrides, TextureConfig};
use crate::encode::{encode, Effort, Format};
use crate::export;
use crate::pipeline::{ImageJob, Target};
use crate::request::{TileSpec, WindowSpec, COORD_MAX, COORD_MIN, MAX_WINDOW_SIDE};
use crate::textures::{exemplar_bytes, load_registry, Texture};
use textile_core::files::write_atomic;

/// A progress bar on the terminal, labelled with what the work is.
struct Bar(Mutex<Option<ProgressBar>>, &'static str);

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
fn toroidal_flag(s: &str) -> Option<bool> {
    match s {
        "true" => Some(true),
        "false" => Some(false),
        _ => None,
    }
}

fn read_exemplar(path: &Path, opts: &ExemplarOptions) -> Result<Exemplar, Box<dyn std::error::Error>> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    Ok(Exemplar::from_bytes(&bytes, opts).map_err(|e| format!("{}: {e}", path.display()))?)
}

/// `textile analyze EXEMPLAR -o FILE`.
pub fn analyze(a: AnalyzeArgs) -> CliResult {
    let toroidal = toroidal_flag(&a.toroidal);
    let ex = read_exemplar(&a.exemplar, &ExemplarOptions { max_input_side: a.max_side, toroidal })?;
    ex.check_not_flat().map_err(|e| format!("{}: {e}", a.exemplar.display()))?;
    let t = std::time::Instant::now();
    let an = Analysis::try_build_with(&ex, a.index, &Bar(Mutex::new(None), "analysing"), &Cancel::new())?;
    an.save(&a.output)?;
    // The umbrella mode's extraction beside it (`FILE.umbrella`), for `textile info` and for
    // a server whose data directory holds both.
    let beside = a.output.with_extension("umbrella");
    if let (_, textile_core::modes::umbrella::store::Source::Computed(Some(e))) =
        textile_core::modes::umbrella::store::load_or_extract(&ex, &beside, true)
    {
        return Err(e.into());
    }
    println!(
        "analysed {} ({}x{} → {}x{}, toroidal {}, {} search) in {:.2}s → {} (id {})",
        a.exemplar.display(),
        ex.preparation.input_width,
        ex.preparation.input_height,
        ex.side,
        ex.side,
        ex.toroidal,
        an.header.index.name(),
        t.elapsed().as_secs_f64(),
        a.output.display(),
        an.header.id
    );
    Ok(())
}

/// `textile tileable EXEMPLAR --size N -o FILE`.
pub fn tileable(a: TileableArgs) -> CliResult {
    use textile_core::tileable::{synthesize, Search, TileableOptions};
    let format = output_format(&a.output)?;
    let toroidal = toroidal_flag(&a.toroidal);
    let ex = read_exemplar(&a.exemplar, &ExemplarOptions { max_input_side: a.max_side, toroidal })?;
    let search = if a.exact { Search::Exact } else { Search::Tsvq { backtrack: a.backtrack } };
    let opts = TileableOptions { size: a.size, seed: a.seed, search };
    let t = std::time::Instant::now();
    let img = synthesize(&ex, &opts, &Bar(Mutex::new(None), "synthesizing"), &Cancel::new())?;
    let bytes = encode(&img.pixels, img.width, img.height, format, Effort::Tight)?;
    write_atomic(&a.output, &bytes)?;
    println!(
        "wrote {} ({}x{}, tileable) from {} ({}x{}, toroidal {}) in {:.2}s, {}",
        a.output.display(),
        a.size,
        a.size,
        a.exemplar.display(),
        ex.side,
        ex.side,
        ex.toroidal,
        t.elapsed().as_secs_f64(),
        if a.exact { "exhaustive search".to_string() } else { format!("TSVQ search, {} leaves", a.backtrack) }
    );
    Ok(())
}

/// `textile info FILE`.
pub fn info(a: InfoArgs) -> CliResult {
    let an = Analysis::load(&a.file)?;
    let h = &an.header;
    println!("file:              {}", a.file.display());
    println!("analysis id:       {}", h.id);
    println!("file hash:         {}", an.file_hash());
    println!("format version:    {}", textile_core::analysis::file::FORMAT_VERSION);
    println!("algorithm version: {}", h.algorithm_version);
    println!(
        "exemplar:          {}x{} (input {}x{}, crop {})",
        h.side, h.side, h.preparation.input_width, h.preparation.input_height, h.preparation.crop_side
    );
    println!(
        "toroidal:          {} ({})",
        h.toroidal,
        if h.preparation.toroidal_forced { "forced" } else { "detected" }
    );
    println!("levels:            {} (native zoom {})", h.levels + 1, h.levels);
    println!("candidate search:  {}", h.index.name());
    // The umbrella mode's extraction: stored beside the file (`FILE.umbrella`) when there is
    // one for this exemplar, else computed from the exemplar the file holds.
    let beside = a.file.with_extension("umbrella");
    let ex = an.exemplar();
    let (stored, from) = match textile_core::modes::umbrella::store::read(&beside) {
        Ok((id, outcome)) if id == textile_core::modes::umbrella::extraction_id(&ex) => {
            (Some(outcome), format!("stored in {}", beside.display()))
        }
        Ok(_) => (None, format!("computed ({} is of another exemplar or extraction version)", beside.display())),
        Err(textile_core::CoreError::Io { .. }) => (None, "computed".to_string()),
        Err(e) => (None, format!("computed ({e})")),
    };
    let outcome = match stored {
        Some(outcome) => textile_core::modes::umbrella::outcome_result(outcome),
        None => textile_core::modes::umbrella::elements(&ex).map(|(el, _)| el),
    };
    match outcome {
        Ok(el) => println!(
            "umbrella elements: {} found, {} bases, mean area {:.0} texels, sizes {:.2}–{:.2} of the mean, orientations ±{}°, foreground {:.0} % ({})",
            el.found,
            el.bases.len(),
            el.mean_area,
            el.scale_spread.0,
            el.scale_spread.1,
            el.orientation_spread,
            100.0 * el.foreground,
            el.segmentation
        ),
        Err(e) => println!("umbrella elements: none ({e})"),
    }
    println!(
        "umbrella source:   {from} (extraction version {})",
        textile_core::modes::umbrella::extract::EXTRACTION_VERSION
    );
    if let Some(l) = h.lattice {
        let (cw, ch) = l.cell(h.side);
        println!("lattice:           {}x{} cells of {cw}x{ch} texels (near-regular)", l.nx, l.ny);
    }
    Ok(())
}

/// The image format an output file's extension names.
fn output_format(output: &Path) -> Result<Format, &'static str> {
    output
        .extension()
        .and_then(|e| e.to_str())
        .and_then(Format::from_ext)
        .ok_or("output must end in .png, .jpg, .jpeg or .webp")
}

/// `textile render --mode umbrella --debug-umbrellas`: the extraction's sheet.
fn debug_umbrellas(tex: &Texture, params: &ModeParams, output: &Path) -> CliResult {
    use textile_core::modes::umbrella::{arrange::Arrangement, elements, sheet::debug_sheet};
    let ModeParams::Umbrella(p) = params else {
        return Err("--debug-umbrellas needs --mode umbrella".into());
    };
    let format = output_format(output)?;
    let (el, id) = elements(&tex.exemplar)?;
    let img = debug_sheet(&el, &Arrangement::new(&el, p, &id));
    write_atomic(output, &encode(&img.pixels, img.width, img.height, format, Effort::Tight)?)?;
    println!(
        "wrote {} ({}x{}): {} bases of {} elements found ({})",
        output.display(),
        img.width,
        img.height,
        el.bases.len(),
        el.found,
        el.segmentation
    );
    Ok(())
}

/// Every mode's parameters, one per line, for `textile render --list-params` (a closed pipe,
/// as with `| head`, ends the listing quietly).
fn list_params() -> std::io::Result<()> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    let line = |out: &mut std::io::StdoutLock, s: &textile_core::ParamSpec, who: &str| {
        let d = s.describe();
        let range = match (d.get("min"), d.get("max"), d.get("values")) {
            (_, _, Some(v)) if v.is_array() => format!("one of {v}"),
            (Some(lo), Some(hi), _) => format!("{lo}..={hi}"),
            _ => String::new(),
        };
        let scope = if s.scope == Scope::Texture { ", texture setting" } else { "" };
        let kind = d["type"].as_str().unwrap_or("");
        writeln!(out, "  {:<12} {who:<8} {kind} {range}{scope}\n               {}", s.name, s.help)
    };
    writeln!(out, "common (--mode, --seed, --world, or --param):")?;
    for s in COMMON {
        line(&mut out, s, "")?;
    }
    for m in textile_core::modes::all() {
        writeln!(out, "mode={} (v{}): {}", m.name, m.version, m.summary)?;
        for s in m.specs {
            line(&mut out, s, m.name)?;
        }
    }
    Ok(())
}

/// `textile render`.
pub fn render(a: RenderArgs) -> CliResult {
    if a.list_params {
        return match list_params() {
            Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(e.into()),
            _ => Ok(()),
        };
    }
    let output = a.output.clone().ok_or("--output is required")?;
    let tex: Arc<Texture> = if let Some(path) = &a.exemplar {
        let toroidal = a.lattice.map(|_| true);
        let mut ex = read_exemplar(path, &ExemplarOptions { toroidal, ..ExemplarOptions::default() })?;
        if let Some([nx, ny]) = a.lattice {
            ex = ex.with_lattice(nx, ny)?;
        }
        let an = Analysis::try_build_with(&ex, a.index, &textile_core::NoProgress, &Cancel::new())?;
        Arc::new(Texture::new(TextureConfig::new("exemplar", &path.display().to_string()), 0, ex, an)?)
    } else {
        configured_texture(&a.config, a.texture.as_deref().unwrap_or_default())?
    };
    // The flags and `--param` pairs are read like a query string, with texture settings allowed.
    let mut pairs = param_pairs(&a.params, &a.mode, a.seed, a.world)?;
    if let Some(file) = &a.controls {
        let text = std::fs::read(file).map_err(|e| format!("--controls {}: {e}", file.display()))?;
        let json: serde_json::Value =
            serde_json::from_slice(&text).map_err(|e| format!("--controls {}: not JSON: {e}", file.display()))?;
        // As a client would send it: compact JSON, base64url.
        let compact = serde_json::to_vec(&json).map_err(|e| e.to_string())?;
        pairs.push(("controls".into(), base64::engine::general_purpose::URL_SAFE_NO_PAD.encode(compact)));
    }
    let params = tex.defaults.request(&tex.source(), ParamReader::texture(pairs)?)?;
    if a.debug_umbrellas {
        return debug_umbrellas(&tex, &params, &output);
    }
    let z = a.z.unwrap_or(tex.native_zoom());
    if z > tex.max_zoom() {
        return Err(format!("--z {z} is outside 0..={}", tex.max_zoom()).into());
    }
    if let Some(cam) = &a.camera {
        return render_camera(&tex, &params, cam, &a.at, &a.size, &output);
    }
    let format = output_format(&output)?;
    let target = if let Some(win) = &a.window {
        let v: Vec<i64> = win
            .split(',')
            .map(|s| s.trim().parse::<i64>())
            .collect::<Result<_, _>>()
            .map_err(|_| "--window must be X,Y,W,H integers")?;
        let [x, y, w, h] = v[..] else {
            return Err("--window must be X,Y,W,H".into());
        };
        if !(1..=MAX_WINDOW_SIDE).contains(&w) || !(1..=MAX_WINDOW_SIDE).contains(&h) {
            return Err(format!("--window width and height must be 1..={MAX_WINDOW_SIDE}").into());
        }
        Target::Window(WindowSpec { z, x, y, w, h, format })
    } else {
        let (x, y) = (a.x.unwrap_or(0), a.y.unwrap_or(0));
        if !(COORD_MIN..=COORD_MAX).contains(&x) || !(COORD_MIN..=COORD_MAX).contains(&y) {
            return Err("--x and --y must be in [-2^31, 2^31-1]".into());
        }
        Target::Tile(TileSpec { z, x, y, scale: 1, format })
    };
    let (bytes, r) = ImageJob { tex, params, target }.bytes(&Pyramid::off())?;
    write_atomic(&output, &bytes)?;
    println!("wrote {} ({}x{})", output.display(), r.image.width, r.image.height);
    Ok(())
}

/// A configured or uploaded texture, loaded (analysed if its analysis is not stored) from the
/// data directory.
fn configured_texture(c: &ConfigArgs, id: &str) -> Result<Arc<Texture>, Box<dyn std::error::Error>> {
    let overrides = Overrides { data_dir: c.data_dir.clone(), ..Default::default() };
    let cfg = crate::uploads::with_stored(&Config::load(c.config.as_deref(), &overrides)?, &|s| eprintln!("{s}"));
    let mut only = cfg.clone();
    only.textures.retain(|t| t.id == id);
    if only.textures.is_empty() {
        let ids: Vec<_> = cfg.textures.iter().map(|t| t.id.as_str()).collect();
        return Err(format!("no texture '{id}'; configured: {}", ids.join(", ")).into());
    }
    let _ = exemplar_bytes(&only, &only.textures[0])?;
    let reg = load_registry(&only, &|s| eprintln!("{s}"))?;
    Ok(reg.list[0].clone())
}

/// The `--param KEY=VALUE` pairs and the flags, as query pairs.
fn param_pairs(
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

/// `textile export`: tiles into a PMTiles or MBTiles archive.
pub fn export(a: ExportArgs) -> CliResult {
    let tex = configured_texture(&a.config, &a.texture)?;
    let pairs = param_pairs(&a.params, &a.mode, a.seed, None)?;
    let bbox = match &a.bbox {
        Some(b) => {
            let v: Vec<u32> = b
                .split(',')
                .map(|s| s.trim().parse::<u32>())
                .collect::<Result<_, _>>()
                .map_err(|_| "--bbox must be X0,Y0,X1,Y1 non-negative integers")?;
            let [x0, y0, x1, y1] = v[..] else {
                return Err("--bbox must be X0,Y0,X1,Y1".into());
            };
            Some((x0, y0, x1, y1))
        }
        None => None,
    };
    let zooms = match &a.zoom {
        Some(z) => {
            let (lo, hi) = z.split_once("..").unwrap_or((z, z));
            let n = |s: &str| s.trim().parse::<u32>().map_err(|_| format!("--zoom '{z}' must be MIN..MAX or Z"));
            Some((n(lo)?, n(hi)?))
        }
        None => None,
    };
    let format = Format::from_ext(&a.format).ok_or("--format must be png, jpg or webp")?;
    let plan = export::Plan::new(tex, pairs, a.world, bbox, zooms, format)?;
    let ext = a.output.extension().and_then(|e| e.to_str()).unwrap_or("");
    if !matches!(ext, "pmtiles" | "mbtiles") {
        return Err(format!("{}: the archive must end in .pmtiles or .mbtiles", a.output.display()).into());
    }
    eprintln!(
        "exporting {} tiles of '{}{}' (archive zooms {}..={}) to {}",
        plan.count(),
        plan.tex.config.id,
        plan.query_suffix(),
        plan.zooms.0,
        plan.zooms.1,
        a.output.display()
    );
    let r = export::run(&plan, &a.output)?;
    println!(
        "wrote {} ({} tiles, {} bytes) in {:.1} s: {:.0} tiles/s",
        a.output.display(),
        r.tiles,
        r.bytes,
        r.secs,
        r.tiles as f64 / r.secs.max(1e-9)
    );
    Ok(())
}

/// Sky above the horizon of a camera view.
const SKY: [u8; 3] = [196, 214, 232];
/// Largest camera image side.
const MAX_CAMERA_SIDE: u32 = 4096;

/// `textile render --camera`: a perspective view of the ground plane, every pixel a filtered
/// per-sample query (the same sampler as `POST /samples`), through one pyramidal cache.
fn render_camera(tex: &Texture, params: &ModeParams, cam: &str, at: &str, size: &str, output: &Path) -> CliResult {
    let nums = |s: &str, n: usize, what: &str| -> Result<Vec<f64>, String> {
        let v: Vec<f64> = s.split(',').map(|t| t.trim().parse::<f64>()).collect::<Result<_, _>>().map_err(|_| what)?;
        if v.len() == n {
            Ok(v)
        } else {
            Err(what.to_string())
        }
    };
    let c = nums(cam, 4, "--camera must be HEIGHT,PITCH,YAW,FOV numbers")?;
    let p = nums(at, 2, "--at must be X,Y numbers")?;
    let (w, h) = size
        .split_once('x')
        .and_then(|(w, h)| Some((w.trim().parse::<u32>().ok()?, h.trim().parse::<u32>().ok()?)))
        .filter(|&(w, h)| (1..=MAX_CAMERA_SIDE).contains(&w) && (1..=MAX_CAMERA_SIDE).contains(&h))
        .ok_or(format!("--size must be WxH with sides 1..={MAX_CAMERA_SIDE}"))?;
    let camera =
        GroundCamera { x: p[0], y: p[1], height: c[0], pitch: c[1], yaw: c[2], fov: c[3], width: w, height_px: h };
    camera.check()?;
    let format = output_format(output)?;
    let started = std::time::Instant::now();
    let view = camera.footprints();
    let ground: Vec<Footprint> = view.iter().flatten().copied().collect();
    let cache = Pyramid::new(64 << 20);
    let max_zoom_out = tex.native_zoom() - tex.min_zoom();
    let s = samples::footprints(params, &tex.source(), &cache, &ground, max_zoom_out)?;
    let mut colors = s.colors.iter();
    let pixels: Vec<u8> =
        view.iter().flat_map(|f| if f.is_some() { *colors.next().unwrap_or(&SKY) } else { SKY }).collect();
    let bytes = encode(&pixels, w, h, format, Effort::Tight)?;
    write_atomic(output, &bytes)?;
    println!(
        "wrote {} ({w}x{h}): {} ground samples in {:.2} s, {} pixels computed ({:.2} per sample, {} windows)",
        output.display(),
        ground.len(),
        started.elapsed().as_secs_f64(),
        s.synthesized,
        s.synthesized as f64 / ground.len().max(1) as f64,
        s.windows
    );
    Ok(())
}
