//! Property tests of every control together (issue 14): for random features (straddling the
//! window's borders and its padding), strokes and noise, on exemplars with and without a
//! randomness mask and a lattice, near the origin and far away, a window is the same pixels as
//! its parts rendered separately — parts through a shared pyramidal cache, in either order, the
//! window without one — at native zoom, zoomed out and magnified.

mod common;

use std::sync::OnceLock;

use base64::Engine;
use proptest::prelude::*;
use textile_core::{Analysis, Defaults, Exemplar, NoProgress, ParamReader, Pyramid, Rect, RgbWindow, Source, View};

/// Three 64² exemplars: plain gravel (not toroidal), a toroidal one with a randomness mask
/// keeping a 16×16 box, and a toroidal one with a 4×4 lattice.
fn textures() -> &'static [(Exemplar, Analysis)] {
    static T: OnceLock<Vec<(Exemplar, Analysis)>> = OnceLock::new();
    T.get_or_init(|| {
        let plain = common::small_exemplar().clone();
        let toroidal = common::toroidal_exemplar(64, 21);
        let px: Vec<[u8; 4]> = (0..64 * 64)
            .map(|i| {
                let v = if (20..36).contains(&(i % 64)) && (20..36).contains(&(i / 64)) { 0 } else { 255 };
                [v, v, v, 255]
            })
            .collect();
        let opts = textile_core::ExemplarOptions { toroidal: Some(true), ..Default::default() };
        let mask = Exemplar::from_rgba(64, 64, &px, &opts);
        let masked = toroidal.clone().with_randomness_mask(&mask).unwrap();
        let lattice = toroidal.with_lattice(4, 4).unwrap();
        [plain, masked, lattice]
            .into_iter()
            .map(|ex| {
                let an = Analysis::build(&ex, &NoProgress);
                (ex, an)
            })
            .collect()
    })
}

fn render(t: &(Exemplar, Analysis), controls: &str, seed: &str, pyr: &Pyramid, view: View) -> RgbWindow {
    let src = Source::new(&t.0, &t.1);
    let mut q = vec![("mode", "synth"), ("seed", seed)];
    if !controls.is_empty() {
        q.push(("controls", controls));
    }
    let p = Defaults::builtin(&src).request(&src, ParamReader::request(q).unwrap()).unwrap();
    p.render(&src, pyr, view).unwrap().image
}

/// A view of `rect` at zoom offset `dz` (−2..=1: zoomed out, native, magnified).
fn view(rect: Rect, dz: i32) -> View {
    View::at(-dz as i64, rect)
}

/// Controls JSON: features and strokes at offsets from `(x0, y0)`, optional noise.
fn controls_json(
    x0: i64,
    y0: i64,
    features: &[(i64, i64, i64, i64, i64, i64)],
    strokes: &[(i64, i64, i64, i64, u8)],
    noise: Option<(u32, u8, u8)>,
) -> String {
    let f: Vec<String> = features
        .iter()
        .map(|&(dx, dy, u, v, inner, extra)| {
            format!(
                r#"{{"at": [{}, {}], "source": [{u}, {v}], "inner": {inner}, "outer": {}}}"#,
                x0 + dx,
                y0 + dy,
                inner + extra
            )
        })
        .collect();
    let s: Vec<String> = strokes
        .iter()
        .map(|&(dx, dy, r, soft, value)| {
            format!(
                r#"{{"at": [{}, {}], "radius": {r}, "soft": {soft}, "value": {}}}"#,
                x0 + dx,
                y0 + dy,
                value as f64 / 10.0
            )
        })
        .collect();
    let mut parts = vec![format!(r#""features": [{}]"#, f.join(", ")), format!(r#""strokes": [{}]"#, s.join(", "))];
    if let Some((scale, lo, hi)) = noise {
        let (lo, hi) = (lo.min(hi) as f64 / 10.0, lo.max(hi) as f64 / 10.0);
        parts.push(format!(r#""noise": {{"scale": {}, "range": [{lo}, {hi}]}}"#, 1u32 << scale));
    }
    format!("{{{}}}", parts.join(", "))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, .. ProptestConfig::default() })]

    #[test]
    fn every_control_keeps_windows_stitched_parts(
        tex in 0usize..3,
        far in prop::sample::select(vec![0i64, -(1 << 38), (1 << 39) - 400, 12345]),
        w in 8i64..120, h in 8i64..120,
        cut in 0.05f64..0.95, vertical in any::<bool>(),
        features in prop::collection::vec((-60i64..180, -60i64..180, 0i64..64, 0i64..64, 0i64..14, 0i64..40), 0..4),
        strokes in prop::collection::vec((-60i64..180, -60i64..180, 0i64..30, 0i64..20, 0u8..=10), 0..4),
        noise in prop::option::of((3u32..8, 0u8..=10, 0u8..=10)),
        dz in -2i32..=1, seed in 0u32..1000, reversed in any::<bool>(),
    ) {
        let t = &textures()[tex];
        let c = controls_json(far, far, &features, &strokes, noise);
        let controls = base64::engine::general_purpose::URL_SAFE_NO_PAD.encode(&c);
        let seed = seed.to_string();
        // The window over the controls' area at its zoom (coordinates scale with it).
        let o = if dz < 0 { far >> -dz } else { far << dz };
        let whole_rect = Rect::new(o, o, w, h);
        let whole = render(t, &controls, &seed, &Pyramid::off(), view(whole_rect, dz));
        let parts = if vertical {
            let s = ((w as f64 * cut) as i64).clamp(1, w - 1);
            [(Rect::new(o, o, s, h), (0, 0)), (Rect::new(o + s, o, w - s, h), (s as u32, 0))]
        } else {
            let s = ((h as f64 * cut) as i64).clamp(1, h - 1);
            [(Rect::new(o, o, w, s), (0, 0)), (Rect::new(o, o + s, w, h - s), (0, s as u32))]
        };
        let cache = Pyramid::new(16 << 20);
        let order: Vec<usize> = if reversed { vec![1, 0] } else { vec![0, 1] };
        for i in order {
            let (r, (ox, oy)) = parts[i];
            let part = render(t, &controls, &seed, &cache, view(r, dz));
            prop_assert_eq!(&part, &common::crop(&whole, ox, oy, r.width() as u32, r.height() as u32), "{} part {}", c, i);
        }
    }
}
