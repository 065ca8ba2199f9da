//! Chaos mosaic: window composition at every zoom, zero iterations = the tiling, seeds, the
//! period (a mosaic on a torus), and parameter validation.

mod common;

use proptest::prelude::*;
use textile_core::modes::mosaic::{render, MosaicParams};
use textile_core::{Exemplar, Rect, RgbWindow};

type Render = fn(&Exemplar, &MosaicParams, u32, Rect) -> textile_core::Result<RgbWindow>;

fn stitch(render: Render, ex: &Exemplar, p: &MosaicParams, k: u32, whole: Rect, sx: i64, sy: i64) -> Vec<u8> {
    let w = whole.width() as usize;
    let mut out = vec![0u8; 3 * whole.area() as usize];
    for (y0, y1) in [(whole.y0, whole.y0 + sy), (whole.y0 + sy, whole.y1)] {
        for (x0, x1) in [(whole.x0, whole.x0 + sx), (whole.x0 + sx, whole.x1)] {
            let r = Rect { x0, y0, x1, y1 };
            let part = render(ex, p, k, r).unwrap();
            for j in 0..r.height() as usize {
                for i in 0..r.width() as usize {
                    let d = 3 * ((y0 - whole.y0) as usize * w + j * w + (x0 - whole.x0) as usize + i);
                    let s = 3 * (j * r.width() as usize + i);
                    out[d..d + 3].copy_from_slice(&part.pixels[s..s + 3]);
                }
            }
        }
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, .. ProptestConfig::default() })]

    #[test]
    fn union_equals_stitched_parts(
        far in prop::sample::select(vec![0i64, -(1 << 38), 1 << 38, 12345]),
        dx in -3000i64..3000, dy in -3000i64..3000,
        w in 2i64..300, h in 2i64..300, fx in 0.0f64..1.0, fy in 0.0f64..1.0,
        k in prop::sample::select(vec![0u32, 0, 1, 2, 3, 4, 6]), seed in any::<u64>(), it in 0u32..12,
        world in prop::sample::select(vec![None, Some(256i64), Some(4096)]),
    ) {
        let view: Render = render;
        let ex = common::small_exemplar();
        let p = MosaicParams { seed, iterations: it, period: world, ..MosaicParams::default() };
        let whole = Rect::new((far >> k) + dx, (far >> k) + dy, w, h);
        let sx = ((w as f64 * fx) as i64).clamp(1, w - 1);
        let sy = ((h as f64 * fy) as i64).clamp(1, h - 1);
        let full = view(ex, &p, k, whole).unwrap();
        prop_assert_eq!(full.pixels, stitch(view, ex, &p, k, whole, sx, sy));
    }
}

#[test]
fn zoomed_out_views_of_the_plain_tiling_are_its_exact_box_filter() {
    // Without moved blocks or smoothing every pixel's footprint lies in one tile of the
    // exemplar: the average of the footprint around the centre's source is the box filter of
    // the native pixels, byte for byte (zoom-outs 1–3, where the view averages footprints).
    let ex = common::small_exemplar();
    let p = MosaicParams { iterations: 0, smoothing: 0, ..MosaicParams::default() };
    for k in 1..=3 {
        let f = 1i64 << k;
        for r in [Rect::new(-37, 5, 70, 45), Rect::new((1 << 30) + 3, -(1 << 20), 33, 20)] {
            let native = Rect { x0: r.x0 * f, y0: r.y0 * f, x1: r.x1 * f, y1: r.y1 * f };
            let boxed = render(ex, &p, 0, native).unwrap().box_down(f as usize);
            assert_eq!(render(ex, &p, k, r).unwrap(), boxed, "zoom-out {k} {r:?}");
        }
    }
}

fn tiled(ex: &Exemplar, r: Rect) -> Vec<u8> {
    let m = ex.width as i64;
    let mut v = Vec::new();
    for y in r.y0..r.y1 {
        for x in r.x0..r.x1 {
            v.extend_from_slice(&ex.pixels[(y.rem_euclid(m) * m + x.rem_euclid(m)) as usize]);
        }
    }
    v
}

#[test]
fn zero_iterations_without_smoothing_is_the_tiling() {
    let ex = common::small_exemplar();
    let p = MosaicParams { iterations: 0, smoothing: 0, ..MosaicParams::default() };
    for r in [Rect::new(0, 0, 200, 150), Rect::new(-(1 << 30) - 7, 99, 130, 70)] {
        assert_eq!(render(ex, &p, 0, r).unwrap().pixels, tiled(ex, r));
    }
    // With iterations the blocks move: not the tiling.
    let moved = MosaicParams { smoothing: 0, ..MosaicParams::default() };
    let r = Rect::new(0, 0, 256, 256);
    assert_ne!(render(ex, &moved, 0, r).unwrap().pixels, tiled(ex, r));
}

#[test]
fn seeds_change_the_texture_and_periods_repeat() {
    let ex = common::small_exemplar();
    let r = Rect::new(-100, 40, 160, 120);
    let a = render(ex, &MosaicParams { seed: 1, ..MosaicParams::default() }, 0, r).unwrap();
    let b = render(ex, &MosaicParams { seed: 2, ..MosaicParams::default() }, 0, r).unwrap();
    assert_ne!(a, b);
    for period in [256i64, 1024, 8192] {
        let p = MosaicParams { seed: 5, period: Some(period), ..MosaicParams::default() };
        let base: RgbWindow = render(ex, &p, 0, r).unwrap();
        for (i, j) in [(1, 0), (0, -1), (3, 7)] {
            let moved = Rect::new(r.x0 + i * period, r.y0 + j * period, r.width(), r.height());
            assert_eq!(render(ex, &p, 0, moved).unwrap(), base, "period {period} shift ({i},{j})");
        }
    }
}

#[test]
fn invalid_parameters_are_refused() {
    let ex = common::small_exemplar();
    let r = Rect::new(0, 0, 8, 8);
    for p in [
        MosaicParams { iterations: 65, ..MosaicParams::default() },
        MosaicParams { smoothing: 4, ..MosaicParams::default() },
        MosaicParams { block_area: (800, 700), ..MosaicParams::default() },
        MosaicParams { block_area: (10, 750), ..MosaicParams::default() },
        MosaicParams { period: Some(48), ..MosaicParams::default() },
        MosaicParams { period: Some(32), ..MosaicParams::default() },
    ] {
        assert!(matches!(render(ex, &p, 0, r), Err(textile_core::CoreError::Param { .. })), "{p:?}");
    }
}
