//! The request's spatial modulation of randomness (`controls`, R_S, design note §1.9): windows
//! stay the same pixels cut from larger ones with strokes and noise across their borders and
//! far away; a calm stroke (value 0) over an area gives the tiled exemplar there (a toroidal
//! exemplar, whose zero-randomness synthesis is the tiling); no controls change nothing.

mod common;

use base64::Engine;
use textile_core::{Analysis, Defaults, Exemplar, NoProgress, ParamReader, Pyramid, Rect, RgbWindow, Source, View};

fn encode(json: &str) -> String {
    base64::engine::general_purpose::URL_SAFE_NO_PAD.encode(json)
}

fn render(ex: &Exemplar, an: &Analysis, query: &[(&str, &str)], rect: Rect) -> RgbWindow {
    let src = Source::new(ex, an);
    let p = Defaults::builtin(&src).request(&src, ParamReader::request(query.to_vec()).unwrap()).unwrap();
    p.render(&src, &Pyramid::off(), View::native(rect)).unwrap().image
}

#[test]
fn windows_with_strokes_and_noise_are_stitched_parts() {
    let (ex, an) = (common::small_exemplar(), common::small());
    for (x0, y0) in [(-40i64, 30i64), (5 << 35, -(3 << 36))] {
        let controls = encode(&format!(
            r#"{{"noise": {{"scale": 32, "range": [0.1, 0.9]}}, "strokes": [{{"at": [{}, {}], "radius": 9, "soft": 12, "value": 0}}, {{"at": [{}, {}], "radius": 3, "soft": 0, "value": 1}}]}}"#,
            x0 + 40,
            y0 + 31,
            x0 + 70,
            y0 + 60
        ));
        let q = [("controls", controls.as_str())];
        let whole = render(ex, an, &q, Rect::new(x0, y0, 96, 80));
        assert_ne!(whole, render(ex, an, &[], Rect::new(x0, y0, 96, 80)), "the controls change the texture");
        for (px, py, pw, ph) in [(0, 0, 41, 33), (41, 33, 55, 47), (30, 20, 20, 50)] {
            let part = render(ex, an, &q, Rect::new(x0 + px, y0 + py, pw, ph));
            assert_eq!(part, common::crop(&whole, px as u32, py as u32, pw as u32, ph as u32), "at {x0},{y0}");
        }
    }
}

#[test]
fn a_calm_stroke_keeps_the_tiled_exemplar_under_it() {
    let ex = common::toroidal_exemplar(64, 11);
    let an = Analysis::build(&ex, &NoProgress);
    let calm = encode(r#"{"strokes": [{"at": [0, 0], "radius": 3000, "soft": 100, "value": 0}]}"#);
    let q = [("controls", calm.as_str())];
    let near = Rect::new(-60, -40, 120, 90);
    assert_eq!(render(&ex, &an, &q, near), render(&ex, &an, &[("mode", "tiling")], near));
    let far = Rect::new(9000, 9000, 64, 64);
    assert_ne!(render(&ex, &an, &q, far), render(&ex, &an, &[("mode", "tiling")], far));
    // Outside the stroke, the texture is the one without controls.
    assert_eq!(render(&ex, &an, &q, far), render(&ex, &an, &[], far));
}

#[test]
fn inside_a_features_inner_radius_the_output_is_the_exemplar_around_its_source() {
    let (ex, an) = (common::small_exemplar(), common::small());
    let m = ex.width as i64;
    // Two features, one straddling the border of two windows, one far away.
    for (x, y) in [(-37i64, 50i64), (7 << 36, -(9 << 35))] {
        let json = format!(r#"{{"features": [{{"at": [{x}, {y}], "source": [30, 25], "inner": 10, "outer": 24}}]}}"#);
        let c = encode(&json);
        let q = [("controls", c.as_str())];
        let rect = Rect::new(x - 40, y - 30, 80, 64);
        let img = render(ex, an, &q, rect);
        let mut inside = 0;
        for j in 0..rect.height() {
            for i in 0..rect.width() {
                let (dx, dy) = (rect.x0 + i - x, rect.y0 + j - y);
                // Pixels whose seam blend (3 texels) reads only the feature's coordinates.
                if dx * dx + dy * dy < 49 {
                    let (u, v) = ((30 + dx).rem_euclid(m), (25 + dy).rem_euclid(m));
                    assert_eq!(img.pixel(i as u32, j as u32), ex.pixels[(v * m + u) as usize], "({dx}, {dy})");
                    inside += 1;
                }
            }
        }
        assert!(inside > 140);
        // The windows that cut the feature in parts agree with the whole.
        for (px, py, pw, ph) in [(0, 0, 40, 30), (40, 30, 40, 34), (31, 12, 20, 40)] {
            let part = render(ex, an, &q, Rect::new(rect.x0 + px, rect.y0 + py, pw, ph));
            assert_eq!(part, common::crop(&img, px as u32, py as u32, pw as u32, ph as u32));
        }
    }
    // A source outside the exemplar is refused.
    let src = Source::new(ex, an);
    let bad = encode(r#"{"features": [{"at": [0, 0], "source": [64, 3], "inner": 4, "outer": 8}]}"#);
    let e = Defaults::builtin(&src).request(&src, ParamReader::request(vec![("controls", bad.as_str())]).unwrap());
    assert!(e.unwrap_err().to_string().contains("outside"));
}
