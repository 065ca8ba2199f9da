//! The computation-ratio study of Wei & Levoy 2003 (their Figures 4, 8 and 9) on textile's engine:
//! request traces fed through per-sample queries ([`textile_core::samples`]) and the pyramidal
//! cache, printing for each the **computation ratio** (pixels computed at all levels ÷ samples
//! requested; a pixel counts once per level however many correction subpasses touched it) and
//! the time per sample, over level-cache sizes from 16 KiB to 256 MiB. Markdown tables on stdout.
//!
//! `cargo bench -p textile-core --bench samples` (about two minutes on two cores);
//! `-- --quick` for a shorter run with fewer cache sizes.

use std::path::PathBuf;
use std::time::Instant;

use textile_core::samples::camera::GroundCamera;
use textile_core::samples::{self, Footprint, Texel};
use textile_core::{
    Analysis, Defaults, Exemplar, ExemplarOptions, ModeParams, NoProgress, ParamReader, Pyramid, Rect, Source, View,
};

const KIB: u64 = 1 << 10;
const MIB: u64 = 1 << 20;

/// splitmix64: a deterministic stream of trace coordinates.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: i64) -> i64 {
        (self.next() % n as u64) as i64
    }
}

struct Setup {
    ex: Exemplar,
    an: Analysis,
}

impl Setup {
    fn new() -> Self {
        let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../config/exemplars/gravel.png");
        let bytes = std::fs::read(&path).expect("embedded gravel");
        let ex = Exemplar::from_bytes(&bytes, &ExemplarOptions::default()).expect("exemplar");
        let an = Analysis::build(&ex, &NoProgress);
        Setup { ex, an }
    }
    fn src(&self) -> Source<'_> {
        Source::new(&self.ex, &self.an)
    }
    fn params(&self) -> ModeParams {
        let src = self.src();
        Defaults::builtin(&src)
            .request(&src, ParamReader::request([("mode", "synth")]).expect("query"))
            .expect("params")
    }
}

/// What a trace cost: pixels computed, samples requested, seconds.
#[derive(Default, Clone, Copy)]
struct Cost {
    computed: u64,
    samples: u64,
    secs: f64,
}

impl Cost {
    fn ratio(&self) -> f64 {
        self.computed as f64 / self.samples.max(1) as f64
    }
    fn us_per_sample(&self) -> f64 {
        self.secs * 1e6 / self.samples.max(1) as f64
    }
    fn add(&mut self, computed: u64, samples: u64) {
        self.computed += computed;
        self.samples += samples;
    }
}

/// Texel batches, one query each, through one cache.
fn run_texels(s: &Setup, cache: &Pyramid, batches: &[Vec<Texel>]) -> Cost {
    let (p, src) = (s.params(), s.src());
    let t = Instant::now();
    let mut c = Cost::default();
    for b in batches {
        let r = samples::texels(&p, &src, cache, b).expect("texels");
        c.add(r.synthesized, b.len() as u64);
    }
    c.secs = t.elapsed().as_secs_f64();
    c
}

/// Camera frames, one query per frame, through one cache.
fn run_frames(s: &Setup, cache: &Pyramid, frames: &[Vec<Footprint>]) -> Vec<Cost> {
    let (p, src) = (s.params(), s.src());
    frames
        .iter()
        .map(|f| {
            let t = Instant::now();
            let r = samples::footprints(&p, &src, cache, f, s.an.levels()).expect("footprints");
            Cost { computed: r.synthesized, samples: f.len() as u64, secs: t.elapsed().as_secs_f64() }
        })
        .collect()
}

fn native(x: i64, y: i64) -> Texel {
    Texel { x, y, zoom_out: 0 }
}

/// Dart-throwing Poisson-disk points with spacing `r` in a `side²` square (a grid of cells
/// of side r/√2 holds at most one point; `tries` darts).
fn poisson(rng: &mut Rng, side: i64, r: i64, tries: usize) -> Vec<Texel> {
    let cell = ((r as f64) / std::f64::consts::SQRT_2).floor().max(1.0) as i64;
    let n = side / cell + 1;
    let mut grid: Vec<Option<(i64, i64)>> = vec![None; (n * n) as usize];
    let mut out = Vec::new();
    for _ in 0..tries {
        let (x, y) = (rng.below(side), rng.below(side));
        let (cx, cy) = (x / cell, y / cell);
        let near = (-2..=2).flat_map(|dy| (-2..=2).map(move |dx| (cx + dx, cy + dy))).any(|(i, j)| {
            (0..n).contains(&i)
                && (0..n).contains(&j)
                && grid[(j * n + i) as usize].is_some_and(|(px, py)| (px - x).pow(2) + (py - y).pow(2) < r * r)
        });
        if !near {
            grid[(cy * n + cx) as usize] = Some((x, y));
            out.push(native(x, y));
        }
    }
    out
}

