//! Development helper: analyse an exemplar and render a window to PNG, printing timings.
//! `cargo run --release -p textile-core --example quick -- EXEMPLAR OUT.png [SIZE] [PARAMS...]`
use std::time::Instant;
use textile_core::*;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let bytes = std::fs::read(&args[1]).expect("read exemplar");
    let size: i64 = args.get(3).map(|s| s.parse().unwrap()).unwrap_or(512);
    let t = Instant::now();
    let ex = Exemplar::from_bytes(&bytes, &ExemplarOptions::default()).unwrap();
    let an = Analysis::build(&ex, &NoProgress);
    eprintln!(
        "analysis {:?} m={} toroidal={} seam={:.2}",
        t.elapsed(),
        an.side(),
        an.header.toroidal,
        ex.preparation.seam_ratio
    );
    let mut p = SynthParams::default();
    for kv in args.iter().skip(4) {
        let (k, v) = kv.split_once('=').unwrap();
        match k {
            "seed" => p.seed = v.parse().unwrap(),
            "r" => p.randomness = Randomness::parse(v).unwrap(),
            "passes" => p.passes = v.parse().unwrap(),
            "kappa" => p.kappa = SynthParams::parse_kappa(v).unwrap(),
            _ => panic!("unknown {k}"),
        }
    }
    let t = Instant::now();
    let img = render(&an, &p, 0, Rect::new(0, 0, size, size)).unwrap();
    eprintln!("render {}x{} {:?}", size, size, t.elapsed());
    for _ in 0..3 {
        let t = Instant::now();
        let _ = render(&an, &p, 0, Rect::new(0, 0, 256, 256)).unwrap();
        eprintln!("256 tile {:?}", t.elapsed());
    }
    image::save_buffer(&args[2], &img.pixels, img.width, img.height, image::ExtendedColorType::Rgb8).unwrap();
}
