//! The randomness mask over the exemplar (`R_E`, design note §1.9): black everywhere, synthesis
//! is the tiling; a black region of the exemplar comes out unbroken wherever it appears;
//! windows stay the same pixels cut from larger ones; the mask is part of the analysis id, and
//! an analysis read from a file serves only with the mask it was made with attached.

mod common;

use textile_core::modes::synth::{synthesize, SynthParams};
use textile_core::{Analysis, Defaults, Exemplar, NoProgress, ParamReader, Pyramid, Rect, RgbWindow, Source, View};

/// `ex` with a mask made by `value(x, y)`, built through the public preparation (an image of
/// the exemplar's size).
fn masked(ex: &Exemplar, value: impl Fn(u32, u32) -> u8) -> Exemplar {
    let m = ex.width;
    let px: Vec<[u8; 4]> = (0..m * m)
        .map(|i| {
            let v = value(i % m, i / m);
            [v, v, v, 255]
        })
        .collect();
    let mask = Exemplar::from_rgba(
        m,
        m,
        &px,
        &textile_core::ExemplarOptions { toroidal: Some(ex.toroidal), ..Default::default() },
    );
    ex.clone().with_randomness_mask(&mask).expect("mask")
}

fn render(ex: &Exemplar, an: &Analysis, mode: &str, rect: Rect) -> RgbWindow {
    let src = Source::new(ex, an);
    let p = Defaults::builtin(&src).request(&src, ParamReader::request(vec![("mode", mode)]).unwrap()).unwrap();
    p.render(&src, &Pyramid::off(), View::native(rect)).unwrap().image
}

#[test]
fn a_black_mask_keeps_the_exemplar_tiled() {
    let ex = masked(&common::toroidal_exemplar(64, 3), |_, _| 0);
    let an = Analysis::build(&ex, &NoProgress);
    let rect = Rect::new(-100, 37, 150, 90);
    assert_eq!(render(&ex, &an, "synth", rect), render(&ex, &an, "tiling", rect));
}

#[test]
fn a_black_region_comes_out_unbroken_and_windows_are_stitched_parts() {
    // A 20×20 black box of the exemplar: it is neither jittered nor corrected, and nothing
    // jumps or is corrected into it, so it is copied whole wherever it appears.
    let plain = common::toroidal_exemplar(64, 5);
    let inside = |x: u32, y: u32| (20..40).contains(&x) && (20..40).contains(&y);
    let ex = masked(&plain, |x, y| if inside(x, y) { 0 } else { 255 });
    // Template match: every place the element's corner texel appears, is the whole 16×16
    // element (the box two texels in from its edge) there, texel for texel?
    let unbroken = |ex: &Exemplar| {
        let an = Analysis::build(ex, &NoProgress);
        let w = synthesize(&an, &SynthParams::default(), an.levels(), Rect::new(0, 0, 512, 512)).unwrap();
        let (mut whole, mut total) = (0, 0);
        for j in 0..512 - 16 {
            for i in 0..512 - 16 {
                if w.get(i, j) != (22, 22) {
                    continue;
                }
                total += 1;
                let copy =
                    (0..16).all(|dy| (0..16).all(|dx| w.get(i + dx, j + dy) == (22 + dx as u32, 22 + dy as u32)));
                whole += copy as usize;
            }
        }
        (whole as f64 / total.max(1) as f64, total)
    };
    let (with_mask, n) = unbroken(&ex);
    let (without, _) = unbroken(&plain);
    assert!(n >= 5, "the element appears ({n} times)");
    // Measured: 64 of 64 appearances whole with the mask, 0 of 41 without.
    assert!(with_mask >= 0.95 && without < 0.5, "whole: {with_mask:.3} with the mask, {without:.3} without");
    // Windows are the same pixels cut from a larger one.
    let an = Analysis::build(&ex, &NoProgress);
    let big = render(&ex, &an, "synth", Rect::new(-50, 70, 96, 80));
    let part = render(&ex, &an, "synth", Rect::new(-19, 101, 40, 30));
    for j in 0..30 {
        for i in 0..40 {
            assert_eq!(part.pixel(i, j), big.pixel(i + 31, j + 31));
        }
    }
}

#[test]
fn the_mask_is_part_of_the_analysis_and_must_be_attached() {
    let plain = common::toroidal_exemplar(64, 7);
    let ex = masked(&plain, |x, _| (x * 4) as u8);
    let other = masked(&plain, |_, y| (y * 4) as u8);
    let an = Analysis::build(&ex, &NoProgress);
    assert_ne!(an.header.id, Analysis::build(&plain, &NoProgress).header.id);
    assert_ne!(an.header.id, Analysis::build(&other, &NoProgress).header.id);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("a.tex");
    an.save(&path).unwrap();
    let mut loaded = Analysis::load(&path).unwrap();
    let rect = Rect::new(0, 0, 32, 32);
    let err = synthesize(&loaded, &SynthParams::default(), loaded.levels(), rect).unwrap_err();
    assert!(err.to_string().contains("randomness mask"), "{err}");
    assert!(loaded.attach(&other).is_err() && loaded.attach(&plain).is_err());
    loaded.attach(&ex).unwrap();
    assert_eq!(
        synthesize(&loaded, &SynthParams::default(), loaded.levels(), rect).unwrap(),
        synthesize(&an, &SynthParams::default(), an.levels(), rect).unwrap()
    );
}