/// The 512² area rasterized in `t × t` tiles, row-major; each tile one query (scanline within).
fn tiled(t: i64) -> Vec<Vec<Texel>> {
    let mut out = Vec::new();
    for ty in (0..512).step_by(t as usize) {
        for tx in (0..512).step_by(t as usize) {
            out.push((ty..ty + t).flat_map(|y| (tx..tx + t).map(move |x| native(x, y))).collect());
        }
    }
    out
}

fn camera() -> GroundCamera {
    GroundCamera { pitch: 25.0, ..GroundCamera::new(5000.0, 7000.0, 48.0, 512, 512) }
}

fn frame(c: &GroundCamera) -> Vec<Footprint> {
    c.footprints().into_iter().flatten().collect()
}

fn size_label(b: u64) -> String {
    if b >= MIB {
        format!("{} MiB", b / MIB)
    } else {
        format!("{} KiB", b / KIB)
    }
}

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let s = Setup::new();
    let sizes: Vec<u64> = if quick {
        vec![16 * KIB, MIB, 64 * MIB]
    } else {
        vec![16 * KIB, 64 * KIB, 256 * KIB, MIB, 4 * MIB, 16 * MIB, 64 * MIB, 256 * MIB]
    };
    println!(
        "# Computation ratio (Wei & Levoy 2003, Figures 4, 8, 9) — embedded gravel 128², mode=synth defaults, {} rayon threads\n",
        rayon::current_num_threads()
    );

    // Isolated samples: each far from the others, cold.
    let mut rng = Rng(1);
    let singles: Vec<Texel> = (0..200).map(|i| native(i * 100_000 + rng.below(1000), rng.below(1 << 30))).collect();
    let mut one = Cost::default();
    let t = Instant::now();
    for p in &singles {
        let c = run_texels(&s, &Pyramid::new(64 * MIB), &[vec![*p]]);
        one.add(c.computed, c.samples);
    }
    one.secs = t.elapsed().as_secs_f64();
    println!("## One isolated sample (cold, 200 of them)\n");
    println!("| computed per sample | time per sample | target |\n|---|---|---|");
    println!("| {:.0} | {:.3} ms | ≤ 2 ms |\n", one.ratio(), one.us_per_sample() / 1000.0);

    // 65 536 random samples in a 4096² area, one batch, cold.
    let mut rng = Rng(2);
    let random: Vec<Texel> = (0..65_536).map(|_| native(rng.below(4096), rng.below(4096))).collect();
    let c = run_texels(&s, &Pyramid::new(64 * MIB), std::slice::from_ref(&random));
    println!("## 65 536 uniform random samples in a 4096² area (one batch, cold, 64 MiB cache)\n");
    println!("| computed per sample | total time | target |\n|---|---|---|");
    println!("| {:.2} | {:.2} s | ≤ 1 s |\n", c.ratio(), c.secs);

    // Patterns × cache sizes.
    let mut rng = Rng(3);
    let disk = poisson(&mut rng, 1024, 16, 20_000);
    let circle: Vec<Texel> = {
        let mut v: Vec<Texel> = (0..4096)
            .map(|i| {
                let a = i as f64 / 4096.0 * std::f64::consts::TAU;
                native((512.0 + 400.0 * a.cos()).round() as i64, (512.0 + 400.0 * a.sin()).round() as i64)
            })
            .collect();
        v.dedup();
        v
    };
    let one_by_one = |v: &[Texel]| v.iter().map(|t| vec![*t]).collect::<Vec<_>>();
    let cam = camera();
    let standing = vec![frame(&cam)];
    let moving: Vec<Vec<Footprint>> = (0..16).map(|k| frame(&cam.forward(32.0 * k as f64))).collect();
    println!("## Request patterns × level-cache size: computation ratio (µs per sample)\n");
    println!(
        "Poisson disk: {} points, spacing 16, in 1024², asked one at a time; circle: {} points of a radius-400 circle, one at a time; tiles t×t: a 512² area rasterized in t×t tiles, one query per tile; perspective: 512² screen over the plane (48 texels up, 25° pitch, 60° lens), {} ground samples per frame, trilinear; moving forward: 16 frames 32 texels apart, figures of frames 2–16.\n",
        disk.len(),
        circle.len(),
        standing[0].len()
    );
    let mut header = "| pattern |".to_string();
    let mut rule = "|---|".to_string();
    for &b in &sizes {
        header += &format!(" {} |", size_label(b));
        rule += "---|";
    }
    println!("{header}\n{rule}");
    let row = |name: &str, f: &dyn Fn(&Pyramid) -> Cost| {
        let mut line = format!("| {name} |");
        for &b in &sizes {
            let c = f(&Pyramid::new(b));
            line += &format!(" {:.2} ({:.1}) |", c.ratio(), c.us_per_sample());
        }
        println!("{line}");
    };
    row("Poisson disk", &|p| run_texels(&s, p, &one_by_one(&disk)));
    row("circle", &|p| run_texels(&s, p, &one_by_one(&circle)));
    let tile_sizes: &[i64] = if quick { &[8, 64] } else { &[4, 16, 64, 256] };
    for &t in tile_sizes {
        let batches = tiled(t);
        row(&format!("tiles {t}×{t}"), &|p| run_texels(&s, p, &batches));
    }
    row("perspective, standing", &|p| run_frames(&s, p, &standing)[0]);
    row("perspective, moving forward", &|p| {
        let all = run_frames(&s, p, &moving);
        all[1..].iter().fold(Cost::default(), |a, c| Cost {
            computed: a.computed + c.computed,
            samples: a.samples + c.samples,
            secs: a.secs + c.secs,
        })
    });

    // Tiled rasterization over tile sizes (Figure 8), 64 MiB cache and no cache.
    println!("\n## Tiled rasterization of a 512² area: tile size (one query per tile)\n");
    println!(
        "| tile | ratio, 64 MiB cache | µs/sample | ratio, no shared cache (each tile alone) |\n|---|---|---|---|"
    );
    let sides: &[i64] = if quick { &[1, 8, 64, 512] } else { &[1, 2, 4, 8, 16, 32, 64, 128, 256, 512] };
    for &t in sides {
        let batches = tiled(t);
        let warm = run_texels(&s, &Pyramid::new(64 * MIB), &batches);
        // Without sharing between tiles: the cold cost of up to 64 of them, spread over the area,
        // each in a cache of its own (its samples still share their cones).
        let step = (batches.len() / 64).max(1);
        let (comp, n) = batches.iter().step_by(step).take(64).fold((0u64, 0u64), |(c, n), b| {
            let r = samples::texels(&s.params(), &s.src(), &Pyramid::new(64 * MIB), b).expect("tile");
            (c + r.synthesized, n + b.len() as u64)
        });
        let alone = format!("{:.2}", comp as f64 / n as f64);
        println!("| {t}×{t} | {:.3} | {:.2} | {alone} |", warm.ratio(), warm.us_per_sample());
    }

    // A cold perspective frame against the tiles covering the same texels.
    println!("\n## A cold 512² perspective frame against the tiles that cover the same texels\n");
    let f = frame(&cam);
    let frame_cost = run_frames(&s, &Pyramid::new(64 * MIB), std::slice::from_ref(&f))[0];
    let taps = samples::filter::taps(&f, s.an.levels()).expect("taps");
    let mut tiles: Vec<(u32, i64, i64)> = taps
        .iter()
        .flat_map(|t| t.iter().map(|(x, _)| (x.zoom_out, x.x.div_euclid(256), x.y.div_euclid(256))).collect::<Vec<_>>())
        .collect();
    tiles.sort_unstable();
    tiles.dedup();
    let (p, src) = (s.params(), s.src());
    let cache = Pyramid::new(64 * MIB);
    let t = Instant::now();
    let mut computed = 0;
    for &(k, tx, ty) in &tiles {
        computed +=
            p.render(&src, &cache, View::out(k, Rect::new(256 * tx, 256 * ty, 256, 256))).expect("tile").synthesized;
    }
    let tile_secs = t.elapsed().as_secs_f64();
    println!("| | time | computed pixels |\n|---|---|---|");
    println!("| frame via samples ({} samples) | {:.3} s | {} |", f.len(), frame_cost.secs, frame_cost.computed);
    println!(
        "| the {} tiles covering its texels (shared 64 MiB cache) | {:.3} s | {computed} |",
        tiles.len(),
        tile_secs
    );
    println!("| ratio frame ÷ tiles (target ≤ 4) | {:.2} | |", frame_cost.secs / tile_secs);
}
