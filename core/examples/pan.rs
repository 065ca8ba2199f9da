//! Development helper: the computation ratio of a panning sweep of 256² tiles through a
//! pyramidal cache, and timings.
//! `cargo run --release -p textile-core --example pan -- EXEMPLAR [COLS ROWS CACHE_MIB]`
use std::time::Instant;
use textile_core::modes::synth::{self as synth, synthesize_with, SynthParams};
use textile_core::*;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let bytes = std::fs::read(&args[1]).expect("read exemplar");
    let arg = |i: usize, d: i64| args.get(i).map(|s| s.parse().expect("number")).unwrap_or(d);
    let (cols, rows, mib) = (arg(2, 8), arg(3, 5), arg(4, 64));
    let ex = Exemplar::from_bytes(&bytes, &ExemplarOptions::default()).expect("exemplar");
    let an = Analysis::build(&ex, &NoProgress);
    let p = SynthParams::default();
    let pyr = Pyramid::new((mib as u64) << 20);
    let (mut synthesized, mut delivered) = (0u64, 0u64);
    let t = Instant::now();
    for i in 0..cols {
        for j in 0..rows {
            let r = Rect::new(256 * i, 256 * j, 256, 256);
            let s = synthesize_with(&pyr, &an, &p, an.levels(), r).expect("synth");
            synthesized += s.synthesized;
            delivered += 65536;
        }
    }
    let el = t.elapsed();
    let whole = synth::synthesis_cost(&an, &p, an.levels(), Rect::new(0, 0, 256 * cols, 256 * rows));
    println!("one window: ratio {:.3}", whole as f64 / delivered as f64);
    println!(
        "{cols}x{rows} tiles: ratio {:.3}, {:.2} ms/tile, {:?}",
        synthesized as f64 / delivered as f64,
        el.as_secs_f64() * 1000.0 / (cols * rows) as f64,
        pyr.stats()
    );
}
