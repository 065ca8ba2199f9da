//! Per-sample queries: every sample equals the pixel of a window that contains it, for every
//! mode and zoom, in any order, alone or in a batch, cached or not; filtered samples at texel
//! centres with `lod = 0` equal integer samples; a batch shares its cones through the cache.

mod common;

use proptest::prelude::*;
use textile_core::samples::{self, Footprint, Texel};
use textile_core::{Defaults, ModeParams, ParamReader, Pyramid, Rect, Source, View, MODE_NAMES};

fn params(src: &Source, mode: &str) -> ModeParams {
    Defaults::builtin(src).request(src, ParamReader::request([("mode", mode), ("seed", "3")]).unwrap()).unwrap()
}

/// The pixel of `t` cut from a 48×40 window around it.
fn from_window(p: &ModeParams, src: &Source, t: Texel) -> [u8; 3] {
    let rect = Rect::new(t.x - 17, t.y - 23, 48, 40);
    let w = p.render(src, &Pyramid::off(), View::out(t.zoom_out, rect)).unwrap();
    w.image.pixel(17, 23)
}

fn texels(seed: u64, n: usize, spread: i64) -> Vec<Texel> {
    (0..n as i64)
        .map(|i| {
            let h = textile_core::hash::hash(0x5A, seed, i, 0, 0);
            let x = (h as i64 % spread) - spread / 2 + if i % 3 == 0 { -(1 << 36) } else { 0 };
            let y = ((h >> 20) as i64 % spread) - spread / 2;
            Texel { x, y, zoom_out: (h >> 60) as u32 % 3 }
        })
        .collect()
}

#[test]
fn samples_equal_window_pixels_for_every_mode() {
    let (ex, an) = (common::small_exemplar(), common::small());
    let prepared = textile_core::modes::Prepared::compute(ex).unwrap();
    let src = Source::new(ex, an).with_prepared(&prepared);
    let pts = texels(1, 40, 300);
    for mode in MODE_NAMES {
        let p = params(&src, mode);
        let got = samples::texels(&p, &src, &Pyramid::new(16 << 20), &pts).unwrap();
        for (t, c) in pts.iter().zip(&got.colors) {
            assert_eq!(*c, from_window(&p, &src, *t), "mode {mode}, {t:?}");
        }
    }
}

#[test]
fn order_batching_and_cache_do_not_change_samples() {
    let (ex, an) = (common::small_exemplar(), common::small());
    let prepared = textile_core::modes::Prepared::compute(ex).unwrap();
    let src = Source::new(ex, an).with_prepared(&prepared);
    let p = params(&src, "synth");
    let pts = texels(2, 300, 200);
    let whole = samples::texels(&p, &src, &Pyramid::off(), &pts).unwrap().colors;
    // Reversed, in a warm cache.
    let cache = Pyramid::new(32 << 20);
    let rev: Vec<Texel> = pts.iter().rev().copied().collect();
    let mut got = samples::texels(&p, &src, &cache, &rev).unwrap().colors;
    got.reverse();
    assert_eq!(got, whole);
    // One by one, through the same (now warm) cache.
    for (i, t) in pts.iter().enumerate().step_by(7) {
        assert_eq!(samples::texels(&p, &src, &cache, &[*t]).unwrap().colors[0], whole[i], "{t:?}");
    }
}

#[test]
fn a_batch_computes_shared_cones_once() {
    let (ex, an) = (common::small_exemplar(), common::small());
    let prepared = textile_core::modes::Prepared::compute(ex).unwrap();
    let src = Source::new(ex, an).with_prepared(&prepared);
    let p = params(&src, "synth");
    // 64 texels spread over a 64×64 native area.
    let pts: Vec<Texel> = (0..64).map(|i| Texel { x: (i % 8) * 8 + 3, y: (i / 8) * 8 + 5, zoom_out: 0 }).collect();
    let batch = samples::texels(&p, &src, &Pyramid::new(16 << 20), &pts).unwrap();
    let apart: u64 = pts.iter().map(|t| samples::texels(&p, &src, &Pyramid::off(), &[*t]).unwrap().synthesized).sum();
    assert!(batch.synthesized * 4 < apart, "batch {} vs one cone per point {apart}", batch.synthesized);
    // Seen before as a tile: nothing more to compute.
    let cache = Pyramid::new(16 << 20);
    p.render(&src, &cache, View::native(Rect::new(0, 0, 64, 64))).unwrap();
    assert_eq!(samples::texels(&p, &src, &cache, &pts).unwrap().synthesized, 0);
}

