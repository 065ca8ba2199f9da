//! Spatial determinism of window synthesis: a window equals the same pixels cut from any larger
//! window, at every level, anywhere on the plane; and the result does not depend on thread
//! count, a save/load round trip, or request order.

mod common;

use proptest::prelude::*;
use textile_core::modes::synth::{render, synthesize, Randomness, SynthParams};
use textile_core::{Analysis, NoProgress, Rect};

fn stitched(an: &Analysis, p: &SynthParams, level: u32, whole: Rect, sx: i64, sy: i64) -> Vec<u32> {
    // Four parts split at (sx, sy) (relative to the window origin), synthesized separately.
    let w = whole.width() as usize;
    let mut out = vec![u32::MAX; whole.area() as usize];
    let xs = [(whole.x0, whole.x0 + sx), (whole.x0 + sx, whole.x1)];
    let ys = [(whole.y0, whole.y0 + sy), (whole.y0 + sy, whole.y1)];
    for &(y0, y1) in &ys {
        for &(x0, x1) in &xs {
            let r = Rect { x0, y0, x1, y1 };
            if r.is_empty() {
                continue;
            }
            let part = synthesize(an, p, level, r).expect("part");
            for j in 0..r.height() {
                for i in 0..r.width() {
                    let dst = (y0 - whole.y0 + j) as usize * w + (x0 - whole.x0 + i) as usize;
                    out[dst] = part.coords[(j * r.width() + i) as usize];
                }
            }
        }
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, .. ProptestConfig::default() })]

    #[test]
    fn union_equals_stitched_parts(
        far in prop::sample::select(vec![0i64, -(1 << 40), 1 << 40, -(1 << 31) * 256, 977]),
        dx in -600i64..600, dy in -600i64..600,
        w in 2i64..300, h in 2i64..300,
        fx in 0.0f64..1.0, fy in 0.0f64..1.0,
        level in 0u32..=6, seed in any::<u64>(),
    ) {
        let an = common::small();
        let p = SynthParams { seed, ..SynthParams::default() };
        let whole = Rect::new(far + dx, far + dy, w, h);
        let sx = ((w as f64 * fx) as i64).clamp(1, w - 1);
        let sy = ((h as f64 * fy) as i64).clamp(1, h - 1);
        let full = synthesize(an, &p, level, whole).expect("whole");
        prop_assert_eq!(full.coords, stitched(an, &p, level, whole, sx, sy));
    }
}

#[test]
fn single_pixels_agree_with_a_window() {
    let an = common::small();
    let p = SynthParams::default();
    let whole = synthesize(an, &p, 6, Rect::new(-7, -9, 23, 19)).unwrap();
    for (j, i) in [(0, 0), (5, 7), (18, 22), (11, 3)] {
        let one = synthesize(an, &p, 6, Rect::new(-7 + i, -9 + j, 1, 1)).unwrap();
        assert_eq!(one.coords[0], whole.coords[(j * 23 + i) as usize], "pixel ({i},{j})");
    }
}

#[test]
fn thread_count_does_not_change_pixels() {
    let an = common::small();
    let p = SynthParams { seed: 42, ..SynthParams::default() };
    let r = Rect::new(-300, 129, 301, 257);
    let run =
        |n| rayon::ThreadPoolBuilder::new().num_threads(n).build().unwrap().install(|| render(an, &p, 0, r).unwrap());
    let one = run(1);
    assert_eq!(one, run(4));
    assert_eq!(one, run(7));
}

#[test]
fn save_load_round_trip_gives_identical_output() {
    let an = common::small();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("gravel.tex");
    an.save(&path).unwrap();
    let back = Analysis::load(&path).unwrap();
    assert_eq!(back.header, an.header);
    let p = SynthParams { seed: 3, ..SynthParams::default() };
    let r = Rect::new(1000, -2000, 128, 96);
    assert_eq!(render(an, &p, 0, r).unwrap(), render(&back, &p, 0, r).unwrap());
    assert_eq!(back.to_bytes(), an.to_bytes());
}

#[test]
fn periodic_output_repeats_exactly_with_its_period() {
    let an = common::small();
    let n = 256;
    let p = SynthParams { seed: 9, period: Some(n), ..SynthParams::default() };
    let base = render(an, &p, 0, Rect::new(-40, 17, 96, 80)).unwrap();
    for (i, j) in [(1, 0), (0, 1), (-1, 3), (1 << 20, -(1 << 22))] {
        let moved = render(an, &p, 0, Rect::new(-40 + n * i, 17 + n * j, 96, 80)).unwrap();
        assert_eq!(base, moved, "shift by ({i},{j}) periods");
    }
    // Without a period the same shift gives another texture.
    let q = SynthParams { period: None, ..p.clone() };
    assert_ne!(
        render(an, &q, 0, Rect::new(-40, 17, 96, 80)).unwrap(),
        render(an, &q, 0, Rect::new(216, 17, 96, 80)).unwrap()
    );
}

#[test]
fn seeds_give_different_textures() {
    let an = common::small();
    let r = Rect::new(0, 0, 64, 64);
    let a = render(an, &SynthParams { seed: 1, ..SynthParams::default() }, 0, r).unwrap();
    let b = render(an, &SynthParams { seed: 2, ..SynthParams::default() }, 0, r).unwrap();
    let differing = a.pixels.iter().zip(&b.pixels).filter(|(x, y)| x != y).count();
    assert!(differing > a.pixels.len() / 2, "only {differing} bytes differ");
}

#[test]
fn zero_randomness_without_correction_is_the_tiled_exemplar_anywhere() {
    let an = common::small();
    let p = SynthParams { randomness: Randomness::Uniform(0), passes: 0, ..SynthParams::default() };
    let m = an.width() as i64;
    for (x0, y0) in [(0, 0), (-77, -5), (1 << 40, -(1 << 39) - 3)] {
        let w = synthesize(an, &p, an.levels(), Rect::new(x0, y0, 70, 70)).unwrap();
        for j in 0..70 {
            for i in 0..70 {
                let (sx, sy) = w.get(i as usize, j as usize);
                assert_eq!((sx as i64, sy as i64), ((x0 + i).rem_euclid(m), (y0 + j).rem_euclid(m)));
            }
        }
    }
}

#[test]
fn coherent_zoomed_out_views_are_the_box_average_of_native_pixels() {
    // A zoomed-out pixel shows the box mean of the exemplar block its coarse coordinate's
    // descendants would cover: exactly its native pixels box-filtered wherever synthesis keeps
    // coherence. Without jitter or correction it keeps it everywhere on a toroidal exemplar
    // (on another, the tiling's wraps are seams, which native views blend).
    let an = &Analysis::build(&common::toroidal_exemplar(64, 11), &NoProgress);
    let p = SynthParams { randomness: Randomness::Uniform(0), passes: 0, ..SynthParams::default() };
    for k in 1..=3u32 {
        let f = 1i64 << k;
        for (x0, y0) in [(-64, 32), (1 << 30, -(1 << 29) - 8)] {
            let native = render(an, &p, 0, Rect::new(x0 * f, y0 * f, 64 * f, 32 * f)).unwrap();
            let out = render(an, &p, k, Rect::new(x0, y0, 64, 32)).unwrap();
            assert_eq!(out, native.box_down(f as usize), "zoom-out {k} at ({x0}, {y0})");
        }
    }
}
