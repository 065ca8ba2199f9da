//! The one-shot commands: `analyze` (with a progress bar), `render` (a tile or window to an
//! image file, for scripts) and `info` (an analysis file's header).

use std::path::Path;
use std::sync::{Arc, Mutex};

use indicatif::{ProgressBar, ProgressStyle};
use textile_core::{Analysis, Exemplar, ExemplarOptions, Progress, Randomness, SynthParams};

use crate::cli::{AnalyzeArgs, InfoArgs, RenderArgs};
use crate::config::{Config, Overrides};
use crate::encode::{encode, Format};
use textile_core::Pyramid;

use crate::render::{render_tile, render_window};
use crate::serve::CliResult;
use crate::textures::{exemplar_bytes, load_registry, Texture};
use crate::tile_request::{RenderParams, TileSpec, WindowSpec, COORD_MAX, COORD_MIN, MAX_WINDOW_SIDE, TILE_SIZE};

struct Bar(Mutex<Option<ProgressBar>>);

impl Progress for Bar {
    fn step(&self, done: u32, total: u32, what: &str) {
        let mut g = self.0.lock().unwrap_or_else(|e| e.into_inner());
        let bar = g.get_or_insert_with(|| {
            let b = ProgressBar::new(total as u64);
            if let Ok(s) = ProgressStyle::with_template("{spinner} analysing [{bar:30}] {pos}/{len} {msg} ({elapsed})")
            {
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

fn read_exemplar(path: &Path, opts: &ExemplarOptions) -> Result<Exemplar, Box<dyn std::error::Error>> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    Ok(Exemplar::from_bytes(&bytes, opts).map_err(|e| format!("{}: {e}", path.display()))?)
}

/// `textile analyze EXEMPLAR -o FILE`.
pub fn analyze(a: AnalyzeArgs) -> CliResult {
    let toroidal = match a.toroidal.as_str() {
        "true" => Some(true),
        "false" => Some(false),
        _ => None,
    };
    let ex = read_exemplar(&a.exemplar, &ExemplarOptions { max_input_side: a.max_side, toroidal })?;
    let t = std::time::Instant::now();
    let an = Analysis::build(&ex, &Bar(Mutex::new(None)));
    an.save(&a.output)?;
    println!(
        "analysed {} ({}x{} → {}x{}, toroidal {}) in {:.2}s → {} (id {})",
        a.exemplar.display(),
        ex.preparation.input_width,
        ex.preparation.input_height,
        ex.side,
        ex.side,
        ex.toroidal,
        t.elapsed().as_secs_f64(),
        a.output.display(),
        an.header.id
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
    println!("format version:    {}", textile_core::analysis_file::FORMAT_VERSION);
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
    Ok(())
}

/// `textile render`.
pub fn render(a: RenderArgs) -> CliResult {
    let tex: Arc<Texture> = if let Some(path) = &a.exemplar {
        let ex = read_exemplar(path, &ExemplarOptions::default())?;
        let an = Analysis::build(&ex, &textile_core::NoProgress);
        Arc::new(texture_from(an))
    } else {
        let id = a.texture.clone().unwrap_or_default();
        let overrides = Overrides { data_dir: a.config.data_dir.clone(), ..Default::default() };
        let cfg = Config::load(a.config.config.as_deref(), &overrides)?;
        let mut only = cfg.clone();
        only.textures.retain(|t| t.id == id);
        if only.textures.is_empty() {
            let ids: Vec<_> = cfg.textures.iter().map(|t| t.id.as_str()).collect();
            return Err(format!("no texture '{id}'; configured: {}", ids.join(", ")).into());
        }
        let _ = exemplar_bytes(&only, &only.textures[0])?;
        let reg = load_registry(&only, &|s| eprintln!("{s}"), &textile_core::NoProgress)?;
        reg.list[0].clone()
    };
    let mut synth = tex.defaults.clone();
    if let Some(s) = a.seed {
        synth.seed = s;
    }
    if let Some(r) = &a.randomness {
        synth.randomness = Randomness::parse(r)?;
    }
    if let Some(w) = a.world {
        if !w.is_power_of_two() || w > 1 << 31 {
            return Err("--world must be a power of two up to 2^31".into());
        }
        synth.period = Some(w as i64 * TILE_SIZE);
    }
    if let Some(p) = a.passes {
        synth.passes = p;
    }
    if let Some(k) = &a.kappa {
        synth.kappa = SynthParams::parse_kappa(k)?;
    }
    synth.validate_for(&tex.analysis)?;
    let z = a.z.unwrap_or(tex.native_zoom());
    if z > tex.max_zoom() {
        return Err(format!("--z {z} is outside 0..={}", tex.max_zoom()).into());
    }
    let fmt = a
        .output
        .extension()
        .and_then(|e| e.to_str())
        .and_then(Format::from_ext)
        .ok_or("output must end in .png, .jpg, .jpeg or .webp")?;
    let p = if a.mode == "mosaic" {
        let m = textile_core::MosaicParams {
            seed: synth.seed,
            period: synth.period,
            iterations: a.iterations.unwrap_or(10),
            smoothing: a.smoothing.unwrap_or(3),
            ..Default::default()
        };
        m.validate_for(&tex.analysis)?;
        RenderParams::Mosaic(m)
    } else {
        RenderParams::Synth(synth)
    };
    let img = if let Some(win) = &a.window {
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
        render_window(&Pyramid::off(), &tex, &p, &WindowSpec { z, x, y, w, h, format: fmt })?.image
    } else {
        let (x, y) = (a.x.unwrap_or(0), a.y.unwrap_or(0));
        if !(COORD_MIN..=COORD_MAX).contains(&x) || !(COORD_MIN..=COORD_MAX).contains(&y) {
            return Err("--x and --y must be in [-2^31, 2^31-1]".into());
        }
        render_tile(&Pyramid::off(), &tex, &p, &TileSpec { z, x, y, scale: 1, format: fmt })?.image
    };
    let bytes = encode(&img.pixels, img.width, img.height, fmt, p.effort())?;
    write_atomic(&a.output, &bytes)?;
    println!("wrote {} ({}x{})", a.output.display(), img.width, img.height);
    Ok(())
}

fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let tmp = path.with_extension(format!("tmp-{}", std::process::id()));
    std::fs::write(&tmp, bytes)?;
    std::fs::rename(&tmp, path).inspect_err(|_| {
        let _ = std::fs::remove_file(&tmp);
    })
}

fn texture_from(an: Analysis) -> Texture {
    let file_hash = an.file_hash();
    Texture {
        config: crate::config::TextureConfig {
            id: "exemplar".into(),
            name: "exemplar".into(),
            exemplar: String::new(),
            toroidal: crate::config::Toroidal::Auto,
            default_mode: "synth".into(),
            default_seed: 0,
            default_randomness: String::new(),
            kappa: None,
            attribution: String::new(),
        },
        analysis: Arc::new(an),
        file_hash,
        exemplar_png: Vec::new(),
        defaults: SynthParams::default(),
    }
}
