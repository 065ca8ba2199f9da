//! Candidate-search benchmark (issue: fast analysis of large exemplars): analysis time with the
//! exact k-d tree search and with the coherent grid search, and the recall of the exact
//! candidate sets (a coherent candidate counts when it is the same texel or one texel off), per
//! exemplar and side, with the per-level recall of `C_2`.
//!
//! `cargo bench -p textile-core --bench index [-- SIDES]` (default sides 64,128,256,512; the
//! exemplars are the development set's 256² `gravel`, `bark` and `brick`, resampled; set
//! `SHARED` to the shared directory when it is not beside the repository).

use std::path::PathBuf;
use std::time::Instant;

use textile_core::analysis::{IndexChoice, FIRST_CORRECTED_LEVEL};
use textile_core::{Analysis, Cancel, Exemplar, ExemplarOptions, NoProgress};

fn exemplar(name: &str, side: u32) -> Option<Exemplar> {
    let shared = std::env::var("SHARED")
        .map(PathBuf::from)
        .unwrap_or_else(|_| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared"));
    let bytes = std::fs::read(shared.join(format!("exemplars/{name}_256.png"))).ok()?;
    let img = image::load_from_memory(&bytes).ok()?.to_rgba8();
    let img = image::imageops::resize(&img, side, side, image::imageops::FilterType::Lanczos3);
    let px: Vec<[u8; 4]> = img.pixels().map(|p| p.0).collect();
    Some(Exemplar::from_rgba(side, side, &px, &ExemplarOptions::default()))
}

/// Fraction of candidates `k` of `b` within one texel (toroidal distance) of those of `a`.
fn recall(a: &Analysis, b: &Analysis, level: usize, k: usize) -> f64 {
    let m = a.width() as i64;
    let (ca, cb) = (&a.corrected[level].cands, &b.corrected[level].cands);
    let near = |p: u32, q: u32| {
        let d = |u: i64, v: i64| (u - v).abs().min(m - (u - v).abs());
        d((p & 0xFFFF) as i64, (q & 0xFFFF) as i64) <= 1 && d((p >> 16) as i64, (q >> 16) as i64) <= 1
    };
    ca.iter().zip(cb).filter(|(x, y)| near(x[k].coord, y[k].coord)).count() as f64 / ca.len() as f64
}

fn main() {
    let sides: Vec<u32> = std::env::args()
        .skip(1)
        .find(|a| !a.starts_with('-'))
        .map(|s| s.split(',').filter_map(|v| v.parse().ok()).collect())
        .unwrap_or_else(|| vec![64, 128, 256, 512]);
    println!(
        "| exemplar | side | exact s | coherent s | speed-up | recall C1 | recall C2 | C2 per level (coarse → fine) |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for name in ["gravel", "bark", "brick"] {
        for &side in &sides {
            let Some(ex) = exemplar(name, side) else {
                eprintln!("{name}_256.png not found: set SHARED to the shared directory");
                return;
            };
            let time = |index| {
                let t = Instant::now();
                let a = Analysis::try_build_with(&ex, index, &NoProgress, &Cancel::new()).expect("analysis");
                (a, t.elapsed().as_secs_f64())
            };
            let (exact, te) = time(IndexChoice::Exact);
            let (fast, tf) = time(IndexChoice::Coherent);
            let levels = exact.corrected.len();
            let mean = |k| (0..levels).map(|l| recall(&exact, &fast, l, k)).sum::<f64>() / levels as f64;
            let per: Vec<String> = (0..levels)
                .map(|l| format!("{}: {:.1}", l as u32 + FIRST_CORRECTED_LEVEL, 100.0 * recall(&exact, &fast, l, 1)))
                .collect();
            println!(
                "| {name} | {side}² | {te:.2} | {tf:.2} | {:.1}× | {:.1} % | {:.1} % | {} |",
                te / tf,
                100.0 * mean(0),
                100.0 * mean(1),
                per.join(", ")
            );
        }
    }
}
