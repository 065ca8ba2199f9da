//! Cold synth cost per output pixel for exemplars of several shapes (issue 72): `cargo run
//! --release -p textile-core --example shape_cost -- [WxH …]`, times 40 cold 256² native tiles
//! of the development set's 256² gravel resized to each shape, interleaved over 5 rounds (the
//! median round per shape); run under `valgrind --tool=callgrind --toggle-collect='*render_map*'`
//! with one shape for instruction counts (`TILES=0` for the analysis alone, to subtract).
use textile_core::modes::synth::{render, synthesis_cost, SynthParams};
use textile_core::{Analysis, Exemplar, ExemplarOptions, NoProgress, Rect};

fn main() {
    let path = format!("{}/../../shared/exemplars/gravel_256.png", env!("CARGO_MANIFEST_DIR"));
    let img = image::load_from_memory(&std::fs::read(path).expect("gravel_256.png")).expect("decode").to_rgba8();
    let shapes: Vec<(u32, u32)> = std::env::args()
        .skip(1)
        .filter_map(|a| a.split_once('x').and_then(|(w, h)| Some((w.parse().ok()?, h.parse().ok()?))))
        .collect();
    let shapes = if shapes.is_empty() { vec![(128, 128), (100, 100), (300, 200)] } else { shapes };
    let tiles: i64 =
        std::env::var("TILES").ok().and_then(|v| v.parse().ok()).unwrap_or(if shapes.len() == 1 { 8 } else { 40 });
    let rounds = if shapes.len() == 1 { 1 } else { 5 };
    let p = SynthParams::default();
    let analyses: Vec<Analysis> = shapes
        .iter()
        .map(|&(w, h)| {
            let img = image::imageops::resize(&img, w, h, image::imageops::FilterType::Triangle);
            let px: Vec<[u8; 4]> = img.pixels().map(|p| p.0).collect();
            Analysis::build(&Exemplar::from_rgba(w, h, &px, &ExemplarOptions::default()), &NoProgress)
        })
        .collect();
    let mut times = vec![Vec::new(); shapes.len()];
    for round in 0..rounds {
        for (k, an) in analyses.iter().enumerate() {
            let t = std::time::Instant::now();
            for i in 0..tiles {
                render(an, &p, 0, Rect::new(256 * i, 4096 * (round + 1), 256, 256)).expect("render");
            }
            times[k].push(t.elapsed().as_secs_f64() * 1000.0 / tiles as f64);
        }
    }
    for (k, ((w, h), an)) in shapes.iter().zip(&analyses).enumerate() {
        let mut t = times[k].clone();
        t.sort_by(f64::total_cmp);
        let cost = synthesis_cost(an, &p, an.levels(), Rect::new(0, 0, 262, 262));
        println!(
            "{w}x{h}: levels {}, {cost} px computed per tile, {:.2} ms per cold 256² tile (median of {rounds})",
            an.levels(),
            t[t.len() / 2]
        );
    }
}
