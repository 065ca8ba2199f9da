//! Magnification beyond native zoom (design note §1.8): magnified windows are the same pixels
//! cut from any larger magnified window (every mode, across texel and tile borders, far away),
//! a magnified view box-filtered back is close to the native one, and magnifying past the
//! supported steps is an error.

mod common;

use textile_core::modes::magnify::MAX_ZOOM_IN;
use textile_core::{Defaults, ParamReader, Pyramid, Rect, RgbWindow, Source, View};

fn render(mode: &str, view: View) -> RgbWindow {
    let (ex, an) = (common::small_exemplar(), common::small());
    let src = Source::new(ex, an);
    let p = Defaults::builtin(&src).request(&src, ParamReader::request(vec![("mode", mode)]).unwrap()).unwrap();
    p.render(&src, &Pyramid::off(), view).unwrap().image
}

#[test]
fn magnified_windows_equal_the_same_pixels_of_a_larger_one_in_every_mode() {
    for mode in ["synth", "mosaic", "tiling"] {
        for k in 1..=MAX_ZOOM_IN {
            for (x0, y0) in [(-37i64, 21i64), (3 << 36, -(5 << 33) + 3)] {
                let big = Rect::new(x0, y0, 70, 50);
                let whole = render(mode, View::at(-(k as i64), big));
                assert_eq!((whole.width, whole.height), (70, 50));
                // Parts cut at odd places: inside texels and across them.
                for (px, py, pw, ph) in [(0, 0, 33, 17), (33, 17, 37, 33), (5, 29, 11, 21)] {
                    let part = render(mode, View::at(-(k as i64), Rect::new(x0 + px, y0 + py, pw, ph)));
                    assert_eq!(
                        part,
                        common::crop(&whole, px as u32, py as u32, pw as u32, ph as u32),
                        "{mode} k {k} at {x0},{y0}"
                    );
                }
            }
        }
    }
}

#[test]
fn a_magnified_view_box_filtered_back_is_close_to_the_native_one() {
    // Magnifying interpolates between texel centres, so its 2^k × 2^k box average is a slight
    // blur of the native texel: bounded by the texel's differences to its neighbours. Measured
    // on the gravel crop: mean absolute difference per channel 5.6 (of 255) for k = 1, 2, 3;
    // the same view one texel off scores 16.5. The bound (10) leaves room for other textures'
    // contrast and catches any misplacement.
    let native = render("synth", View::native(Rect::new(-20, 40, 64, 64)));
    for k in 1..=3u32 {
        let s = 1i64 << k;
        let mag = render("synth", View::at(-(k as i64), Rect::new(-20 * s, 40 * s, 64 * s, 64 * s)));
        let back = mag.box_down(s as usize);
        let mad = back.pixels.iter().zip(&native.pixels).map(|(a, b)| a.abs_diff(*b) as f64).sum::<f64>()
            / native.pixels.len() as f64;
        assert!(mad < 10.0, "k {k}: mean absolute difference {mad:.2}");
        let shifted = render("synth", View::native(Rect::new(-19, 40, 64, 64)));
        let off = back.pixels.iter().zip(&shifted.pixels).map(|(a, b)| a.abs_diff(*b) as f64).sum::<f64>()
            / native.pixels.len() as f64;
        assert!(off > mad * 2.0, "k {k}: one texel off {off:.2} against {mad:.2}");
    }
}

#[test]
fn magnifying_beyond_the_supported_steps_is_an_error() {
    let (ex, an) = (common::small_exemplar(), common::small());
    let src = Source::new(ex, an);
    let p =
        Defaults::builtin(&src).request(&src, ParamReader::request(Vec::<(String, String)>::new()).unwrap()).unwrap();
    let err = p.render(&src, &Pyramid::off(), View::at(-(MAX_ZOOM_IN as i64) - 1, Rect::new(0, 0, 8, 8)));
    assert!(err.unwrap_err().to_string().contains("magnification"));
}
