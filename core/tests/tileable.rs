//! `tileable` (Wei & Levoy 2000 with a TSVQ): the output wraps without a seam, the same seed
//! gives the same bytes, the TSVQ with unlimited backtracking finds exactly what exhaustive
//! search finds, and unusable sizes are clear errors (tiny exemplars: `tests/cli.rs`).

mod common;

use textile_core::tileable::{synthesize, Search, TileableOptions};
use textile_core::{Cancel, CoreError, Exemplar, ExemplarOptions, NoProgress, RgbWindow};

fn gravel(side: u32) -> Exemplar {
    let bytes = std::fs::read(common::embedded_exemplar("gravel.png")).unwrap();
    let img = image::load_from_memory(&bytes).unwrap().to_rgba8();
    let img = image::imageops::resize(&img, side, side, image::imageops::FilterType::Triangle);
    let px: Vec<[u8; 4]> = img.pixels().map(|p| p.0).collect();
    Exemplar::from_rgba(side, side, &px, &ExemplarOptions { toroidal: Some(false), ..Default::default() })
}

fn run(ex: &Exemplar, size: u32, seed: u64, search: Search) -> RgbWindow {
    synthesize(ex, &TileableOptions { size, seed, search }, &NoProgress, &Cancel::new()).unwrap()
}

/// Mean absolute difference between horizontally and vertically adjacent pixels: across the
/// wrap (last column to first, last row to first) over elsewhere. About 1 for a seamless tile.
fn wrap_seam_ratio(img: &RgbWindow) -> f64 {
    let (w, h) = (img.width as usize, img.height as usize);
    let px = |x: usize, y: usize| &img.pixels[3 * (y * w + x)..3 * (y * w + x) + 3];
    let diff = |a: &[u8], b: &[u8]| a.iter().zip(b).map(|(a, b)| (*a as f64 - *b as f64).abs()).sum::<f64>();
    let (mut wrap, mut nw, mut inner, mut ni) = (0.0, 0.0, 0.0, 0.0);
    for y in 0..h {
        for x in 0..w {
            let (right, down) = (px((x + 1) % w, y), px(x, (y + 1) % h));
            let d = diff(px(x, y), right) + 0.0;
            if x + 1 == w {
                (wrap, nw) = (wrap + d, nw + 1.0);
            } else {
                (inner, ni) = (inner + d, ni + 1.0);
            }
            let d = diff(px(x, y), down);
            if y + 1 == h {
                (wrap, nw) = (wrap + d, nw + 1.0);
            } else {
                (inner, ni) = (inner + d, ni + 1.0);
            }
        }
    }
    (wrap / nw) / (inner / ni)
}

#[test]
fn the_output_wraps_without_a_seam_and_a_seed_gives_the_same_bytes() {
    let ex = gravel(128);
    let search = Search::Tsvq { backtrack: 8 };
    let a = run(&ex, 128, 5, search);
    assert_eq!((a.width, a.height, a.pixels.len()), (128, 128, 3 * 128 * 128));
    let ratio = wrap_seam_ratio(&a);
    assert!((0.8..=1.2).contains(&ratio), "seam ratio {ratio}");
    // What the measure sees in an image that does not wrap: the exemplar itself.
    let plain = RgbWindow { width: 128, height: 128, pixels: ex.pixels.iter().flatten().copied().collect() };
    assert!(wrap_seam_ratio(&plain) > 1.3, "the seam measure sees no seam in the raw exemplar");
    assert_eq!(run(&ex, 128, 5, search), a, "same seed, same bytes");
    assert_ne!(run(&ex, 128, 6, search), a, "another seed, another texture");
    // Every output pixel is an exemplar colour.
    let colours: std::collections::HashSet<[u8; 3]> = ex.pixels.iter().copied().collect();
    assert!(a.pixels.chunks_exact(3).all(|p| colours.contains(&[p[0], p[1], p[2]])));
}

#[test]
fn tsvq_with_unlimited_backtracking_equals_exhaustive_search() {
    let ex = gravel(32);
    for seed in [1, 2] {
        let exact = run(&ex, 32, seed, Search::Exact);
        assert_eq!(run(&ex, 32, seed, Search::Tsvq { backtrack: usize::MAX }), exact, "seed {seed}");
    }
}

#[test]
fn unusable_requests_are_clear_errors() {
    let ex = gravel(128);
    let err = |size, search| {
        synthesize(&ex, &TileableOptions { size, seed: 0, search }, &NoProgress, &Cancel::new()).unwrap_err()
    };
    let s = Search::Tsvq { backtrack: 8 };
    for (size, says) in [(100, "multiple of 8"), (16, "outside 32"), (8192, "outside 32")] {
        let e = err(size, s);
        assert!(matches!(e, CoreError::Param { name: "size", .. }), "{e}");
        assert!(e.to_string().contains(says), "{size}: {e}");
    }
    assert!(err(64, Search::Tsvq { backtrack: 0 }).to_string().contains("at least 1"));
}

#[test]
fn make_toroidal_gives_an_exemplar_that_wraps() {
    let ex = gravel(64);
    assert!(!ex.toroidal && ex.preparation.seam_ratio > 1.5, "{}", ex.preparation.seam_ratio);
    let t = textile_core::tileable::make_toroidal(&ex, 0).unwrap();
    assert_eq!((t.width, t.toroidal, t.preparation.toroidal_synthesized), (64, true, true));
    assert!(t.preparation.seam_ratio <= 1.5, "seam ratio {}", t.preparation.seam_ratio);
    assert_eq!(textile_core::tileable::make_toroidal(&ex, 0).unwrap(), t, "deterministic");
}
