//! The umbrella mode's storage (issue 15; the paper's Table 1): words of
//! `J = b·w·h + 2·b·v + n·(1 + 3v) + k·W·H` for a region of 64 × 24 grid cells — base textures,
//! base vertices, modified umbrellas, cell lists (their actual mean length) — against the
//! texture it represents, one word per texel at native resolution. Development exemplars from
//! `../shared/exemplars` when present, else the test fixtures.
//!
//! `cargo bench -p textile-core --bench umbrella_storage`

use std::path::PathBuf;

use textile_core::modes::umbrella::extract::RAYS;
use textile_core::modes::umbrella::{arrange::Arrangement, elements, storage_words, UmbrellaParams};
use textile_core::{Exemplar, ExemplarOptions};

fn main() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    println!("| exemplar | b | elements | G | n | mean list | J (words) | texture (words) | ratio |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for name in ["leaves", "smallstone", "gravel", "granite"] {
        let shared = root.join(format!("../../shared/exemplars/{name}.png"));
        let fixture = root.join(format!("tests/fixtures/{name}.png"));
        let Some(bytes) = std::fs::read(&shared).or_else(|_| std::fs::read(&fixture)).ok() else {
            println!("| {name} | (not found) |");
            continue;
        };
        let ex = Exemplar::from_bytes(&bytes, &ExemplarOptions::default()).expect("exemplar");
        let Ok((el, id)) = elements(&ex) else {
            println!("| {name} | no elements |");
            continue;
        };
        let p = UmbrellaParams::default();
        let arr = Arrangement::new(&el, &p, &id);
        let (cw, ch) = (64i64, 24i64);
        let lists = arr.lists(0, 0, cw, ch);
        let mean_list = lists.iter().map(|l| l.len()).sum::<usize>() as f64 / lists.len() as f64;
        let j = storage_words(&el, &arr, cw as u64, ch as u64) as f64 - (arr.k as f64 - mean_list) * (cw * ch) as f64;
        let texture = (cw * arr.g * ch * arr.g) as f64;
        println!(
            "| {name} | {} | {} | {} | {} | {mean_list:.1} | {j:.0} | {texture:.0} | {:.1}:1 |",
            el.bases.len(),
            el.found,
            arr.g,
            arr.table.len(),
            texture / j
        );
    }
    println!("(v = {} vertices per umbrella: the centre and {RAYS} rim vertices)", RAYS + 1);
}
