//! Analysis cost of degenerate exemplars (issue: no exemplar can starve the service): flat,
//! near-flat, periodic and binary images, whose neighbourhoods are equal or nearly so, against
//! a natural exemplar of the same side. Prints the time of each and its ratio to the natural
//! one (the bound: 2×), and the number of progress steps with the longest gap between two.
//!
//! `cargo bench -p textile-core --bench degenerate [-- SIDE]` (default 256; the natural exemplar
//! is the embedded gravel, resampled).

use std::sync::Mutex;
use std::time::{Duration, Instant};

use textile_core::{Analysis, Cancel, Exemplar, ExemplarOptions, Progress};

/// Records the longest time between two progress reports.
struct Gaps(Mutex<(Instant, Duration, u32)>);

impl Progress for Gaps {
    fn step(&self, _: u32, _: u32, _: &str) {
        let mut g = self.0.lock().unwrap();
        let now = Instant::now();
        g.1 = g.1.max(now - g.0);
        g.0 = now;
        g.2 += 1;
    }
}

/// A small deterministic generator (xorshift).
fn noise(seed: u64) -> impl FnMut() -> u64 {
    let mut z = seed | 1;
    move || {
        z ^= z << 13;
        z ^= z >> 7;
        z ^= z << 17;
        z
    }
}

fn exemplars(side: u32) -> Vec<(&'static str, Exemplar)> {
    let n = side as usize;
    let make = |f: &dyn Fn(usize, usize) -> [u8; 3]| {
        let px: Vec<[u8; 4]> = (0..n * n).map(|i| f(i % n, i / n)).map(|[r, g, b]| [r, g, b, 255]).collect();
        Exemplar::from_rgba(side, side, &px, &ExemplarOptions::default())
    };
    let natural = {
        let bytes = std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/../config/exemplars/gravel.png")).unwrap();
        let img = image::load_from_memory(&bytes).unwrap().to_rgba8();
        let img = image::imageops::resize(&img, side, side, image::imageops::FilterType::Lanczos3);
        let px: Vec<[u8; 4]> = img.pixels().map(|p| p.0).collect();
        Exemplar::from_rgba(side, side, &px, &ExemplarOptions::default())
    };
    let near_flat: Vec<[u8; 3]> = {
        let mut r = noise(1);
        (0..n * n).map(|_| [0; 3].map(|_: u8| (127 + r() % 3) as u8)).collect()
    };
    let binary: Vec<u8> = {
        let mut r = noise(2);
        (0..n * n).map(|_| if r().is_multiple_of(2) { 0 } else { 255 }).collect()
    };
    let colour: Vec<[u8; 3]> = {
        let mut r = noise(3);
        (0..n * n).map(|_| [0; 3].map(|_: u8| (r() % 256) as u8)).collect()
    };
    vec![
        ("natural (gravel)", natural),
        ("all black", make(&|_, _| [0; 3])),
        ("near-flat noise 128 ± 1", make(&|x, y| near_flat[y * n + x])),
        ("checkerboard 1 px", make(&|x, y| [((x + y) % 2 * 255) as u8; 3])),
        ("checkerboard 8 px", make(&|x, y| [((x / 8 + y / 8) % 2 * 255) as u8; 3])),
        ("binary noise", make(&|x, y| [binary[y * n + x]; 3])),
        ("colour noise", make(&|x, y| colour[y * n + x])),
    ]
}

fn main() {
    let side: u32 = std::env::args().skip(1).find(|a| !a.starts_with('-')).and_then(|s| s.parse().ok()).unwrap_or(256);
    println!("| exemplar ({side}²) | spread | analysis s | × natural | steps | longest gap s |");
    println!("|---|---|---|---|---|---|");
    let mut natural = None;
    for (name, ex) in exemplars(side) {
        let gaps = Gaps(Mutex::new((Instant::now(), Duration::ZERO, 0)));
        let t = Instant::now();
        Analysis::try_build(&ex, &gaps, &Cancel::new()).expect("analysis");
        let s = t.elapsed().as_secs_f64();
        let base = *natural.get_or_insert(s);
        let (_, gap, steps) = *gaps.0.lock().unwrap();
        println!("| {name} | {:.2} | {s:.2} | {:.2} | {steps} | {:.2} |", ex.spread(), s / base, gap.as_secs_f64());
    }
}
