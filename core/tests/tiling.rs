//! `mode=tiling` is the exemplar repeated as it is: native pixels are the exemplar's texels at
//! `(x mod m, y mod m)`, a zoomed-out pixel is the exact box average of the texels it covers,
//! and seed and world change nothing.

mod common;

use textile_core::{Defaults, ParamReader, Pyramid, Rect, RgbWindow, Source, View};

fn render(query: &[(&str, &str)], zoom_out: u32, rect: Rect) -> RgbWindow {
    let (ex, an) = (common::small_exemplar(), common::small());
    let src = Source::new(ex, an);
    let mut pairs = vec![("mode", "tiling")];
    pairs.extend_from_slice(query);
    let p = Defaults::builtin(&src).request(&src, ParamReader::request(pairs).unwrap()).unwrap();
    p.render(&src, &Pyramid::off(), View::out(zoom_out, rect)).unwrap().image
}

#[test]
fn native_pixels_are_the_exemplar_repeated() {
    let ex = common::small_exemplar();
    let m = ex.width as i64;
    let rect = Rect::new(-3 * m - 5, 7 * m + 11, 150, 90);
    let img = render(&[], 0, rect);
    for j in 0..rect.height() {
        for i in 0..rect.width() {
            let (x, y) = ((rect.x0 + i).rem_euclid(m), (rect.y0 + j).rem_euclid(m));
            assert_eq!(img.pixel(i as u32, j as u32), ex.pixels[(y * m + x) as usize], "({i}, {j})");
        }
    }
}

#[test]
fn zoomed_out_pixels_are_box_averages_and_seed_and_world_change_nothing() {
    let rect = Rect::new(-40, 24, 48, 32);
    for k in 1..=3u32 {
        let f = 1i64 << k;
        let native = render(&[], 0, Rect { x0: rect.x0 * f, y0: rect.y0 * f, x1: rect.x1 * f, y1: rect.y1 * f });
        assert_eq!(render(&[], k, rect), native.box_down(f as usize), "zoom-out {k}");
    }
    let far = render(&[], 12, rect);
    let mean = far.pixel(0, 0);
    assert!(far.pixels.chunks(3).all(|p| p == mean), "beyond the pyramid: one colour");
    assert_eq!(render(&[("seed", "7"), ("world", "4")], 1, rect), render(&[], 1, rect));
}
