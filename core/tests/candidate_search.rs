//! The two candidate searches of the analysis (`index`): the coherent search keeps the rules of
//! the exact one (`C_1` is the texel itself, `C_2` far enough from it), finds mostly the same
//! `C_2`, and gives identical analysis bytes whatever the thread count.

mod common;

use textile_core::analysis::{IndexChoice, SearchIndex};
use textile_core::{Analysis, Cancel, Exemplar, ExemplarOptions, NoProgress};

/// The embedded gravel at `side`² (non-toroidal, stochastic: the hard case for search).
fn gravel(side: u32) -> Exemplar {
    let img = image::open(common::embedded_exemplar("gravel.png")).expect("decode").to_rgba8();
    let img = image::imageops::resize(&img, side, side, image::imageops::FilterType::Lanczos3);
    let px: Vec<[u8; 4]> = img.pixels().map(|p| p.0).collect();
    Exemplar::from_rgba(side, side, &px, &ExemplarOptions { toroidal: Some(false), ..Default::default() })
}

fn bytes(a: &Analysis) -> Vec<u8> {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("a.tex");
    a.save(&path).expect("save");
    std::fs::read(&path).expect("read")
}

#[test]
fn coherent_candidates_keep_the_rules_and_mostly_equal_the_exact_ones() {
    let ex = gravel(256);
    let exact = Analysis::try_build_with(&ex, IndexChoice::Exact, &NoProgress, &Cancel::new()).unwrap();
    let fast = Analysis::try_build_with(&ex, IndexChoice::Coherent, &NoProgress, &Cancel::new()).unwrap();
    assert_eq!(exact.header.index, SearchIndex::Exact);
    assert_eq!(fast.header.index, SearchIndex::Coherent);
    assert_ne!(exact.header.id, fast.header.id, "the search is part of the analysis id");
    let m = 256i64;
    let xy = |c: u32| ((c & 0xFFFF) as i64, (c >> 16) as i64);
    let (mut near, mut total) = (0usize, 0usize);
    for (i, (e, f)) in exact.corrected.iter().zip(&fast.corrected).enumerate() {
        let separation = (m * 5 + 99) / 100;
        for (u, (ce, cf)) in e.cands.iter().zip(&f.cands).enumerate() {
            // Every texel, along the edges too, is its own first candidate.
            let own = (u as i64 % m) as u32 | ((u as i64 / m) as u32) << 16;
            assert_eq!((ce[0].coord, cf[0].coord), (own, own), "level {i} texel {u}");
            let ((x1, y1), (x2, y2)) = (xy(cf[0].coord), xy(cf[1].coord));
            assert!((x1 - x2).pow(2) + (y1 - y2).pow(2) >= separation * separation, "level {i} texel {u}: too close");
            // The feature stored with a candidate is its texel's.
            assert_eq!(cf[1].feat, e.cands[(y2 * m + x2) as usize][0].feat, "level {i} texel {u}");
            let ((a, b), (c, d)) = (xy(ce[1].coord), xy(cf[1].coord));
            near += ((a - c).abs() <= 1 && (b - d).abs() <= 1) as usize;
            total += 1;
        }
    }
    let recall = near as f64 / total as f64;
    assert!(recall >= 0.95, "recall of the exact second candidates {recall:.3}");
}

#[test]
fn analyses_are_identical_with_one_thread_and_many() {
    let ex = gravel(128);
    for index in [IndexChoice::Coherent, IndexChoice::Exact] {
        let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
        let many = rayon::ThreadPoolBuilder::new().num_threads(4).build().unwrap();
        let a = one.install(|| Analysis::try_build_with(&ex, index, &NoProgress, &Cancel::new()).unwrap());
        let b = many.install(|| Analysis::try_build_with(&ex, index, &NoProgress, &Cancel::new()).unwrap());
        assert_eq!(bytes(&a), bytes(&b), "{index:?}");
    }
}

#[test]
fn auto_is_exact_below_256_and_coherent_from_256() {
    assert_eq!(IndexChoice::Auto.resolve(128), SearchIndex::Exact);
    assert_eq!(IndexChoice::Auto.resolve(256), SearchIndex::Coherent);
    assert_eq!(IndexChoice::Exact.resolve(1024), SearchIndex::Exact);
    assert!(IndexChoice::parse("kd").is_err());
}
