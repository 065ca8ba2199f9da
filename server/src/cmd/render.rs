//! `textile render`: a tile, a window, a perspective camera view (through per-sample queries)
//! or a picture of what a mode prepared (`--sheet`), to an image file; `--list-params` lists
//! every mode's parameters.

use std::path::Path;
use std::sync::Arc;

use base64::Engine;
use textile_core::files::write_atomic;
use textile_core::maps::MapChoice;
use textile_core::modes::params::{Scope, COMMON};
use textile_core::samples::{self, camera::GroundCamera, Footprint};
use textile_core::{Analysis, Cancel, ModeParams, ParamReader, Pyramid};

use super::args::{CliResult, RenderArgs};
use super::{configured_landscape, configured_texture, output_format, param_pairs};
use crate::config::TextureConfig;
use crate::encode::{encode, Effort, Format};
use crate::output::Output;
use crate::pipeline::landscape::{LandscapeJob, LandscapeMap};
use crate::pipeline::{ImageJob, Target};
use crate::request::{TileSpec, WindowSpec, COORD_MAX, COORD_MIN, MAX_WINDOW_SIDE};
use crate::scene::model::Model;
use crate::textures::{Landscape, Served, Texture};

/// `textile render --sheet`: a picture of what the mode prepared for the texture.
fn sheet(tex: &Texture, params: &ModeParams, output: &Path) -> CliResult {
    let format = output_format(output)?;
    let Some(img) = params.sheet(&tex.source()) else {
        return Err(format!("--sheet: mode={} prepares nothing to draw", params.name()).into());
    };
    let img = img?;
    write_atomic(output, &encode(&img.pixels, img.width, img.height, format, Effort::Tight)?)?;
    let what: Vec<String> = tex
        .prepared
        .all()
        .iter()
        .filter(|(m, _)| *m == params.name())
        .map(|(_, s)| format!("{} ({})", s.what(), s.summary()))
        .collect();
    println!("wrote {} ({}x{}): {}", output.display(), img.width, img.height, what.join(", "));
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
pub fn run(a: RenderArgs) -> CliResult {
    if a.list_params {
        return match list_params() {
            Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(e.into()),
            _ => Ok(()),
        };
    }
    let output = a.output.clone().ok_or("--output is required")?;
    if a.exemplar.is_none() {
        if let Some(land) = configured_landscape(&a.config, a.texture.as_deref().unwrap_or_default())? {
            return render_landscape(&a, land, &output);
        }
    }
    let tex: Arc<Texture> = if let Some(path) = &a.exemplar {
        let ex = a.recipe.make(path)?;
        let an = Analysis::try_build_with(&ex, a.recipe.index, &textile_core::NoProgress, &Cancel::new())?;
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
    // A GLB reads its own `relief` (as the served one does), the image its mode's parameters.
    let glb = output.extension().is_some_and(|e| e == "glb");
    let model_pairs = pairs.clone();
    if glb {
        pairs.retain(|(k, _)| k != "relief");
    }
    let params = tex.defaults.request(&tex.source(), ParamReader::texture(pairs)?)?;
    // A texture made from --exemplar has no data directory: what its mode prepares is made once
    // here, in memory, not again by every window the mode renders (a camera view renders many).
    if let (Some(_), Some(step)) = (&a.exemplar, params.info().preparation) {
        let input = textile_core::prepare::Input::exemplar(&tex.exemplar);
        step.run(&tex.prepared, &input, None, false, &|| false, &textile_core::NoProgress, &Cancel::new())?;
    }
    let map = crate::request::parse_map(&tex, &a.map, output_format(&output).unwrap_or(crate::encode::Format::Png))?;
    if map != MapChoice::Albedo && (a.sheet || a.camera.is_some()) {
        return Err("--map applies to tiles and windows (not --sheet or --camera)".into());
    }
    if a.sheet {
        return sheet(&tex, &params, &output);
    }
    let z = a.z.unwrap_or(tex.native_zoom());
    if z > tex.max_zoom() {
        return Err(format!("--z {z} is outside 0..={}", tex.max_zoom()).into());
    }
    if let Some(cam) = &a.camera {
        return render_camera(&tex, &params, cam, &a.at, &a.size, &output);
    }
    if glb {
        if a.window.is_some() || a.sheet || a.camera.is_some() || map != MapChoice::Albedo {
            return Err("a .glb output is a tile's model: --x, --y, --z and --param only".into());
        }
        let (x, y) = (a.x.unwrap_or(0), a.y.unwrap_or(0));
        if !(COORD_MIN..=COORD_MAX).contains(&x) || !(COORD_MIN..=COORD_MAX).contains(&y) {
            return Err("--x and --y must be in [-2^31, 2^31-1]".into());
        }
        let spec = TileSpec { z, x, y, scale: 1, format: Format::Png };
        let model = Model::read(Served::Texture(tex), spec, 1, ParamReader::texture(model_pairs)?, Default::default())?;
        let bytes = Output::Glb(model).bytes(&Pyramid::off())?;
        write_atomic(&output, &bytes)?;
        println!("wrote {} (GLB of tile {z}/{}/{}, {} bytes)", output.display(), spec.x, spec.y, bytes.len());
        return Ok(());
    }
    let format = output_format(&output)?;
    let target = target_of(&a, z, format)?;
    let (bytes, r) = ImageJob { tex, params, target, map, dem: None }.bytes(&Pyramid::off())?;
    write_atomic(&output, &bytes)?;
    println!("wrote {} ({}x{})", output.display(), r.image.width, r.image.height);
    Ok(())
}

/// The tile (`--x`, `--y`) or window (`--window X,Y,W,H`) at zoom `z` the flags ask for.
fn target_of(a: &RenderArgs, z: u32, format: Format) -> Result<Target, Box<dyn std::error::Error>> {
    if let Some(win) = &a.window {
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
        return Ok(Target::Window(WindowSpec { z, x, y, w, h, format }));
    }
    let (x, y) = (a.x.unwrap_or(0), a.y.unwrap_or(0));
    if !(COORD_MIN..=COORD_MAX).contains(&x) || !(COORD_MIN..=COORD_MAX).contains(&y) {
        return Err("--x and --y must be in [-2^31, 2^31-1]".into());
    }
    Ok(Target::Tile(TileSpec { z, x, y, scale: 1, format }))
}

/// `textile render --texture LANDSCAPE`: a tile or window of a landscape, or a tile's model
/// (`.glb`, with `--param relief=…`), the bytes the server serves for it.
fn render_landscape(a: &RenderArgs, land: Arc<Landscape>, output: &Path) -> CliResult {
    let glb = output.extension().is_some_and(|e| e == "glb");
    let relief_only = a.params.iter().all(|p| glb && p.starts_with("relief="));
    if a.sheet || a.camera.is_some() || a.mode.is_some() || !relief_only || a.controls.is_some() {
        return Err("a landscape renders tiles and windows with --seed, --world and --map, and .glb tiles with \
                    --param relief=… too (its layers' parameters are in its configuration)"
            .into());
    }
    let z = a.z.unwrap_or(land.native_zoom);
    if !(land.min_zoom..=land.max_zoom).contains(&z) {
        return Err(format!("--z {z} is outside {}..={}", land.min_zoom, land.max_zoom).into());
    }
    let mut pairs = param_pairs(&a.params, &None, a.seed, a.world)?;
    let levels = Pyramid::new(64 << 20);
    if glb {
        if a.window.is_some() || a.map != "albedo" {
            return Err("a .glb output is a tile's model: --x, --y, --z, --seed, --world and relief only".into());
        }
        let Target::Tile(spec) = target_of(a, z, Format::Png)? else {
            return Err("a .glb output is a tile's model".into());
        };
        let model = Model::read(Served::Landscape(land), spec, 1, ParamReader::request(pairs)?, Default::default())?;
        let bytes = Output::Glb(model).bytes(&levels)?;
        write_atomic(output, &bytes)?;
        println!("wrote {} (GLB of landscape tile {z}/{}/{}, {} bytes)", output.display(), spec.x, spec.y, bytes.len());
        return Ok(());
    }
    let format = output_format(output)?;
    let target = target_of(a, z, format)?;
    pairs.push(("map".into(), a.map.clone()));
    let mut r = ParamReader::request(pairs)?;
    let map = LandscapeMap::read(&land, &mut r, format)?;
    let job = LandscapeJob::new(land, target, map, r)?;
    let bytes = Output::Landscape(job).bytes(&levels)?;
    write_atomic(output, &bytes)?;
    println!("wrote {} (landscape, {} bytes)", output.display(), bytes.len());
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
