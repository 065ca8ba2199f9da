//! Zoom consistency: for every mode, a tile one zoom step out against its four children
//! box-filtered 2×2, on 16 far-apart tiles, at every zoom from native − 1 to the minzoom, on two
//! embedded exemplars. Zoomed-out tiles are rendered at the cost of native ones, not from 4^k
//! times the finest pixels, so they are close to, not exactly, the box filter of their
//! children. The bounds, in 1/255 per channel (mean |difference| over the 16 tiles; the worst
//! tile; the worst drift of a tile's mean colour):
//!
//! - `tiling`, `mosaic`: 3, 5, 1. Their zoomed-out pixels are exact box means of the exemplar
//!   around one label's source; only pixels across a block edge (mosaic) and rounding differ.
//! - `synth`: 8, 9, 1. A zoomed-out tile shows the coordinates of synthesis level `L − k` with
//!   the exact box mean of the exemplar block their descendants would cover; what the finer
//!   levels' correction moves is the difference (measured 3.5, 5.6, 7.2, 6.6, 2.8, … on the
//!   gravel from one step out; at most 4.2 on the brick). The exact alternative, synthesizing
//!   the finest level under the zoomed-out tile, costs 4^k times the pixels.
//! - `umbrella`: 5, 5.5, 2 at every zoom but the one where drawn umbrellas hand over to the
//!   background (measured 14.5 and 15.0 there): 16, 17, 2.

mod common;

use textile_core::{
    Analysis, Defaults, Exemplar, ExemplarOptions, ModeParams, NoProgress, ParamReader, Pyramid, Rect, RgbWindow,
    Source, View, MODE_NAMES,
};

fn source(name: &str) -> (Exemplar, Analysis) {
    let bytes = std::fs::read(common::embedded_exemplar(name)).expect("read exemplar");
    let ex = Exemplar::from_bytes(&bytes, &ExemplarOptions::default()).expect("decode exemplar");
    let an = Analysis::build(&ex, &NoProgress);
    (ex, an)
}

fn params(src: &Source, mode: &str) -> ModeParams {
    Defaults::builtin(src).request(src, ParamReader::request([("mode", mode)]).unwrap()).unwrap()
}

fn render(p: &ModeParams, src: &Source, zoom_out: u32, rect: Rect) -> RgbWindow {
    p.render(src, &Pyramid::off(), View::out(zoom_out, rect)).unwrap().image
}

/// `(mean |a − b| per channel, |mean a − mean b| per channel)` over all pixels, in 1/255.
fn compare(a: &RgbWindow, b: &RgbWindow) -> (f64, f64) {
    assert_eq!((a.width, a.height), (b.width, b.height));
    let n = a.pixels.len() as f64;
    let mad = a.pixels.iter().zip(&b.pixels).map(|(&x, &y)| (x as f64 - y as f64).abs()).sum::<f64>() / n;
    let mut drift: f64 = 0.0;
    for c in 0..3 {
        let mean = |w: &RgbWindow| w.pixels.iter().skip(c).step_by(3).map(|&v| v as f64).sum::<f64>() * 3.0 / n;
        drift = drift.max((mean(a) - mean(b)).abs());
    }
    (mad, drift)
}

/// Sixteen tiles of side `side` far apart (a 4×4 grid of positions thousands of tiles apart).
fn far_tiles(side: i64) -> impl Iterator<Item = Rect> {
    (0..16i64).map(move |i| {
        let (tx, ty) = ((i % 4) * 7919 - 13_000, (i / 4) * 6007 - 9_000);
        Rect::new(tx * side, ty * side, side, side)
    })
}

/// `(mean, worst tile, drift)` bounds of a mode (see the module comment).
fn bounds(mode: &str) -> (f64, f64, f64) {
    match mode {
        "synth" => (8.0, 9.0, 1.0),
        "umbrella" => (5.0, 5.5, 2.0),
        _ => (3.0, 5.0, 1.0),
    }
}

/// Bounds of the one zoom at which a mode changes representation, if it has one.
fn handover_bounds(mode: &str) -> Option<(f64, f64, f64)> {
    (mode == "umbrella").then_some((16.0, 17.0, 2.0))
}

#[test]
fn zoomed_out_tiles_are_close_to_their_children_box_filtered() {
    let side = 64;
    let mut failures = Vec::new();
    for name in ["gravel.png", "brick.png"] {
        let (ex, an) = source(name);
        let prepared = textile_core::modes::Prepared::compute(&ex).unwrap();
        let src = Source::new(&ex, &an).with_prepared(&prepared);
        for mode in MODE_NAMES {
            let p = params(&src, mode);
            let mut beyond = Vec::new();
            for k in 1..=src.levels() {
                let (mut sum, mut worst, mut drift) = (0.0, 0.0f64, 0.0f64);
                let tiles: Vec<Rect> = far_tiles(side).collect();
                for &r in &tiles {
                    let parent = render(&p, &src, k, r);
                    let children = render(&p, &src, k - 1, r.children()).box_down(2);
                    let (mad, d) = compare(&parent, &children);
                    sum += mad;
                    worst = worst.max(mad);
                    drift = drift.max(d);
                }
                let mean = sum / tiles.len() as f64;
                eprintln!(
                    "{name} {mode} zoom-out {k}: mean |parent − children box-filtered| {mean:.2}, worst tile {worst:.2}, worst mean drift {drift:.2}"
                );
                let (bm, bw, bd) = bounds(mode);
                if mean > bm || worst > bw || drift > bd {
                    beyond.push((k, mean, worst, drift));
                }
            }
            // At most one zoom may exceed the bounds, within the handover bounds.
            let within = |&(_, m, w, d): &(u32, f64, f64, f64)| {
                handover_bounds(mode).is_some_and(|(bm, bw, bd)| m <= bm && w <= bw && d <= bd)
            };
            if beyond.len() > 1 || !beyond.iter().all(within) {
                failures.push(format!("{name} {mode}: (zoom-out, mean, worst, drift) beyond the bounds: {beyond:.2?}"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
