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