#[test]
fn filtered_samples_at_centres_equal_texels_and_blend_between_levels() {
    let (ex, an) = (common::small_exemplar(), common::small());
    let prepared = textile_core::modes::Prepared::compute(ex).unwrap();
    let src = Source::new(ex, an).with_prepared(&prepared);
    for mode in MODE_NAMES {
        let p = params(&src, mode);
        let pts = texels(3, 30, 500);
        let fps: Vec<Footprint> = pts
            .iter()
            .map(|t| {
                let s = (1u64 << t.zoom_out) as f64;
                Footprint { u: (t.x as f64 + 0.5) * s, v: (t.y as f64 + 0.5) * s, lod: t.zoom_out as f32 }
            })
            .collect();
        let a = samples::texels(&p, &src, &Pyramid::off(), &pts).unwrap().colors;
        let b = samples::footprints(&p, &src, &Pyramid::off(), &fps, 6).unwrap().colors;
        assert_eq!(a, b, "mode {mode}");
    }
    // Halfway between two texels: their average (within rounding).
    let p = params(&src, "synth");
    let c = samples::texels(
        &p,
        &src,
        &Pyramid::off(),
        &[Texel { x: 4, y: 9, zoom_out: 0 }, Texel { x: 5, y: 9, zoom_out: 0 }],
    )
    .unwrap()
    .colors;
    let mid = samples::footprints(&p, &src, &Pyramid::off(), &[Footprint { u: 5.0, v: 9.5, lod: 0.0 }], 6).unwrap();
    for ch in 0..3 {
        let avg = (c[0][ch] as i32 + c[1][ch] as i32 + 1) / 2;
        assert!((mid.colors[0][ch] as i32 - avg).abs() <= 1, "{:?} vs {c:?}", mid.colors[0]);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]
    /// Any split of a batch gives the same colours as the whole.
    #[test]
    fn split_batches_agree(seed in 0u64..1000, cut in 1usize..59) {
        let (ex, an) = (common::small_exemplar(), common::small());
        let prepared = textile_core::modes::Prepared::compute(ex).unwrap();
        let src = Source::new(ex, an).with_prepared(&prepared);
        let p = params(&src, "synth");
        let pts = texels(seed, 60, 150);
        let whole = samples::texels(&p, &src, &Pyramid::off(), &pts).unwrap().colors;
        let mut parts = samples::texels(&p, &src, &Pyramid::off(), &pts[..cut]).unwrap().colors;
        parts.extend(samples::texels(&p, &src, &Pyramid::off(), &pts[cut..]).unwrap().colors);
        prop_assert_eq!(parts, whole);
    }
}

#[test]
fn batches_bigger_than_a_chunk_equal_the_window_they_cover() {
    // 70 000 texels (over one chunk of 65 536) in a shuffled 256² area, with duplicates; and as
    // many footprints at texel centres, lod 0 (over one footprint chunk).
    let (ex, an) = (common::small_exemplar(), common::small());
    let prepared = textile_core::modes::Prepared::compute(ex).unwrap();
    let src = Source::new(ex, an).with_prepared(&prepared);
    let p = params(&src, "synth");
    let rect = Rect::new(-100, 40, 256, 256);
    let window = p.render(&src, &Pyramid::off(), View::native(rect)).unwrap();
    let pts: Vec<Texel> = (0..70_000u64)
        .map(|i| {
            let h = textile_core::hash::hash(0x7C, 9, i as i64, 0, 0);
            Texel { x: rect.x0 + (h % 256) as i64, y: rect.y0 + ((h >> 16) % 256) as i64, zoom_out: 0 }
        })
        .collect();
    let cache = Pyramid::new(64 << 20);
    let got = samples::texels(&p, &src, &cache, &pts).unwrap();
    for (t, c) in pts.iter().zip(&got.colors) {
        assert_eq!(*c, window.image.pixel((t.x - rect.x0) as u32, (t.y - rect.y0) as u32), "{t:?}");
    }
    let fps: Vec<Footprint> =
        pts.iter().take(10_000).map(|t| Footprint { u: t.x as f64 + 0.5, v: t.y as f64 + 0.5, lod: 0.0 }).collect();
    let got = samples::footprints(&p, &src, &cache, &fps, 0).unwrap();
    assert_eq!(got.colors[..], samples::texels(&p, &src, &cache, &pts[..10_000]).unwrap().colors[..]);
    // A bad sample past the first chunk is named by its place in the whole batch.
    let mut bad = fps.clone();
    bad[9_000].u = f64::NAN;
    let e = samples::footprints(&p, &src, &cache, &bad, 0).unwrap_err();
    assert!(e.to_string().contains("9000"), "{e}");
}
